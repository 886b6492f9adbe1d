//! The sphere: faces against an independent brute-force hull, order independence, exact
//! degenerate sets (cube, octahedron, lon/lat grids with repeated poles), small sets and
//! hemispheres (CGAL's dimension), hidden points, removals against fresh builds, and the
//! Voronoi cells (areas, the equal-distance property of their vertices).

use std::collections::BTreeSet;
use std::f64::consts::PI;

use orbitri::predicates::spherical::{orient_origin, side_of_circle};
use orbitri::predicates::Sign;
use orbitri::sort::SplitMix;
use orbitri::spherical::{lonlat_to_point, normalized, SphericalDelaunay, Status};
use orbitri::{Error, InputId};

fn random_points(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = SplitMix::new(seed);
    (0..n).map(|_| r.on_sphere()).collect()
}

/// A face as a rotation-invariant key: its least id first, the cyclic order kept.
fn key(f: [InputId; 3]) -> [u32; 3] {
    let k = (0..3).min_by_key(|&k| f[k]).unwrap();
    [f[k].0, f[(k + 1) % 3].0, f[(k + 2) % 3].0]
}

fn face_set(tri: &SphericalDelaunay) -> BTreeSet<[u32; 3]> {
    tri.faces().into_iter().map(key).collect()
}

/// No point strictly beyond the plane of any face (unperturbed, exact), every face
/// counter-clockwise about the centre, and the face count of a triangulated sphere.
fn check_empty(tri: &SphericalDelaunay, pts: &[[f64; 3]]) {
    tri.is_valid().unwrap();
    for f in tri.faces() {
        let [a, b, c] = f.map(|i| pts[i.index()]);
        assert_eq!(orient_origin(&a, &b, &c), Sign::Positive);
        for q in pts {
            assert_ne!(side_of_circle(&a, &b, &c, q), Sign::Positive, "{f:?}");
        }
    }
    if tri.covers_sphere() {
        assert_eq!(tri.faces().len(), 2 * tri.number_of_vertices() - 4);
    }
}

/// The faces of the hull by brute force over all triples (points in general position):
/// those that hold the centre strictly inside, or with `ghosts` all of them.
fn brute_hull(pts: &[[f64; 3]], ghosts: bool) -> BTreeSet<[u32; 3]> {
    let n = pts.len();
    let mut out = BTreeSet::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                if i == j || j == k || i == k {
                    continue;
                }
                let (a, b, c) = (&pts[i], &pts[j], &pts[k]);
                if !ghosts && orient_origin(a, b, c) != Sign::Positive {
                    continue;
                }
                if pts
                    .iter()
                    .all(|q| side_of_circle(a, b, c, q) != Sign::Positive)
                {
                    out.insert(key([i, j, k].map(InputId::new)));
                }
            }
        }
    }
    out
}

#[test]
fn random_faces_equal_the_brute_force_hull() {
    for seed in 0..5 {
        let pts = random_points(40, seed);
        let tri = SphericalDelaunay::build(&pts).unwrap();
        assert_eq!(tri.dimension(), 2);
        assert!(tri.covers_sphere());
        assert_eq!(face_set(&tri), brute_hull(&pts, false), "seed {seed}");
    }
    let pts = random_points(3000, 7);
    let tri = SphericalDelaunay::build(&pts).unwrap();
    assert_eq!(tri.number_of_vertices(), 3000);
    check_empty(&tri, &pts);
}

#[test]
fn faces_do_not_depend_on_the_order() {
    // a lon/lat grid: many cocircular quadruples, so the perturbation decides
    let mut pts = Vec::new();
    for i in 0..24 {
        for j in -5..=5 {
            pts.push(lonlat_to_point(0, i as f64 * 15.0, j as f64 * 15.0).unwrap());
        }
    }
    let tri = SphericalDelaunay::build(&pts).unwrap();
    check_empty(&tri, &pts);
    let reference: BTreeSet<[[u64; 3]; 3]> = tri
        .faces()
        .into_iter()
        .map(|f| coords_key(f.map(|i| pts[i.index()])))
        .collect();
    let mut r = SplitMix::new(5);
    for _ in 0..3 {
        let mut shuffled = pts.clone();
        for k in (1..shuffled.len()).rev() {
            shuffled.swap(k, r.below(k + 1));
        }
        // one by one in the shuffled order, not the built-in spatial order
        let mut t = SphericalDelaunay::new();
        for p in &shuffled {
            t.insert(*p).unwrap();
        }
        let got: BTreeSet<[[u64; 3]; 3]> = t
            .faces()
            .into_iter()
            .map(|f| coords_key(f.map(|i| shuffled[i.index()])))
            .collect();
        assert_eq!(got, reference);
    }
}

/// A face by its coordinates, rotated to start at the least.
fn coords_key(f: [[f64; 3]; 3]) -> [[u64; 3]; 3] {
    let b = f.map(|p| p.map(f64::to_bits));
    let k = (0..3).min_by_key(|&k| b[k]).unwrap();
    [b[k], b[(k + 1) % 3], b[(k + 2) % 3]]
}

#[test]
fn exact_degenerate_sets() {
    let s = 3f64.sqrt().recip();
    let cube: Vec<[f64; 3]> = (0..8)
        .map(|k| [0, 1, 2].map(|b| if k >> b & 1 == 1 { s } else { -s }))
        .collect();
    let octahedron = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    // a lon/lat grid whose poles are given once per longitude
    let mut grid = Vec::new();
    for i in 0..36 {
        for j in -9..=9 {
            grid.push(lonlat_to_point(0, i as f64 * 10.0, j as f64 * 10.0).unwrap());
        }
    }
    for (name, pts, vertices) in [
        ("cube", cube, 8),
        ("octahedron", octahedron, 6),
        ("grid", grid, 36 * 17 + 2),
    ] {
        let tri = SphericalDelaunay::build(&pts).unwrap();
        check_empty(&tri, &pts);
        assert!(tri.hidden().is_empty(), "{name}");
        assert_eq!(tri.number_of_vertices(), vertices, "{name}");
        assert_eq!(tri.duplicates(), pts.len() - vertices, "{name}");
        let cells = tri.voronoi_cells().unwrap();
        let total: f64 = cells.iter().map(|c| c.area).sum();
        assert!((total - 4.0 * PI).abs() < 1e-12, "{name}: {total}");
    }
}

#[test]
fn small_sets_and_hemispheres_follow_cgal() {
    let e = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.6, 0.8, 0.0],
    ];
    let mut tri = SphericalDelaunay::new();
    assert_eq!(tri.dimension(), -2);
    tri.insert(e[0]).unwrap();
    assert_eq!(tri.dimension(), -1);
    tri.insert(e[1]).unwrap();
    assert_eq!(tri.dimension(), 0);
    tri.insert(e[3]).unwrap();
    // three points on the equator: one plane
    assert_eq!(tri.dimension(), 1);
    assert!(tri.faces().is_empty());
    tri.is_valid().unwrap();
    tri.insert(e[2]).unwrap();
    assert_eq!(tri.dimension(), 2);
    // four points in a hemisphere: the faces that face away from the centre only
    assert!(!tri.covers_sphere());
    check_empty(&tri, &[e[0], e[1], e[3], e[2]]);
    check_closed(&tri, &[e[0], e[1], e[3], e[2]]);
    // the south pole alone does not enclose the centre (every point has x ≥ 0) ...
    tri.insert([0.0, 0.0, -1.0]).unwrap();
    assert!(!tri.covers_sphere());
    tri.is_valid().unwrap();
    tri.remove(InputId(4)).unwrap();
    // ... a point below all three axes does
    tri.insert([-0.5, -0.5, -0.5f64.sqrt()]).unwrap();
    assert!(tri.covers_sphere());
    tri.is_valid().unwrap();
    assert_eq!(tri.faces().len(), 6);

    // a random hemisphere: faces equal the brute-force hull's faces about the centre
    let pts: Vec<[f64; 3]> = random_points(60, 3)
        .into_iter()
        .map(|p| [p[0], p[1], p[2].abs()])
        .collect();
    let tri = SphericalDelaunay::build(&pts).unwrap();
    assert!(!tri.covers_sphere());
    check_empty(&tri, &pts);
    assert_eq!(face_set(&tri), brute_hull(&pts, false));
    // and every point is a vertex
    assert_eq!(tri.number_of_vertices(), 60);
}

/// The faces and ghost faces close up: no point strictly beyond a ghost face, which does
/// not hold the centre strictly inside; every directed edge once, its reverse once, and
/// the neighbours across them; `2V − 4` faces in all; the Voronoi cells tile the sphere.
fn check_closed(tri: &SphericalDelaunay, pts: &[[f64; 3]]) {
    check_empty(tri, pts);
    let (faces, ghosts) = (tri.faces(), tri.ghost_faces());
    for f in &ghosts {
        let [a, b, c] = f.map(|i| pts[i.index()]);
        assert_ne!(orient_origin(&a, &b, &c), Sign::Positive, "{f:?}");
        for q in pts {
            assert_ne!(side_of_circle(&a, &b, &c, q), Sign::Positive, "{f:?}");
        }
    }
    let all: Vec<[InputId; 3]> = faces.iter().chain(&ghosts).copied().collect();
    assert_eq!(all.len(), 2 * tri.number_of_vertices() - 4);
    let mut edges = std::collections::HashMap::new();
    for (n, f) in all.iter().enumerate() {
        for k in 0..3 {
            assert!(edges.insert((f[k], f[(k + 1) % 3]), n).is_none(), "{f:?}");
        }
    }
    for (f, across) in all.iter().zip(tri.neighbors()) {
        for k in 0..3 {
            assert_eq!(edges[&(f[(k + 2) % 3], f[(k + 1) % 3])], across[k]);
        }
    }
    let cells = tri.voronoi_cells().unwrap();
    let total: f64 = cells.iter().map(|c| c.area).sum();
    assert!((total - 4.0 * PI).abs() < 1e-12 * 4.0 * PI, "{total}");
    let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    for c in &cells {
        let s = pts[c.site.index()];
        assert!(c.area > 0.0);
        for (k, v) in c.vertices.iter().enumerate() {
            let n = pts[c.neighbors[k].index()];
            assert!((dot(v, &s) - dot(v, &n)).abs() < 1e-12);
            // no site nearer to a vertex than its own
            for q in pts {
                assert!(dot(v, q) <= dot(v, &s) + 1e-12);
            }
        }
    }
}

#[test]
fn ghost_faces_close_hemispheres() {
    // a random hemisphere: with the ghost faces, the whole brute-force hull
    let pts: Vec<[f64; 3]> = random_points(200, 8)
        .into_iter()
        .map(|p| [p[0], p[1], p[2].abs()])
        .collect();
    let tri = SphericalDelaunay::build(&pts).unwrap();
    check_closed(&tri, &pts);
    let hull: BTreeSet<[u32; 3]> = tri
        .faces()
        .into_iter()
        .chain(tri.ghost_faces())
        .map(key)
        .collect();
    assert_eq!(hull, brute_hull(&pts, true));

    // the equator's axis points and the north pole: the square through the centre is
    // fanned from its greatest vertex, (1, 0, 0)
    let mut pts = vec![
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    pts.push([0.0, 0.0, 1.0]);
    let tri = SphericalDelaunay::build(&pts).unwrap();
    check_closed(&tri, &pts);
    let ghosts: BTreeSet<[u32; 3]> = tri.ghost_faces().into_iter().map(key).collect();
    assert_eq!(ghosts, BTreeSet::from([[0, 2, 1], [0, 3, 2]]));

    // grids: a hemisphere with its rim on the equator, a cap (its rim a small circle),
    // an octant (a rim on three great circles, the centre outside), a lune
    let grid = |lon: std::ops::RangeInclusive<i32>, lat: std::ops::RangeInclusive<i32>| {
        let mut out = Vec::new();
        for i in lon {
            for j in lat.clone() {
                out.push(lonlat_to_point(0, i as f64 * 10.0, j as f64 * 10.0).unwrap());
            }
        }
        out
    };
    for (name, pts) in [
        ("hemisphere", grid(0..=35, 0..=9)),
        ("cap", grid(0..=35, 3..=9)),
        ("octant", grid(0..=9, 0..=9)),
        ("lune", grid(0..=18, -9..=9)),
    ] {
        let tri = SphericalDelaunay::build(&pts).unwrap();
        assert!(!tri.covers_sphere(), "{name}");
        assert!(!tri.ghost_faces().is_empty(), "{name}");
        check_closed(&tri, &pts);
        // the faces do not depend on the order
        let mut shuffled: Vec<usize> = (0..pts.len()).collect();
        let mut r = SplitMix::new(3);
        for k in (1..shuffled.len()).rev() {
            shuffled.swap(k, r.below(k + 1));
        }
        let other = SphericalDelaunay::build(&shuffled.iter().map(|&k| pts[k]).collect::<Vec<_>>())
            .unwrap();
        let coords =
            |tri: &SphericalDelaunay, order: &dyn Fn(usize) -> usize| -> BTreeSet<[[u64; 3]; 3]> {
                tri.ghost_faces()
                    .into_iter()
                    // (the poles repeat, with zeros of either sign)
                    .map(|f| coords_key(f.map(|i| pts[order(i.index())].map(|x| x + 0.0))))
                    .collect()
            };
        assert_eq!(
            coords(&tri, &|i| i),
            coords(&other, &|i| shuffled[i]),
            "{name}"
        );
    }

    // four points in a cap of 1e-3 radians
    let pts: Vec<[f64; 3]> = [(0.0, 0.0), (1e-3, 0.0), (0.0, 1e-3), (-7e-4, -7e-4)]
        .iter()
        .map(|&(x, y): &(f64, f64)| [x, y, (1.0 - x * x - y * y).sqrt()])
        .collect();
    let tri = SphericalDelaunay::build(&pts).unwrap();
    check_closed(&tri, &pts);
}

#[test]
fn points_inside_the_hull_are_hidden_and_come_back() {
    let mut pts = random_points(200, 11);
    // four points within 1e-4 of the north pole around a fifth pulled in by 4e-7
    let d = 1e-4;
    let cap = [[d, 0.0], [0.0, d], [-d, 0.0], [0.0, -d]];
    for [x, y] in cap {
        pts.push(normalized(&[[x, y, 1.0]]).unwrap()[0]);
    }
    pts.push([0.0, 0.0, 1.0 - 4e-7]);
    let inner = InputId::new(pts.len() - 1);
    let mut tri = SphericalDelaunay::build(&pts).unwrap();
    assert_eq!(tri.hidden(), vec![inner]);
    assert_eq!(tri.status(inner), Some(Status::Hidden));
    assert_eq!(tri.number_of_vertices(), 204);
    check_empty(&tri, &pts);
    // the cap's plane is 5e-9 below the pole: without one of its points the others, and
    // then the faces to the random points around, still cover the inner point ...
    tri.remove(InputId(200)).unwrap();
    assert_eq!(tri.status(inner), Some(Status::Hidden));
    for k in 201..204 {
        tri.remove(InputId(k)).unwrap();
    }
    // ... until the cap is gone: the nearest faces are then far below it
    assert_eq!(tri.status(inner), Some(Status::Vertex));
    assert!(tri.hidden().is_empty());
    tri.is_valid().unwrap();
    // inserting the cap again hides it again
    for p in &pts[200..204] {
        assert_eq!(tri.insert(*p).unwrap(), Status::Vertex);
    }
    assert_eq!(tri.status(inner), Some(Status::Hidden));
    assert_eq!(tri.number_of_vertices(), 204);
    tri.is_valid().unwrap();
}

#[test]
fn removals_equal_fresh_builds() {
    let pts = random_points(400, 21);
    let mut tri = SphericalDelaunay::build(&pts).unwrap();
    let mut r = SplitMix::new(2);
    let mut alive: Vec<usize> = (0..pts.len()).collect();
    for step in 0..396 {
        let k = alive.swap_remove(r.below(alive.len()));
        tri.remove(InputId::new(k)).unwrap();
        assert!(tri.remove(InputId::new(k)).is_err());
        if step % 37 == 0 || alive.len() < 12 {
            tri.is_valid().unwrap();
            let kept: Vec<[f64; 3]> = alive.iter().map(|&i| pts[i]).collect();
            let fresh = SphericalDelaunay::build(&kept).unwrap();
            let ours: BTreeSet<[[u64; 3]; 3]> = tri
                .faces()
                .into_iter()
                .map(|f| coords_key(f.map(|i| pts[i.index()])))
                .collect();
            let theirs: BTreeSet<[[u64; 3]; 3]> = fresh
                .faces()
                .into_iter()
                .map(|f| coords_key(f.map(|i| kept[i.index()])))
                .collect();
            assert_eq!(ours, theirs, "after {} removals", step + 1);
            assert_eq!(tri.dimension(), fresh.dimension());
            assert_eq!(tri.covers_sphere(), fresh.covers_sphere());
        }
    }
    assert_eq!(tri.number_of_vertices(), 4);
}

#[test]
fn bad_input_is_a_typed_error() {
    assert!(matches!(
        SphericalDelaunay::build(&[]),
        Err(Error::EmptyInput)
    ));
    let r = SphericalDelaunay::build(&[[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    assert!(matches!(r, Err(Error::OffSphere { index: 1, .. })), "{r:?}");
    let r = SphericalDelaunay::build(&[[f64::NAN, 0.0, 1.0]]);
    assert!(matches!(
        r,
        Err(Error::NonFiniteCoordinate { index: 0, .. })
    ));
    assert!(SphericalDelaunay::build_lonlat(&[[0.0, 91.0]]).is_err());
    assert!(normalized(&[[0.0; 3]]).is_err());
    let mut tri = SphericalDelaunay::build(&random_points(10, 1)).unwrap();
    assert!(tri.insert([0.0, 0.0, 0.5]).is_err());
    assert_eq!(tri.number_of_input_points(), 10);
    assert!(tri.remove(InputId(10)).is_err());
    tri.is_valid().unwrap();
}

#[test]
fn lonlat_is_exact_at_the_poles_the_axes_and_antipodes() {
    assert_eq!(lonlat_to_point(0, 0.0, 90.0).unwrap(), [0.0, 0.0, 1.0]);
    assert_eq!(lonlat_to_point(0, 123.0, -90.0).unwrap()[2], -1.0);
    assert_eq!(lonlat_to_point(0, 90.0, 0.0).unwrap(), [0.0, 1.0, 0.0]);
    assert_eq!(lonlat_to_point(0, -180.0, 0.0).unwrap(), [-1.0, 0.0, 0.0]);
    // antipodes exactly: (λ + 180, −φ) ↦ −p (longitudes in 1/1024 degrees: λ + 180 exact)
    let mut r = SplitMix::new(3);
    for _ in 0..1000 {
        let lon = (r.unit() * 360.0 * 1024.0).round() / 1024.0 - 180.0;
        let lat = r.unit() * 180.0 - 90.0;
        let p = lonlat_to_point(0, lon, lat).unwrap();
        assert_eq!(
            lonlat_to_point(0, lon + 180.0, -lat).unwrap(),
            p.map(|x| -x)
        );
    }
    let p = lonlat_to_point(0, 30.0, 45.0).unwrap();
    let back = orbitri::spherical::point_to_lonlat(&p);
    assert!((back[0] - 30.0).abs() < 1e-12 && (back[1] - 45.0).abs() < 1e-12);
}

#[test]
fn voronoi_vertices_are_equidistant_and_areas_sum_to_four_pi() {
    let pts = random_points(20_000, 5);
    let tri = SphericalDelaunay::build(&pts).unwrap();
    let cells = tri.voronoi_cells().unwrap();
    assert_eq!(cells.len(), 20_000);
    let total: f64 = cells.iter().map(|c| c.area).sum();
    assert!((total - 4.0 * PI).abs() < 1e-12 * 4.0 * PI, "{total}");
    let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    for c in cells.iter().step_by(97) {
        let s = pts[c.site.index()];
        assert!(c.area > 0.0);
        assert!(dot(&c.centroid, &s) > 0.99);
        for (k, v) in c.vertices.iter().enumerate() {
            // the arc's two sites are equally far from both its ends
            let n = pts[c.neighbors[k].index()];
            let w = &c.vertices[(k + 1) % c.vertices.len()];
            assert!((dot(v, &s) - dot(v, &n)).abs() < 1e-12);
            assert!((dot(w, &s) - dot(w, &n)).abs() < 1e-12);
            assert!(c.arc_lengths[k] > 0.0);
        }
    }
    // neighbours are mutual
    let by_site: std::collections::HashMap<InputId, &orbitri::SphericalCell> =
        cells.iter().map(|c| (c.site, c)).collect();
    for c in cells.iter().step_by(13) {
        for n in &c.neighbors {
            assert!(by_site[n].neighbors.contains(&c.site));
        }
    }
}

#[test]
fn a_build_reports_its_progress_and_stops_when_asked() {
    // the rounds are sorted on a helper thread while the ones before them are inserted:
    // the counts rise to the end, and a stop returns at once, the helper with it
    let pts = random_points(30_000, 8);
    let mut seen = Vec::new();
    let tri = SphericalDelaunay::build_with(&pts, |k| {
        seen.push(k);
        std::ops::ControlFlow::Continue(())
    })
    .unwrap();
    assert_eq!(tri.number_of_vertices(), 30_000);
    assert!(seen.windows(2).all(|w| w[0] <= w[1]), "{seen:?}");
    assert_eq!((seen[0], *seen.last().unwrap()), (0, 30_000));
    assert!(seen.len() >= 30_000 / 4096, "{} reports", seen.len());
    let mut last = 0;
    let stopped = SphericalDelaunay::build_with(&pts, |k| {
        last = k;
        if k >= 10_000 {
            std::ops::ControlFlow::Break(())
        } else {
            std::ops::ControlFlow::Continue(())
        }
    });
    assert!(matches!(stopped, Err(Error::Interrupted)));
    assert!((10_000..20_000).contains(&last), "stopped at {last}");
}
