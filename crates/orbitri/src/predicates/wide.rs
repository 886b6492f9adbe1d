//! Exact evaluation on fixed-width integers: the exact path of the flat spaces' predicates
//! whenever the integer differences (every value of one predicate scaled by one power of
//! two, as in [`super::exact`]) stay below [`LIMIT`] = 2⁶² in magnitude — every test whose
//! coordinates span fewer than about 60 binary orders, such as the cospherical tests of a
//! crystal lattice. No allocation; larger values take the big integers.
//!
//! Bounds, with `|d| < 2⁶²`: a product of two coordinates is below 2¹²⁴, a 2×2 minor
//! below 2¹²⁵ and a squared length (up to three terms) below 2¹²⁶, all within `i128`;
//! lifts `|d|² − Δw` are asked to stay below 2¹²⁶ too. A 3×3 determinant is below
//! 3·2⁶²·2¹²⁵ < 2¹⁸⁹, held as `hi·2⁶⁴ + lo` with an `i128` high part; a lifted term is
//! below 2¹²⁶·2¹⁸⁹ = 2³¹⁵, and the lifted determinant's positive terms and its negative
//! ones are summed apart, as magnitudes of five 64-bit limbs (each sum below 2³¹⁷), then
//! compared.

use super::Sign;

/// The exclusive bound on the magnitude of an integer difference this module takes.
pub const LIMIT: i128 = 1 << 62;

/// The exclusive bound on the magnitude of a lift `|d|² − Δw` this module takes.
pub const LIFT_LIMIT: i128 = 1 << 126;

/// A signed integer below 2¹⁹¹ in magnitude, `hi·2⁶⁴ + lo`: a 3×3 determinant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct I192 {
    hi: i128,
    lo: u64,
}

impl I192 {
    /// `x·m` for `|m| < 2¹²⁷`: `m = (m >> 64)·2⁶⁴ + (m mod 2⁶⁴)`, each part's product
    /// within `i128`.
    #[inline(always)]
    fn product(x: i64, m: i128) -> I192 {
        let low = x as i128 * (m as u64) as i128;
        let high = x as i128 * (m >> 64);
        I192 {
            hi: high + (low >> 64),
            lo: low as u64,
        }
    }

    #[inline(always)]
    fn add(self, other: I192) -> I192 {
        let (lo, carry) = self.lo.overflowing_add(other.lo);
        I192 {
            hi: self.hi + other.hi + carry as i128,
            lo,
        }
    }

    #[inline(always)]
    fn neg(self) -> I192 {
        I192 {
            hi: -self.hi - (self.lo != 0) as i128,
            lo: self.lo.wrapping_neg(),
        }
    }

    /// The sign and the magnitude's limbs, least significant first.
    #[inline(always)]
    fn split(self) -> (bool, [u64; 3]) {
        let negative = self.hi < 0;
        let m = if negative { self.neg() } else { self };
        (negative, [m.lo, m.hi as u64, (m.hi >> 64) as u64])
    }

    fn sign(self) -> Sign {
        match self.hi.cmp(&0) {
            std::cmp::Ordering::Less => Sign::Negative,
            std::cmp::Ordering::Equal if self.lo == 0 => Sign::Zero,
            _ => Sign::Positive,
        }
    }
}

/// `a·d − b·c` of coordinates below [`LIMIT`].
#[inline(always)]
fn minor(a: i64, b: i64, c: i64, d: i64) -> i128 {
    a as i128 * d as i128 - b as i128 * c as i128
}

/// The determinant of `D` rows (`D` 2 or 3) of coordinates below [`LIMIT`].
#[inline(always)]
fn det<const D: usize>(rows: [&[i64; D]; D]) -> I192 {
    const { assert!(D == 2 || D == 3) };
    let r = |i: usize, c: usize| rows[i][c];
    if D == 2 {
        let m = minor(r(0, 0), r(0, 1), r(1, 0), r(1, 1));
        return I192 {
            hi: m >> 64,
            lo: m as u64,
        };
    }
    let m12 = minor(r(1, 1), r(1, 2), r(2, 1), r(2, 2));
    let m02 = minor(r(1, 0), r(1, 2), r(2, 0), r(2, 2));
    let m01 = minor(r(1, 0), r(1, 1), r(2, 0), r(2, 1));
    I192::product(r(0, 0), m12)
        .add(I192::product(r(0, 1), m02).neg())
        .add(I192::product(r(0, 2), m01))
}

/// The sign of the determinant of `D` rows (`D` 2 or 3) below [`LIMIT`].
pub fn det_sign<const D: usize>(rows: [&[i64; D]; D]) -> Sign {
    det(rows).sign()
}

/// Adds the product of magnitudes `a·b` to the 320-bit magnitude `acc` (which must hold it).
#[inline(always)]
fn add_product(acc: &mut [u64; 5], a: u128, b: [u64; 3]) {
    for (i, &x) in [a as u64, (a >> 64) as u64].iter().enumerate() {
        let mut carry = 0u128;
        for (j, &y) in b.iter().enumerate() {
            let t = x as u128 * y as u128 + acc[i + j] as u128 + carry;
            acc[i + j] = t as u64;
            carry = t >> 64;
        }
        for slot in &mut acc[i + 3..] {
            let t = *slot as u128 + carry;
            *slot = t as u64;
            carry = t >> 64;
        }
    }
}

/// [`super::exact::lifted_side`] on rows below [`LIMIT`] and lifts below [`LIFT_LIMIT`]:
/// the sign of the `(D+1)×(D+1)` determinant of rows `(d_i, l_i)` times `(−1)^D`. The
/// positive and the negative terms are summed apart, as magnitudes, and compared.
pub fn lifted_side<const D: usize, const N: usize>(d: &[[i64; D]; N], l: &[i128; N]) -> Sign {
    debug_assert_eq!(N, D + 1);
    let mut sums = [[0u64; 5]; 2];
    for i in 0..N {
        let mut rows = [&d[0]; D];
        for (slot, k) in (0..N).filter(|&k| k != i).enumerate() {
            rows[slot] = &d[k];
        }
        let (negative, m) = det::<D>(rows).split();
        let odd = (i + D) & 1 == 1;
        add_product(
            &mut sums[(negative ^ (l[i] < 0) ^ odd) as usize],
            l[i].unsigned_abs(),
            m,
        );
    }
    let [plus, minus] = sums;
    let s = Sign::from(plus.iter().rev().cmp(minus.iter().rev()));
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

    fn big(x: I192) -> BigInt {
        (BigInt::from(x.hi) << 64usize) + BigInt::from(x.lo)
    }

    fn near_limit() -> impl Strategy<Value = i64> {
        let m = (LIMIT - 1) as i64;
        prop_oneof![-m..=m, Just(m), Just(-m), Just(0), -3i64..=3]
    }

    fn big_rows<const D: usize, const N: usize>(d: &[[i64; D]; N]) -> Vec<[BigInt; D]> {
        d.iter().map(|r| r.map(BigInt::from)).collect()
    }

    fn big_lifts<const N: usize>(l: &[i128; N]) -> Vec<BigInt> {
        l.iter().map(|&x| BigInt::from(x)).collect()
    }

    proptest! {
        #[test]
        fn products_and_sums_are_those_of_big_integers(
            x in any::<i64>(), m in any::<i128>(), y in any::<i64>(), n in any::<i128>(),
            a in any::<u128>(), b in prop::array::uniform3(any::<u64>()),
        ) {
            let (p, q) = (I192::product(x, m >> 1), I192::product(y, n >> 1));
            prop_assert_eq!(big(p), BigInt::from(x) * BigInt::from(m >> 1));
            prop_assert_eq!(big(p.add(q.neg())), big(p) - big(q));
            let (negative, limbs) = p.split();
            let magnitude = limbs.iter().rev().fold(BigInt::from(0), |v, &l| (v << 64usize) + l);
            prop_assert_eq!(if negative { -magnitude } else { magnitude }, big(p));
            let mut acc = [u64::MAX >> 2, 7, 0, 0, 0];
            add_product(&mut acc, a >> 2, [b[0], b[1], b[2] >> 3]);
            let sum = acc.iter().rev().fold(BigInt::from(0), |v, &l| (v << 64usize) + l);
            let b = (BigInt::from(b[2] >> 3) << 128usize) + (BigInt::from(b[1]) << 64usize) + b[0];
            prop_assert_eq!(sum, BigInt::from(a >> 2) * b + (BigInt::from(7) << 64usize) + (u64::MAX >> 2));
        }

        #[test]
        fn lifted_sides_are_those_of_big_integers_3d(
            d in prop::array::uniform4(prop::array::uniform3(near_limit())),
            w in prop::array::uniform4(-(1i128 << 125)..(1i128 << 125)),
        ) {
            let b = big_rows(&d);
            for l in [lifts(&d, &[0; 4]).unwrap(), w] {
                prop_assert_eq!(lifted_side(&d, &l), exact::lifted_side::<3>(&b, &big_lifts(&l)));
            }
            prop_assert_eq!(det_sign([&d[0], &d[1], &d[2]]), exact::sign(&exact::det3(&b[0], &b[1], &b[2])));
        }

        #[test]
        fn lifted_sides_are_those_of_big_integers_2d(
            d in prop::array::uniform3(prop::array::uniform2(near_limit())),
            w in prop::array::uniform3(-(1i128 << 100)..(1i128 << 100)),
        ) {
            let l = lifts(&d, &w).unwrap();
            let b = big_rows(&d);
            prop_assert_eq!(lifted_side(&d, &l), exact::lifted_side::<2>(&b, &big_lifts(&l)));
            prop_assert_eq!(det_sign([&d[0], &d[1]]), exact::sign(&exact::det::<2>([&b[0], &b[1]])));
        }
    }

    #[test]
    fn the_extremes_fit() {
        // every row at the limit, signs chosen to make each term as large as it gets
        let m = (LIMIT - 1) as i64;
        let d = [[m, -m, m], [-m, -m, m], [m, m, m], [-m, m, -m]];
        let b = big_rows(&d);
        let l = lifts(&d, &[0; 4]).unwrap();
        assert_eq!(
            lifted_side(&d, &l),
            exact::lifted_side::<3>(&b, &big_lifts(&l))
        );
        let l = [
            LIFT_LIMIT - 1,
            -(LIFT_LIMIT - 1),
            LIFT_LIMIT - 1,
            -(LIFT_LIMIT - 1),
        ];
        assert_eq!(
            lifted_side(&d, &l),
            exact::lifted_side::<3>(&b, &big_lifts(&l))
        );
        assert_eq!(lifts(&d, &[-(LIFT_LIMIT / 2); 4]), None);
        // a tie: four points (not on one plane) on the unit sphere about (1, 0, 0), which
        // passes through the query at the origin; the centre as query is inside
        let t = [[2, 0, 0], [1, 1, 0], [1, 0, 1], [1, -1, 0]];
        assert_eq!(lifted_side(&t, &lifts(&t, &[0; 4]).unwrap()), Sign::Zero);
        let centred = t.map(|r| [r[0] - 1, r[1], r[2]]);
        let l = lifts(&centred, &[0; 4]).unwrap();
        let want = exact::lifted_side::<3>(&big_rows(&centred), &big_lifts(&l));
        assert_ne!(want, Sign::Zero);
        assert_eq!(lifted_side(&centred, &l), want);
    }
}
