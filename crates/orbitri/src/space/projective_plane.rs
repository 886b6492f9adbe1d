//! The real projective plane RP² = S²/{±1} (thesis §4.3.3) as an orbit space of the
//! engine: the group of the antipodal map, cells triangles of the sphere's points
//! `±p` (an [`Antipode`] per vertex), the Delaunay triangulation that of the centrally
//! symmetric set `±P` on the sphere (the boundary of its convex hull), projected.
//!
//! The ladder has two levels: the 2-sheeted covering S² (both copies of every point), then
//! RP² itself once Criterion 4.3.4 holds: every empty spherical disk of diameter below π/2,
//! i.e. every cell's circumradius below π/4 (chord² `2 − √2`), so that no edge is as long
//! as π/2 and no two edges make a cycle in the quotient. The antipodal map reverses
//! orientation, so cells are stored positively oriented in their frames (`MAY_REVERSE`).
//!
//! Three anchors `±δ·uᵢ` (an octahedron shrunk to the centre) make the first covering, as
//! the sphere's four do; they are hidden once the points span space. Ties (four points on
//! one circle) are broken as on the sphere, by an order of the points of RP² (their
//! canonical representatives), so both copies of a configuration get the same answer.

use super::sphere::{circumradius2_of, sphere_key, Sphere};
use super::{Lifted, OrbitSpace};
use crate::predicates::spherical;
use crate::predicates::Sign;

/// An element of the antipodal group {±1}: `Antipode(true)` takes a point to its antipode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Antipode(pub bool);

crate::tds::unpacked!(Antipode);

/// The real projective plane, with its set of anchors (as [`Sphere::with_anchors`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProjectivePlane {
    sphere: Sphere,
}

type L = Lifted<[f64; 3], Antipode>;

/// The position of a lifted point: `p` or `−p` (exact).
#[inline]
fn at(x: &L) -> [f64; 3] {
    if x.1 .0 {
        x.0.map(|c| -c)
    } else {
        x.0
    }
}

/// True when no vertex of the lifted cell is negated: the stored cells away from the seam of
/// the representatives (the equator), whose predicates then read the points in place.
#[inline(always)]
fn plain(s: &[L; 3]) -> bool {
    !(s[0].1 .0 | s[1].1 .0 | s[2].1 .0)
}

/// The representative of `p`'s class in RP²: the one whose last non-zero coordinate (in the
/// order z, y, x) is positive.
pub fn canonical(p: &[f64; 3]) -> [f64; 3] {
    match [p[2], p[1], p[0]].into_iter().find(|&c| c != 0.0) {
        Some(c) if c < 0.0 => p.map(|x| -x),
        _ => *p,
    }
}

/// The perturbed in-circle test of four points on one circle (see
/// [`ProjectivePlane::in_sphere`]): kept out of line, so that the filtered test inlines.
#[cold]
#[inline(never)]
fn tie(s: [[f64; 3]; 3], x: [f64; 3]) -> Sign {
    let keys = [s[0], s[1], s[2], x].map(|p| canonical(&p));
    spherical::in_circle(&s, x, |i, j| {
        Sign::from(keys[i].partial_cmp(&keys[j]).expect("finite coordinates"))
    })
}

impl ProjectivePlane {
    /// The projective plane with the anchor set `k`: three of the sphere's set `k`
    /// directions (linearly independent), in canonical form.
    pub fn with_anchors(k: u64) -> ProjectivePlane {
        ProjectivePlane {
            sphere: Sphere::with_anchors(k),
        }
    }

    /// The number of the anchor set.
    pub fn anchor_set(&self) -> u64 {
        self.sphere.anchor_set()
    }

    /// True when `p` or `−p` lies exactly along one of the anchors' directions.
    pub fn meets_anchor(&self, p: &[f64; 3]) -> bool {
        self.sphere.meets_anchor(p)
    }
}

impl OrbitSpace<3> for ProjectivePlane {
    type Point = [f64; 3];
    type Elem = Antipode;

    fn identity(&self) -> Antipode {
        Antipode(false)
    }

    fn compose(&self, a: Antipode, b: Antipode) -> Antipode {
        Antipode(a.0 ^ b.0)
    }

    fn inverse(&self, a: Antipode) -> Antipode {
        a
    }

    fn euler_characteristic(&self) -> i64 {
        1
    }

    #[inline]
    fn orient(&self, s: &[L; 3]) -> Sign {
        if plain(s) {
            return spherical::orient_unit(&s[0].0, &s[1].0, &s[2].0);
        }
        spherical::orient_unit(&at(&s[0]), &at(&s[1]), &at(&s[2]))
    }

    /// Ties are broken as on the sphere, by the lexicographic order of the canonical
    /// representatives: both copies of a configuration are ordered alike. A tie never holds
    /// both copies of one point (their plane would pass through the centre, and the cell be
    /// flat).
    #[inline]
    fn in_sphere(&self, s: &[L; 3], q: L) -> Sign {
        if plain(s) & !q.1 .0 {
            return match spherical::side_unit(&s[0].0, &s[1].0, &s[2].0, &q.0) {
                Sign::Zero => tie([s[0].0, s[1].0, s[2].0], q.0),
                decided => decided,
            };
        }
        let [a, b, c] = [at(&s[0]), at(&s[1]), at(&s[2])];
        let x = at(&q);
        match spherical::side_unit(&a, &b, &c, &x) {
            Sign::Zero => tie([a, b, c], x),
            decided => decided,
        }
    }

    #[inline(always)]
    fn orient_stored(&self, p: [&[f64; 3]; 3], off: &[Antipode; 3]) -> Sign {
        if !(off[0].0 | off[1].0 | off[2].0) {
            return spherical::orient_unit(p[0], p[1], p[2]);
        }
        self.orient(&[(*p[0], off[0]), (*p[1], off[1]), (*p[2], off[2])])
    }

    #[inline(always)]
    fn in_sphere_stored(&self, p: [&[f64; 3]; 3], off: &[Antipode; 3], q: L) -> Sign {
        if !(off[0].0 | off[1].0 | off[2].0 | q.1 .0) {
            return match spherical::side_unit(p[0], p[1], p[2], &q.0) {
                Sign::Zero => tie([*p[0], *p[1], *p[2]], q.0),
                decided => decided,
            };
        }
        self.in_sphere(&[(*p[0], off[0]), (*p[1], off[1]), (*p[2], off[2])], q)
    }

    fn cospherical(&self, s: &[L; 3], q: L) -> bool {
        spherical::side_unit(&at(&s[0]), &at(&s[1]), &at(&s[2]), &at(&q)) == Sign::Zero
    }

    fn coincide(&self, a: L, b: L) -> bool {
        at(&a) == at(&b)
    }

    fn circumradius2(&self, s: &[L; 3]) -> f64 {
        circumradius2_of(&[at(&s[0]), at(&s[1]), at(&s[2])])
    }

    /// The projective plane carries no weights: the in-circle test (see the sphere's).
    fn power_test(&self, s: &[L; 3], ws: &[f64; 3], q: L, wq: f64) -> Sign {
        debug_assert!(ws.iter().all(|&w| w == wq), "unweighted");
        self.in_sphere(s, q)
    }

    fn orthogonal(&self, s: &[L; 3], ws: &[f64; 3], q: L, wq: f64) -> bool {
        debug_assert!(ws.iter().all(|&w| w == wq), "unweighted");
        self.cospherical(s, q)
    }

    /// The pole of the lifted cell relative to its vertex 0.
    fn orthocenter(&self, s: &[L; 3], _: &[f64; 3]) -> [f64; 3] {
        let [a, b, c] = [at(&s[0]), at(&s[1]), at(&s[2])];
        let n = super::pole(&a, &b, &c);
        std::array::from_fn(|k| n[k] - a[k])
    }

    fn ortho_distance2(&self, s: &[L; 3], _: &[f64; 3]) -> f64 {
        self.circumradius2(s)
    }

    fn levels(&self) -> usize {
        2
    }

    /// Level 1: Criterion 4.3.4, a circumradius below π/4 (chord² `2 − √2`), with a
    /// margin.
    fn criterion_radius2(&self, level: usize) -> f64 {
        if level == 0 {
            f64::INFINITY
        } else {
            (2.0 - std::f64::consts::SQRT_2) * (1.0 - 1e-7)
        }
    }

    /// A cap of angular radius below π/2 holds at most one of `±p`.
    fn single_lift_radius2(&self) -> f64 {
        2.0 * (1.0 - 1e-7)
    }

    fn covering_copies(&self, level: usize) -> Vec<Antipode> {
        if level == 0 {
            vec![Antipode(false), Antipode(true)]
        } else {
            vec![Antipode(false)]
        }
    }

    const MAY_REVERSE: bool = true;

    fn translations_only(&self) -> bool {
        false
    }

    fn reverses_orientation(&self, g: Antipode) -> bool {
        g.0
    }

    /// In RP², a cell and its antipodal copy become one: the copy with at most one vertex
    /// negated (of three elements, exactly one of the two copies has that).
    fn normalize(&self, off: &mut [Antipode; 3], level: usize) -> bool {
        if level == 0 || off.iter().filter(|g| g.0).count() < 2 {
            return false;
        }
        for g in off.iter_mut() {
            g.0 = !g.0;
        }
        true
    }

    fn dummy_points(&self) -> Vec<[f64; 3]> {
        Vec::new()
    }

    fn sheets(&self, level: usize) -> usize {
        if level == 0 {
            2
        } else {
            1
        }
    }

    fn sheet_of(&self, g: Antipode, level: usize) -> usize {
        if level == 0 {
            usize::from(g.0)
        } else {
            0
        }
    }

    fn near(&self, z: L, pts: &[[f64; 3]], radius: f64, out: &mut Vec<(u32, Antipode)>) {
        let r2 = radius * radius * (1.0 + 1e-9);
        let c = at(&z);
        for (i, p) in pts.iter().enumerate() {
            for g in [Antipode(false), Antipode(true)] {
                let x = at(&(*p, g));
                let d = [x[0] - c[0], x[1] - c[1], x[2] - c[2]];
                if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= r2 {
                    out.push((i as u32, g));
                }
            }
        }
    }

    fn edge_bound(&self, _: usize) -> f64 {
        2.0
    }

    fn spatial_key(&self, p: &[f64; 3]) -> u64 {
        sphere_key(p)
    }

    const KEY_BITS: u32 = Sphere::KEY_BITS;
    const HIDES: bool = true;

    fn anchors(&self) -> Vec<[f64; 3]> {
        self.sphere.anchors()[..3].iter().map(canonical).collect()
    }

    fn anchor_cells(&self) -> Vec<[(u32, Antipode); 3]> {
        (0..8)
            .map(|m| std::array::from_fn(|i| (i as u32, Antipode(m >> i & 1 == 1))))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::delaunay::Engine;
    use crate::sort::SplitMix;

    /// A face of S² or RP² by the bits of its lifted vertices, the same for a face and its
    /// antipode.
    fn key(f: [[f64; 3]; 3]) -> [[u64; 3]; 3] {
        let sorted = |f: [[f64; 3]; 3]| {
            let mut b = f.map(|p| p.map(f64::to_bits));
            b.sort_unstable();
            b
        };
        sorted(f).min(sorted(f.map(|p| p.map(|x| -x))))
    }

    /// The predicates on points read where they are stored equal those on lifted copies, on
    /// the sphere and in RP² (with and without negated vertices), ties included: four of
    /// the cube's corners lie on one circle.
    #[test]
    fn predicates_on_stored_points_equal_those_on_lifted_ones() {
        let mut r = SplitMix::new(9);
        let mut pts: Vec<[f64; 3]> = (0..30).map(|_| r.on_sphere()).collect();
        let c = 1.0 / 3f64.sqrt();
        pts.extend([[c, c, c], [c, -c, c], [-c, -c, c], [-c, c, c], [c, c, -c]]);
        let (sphere, rp2) = (Sphere::default(), ProjectivePlane::default());
        let mut ties = 0;
        for _ in 0..4000 {
            let k: [usize; 4] = std::array::from_fn(|_| r.below(pts.len()));
            if (0..4).any(|i| (0..i).any(|j| k[i] == k[j])) {
                continue;
            }
            let p = [&pts[k[0]], &pts[k[1]], &pts[k[2]]];
            let off: [Antipode; 4] = std::array::from_fn(|_| Antipode(r.below(3) == 0));
            let lifted = [(*p[0], off[0]), (*p[1], off[1]), (*p[2], off[2])];
            let q = (pts[k[3]], off[3]);
            let (o, w) = ([off[0], off[1], off[2]], lifted.map(|x| (x.0, ())));
            assert_eq!(rp2.orient_stored(p, &o), rp2.orient(&lifted));
            assert_eq!(sphere.orient_stored(p, &[(); 3]), sphere.orient(&w));
            if rp2.orient(&lifted) == Sign::Positive {
                let x = rp2.in_sphere(&lifted, q);
                assert_eq!(rp2.in_sphere_stored(p, &o, q), x);
                ties += rp2.cospherical(&lifted, q) as usize;
            }
            if sphere.orient(&w) == Sign::Positive {
                let x = sphere.in_sphere(&w, (q.0, ()));
                assert_eq!(sphere.in_sphere_stored(p, &[(); 3], (q.0, ())), x);
            }
        }
        assert!(ties > 0, "some picks are four corners on one circle");
    }

    #[test]
    fn anchors_alone_are_a_covering_of_the_projective_plane() {
        let e = Engine::new(ProjectivePlane::default());
        e.is_valid().unwrap();
        assert_eq!((e.number_of_cells(), e.sheets()), (8, 2));
    }

    #[test]
    fn the_quotient_is_the_sphere_of_both_copies_projected() {
        let mut r = SplitMix::new(6);
        let pts: Vec<[f64; 3]> = (0..600).map(|_| canonical(&r.on_sphere())).collect();
        let mut e = Engine::new(ProjectivePlane::default());
        let mut switched = None;
        for (k, p) in pts.iter().enumerate() {
            e.insert(*p);
            if k < 10 || k % 100 == 0 {
                e.is_valid().unwrap();
            }
            if switched.is_none() && e.is_one_sheeted() {
                switched = Some(k);
            }
        }
        e.is_valid().unwrap();
        assert!(e.is_one_sheeted(), "600 points satisfy the criterion");
        assert!(switched.unwrap() > 3);
        // χ = 1: F = 2V − 2
        assert_eq!(e.number_of_cells(), 2 * 600 - 2);
        let mut s = Engine::new(Sphere::default());
        for p in &pts {
            s.insert(*p);
            s.insert(p.map(|x| -x));
        }
        let lifted = |cell: [([f64; 3], Antipode); 3]| key(cell.map(|x| at(&x)));
        let ours: std::collections::BTreeSet<_> =
            e.cell_ids().map(|c| lifted(e.lifted_cell(c))).collect();
        let sphere: std::collections::BTreeSet<_> = s
            .cell_ids()
            .map(|c| key(s.lifted_cell(c).map(|x| x.0)))
            .collect();
        assert_eq!(ours, sphere);
    }

    #[test]
    fn cocircular_points_and_removals() {
        // a lon/lat grid (many ties), then removals back into the covering
        let mut pts = Vec::new();
        for i in 0..12 {
            for j in 1..6 {
                let (l, f) = (
                    (i as f64 * 30.0).to_radians(),
                    (j as f64 * 15.0).to_radians(),
                );
                pts.push(canonical(&[f.cos() * l.cos(), f.cos() * l.sin(), f.sin()]));
            }
        }
        pts.push([0.0, 0.0, 1.0]);
        let mut e = Engine::new(ProjectivePlane::default());
        for p in &pts {
            e.insert(*p);
        }
        e.is_valid().unwrap();
        assert_eq!(e.number_of_cells(), 2 * pts.len() - 2);
        let mut r = SplitMix::new(2);
        while e.number_of_points() > 1 {
            let p = crate::ids::PointId::new(3 + r.below(e.number_of_points()));
            e.remove_point(p);
            e.is_valid().unwrap();
        }
    }
}
