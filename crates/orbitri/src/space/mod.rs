//! Orbit spaces as plug-ins of the engine: each knows its group elements (offsets), its exact
//! predicates on lifted points, its covering space and its switch criterion.

mod flat_manifold;
mod flat_torus;
mod flat_torus2;
mod flat_torus3;
mod klein_bottle;
mod lattice;
mod left_order;
mod metric;
mod platycosms;
mod projective_plane;
mod sphere;
mod sublattice;

pub use flat_manifold::{Coset, FlatManifold, Motion};
pub use flat_torus::{FlatTorus, FlatTorus2, FlatTorus3, Offset3};
pub(crate) use lattice::ldexp;
pub use lattice::{Ladder, Lattice, Level, MAX_COPIES, MAX_DEFECT};
pub use projective_plane::{canonical as projective_representative, Antipode, ProjectivePlane};
pub(crate) use sphere::sphere_key;
pub use sphere::{pole, Sphere};
pub use sublattice::Sublattice;

use crate::predicates::Sign;
use std::fmt::Debug;
use std::hash::Hash;

/// A point of the domain together with the group element that lifts it into the universal
/// cover: for a flat torus, the lifted point is `p + o·M`.
pub type Lifted<P, O> = (P, O);

/// An orbit space whose triangulations have cells of `N` vertices.
pub trait OrbitSpace<const N: usize>: Clone + Sync + Send {
    /// A point of the fundamental domain.
    type Point: Copy + Debug + PartialEq + Send + Sync;
    /// A group element, as stored per cell vertex (flat torus: an integer offset vector).
    /// It acts on points from the left: a cell vertex `(p, g)` lies at `g·p`, and
    /// translating a cell by `h` makes its elements `h∘g`.
    type Elem: Copy + Debug + Eq + Hash + Ord + Send + Sync + crate::tds::Packing;

    /// The identity element.
    fn identity(&self) -> Self::Elem;
    /// `a∘b`: first `b`, then `a`.
    fn compose(&self, a: Self::Elem, b: Self::Elem) -> Self::Elem;
    /// `a⁻¹`.
    fn inverse(&self, a: Self::Elem) -> Self::Elem;
    /// `b⁻¹∘a`: the element `a` seen from the frame of `b` (a vertex's element relative to
    /// another vertex of the same cell; a query carried into a neighbour's frame). Invariant
    /// under translating both by the same element.
    #[inline]
    fn relative(&self, a: Self::Elem, b: Self::Elem) -> Self::Elem {
        self.compose(self.inverse(b), a)
    }
    /// `to∘from⁻¹`: the element that carries the frame of `from` onto the frame of `to`
    /// (the translation between two cells sharing a vertex).
    #[inline]
    fn carry(&self, from: Self::Elem, to: Self::Elem) -> Self::Elem {
        self.compose(to, self.inverse(from))
    }
    /// The Euler characteristic of the space (0 for every closed flat manifold), which
    /// `is_valid` checks.
    fn euler_characteristic(&self) -> i64;
    /// Exact orientation of the lifted simplex.
    fn orient(&self, s: &[Lifted<Self::Point, Self::Elem>; N]) -> Sign;
    /// Exact, symbolically perturbed in-sphere test: `Positive` when `q` is inside the
    /// circumsphere of the positively oriented `s`, never `Zero` for a point distinct from
    /// the vertices. The perturbation is invariant under the group (a torus's lexicographic
    /// order of lifted positions; a manifold's order of points and of copies by the group's
    /// left order), so every copy of a configuration gets the same answer.
    fn in_sphere(
        &self,
        s: &[Lifted<Self::Point, Self::Elem>; N],
        q: Lifted<Self::Point, Self::Elem>,
    ) -> Sign;
    /// [`OrbitSpace::orient`] of the points `p` lifted by `off`, read where they are stored
    /// (see [`OrbitSpace::in_sphere_stored`]).
    #[inline(always)]
    fn orient_stored(&self, p: [&Self::Point; N], off: &[Self::Elem; N]) -> Sign {
        self.orient(&std::array::from_fn(|i| (*p[i], off[i])))
    }
    /// [`OrbitSpace::in_sphere`] of the points `p` lifted by `off`, read where they are
    /// stored: a space may test them without copying them into a lifted simplex first (the
    /// default copies).
    #[inline(always)]
    fn in_sphere_stored(
        &self,
        p: [&Self::Point; N],
        off: &[Self::Elem; N],
        q: Lifted<Self::Point, Self::Elem>,
    ) -> Sign {
        self.in_sphere(&std::array::from_fn(|i| (*p[i], off[i])), q)
    }
    /// Exact test whether `q` lies on the circumsphere of `s` (no perturbation): the
    /// Voronoi vertices of such cells coincide.
    fn cospherical(
        &self,
        s: &[Lifted<Self::Point, Self::Elem>; N],
        q: Lifted<Self::Point, Self::Elem>,
    ) -> bool;
    /// Exact test whether two lifted points coincide.
    fn coincide(
        &self,
        a: Lifted<Self::Point, Self::Elem>,
        b: Lifted<Self::Point, Self::Elem>,
    ) -> bool;
    /// Squared circumradius, certified to a relative accuracy of about `2^-28` (infinite for
    /// a flat simplex): enough for the switch criterion, whose radii carry a margin of
    /// `1e-7`, and cheaper than [`OrbitSpace::circumcenter`] for slivers.
    fn circumradius2(&self, s: &[Lifted<Self::Point, Self::Elem>; N]) -> f64 {
        self.ortho_distance2(s, &[0.0; N])
    }
    /// The circumcenter of the lifted simplex relative to its vertex 0, in Cartesian
    /// coordinates, certified: a floating-point evaluation whose error bound is below
    /// `2^-36` of its magnitude (and of the simplex's extent) is accepted, otherwise it is
    /// computed exactly and rounded. Infinite coordinates for a flat simplex.
    fn circumcenter(&self, s: &[Lifted<Self::Point, Self::Elem>; N]) -> Self::Point {
        self.orthocenter(s, &[0.0; N])
    }
    /// Exact, symbolically perturbed power test of weighted points: `Positive` when `q` of
    /// weight `wq` is in conflict with the positively oriented `s` of weights `ws` (its
    /// power distance `|q − z|² − wq` to their orthogonal sphere `(z, ρ)` is below `ρ`).
    /// Ties are broken by the perturbation of [`OrbitSpace::in_sphere`], which with equal
    /// weights it equals.
    fn power_test(
        &self,
        s: &[Lifted<Self::Point, Self::Elem>; N],
        ws: &[f64; N],
        q: Lifted<Self::Point, Self::Elem>,
        wq: f64,
    ) -> Sign;
    /// Exact test whether `q` is orthogonal to the orthogonal sphere of `s` (no
    /// perturbation): the power-diagram vertices of such cells coincide.
    fn orthogonal(
        &self,
        s: &[Lifted<Self::Point, Self::Elem>; N],
        ws: &[f64; N],
        q: Lifted<Self::Point, Self::Elem>,
        wq: f64,
    ) -> bool;
    /// The orthocenter (center of the sphere orthogonal to every weighted vertex) relative
    /// to vertex 0, certified as [`OrbitSpace::circumcenter`], which it is for equal weights.
    fn orthocenter(&self, s: &[Lifted<Self::Point, Self::Elem>; N], ws: &[f64; N]) -> Self::Point;
    /// The squared distance from the orthocenter to vertex 0, certified as
    /// [`OrbitSpace::circumradius2`], which it is for equal weights.
    fn ortho_distance2(&self, s: &[Lifted<Self::Point, Self::Elem>; N], ws: &[f64; N]) -> f64;
    /// Number of levels of the covering ladder: level 0 is a covering in which every
    /// non-empty point set has a Delaunay triangulation, each next level has fewer sheets, and
    /// the last is the orbit space itself (1 sheet). A lift level, if any, is numbered
    /// `levels()` ([`OrbitSpace::lift_level`]).
    fn levels(&self) -> usize;
    /// A covering with fewer sheets than level 0, outside the ladder (no cover of level 0,
    /// so never descended to), to which a quotient is lifted when points cannot leave it in
    /// place: its level number (`levels()`, after the ladder's), every per-level method
    /// answering for it. `None` when there is none.
    fn lift_level(&self) -> Option<usize> {
        None
    }
    /// Squared circumradius below which every cell allows `level`: then the level's space
    /// is triangulated for this point set and every superset (Corollary 9 of Caroli–Teillaud,
    /// `Δ < δ(H)/2`, i.e. radius `< δ(H)/4`), with a safety margin. Infinite for level 0.
    fn criterion_radius2(&self, level: usize) -> f64;
    /// Squared radius below which a ball holds at most one lift of any point (`δ/2`), with
    /// a safety margin: a conflict region made of such balls lifts consistently.
    fn single_lift_radius2(&self) -> f64;
    /// The offsets of the copies of one point in the covering of `level` (one per sheet).
    fn covering_copies(&self, level: usize) -> Vec<Self::Elem>;
    /// False when no element can reverse orientation, known at compile time: the engine then
    /// drops the slot bookkeeping of [`OrbitSpace::normalize`]'s reversals (a torus's path).
    const MAY_REVERSE: bool = true;
    /// True when every element is a translation (a torus). Otherwise the engine moves to the
    /// quotient only once its criterion holds (`try_one_sheet`'s shortcut is the tori's).
    fn translations_only(&self) -> bool {
        true
    }
    /// Whether the element reverses orientation (a reflection or glide reflection; never for
    /// a torus).
    fn reverses_orientation(&self, g: Self::Elem) -> bool;
    /// Moves a cell's elements by a group element `h` of the space of `level` (`g_i ↦ h∘g_i`)
    /// into canonical form: cells that differ by such an element get equal elements. Returns
    /// whether `h` reverses orientation: the engine then swaps two vertices, so that the cell
    /// stays positively oriented in its own frame.
    fn normalize(&self, off: &mut [Self::Elem; N], level: usize) -> bool;
    /// A dummy point set whose Delaunay triangulation satisfies the switch criterion.
    fn dummy_points(&self) -> Vec<Self::Point>;
    /// Number of sheets of the covering of `level` (`covering_copies(level).len()`).
    fn sheets(&self, level: usize) -> usize;
    /// Index of the sheet of `level` holding a lifted copy with offset `o`.
    fn sheet_of(&self, o: Self::Elem, level: usize) -> usize;
    /// Appends to `out` every lifted copy `(i, o)` of `pts[i]` whose position is within
    /// `radius` of the lifted point `z` (generous: a copy slightly farther may be included).
    fn near(
        &self,
        z: Lifted<Self::Point, Self::Elem>,
        pts: &[Self::Point],
        radius: f64,
        out: &mut Vec<(u32, Self::Elem)>,
    );
    /// An upper bound on the length of a Delaunay edge: at level 0 for any non-empty point
    /// set, at a later level under that level's criterion.
    fn edge_bound(&self, level: usize) -> f64;
    /// The Cartesian position of a lifted point, rounded (a 2D point with a zero third
    /// coordinate), and a bound on its distance to the exact one, in spaces whose in-sphere
    /// and power tests are those of Euclidean balls at these positions and whose perturbed
    /// tests order every pencil of spheres: what lets a large hole's apex search look only
    /// near a sphere. `None` (the default) elsewhere.
    fn ball_position(&self, _: Lifted<Self::Point, Self::Elem>) -> Option<([f64; 3], f64)> {
        None
    }
    /// A key along a space-filling curve, for spatial sorting: the index along a Hilbert
    /// curve of `KEY_BITS` bits, whose leading `D·b` bits index the grid of `2^b` cells per
    /// axis over the domain (the jump-and-walk grid).
    fn spatial_key(&self, p: &Self::Point) -> u64;
    /// The width of [`OrbitSpace::spatial_key`], at most 63.
    const KEY_BITS: u32;
    /// True when an inserted point need not become a vertex (the sphere's points strictly
    /// inside the hull of the others): the engine then hides points as for weighted ones.
    const HIDES: bool = false;
    /// Symbolic points that every triangulation holds (as points `0..k`) so that even one
    /// point has a triangulation of level 0: the sphere's infinitesimal tetrahedron around
    /// the centre. An anchor is hidden, not removed, once the points enclose it. None for
    /// the flat spaces, whose level 0 triangulates every non-empty point set.
    fn anchors(&self) -> Vec<Self::Point> {
        Vec::new()
    }
    /// The cells of the level-0 triangulation of the anchors alone: (anchor, element) per
    /// vertex, in either orientation.
    fn anchor_cells(&self) -> Vec<[(u32, Self::Elem); N]> {
        Vec::new()
    }
}

/// A flat orbit space as the facade, the Voronoi layer and the writers see it: points
/// `[f64; D]` in the user's units outside, in the space's internal frame (a power-of-two
/// scaling, see [`Lattice`]) inside, each stored at a canonical representative in the
/// fundamental domain. A stored point may be in coordinates of the space's own (lattice
/// coordinates for the hexagonal screws): its position is always `lifted_position` of it
/// with the identity, and constructions (positions, differences, circumcenters) are
/// Cartesian in the internal frame.
pub trait FlatSpace<const D: usize, const N: usize>:
    OrbitSpace<N, Point = [f64; D]> + Clone
{
    /// The stored representative of a user point in the fundamental domain, and whether it
    /// moved; `None` when it lies too far away to be wrapped exactly.
    fn canonical_point(&self, x: &[f64; D]) -> Option<([f64; D], bool)>;
    /// An internal point in user units (exact).
    fn to_user(&self, x: [f64; D]) -> [f64; D];
    /// An internal length (`power` 1), area (2) or volume (3) in user units.
    fn measure_to_user(&self, x: f64, power: i32) -> f64;
    /// The Cartesian position of a lifted point, internal frame, rounded.
    fn lifted_position(&self, p: Lifted<[f64; D], Self::Elem>) -> [f64; D];
    /// The difference of two lifted points, internal frame, within a few units in the last
    /// place of their magnitudes (not through rounded positions).
    fn lifted_difference(
        &self,
        a: Lifted<[f64; D], Self::Elem>,
        b: Lifted<[f64; D], Self::Elem>,
    ) -> [f64; D];
    /// A vector in the frame of `g` seen from the frame of the identity: `A⁻¹·v` for
    /// `g: x ↦ A·x + t` (`v` itself for a translation).
    fn untwist(&self, g: Self::Elem, v: [f64; D]) -> [f64; D];
    /// The element `g` with `g·from = to` exactly, when `from` and `to` (stored points) are
    /// two representatives of one point of the space.
    fn relating(&self, from: [f64; D], to: [f64; D]) -> Option<Self::Elem>;
    /// The canonical frame of a face given by (vertex, element) pairs: the element `h`
    /// such that two faces that differ by a group element get equal pairs once each is
    /// moved by its frame (`h∘g` for every element `g`) and sorted.
    fn face_frame(&self, pairs: &[(u32, Self::Elem)]) -> Self::Elem;
    /// A face in canonical form modulo the group: moved into its [`Self::face_frame`],
    /// sorted.
    fn canonical_face(&self, pairs: &mut [(u32, Self::Elem)]) {
        let h = self.face_frame(pairs);
        for p in pairs.iter_mut() {
            p.1 = self.compose(h, p.1);
        }
        pairs.sort_unstable();
    }
    /// A weight (a squared length) of the user in the internal frame: exact, or `inf`/`0`
    /// where the doubles cannot hold it.
    fn weight_to_internal(&self, w: f64) -> f64;
    /// An internal weight in user units (exact).
    fn weight_to_user(&self, w: f64) -> f64 {
        self.measure_to_user(w, 2)
    }
    /// The space for weighted points whose weights spread over `spread` (largest − least,
    /// internal frame): coverings and dummy points safe for it. `None` when no covering
    /// is proven safe ([`FlatSpace::max_spread`] is the limit).
    fn for_spread(&self, spread: f64) -> Option<Self>;
    /// The largest spread [`FlatSpace::for_spread`] accepts (internal frame).
    fn max_spread(&self) -> f64;
    /// The volume (area in 2D) of the space, in user units.
    fn volume(&self) -> f64;
    /// Ok when the space's volume is a normal double in user units (see
    /// [`Lattice::check_volume_representable`]).
    fn check_volume_representable(&self) -> crate::error::Result<()>;
}

/// A point of the plane or of space as three coordinates (the third zero in the plane).
pub(crate) fn padded<const D: usize>(x: [f64; D]) -> [f64; 3] {
    std::array::from_fn(|c| if c < D { x[c] } else { 0.0 })
}

/// The canonical frame of a few (tag, element) pairs (at most 4: a cell or one of its faces):
/// among the translations by `g_i⁻¹`, which bring item `i` to the identity, the one that
/// gives the least sorted list of pairs. It is unique for a torsion-free group: no element
/// other than the identity permutes a finite set of elements.
pub(crate) fn least_frame<S: OrbitSpace<N>, const N: usize, T: Ord + Copy>(
    space: &S,
    items: &[(T, S::Elem)],
) -> S::Elem {
    const MAX: usize = 4;
    let len = items.len();
    assert!((1..=MAX).contains(&len), "a frame of 1 to {MAX} items");
    let mut best = [items[0]; MAX];
    let mut moved = [items[0]; MAX];
    let mut frame = None;
    for &(_, g) in items {
        let h = space.inverse(g);
        for (m, &(t, x)) in moved.iter_mut().zip(items) {
            *m = (t, space.compose(h, x));
        }
        moved[..len].sort_unstable();
        if frame.is_none() || moved[..len] < best[..len] {
            best = moved;
            frame = Some(h);
        }
    }
    frame.expect("at least one item")
}
