//! The exact metric of a space whose points are stored in lattice coordinates: the Gram
//! matrix `G` of the lattice, so that a lifted difference `x` (in lattice units) has squared
//! length `xᵀ·G·x`, and the in-sphere test it defines. Orientation needs no metric: the
//! determinant of lattice coordinates has the sign of the Cartesian one (the lattice's
//! basis is positively oriented).
//!
//! Each entry is given exactly as `m·s²` with a small integer `m` and a double `s` (a side
//! of the box): the entries of a hexagonal lattice of side `a` are `a²` and `a²/2`, which
//! after doubling are `2a²` and `a²`. The filter uses the entries rounded; the exact
//! fallback multiplies them out in big integers.

use num_bigint::BigInt;

use super::flat_torus::L;
use super::FlatTorus;
use crate::error::{Error, Result};
use crate::predicates::exact::{self, Scaled};
use crate::predicates::filter;
use crate::predicates::Sign;

/// A Gram matrix with exact entries `G_jk = m_jk·s_jk²` (any positive multiple of the true
/// one: in-sphere signs do not change under scaling).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Gram<const D: usize> {
    exact: [[(i64, f64); D]; D],
    /// The entries rounded and scaled by one power of two so the largest lies in `[1, 2)`.
    approx: [[f64; D]; D],
    /// `Σ|approx|`.
    sum: f64,
}

impl<const D: usize> Gram<D> {
    /// The Gram matrix of entries `m·s²`, symmetric and positive definite; entries below
    /// `2⁻⁶⁰` of the largest (a box too elongated for the filter's range) are refused.
    pub(super) fn new(exact: [[(i64, f64); D]; D]) -> Result<Self> {
        let value = |(m, s): (i64, f64)| m as f64 * s * s;
        let raw = exact.map(|r| r.map(value));
        let largest = raw.iter().flatten().fold(0.0f64, |a, &x| a.max(x.abs()));
        if !(largest.is_finite() && largest > 0.0) {
            return Err(Error::InvalidBox(format!(
                "the metric {raw:?} is out of the range of the doubles"
            )));
        }
        let k = -largest.log2().floor() as i32;
        let approx = raw.map(|r| r.map(|x| super::ldexp(x, k)));
        let smallest = approx
            .iter()
            .flatten()
            .filter(|x| **x != 0.0)
            .fold(f64::INFINITY, |a, &x| a.min(x.abs()));
        if smallest < 2f64.powi(-60) {
            return Err(Error::InvalidBox(format!(
                "the box is too elongated: its metric spans more than 2^60 ({raw:?})"
            )));
        }
        let symmetric = (0..D).all(|j| (0..D).all(|i| exact[i][j] == exact[j][i]));
        if !symmetric || !positive_definite(&approx) {
            return Err(Error::InvalidBox(format!(
                "{raw:?} is not a symmetric positive definite metric"
            )));
        }
        let sum = approx.iter().flatten().map(|x| x.abs()).sum();
        Ok(Gram { exact, approx, sum })
    }

    /// `xᵀ·G·x` in the scale of the rounded entries.
    #[cfg(test)]
    fn length2(&self, x: &[f64; D]) -> f64 {
        (0..D)
            .flat_map(|j| (0..D).map(move |k| (j, k)))
            .map(|(j, k)| self.approx[j][k] * x[j] * x[k])
            .sum()
    }

    /// The in-sphere sign of `q` against the positively oriented lifted simplex `s` (lattice
    /// coordinates of the torus `unit`, whose lattice is the identity), without perturbation:
    /// `Zero` when cospherical. Exact.
    pub(super) fn in_sphere<const N: usize>(
        &self,
        unit: &FlatTorus<D>,
        s: &[L<D>; N],
        q: L<D>,
    ) -> Sign {
        let (d, b) = unit.rows::<N>(std::array::from_fn(|i| &s[i]), &q);
        filter::in_sphere_metric(&d, b, &self.approx, self.sum)
            .unwrap_or_else(|| self.power_exact(unit, s, &[0.0; N], q, 0.0))
    }

    /// The power test of weighted lifted points (lattice coordinates of `unit`, weights
    /// squared Cartesian lengths) without perturbation: `Zero` when `q` is orthogonal to the
    /// orthogonal sphere of `s`; the in-sphere test for equal weights. Exact.
    pub(super) fn power_exact<const N: usize>(
        &self,
        unit: &FlatTorus<D>,
        s: &[L<D>; N],
        ws: &[f64; N],
        q: L<D>,
        wq: f64,
    ) -> Sign {
        let mut pts = s.to_vec();
        pts.push(q);
        let (l, _, ed) = unit.exact_lift_weighted(&pts, &[]);
        let d: Vec<[BigInt; D]> = (0..N)
            .map(|i| std::array::from_fn(|c| &l[i][c] - &l[N][c]))
            .collect();
        let scale = Scaled::new(self.exact.iter().flatten().map(|e| e.1));
        // squared lengths below are integers at 2^e; the weight differences at 2^ew
        let e = 2 * (scale.exponent() + ed);
        let dws: Vec<f64> = ws.iter().map(|w| w - wq).collect();
        let wscale = Scaled::new(dws.iter().copied());
        let (ew, lift_shift) = if wscale.exponent() >= e {
            (e, 0)
        } else {
            (wscale.exponent(), (e - wscale.exponent()) as usize)
        };
        let dw: Vec<BigInt> = dws
            .iter()
            .map(|&x| wscale.int(x) << (wscale.exponent() - ew) as usize)
            .collect();
        let g: Vec<Vec<BigInt>> = self
            .exact
            .iter()
            .map(|r| {
                r.iter()
                    .map(|&(m, side)| {
                        let x = scale.int(side);
                        BigInt::from(m) * &x * &x
                    })
                    .collect()
            })
            .collect();
        let lifts: Vec<BigInt> = (0..N)
            .map(|i| {
                let mut len = BigInt::from(0);
                for j in 0..D {
                    for k in 0..D {
                        len += &g[j][k] * &d[i][j] * &d[i][k];
                    }
                }
                (len << lift_shift) - &dw[i]
            })
            .collect();
        exact::lifted_side(&d, &lifts)
    }
}

/// Sylvester's criterion on the leading minors (2D and 3D).
fn positive_definite<const D: usize>(g: &[[f64; D]; D]) -> bool {
    let m1 = g[0][0];
    let m2 = g[0][0] * g[1][1] - g[0][1] * g[1][0];
    let m3 = if D == 3 {
        let r: Vec<&[f64]> = g.iter().map(|r| &r[..]).collect();
        r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
            - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
            + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0])
    } else {
        1.0
    };
    m1 > 0.0 && m2 > 0.0 && m3 > 0.0
}

#[cfg(test)]
mod tests {
    use super::super::flat_torus::UnperturbedInSphere;
    use super::super::{Lattice, OrbitSpace};
    use super::*;

    fn unit3() -> FlatTorus<3> {
        FlatTorus::new(Lattice::cuboid([1.0; 3]).unwrap())
    }

    fn random(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    /// With the identity metric the test is the torus's Euclidean one, also on the
    /// near-degenerate inputs that need the exact fallback.
    #[test]
    fn the_identity_metric_is_the_euclidean_test() {
        let unit = unit3();
        let gram = Gram::new([
            [(1, 1.0), (0, 0.0), (0, 0.0)],
            [(0, 0.0), (1, 1.0), (0, 0.0)],
            [(0, 0.0), (0, 0.0), (1, 1.0)],
        ])
        .unwrap();
        let mut seed = 7;
        let mut undecided = 0;
        for trial in 0..4000 {
            let p: [L<3>; 5] = if trial % 2 == 0 {
                std::array::from_fn(|_| {
                    (
                        std::array::from_fn(|_| random(&mut seed)),
                        std::array::from_fn(|_| (random(&mut seed) * 3.0) as i8 - 1),
                    )
                })
            } else {
                // a query on the circumsphere of a cube's corner, up to an ulp or two: the
                // filter cannot decide
                let at = |v: [f64; 3]| (v, [0i8; 3]);
                let nudge = f64::EPSILON * ((trial / 2) % 3) as f64;
                [
                    at([0.0, 0.0, 0.0]),
                    at([1.0, 0.0, 0.0]),
                    at([0.0, 1.0, 0.0]),
                    at([0.0, 0.0, 1.0]),
                    at([1.0, 1.0, 1.0 - nudge]),
                ]
            };
            let s = [p[0], p[1], p[2], p[3]];
            if unit.orient(&s) != Sign::Positive {
                continue;
            }
            let (d, b) = unit.rows::<4>(std::array::from_fn(|i| &s[i]), &p[4]);
            if filter::in_sphere_metric(&d, b, &gram.approx, gram.sum).is_none() {
                undecided += 1;
            }
            let want = unit.in_sphere_unperturbed(&s, p[4]);
            assert_eq!(gram.in_sphere(&unit, &s, p[4]), want, "{p:?}");
        }
        assert!(undecided > 100, "{undecided}");
    }

    /// In a hexagonal metric the six nearest lattice points of the origin are equidistant:
    /// any four of them and a fifth are cospherical (a sign the filter cannot give), and a
    /// point nudged inward or outward is inside or outside.
    #[test]
    fn hexagonal_neighbours_are_cospherical() {
        let unit = unit3();
        let a = 0.7f64;
        let c = 1.3f64;
        let gram = Gram::new([
            [(2, a), (1, a), (0, 0.0)],
            [(1, a), (2, a), (0, 0.0)],
            [(0, 0.0), (0, 0.0), (2, c)],
        ])
        .unwrap();
        // lattice coordinates of the hexagonal neighbours of 0 (a2 at 60° from a1): ±a1,
        // ±a2, ±(a1 − a2); and ±e3 at height c
        let at = |x: [f64; 3]| (x, [0i8; 3]);
        let ring = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
        ];
        let equal = gram.length2(&ring[0]);
        for r in ring {
            assert!((gram.length2(&r) - equal).abs() < 1e-15);
        }
        // a sphere through four of the ring (they are coplanar: lift one out of the plane)
        let top = [0.0, 0.0, 1.0];
        let s = [at(ring[0]), at(ring[1]), at(ring[2]), at(top)];
        let s = if unit.orient(&s) == Sign::Positive {
            s
        } else {
            [s[1], s[0], s[2], s[3]]
        };
        // the fourth ring point lies on the sphere through three ring points and e3 only if
        // that sphere is centred on the axis: it is (the ring is a circle about the axis)
        assert_eq!(gram.in_sphere(&unit, &s, at(ring[3])), Sign::Zero);
        assert_eq!(gram.in_sphere(&unit, &s, at([0.0, -1.0, 0.0])), Sign::Zero);
        assert_eq!(gram.in_sphere(&unit, &s, at([1.0, -1.0, 0.0])), Sign::Zero);
        assert_eq!(
            gram.in_sphere(&unit, &s, at([-1.0 + 1e-17, 0.0, 0.0])),
            Sign::Zero,
            "-1 + 1e-17 rounds to -1"
        );
        assert_eq!(
            gram.in_sphere(&unit, &s, at([-1.0 + f64::EPSILON, 0.0, 0.0])),
            Sign::Positive
        );
        assert_eq!(
            gram.in_sphere(&unit, &s, at([-1.0 - 2.0 * f64::EPSILON, 0.0, 0.0])),
            Sign::Negative
        );
        // in Euclidean lattice coordinates the same five points are not cospherical
        let euclid = unit.in_sphere_unperturbed(&s, at(ring[3]));
        assert_ne!(euclid, Sign::Zero);
    }

    #[test]
    fn bad_metrics_are_refused() {
        let bad = [[(1, 1.0), (2, 1.0)], [(2, 1.0), (1, 1.0)]];
        assert!(Gram::<2>::new(bad).is_err());
        let skew = [[(1, 1.0), (1, 0.5)], [(0, 0.0), (1, 1.0)]];
        assert!(Gram::<2>::new(skew).is_err());
        let flat = [[(1, 1.0), (0, 0.0)], [(0, 0.0), (1, 1e-20)]];
        assert!(Gram::<2>::new(flat).is_err());
        let nan = [[(1, f64::NAN), (0, 0.0)], [(0, 0.0), (1, 1.0)]];
        assert!(Gram::<2>::new(nan).is_err());
    }
}
