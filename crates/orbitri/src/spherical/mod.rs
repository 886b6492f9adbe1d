//! `SphericalDelaunay`: the Delaunay triangulation of points on the unit sphere S² (thesis
//! §4.3.1) on the generic engine ([`crate::space::Sphere`]), with the input bookkeeping
//! of the sphere: points given as unit vectors or longitude/latitude, duplicates, points
//! hidden inside the hull of the others, CGAL's `dimension()` for small and flat sets, and
//! the faces by input ids.
//!
//! Semantics, exactly for the doubles given: the faces are those of the convex hull of the
//! points that have the centre strictly on their inner side (for points on one sphere, the
//! spherical Delaunay triangulation; otherwise the regular triangulation on the sphere
//! that CGAL computes). Four points on one circle are separated by a symbolic perturbation
//! (later points of the lexicographic order pulled further towards the centre), so the
//! faces never depend on the insertion order. A point strictly inside the hull of the others
//! (possible only for points off the sphere by rounding) is *hidden*: kept, reported, and a
//! vertex again when a removal uncovers it.

mod ghost;
mod voronoi;

pub use voronoi::SphericalCell;

use std::collections::BTreeMap;

use rayon::prelude::*;
use std::ops::ControlFlow;

use crate::delaunay::{Engine, Inserted, Invalid, Item};
use crate::error::{Error, Result};
use crate::ids::{CellId, InputId, PointId};
use crate::predicates::spherical::{orient_origin, side_of_circle};
use crate::predicates::Sign;
use crate::sort::Brio;
use crate::space::{
    projective_representative, sphere_key, Antipode, OrbitSpace, ProjectivePlane, Sphere,
};

/// How far `|p|²` may be from 1 for a point given as on the unit sphere (doubles rarely
/// are exactly): about single precision, so that a wrong column or unnormalized vectors
/// are caught, while rounded unit vectors pass.
pub const NORM_TOLERANCE: f64 = 1.0 / (1u64 << 20) as f64;

/// `input_point` of a hidden input.
const HIDDEN: PointId = PointId(u32::MAX - 1);

/// What became of an inserted point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// A vertex of the triangulation.
    Vertex,
    /// It coincides with the point of this earlier input.
    Duplicate(InputId),
    /// Strictly inside the hull of the others: no vertex (see the module's semantics).
    Hidden,
}

/// The unit vector of a longitude and latitude in degrees: `(cos φ cos λ, cos φ sin λ,
/// sin φ)`. An error names a non-finite value or a latitude beyond ±90°.
pub fn lonlat_to_point(index: usize, lon: f64, lat: f64) -> Result<[f64; 3]> {
    for (axis, v) in [lon, lat].into_iter().enumerate() {
        if !v.is_finite() {
            return Err(Error::NonFiniteCoordinate {
                index,
                axis,
                value: v,
            });
        }
    }
    if lat.abs() > 90.0 {
        return Err(Error::InvalidOption {
            option: "latitude",
            value: format!("{lat} (point {index})"),
            limit: "must lie within [-90, 90] degrees".into(),
        });
    }
    // antipodes exactly: `(λ + 180, −φ)` gives the negated vector (the longitude reduced
    // to [0, 180) and its half turn applied as a sign; the latitude's sign applied after)
    let r = lon.rem_euclid(360.0);
    let (r, turn) = if r >= 180.0 {
        (r - 180.0, -1.0)
    } else {
        (r, 1.0)
    };
    let (sl, cl) = match r {
        0.0 => (0.0, 1.0),
        90.0 => (1.0, 0.0),
        _ => r.to_radians().sin_cos(),
    };
    let (sf, cf) = match lat.abs() {
        90.0 => (1.0, 0.0),
        0.0 => (0.0, 1.0),
        a => a.to_radians().sin_cos(),
    };
    let sf = if lat < 0.0 { -sf } else { sf };
    let (sl, cl) = (turn * sl, turn * cl);
    Ok([cf * cl, cf * sl, sf])
}

/// The longitude and latitude in degrees of a point of the sphere (longitude in
/// `(-180, 180]`).
pub fn point_to_lonlat(p: &[f64; 3]) -> [f64; 2] {
    let h = p[0].hypot(p[1]);
    [p[1].atan2(p[0]).to_degrees(), p[2].atan2(h).to_degrees()]
}

/// Each point moved radially onto the unit sphere (rounded: within a few units in the last
/// place); an error names a non-finite or zero vector.
pub fn normalized(points: &[[f64; 3]]) -> Result<Vec<[f64; 3]>> {
    points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            check_finite(i, p)?;
            // (scaled first: no overflow or underflow in the norm)
            let m = p.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            if m == 0.0 {
                return Err(Error::OffSphere {
                    index: i,
                    norm: 0.0,
                });
            }
            let s = p.map(|x| x / m);
            let n2 = s.iter().map(|x| x * x).sum::<f64>().sqrt();
            Ok(s.map(|x| x / n2))
        })
        .collect()
}

/// A space of this facade: the sphere, or the projective plane (the sphere modulo ±1).
pub trait SphericalSpace:
    OrbitSpace<3, Point = [f64; 3]> + Copy + Default + std::fmt::Debug + 'static
{
    /// The space with the anchor set `k` (see [`Sphere::with_anchors`]).
    fn with_anchors(k: u64) -> Self;
    /// True when `p` lies exactly along an anchor's direction.
    fn meets_anchor(&self, p: &[f64; 3]) -> bool;
    /// The stored representative of a point of the sphere.
    fn representative(p: [f64; 3]) -> [f64; 3];
    /// The position of a lifted point on the sphere.
    fn position(p: [f64; 3], g: Self::Elem) -> [f64; 3];
    /// Whether a group element takes points to their antipodes (never on the sphere).
    fn is_antipode(g: Self::Elem) -> bool;
    /// The area of the space: 4π, 2π.
    const AREA: f64;
    /// True when a point and its antipode are one point (the projective plane).
    const ANTIPODAL: bool;
    /// The space's name in outputs (`--space` of the command).
    const NAME: &'static str;
}

impl SphericalSpace for Sphere {
    fn with_anchors(k: u64) -> Self {
        Sphere::with_anchors(k)
    }
    fn meets_anchor(&self, p: &[f64; 3]) -> bool {
        Sphere::meets_anchor(self, p)
    }
    fn representative(p: [f64; 3]) -> [f64; 3] {
        p
    }
    fn position(p: [f64; 3], _: ()) -> [f64; 3] {
        p
    }
    fn is_antipode(_: ()) -> bool {
        false
    }
    const AREA: f64 = 4.0 * std::f64::consts::PI;
    const ANTIPODAL: bool = false;
    const NAME: &'static str = "sphere";
}

impl SphericalSpace for ProjectivePlane {
    fn with_anchors(k: u64) -> Self {
        ProjectivePlane::with_anchors(k)
    }
    fn meets_anchor(&self, p: &[f64; 3]) -> bool {
        ProjectivePlane::meets_anchor(self, p)
    }
    fn representative(p: [f64; 3]) -> [f64; 3] {
        projective_representative(&p)
    }
    fn position(p: [f64; 3], g: Antipode) -> [f64; 3] {
        if g.0 {
            p.map(|x| -x)
        } else {
            p
        }
    }
    fn is_antipode(g: Antipode) -> bool {
        g.0
    }
    const AREA: f64 = 2.0 * std::f64::consts::PI;
    const ANTIPODAL: bool = true;
    const NAME: &'static str = "projective-plane";
}

/// The Delaunay triangulation of points on the unit sphere.
pub type SphericalDelaunay = SphericalTriangulation<Sphere>;

/// The triangulation of the real projective plane RP² = S²/{±1}: points `p` and `−p` are
/// one point (a duplicate), faces are listed with the sign of each vertex
/// ([`SphericalTriangulation::face_signs`]).
pub type ProjectiveDelaunay = SphericalTriangulation<ProjectivePlane>;

/// The space with the first anchor set that none of `points` meets.
fn anchors_for<S: SphericalSpace>(points: &[[f64; 3]]) -> S {
    (0..)
        .map(S::with_anchors)
        .find(|s| !points.par_iter().any(|p| s.meets_anchor(p)))
        .expect("each point meets at most one set")
}

fn check_finite(index: usize, p: &[f64; 3]) -> Result<()> {
    match p.iter().position(|x| !x.is_finite()) {
        Some(axis) => Err(Error::NonFiniteCoordinate {
            index,
            axis,
            value: p[axis],
        }),
        None => Ok(()),
    }
}

/// Ok for a point within [`NORM_TOLERANCE`] of the unit sphere, else the error naming it.
fn check_point(index: usize, p: &[f64; 3]) -> Result<()> {
    check_finite(index, p)?;
    let n2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    if (n2 - 1.0).abs() > NORM_TOLERANCE {
        return Err(Error::OffSphere {
            index,
            norm: n2.sqrt(),
        });
    }
    Ok(())
}

/// The faces of a spherical triangulation ([`SphericalTriangulation::face_table`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FaceTable {
    /// The (solid) faces: input ids, counter-clockwise seen from outside once lifted by
    /// the signs.
    pub faces: Vec<[InputId; 3]>,
    /// Per vertex of a face, whether it is the antipode of its stored point.
    pub signs: Vec<[bool; 3]>,
    /// The ghost faces (points in a closed hemisphere), counter-clockwise seen from
    /// outside the hull; they are numbered after the faces.
    pub ghosts: Vec<[InputId; 3]>,
    /// For every face, then every ghost face, the face across each edge (opposite corner
    /// `k`) in that numbering.
    pub neighbors: Vec<[usize; 3]>,
}

/// The Delaunay triangulation of points on the unit sphere ([`SphericalDelaunay`]), or of
/// the real projective plane ([`ProjectiveDelaunay`]): one facade for both.
#[derive(Debug)]
pub struct SphericalTriangulation<S: SphericalSpace> {
    engine: Engine<S, 3>,
    /// Input → its point in the engine (`NONE` once removed, [`HIDDEN`]).
    input_point: Vec<PointId>,
    /// Engine point → the input id of its first occurrence (`NONE` for the anchors).
    point_input: Vec<InputId>,
    /// Inputs that share a point with an earlier one.
    duplicates: usize,
    /// The hidden inputs and their points.
    hidden: BTreeMap<InputId, [f64; 3]>,
}

impl<S: SphericalSpace> Default for SphericalTriangulation<S> {
    fn default() -> Self {
        Self::new()
    }
}

impl<S: SphericalSpace> SphericalTriangulation<S> {
    /// An empty triangulation.
    pub fn new() -> Self {
        Self::with_space(S::default())
    }

    /// An empty triangulation with the anchors of `space`.
    fn with_space(space: S) -> Self {
        let engine = Engine::new(space);
        let anchors = engine.points().len();
        SphericalTriangulation {
            engine,
            input_point: Vec::new(),
            point_input: vec![InputId::NONE; anchors],
            duplicates: 0,
            hidden: BTreeMap::new(),
        }
    }

    /// The triangulation of `points` (unit vectors, each within [`NORM_TOLERANCE`] of the
    /// sphere; see [`normalized`] for others), inserted in BRIO + Hilbert order.
    ///
    /// ```
    /// use orbitri::spherical::SphericalDelaunay;
    /// let s = 0.5f64.sqrt();
    /// let octahedron = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
    ///                   [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [s, s, 0.0]];
    /// let tri = SphericalDelaunay::build(&octahedron).unwrap();
    /// assert_eq!(tri.dimension(), 2);
    /// assert_eq!(tri.faces().len(), 2 * 7 - 4);
    /// assert!(tri.is_valid().is_ok());
    /// ```
    pub fn build(points: &[[f64; 3]]) -> Result<Self> {
        Self::build_with(points, |_| ControlFlow::Continue(()))
    }

    /// [`Self::build`] of longitudes and latitudes in degrees ([`lonlat_to_point`]).
    pub fn build_lonlat(lonlat: &[[f64; 2]]) -> Result<Self> {
        let pts = lonlat
            .iter()
            .enumerate()
            .map(|(i, l)| lonlat_to_point(i, l[0], l[1]))
            .collect::<Result<Vec<_>>>()?;
        Self::build(&pts)
    }

    /// [`Self::build`] with a progress callback, called with the number of points inserted
    /// so far (before the first, every 4096 points, at the end); [`ControlFlow::Break`]
    /// stops the construction with [`Error::Interrupted`].
    pub fn build_with(
        points: &[[f64; 3]],
        progress: impl FnMut(usize) -> ControlFlow<()>,
    ) -> Result<Self> {
        Self::build_with_threads(points, None, progress)
    }

    /// [`Self::build_with`] inserting in parallel on `threads` threads (the
    /// triangulation is stored the same, slot for slot, whatever their number; so are the
    /// later batches of [`Self::insert_all`]); `None`: one by one.
    pub fn build_with_threads(
        points: &[[f64; 3]],
        threads: Option<usize>,
        mut progress: impl FnMut(usize) -> ControlFlow<()>,
    ) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::EmptyInput);
        }
        // (the checks, the anchors' choice and the keys in parallel: a tenth of the build)
        if let Some(e) = points
            .par_iter()
            .enumerate()
            .find_map_first(|(i, p)| check_point(i, p).err())
        {
            return Err(e);
        }
        let mut tri = Self::with_space(anchors_for::<S>(points));
        tri.engine.set_threads(threads);
        tri.engine.reserve(points.len() + 4, 2 * points.len() + 8);
        tri.input_point = vec![PointId::NONE; points.len()];
        tri.insert_rounds(points, 0x0b17, 0, &mut progress)?;
        if progress(points.len()).is_break() {
            return Err(Error::Interrupted);
        }
        Ok(tri)
    }

    /// Inserts one more point (its input id is the number of points given so far).
    pub fn insert(&mut self, p: [f64; 3]) -> Result<Status> {
        check_point(self.input_point.len(), &p)?;
        if self.engine.space().meets_anchor(&p) {
            self.reanchor(&[p]);
        }
        let i = InputId::new(self.input_point.len());
        self.input_point.push(PointId::NONE);
        Ok(self.insert_checked(i, p))
    }

    /// Inserts a batch of points, all or nothing: every row is checked first (an error
    /// names it by its row and changes nothing), then they go in by BRIO + Hilbert order.
    /// Input ids follow the rows' order. Returns what became of each.
    pub fn insert_all(&mut self, points: &[[f64; 3]]) -> Result<Vec<Status>> {
        let first = self.input_point.len();
        for (k, p) in points.iter().enumerate() {
            check_point(first + k, p)?;
        }
        if points.iter().any(|p| self.engine.space().meets_anchor(p)) {
            self.reanchor(points);
        }
        self.input_point.resize(first + points.len(), PointId::NONE);
        let unstoppable = &mut |_| ControlFlow::Continue(());
        self.insert_rounds(points, 0x0b17 ^ first as u64, first, unstoppable)
            .expect("no progress callback to stop it");
        // (statuses as they are now: a later point may have hidden an earlier one)
        Ok((first..first + points.len())
            .map(|i| self.status(InputId::new(i)).expect("just inserted"))
            .collect())
    }

    /// Triangulates the points again with anchors that neither they nor `more` meet (a
    /// point along an anchor's direction: rare, but exactly possible). Input ids stay.
    fn reanchor(&mut self, more: &[[f64; 3]]) {
        let live: Vec<(InputId, [f64; 3])> = (0..self.input_point.len())
            .map(InputId::new)
            .filter_map(|i| self.point(i).map(|p| (i, p)))
            .collect();
        let all: Vec<[f64; 3]> = live
            .iter()
            .map(|x| x.1)
            .chain(more.iter().copied())
            .collect();
        let space = anchors_for::<S>(&all);
        let n = self.input_point.len();
        let threads = self.engine.threads();
        *self = Self::with_space(space);
        self.engine.set_threads(threads);
        self.input_point = vec![PointId::NONE; n];
        for (i, p) in live {
            self.insert_checked(i, p);
        }
    }

    /// Inserts input `i` (its slot in `input_point` exists) at the checked point `p`.
    fn insert_checked(&mut self, i: InputId, p: [f64; 3]) -> Status {
        let p = S::representative(p);
        self.insert_stored(i, p, sphere_key(&p))
    }

    /// [`Self::insert_checked`] of a stored representative and its spatial key.
    fn insert_stored(&mut self, i: InputId, p: [f64; 3], key: u64) -> Status {
        let r = self.engine.insert_keyed(p, 0.0, key);
        self.record(i, p, r)
    }

    /// Inserts `points` (input ids from `first`, their slots in `input_point` made) in
    /// BRIO + Hilbert order, a round at a time, each sorted while the one before it is
    /// inserted one at a time, or with threads on them before it
    /// ([`crate::sort::in_rounds`]); `Err` if `progress` stopped it.
    fn insert_rounds(
        &mut self,
        points: &[[f64; 3]],
        seed: u64,
        first: usize,
        progress: &mut impl FnMut(usize) -> ControlFlow<()>,
    ) -> Result<()> {
        let mut done = 0;
        let stored = |i: u32| S::representative(points[i as usize]);
        let ahead = self.engine.threads().is_none();
        // (with threads, eightfold rounds, each one wave: a tenth off two threads on the
        // sphere)
        let order = if self.engine.eightfold_rounds() {
            Brio::new(seed, 3)
        } else {
            Brio::doubling(seed)
        };
        let outcome = crate::sort::in_rounds(
            points.len(),
            (Some(order), ahead),
            |i| sphere_key(&stored(i)),
            // the stored representatives, gathered with their keys (with threads, on them)
            |round| -> Vec<Item<[f64; 3]>> {
                let item =
                    |(key, i): (u64, u32)| ((first + i as usize) as u32, stored(i), 0.0, key);
                if ahead {
                    round.into_iter().map(item).collect()
                } else {
                    round.into_par_iter().map(item).collect()
                }
            },
            |items| {
                self.insert_items(&items, &mut |k| progress(done + k))?;
                done += items.len();
                Ok(())
            },
        );
        self.engine.end_batch();
        outcome
    }

    /// Inserts `items` (tagged with their input ids) by the engine's parallel insertion,
    /// and records each in the engine's order; `Err` if `progress` stopped it.
    fn insert_items(
        &mut self,
        items: &[Item<[f64; 3]>],
        progress: &mut impl FnMut(usize) -> ControlFlow<()>,
    ) -> Result<()> {
        let (log, flow) = self.engine.insert_parallel(items, &mut *progress);
        if flow.is_break() {
            return Err(Error::Interrupted);
        }
        let tables = (&mut self.point_input, &mut self.input_point[..]);
        if log.record_if_all_new(items, tables, |_| true) {
            return Ok(());
        }
        // (the input ids come in a random order: their slots are loaded ahead)
        let ahead = |e: usize| {
            log.events
                .get(e + 16)
                .map(|x| items[x.0 as usize].0 as usize)
        };
        for (e, (k, r, hid)) in log.iter().enumerate() {
            if let Some(slot) = ahead(e).and_then(|i| self.input_point.get(i)) {
                crate::tds::prefetch(slot);
            }
            self.engine.hidden_log.extend_from_slice(hid);
            let (i, p, _, _) = items[k as usize];
            self.record(InputId(i), p, r);
        }
        Ok(())
    }

    /// Records what became of input `i` at the stored representative `p`.
    fn record(&mut self, i: InputId, p: [f64; 3], r: Inserted) -> Status {
        match r {
            Inserted::New(q) => {
                // the new point came last, then the points it hid left, the last point
                // taking each one's id: followed here in the same order
                self.input_point[i.index()] = PointId::new(self.point_input.len());
                self.point_input.push(i);
                self.absorb_hidden();
                debug_assert_eq!(self.input_point[i.index()], q);
                Status::Vertex
            }
            Inserted::Duplicate(q) => {
                self.input_point[i.index()] = q;
                self.duplicates += 1;
                let first = &mut self.point_input[q.index()];
                *first = (*first).min(i);
                Status::Duplicate(*first)
            }
            Inserted::Hidden => {
                self.input_point[i.index()] = HIDDEN;
                self.hidden.insert(i, p);
                Status::Hidden
            }
        }
    }

    /// The inputs of engine point `p`.
    fn inputs_of(&self, p: PointId) -> Vec<InputId> {
        if self.duplicates == 0 {
            vec![self.point_input[p.index()]]
        } else {
            (0..self.input_point.len())
                .filter(|&j| self.input_point[j] == p)
                .map(InputId::new)
                .collect()
        }
    }

    /// The points the engine's last insertion hid: their inputs become hidden, and the
    /// point ids follow the engine's renumbering (the last point takes each one's id).
    fn absorb_hidden(&mut self) {
        for h in std::mem::take(&mut self.engine.hidden_log) {
            let inputs = self.inputs_of(h.id);
            self.duplicates -= inputs.len() - 1;
            for j in inputs {
                self.input_point[j.index()] = HIDDEN;
                self.hidden.insert(j, h.point);
            }
            self.forget_point(h.id);
        }
    }

    /// After the engine dropped point `p` and moved its last point into `p`'s slot.
    fn forget_point(&mut self, p: PointId) {
        let last = PointId::new(self.point_input.len() - 1);
        let moved = self.inputs_of(last);
        self.point_input.swap_remove(p.index());
        if p != last {
            for j in moved {
                self.input_point[j.index()] = p;
            }
        }
    }

    /// Removes input `i`; the others keep their ids. Hidden points that the removal
    /// uncovers become vertices. An unknown or removed id is an error that changes nothing.
    pub fn remove(&mut self, i: InputId) -> Result<()> {
        let p = match self.input_point.get(i.index()) {
            None => {
                return Err(Error::UnknownInput {
                    id: i.0 as u64,
                    why: format!(
                        "out of range ({} input points were given)",
                        self.input_point.len()
                    ),
                })
            }
            Some(&p) if p == PointId::NONE => {
                return Err(Error::UnknownInput {
                    id: i.0 as u64,
                    why: "was removed".into(),
                })
            }
            Some(&p) => p,
        };
        self.input_point[i.index()] = PointId::NONE;
        if p == HIDDEN {
            self.hidden.remove(&i);
            return Ok(());
        }
        if self.duplicates > 0 {
            let others = self.inputs_of(p);
            if let Some(&next) = others.first() {
                self.duplicates -= 1;
                self.point_input[p.index()] = next;
                return Ok(());
            }
        }
        self.engine.remove_point(p);
        self.forget_point(p);
        let hidden: Vec<(InputId, [f64; 3])> = self.hidden.iter().map(|(&j, &x)| (j, x)).collect();
        for (j, x) in hidden {
            if self.engine.would_appear(x, 0.0) {
                self.hidden.remove(&j);
                self.insert_checked(j, x);
            }
        }
        Ok(())
    }

    /// Removes the inputs `ids`, in that order, all or nothing: an unknown, removed or
    /// repeated id is an error naming it, and nothing changes.
    pub fn remove_all(&mut self, ids: &[InputId]) -> Result<()> {
        let mut seen = std::collections::HashSet::with_capacity(ids.len());
        for &i in ids {
            self.live(i)?;
            if !seen.insert(i) {
                return Err(Error::UnknownInput {
                    id: i.0 as u64,
                    why: "is given twice".into(),
                });
            }
        }
        for &i in ids {
            self.remove(i)?;
        }
        Ok(())
    }

    /// Number of input points given (removed ones included: ids are never reused).
    pub fn number_of_input_points(&self) -> usize {
        self.input_point.len()
    }

    /// Number of vertices: distinct points that are not hidden.
    pub fn number_of_vertices(&self) -> usize {
        self.engine.number_of_points()
    }

    /// Inputs that coincide with an earlier one.
    pub fn duplicates(&self) -> usize {
        self.duplicates
    }

    /// The hidden inputs, sorted.
    pub fn hidden(&self) -> Vec<InputId> {
        self.hidden.keys().copied().collect()
    }

    /// What became of input `i`, `None` for an id never given or removed.
    pub fn status(&self, i: InputId) -> Option<Status> {
        match *self.input_point.get(i.index())? {
            PointId::NONE => None,
            HIDDEN => Some(Status::Hidden),
            p if self.point_input[p.index()] == i => Some(Status::Vertex),
            p => Some(Status::Duplicate(self.point_input[p.index()])),
        }
    }

    /// The coordinates of input `i` as stored (its first occurrence's for a duplicate).
    pub fn point(&self, i: InputId) -> Option<[f64; 3]> {
        match *self.input_point.get(i.index())? {
            PointId::NONE => None,
            HIDDEN => self.hidden.get(&i).copied(),
            p => Some(self.engine.points()[p.index()]),
        }
    }

    /// The input ids of the vertices, in the engine's order.
    pub fn vertices(&self) -> Vec<InputId> {
        self.point_input[self.anchors()..].to_vec()
    }

    fn anchors(&self) -> usize {
        self.engine.points().len() - self.engine.number_of_points()
    }

    /// The dimension of the triangulation as CGAL's `Triangulation_on_sphere_2` gives it:
    /// −2 without vertices, −1 with one, 0 with two, 1 when all vertices lie on one plane
    /// (one circle of the sphere; in RP², one projective line: a great circle), 2
    /// otherwise.
    pub fn dimension(&self) -> i32 {
        let reps = &self.engine.points()[self.anchors()..];
        match reps.len() {
            0 => return -2,
            1 => return -1,
            2 => return 0,
            _ => {}
        }
        let pts: Vec<[f64; 3]> = reps
            .iter()
            .flat_map(|&p| {
                self.engine
                    .space()
                    .covering_copies(0)
                    .into_iter()
                    .map(move |g| S::position(p, g))
            })
            .collect();
        // three distinct points near the sphere are never on one line
        let (a, b) = (&pts[0], &pts[1]);
        let Some(c) = pts[2..].iter().find(|c| !collinear(a, b, c)) else {
            return 1;
        };
        if pts.iter().any(|q| side_of_circle(a, b, c, q) != Sign::Zero) {
            2
        } else {
            1
        }
    }

    /// True when the points enclose the centre strictly (no anchor is a vertex): the
    /// faces then cover the sphere. Otherwise the points lie in a closed hemisphere, and
    /// the faces cover the part of the sphere where the hull has the centre inside.
    pub fn covers_sphere(&self) -> bool {
        (0..self.anchors()).all(|a| self.engine.is_hidden_anchor(PointId::new(a)))
    }

    /// True for an engine cell with no anchor.
    fn is_face(&self, c: CellId) -> bool {
        let anchors = self.anchors();
        let e = &self.engine;
        e.cell(c)
            .v
            .iter()
            .all(|&v| e.point_of(v).index() >= anchors)
    }

    /// The faces with their signs, the ghost faces and the neighbours, from one pass over
    /// the cells (what [`Self::faces`], [`Self::face_signs`], [`Self::ghost_faces`] and
    /// [`Self::neighbors`] give one by one).
    pub fn face_table(&self) -> FaceTable {
        let e = &self.engine;
        let (reps, orbit) = self.face_orbits();
        let ghosts = self.ghosts();
        let input = |p: PointId| self.point_input[p.index()];
        let solid = reps.len();
        let cells = || reps.iter().map(|&c| e.cell(c));
        let mut neighbors: Vec<[usize; 3]> = cells()
            .map(|cell| {
                std::array::from_fn(|k| match orbit[cell.n[k].index()] {
                    usize::MAX => {
                        let edge = (cell.v[(k + 2) % 3], cell.v[(k + 1) % 3]);
                        solid + ghosts.by_edge[&(e.point_of(edge.0), e.point_of(edge.1))]
                    }
                    f => f,
                })
            })
            .collect();
        neighbors.extend((0..ghosts.faces.len()).map(|f| {
            std::array::from_fn(|k| match ghosts.across(f, k) {
                Ok(g) => solid + g,
                Err(c) => orbit[c.index()],
            })
        }));
        FaceTable {
            faces: cells()
                .map(|cell| cell.v.map(|v| input(e.point_of(v))))
                .collect(),
            signs: cells().map(|cell| cell.off.map(S::is_antipode)).collect(),
            ghosts: ghosts.faces.iter().map(|f| f.map(input)).collect(),
            neighbors,
        }
    }

    /// The faces (CGAL's solid faces) by input ids of their vertices, counter-clockwise
    /// seen from outside (in RP², the lifted face `signs·points`: [`Self::face_signs`]);
    /// none when [`Self::dimension`] is below 2. One per face of the space, also while the
    /// projective plane is stored in its covering sphere.
    pub fn faces(&self) -> Vec<[InputId; 3]> {
        self.face_table().faces
    }

    /// Per face of [`Self::faces`], whether each vertex is the antipode of its stored
    /// point (always false on the sphere). At most one per face is.
    pub fn face_signs(&self) -> Vec<[bool; 3]> {
        self.face_table().signs
    }

    /// CGAL's ghost faces: for points in a closed hemisphere ([`Self::covers_sphere`]
    /// false, dimension 2), the faces of the hull that do not hold the centre strictly
    /// inside; their empty caps are a hemisphere or more. With [`Self::faces`] they cover
    /// the sphere. Input ids, counter-clockwise seen from outside the hull; ties (four
    /// rim points on one plane) broken as for the faces.
    ///
    /// ```
    /// use orbitri::spherical::SphericalDelaunay;
    /// // the equator's four axis points and the north pole: the equator's square is
    /// // flat through the centre, two ghost faces
    /// let pts = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let tri = SphericalDelaunay::build(&pts).unwrap();
    /// assert_eq!((tri.faces().len(), tri.ghost_faces().len()), (4, 2));
    /// ```
    pub fn ghost_faces(&self) -> Vec<[InputId; 3]> {
        self.face_table().ghosts
    }

    /// The faces of the space (one stored cell per orbit, the copy in the quotient's
    /// canonical form) and, per stored cell, the index of its orbit (`usize::MAX` for a
    /// cell with an anchor). Empty below dimension 2.
    fn face_orbits(&self) -> (Vec<CellId>, Vec<usize>) {
        let e = &self.engine;
        let mut orbit = vec![usize::MAX; e.cell_slots()];
        let mut reps = Vec::new();
        if self.dimension() < 2 {
            return (reps, orbit);
        }
        if e.sheets() == 1 {
            // stored as the space itself: every face its own orbit
            for c in e.cell_ids().filter(|&c| self.is_face(c)) {
                orbit[c.index()] = reps.len();
                reps.push(c);
            }
            return (reps, orbit);
        }
        let last = e.space().levels() - 1;
        let mut index: std::collections::HashMap<[(PointId, S::Elem); 3], usize> =
            std::collections::HashMap::new();
        for c in e.cell_ids().filter(|&c| self.is_face(c)) {
            let cell = e.cell(c);
            let mut off = cell.off;
            // a covering's copy that is already canonical represents its orbit
            let canonical = !e.space().normalize(&mut off, last) && off == cell.off;
            let mut key: [(PointId, S::Elem); 3] =
                std::array::from_fn(|k| (e.point_of(cell.v[k]), off[k]));
            key.sort_unstable();
            let k = *index.entry(key).or_insert_with(|| {
                reps.push(c);
                reps.len() - 1
            });
            if canonical {
                reps[k] = c;
            }
            orbit[c.index()] = k;
        }
        (reps, orbit)
    }

    /// For each face of [`Self::faces`] and then each of [`Self::ghost_faces`], the face
    /// across each edge (edge `k` is opposite vertex `k`), numbered the same way: an index
    /// from `faces().len()` on is a ghost face.
    pub fn neighbors(&self) -> Vec<[usize; 3]> {
        self.face_table().neighbors
    }

    /// The Delaunay neighbours of input `i` (vertices joined to it by an edge of a face),
    /// sorted; empty for a hidden input.
    pub fn vertex_neighbors(&self, i: InputId) -> Result<Vec<InputId>> {
        let p = self.live(i)?;
        if p == HIDDEN {
            return Ok(Vec::new());
        }
        let e = &self.engine;
        let mut out: Vec<InputId> = e
            .neighbours(e.vertex_of_point(p))
            .into_iter()
            .map(|(v, _)| self.point_input[e.point_of(v).index()])
            .filter(|&j| j != InputId::NONE)
            .collect();
        out.sort_unstable();
        out.dedup();
        Ok(out)
    }

    /// The engine point of a live input, or the error naming it.
    fn live(&self, i: InputId) -> Result<PointId> {
        match self.input_point.get(i.index()) {
            Some(&p) if p != PointId::NONE => Ok(p),
            _ => Err(Error::UnknownInput {
                id: i.0 as u64,
                why: "was never given or was removed".into(),
            }),
        }
    }

    /// The face whose cone from the centre holds the direction `p` (any non-zero finite
    /// vector), `None` outside the faces (a hemisphere set).
    pub fn locate(&self, p: [f64; 3]) -> Result<Option<[InputId; 3]>> {
        check_finite(0, &p)?;
        if p == [0.0; 3] {
            return Err(Error::OffSphere {
                index: 0,
                norm: 0.0,
            });
        }
        let e = &self.engine;
        let (c, _) = e.locate(S::representative(p));
        Ok(self
            .is_face(c)
            .then(|| e.cell(c).v.map(|v| self.point_input[e.point_of(v).index()])))
    }

    /// Checks the engine's triangulation (orientation, local Delaunay, Euler
    /// characteristic 2) and that every face holds the centre strictly inside.
    pub fn is_valid(&self) -> std::result::Result<(), Invalid> {
        self.engine.is_valid()?;
        let e = &self.engine;
        for c in e.cell_ids().filter(|&c| self.is_face(c)) {
            let [a, b, d] = e.lifted_cell(c).map(|(p, g)| S::position(p, g));
            if orient_origin(&a, &b, &d) != Sign::Positive {
                return Err(Invalid(format!(
                    "face {c} does not face away from the centre"
                )));
            }
        }
        Ok(())
    }

    /// The engine (for the Voronoi layer and tests).
    pub fn engine(&self) -> &Engine<S, 3> {
        &self.engine
    }
}

/// True when three points lie on one line (exactly): then no plane passes through them,
/// and every point, among them four affinely independent ones, is on "their plane".
fn collinear(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> bool {
    [[0.0; 3], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 4.0]]
        .iter()
        .all(|q| side_of_circle(a, b, c, q) == Sign::Zero)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sort::SplitMix;

    #[test]
    fn anchors_are_chosen_away_from_the_points() {
        // points exactly along two directions of the first set, coordinates within the
        // unit bound of the sphere's static filters (the facade's norm check would refuse
        // them, so the engine takes them directly)
        let t = Sphere::default().anchor_directions();
        let mut pts = vec![
            t[0].map(|x| x * 0.5f64.powi(21)),
            t[3].map(|x| -x * 0.5f64.powi(23)),
        ];
        let mut r = SplitMix::new(8);
        for _ in 0..200 {
            pts.push(r.on_sphere());
        }
        let space = anchors_for::<Sphere>(&pts);
        assert_ne!(space.anchor_set(), 0);
        assert!(pts.iter().all(|p| !space.meets_anchor(p)));
        let mut e = Engine::new(space);
        for p in &pts {
            e.insert(*p);
        }
        e.is_valid().unwrap();
        // (the two short points lie inside the hull of the unit ones: hidden)
        assert_eq!(e.number_of_points() + e.hidden_log.len(), 202);
        assert!(!Sphere::default().meets_anchor(&pts[5]));
    }
}
