//! The incremental Delaunay engine, written once for every orbit space and dimension
//! (`N` = vertices per cell). It stores a triangulation of one level of the space's covering
//! ladder: a covering space (every point present once per sheet) until the criterion of the
//! next level holds, then the next level, down to the 1-sheeted quotient (thesis Algorithm
//! 2.3.1 with one covering; Bogdanov–Teillaud–Vegter's 8 → 4 → 2 → 1 with several). Cells
//! store each vertex's offset in units of the original lattice, so one insertion code path
//! serves every level.

mod ball_index;
mod covering;
mod flip;
mod insert;
mod locator;
mod parallel;
mod remove;
mod ridges;
mod validate;
mod wrap;

use rustc_hash::FxHashSet;

use crate::ids::{CellId, PointId, VertexId};
use crate::predicates::Sign;
use crate::sort::SplitMix;
use crate::space::{Lifted, OrbitSpace};
use crate::tds::{Cell, Tds};

pub use parallel::{Item, Log};
pub use remove::{Moved, Removal};
pub use validate::Invalid;

/// A lifted point of the space `S` (cells of `N` vertices).
pub type LiftedOf<S, const N: usize> =
    Lifted<<S as OrbitSpace<N>>::Point, <S as OrbitSpace<N>>::Elem>;
/// The lifted vertices of one cell.
pub type LiftedCell<S, const N: usize> = [LiftedOf<S, N>; N];
/// A vertex id with a lifted position.
pub type Candidate<S, const N: usize> = (VertexId, LiftedOf<S, N>);

/// The cells of a star kept in a list while fewer (see [`Engine::star`]).
const STAR_SCANNED: usize = 256;

/// Reusable buffers of one insertion or removal (no allocation per point).
#[derive(Clone, Debug)]
struct Scratch<O> {
    /// Conflict cells with the query's offset in each cell's frame.
    conflict: Vec<(CellId, O)>,
    /// Boundary facets: (index into `conflict`, facet).
    boundary: Vec<(u32, u8)>,
    /// New cells, parallel to `boundary` (2D flips: the cells whose edge opposite the new
    /// vertex is still to test).
    created: Vec<CellId>,
    /// Weighted: the vertices an insertion hid (those of conflict cells on no boundary
    /// facet), accumulated over the copies of a point.
    hidden: Vec<VertexId>,
}

// (not derived: that would ask the group elements for a `Default`)
impl<O> Default for Scratch<O> {
    fn default() -> Self {
        Scratch {
            conflict: Vec::new(),
            boundary: Vec::new(),
            created: Vec::new(),
            hidden: Vec::new(),
        }
    }
}

/// 2D working memory of an insertion, next to [`Scratch`] (kept apart: moving a larger
/// scratch costs a copy by call).
#[derive(Clone, Debug, Default)]
struct Around {
    /// Each boundary edge's ends in the order of a walk around the conflict region, and
    /// the edge's slot in the outside cell; parallel to the scratch's `boundary`, which is
    /// then in that order.
    rim: Vec<(VertexId, VertexId, u8)>,
    /// The depth-first search's stack: (index into `conflict`, next edge, step to the edge
    /// after it, edges left).
    stack: Vec<insert::Frame>,
}

/// The result of inserting one point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Inserted {
    /// A new point (vertex of the quotient) with this id.
    New(PointId),
    /// The point coincides with the existing point of this id (and has its weight).
    Duplicate(PointId),
    /// The weighted point is hidden: its power cell is empty, it has no vertex.
    Hidden,
}

/// A point that an insertion hid (weighted triangulations): it left the triangulation, and
/// the last point took its id, as in [`Engine::remove_point`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HiddenPoint<P> {
    /// Its id when it was hidden.
    pub id: PointId,
    pub point: P,
    pub weight: f64,
}

/// How removals go at the space's lift level (see `Engine::remove_first_points`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lift {
    /// Its criterion is known to hold, so that the covering is a triangulation for the
    /// points and every superset: each removal keeps it.
    Criterion,
    /// Without it: the points below `stays` leave, each removal checked to keep the
    /// covering simplicial, and the others must reach the quotient.
    Checked { stays: usize },
    /// A removal showed that the points that stay cannot reach the quotient.
    Lost,
}

/// A Delaunay triangulation of an orbit space.
#[derive(Clone, Debug)]
pub struct Engine<S: OrbitSpace<N>, const N: usize> {
    pub(crate) space: S,
    /// The distinct points (dummy points, while present, at the end).
    pub(crate) points: Vec<S::Point>,
    /// A regular (weighted Delaunay) triangulation: the power test replaces the in-sphere
    /// test, and points can be hidden.
    pub(crate) weighted: bool,
    /// Weighted: the weight of each point (squared length, internal frame).
    pub(crate) weights: Vec<f64>,
    /// Weighted: the largest weight inserted since the triangulation was emptied. A cell's
    /// edges are shorter than twice `√(ρ + W − w)` for its orthogonal sphere's `ρ` and a
    /// least weight `w` (thesis Lemma 2.3.10), so `|z − p_0|² + W − w_0` plays the squared
    /// circumradius in the switch criterion (see [`Self::radius2`]).
    pub(crate) weight_max: f64,
    /// The number of anchors of the space ([`OrbitSpace::anchors`]): points `0..anchors`,
    /// never renumbered, whose vertices are only marked (no cell) while hidden.
    pub(crate) anchors: usize,
    /// Weighted: the points the insertions since the caller last looked hid, in order.
    pub(crate) hidden_log: Vec<HiddenPoint<S::Point>>,
    /// Vertex → its point (1-sheeted: the identity; covering: one vertex per copy).
    pub(crate) vpoint: Vec<PointId>,
    /// Vertex → one incident cell.
    pub(crate) vcell: Vec<CellId>,
    pub(crate) tds: Tds<S::Elem, N>,
    /// The level of the covering ladder the triangulation lives in.
    pub(crate) level: usize,
    /// `level` is the last one: the quotient itself.
    pub(crate) one_sheeted: bool,
    /// True while the switch criterion is known to hold, so that further insertions keep a
    /// valid 1-sheeted triangulation.
    pub(crate) guaranteed: bool,
    /// How removals go at the space's lift level ([`OrbitSpace::lift_level`]).
    lift: Lift,
    /// While the criterion of the next level (of the quotient once there) is not known to
    /// hold: cells whose circumradius is too large for it, and their number.
    big: Vec<bool>,
    big_count: usize,
    /// The squared circumradius that makes a cell big.
    big_limit: f64,
    /// The offsets of one point's copies in the current covering.
    copies: Vec<S::Elem>,
    hint: CellId,
    /// In a covering, per copy: a cell near the last inserted point's copy, its vertices
    /// (a freed and reused slot fails the check) and the shift, so that each copy of the
    /// next point walks from its own neighbourhood instead of a period away.
    copy_hints: Vec<(CellId, [VertexId; N], S::Elem)>,
    /// Where the last inserted point sits in the hint cell's frame, relative to its own
    /// offset: the next query (spatially close) starts its walk lifted by this translation,
    /// not a period away when the hint cell straddles the domain boundary.
    hint_shift: S::Elem,
    rng: SplitMix,
    scratch: Scratch<S::Elem>,
    around: Around,
    /// 3D: the star's boundary edges, to pair its new cells.
    ridges: ridges::Ridges,
    /// Jump-and-walk grid of the 1-sheeted triangulation.
    locator: locator::Locator,
    /// Threads of the parallel bulk insertion (0: one by one).
    threads: usize,
    /// The parallel insertion's spatial key of each point, as far as computed, kept from
    /// one call of [`Engine::insert_parallel`] (a BRIO round) to the next until the batch
    /// ends ([`Engine::end_batch`]): computing every key at each call took a tenth of a
    /// second a round at 10⁶ points. (Keys of points renumbered within a batch by a hiding
    /// insertion go stale; that only moves chunk borders.)
    wave_keys: Vec<u64>,
}

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// An empty triangulation of the space.
    pub fn new(space: S) -> Self {
        let mut e = Engine {
            anchors: space.anchors().len(),
            hint_shift: space.identity(),
            copies: Vec::new(),
            big_limit: 0.0,
            space,
            points: Vec::new(),
            weighted: false,
            weights: Vec::new(),
            weight_max: f64::NEG_INFINITY,
            hidden_log: Vec::new(),
            vpoint: Vec::new(),
            vcell: Vec::new(),
            tds: Tds::new(),
            level: 0,
            one_sheeted: false,
            guaranteed: false,
            lift: Lift::Criterion,
            big: Vec::new(),
            big_count: 0,
            hint: CellId(0),
            copy_hints: Vec::new(),
            rng: SplitMix::new(0x5eed),
            scratch: Scratch::default(),
            around: Around::default(),
            ridges: ridges::Ridges::default(),
            locator: locator::Locator::default(),
            threads: 0,
            wave_keys: Vec::new(),
        };
        e.clear();
        e
    }

    /// Forgets every point: the empty triangulation, whose first insertion starts in the
    /// covering of level 0 again.
    pub(crate) fn clear(&mut self) {
        let last = self.space.levels() - 1;
        self.points.clear();
        self.weights.clear();
        self.weight_max = f64::NEG_INFINITY;
        self.vpoint.clear();
        self.vcell.clear();
        self.tds.clear();
        self.level = 0;
        self.one_sheeted = false;
        self.guaranteed = false;
        self.big.clear();
        self.big_count = 0;
        self.big_limit = self.space.criterion_radius2(last.min(1));
        self.copies = self.space.covering_copies(0);
        self.hint = CellId(0);
        self.hint_shift = self.space.identity();
        self.copy_hints.clear();
        self.wave_keys = Vec::new();
        if self.anchors > 0 {
            self.install_anchors();
        }
    }

    /// True when an insertion may hide points: a regular triangulation, or a space whose
    /// points need not all be vertices ([`OrbitSpace::HIDES`]).
    #[inline(always)]
    pub(crate) fn hides(&self) -> bool {
        self.weighted || S::HIDES
    }

    /// The number of points other than the anchors.
    pub fn number_of_points(&self) -> usize {
        self.points.len() - self.anchors
    }

    /// True when point `p` is an anchor that is hidden (has no vertex in any cell).
    pub fn is_hidden_anchor(&self, p: PointId) -> bool {
        p.index() < self.anchors && self.vcell[self.vertex_of_point(p).index()] == CellId::NONE
    }

    /// An empty regular (weighted Delaunay) triangulation of the space: points come with
    /// weights ([`Self::insert_weighted`]) and may be hidden.
    pub fn new_weighted(space: S) -> Self {
        let mut e = Self::new(space);
        e.weighted = true;
        e
    }

    /// True for a regular (weighted) triangulation.
    pub fn is_weighted(&self) -> bool {
        self.weighted
    }

    /// The weights of the points (internal frame; empty when unweighted).
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// The weight of vertex `v` (0 when unweighted).
    #[inline(always)]
    pub fn vertex_weight(&self, v: VertexId) -> f64 {
        if self.weighted {
            self.weights[self.point_index(v)]
        } else {
            0.0
        }
    }

    /// The weights of the vertices `vids` (zeros when unweighted).
    #[inline(always)]
    fn weights_of(&self, vids: &[VertexId; N]) -> [f64; N] {
        vids.map(|v| self.vertex_weight(v))
    }

    /// The weights of the vertices of cell `c` (zeros when unweighted).
    #[inline]
    pub fn cell_weights(&self, c: CellId) -> [f64; N] {
        self.weights_of(&self.tds.cells[c.index()].v)
    }

    /// True when the lifted point `q` of weight `wq` conflicts with the positively oriented
    /// lifted simplex `s` of vertices `vids`: inside its circumsphere, or for weighted
    /// points of negative power distance to its orthogonal sphere (perturbed: never a tie).
    #[inline(always)]
    pub(crate) fn in_conflict(
        &self,
        s: &LiftedCell<S, N>,
        vids: &[VertexId; N],
        q: LiftedOf<S, N>,
        wq: f64,
    ) -> bool {
        if self.weighted {
            self.space.power_test(s, &self.weights_of(vids), q, wq) == Sign::Positive
        } else {
            self.space.in_sphere(s, q) == Sign::Positive
        }
    }

    /// [`Self::in_conflict`] of the stored cell `c`, `q` lifted into its frame.
    #[inline(always)]
    pub(crate) fn cell_conflicts(&self, c: CellId, q: LiftedOf<S, N>, wq: f64) -> bool {
        if self.weighted {
            return self.in_conflict(&self.lifted_cell(c), &self.tds.cells[c.index()].v, q, wq);
        }
        let (p, off) = self.stored_cell(c);
        self.space.in_sphere_stored(p, &off, q) == Sign::Positive
    }

    /// The stored points of cell `c`'s vertices, where they are, and their offsets (the
    /// lifted cell without copying the points).
    #[inline(always)]
    pub(crate) fn stored_cell(&self, c: CellId) -> ([&S::Point; N], [S::Elem; N]) {
        let cell = &self.tds.cells[c.index()];
        (
            std::array::from_fn(|i| &self.points[self.point_index(cell.v[i])]),
            self.tds.off(c),
        )
    }

    /// What the switch criterion compares with the squared radii of the ladder: the
    /// squared circumradius, or for weighted points `|z − p_0|² + W − w_0` (`z` the
    /// orthocenter, `W` the largest weight), which bounds a quarter of the squared length
    /// of any edge the cell's orthogonal sphere allows.
    #[inline]
    pub(crate) fn radius2(&self, s: &LiftedCell<S, N>, vids: &[VertexId; N]) -> f64 {
        if self.weighted {
            let ws = self.weights_of(vids);
            self.space.ortho_distance2(s, &ws) + (self.weight_max - ws[0])
        } else {
            self.space.circumradius2(s)
        }
    }

    /// [`Self::radius2`] of a stored cell.
    fn cell_radius2(&self, c: CellId) -> f64 {
        self.radius2(&self.lifted_cell(c), &self.tds.cells[c.index()].v)
    }

    /// Appends a point (and its weight when weighted).
    fn push_point(&mut self, p: S::Point, w: f64) {
        self.points.push(p);
        if self.weighted {
            self.weights.push(w);
            if w > self.weight_max {
                // the criterion was known for a smaller spread of weights
                self.weight_max = w;
                if self.guaranteed {
                    self.set_guaranteed(false);
                } else if !self.tds.is_empty() {
                    self.recount_big();
                }
            }
        }
    }

    /// Drops the last point (and its weight).
    fn pop_point(&mut self) {
        self.points.pop();
        if self.weighted {
            self.weights.pop();
        }
    }

    /// Reserves room for about `cells` cells and `points` points, and sizes the
    /// point-location grid for them (bulk construction).
    pub fn reserve(&mut self, points: usize, cells: usize) {
        self.locator.planned = self.points.len() + points;
        self.points.reserve(points);
        self.vpoint.reserve(points);
        self.vcell.reserve(points);
        self.tds.reserve(cells);
    }

    /// The orbit space.
    pub fn space(&self) -> &S {
        &self.space
    }

    /// The distinct points, in insertion order of their first occurrence.
    pub fn points(&self) -> &[S::Point] {
        &self.points
    }

    /// Number of sheets of the stored triangulation (1 once it lives in the quotient).
    pub fn sheets(&self) -> usize {
        if self.points.is_empty() {
            1
        } else {
            self.space.sheets(self.level)
        }
    }

    /// The level of the covering ladder the triangulation lives in (the last is the
    /// quotient), or the space's lift level ([`OrbitSpace::lift_level`], numbered after
    /// the ladder's).
    pub fn level(&self) -> usize {
        self.level
    }

    /// The last level: the quotient.
    pub(crate) fn last_level(&self) -> usize {
        self.space.levels() - 1
    }

    /// True when the stored triangulation is the 1-sheeted quotient.
    pub fn is_one_sheeted(&self) -> bool {
        self.one_sheeted
    }

    /// True when the switch criterion (`Δ < δ/2`) is known to hold.
    pub fn criterion_holds(&self) -> bool {
        self.guaranteed
    }

    /// Number of stored vertices (`sheets × points`).
    pub fn number_of_vertices(&self) -> usize {
        self.vpoint.len()
    }

    /// Number of stored cells.
    pub fn number_of_cells(&self) -> usize {
        self.tds.len()
    }

    /// One more than the largest cell id (live or free): the length of a table by cell id.
    pub fn cell_slots(&self) -> usize {
        self.tds.cells.len()
    }

    /// Ids of the stored cells.
    pub fn cell_ids(&self) -> impl Iterator<Item = CellId> + '_ {
        self.tds.ids()
    }

    /// Asks the processor to start loading cell `c` (see [`crate::tds::prefetch`]).
    #[inline(always)]
    pub(crate) fn prefetch_cell(&self, c: CellId) {
        crate::tds::prefetch(&self.tds.cells[c.index()]);
    }

    /// Starts loading the points of cell `c`'s vertices.
    pub(crate) fn prefetch_points(&self, c: CellId) {
        for v in self.vertices(c) {
            crate::tds::prefetch(&self.points[self.point_index(v)]);
        }
    }

    /// A stored cell (a copy).
    #[inline(always)]
    pub fn cell(&self, c: CellId) -> Cell<S::Elem, N> {
        self.tds.cell(c)
    }

    /// The vertices of cell `c` (its elements not decoded).
    #[inline(always)]
    pub(crate) fn vertices(&self, c: CellId) -> [VertexId; N] {
        self.tds.cells[c.index()].v
    }

    /// The neighbours of cell `c` (its elements not decoded).
    #[inline(always)]
    pub(crate) fn adjacent(&self, c: CellId) -> [CellId; N] {
        self.tds.cells[c.index()].n
    }

    /// The element of vertex `i` of cell `c` (the other slots not decoded).
    #[inline(always)]
    pub(crate) fn element(&self, c: CellId, i: usize) -> S::Elem {
        self.tds.off_at(c, i)
    }

    /// The point of a vertex: the vertex's own id once 1-sheeted (no load).
    #[inline]
    pub fn point_of(&self, v: VertexId) -> PointId {
        debug_assert!(!self.one_sheeted || self.vpoint.get(v.index()) == Some(&PointId(v.0)));
        PointId(self.point_index(v) as u32)
    }

    /// The lifted vertex `i` of cell `c`.
    #[inline(always)]
    pub fn lifted(&self, c: CellId, i: usize) -> LiftedOf<S, N> {
        let cell = &self.tds.cells[c.index()];
        (
            self.points[self.point_index(cell.v[i])],
            self.tds.off_at(c, i),
        )
    }

    /// The point of vertex `v` (the identity once 1-sheeted: no indirection on the hot path).
    #[inline(always)]
    fn point_index(&self, v: VertexId) -> usize {
        if self.one_sheeted {
            v.index()
        } else {
            self.vpoint[v.index()].index()
        }
    }

    /// All lifted vertices of cell `c`.
    #[inline(always)]
    pub fn lifted_cell(&self, c: CellId) -> LiftedCell<S, N> {
        // (an explicit loop: `array::from_fn` and `array::map` measured 20% slower here)
        let cell = &self.tds.cells[c.index()];
        let off = self.tds.off(c);
        let mut out = [(self.points[0], off[0]); N];
        for i in 0..N {
            out[i] = (self.points[self.point_index(cell.v[i])], off[i]);
        }
        out
    }

    /// The offset that maps the frame of `d = neighbour(c, i)` onto the frame of `c`.
    #[inline(always)]
    pub fn translation(&self, c: CellId, i: usize, d: CellId) -> S::Elem {
        let (cc, dc) = (&self.tds.cells[c.index()], &self.tds.cells[d.index()]);
        let one = self.space.identity();
        if self.tds.all_are(c, one) && self.tds.all_are(d, one) {
            return one;
        }
        let k = (i + 1) % N;
        let j = dc.index_of(cc.v[k]).expect("neighbours share a facet");
        self.space
            .carry(self.tds.off_at(d, j), self.tds.off_at(c, k))
    }

    /// The cells incident to vertex `v`: (cell, index of `v` in it, shift from the cell's
    /// frame to the frame of the first cell, so that the star lifts as one piece).
    pub fn star(&self, v: VertexId) -> Vec<(CellId, usize, S::Elem)> {
        let c0 = self.vcell[v.index()];
        let i0 = self.tds.cells[c0.index()]
            .index_of(v)
            .expect("vcell holds its vertex");
        let mut star = vec![(c0, i0, self.space.identity())];
        // the cells met so far, apart: a scan of bare ids is several times cheaper than a
        // set, until the star is large
        let mut seen = vec![c0];
        let mut many = FxHashSet::default();
        let mut next = 0;
        while next < star.len() {
            let (c, i, shift) = star[next];
            for k in (0..N).filter(|&k| k != i) {
                let d = self.tds.cells[c.index()].n[k];
                if seen.len() < STAR_SCANNED {
                    if seen.contains(&d) {
                        continue;
                    }
                    seen.push(d);
                    if seen.len() == STAR_SCANNED {
                        many.extend(seen.iter().copied());
                    }
                } else if !many.insert(d) {
                    continue;
                }
                let t = self.space.compose(shift, self.translation(c, k, d));
                let j = self.tds.cells[d.index()]
                    .index_of(v)
                    .expect("a neighbour through a facet holding v holds v");
                star.push((d, j, t));
            }
            next += 1;
        }
        star
    }

    /// The neighbours of vertex `v`: each (vertex, its offset relative to `v`) once, sorted.
    pub fn neighbours(&self, v: VertexId) -> Vec<(VertexId, S::Elem)> {
        let mut out = Vec::new();
        for (c, k, _) in self.star(v) {
            let cell = self.tds.cell(c);
            for j in (0..N).filter(|&j| j != k) {
                out.push((cell.v[j], self.space.relative(cell.off[j], cell.off[k])));
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Gives point `p` the representative `coords`, where `coords + t·M` is its current
    /// position: every copy's star gets its offset shifted by `t`, so no cell moves. In a
    /// covering each copy is renamed for the sheet of its new offset (an element outside
    /// the level's group moves the copies between sheets).
    pub(crate) fn move_representative(&mut self, p: PointId, coords: S::Point, t: S::Elem) {
        // the point itself once 1-sheeted; its copies `p·S … p·S+S−1` in the covering
        let copies = self.space.sheets(self.level) as u32;
        let mut slots: Vec<(CellId, usize)> = Vec::new();
        let mut homes: Vec<(VertexId, CellId)> = Vec::new();
        for v in p.0 * copies..(p.0 + 1) * copies {
            let v = VertexId(v);
            debug_assert_eq!(self.vpoint[v.index()], p);
            let c = self.vcell[v.index()];
            if c == CellId::NONE {
                continue;
            }
            let k = self.tds.cells[c.index()].index_of(v).unwrap_or(0);
            let moved = self.space.compose(self.tds.off_at(c, k), t);
            homes.push((self.vertex_id(p, moved), c));
            slots.extend(self.star(v).iter().map(|&(c, k, _)| (c, k)));
        }
        // (a cell with two copies changes once)
        slots.sort_unstable();
        for cell_slots in slots.chunk_by(|a, b| a.0 == b.0) {
            let c = cell_slots[0].0;
            let mut cell = self.tds.cell(c);
            for &(_, k) in cell_slots {
                cell.off[k] = self.space.compose(cell.off[k], t);
                cell.v[k] = self.vertex_id(p, cell.off[k]);
            }
            self.canonicalize(&mut cell);
            self.tds.put(c, cell);
        }
        for (v, c) in homes {
            self.vcell[v.index()] = c;
        }
        self.points[p.index()] = coords;
    }

    /// A vertex of point `p`: the point's own id once 1-sheeted, its copy on sheet 0
    /// (offset zero) in the covering.
    pub fn vertex_of_point(&self, p: PointId) -> VertexId {
        if self.one_sheeted {
            VertexId(p.0)
        } else {
            let sheets = self.space.sheets(self.level) as u32;
            VertexId(p.0 * sheets + self.space.sheet_of(self.space.identity(), self.level) as u32)
        }
    }

    /// Exact orientation of a stored cell.
    pub fn orientation(&self, c: CellId) -> Sign {
        self.space.orient(&self.lifted_cell(c))
    }

    /// Puts a cell's elements in the canonical form of the current level. When that moves
    /// the cell by an orientation-reversing element, slots 0 and 1 are exchanged, so that
    /// the cell stays positively oriented in its frame; callers find slots by vertex
    /// ([`Self::slot`]), never by position.
    #[inline]
    fn canonicalize(&self, cell: &mut Cell<S::Elem, N>) {
        if self.space.normalize(&mut cell.off, self.level) && S::MAY_REVERSE {
            cell.swap_slots(0, 1);
        }
    }

    /// The slot of vertex `x` in cell `c`, which is `guess` unless canonicalizing the cell
    /// exchanged slots.
    #[inline(always)]
    fn slot(&self, c: CellId, x: VertexId, guess: usize) -> usize {
        if !S::MAY_REVERSE {
            return guess;
        }
        let cell = &self.tds.cells[c.index()];
        if cell.v[guess] == x {
            guess
        } else {
            cell.index_of(x).expect("the cell holds the vertex")
        }
    }

    /// Creates a cell in canonical form and keeps the criterion bookkeeping.
    #[inline(always)]
    fn make_cell(&mut self, v: [VertexId; N], off: [S::Elem; N]) -> CellId {
        let mut cell = Cell::new(v, off);
        self.canonicalize(&mut cell);
        self.add_cell(cell)
    }

    /// Stores a canonical cell and keeps the criterion bookkeeping.
    #[inline(always)]
    fn add_cell(&mut self, cell: Cell<S::Elem, N>) -> CellId {
        let id = self.tds.create(cell);
        self.added(id)
    }

    /// Creates a cell of vertices `v` with the elements of the live cell `like` (canonical
    /// already) and keeps the criterion bookkeeping.
    #[inline(always)]
    fn make_cell_like(&mut self, v: [VertexId; N], like: CellId) -> CellId {
        let id = self.tds.create_like(v, like);
        self.added(id)
    }

    /// Keeps the criterion bookkeeping of the new cell `id`.
    #[inline(always)]
    fn added(&mut self, id: CellId) -> CellId {
        if !self.guaranteed {
            self.track(id);
        }
        id
    }

    /// Records whether cell `c` is too large for the criterion of the next level.
    fn track(&mut self, c: CellId) {
        let big = self.cell_radius2(c) >= self.big_limit;
        if self.big.len() <= c.index() {
            self.big.resize(c.index() + 1, false);
        }
        self.big[c.index()] = big;
        self.big_count += big as usize;
    }

    /// Declares whether the switch criterion of the quotient is known to hold; when it stops
    /// being known, every cell is examined so that the count of large cells is exact.
    fn set_guaranteed(&mut self, holds: bool) {
        if holds {
            self.big.clear();
            self.big_count = 0;
        } else if self.guaranteed {
            self.recount_big();
        }
        self.guaranteed = holds;
    }

    /// The squared circumradius that makes a cell big: the criterion of the level after the
    /// current one (of the quotient once there).
    pub(super) fn next_limit(&self) -> f64 {
        let target = (self.level + 1).min(self.last_level());
        self.space.criterion_radius2(target)
    }

    /// Examines every cell against the criterion of the level after the current one (of the
    /// quotient once there).
    fn recount_big(&mut self) {
        self.big_limit = self.next_limit();
        self.big.clear();
        self.big_count = 0;
        let ids: Vec<CellId> = self.tds.ids().collect();
        for c in ids {
            self.track(c);
        }
    }

    /// Deletes a cell and keeps the criterion bookkeeping.
    fn kill_cell(&mut self, c: CellId) {
        if !self.guaranteed && self.big[c.index()] {
            self.big[c.index()] = false;
            self.big_count -= 1;
        }
        self.tds.delete(c);
    }

    /// Points `vcell` of every vertex of `c` at `c`.
    #[inline]
    fn attach(&mut self, c: CellId) {
        let v = self.tds.cells[c.index()].v;
        for x in v {
            self.vcell[x.index()] = c;
        }
    }

    /// Links facet `i` of `a` with facet `j` of `b`.
    #[inline]
    fn link(&mut self, a: CellId, i: usize, b: CellId, j: usize) {
        self.tds.cells[a.index()].n[i] = b;
        self.tds.cells[b.index()].n[j] = a;
    }

    /// A live cell to start a walk from, and the translation to apply to a query near the
    /// last inserted point.
    fn start_cell(&self) -> (CellId, S::Elem) {
        if self.hint != CellId::NONE
            && self.hint.index() < self.tds.cells.len()
            && self.tds.is_alive(self.hint)
        {
            (self.hint, self.hint_shift)
        } else {
            (
                self.tds.ids().next().expect("a non-empty triangulation"),
                self.space.identity(),
            )
        }
    }
}

/// A unit cube torus started from its dummy points, then 2000 points (seed 3) inserted one
/// at a time: on the four planes `z = 0, 1/4, 1/2, 3/4`, or with `slab = Some(t)` uniform
/// in the slab `z < t` beside a vacuum. With the points: the start of the tests of the
/// dummy points' early leaving.
#[cfg(test)]
pub(crate) fn from_dummies(
    slab: Option<f64>,
) -> (Engine<crate::space::FlatTorus3, 4>, Vec<[f64; 3]>) {
    let space = crate::space::FlatTorus3::cuboid([1.0; 3]).unwrap();
    let mut e = Engine::new(space.clone());
    e.points = space.dummy_points();
    e.bootstrap_one_sheeted();
    let mut r = SplitMix::new(3);
    let pts: Vec<[f64; 3]> = (0..2000)
        .map(|i| {
            let z = slab.map_or(0.25 * (i % 4) as f64, |t| t * r.unit());
            [r.unit(), r.unit(), z]
        })
        .collect();
    for &p in &pts {
        e.insert(p);
    }
    (e, pts)
}

/// A unit cube torus with `n` uniform random points (seed `seed`) inserted one at a time:
/// the engine the module's unit tests start from.
#[cfg(test)]
fn uniform_cube(n: usize, seed: u64) -> Engine<crate::space::FlatTorus3, 4> {
    let mut e = Engine::new(crate::space::FlatTorus3::cuboid([1.0; 3]).unwrap());
    let mut r = SplitMix::new(seed);
    for _ in 0..n {
        e.insert([r.unit(), r.unit(), r.unit()]);
    }
    e
}
