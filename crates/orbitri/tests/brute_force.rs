//! Brute-force checks (empty spheres against all periodic copies, volumes, facets) on
//! cubes, cuboids, triclinic cells, crystals, tiny sets; order independence.

mod common;
use common::*;
use orbitri::sort::SplitMix;
use orbitri::{BuildOptions, Copies, FlatTorus3, InputId, Inserted, PeriodicDelaunay3, PointId};

fn build(space: FlatTorus3, pts: &[[f64; 3]], opts: BuildOptions) -> PeriodicDelaunay3 {
    let tri =
        PeriodicDelaunay3::build_with(space, pts, opts, |_| std::ops::ControlFlow::Continue(()))
            .unwrap();
    tri.is_valid().unwrap();
    brute_force_check(&tri, pts);
    tri
}

fn triclinic() -> FlatTorus3 {
    FlatTorus3::triclinic([[1.0, 0.0, 0.0], [0.31, 0.9, 0.0], [-0.22, 0.17, 1.1]]).unwrap()
}

#[test]
fn tiny_sets_stay_in_the_covering_and_are_correct() {
    for n in 1..=10 {
        let pts = uniform(n, n as u64, [1.0; 3]);
        let tri = build(
            FlatTorus3::cuboid([1.0; 3]).unwrap(),
            &pts,
            BuildOptions::default(),
        );
        assert_eq!(tri.number_of_vertices(), n);
        if n <= 5 {
            assert_eq!(tri.sheets(), 27, "{n} points cannot triangulate the torus");
            assert!(!tri.is_one_sheeted());
        }
        // Euler: in the covering, every vertex copy has 6 cells on average... V − E + F − C = 0
        let e = tri.stored_edges().len();
        let f = tri.stored_facets().len();
        let v = tri.number_of_vertices() * tri.sheets();
        assert_eq!(
            v as i64 - e as i64 + f as i64 - tri.number_of_stored_cells() as i64,
            0
        );
    }
}

#[test]
fn cuboids_and_triclinic_cells() {
    for (space, scale) in [
        (
            FlatTorus3::cuboid([1.0, 2.0, 0.5]).unwrap(),
            [1.0, 2.0, 0.5],
        ),
        (
            FlatTorus3::cuboid([3.0, 3.0, 3.0]).unwrap(),
            [3.0, 3.0, 3.0],
        ),
        (triclinic(), [1.5, 1.5, 1.5]),
    ] {
        for n in [7, 60, 1500] {
            let pts = uniform(n, 11 + n as u64, scale);
            let tri = build(space.clone(), &pts, BuildOptions::default());
            assert_eq!(tri.number_of_vertices(), n);
            if n >= 1500 {
                assert_eq!(tri.sheets(), 1);
            }
        }
    }
}

#[test]
fn insertion_order_does_not_matter() {
    for (space, n, scale) in [
        (FlatTorus3::cuboid([1.0; 3]).unwrap(), 300, [1.0; 3]),
        (FlatTorus3::cuboid([1.0; 3]).unwrap(), 1200, [1.0; 3]),
        (triclinic(), 500, [1.0; 3]),
    ] {
        let pts = uniform(n, 5, scale);
        let reference = canonical_cells(
            &build(space.clone(), &pts, BuildOptions::default()).cells(Copies::Unique),
        );
        let mut rng = SplitMix::new(99);
        for trial in 0..3 {
            let mut perm: Vec<usize> = (0..n).collect();
            for i in (1..n).rev() {
                perm.swap(i, rng.below(i + 1));
            }
            let shuffled: Vec<[f64; 3]> = perm.iter().map(|&i| pts[i]).collect();
            let opts = BuildOptions {
                seed: trial,
                spatial_sort: trial != 1,
                dummy_threshold: if trial == 2 { usize::MAX } else { 1000 },
                ..BuildOptions::default()
            };
            let tri = PeriodicDelaunay3::build_with(space.clone(), &shuffled, opts, |_| {
                std::ops::ControlFlow::Continue(())
            })
            .unwrap();
            tri.is_valid().unwrap();
            let mapped: Vec<orbitri::CellView> = tri
                .cells(Copies::Unique)
                .into_iter()
                .map(|mut c| {
                    c.vertices = c.vertices.map(|v| InputId::new(perm[v.index()]));
                    c
                })
                .collect();
            assert_eq!(canonical_cells(&mapped), reference, "trial {trial}");
        }
    }
}

#[test]
fn crystal_lattices_with_inexact_coordinates() {
    // lattice constant 0.1 is not a binary fraction: every cospherical test is exact work
    let sc = crystal(6, &[[0.0; 3]], 0.1);
    let tri = build(
        FlatTorus3::cuboid([0.6; 3]).unwrap(),
        &sc,
        BuildOptions::default(),
    );
    assert_eq!(tri.number_of_cells(), 6 * 216);
    let fcc = crystal(
        4,
        &[
            [0.0, 0.0, 0.0],
            [0.5, 0.5, 0.0],
            [0.5, 0.0, 0.5],
            [0.0, 0.5, 0.5],
        ],
        0.3,
    );
    let tri = build(
        FlatTorus3::cuboid([1.2; 3]).unwrap(),
        &fcc,
        BuildOptions::default(),
    );
    // each FCC point: 8 tetrahedral holes/4 + 4 octahedral holes ... 2 tets + 1 octahedron (4 cells) per point
    assert_eq!(tri.number_of_cells(), 6 * fcc.len());
    let bcc = crystal(5, &[[0.0; 3], [0.5; 3]], 0.2);
    let tri = build(
        FlatTorus3::cuboid([1.0; 3]).unwrap(),
        &bcc,
        BuildOptions::default(),
    );
    assert_eq!(tri.number_of_cells(), 6 * bcc.len());
}

#[test]
fn fcc_in_its_primitive_triclinic_cell_tiled() {
    // the FCC lattice as a triclinic torus spanned by 3 primitive vectors, 4×4×4 points
    let a = [[0.0, 0.5, 0.5], [0.5, 0.0, 0.5], [0.5, 0.5, 0.0]];
    let k = 4.0;
    let space = FlatTorus3::triclinic(a.map(|r| r.map(|x| x * k))).unwrap();
    let mut pts = Vec::new();
    for i in 0..4 {
        for j in 0..4 {
            for l in 0..4 {
                pts.push(std::array::from_fn(|c| {
                    i as f64 * a[0][c] + j as f64 * a[1][c] + l as f64 * a[2][c]
                }));
            }
        }
    }
    let tri = build(space, &pts, BuildOptions::default());
    assert_eq!(tri.number_of_vertices(), 64);
    assert_eq!(tri.number_of_cells(), 6 * 64);
}

#[test]
fn duplicates_and_wrapping_lose_nothing() {
    let mut pts = uniform(500, 3, [1.0; 3]);
    pts[20] = [0.375, 0.625, 0.125];
    pts.push(pts[10]);
    // a lattice translate, exactly representable: wraps onto point 20 bit for bit
    pts.push([1.375, -1.375, 3.125]);
    pts.push([1.0, 0.5, 0.5]); // on the upper face (CGAL issue #7479)
    pts.push([-1e-20, 0.25, 1.0]);
    let tri = build(
        FlatTorus3::cuboid([1.0; 3]).unwrap(),
        &pts,
        BuildOptions::default(),
    );
    assert_eq!(tri.duplicates(), 2);
    assert_eq!(tri.number_of_vertices(), 502);
    assert_eq!(tri.wrapped(), 3);
    let first = tri.first_occurrences();
    assert_eq!(first[500], InputId(10));
    assert_eq!(first[501], InputId(20));
    assert_eq!(first[502], InputId(502));
    assert_eq!(
        tri.point(tri.vertex_of_input(InputId(502))),
        [0.0, 0.5, 0.5]
    );
    assert_eq!(
        tri.point(tri.vertex_of_input(InputId(503))),
        [0.0, 0.25, 0.0]
    );
    for (i, f) in first.iter().enumerate() {
        assert_eq!(
            tri.input_of_vertex(tri.vertex_of_input(InputId::new(i))),
            *f
        );
    }
}

#[test]
fn incremental_insertion_matches_bulk() {
    let pts = uniform(700, 8, [1.0; 3]);
    let mut inc = PeriodicDelaunay3::new(FlatTorus3::cuboid([1.0; 3]).unwrap());
    for (i, p) in pts.iter().enumerate() {
        // inserted one by one, a point's id is its input id
        assert_eq!(inc.insert(*p).unwrap(), Inserted::New(PointId::new(i)));
        if i < 4 {
            assert_eq!(inc.sheets(), 27);
        }
    }
    assert_eq!(inc.insert(pts[3]).unwrap(), Inserted::Duplicate(PointId(3)));
    inc.is_valid().unwrap();
    let bulk = build(
        FlatTorus3::cuboid([1.0; 3]).unwrap(),
        &pts,
        BuildOptions::default(),
    );
    assert_eq!(
        canonical_cells(&inc.cells(Copies::Unique)),
        canonical_cells(&bulk.cells(Copies::Unique))
    );
    // inserting into a forced 1-sheeted triangulation (criterion not guaranteed) stays correct
    let few = uniform(120, 4, [1.0; 3]);
    let mut t = build(
        FlatTorus3::cuboid([1.0; 3]).unwrap(),
        &few,
        BuildOptions::default(),
    );
    let extra = uniform(30, 77, [1.0; 3]);
    for p in &extra {
        t.insert(*p).unwrap();
    }
    t.is_valid().unwrap();
    let all: Vec<[f64; 3]> = few.iter().chain(extra.iter()).copied().collect();
    brute_force_check(&t, &all);
}

#[test]
fn clustered_points_leave_the_dummies_from_the_covering() {
    // all points in a small ball: the last dummy points cannot leave the quotient, so the
    // triangulation is lifted to the covering, where they leave; it stays there (checked
    // against every image by `build`) with the cells of a build without dummy points
    let mut pts = uniform(300, 21, [0.1; 3]);
    pts.iter_mut()
        .for_each(|p| p.iter_mut().for_each(|x| *x += 0.45));
    let opts = BuildOptions {
        dummy_threshold: 200,
        ..Default::default()
    };
    let tri = build(FlatTorus3::cuboid([1.0; 3]).unwrap(), &pts, opts);
    assert!(tri.used_dummy_points());
    assert_eq!(tri.sheets(), 27);
    let cover = BuildOptions {
        dummy_threshold: usize::MAX,
        ..Default::default()
    };
    let other = build(FlatTorus3::cuboid([1.0; 3]).unwrap(), &pts, cover);
    assert!(!other.used_dummy_points());
    assert_eq!(
        canonical_cells(&tri.cells(Copies::Unique)),
        canonical_cells(&other.cells(Copies::Unique))
    );
}

#[test]
fn access_api() {
    let pts = uniform(400, 2, [1.0; 3]);
    let tri = build(
        FlatTorus3::cuboid([1.0; 3]).unwrap(),
        &pts,
        BuildOptions::default(),
    );
    let cells = tri.cells(Copies::Unique);
    let edges = tri.edges();
    let facets = tri.facets();
    assert_eq!(facets.len(), 2 * cells.len());
    assert_eq!(edges.len(), tri.number_of_vertices() + cells.len());
    let degree_sum: usize = (0..pts.len())
        .map(|i| tri.vertex_neighbors(InputId::new(i)).len())
        .sum();
    assert_eq!(degree_sum, 2 * edges.len());
    for n in tri.vertex_neighbors(InputId(0)) {
        let d = [0, 1, 2].map(|c| pts[n.0.index()][c] + n.1[c] as f64 - pts[0][c]);
        assert!(
            d.iter().map(|x| x * x).sum::<f64>() < 0.5,
            "neighbour far away: {n:?}"
        );
    }
    // locate: the point is inside (or on) the returned cell
    for q in uniform(50, 123, [1.0; 3])
        .iter()
        .chain([[1.5, -0.2, 0.7]].iter())
    {
        let (cell, o) = tri.locate(*q).unwrap();
        let wq = tri.space().lattice().wrap(*q).unwrap().0;
        let corner = |i: usize| {
            [0, 1, 2].map(|c| {
                tri.point(tri.vertex_of_input(cell.vertices[i]))[c] + cell.offsets[i][c] as f64
            })
        };
        let qq = [0, 1, 2].map(|c| wq[c] + o[c] as f64);
        for i in 0..4 {
            let mut s = [corner(0), corner(1), corner(2), corner(3)];
            s[i] = qq;
            let d = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            let (a, b, c) = (d(s[1], s[0]), d(s[2], s[0]), d(s[3], s[0]));
            let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]);
            assert!(det >= -1e-12, "query outside the located cell");
        }
    }
    // STORED in the covering: every copy
    let small = build(
        FlatTorus3::cuboid([1.0; 3]).unwrap(),
        &pts[..3],
        BuildOptions::default(),
    );
    assert_eq!(
        small.cells(Copies::Stored).len(),
        27 * small.cells(Copies::Unique).len()
    );
    // neighbours from a vertex's star agree with the unique edges, also in the covering
    let degrees: usize = (0..3)
        .map(|i| small.vertex_neighbors(InputId(i)).len())
        .sum();
    assert_eq!(degrees, 2 * small.edges().len());
}

#[test]
fn bad_input_is_rejected_with_the_place() {
    let torus = FlatTorus3::cuboid([1.0; 3]).unwrap();
    let e = PeriodicDelaunay3::build(torus.clone(), &[]).unwrap_err();
    assert_eq!(e.to_string(), "the input holds no points");
    let e = PeriodicDelaunay3::build(torus.clone(), &[[0.1, 0.2, 0.3], [0.0, f64::INFINITY, 0.0]])
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "point 1: coordinate 1 is inf, not a finite number"
    );
    let mut t = PeriodicDelaunay3::new(torus);
    assert!(t.insert([f64::NAN, 0.0, 0.0]).is_err());
    assert!(t.locate([0.5; 3]).is_err());
}

fn gaussian_clusters(clusters: usize, per: usize, sigma: f64, seed: u64) -> Vec<[f64; 3]> {
    let mut r = SplitMix::new(seed);
    let centers: Vec<[f64; 3]> = (0..clusters)
        .map(|_| [r.unit(), r.unit(), r.unit()])
        .collect();
    let mut out = Vec::new();
    for i in 0..clusters * per {
        let c = centers[i % clusters];
        out.push(std::array::from_fn(|k| {
            let g =
                (-2.0 * (1.0 - r.unit()).ln()).sqrt() * (std::f64::consts::TAU * r.unit()).cos();
            (c[k] + sigma * g).rem_euclid(1.0) % 1.0
        }));
    }
    out
}

#[test]
fn clustered_points_keep_the_dummy_start_without_the_criterion() {
    // 20 clusters: large empty balls remain once the dummies are gone, so the criterion
    // fails, but the quotient is still a triangulation (no cycle of length ≤ 2)
    let pts = gaussian_clusters(20, 40, 0.02, 5);
    let opts = BuildOptions {
        dummy_threshold: 300,
        ..Default::default()
    };
    let tri = build(FlatTorus3::cuboid([1.0; 3]).unwrap(), &pts, opts);
    assert!(tri.used_dummy_points());
    assert_eq!(tri.sheets(), 1);
    assert!(!tri.engine().criterion_holds());
    let covering = build(
        FlatTorus3::cuboid([1.0; 3]).unwrap(),
        &pts,
        BuildOptions {
            dummy_threshold: usize::MAX,
            ..Default::default()
        },
    );
    assert_eq!(
        canonical_cells(&tri.cells(Copies::Unique)),
        canonical_cells(&covering.cells(Copies::Unique))
    );
    // more points into the quotient that is a triangulation without the criterion
    let mut tri = tri;
    let extra = uniform(200, 31, [1.0; 3]);
    for p in &extra {
        tri.insert(*p).unwrap();
    }
    tri.is_valid().unwrap();
    let all: Vec<[f64; 3]> = pts.iter().chain(extra.iter()).copied().collect();
    brute_force_check(&tri, &all);
    let bulk = build(
        FlatTorus3::cuboid([1.0; 3]).unwrap(),
        &all,
        BuildOptions::default(),
    );
    assert_eq!(
        canonical_cells(&tri.cells(Copies::Unique)),
        canonical_cells(&bulk.cells(Copies::Unique))
    );
}

#[test]
fn degenerate_point_sets() {
    let torus = || FlatTorus3::cuboid([1.0; 3]).unwrap();
    // one point given fifty times
    let same = vec![[0.3, 0.6, 0.9]; 50];
    let tri = build(torus(), &same, BuildOptions::default());
    assert_eq!(
        (tri.number_of_vertices(), tri.duplicates(), tri.sheets()),
        (1, 49, 27)
    );
    assert_eq!(tri.first_occurrences(), vec![InputId(0); 50]);
    // all points on one plane, on one line, and on a plane of a grid
    let mut r = SplitMix::new(17);
    let plane: Vec<[f64; 3]> = (0..150).map(|_| [r.unit(), r.unit(), 0.5]).collect();
    build(torus(), &plane, BuildOptions::default());
    let line: Vec<[f64; 3]> = (0..40).map(|_| [r.unit(), 0.25, 0.75]).collect();
    build(torus(), &line, BuildOptions::default());
    let grid_plane: Vec<[f64; 3]> = (0..144)
        .map(|i| [(i % 12) as f64 / 12.0, (i / 12) as f64 / 12.0, 0.0])
        .collect();
    build(
        torus(),
        &grid_plane,
        BuildOptions {
            dummy_threshold: 100,
            ..Default::default()
        },
    );
}
