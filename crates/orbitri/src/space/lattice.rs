//! A lattice of translations in `D` dimensions: validation, fractional coordinates and
//! wrapping into the half-open domain, the systole, and the choice of covering space and
//! dummy point set that Algorithm 2.3.1 needs for an arbitrary lattice.

use super::sublattice::Sublattice;
use crate::error::{Error, Result};
use crate::predicates::filter::Rows;

/// How the covering spaces of a flat torus are chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Ladder {
    /// One covering of `h_i` copies per lattice vector, then the torus: the thesis's
    /// Algorithm 2.3.1 (27 sheets for a cube, 9 for a square).
    Grid,
    /// Sublattices of index `2^k`, each of index 2 in the next (Bogdanov–Teillaud–Vegter,
    /// EuroCG 2012), descended one step whenever the next step's criterion holds: 16 (one
    /// point only), 8, 4, 2 and 1 sheets for a square. Each step keeps the sublattice of index
    /// 2 with the longest shortest vector. 2D only; other dimensions get [`Ladder::Grid`].
    #[default]
    Halving,
}

/// One covering of a ladder: its group of translations (in lattice units) and that group's
/// systole (its shortest translation).
///
/// Why each level is safe (Proposition 5 of Bogdanov–Teillaud–Vegter, which holds for any
/// sublattice `H` of any lattice `G`: its proof applies Corollary 9 of Caroli–Teillaud to
/// the group `H` acting on `G·S`): if the largest empty ball of `G·S` has diameter
/// `Δ < δ(H)/2`, the projection of `DT(G·S')` to `E^D/H` is a triangulation for every
/// `S' ⊇ S`. The engine moves to a level when every circumradius is below `δ(H)/4`, i.e.
/// `Δ < δ(H)/2`, and never goes back up while points are added. Level 0 needs no test:
/// its systole exceeds twice the largest empty ball one point can leave.
#[derive(Clone, Debug, PartialEq)]
pub struct Level<const D: usize> {
    pub sub: Sublattice<D>,
    /// In the lattice's internal frame (user units: times [`Lattice::unit`]).
    pub systole: f64,
}

/// Largest accepted orthogonality defect `Π|b_i| / |det|`. Within it, the coefficients of a
/// shortest lattice vector are bounded by the defect, so enumerating `|x_i| ≤ 4` finds it.
pub const MAX_DEFECT: f64 = 4.0;
const ENUM: i32 = 4;
/// Largest number of copies per lattice vector in the initial covering. Offsets are stored
/// in 8 bits: a normalized covering cell holds offsets below `2h`, and a walking query
/// drifts by at most about one more `h`, so `3·24 = 72` stays well inside `i8`.
pub const MAX_COPIES: i32 = 24;

/// A lattice given by `D` linearly independent row vectors; the domain is
/// `{ f·M : f ∈ [0,1)^D }`.
///
/// **The internal frame.** Everything the triangulation computes happens in a frame where
/// lengths are measured in `unit`, the power of two that brings the largest entry of `M` into
/// `[1, 2)`. Scaling by a power of two is exact, so a triangulation does not depend on the
/// scale of its input at all: the box `1e-300` and the box `1e300` give the same cells, and
/// the floating-point filters, circumradii and covering tests never underflow or overflow.
/// A coordinate smaller than `2^-1022·unit` becomes subnormal in that frame and is rounded to
/// a multiple of `2^-1074·unit` (the finest resolution the doubles allow at that scale); the
/// methods without the `_in` suffix take and return the user's units.
#[derive(Clone, Debug, PartialEq)]
pub struct Lattice<const D: usize> {
    /// The rows in the internal frame.
    pub(crate) rows: Rows<D>,
    /// One internal length unit in user units (a power of two).
    unit: f64,
    exponent: i32,
    inv: [[f64; D]; D],
    systole: f64,
    volume: f64,
}

/// `x·2^k`, correctly rounded for every `k`: `±inf` above the doubles' range, `±0` or a
/// subnormal below it.
pub(crate) fn ldexp(x: f64, k: i32) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    // x into [1, 2), exactly (a subnormal only grows, a normal stays normal)
    let e = exponent_of(x);
    let x = if -e > 1023 {
        x * pow2(537) * pow2(-e - 537)
    } else {
        x * pow2(-e)
    };
    let k = k.saturating_add(e);
    if k > 1023 {
        x * f64::INFINITY
    } else if k >= -1022 {
        x * pow2(k)
    } else if k < -1080 {
        x * 0.0
    } else {
        // the first factor keeps it normal (exact), the second rounds once
        x * pow2(-537) * pow2(k + 537)
    }
}

/// `2^k` for `−1074 ≤ k ≤ 1023`.
fn pow2(k: i32) -> f64 {
    if k >= -1022 {
        f64::from_bits(((k + 1023) as u64) << 52)
    } else {
        f64::from_bits(1u64 << (k + 1074))
    }
}

/// `⌊log₂|x|⌋` of a finite non-zero double (subnormals included).
fn exponent_of(x: f64) -> i32 {
    let bits = x.abs().to_bits();
    let biased = (bits >> 52) as i32;
    if biased > 0 {
        biased - 1023
    } else {
        // subnormal: the leading bit of the fraction
        -1074 + (63 - bits.leading_zeros() as i32)
    }
}

impl<const D: usize> Lattice<D> {
    /// An axis-aligned box `[0,L_0) × … × [0,L_{D−1})`.
    pub fn cuboid(lengths: [f64; D]) -> Result<Self> {
        for (i, l) in lengths.iter().enumerate() {
            if !l.is_finite() || *l <= 0.0 {
                return Err(Error::InvalidBox(format!(
                    "length {i} is {l}; box lengths must be positive and finite"
                )));
            }
        }
        let mut m = [[0.0; D]; D];
        for i in 0..D {
            m[i][i] = lengths[i];
        }
        Self::build(m, true)
    }

    /// A general lattice; `rows[i]` is the i-th lattice vector.
    pub fn new(rows: [[f64; D]; D]) -> Result<Self> {
        for (i, r) in rows.iter().enumerate() {
            for (j, v) in r.iter().enumerate() {
                if !v.is_finite() {
                    return Err(Error::InvalidBox(format!(
                        "lattice vector {i}, component {j} is {v}"
                    )));
                }
            }
            if r.iter().all(|v| *v == 0.0) {
                return Err(Error::InvalidBox(format!("lattice vector {i} is zero")));
            }
        }
        let diagonal = (0..D).all(|i| (0..D).all(|j| i == j || rows[i][j] == 0.0));
        if diagonal && (0..D).any(|i| rows[i][i] < 0.0) {
            let mut l = [0.0; D];
            for i in 0..D {
                l[i] = rows[i][i].abs();
            }
            return Self::cuboid(l);
        }
        Self::build(rows, diagonal)
    }

    fn build(user: [[f64; D]; D], diagonal: bool) -> Result<Self> {
        let largest = user.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
        let exponent = exponent_of(largest);
        let m = user.map(|r| r.map(|x| ldexp(x, -exponent)));
        if let Some(i) = (0..D).find(|&i| norm(&m[i]) < 1e-200) {
            return Err(Error::InvalidBox(format!(
                "too elongated: lattice vector {i} is {} times shorter than the longest entry",
                largest / norm(&user[i])
            )));
        }
        let (det, inv) = invert(&m);
        let norms: f64 = m.iter().map(norm).product();
        if det == 0.0 || !det.is_finite() || det.abs() <= 1e-12 * norms {
            return Err(Error::SingularLattice {
                det: ldexp(det.abs(), exponent * D as i32),
            });
        }
        let defect = norms / det.abs();
        if defect > MAX_DEFECT {
            return Err(Error::SkewedLattice {
                defect,
                limit: MAX_DEFECT,
            });
        }
        let rows = Rows { m, diagonal };
        let systole = shortest_vector(&rows, &diagonal_basis([1; D]));
        let lattice = Lattice {
            rows,
            unit: pow2(exponent),
            exponent,
            inv,
            systole,
            volume: det.abs(),
        };
        lattice.covering_or_error()?;
        Ok(lattice)
    }

    /// The covering of [`Self::covering`], or the "too elongated" error when it would need
    /// more than [`MAX_COPIES`] copies along some vector.
    fn covering_or_error(&self) -> Result<[i32; D]> {
        let too_elongated = |i: usize, copies: String| {
            Error::InvalidBox(format!(
                "too elongated: the covering space would need {copies} copies along vector {i} (at most {MAX_COPIES}); keep each edge above 1/{} of the box diagonal",
                MAX_COPIES / 2
            ))
        };
        // the sublattice holds h_i·b_i, so h_i > need/|b_i|: decided before any search
        let need = self.one_point_need();
        if let Some(i) = (0..D).find(|&i| need / norm(&self.rows.m[i]) >= MAX_COPIES as f64) {
            let at_least = (need / norm(&self.rows.m[i])).floor();
            return Err(too_elongated(i, format!("more than {at_least:.3e}")));
        }
        let h = self.covering();
        match (0..D).find(|&i| h[i] > MAX_COPIES) {
            Some(i) => Err(too_elongated(i, h[i].to_string())),
            None => Ok(h),
        }
    }

    /// One internal length unit in user units: the power of two by which the user's
    /// coordinates are divided (see the type's documentation).
    pub fn unit(&self) -> f64 {
        self.unit
    }

    /// A user measure (`power` 1: length, 2: area or weight) in the internal frame: exact,
    /// or `inf`/`0` where the doubles cannot hold it.
    pub(crate) fn measure_to_internal(&self, x: f64, power: i32) -> f64 {
        ldexp(x, (-self.exponent * power).clamp(-2100, 2100))
    }

    /// A user point in the internal frame (exact unless it becomes subnormal there).
    pub(crate) fn to_internal(&self, x: [f64; D]) -> [f64; D] {
        x.map(|v| ldexp(v, -self.exponent))
    }

    /// An internal point in user units (exact).
    pub(crate) fn to_user(&self, x: [f64; D]) -> [f64; D] {
        x.map(|v| ldexp(v, self.exponent))
    }

    /// An internal length, area (`power` 2) or volume (`power` 3) in user units: exact, or
    /// `inf`/`0` where the doubles cannot hold it.
    pub(crate) fn measure_to_user(&self, x: f64, power: i32) -> f64 {
        ldexp(x, (self.exponent * power).clamp(-2100, 2100))
    }

    /// The lattice vectors (rows).
    pub fn vectors(&self) -> [[f64; D]; D] {
        self.rows.m.map(|r| self.to_user(r))
    }

    /// How much a Cartesian move of length `r` (internal frame) can change each fractional
    /// coordinate: `r` times the length of the matching column of `M⁻¹`.
    pub(crate) fn fractional_reach(&self, r: f64) -> [f64; D] {
        std::array::from_fn(|c| {
            let col: f64 = (0..D)
                .map(|k| {
                    let unit: [f64; D] = std::array::from_fn(|j| if j == k { 1.0 } else { 0.0 });
                    self.fractional_in(&unit)[c].powi(2)
                })
                .sum();
            r * col.sqrt()
        })
    }

    /// Volume (area in 2D) of the domain in the internal frame.
    pub(crate) fn volume_in(&self) -> f64 {
        self.volume
    }

    /// Length of the shortest non-zero lattice vector (δ).
    pub fn systole(&self) -> f64 {
        self.measure_to_user(self.systole, 1)
    }

    /// Volume (area in 2D) of the domain; `inf` or `0` when the doubles cannot hold it (a
    /// 3D box of side beyond about `5.6e102` or below `6.1e-103`).
    pub fn volume(&self) -> f64 {
        self.measure_to_user(self.volume, D as i32)
    }

    /// Ok when the domain volume is a normal double, so that the Voronoi volumes, which sum
    /// to it, can be represented in the user's units (a cell far smaller than the domain may
    /// still be subnormal); the typed error otherwise.
    pub fn check_volume_representable(&self) -> Result<()> {
        if self.volume().is_normal() {
            Ok(())
        } else {
            Err(Error::UnrepresentableVolume {
                log2: self.volume.log2() + (self.exponent * D as i32) as f64,
            })
        }
    }

    /// Fractional (lattice) coordinates `x·M⁻¹`, approximately.
    pub fn fractional(&self, x: &[f64; D]) -> [f64; D] {
        self.fractional_in(&self.to_internal(*x))
    }

    /// Cartesian coordinates of fractional coordinates.
    pub fn cartesian(&self, f: &[f64; D]) -> [f64; D] {
        self.to_user(self.cartesian_in(f))
    }

    /// Wraps a point into the half-open domain. Returns the wrapped point and whether it
    /// moved, or `None` for a triclinic lattice when the point is so far away (beyond about
    /// `2^50` periods) that no exact wrap exists in floating point. For a box, the result lies
    /// exactly in `[0, L)` per axis (a point on the upper face goes to 0); for a triclinic
    /// lattice the domain test uses rounded fractional coordinates.
    pub fn wrap(&self, x: [f64; D]) -> Option<([f64; D], bool)> {
        self.wrap_in(x).map(|(y, moved)| (self.to_user(y), moved))
    }

    /// [`Self::wrap`] into the internal frame.
    pub(crate) fn wrap_in(&self, x: [f64; D]) -> Option<([f64; D], bool)> {
        // `-0.0 + 0.0 = +0.0`: one zero, so that coordinate comparisons agree with geometry
        let x = x.map(|v| v + 0.0);
        if self.rows.diagonal {
            let mut y = x;
            let mut moved = false;
            for (c, yc) in y.iter_mut().enumerate() {
                let l = ldexp(self.rows.m[c][c], self.exponent);
                if *yc >= 0.0 && *yc < l {
                    continue;
                }
                moved = true;
                // the remainder is exact at every magnitude (IEEE fmod); only adding the
                // period to a negative one rounds
                let mut v = *yc % l;
                if v < 0.0 {
                    v += l;
                    if v >= l {
                        v = 0.0;
                    }
                }
                *yc = v + 0.0;
            }
            return Some((self.to_internal(y), moved));
        }
        let mut y = self.to_internal(x);
        if y.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let mut moved = false;
        for _ in 0..4 {
            let f = self.fractional_in(&y);
            if f.iter().all(|v| (0.0..1.0).contains(v)) {
                return Some((y, moved));
            }
            if f.iter().any(|v| v.abs() > 1e15) {
                return None;
            }
            moved = true;
            let mut shift = [0.0; D];
            for c in 0..D {
                let k = f[c].floor();
                // A coordinate that floors to 0 but rounds to 1 sits on the upper face.
                shift[c] = if k == 0.0 && f[c] >= 1.0 { 1.0 } else { k };
            }
            let s = self.cartesian_in(&shift);
            for c in 0..D {
                y[c] -= s[c];
            }
        }
        // rounding may leave a point a hair outside: close enough for the engine's offsets
        let f = self.fractional_in(&y);
        f.iter()
            .all(|v| (-1e-9..1.0 + 1e-9).contains(v))
            .then_some((y, moved))
    }

    /// Fractional coordinates of an internal point.
    pub(crate) fn fractional_in(&self, x: &[f64; D]) -> [f64; D] {
        let mut f = [0.0; D];
        for (c, fc) in f.iter_mut().enumerate() {
            for k in 0..D {
                *fc += x[k] * self.inv[k][c];
            }
        }
        f
    }

    /// The internal point of fractional coordinates.
    pub(crate) fn cartesian_in(&self, f: &[f64; D]) -> [f64; D] {
        let mut x = [0.0; D];
        for (k, fk) in f.iter().enumerate() {
            for (c, xc) in x.iter_mut().enumerate() {
                *xc += fk * self.rows.m[k][c];
            }
        }
        x
    }

    /// The systole in the internal frame.
    pub(crate) fn systole_in(&self) -> f64 {
        self.systole
    }

    /// The covering used for tiny point sets: `h_i` copies along lattice vector `i` such that
    /// the systole of the sublattice `{Σ h_i x_i b_i}` exceeds twice the largest empty-ball
    /// diameter a single point can leave, `√(Σ|b_i|²)` (covering radius ≤ ½√(Σ|b_i*|²));
    /// Corollary 9 of Caroli–Teillaud then makes the covering a triangulation for any point
    /// set (Lemma 2.3.8 of the thesis for cuboids). A cube uses 3 per axis (Theorem 2.2.8).
    /// At most [`MAX_COPIES`] per axis: more elongated boxes are rejected at construction.
    pub fn covering(&self) -> [i32; D] {
        self.covering_search().0
    }

    /// [`Self::covering`] and the number of steps its search took: each step adds one copy
    /// along one vector, and the search stops once a count exceeds [`MAX_COPIES`], so it
    /// takes at most `D·MAX_COPIES + 1` steps whatever the lattice.
    fn covering_search(&self) -> ([i32; D], usize) {
        let l0 = self.rows.m[0][0];
        if self.rows.diagonal && (0..D).all(|i| self.rows.m[i][i] == l0) {
            return ([3; D], 0);
        }
        self.covering_search_for(self.one_point_need())
    }

    /// The diagonal covering `h` (copies per lattice vector) whose systole exceeds `big`
    /// (internal frame), grown from below along the shortest `h_i·b_i`, and the steps taken.
    fn covering_search_for(&self, big: f64) -> ([i32; D], usize) {
        let mut steps = 0;
        // start below the answer and grow the copies along the currently shortest vector
        let mut h: [i32; D] =
            std::array::from_fn(|i| ((big / norm(&self.rows.m[i])).floor() as i32).max(1));
        while shortest_vector(&self.rows, &diagonal_basis(h)) <= big {
            if h.iter().any(|&x| x > MAX_COPIES) {
                // no acceptable covering: `covering_or_error` reports it
                break;
            }
            let i = (0..D).min_by(|&a, &b| {
                let la = h[a] as f64 * norm(&self.rows.m[a]);
                let lb = h[b] as f64 * norm(&self.rows.m[b]);
                la.total_cmp(&lb)
            });
            h[i.unwrap()] += 1;
            steps += 1;
        }
        (h, steps)
    }

    /// Twice the largest empty-ball diameter one point's orbit can leave, bounded by
    /// `√(Σ|b_i|²)` (covering radius ≤ ½√(Σ|b_i|²)), with a relative margin: a covering whose
    /// systole exceeds it triangulates every non-empty point set.
    pub(crate) fn one_point_need(&self) -> f64 {
        2.0 * self.rows.m.iter().map(|r| dot(r, r)).sum::<f64>().sqrt() * (1.0 + 1e-9)
    }

    /// The two-level ladder of a space whose translations are this lattice and whose one
    /// point leaves empty balls of diameter below `need/2` (internal frame): the diagonal
    /// covering whose systole exceeds `need`, then the lattice itself.
    pub(crate) fn grid_ladder_for(&self, need: f64) -> Vec<Level<D>> {
        let (h, _) = self.covering_search_for(need);
        vec![
            Level {
                sub: Sublattice::diagonal(h),
                systole: shortest_vector(&self.rows, &diagonal_basis(h)),
            },
            Level {
                sub: Sublattice::identity(),
                systole: self.systole,
            },
        ]
    }

    /// The coverings a triangulation passes through on its way to the torus: level 0
    /// triangulates any non-empty point set, each next level has fewer sheets, the last is the
    /// torus itself (`Z^D`). [`Ladder::Halving`] falls back to [`Ladder::Grid`] when its
    /// offsets would not fit the 8-bit range.
    pub fn ladder(&self, kind: Ladder) -> Vec<Level<D>> {
        self.ladder_for(kind, self.one_point_need())
    }

    /// [`Self::ladder`] whose level 0 has a systole above `need` (internal frame) instead
    /// of [`Self::one_point_need`] (weighted points ask more). `None` when no covering of at
    /// most [`MAX_COPIES`] copies per vector is long enough.
    pub(crate) fn weighted_ladder(&self, kind: Ladder, need: f64) -> Option<Vec<Level<D>>> {
        let ladder = self.ladder_for(kind, need);
        (ladder[0].systole > need).then_some(ladder)
    }

    /// The covering of two copies along each vector, when a ladder's only covering has more
    /// sheets (a 3D grid: 8 sheets against 27): its systole is twice the lattice's, so that
    /// a point set with no empty ball of that systole's half (a slab beside a vacuum thinner
    /// than the box) is triangulated there. It lies between level 0 and the torus but is no
    /// cover of level 0, so it is never descended to: the engine lifts a quotient to it
    /// (`Engine::unfold`) before trying level 0.
    pub(crate) fn lift_level(&self, ladder: &[Level<D>]) -> Option<Level<D>> {
        let sub = Sublattice::diagonal([2; D]);
        (ladder.len() == 2 && sub.index() < ladder[0].sub.index()).then(|| Level {
            systole: shortest_vector(&self.rows, &diagonal_basis([2; D])),
            sub,
        })
    }

    /// The longest systole a diagonal covering of at most [`MAX_COPIES`] copies per vector
    /// reaches (internal frame).
    pub(crate) fn longest_covering_systole(&self) -> f64 {
        shortest_vector(&self.rows, &diagonal_basis([MAX_COPIES; D]))
    }

    fn ladder_for(&self, kind: Ladder, need: f64) -> Vec<Level<D>> {
        let identity = Level {
            sub: Sublattice::identity(),
            systole: self.systole,
        };
        let unweighted = need == self.one_point_need();
        let grid = || {
            let h = if unweighted {
                self.covering()
            } else {
                self.covering_search_for(need).0
            };
            vec![
                Level {
                    sub: Sublattice::diagonal(h),
                    systole: shortest_vector(&self.rows, &diagonal_basis(h)),
                },
                identity.clone(),
            ]
        };
        // In 3D an index-2^k covering safe for one point of a cube has at least 32 sheets
        // (Hermite's constant bounds its systole: δ³ ≤ √2·index, and δ > 2√3 is needed), more
        // than the grid's 27: halving is for 2D.
        if kind == Ladder::Grid || D != 2 {
            return grid();
        }
        let mut chain = vec![identity.clone()];
        let mut basis = diagonal_basis([1; D]);
        while chain.last().unwrap().systole <= need {
            if chain.len() > 2 * D * 6 {
                return grid();
            }
            // among the 2^D − 1 sublattices of index 2, the one with the longest shortest vector
            let (best, systole) = (1..1usize << D)
                .map(|phi| {
                    let b = reduce_basis(&self.rows, index_two(&basis, phi));
                    (b, shortest_vector(&self.rows, &b))
                })
                .fold(None, |acc: Option<([[i32; D]; D], f64)>, cand| match acc {
                    Some(a) if a.1 >= cand.1 => Some(a),
                    _ => Some(cand),
                })
                .unwrap();
            basis = best;
            chain.push(Level {
                sub: Sublattice::new(best),
                systole,
            });
        }
        if chain
            .iter()
            .any(|l| (0..D).any(|c| l.sub.span(c) > MAX_COPIES))
        {
            return grid();
        }
        chain.reverse();
        // a level no longer than the next one is entered only together with it: skip it
        let mut k = 1;
        while k + 1 < chain.len() {
            if chain[k].systole <= chain[k + 1].systole * (1.0 + 1e-12) {
                chain.remove(k);
            } else {
                k += 1;
            }
        }
        chain
    }

    /// A jittered grid of `Π k_i` dummy points in fractional coordinates whose largest empty
    /// ball has diameter below `δ/2`: with `S = √(Σ|b_i/k_i|²)` the grid's empty balls have
    /// diameter at most `S`, the jitter (2% of a grid step per axis) adds at most `0.04·S`,
    /// and `k_i` is chosen so that `1.04·S < δ/2`.
    pub fn dummy_grid(&self) -> Vec<[f64; D]> {
        self.dummy_grid_for(self.systole, 0, 1)
    }

    /// [`Self::dummy_grid`] for a space of systole `systole` (internal frame) whose domain
    /// is the part of this lattice's below `1/parts` along `axis`: the counts along `axis`
    /// are a multiple of `parts`, and only the grid points in that slab are kept (the
    /// space's group maps them onto the others).
    pub(crate) fn dummy_grid_for(&self, systole: f64, axis: usize, parts: usize) -> Vec<[f64; D]> {
        let mut k = [0usize; D];
        for i in 0..D {
            let x = norm(&self.rows.m[i]) * (D as f64).sqrt() * 2.0 * 1.04 / systole;
            k[i] = (x.floor() as usize + 1).max(2);
        }
        k[axis] = k[axis].div_ceil(parts) * parts;
        let keep = k[axis] / parts;
        let total: usize = k.iter().product();
        let mut rng = crate::sort::SplitMix::new(0x0b17_2a11);
        let mut out = Vec::with_capacity(total / parts);
        for idx in 0..total {
            let mut rem = idx;
            let mut f = [0.0; D];
            let mut inside = true;
            for i in 0..D {
                let g = rem % k[i];
                rem /= k[i];
                let jitter = 0.02 * (2.0 * rng.unit() - 1.0);
                f[i] = (g as f64 + 0.5 + jitter) / k[i] as f64;
                inside &= i != axis || g < keep;
            }
            // inside the domain by construction (f ∈ (0, 1)): no wrap, no trip to user units
            if inside {
                out.push(self.cartesian_in(&f));
            }
        }
        out
    }
}

/// The sublattice of index 2 of the lattice spanned by `basis`: the kernel of
/// `x ↦ φ·x mod 2` for the non-zero parity vector `phi` (a bit per generator).
fn index_two<const D: usize>(basis: &[[i32; D]; D], phi: usize) -> [[i32; D]; D] {
    let j = phi.trailing_zeros() as usize;
    std::array::from_fn(|i| {
        if i == j {
            basis[j].map(|x| 2 * x)
        } else if phi >> i & 1 == 1 {
            std::array::from_fn(|c| basis[i][c] + basis[j][c])
        } else {
            basis[i]
        }
    })
}

fn diagonal_basis<const D: usize>(h: [i32; D]) -> [[i32; D]; D] {
    std::array::from_fn(|i| std::array::from_fn(|j| if i == j { h[i] } else { 0 }))
}

fn dot<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm<const D: usize>(a: &[f64; D]) -> f64 {
    dot(a, a).sqrt()
}

/// The Cartesian vectors `basis·M` of a sublattice given in lattice units.
fn cartesian_basis<const D: usize>(rows: &Rows<D>, basis: &[[i32; D]; D]) -> [[f64; D]; D] {
    std::array::from_fn(|k| {
        let mut v = [0.0; D];
        for j in 0..D {
            for c in 0..D {
                v[c] += basis[k][j] as f64 * rows.m[j][c];
            }
        }
        v
    })
}

/// Shortest non-zero vector of the sublattice spanned by `basis·M` (enumeration, exact for
/// bases with orthogonality defect at most [`MAX_DEFECT`]).
fn shortest_vector<const D: usize>(rows: &Rows<D>, basis: &[[i32; D]; D]) -> f64 {
    let b = cartesian_basis(rows, basis);
    let side = (2 * ENUM + 1) as usize;
    let total = side.pow(D as u32);
    let mut best = f64::INFINITY;
    for idx in 0..total {
        let mut rem = idx;
        let mut t = [0i32; D];
        for tc in t.iter_mut() {
            *tc = (rem % side) as i32 - ENUM;
            rem /= side;
        }
        if t.iter().all(|&v| v == 0) {
            continue;
        }
        let mut v = [0.0; D];
        for k in 0..D {
            for c in 0..D {
                v[c] += t[k] as f64 * b[k][c];
            }
        }
        best = best.min(norm(&v));
    }
    best
}

/// Reduces an integer basis for the Cartesian metric by pairwise Lagrange steps (Lagrange's
/// algorithm in 2D), so that enumeration finds its shortest vector.
fn reduce_basis<const D: usize>(rows: &Rows<D>, mut basis: [[i32; D]; D]) -> [[i32; D]; D] {
    loop {
        let mut changed = false;
        for i in 0..D {
            for j in 0..D {
                if i == j {
                    continue;
                }
                let b = cartesian_basis(rows, &basis);
                let mu = (dot(&b[i], &b[j]) / dot(&b[i], &b[i])).round();
                let shorter: [f64; D] = std::array::from_fn(|c| b[j][c] - mu * b[i][c]);
                // strictly shorter only: the loop ends on a discrete lattice
                if mu != 0.0 && dot(&shorter, &shorter) < dot(&b[j], &b[j]) * (1.0 - 1e-12) {
                    for c in 0..D {
                        basis[j][c] -= mu as i32 * basis[i][c];
                    }
                    changed = true;
                }
            }
        }
        if !changed {
            return basis;
        }
    }
}

/// Determinant and inverse by Gauss–Jordan elimination with partial pivoting.
fn invert<const D: usize>(m: &[[f64; D]; D]) -> (f64, [[f64; D]; D]) {
    let mut a = *m;
    let mut inv = [[0.0; D]; D];
    for (i, r) in inv.iter_mut().enumerate() {
        r[i] = 1.0;
    }
    let mut det = 1.0;
    for col in 0..D {
        let piv = (col..D)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        if a[piv][col] == 0.0 {
            return (0.0, inv);
        }
        if piv != col {
            a.swap(piv, col);
            inv.swap(piv, col);
            det = -det;
        }
        let p = a[col][col];
        det *= p;
        for j in 0..D {
            a[col][j] /= p;
            inv[col][j] /= p;
        }
        for r in 0..D {
            if r != col {
                let f = a[r][col];
                if f != 0.0 {
                    for j in 0..D {
                        a[r][j] -= f * a[col][j];
                        inv[r][j] -= f * inv[col][j];
                    }
                }
            }
        }
    }
    (det, inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_uses_27_sheets_and_cuboid_lemma_2_3_8() {
        assert_eq!(
            Lattice::cuboid([1.0, 1.0, 1.0]).unwrap().covering(),
            [3, 3, 3]
        );
        // Lemma 2.3.8: h_i > 2‖c‖/c_i for c = (1, 1, 2): ‖c‖ = √6 → h = (5, 5, 3)
        assert_eq!(
            Lattice::cuboid([1.0, 1.0, 2.0]).unwrap().covering(),
            [5, 5, 3]
        );
        assert_eq!(
            Lattice::cuboid([1.0, 2.0, 0.5]).unwrap().covering(),
            [5, 3, 10]
        );
        // the covering of an elongated box needs many copies: at most MAX_COPIES per axis
        assert_eq!(Lattice::cuboid([1.0, 1.0, 9.0]).unwrap().covering()[0], 19);
        assert!(matches!(
            Lattice::cuboid([1.0, 1.0, 14.0]),
            Err(Error::InvalidBox(_))
        ));
    }

    #[test]
    fn bad_boxes_are_rejected() {
        assert!(matches!(
            Lattice::cuboid([1.0, 0.0, 1.0]),
            Err(Error::InvalidBox(_))
        ));
        assert!(matches!(
            Lattice::cuboid([1.0, -2.0, 1.0]),
            Err(Error::InvalidBox(_))
        ));
        assert!(matches!(
            Lattice::cuboid([1.0, f64::NAN, 1.0]),
            Err(Error::InvalidBox(_))
        ));
        let singular = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        assert!(matches!(
            Lattice::new(singular),
            Err(Error::SingularLattice { .. })
        ));
        let skewed = [[1.0, 0.0, 0.0], [10.0, 0.1, 0.0], [0.0, 0.0, 1.0]];
        assert!(matches!(
            Lattice::new(skewed),
            Err(Error::SkewedLattice { .. })
        ));
    }

    #[test]
    fn systole_and_volume_of_triclinic() {
        let l = Lattice::new([[1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.3, 0.2, 0.9]]).unwrap();
        assert!((l.volume() - 0.9).abs() < 1e-12);
        assert!((l.systole() - 0.9f64.hypot(0.2).hypot(0.3).min(1.0)).abs() < 1e-12);
    }

    #[test]
    fn wrapping_lands_in_the_half_open_domain() {
        let b = Lattice::cuboid([1.0, 2.0, 1.0]).unwrap();
        assert_eq!(b.wrap([1.0, 2.0, -1e-20]), Some(([0.0, 0.0, 0.0], true)));
        assert_eq!(b.wrap([0.5, 0.5, 0.5]), Some(([0.5, 0.5, 0.5], false)));
        assert!(b.wrap([-0.0, 0.5, 0.5]).unwrap().0[0].is_sign_positive());
        assert_eq!(b.wrap([-0.25, 4.5, 3.75]).unwrap().0, [0.75, 0.5, 0.75]);
        // a box wraps exactly at any distance (IEEE remainder)
        assert_eq!(b.wrap([1e300 + 0.0, 0.5, 0.5]).unwrap().0[0], 1e300 % 1.0);
        assert_eq!(b.wrap([-1e300, 0.5, 0.5]).unwrap().0[0], 0.0);
        let t = Lattice::new([[1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.3, 0.2, 0.9]]).unwrap();
        // a triclinic lattice cannot wrap a point 1e300 periods away exactly
        assert_eq!(t.wrap([1e300, 0.0, 0.0]), None);
        for x in [[2.3, -1.7, 5.1], [-0.1, -0.1, -0.1], [1.8, 1.2, 0.95]] {
            let (y, _) = t.wrap(x).unwrap();
            let f = t.fractional(&y);
            assert!(f.iter().all(|v| (-1e-12..1.0).contains(v)), "{f:?}");
            // y − x is a lattice vector
            let d = t.fractional(&[y[0] - x[0], y[1] - x[1], y[2] - x[2]]);
            assert!(d.iter().all(|v| (v - v.round()).abs() < 1e-9));
        }
    }

    #[test]
    fn halving_ladders_are_nested_and_safe() {
        let h = 3f64.sqrt() / 2.0;
        for l in [
            Lattice::cuboid([1.0, 1.0]).unwrap(),
            Lattice::cuboid([1.0, 3.0]).unwrap(),
            Lattice::new([[1.0, 0.0], [0.5, h]]).unwrap(),
            Lattice::new([[1.0, 0.0], [-0.35, 0.8]]).unwrap(),
        ] {
            let ladder = l.ladder(Ladder::Halving);
            assert!(ladder.last().unwrap().sub.is_identity());
            // level 0 triangulates a single point
            assert!(ladder[0].systole > l.one_point_need());
            for w in ladder.windows(2) {
                // each level is a sublattice of the next, of index a power of two
                for row in w[0].sub.rows() {
                    assert_eq!(w[1].sub.reduce(row), [0, 0]);
                }
                let ratio = w[0].sub.index() / w[1].sub.index();
                assert!(ratio.is_power_of_two() && ratio >= 2);
                // and a strictly longer shortest vector, else the level would be useless
                assert!(w[0].systole > w[1].systole);
                // the systole is that of the sublattice, checked by brute force
                let m = l.vectors();
                let rows = w[0].sub.rows();
                let mut best = f64::INFINITY;
                for x in -6i32..=6 {
                    for y in -6i32..=6 {
                        if (x, y) == (0, 0) {
                            continue;
                        }
                        let t = [
                            x * rows[0][0] + y * rows[1][0],
                            x * rows[0][1] + y * rows[1][1],
                        ];
                        let v = [
                            t[0] as f64 * m[0][0] + t[1] as f64 * m[1][0],
                            t[0] as f64 * m[0][1] + t[1] as f64 * m[1][1],
                        ];
                        best = best.min(v[0].hypot(v[1]));
                    }
                }
                assert!(
                    (best - w[0].systole * l.unit()).abs() < 1e-12,
                    "{best} {}",
                    w[0].systole
                );
            }
        }
        // the grid ladder is the thesis's covering, also what 3D gets for halving
        for kind in [Ladder::Grid, Ladder::Halving] {
            let cube = Lattice::cuboid([1.0; 3]).unwrap().ladder(kind);
            assert_eq!(
                cube.iter().map(|l| l.sub.index()).collect::<Vec<_>>(),
                [27, 1]
            );
        }
    }

    #[test]
    fn ldexp_is_exact_scaling_with_one_rounding() {
        for x in [1.0, -3.5, 0.1, 1e-310, 5e-324, f64::MAX, 1.5e300] {
            for k in [-2200, -1100, -1074, -600, -1, 0, 1, 600, 1100, 2200] {
                let want = if k >= 0 {
                    (0..k).fold(x, |a, _| a * 2.0)
                } else {
                    // exact halving down to where it would round: compare with powi on
                    // representable cases only
                    let y = (0..-k).fold(x, |a, _| a / 2.0);
                    if y != 0.0 && y.abs() < f64::MIN_POSITIVE {
                        continue;
                    }
                    y
                };
                assert_eq!(ldexp(x, k), want, "{x} {k}");
            }
        }
        // one rounding into the subnormals: 1.75·2^-1074 rounds to 2^-1073
        assert_eq!(ldexp(1.75, -1074), 2.0 * 5e-324);
        assert_eq!(ldexp(1.0, -1075), 0.0);
        assert_eq!(ldexp(1.5, -1075), 5e-324);
        assert_eq!(exponent_of(5e-324), -1074);
        assert_eq!(exponent_of(1.0), 0);
        assert_eq!(exponent_of(-3.0), 1);
    }

    #[test]
    fn the_internal_frame_is_a_power_of_two() {
        for scale in [1e-300, 1e-120, 1.0, 3.0, 1e110, 1e300] {
            let l = Lattice::cuboid([scale, scale, 2.0 * scale]).unwrap();
            let m = l.rows.m;
            assert!((1.0..2.0).contains(&m[2][2]), "{m:?}");
            assert_eq!(l.vectors()[2][2], 2.0 * scale);
            assert_eq!(l.unit().log2().fract(), 0.0);
        }
        assert!(Lattice::cuboid([1e100; 3])
            .unwrap()
            .check_volume_representable()
            .is_ok());
        assert!(matches!(
            Lattice::cuboid([1e110; 3]).unwrap().check_volume_representable(),
            Err(Error::UnrepresentableVolume { log2 }) if (log2 - 1096.0).abs() < 1.0
        ));
        assert!(Lattice::cuboid([1e-110; 3])
            .unwrap()
            .check_volume_representable()
            .is_err());
        assert!(Lattice::cuboid([1e-110; 2])
            .unwrap()
            .check_volume_representable()
            .is_ok());
    }

    /// Elongated and skewed lattices: the covering search ends within its step bound (a
    /// step count, not the clock), with a covering or the "too elongated" error.
    #[test]
    fn covering_search_is_bounded() {
        let mut seed = 99u64;
        let mut unit = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..400 {
            let l: [f64; 3] = std::array::from_fn(|_| 2f64.powf(12.0 * unit() - 6.0));
            let t: [f64; 3] = std::array::from_fn(|_| unit() - 0.5);
            let m = [
                [l[0], 0.0, 0.0],
                [t[0] * l[0], l[1], 0.0],
                [t[1] * l[0], t[2] * l[1], l[2]],
            ];
            let Ok(lattice) = Lattice::new(m) else {
                continue;
            };
            let (h, steps) = lattice.covering_search();
            assert!(
                steps <= 3 * MAX_COPIES as usize + 1,
                "{steps} steps for {m:?}"
            );
            assert!(h.iter().all(|&x| x <= MAX_COPIES));
            // and the search from an unchecked lattice stops too
            let raw = Lattice {
                rows: Rows {
                    m: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1e-3]],
                    diagonal: true,
                },
                ..lattice.clone()
            };
            assert!(raw.covering_search().1 <= 3 * MAX_COPIES as usize + 1);
        }
    }

    #[test]
    fn dummy_grid_size() {
        assert_eq!(Lattice::cuboid([1.0; 3]).unwrap().dummy_grid().len(), 64);
    }
}
