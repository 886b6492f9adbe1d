//! The parallel bulk build: every thread count stores the same triangulation, slot for slot
//! (so every output is the same, bit for bit), and it is the triangulation of inserting the
//! points one by one (the sequential code).

mod common;
use orbitri::spherical::{ProjectiveDelaunay, SphericalDelaunay, Status};
use std::ops::ControlFlow;

use orbitri::{
    BuildOptions, Copies, FlatTorus2, FlatTorus3, InputId, Inserted, PeriodicDelaunay2,
    PeriodicDelaunay3,
};

/// The same value (its full `Debug` text, floats to the last bit) with 1, 2, 3 and 5
/// threads.
fn same_for_every_thread_count<T: std::fmt::Debug>(f: impl Fn(Option<usize>) -> T) {
    let one = format!("{:?}", f(Some(1)));
    for threads in [2, 3, 5] {
        assert!(
            format!("{:?}", f(Some(threads))) == one,
            "{threads} threads build another triangulation than one"
        );
    }
}

fn with_threads(threads: Option<usize>) -> BuildOptions {
    BuildOptions {
        threads,
        ..BuildOptions::default()
    }
}

fn go(_: usize) -> ControlFlow<()> {
    ControlFlow::Continue(())
}

#[test]
fn a_torus_build_is_the_same_for_every_thread_count_and_equals_the_sequential_one() {
    let torus =
        FlatTorus3::triclinic([[1.0, 0.0, 0.0], [0.3, 0.9, 0.0], [-0.2, 0.2, 1.1]]).unwrap();
    let mut pts = common::uniform(6_000, 7, [1.0; 3]);
    // duplicates, also through a period
    pts.extend_from_within(100..120);
    pts.push([pts[5][0] + 1.0, pts[5][1], pts[5][2]]);
    same_for_every_thread_count(|threads| {
        let tri =
            PeriodicDelaunay3::build_with(torus.clone(), &pts, with_threads(threads), go).unwrap();
        let volumes: Vec<f64> = tri.voronoi_measures().iter().map(|c| c.volume).collect();
        (tri.cells(Copies::Stored), tri.first_occurrences(), volumes)
    });
    let bulk =
        PeriodicDelaunay3::build_with(torus.clone(), &pts, with_threads(Some(2)), go).unwrap();
    assert!(bulk.is_valid().is_ok());
    common::brute_force_check(&bulk, &pts);
    let mut one_by_one = PeriodicDelaunay3::new(torus);
    for p in &pts {
        one_by_one.insert(*p).unwrap();
    }
    assert_eq!(
        common::canonical_cells(&bulk.cells(Copies::Unique)),
        common::canonical_cells(&one_by_one.cells(Copies::Unique))
    );
    assert_eq!(bulk.first_occurrences(), one_by_one.first_occurrences());
}

#[test]
fn an_unsorted_build_with_threads_is_the_same_for_every_thread_count_and_equals_one_by_one() {
    // without the spatial sort the items come in their order: each wave is a copy sorted
    // along the curve, its items named by their index (a sorted one is read in place)
    let torus = FlatTorus3::cuboid([1.0, 1.5, 1.0]).unwrap();
    let mut pts = common::uniform(9_000, 3, [1.0, 1.5, 1.0]);
    pts.extend_from_within(4000..4010);
    let unsorted = |threads| BuildOptions {
        threads,
        spatial_sort: false,
        ..BuildOptions::default()
    };
    same_for_every_thread_count(|threads| {
        let tri =
            PeriodicDelaunay3::build_with(torus.clone(), &pts, unsorted(threads), go).unwrap();
        (tri.cells(Copies::Stored), tri.first_occurrences())
    });
    let bulk = PeriodicDelaunay3::build_with(torus.clone(), &pts, unsorted(Some(2)), go).unwrap();
    let one_by_one = PeriodicDelaunay3::build_with(torus, &pts, unsorted(None), go).unwrap();
    assert!(bulk.is_valid().is_ok());
    common::brute_force_check(&bulk, &pts);
    assert_eq!(
        common::canonical_cells(&bulk.cells(Copies::Unique)),
        common::canonical_cells(&one_by_one.cells(Copies::Unique))
    );
    assert_eq!(bulk.first_occurrences(), one_by_one.first_occurrences());
    assert_eq!(bulk.number_of_vertices(), 9_000);
}

#[test]
fn a_cocircular_grid_and_a_batch_are_the_same_for_every_thread_count() {
    // every square of the grid is cocircular: the perturbation decides, whatever the order
    let grid: Vec<[f64; 2]> = (0..150 * 150)
        .map(|i| [(i % 150) as f64 / 150.0, (i / 150) as f64 / 150.0])
        .collect();
    let torus = FlatTorus2::cuboid([1.0, 1.0]).unwrap();
    let canonical = |t: &PeriodicDelaunay2| {
        let mut cells: Vec<Vec<(InputId, [i8; 2])>> = t
            .cells(Copies::Unique)
            .iter()
            .map(|c| {
                let mut v: Vec<(InputId, [i8; 2])> =
                    (0..3).map(|k| (c.vertices[k], c.offsets[k])).collect();
                v.sort_unstable();
                let m = [0, 1].map(|a| v.iter().map(|x| x.1[a]).min().unwrap());
                v.iter_mut()
                    .for_each(|x| x.1 = [x.1[0] - m[0], x.1[1] - m[1]]);
                v
            })
            .collect();
        cells.sort_unstable();
        cells
    };
    same_for_every_thread_count(|threads| {
        let mut tri = PeriodicDelaunay2::build_with(
            torus.clone(),
            &grid[..10_000],
            with_threads(threads),
            go,
        )
        .unwrap();
        let got = tri.insert_all(&grid[10_000..]).unwrap();
        (tri.cells(Copies::Stored), got)
    });
    let bulk =
        PeriodicDelaunay2::build_with(torus.clone(), &grid, with_threads(Some(2)), go).unwrap();
    let mut one_by_one = PeriodicDelaunay2::new(torus);
    for p in &grid {
        assert!(matches!(one_by_one.insert(*p).unwrap(), Inserted::New(_)));
    }
    assert_eq!(canonical(&bulk), canonical(&one_by_one));
}

#[test]
fn small_and_large_batches_are_the_same_for_every_thread_count_and_equal_one_by_one() {
    let torus = FlatTorus3::cuboid([1.0; 3]).unwrap();
    let pts = common::uniform(4_000, 11, [1.0; 3]);
    let batches = |threads| {
        let mut tri =
            PeriodicDelaunay3::build_with(torus.clone(), &pts[..2500], with_threads(threads), go)
                .unwrap();
        // under a 32nd of the points: one at a time even with threads; then waves
        let small = tri.insert_all(&pts[2500..2560]).unwrap();
        let large = tri.insert_all(&pts[2560..]).unwrap();
        (tri, small, large)
    };
    same_for_every_thread_count(|threads| {
        let (tri, small, large) = batches(threads);
        (tri.cells(Copies::Stored), small, large)
    });
    let (tri, ..) = batches(Some(2));
    assert!(tri.is_valid().is_ok());
    let mut one_by_one = PeriodicDelaunay3::new(torus);
    for p in &pts {
        one_by_one.insert(*p).unwrap();
    }
    assert_eq!(
        common::canonical_cells(&tri.cells(Copies::Unique)),
        common::canonical_cells(&one_by_one.cells(Copies::Unique))
    );
}

#[test]
fn a_cospherical_cube_grid_is_the_same_for_every_thread_count_and_equals_the_sequential_one() {
    // every cube of the grid is cospherical (the perturbation decides), and the regions of
    // the points inserted into it are large: the 3D chunks' visit marks, one a region cell
    let k = 16;
    let grid: Vec<[f64; 3]> = (0..k * k * k)
        .map(|i| [i % k, (i / k) % k, i / (k * k)].map(|x| x as f64 / k as f64))
        .collect();
    let torus = FlatTorus3::cuboid([1.0; 3]).unwrap();
    same_for_every_thread_count(|threads| {
        let tri =
            PeriodicDelaunay3::build_with(torus.clone(), &grid, with_threads(threads), go).unwrap();
        tri.cells(Copies::Stored)
    });
    let bulk =
        PeriodicDelaunay3::build_with(torus.clone(), &grid, with_threads(Some(2)), go).unwrap();
    assert!(bulk.is_valid().is_ok());
    let mut one_by_one = PeriodicDelaunay3::new(torus);
    for p in &grid {
        assert!(matches!(one_by_one.insert(*p).unwrap(), Inserted::New(_)));
    }
    assert_eq!(
        common::canonical_cells(&bulk.cells(Copies::Unique)),
        common::canonical_cells(&one_by_one.cells(Copies::Unique))
    );
}

#[test]
fn sphere_and_projective_plane_builds_are_the_same_for_every_thread_count() {
    let mut r = orbitri::sort::SplitMix::new(11);
    let mut pts: Vec<[f64; 3]> = (0..30_000).map(|_| r.on_sphere()).collect();
    // duplicates, and antipodes (duplicates on RP²)
    pts.extend_from_within(0..10);
    pts.push(pts[20].map(|x| -x));
    // points just inside the hull (hidden), and just outside it (each hides the point it
    // covers: inserted after its wave, by the sequential code, when that one came first)
    let (inner, outer): (Vec<[f64; 3]>, Vec<[f64; 3]>) = (100..150)
        .map(|i| {
            (
                pts[i].map(|x| x * (1.0 - 1e-12)),
                pts[i + 100].map(|x| x * (1.0 + 1e-12)),
            )
        })
        .unzip();
    pts.extend(inner.into_iter().chain(outer));
    let sorted = |mut faces: Vec<[InputId; 3]>| {
        for f in &mut faces {
            let k = (0..3).min_by_key(|&k| f[k]).unwrap();
            f.rotate_left(k);
        }
        faces.sort_unstable();
        faces
    };
    same_for_every_thread_count(|threads| {
        let s = SphericalDelaunay::build_with_threads(&pts, threads, go).unwrap();
        let areas: Vec<f64> = s.voronoi_cells().unwrap().iter().map(|c| c.area).collect();
        (s.faces(), areas)
    });
    same_for_every_thread_count(|threads| {
        ProjectiveDelaunay::build_with_threads(&pts, threads, go)
            .unwrap()
            .faces()
    });
    let bulk = SphericalDelaunay::build_with_threads(&pts, Some(2), go).unwrap();
    assert!(bulk.is_valid().is_ok());
    let mut one_by_one = SphericalDelaunay::build(&pts[..3]).unwrap();
    for p in &pts[3..] {
        one_by_one.insert(*p).unwrap();
    }
    assert_eq!(sorted(bulk.faces()), sorted(one_by_one.faces()));
    let statuses = |t: &SphericalDelaunay| -> Vec<Option<Status>> {
        (0..pts.len()).map(|i| t.status(InputId::new(i))).collect()
    };
    assert_eq!(statuses(&bulk), statuses(&one_by_one));
    let hidden = statuses(&bulk)
        .iter()
        .filter(|s| matches!(s, Some(Status::Hidden)))
        .count();
    assert_eq!(
        hidden, 100,
        "the inner points and the points the outer ones cover"
    );
    let rp2 = ProjectiveDelaunay::build_with_threads(&pts, Some(2), go).unwrap();
    assert!(rp2.is_valid().is_ok());
    assert_eq!(rp2.faces().len(), 2 * rp2.number_of_vertices() - 2);
}
