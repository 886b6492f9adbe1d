//! Every closed flat manifold against the independent universal-cover checker
//! (`common/universal.rs`, exact, sharing no code with the engine), against orbitri's own
//! torus triangulation of the unfolded point set, and through the Voronoi volumes.

mod common;
use std::collections::BTreeSet;
use std::ops::ControlFlow;

use common::geometry;
use common::universal::{check, Isometry, Manifold};
use orbitri::sort::SplitMix;
use orbitri::{
    BuildOptions, Copies, FlatManifold, FlatSpace, FlatTorus, InputId, Motion, OrbitSpace,
    PeriodicDelaunay, Triangulation,
};

fn random<const D: usize>(n: usize, seed: u64, scale: [f64; D]) -> Vec<[f64; D]> {
    let mut r = SplitMix::new(seed);
    (0..n)
        .map(|_| std::array::from_fn(|i| r.unit() * scale[i]))
        .collect()
}

fn isometry<const D: usize>(m: &FlatManifold<D>, g: Motion<D>) -> Isometry<D> {
    let (a, t) = m.isometry(g);
    Isometry { a, t }
}

/// Checks the triangulation with the universal-cover checker and the Voronoi volumes.
fn verify<const D: usize, const N: usize>(tri: &Triangulation<D, N, FlatManifold<D>>, what: &str)
where
    FlatManifold<D>: FlatSpace<D, N, Elem = Motion<D>>,
{
    tri.is_valid().unwrap_or_else(|e| panic!("{what}: {e}"));
    let m = tri.space();
    let volume: f64 = tri.voronoi_cells().iter().map(|c| c.volume).sum();
    assert!(
        (volume - m.volume()).abs() <= 1e-12 * m.volume(),
        "{what}: Voronoi volumes sum to {volume}, not {}",
        m.volume()
    );
    let turns = match m.name() {
        "tricosm" => 3,
        "hexacosm" => 6,
        _ => 0,
    };
    if turns > 0 {
        return verify_hexagonal(tri, turns, what);
    }
    let manifold = Manifold {
        generators: m
            .generators()
            .into_iter()
            .map(|(a, t)| Isometry { a, t })
            .collect(),
        volume: m.volume(),
        euler: 0,
        metric: [1.0; D],
    };
    let cells: Vec<([u32; N], [Isometry<D>; N])> = tri
        .cells(Copies::Unique)
        .iter()
        .map(|c| {
            (
                c.vertices.map(|i| tri.vertex_of_input(i).0),
                c.offsets.map(|g| isometry(m, g)),
            )
        })
        .collect();
    check(&manifold, &tri.points(), &cells).unwrap_or_else(|e| panic!("{what}: {e}"));
}

/// The checker in coordinates where a hexagonal screw space's group is rational: with
/// `u` the stored coordinates in the lattice `(a1, a2, a3)/q` (`q` = turns, `a2` at 60°
/// from `a1`), `y = (u1 + u2/2, u2/2, u3)` has the metric `diag(1, 3, (q·L3/L1)²)` up to
/// scale, the translations `q·(1, 0, 0)`, `q·(½, ½, 0)`, `q·(0, 0, 1)`, and the sixth of a
/// turn `(y1, y2) ↦ (y1/2 − 3y2/2, y1/2 + y2/2)`. Coset `c` is the screw to the power `c`
/// (the presentation in `platycosms.rs`); the test box has `L1 = 1`.
#[allow(clippy::type_complexity)]
fn hexagonal_frame<const D: usize, const N: usize>(
    tri: &Triangulation<D, N, FlatManifold<D>>,
    turns: usize,
) -> (
    Manifold<D>,
    Vec<[f64; D]>,
    Vec<([u32; N], [Isometry<D>; N])>,
)
where
    FlatManifold<D>: FlatSpace<D, N, Elem = Motion<D>>,
{
    assert_eq!((D, BOX[0], BOX[1]), (3, 1.0, 1.0));
    let q = turns as f64;
    let y = |u: &[f64; D]| -> [f64; D] {
        std::array::from_fn(|i| match i {
            0 => u[0] + u[1] / 2.0,
            1 => u[1] / 2.0,
            _ => u[2],
        })
    };
    let mul = |a: &[[f64; D]; D], b: &[[f64; D]; D]| -> [[f64; D]; D] {
        std::array::from_fn(|i| std::array::from_fn(|j| (0..D).map(|k| a[i][k] * b[k][j]).sum()))
    };
    let mut sixth = Isometry::<D>::identity().a;
    (sixth[0][0], sixth[0][1], sixth[1][0], sixth[1][1]) = (0.5, -1.5, 0.5, 0.5);
    let step = if turns == 3 {
        mul(&sixth, &sixth)
    } else {
        sixth
    };
    let mut powers = vec![Isometry::<D>::identity().a];
    for c in 1..turns {
        powers.push(mul(&powers[c - 1], &step));
    }
    let unit = |i: usize| -> [f64; D] { std::array::from_fn(|j| if i == j { q } else { 0.0 }) };
    let mut generators: Vec<Isometry<D>> =
        (0..D).map(|i| Isometry::translation(y(&unit(i)))).collect();
    generators.push(Isometry {
        a: step,
        t: std::array::from_fn(|i| if i == 2 { 1.0 } else { 0.0 }),
    });
    let manifold = Manifold {
        generators,
        volume: q * q / 2.0,
        euler: 0,
        metric: std::array::from_fn(|i| [1.0, 3.0, q * q * BOX[2] * BOX[2]][i]),
    };
    let element = |g: Motion<D>| {
        let t: [f64; D] = std::array::from_fn(|i| {
            let shift = if i == 2 { g.coset as f64 } else { 0.0 };
            shift + q * g.offset[i] as f64
        });
        Isometry {
            a: powers[g.coset as usize],
            t: y(&t),
        }
    };
    let cells: Vec<([u32; N], [Isometry<D>; N])> = tri
        .cells(Copies::Unique)
        .iter()
        .map(|c| {
            (
                c.vertices.map(|i| tri.vertex_of_input(i).0),
                c.offsets.map(element),
            )
        })
        .collect();
    let stored: Vec<[f64; D]> = tri.engine().points().iter().map(y).collect();
    (manifold, stored, cells)
}

fn verify_hexagonal<const D: usize, const N: usize>(
    tri: &Triangulation<D, N, FlatManifold<D>>,
    turns: usize,
    what: &str,
) where
    FlatManifold<D>: FlatSpace<D, N, Elem = Motion<D>>,
{
    let (manifold, stored, cells) = hexagonal_frame(tri, turns);
    check(&manifold, &stored, &cells).unwrap_or_else(|e| panic!("{what} (lattice frame): {e}"));
}

/// The check in the hexagonal frame is not vacuous: a cell with one vertex moved to
/// another image, or the same triangulation in the wrong metric, fails it.
#[test]
fn the_hexagonal_check_rejects_wrong_cells() {
    for (name, turns) in [("tricosm", 3), ("hexacosm", 6)] {
        let m = FlatManifold::platycosm(name, BOX).unwrap();
        let tri = Triangulation::build(m, &random(400, 21, BOX)).unwrap();
        assert!(tri.is_one_sheeted());
        let (manifold, stored, cells) = hexagonal_frame::<3, 4>(&tri, turns);
        check(&manifold, &stored, &cells).unwrap();
        let mut moved = cells.clone();
        moved[5].1[2].t[2] += turns as f64;
        assert!(check(&manifold, &stored, &moved).is_err(), "{name}");
        // a hexagonal lattice is no square one: the same cells are not Delaunay for the
        // metric diag(1, 1, ·) (the sixth of a turn is not even its isometry)
        let square = Manifold {
            metric: [1.0, 1.0, manifold.metric[2]],
            ..manifold
        };
        assert!(check(&square, &stored, &cells).is_err(), "{name}");
    }
}

/// Dyadic boxes, so that every group element is exact in doubles (the checker asks it).
const BOX: [f64; 3] = [1.0, 1.0, 1.25];

#[test]
fn klein_bottles_pass_the_universal_check() {
    for (a, b) in [(1.0, 1.0), (0.5, 1.25), (2.0, 0.75)] {
        for (n, seed) in [(1, 1), (4, 2), (12, 3), (150, 4), (1500, 5)] {
            let klein = FlatManifold::klein_bottle(a, b).unwrap();
            let tri = Triangulation::build(klein, &random(n, seed, [a, b])).unwrap();
            verify::<2, 3>(&tri, &format!("klein {a}×{b}, {n} points"));
        }
    }
}

#[test]
fn platycosms_pass_the_universal_check() {
    for name in FlatManifold::PLATYCOSMS {
        for (n, seed) in [(1, 1), (3, 2), (10, 3), (40, 4), (1500, 5)] {
            let m = FlatManifold::platycosm(name, BOX).unwrap();
            let tri = Triangulation::build(m, &random(n, seed, BOX)).unwrap();
            verify::<3, 4>(&tri, &format!("{name}, {n} points"));
        }
    }
}

#[test]
fn the_groups_are_what_their_names_say() {
    let expect = [
        ("torocosm", 1, true),
        ("dicosm", 2, true),
        ("tricosm", 3, true),
        ("tetracosm", 4, true),
        ("hexacosm", 6, true),
        ("didicosm", 4, true),
        ("first-amphicosm", 2, false),
        ("second-amphicosm", 2, false),
        ("first-amphidicosm", 4, false),
        ("second-amphidicosm", 4, false),
    ];
    for (name, index, orientable) in expect {
        let m = FlatManifold::platycosm(name, BOX).unwrap();
        assert_eq!(
            (m.index(), m.is_orientable()),
            (index, orientable),
            "{name}"
        );
        // a square or a 60° rhombus of side 1 across, 1.25 along the third axis
        let across = if matches!(name, "tricosm" | "hexacosm") {
            3f64.sqrt() / 2.0
        } else {
            1.0
        };
        assert!((m.volume() - 1.25 * across).abs() < 1e-15, "{name}");
        assert!(m.systole() > 0.0, "{name}: torsion-free");
    }
    let klein = FlatManifold::klein_bottle(1.0, 1.0).unwrap();
    assert_eq!((klein.index(), klein.is_orientable()), (2, false));
    assert!(FlatManifold::platycosm("tetracosm", [1.0, 2.0, 1.0]).is_err());
    assert!(FlatManifold::platycosm("tricosm-of-mars", BOX).is_err());
    let e = FlatManifold::platycosm("hexacosm", [1.0, 1.5, 1.0])
        .unwrap_err()
        .to_string();
    assert!(e.contains("L1 = L2"), "{e}");
    assert!(FlatManifold::platycosm("dicosm", [1.0, 0.0, 1.0]).is_err());
}

/// The cells of a manifold lifted to the torus of its translations, on the unfolded points
/// (each point's images under the coset representatives, wrapped), equal orbitri's torus
/// triangulation of those points.
fn unfolds_to_the_torus<const D: usize, const N: usize>(m: FlatManifold<D>, n: usize, seed: u64)
where
    FlatManifold<D>: FlatSpace<D, N, Elem = Motion<D>>,
    FlatTorus<D>: FlatSpace<D, N, Elem = [i8; D]>,
{
    let what = m.name();
    let lengths = std::array::from_fn(|i| BOX[i]);
    let tri = Triangulation::build(m.clone(), &random(n, seed, lengths)).unwrap();
    assert!(tri.is_one_sheeted(), "{what}");
    let rows = m.translations().vectors();
    let torus = FlatTorus::new(m.translations().clone());
    let k = m.index();
    let apply = |g: Motion<D>, p: [f64; D]| {
        let (a, t) = m.isometry(g);
        std::array::from_fn(|i| (0..D).map(|j| a[i][j] * p[j]).sum::<f64>() + t[i])
    };
    let coset = |c: usize| Motion {
        coset: c as u8,
        offset: [0; D],
    };
    let pts = tri.points();
    // cover point c·n + v: the image of point v under coset representative c
    let mut cover = Vec::new();
    for c in 0..k {
        for &p in &pts {
            cover.push(torus.lattice().wrap(apply(coset(c), p)).unwrap().0);
        }
    }
    let unfolded = PeriodicDelaunay::<D, N>::build(torus.clone(), &cover).unwrap();
    // (the cover's input ids, as numbers)
    let canon = |mut cell: Vec<(u32, [i8; D])>| {
        FlatSpace::<D, N>::canonical_face(&torus, &mut cell);
        cell
    };
    let expected: BTreeSet<Vec<(u32, [i8; D])>> = unfolded
        .cells(Copies::Unique)
        .iter()
        .map(|c| canon(c.vertices.iter().map(|v| v.0).zip(c.offsets).collect()))
        .collect();
    let inv = m.translations().clone();
    let mut lifted = BTreeSet::new();
    for c in tri.cells(Copies::Unique) {
        for r in 0..k {
            let cell = (0..N)
                .map(|j| {
                    let v = tri.vertex_of_input(c.vertices[j]);
                    let g = OrbitSpace::<N>::compose(&m, coset(r), c.offsets[j]);
                    let x = apply(g, pts[v.index()]);
                    let u = g.coset as u32 * pts.len() as u32 + v.0;
                    let d: [f64; D] = std::array::from_fn(|i| x[i] - cover[u as usize][i]);
                    (u, inv.fractional(&d).map(|f| f.round() as i8))
                })
                .collect();
            lifted.insert(canon(cell));
        }
    }
    let _ = rows;
    assert_eq!(lifted.len(), expected.len(), "{what}");
    assert!(lifted == expected, "{what}: the unfolded cells differ");
    // each point's Voronoi cell is its cell in the unfolded torus, as are its images'
    let here = tri.voronoi_cells();
    let there = unfolded.voronoi_cells();
    let mut at_vertex = vec![usize::MAX; unfolded.number_of_vertices()];
    for (i, x) in there.iter().enumerate() {
        at_vertex[unfolded.vertex_of_input(x.point).index()] = i;
    }
    for cell in &here {
        let v = tri.vertex_of_input(cell.point).index();
        for c in 0..k {
            let u = InputId::new(c * pts.len() + v);
            let w = &there[at_vertex[unfolded.vertex_of_input(u).index()]];
            assert!(
                (cell.volume - w.volume).abs() <= 1e-12 * cell.volume,
                "{what}: point {v}: {} here, {} in the cover",
                cell.volume,
                w.volume
            );
            assert_eq!(cell.faces.len(), w.faces.len(), "{what}: point {v}");
        }
    }
}

#[test]
fn manifolds_unfold_to_their_torus_triangulation() {
    unfolds_to_the_torus::<2, 3>(FlatManifold::klein_bottle(1.0, 1.0).unwrap(), 300, 7);
    for name in FlatManifold::PLATYCOSMS {
        unfolds_to_the_torus::<3, 4>(FlatManifold::platycosm(name, BOX).unwrap(), 1500, 8);
    }
}

/// A cubic crystal (every cell decided by the symbolic perturbation) and random points in
/// two orders give the same triangulation in every platycosm.
#[test]
fn crystals_and_orders_give_one_triangulation() {
    let grid: Vec<[f64; 3]> = (0..8 * 8 * 10)
        .map(|i| [i % 8, i / 8 % 8, i / 64].map(|x| (x as f64 + 0.5) * 0.125))
        .collect();
    for name in FlatManifold::PLATYCOSMS {
        let m = FlatManifold::platycosm(name, BOX).unwrap();
        // the hexagonal spaces get the same grid in their own lattice's coordinates: a
        // hexagonal crystal
        let crystal = if matches!(name, "tricosm" | "hexacosm") {
            let t = m.translations().clone();
            let k = m.index() as f64;
            grid.iter()
                .map(|g| t.cartesian(&[g[0], g[1], g[2] / 1.25 / k]))
                .collect()
        } else {
            grid.clone()
        };
        for pts in [crystal, random(1500, 9, BOX)] {
            let m = m.clone();
            // from the dummy points, as large inputs are built (the covering path is
            // exercised by the smaller sets above)
            let opts = BuildOptions {
                dummy_threshold: 500,
                ..BuildOptions::default()
            };
            let build = |m: FlatManifold<3>, pts: &[[f64; 3]]| {
                Triangulation::<3, 4, _>::build_with(m, pts, opts, |_| ControlFlow::Continue(()))
                    .unwrap()
            };
            let a = build(m.clone(), &pts);
            assert!(a.used_dummy_points(), "{name}");
            a.is_valid().unwrap_or_else(|e| panic!("{name}: {e}"));
            let mut rev = pts.clone();
            rev.reverse();
            let b = build(m, &rev);
            b.is_valid().unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(a.is_one_sheeted() && b.is_one_sheeted(), "{name}");
            assert!(
                geometry(&a) == geometry(&b),
                "{name}: the input order changed the cells"
            );
            let volume: f64 = a.voronoi_cells().iter().map(|c| c.volume).sum();
            assert!(
                (volume - a.space().volume()).abs() < 1e-12,
                "{name}: {volume}"
            );
        }
    }
}

/// Images of the points under the generators are the same points of the manifold: each is
/// a duplicate of its first occurrence, whatever the element (dyadic coordinates keep the
/// images exact).
#[test]
fn images_under_the_group_are_duplicates() {
    let dyadic: Vec<[f64; 3]> = random(60, 13, BOX)
        .iter()
        .map(|p| p.map(|x| (x * 1024.0).floor() / 1024.0))
        .collect();
    for name in FlatManifold::PLATYCOSMS {
        let m = FlatManifold::platycosm(name, BOX).unwrap();
        // in the hexagonal spaces, points of dyadic lattice coordinates: their images,
        // computed in doubles, round back to the same lattice coordinates
        let pts: Vec<[f64; 3]> = if matches!(name, "tricosm" | "hexacosm") {
            let t = m.translations().clone();
            dyadic
                .iter()
                .map(|p| t.cartesian(&[p[0], p[1], p[2] / 8.0]))
                .collect()
        } else {
            dyadic.clone()
        };
        let mut all = pts.clone();
        for (a, t) in m.generators() {
            all.extend(pts.iter().map(|p| {
                std::array::from_fn(|i| (0..3).map(|j| a[i][j] * p[j]).sum::<f64>() + t[i])
            }));
        }
        let tri = Triangulation::<3, 4, _>::build(m.clone(), &all).unwrap();
        tri.is_valid().unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(tri.number_of_vertices(), pts.len(), "{name}");
        assert_eq!(tri.duplicates(), all.len() - pts.len(), "{name}");
        let first = tri.first_occurrences();
        assert!(
            (0..all.len()).all(|i| first[i].index() == i % pts.len()),
            "{name}"
        );
    }
}
