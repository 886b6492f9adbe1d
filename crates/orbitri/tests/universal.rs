//! The universal-cover checker (`common/universal.rs`): it accepts the library's tori, rejects
//! mutated triangulations with the right message, enumerates a Klein bottle group correctly
//! and accepts a Klein bottle triangulation found here by brute force.

mod common;
use std::collections::HashSet;

use common::universal::{check, Element, Group, Isometry, Manifold};
use num_rational::BigRational;
use orbitri::sort::SplitMix;
use orbitri::triangulation::Torus;
use orbitri::{Copies, FlatTorus, FlatTorus2, FlatTorus3, PeriodicDelaunay};

type Cell<const D: usize, const N: usize> = ([u32; N], [Isometry<D>; N]);

/// `Σ o_k·row_k`, asserted exact in doubles.
fn translation<const D: usize>(rows: &[[f64; D]; D], o: &[i8; D]) -> [f64; D] {
    let q = |x: f64| BigRational::from_float(x).unwrap();
    std::array::from_fn(|i| {
        let t = (0..D).map(|k| o[k] as f64 * rows[k][i]).sum::<f64>();
        let exact: BigRational = (0..D).map(|k| q(o[k] as f64) * q(rows[k][i])).sum();
        assert_eq!(
            q(t),
            exact,
            "offset {o:?}: translation not exact in doubles"
        );
        t
    })
}

/// A torus triangulation as checker data: points by vertex, one cell per orbit.
fn data<const D: usize, const N: usize>(
    tri: &PeriodicDelaunay<D, N>,
) -> (Manifold<D>, Vec<[f64; D]>, Vec<Cell<D, N>>)
where
    FlatTorus<D>: Torus<D, N>,
{
    let rows = tri.space().lattice().vectors();
    let cells = tri
        .cells(Copies::Unique)
        .iter()
        .map(|c| {
            (
                c.vertices.map(|i| tri.vertex_of_input(i).0),
                std::array::from_fn(|k| Isometry::translation(translation(&rows, &c.offsets[k]))),
            )
        })
        .collect();
    (Manifold::torus(rows), tri.points(), cells)
}

fn random<const D: usize>(n: usize, seed: u64, scale: [f64; D]) -> Vec<[f64; D]> {
    let mut r = SplitMix::new(seed);
    (0..n)
        .map(|_| std::array::from_fn(|i| r.unit() * scale[i]))
        .collect()
}

fn timed<T>(what: &str, f: impl FnOnce() -> T) -> T {
    let t = std::time::Instant::now();
    let x = f();
    eprintln!("{what}: {:.3} s", t.elapsed().as_secs_f64());
    x
}

const TRICLINIC2: [[f64; 2]; 2] = [[1.0, 0.0], [0.5, 0.75]];
const TRICLINIC3: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.25, 1.0, 0.0], [-0.5, 0.375, 0.75]];

fn torus2(n: usize, seed: u64) -> (Manifold<2>, Vec<[f64; 2]>, Vec<Cell<2, 3>>) {
    let space = FlatTorus2::triclinic(TRICLINIC2).unwrap();
    // fractional coordinates to Cartesian: inside the domain
    let pts: Vec<[f64; 2]> = random(n, seed, [1.0, 1.0])
        .iter()
        .map(|f| [f[0] + f[1] * 0.5, f[1] * 0.75])
        .collect();
    data(&PeriodicDelaunay::build(space, &pts).unwrap())
}

#[test]
fn accepts_library_tori_3d() {
    // a cuboid's translations are exact for any lengths (offsets are small)
    for (n, scale) in [(500, [1.0, 1.3, 0.9]), (300, [1.0, 1.5, 0.75])] {
        let space = FlatTorus3::cuboid(scale).unwrap();
        let tri = PeriodicDelaunay::build(space, &random(n, 7, scale)).unwrap();
        let (m, p, c) = data(&tri);
        timed(&format!("3D cuboid {scale:?}, {n} points"), || {
            check(&m, &p, &c)
        })
        .unwrap();
    }
    let space = FlatTorus3::triclinic(TRICLINIC3).unwrap();
    let frac = random(300, 8, [1.0; 3]);
    let pts: Vec<[f64; 3]> = frac
        .iter()
        .map(|f| std::array::from_fn(|i| (0..3).map(|k| f[k] * TRICLINIC3[k][i]).sum()))
        .collect();
    let (m, p, c) = data(&PeriodicDelaunay::build(space, &pts).unwrap());
    timed("3D triclinic, 300 points", || check(&m, &p, &c)).unwrap();
}

#[test]
fn accepts_library_tori_2d() {
    for n in [500, 2000] {
        let (m, p, c) = torus2(n, 11);
        timed(&format!("2D triclinic, {n} points"), || check(&m, &p, &c)).unwrap();
    }
}

/// Tiny sets: the triangulations live in coverings, the quotient has loops and multiple edges.
#[test]
fn accepts_tiny_library_tori() {
    for n in 1..=8 {
        let (m, p, c) = torus2(n, 100 + n as u64);
        check(&m, &p, &c).unwrap_or_else(|e| panic!("2D, {n} points: {e}"));
        let space = FlatTorus3::cuboid([1.0, 1.5, 0.75]).unwrap();
        let tri = PeriodicDelaunay::build(space, &random(n, 200 + n as u64, [1.0, 1.5, 0.75]));
        let (m, p, c) = data(&tri.unwrap());
        check(&m, &p, &c).unwrap_or_else(|e| panic!("3D, {n} points: {e}"));
    }
}

fn expect_err<const D: usize, const N: usize>(
    m: &Manifold<D>,
    p: &[[f64; D]],
    c: &[Cell<D, N>],
    words: &[&str],
) -> String {
    let e = check(m, p, c).expect_err("the mutation was accepted");
    assert!(
        words.iter().any(|w| e.contains(w)),
        "unexpected message: {e}"
    );
    e
}

fn orientation2(p: &[[f64; 2]], c: &Cell<2, 3>) -> f64 {
    let x: Vec<[f64; 2]> = (0..3).map(|k| c.1[k].apply(p[c.0[k] as usize])).collect();
    (x[1][0] - x[0][0]) * (x[2][1] - x[0][1]) - (x[1][1] - x[0][1]) * (x[2][0] - x[0][0])
}

#[test]
fn rejects_a_dropped_cell() {
    let (m, p, mut c) = torus2(300, 3);
    c.remove(17);
    expect_err(&m, &p, &c, &["facet"]);
}

#[test]
fn rejects_a_vertex_moved_to_another_lift() {
    let (m, p, c) = torus2(300, 4);
    for i in [0, 50, 100] {
        // the first lattice translation that keeps the cell positively oriented
        let moved = [[1.0, 0.0], [0.5, 0.75], [-1.0, 0.0], [-0.5, -0.75]]
            .into_iter()
            .map(|t| {
                let mut c = c.clone();
                let g = &mut c[i].1[2];
                g.t = [g.t[0] + t[0], g.t[1] + t[1]];
                c
            })
            .find(|c| orientation2(&p, &c[i]) > 1e-9)
            .unwrap();
        // (a far lift may first break the bound on circumradii)
        let e = expect_err(
            &m,
            &p,
            &moved,
            &["circumsphere", "facet", "covering radius"],
        );
        eprintln!("{e}");
    }
}

#[test]
fn rejects_a_far_lift() {
    // a vertex five periods away: a huge circumcircle, caught by the covering radius bound
    let (m, p, c) = torus2(300, 4);
    let far = [[5.0, 0.0], [-5.0, 0.0]]
        .into_iter()
        .map(|t| {
            let mut c = c.clone();
            c[0].1[1].t = [c[0].1[1].t[0] + t[0], c[0].1[1].t[1] + t[1]];
            c
        })
        .find(|c| orientation2(&p, &c[0]) > 0.0)
        .unwrap();
    expect_err(&m, &p, &far, &["exceeds the covering radius bound"]);
}

#[test]
fn rejects_points_equal_modulo_g_and_a_wrong_euler_characteristic() {
    let (m, mut p, c) = torus2(100, 12);
    let wrong = Manifold { euler: 1, ..m };
    expect_err(&wrong, &p, &c, &["Euler characteristic 0"]);
    // two new points, one the other's image by a lattice translation (exact in doubles)
    p.extend([[0.125, 0.25], [0.625, 1.0]]);
    expect_err(&wrong, &p, &c, &["coincide modulo G"]);
}

#[test]
fn rejects_swapped_vertices() {
    let (m, p, mut c) = torus2(300, 5);
    c[9].0.swap(0, 1);
    c[9].1.swap(0, 1);
    expect_err(&m, &p, &c, &["not positively oriented"]);
}

#[test]
fn rejects_a_moved_point() {
    let (m, mut p, c) = torus2(300, 6);
    // the point image nearest outside some cell's circumcircle, pushed just inside it
    let mut best = (f64::MAX, 0, [0.0; 2]);
    for cell in &c {
        let x: Vec<[f64; 2]> = (0..3)
            .map(|k| cell.1[k].apply(p[cell.0[k] as usize]))
            .collect();
        let (b, cc) = (
            [x[1][0] - x[0][0], x[1][1] - x[0][1]],
            [x[2][0] - x[0][0], x[2][1] - x[0][1]],
        );
        let d = 2.0 * (b[0] * cc[1] - b[1] * cc[0]);
        let (b2, c2) = (b[0] * b[0] + b[1] * b[1], cc[0] * cc[0] + cc[1] * cc[1]);
        let z = [
            x[0][0] + (cc[1] * b2 - b[1] * c2) / d,
            x[0][1] + (b[0] * c2 - cc[0] * b2) / d,
        ];
        let r = ((x[0][0] - z[0]).powi(2) + (x[0][1] - z[1]).powi(2)).sqrt();
        for (j, q) in p.iter().enumerate() {
            if cell.0.contains(&(j as u32)) {
                continue;
            }
            for o in [-2, -1, 0, 1, 2] {
                for s in [-2, -1, 0, 1, 2] {
                    let w = [q[0] + o as f64 + 0.5 * s as f64, q[1] + 0.75 * s as f64];
                    let dz = [z[0] - w[0], z[1] - w[1]];
                    let gap = (dz[0] * dz[0] + dz[1] * dz[1]).sqrt() - r;
                    if gap > 1e-12 && gap < best.0 {
                        let u = (dz[0] * dz[0] + dz[1] * dz[1]).sqrt();
                        best = (gap, j, [dz[0] / u, dz[1] / u]);
                    }
                }
            }
        }
    }
    let (gap, j, dir) = best;
    eprintln!("moving point {j} by {:e}", 2.0 * gap);
    p[j] = [p[j][0] + 2.0 * gap * dir[0], p[j][1] + 2.0 * gap * dir[1]];
    let e = expect_err(&m, &p, &c, &["strictly inside"]);
    eprintln!("{e}");
}

#[test]
fn rejects_a_translated_duplicate() {
    let (m, p, mut c) = torus2(300, 7);
    let mut dup = c[3];
    for g in &mut dup.1 {
        g.t = [g.t[0] + 0.5, g.t[1] + 0.75];
    }
    c.push(dup);
    expect_err(&m, &p, &c, &["duplicates cell 3"]);
}

#[test]
fn rejects_mutations_in_3d() {
    let space = FlatTorus3::cuboid([1.0, 1.5, 0.75]).unwrap();
    let tri = PeriodicDelaunay::build(space, &random(200, 9, [1.0, 1.5, 0.75])).unwrap();
    let (m, p, c) = data(&tri);
    let mut d = c.clone();
    d.remove(0);
    expect_err(&m, &p, &d, &["facet"]);
    let mut d = c.clone();
    d[5].0.swap(1, 2);
    d[5].1.swap(1, 2);
    expect_err(&m, &p, &d, &["not positively oriented"]);
    let mut d = c.clone();
    let mut dup = c[8];
    dup.1.iter_mut().for_each(|g| g.t[2] -= 0.75);
    d.push(dup);
    expect_err(&m, &p, &d, &["duplicates cell 8"]);
    // a wrong volume for the manifold
    let wrong = Manifold {
        volume: 1.0,
        ..Manifold::torus(tri.space().lattice().vectors())
    };
    expect_err(&wrong, &p, &c, &["volume"]);
}

// ---- the Klein bottle ----------------------------------------------------------------

/// γ: (x, y) ↦ (x + 1, −y) and τ: (x, y) ↦ (x, y + 1); area 1.
fn klein() -> Manifold<2> {
    Manifold {
        generators: vec![
            Isometry {
                a: [[1.0, 0.0], [0.0, -1.0]],
                t: [1.0, 0.0],
            },
            Isometry::translation([0.0, 1.0]),
        ],
        volume: 1.0,
        euler: 0,
        metric: [1.0; 2],
    }
}

fn int(x: &BigRational) -> i64 {
    assert!(x.is_integer(), "{x} is not an integer");
    x.to_integer().try_into().unwrap()
}

#[test]
fn klein_bottle_group() {
    let m = klein();
    let one = [1.0, 1.0].map(|x| BigRational::from_float(x).unwrap());
    let g = Group::new(&m.generators, &one).unwrap();
    assert_eq!(g.cosets.len(), 2);
    assert_eq!(g.covolume, BigRational::from_float(1.0).unwrap());
    let exact = |i: &Isometry<2>| Element::from_isometry(i, &one).unwrap();
    let gamma = exact(&m.generators[0]);
    let tau = exact(&m.generators[1]);
    assert_eq!(
        gamma.compose(&gamma),
        exact(&Isometry::translation([2.0, 0.0]))
    );
    assert_eq!(gamma.compose(&tau).compose(&gamma.inverse()), tau.inverse());
    let near = g.elements_near([0.0, 0.0], 6.0).unwrap();
    let flip = [[1.0, 0.0], [0.0, -1.0]];
    for e in &near {
        let (tx, ty) = (int(&e.t[0]), int(&e.t[1]));
        if e.is_translation() {
            assert_eq!(tx % 2, 0, "{e:?}");
            assert!(tx != 0 || ty != 0 || e.is_identity());
        } else {
            assert_eq!(e.approx().a, flip);
            assert_eq!(tx.rem_euclid(2), 1, "{e:?}");
        }
        assert!(tx * tx + ty * ty <= 36);
    }
    // exactly the elements of a breadth-first search by word length: a word of length
    // ≤ 14 reaches every element with |t| ≤ 6 (γ^j τ^m, |j|, |m| ≤ 6, and more)
    let gens = [gamma.clone(), gamma.inverse(), tau.clone(), tau.inverse()];
    let mut seen = HashSet::from([Element::identity()]);
    let mut layer = vec![Element::identity()];
    for _ in 0..14 {
        let mut next = Vec::new();
        for e in &layer {
            for s in &gens {
                let f = e.compose(s);
                if seen.insert(f.clone()) {
                    next.push(f);
                }
            }
        }
        layer = next;
    }
    let by_words: HashSet<Element<2>> = seen
        .into_iter()
        .filter(|e| {
            let (tx, ty) = (int(&e.t[0]), int(&e.t[1]));
            tx * tx + ty * ty <= 36
        })
        .collect();
    let enumerated: HashSet<Element<2>> = near.into_iter().collect();
    assert_eq!(enumerated.len(), by_words.len());
    assert_eq!(enumerated, by_words);
    // membership
    let glide = |t: [f64; 2]| exact(&Isometry { a: flip, t });
    assert!(g.contains(&glide([3.0, 2.0])));
    assert!(g.contains(&glide([-1.0, -5.0])));
    assert!(!g.contains(&glide([2.0, 0.0])));
    assert!(!g.contains(&glide([1.0, 0.5])));
    assert!(!g.contains(&exact(&Isometry::translation([1.0, 0.0]))));
    assert!(!g.contains(&exact(&Isometry::translation([0.0, 0.5]))));
}

/// A Klein bottle element in units of 1/64: (x, y) ↦ (x + a, s·y + b).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
struct Kl {
    s: i64,
    a: i64,
    b: i64,
}

const U: i64 = 64;

impl Kl {
    fn then(self, o: Kl) -> Kl {
        // o ∘ self
        Kl {
            s: o.s * self.s,
            a: self.a + o.a,
            b: o.s * self.b + o.b,
        }
    }
    fn inv(self) -> Kl {
        Kl {
            s: self.s,
            a: -self.a,
            b: -self.s * self.b,
        }
    }
    fn apply(self, p: [i64; 2]) -> [i64; 2] {
        [p[0] + self.a, self.s * p[1] + self.b]
    }
    fn isometry(self) -> Isometry<2> {
        Isometry {
            a: [[1.0, 0.0], [0.0, self.s as f64]],
            t: [self.a as f64 / U as f64, self.b as f64 / U as f64],
        }
    }
}

fn orient(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> i128 {
    let (bx, by, cx, cy) = (b[0] - a[0], b[1] - a[1], c[0] - a[0], c[1] - a[1]);
    (bx * cy - by * cx) as i128
}

/// > 0 when `d` is inside the circle through the counter-clockwise `a, b, c`.
fn in_circle(a: [i64; 2], b: [i64; 2], c: [i64; 2], d: [i64; 2]) -> i128 {
    let r = |p: [i64; 2]| {
        let (x, y) = ((p[0] - d[0]) as i128, (p[1] - d[1]) as i128);
        (x, y, x * x + y * y)
    };
    let (ax, ay, a2) = r(a);
    let (bx, by, b2) = r(b);
    let (cx, cy, c2) = r(c);
    ax * (by * c2 - b2 * cy) - ay * (bx * c2 - b2 * cx) + a2 * (bx * cy - by * cx)
}

/// The Delaunay triangles of the Klein bottle orbit of `pts` (units of 1/64, in the unit
/// square), one per orbit, counter-clockwise, found by brute force: a triangle with a
/// vertex at an original point, the others within `reach`, and no image strictly inside.
/// Panics on a cocircular configuration (choose other points).
fn klein_delaunay(pts: &[[i64; 2]]) -> Vec<[(usize, Kl); 3]> {
    let mut elements = Vec::new();
    for a in -4..=4i64 {
        for b in -4..=4 {
            let s = if a % 2 == 0 { 1 } else { -1 };
            elements.push(Kl {
                s,
                a: a * U,
                b: b * U,
            });
        }
    }
    let images: Vec<(usize, Kl, [i64; 2])> = elements
        .iter()
        .flat_map(|&g| {
            pts.iter()
                .enumerate()
                .map(move |(i, &p)| (i, g, g.apply(p)))
        })
        .collect();
    let id = Kl { s: 1, a: 0, b: 0 };
    let reach = 2 * U;
    let mut seen = HashSet::new();
    let mut out = Vec::new();
    for (i, &p) in pts.iter().enumerate() {
        let d2 = |x: [i64; 2]| (x[0] - p[0]).pow(2) + (x[1] - p[1]).pow(2);
        // nearest first: a point inside a circle through p is then found early
        let mut by_distance: Vec<[i64; 2]> = images.iter().map(|x| x.2).collect();
        by_distance.sort_by_key(|&x| d2(x));
        let near: Vec<&(usize, Kl, [i64; 2])> = images
            .iter()
            .filter(|x| x.2 != p && d2(x.2) <= reach * reach)
            .collect();
        for &&(j, g, q) in &near {
            for &&(k, h, r) in &near {
                if orient(p, q, r) <= 0 || by_distance.iter().any(|&x| in_circle(p, q, r, x) > 0) {
                    continue;
                }
                let on = by_distance
                    .iter()
                    .filter(|&&x| in_circle(p, q, r, x) == 0)
                    .count();
                assert_eq!(
                    on, 3,
                    "cocircular points: choose others ({p:?} {q:?} {r:?})"
                );
                let tri = [(i, id), (j, g), (k, h)];
                let key = (0..3)
                    .map(|k0| {
                        let mut v: Vec<(usize, Kl)> = tri
                            .iter()
                            .map(|&(v, e)| (v, e.then(tri[k0].1.inv())))
                            .collect();
                        v.sort();
                        v
                    })
                    .min()
                    .unwrap();
                if seen.insert(key) {
                    out.push(tri);
                }
            }
        }
    }
    out
}

fn klein_points(n: usize, seed: u64) -> Vec<[i64; 2]> {
    let mut r = SplitMix::new(seed);
    (0..n)
        .map(|_| [(r.unit() * U as f64) as i64, (r.unit() * U as f64) as i64])
        .collect()
}

fn klein_cells(tris: &[[(usize, Kl); 3]]) -> Vec<Cell<2, 3>> {
    tris.iter()
        .map(|t| (t.map(|x| x.0 as u32), t.map(|x| x.1.isometry())))
        .collect()
}

#[test]
fn klein_bottle_triangulations() {
    for (n, seed) in [(3, 1), (5, 2), (8, 3), (13, 4)] {
        let pts = klein_points(n, seed);
        let tris = klein_delaunay(&pts);
        // χ = 0: F = 2V
        assert_eq!(tris.len(), 2 * n, "{n} points");
        let points: Vec<[f64; 2]> = pts.iter().map(|p| p.map(|x| x as f64 / U as f64)).collect();
        let cells = klein_cells(&tris);
        let m = klein();
        check(&m, &points, &cells).unwrap_or_else(|e| panic!("{n} points: {e}"));

        // mutations
        let mut c = cells.clone();
        c.pop();
        expect_err(&m, &points, &c, &["facet"]);
        let mut c = cells.clone();
        c[1].0.swap(1, 2);
        c[1].1.swap(1, 2);
        expect_err(&m, &points, &c, &["not positively oriented"]);
        // a vertex moved to another lift by γ²: a different (wrong) triangle
        let mut c = cells.clone();
        let g = tris[0][2].1.then(Kl {
            s: 1,
            a: 2 * U,
            b: 0,
        });
        c[0].1[2] = g.isometry();
        assert!(check(&m, &points, &c).is_err());
        // an element outside the group
        let mut c = cells.clone();
        c[0].1[1].t[1] += 0.5;
        expect_err(&m, &points, &c, &["not an element of G"]);
        let torus = Manifold::torus([[2.0, 0.0], [0.0, 1.0]]);

        // its orientation double cover: the 2×1 torus with points p_i and γ·p_i, cells c and
        // γ·c (orientation reversed, so two vertices swap)
        let gamma = Kl { s: -1, a: U, b: 0 };
        let double: Vec<[f64; 2]> = pts
            .iter()
            .chain(
                pts.iter()
                    .map(|&p| gamma.apply(p))
                    .collect::<Vec<_>>()
                    .iter(),
            )
            .map(|p| p.map(|x| x as f64 / U as f64))
            .collect();
        // a Klein element g = (s, a, b) is a translation of p_i (s = 1) or of γ·p_i (s = −1)
        let lift = |v: usize, g: Kl| -> (u32, Isometry<2>) {
            let (v, a) = if g.s == 1 { (v, g.a) } else { (v + n, g.a - U) };
            (v as u32, Kl { s: 1, a, b: g.b }.isometry())
        };
        let mut cover = Vec::new();
        for t in &tris {
            for h in [Kl { s: 1, a: 0, b: 0 }, gamma] {
                let mut v: Vec<(u32, Isometry<2>)> =
                    t.iter().map(|&(v, g)| lift(v, g.then(h))).collect();
                if h.s == -1 {
                    v.swap(1, 2);
                }
                cover.push(([v[0].0, v[1].0, v[2].0], [v[0].1, v[1].1, v[2].1]));
            }
        }
        check(&torus, &double, &cover).unwrap_or_else(|e| panic!("double cover, {n}: {e}"));
    }
}
