//! The covering ladder on random point sets: how many points each level of the halving ladder
//! (16/8/4/2/1 sheets for a square) needs, against the thesis's single 9-sheeted covering, and
//! how many point copies each inserts before it reaches the 1-sheeted torus.
//!
//! `cargo run --release -p orbitri --example ladder [RUNS]` prints one Markdown table.

use orbitri::sort::SplitMix;
use orbitri::space::{FlatTorus, Ladder, Lattice};
use orbitri::{Engine, OrbitSpace};

/// Inserts uniform random points until the triangulation is 1-sheeted; returns the number of
/// points at which each level was first reached and the copies inserted on the way.
fn run(lattice: &Lattice<2>, kind: Ladder, seed: u64) -> (Vec<usize>, usize) {
    let torus = FlatTorus::with_ladder(lattice.clone(), kind);
    let levels = torus.levels();
    let mut reached = vec![usize::MAX; levels];
    let mut e = Engine::new(torus);
    let mut rng = SplitMix::new(seed);
    let mut copies = 0;
    let mut n = 0;
    while !e.is_one_sheeted() {
        let f = [rng.unit(), rng.unit()];
        let p = lattice.wrap(lattice.cartesian(&f)).unwrap().0;
        copies += e.sheets();
        e.insert(p);
        n += 1;
        for r in reached.iter_mut().take(e.level() + 1) {
            *r = (*r).min(n);
        }
    }
    (reached, copies)
}

fn median(mut v: Vec<usize>) -> f64 {
    v.sort_unstable();
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m] as f64
    } else {
        (v[m - 1] + v[m]) as f64 / 2.0
    }
}

fn main() {
    let runs: u64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().expect("RUNS is a number"))
        .unwrap_or(200);
    let h = 3f64.sqrt() / 2.0;
    let cases: [(&str, Lattice<2>); 4] = [
        ("square 1×1", Lattice::cuboid([1.0, 1.0]).unwrap()),
        ("rectangle 1×2", Lattice::cuboid([1.0, 2.0]).unwrap()),
        ("hexagonal", Lattice::new([[1.0, 0.0], [0.5, h]]).unwrap()),
        ("oblique", Lattice::new([[1.0, 0.0], [0.3, 0.9]]).unwrap()),
    ];
    println!("Median over {runs} random sets (uniform, one point at a time).\n");
    println!("| lattice | halving sheets | points to reach each level | points to 1 sheet (halving / grid) | copies inserted until 1 sheet (halving / grid) |");
    println!("|---|---|---|---|---|");
    for (name, lattice) in cases {
        let torus = FlatTorus::with_ladder(lattice.clone(), Ladder::Halving);
        let sheets: Vec<usize> = (0..torus.levels()).map(|k| torus.sheets(k)).collect();
        let grid_sheets = FlatTorus::with_ladder(lattice.clone(), Ladder::Grid).sheets(0);
        let mut reach: Vec<Vec<usize>> = vec![Vec::new(); sheets.len()];
        let (mut one_h, mut one_g, mut cop_h, mut cop_g) = (vec![], vec![], vec![], vec![]);
        for seed in 1..=runs {
            let (r, c) = run(&lattice, Ladder::Halving, seed);
            for k in 0..r.len() {
                reach[k].push(r[k]);
            }
            one_h.push(*r.last().unwrap());
            cop_h.push(c);
            let (rg, cg) = run(&lattice, Ladder::Grid, seed);
            one_g.push(*rg.last().unwrap());
            cop_g.push(cg);
        }
        let levels: Vec<String> = sheets
            .iter()
            .zip(&reach)
            .map(|(s, r)| format!("{s}: {}", median(r.clone())))
            .collect();
        let sheets: Vec<String> = sheets.iter().map(|s| s.to_string()).collect();
        println!(
            "| {name} | {} (grid {grid_sheets}) | {} | {} / {} | {} / {} |",
            sheets.join("→"),
            levels.join(", "),
            median(one_h),
            median(one_g),
            median(cop_h),
            median(cop_g)
        );
    }
}
