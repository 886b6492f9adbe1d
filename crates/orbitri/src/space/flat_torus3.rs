//! The 3D flat torus: orientation and in-sphere determinants of lifted tetrahedra, and the
//! rest of its orbit-space plug-in.

use num_bigint::BigInt;

use super::flat_torus::{
    flat_torus_plugin, lift, UnperturbedInSphere, CENTER_TOLERANCE, L, RADIUS_TOLERANCE,
};
use super::{FlatTorus, OrbitSpace};
use crate::predicates::filter;
use crate::predicates::Sign;

type L3 = L<3>;

impl FlatTorus<3> {
    /// The circumcenter relative to vertex 0, certified to within `tolerance` (see
    /// [`FlatTorus::certified_center`]).
    fn center_within(&self, s: &[L3; 4], ws: &[f64; 4], tolerance: f64) -> [f64; 3] {
        self.certified_center(s, ws, tolerance, center_polynomials, |d, w| {
            let l: [BigInt; 3] = std::array::from_fn(|i| {
                &d[i][0] * &d[i][0] + &d[i][1] * &d[i][1] + &d[i][2] * &d[i][2] - &w[i]
            });
            let cross = |a: &[BigInt; 3], b: &[BigInt; 3]| -> [BigInt; 3] {
                [
                    &a[1] * &b[2] - &a[2] * &b[1],
                    &a[2] * &b[0] - &a[0] * &b[2],
                    &a[0] * &b[1] - &a[1] * &b[0],
                ]
            };
            let (c12, c20, c01) = (
                cross(&d[1], &d[2]),
                cross(&d[2], &d[0]),
                cross(&d[0], &d[1]),
            );
            let det = &d[0][0] * &c12[0] + &d[0][1] * &c12[1] + &d[0][2] * &c12[2];
            let num = std::array::from_fn(|k| &l[0] * &c12[k] + &l[1] * &c20[k] + &l[2] * &c01[k]);
            (num, det)
        })
    }

    /// The in-sphere sign without perturbation (`Zero` when cospherical), exact.
    #[inline(always)]
    fn in_sphere_raw(&self, s: &[L3; 4], q: L3) -> Sign {
        let (d, b) = self.rows([&s[0], &s[1], &s[2], &s[3]], &q);
        filter::in_sphere3(&d, b).unwrap_or_else(|| self.side_exact(s, q, None))
    }
}

/// The orthocenter `Σ l_i (d_j × d_k) / (2·det)` of the edge vectors `d` with lifts
/// `l_i = |d_i|² − w_i` (Cramer's rule; the circumcenter for zero weights).
fn center_polynomials(
    d: &[[f64; 3]; 3],
    w: &[f64; 3],
    minus: fn(f64, f64) -> f64,
) -> ([f64; 3], f64) {
    let l: [f64; 3] = std::array::from_fn(|i| {
        minus(
            d[i][0] * d[i][0] + d[i][1] * d[i][1] + d[i][2] * d[i][2],
            w[i],
        )
    });
    let cross = |a: &[f64; 3], b: &[f64; 3]| {
        [
            minus(a[1] * b[2], a[2] * b[1]),
            minus(a[2] * b[0], a[0] * b[2]),
            minus(a[0] * b[1], a[1] * b[0]),
        ]
    };
    let (c12, c20, c01) = (
        cross(&d[1], &d[2]),
        cross(&d[2], &d[0]),
        cross(&d[0], &d[1]),
    );
    let det = d[0][0] * c12[0] + d[0][1] * c12[1] + d[0][2] * c12[2];
    (
        std::array::from_fn(|k| l[0] * c12[k] + l[1] * c20[k] + l[2] * c01[k]),
        det,
    )
}

impl UnperturbedInSphere<3, 4> for FlatTorus<3> {
    #[inline(always)]
    fn in_sphere_unperturbed(&self, s: &[L3; 4], q: L3) -> Sign {
        self.in_sphere_raw(s, q)
    }
}

impl OrbitSpace<4> for FlatTorus<3> {
    type Point = [f64; 3];
    type Elem = [i8; 3];

    flat_torus_plugin!(4, 3);

    #[inline(always)]
    fn orient(&self, s: &[L3; 4]) -> Sign {
        let (d, b) = self.rows([&s[1], &s[2], &s[3]], &s[0]);
        filter::orient3(&d, b).unwrap_or_else(|| self.orient_exact(s))
    }

    #[inline(always)]
    fn in_sphere(&self, s: &[L3; 4], q: L3) -> Sign {
        match self.in_sphere_raw(s, q) {
            Sign::Zero => self.perturbed(s, q, |t| self.orient(t)),
            sign => sign,
        }
    }

    #[inline(always)]
    fn orient_stored(&self, p: [&[f64; 3]; 4], off: &[[i8; 3]; 4]) -> Sign {
        let (d, b) = self.rows_stored([p[1], p[2], p[3]], [off[1], off[2], off[3]], (p[0], off[0]));
        filter::orient3(&d, b).unwrap_or_else(|| self.orient_exact(&lift(p, off)))
    }

    #[inline(always)]
    fn in_sphere_stored(&self, p: [&[f64; 3]; 4], off: &[[i8; 3]; 4], q: L3) -> Sign {
        let (d, b) = self.rows_stored(p, *off, (&q.0, q.1));
        match filter::in_sphere3(&d, b) {
            Some(Sign::Zero) | None => self.in_sphere(&lift(p, off), q),
            Some(sign) => sign,
        }
    }

    fn ortho_distance2(&self, s: &[L3; 4], ws: &[f64; 4]) -> f64 {
        let x = self.center_within(s, ws, RADIUS_TOLERANCE);
        x[0] * x[0] + x[1] * x[1] + x[2] * x[2]
    }

    fn orthocenter(&self, s: &[L3; 4], ws: &[f64; 4]) -> [f64; 3] {
        self.center_within(s, ws, CENTER_TOLERANCE)
    }

    const KEY_BITS: u32 = 63;

    fn spatial_key(&self, p: &[f64; 3]) -> u64 {
        crate::sort::hilbert(self.grid_cell(p, 21), 21)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::space::{FlatTorus2, FlatTorus3, Ladder};

    fn unit() -> FlatTorus3 {
        FlatTorus3::cuboid([1.0; 3]).unwrap()
    }

    /// The corner of a cube of side 0.5 at the origin: its circumsphere passes through all
    /// eight corners of that cube.
    fn corner_tetrahedron() -> [L3; 4] {
        let z = [0i8; 3];
        [
            ([0.0, 0.0, 0.0], z),
            ([0.5, 0.0, 0.0], z),
            ([0.0, 0.5, 0.0], z),
            ([0.0, 0.0, 0.5], z),
        ]
    }

    #[test]
    fn orientation_and_in_sphere_conventions() {
        let t = unit();
        let z = [0i8; 3];
        let s = [
            ([0.1, 0.1, 0.1], z),
            ([0.6, 0.1, 0.1], z),
            ([0.1, 0.6, 0.1], z),
            ([0.1, 0.1, 0.6], z),
        ];
        assert_eq!(t.orient(&s), Sign::Positive);
        assert_eq!(t.in_sphere(&s, ([0.2, 0.2, 0.2], z)), Sign::Positive);
        assert_eq!(t.in_sphere(&s, ([0.9, 0.9, 0.9], z)), Sign::Negative);
        // the same point one period away is outside
        assert_eq!(
            t.in_sphere(&s, ([0.2, 0.2, 0.2], [1, 0, 0])),
            Sign::Negative
        );
        // a lifted copy of the whole configuration gives the same answers
        let o = [1i8, -1, 2];
        let s2 = s.map(|(p, _)| (p, o));
        assert_eq!(t.orient(&s2), Sign::Positive);
        assert_eq!(t.in_sphere(&s2, ([0.2, 0.2, 0.2], o)), Sign::Positive);
    }

    #[test]
    fn exact_on_tiny_differences() {
        let t = unit();
        let z = [0i8; 3];
        let e = 2f64.powi(-60);
        // nearly flat: the filter must defer, the exact answer is positive
        let s = [
            ([0.0, 0.0, 0.0], z),
            ([0.5, 0.0, 0.0], z),
            ([0.0, 0.5, 0.0], z),
            ([0.25, 0.25, e], z),
        ];
        assert!(filter::orient3(
            &[[0.5, 0.0, 0.0], [0.0, 0.5, 0.0], [0.25, 0.25, e]],
            [0.5; 3]
        )
        .is_none());
        assert_eq!(t.orient(&s), Sign::Positive);
        let mut below = s;
        below[3].0[2] = -e;
        assert_eq!(t.orient(&below), Sign::Negative);
        let flat = [
            ([0.0, 0.0, 0.5], z),
            ([0.5, 0.0, 0.5], z),
            ([0.0, 0.5, 0.5], z),
            ([0.5, 0.5, 0.5], z),
        ];
        assert_eq!(t.orient(&flat), Sign::Zero);
        // across the boundary: (0.9,..) at offset -1 equals (-0.1, ..)
        let w = [
            ([0.9, 0.0, 0.0], [-1, 0, 0]),
            ([0.5, 0.0, 0.0], z),
            ([0.0, 0.5, 0.0], z),
            ([0.0, 0.0, 0.5], z),
        ];
        assert_eq!(t.orient(&w), Sign::Positive);
    }

    #[test]
    fn cospherical_ties_are_perturbed_consistently() {
        let t = unit();
        let z = [0i8; 3];
        // corners of a cube: all cospherical
        let s = corner_tetrahedron();
        let q = ([0.5, 0.5, 0.5], z);
        let base = t.in_sphere(&s, q);
        assert_ne!(base, Sign::Zero);
        for o in [[1i8, 0, 0], [0, -1, 3], [2, 2, 2]] {
            let s2 = s.map(|(p, _)| (p, o));
            assert_eq!(t.in_sphere(&s2, (q.0, o)), base, "copy {o:?}");
        }
        assert!(t.coincide(([0.0, 0.5, 0.5], [1, 0, 0]), ([1.0, 0.5, 0.5], z)));
        assert!(!t.coincide(([0.0, 0.5, 0.5], [1, 0, 0]), ([0.5, 0.5, 0.5], z)));
        assert_eq!(
            t.compare_lifted(([0.0, 0.9, 0.0], [1, 0, 0]), ([0.5, 0.0, 0.0], z)),
            Sign::Positive
        );
    }

    #[test]
    fn circumradius_and_normalize() {
        let t = unit();
        let s = corner_tetrahedron();
        assert!((t.circumradius2(&s) - 0.1875).abs() < 1e-15);
        let mut off = [[1i8, 2, 0], [1, 1, 0], [2, 1, 1], [1, 1, 0]];
        t.normalize(&mut off, 1);
        assert_eq!(off, [[0, 1, 0], [0, 0, 0], [1, 0, 1], [0, 0, 0]]);
        let mut off = [[4i8, -1, 0], [3, 0, 0], [4, 0, 1], [3, 0, 0]];
        t.normalize(&mut off, 0);
        assert_eq!(off, [[1, 2, 0], [0, 3, 0], [1, 3, 1], [0, 3, 0]]);
        assert_eq!(t.covering_copies(0).len(), 27);
        assert_eq!(t.levels(), 2);
    }

    /// The lift level: two copies along each vector, after the ladder's levels, with twice
    /// the torus's systole; weighted tori keep it; a 2D torus has one only on the grid
    /// ladder (the halving ladder's levels lie between level 0 and the torus already).
    #[test]
    fn the_lift_level_has_two_copies_along_each_vector() {
        for t in [unit(), unit().for_spread(0.01).unwrap()] {
            let lift = t.lift_level().expect("a 3D torus has a lift level");
            assert_eq!(lift, t.levels());
            assert_eq!(t.sheets(lift), 8);
            let mut copies = t.covering_copies(lift);
            copies.sort_unstable();
            let want: Vec<[i8; 3]> = (0..8).map(|k| [k >> 2 & 1, k >> 1 & 1, k & 1]).collect();
            assert_eq!(copies, want);
            let quotient = t.criterion_radius2(t.levels() - 1);
            assert!((t.criterion_radius2(lift) / quotient - 4.0).abs() < 1e-12);
            let bound = t.edge_bound(t.levels() - 1);
            assert!((t.edge_bound(lift) - 2.0 * bound).abs() < 1e-12);
            // the canonical form moves a cell by one element of 2ℤ³, and is kept
            let was = [[3i8, -1, 2], [2, 0, 2], [3, 0, 3], [2, 0, 2]];
            let mut off = was;
            t.normalize(&mut off, lift);
            let by: [i8; 3] = std::array::from_fn(|c| off[0][c] - was[0][c]);
            assert!(by.iter().all(|x| x % 2 == 0));
            assert!((0..4).all(|i| (0..3).all(|c| off[i][c] - was[i][c] == by[c])));
            let again = off;
            t.normalize(&mut off, lift);
            assert_eq!(off, again);
            let sheets: std::collections::BTreeSet<usize> =
                copies.iter().map(|&o| t.sheet_of(o, lift)).collect();
            assert_eq!(sheets.len(), 8);
        }
        let square = FlatTorus2::cuboid([1.0; 2]).unwrap();
        assert_eq!(OrbitSpace::<3>::lift_level(&square), None);
        let grid = FlatTorus2::with_ladder(square.lattice.clone(), Ladder::Grid);
        let lift = OrbitSpace::<3>::lift_level(&grid).expect("the grid ladder has one");
        assert_eq!(OrbitSpace::<3>::sheets(&grid, lift), 4);
    }

    /// Slivers: four points near one circle, lifted off its plane by `h`. The circumradius
    /// (certified to `2^-28`, for the criterion) agrees with the tight circumcenter's, to
    /// within that, however flat the sliver; the radius tends to the circle's, 0.1.
    #[test]
    fn sliver_circumradius() {
        let t = unit();
        let z = [0i8; 3];
        for h in [1e-3, 1e-7, 1e-11, 1e-14] {
            let s = [
                ([0.6, 0.5, 0.5], z),
                ([0.5, 0.6, 0.5 + h], z),
                ([0.4, 0.5, 0.5], z),
                ([0.5, 0.4, 0.5 + h], z),
            ];
            let r2 = t.circumradius2(&s);
            let x = t.circumcenter(&s);
            let tight = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
            assert!(
                ((r2 - tight) / tight).abs() < 2f64.powi(-27),
                "h = {h}: {r2} vs {tight}"
            );
            assert!((r2 - 0.01).abs() < 1e-6, "h = {h}: {r2}");
        }
        let flat = [
            ([0.6, 0.5, 0.5], z),
            ([0.5, 0.6, 0.5], z),
            ([0.4, 0.5, 0.5], z),
            ([0.5, 0.4, 0.5], z),
        ];
        assert_eq!(t.circumradius2(&flat), f64::INFINITY);
    }
}
