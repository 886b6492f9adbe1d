//! The 2D flat torus on the same engine: triangulations equal CGAL's P2T2 (canonical triangle
//! lists of the anchor harness, cocircular square grids included), pass an independent
//! brute-force check on squares, rectangles, hexagonal and oblique lattices at every level of
//! the covering ladder, and do not depend on the insertion order.

use std::collections::HashMap;

use orbitri::sort::SplitMix;
use orbitri::space::{FlatTorus, Ladder, Lattice};
use orbitri::{
    BuildOptions, CellView, Copies, Engine, FlatTorus2, InputId, Inserted, OrbitSpace,
    PeriodicDelaunay2, PointId,
};

fn data(name: &str) -> String {
    std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
    .unwrap()
}

fn numbers<T: std::str::FromStr>(line: &str) -> Vec<T>
where
    T::Err: std::fmt::Debug,
{
    line.split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect()
}

fn lift(p: [f64; 2], o: [i8; 2], m: &[[f64; 2]; 2]) -> [f64; 2] {
    [
        p[0] + o[0] as f64 * m[0][0] + o[1] as f64 * m[1][0],
        p[1] + o[0] as f64 * m[0][1] + o[1] as f64 * m[1][1],
    ]
}

/// Brute-force check, sharing nothing with the library's geometry: counter-clockwise
/// triangles whose areas sum to sheets × domain area, every edge shared by exactly two
/// triangles per sheet, Euler characteristic 0, and every circumcircle empty of all periodic
/// copies of all points (points on the circle allowed, relative tolerance 1e-9).
fn brute_force(tri: &PeriodicDelaunay2) {
    let m = tri.space().lattice().vectors();
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let inv = [
        [m[1][1] / det, -m[0][1] / det],
        [-m[1][0] / det, m[0][0] / det],
    ];
    let area_dom = det.abs();
    let sheets = tri.sheets();
    let cells = tri.cells(Copies::Stored);
    let point = |i: InputId| tri.point(tri.vertex_of_input(i));
    let mut total = 0.0;
    let mut edges: HashMap<Vec<(InputId, [i8; 2])>, usize> = HashMap::new();
    for c in &cells {
        let p: [[f64; 2]; 3] =
            std::array::from_fn(|i| lift(point(c.vertices[i]), c.offsets[i], &m));
        let (ax, ay, bx, by) = (
            p[1][0] - p[0][0],
            p[1][1] - p[0][1],
            p[2][0] - p[0][0],
            p[2][1] - p[0][1],
        );
        let d = ax * by - ay * bx;
        assert!(d > 0.0, "triangle {c:?} is not counter-clockwise");
        total += d / 2.0;
        let (la, lb) = (ax * ax + ay * ay, bx * bx + by * by);
        let z = [
            p[0][0] + (by * la - ay * lb) / (2.0 * d),
            p[0][1] + (ax * lb - bx * la) / (2.0 * d),
        ];
        let r2 = (p[0][0] - z[0]).powi(2) + (p[0][1] - z[1]).powi(2);
        let r = r2.sqrt();
        let fz = [
            z[0] * inv[0][0] + z[1] * inv[1][0],
            z[0] * inv[0][1] + z[1] * inv[1][1],
        ];
        let span: [f64; 2] = std::array::from_fn(|j| r * inv[0][j].hypot(inv[1][j]) * 1.001);
        for (v, &q) in tri.points().iter().enumerate() {
            let i = tri.input_of_vertex(PointId::new(v));
            let fq = [
                q[0] * inv[0][0] + q[1] * inv[1][0],
                q[0] * inv[0][1] + q[1] * inv[1][1],
            ];
            let lo: [i32; 2] = std::array::from_fn(|j| (fz[j] - fq[j] - span[j]).floor() as i32);
            let hi: [i32; 2] = std::array::from_fn(|j| (fz[j] - fq[j] + span[j]).ceil() as i32);
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    let o = [x as i8, y as i8];
                    if (0..3).any(|k| c.vertices[k] == i && c.offsets[k] == o) {
                        continue;
                    }
                    let l = lift(q, o, &m);
                    let d2 = (l[0] - z[0]).powi(2) + (l[1] - z[1]).powi(2);
                    assert!(
                        d2 >= r2 * (1.0 - 1e-9),
                        "point {i} at {o:?} is inside the circle of {c:?}"
                    );
                }
            }
        }
        for skip in 0..3 {
            let mut f: Vec<(InputId, [i8; 2])> = (0..3)
                .filter(|&k| k != skip)
                .map(|k| (c.vertices[k], c.offsets[k]))
                .collect();
            for k in 0..2 {
                let mn = f.iter().map(|x| x.1[k]).min().unwrap();
                f.iter_mut().for_each(|x| x.1[k] -= mn);
            }
            f.sort_unstable();
            *edges.entry(f).or_default() += 1;
        }
    }
    assert!(
        (total - area_dom * sheets as f64).abs() <= 1e-9 * area_dom * sheets as f64,
        "areas sum to {total}, expected {sheets} × {area_dom}"
    );
    // an edge orbit of the quotient appears once per sheet, in two triangles each
    assert!(edges.values().all(|&n| n == 2 * sheets));
    // Euler characteristic of the torus (and of each covering torus): V − E + F = 0
    let v = tri.number_of_vertices() * sheets;
    assert_eq!(
        v as i64 - (edges.len() * sheets) as i64 + cells.len() as i64,
        0
    );
}

/// Canonical triangles: (input id, offset) pairs sorted, offsets translated to
/// componentwise minimum 0, lines sorted (the anchor's dump format).
fn canonical(cells: &[CellView<2, 3>]) -> Vec<[i64; 9]> {
    let mut out: Vec<[i64; 9]> = cells
        .iter()
        .map(|c| {
            let mut pairs: Vec<(InputId, [i8; 2])> =
                (0..3).map(|i| (c.vertices[i], c.offsets[i])).collect();
            pairs.sort_unstable();
            for k in 0..2 {
                let m = pairs.iter().map(|p| p.1[k]).min().unwrap();
                pairs.iter_mut().for_each(|p| p.1[k] -= m);
            }
            let mut line = [0i64; 9];
            for (i, (v, o)) in pairs.iter().enumerate() {
                line[i] = i64::from(v.0);
                line[3 + 2 * i] = o[0] as i64;
                line[4 + 2 * i] = o[1] as i64;
            }
            line
        })
        .collect();
    out.sort_unstable();
    out
}

fn uniform(lattice: &Lattice<2>, n: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut r = SplitMix::new(seed);
    (0..n)
        .map(|_| lattice.cartesian(&[r.unit(), r.unit()]))
        .collect()
}

fn lattices() -> Vec<(&'static str, Lattice<2>)> {
    let h = 3f64.sqrt() / 2.0;
    vec![
        ("square", Lattice::cuboid([1.0, 1.0]).unwrap()),
        ("rectangle", Lattice::cuboid([1.0, 2.5]).unwrap()),
        ("hexagonal", Lattice::new([[1.0, 0.0], [0.5, h]]).unwrap()),
        ("oblique", Lattice::new([[1.0, 0.0], [-0.35, 0.8]]).unwrap()),
    ]
}

#[test]
fn the_triangulations_equal_cgal_p2t2() {
    for name in ["rand2_n30_s1", "rand2_n1000_s1", "sq10_int", "sq10_unit"] {
        let text = data(&format!("{name}.txt"));
        let mut lines = text.lines().filter(|l| !l.trim().is_empty());
        let per: Vec<f64> = numbers(lines.next().unwrap());
        let pts: Vec<[f64; 2]> = lines.map(numbers::<f64>).map(|v| [v[0], v[1]]).collect();
        let torus = FlatTorus2::cuboid([per[0], per[1]]).unwrap();
        // bulk (dummy start for 1000 points) and one point at a time in file order
        let bulk = PeriodicDelaunay2::build(torus.clone(), &pts).unwrap();
        let mut inc = PeriodicDelaunay2::new(torus);
        for p in &pts {
            inc.insert(*p).unwrap();
        }
        inc.try_one_sheet();
        let dump = data(&format!("{name}.dump2"));
        let mut dl = dump.lines();
        let header: Vec<usize> = numbers(dl.next().unwrap());
        let expected: Vec<[i64; 9]> = dl.map(|l| numbers::<i64>(l).try_into().unwrap()).collect();
        for tri in [&bulk, &inc] {
            tri.is_valid().unwrap();
            assert_eq!(
                (
                    tri.sheets(),
                    tri.number_of_vertices(),
                    tri.number_of_cells()
                ),
                (header[0], header[1], header[2]),
                "{name}"
            );
            assert!(
                canonical(&tri.cells(Copies::Stored)) == expected,
                "{name}: triangles differ from CGAL's"
            );
        }
        assert_eq!(bulk.used_dummy_points(), pts.len() >= 1000);
    }
}

/// Removal against CGAL: the even inputs of `rand2_n1000_s1` removed leave CGAL's
/// triangulation of the odd ones (`rand2_n1000_s1_odd`: its point `k` is our input `2k + 1`).
#[test]
fn removal_equals_cgal_on_the_survivors() {
    let text = data("rand2_n1000_s1.txt");
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let per: Vec<f64> = numbers(lines.next().unwrap());
    let pts: Vec<[f64; 2]> = lines.map(numbers::<f64>).map(|v| [v[0], v[1]]).collect();
    let torus = FlatTorus2::cuboid([per[0], per[1]]).unwrap();
    let mut tri = PeriodicDelaunay2::build(torus, &pts).unwrap();
    for i in (0..pts.len()).step_by(2) {
        tri.remove(orbitri::InputId::new(i)).unwrap();
    }
    tri.is_valid().unwrap();
    let dump = data("rand2_n1000_s1_odd.dump2");
    let mut dl = dump.lines();
    let header: Vec<usize> = numbers(dl.next().unwrap());
    let expected: Vec<[i64; 9]> = dl.map(|l| numbers::<i64>(l).try_into().unwrap()).collect();
    assert_eq!(
        (
            tri.sheets(),
            tri.number_of_vertices(),
            tri.number_of_cells()
        ),
        (header[0], header[1], header[2])
    );
    let mut cells = tri.cells(Copies::Stored);
    for cell in cells.iter_mut() {
        cell.vertices = cell.vertices.map(|i| orbitri::InputId((i.0 - 1) / 2));
    }
    assert!(
        canonical(&cells) == expected,
        "triangles differ from CGAL's"
    );
}

#[test]
fn random_sets_on_every_lattice_pass_the_brute_force_check() {
    for (name, lattice) in lattices() {
        for (n, seed) in [(1, 1), (2, 2), (5, 3), (40, 4), (400, 5), (3000, 6)] {
            let pts = uniform(&lattice, n, seed);
            let tri = PeriodicDelaunay2::build(FlatTorus::new(lattice.clone()), &pts).unwrap();
            tri.is_valid()
                .unwrap_or_else(|e| panic!("{name} n={n}: {e}"));
            assert_eq!(tri.number_of_vertices(), n, "{name} n={n}");
            brute_force(&tri);
            if n <= 3 {
                // 3 points have 9 edges in the torus: no simplicial complex there
                assert!(tri.sheets() > 1, "{name} n={n}");
            }
            if n >= 400 {
                assert_eq!(tri.sheets(), 1, "{name} n={n}");
                // exactly 2 triangles per point on a torus
                assert_eq!(tri.number_of_cells(), 2 * n);
            }
        }
    }
}

#[test]
fn every_level_of_the_ladder_is_a_delaunay_triangulation() {
    for (name, lattice) in lattices() {
        let torus = FlatTorus::new(lattice.clone());
        let sheets: Vec<usize> = (0..torus.levels()).map(|k| torus.sheets(k)).collect();
        let mut tri = PeriodicDelaunay2::new(torus);
        let mut seen = vec![false; sheets.len()];
        for p in uniform(&lattice, 120, 7) {
            tri.insert(p).unwrap();
            tri.is_valid().unwrap_or_else(|e| panic!("{name}: {e}"));
            brute_force(&tri);
            let level = tri.engine().level();
            assert_eq!(tri.sheets(), sheets[level]);
            seen[level] = true;
            // never back up the ladder while points are added
            assert!(seen[level + 1..].iter().all(|s| !s), "{name}");
        }
        assert!(tri.is_one_sheeted(), "{name}");
        assert!(seen.iter().filter(|&&s| s).count() >= 3, "{name}: {seen:?}");
    }
}

#[test]
fn the_ladder_reaches_one_sheet_with_the_same_points_as_the_9_sheeted_covering() {
    // the last step's criterion is the 9-sheeted covering's; the ladder just inserts fewer
    // copies before it
    for (_, lattice) in lattices() {
        for seed in 1..=10 {
            let pts = uniform(&lattice, 400, seed);
            let mut reached = Vec::new();
            for kind in [Ladder::Halving, Ladder::Grid] {
                let mut e = Engine::new(FlatTorus::with_ladder(lattice.clone(), kind));
                let mut copies = 0;
                let n = pts
                    .iter()
                    .position(|p| {
                        copies += e.sheets();
                        e.insert(*p);
                        e.is_one_sheeted()
                    })
                    .expect("400 points reach the torus");
                reached.push((n, copies));
            }
            assert_eq!(reached[0].0, reached[1].0);
            assert!(reached[0].1 < reached[1].1, "{reached:?}");
        }
    }
}

#[test]
fn the_square_ladder_is_16_8_4_2_1_and_the_grid_is_9() {
    let torus = FlatTorus2::cuboid([1.0, 1.0]).unwrap();
    let sheets: Vec<usize> = (0..torus.levels()).map(|k| torus.sheets(k)).collect();
    assert_eq!(sheets, [16, 8, 4, 2, 1]);
    // the groups of Bogdanov–Teillaud–Vegter: even length, then 2Z², then ⟨(2,2),(2,−2)⟩
    let rows: Vec<[[i32; 2]; 2]> = torus.ladder().iter().map(|l| l.sub.rows()).collect();
    assert_eq!(rows[3], [[1, 1], [0, 2]]);
    assert_eq!(rows[2], [[2, 0], [0, 2]]);
    assert_eq!(rows[1], [[2, 2], [0, 4]]);
    let systoles: Vec<f64> = torus.ladder().iter().map(|l| l.systole).collect();
    let s2 = 2f64.sqrt();
    for (a, b) in systoles.iter().zip([4.0, 2.0 * s2, 2.0, s2, 1.0]) {
        assert!((a - b).abs() < 1e-12, "{systoles:?}");
    }
    let grid = FlatTorus::with_ladder(torus.lattice().clone(), Ladder::Grid);
    assert_eq!((grid.levels(), grid.sheets(0)), (2, 9));
}

#[test]
fn cocircular_grids_triangulate_exactly() {
    // square grid with an inexact spacing: 4 cocircular points everywhere
    let mut sq = Vec::new();
    for i in 0..12 {
        for j in 0..12 {
            sq.push([i as f64 * 0.1, j as f64 * 0.1]);
        }
    }
    // honeycomb in its hexagonal cell: 6 cocircular points around every hexagon
    let h = 3f64.sqrt() / 2.0;
    let hex = Lattice::new([[0.9, 0.0], [0.45, 0.9 * h]]).unwrap();
    let mut honey = Vec::new();
    for i in 0..9 {
        for j in 0..9 {
            for b in [[1.0 / 3.0, 1.0 / 3.0], [2.0 / 3.0, 2.0 / 3.0]] {
                honey.push(hex.cartesian(&[(i as f64 + b[0]) / 9.0, (j as f64 + b[1]) / 9.0]));
            }
        }
    }
    for (torus, pts) in [
        (FlatTorus2::cuboid([1.2, 1.2]).unwrap(), sq),
        (FlatTorus::new(hex), honey),
    ] {
        let n = pts.len();
        let tri = PeriodicDelaunay2::build(torus.clone(), &pts).unwrap();
        tri.is_valid().unwrap();
        brute_force(&tri);
        assert_eq!((tri.sheets(), tri.number_of_cells()), (1, 2 * n));
        // the same triangles for every insertion order: the perturbation is symbolic
        let mut rev = PeriodicDelaunay2::new(torus);
        for p in pts.iter().rev() {
            rev.insert(*p).unwrap();
        }
        // reversed input ids map back to n − 1 − id
        let back: Vec<CellView<2, 3>> = rev
            .cells(Copies::Unique)
            .into_iter()
            .map(|c| CellView {
                vertices: c.vertices.map(|v| InputId(n as u32 - 1 - v.0)),
                offsets: c.offsets,
            })
            .collect();
        assert!(
            canonical(&tri.cells(Copies::Unique)) == canonical(&back),
            "the triangles depend on the insertion order"
        );
    }
}

#[test]
fn insertion_order_and_construction_path_do_not_matter() {
    for (name, lattice) in lattices() {
        let pts = uniform(&lattice, 1500, 9);
        let torus = FlatTorus::new(lattice.clone());
        let reference = canonical(
            &PeriodicDelaunay2::build(torus.clone(), &pts)
                .unwrap()
                .cells(Copies::Unique),
        );
        for (seed, threshold, sort) in [
            (1, usize::MAX, false),
            (2, 100, true),
            (3, usize::MAX, true),
        ] {
            let opts = BuildOptions {
                dummy_threshold: threshold,
                seed,
                spatial_sort: sort,
                ..BuildOptions::default()
            };
            let tri = PeriodicDelaunay2::build_with(torus.clone(), &pts, opts, |_| {
                std::ops::ControlFlow::Continue(())
            })
            .unwrap();
            assert_eq!(
                canonical(&tri.cells(Copies::Unique)),
                reference,
                "{name} {seed}"
            );
        }
        let mut r = SplitMix::new(4);
        let mut shuffled: Vec<usize> = (0..pts.len()).collect();
        for i in (1..shuffled.len()).rev() {
            shuffled.swap(i, r.below(i + 1));
        }
        let mut inc = PeriodicDelaunay2::new(torus);
        let mut order = Vec::new();
        for &i in &shuffled {
            inc.insert(pts[i]).unwrap();
            order.push(InputId::new(i));
        }
        // incremental input ids follow the shuffled order: map them back
        let back: Vec<CellView<2, 3>> = inc
            .cells(Copies::Unique)
            .into_iter()
            .map(|c| CellView {
                vertices: c.vertices.map(|v| order[v.index()]),
                offsets: c.offsets,
            })
            .collect();
        assert!(canonical(&back) == reference, "{name} incremental");
    }
}

#[test]
fn duplicates_and_wrapping_lose_nothing_in_2d() {
    let torus = FlatTorus2::cuboid([2.0, 1.0]).unwrap();
    let pts = vec![
        [0.5, 0.5],
        [2.5, 1.5], // the first point again, a period away
        [1.5, 0.25],
        [-0.5, 0.25], // the third point again
        [1.0, 0.75],
        [0.5, 0.5],
    ];
    let mut all = pts.clone();
    all.extend(uniform(torus.lattice(), 200, 3));
    let tri = PeriodicDelaunay2::build(torus.clone(), &all).unwrap();
    assert_eq!(tri.duplicates(), 3);
    assert_eq!(tri.wrapped(), 2);
    assert_eq!(tri.number_of_vertices(), all.len() - 3);
    let firsts = tri.first_occurrences();
    assert_eq!(&firsts[..6], &[0, 0, 2, 2, 4, 0].map(InputId));
    brute_force(&tri);
    let mut inc = PeriodicDelaunay2::new(torus);
    assert_eq!(inc.insert([0.5, 0.5]).unwrap(), Inserted::New(PointId(0)));
    assert_eq!(
        inc.insert([2.5, -0.5]).unwrap(),
        Inserted::Duplicate(PointId(0))
    );
}

#[test]
fn access_api_in_2d() {
    let lattice = Lattice::new([[1.0, 0.0], [0.5, 0.9]]).unwrap();
    let pts = uniform(&lattice, 300, 12);
    let tri = PeriodicDelaunay2::build(FlatTorus::new(lattice), &pts).unwrap();
    let edges = tri.edges();
    // Euler: V − E + F = 0, and each vertex's neighbour list matches the edges at it
    assert_eq!(300 + tri.number_of_cells(), edges.len());
    let degree: usize = (0..300)
        .map(|i| tri.vertex_neighbors(InputId(i)).len())
        .sum();
    assert_eq!(degree, 2 * edges.len());
    assert_eq!(tri.facets().len(), edges.len());
    // the located triangle contains the query (barycentric test, independent)
    let m = tri.space().lattice().vectors();
    for q in [[0.3, 0.2], [0.99, 0.01], [1.2, 0.85]] {
        let (c, o) = tri.locate(q).unwrap();
        let w = tri.space().lattice().wrap(q).unwrap().0;
        let z = lift(w, o, &m);
        let p: Vec<[f64; 2]> = (0..3)
            .map(|i| {
                lift(
                    tri.point(tri.vertex_of_input(c.vertices[i])),
                    c.offsets[i],
                    &m,
                )
            })
            .collect();
        for i in 0..3 {
            let (a, b) = (p[i], p[(i + 1) % 3]);
            let side = (b[0] - a[0]) * (z[1] - a[1]) - (b[1] - a[1]) * (z[0] - a[0]);
            assert!(side >= -1e-12, "{q:?} outside the located triangle");
        }
    }
}
