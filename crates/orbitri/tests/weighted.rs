//! Weighted points (regular triangulations): an independent brute force (every cell's
//! orthogonal sphere is power-empty against all nearby periodic copies of every input,
//! hidden ones included; the cells tile the domain), zero and equal weights against the
//! unweighted triangulation, a constant added to every weight, hidden points and their
//! return after removals, and bad weights.

mod common;

use orbitri::sort::SplitMix;
use orbitri::{
    Copies, Error, FlatTorus, InputId, Inserted, PeriodicDelaunay, PeriodicDelaunay2,
    PeriodicDelaunay3,
};
use proptest::prelude::*;

/// Solves `A x = b` by Gaussian elimination with partial pivoting (independent of the
/// library's geometry).
fn solve<const D: usize>(mut a: [[f64; D]; D], mut b: [f64; D]) -> [f64; D] {
    for col in 0..D {
        let piv = (col..D)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        a.swap(col, piv);
        b.swap(col, piv);
        for r in col + 1..D {
            let f = a[r][col] / a[col][col];
            let pivot_row = a[col];
            for (x, p) in a[r].iter_mut().zip(pivot_row).skip(col) {
                *x -= f * p;
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = [0.0; D];
    for r in (0..D).rev() {
        let s: f64 = (r + 1..D).map(|c| a[r][c] * x[c]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    x
}

fn det<const D: usize>(m: [[f64; D]; D]) -> f64 {
    if D == 2 {
        m[0][0] * m[1][1] - m[0][1] * m[1][0]
    } else {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    }
}

/// The brute force: orthospheres power-empty against every copy of every input within
/// a window of offsets, stored cells positively oriented and of total volume `sheets ×`
/// the domain's, and every input a vertex, a duplicate or hidden.
fn check<const D: usize, const N: usize>(
    tri: &PeriodicDelaunay<D, N>,
    pts: &[[f64; D]],
    weights: &[f64],
) where
    FlatTorus<D>: orbitri::OrbitSpace<N, Point = [f64; D], Elem = [i8; D]>,
{
    tri.is_valid().unwrap();
    let m = tri.space().lattice().vectors();
    let scale2: f64 = m.iter().flatten().map(|x| x * x).sum();
    let wrapped: Vec<[f64; D]> = (0..pts.len())
        .map(|i| tri.position(InputId::new(i), [0; D]))
        .collect();
    let lift = |x: [f64; D], o: [i8; D]| -> [f64; D] {
        std::array::from_fn(|c| x[c] + (0..D).map(|k| o[k] as f64 * m[k][c]).sum::<f64>())
    };
    let window: Vec<[i8; D]> = (0..5usize.pow(D as u32))
        .map(|mut k| {
            std::array::from_fn(|_| {
                let o = (k % 5) as i8 - 2;
                k /= 5;
                o
            })
        })
        .collect();
    // every copy in the window, sorted along the first axis (each cell then looks at a slab)
    let mut copies: Vec<([f64; D], f64, usize)> = Vec::new();
    for (j, &x) in wrapped.iter().enumerate() {
        for &o in &window {
            copies.push((lift(x, o), weights[j], j));
        }
    }
    copies.sort_by(|a, b| a.0[0].total_cmp(&b.0[0]));
    let wmax = weights.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b));
    let mut volume = 0.0;
    for cell in tri.cells(Copies::Stored) {
        let p: [[f64; D]; N] =
            std::array::from_fn(|k| lift(wrapped[cell.vertices[k].index()], cell.offsets[k]));
        let w: [f64; N] = std::array::from_fn(|k| weights[cell.vertices[k].index()]);
        let d: [[f64; D]; D] =
            std::array::from_fn(|i| std::array::from_fn(|c| p[i + 1][c] - p[0][c]));
        let v = det(d) / if D == 3 { 6.0 } else { 2.0 };
        assert!(v > 0.0, "a cell is not positively oriented");
        volume += v;
        // 2 (p_i − p_0)·z = |p_i|² − |p_0|² − w_i + w_0
        let n2 = |x: [f64; D]| x.iter().map(|t| t * t).sum::<f64>();
        let a: [[f64; D]; D] = std::array::from_fn(|i| d[i].map(|t| 2.0 * t));
        let b: [f64; D] = std::array::from_fn(|i| n2(p[i + 1]) - n2(p[0]) - w[i + 1] + w[0]);
        let z = solve(a, b);
        let power = |x: [f64; D], wx: f64| n2(std::array::from_fn(|c| x[c] - z[c])) - wx;
        let rho = power(p[0], w[0]);
        // a copy in conflict has |x − z|² < ρ + w ≤ ρ + wmax
        let reach = (rho + wmax).max(0.0).sqrt() * (1.0 + 1e-6) + 1e-9;
        let from = copies.partition_point(|c| c.0[0] < z[0] - reach);
        for &(x, wx, j) in copies[from..].iter().take_while(|c| c.0[0] <= z[0] + reach) {
            let pw = power(x, wx) - rho;
            assert!(
                pw > -1e-9 * scale2,
                "input {j} (weight {wx}) at {x:?} is inside the orthogonal sphere of {cell:?}: {pw}"
            );
        }
        assert!(
            reach < 2.0 * scale2.sqrt(),
            "the window holds every copy in reach"
        );
    }
    let domain = det(m).abs();
    let sheets = tri.sheets() as f64;
    assert!(
        ((volume / sheets - domain) / domain).abs() < 1e-9,
        "{volume} vs {sheets}×{domain}"
    );
    let hidden = tri.hidden();
    assert_eq!(
        tri.number_of_vertices() + tri.duplicates() + hidden.len(),
        pts.len(),
        "every input is a vertex, a duplicate or hidden"
    );
    for i in hidden {
        assert!(tri.is_hidden(i));
    }
}

fn random<const D: usize>(n: usize, seed: u64, box_: f64, wmax: f64) -> (Vec<[f64; D]>, Vec<f64>) {
    let mut r = SplitMix::new(seed);
    let pts = (0..n)
        .map(|_| std::array::from_fn(|_| r.unit() * box_))
        .collect();
    let w = (0..n).map(|_| r.unit() * wmax).collect();
    (pts, w)
}

#[test]
fn random_weights_in_3d_cube_cuboid_and_triclinic() {
    let spaces = [
        (FlatTorus::cuboid([1.0; 3]).unwrap(), 1.0),
        (FlatTorus::cuboid([1.0, 1.5, 0.8]).unwrap(), 0.8),
        (
            FlatTorus::triclinic([[1.0, 0.0, 0.0], [0.31, 0.9, 0.0], [-0.22, 0.17, 1.1]]).unwrap(),
            0.9,
        ),
    ];
    for (space, b) in spaces {
        for (n, wmax) in [
            (5, 0.01),
            (40, 0.01),
            (300, 0.003),
            (2500, 0.0004),
            (2500, 0.004),
        ] {
            let (pts, w) = random::<3>(n, n as u64 + 3, b, wmax);
            let tri = PeriodicDelaunay3::build_weighted(space.clone(), &pts, &w).unwrap();
            check(&tri, &pts, &w);
            if n >= 2500 && wmax > 0.001 {
                assert!(
                    !tri.hidden().is_empty(),
                    "{n} points with weights up to {wmax}"
                );
            }
        }
    }
}

#[test]
fn random_weights_in_2d() {
    let spaces = [
        FlatTorus::cuboid([1.0, 1.0]).unwrap(),
        FlatTorus::cuboid([1.0, 0.7]).unwrap(),
        FlatTorus::triclinic([[1.0, 0.0], [0.4, 0.8]]).unwrap(),
    ];
    for space in spaces {
        for (n, wmax) in [(3, 0.02), (30, 0.02), (400, 0.003), (3000, 0.0005)] {
            let (pts, w) = random::<2>(n, n as u64 + 7, 0.7, wmax);
            let tri = PeriodicDelaunay2::build_weighted(space.clone(), &pts, &w).unwrap();
            check(&tri, &pts, &w);
        }
    }
}

/// Zero weights, equal weights and a constant added to every weight change nothing.
#[test]
fn equal_weights_are_the_delaunay_triangulation() {
    let space = FlatTorus::cuboid([1.0; 3]).unwrap();
    for n in [10, 1500] {
        let (pts, w) = random::<3>(n, 21, 1.0, 0.002);
        let plain = PeriodicDelaunay3::build(space.clone(), &pts).unwrap();
        let mut cells = plain.cells(Copies::Unique);
        cells.sort();
        for c in [0.0, 0.25, -3.0] {
            let same = vec![c; n];
            let t = PeriodicDelaunay3::build_weighted(space.clone(), &pts, &same).unwrap();
            let mut tc = t.cells(Copies::Unique);
            tc.sort();
            assert_eq!(tc, cells, "all weights {c}");
        }
        let base = PeriodicDelaunay3::build_weighted(space.clone(), &pts, &w).unwrap();
        let shifted: Vec<f64> = w.iter().map(|x| x + 0.5).collect();
        let t = PeriodicDelaunay3::build_weighted(space.clone(), &pts, &shifted).unwrap();
        let (mut a, mut b) = (base.cells(Copies::Unique), t.cells(Copies::Unique));
        a.sort();
        b.sort();
        assert_eq!(a, b);
        assert_eq!(base.hidden(), t.hidden());
    }
}

/// A point on another point: a larger weight hides the other, a smaller one is hidden, an
/// equal one is a duplicate.
#[test]
fn coincident_points_of_different_weights() {
    let space = FlatTorus::cuboid([1.0; 2]).unwrap();
    let (pts, w) = random::<2>(50, 3, 1.0, 0.0);
    let mut tri = PeriodicDelaunay2::build_weighted(space, &pts, &w).unwrap();
    assert_eq!(tri.insert_weighted(pts[7], -0.1).unwrap(), Inserted::Hidden);
    assert!(matches!(
        tri.insert_weighted(pts[7], 0.0).unwrap(),
        Inserted::Duplicate(_)
    ));
    assert!(matches!(
        tri.insert_weighted(pts[7], 0.001).unwrap(),
        Inserted::New(_)
    ));
    assert!(tri.is_hidden(InputId(7)));
    assert!(
        tri.is_hidden(InputId(51)),
        "its duplicate is hidden with it"
    );
    assert!(tri.is_hidden(InputId(50)));
    assert_eq!(
        tri.hidden()[..3],
        [InputId(7), InputId(50), InputId(51)],
        "{:?}",
        tri.hidden()
    );
    let mut all_pts = pts.clone();
    all_pts.extend([pts[7]; 3]);
    let mut all_w = w.clone();
    all_w.extend([-0.1, 0.0, 0.001]);
    check(&tri, &all_pts, &all_w);
    // removing the heavy point uncovers the others
    let how = tri.remove(InputId(52)).unwrap();
    assert!(
        !tri.is_hidden(InputId(7)),
        "{how:?} {:?} {:?}",
        tri.hidden(),
        tri.weights()
    );
    assert!(tri.is_hidden(InputId(50)));
    tri.is_valid().unwrap();
}

/// Removals uncover hidden points: the result equals a fresh build of what is left.
#[test]
fn removal_uncovers_hidden_points() {
    let space = FlatTorus::cuboid([1.0; 3]).unwrap();
    let (pts, w) = random::<3>(3000, 5, 1.0, 0.004);
    let mut tri = PeriodicDelaunay3::build_weighted(space.clone(), &pts, &w).unwrap();
    let hidden_before = tri.hidden().len();
    assert!(hidden_before > 50, "{hidden_before}");
    let mut r = SplitMix::new(9);
    let mut gone = std::collections::BTreeSet::new();
    while gone.len() < 1500 {
        gone.insert(r.below(3000));
    }
    let ids: Vec<InputId> = gone.iter().map(|&i| InputId::new(i)).collect();
    for &i in &ids[..300] {
        tri.remove(i).unwrap();
    }
    tri.remove_all(&ids[300..]).unwrap();
    let left: Vec<usize> = (0..3000).filter(|i| !gone.contains(i)).collect();
    let lp: Vec<[f64; 3]> = left.iter().map(|&i| pts[i]).collect();
    let lw: Vec<f64> = left.iter().map(|&i| w[i]).collect();
    let fresh = PeriodicDelaunay3::build_weighted(space, &lp, &lw).unwrap();
    let rename = |v: InputId| InputId::new(left[v.index()]);
    let mut want: Vec<_> = fresh
        .cells(Copies::Unique)
        .into_iter()
        .map(|mut c| {
            c.vertices = c.vertices.map(rename);
            c
        })
        .collect();
    let hidden_want: Vec<InputId> = fresh.hidden().into_iter().map(rename).collect();
    assert_eq!(tri.hidden(), hidden_want);
    let mut got = tri.cells(Copies::Unique);
    // the same cells up to the frame each is stored in
    let canon = |c: &orbitri::CellView<3, 4>| {
        let mut pairs: Vec<(u32, [i8; 3])> =
            (0..4).map(|k| (c.vertices[k].0, c.offsets[k])).collect();
        for a in 0..3 {
            let lo = pairs.iter().map(|p| p.1[a]).min().unwrap();
            for p in pairs.iter_mut() {
                p.1[a] -= lo;
            }
        }
        pairs.sort();
        pairs
    };
    let mut g: Vec<_> = got.iter_mut().map(|c| canon(c)).collect();
    let mut h: Vec<_> = want.iter_mut().map(|c| canon(c)).collect();
    g.sort();
    h.sort();
    assert_eq!(g, h);
}

#[test]
fn bad_weights_are_errors_naming_the_point() {
    let space = FlatTorus::cuboid([1.0; 3]).unwrap();
    let (pts, mut w) = random::<3>(20, 1, 1.0, 0.01);
    assert!(matches!(
        PeriodicDelaunay3::build_weighted(space.clone(), &pts, &w[..19]),
        Err(Error::WeightCount {
            points: 20,
            weights: 19
        })
    ));
    w[4] = f64::NAN;
    assert!(matches!(
        PeriodicDelaunay3::build_weighted(space.clone(), &pts, &w),
        Err(Error::BadWeight { index: 4, .. })
    ));
    w[4] = 1e9;
    let e = PeriodicDelaunay3::build_weighted(space.clone(), &pts, &w).unwrap_err();
    assert!(matches!(e, Error::WeightSpread { index: 4, .. }), "{e}");
    w[4] = 0.0;
    let mut tri = PeriodicDelaunay3::build_weighted(space, &pts, &w).unwrap();
    let before = tri.cells(Copies::Stored);
    assert!(matches!(
        tri.insert_weighted([0.5; 3], f64::INFINITY),
        Err(Error::BadWeight { index: 20, .. })
    ));
    assert!(tri.insert_weighted([0.5; 3], 1e9).is_err());
    assert_eq!(tri.cells(Copies::Stored), before);
    assert_eq!(tri.number_of_input_points(), 20);
}

/// A wide spread of weights moves a small set to a larger covering and back.
#[test]
fn wide_spreads_take_larger_coverings() {
    let space = FlatTorus::cuboid([1.0; 3]).unwrap();
    let (pts, mut w) = random::<3>(12, 8, 1.0, 0.0);
    w[0] = 0.3;
    let tri = PeriodicDelaunay3::build_weighted(space.clone(), &pts, &w).unwrap();
    assert!(tri.sheets() > 27, "{}", tri.sheets());
    check(&tri, &pts, &w);
    let (pts, w) = random::<3>(4000, 8, 1.0, 0.001);
    let mut tri = PeriodicDelaunay3::build_weighted(space, &pts, &w).unwrap();
    assert_eq!(tri.sheets(), 1);
    tri.insert_weighted([0.5; 3], 0.02).unwrap();
    let mut all_p = pts.clone();
    all_p.push([0.5; 3]);
    let mut all_w = w.clone();
    all_w.push(0.02);
    check(&tri, &all_p, &all_w);
}

/// Power cells: volumes sum to the domain's, hidden inputs get empty cells, and each
/// cell's volume agrees with an independent estimate (the share of sample points whose
/// least power distance goes to its point); equal weights give the Voronoi cells.
#[test]
fn laguerre_cells() {
    for (n, wmax) in [(40usize, 0.01), (2000, 0.002)] {
        let (pts, w) = random::<3>(n, 17, 1.0, wmax);
        let space = FlatTorus::cuboid([1.0; 3]).unwrap();
        let tri = PeriodicDelaunay3::build_weighted(space.clone(), &pts, &w).unwrap();
        let cells = tri.voronoi_cells();
        assert_eq!(cells.len(), n - tri.duplicates());
        let total: f64 = cells.iter().map(|c| c.volume).sum();
        assert!((total - 1.0).abs() < 1e-12, "{total}");
        for c in &cells {
            assert_eq!(c.volume == 0.0, tri.is_hidden(c.point), "{:?}", c.point);
            assert!(c.volume >= 0.0);
        }
        // sampled shares: each sample goes to the least power distance over nearby copies
        let mut r = SplitMix::new(4);
        let samples = 20_000;
        let mut count = vec![0usize; n];
        for _ in 0..samples {
            let x: [f64; 3] = std::array::from_fn(|_| r.unit());
            let mut best = (f64::INFINITY, 0);
            for (j, p) in pts.iter().enumerate() {
                let d2: f64 = (0..3)
                    .map(|c| {
                        let t = (x[c] - p[c]).rem_euclid(1.0);
                        t.min(1.0 - t).powi(2)
                    })
                    .sum();
                if d2 - w[j] < best.0 {
                    best = (d2 - w[j], j);
                }
            }
            count[best.1] += 1;
        }
        for c in &cells {
            let share = count[c.point.index()] as f64 / samples as f64;
            let sigma = (c.volume * (1.0 - c.volume) / samples as f64).sqrt();
            assert!(
                (share - c.volume).abs() < 6.0 * sigma + 1e-4,
                "{:?}: sampled {share} vs {}",
                c.point,
                c.volume
            );
        }
        let plain = PeriodicDelaunay3::build(space.clone(), &pts).unwrap();
        let same = PeriodicDelaunay3::build_weighted(space, &pts, &vec![0.5; n]).unwrap();
        for (a, b) in plain.voronoi_cells().iter().zip(same.voronoi_cells()) {
            assert!((a.volume - b.volume).abs() < 1e-14);
        }
    }
    // 2D: areas sum to the box's
    let (pts, w) = random::<2>(500, 2, 1.0, 0.004);
    let tri = PeriodicDelaunay2::build_weighted(FlatTorus::cuboid([1.0, 1.0]).unwrap(), &pts, &w)
        .unwrap();
    let total: f64 = tri.voronoi_cells().iter().map(|c| c.volume).sum();
    assert!((total - 1.0).abs() < 1e-12, "{total}");
    assert!(!tri.hidden().is_empty());
}

/// The Klein bottle takes equal weights (its Delaunay triangulation) and refuses a spread.
#[test]
fn manifolds_take_equal_weights_only() {
    let klein = orbitri::FlatManifold::klein_bottle(1.0, 1.0).unwrap();
    let (pts, _) = random::<2>(200, 4, 1.0, 0.0);
    let plain = orbitri::KleinTriangulation::build(klein.clone(), &pts).unwrap();
    let same =
        orbitri::KleinTriangulation::build_weighted(klein.clone(), &pts, &[0.01; 200]).unwrap();
    same.is_valid().unwrap();
    assert_eq!(plain.cells(Copies::Unique), same.cells(Copies::Unique));
    let mut w = vec![0.0; 200];
    w[9] = 0.001;
    let e = orbitri::KleinTriangulation::build_weighted(klein, &pts, &w).unwrap_err();
    assert!(matches!(e, Error::BadWeight { index: 9, .. }), "{e}");
}

/// A regular triangulation built point by point from empty (`new_weighted`, then
/// `insert_all_weighted` and `insert_weighted`) is the bulk build's.
#[test]
fn incremental_equals_bulk() {
    let space = FlatTorus::cuboid([1.0, 0.8, 1.2]).unwrap();
    let (pts, w) = random::<3>(1500, 31, 0.8, 0.003);
    let bulk = PeriodicDelaunay3::build_weighted(space.clone(), &pts, &w).unwrap();
    let mut inc = PeriodicDelaunay3::new_weighted(space);
    inc.insert_all_weighted(&pts[..700], &w[..700]).unwrap();
    for k in 700..1500 {
        inc.insert_weighted(pts[k], w[k]).unwrap();
    }
    inc.is_valid().unwrap();
    assert_eq!(inc.hidden(), bulk.hidden());
    assert_eq!(common::geometry(&inc), common::geometry(&bulk));
    assert!(matches!(
        inc.insert_all_weighted(&pts[..3], &w[..2]),
        Err(Error::WeightCount {
            points: 3,
            weights: 2
        })
    ));
}

#[derive(Clone, Debug)]
enum Op {
    Insert([f64; 2], f64),
    Remove(usize),
    RemoveAll(usize, usize),
    Move(usize, [f64; 2]),
}

fn op() -> impl Strategy<Value = Op> {
    // grid coordinates and a few weights: coincident points of other weights, orthogonal
    // ties and hidden points are common
    let coord = (0u32..12).prop_map(|k| k as f64 / 12.0);
    let point = [coord.clone(), coord];
    let weight = (0u32..4).prop_map(|k| k as f64 * 0.002);
    prop_oneof![
        4 => (point.clone(), weight).prop_map(|(p, w)| Op::Insert(p, w)),
        2 => any::<usize>().prop_map(Op::Remove),
        1 => (any::<usize>(), 1usize..5).prop_map(|(a, k)| Op::RemoveAll(a, k)),
        1 => (any::<usize>(), point).prop_map(|(i, p)| Op::Move(i, p)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(40),
        ..ProptestConfig::default()
    })]

    /// Random weighted insertions, removals and moves on a grid: valid after every step,
    /// every input a vertex, a duplicate or hidden, and at the end the fresh build's cells
    /// and hidden points.
    #[test]
    fn random_weighted_sequences(ops in proptest::collection::vec(op(), 1..70)) {
        let space = FlatTorus::cuboid([1.0, 1.0]).unwrap();
        let mut tri = PeriodicDelaunay2::new_weighted(space.clone());
        for (step, op) in ops.iter().enumerate() {
            let live: Vec<usize> = (0..tri.number_of_input_points())
                .filter(|&i| tri.contains(InputId::new(i)))
                .collect();
            match *op {
                Op::Insert(p, w) => {
                    tri.insert_weighted(p, w).unwrap();
                }
                Op::Remove(k) if !live.is_empty() => {
                    tri.remove(InputId::new(live[k % live.len()])).unwrap();
                }
                Op::RemoveAll(a, k) if !live.is_empty() => {
                    let mut ids: Vec<InputId> =
                        (0..k).map(|j| InputId::new(live[(a + 5 * j) % live.len()])).collect();
                    ids.sort_unstable();
                    ids.dedup();
                    tri.remove_all(&ids).unwrap();
                }
                Op::Move(k, p) if !live.is_empty() => {
                    tri.move_point(InputId::new(live[k % live.len()]), p).unwrap();
                }
                _ => {}
            }
            if tri.number_of_vertices() > 0 {
                prop_assert!(tri.is_valid().is_ok(), "step {step} {op:?}: {:?}", tri.is_valid());
            }
            let live = (0..tri.number_of_input_points()).filter(|&i| tri.contains(InputId::new(i))).count();
            prop_assert_eq!(tri.number_of_vertices() + tri.duplicates() + tri.hidden().len(), live);
        }
        let live: Vec<usize> = (0..tri.number_of_input_points())
            .filter(|&i| tri.contains(InputId::new(i)))
            .collect();
        if !live.is_empty() {
            let pts: Vec<[f64; 2]> = live.iter().map(|&i| tri.position(InputId::new(i), [0, 0])).collect();
            let ws: Vec<f64> = live.iter().map(|&i| tri.weights()[i]).collect();
            let fresh = PeriodicDelaunay2::build_weighted(space, &pts, &ws).unwrap();
            let hidden: Vec<InputId> = fresh.hidden().iter().map(|h| InputId::new(live[h.index()])).collect();
            prop_assert_eq!(tri.hidden(), hidden);
            if fresh.sheets() == tri.sheets() {
                prop_assert!(common::geometry(&tri) == common::geometry(&fresh));
            }
        }
    }
}
