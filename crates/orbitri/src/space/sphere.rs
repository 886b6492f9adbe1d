//! The sphere S² (thesis §4.3.1) as an orbit space of the engine: the trivial group, cells
//! are triangles `[f64; 3]³` positively oriented about the centre, and the Delaunay
//! triangulation is the boundary of the convex hull of the points (the spherical Delaunay
//! triangulation for points on the unit sphere, the regular triangulation on the sphere for
//! points near it: a point strictly inside the hull of the others is hidden).
//!
//! Four anchors `δ·tᵢ` (a tetrahedron around the centre shrunk to it, `δ` infinitesimal, see
//! [`spherical::side_of_circle`]) keep the centre strictly inside the hull of any point set,
//! so that one point, three points or a hemisphere are triangulations too: the cells free
//! of anchors are exactly the faces of the hull that have the centre strictly on their
//! inner side (CGAL's solid faces), and an anchor is hidden once the points enclose the
//! centre.

use super::{Lifted, OrbitSpace};
use crate::predicates::spherical::{self, ANCHOR_SCALE};
use crate::predicates::Sign;

/// The unit sphere S², with its set of anchors ([`Sphere::with_anchors`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    anchor_set: u64,
    /// The anchors' directions (integers).
    directions: [[f64; 3]; 4],
}

impl Default for Sphere {
    fn default() -> Self {
        Sphere::with_anchors(0)
    }
}

/// The anchor directions of set `k` (see [`Sphere::with_anchors`]).
fn directions(k: u64) -> [[f64; 3]; 4] {
    let mut r = crate::sort::SplitMix::new(0xa9c4_0000 ^ k);
    loop {
        let mut v = [[0.0; 3]; 4];
        for t in v.iter_mut().take(3) {
            *t = std::array::from_fn(|_| r.below(1 << 22) as f64 - (1 << 21) as f64);
        }
        v[3] = std::array::from_fn(|k| -(v[0][k] + v[1][k] + v[2][k]));
        // (spanning, and no two along one line: then no three coplanar with the centre
        // either, as each triple spans with the fourth)
        let independent = (0..4).all(|i| {
            let [a, b, c] = [v[(i + 1) % 4], v[(i + 2) % 4], v[(i + 3) % 4]];
            spherical::orient_origin(&a, &b, &c) != Sign::Zero
        });
        if independent {
            return v;
        }
    }
}

impl Sphere {
    /// The sphere with the anchor set `k`: four integer directions `tᵢ` (coordinates below
    /// 2²², in general position, `t₃ = −(t₀ + t₁ + t₂)` so that the centre is their
    /// centroid) drawn from a generator seeded with `k`. A point exactly along an anchor's
    /// direction would make a flat cell with it, which no perturbation separates; the
    /// facade picks a set that no point meets ([`Sphere::meets_anchor`]).
    pub fn with_anchors(k: u64) -> Sphere {
        Sphere {
            anchor_set: k,
            directions: directions(k),
        }
    }

    /// The number of the anchor set.
    pub fn anchor_set(&self) -> u64 {
        self.anchor_set
    }

    /// The anchors' directions (integers, exact as doubles).
    pub fn anchor_directions(&self) -> [[f64; 3]; 4] {
        self.directions
    }

    /// True when `p` lies exactly along (or against) one of the anchors' directions.
    pub fn meets_anchor(&self, p: &[f64; 3]) -> bool {
        let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        self.anchor_directions().iter().any(|t| {
            // |p × t| is small first (cheap), then zero exactly: det[p; t; e_k] = 0 for all k
            let n = cross(p, t);
            dot(&n, &n) <= 1e-12 * dot(p, p) * dot(t, t)
                && axes
                    .iter()
                    .all(|e| spherical::orient_origin(p, t, e) == Sign::Zero)
        })
    }
}

/// A lifted point of the sphere (the group is trivial).
type L = Lifted<[f64; 3], ()>;

fn cross(u: &[f64; 3], v: &[f64; 3]) -> [f64; 3] {
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

/// `(b − a) × (c − a)`.
fn normal(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> [f64; 3] {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    cross(&u, &v)
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The pole of the circumcircle of the positively oriented triangle `abc` of points near
/// the unit sphere: the unit normal of its plane, pointing away from the centre (the
/// spherical circumcentre, a vertex of the Voronoi diagram). Each coordinate is within a
/// few units in the last place of the exact unit normal unless the triangle is a sliver.
pub fn pole(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> [f64; 3] {
    let n = normal(a, b, c);
    let len = dot(&n, &n).sqrt();
    n.map(|x| x / len)
}

/// The squared chord from the pole of the positively oriented triangle `s` to its vertex 0
/// (`2 − 2 cos θ` for the angular radius `θ`), accurate to about `1e-12` absolute; 4 (the
/// largest) for a cell with an anchor.
pub(crate) fn circumradius2_of(s: &[[f64; 3]; 3]) -> f64 {
    if s.iter().any(spherical::is_anchor) {
        return 4.0;
    }
    let n = pole(&s[0], &s[1], &s[2]);
    let r = dot(&s[0], &s[0]).sqrt();
    (2.0 - 2.0 * dot(&n, &s[0]) / r).clamp(0.0, 4.0)
}

/// The key of a point along a space-filling curve over the sphere: the cube face its
/// direction passes through (3 bits), then the Hilbert index of its gnomonic coordinates on
/// that face (16 bits per axis: far finer than a sort needs, and half the work of 30).
pub(crate) fn sphere_key(p: &[f64; 3]) -> u64 {
    let a = p.map(f64::abs);
    let axis = if a[0] >= a[1] && a[0] >= a[2] {
        0
    } else if a[1] >= a[2] {
        1
    } else {
        2
    };
    let face = 2 * axis as u64 + u64::from(p[axis] < 0.0);
    let half = 0.5 * (1u32 << 16) as f64 / a[axis];
    let cell = |x: f64| -> u32 { ((x * half + (1u32 << 15) as f64) as u32).min((1 << 16) - 1) };
    let h = crate::sort::hilbert::<2>([cell(p[(axis + 1) % 3]), cell(p[(axis + 2) % 3])], 16);
    (face << 32) | h
}

/// The perturbed in-circle test of four points on one circle (see [`Sphere::in_sphere`]).
#[cold]
#[inline(never)]
fn tie(s: &[L; 3], q: L) -> Sign {
    let pts = [s[0].0, s[1].0, s[2].0, q.0];
    spherical::in_circle(&[pts[0], pts[1], pts[2]], q.0, |i, j| {
        Sign::from(pts[i].partial_cmp(&pts[j]).expect("finite coordinates"))
    })
}

impl OrbitSpace<3> for Sphere {
    type Point = [f64; 3];
    type Elem = ();

    fn identity(&self) {}
    fn compose(&self, _: (), _: ()) {}
    fn inverse(&self, _: ()) {}

    fn euler_characteristic(&self) -> i64 {
        2
    }

    #[inline]
    fn orient(&self, s: &[L; 3]) -> Sign {
        spherical::orient_unit(&s[0].0, &s[1].0, &s[2].0)
    }

    /// Ties are broken by pulling the later points of the lexicographic order of
    /// coordinates further towards the centre: the same whatever the insertion order.
    #[inline]
    fn in_sphere(&self, s: &[L; 3], q: L) -> Sign {
        match spherical::side_unit(&s[0].0, &s[1].0, &s[2].0, &q.0) {
            Sign::Zero => tie(s, q),
            decided => decided,
        }
    }

    #[inline(always)]
    fn orient_stored(&self, p: [&[f64; 3]; 3], _: &[(); 3]) -> Sign {
        spherical::orient_unit(p[0], p[1], p[2])
    }

    #[inline(always)]
    fn in_sphere_stored(&self, p: [&[f64; 3]; 3], _: &[(); 3], q: L) -> Sign {
        match spherical::side_unit(p[0], p[1], p[2], &q.0) {
            Sign::Zero => tie(&[(*p[0], ()), (*p[1], ()), (*p[2], ())], q),
            decided => decided,
        }
    }

    fn cospherical(&self, s: &[L; 3], q: L) -> bool {
        spherical::side_unit(&s[0].0, &s[1].0, &s[2].0, &q.0) == Sign::Zero
    }

    fn coincide(&self, a: L, b: L) -> bool {
        a.0 == b.0
    }

    /// The squared chord from the cell's pole to its vertex 0 (4 for a cell with an anchor).
    fn circumradius2(&self, s: &[L; 3]) -> f64 {
        circumradius2_of(&[s[0].0, s[1].0, s[2].0])
    }

    /// The sphere carries no weights (its triangulations are never weighted): this is the
    /// in-circle test, which the power test of equal weights is.
    fn power_test(&self, s: &[L; 3], ws: &[f64; 3], q: L, wq: f64) -> Sign {
        debug_assert!(
            ws.iter().all(|&w| w == wq),
            "the sphere's points are unweighted"
        );
        self.in_sphere(s, q)
    }

    fn orthogonal(&self, s: &[L; 3], ws: &[f64; 3], q: L, wq: f64) -> bool {
        debug_assert!(
            ws.iter().all(|&w| w == wq),
            "the sphere's points are unweighted"
        );
        self.cospherical(s, q)
    }

    /// The pole of the cell ([`pole`]) relative to vertex 0.
    fn orthocenter(&self, s: &[L; 3], _: &[f64; 3]) -> [f64; 3] {
        let n = pole(&s[0].0, &s[1].0, &s[2].0);
        std::array::from_fn(|k| n[k] - s[0].0[k])
    }

    fn ortho_distance2(&self, s: &[L; 3], _: &[f64; 3]) -> f64 {
        self.circumradius2(s)
    }

    fn levels(&self) -> usize {
        1
    }

    fn criterion_radius2(&self, _: usize) -> f64 {
        f64::INFINITY
    }

    fn single_lift_radius2(&self) -> f64 {
        f64::INFINITY
    }

    fn covering_copies(&self, _: usize) -> Vec<()> {
        vec![()]
    }

    const MAY_REVERSE: bool = false;

    fn reverses_orientation(&self, _: ()) -> bool {
        false
    }

    fn normalize(&self, _: &mut [(); 3], _: usize) -> bool {
        false
    }

    fn dummy_points(&self) -> Vec<[f64; 3]> {
        Vec::new()
    }

    fn sheets(&self, _: usize) -> usize {
        1
    }

    fn sheet_of(&self, _: (), _: usize) -> usize {
        0
    }

    fn near(&self, z: L, pts: &[[f64; 3]], radius: f64, out: &mut Vec<(u32, ())>) {
        let r2 = radius * radius * (1.0 + 1e-9);
        for (i, p) in pts.iter().enumerate() {
            let d = [p[0] - z.0[0], p[1] - z.0[1], p[2] - z.0[2]];
            if dot(&d, &d) <= r2 {
                out.push((i as u32, ()));
            }
        }
    }

    fn edge_bound(&self, _: usize) -> f64 {
        2.0
    }

    fn spatial_key(&self, p: &[f64; 3]) -> u64 {
        sphere_key(p)
    }

    const KEY_BITS: u32 = 35;
    const HIDES: bool = true;

    fn anchors(&self) -> Vec<[f64; 3]> {
        // (the directions are integers below 2²³: scaled by 2⁻¹⁰⁰⁰ exactly, and far below
        // the 2⁻⁹⁰⁰ that marks an anchor)
        self.anchor_directions()
            .iter()
            .map(|t| t.map(|x| x * ANCHOR_SCALE / (1u64 << 23) as f64))
            .collect()
    }

    fn anchor_cells(&self) -> Vec<[(u32, ()); 3]> {
        [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]]
            .map(|c| c.map(|i| (i, ())))
            .to_vec()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::delaunay::Engine;
    use crate::sort::SplitMix;

    #[test]
    fn anchors_alone_are_a_valid_sphere() {
        let e = Engine::new(Sphere::default());
        e.is_valid().unwrap();
        assert_eq!(e.number_of_cells(), 4);
        assert_eq!(e.number_of_points(), 0);
    }

    #[test]
    fn random_points_hide_every_anchor() {
        let mut e = Engine::new(Sphere::default());
        let mut r = SplitMix::new(1);
        for k in 0..500 {
            e.insert(r.on_sphere());
            if k < 12 || k % 50 == 0 {
                e.is_valid().unwrap();
            }
        }
        e.is_valid().unwrap();
        assert!((0..4).all(|a| e.is_hidden_anchor(crate::ids::PointId(a))));
        // a triangulated sphere: 2V − 4 faces
        assert_eq!(e.number_of_cells(), 2 * 500 - 4);
    }

    #[test]
    fn anchors_enclose_the_centre_and_points_along_them_are_detected() {
        for k in 0..20 {
            let s = Sphere::with_anchors(k);
            let t = s.anchor_directions();
            // the centre is strictly inside: each face turns its outer side away from it
            let e = Engine::new(s);
            e.is_valid().unwrap();
            assert_eq!(e.number_of_cells(), 4);
            assert!(s.meets_anchor(&t[1].map(|x| x * 0.5f64.powi(22))));
            assert!(s.meets_anchor(&t[2].map(|x| -x)));
            assert!(!s.meets_anchor(&[0.0, 0.0, 1.0]));
        }
    }

    #[test]
    fn keys_follow_the_cube_faces() {
        assert_eq!(sphere_key(&[1.0, 0.0, 0.0]) >> 32, 0);
        assert_eq!(sphere_key(&[-1.0, 0.0, 0.0]) >> 32, 1);
        assert_eq!(sphere_key(&[0.0, 0.0, -1.0]) >> 32, 5);
        assert!(sphere_key(&[0.0, 0.0, -1.0]) < 1 << Sphere::KEY_BITS);
        // neighbours on a face are near along the curve; the face's corners stay on it
        let k = |x: f64, y: f64| sphere_key(&[1.0, x, y]) & 0xffff_ffff;
        assert!(k(0.999_999, 0.999_999) < 1 << 32 && k(-1.0, -1.0) < 1 << 32);
    }
}
