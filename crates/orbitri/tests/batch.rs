//! Batch insertion: all or nothing, spatially sorted, and the same triangulation as a bulk
//! build of everything, with the same first occurrences.

mod common;
use orbitri::{
    Copies, Error, FlatTorus2, FlatTorus3, InputId, Inserted, PeriodicDelaunay2, PeriodicDelaunay3,
};

fn sorted<T: Ord>(mut v: Vec<T>) -> Vec<T> {
    v.sort();
    v
}

#[test]
fn a_batch_equals_the_bulk_build_of_everything() {
    let torus =
        FlatTorus3::triclinic([[1.0, 0.0, 0.0], [0.3, 0.9, 0.0], [-0.2, 0.2, 1.1]]).unwrap();
    let a = common::uniform(1500, 1, [1.0; 3]);
    let mut b = common::uniform(1500, 2, [1.0; 3]);
    // duplicates inside the batch and of earlier points, and an exact lattice translate of an
    // earlier point of the batch that comes first in the batch
    b.push(a[3]);
    b.push(b[10]);
    let m = torus.lattice().vectors();
    let translate = |p: [f64; 3]| std::array::from_fn(|c| p[c] + m[0][c] + m[1][c]);
    b.insert(0, translate(b[20]));
    let mut tri = PeriodicDelaunay3::build(torus.clone(), &a).unwrap();
    let got = tri.insert_all(&b).unwrap();
    assert_eq!(got.len(), b.len());
    assert!(tri.is_valid().is_ok());
    let all: Vec<[f64; 3]> = a.iter().chain(&b).copied().collect();
    let bulk = PeriodicDelaunay3::build(torus, &all).unwrap();
    // (cells compared in canonical form: a cell's vertex rotation depends on its history)
    let same = common::canonical_cells(&tri.cells(Copies::Unique))
        == common::canonical_cells(&bulk.cells(Copies::Unique));
    assert!(
        same,
        "the batch gives another triangulation than the bulk build"
    );
    assert_eq!(tri.first_occurrences(), bulk.first_occurrences());
    assert_eq!(tri.points().len(), bulk.points().len());
    for i in (0..all.len()).map(InputId::new) {
        assert_eq!(
            tri.point(tri.vertex_of_input(i)),
            bulk.point(bulk.vertex_of_input(i)),
            "input {i}"
        );
    }
    assert!(matches!(
        got[a.len() - a.len() + 1501],
        Inserted::Duplicate(_)
    ));
}

#[test]
fn a_bad_point_leaves_the_triangulation_unchanged() {
    let torus =
        FlatTorus3::triclinic([[1.0, 0.0, 0.0], [0.3, 0.9, 0.0], [-0.2, 0.2, 1.1]]).unwrap();
    let a = common::uniform(200, 3, [1.0; 3]);
    let mut tri = PeriodicDelaunay3::build(torus, &a).unwrap();
    let before = sorted(tri.cells(Copies::Stored));
    let mut b = common::uniform(10, 4, [1.0; 3]);
    b[5][1] = f64::NAN;
    let e = tri.insert_all(&b).unwrap_err();
    assert!(
        matches!(
            e,
            Error::NonFiniteCoordinate {
                index: 5,
                axis: 1,
                ..
            }
        ),
        "{e}"
    );
    b[5][1] = 0.5;
    b[7] = [1e300, 0.0, 0.0];
    let e = tri.insert_all(&b).unwrap_err();
    assert!(matches!(e, Error::OutOfReach { index: 7, .. }), "{e}");
    assert_eq!(tri.number_of_input_points(), 200);
    assert_eq!(sorted(tri.cells(Copies::Stored)), before);
    // and a 2D batch into an empty triangulation
    let mut t2 = PeriodicDelaunay2::new(FlatTorus2::cuboid([1.0, 2.0]).unwrap());
    let pts: Vec<[f64; 2]> = common::uniform(300, 5, [1.0, 2.0, 1.0])
        .iter()
        .map(|p| [p[0], p[1]])
        .collect();
    t2.insert_all(&pts).unwrap();
    assert!(t2.is_valid().is_ok());
    assert_eq!(t2.number_of_vertices(), 300);
}
