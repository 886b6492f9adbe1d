//! Point location by a remembering stochastic walk, the conflict region by breadth-first
//! search (in 2D depth-first, its boundary in order around it), and starring the hole.

use super::{Engine, HiddenPoint, Inserted, LiftedOf, Scratch};
use crate::ids::{CellId, PointId, VertexId};
use crate::predicates::Sign;
use crate::sort::SplitMix;
use crate::space::OrbitSpace;
use crate::tds::replaced;

/// Why a lifted point was not inserted.
pub(crate) enum Refused {
    /// It coincides with this vertex.
    Duplicate(VertexId),
    /// Starring its conflict region would break the quotient (1-sheeted without criterion).
    NotSimplicial,
    /// Weighted: it conflicts with no cell (its power cell is empty).
    Hidden,
}

/// 2D: true when the boundary edges of `rim` (all `edges` of them) chain into one closed
/// walk, each edge's end the next one's start (always, for a disk; checked, since the fan
/// relies on it).
pub(super) fn closes(rim: &[(VertexId, VertexId, u8)], edges: usize) -> bool {
    rim.len() == edges
        && rim.windows(2).all(|w| w[0].1 == w[1].0)
        && rim.last().map(|e| e.1) == rim.first().map(|e| e.0)
}

/// A frame of the 2D search around a conflict region: the triangle's index in the region,
/// its next edge, the turn from edge to edge (1 or 2) and the edges left.
pub(super) type Frame = (u32, u8, u8, u8);

/// The next edge of the 2D search around a region: (the triangle's index in the region,
/// the edge, the turn), its frame moved past it; `None` when the search is over.
#[inline(always)]
pub(super) fn next_edge(stack: &mut Vec<Frame>) -> Option<(u32, usize, usize)> {
    while let Some(top) = stack.last_mut() {
        if top.3 == 0 {
            stack.pop();
            continue;
        }
        let (ci, i, step) = (top.0, top.1 as usize, top.2 as usize);
        top.1 = ((i + step) % 3) as u8;
        top.3 -= 1;
        return Some((ci, i, step));
    }
    None
}

/// The ends of edge `i` of a triangle with vertices `v`, in the order of a walk around it
/// turning by `step`.
#[inline(always)]
pub(super) fn edge_ends(v: &[VertexId], i: usize, step: usize) -> (VertexId, VertexId) {
    (v[(i + step) % 3], v[(i + 2 * step) % 3])
}

/// Enters triangle `k` of the region (vertices `v`) through its edge `j`, whose walk ends at
/// `b`: the search goes on from the edge after it, `b` to the third vertex.
#[inline(always)]
pub(super) fn enter(stack: &mut Vec<Frame>, k: usize, v: &[VertexId], j: usize, b: VertexId) {
    let step = if v[(j + 1) % 3] == b { 1 } else { 2 };
    stack.push((k as u32, ((j + step) % 3) as u8, step as u8, 2));
}

/// The slot of vertex `y` in a new 2D cell with vertices `v`, built on edge `i` of a
/// conflict cell (`y` at slot `i + 1` or `i + 2`, unless canonicalizing moved it).
#[inline(always)]
pub(super) fn slot_in<const N: usize>(v: &[VertexId; N], y: VertexId, i: usize) -> usize {
    let (s1, s2) = ((i + 1) % 3, (i + 2) % 3);
    if v[s1] == y {
        s1
    } else if v[s2] == y {
        s2
    } else {
        v.iter()
            .position(|&w| w == y)
            .expect("the cell holds the vertex")
    }
}

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// The cell containing the lifted point `q`, and `q`'s offset in that cell's frame.
    /// Remembering stochastic walk: never step back through the facet just crossed, and try
    /// the facets in a random rotation drawn from `rng` (the walk's only state: the
    /// triangulation is only read).
    pub fn walk(&self, q: LiftedOf<S, N>, start: CellId, rng: &mut SplitMix) -> (CellId, S::Elem) {
        let (c, qo, _) = self
            .walk_within(q, start, rng, |_| true)
            .expect("a walk through every cell ends in one");
        (c, qo)
    }

    /// [`Self::walk`] through the cells that `inside` accepts (`start` among them): `None`
    /// when it would step into another. The flag is true when the point is strictly inside
    /// the cell found (on none of its facets' planes).
    #[inline(always)]
    pub(super) fn walk_within(
        &self,
        q: LiftedOf<S, N>,
        start: CellId,
        rng: &mut SplitMix,
        inside: impl Fn(CellId) -> bool,
    ) -> Option<(CellId, S::Elem, bool)> {
        let (p, mut qo) = q;
        let mut c = start;
        let mut prev = CellId::NONE;
        'walk: loop {
            let r = rng.below(N);
            self.tds.prefetch_neighbours(c);
            let (mut pts, mut offs) = self.stored_cell(c);
            // (the facet just crossed has the point strictly on this cell's side)
            let mut strict = true;
            for k in 0..N {
                let i = (r + k) % N;
                let d = self.tds.cells[c.index()].n[i];
                if d == prev {
                    continue;
                }
                let keep = (pts[i], offs[i]);
                (pts[i], offs[i]) = (&p, qo);
                let o = self.space.orient_stored(pts, &offs);
                (pts[i], offs[i]) = keep;
                if o == Sign::Negative {
                    if !inside(d) {
                        return None;
                    }
                    let t = self.translation(c, i, d);
                    qo = self.space.relative(qo, t);
                    prev = c;
                    c = d;
                    continue 'walk;
                }
                strict &= o == Sign::Positive;
            }
            return Some((c, qo, strict));
        }
    }

    /// [`Self::walk`] with the engine's own random generator (insertion).
    /// (The flag: strictly inside, as [`Self::walk_within`].)
    fn locate_from(&mut self, q: LiftedOf<S, N>, start: CellId) -> (CellId, S::Elem, bool) {
        let mut rng = self.rng.clone();
        let found = self
            .walk_within(q, start, &mut rng, |_| true)
            .expect("a walk through every cell ends in one");
        self.rng = rng;
        found
    }

    /// The cell containing the point (at the identity), walking from a vertex near it (the
    /// jump-and-walk grid) or else from the last insertion; it only reads the
    /// triangulation, so queries may run in parallel.
    pub fn locate(&self, p: S::Point) -> (CellId, S::Elem) {
        let from = self
            .jump(self.space.spatial_key(&p))
            .unwrap_or_else(|| self.start_cell());
        self.locate_from_cell(p, from)
    }

    /// The cell containing the point (at the identity), walking from `from`, a cell near
    /// it and the shift that lifts it there (see [`Self::walk`]): consecutive queries of
    /// a spatially sorted batch each start from the previous answer.
    pub fn locate_from_cell(&self, p: S::Point, from: (CellId, S::Elem)) -> (CellId, S::Elem) {
        self.walk((p, from.1), from.0, &mut SplitMix::new(0x10ca7e))
    }

    /// True when the weighted point `p` of weight `w` would be a vertex if inserted (or a
    /// duplicate): its power cell is not empty.
    pub fn would_appear(&self, p: S::Point, w: f64) -> bool {
        if self.points.is_empty() {
            return true;
        }
        let (c, qo) = self.locate(p);
        self.cell_conflicts(c, (p, qo), w) || self.coincident_vertex(c, (p, qo), w).is_some()
    }

    /// The vertex of cell `c` at the lifted point `q` of weight `wq`, if any (a weighted
    /// point on another of a different weight hides it or is hidden: no duplicate).
    #[inline(always)]
    pub(super) fn coincident_vertex(
        &self,
        c: CellId,
        q: LiftedOf<S, N>,
        wq: f64,
    ) -> Option<VertexId> {
        (0..N)
            .find(|&i| {
                self.vertex_weight(self.tds.cells[c.index()].v[i]) == wq
                    && self.space.coincide(self.lifted(c, i), q)
            })
            .map(|i| self.tds.cells[c.index()].v[i])
    }

    /// Drops the last point and its vertex, just pushed (1-sheeted, or one copy pushed).
    pub(super) fn unpush_point(&mut self) {
        self.pop_point();
        self.vpoint.pop();
        self.vcell.pop();
    }

    /// Collects the cells in conflict with the point `p` of weight `wq` (whose circumsphere
    /// contains it; for weighted points, of negative power distance), starting at `c0`,
    /// which contains `p` lifted by `q0` and conflicts with it, and the facets bounding them.
    fn find_conflicts(&mut self, c0: CellId, q0: S::Elem, p: S::Point, wq: f64) {
        if N == 3 {
            return self.find_conflicts_around(c0, q0, p, wq);
        }
        let (inside, outside) = self.tds.new_visit();
        let mut scratch = std::mem::take(&mut self.scratch);
        scratch.conflict.clear();
        scratch.boundary.clear();
        scratch.conflict.push((c0, q0));
        self.tds.set_stamp(c0, inside);
        let mut next = 0;
        while next < scratch.conflict.len() {
            let (c, qo) = scratch.conflict[next];
            for i in 0..N {
                let d = self.tds.cells[c.index()].n[i];
                let st = self.tds.stamp(d);
                if st == inside {
                    continue;
                }
                if st != outside {
                    if let Some(qd) = self.conflict_across((c, i, d), (p, qo), wq) {
                        self.tds.set_stamp(d, inside);
                        self.tds.prefetch_neighbours(d);
                        scratch.conflict.push((d, qd));
                        continue;
                    }
                    self.tds.set_stamp(d, outside);
                }
                scratch.boundary.push((next as u32, i as u8));
            }
            next += 1;
        }
        self.scratch = scratch;
    }

    /// 2D: [`Self::find_conflicts`] by depth-first search, each triangle's edges taken in
    /// the order of a walk around it, so that the boundary edges come in the order of a
    /// walk around the region (a disk), with their ends in `around.rim`. A neighbour seen
    /// through a reflection ([`OrbitSpace::MAY_REVERSE`]) lists its vertices the other way
    /// round: the shared edge's ends tell which way to turn in it.
    fn find_conflicts_around(&mut self, c0: CellId, q0: S::Elem, p: S::Point, wq: f64) {
        let (inside, outside) = self.tds.new_visit();
        let mut scratch = std::mem::take(&mut self.scratch);
        let mut around = std::mem::take(&mut self.around);
        scratch.conflict.clear();
        scratch.boundary.clear();
        around.rim.clear();
        around.stack.clear();
        scratch.conflict.push((c0, q0));
        self.tds.set_stamp(c0, inside);
        around.stack.push((0, 0, 1, 3));
        while let Some((ci, i, step)) = next_edge(&mut around.stack) {
            let (c, qo) = scratch.conflict[ci as usize];
            let cell = &self.tds.cells[c.index()];
            let d = cell.n[i];
            let st = self.tds.stamp(d);
            if st == inside {
                continue;
            }
            // the edge's ends in the order of the walk
            let (a, b) = edge_ends(&cell.v, i, step);
            let j = self.mirror_of(d, c);
            if st != outside {
                if let Some(qd) = self.conflict_across((c, i, d), (p, qo), wq) {
                    self.tds.set_stamp(d, inside);
                    self.tds.prefetch_neighbours(d);
                    scratch.conflict.push((d, qd));
                    let k = scratch.conflict.len() - 1;
                    enter(&mut around.stack, k, &self.tds.cells[d.index()].v, j, b);
                    continue;
                }
                self.tds.set_stamp(d, outside);
            }
            scratch.boundary.push((ci, i as u8));
            around.rim.push((a, b, j as u8));
        }
        self.scratch = scratch;
        self.around = around;
    }

    /// Replaces the conflict region by the cone from the new vertex `x` (lifted with offset
    /// `qoff` as inserted) over its boundary (never inlined: see
    /// [`Self::conflict_region_at`]).
    #[inline(never)]
    pub(super) fn star_hole(&mut self, x: VertexId, qoff: S::Elem) {
        let mut scratch = std::mem::take(&mut self.scratch);
        scratch.created.clear();
        if N == 3 && closes(&self.around.rim, scratch.boundary.len()) {
            self.star_around(&mut scratch, x);
        } else {
            self.star_rotating(&mut scratch, x);
        }
        self.after_star(&mut scratch, x, qoff);
        self.scratch = scratch;
    }

    /// 2D: the new triangles in the order of the walk around the region, each linked to
    /// the next (they share the edge from `x` to the end of this one's edge).
    fn star_around(&mut self, scratch: &mut Scratch<S::Elem>, x: VertexId) {
        let rim = std::mem::take(&mut self.around.rim);
        for (&facet, &(_, _, j)) in scratch.boundary.iter().zip(&rim) {
            let (nc, outside) = self.cell_on_facet(scratch, facet, x);
            self.link(nc, self.slot(nc, x, facet.1 as usize), outside, j as usize);
            scratch.created.push(nc);
        }
        let m = rim.len();
        for k in 0..m {
            let next = if k + 1 == m { 0 } else { k + 1 };
            let (nc, nd) = (scratch.created[k], scratch.created[next]);
            // the edge from `x` to the common vertex: opposite this edge's start here, the
            // next edge's end there
            let sa = self.slot_of(nc, rim[k].0, scratch.boundary[k].1 as usize);
            let sb = self.slot_of(nd, rim[next].1, scratch.boundary[next].1 as usize);
            self.link(nc, sa, nd, sb);
        }
        self.around.rim = rim;
    }

    /// The point `q` (lifted by `q.1` in cell `c`) lifted into `c`'s neighbour `d` across
    /// facet `i`, if `d` is in conflict with it (weight `wq`).
    #[inline(always)]
    pub(super) fn conflict_across(
        &self,
        (c, i, d): (CellId, usize, CellId),
        (p, qo): LiftedOf<S, N>,
        wq: f64,
    ) -> Option<S::Elem> {
        let qd = self.space.relative(qo, self.translation(c, i, d));
        self.cell_conflicts(d, (p, qd), wq).then_some(qd)
    }

    /// The slot of neighbour `c` in its neighbour `d`.
    #[inline(always)]
    pub(super) fn mirror_of(&self, d: CellId, c: CellId) -> usize {
        self.tds.cells[d.index()]
            .mirror(c)
            .expect("symmetric neighbours")
    }

    /// The new cell on boundary facet `(ci, i)` of the conflict region: conflict cell `ci`
    /// with `x` (lifted as the point is there) in place of its vertex `i`; returned with
    /// the conflict cell's neighbour across that facet. When `x`'s element there is the
    /// one it replaces (inside the domain, every element is the identity), the new cell has
    /// the conflict cell's elements, which are canonical, and takes them as stored.
    #[inline(always)]
    fn cell_on_facet(
        &mut self,
        scratch: &Scratch<S::Elem>,
        (ci, i): (u32, u8),
        x: VertexId,
    ) -> (CellId, CellId) {
        let (c, qo) = scratch.conflict[ci as usize];
        let i = i as usize;
        let stored = &self.tds.cells[c.index()];
        let (v, outside) = (replaced(stored.v, i, x), stored.n[i]);
        let nc = if self.tds.off_at(c, i) == qo {
            self.make_cell_like(v, c)
        } else {
            self.make_cell(v, replaced(self.tds.off(c), i, qo))
        };
        (nc, outside)
    }

    /// The slot of vertex `y` in the new 2D cell `c` built on edge `i` of a conflict cell.
    #[inline(always)]
    fn slot_of(&self, c: CellId, y: VertexId, i: usize) -> usize {
        slot_in(&self.tds.cells[c.index()].v, y, i)
    }

    /// The new cells, one per boundary facet (any dimension, the boundary in any order),
    /// linked to each other by their ridges (3D) or by rotating through the conflict region.
    fn star_rotating(&mut self, scratch: &mut Scratch<S::Elem>, x: VertexId) {
        // 1. one new cell per boundary facet, linked to the outside neighbour; the conflict
        //    cell's pointer through that facet is redirected to the new cell.
        for &facet in &scratch.boundary {
            let (nc, d) = self.cell_on_facet(scratch, facet, x);
            let (c, i) = (scratch.conflict[facet.0 as usize].0, facet.1 as usize);
            let j = self.mirror_of(d, c);
            self.link(nc, self.slot(nc, x, i), d, j);
            self.tds.cells[c.index()].n[i] = nc;
            scratch.created.push(nc);
        }
        // 2. link the new cells to each other
        if N == 4 && self.link_by_ridges(scratch, x) {
            return;
        }
        self.link_by_rotation(scratch);
    }

    /// 3D: links the new cells across their facets through `x`, pairing them by the
    /// boundary edge each facet stands on ([`Ridges`](super::ridges::Ridges)). False,
    /// linking nothing, when the star is not simplicial.
    fn link_by_ridges(&mut self, scratch: &Scratch<S::Elem>, x: VertexId) -> bool {
        let mut ridges = std::mem::take(&mut self.ridges);
        let cells = scratch
            .created
            .iter()
            .zip(&scratch.boundary)
            .map(|(&nc, &(_, i))| {
                (
                    nc.0,
                    self.tds.cells[nc.index()].v,
                    self.slot(nc, x, i as usize),
                )
            });
        let linked = match ridges.pair(cells) {
            Some(pairs) => {
                for &(c, k, d, l) in pairs {
                    self.link(CellId(c), k as usize, CellId(d), l as usize);
                }
                true
            }
            None => false,
        };
        self.ridges = ridges;
        linked
    }

    /// Links the new cells around each ridge by rotating through the conflict region (its
    /// cells' pointers through the boundary facets already redirected to the new cells).
    fn link_by_rotation(&mut self, scratch: &Scratch<S::Elem>) {
        let inside = self.tds.stamp(scratch.conflict[0].0);
        for (k, &(ci, i)) in scratch.boundary.iter().enumerate() {
            let nc = scratch.created[k];
            let c0 = scratch.conflict[ci as usize].0;
            // slots of the new cell (the one of `x` is linked already)
            for j in 0..N {
                if self.tds.cells[nc.index()].n[j] != CellId::NONE {
                    continue;
                }
                let (mut u, mut w) = (
                    self.tds.cells[c0.index()].v[i as usize],
                    self.tds.cells[nc.index()].v[j],
                );
                let mut cur = c0;
                loop {
                    let cc = &self.tds.cells[cur.index()];
                    let kw = cc.index_of(w).expect("ridge rotation");
                    let nb = cc.n[kw];
                    if self.tds.stamp(nb) != inside {
                        // (cur, kw) is a boundary facet and nb the new cell built on it
                        let ku = cc.index_of(u).expect("ridge rotation");
                        self.link(nc, j, nb, self.slot(nb, u, ku));
                        break;
                    }
                    let m = self.mirror_of(nb, cur);
                    let xv = self.tds.cells[nb.index()].v[m];
                    w = u;
                    u = xv;
                    cur = nb;
                }
            }
        }
    }

    /// After the new cells are linked: the conflict cells die, the new ones are attached to
    /// their vertices, hidden vertices are collected, and the next walk starts at `x`.
    fn after_star(&mut self, scratch: &mut Scratch<S::Elem>, x: VertexId, qoff: S::Elem) {
        // a vertex of the region on none of its boundary facets is hidden; its vertex then
        // points at no live cell once the new cells are attached. The region is a disk (a
        // ball): in 2D, `C` triangles with `B` boundary edges have `1 + (C − B)/2` vertices
        // inside, so `C = B − 2` means none, and the scan is skipped.
        let first_hidden = scratch.hidden.len();
        let inner = N != 3 || scratch.conflict.len() + 2 != scratch.boundary.len();
        let hiding = self.hides() && inner;
        if hiding {
            for &(c, _) in &scratch.conflict {
                scratch.hidden.extend(self.tds.cells[c.index()].v);
            }
        }
        for &(c, _) in &scratch.conflict {
            self.kill_cell(c);
        }
        for &nc in &scratch.created {
            self.attach(nc);
        }
        if hiding {
            let mut k = first_hidden;
            for j in first_hidden..scratch.hidden.len() {
                let v = scratch.hidden[j];
                if !self.tds.is_alive(self.vcell[v.index()])
                    && !scratch.hidden[first_hidden..k].contains(&v)
                {
                    scratch.hidden[k] = v;
                    k += 1;
                }
            }
            scratch.hidden.truncate(k);
        }
        let first = scratch.created[0];
        let k = self.tds.cells[first.index()]
            .index_of(x)
            .expect("new cells hold the new vertex");
        self.hint = first;
        self.hint_shift = self.space.carry(qoff, self.tds.off_at(first, k));
    }

    /// True when a vertex of the conflict region `conflict` lies on none of its `boundary`
    /// facets (starring it would hide that vertex).
    pub(super) fn hides_vertices(
        &self,
        conflict: &[(CellId, S::Elem)],
        boundary: &[(u32, u8)],
    ) -> bool {
        if N == 3 {
            // a disk of `C` triangles and `B` boundary edges has `1 + (C − B)/2` inner
            // vertices
            return conflict.len() + 2 != boundary.len();
        }
        let on_boundary = |v: VertexId| {
            boundary.iter().any(|&(ci, i)| {
                let cell = &self.tds.cells[conflict[ci as usize].0.index()];
                cell.v
                    .iter()
                    .enumerate()
                    .any(|(k, &w)| k != i as usize && w == v)
            })
        };
        conflict
            .iter()
            .any(|&(c, _)| self.tds.cells[c.index()].v.iter().any(|&v| !on_boundary(v)))
    }

    /// True when starring the current conflict region keeps the quotient a simplicial
    /// complex, for a 1-sheeted triangulation without the criterion: every conflict sphere
    /// holds a single lift of the new point, and the new edges (all at the new point) join it
    /// to each neighbour with one offset only (no cycle of length ≤ 2, Theorem 2.2.8).
    fn star_keeps_simplicial(&self) -> bool {
        let limit = self.space.single_lift_radius2();
        if self
            .scratch
            .conflict
            .iter()
            .any(|&(c, _)| self.cell_radius2(c) >= limit)
        {
            return false;
        }
        let mut seen: Vec<(VertexId, S::Elem)> = Vec::new();
        for &(ci, i) in &self.scratch.boundary {
            let (c, qo) = self.scratch.conflict[ci as usize];
            let cell = self.tds.cell(c);
            for k in (0..N).filter(|&k| k != i as usize) {
                let rel = self.space.relative(cell.off[k], qo);
                match seen.iter().find(|e| e.0 == cell.v[k]) {
                    Some(e) if e.1 != rel => return false,
                    Some(_) => {}
                    None => seen.push((cell.v[k], rel)),
                }
            }
        }
        true
    }

    /// Inserts the lifted point `q` of point `point` as vertex `x`, or says why not.
    /// The walk starts at `from` (a cell and the shift that lifts `q` into its frame) or,
    /// without it, from the last insertion. Strictly inside a triangle where
    /// [`Self::flips`], by splitting it and flipping; else by starring the conflict region.
    pub(crate) fn insert_lifted(
        &mut self,
        q: LiftedOf<S, N>,
        x: VertexId,
        check_duplicate: bool,
        from: Option<(CellId, S::Elem)>,
    ) -> Result<(), Refused> {
        let (c, qo, strict) = self.locate_lifted(q, from);
        if strict && self.flips() {
            // (strictly inside a triangle: no vertex there, no duplicate)
            self.insert_by_flips(c, (q.0, qo), x, q.1);
            return Ok(());
        }
        self.conflict_region_at((c, qo), q, x, check_duplicate)?;
        self.star_hole(x, q.1);
        Ok(())
    }

    /// The cell containing the lifted point `q`, found from `from` (or the last insertion),
    /// `q`'s element in its frame, and whether `q` is strictly inside it.
    #[inline(always)]
    fn locate_lifted(
        &mut self,
        q: LiftedOf<S, N>,
        from: Option<(CellId, S::Elem)>,
    ) -> (CellId, S::Elem, bool) {
        let (start, shift) = from.unwrap_or_else(|| self.start_cell());
        self.locate_from((q.0, self.space.compose(shift, q.1)), start)
    }

    /// Locates `q` and collects its conflict region (in the scratch), or says why it would
    /// not be inserted: the first half of an insertion that stars the region.
    pub(super) fn conflict_region(
        &mut self,
        q: LiftedOf<S, N>,
        x: VertexId,
        check_duplicate: bool,
        from: Option<(CellId, S::Elem)>,
    ) -> Result<(), Refused> {
        let (c, qo, _) = self.locate_lifted(q, from);
        self.conflict_region_at((c, qo), q, x, check_duplicate)
    }

    /// [`Self::conflict_region`] once `q` is located: in cell `c`, lifted by `qo`. (Like
    /// [`Self::star_hole`], never inlined: kept apart, the two run 4 % faster on the sphere.)
    #[inline(never)]
    fn conflict_region_at(
        &mut self,
        (c, qo): (CellId, S::Elem),
        q: LiftedOf<S, N>,
        x: VertexId,
        check_duplicate: bool,
    ) -> Result<(), Refused> {
        let wq = self.vertex_weight(x);
        if check_duplicate {
            if let Some(v) = self.coincident_vertex(c, (q.0, qo), wq) {
                self.hint = c;
                self.hint_shift = self.space.carry(q.1, qo);
                return Err(Refused::Duplicate(v));
            }
        }
        if self.hides() && !self.cell_conflicts(c, (q.0, qo), wq) {
            self.hint = c;
            self.hint_shift = self.space.carry(q.1, qo);
            return Err(Refused::Hidden);
        }
        self.find_conflicts(c, qo, q.0, wq);
        if self.one_sheeted && !self.guaranteed && !self.star_keeps_simplicial() {
            return Err(Refused::NotSimplicial);
        }
        Ok(())
    }

    /// Inserts a point of the domain. In the covering space every copy is inserted, and the
    /// triangulation switches to the 1-sheeted quotient as soon as the criterion holds.
    pub fn insert(&mut self, p: S::Point) -> Inserted {
        self.insert_weighted(p, 0.0)
    }

    /// Inserts a point of weight `w` (ignored unless the triangulation is weighted). A
    /// weighted point whose power cell is empty is [`Inserted::Hidden`]; the points it
    /// hides leave the triangulation, each renumbering the last point into its id, and
    /// are logged in `hidden_log`, in order.
    pub fn insert_weighted(&mut self, p: S::Point, w: f64) -> Inserted {
        self.insert_keyed(p, w, self.space.spatial_key(&p))
    }

    /// [`Self::insert_weighted`] for a point whose spatial key the caller has computed
    /// already (to sort a batch): `key` must be `space().spatial_key(&p)`.
    pub fn insert_keyed(&mut self, p: S::Point, w: f64, key: u64) -> Inserted {
        debug_assert_eq!(key, self.space.spatial_key(&p));
        self.scratch.hidden.clear();
        self.insert_point(p, w, key)
    }

    /// After inserting point `pi`: drops the points whose vertices it hid, largest id
    /// first (so that the last point, which takes a dropped id, is never hidden itself),
    /// and returns the new point's id after that renumbering.
    fn drop_hidden(&mut self, mut pi: PointId) -> PointId {
        if self.scratch.hidden.is_empty() {
            return pi;
        }
        let mut gone: Vec<PointId> = std::mem::take(&mut self.scratch.hidden)
            .into_iter()
            .map(|v| self.point_of(v))
            .collect();
        gone.sort_unstable_by(|a, b| b.cmp(a));
        gone.dedup();
        for p in gone {
            if p.index() < self.anchors {
                // an anchor is only marked (all its copies, hidden together by symmetry): it
                // comes back when the points stop enclosing it
                let sheets = self.space.sheets(self.level);
                self.vcell[p.index() * sheets..(p.index() + 1) * sheets].fill(CellId::NONE);
                continue;
            }
            self.hidden_log.push(HiddenPoint {
                id: p,
                point: self.points[p.index()],
                weight: self.weights.get(p.index()).copied().unwrap_or(0.0),
            });
            let last = PointId::new(self.points.len() - 1);
            self.renumber_last_point(p);
            if last == pi {
                pi = p;
            }
        }
        // (the jump-and-walk grid is a cache checked on use: renumbered points need nothing)
        pi
    }

    fn insert_point(&mut self, p: S::Point, w: f64, key: u64) -> Inserted {
        if self.points.is_empty() {
            self.push_point(p, w);
            self.bootstrap_covering();
            return Inserted::New(PointId(0));
        }
        let pi = PointId::new(self.points.len());
        if self.one_sheeted {
            let from = self.insertion_start(key);
            self.push_point(p, w);
            self.vpoint.push(pi);
            self.vcell.push(CellId::NONE);
            // once 1-sheeted, the vertex of a point has its id
            match self.insert_lifted((p, self.space.identity()), VertexId(pi.0), true, from) {
                Ok(()) => {
                    let pi = self.drop_hidden(pi);
                    if !self.guaranteed && self.big_count == 0 {
                        self.set_guaranteed(true);
                    }
                    self.note_vertex(VertexId(pi.0), key);
                    Inserted::New(pi)
                }
                Err(refused) => {
                    self.unpush_point();
                    match refused {
                        Refused::Duplicate(v) => Inserted::Duplicate(self.vpoint[v.index()]),
                        Refused::Hidden => Inserted::Hidden,
                        Refused::NotSimplicial => {
                            // the quotient would stop being a triangulation: continue in
                            // the covering space
                            self.rebuild_in_covering();
                            self.insert_point(p, w, key)
                        }
                    }
                }
            }
        } else {
            self.push_point(p, w);
            for k in 0..self.copies.len() {
                let o = self.copies[k];
                let x = VertexId::new(self.vpoint.len());
                self.vpoint.push(pi);
                self.vcell.push(CellId::NONE);
                if let Some(&(c, v, shift)) = self.copy_hints.get(k) {
                    if self.tds.is_alive(c) && self.tds.cells[c.index()].v == v {
                        (self.hint, self.hint_shift) = (c, shift);
                    }
                }
                let inserted = self.insert_lifted((p, o), x, k == 0, None);
                let here = (
                    self.hint,
                    self.tds.cells[self.hint.index()].v,
                    self.hint_shift,
                );
                match self.copy_hints.get_mut(k) {
                    Some(h) => *h = here,
                    None => self.copy_hints.push(here),
                }
                if let Err(refused) = inserted {
                    // (refused on the first copy: the others are its images)
                    self.unpush_point();
                    return match refused {
                        Refused::Duplicate(v) => Inserted::Duplicate(self.vpoint[v.index()]),
                        Refused::Hidden => Inserted::Hidden,
                        Refused::NotSimplicial => {
                            unreachable!("the covering is always a triangulation")
                        }
                    };
                }
            }
            let pi = self.drop_hidden(pi);
            self.descend();
            Inserted::New(pi)
        }
    }
}
