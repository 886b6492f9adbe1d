//! Exact evaluation with big integers. Every finite double is `m·2^e` with an integer `m`;
//! scaling all values of one predicate by the same power of two turns them into integers
//! without changing any sign, so determinants are computed exactly on `BigInt`s.

use num_bigint::BigInt;
use num_traits::{Signed, Zero};

use super::Sign;

/// Splits a finite double into `(m, e)` with `x = m·2^e` and `m` odd (or zero).
pub(crate) fn decompose(x: f64) -> (i64, i32) {
    if x == 0.0 {
        return (0, 0);
    }
    let bits = x.to_bits();
    let sign = if bits >> 63 == 1 { -1 } else { 1 };
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = bits & ((1u64 << 52) - 1);
    let (mut m, mut e) = if exp == 0 {
        (frac as i64, -1074)
    } else {
        ((frac | (1u64 << 52)) as i64, exp - 1075)
    };
    let tz = m.trailing_zeros() as i32;
    m >>= tz;
    e += tz;
    (sign * m, e)
}

/// A set of doubles brought to a common scale `2^emin`, as big integers.
pub struct Scaled {
    emin: i32,
}

impl Scaled {
    /// The common scale of `values` (all finite).
    pub fn new(values: impl IntoIterator<Item = f64>) -> Scaled {
        let emin = values
            .into_iter()
            .filter(|v| *v != 0.0)
            .map(|v| decompose(v).1)
            .min()
            .unwrap_or(0);
        Scaled { emin }
    }

    /// The common scale of lengths `values` and squared lengths `squares` (weights, all
    /// finite): the lengths are integers at `2^emin`, the squares at `2^(2·emin)`.
    pub fn with_squares(
        values: impl IntoIterator<Item = f64>,
        squares: impl IntoIterator<Item = f64>,
    ) -> Scaled {
        let e = Scaled::new(values).emin;
        let half = squares
            .into_iter()
            .filter(|v| *v != 0.0)
            .map(|v| decompose(v).1.div_euclid(2))
            .min()
            .unwrap_or(e);
        Scaled { emin: e.min(half) }
    }

    /// `x / 2^(2·emin)` as an exact integer (a squared length, see [`Self::with_squares`]).
    pub fn int2(&self, x: f64) -> BigInt {
        let (m, e) = decompose(x);
        BigInt::from(m) << ((e - 2 * self.emin) as usize)
    }

    /// The common scale: the integers are the values divided by `2^exponent`.
    pub fn exponent(&self) -> i32 {
        self.emin
    }

    /// `x / 2^emin` as an exact integer.
    pub fn int(&self, x: f64) -> BigInt {
        let (m, e) = decompose(x);
        BigInt::from(m) << ((e - self.emin) as usize)
    }
}

/// The sign of a big integer.
pub fn sign(x: &BigInt) -> Sign {
    if x.is_zero() {
        Sign::Zero
    } else if x.is_positive() {
        Sign::Positive
    } else {
        Sign::Negative
    }
}

/// `num / den · 2^exp` as a double, within two units in the last place (`den ≠ 0`); `±inf`
/// or `0` beyond the range of doubles.
pub fn ratio_to_f64(num: &BigInt, den: &BigInt, exp: i32) -> f64 {
    use num_traits::ToPrimitive;
    if num.is_zero() {
        return 0.0;
    }
    let negative = num.is_negative() != den.is_negative();
    let (a, b) = (num.abs(), den.abs());
    // a quotient of at least 64 bits: its truncation and the rounding to 53 bits are the
    // only errors
    let shift = b.bits() as i64 - a.bits() as i64 + 64;
    let q = if shift >= 0 {
        (a << shift as usize) / b
    } else {
        a / (b << (-shift) as usize)
    };
    let m = q.to_f64().unwrap_or(f64::INFINITY);
    let v = crate::space::ldexp(m, (exp as i64 - shift).clamp(-5000, 5000) as i32);
    if negative {
        -v
    } else {
        v
    }
}

/// The determinant of `D` rows of `D` big integers (`D` 2 or 3).
pub fn det<const D: usize>(rows: [&[BigInt; D]; D]) -> BigInt {
    if D == 2 {
        &rows[0][0] * &rows[1][1] - &rows[0][1] * &rows[1][0]
    } else {
        let r = |i: usize| -> [BigInt; 3] { std::array::from_fn(|c| rows[i][c].clone()) };
        det3(&r(0), &r(1), &r(2))
    }
}

/// The side of the in-sphere or power test from its exact rows `d_i = a_i − q` and lifts
/// `l_i` (`|d_i|²`, or `|d_i|² − (w_i − w_q)` for weighted points): the sign of the
/// `(D+1)×(D+1)` determinant of rows `(d_i, l_i)`, expanded along the lifts, times
/// `(−1)^D`; positive when `q` is inside the sphere (in conflict with the orthogonal
/// sphere) of the positively oriented `a_0..a_D`.
pub fn lifted_side<const D: usize>(d: &[[BigInt; D]], l: &[BigInt]) -> Sign {
    let n = D + 1;
    let mut total = BigInt::from(0);
    for i in 0..n {
        let mut rows = [&d[0]; D];
        for (slot, k) in (0..n).filter(|&k| k != i).enumerate() {
            rows[slot] = &d[k];
        }
        let term = &l[i] * det::<D>(rows);
        if (i + D) & 1 == 0 {
            total += term;
        } else {
            total -= term;
        }
    }
    let s = sign(&total);
    if D & 1 == 0 {
        s
    } else {
        s.flip()
    }
}

/// `det [a; b; c]` of three rows.
pub fn det3(a: &[BigInt; 3], b: &[BigInt; 3], c: &[BigInt; 3]) -> BigInt {
    &a[0] * (&b[1] * &c[2] - &b[2] * &c[1]) - &a[1] * (&b[0] * &c[2] - &b[2] * &c[0])
        + &a[2] * (&b[0] * &c[1] - &b[1] * &c[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decompose_round_trips() {
        for x in [1.0, -3.5, 0.1, 1e-310, 5e-324, f64::MAX, -2.0f64.powi(-60)] {
            let (m, e) = decompose(x);
            assert_eq!(m as f64 * 2f64.powi(e), x, "{x}");
            assert!(m % 2 != 0);
        }
    }

    #[test]
    fn scaled_integers_are_exact() {
        let s = Scaled::new([0.5, 0.25, 3.0]);
        assert_eq!(s.int(0.25), BigInt::from(1));
        assert_eq!(s.int(3.0), BigInt::from(12));
    }

    #[test]
    fn ratios_round_to_nearby_doubles() {
        let third = ratio_to_f64(&BigInt::from(1), &BigInt::from(3), 0);
        assert!((third - 1.0 / 3.0).abs() <= 2.0 * f64::EPSILON / 3.0);
        assert_eq!(ratio_to_f64(&BigInt::from(-6), &BigInt::from(4), 3), -12.0);
        assert_eq!(ratio_to_f64(&BigInt::from(0), &BigInt::from(7), 0), 0.0);
        let big = BigInt::from(1) << 3000usize;
        let x = ratio_to_f64(&BigInt::from(5), &big, 2990);
        assert_eq!(x, 5.0 / 1024.0);
        assert_eq!(ratio_to_f64(&big, &BigInt::from(1), 0), f64::INFINITY);
    }

    #[test]
    fn squares_share_the_scale() {
        // 0.75 = 3·2^-2 and a weight 2^-7: lengths at 2^-4, squares at 2^-8
        let s = Scaled::with_squares([0.75, 1.0], [2f64.powi(-7), 4.0]);
        assert_eq!(s.exponent(), -4);
        assert_eq!(s.int(0.75), BigInt::from(12));
        assert_eq!(s.int2(2f64.powi(-7)), BigInt::from(2));
        assert_eq!(s.int2(4.0), BigInt::from(1024));
        let t = Scaled::with_squares([0.5], [0.0]);
        assert_eq!(t.exponent(), -1);
    }

    #[test]
    fn determinants() {
        let a = [BigInt::from(2), BigInt::from(0), BigInt::from(1)];
        let b = [BigInt::from(1), BigInt::from(3), BigInt::from(2)];
        let c = [BigInt::from(1), BigInt::from(1), BigInt::from(2)];
        assert_eq!(det3(&a, &b, &c), BigInt::from(6));
        assert_eq!(det::<3>([&a, &b, &c]), BigInt::from(6));
        let (x, y) = (
            [BigInt::from(2), BigInt::from(1)],
            [BigInt::from(5), BigInt::from(4)],
        );
        assert_eq!(det::<2>([&x, &y]), BigInt::from(3));
        assert_eq!(sign(&BigInt::from(-4)), Sign::Negative);
    }
}
