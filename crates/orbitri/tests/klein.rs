//! The Klein bottle through the facade: validity on every path (covering, quotient, dummy
//! points), the unfolding to its torus cover against orbitri's own torus triangulation,
//! Voronoi areas, order independence, crystals and duplicates.

use std::collections::{BTreeSet, HashMap};

use orbitri::sort::SplitMix;
use orbitri::{
    Copies, FlatManifold, FlatSpace, FlatTorus2, InputId, KleinTriangulation, Motion,
    PeriodicDelaunay2, PointId,
};

fn random(n: usize, seed: u64, a: f64, b: f64) -> Vec<[f64; 2]> {
    let mut r = SplitMix::new(seed);
    (0..n).map(|_| [r.unit() * a, r.unit() * b]).collect()
}

fn area_sum(tri: &KleinTriangulation) -> f64 {
    tri.voronoi_cells().iter().map(|c| c.volume).sum()
}

#[test]
fn every_size_is_valid_and_the_cells_tile_the_bottle() {
    for (a, b) in [(1.0, 1.0), (1.0, 2.5), (0.3, 1.0), (2.0, 0.7)] {
        for (n, seed) in [
            (1, 1),
            (2, 2),
            (3, 3),
            (5, 4),
            (10, 5),
            (60, 6),
            (600, 7),
            (2500, 8),
        ] {
            let klein = FlatManifold::klein_bottle(a, b).unwrap();
            let tri = KleinTriangulation::build(klein, &random(n, seed, a, b)).unwrap();
            tri.is_valid()
                .unwrap_or_else(|e| panic!("{a}×{b}, {n} points: {e}"));
            assert_eq!(tri.number_of_vertices(), n);
            if tri.is_one_sheeted() {
                // V − E + F = 0 and 3F = 2E
                assert_eq!(tri.number_of_cells(), 2 * n, "{a}×{b}, {n} points");
            }
            let sum = area_sum(&tri);
            assert!(
                (sum - a * b).abs() <= 1e-12 * a * b,
                "{a}×{b}, {n} points: Voronoi areas sum to {sum}"
            );
            if n >= 2500 {
                assert!(tri.used_dummy_points() && tri.is_one_sheeted());
            }
        }
    }
}

/// The position of a lifted vertex `g·p`, from the element's isometry.
fn apply(klein: &FlatManifold<2>, g: Motion<2>, p: [f64; 2]) -> [f64; 2] {
    let (m, t) = klein.isometry(g);
    std::array::from_fn(|i| m[i][0] * p[0] + m[i][1] * p[1] + t[i])
}

/// The triangulation of the Klein bottle unfolded to its torus cover (the points and their
/// glide images) is the torus triangulation of the unfolded points, cell for cell.
#[test]
fn unfolding_gives_the_torus_triangulation_of_the_cover() {
    let (a, b) = (1.0, 1.5);
    let klein = FlatManifold::klein_bottle(a, b).unwrap();
    let pts = random(400, 11, a, b);
    let tri = KleinTriangulation::build(klein.clone(), &pts).unwrap();
    assert!(tri.is_one_sheeted());
    let glide = Motion {
        coset: 1,
        offset: [0, 0],
    };
    // the cover's points: p_i, then γ(p_i) wrapped into [0, 2a) × [0, b)
    let torus = FlatTorus2::cuboid([2.0 * a, b]).unwrap();
    let mut cover: Vec<[f64; 2]> = tri.points();
    for p in tri.points() {
        let (w, _) = torus.lattice().wrap(apply(&klein, glide, p)).unwrap();
        cover.push(w);
    }
    let unfolded = PeriodicDelaunay2::build(torus, &cover).unwrap();
    assert!(unfolded.is_one_sheeted());
    // the torus's cells as sets of (cover point, offset), least offset at zero
    let canon = |mut c: Vec<(InputId, [i8; 2])>| {
        for k in 0..2 {
            let m = c.iter().map(|x| x.1[k]).min().unwrap();
            c.iter_mut().for_each(|x| x.1[k] -= m);
        }
        c.sort_unstable();
        c
    };
    let expected: BTreeSet<Vec<(InputId, [i8; 2])>> = unfolded
        .cells(Copies::Unique)
        .iter()
        .map(|c| canon(c.vertices.iter().copied().zip(c.offsets).collect()))
        .collect();
    // each Klein cell lifts to two torus cells: by the identity and by the glide
    let n = pts.len() as u32;
    let mut lifted = BTreeSet::new();
    for c in tri.cells(Copies::Unique) {
        for r in [
            Motion {
                coset: 0,
                offset: [0, 0],
            },
            glide,
        ] {
            let cell: Vec<(InputId, [i8; 2])> = (0..3)
                .map(|k| {
                    let v = tri.vertex_of_input(c.vertices[k]);
                    let g = klein_compose(&klein, r, c.offsets[k]);
                    let x = apply(&klein, g, tri.point(v));
                    // the cover point it is a translate of: the cover's input `v` is point
                    // `v`, its input `v + n` the glide image
                    let u = InputId(if g.coset == 0 { v.0 } else { v.0 + n });
                    let base = cover[u.index()];
                    let o = [
                        ((x[0] - base[0]) / (2.0 * a)).round() as i8,
                        ((x[1] - base[1]) / b).round() as i8,
                    ];
                    (u, o)
                })
                .collect();
            lifted.insert(canon(cell));
        }
    }
    assert_eq!(lifted.len(), expected.len());
    assert!(lifted == expected, "the unfolded cells differ");
}

fn klein_compose(klein: &FlatManifold<2>, a: Motion<2>, b: Motion<2>) -> Motion<2> {
    orbitri::OrbitSpace::<3>::compose(klein, a, b)
}

/// Cells as sets of (point coordinates, element) in canonical form modulo the group.
fn geometry(tri: &KleinTriangulation) -> BTreeSet<Vec<(u64, u64, Motion<2>)>> {
    let key: HashMap<InputId, PointId> = (0..tri.number_of_vertices() as u32)
        .map(|v| (tri.input_of_vertex(PointId(v)), PointId(v)))
        .collect();
    tri.cells(Copies::Unique)
        .iter()
        .map(|c| {
            // rank vertices by their coordinates, so that input order does not matter
            let mut order: Vec<PointId> =
                (0..tri.number_of_vertices() as u32).map(PointId).collect();
            order.sort_by(|&x, &y| tri.point(x).partial_cmp(&tri.point(y)).unwrap());
            let rank: HashMap<PointId, u32> = order
                .iter()
                .enumerate()
                .map(|(r, &v)| (v, r as u32))
                .collect();
            let mut pairs: Vec<(u32, Motion<2>)> = c
                .vertices
                .iter()
                .map(|v| rank[&key[v]])
                .zip(c.offsets)
                .collect();
            FlatSpace::<2, 3>::canonical_face(tri.space(), &mut pairs);
            pairs
                .iter()
                .map(|&(r, g)| {
                    let p = tri.point(order[r as usize]);
                    (p[0].to_bits(), p[1].to_bits(), g)
                })
                .collect()
        })
        .collect()
}

#[test]
fn the_input_order_does_not_matter() {
    let klein = FlatManifold::klein_bottle(1.0, 1.0).unwrap();
    let pts = random(300, 21, 1.0, 1.0);
    let mut shuffled = pts.clone();
    let mut r = SplitMix::new(5);
    for i in (1..shuffled.len()).rev() {
        shuffled.swap(i, r.below(i + 1));
    }
    let a = KleinTriangulation::build(klein.clone(), &pts).unwrap();
    let b = KleinTriangulation::build(klein, &shuffled).unwrap();
    assert_eq!(geometry(&a), geometry(&b));
}

/// A square grid: every square's four corners are cocircular, so every triangle is decided
/// by the symbolic perturbation, which must be the same for every copy, reflected or not.
#[test]
fn a_crystal_is_triangulated_consistently_in_any_order() {
    let k = 8;
    let pts: Vec<[f64; 2]> = (0..k * k)
        .map(|i| [(i / k) as f64 / k as f64, (i % k) as f64 / k as f64])
        .collect();
    let klein = FlatManifold::klein_bottle(1.0, 1.0).unwrap();
    let a = KleinTriangulation::build(klein.clone(), &pts).unwrap();
    a.is_valid().unwrap();
    let mut rev = pts.clone();
    rev.reverse();
    let b = KleinTriangulation::build(klein, &rev).unwrap();
    b.is_valid().unwrap();
    assert_eq!(geometry(&a), geometry(&b));
    for c in a.voronoi_cells() {
        assert!((c.volume - 1.0 / 64.0).abs() < 1e-15, "{}", c.volume);
    }
}

#[test]
fn glide_images_are_duplicates() {
    let klein = FlatManifold::klein_bottle(1.0, 1.0).unwrap();
    // dyadic coordinates, so that the images below and their wrapping are exact
    let pts: Vec<[f64; 2]> = random(50, 31, 1.0, 1.0)
        .iter()
        .map(|p| p.map(|x| (x * 1048576.0).floor() / 1048576.0))
        .collect();
    let mut all = pts.clone();
    // γ(p) = (x + 1, −y) and γ⁻¹(p) = (x − 1, −y) are the same points of the bottle
    all.extend(pts.iter().map(|p| [p[0] + 1.0, -p[1]]));
    all.extend(pts.iter().map(|p| [p[0] - 1.0, -p[1] + 3.0]));
    let tri = KleinTriangulation::build(klein, &all).unwrap();
    tri.is_valid().unwrap();
    assert_eq!(tri.number_of_vertices(), 50);
    assert_eq!(tri.duplicates(), 100);
    assert_eq!(tri.first_occurrences()[60], InputId(10));
    assert_eq!(tri.wrapped(), 100);
}

#[test]
fn bad_bottles_are_typed_errors() {
    for (a, b) in [
        (0.0, 1.0),
        (1.0, -1.0),
        (f64::NAN, 1.0),
        (f64::INFINITY, 1.0),
        (1e308, 1.0),
    ] {
        assert!(FlatManifold::klein_bottle(a, b).is_err(), "{a} × {b}");
    }
    let klein = FlatManifold::klein_bottle(1.0, 1.0).unwrap();
    assert!(KleinTriangulation::build(klein.clone(), &[]).is_err());
    assert!(KleinTriangulation::build(klein, &[[0.5, f64::NAN]]).is_err());
}
