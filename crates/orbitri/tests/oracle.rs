//! The same triangulation as CGAL's (canonical cell lists from the anchor harness), cell for
//! cell, including degenerate crystals where the symbolic perturbation decides.

mod common;
use common::*;
use orbitri::{BuildOptions, Copies, FlatTorus3, PeriodicDelaunay3};

fn check(name: &str, opts: BuildOptions) {
    let (per, pts) = read_oracle_input(name);
    let ((sheets, v, c), expected) = read_dump(name);
    let tri = PeriodicDelaunay3::build_with(FlatTorus3::cuboid(per).unwrap(), &pts, opts, |_| {
        std::ops::ControlFlow::Continue(())
    })
    .unwrap();
    tri.is_valid().unwrap();
    assert_eq!(
        (
            tri.sheets(),
            tri.number_of_vertices(),
            tri.number_of_cells()
        ),
        (sheets, v, c),
        "{name}"
    );
    assert_eq!(
        canonical_cells(&tri.cells(Copies::Unique)),
        expected,
        "{name}: cells differ from CGAL's"
    );
}

#[test]
fn random_sets_match_cgal() {
    for name in ["rand3_n100_s1", "rand3_n1000_s1"] {
        check(name, BuildOptions::default());
        check(
            name,
            BuildOptions {
                dummy_threshold: usize::MAX,
                ..Default::default()
            },
        );
        check(
            name,
            BuildOptions {
                dummy_threshold: 0,
                ..Default::default()
            },
        );
    }
}

#[test]
fn crystals_match_cgal() {
    for name in [
        "sc10_unit",
        "sc10_int",
        "bcc10_unit",
        "bcc10_int",
        "fcc10_int",
    ] {
        check(name, BuildOptions::default());
    }
}

#[test]
fn crystals_match_cgal_in_the_covering_and_in_input_order() {
    for name in ["sc10_int", "bcc10_int"] {
        check(
            name,
            BuildOptions {
                dummy_threshold: usize::MAX,
                spatial_sort: false,
                ..Default::default()
            },
        );
    }
}
