//! Minimal failing inputs found by the property tests, kept as regressions.

mod common;
use common::*;
use orbitri::{BuildOptions, Copies, FlatTorus3, InputId, PeriodicDelaunay3};

fn check(space: FlatTorus3, pts: &[[f64; 3]], dummy_threshold: usize) {
    let opts = BuildOptions {
        dummy_threshold,
        ..Default::default()
    };
    let tri =
        PeriodicDelaunay3::build_with(space, pts, opts, |_| std::ops::ControlFlow::Continue(()))
            .unwrap();
    tri.is_valid().unwrap();
    brute_force_check(&tri, pts);
}

#[test]
fn grid_points_in_a_small_cube_covering() {
    let pts = [
        [0.0, 0.0, 0.0],
        [0.4, 1.2000000000000002, 0.0],
        [1.0, -0.2, -0.4],
        [0.0, 0.0, 0.0],
        [1.0, -0.2, 0.6000000000000001],
    ];
    check(FlatTorus3::cuboid([0.8; 3]).unwrap(), &pts, usize::MAX);
}

/// Found by a 240-case proptest run: input 0 is `c`, input 1 the origin (an exact lattice
/// translate, so a duplicate). In a triclinic box `c` rounds to fractional 0.999… and stays
/// `c`; built in spatial order, the origin came first and the point kept the origin's
/// coordinates, so the offsets of input 0's cells were relative to the wrong representative.
/// Now every point keeps the wrapped coordinates of its first occurrence.
#[test]
fn a_duplicate_keeps_the_coordinates_of_its_first_occurrence() {
    let rows = [
        [0.8, 0.0, 0.0],
        [0.24, 0.8, 0.0],
        [-0.16, 0.2, 1.2416668057491016],
    ];
    let at = |f: f64| -> [f64; 3] { std::array::from_fn(|c| f * rows[2][c]) };
    let pts = [at(1.0), at(0.0), at(-0.25)];
    let space = || FlatTorus3::triclinic(rows).unwrap();
    let bulk = PeriodicDelaunay3::build_with(space(), &pts, BuildOptions::default(), |_| {
        std::ops::ControlFlow::Continue(())
    })
    .unwrap();
    bulk.is_valid().unwrap();
    brute_force_check(&bulk, &pts);
    let mut inc = PeriodicDelaunay3::new(space());
    for p in &pts {
        inc.insert(*p).unwrap();
    }
    inc.is_valid().unwrap();
    brute_force_check(&inc, &pts);
    assert_eq!(
        canonical_cells(&inc.cells(Copies::Unique)),
        canonical_cells(&bulk.cells(Copies::Unique))
    );
    let wrapped_c = bulk.space().lattice().wrap(pts[0]).unwrap().0;
    assert_eq!(bulk.point(bulk.vertex_of_input(InputId(0))), wrapped_c);
    assert_eq!(inc.point(inc.vertex_of_input(InputId(0))), wrapped_c);
}
