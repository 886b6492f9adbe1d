//! The combinatorial simplicial complex: cells of `N` vertices with their `N` neighbours
//! (neighbour `i` is opposite vertex `i`) and one group element per vertex, typed ids, a free
//! list, and generation stamps for visits.

use rayon::prelude::*;

pub use crate::ids::{CellId, VertexId};

/// A cell: vertex ids, neighbour ids, the offset of each vertex, and a visit stamp (kept
/// in the cell so that a visit touches one cache line).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cell<O, const N: usize> {
    pub v: [VertexId; N],
    pub n: [CellId; N],
    pub off: [O; N],
    stamp: u32,
}

impl<O: Copy, const N: usize> Cell<O, N> {
    /// A cell with no neighbours yet.
    pub fn new(v: [VertexId; N], off: [O; N]) -> Self {
        Cell {
            v,
            n: [CellId::NONE; N],
            off,
            stamp: 0,
        }
    }

    /// Index of vertex `x` in this cell.
    #[inline]
    pub fn index_of(&self, x: VertexId) -> Option<usize> {
        first_equal(&self.v, x)
    }

    /// Exchanges slots `a` and `b`: vertices, neighbours and elements together (the same
    /// cell, with the opposite orientation of its vertex order).
    #[inline]
    pub fn swap_slots(&mut self, a: usize, b: usize) {
        self.v.swap(a, b);
        self.n.swap(a, b);
        self.off.swap(a, b);
    }

    /// The cell's stamp: the mark of a visit, or during a parallel pass its owner.
    #[inline]
    pub fn stamp(&self) -> u32 {
        self.stamp
    }

    /// Sets the cell's stamp.
    #[inline]
    pub fn set_stamp(&mut self, s: u32) {
        self.stamp = s;
    }

    /// Index of neighbour `c` in this cell.
    #[inline]
    pub fn mirror(&self, c: CellId) -> Option<usize> {
        first_equal(&self.n, c)
    }
}

/// The first slot of `a` holding `x`. All slots are compared at once, into a bit mask: the
/// compiler makes it one vector comparison, where a search stopping at the first match
/// mispredicts a branch about once a call (the slot is as good as random).
#[inline(always)]
fn first_equal<T: PartialEq + Copy, const N: usize>(a: &[T; N], x: T) -> Option<usize> {
    let mut mask = 0u32;
    for (k, &y) in a.iter().enumerate() {
        mask |= u32::from(y == x) << k;
    }
    (mask != 0).then(|| mask.trailing_zeros() as usize)
}

/// `a` with `x` in slot `i`, chosen slot by slot (where a store into a computed slot
/// followed by a copy of the whole cell waits for the store).
#[inline(always)]
pub fn replaced<T: Copy, const N: usize>(a: [T; N], i: usize, x: T) -> [T; N] {
    std::array::from_fn(|k| if k == i { x } else { a[k] })
}

/// Asks the processor to start loading `x` into its caches, every line it spans (a
/// 48-byte cell straddles two lines one time in two): a hint, nothing on other
/// architectures.
#[inline(always)]
pub fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        let start = x as *const T as *const i8;
        let size = std::mem::size_of::<T>();
        let mut at = 0;
        while at < size {
            // SAFETY: prefetching is only a hint; the addresses lie within a live reference.
            unsafe {
                std::arch::x86_64::_mm_prefetch(start.add(at), std::arch::x86_64::_MM_HINT_T0)
            };
            at += 64;
        }
        if size > 1 {
            // SAFETY: as above (the last byte: the line the steps above may have missed)
            unsafe {
                std::arch::x86_64::_mm_prefetch(start.add(size - 1), std::arch::x86_64::_MM_HINT_T0)
            };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

/// Cell storage with a free list and visit stamps.
#[derive(Clone, Debug, Default)]
pub struct Tds<O, const N: usize> {
    pub cells: Vec<Cell<O, N>>,
    free: Vec<CellId>,
    generation: u32,
}

impl<O: Copy, const N: usize> Tds<O, N> {
    /// An empty complex.
    pub fn new() -> Self {
        Tds {
            cells: Vec::new(),
            free: Vec::new(),
            generation: 0,
        }
    }

    /// Adds a cell, reusing a free slot when there is one.
    #[inline]
    pub fn create(&mut self, c: Cell<O, N>) -> CellId {
        if let Some(id) = self.free.pop() {
            // keep the old stamp: it belongs to an earlier visit
            let stamp = self.cells[id.index()].stamp;
            self.cells[id.index()] = Cell { stamp, ..c };
            id
        } else {
            self.cells.push(c);
            CellId::new(self.cells.len() - 1)
        }
    }

    /// Removes a cell (its slot goes to the free list).
    #[inline]
    pub fn delete(&mut self, id: CellId) {
        self.cells[id.index()].v[0] = VertexId::NONE;
        self.free.push(id);
    }

    /// Grows the store to `len` slots, each new one a copy of `dead`, written on rayon's
    /// threads: fresh memory is first touched there (a parallel pass reserves its new
    /// cells' slots at once, 3.4 million of them in the last wave of 10⁶ points in a cube,
    /// 0.1 s on one thread).
    pub fn grow(&mut self, len: usize, dead: Cell<O, N>)
    where
        O: Send + Sync,
    {
        let more = len.saturating_sub(self.cells.len());
        self.cells.reserve(more);
        self.cells.spare_capacity_mut()[..more]
            .par_chunks_mut(1 << 14)
            .for_each(|slots| slots.iter_mut().for_each(|c| _ = c.write(dead)));
        // SAFETY: the capacity holds `more` slots after the length, all written above
        unsafe { self.cells.set_len(self.cells.len() + more) };
    }

    /// Takes every free slot (the caller fills them or [`Self::delete`]s them again).
    pub fn take_free(&mut self) -> Vec<CellId> {
        std::mem::take(&mut self.free)
    }

    /// True if the slot holds a live cell.
    #[inline]
    pub fn is_alive(&self, id: CellId) -> bool {
        self.cells[id.index()].v[0] != VertexId::NONE
    }

    /// Number of live cells.
    pub fn len(&self) -> usize {
        self.cells.len() - self.free.len()
    }

    /// True when there is no live cell.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Ids of the live cells.
    pub fn ids(&self) -> impl Iterator<Item = CellId> + '_ {
        (0..self.cells.len() as u32)
            .map(CellId)
            .filter(|&i| self.is_alive(i))
    }

    /// Starts a new visit and returns two fresh stamp values (for "in" and "out").
    #[inline]
    pub fn new_visit(&mut self) -> (u32, u32) {
        if self.generation >= u32::MAX - 4 {
            self.cells.iter_mut().for_each(|c| c.stamp = 0);
            self.generation = 0;
        }
        self.generation += 2;
        (self.generation - 1, self.generation)
    }

    /// Reserves `k` stamp values that no later visit takes (the owners of a parallel pass)
    /// and returns the first.
    pub fn reserve_stamps(&mut self, k: u32) -> u32 {
        if self.generation >= u32::MAX - 4 - k {
            self.cells.iter_mut().for_each(|c| c.stamp = 0);
            self.generation = 0;
        }
        let first = self.generation + 1;
        self.generation += k;
        first
    }

    /// Asks the processor to start loading the neighbours of `c`: the conflict search and
    /// the walk visit them next, and overlapping their cache misses saves more than it costs.
    #[inline(always)]
    pub fn prefetch_neighbours(&self, c: CellId) {
        for &d in &self.cells[c.index()].n {
            if let Some(cell) = self.cells.get(d.index()) {
                prefetch(cell);
            }
        }
    }

    /// The stamp of a cell.
    #[inline]
    pub fn stamp(&self, id: CellId) -> u32 {
        self.cells[id.index()].stamp
    }

    /// Sets the stamp of a cell.
    #[inline]
    pub fn set_stamp(&mut self, id: CellId, s: u32) {
        self.cells[id.index()].stamp = s;
    }

    /// Drops every cell.
    pub fn clear(&mut self) {
        self.cells.clear();
        self.free.clear();
    }

    /// Reserves room for `n` more cells.
    pub fn reserve(&mut self, n: usize) {
        self.cells.reserve(n);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typed_ids_keep_a_cell_in_48_bytes() {
        assert_eq!(std::mem::size_of::<Cell<[i8; 3], 4>>(), 48);
    }

    #[test]
    fn growing_appends_copies_of_the_dead_cell_and_keeps_the_others() {
        let mut tds: Tds<u8, 3> = Tds::new();
        let live = Cell::new([1, 2, 3].map(VertexId), [0; 3]);
        let a = tds.create(live);
        let dead = Cell::new([VertexId::NONE; 3], [7; 3]);
        // more slots than one of the parallel writers' pieces
        tds.grow(40_000, dead);
        assert_eq!(tds.cells.len(), 40_000);
        assert_eq!(tds.cells[a.index()], live);
        assert!(tds.cells[1..].iter().all(|&c| c == dead));
        tds.grow(10, live);
        assert_eq!(tds.cells.len(), 40_000);
    }

    #[test]
    fn slot_searches_find_the_first_match_or_none() {
        let (a, b) = (CellId::new(7), CellId::new(9));
        let mut cell: Cell<u8, 4> = Cell::new([3, 5, 8, 1].map(VertexId), [0; 4]);
        cell.n = [b, a, b, CellId::NONE];
        // a neighbour across two facets (small coverings) is found at its first slot
        assert_eq!(cell.mirror(b), Some(0));
        assert_eq!(cell.mirror(a), Some(1));
        assert_eq!(cell.mirror(CellId::NONE), Some(3));
        assert_eq!(cell.mirror(CellId::new(8)), None);
        for (k, v) in [3, 5, 8, 1].into_iter().enumerate() {
            assert_eq!(cell.index_of(VertexId(v)), Some(k));
        }
        assert_eq!(cell.index_of(VertexId(4)), None);
    }

    #[test]
    fn replaced_changes_one_slot_only() {
        assert_eq!(replaced([1, 2, 3, 4], 2, 9), [1, 2, 9, 4]);
        assert_eq!(replaced([1, 2, 3], 0, 7), [7, 2, 3]);
        // a slot past the end changes nothing
        assert_eq!(replaced([1, 2, 3], 3, 7), [1, 2, 3]);
    }

    #[test]
    fn create_delete_reuse() {
        let mut t: Tds<u8, 3> = Tds::new();
        let vs = |v: [u32; 3]| v.map(VertexId);
        let a = t.create(Cell::new(vs([0, 1, 2]), [0; 3]));
        let b = t.create(Cell::new(vs([1, 2, 3]), [0; 3]));
        assert_eq!(t.len(), 2);
        t.delete(a);
        assert!(!t.is_alive(a) && t.is_alive(b));
        assert_eq!(t.ids().collect::<Vec<_>>(), vec![b]);
        let c = t.create(Cell::new(vs([4, 5, 6]), [0; 3]));
        assert_eq!(c, a);
        assert_eq!(t.cells[c.index()].index_of(VertexId(5)), Some(1));
        let (i, o) = t.new_visit();
        assert_ne!(i, o);
        let first = t.reserve_stamps(8);
        let (i2, o2) = t.new_visit();
        assert!(first > o && first + 7 < i2.min(o2));
        t.set_stamp(b, i);
        assert_eq!(t.stamp(b), i);
        assert_eq!(t.cells[b.index()].mirror(CellId::NONE), Some(0));
    }
}
