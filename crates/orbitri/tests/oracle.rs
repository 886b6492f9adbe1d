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

/// Removal against CGAL: the even input points of `rand3_n1000_s1` removed (0, 2, 4, … in
/// that order, as the anchor's `p3dt3rm` does) leave CGAL's triangulation of the odd ones
/// (`rand3_n1000_s1_odd`, dumped by the anchor: its point `k` is our input `2k + 1`).
#[test]
fn removal_matches_cgal_on_the_survivors() {
    let (per, pts) = read_oracle_input("rand3_n1000_s1");
    let ((sheets, v, c), expected) = read_dump("rand3_n1000_s1_odd");
    let mut tri = PeriodicDelaunay3::build(FlatTorus3::cuboid(per).unwrap(), &pts).unwrap();
    for i in (0..pts.len()).step_by(2) {
        tri.remove(orbitri::InputId::new(i)).unwrap();
    }
    tri.is_valid().unwrap();
    assert_eq!(
        (
            tri.sheets(),
            tri.number_of_vertices(),
            tri.number_of_cells()
        ),
        (sheets, v, c)
    );
    let mut cells = tri.cells(Copies::Unique);
    for cell in cells.iter_mut() {
        cell.vertices = cell.vertices.map(|i| orbitri::InputId((i.0 - 1) / 2));
    }
    assert_eq!(
        canonical_cells(&cells),
        expected,
        "cells differ from CGAL's"
    );
}
