//! Jump and walk for queries in any order: a coarse grid over the domain, one vertex per
//! grid cell, from which a walk starts when a query is far from the last one. The grid
//! cells are the prefixes of the space's Hilbert keys ([`OrbitSpace::spatial_key`]), so
//! that about two points share one; a walk from a vertex of the query's own grid cell takes
//! a few steps whatever `n`, where a walk from the last insertion crosses `n^(1/D)` cells.
//!
//! The grid is a cache, never trusted: an entry is used only if its vertex still exists. A
//! vertex that has since moved only makes a longer walk (the walk is correct from any
//! cell), and a point that takes a new id names its grid cell again (`relocate`), so
//! removals, renumberings and moves need no other bookkeeping beyond an occasional refill.
//! (Checking that the entry's point still lies in its grid cell cost a cache miss and a
//! key per jump: 8 % of a 10⁶-point build on the sphere.)

use std::sync::atomic::Ordering::Relaxed;

use rayon::prelude::*;

use super::Engine;
use crate::ids::{CellId, PointId, VertexId};
use crate::space::OrbitSpace;

/// Grid cells this close along the curve to the last insertion's are walked to from it
/// (its cells are in cache), not jumped to.
const NEAR: usize = 1;

/// The grid: `slots[key >> shift]` is a vertex whose point had that key prefix.
#[derive(Clone, Debug, Default)]
pub(super) struct Locator {
    shift: u32,
    slots: Vec<VertexId>,
    /// The number of points when the grid was sized: refilled at twice that.
    sized_for: usize,
    /// The number of points a bulk build announced ([`Engine::reserve`]): the grid is
    /// sized for them from the start, rather than refilled as they double (recomputing
    /// every key each time: a tenth of the sphere's keys at 10⁶ points).
    pub(super) planned: usize,
    /// The grid cell of the last insertion: the next one jumps only from another.
    last: usize,
}

impl Locator {
    /// The grid cell of a spatial key.
    #[inline]
    fn slot(&self, key: u64) -> usize {
        (key >> self.shift) as usize
    }
}

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// Sizes the grid for the current points (about two per grid cell, refinement by whole
    /// levels of the Hilbert curve) and fills it; 1-sheeted only.
    pub(super) fn refill_locator(&mut self) {
        let dim = (N - 1) as u32;
        let n = self.points.len().max(self.locator.planned);
        let mut bits = 0;
        while bits < S::KEY_BITS / dim && (1usize << (dim * (bits + 1))) <= n / 2 {
            bits += 1;
        }
        let mut slots = std::mem::take(&mut self.locator.slots);
        slots.clear();
        slots.resize(1 << (dim * bits), VertexId::NONE);
        self.locator = Locator {
            shift: S::KEY_BITS - dim * bits,
            slots,
            sized_for: n.max(1),
            last: usize::MAX,
            planned: self.locator.planned,
        };
        for (i, p) in self.points.iter().enumerate() {
            let k = self.locator.slot(self.space.spatial_key(p));
            self.locator.slots[k] = VertexId::new(i);
        }
    }

    /// After the points were renumbered by `map` (1-sheeted, old point → new, or
    /// [`PointId::NONE`] for a dropped one): each grid cell names its vertex's new id, or
    /// none. (Refilling would compute every key again: 4 % of a 10⁶-point build in a cube,
    /// whose dummy points are dropped at the end.) When most points were dropped, the grid
    /// is refilled instead, rather than left with most of its cells naming none.
    pub(super) fn renumber_locator(&mut self, map: &[PointId]) {
        // (`compact` has dropped the points already)
        let dropped = map.len() - self.points.len();
        if self.locator.slots.is_empty() || 2 * dropped > map.len() {
            return self.refill_locator();
        }
        for v in self
            .locator
            .slots
            .iter_mut()
            .filter(|v| **v != VertexId::NONE)
        {
            *v = match map.get(v.index()) {
                Some(&p) if p != PointId::NONE => VertexId(p.0),
                _ => VertexId::NONE,
            };
        }
        self.locator.last = usize::MAX;
    }

    /// Records vertex `v` (1-sheeted), whose point has spatial key `key`, in the grid,
    /// refilling it when the points have doubled since it was sized.
    pub(super) fn note_vertex(&mut self, v: VertexId, key: u64) {
        if self.points.len() >= 2 * self.locator.sized_for {
            self.refill_locator();
        } else {
            let k = self.locator.slot(key);
            self.locator.slots[k] = v;
        }
    }

    /// [`Self::note_vertex`] of the vertices `first..first + count` in id order, vertex
    /// `first + i` at spatial key `key(i)`, on rayon's pool: each grid cell they fall in
    /// ends naming the largest of them there, as noting them one by one does (its entry
    /// cleared first, then an atomic maximum: the same whatever the threads' order).
    pub(super) fn note_vertices(
        &mut self,
        first: usize,
        count: usize,
        key: impl Fn(usize) -> u64 + Sync,
    ) {
        if count == 0 {
            return;
        }
        if self.points.len() >= 2 * self.locator.sized_for {
            return self.refill_locator();
        }
        let locator = &mut self.locator;
        let shift = locator.shift;
        let slots = crate::ids::atomics(&mut locator.slots);
        let cell = |i: usize| &slots[(key(i) >> shift) as usize];
        let all = || (0..count).into_par_iter().with_min_len(1 << 12);
        all().for_each(|i| cell(i).store(0, Relaxed));
        all().for_each(|i| _ = cell(i).fetch_max((first + i) as u32, Relaxed));
    }

    /// After point `p` took a new id (1-sheeted: its vertex has it), its grid cell names it
    /// again.
    pub(super) fn relocate(&mut self, p: usize) {
        if self.one_sheeted && !self.locator.slots.is_empty() {
            let k = self.locator.slot(self.space.spatial_key(&self.points[p]));
            self.locator.slots[k] = VertexId::new(p);
        }
    }

    /// Where an insertion of a point with spatial key `key` starts walking: from the grid
    /// when the point is in another grid cell than the last insertion's (spatially sorted
    /// insertions keep walking from the last one, whose cells are in cache).
    pub(super) fn insertion_start(&mut self, key: u64) -> Option<(CellId, S::Elem)> {
        let k = self.locator.slot(key);
        if std::mem::replace(&mut self.locator.last, k).abs_diff(k) <= NEAR {
            return None;
        }
        self.jump(key)
    }

    /// A cell near the point with spatial key `key`, and the shift that lifts the point
    /// into its frame: from the grid when its entry is still good, else `None`.
    pub(super) fn jump(&self, key: u64) -> Option<(CellId, S::Elem)> {
        if !self.one_sheeted {
            return None;
        }
        let k = self.locator.slot(key);
        let v = *self.locator.slots.get(k)?;
        let c = *self.vcell.get(v.index())?;
        // (a vertex since moved starts a longer walk, never a wrong one; renumbered points
        // take their slot along, see `relocate`)
        if c == CellId::NONE {
            return None;
        }
        let cell = &self.tds.cells[c.index()];
        let i = cell.index_of(v)?;
        // the query, near the vertex's point, is lifted like the vertex in this cell
        Some((c, self.tds.off_at(c, i)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::delaunay::uniform_cube;

    /// Every grid cell names none or a vertex whose point has that key prefix.
    fn grid_is_true<S: OrbitSpace<N>, const N: usize>(e: &Engine<S, N>) -> usize {
        let named = e.locator.slots.iter().enumerate();
        let named: Vec<_> = named.filter(|(_, v)| **v != VertexId::NONE).collect();
        for &(k, v) in &named {
            let p = &e.points[e.point_of(*v).index()];
            assert_eq!(e.locator.slot(e.space.spatial_key(p)), k, "grid cell {k}");
        }
        named.len()
    }

    #[test]
    fn vertices_noted_at_once_leave_the_grid_as_noted_one_by_one() {
        let mut e = uniform_cube(3000, 5);
        let keys: Vec<u64> = e.points.iter().map(|p| e.space.spatial_key(p)).collect();
        // stale entries too: a vertex named far from its point, and one past the points
        let n = e.locator.slots.len();
        e.locator.slots[n / 2] = VertexId::new(2999);
        e.locator.slots[n / 3] = VertexId::new(5000);
        let mut one_by_one = e.clone();
        // points 1000.. noted again, with keys that fall on grid cells named before
        let key = |i: usize| keys[1000 + (i * 7) % 2000];
        for i in 0..2000 {
            one_by_one.note_vertex(VertexId::new(1000 + i), key(i));
        }
        e.note_vertices(1000, 2000, key);
        assert_eq!(e.locator.slots, one_by_one.locator.slots);
        // nothing noted: nothing changes (no refill either)
        let before = e.locator.slots.clone();
        e.locator.sized_for = 1;
        e.note_vertices(3000, 0, key);
        assert_eq!(e.locator.slots, before);
        // the points doubled since the grid was sized: refilled, as one by one does
        one_by_one.locator.sized_for = 1;
        one_by_one.note_vertex(VertexId::new(1000), key(0));
        e.note_vertices(1000, 1, key);
        assert_eq!(e.locator.slots, one_by_one.locator.slots);
    }

    #[test]
    fn the_grid_follows_the_points_through_renumbering() {
        let mut e = uniform_cube(3000, 7);
        assert!(e.is_one_sheeted());
        let before = e.locator.slots.clone();
        let full = grid_is_true(&e);
        assert!(full > 500, "{full} grid cells named");
        // every third point removed: the others keep their grid cells under new ids
        let gone: Vec<PointId> = (0..3000).step_by(3).map(PointId::new).collect();
        let (map, rebuilt) = e.remove_points(&gone);
        assert!(!rebuilt);
        let kept = grid_is_true(&e);
        for (k, (&was, &now)) in before.iter().zip(&e.locator.slots).enumerate() {
            let want = match was {
                VertexId::NONE => VertexId::NONE,
                v if map[v.index()] == PointId::NONE => VertexId::NONE,
                v => VertexId(map[v.index()].0),
            };
            assert_eq!(now, want, "grid cell {k}");
        }
        assert!(
            kept < full && kept > full / 2,
            "{kept} of {full} grid cells kept"
        );
        // most of the rest removed: the grid is filled again from the points left
        let gone: Vec<PointId> = (0..1200).map(PointId::new).collect();
        assert!(!e.remove_points(&gone).1);
        let refilled = grid_is_true(&e);
        let key = |p| e.locator.slot(e.space.spatial_key(p));
        let mut cells: Vec<usize> = e.points.iter().map(key).collect();
        cells.sort_unstable();
        cells.dedup();
        assert_eq!(
            refilled,
            cells.len(),
            "every grid cell with a point names one"
        );
    }
}
