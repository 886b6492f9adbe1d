use orbitri::sort::SplitMix;
use orbitri::{BuildOptions, FlatTorus3, PeriodicDelaunay3};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args[1].parse().unwrap();
    let b: Vec<f64> = if args[2] == "t" {
        vec![]
    } else {
        args[2].split(',').map(|s| s.parse().unwrap()).collect()
    };
    let thr: usize = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(1000);
    let space = if b.len() == 3 {
        FlatTorus3::cuboid([b[0], b[1], b[2]]).unwrap()
    } else {
        FlatTorus3::triclinic([[1.0, 0.0, 0.0], [0.31, 0.9, 0.0], [-0.22, 0.17, 1.1]]).unwrap()
    };
    let mut r = SplitMix::new(11 + n as u64);
    let s = if b.len() == 3 {
        [b[0], b[1], b[2]]
    } else {
        [1.5; 3]
    };
    let pts: Vec<[f64; 3]> = (0..n)
        .map(|_| [r.unit() * s[0], r.unit() * s[1], r.unit() * s[2]])
        .collect();
    let t = std::time::Instant::now();
    let tri = PeriodicDelaunay3::build_with(
        space,
        &pts,
        BuildOptions {
            dummy_threshold: thr,
            ..Default::default()
        },
        |_| std::ops::ControlFlow::Continue(()),
    )
    .unwrap();
    println!(
        "n={n} sheets={} C={} dummies={} build={:.3}s",
        tri.sheets(),
        tri.number_of_cells(),
        tri.used_dummy_points(),
        t.elapsed().as_secs_f64()
    );
    let t = std::time::Instant::now();
    tri.is_valid().unwrap();
    println!("valid {:.3}s", t.elapsed().as_secs_f64());
}
