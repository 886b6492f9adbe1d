//! Floating-point evaluation of lifted differences and determinants with certified error
//! bounds. Each function returns `None` when the bound cannot certify the sign.

use super::Sign;

const U: f64 = f64::EPSILON * 0.5;
/// Rows whose magnitude bound lies outside this range skip the filter (no underflow or
/// overflow can then occur in a degree-5 product).
pub(crate) const TINY: f64 = 1.0 / HUGE; // 2^-200
pub(crate) const HUGE: f64 = (1u128 << 100) as f64 * (1u128 << 100) as f64; // 2^200

/// A lattice given by its rows (the lattice vectors), as the predicates need it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rows<const D: usize> {
    pub m: [[f64; D]; D],
    /// True when the matrix is diagonal (cube or cuboid): the lattice sum is one product.
    pub diagonal: bool,
}

impl<const D: usize> Rows<D> {
    /// `t·M` for an integer offset vector, each component with the sum of the absolute
    /// values of its terms (the magnitude the error bound is relative to).
    #[inline]
    pub fn apply(&self, t: [i32; D]) -> ([f64; D], [f64; D]) {
        let mut s = [0.0; D];
        let mut a = [0.0; D];
        if self.diagonal {
            for c in 0..D {
                s[c] = t[c] as f64 * self.m[c][c];
                a[c] = s[c].abs();
            }
        } else {
            for (k, row) in self.m.iter().enumerate() {
                if t[k] == 0 {
                    continue;
                }
                let tk = t[k] as f64;
                for c in 0..D {
                    let v = tk * row[c];
                    s[c] += v;
                    a[c] += v.abs();
                }
            }
        }
        (s, a)
    }
}

/// The lifted difference `(p + t·M) − (p0 + t0·M)` and a bound `B` such that every component
/// is off by at most `6u·B` and at most `B(1+u)` in magnitude.
#[inline(always)]
pub fn lifted_diff<const D: usize>(
    rows: &Rows<D>,
    p: &[f64; D],
    t: [i32; D],
    p0: &[f64; D],
    t0: [i32; D],
) -> ([f64; D], f64) {
    let mut d = [0.0; D];
    let mut dt = [0i32; D];
    let mut any = false;
    for c in 0..D {
        d[c] = p[c] - p0[c];
        dt[c] = t[c] - t0[c];
        any |= dt[c] != 0;
    }
    let mut b = 0.0f64;
    if any {
        let (s, a) = rows.apply(dt);
        for c in 0..D {
            let bc = d[c].abs() + a[c];
            d[c] += s[c];
            b = b.max(bc);
        }
    } else {
        for v in &d {
            b = b.max(v.abs());
        }
    }
    (d, b)
}

/// `p − p0` for two points in the same frame, with the same bound convention as
/// [`lifted_diff`] (here the error is at most `u·B`).
#[inline(always)]
pub fn plain_diff<const D: usize>(p: &[f64; D], p0: &[f64; D]) -> ([f64; D], f64) {
    let mut d = [0.0; D];
    let mut b = 0.0f64;
    for c in 0..D {
        d[c] = p[c] - p0[c];
        b = b.max(d[c].abs());
    }
    (d, b)
}

#[inline]
fn in_range(b: f64) -> bool {
    (TINY..=HUGE).contains(&b) || b == 0.0
}

#[inline]
fn det3(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> f64 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// Orientation of the tetrahedron with edge vectors `d1, d2, d3` (bounds `b`).
///
/// Bound: each of the 6 products of three entries is off by at most `((1+6u)³−1)·B₁B₂B₃(1+u)³
/// ≤ 18.1u·B₁B₂B₃` from the inputs and by at most `5u·B₁B₂B₃` from its own evaluation (two
/// products, one difference, one product, two sums); `6·(18.1+5) < 160`.
#[inline(always)]
pub fn orient3(d: &[[f64; 3]; 3], b: [f64; 3]) -> Option<Sign> {
    if !(in_range(b[0]) && in_range(b[1]) && in_range(b[2])) {
        return None;
    }
    let det = det3(&d[0], &d[1], &d[2]);
    decide(det, 160.0 * U * b[0] * b[1] * b[2])
}

/// In-sphere determinant for rows `d_i = a_i − q` (bounds `b`): positive when `q` is inside
/// the sphere of the positively oriented `a_0..a_3`.
///
/// Bound: the 24 terms `l_i·(three entries of the other rows)` are each at most
/// `3·B_max·ΠB` in magnitude; relative to that, the inputs contribute `3·6u + 15u` (`l_i` is
/// a sum of three squares, each off by `12u·B²`, plus `3u` to evaluate) and the evaluation
/// about `10u`; `72·(43u)·B_max·ΠB < 4096u·B_max·ΠB`.
#[inline(always)]
pub fn in_sphere3(d: &[[f64; 3]; 4], b: [f64; 4]) -> Option<Sign> {
    if !b.iter().all(|&x| in_range(x)) {
        return None;
    }
    let l: [f64; 4] =
        std::array::from_fn(|i| d[i][0] * d[i][0] + d[i][1] * d[i][1] + d[i][2] * d[i][2]);
    let det = -l[0] * det3(&d[1], &d[2], &d[3]) + l[1] * det3(&d[0], &d[2], &d[3])
        - l[2] * det3(&d[0], &d[1], &d[3])
        + l[3] * det3(&d[0], &d[1], &d[2]);
    let bmax = b[0].max(b[1]).max(b[2]).max(b[3]);
    // inside ⇔ det < 0 for this row layout
    decide(-det, 4096.0 * U * bmax * b[0] * b[1] * b[2] * b[3])
}

/// Orientation of the triangle with edge vectors `d1, d2` (bounds `b`).
///
/// Bound: each of the 2 products is off by at most `((1+6u)²−1)·B₁B₂(1+u)² ≤ 12.1u·B₁B₂`
/// from the inputs and `2u·B₁B₂` from its evaluation; `2·14.1 < 64`.
#[inline]
pub fn orient2(d: &[[f64; 2]; 2], b: [f64; 2]) -> Option<Sign> {
    if !(in_range(b[0]) && in_range(b[1])) {
        return None;
    }
    let det = d[0][0] * d[1][1] - d[0][1] * d[1][0];
    decide(det, 64.0 * U * b[0] * b[1])
}

/// In-circle determinant for rows `d_i = a_i − q` (bounds `b`): positive when `q` is inside
/// the circle of the counter-clockwise `a_0, a_1, a_2`.
///
/// Bound: the 6 terms `l_i·(two entries of the other rows)` are each at most `2·B_max·ΠB`;
/// relative to that, the inputs contribute `2·6u + 13u` and the evaluation about `6u`;
/// `12·31u < 1024u`.
#[inline]
pub fn in_circle(d: &[[f64; 2]; 3], b: [f64; 3]) -> Option<Sign> {
    if !b.iter().all(|&x| in_range(x)) {
        return None;
    }
    let l: [f64; 3] = std::array::from_fn(|i| d[i][0] * d[i][0] + d[i][1] * d[i][1]);
    let m = |a: usize, c: usize| d[a][0] * d[c][1] - d[a][1] * d[c][0];
    let det = l[0] * m(1, 2) - l[1] * m(0, 2) + l[2] * m(0, 1);
    let bmax = b[0].max(b[1]).max(b[2]);
    decide(det, 1024.0 * U * bmax * b[0] * b[1] * b[2])
}

/// In-sphere determinant for rows `d_i = a_i − q` (bounds `b`, `N = D + 1`, `D` 2 or 3) in
/// coordinates whose squared length is `xᵀ·G·x`: positive when `q` is inside the sphere of
/// the positively oriented `a_0..a_D`. `g` holds `G`'s entries, each within `u` of the exact
/// one relative to it, and `gsum` their absolute sum, at most 2.
///
/// Bound: each lifted length `l_i = Σ G_jk d_ij d_ik` is at most `gsum·B_i²` and off by at
/// most `(12.1 + 1 + 2 + D²)u` of that (inputs, `G`, two products, the sum); each minor's
/// `D!` products of `D` entries are off by `(6.1D + D − 1 + D!)u` of `D!·ΠB`; the
/// `(D+1)·D!` terms `l_i·(product)` are each at most `gsum·B_max·ΠB`: below `1260u` of
/// `gsum·B_max·ΠB` in 3D and `240u` in 2D, bounded by `2048u` and `512u`. Entries of `G`
/// below `2⁻⁶⁰` of the largest are refused by the caller, so nothing underflows.
#[inline]
pub fn in_sphere_metric<const D: usize, const N: usize>(
    d: &[[f64; D]; N],
    b: [f64; N],
    g: &[[f64; D]; D],
    gsum: f64,
) -> Option<Sign> {
    if !b.iter().all(|&x| in_range(x)) {
        return None;
    }
    let l: [f64; N] = std::array::from_fn(|i| {
        let mut s = 0.0;
        for j in 0..D {
            for k in 0..D {
                s += g[j][k] * d[i][j] * d[i][k];
            }
        }
        s
    });
    let det = expand_lifts(d, &l);
    let bmax = b.iter().fold(0.0f64, |m, &x| m.max(x));
    let prod: f64 = b.iter().product();
    let c = if D == 2 { 512.0 } else { 2048.0 };
    // inside ⇔ the determinant has the sign of (−1)^D
    let inside = if D & 1 == 0 { det } else { -det };
    decide(inside, c * U * gsum * bmax * prod)
}

/// Power test of weighted points for rows `d_i = a_i − q` (bounds `b`, `N = D + 1`, `D` 2 or
/// 3) and weight differences `dw_i = w_i − w_q` (each within `u` of the exact difference):
/// positive when `q` is in conflict with the positively oriented `a_0..a_D`, i.e. its power
/// distance to their orthogonal sphere is negative. The lifts are `l_i = |d_i|² − dw_i`;
/// with equal weights this is the in-sphere determinant.
///
/// Bound: with `Λ_i = D·B_i² + |dw_i|`, each lift is off by at most `(12.1 + D + 3)u·Λ_i`
/// (inputs, the sum of squares, `dw_i`, the subtraction); each minor's `D!` products of `D`
/// entries by `(6.1D + D − 1 + D!)u` of `D!·Π_{j≠i}B_j`; a term `l_i·minor_i` by at most
/// `50u·D!·Λ_i·Π_{j≠i}B_j` and the sum of the `N` terms by `Nu` of their magnitudes: below
/// `330u·T` in 3D with `T = Σ_i Λ_i·Π_{j≠i}B_j`, bounded by `1024u·T`. Lifts outside
/// `[2⁻⁴⁰⁰, 2⁴⁰⁰]` (unless zero) skip the filter, so nothing underflows or overflows.
#[inline]
pub fn power<const D: usize, const N: usize>(
    d: &[[f64; D]; N],
    b: [f64; N],
    dw: [f64; N],
) -> Option<Sign> {
    if !b.iter().all(|&x| in_range(x)) {
        return None;
    }
    let mut lambda = [0.0; N];
    for i in 0..N {
        lambda[i] = D as f64 * b[i] * b[i] + dw[i].abs();
        if !(lambda[i] == 0.0 || (TINY * TINY..=HUGE * HUGE).contains(&lambda[i])) {
            return None;
        }
    }
    let l: [f64; N] = std::array::from_fn(|i| {
        let mut s = 0.0;
        for c in 0..D {
            s += d[i][c] * d[i][c];
        }
        s - dw[i]
    });
    let det = expand_lifts(d, &l);
    let t: f64 = (0..N)
        .map(|i| lambda[i] * (0..N).filter(|&k| k != i).map(|k| b[k]).product::<f64>())
        .sum();
    // in conflict ⇔ the determinant has the sign of (−1)^D
    let inside = if D & 1 == 0 { det } else { -det };
    decide(inside, 1024.0 * U * t)
}

/// The determinant of the `(D+1)×(D+1)` matrix whose rows are `(d_i, l_i)`, expanded along
/// its last column: `Σ_i ± l_i · det(d without row i)` (`D` 2 or 3).
#[inline(always)]
fn expand_lifts<const D: usize, const N: usize>(d: &[[f64; D]; N], l: &[f64; N]) -> f64 {
    let mut det = 0.0;
    for (i, li) in l.iter().enumerate() {
        let mut rows = [&[][..]; 3];
        for (slot, k) in (0..N).filter(|&k| k != i).enumerate() {
            rows[slot] = &d[k][..];
        }
        let minor = if D == 2 {
            rows[0][0] * rows[1][1] - rows[0][1] * rows[1][0]
        } else {
            rows[0][0] * (rows[1][1] * rows[2][2] - rows[1][2] * rows[2][1])
                - rows[0][1] * (rows[1][0] * rows[2][2] - rows[1][2] * rows[2][0])
                + rows[0][2] * (rows[1][0] * rows[2][1] - rows[1][1] * rows[2][0])
        };
        // cofactor sign along the last column
        if (i + D) & 1 == 0 {
            det += li * minor;
        } else {
            det -= li * minor;
        }
    }
    det
}

/// The sign of `det` when its error is below `err`; an exact zero when everything is zero.
#[inline]
fn decide(det: f64, err: f64) -> Option<Sign> {
    if det > err {
        Some(Sign::Positive)
    } else if det < -err {
        Some(Sign::Negative)
    } else if err == 0.0 {
        Some(Sign::Zero)
    } else {
        None
    }
}

/// Sign of one lifted coordinate difference component with its bound, or `None`.
#[inline]
pub fn component(d: f64, b: f64) -> Option<Sign> {
    decide(d, 6.0 * U * b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_tetrahedron_signs() {
        let d = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(orient3(&d, [1.0; 3]), Some(Sign::Positive));
        let q = [0.25, 0.25, 0.25];
        let a = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let rows: [[f64; 3]; 4] = std::array::from_fn(|i| std::array::from_fn(|c| a[i][c] - q[c]));
        assert_eq!(in_sphere3(&rows, [1.0; 4]), Some(Sign::Positive));
        let far: [[f64; 3]; 4] = std::array::from_fn(|i| std::array::from_fn(|c| a[i][c] - 5.0));
        assert_eq!(in_sphere3(&far, [6.0; 4]), Some(Sign::Negative));
    }

    #[test]
    fn near_degenerate_is_undecided() {
        // four coplanar points: the filter must not claim a sign
        let d = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        assert_eq!(orient3(&d, [1.0; 3]), None);
        assert_eq!(component(1e-30, 1.0), None);
        assert_eq!(component(0.5, 1.0), Some(Sign::Positive));
    }

    #[test]
    fn lattice_sums() {
        let r = Rows {
            m: [[1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.0, 0.0, 2.0]],
            diagonal: false,
        };
        let (s, a) = r.apply([1, -2, 1]);
        assert_eq!(s, [0.0, -2.0, 2.0]);
        assert_eq!(a, [2.0, 2.0, 2.0]);
        let (d, b) = lifted_diff(
            &r,
            &[0.25, 0.5, 0.5],
            [1, 0, 0],
            &[0.25, 0.5, 0.5],
            [0, 0, 0],
        );
        assert_eq!(d, [1.0, 0.0, 0.0]);
        assert_eq!(b, 1.0);
    }
}
