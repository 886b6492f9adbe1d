//! Predicates on the sphere (thesis §4.3.1), for points given in `E³` near the unit sphere:
//! a spherical triangle `abc` is positively oriented when `det[a; b; c] > 0` (counter-clockwise
//! seen from outside), and `q` lies inside its circumcircle when `q` and the origin are on
//! different sides of the plane through `a, b, c`. The triangles are the faces of the convex
//! hull of the points: the spherical Delaunay triangulation for points on one sphere, the
//! regular triangulation on the sphere for points near it. Exact for all doubles: the
//! floating-point filter of [`filter::orient3`], then big integers. Ties (four points on one
//! plane) are broken by pulling every point towards the origin by an infinitesimal, the
//! larger the later the point comes in a given order ([`in_circle`]).

use super::exact::{self, Scaled};
use super::filter;
use super::{perturbed_by, Sign};

/// Largest absolute coordinate of each row (the filter's bounds).
fn bounds<const K: usize>(rows: &[[f64; 3]; K]) -> [f64; K] {
    rows.map(|r| r.iter().fold(0.0f64, |m, x| m.max(x.abs())))
}

/// Coordinates of an anchor: `t·2⁻¹⁰⁰⁰` for a small integer vector `t`, standing for `δ·t`
/// with `δ` infinitesimal (no point near the unit sphere comes close).
pub const ANCHOR_SCALE: f64 = f64::from_bits((1023 - 1000) << 52);

/// True for an anchor: every coordinate below `2⁻⁹⁰⁰` in magnitude.
#[inline]
pub fn is_anchor(p: &[f64; 3]) -> bool {
    p.iter()
        .all(|x| x.abs() < f64::from_bits((1023 - 900) << 52))
}

/// The direction of a point: an anchor scaled up by `2¹⁰⁰⁰` (exactly), others as they are.
/// Orientations about the origin keep their sign.
fn direction(p: &[f64; 3]) -> [f64; 3] {
    if is_anchor(p) {
        p.map(|x| x / ANCHOR_SCALE)
    } else {
        *p
    }
}

/// `det[a; b; c]` exactly: the orientation of `a, b, c` about the origin (an anchor counts
/// by its direction).
#[inline]
pub fn orient_origin(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> Sign {
    let rows = [*a, *b, *c];
    match filter::orient3(&rows, bounds(&rows)) {
        Some(s) => s,
        None => orient_exact(rows),
    }
}

/// [`orient_origin`] in big integers.
#[cold]
#[inline(never)]
fn orient_exact(rows: [[f64; 3]; 3]) -> Sign {
    let rows = rows.map(|r| direction(&r));
    let scale = Scaled::new(rows.iter().flatten().copied());
    let ints = rows.map(|r| r.map(|x| scale.int(x)));
    exact::sign(&exact::det3(&ints[0], &ints[1], &ints[2]))
}

/// The side of `q` of the plane through `a, b, c` (positively oriented): `Positive` when
/// `q` is inside their circumcircle on the sphere (away from the origin), `Zero` on it.
/// Anchors are taken symbolically (order by order in `δ`); when the filter decides, the
/// infinitesimal terms are below its error bound and cannot change the sign.
#[inline]
pub fn side_of_circle(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3], q: &[f64; 3]) -> Sign {
    // det[b − a; c − a; q − a] is −det[a; b; c] at the origin: q and the origin are on
    // different sides exactly when it is positive
    let (d0, b0) = filter::plain_diff(b, a);
    let (d1, b1) = filter::plain_diff(c, a);
    let (d2, b2) = filter::plain_diff(q, a);
    match filter::orient3(&[d0, d1, d2], [b0, b1, b2]) {
        Some(s) => s,
        None => side_exact(a, b, c, q),
    }
}

/// [`side_of_circle`] in big integers.
#[cold]
#[inline(never)]
fn side_exact(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3], q: &[f64; 3]) -> Sign {
    if [a, b, c, q].iter().any(|p| is_anchor(p)) {
        return anchored_side(&[*a, *b, *c, *q]);
    }
    let scale = Scaled::new(a.iter().chain(b).chain(c).chain(q).copied());
    let ia = a.map(|x| scale.int(x));
    let diff = |p: &[f64; 3]| -> [num_bigint::BigInt; 3] {
        std::array::from_fn(|k| scale.int(p[k]) - &ia[k])
    };
    exact::sign(&exact::det3(&diff(b), &diff(c), &diff(q)))
}

/// The largest coordinate of a point of the sphere (`|p|² ≤ 1 + 2⁻²⁰`) or of an anchor,
/// in magnitude: the static filters below hold for such points.
const UNIT_BOUND: f64 = 1.0 + 1.0 / (1u64 << 20) as f64;
const U: f64 = f64::EPSILON * 0.5;

fn det3(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> f64 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// [`orient_origin`] of points with coordinates at most `1 + 2⁻²⁰` in magnitude (the
/// sphere's): a static filter, no bounds to compute. With exact entries the evaluation
/// errs by at most `7u` times the sum of the six products' magnitudes (Shewchuk), at most
/// `42u·B³`; twice that decides. (Underflow with an anchor's tiny entries adds far less.)
#[inline]
pub fn orient_unit(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> Sign {
    const ERR: f64 = 84.0 * U * UNIT_BOUND * UNIT_BOUND * UNIT_BOUND;
    let det = det3(a, b, c);
    if det > ERR {
        Sign::Positive
    } else if det < -ERR {
        Sign::Negative
    } else {
        orient_origin(a, b, c)
    }
}

/// [`side_of_circle`] of points with coordinates at most `1 + 2⁻²⁰` in magnitude: a static
/// filter. The differences (at most `2B`) are each within `u` relative of the exact ones,
/// which puts each of the six products of three within `3u` (plus second order), and the
/// evaluation adds `7u` of their sum: at most `60u·(2B)³`; `1024u·B³` decides. When it
/// decides with anchors among the points, their infinitesimal terms are far below it.
#[inline(always)]
pub fn side_unit(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3], q: &[f64; 3]) -> Sign {
    const ERR: f64 = 1024.0 * U * UNIT_BOUND * UNIT_BOUND * UNIT_BOUND;
    let d = |p: &[f64; 3]| [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let det = det3(&d(b), &d(c), &d(q));
    if det > ERR {
        Sign::Positive
    } else if det < -ERR {
        Sign::Negative
    } else {
        side_of_circle(a, b, c, q)
    }
}

/// [`side_of_circle`] with anchors among the points, exactly: the determinant
/// `det[b − a; c − a; q − a] = det[b; c; q] − det[a; c; q] + det[a; b; q] − det[a; b; c]` is a
/// polynomial in `δ`, each term of the order of its number of anchors; its sign is that of
/// the lowest order whose terms do not cancel (`Zero` when all do).
fn anchored_side(rows: &[[f64; 3]; 4]) -> Sign {
    let anchor = rows.map(|r| is_anchor(&r));
    let dirs = rows.map(|r| direction(&r));
    let scale = Scaled::new(dirs.iter().flatten().copied());
    let ints = dirs.map(|r| r.map(|x| scale.int(x)));
    let mut orders: [num_bigint::BigInt; 4] = Default::default();
    for k in 0..4 {
        let o: Vec<usize> = (0..4).filter(|&i| i != k).collect();
        let m = o.iter().filter(|&&i| anchor[i]).count();
        let d = exact::det3(&ints[o[0]], &ints[o[1]], &ints[o[2]]);
        if k % 2 == 0 {
            orders[m] += d;
        } else {
            orders[m] -= d;
        }
    }
    orders
        .iter()
        .map(exact::sign)
        .find(|&s| s != Sign::Zero)
        .unwrap_or(Sign::Zero)
}

/// The perturbed in-circle test of `q` against the positively oriented triangle `s`:
/// [`side_of_circle`], and on a tie the sign of the determinant once every point `p` is
/// replaced by `(1 − ε_p)·p`, with `ε_p` infinitesimal and larger for later points of the
/// order `compare` (on indices, `3` meaning `q`). Never `Zero` for four distinct points
/// with `s` positively oriented. Pulling `p` in by `ε_p` adds `ε_p` times the orientation
/// of the other three about the origin to the determinant, the same terms as the lifting
/// perturbation of a flat space (the same loop, `perturbed_by`).
pub fn in_circle(s: &[[f64; 3]; 3], q: [f64; 3], compare: impl Fn(usize, usize) -> Sign) -> Sign {
    match side_of_circle(&s[0], &s[1], &s[2], &q) {
        Sign::Zero => perturbed_by(s, q, |t| orient_origin(&t[0], &t[1], &t[2]), compare),
        decided => decided,
    }
}

/// Whether `q` lies strictly beyond the plane of a face `s` of the hull, counter-clockwise
/// seen from outside and facing the centre or not (a ghost face: the far side of a
/// hemisphere set): [`side_of_circle`], on a tie [`in_circle`]'s perturbation with the
/// query's coefficient minus the orientation of `s`. Where `s` and `q` lie on one plane
/// through the centre, pulling towards the centre keeps them there; then every point `p`
/// also moves by `η_p·(1, ζ, ζ²)`, with `η_p` far smaller than every `ε`, larger for later
/// points, and `ζ` infinitesimal. The latest of the four points decides: moved, it changes
/// the determinant by the first non-zero coordinate of the other three's normal. Never
/// `Zero` for four distinct points on the sphere.
pub fn beyond(s: &[[f64; 3]; 3], q: [f64; 3], compare: impl Fn(usize, usize) -> Sign) -> Sign {
    match side_of_circle(&s[0], &s[1], &s[2], &q) {
        Sign::Zero => {}
        decided => return decided,
    }
    match perturbed_by(s, q, |t| orient_origin(&t[0], &t[1], &t[2]), &compare) {
        Sign::Zero => {}
        decided => return decided,
    }
    let latest = (1..4).fold(0, |m, k| {
        if compare(k, m) == Sign::Positive {
            k
        } else {
            m
        }
    });
    let pts = [s[0], s[1], s[2], q];
    let others: Vec<[f64; 3]> = (0..4).filter(|&k| k != latest).map(|k| pts[k]).collect();
    let sign = first_normal_coordinate(&others[0], &others[1], &others[2]);
    // moving point k by v adds (−1)^(3−k) (others' normal)·v to det[p1 − p0; p2 − p0; p3 − p0]
    if latest % 2 == 1 {
        sign
    } else {
        sign.flip()
    }
}

/// The sign of the first non-zero coordinate of `(b − a) × (c − a)`, exactly (`Zero` only
/// for collinear points).
#[cold]
fn first_normal_coordinate(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> Sign {
    let scale = Scaled::new(a.iter().chain(b).chain(c).copied());
    let [a, b, c] = [a, b, c].map(|p| p.map(|x| scale.int(x)));
    let d = |p: &[num_bigint::BigInt; 3], k: usize| &p[k] - &a[k];
    (0..3)
        .map(|k| {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            exact::sign(&(d(&b, i) * d(&c, j) - d(&b, j) * d(&c, i)))
        })
        .find(|&s| s != Sign::Zero)
        .unwrap_or(Sign::Zero)
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_bigint::BigInt;
    use num_rational::BigRational;
    use num_traits::{One, Signed};

    type Q = BigRational;

    fn q(x: f64) -> Q {
        BigRational::from_float(x).unwrap()
    }

    fn det3(m: &[[Q; 3]; 3]) -> Q {
        &m[0][0] * (&m[1][1] * &m[2][2] - &m[1][2] * &m[2][1])
            - &m[0][1] * (&m[1][0] * &m[2][2] - &m[1][2] * &m[2][0])
            + &m[0][2] * (&m[1][0] * &m[2][1] - &m[1][1] * &m[2][0])
    }

    fn sign(x: &Q) -> Sign {
        if x.is_positive() {
            Sign::Positive
        } else if x.is_negative() {
            Sign::Negative
        } else {
            Sign::Zero
        }
    }

    /// An independent evaluation: `det[b'−a'; c'−a'; q'−a']` in rationals, with each point
    /// shrunk by `1 − ε^(4−k)` for its rank `k` (the last point pulled in the most), then
    /// moved by `η^(4−k)·(1, ζ, ζ²)`, each small enough that the lowest non-zero order
    /// decides.
    fn explicit(s: &[[f64; 3]; 3], x: [f64; 3], rank: [usize; 4]) -> Sign {
        let tiny = |bits: usize| Q::new(BigInt::one(), BigInt::from(1u64) << bits);
        let (eps, eta, zeta) = (tiny(200), tiny(2000), tiny(100));
        let pts = [s[0], s[1], s[2], x];
        let power = |base: &Q, n: usize| (0..n).fold(Q::one(), |f, _| f * base);
        let shrunk: Vec<[Q; 3]> = pts
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let l = Q::one() - power(&eps, 4 - rank[i]);
                let m = power(&eta, 4 - rank[i]);
                std::array::from_fn(|c| &l * q(p[c]) + &m * power(&zeta, c))
            })
            .collect();
        let d = |k: usize| -> [Q; 3] { std::array::from_fn(|c| &shrunk[k][c] - &shrunk[0][c]) };
        sign(&det3(&[d(1), d(2), d(3)]))
    }

    #[test]
    fn orientation_and_side_agree_with_rationals() {
        let mut r = crate::sort::SplitMix::new(3);
        for scale in [1.0, 1e-150, 1e150] {
            for _ in 0..2000 {
                let mut p = || [r.unit() - 0.5, r.unit() - 0.5, r.unit() - 0.5].map(|x| x * scale);
                let (a, b, c, x) = (p(), p(), p(), p());
                let m = [a, b, c].map(|v| v.map(q));
                assert_eq!(orient_origin(&a, &b, &c), sign(&det3(&m)));
                let d = [b, c, x].map(|v| std::array::from_fn(|k| q(v[k]) - q(a[k])));
                assert_eq!(side_of_circle(&a, &b, &c, &x), sign(&det3(&d)));
            }
        }
    }

    /// `det[b − a; c − a; q − a]` in rationals with anchors at `2⁻ᵏ·t` for a given `k`.
    fn with_delta(rows: &[[f64; 3]; 4], k: usize) -> Sign {
        let delta = Q::new(BigInt::one(), BigInt::from(1u64) << k);
        let pts: Vec<[Q; 3]> = rows
            .iter()
            .map(|p| {
                if is_anchor(p) {
                    p.map(|x| q(x / ANCHOR_SCALE) * &delta)
                } else {
                    p.map(q)
                }
            })
            .collect();
        let d = |i: usize| -> [Q; 3] { std::array::from_fn(|c| &pts[i][c] - &pts[0][c]) };
        sign(&det3(&[d(1), d(2), d(3)]))
    }

    #[test]
    fn static_filters_agree_with_the_exact_signs() {
        let mut r = crate::sort::SplitMix::new(12);
        let mut unit = |spread: f64| {
            let v = [r.unit() - 0.5, r.unit() - 0.5, r.unit() - 0.5].map(|x| x * spread);
            let v = [v[0], v[1], 1.0 + v[2]];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|x| x / n)
        };
        // from spread-out points to points within 1e-7 of each other
        for spread in [2.0, 1e-3, 1e-7] {
            for _ in 0..3000 {
                let (a, b, c, x) = (unit(spread), unit(spread), unit(spread), unit(spread));
                assert_eq!(orient_unit(&a, &b, &c), orient_origin(&a, &b, &c));
                let m = [a, b, c].map(|v| v.map(q));
                assert_eq!(orient_unit(&a, &b, &c), sign(&det3(&m)));
                let d = [b, c, x].map(|v| std::array::from_fn(|k| q(v[k]) - q(a[k])));
                assert_eq!(side_unit(&a, &b, &c, &x), sign(&det3(&d)));
            }
        }
        // an exact tie: four points on the equator
        let e = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-0.6, 0.8, 0.0],
            [0.0, -1.0, 0.0],
        ];
        assert_eq!(side_unit(&e[0], &e[1], &e[2], &e[3]), Sign::Zero);
    }

    #[test]
    fn anchors_are_infinitesimal() {
        let t = [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ]
        .map(|v: [f64; 3]| v.map(|x| x * ANCHOR_SCALE));
        let mut r = crate::sort::SplitMix::new(9);
        let mut unit = || {
            let v = [r.unit() - 0.5, r.unit() - 0.5, r.unit() - 0.5];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|x| x / n)
        };
        let mut decided = 0;
        for round in 0..3000 {
            let mut rows = [unit(), unit(), unit(), unit()];
            // one to three anchors in random slots
            for k in 0..1 + round % 3 {
                rows[(round / 3 + k) % 4] = t[(round + k) % 4];
            }
            if round % 50 == 0 {
                // a tie at order zero: three real points on a great circle with an anchor
                rows = [
                    t[round % 4],
                    [1.0, 0.0, 0.0],
                    [0.0, 1.0, 0.0],
                    [0.6, -0.8, 0.0],
                ];
            }
            let got = side_of_circle(&rows[0], &rows[1], &rows[2], &rows[3]);
            assert_eq!(got, with_delta(&rows, 400), "{rows:?}");
            decided += usize::from(got != Sign::Zero);
            let o = orient_origin(&rows[0], &rows[1], &rows[2]);
            let m = [rows[0], rows[1], rows[2]].map(|p| direction(&p).map(q));
            assert_eq!(o, sign(&det3(&m)));
        }
        assert!(decided > 2900);
    }

    #[test]
    fn ties_match_the_explicit_shrinking() {
        // points on one plane z = 0.6 (the same double: coplanar exactly), near the sphere
        let ring: Vec<[f64; 3]> = [
            (0.8, 0.0),
            (0.0, 0.8),
            (-0.8, 0.0),
            (0.0, -0.8),
            (0.48, 0.64),
        ]
        .iter()
        .map(|&(x, y)| [x, y, 0.6])
        .chain([[0.8, 0.0, 0.0], [0.0, 0.8, 0.0], [-0.6, -0.64, 0.0]])
        .collect();
        let (mut checked, mut ties) = (0, 0);
        for i in 0..ring.len() {
            for j in 0..ring.len() {
                for k in 0..ring.len() {
                    for l in 0..ring.len() {
                        let ids = [i, j, k, l];
                        if (0..4).any(|u| (u + 1..4).any(|v| ids[u] == ids[v])) {
                            continue;
                        }
                        let s = [ring[i], ring[j], ring[k]];
                        if orient_origin(&s[0], &s[1], &s[2]) != Sign::Positive {
                            continue;
                        }
                        let x = ring[l];
                        ties += usize::from(side_of_circle(&s[0], &s[1], &s[2], &x) == Sign::Zero);
                        let got = in_circle(&s, x, |a, b| Sign::from(ids[a].cmp(&ids[b])));
                        // ranks: the order of the input indices
                        let mut rank = [0; 4];
                        for u in 0..4 {
                            rank[u] = (0..4).filter(|&v| ids[v] < ids[u]).count();
                        }
                        assert_eq!(got, explicit(&s, x, rank), "{ids:?}");
                        assert_ne!(got, Sign::Zero);
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 200 && ties > 50, "{checked} tests, {ties} ties");
    }

    #[test]
    fn ghost_sides_match_the_explicit_perturbation() {
        // a small circle (z = 0.6), a great circle (z = 0) and a tilted plane through the
        // centre (x = y): every face, facing the centre or not
        let pts: Vec<[f64; 3]> = [
            [0.8, 0.0, 0.6],
            [0.0, 0.8, 0.6],
            [-0.48, -0.64, 0.6],
            [0.64, -0.48, 0.6],
            [0.8, 0.0, 0.0],
            [0.0, -0.8, 0.0],
            [-0.6, 0.64, 0.0],
            [0.36, 0.48, 0.0],
            [-0.5, -0.25, 0.0],
            [0.5, 0.5, 0.7],
            [-0.4, -0.4, 0.8],
            [0.6, 0.6, -0.5],
            [0.125, 0.125, -0.75],
            [0.0, 0.5, 0.6],
        ]
        .to_vec();
        let (mut ties, mut flat) = (0, 0);
        let mut r = crate::sort::SplitMix::new(17);
        for i in 0..pts.len() {
            for j in 0..pts.len() {
                for k in 0..pts.len() {
                    let ids = [i, j, k];
                    if i == j || j == k || i == k {
                        continue;
                    }
                    let s = [pts[i], pts[j], pts[k]];
                    for l in (0..pts.len()).filter(|l| !ids.contains(l)) {
                        let x = pts[l];
                        let side = side_of_circle(&s[0], &s[1], &s[2], &x);
                        // a random order of the four (the same order for either test)
                        let key: [u64; 4] = std::array::from_fn(|_| r.next_u64());
                        let got = beyond(&s, x, |a, b| Sign::from(key[a].cmp(&key[b])));
                        assert_ne!(got, Sign::Zero);
                        if side != Sign::Zero {
                            assert_eq!(got, side);
                            continue;
                        }
                        ties += 1;
                        flat += usize::from(orient_origin(&s[0], &s[1], &s[2]) == Sign::Zero);
                        let rank =
                            std::array::from_fn(|u| (0..4).filter(|&v| key[v] < key[u]).count());
                        assert_eq!(got, explicit(&s, x, rank), "{i} {j} {k} {l}");
                    }
                }
            }
        }
        assert!(
            ties > 100 && flat > 50,
            "{ties} ties, {flat} through the centre"
        );
    }
}
