//! Voronoi cells against an independent method: each point's cell is also computed by
//! clipping a large box with the bisector half-spaces of every periodic copy of every other
//! point nearby (no triangulation involved), and must have the same volume and the same
//! neighbours with the same shifts. Crystals give equal cells exactly; volumes sum to the
//! domain; every face is seen from the other side with the negated shift.

use std::collections::BTreeSet;

mod common;
use common::crystal;

use orbitri::sort::SplitMix;
use orbitri::{
    FlatTorus, FlatTorus2, FlatTorus3, InputId, Lattice, PeriodicDelaunay2, PeriodicDelaunay3,
    VoronoiCell,
};

type Poly3 = Vec<Vec<[f64; 3]>>;
/// A bisector half-space `n·x ≤ d` of a neighbour image: (|n|², id, shift, n, d).
type Bisector = (f64, u32, [i8; 3], [f64; 3], f64);

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Clips a convex polyhedron (faces as vertex loops) by `n·x ≤ d`; returns whether a new face
/// (a non-empty cap) was created.
fn clip3(poly: &mut Poly3, n: [f64; 3], d: f64) -> bool {
    let eps = 1e-14;
    let mut cap: Vec<[f64; 3]> = Vec::new();
    let mut out: Poly3 = Vec::new();
    for face in poly.iter() {
        let mut f = Vec::new();
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            let (da, db) = (dot3(n, a) - d, dot3(n, b) - d);
            if da <= eps {
                f.push(a);
            }
            if (da < -eps && db > eps) || (da > eps && db < -eps) {
                let t = da / (da - db);
                let x = [
                    a[0] + t * (b[0] - a[0]),
                    a[1] + t * (b[1] - a[1]),
                    a[2] + t * (b[2] - a[2]),
                ];
                f.push(x);
                cap.push(x);
            } else if da.abs() <= eps {
                cap.push(a);
            }
        }
        if f.len() >= 3 {
            out.push(f);
        }
    }
    // order the cap around its centroid in the plane
    cap.sort_by(|a, b| a.partial_cmp(b).unwrap());
    cap.dedup_by(|a, b| dot3(sub3(*a, *b), sub3(*a, *b)) < 1e-24);
    let created = cap.len() >= 3;
    if created {
        let c = cap
            .iter()
            .fold([0.0; 3], |s, p| [s[0] + p[0], s[1] + p[1], s[2] + p[2]]);
        let c = c.map(|x| x / cap.len() as f64);
        let u = sub3(cap[0], c);
        let w = cross3(n, u);
        cap.sort_by(|a, b| {
            let (da, db) = (sub3(*a, c), sub3(*b, c));
            let ta = dot3(da, w).atan2(dot3(da, u));
            let tb = dot3(db, w).atan2(dot3(db, u));
            ta.total_cmp(&tb)
        });
        out.push(cap);
    }
    *poly = out;
    created
}

fn volume3(poly: &Poly3, inside: [f64; 3]) -> f64 {
    poly.iter()
        .map(|f| {
            (1..f.len() - 1)
                .map(|t| {
                    dot3(
                        sub3(f[0], inside),
                        cross3(sub3(f[t], inside), sub3(f[t + 1], inside)),
                    )
                    .abs()
                        / 6.0
                })
                .sum::<f64>()
        })
        .sum()
}

/// The Voronoi cell of point `i` by clipping: volume and the neighbours (id, shift) whose
/// bisector bounds a face of positive area.
fn clipped3(m: [[f64; 3]; 3], pts: &[[f64; 3]], i: usize) -> (f64, BTreeSet<(u32, [i8; 3])>) {
    let p = pts[i];
    let r = 3.0 * (0..3).map(|k| dot3(m[k], m[k])).sum::<f64>().sqrt();
    let mut poly: Poly3 = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            // a face of the cube [p − r, p + r]³
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut face = Vec::new();
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let mut x = p;
                x[axis] += sign * r;
                x[u] += a * r;
                x[v] += b * r;
                face.push(x);
            }
            poly.push(face);
        }
    }
    let mut planes: Vec<Bisector> = Vec::new();
    for (j, q) in pts.iter().enumerate() {
        for x in -2i8..=2 {
            for y in -2i8..=2 {
                for z in -2i8..=2 {
                    if j == i && (x, y, z) == (0, 0, 0) {
                        continue;
                    }
                    let o = [x as f64, y as f64, z as f64];
                    let l: [f64; 3] =
                        std::array::from_fn(|c| q[c] + (0..3).map(|k| o[k] * m[k][c]).sum::<f64>());
                    let n = sub3(l, p);
                    let d = (dot3(l, l) - dot3(p, p)) / 2.0;
                    planes.push((dot3(n, n), j as u32, [x, y, z], n, d));
                }
            }
        }
    }
    // nearest first: the cell shrinks fast
    planes.sort_by(|a, b| a.0.total_cmp(&b.0));
    for &(_, _, _, n, d) in &planes {
        clip3(&mut poly, n, d);
    }
    let vol = volume3(&poly, p);
    // a neighbour: its bisector holds a face of the final cell
    let mut nb = BTreeSet::new();
    for &(_, j, o, n, d) in &planes {
        for f in &poly {
            if f.len() >= 3 && f.iter().all(|x| (dot3(n, *x) - d).abs() < 1e-9) {
                let area = (1..f.len() - 1)
                    .map(|t| {
                        let c = cross3(sub3(f[t], f[0]), sub3(f[t + 1], f[0]));
                        dot3(c, c).sqrt() / 2.0
                    })
                    .sum::<f64>();
                if area > 1e-12 {
                    nb.insert((j, o));
                }
            }
        }
    }
    (vol, nb)
}

/// The same in 2D: polygon clipping (Sutherland–Hodgman).
fn clipped2(m: [[f64; 2]; 2], pts: &[[f64; 2]], i: usize) -> (f64, BTreeSet<(u32, [i8; 2])>) {
    let p = pts[i];
    let r = 3.0 * (m[0][0].hypot(m[0][1]) + m[1][0].hypot(m[1][1]));
    let mut poly = vec![
        [p[0] - r, p[1] - r],
        [p[0] + r, p[1] - r],
        [p[0] + r, p[1] + r],
        [p[0] - r, p[1] + r],
    ];
    let mut nb = BTreeSet::new();
    let mut planes = Vec::new();
    for (j, q) in pts.iter().enumerate() {
        for x in -2i8..=2 {
            for y in -2i8..=2 {
                if j == i && (x, y) == (0, 0) {
                    continue;
                }
                let l = [
                    q[0] + x as f64 * m[0][0] + y as f64 * m[1][0],
                    q[1] + x as f64 * m[0][1] + y as f64 * m[1][1],
                ];
                let n = [l[0] - p[0], l[1] - p[1]];
                let d = (l[0] * l[0] + l[1] * l[1] - p[0] * p[0] - p[1] * p[1]) / 2.0;
                planes.push((n[0] * n[0] + n[1] * n[1], j as u32, [x, y], n, d));
            }
        }
    }
    planes.sort_by(|a, b| a.0.total_cmp(&b.0));
    for &(_, _, _, n, d) in &planes {
        let mut out = Vec::new();
        for k in 0..poly.len() {
            let (a, b): ([f64; 2], [f64; 2]) = (poly[k], poly[(k + 1) % poly.len()]);
            let (da, db) = (n[0] * a[0] + n[1] * a[1] - d, n[0] * b[0] + n[1] * b[1] - d);
            if da <= 0.0 {
                out.push(a);
            }
            if (da < 0.0) != (db < 0.0) && da != 0.0 && db != 0.0 {
                let t = da / (da - db);
                out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        poly = out;
    }
    let mut area = 0.0;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        area += a[0] * b[1] - a[1] * b[0];
        // an edge on a bisector: that image is a neighbour
        for &(_, j, o, n, d) in &planes {
            let on = |x: [f64; 2]| (n[0] * x[0] + n[1] * x[1] - d).abs() < 1e-9;
            if on(a) && on(b) && (a[0] - b[0]).hypot(a[1] - b[1]) > 1e-12 {
                nb.insert((j, o));
            }
        }
    }
    (area / 2.0, nb)
}

/// (neighbour's input id, shift) of every face, as the clipping lists them.
fn faces_of<const D: usize>(c: &VoronoiCell<D>) -> BTreeSet<(u32, [i8; D])> {
    c.faces.iter().map(|f| (f.neighbor.0, f.shift)).collect()
}

fn check_pairs<const D: usize>(cells: &[VoronoiCell<D>]) {
    let by_point: std::collections::HashMap<InputId, &VoronoiCell<D>> =
        cells.iter().map(|c| (c.point, c)).collect();
    for c in cells {
        for f in &c.faces {
            let back = by_point[&f.neighbor]
                .faces
                .iter()
                .find(|g| g.neighbor == c.point && g.shift == f.shift.map(|x| -x))
                .unwrap_or_else(|| {
                    panic!(
                        "face {}→{} {:?} has no mirror",
                        c.point, f.neighbor, f.shift
                    )
                });
            // relative to the cell's size: a sliver face is tiny in both cells
            let scale = c.volume.powf((D as f64 - 1.0) / D as f64);
            assert!((back.area - f.area).abs() <= 1e-9 * scale);
        }
    }
}

fn uniform3(lattice: &Lattice<3>, n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = SplitMix::new(seed);
    (0..n)
        .map(|_| lattice.cartesian(&[r.unit(), r.unit(), r.unit()]))
        .collect()
}

fn uniform2(lattice: &Lattice<2>, n: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut r = SplitMix::new(seed);
    (0..n)
        .map(|_| lattice.cartesian(&[r.unit(), r.unit()]))
        .collect()
}

#[test]
fn cells_equal_clipped_cells_in_3d() {
    for lattice in [
        Lattice::cuboid([1.0, 1.0, 1.0]).unwrap(),
        Lattice::cuboid([1.0, 1.3, 0.8]).unwrap(),
        Lattice::new([[1.0, 0.0, 0.0], [0.3, 0.9, 0.0], [-0.2, 0.25, 1.1]]).unwrap(),
    ] {
        for (n, seed) in [(2, 1), (7, 2), (40, 3)] {
            let pts = uniform3(&lattice, n, seed);
            let tri = PeriodicDelaunay3::build(FlatTorus::new(lattice.clone()), &pts).unwrap();
            let m = lattice.vectors();
            let wrapped: Vec<[f64; 3]> = (0..n)
                .map(|i| tri.point(tri.vertex_of_input(InputId::new(i))))
                .collect();
            let cells = tri.voronoi_cells();
            let total: f64 = cells.iter().map(|c| c.volume).sum();
            assert!((total - lattice.volume()).abs() <= 1e-12 * lattice.volume());
            check_pairs(&cells);
            for c in &cells {
                let (vol, nb) = clipped3(m, &wrapped, c.point.index());
                assert!(
                    (c.volume - vol).abs() <= 1e-9 * vol,
                    "n={n} point {}: {} vs clipped {vol}",
                    c.point,
                    c.volume
                );
                assert_eq!(faces_of(c), nb, "n={n} point {}", c.point);
            }
        }
    }
}

#[test]
fn cells_equal_clipped_cells_in_2d() {
    let h = 3f64.sqrt() / 2.0;
    for lattice in [
        Lattice::cuboid([1.0, 1.0]).unwrap(),
        Lattice::cuboid([1.0, 2.5]).unwrap(),
        Lattice::new([[1.0, 0.0], [0.5, h]]).unwrap(),
        Lattice::new([[1.0, 0.0], [-0.35, 0.8]]).unwrap(),
    ] {
        for (n, seed) in [(1, 1), (3, 2), (60, 3)] {
            let pts = uniform2(&lattice, n, seed);
            let tri = PeriodicDelaunay2::build(FlatTorus::new(lattice.clone()), &pts).unwrap();
            let m = lattice.vectors();
            let wrapped: Vec<[f64; 2]> = (0..n)
                .map(|i| tri.point(tri.vertex_of_input(InputId::new(i))))
                .collect();
            let cells = tri.voronoi_cells();
            let total: f64 = cells.iter().map(|c| c.volume).sum();
            assert!((total - lattice.volume()).abs() <= 1e-12 * lattice.volume());
            check_pairs(&cells);
            for c in &cells {
                let (area, nb) = clipped2(m, &wrapped, c.point.index());
                assert!((c.volume - area).abs() <= 1e-9 * area);
                assert_eq!(faces_of(c), nb, "n={n} point {}", c.point);
                // the polygon is counter-clockwise and its edges are the faces
                let v = &c.vertices;
                let shoelace: f64 = (0..v.len())
                    .map(|k| {
                        let (a, b) = (v[k], v[(k + 1) % v.len()]);
                        a[0] * b[1] - a[1] * b[0]
                    })
                    .sum::<f64>()
                    / 2.0;
                assert!((shoelace - c.volume).abs() <= 1e-9 * c.volume);
                assert_eq!(c.faces.len(), v.len());
            }
        }
    }
}

#[test]
fn crystal_cells_are_equal_and_exact() {
    let sc = vec![[0.0, 0.0, 0.0]];
    let bcc = vec![[0.0, 0.0, 0.0], [0.5, 0.5, 0.5]];
    let fcc = vec![
        [0.0, 0.0, 0.0],
        [0.5, 0.5, 0.0],
        [0.5, 0.0, 0.5],
        [0.0, 0.5, 0.5],
    ];
    // (cube, 6 faces, 8 vertices), (truncated octahedron, 14, 24), (rhombic dodecahedron, 12, 14)
    for (basis, faces, vertices) in [(sc, 6, 8), (bcc, 14, 24), (fcc, 12, 14)] {
        // a binary lattice constant keeps the crystal exactly degenerate: the exact cells
        // have exactly the ideal faces; with 0.1 the rounded coordinates are the exact input,
        // and an FCC cell then has three more faces of area about 1e-17
        for a in [0.125, 0.1] {
            let pts = crystal(5, &basis, a);
            let side = 5.0 * a;
            let tri =
                PeriodicDelaunay3::build(FlatTorus3::cuboid([side; 3]).unwrap(), &pts).unwrap();
            let expect = side * side * side / pts.len() as f64;
            for c in tri.voronoi_cells() {
                assert!((c.volume - expect).abs() <= 1e-12 * expect, "{}", c.volume);
                let big = c.faces.iter().filter(|f| f.area > 1e-9 * a * a).count();
                assert_eq!(big, faces);
                if a == 0.125 {
                    assert_eq!((c.faces.len(), c.vertices.len()), (faces, vertices));
                }
            }
        }
    }
    // 2D: a square grid (squares) and a honeycomb (triangles)
    let mut sq = Vec::new();
    for i in 0..10 {
        for j in 0..10 {
            sq.push([i as f64 * 0.1, j as f64 * 0.1]);
        }
    }
    let tri = PeriodicDelaunay2::build(FlatTorus2::cuboid([1.0; 2]).unwrap(), &sq).unwrap();
    for c in tri.voronoi_cells() {
        assert!((c.volume - 0.01).abs() <= 1e-12 * 0.01);
        assert_eq!(c.faces.len(), 4);
    }
    let h = 3f64.sqrt() / 2.0;
    let hex = Lattice::new([[1.0, 0.0], [0.5, h]]).unwrap();
    let mut honey = Vec::new();
    for i in 0..8 {
        for j in 0..8 {
            for b in [1.0 / 3.0, 2.0 / 3.0] {
                honey.push(hex.cartesian(&[(i as f64 + b) / 8.0, (j as f64 + b) / 8.0]));
            }
        }
    }
    let tri = PeriodicDelaunay2::build(FlatTorus::new(hex.clone()), &honey).unwrap();
    let expect = hex.volume() / 128.0;
    for c in tri.voronoi_cells() {
        assert!((c.volume - expect).abs() <= 1e-12 * expect);
        // √3/2 is rounded: the hexagons are cocircular only up to rounding, and the exact
        // cells of the rounded points have slivers besides the 3 real faces
        assert_eq!(c.faces.iter().filter(|f| f.area > 1e-9).count(), 3);
    }
}

#[test]
fn volumes_sum_to_the_domain_and_duplicates_share_cells() {
    let lattice = Lattice::new([[1.0, 0.0, 0.0], [0.3, 0.9, 0.0], [-0.2, 0.25, 1.1]]).unwrap();
    let mut pts = uniform3(&lattice, 20000, 8);
    pts.push(pts[5]);
    let tri = PeriodicDelaunay3::build(FlatTorus::new(lattice.clone()), &pts).unwrap();
    let cells = tri.voronoi_cells();
    assert_eq!(cells.len(), 20000);
    let total: f64 = cells.iter().map(|c| c.volume).sum();
    assert!((total - lattice.volume()).abs() <= 1e-12 * lattice.volume());
    check_pairs(&cells);
    assert_eq!(
        tri.voronoi_cell(InputId(20000)),
        tri.voronoi_cell(InputId(5))
    );
    // the lean measures (summed by pieces, see `voronoi_measures.rs`) are the cells' own
    let measures = tri.voronoi_measures();
    assert_eq!(measures.len(), cells.len());
    for (m, c) in measures.iter().zip(&cells) {
        let whole = orbitri::CellMeasures::from(c);
        assert_eq!((m.point, m.faces), (whole.point, whole.faces));
        assert!((m.volume - whole.volume).abs() <= 1e-9 * whole.volume);
    }
    // the Delaunay edges: each once, lengths are the lifted distances, E = V + C
    let m = lattice.vectors();
    let edges = tri.delaunay_edges();
    assert_eq!(edges.len(), 20000 + tri.number_of_cells());
    for e in edges.iter().take(500) {
        let a = tri.point(tri.vertex_of_input(e.i));
        let b = tri.point(tri.vertex_of_input(e.j));
        let l: [f64; 3] = std::array::from_fn(|x| {
            b[x] + (0..3).map(|k| e.shift[k] as f64 * m[k][x]).sum::<f64>() - a[x]
        });
        let d = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
        assert!((d - e.length).abs() <= 1e-12 * d);
    }
    // each unordered pair once, and the pairs' areas are the faces' areas counted twice
    let pairs = tri.voronoi_neighbors();
    let faces: usize = cells.iter().map(|c| c.faces.len()).sum();
    assert_eq!(2 * pairs.len(), faces);
    let area: f64 = cells
        .iter()
        .flat_map(|c| c.faces.iter().map(|f| f.area))
        .sum();
    let pair_area: f64 = pairs.iter().map(|p| p.area).sum();
    assert!((area - 2.0 * pair_area).abs() <= 1e-9 * area);
    // centroids lie inside their cells: closer to their own point than to any neighbour
    for c in cells.iter().take(200) {
        let d0: f64 = (0..3)
            .map(|k| (c.centroid[k] - c.position[k]).powi(2))
            .sum();
        for f in &c.faces {
            let m = lattice.vectors();
            let q = tri.point(tri.vertex_of_input(f.neighbor));
            let l: [f64; 3] = std::array::from_fn(|x| {
                q[x] + (0..3).map(|k| f.shift[k] as f64 * m[k][x]).sum::<f64>()
            });
            let d1: f64 = (0..3).map(|k| (c.centroid[k] - l[k]).powi(2)).sum();
            assert!(d0 < d1);
        }
    }
}
