//! Removing and moving points (issue "Dynamic triangulations"): every result against a
//! fresh build of the surviving points, cell for cell, on the lattices users have (cube,
//! cuboid, triclinic; square, hexagonal, oblique) and two manifolds; removal down to no
//! point and back; duplicates; bad ids; random sequences of insertions, removals and moves.

use std::collections::BTreeSet;

use orbitri::sort::SplitMix;
use orbitri::{
    BuildOptions, Copies, Error, FlatManifold, FlatSpace, FlatTorus, InputId, PointId, Removal,
    Triangulation,
};
use proptest::prelude::*;

mod common;
use common::geometry;

/// The live input ids' points, in input order.
fn survivors<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    tri: &Triangulation<D, N, S>,
) -> Vec<[f64; D]> {
    let first = tri.first_occurrences();
    (0..tri.number_of_input_points())
        .filter(|&i| first[i] != InputId::NONE)
        .map(|i| tri.point(tri.vertex_of_input(InputId::new(i))))
        .collect()
}

/// The triangulation equals a fresh build of its surviving points when both live in the
/// same space (a removal that stayed 1-sheeted while the fresh build of few points starts
/// in a covering is a valid triangulation of another space: only the quotient's is
/// compared).
fn same_as_fresh<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    tri: &Triangulation<D, N, S>,
    what: &str,
) -> bool {
    tri.is_valid().unwrap_or_else(|e| panic!("{what}: {e}"));
    let pts = survivors(tri);
    if pts.is_empty() {
        assert_eq!(tri.number_of_vertices(), 0, "{what}");
        return false;
    }
    let fresh = Triangulation::<D, N, S>::build(tri.space().clone(), &pts).unwrap();
    if fresh.sheets() != tri.sheets() {
        return false;
    }
    assert!(
        geometry(tri) == geometry(&fresh),
        "{what}: the cells differ from a fresh build of the survivors"
    );
    true
}

fn random<const D: usize>(n: usize, seed: u64, scale: [f64; D]) -> Vec<[f64; D]> {
    let mut r = SplitMix::new(seed);
    (0..n)
        .map(|_| std::array::from_fn(|i| r.unit() * scale[i]))
        .collect()
}

fn tori3() -> Vec<(&'static str, FlatTorus<3>)> {
    vec![
        ("cube", FlatTorus::cuboid([1.0; 3]).unwrap()),
        ("cuboid", FlatTorus::cuboid([1.0, 0.75, 1.5]).unwrap()),
        (
            "triclinic",
            FlatTorus::triclinic([[1.0, 0.0, 0.0], [0.3, 0.9, 0.0], [-0.2, 0.25, 1.1]]).unwrap(),
        ),
    ]
}

fn tori2() -> Vec<(&'static str, FlatTorus<2>)> {
    vec![
        ("square", FlatTorus::cuboid([1.0; 2]).unwrap()),
        (
            "hexagonal",
            FlatTorus::triclinic([[1.0, 0.0], [0.5, 3f64.sqrt() / 2.0]]).unwrap(),
        ),
        (
            "oblique",
            FlatTorus::triclinic([[1.0, 0.0], [0.35, 0.8]]).unwrap(),
        ),
    ]
}

/// The build of `pts` (weighted by `w` if given) and the build through the covering, which
/// uses no dummy point: the first used its dummy points, and both have the same cells.
fn built_both_ways<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    space: &S,
    pts: &[[f64; D]],
    w: Option<&[f64]>,
    name: &str,
) -> (Triangulation<D, N, S>, Triangulation<D, N, S>) {
    let cover = BuildOptions {
        dummy_threshold: usize::MAX,
        ..Default::default()
    };
    let go = |_| std::ops::ControlFlow::Continue(());
    let (tri, other) = match w {
        None => (
            Triangulation::<D, N, S>::build(space.clone(), pts),
            Triangulation::<D, N, S>::build_with(space.clone(), pts, cover, go),
        ),
        Some(w) => (
            Triangulation::<D, N, S>::build_weighted(space.clone(), pts, w),
            Triangulation::<D, N, S>::build_weighted_with(space.clone(), pts, w, cover, go),
        ),
    };
    let (tri, other) = (tri.unwrap(), other.unwrap());
    assert!(
        tri.used_dummy_points() && !other.used_dummy_points(),
        "{name}"
    );
    assert!(geometry(&tri) == geometry(&other), "{name}");
    (tri, other)
}

/// `n` points on four parallel lines (2D) or planes (3D) across the last axis, a quarter
/// of its length `len` apart, then `lone` points halfway between the first two: every
/// dummy point (halfway between two planes too) and every lone point has a star of
/// hundreds of cells.
fn on_planes<const D: usize>(n: usize, lone: usize, len: f64, seed: u64) -> Vec<[f64; D]> {
    let mut r = SplitMix::new(seed);
    (0..n + lone)
        .map(|i| {
            let z = if i >= n { 0.125 } else { (i % 4) as f64 * 0.25 } * len;
            std::array::from_fn(|c| if c + 1 < D { r.unit() } else { z })
        })
        .collect()
}

/// Points on planes: the dummy points leave early (after a BRIO round, once the planes
/// are dense enough for the criterion), and the lone points' large holes are filled by
/// gift wrapping through its index of the candidates (each apex found so is checked
/// against trying every candidate in debug builds): the build equals one through the
/// covering, which removes no dummy point, and removing the lone points gives a fresh
/// build of the others. Weighted points too (on the tori), and a
/// manifold (whose holes are wrapped without the index).
#[test]
fn large_holes_on_planes_equal_builds_without_them() {
    fn check<const D: usize, const N: usize, S: FlatSpace<D, N>>(
        space: S,
        len: f64,
        name: &str,
        weighted: bool,
    ) {
        let (n, lone) = (4000, 3);
        let pts = on_planes::<D>(n, lone, len, 5);
        let (mut tri, _) = built_both_ways(&space, &pts, None, name);
        for i in n..n + lone {
            assert_eq!(
                tri.remove(InputId::new(i)).unwrap(),
                Removal::InPlace,
                "{name}"
            );
        }
        assert!(same_as_fresh(&tri, name), "{name}");
        if !weighted {
            return;
        }
        let w: Vec<f64> = (0..n + lone).map(|i| 1e-4 * (i % 7) as f64).collect();
        built_both_ways(&space, &pts, Some(&w), &format!("{name}, weighted"));
    }
    check::<3, 4, _>(FlatTorus::cuboid([1.0; 3]).unwrap(), 1.0, "cube", true);
    check::<2, 3, _>(FlatTorus::cuboid([1.0; 2]).unwrap(), 1.0, "square", true);
    let dicosm = FlatManifold::platycosm("dicosm", [1.0, 1.0, 1.25]).unwrap();
    // (weights in a manifold are equal)
    check::<3, 4, _>(dicosm, 1.25, "dicosm", false);
}

/// Points in a thin slab with a vacuum beside it: some dummy points, alone in the vacuum,
/// cannot leave the quotient without joining two copies of a point, so the triangulation
/// goes on in a covering (lifted, not built again: a 3D torus's 8-sheeted lift level,
/// where the slab's vacuum is narrow enough) and comes back to the quotient if it can.
/// The build equals one through the covering (no dummy point, which stays in the ladder's
/// level 0: 27 sheets) and stays dynamic (a removal and an insertion after it give a
/// fresh build's cells); with weights too.
#[test]
fn slabs_beside_a_vacuum_equal_builds_without_dummy_points() {
    fn check<const D: usize, const N: usize, S: FlatSpace<D, N>>(
        space: S,
        pts: &[[f64; D]],
        sheets: (usize, usize),
        name: &str,
        weighted: Option<(usize, usize)>,
    ) {
        let (mut tri, other) = built_both_ways(&space, pts, None, name);
        assert_eq!((tri.sheets(), other.sheets()), sheets, "{name}");
        tri.remove(InputId::new(7)).unwrap();
        let mut p = pts[3];
        p[0] = (p[0] + 0.5).fract();
        tri.insert(p).unwrap();
        assert!(same_as_fresh(&tri, name), "{name}");
        let Some(weighted_sheets) = weighted else {
            // (weights in a manifold are equal)
            return;
        };
        let w: Vec<f64> = (0..pts.len()).map(|i| 1e-5 * (i % 7) as f64).collect();
        let name = format!("{name}, weighted");
        let (tri, other) = built_both_ways(&space, pts, Some(&w), &name);
        assert_eq!((tri.sheets(), other.sheets()), weighted_sheets, "{name}");
    }
    let cube = FlatTorus::cuboid([1.0; 3]).unwrap();
    let slab = random(1200, 7, [1.0, 1.0, 0.05]);
    // (weighted, level 0 has 64 sheets: see `FlatTorus::for_spread`)
    check::<3, 4, _>(cube.clone(), &slab, (8, 27), "cube, 5 %", Some((8, 64)));
    check::<3, 4, _>(
        cube.clone(),
        &random(1200, 7, [1.0, 1.0, 0.15]),
        (1, 1),
        "cube, 15 %",
        Some((1, 1)),
    );
    let square = FlatTorus::cuboid([1.0; 2]).unwrap();
    check::<2, 3, _>(
        square,
        &random(1200, 7, [1.0, 0.05]),
        (1, 1),
        "square, 5 %",
        Some((1, 1)),
    );
    // the manifold whose group is its translations takes the same way
    let torocosm = FlatManifold::platycosm("torocosm", [1.0; 3]).unwrap();
    check::<3, 4, _>(torocosm, &slab, (64, 64), "torocosm, 5 %", None);
    // a slab left in the covering comes down to the quotient as points fill the vacuum
    let mut tri = Triangulation::<3, 4, _>::build(cube, &slab).unwrap();
    assert_eq!(tri.sheets(), 8);
    for p in random(1000, 8, [1.0; 3]) {
        tri.insert(p).unwrap();
    }
    assert_eq!(tri.sheets(), 1);
    assert!(same_as_fresh(&tri, "cube, 5 %, filled"));
}

/// Removing every other point of a large set stays in the quotient, in place, and gives
/// the fresh build of the other half.
#[test]
fn removals_equal_a_fresh_build_of_the_survivors() {
    for (name, torus) in tori3() {
        let mut tri = Triangulation::<3, 4, _>::build(torus, &random(3000, 1, [1.0; 3])).unwrap();
        for i in (0..3000).step_by(2) {
            assert_eq!(
                tri.remove(InputId::new(i)).unwrap(),
                Removal::InPlace,
                "{name}"
            );
        }
        assert_eq!(tri.number_of_vertices(), 1500);
        assert!(same_as_fresh(&tri, name), "{name}: one-sheeted both");
    }
    // the same removals at once: one renumbering at the end, the same cells
    for (name, torus) in tori3() {
        let pts = random(3000, 1, [1.0; 3]);
        let mut one = Triangulation::<3, 4, _>::build(torus.clone(), &pts).unwrap();
        let mut all = Triangulation::<3, 4, _>::build(torus, &pts).unwrap();
        let ids: Vec<InputId> = (0..3000).rev().step_by(3).map(InputId::new).collect();
        for &i in &ids {
            one.remove(i).unwrap();
        }
        assert_eq!(all.remove_all(&ids).unwrap(), Removal::InPlace);
        all.is_valid().unwrap();
        assert!(geometry(&one) == geometry(&all), "{name}");
        assert_eq!(one.first_occurrences(), all.first_occurrences(), "{name}");
        assert!(same_as_fresh(&all, name));
        // all or nothing
        let before = geometry(&all);
        assert!(
            all.remove_all(&[InputId(1), InputId(2)]).is_err(),
            "2 was removed"
        );
        assert!(all.remove_all(&[InputId(1), InputId(1)]).is_err(), "twice");
        assert!(geometry(&all) == before);
        // everything
        let live: Vec<InputId> = (0..3000)
            .map(InputId::new)
            .filter(|i| !ids.contains(i))
            .collect();
        all.remove_all(&live).unwrap();
        assert_eq!((all.number_of_vertices(), all.number_of_cells()), (0, 0));
    }
    for (name, torus) in tori2() {
        let mut tri = Triangulation::<2, 3, _>::build(torus, &random(2000, 2, [1.0; 2])).unwrap();
        let mut r = SplitMix::new(3);
        let mut ids: Vec<usize> = (0..2000).collect();
        for k in (1..ids.len()).rev() {
            ids.swap(k, (r.next_u64() % (k as u64 + 1)) as usize);
        }
        for &i in &ids[..1000] {
            tri.remove(InputId::new(i)).unwrap();
        }
        assert!(same_as_fresh(&tri, name), "{name}");
    }
}

/// Down to no point, the way back up the covering on the way (a few points cannot keep a
/// simplicial quotient), then inserting again.
#[test]
fn removal_down_to_nothing_and_back() {
    for (name, torus) in tori3().into_iter().take(2) {
        // enough points for the build to start in the quotient (dummy points)
        let n = 1100;
        let pts = random(n, 4, [1.0; 3]);
        let mut tri = Triangulation::<3, 4, _>::build(torus, &pts).unwrap();
        assert_eq!(tri.sheets(), 1, "{name}");
        let mut sheets = BTreeSet::new();
        for i in (0..n).rev() {
            tri.remove(InputId::new(i)).unwrap();
            if i > 0 {
                sheets.insert(tri.sheets());
            }
            if [1000, 600, 300, 40, 20, 9, 3].contains(&i) {
                same_as_fresh(&tri, name);
            } else if i % 101 == 0 || i < 30 {
                tri.is_valid().unwrap_or_else(|e| panic!("{name}: {e}"));
            }
        }
        assert_eq!((tri.number_of_vertices(), tri.number_of_cells()), (0, 0));
        assert!(
            sheets.len() > 1,
            "{name}: went back to the covering ({sheets:?})"
        );
        // the quotient went back up once; the covering of level 0 then removed in place
        assert_eq!(tri.removal_rebuilds(), 1, "{name}");
        for p in &pts[..20] {
            tri.insert(*p).unwrap();
        }
        assert!(same_as_fresh(&tri, name) || tri.sheets() > 1);
        tri.is_valid().unwrap();
    }
    for (name, torus) in tori2() {
        let mut tri = Triangulation::<2, 3, _>::build(torus, &random(40, 5, [1.0; 2])).unwrap();
        let mut levels = BTreeSet::new();
        for i in 0..40 {
            tri.remove(InputId::new(i)).unwrap();
            levels.insert(tri.sheets());
            tri.is_valid().unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        // the 2D ladder: the way back stops at the level the remaining points allow
        assert!(levels.len() >= 3, "{name}: {levels:?}");
    }
}

#[test]
fn manifolds_remove_and_move_too() {
    let klein = FlatManifold::klein_bottle(1.0, 0.75).unwrap();
    let mut k = Triangulation::<2, 3, _>::build(klein, &random(1500, 6, [1.0, 0.75])).unwrap();
    let hw = FlatManifold::platycosm("didicosm", [1.0, 1.0, 1.25]).unwrap();
    let mut m = Triangulation::<3, 4, _>::build(hw, &random(1500, 7, [1.0, 1.0, 1.25])).unwrap();
    for i in (0..1500).step_by(3) {
        k.remove(InputId::new(i)).unwrap();
        m.remove(InputId::new(i)).unwrap();
    }
    let mut r = SplitMix::new(8);
    for i in (1..1500).step_by(3) {
        let mut jiggle = |x: f64| x + (r.unit() - 0.5) * 1e-3;
        let p = k.point(k.vertex_of_input(InputId::new(i)));
        k.move_point(InputId::new(i), p.map(&mut jiggle)).unwrap();
        let q = m.point(m.vertex_of_input(InputId::new(i)));
        m.move_point(InputId::new(i), q.map(&mut jiggle)).unwrap();
    }
    assert!(same_as_fresh(&k, "klein"));
    assert!(same_as_fresh(&m, "didicosm"));
}

/// Small moves mostly keep the combinatorics and only change coordinates; large ones
/// remove and insert; a move onto another point makes a duplicate.
#[test]
fn moves_keep_ids_and_equal_a_fresh_build() {
    let torus = FlatTorus::cuboid([1.0; 3]).unwrap();
    let n = 2000;
    let mut tri = Triangulation::<3, 4, _>::build(torus, &random(n, 9, [1.0; 3])).unwrap();
    let spacing = (1.0 / n as f64).cbrt();
    let mut r = SplitMix::new(10);
    let mut fast = 0;
    for i in 0..n {
        let id = InputId::new(i);
        let p = tri.point(tri.vertex_of_input(id));
        let to = p.map(|x| x + (r.unit() - 0.5) * 0.02 * spacing);
        fast += tri.move_point(id, to).unwrap() as usize;
    }
    assert!(fast > n / 2, "{fast} of {n} moves changed coordinates only");
    assert!(same_as_fresh(&tri, "small moves"));
    // large moves: anywhere in the box, across its boundary too
    for i in (0..n).step_by(5) {
        let to = [r.unit() * 3.0 - 1.0, r.unit(), r.unit() - 1.0];
        tri.move_point(InputId::new(i), to).unwrap();
    }
    assert!(same_as_fresh(&tri, "large moves"));
    // onto another point: a duplicate, the ids kept
    let target = tri.point(tri.vertex_of_input(InputId(1)));
    tri.move_point(InputId(3), target).unwrap();
    assert_eq!(
        tri.vertex_of_input(InputId(3)),
        tri.vertex_of_input(InputId(1))
    );
    assert_eq!(tri.duplicates(), 1);
    assert_eq!(tri.number_of_vertices(), n - 1);
    // and away again
    tri.move_point(InputId(3), [0.123, 0.456, 0.789]).unwrap();
    assert_eq!((tri.duplicates(), tri.number_of_vertices()), (0, n));
    assert!(same_as_fresh(&tri, "duplicates"));
    // onto the point stored last, and the point stored last onto another: the last
    // point's slot moves, and every input keeps its coordinates
    let last = |tri: &Triangulation<3, 4, _>| {
        tri.input_of_vertex(PointId::new(tri.number_of_vertices() - 1))
    };
    let (a, b) = (InputId(10), last(&tri));
    tri.move_point(a, tri.point(tri.vertex_of_input(b)))
        .unwrap();
    assert_eq!(tri.vertex_of_input(a), tri.vertex_of_input(b));
    let (c, d) = (last(&tri), InputId(11));
    let want = tri.point(tri.vertex_of_input(d));
    tri.move_point(c, want).unwrap();
    assert_eq!(tri.vertex_of_input(c), tri.vertex_of_input(d));
    assert_eq!(tri.point(tri.vertex_of_input(c)), want);
    assert_eq!((tri.duplicates(), tri.number_of_vertices()), (2, n - 2));
    assert!(same_as_fresh(&tri, "duplicates of the last point"));
    // the 1-sheeted quotient held through all of it: no move needed the covering
    assert_eq!(tri.removal_rebuilds(), 0);
}

#[test]
fn duplicates_keep_their_point_until_the_last_goes() {
    let torus = FlatTorus::cuboid([1.0; 2]).unwrap();
    let mut pts = random(300, 11, [1.0; 2]);
    pts[5] = [0.375, 0.6875];
    pts.push(pts[5]); // input 300 duplicates input 5
    pts.push([1.375, -0.3125]); // 301: an exact image of it
    let mut tri = Triangulation::<2, 3, _>::build(torus, &pts).unwrap();
    assert_eq!(tri.duplicates(), 2);
    let p = tri.vertex_of_input(InputId(5));
    let at = tri.point(p);
    tri.remove(InputId(5)).unwrap();
    assert_eq!(tri.number_of_vertices(), 300);
    assert_eq!(tri.first_occurrences()[300], InputId(300));
    assert_eq!(tri.first_occurrences()[301], InputId(300));
    assert_eq!(tri.first_occurrences()[5], InputId::NONE);
    assert_eq!(tri.point(tri.vertex_of_input(InputId(301))), at);
    tri.remove(InputId(300)).unwrap();
    assert_eq!(tri.number_of_vertices(), 300);
    tri.remove(InputId(301)).unwrap();
    assert_eq!((tri.number_of_vertices(), tri.duplicates()), (299, 0));
    assert!(same_as_fresh(&tri, "duplicates"));
}

#[test]
fn bad_ids_and_coordinates_change_nothing() {
    let torus = FlatTorus::cuboid([1.0; 3]).unwrap();
    let mut tri = Triangulation::<3, 4, _>::build(torus, &random(500, 12, [1.0; 3])).unwrap();
    tri.remove(InputId(17)).unwrap();
    let before = geometry(&tri);
    let e = tri.remove(InputId(17)).unwrap_err();
    assert!(matches!(e, Error::UnknownInput { id: 17, .. }));
    assert_eq!(e.to_string(), "input id 17: was removed");
    let e = tri.remove(InputId(500)).unwrap_err().to_string();
    assert_eq!(
        e,
        "input id 500: out of range (500 input points were given)"
    );
    assert!(tri.remove(InputId::NONE).is_err());
    assert!(tri.move_point(InputId(17), [0.5; 3]).is_err());
    let e = tri
        .move_point(InputId(3), [0.5, f64::NAN, 0.5])
        .unwrap_err();
    assert!(
        matches!(e, Error::NonFiniteCoordinate { index: 3, axis: 1, value } if value.is_nan()),
        "{e}"
    );
    assert!(tri
        .move_point(InputId(3), [0.5, 0.5, f64::INFINITY])
        .is_err());
    // a batch of moves is all or nothing: a bad id or coordinate anywhere moves none
    let e = tri.move_all(&[InputId(3), InputId(17)], &[[0.5; 3], [0.25; 3]]);
    assert_eq!(e.unwrap_err().to_string(), "input id 17: was removed");
    let e = tri.move_all(&[InputId(3), InputId(3)], &[[0.5; 3], [0.25; 3]]);
    assert_eq!(e.unwrap_err().to_string(), "input id 3: is given twice");
    let e = tri.move_all(
        &[InputId(3), InputId(4)],
        &[[0.5; 3], [0.25, f64::NAN, 0.5]],
    );
    assert!(matches!(
        e,
        Err(Error::NonFiniteCoordinate {
            index: 4,
            axis: 1,
            ..
        })
    ));
    let e = tri.move_all(&[InputId(3), InputId(4)], &[[0.5; 3]]);
    assert_eq!(
        e.unwrap_err().to_string(),
        "number of target points 1 is out of range: must equal the number of ids, 2"
    );
    assert!(geometry(&tri) == before);
    let fast = tri
        .move_all(&[InputId(3), InputId(4)], &[[0.5; 3], [0.25; 3]])
        .unwrap();
    assert_eq!(fast.len(), 2);
    assert_eq!(tri.point(tri.vertex_of_input(InputId(4))), [0.25; 3]);
    tri.is_valid().unwrap();
}

/// One step of a random sequence.
#[derive(Clone, Debug)]
enum Op {
    Insert([f64; 2]),
    Remove(usize),
    RemoveAll(usize, usize),
    Move(usize, [f64; 2]),
}

fn op() -> impl Strategy<Value = Op> {
    // coordinates on a coarse grid: cospherical sets and duplicates are common
    let coord = (0u32..16).prop_map(|k| k as f64 / 16.0);
    let point = [coord.clone(), coord];
    prop_oneof![
        3 => point.clone().prop_map(Op::Insert),
        2 => any::<usize>().prop_map(Op::Remove),
        1 => (any::<usize>(), 1usize..6).prop_map(|(a, k)| Op::RemoveAll(a, k)),
        2 => (any::<usize>(), point).prop_map(|(i, p)| Op::Move(i, p)),
    ]
}

proptest! {
    // 48 cases in the test suite; PROPTEST_CASES=… for a longer run
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(48),
        ..ProptestConfig::default()
    })]

    /// Random insertions, removals and moves on grid points (crystals and duplicates) in
    /// the three 2D lattices: valid after every step, and the fresh build's cells at the end.
    #[test]
    fn random_sequences_stay_delaunay(ops in proptest::collection::vec(op(), 1..80), lattice in 0usize..3) {
        let (name, torus) = tori2().swap_remove(lattice);
        let mut tri = Triangulation::<2, 3, _>::new(torus);
        for (step, op) in ops.iter().enumerate() {
            let live: Vec<usize> = tri
                .first_occurrences()
                .iter()
                .enumerate()
                .filter(|(_, f)| **f != InputId::NONE)
                .map(|(i, _)| i)
                .collect();
            match *op {
                Op::Insert(p) => {
                    tri.insert(p).unwrap();
                }
                Op::Remove(k) if !live.is_empty() => {
                    tri.remove(InputId::new(live[k % live.len()])).unwrap();
                }
                Op::RemoveAll(a, k) if !live.is_empty() => {
                    let mut ids: Vec<InputId> =
                        (0..k).map(|j| InputId::new(live[(a + 7 * j) % live.len()])).collect();
                    ids.sort_unstable();
                    ids.dedup();
                    tri.remove_all(&ids).unwrap();
                }
                Op::Move(k, p) if !live.is_empty() => {
                    tri.move_point(InputId::new(live[k % live.len()]), p).unwrap();
                }
                _ => {
                    prop_assert!(tri.remove(InputId(0)).is_err());
                }
            }
            if tri.number_of_vertices() > 0 {
                prop_assert!(tri.is_valid().is_ok(), "{name}, step {step} {op:?}: {:?}", tri.is_valid());
            }
        }
        same_as_fresh(&tri, name);
    }
}

/// `find_simplex` gives, per query, the row of `cells(Stored)` that `locate` finds, also
/// after removals (freed cell slots) and for queries outside the domain.
#[test]
fn find_simplex_rows_are_locate_cells() {
    let torus = FlatTorus::cuboid([1.0; 3]).unwrap();
    let mut tri = Triangulation::<3, 4, _>::build(torus, &random(800, 13, [1.0; 3])).unwrap();
    let ids: Vec<InputId> = (0..800).step_by(3).map(InputId::new).collect();
    tri.remove_all(&ids).unwrap();
    let queries: Vec<[f64; 3]> = random(500, 14, [3.0; 3])
        .into_iter()
        .map(|q| q.map(|x| x - 1.0))
        .collect();
    let rows = tri.find_simplex(&queries).unwrap();
    let cells = tri.cells(Copies::Stored);
    for (q, &k) in queries.iter().zip(&rows) {
        let (cell, _) = tri.locate(*q).unwrap();
        assert_eq!(cells[k].vertices, cell.vertices);
        assert_eq!(cells[k].offsets, cell.offsets);
    }
    let e = tri
        .find_simplex(&[[0.5; 3], [0.5, f64::NAN, 0.5]])
        .unwrap_err();
    assert!(matches!(
        e,
        Error::NonFiniteCoordinate {
            index: 1,
            axis: 1,
            ..
        }
    ));
}

/// Points inserted one at a time in random order (each walk starting from the jump-and-walk
/// grid), then removed, inserted and moved, give the bulk build's cells; `find_simplex`
/// returns, for every query, a cell that contains it (checked with plain orientations of
/// the cell's vertex positions, translated by small lattice vectors).
#[test]
fn any_order_insertion_and_location() {
    for (name, torus) in tori3() {
        // (uniform in each domain: a cuboid's points from the unit cube would leave a slab
        // empty, and keep the triangulation in the covering)
        let scale = if name == "cuboid" {
            [1.0, 0.75, 1.5]
        } else {
            [1.0; 3]
        };
        let pts = random(3000, 21, scale);
        let mut tri = Triangulation::<3, 4, _>::new(torus.clone());
        for p in &pts {
            tri.insert(*p).unwrap();
        }
        let bulk = Triangulation::<3, 4, _>::build(torus.clone(), &pts).unwrap();
        assert!(geometry(&tri) == geometry(&bulk), "{name}: random order");
        for i in (0..3000).step_by(3) {
            tri.remove(InputId::new(i)).unwrap();
        }
        for p in random(400, 22, scale) {
            tri.insert(p).unwrap();
        }
        let mut r = SplitMix::new(23);
        for i in (1..3000).step_by(6) {
            let to = scale.map(|l| r.unit() * l);
            tri.move_point(InputId::new(i), to).unwrap();
        }
        assert!(same_as_fresh(&tri, name));
        let queries = random(300, 24, scale);
        let rows = tri.find_simplex(&queries).unwrap();
        let cells = tri.cells(Copies::Stored);
        let orient = |a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]| {
            let (u, v, w) = (
                [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
                [d[0] - a[0], d[1] - a[1], d[2] - a[2]],
            );
            u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                + u[2] * (v[0] * w[1] - v[1] * w[0])
        };
        for (q, &k) in queries.iter().zip(&rows) {
            let cell = &cells[k];
            let inside = (0..125).any(|t: i32| {
                let t = [t % 5 - 2, t / 5 % 5 - 2, t / 25 - 2];
                let x: Vec<[f64; 3]> = (0..4)
                    .map(|i| {
                        let o = std::array::from_fn(|c| cell.offsets[i][c] - t[c] as i8);
                        tri.position(cell.vertices[i], o)
                    })
                    .collect();
                let whole = orient(x[0], x[1], x[2], x[3]);
                (0..4).all(|i| {
                    let mut y = [x[0], x[1], x[2], x[3]];
                    y[i] = *q;
                    orient(y[0], y[1], y[2], y[3]) >= -1e-12 * whole.abs()
                })
            });
            assert!(inside, "{name}: query {q:?} is not in cell {k}");
        }
    }
}
