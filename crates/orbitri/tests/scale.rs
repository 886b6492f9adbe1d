//! Every input at every scale: a triangulation is the same, cell for cell, when every
//! coordinate and the lattice are scaled by a power of two, from the smallest boxes the
//! doubles hold to the largest; elongated boxes get a result or the documented error; and the
//! Voronoi cells of adversarial sets (points one ulp apart, wrapped near-duplicates, jittered
//! grids, tight clusters) are finite, non-negative, sum to the domain and hold their
//! centroids.

mod common;
use orbitri::triangulation::Torus;
use orbitri::{
    Copies, Error, FlatTorus, FlatTorus2, FlatTorus3, Lattice, PeriodicDelaunay, PeriodicDelaunay2,
    PeriodicDelaunay3,
};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;

/// `x·2^k` for the test's inputs (exact: they keep their bits at every scale used).
fn scaled(x: f64, k: i32) -> f64 {
    let mut y = x;
    let step = if k >= 0 { 2.0 } else { 0.5 };
    for _ in 0..k.unsigned_abs() {
        y *= step;
    }
    y
}

/// Points on a `2^-20` grid of the unit cell, in lattice coordinates, mapped by `m`: every
/// coordinate keeps its bits under scalings by `2^k`, `|k| ≤ 1000`.
fn grid_points<const D: usize>(n: usize, seed: u64, m: &[[f64; D]; D]) -> Vec<[f64; D]> {
    let mut s = seed;
    let mut next = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 33) % (1 << 20)) as f64 / (1u64 << 20) as f64
    };
    (0..n)
        .map(|_| {
            let f: [f64; D] = std::array::from_fn(|_| next());
            std::array::from_fn(|c| (0..D).map(|k| f[k] * m[k][c]).sum())
        })
        .collect()
}

type Cells<const D: usize, const N: usize> = Vec<orbitri::CellView<D, N>>;

/// The stored cells, the sheets and the Voronoi volumes (when the domain volume is a normal
/// double) of `points` in the lattice `m`.
fn run<const D: usize, const N: usize>(
    m: [[f64; D]; D],
    points: &[[f64; D]],
) -> (Cells<D, N>, usize, Option<Vec<f64>>)
where
    FlatTorus<D>: Torus<D, N>,
{
    let torus = FlatTorus::<D>::new(Lattice::new(m).unwrap());
    let tri = PeriodicDelaunay::<D, N>::build(torus, points).unwrap();
    assert!(tri.is_valid().is_ok(), "{:?}", tri.is_valid());
    let mut cells = tri.cells(Copies::Stored);
    cells.sort();
    let volume = tri.space().lattice().volume();
    let volumes = (volume.is_normal()).then(|| {
        let v: Vec<f64> = tri.voronoi_cells().iter().map(|c| c.volume).collect();
        let sum: f64 = v.iter().sum();
        assert!(
            ((sum - volume) / volume).abs() < 1e-12,
            "{sum} against {volume}"
        );
        v
    });
    (cells, tri.sheets(), volumes)
}

/// Compares the triangulation of `points` in `m` with that of everything scaled by `2^k`.
fn same_at_scale<const D: usize, const N: usize>(m: [[f64; D]; D], points: &[[f64; D]], k: i32)
where
    FlatTorus<D>: Torus<D, N>,
{
    let (cells, sheets, volumes) = run::<D, N>(m, points);
    let ms = m.map(|r| r.map(|x| scaled(x, k)));
    let ps: Vec<[f64; D]> = points.iter().map(|p| p.map(|x| scaled(x, k))).collect();
    let (cells_s, sheets_s, volumes_s) = run::<D, N>(ms, &ps);
    assert_eq!(sheets, sheets_s, "scale 2^{k}");
    assert_eq!(cells, cells_s, "scale 2^{k}");
    if let (Some(a), Some(b)) = (volumes, volumes_s) {
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(scaled(*x, k * D as i32), *y, "scale 2^{k}");
        }
    }
}

const CUBE: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
const TRICLINIC: [[f64; 3]; 3] = [
    [1.0, 0.0, 0.0],
    [0.25, 0.875, 0.0],
    [-0.125, 0.1875, 1.0625],
];
const SQUARE: [[f64; 2]; 2] = [[1.0, 0.0], [0.0, 1.0]];
const OBLIQUE: [[f64; 2]; 2] = [[1.0, 0.0], [0.375, 0.8125]];

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, rng_seed: RngSeed::Fixed(20261129), ..ProptestConfig::default() })]

    #[test]
    fn scale_invariance_3d(k in -1000i32..=1000, n in 1usize..60, seed in any::<u64>(), triclinic in any::<bool>()) {
        let m = if triclinic { TRICLINIC } else { CUBE };
        same_at_scale::<3, 4>(m, &grid_points(n, seed, &m), k);
    }

    #[test]
    fn scale_invariance_2d(k in -1000i32..=1000, n in 1usize..200, seed in any::<u64>(), oblique in any::<bool>()) {
        let m = if oblique { OBLIQUE } else { SQUARE };
        same_at_scale::<2, 3>(m, &grid_points(n, seed, &m), k);
    }

    /// Elongated and skewed boxes: a triangulation or a typed box error, never a hang (the
    /// covering search is bounded by `D·MAX_COPIES` steps by construction).
    #[test]
    fn elongated_boxes_give_a_result_or_the_error(
        e in prop::array::uniform3(-60i32..=60),
        tilt in prop::array::uniform3(-1.0f64..1.0),
        n in 1usize..12,
    ) {
        let l = e.map(|x| 2f64.powi(x / 4));
        let m = [[l[0], 0.0, 0.0], [tilt[0] * l[0], l[1], 0.0], [tilt[1] * l[0], tilt[2] * l[1], l[2]]];
        match Lattice::new(m) {
            Ok(lattice) => {
                let pts = grid_points(n, 7, &m);
                let tri = PeriodicDelaunay3::build(FlatTorus3::new(lattice), &pts).unwrap();
                prop_assert!(tri.is_valid().is_ok());
            }
            Err(Error::InvalidBox(msg)) => prop_assert!(msg.contains("too elongated"), "{}", msg),
            Err(Error::SkewedLattice { .. }) | Err(Error::SingularLattice { .. }) => {}
            Err(other) => prop_assert!(false, "{other}"),
        }
        let l2 = [l[0], l[1]];
        match Lattice::new([[l2[0], 0.0], [tilt[0] * l2[0], l2[1]]]) {
            Ok(_) | Err(Error::SkewedLattice { .. }) => {}
            Err(Error::InvalidBox(msg)) => prop_assert!(msg.contains("too elongated"), "{}", msg),
            Err(other) => prop_assert!(false, "{other}"),
        }
    }
}

/// A fixed large case at the extremes: 3000 points, cube and triclinic, 2D and 3D.
#[test]
fn three_thousand_points_at_the_extremes() {
    for k in [-1000, -333, 370, 1000] {
        same_at_scale::<3, 4>(CUBE, &grid_points(3000, 3, &CUBE), k);
        same_at_scale::<3, 4>(TRICLINIC, &grid_points(3000, 4, &TRICLINIC), k);
        same_at_scale::<2, 3>(OBLIQUE, &grid_points(3000, 5, &OBLIQUE), k);
    }
}

/// The defects reported at extreme scales, each as it was found.
#[test]
fn extreme_boxes_regressions() {
    let cube = |l: f64| FlatTorus3::cuboid([l; 3]).unwrap();
    // one point in a box of 1e100 panicked ("the first Delaunay cell exists")
    let t = PeriodicDelaunay3::build(cube(1e100), &[[0.3e100, 0.1e100, 0.7e100]]).unwrap();
    assert_eq!((t.sheets(), t.number_of_vertices()), (27, 1));
    assert!(t.is_valid().is_ok());
    // two points in a box of 1e-100 panicked (offsets out of range)
    let pts = [
        [0.1e-100, 0.2e-100, 0.3e-100],
        [0.6e-100, 0.5e-100, 0.9e-100],
    ];
    let t = PeriodicDelaunay3::build(cube(1e-100), &pts).unwrap();
    assert!(t.is_valid().is_ok());
    assert_eq!(t.number_of_vertices(), 2);
    // 2D box of 1e-120 panicked (index out of bounds)
    let t = PeriodicDelaunay2::build(
        FlatTorus2::cuboid([1e-120; 2]).unwrap(),
        &[
            [0.2e-120, 0.3e-120],
            [0.7e-120, 0.1e-120],
            [0.5e-120, 0.8e-120],
        ],
    )
    .unwrap();
    assert!(t.is_valid().is_ok());
    // one point in a box of 1e-90 claimed one sheet with cells `0 0 0 0`
    let t = PeriodicDelaunay3::build(cube(1e-90), &[[0.5e-90; 3]]).unwrap();
    assert_eq!(t.sheets(), 27);
    assert!(t.is_valid().is_ok());
    // four points scaled by 1e-90 lost a point and repeated vertex ids
    let four = [
        [0.1, 0.2, 0.3],
        [0.6, 0.1, 0.4],
        [0.3, 0.7, 0.2],
        [0.8, 0.8, 0.9],
    ];
    let small: Vec<[f64; 3]> = four.iter().map(|p| p.map(|x| x * 1e-90)).collect();
    let t = PeriodicDelaunay3::build(cube(1e-90), &small).unwrap();
    assert_eq!(t.number_of_vertices(), 4);
    assert!(t.is_valid().is_ok());
    for c in t.cells(Copies::Stored) {
        let mut v = c.vertices.to_vec();
        v.sort();
        v.dedup();
        assert!(v.len() > 1);
    }
    // boxes whose determinant under- or overflows were "singular"
    for l in [1e-120, 1e110, 1e-300, 1e300, 5e-324 * 4.0, f64::MAX / 2.0] {
        let lattice = Lattice::cuboid([l; 3]).unwrap();
        assert_eq!(lattice.vectors()[0][0], l);
        assert!(Lattice::cuboid([l, l]).is_ok());
    }
}

/// Elongated boxes that hung forever in the covering search.
#[test]
fn elongated_boxes_are_rejected_at_once() {
    for l in [[1.0, 1.0, 1e-17], [1.0, 1e-300, 1.0], [1e300, 1.0, 1.0]] {
        match Lattice::cuboid(l) {
            Err(Error::InvalidBox(msg)) => assert!(msg.contains("too elongated"), "{msg}"),
            other => panic!("{l:?}: {other:?}"),
        }
    }
    for l in [[1.0, 1e-10], [1e-10, 1.0], [1.0, 1e-300]] {
        assert!(
            matches!(Lattice::cuboid(l), Err(Error::InvalidBox(_))),
            "{l:?}"
        );
    }
}

/// Points out of reach of an exact wrap get a typed error naming them.
#[test]
fn far_points_are_named() {
    let tri = FlatTorus3::triclinic(TRICLINIC).unwrap();
    let err = PeriodicDelaunay3::build(tri, &[[0.5; 3], [1e300, 0.0, 0.0]]).unwrap_err();
    assert!(matches!(err, Error::OutOfReach { index: 1, .. }), "{err}");
    // a box wraps any finite point exactly
    let cube = FlatTorus3::cuboid([1.0; 3]).unwrap();
    let t = PeriodicDelaunay3::build(cube, &[[0.5; 3], [1e300, -1e300, 0.25]]).unwrap();
    assert_eq!(t.number_of_vertices(), 2);
}

/// Checks a Voronoi diagram: finite non-negative volumes summing to the domain to 1e-12,
/// every centroid on the point's side of each face's bisector.
fn check_voronoi<const D: usize, const N: usize>(tri: &PeriodicDelaunay<D, N>)
where
    FlatTorus<D>: Torus<D, N>,
{
    assert!(tri.is_valid().is_ok());
    let cells = tri.voronoi_cells();
    let domain = tri.space().lattice().volume();
    let mut sum = 0.0;
    for c in &cells {
        assert!(c.volume.is_finite() && c.volume >= 0.0, "{}", c.volume);
        sum += c.volume;
        assert!(c.centroid.iter().all(|x| x.is_finite()));
        assert!(c.vertices.iter().flatten().all(|x| x.is_finite()));
        let rel: Vec<[f64; D]> = c
            .vertices
            .iter()
            .map(|v| std::array::from_fn(|k| v[k] - c.position[k]))
            .collect();
        let g: [f64; D] = std::array::from_fn(|k| c.centroid[k] - c.position[k]);
        let size = rel.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
        for f in &c.faces {
            assert!(f.area.is_finite() && f.area >= 0.0);
            // the centroid is inside the (convex) cell: behind every face's plane
            let v: Vec<&[f64; D]> = f.vertices.iter().map(|&i| &rel[i as usize]).collect();
            let normal: Vec<f64> = if D == 2 {
                vec![v[1][1] - v[0][1], v[0][0] - v[1][0]]
            } else {
                let mut n = [0.0; 3];
                for k in 0..v.len() {
                    let (a, b) = (v[k], v[(k + 1) % v.len()]);
                    n[0] += a[1] * b[2] - a[2] * b[1];
                    n[1] += a[2] * b[0] - a[0] * b[2];
                    n[2] += a[0] * b[1] - a[1] * b[0];
                }
                n.to_vec()
            };
            let len = normal.iter().map(|x| x * x).sum::<f64>().sqrt();
            if len <= 1e-9 * size.powi(D as i32 - 1) {
                continue;
            }
            let side: f64 = (0..D).map(|k| (g[k] - v[0][k]) * normal[k]).sum();
            assert!(
                side <= 1e-9 * len * size,
                "centroid of {} outside its face towards {}: side {side:e} len {len:e} size {size} centroid {:?} face {:?} vol {}",
                c.point,
                f.neighbor,
                c.centroid,
                v,
                c.volume
            );
        }
    }
    assert!(
        ((sum - domain) / domain).abs() < 1e-12,
        "sum {sum} against {domain}"
    );
}

fn build3(l: f64, pts: &[[f64; 3]]) -> PeriodicDelaunay3 {
    PeriodicDelaunay3::build(FlatTorus3::cuboid([l; 3]).unwrap(), pts).unwrap()
}

fn build2(l: f64, pts: &[[f64; 2]]) -> PeriodicDelaunay2 {
    PeriodicDelaunay2::build(FlatTorus2::cuboid([l; 2]).unwrap(), pts).unwrap()
}

#[test]
fn voronoi_of_points_one_ulp_apart() {
    let mut pts = common::uniform(40, 3, [1.0; 3]);
    let a = pts[0];
    pts.push([f64::from_bits(a[0].to_bits() + 1), a[1], a[2]]);
    check_voronoi(&build3(1.0, &pts));
    let mut pts2: Vec<[f64; 2]> = pts.iter().map(|p| [p[0], p[1]]).collect();
    pts2.push([a[0], f64::from_bits(a[1].to_bits() + 1)]);
    check_voronoi(&build2(1.0, &pts2));
    // the pair alone (in the covering)
    check_voronoi(&build3(
        1.0,
        &[a, [f64::from_bits(a[0].to_bits() + 1), a[1], a[2]]],
    ));
}

#[test]
fn voronoi_of_unwrapped_md_coordinates() {
    // 100 points and 20 of them shifted by a box length: they wrap to near-duplicates
    let mut pts = common::uniform(100, 5, [1.0; 3]);
    for i in 0..20 {
        let p = pts[i * 5];
        pts.push([p[0] + 1.0, p[1] - 1.0, p[2] + 1.0]);
    }
    let tri = build3(1.0, &pts);
    check_voronoi(&tri);
    let pts2: Vec<[f64; 2]> = pts.iter().map(|p| [p[0], p[1]]).collect();
    check_voronoi(&build2(1.0, &pts2));
}

#[test]
fn voronoi_of_a_jittered_grid() {
    let mut pts = Vec::new();
    let mut s = 1u64;
    let mut jitter = move || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1);
        ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e-15
    };
    for i in 0..4 {
        for j in 0..4 {
            for k in 0..4 {
                pts.push([
                    i as f64 + jitter(),
                    j as f64 + jitter(),
                    k as f64 + jitter(),
                ]);
            }
        }
    }
    check_voronoi(&build3(4.0, &pts));
    let pts2: Vec<[f64; 2]> = (0..64)
        .map(|i| [(i / 8) as f64 + jitter(), (i % 8) as f64 + jitter()])
        .collect();
    check_voronoi(&build2(8.0, &pts2));
}

#[test]
fn voronoi_of_tight_clusters() {
    for sigma in [1e-20, 1e-12, 1e-300] {
        let base = common::uniform(30, 9, [1.0; 3]);
        let mut pts = base.clone();
        for (i, b) in base.iter().take(10).enumerate() {
            for j in 0..4 {
                let f = (i * 4 + j) as f64 + 1.0;
                pts.push([
                    b[0] + sigma * f,
                    b[1] - sigma * f * 0.5,
                    b[2] + sigma * (f % 3.0),
                ]);
            }
        }
        check_voronoi(&build3(1.0, &pts));
        let pts2: Vec<[f64; 2]> = pts.iter().map(|p| [p[0], p[1]]).collect();
        check_voronoi(&build2(1.0, &pts2));
    }
}

#[test]
fn voronoi_sums_with_dummy_construction() {
    // a large set on the dummy path with a tight cluster inside
    let mut pts = common::uniform(3000, 11, [1.0; 3]);
    let c = pts[7];
    for j in 0..20 {
        pts.push([c[0] + 1e-14 * j as f64, c[1], c[2] - 3e-15 * j as f64]);
    }
    let tri = build3(1.0, &pts);
    assert!(tri.used_dummy_points());
    check_voronoi(&tri);
}

/// An adversarial set in the unit cell: `kind` 0 pairs one ulp apart, 1 copies shifted by
/// whole periods (they wrap to near-duplicates), 2 a jittered grid, 3 tight clusters.
fn adversarial(kind: u8, n: usize, seed: u64, tiny: f64) -> Vec<[f64; 3]> {
    let base = common::uniform(n, seed, [1.0; 3]);
    let mut pts = base.clone();
    match kind {
        0 => pts.extend(
            base.iter()
                .take(n / 3 + 1)
                .map(|p| p.map(|x| f64::from_bits(x.to_bits() + 1))),
        ),
        1 => pts.extend(
            base.iter()
                .take(n / 4 + 1)
                .map(|p| [p[0] + 1.0, p[1] - 2.0, p[2] + 3.0]),
        ),
        2 => {
            let k = 4;
            pts = (0..k * k * k)
                .map(|i| {
                    let g = [i / (k * k), (i / k) % k, i % k];
                    std::array::from_fn(|c| (g[c] as f64 + 0.5 + tiny * base[i % n][c]) / k as f64)
                })
                .collect();
        }
        _ => {
            for (i, b) in base.iter().take(4).enumerate() {
                for j in 0..5 {
                    let f = (i * 5 + j + 1) as f64;
                    pts.push([
                        b[0] + tiny * f,
                        b[1] - tiny * f * 0.7,
                        b[2] + tiny * (f % 3.0),
                    ]);
                }
            }
        }
    }
    pts
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, rng_seed: RngSeed::Fixed(20261130), ..ProptestConfig::default() })]

    #[test]
    fn voronoi_of_adversarial_sets(kind in 0u8..4, n in 2usize..60, seed in any::<u64>(), e in 1i32..1000) {
        let tiny = 2f64.powi(-e);
        let pts = adversarial(kind, n, seed, tiny);
        check_voronoi(&build3(1.0, &pts));
        let pts2: Vec<[f64; 2]> = pts.iter().map(|p| [p[0], p[1]]).collect();
        check_voronoi(&build2(1.0, &pts2));
    }
}

/// A lattice near the largest doubles: its dummy points stay in the internal frame (they
/// overflowed on a trip through user units).
#[test]
fn dummy_points_of_a_lattice_near_the_largest_doubles() {
    let m = [[1.5e308, 0.0], [1e308, 1.5e308]];
    let torus = FlatTorus2::new(Lattice::new(m).unwrap());
    let mut s = 3u64;
    let pts: Vec<[f64; 2]> = (0..1500)
        .map(|_| {
            let mut next = || {
                s = s.wrapping_mul(6364136223846793005).wrapping_add(1);
                (s >> 11) as f64 / (1u64 << 53) as f64
            };
            let (f0, f1) = (next(), 0.2 * next());
            [f0 * m[0][0] + f1 * m[1][0], f1 * m[1][1]]
        })
        .collect();
    // 1500 points start from the dummy grid (the points fill a fifth of the domain, so the
    // build then falls back to the covering: both paths must hold)
    let tri = PeriodicDelaunay2::build(torus, &pts).unwrap();
    assert!(tri.is_valid().is_ok());
    assert_eq!(tri.number_of_vertices(), 1500);
}
