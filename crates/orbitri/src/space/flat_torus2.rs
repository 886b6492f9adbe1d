//! The 2D flat torus: orientation and in-circle determinants of lifted triangles, and the
//! rest of its orbit-space plug-in. Everything else is shared with 3D (`flat_torus.rs`) and
//! the engine is the same.

use num_bigint::BigInt;

use super::flat_torus::{
    flat_torus_plugin, lift, UnperturbedInSphere, CENTER_TOLERANCE, L, RADIUS_TOLERANCE,
};
use super::{FlatTorus, OrbitSpace};
use crate::predicates::filter;
use crate::predicates::Sign;

type L2 = L<2>;

impl FlatTorus<2> {
    /// The circumcenter relative to vertex 0, certified to within `tolerance` (see
    /// [`FlatTorus::certified_center`]).
    fn center_within(&self, s: &[L2; 3], ws: &[f64; 3], tolerance: f64) -> [f64; 2] {
        self.certified_center(s, ws, tolerance, center_polynomials, |d, w| {
            let l: [BigInt; 2] =
                std::array::from_fn(|i| &d[i][0] * &d[i][0] + &d[i][1] * &d[i][1] - &w[i]);
            let det = &d[0][0] * &d[1][1] - &d[0][1] * &d[1][0];
            let num = [
                &l[0] * &d[1][1] - &l[1] * &d[0][1],
                &l[1] * &d[0][0] - &l[0] * &d[1][0],
            ];
            (num, det)
        })
    }

    /// The in-circle sign without perturbation (`Zero` when cocircular), exact.
    #[inline(always)]
    fn in_sphere_raw(&self, s: &[L2; 3], q: L2) -> Sign {
        let (d, b) = self.rows([&s[0], &s[1], &s[2]], &q);
        filter::in_circle(&d, b).unwrap_or_else(|| self.side_exact(s, q, None))
    }
}

/// The orthocenter `(l_0 d_1⊥ − l_1 d_0⊥) / (2·det)` of the edge vectors `d` with lifts
/// `l_i = |d_i|² − w_i` (Cramer's rule; the circumcenter for zero weights).
fn center_polynomials(
    d: &[[f64; 2]; 2],
    w: &[f64; 2],
    minus: fn(f64, f64) -> f64,
) -> ([f64; 2], f64) {
    let l: [f64; 2] = std::array::from_fn(|i| minus(d[i][0] * d[i][0] + d[i][1] * d[i][1], w[i]));
    let det = minus(d[0][0] * d[1][1], d[0][1] * d[1][0]);
    (
        [
            minus(l[0] * d[1][1], l[1] * d[0][1]),
            minus(l[1] * d[0][0], l[0] * d[1][0]),
        ],
        det,
    )
}

impl UnperturbedInSphere<2, 3> for FlatTorus<2> {
    #[inline(always)]
    fn in_sphere_unperturbed(&self, s: &[L2; 3], q: L2) -> Sign {
        self.in_sphere_raw(s, q)
    }
}

impl OrbitSpace<3> for FlatTorus<2> {
    type Point = [f64; 2];
    type Elem = [i8; 2];

    flat_torus_plugin!(3, 2);

    #[inline(always)]
    fn orient(&self, s: &[L2; 3]) -> Sign {
        let (d, b) = self.rows([&s[1], &s[2]], &s[0]);
        filter::orient2(&d, b).unwrap_or_else(|| self.orient_exact(s))
    }

    #[inline(always)]
    fn in_sphere(&self, s: &[L2; 3], q: L2) -> Sign {
        match self.in_sphere_raw(s, q) {
            Sign::Zero => self.perturbed(s, q, |t| self.orient(t)),
            sign => sign,
        }
    }

    #[inline(always)]
    fn orient_stored(&self, p: [&[f64; 2]; 3], off: &[[i8; 2]; 3]) -> Sign {
        let (d, b) = self.rows_stored([p[1], p[2]], [off[1], off[2]], (p[0], off[0]));
        filter::orient2(&d, b).unwrap_or_else(|| self.orient_exact(&lift(p, off)))
    }

    #[inline(always)]
    fn in_sphere_stored(&self, p: [&[f64; 2]; 3], off: &[[i8; 2]; 3], q: L2) -> Sign {
        let (d, b) = self.rows_stored(p, *off, (&q.0, q.1));
        match filter::in_circle(&d, b) {
            Some(Sign::Zero) | None => self.in_sphere(&lift(p, off), q),
            Some(sign) => sign,
        }
    }

    fn ortho_distance2(&self, s: &[L2; 3], ws: &[f64; 3]) -> f64 {
        let x = self.center_within(s, ws, RADIUS_TOLERANCE);
        x[0] * x[0] + x[1] * x[1]
    }

    fn orthocenter(&self, s: &[L2; 3], ws: &[f64; 3]) -> [f64; 2] {
        self.center_within(s, ws, CENTER_TOLERANCE)
    }

    const KEY_BITS: u32 = 32;

    fn spatial_key(&self, p: &[f64; 2]) -> u64 {
        // 2^16 cells per axis: far finer than any input's spacing needs for a sort, and half
        // the work of 31 bits (the key took 8% of a 10⁶-point build)
        crate::sort::hilbert(self.grid_cell(p, 16), 16)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_and_in_circle_conventions() {
        let t = FlatTorus::<2>::cuboid([1.0, 1.0]).unwrap();
        let z = [0i8; 2];
        let s = [([0.1, 0.1], z), ([0.6, 0.1], z), ([0.1, 0.6], z)];
        assert_eq!(t.orient(&s), Sign::Positive);
        assert_eq!(t.in_sphere(&s, ([0.2, 0.2], z)), Sign::Positive);
        assert_eq!(t.in_sphere(&s, ([0.9, 0.9], z)), Sign::Negative);
        assert_eq!(t.in_sphere(&s, ([0.2, 0.2], [1, 0])), Sign::Negative);
        let o = [2i8, -1];
        assert_eq!(
            t.in_sphere(&s.map(|(p, _)| (p, o)), ([0.2, 0.2], o)),
            Sign::Positive
        );
        // four corners of a square are cocircular: the perturbation decides, the same for
        // every periodic copy
        let sq = [([0.0, 0.0], z), ([0.5, 0.0], z), ([0.0, 0.5], z)];
        let base = t.in_sphere(&sq, ([0.5, 0.5], z));
        assert_ne!(base, Sign::Zero);
        assert_eq!(
            t.in_sphere(&sq.map(|(p, _)| (p, [1, 1])), ([0.5, 0.5], [1, 1])),
            base
        );
        assert!((t.circumradius2(&sq) - 0.125).abs() < 1e-15);
        // nearly collinear: only the exact evaluation can tell
        let e = 2f64.powi(-60);
        assert_eq!(
            t.orient(&[([0.0, 0.0], z), ([0.5, 0.0], z), ([0.25, e], z)]),
            Sign::Positive
        );
        assert_eq!(
            t.orient(&[([0.0, 0.0], z), ([0.5, 0.0], z), ([0.25, -e], z)]),
            Sign::Negative
        );
    }
}
