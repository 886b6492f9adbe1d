//! An independent brute-force checker of Delaunay triangulations of closed flat manifolds
//! `E^D/G` (`G` a Bieberbach group given by generators `x ↦ A·x + t`), in the universal
//! cover and in exact rational arithmetic. Nothing here calls the library: it shares no
//! predicate, no lattice code and no engine with it.
//!
//! The group is built from its generators without a bound on word length: the point group
//! (linear parts) by closure, one coset representative per linear part, the translation
//! subgroup `L` from Schreier's generators, reduced to a basis by exact integer-style row
//! operations. Every element is then `x ↦ A·x + t_A + l` with `l ∈ L`, so the elements within
//! any distance are enumerated exactly and completely from the basis (a pruned breadth-first
//! search by word length would not provably find them all).
//!
//! The predicates (orientation, circumcenters, in-sphere, sides of facets) are evaluated in
//! big integers after scaling every lifted point by one common denominator (see [`Scale`]);
//! the group in big rationals. Floating-point numbers only decide what to test (bounds,
//! buckets, a distance filter with a margin of `1e-9` of the scale, orders of magnitude above
//! rounding); every decision that can fail the check is exact.
#![allow(dead_code)]
// coordinates are indexed by number, as in the formulas
#![allow(clippy::needless_range_loop)]

use std::collections::HashMap;

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};

type Q = BigRational;

/// An isometry x ↦ A·x + t of E^D; A[i][j] is the coefficient of x_j in output coordinate i.
/// Entries are doubles that are exact (A: signed permutation matrices here; t: exact doubles).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Isometry<const D: usize> {
    pub a: [[f64; D]; D],
    pub t: [f64; D],
}

impl<const D: usize> Isometry<D> {
    pub fn identity() -> Self {
        Isometry {
            a: std::array::from_fn(|i| std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 })),
            t: [0.0; D],
        }
    }

    pub fn translation(t: [f64; D]) -> Self {
        Isometry {
            t,
            ..Self::identity()
        }
    }

    /// The image of `x` (in doubles: for building test data).
    pub fn apply(&self, x: [f64; D]) -> [f64; D] {
        std::array::from_fn(|i| (0..D).map(|j| self.a[i][j] * x[j]).sum::<f64>() + self.t[i])
    }
}

pub struct Manifold<const D: usize> {
    pub generators: Vec<Isometry<D>>,
    /// The volume (area in 2D) of the quotient: |det of the translational lattice| / index.
    pub volume: f64,
    /// Euler characteristic the quotient must have (0 for every closed flat manifold).
    pub euler: i64,
    /// The metric: a vector `x` has squared length `Σ w_i x_i²`. Exact doubles, each at least
    /// 1 (so Euclidean balls contain metric balls of the same radius); all 1 in Cartesian
    /// coordinates. Other weights let a space with irrational rotations (a hexagonal
    /// cross-section) be checked in coordinates where its group is rational.
    pub metric: [f64; D],
}

impl<const D: usize> Manifold<D> {
    /// The flat torus of the lattice with these rows.
    pub fn torus(rows: [[f64; D]; D]) -> Self {
        let m: Vec<Vec<Q>> = rows
            .iter()
            .map(|r| r.iter().map(|&x| q(x)).collect())
            .collect();
        Manifold {
            generators: rows.iter().map(|&r| Isometry::translation(r)).collect(),
            volume: f(&det(&m).abs()),
            euler: 0,
            metric: [1.0; D],
        }
    }
}

/// A double as an exact rational (panics on NaN or infinity: callers check first).
fn q(x: f64) -> Q {
    BigRational::from_float(x).expect("finite")
}

fn exact(x: f64, what: &dyn Fn() -> String) -> Result<Q, String> {
    BigRational::from_float(x).ok_or_else(|| format!("{} is not finite ({x})", what()))
}

/// The nearest double (or a huge value: it only feeds bounds).
fn f(x: &Q) -> f64 {
    x.to_f64().unwrap_or(f64::MAX)
}

/// Determinant by cofactor expansion along the first row (D ≤ 3 here).
fn det<T>(m: &[Vec<T>]) -> T
where
    T: Clone + Signed,
    for<'a> &'a T: std::ops::Mul<&'a T, Output = T>,
{
    match m.len() {
        0 => T::one(),
        1 => m[0][0].clone(),
        2 => &m[0][0] * &m[1][1] - &m[0][1] * &m[1][0],
        n => {
            let mut s = T::zero();
            for j in 0..n {
                if m[0][j].is_zero() {
                    continue;
                }
                let minor: Vec<Vec<T>> = m[1..]
                    .iter()
                    .map(|r| (0..n).filter(|&k| k != j).map(|k| r[k].clone()).collect())
                    .collect();
                let c = &m[0][j] * &det(&minor);
                s = if j % 2 == 0 { s + c } else { s - c };
            }
            s
        }
    }
}

fn dot<T, const D: usize>(a: &[T; D], b: &[T; D]) -> T
where
    T: Clone + Signed,
    for<'a> &'a T: std::ops::Mul<&'a T, Output = T>,
{
    let mut s = T::zero();
    for i in 0..D {
        if !a[i].is_zero() && !b[i].is_zero() {
            s = s + &a[i] * &b[i];
        }
    }
    s
}

fn sub<T, const D: usize>(a: &[T; D], b: &[T; D]) -> [T; D]
where
    for<'a> &'a T: std::ops::Sub<&'a T, Output = T>,
{
    std::array::from_fn(|i| &a[i] - &b[i])
}

/// `M⁻¹ = adj(M)/det(M)`: `(M⁻¹)_ij = cofactor_ji / det`.
fn inverse_matrix<const D: usize>(m: &[[Q; D]; D]) -> [[Q; D]; D] {
    let rows: Vec<Vec<Q>> = m.iter().map(|r| r.to_vec()).collect();
    let d = det(&rows);
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let minor: Vec<Vec<Q>> = (0..D)
                .filter(|&r| r != j)
                .map(|r| {
                    (0..D)
                        .filter(|&c| c != i)
                        .map(|c| rows[r][c].clone())
                        .collect()
                })
                .collect();
            let c = det(&minor) / &d;
            if (i + j) % 2 == 0 {
                c
            } else {
                -c
            }
        })
    })
}

fn approx<const D: usize>(x: &[Q; D]) -> [f64; D] {
    std::array::from_fn(|i| f(&x[i]))
}

fn norm(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// A group element with exact entries: `x ↦ a·x + t`. Ordered and hashed exactly.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Element<const D: usize> {
    pub a: [[Q; D]; D],
    pub t: [Q; D],
}

impl<const D: usize> Element<D> {
    pub fn identity() -> Self {
        Element {
            a: std::array::from_fn(|i| {
                std::array::from_fn(|j| if i == j { Q::one() } else { Q::zero() })
            }),
            t: std::array::from_fn(|_| Q::zero()),
        }
    }

    /// The exact element of an isometry of the metric `w` (diagonal weights): finite entries
    /// and a linear part with `Aᵀ·W·A = W`.
    pub fn from_isometry(g: &Isometry<D>, w: &[Q; D]) -> Result<Self, String> {
        let mut a: [[Q; D]; D] = std::array::from_fn(|_| std::array::from_fn(|_| Q::zero()));
        for i in 0..D {
            for j in 0..D {
                a[i][j] = exact(g.a[i][j], &|| format!("A[{i}][{j}] of {g:?}"))?;
            }
        }
        let mut t: [Q; D] = std::array::from_fn(|_| Q::zero());
        for i in 0..D {
            t[i] = exact(g.t[i], &|| format!("t[{i}] of {g:?}"))?;
        }
        let e = Element { a, t };
        for i in 0..D {
            for j in 0..D {
                let s: Q = (0..D).map(|k| &e.a[k][i] * &w[k] * &e.a[k][j]).sum();
                if s != if i == j { w[i].clone() } else { Q::zero() } {
                    return Err(format!("{g:?} is not an isometry (A is not orthogonal)"));
                }
            }
        }
        Ok(e)
    }

    /// `self ∘ other`: first `other`, then `self`.
    pub fn compose(&self, other: &Self) -> Self {
        Element {
            a: std::array::from_fn(|i| {
                std::array::from_fn(|j| (0..D).map(|k| &self.a[i][k] * &other.a[k][j]).sum())
            }),
            t: std::array::from_fn(|i| {
                (0..D).map(|k| &self.a[i][k] * &other.t[k]).sum::<Q>() + &self.t[i]
            }),
        }
    }

    /// The inverse (`A⁻¹ = Aᵀ`, orthogonal).
    pub fn inverse(&self) -> Self {
        // not Aᵀ: A is orthogonal for the metric, which need not be Euclidean
        let a = inverse_matrix(&self.a);
        let t = std::array::from_fn(|i| -(0..D).map(|k| &a[i][k] * &self.t[k]).sum::<Q>());
        Element { a, t }
    }

    pub fn apply(&self, x: &[Q; D]) -> [Q; D] {
        std::array::from_fn(|i| {
            let mut s = self.t[i].clone();
            for k in 0..D {
                if !self.a[i][k].is_zero() && !x[k].is_zero() {
                    s += &self.a[i][k] * &x[k];
                }
            }
            s
        })
    }

    pub fn is_identity(&self) -> bool {
        *self == Self::identity()
    }

    pub fn is_translation(&self) -> bool {
        self.a == Self::identity().a
    }

    /// det A: +1 or −1.
    pub fn det(&self) -> Q {
        det(&self.a.iter().map(|r| r.to_vec()).collect::<Vec<_>>())
    }

    /// The nearest doubles.
    pub fn approx(&self) -> Isometry<D> {
        Isometry {
            a: std::array::from_fn(|i| std::array::from_fn(|j| f(&self.a[i][j]))),
            t: approx(&self.t),
        }
    }
}

/// The group generated by some isometries, as cosets of its translation subgroup.
pub struct Group<const D: usize> {
    /// One element per linear part (the point group), the identity first.
    pub cosets: Vec<Element<D>>,
    /// A basis (rows) of the translation subgroup `L`, size-reduced.
    pub lattice: [[Q; D]; D],
    /// `lattice⁻¹`: a translation `t` is in `L` iff `t·inv` is integral.
    inv: [[Q; D]; D],
    coset_of: HashMap<[[Q; D]; D], usize>,
    /// Volume of `E^D/G`: `|det lattice| / |point group|`.
    pub covolume: Q,
}

/// Largest point group accepted (crystallographic ones have at most 48 elements in 3D).
const MAX_POINT_GROUP: usize = 1000;
/// Largest number of elements or point images one check enumerates.
const MAX_ENUMERATED: usize = 20_000_000;

impl<const D: usize> Group<D> {
    /// Errs if a generator is not an isometry of the metric `w`, the linear parts generate an infinite group, or
    /// the translations do not span `E^D` (the quotient would not be compact).
    pub fn new(generators: &[Isometry<D>], w: &[Q; D]) -> Result<Self, String> {
        let gens: Vec<Element<D>> = generators
            .iter()
            .map(|g| Element::from_isometry(g, w))
            .collect::<Result<_, _>>()?;
        // the point group by closure (a finite monoid of invertible elements is a group)
        let mut cosets = vec![Element::identity()];
        let mut coset_of = HashMap::from([(cosets[0].a.clone(), 0)]);
        let mut i = 0;
        while i < cosets.len() {
            for s in &gens {
                let e = cosets[i].compose(s);
                if !coset_of.contains_key(&e.a) {
                    if cosets.len() == MAX_POINT_GROUP {
                        return Err("the linear parts generate an infinite group".into());
                    }
                    coset_of.insert(e.a.clone(), cosets.len());
                    cosets.push(e);
                }
            }
            i += 1;
        }
        // Schreier: L is generated by r·s·(rep of r·s)⁻¹ over representatives r, generators s
        let mut rows: Vec<[Q; D]> = Vec::new();
        for r in &cosets {
            for s in &gens {
                let e = r.compose(s);
                let u = e.compose(&cosets[coset_of[&e.a]].inverse());
                debug_assert!(u.is_translation());
                if u.t.iter().any(|x| !x.is_zero()) {
                    rows.push(u.t);
                }
            }
        }
        let mut basis = row_reduce(rows)?;
        size_reduce(&mut basis);
        let m: Vec<Vec<Q>> = basis.iter().map(|r| r.to_vec()).collect();
        let d = det(&m);
        let inv = inverse_matrix(&basis);
        let covolume = d.abs() / Q::from_integer(BigInt::from(cosets.len()));
        Ok(Group {
            cosets,
            lattice: basis,
            inv,
            coset_of,
            covolume,
        })
    }

    /// Whether `g` is an element of the group.
    pub fn contains(&self, g: &Element<D>) -> bool {
        let Some(&k) = self.coset_of.get(&g.a) else {
            return false;
        };
        let d = sub(&g.t, &self.cosets[k].t);
        (0..D).all(|j| {
            (0..D)
                .map(|i| &d[i] * &self.inv[i][j])
                .sum::<Q>()
                .is_integer()
        })
    }

    /// Every element `h` with `|h·c − c| ≤ bound` in Euclidean length, exactly (`c` and
    /// `bound` as given): a superset of the metric ball when the weights are at least 1.
    pub fn elements_near(&self, c: [f64; D], bound: f64) -> Result<Vec<Element<D>>, String> {
        let cq: [Q; D] = c.map(q);
        let b2 = q(bound) * q(bound);
        let basis: Vec<[f64; D]> = self.lattice.iter().map(approx).collect();
        // |coefficient j| of a vector x is at most |x|·|column j of inv|
        let col: [f64; D] =
            std::array::from_fn(|j| norm(&(0..D).map(|i| f(&self.inv[i][j])).collect::<Vec<_>>()));
        let mut out = Vec::new();
        for r in &self.cosets {
            // h = (A, t_A + l): h·c − c = w + l with w = r·c − c
            let w = sub(&r.apply(&cq), &cq);
            let u: [f64; D] =
                std::array::from_fn(|j| f(&(0..D).map(|i| &w[i] * &self.inv[i][j]).sum::<Q>()));
            // l = k·lattice with k_j ∈ −u_j ± bound·col_j, widened by one for rounding
            let lo: [i64; D] = std::array::from_fn(|j| (-u[j] - bound * col[j]).floor() as i64 - 1);
            let hi: [i64; D] = std::array::from_fn(|j| (-u[j] + bound * col[j]).ceil() as i64 + 1);
            let count = (0..D).map(|j| (hi[j] - lo[j] + 1) as f64).product::<f64>();
            if count * self.cosets.len() as f64 > MAX_ENUMERATED as f64 {
                return Err(format!(
                    "{count} group elements to enumerate within {bound}: too many"
                ));
            }
            let wf = approx(&w);
            let mut k = lo;
            loop {
                let x: [f64; D] = std::array::from_fn(|i| {
                    wf[i] + (0..D).map(|j| k[j] as f64 * basis[j][i]).sum::<f64>()
                });
                // a filter only, far wider than the rounding of x; the test below is exact
                let size: f64 = (0..D).map(|j| (k[j] as f64 * norm(&basis[j])).abs()).sum();
                let margin = 1e-9 * (bound + norm(&wf) + size) + f64::MIN_POSITIVE;
                if norm(&x) <= bound + margin {
                    let mut h = r.clone();
                    for j in 0..D {
                        if k[j] != 0 {
                            let kq = Q::from_integer(BigInt::from(k[j]));
                            for i in 0..D {
                                h.t[i] += &kq * &self.lattice[j][i];
                            }
                        }
                    }
                    let d = sub(&h.apply(&cq), &cq);
                    if dot(&d, &d) <= b2 {
                        out.push(h);
                    }
                }
                // odometer over the box
                let mut j = 0;
                while j < D && k[j] == hi[j] {
                    k[j] = lo[j];
                    j += 1;
                }
                if j == D {
                    break;
                }
                k[j] += 1;
            }
        }
        Ok(out)
    }
}

/// A basis of the group generated by `rows` (rationals): Euclid's algorithm column by column
/// (a finitely generated subgroup of Q is cyclic, so it terminates).
fn row_reduce<const D: usize>(mut rows: Vec<[Q; D]>) -> Result<[[Q; D]; D], String> {
    for c in 0..D {
        loop {
            let pivot = (c..rows.len())
                .filter(|&r| !rows[r][c].is_zero())
                .min_by(|&a, &b| rows[a][c].abs().cmp(&rows[b][c].abs()));
            let Some(p) = pivot else {
                return Err("the translations of the group do not span space".into());
            };
            rows.swap(c, p);
            let mut done = true;
            for r in c + 1..rows.len() {
                if !rows[r][c].is_zero() {
                    let k = (&rows[r][c] / &rows[c][c]).floor();
                    for i in 0..D {
                        let v = &k * &rows[c][i];
                        rows[r][i] -= v;
                    }
                    done &= rows[r][c].is_zero();
                }
            }
            if done {
                break;
            }
        }
    }
    Ok(std::array::from_fn(|i| rows[i].clone()))
}

/// Pairwise size reduction: `b_i −= round(μ)·b_j` while some `|μ| = |b_i·b_j|/|b_j|² > 1/2`
/// (each step shortens `b_i`, and a lattice has finitely many short vectors). Only the
/// cost of the enumeration depends on the basis.
fn size_reduce<const D: usize>(b: &mut [[Q; D]; D]) {
    let half = Q::new(BigInt::from(1), BigInt::from(2));
    loop {
        let mut changed = false;
        for i in 0..D {
            for j in 0..D {
                if i == j {
                    continue;
                }
                let mu = dot(&b[i], &b[j]) / dot(&b[j], &b[j]);
                if mu.abs() > half {
                    let k = mu.round();
                    let bj = b[j].clone();
                    for c in 0..D {
                        b[i][c] -= &k * &bj[c];
                    }
                    changed = true;
                }
            }
        }
        if !changed {
            return;
        }
    }
}

type Z = BigInt;

fn gcd(mut a: Z, mut b: Z) -> Z {
    while !b.is_zero() {
        let r = &a % &b;
        a = b;
        b = r;
    }
    a.abs()
}

fn lcm<'a>(values: impl Iterator<Item = &'a Q>) -> Z {
    values.fold(Z::one(), |l, x| {
        let d = x.denom();
        let g = gcd(l.clone(), d.clone());
        l / g * d
    })
}

/// `x·scale`, which must be an integer.
fn integral(x: &Q, scale: &Z) -> Z {
    let y = x * Q::from_integer(scale.clone());
    assert!(y.is_integer(), "{x} times {scale} is not an integer");
    y.to_integer()
}

/// The integers of one computation: every lifted point `g·p` times `L = d_A·d_P·d_T` is an
/// integer vector, where `d_A`, `d_T` and `d_P` are common denominators of the linear parts
/// (a finite point group), of the translations (all in `t_A + L`) and of the points. With
/// them every predicate below is a polynomial in integers: no gcd on the hot paths.
struct Scale {
    /// `d_A`, `d_T`, `L`
    a: Z,
    t: Z,
    l: Z,
}

/// Interned group elements (ids compare and hash cheaply), with cached relative elements
/// and each element's integer form `(A·d_A, t·L)`.
struct Elements<const D: usize> {
    list: Vec<Element<D>>,
    int: Vec<([[Z; D]; D], [Z; D])>,
    id: HashMap<Element<D>, u32>,
    inverse: Vec<Option<u32>>,
    /// `(a, b) ↦ id of a⁻¹·b`
    rel: HashMap<(u32, u32), u32>,
}

impl<const D: usize> Elements<D> {
    fn new(scale: &Scale) -> Self {
        let mut s = Elements {
            list: Vec::new(),
            int: Vec::new(),
            id: HashMap::new(),
            inverse: Vec::new(),
            rel: HashMap::new(),
        };
        s.intern(Element::identity(), scale);
        s
    }

    /// The id of a group element (callers only pass elements of the group).
    fn intern(&mut self, e: Element<D>, scale: &Scale) -> u32 {
        if let Some(&i) = self.id.get(&e) {
            return i;
        }
        let i = self.list.len() as u32;
        self.int.push((
            e.a.each_ref()
                .map(|r| r.each_ref().map(|x| integral(x, &scale.a))),
            e.t.each_ref().map(|x| integral(x, &scale.l)),
        ));
        self.id.insert(e.clone(), i);
        self.list.push(e);
        self.inverse.push(None);
        i
    }

    fn rel(&mut self, a: u32, b: u32, scale: &Scale) -> u32 {
        if a == b {
            return 0;
        }
        if let Some(&r) = self.rel.get(&(a, b)) {
            return r;
        }
        let ia = match self.inverse[a as usize] {
            Some(x) => x,
            None => {
                let x = self.intern(self.list[a as usize].inverse(), scale);
                self.inverse[a as usize] = Some(x);
                x
            }
        };
        let r = self.intern(
            self.list[ia as usize].compose(&self.list[b as usize]),
            scale,
        );
        self.rel.insert((a, b), r);
        r
    }

    /// `L·(g·p)` from `p·d_P`: `(A·d_A)(p·d_P)·d_T + t·L`.
    fn lift(&self, e: u32, p: &[Z; D], scale: &Scale) -> [Z; D] {
        let (a, t) = &self.int[e as usize];
        std::array::from_fn(|i| {
            let mut s = Z::zero();
            for k in 0..D {
                if !a[i][k].is_zero() {
                    s += &a[i][k] * &p[k];
                }
            }
            s * &scale.t + &t[i]
        })
    }
}

/// Integer lifted points `L·(g·points[p])`, cached by (point, element id).
struct Lifts<'a, const D: usize> {
    /// `points·d_P`
    points: &'a [[Z; D]],
    scale: &'a Scale,
    cache: HashMap<(u32, u32), [Z; D]>,
}

impl<const D: usize> Lifts<'_, D> {
    fn get(&mut self, el: &Elements<D>, p: u32, e: u32) -> [Z; D] {
        self.cache
            .entry((p, e))
            .or_insert_with(|| el.lift(e, &self.points[p as usize], self.scale))
            .clone()
    }
}

/// Buckets of approximate points (counting sort into a dense grid; positions outside the
/// grid are clamped into its border buckets, queries likewise, so nothing is ever missed).
struct Grid<const D: usize> {
    lo: [f64; D],
    size: f64,
    dims: [usize; D],
    start: Vec<u32>,
    items: Vec<u32>,
}

impl<const D: usize> Grid<D> {
    fn new(pts: &[[f64; D]], lo: [f64; D], hi: [f64; D]) -> Self {
        let vol: f64 = (0..D).map(|i| (hi[i] - lo[i]).max(0.0)).product();
        // about two points per bucket, at most 129 buckets a side
        let mut size = (2.0 * vol / pts.len().max(1) as f64).powf(1.0 / D as f64);
        let widest = (0..D).map(|i| hi[i] - lo[i]).fold(0.0, f64::max);
        size = size.max(widest / 128.0);
        if !(size > 0.0 && size.is_finite()) {
            size = 1.0;
        }
        let dims = std::array::from_fn(|i| (((hi[i] - lo[i]) / size) as usize).min(128) + 1);
        let mut g = Grid {
            lo,
            size,
            dims,
            start: Vec::new(),
            items: Vec::new(),
        };
        let buckets: usize = dims.iter().product();
        let keys: Vec<usize> = pts.iter().map(|p| g.index(g.bucket(p))).collect();
        let mut start = vec![0u32; buckets + 1];
        for &k in &keys {
            start[k + 1] += 1;
        }
        for k in 0..buckets {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; pts.len()];
        for (i, &k) in keys.iter().enumerate() {
            items[fill[k] as usize] = i as u32;
            fill[k] += 1;
        }
        g.start = start;
        g.items = items;
        g
    }

    fn bucket(&self, p: &[f64; D]) -> [usize; D] {
        std::array::from_fn(|i| {
            let x = ((p[i] - self.lo[i]) / self.size).floor();
            if x.is_nan() || x < 0.0 {
                0
            } else {
                (x as usize).min(self.dims[i] - 1)
            }
        })
    }

    fn index(&self, b: [usize; D]) -> usize {
        (0..D).rev().fold(0, |acc, i| acc * self.dims[i] + b[i])
    }

    /// Every item in the buckets meeting the box `[lo, hi]`.
    fn query(&self, lo: &[f64; D], hi: &[f64; D], out: &mut Vec<u32>) {
        out.clear();
        let a = self.bucket(lo);
        let b = self.bucket(hi);
        let mut k = a;
        loop {
            let i = self.index(k);
            out.extend_from_slice(&self.items[self.start[i] as usize..self.start[i + 1] as usize]);
            let mut j = 0;
            while j < D && k[j] == b[j] {
                k[j] = a[j];
                j += 1;
            }
            if j == D {
                return;
            }
            k[j] += 1;
        }
    }
}

/// A lifted cell in the frame where its vertex 0 is `points[p_0]` itself (integer
/// coordinates, times `L`).
struct Lifted<const D: usize, const N: usize> {
    /// (point, element id) per vertex, the element `g_0⁻¹·g_k`.
    v: [(u32, u32); N],
    x: Vec<[Z; D]>,
    /// The circumcenter is `x_0 + yn/yd`.
    yn: [Z; D],
    yd: Z,
    /// Approximate circumcenter and radius in user units.
    center: [f64; D],
    radius: f64,
}

impl<const D: usize, const N: usize> Lifted<D, N> {
    /// Whether `q` is strictly inside the circumsphere: `|q − x0|² − 2(q − x0)·y < 0` in
    /// the metric of integer weights `w`.
    fn inside(&self, q: &[Z; D], w: &[Z; D]) -> bool {
        let d = sub(q, &self.x[0]);
        let wd: [Z; D] = std::array::from_fn(|i| &w[i] * &d[i]);
        let s = dot(&wd, &d) * &self.yd - Z::from(2) * dot(&wd, &self.yn);
        s.sign() == -self.yd.sign()
    }
}

/// Relative difference of two positive rationals, as a double.
fn relative(a: &Q, b: &Q) -> f64 {
    f(&((a - b).abs() / b))
}

fn orient<const D: usize>(x: &[[Z; D]], y: &[Z; D]) -> Z {
    let mut m: Vec<Vec<Z>> = x[1..].iter().map(|p| sub(p, &x[0]).to_vec()).collect();
    m.push(sub(y, &x[0]).to_vec());
    det(&m)
}

/// Checks a triangulation of the quotient given as cells: each cell is N point indices and,
/// per vertex, the group element g_k such that the vertex sits at g_k·points[v_k] in the
/// universal cover. Returns Err(message naming the cell/point) on the first failure.
///
/// In order: the group (its volume against `m.volume`, relative 1e-12), the points (finite,
/// distinct modulo G, none fixed by an element) and elements (in G); per cell, positive
/// orientation and an empty circumsphere; duplicates modulo G; every facet orbit met by
/// exactly two cells, on opposite sides; the exact total volume; every point a vertex; the
/// Euler characteristic.
pub fn check<const D: usize, const N: usize>(
    m: &Manifold<D>,
    points: &[[f64; D]],
    cells: &[([u32; N], [Isometry<D>; N])],
) -> Result<(), String> {
    assert_eq!(N, D + 1, "cells of E^{D} have {} vertices", D + 1);
    if m.metric.iter().any(|&w| !(w >= 1.0 && w.is_finite())) {
        return Err(format!(
            "the metric {:?} needs weights of at least 1",
            m.metric
        ));
    }
    let wq: [Q; D] = m.metric.map(q);
    // the same metric, scaled to integers (scaling changes no circumcenter and no sign)
    let wden = lcm(wq.iter());
    let wz: [Z; D] = wq.each_ref().map(|x| integral(x, &wden));
    let norm_w = |x: &[f64; D]| {
        (0..D)
            .map(|i| m.metric[i] * x[i] * x[i])
            .sum::<f64>()
            .sqrt()
    };
    let group = Group::new(&m.generators, &wq)?;
    let given = exact(m.volume, &|| "the manifold's volume".into())?;
    if given != group.covolume {
        let r = relative(&given, &group.covolume);
        if r.is_nan() || r > 1e-12 {
            return Err(format!(
                "the manifold's volume is {}, its group's is {} (relative difference {r:e})",
                m.volume,
                f(&group.covolume)
            ));
        }
    }
    if points.is_empty() {
        return Err("no points".into());
    }
    let mut pq = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        let mut x: [Q; D] = std::array::from_fn(|_| Q::zero());
        for k in 0..D {
            x[k] = exact(p[k], &|| format!("point {i} {p:?}"))?;
        }
        pq.push(x);
    }
    let dp = lcm(pq.iter().flatten());
    let scale = {
        let a = lcm(group.cosets.iter().flat_map(|e| e.a.iter().flatten()));
        let t = lcm(group
            .cosets
            .iter()
            .flat_map(|e| e.t.iter())
            .chain(group.lattice.iter().flatten()));
        let l = &a * &dp * &t;
        Scale { a, t, l }
    };
    let lscale = Q::from_integer(scale.l.clone());
    let pz: Vec<[Z; D]> = pq
        .iter()
        .map(|p| p.each_ref().map(|x| integral(x, &dp)))
        .collect();
    let mut el = Elements::<D>::new(&scale);
    let mut lifts = Lifts {
        points: &pz,
        scale: &scale,
        cache: HashMap::new(),
    };

    // the cells' elements, interned by bit pattern first (most repeat)
    let mut by_bits: HashMap<Vec<u64>, u32> = HashMap::new();
    let mut given_ids: Vec<[(u32, u32); N]> = Vec::with_capacity(cells.len());
    for (c, (vs, gs)) in cells.iter().enumerate() {
        let mut ids = [(0u32, 0u32); N];
        for k in 0..N {
            if vs[k] as usize >= points.len() {
                return Err(format!("cell {c} {vs:?}: vertex {k} is not a point index"));
            }
            let bits: Vec<u64> = gs[k]
                .a
                .iter()
                .flatten()
                .chain(gs[k].t.iter())
                .map(|x| (x + 0.0).to_bits())
                .collect();
            let e = match by_bits.get(&bits) {
                Some(&e) => e,
                None => {
                    let g = Element::from_isometry(&gs[k], &wq)
                        .map_err(|s| format!("cell {c} {vs:?}, vertex {k}: {s}"))?;
                    if !group.contains(&g) {
                        return Err(format!(
                            "cell {c} {vs:?}, vertex {k}: {:?} is not an element of G",
                            gs[k]
                        ));
                    }
                    let e = el.intern(g, &scale);
                    by_bits.insert(bits, e);
                    e
                }
            };
            ids[k] = (vs[k], e);
        }
        given_ids.push(ids);
    }

    // per cell: orientation, circumsphere (in the frame of its vertex 0), volume
    let basis: Vec<[f64; D]> = group.lattice.iter().map(approx).collect();
    let rho = 0.5 * basis.iter().map(norm_w).sum::<f64>();
    let mut total = Z::zero();
    let mut lifted: Vec<Lifted<D, N>> = Vec::with_capacity(cells.len());
    for (c, ids) in given_ids.iter().enumerate() {
        let g0 = ids[0].1;
        let v: [(u32, u32); N] = std::array::from_fn(|k| (ids[k].0, el.rel(g0, ids[k].1, &scale)));
        let x: Vec<[Z; D]> = v.iter().map(|&(p, e)| lifts.get(&el, p, e)).collect();
        let rows: Vec<Vec<Z>> = x[1..].iter().map(|p| sub(p, &x[0]).to_vec()).collect();
        let vol = det(&rows);
        // orient(g0⁻¹·cell) = det(A_g0)·orient(cell)
        let sign = if el.list[g0 as usize].det().is_positive() {
            vol.sign()
        } else {
            -vol.sign()
        };
        if sign != num_bigint::Sign::Plus {
            return Err(format!(
                "cell {c} {:?}: not positively oriented ({sign:?})",
                cells[c].0
            ));
        }
        total += vol.abs();
        // circumcenter y − x0: 2 d_k·W·y = d_k·W·d_k, by Cramer's rule
        let weighted: Vec<Vec<Z>> = rows
            .iter()
            .map(|r| r.iter().zip(&wz).map(|(v, w)| v * w).collect())
            .collect();
        let rhs: Vec<Z> = rows
            .iter()
            .zip(&weighted)
            .map(|(r, rw)| r.iter().zip(rw).map(|(v, vw)| v * vw).sum())
            .collect();
        let yn: [Z; D] = std::array::from_fn(|i| {
            let mut mi = weighted.clone();
            for k in 0..D {
                mi[k][i] = rhs[k].clone();
            }
            det(&mi)
        });
        let yd = Z::from(2) * det(&weighted);
        let to_user = |z: &Z| Q::new(z.clone(), &yd * &scale.l);
        let center = std::array::from_fn(|i| f(&(&pq[v[0].0 as usize][i] + to_user(&yn[i]))));
        let ynw: [Z; D] = std::array::from_fn(|i| &yn[i] * &wz[i]);
        let radius = f(&Q::new(
            dot(&ynw, &yn),
            &yd * &yd * &scale.l * &scale.l * &wden,
        ))
        .sqrt();
        lifted.push(Lifted {
            v,
            x,
            yn,
            yd,
            center,
            radius,
        });
    }

    // A sphere wider than ρ = ½Σ|b_j| holds an image of any point: z − x0 = Σ c_j b_j and
    // x0 + Σ round(c_j) b_j is within ρ of z. Such cells fail here, the others bound B.
    for (c, l) in lifted.iter().enumerate() {
        if l.radius > 1.01 * rho {
            let y: [f64; D] =
                std::array::from_fn(|i| f(&Q::new(l.yn[i].clone(), &l.yd * &scale.l)));
            let mut t: [Z; D] = std::array::from_fn(|_| Z::zero());
            for j in 0..D {
                let cj = (0..D).map(|i| y[i] * f(&group.inv[i][j])).sum::<f64>();
                let k = Z::from(cj.round() as i64);
                for i in 0..D {
                    t[i] += &k * integral(&group.lattice[j][i], &scale.l);
                }
            }
            let image: [Z; D] = std::array::from_fn(|i| &l.x[0][i] + &t[i]);
            return Err(format!(
                "cell {c} {:?}: circumradius {} exceeds the covering radius bound {rho}{}",
                cells[c].0,
                l.radius,
                if l.inside(&image, &wz) {
                    format!(
                        "; point {}'s image by translation {:?} is inside",
                        l.v[0].0,
                        t.each_ref()
                            .map(|x| f(&(Q::from_integer(x.clone()) / &lscale)))
                    )
                } else {
                    String::new()
                }
            ));
        }
    }

    // The bound. Let c0 be the center of the points' bounding box and R_P their largest
    // distance to it. If h·p_i is strictly inside the sphere (z, r) of a cell (in its frame,
    // vertex 0 at p_{v0}), then since h is an isometry |h·c0 − h·p_i| = |c0 − p_i| ≤ R_P, so
    // |h·c0 − c0| < |z − c0| + r + R_P ≤ B, with |z − c0| ≤ r + |p_{v0} − c0| ≤ r + R_P and
    // r ≤ 1.01ρ (above): B stays below 2.02ρ + 2R_P. Two points within δ of each other
    // need |h·c0 − c0| ≤ 2R_P + δ. Enumerate every h with |h·c0 − c0| ≤ B (exactly), widen
    // B by a relative 1e-6 and δ, far above the rounding of the doubles that compute it.
    let lo: [f64; D] =
        std::array::from_fn(|i| points.iter().map(|p| p[i]).fold(f64::MAX, f64::min));
    let hi: [f64; D] =
        std::array::from_fn(|i| points.iter().map(|p| p[i]).fold(f64::MIN, f64::max));
    let c0: [f64; D] = std::array::from_fn(|i| 0.5 * lo[i] + 0.5 * hi[i]);
    // distances in the metric (the bound below rests on the group's isometries); Euclidean
    // distances are at most these, so the Euclidean filters further down only widen
    let dist = |a: &[f64; D], b: &[f64; D]| norm_w(&std::array::from_fn(|i| a[i] - b[i]));
    let rp = points.iter().map(|p| dist(p, &c0)).fold(0.0, f64::max);
    let reach = lifted
        .iter()
        .map(|l| dist(&l.center, &c0) + l.radius)
        .fold(rp, f64::max);
    let delta = 1e-9 * (norm_w(&c0) + rp + reach + rho);
    let bound = (reach + rp) * (1.0 + 1e-6) + delta;
    let elements = group.elements_near(c0, bound)?;
    if elements.len() * points.len() > MAX_ENUMERATED {
        return Err(format!(
            "{} images of {} points to test: too many",
            elements.len() * points.len(),
            points.len()
        ));
    }
    let mut images: Vec<[f64; D]> = Vec::with_capacity(elements.len() * points.len());
    let mut image_of: Vec<(u32, u32)> = Vec::with_capacity(images.capacity());
    for h in elements {
        let g = h.approx();
        let e = el.intern(h, &scale);
        for (i, p) in points.iter().enumerate() {
            images.push(g.apply(*p));
            image_of.push((i as u32, e));
        }
    }
    let reach_all = bound + rp + delta;
    let grid = Grid::new(
        &images,
        c0.map(|x| x - reach_all),
        c0.map(|x| x + reach_all),
    );
    let mut found = Vec::new();

    // points distinct modulo G (and none fixed by a non-identity element)
    for (j, p) in points.iter().enumerate() {
        grid.query(&p.map(|x| x - delta), &p.map(|x| x + delta), &mut found);
        for &k in &found {
            let (i, e) = image_of[k as usize];
            if (i as usize, e) == (j, 0) || dist(&images[k as usize], p) > delta {
                continue;
            }
            if lifts.get(&el, i, e) == lifts.get(&el, j as u32, 0) {
                let h = el.list[e as usize].approx();
                return Err(if i as usize == j {
                    format!("point {j} is fixed by the non-identity element {h:?}")
                } else {
                    format!("point {i}'s image by {h:?} is point {j}: points coincide modulo G")
                });
            }
        }
    }

    // empty circumspheres
    for (c, l) in lifted.iter().enumerate() {
        let r = l.radius + delta;
        grid.query(
            &std::array::from_fn(|i| l.center[i] - r),
            &std::array::from_fn(|i| l.center[i] + r),
            &mut found,
        );
        for &k in &found {
            if dist(&images[k as usize], &l.center) > r {
                continue;
            }
            let (i, e) = image_of[k as usize];
            if l.inside(&lifts.get(&el, i, e), &wz) {
                return Err(format!(
                    "cell {c} {:?}: point {i}'s image by {:?} is strictly inside its circumsphere",
                    cells[c].0,
                    el.list[e as usize].approx()
                ));
            }
        }
    }

    // faces modulo G: the key of a face is min over k0 of sorted {(p_k, g_k0⁻¹·g_k)}
    let mut faces: Vec<HashMap<Vec<(u32, u32)>, usize>> = vec![HashMap::new(); N];
    // facet orbits: incidences (cell, opposite slot, slot of the chosen k0)
    let mut incidences: Vec<Vec<(usize, usize, usize)>> = Vec::new();
    for (c, l) in lifted.iter().enumerate() {
        let rel: Vec<Vec<u32>> = (0..N)
            .map(|a| (0..N).map(|b| el.rel(l.v[a].1, l.v[b].1, &scale)).collect())
            .collect();
        for mask in 1u32..(1 << N) {
            let slots: Vec<usize> = (0..N).filter(|&k| mask >> k & 1 == 1).collect();
            let (key, k0) = slots
                .iter()
                .map(|&k0| {
                    let mut key: Vec<(u32, u32)> =
                        slots.iter().map(|&k| (l.v[k].0, rel[k0][k])).collect();
                    key.sort_unstable();
                    (key, k0)
                })
                .min()
                .unwrap();
            let n = faces[slots.len() - 1].len();
            let id = *faces[slots.len() - 1].entry(key).or_insert(n);
            if slots.len() == N && id != n {
                // one cell key per cell and none repeated so far: the id is the cell's index
                return Err(format!(
                    "cell {c} {:?} duplicates cell {id} {:?} modulo G",
                    cells[c].0, cells[id].0
                ));
            }
            if slots.len() == D {
                if id == incidences.len() {
                    incidences.push(Vec::new());
                }
                let opposite = (0..N).find(|&k| mask >> k & 1 == 0).unwrap();
                incidences[id].push((c, opposite, k0));
            }
        }
    }
    for inc in &incidences {
        let (c, o, k0) = inc[0];
        if inc.len() != 2 {
            let facet: Vec<u32> = (0..N).filter(|&k| k != o).map(|k| cells[c].0[k]).collect();
            return Err(format!(
                "facet {facet:?} of cell {c} {:?} (opposite its vertex {o}) is a facet of {} cell(s) modulo G, not 2",
                cells[c].0,
                inc.len()
            ));
        }
        // h maps the second facet onto the first: h = g_k0 · g'_k0'⁻¹
        let (c2, o2, k2) = inc[1];
        let (a, b) = (&lifted[c], &lifted[c2]);
        let h = el.list[a.v[k0].1 as usize].compose(&el.list[b.v[k2].1 as usize].inverse());
        let across = el.intern(h.compose(&el.list[b.v[o2].1 as usize]), &scale);
        let facet: Vec<[Z; D]> = (0..N).filter(|&k| k != o).map(|k| a.x[k].clone()).collect();
        let s1 = orient(&facet, &a.x[o]).sign();
        let s2 = orient(&facet, &lifts.get(&el, b.v[o2].0, across)).sign();
        if s1 == num_bigint::Sign::NoSign || s1 != -s2 {
            return Err(format!(
                "cells {c} {:?} and {c2} {:?} share a facet modulo G but lie on the same side of it",
                cells[c].0, cells[c2].0
            ));
        }
    }

    let volume = Q::new(
        total,
        Z::from((1..=D as u64).product::<u64>()) * scale.l.pow(D as u32),
    );
    if volume != group.covolume {
        return Err(format!(
            "the cells' volumes sum to {}, the quotient's volume is {} (relative difference {:e})",
            f(&volume),
            f(&group.covolume),
            relative(&volume, &group.covolume)
        ));
    }
    if faces[0].len() != points.len() {
        let used: std::collections::HashSet<u32> = faces[0].keys().map(|k| k[0].0).collect();
        let p = (0..points.len() as u32)
            .find(|p| !used.contains(p))
            .unwrap();
        return Err(format!("point {p} is not a vertex of any cell"));
    }
    let euler: i64 = (0..N)
        .map(|k| if k % 2 == 0 { 1 } else { -1 } * faces[k].len() as i64)
        .sum();
    if euler != m.euler {
        let counts: Vec<usize> = faces.iter().map(HashMap::len).collect();
        return Err(format!(
            "Euler characteristic {euler} (faces per dimension {counts:?}), expected {}",
            m.euler
        ));
    }
    Ok(())
}
