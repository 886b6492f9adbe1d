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

/// Weighted points against CGAL's `Periodic_3_regular_triangulation_3` (the harness's
/// `dump3w`): the same cells and the same hidden points, on random sets with many hidden
/// points, sets of mixed sizes, and crystals of equal and of two weights (every
/// orthogonal sphere degenerate). CGAL needs weights below `c²/64`; so do these sets.
#[test]
fn weighted_sets_match_cgal() {
    for name in [
        "rand3w_n1000_s1",
        "rand3w_n150_s2",
        "mixed3w_n600_s3",
        "bcc5w",
        "bcc5w_two",
    ] {
        let text = std::fs::read_to_string(data_dir().join(format!("{name}.txt"))).unwrap();
        let rows: Vec<Vec<f64>> = text
            .lines()
            .map(|l| l.split_whitespace().map(|s| s.parse().unwrap()).collect())
            .collect();
        let c = rows[0][0];
        let pts: Vec<[f64; 3]> = rows[1..].iter().map(|r| [r[0], r[1], r[2]]).collect();
        let w: Vec<f64> = rows[1..].iter().map(|r| r[3]).collect();
        let dump = std::fs::read_to_string(data_dir().join(format!("{name}.dump3w"))).unwrap();
        let lines: Vec<&str> = dump.lines().collect();
        let head: Vec<usize> = lines[0]
            .split_whitespace()
            .map(|s| s.parse().unwrap())
            .collect();
        let cells: Vec<[i64; 16]> = lines[1..lines.len() - 1]
            .iter()
            .map(|l| {
                let v: Vec<i64> = l.split_whitespace().map(|s| s.parse().unwrap()).collect();
                std::array::from_fn(|i| v[i])
            })
            .collect();
        let hidden: Vec<u32> = lines[lines.len() - 1]
            .split_whitespace()
            .skip(1)
            .map(|s| s.parse().unwrap())
            .collect();
        let tri = PeriodicDelaunay3::build_weighted(FlatTorus3::cuboid([c; 3]).unwrap(), &pts, &w)
            .unwrap();
        tri.is_valid().unwrap();
        let got_hidden: Vec<u32> = tri.hidden().iter().map(|i| i.0).collect();
        assert_eq!(
            got_hidden, hidden,
            "{name}: hidden points differ from CGAL's"
        );
        assert_eq!((tri.number_of_vertices(), head[3]), (head[1], hidden.len()));
        let ours = canonical_cells(&tri.cells(Copies::Unique));
        assert_eq!(ours.len(), head[2], "{name}");
        assert_eq!(ours, cells, "{name}: cells differ from CGAL's");
    }
}
