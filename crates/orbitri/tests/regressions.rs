//! Minimal failing inputs found by the property tests, kept as regressions.

mod common;
use common::*;
use orbitri::{BuildOptions, FlatTorus3, PeriodicDelaunay3};

fn check(space: FlatTorus3, pts: &[[f64; 3]], dummy_threshold: usize) {
    let opts = BuildOptions {
        dummy_threshold,
        ..Default::default()
    };
    let tri = PeriodicDelaunay3::build_with(space, pts, opts, |_| {}).unwrap();
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
