//! Exact evaluation on fixed-width integers: the exact path of the flat spaces' predicates
//! whenever the integer differences (every value of one predicate scaled by one power of
//! two, as in [`super::exact`]) stay below [`LIMIT`] = 2⁶² in magnitude — every test whose
//! coordinates span fewer than about 60 binary orders, such as the cospherical tests of a
//! crystal lattice. No allocation; larger values take the big integers.
//!
//! Bounds, with `|d| < 2⁶²`: a product of two coordinates is below 2¹²⁴, a 2×2 minor
//! below 2¹²⁵ and a squared length (up to three terms) below 2¹²⁶, all within `i128`;
//! lifts `|d|² − Δw` are asked to stay below 2¹²⁶ too. A 3×3 determinant is below
//! 3·2⁶²·2¹²⁵ < 2¹⁸⁹, a lifted term below 2¹²⁶·2¹⁸⁹ and the sum of four below 2³¹⁷: five
//! 64-bit limbs in two's complement hold every intermediate value.

use super::Sign;

/// The exclusive bound on the magnitude of an integer difference this module takes.
pub const LIMIT: i128 = 1 << 62;

/// The exclusive bound on the magnitude of a lift `|d|² − Δw` this module takes.
pub const LIFT_LIMIT: i128 = 1 << 126;

/// A signed integer of 320 bits in two's complement, least significant limb first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Wide([u64; 5]);

impl Wide {
    fn from_i128(x: i128) -> Wide {
        let ext = if x < 0 { u64::MAX } else { 0 };
        Wide([x as u64, (x >> 64) as u64, ext, ext, ext])
    }

    fn is_negative(&self) -> bool {
        (self.0[4] as i64) < 0
    }

    fn neg(self) -> Wide {
        let mut out = [0; 5];
        let mut carry = true;
        for (o, &x) in out.iter_mut().zip(&self.0) {
            let (v, c) = (!x).overflowing_add(carry as u64);
            *o = v;
            carry = c;
        }
        Wide(out)
    }

    fn add(self, other: Wide) -> Wide {
        let mut out = [0; 5];
        let mut carry = false;
        for i in 0..5 {
            let (v, c1) = self.0[i].overflowing_add(other.0[i]);
            let (v, c2) = v.overflowing_add(carry as u64);
            out[i] = v;
            carry = c1 || c2;
        }
        Wide(out)
    }

    /// `self · x`, which must fit (the bounds above).
    #[inline(always)]
    fn mul(self, x: i128) -> Wide {
        let negative = self.is_negative() != (x < 0);
        let a = if self.is_negative() { self.neg() } else { self };
        let b = x.unsigned_abs();
        let b = [b as u64, (b >> 64) as u64];
        let mut out = [0u64; 5];
        for i in 0..5 {
            if a.0[i] == 0 {
                continue;
            }
            let mut carry = 0u128;
            for j in 0..2.min(5 - i) {
                let t = a.0[i] as u128 * b[j] as u128 + out[i + j] as u128 + carry;
                out[i + j] = t as u64;
                carry = t >> 64;
            }
            if i + 2 < 5 {
                out[i + 2] = carry as u64;
            }
        }
        let p = Wide(out);
        if negative {
            p.neg()
        } else {
            p
        }
    }

    fn sign(&self) -> Sign {
        if self.is_negative() {
            Sign::Negative
        } else if self.0.iter().all(|&x| x == 0) {
            Sign::Zero
        } else {
            Sign::Positive
        }
    }
}

/// `a·d − b·c` of coordinates below [`LIMIT`].
#[inline]
fn minor(a: i64, b: i64, c: i64, d: i64) -> i128 {
    a as i128 * d as i128 - b as i128 * c as i128
}

/// The determinant of `D` rows (`D` 2 or 3) of coordinates below [`LIMIT`].
#[inline(always)]
fn det<const D: usize>(rows: [&[i64; D]; D]) -> Wide {
    let r = |i: usize, c: usize| rows[i][c];
    if D == 2 {
        return Wide::from_i128(minor(r(0, 0), r(0, 1), r(1, 0), r(1, 1)));
    }
    let m12 = minor(r(1, 1), r(1, 2), r(2, 1), r(2, 2));
    let m02 = minor(r(1, 0), r(1, 2), r(2, 0), r(2, 2));
    let m01 = minor(r(1, 0), r(1, 1), r(2, 0), r(2, 1));
    Wide::from_i128(m12)
        .mul(r(0, 0) as i128)
        .add(Wide::from_i128(m02).mul(r(0, 1) as i128).neg())
        .add(Wide::from_i128(m01).mul(r(0, 2) as i128))
}

/// The sign of the determinant of `D` rows (`D` 2 or 3) below [`LIMIT`].
pub fn det_sign<const D: usize>(rows: [&[i64; D]; D]) -> Sign {
    det(rows).sign()
}

/// [`super::exact::lifted_side`] on rows below [`LIMIT`] and lifts below [`LIFT_LIMIT`]:
/// the sign of the `(D+1)×(D+1)` determinant of rows `(d_i, l_i)` times `(−1)^D`.
pub fn lifted_side<const D: usize, const N: usize>(d: &[[i64; D]; N], l: &[i128; N]) -> Sign {
    debug_assert_eq!(N, D + 1);
    let mut total = Wide::from_i128(0);
    for i in 0..N {
        let mut rows = [&d[0]; D];
        for (slot, k) in (0..N).filter(|&k| k != i).enumerate() {
            rows[slot] = &d[k];
        }
        let term = det::<D>(rows).mul(l[i]);
        total = total.add(if (i + D) & 1 == 0 { term } else { term.neg() });
    }
    let s = total.sign();
    if D & 1 == 0 {
        s
    } else {
        s.flip()
    }
}

/// The squared length of a row below [`LIMIT`] (below [`LIFT_LIMIT`]).
fn squared_length<const D: usize>(d: &[i64; D]) -> i128 {
    d.iter().map(|&x| x as i128 * x as i128).sum()
}

/// The lifts `|d_i|² − dw_i` of rows below [`LIMIT`], when each is below [`LIFT_LIMIT`].
pub fn lifts<const D: usize, const N: usize>(
    d: &[[i64; D]; N],
    dw: &[i128; N],
) -> Option<[i128; N]> {
    let mut l = [0; N];
    for i in 0..N {
        l[i] = squared_length(&d[i]).checked_sub(dw[i])?;
        if l[i].unsigned_abs() >= LIFT_LIMIT as u128 {
            return None;
        }
    }
    Some(l)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::predicates::exact;
    use num_bigint::BigInt;
    use proptest::prelude::*;

    fn big(w: Wide) -> BigInt {
        let mut v = BigInt::from(0);
        for &x in w.0.iter().rev() {
            v = (v << 64usize) + BigInt::from(x);
        }
        if w.is_negative() {
            v - (BigInt::from(1) << 320usize)
        } else {
            v
        }
    }

    fn near_limit() -> impl Strategy<Value = i64> {
        let m = (LIMIT - 1) as i64;
        prop_oneof![-m..=m, Just(m), Just(-m), Just(0), -3i64..=3]
    }

    fn big_rows<const D: usize, const N: usize>(d: &[[i64; D]; N]) -> Vec<[BigInt; D]> {
        d.iter().map(|r| r.map(BigInt::from)).collect()
    }

    proptest! {
        #[test]
        fn products_and_sums_are_those_of_big_integers(a in any::<i128>(), b in any::<i64>(), c in any::<i128>()) {
            let p = Wide::from_i128(a).mul(b as i128);
            prop_assert_eq!(big(p), BigInt::from(a) * BigInt::from(b));
            let s = Wide::from_i128(a).add(Wide::from_i128(c).neg());
            prop_assert_eq!(big(s), BigInt::from(a) - BigInt::from(c));
            let q = Wide::from_i128(a >> 2).mul(c >> 2).mul(b as i128 >> 2);
            prop_assert_eq!(big(q), BigInt::from(a >> 2) * BigInt::from(c >> 2) * BigInt::from(b >> 2));
        }

        #[test]
        fn lifted_sides_are_those_of_big_integers_3d(d in prop::array::uniform4(prop::array::uniform3(near_limit()))) {
            let l = d.map(|r| squared_length(&r));
            let bl: Vec<BigInt> = l.iter().map(|&x| BigInt::from(x)).collect();
            prop_assert_eq!(lifted_side(&d, &l), exact::lifted_side::<3>(&big_rows(&d), &bl));
            let b = big_rows(&d);
            prop_assert_eq!(det_sign([&d[0], &d[1], &d[2]]), exact::sign(&exact::det3(&b[0], &b[1], &b[2])));
        }

        #[test]
        fn lifted_sides_are_those_of_big_integers_2d(
            d in prop::array::uniform3(prop::array::uniform2(near_limit())),
            w in prop::array::uniform3(-(1i128 << 100)..(1i128 << 100)),
        ) {
            let l: [i128; 3] = std::array::from_fn(|i| squared_length(&d[i]) - w[i]);
            let bl: Vec<BigInt> = l.iter().map(|&x| BigInt::from(x)).collect();
            prop_assert_eq!(lifted_side(&d, &l), exact::lifted_side::<2>(&big_rows(&d), &bl));
            let b = big_rows(&d);
            prop_assert_eq!(det_sign([&d[0], &d[1]]), exact::sign(&exact::det::<2>([&b[0], &b[1]])));
        }
    }

    #[test]
    fn the_extremes_fit() {
        // every row at the limit, signs chosen to make each term as large as it gets
        let m = (LIMIT - 1) as i64;
        let d = [[m, -m, m], [-m, -m, m], [m, m, m], [-m, m, -m]];
        let l = d.map(|r| squared_length(&r));
        let bl: Vec<BigInt> = l.iter().map(|&x| BigInt::from(x)).collect();
        assert_eq!(
            lifted_side(&d, &l),
            exact::lifted_side::<3>(&big_rows(&d), &bl)
        );
        let l = [
            LIFT_LIMIT - 1,
            -(LIFT_LIMIT - 1),
            LIFT_LIMIT - 1,
            -(LIFT_LIMIT - 1),
        ];
        let bl: Vec<BigInt> = l.iter().map(|&x| BigInt::from(x)).collect();
        assert_eq!(
            lifted_side(&d, &l),
            exact::lifted_side::<3>(&big_rows(&d), &bl)
        );
        assert_eq!(
            big(Wide::from_i128(i128::MIN).mul(i128::MIN)),
            BigInt::from(i128::MIN).pow(2)
        );
    }
}
