//! The combinatorial simplicial complex: cells of `N` vertices with their `N` neighbours
//! (neighbour `i` is opposite vertex `i`) and one group element per vertex, typed ids, a free
//! list, and generation stamps for visits. The elements are stored packed where they are
//! small ([`Packing`]: a torus's offsets in one byte a vertex), which keeps a cell of the 3D
//! torus in 40 bytes instead of 48.

use std::fmt::Debug;

use rayon::prelude::*;

pub use crate::ids::{CellId, VertexId};

/// How a cell stores the group element of one of its vertices: packed into a smaller slot
/// when the element is small enough (a cell that holds one element that is not is stored
/// with its elements beside the cells, see [`Tds`]).
pub trait Packing: Copy {
    /// What a cell stores for one vertex.
    type Slot: Copy + Debug + Default + Eq + Send + Sync;
    /// The slot of this element, if it fits in one.
    fn pack(self) -> Option<Self::Slot>;
    /// The element a slot holds.
    fn unpack(slot: Self::Slot) -> Self;
    /// The slots of a cell's elements, if each fits in one.
    #[inline(always)]
    fn pack_all<const N: usize>(off: [Self; N]) -> Option<[Self::Slot; N]> {
        let mut slots = [Self::pack(off[0])?; N];
        for k in 1..N {
            slots[k] = Self::pack(off[k])?;
        }
        Some(slots)
    }
}

/// Elements stored as they are.
macro_rules! unpacked {
    (impl [$($g:tt)*] $t:ty) => {
        impl<$($g)*> $crate::tds::Packing for $t {
            type Slot = $t;
            #[inline(always)]
            fn pack(self) -> Option<$t> {
                Some(self)
            }
            #[inline(always)]
            fn unpack(slot: $t) -> $t {
                slot
            }
            #[inline(always)]
            fn pack_all<const N: usize>(off: [$t; N]) -> Option<[$t; N]> {
                Some(off)
            }
        }
    };
    ($($t:ty),*) => {$(
        $crate::tds::unpacked!(impl [] $t);
    )*};
}
pub(crate) use unpacked;
unpacked!((), u8);

/// The offsets of a flat torus (`D` lattice coordinates) in one byte: their coordinates
/// are its digits of `8 / D` bits (0–15 in 2D, 0–3 in 3D). A cell's offsets are translated
/// so that their least coordinate is 0 in the 1-sheeted torus (a cell is then 0 or 1 on
/// each axis) and a small representative in a covering, where a few cells reach farther
/// (see [`Tds`]).
impl<const D: usize> Packing for [i8; D] {
    type Slot = u8;
    #[inline(always)]
    fn pack(self) -> Option<u8> {
        // (a negative coordinate has its top bit set)
        let bits = digit_bits(D);
        let (mut code, mut all) = (0u8, 0u8);
        for c in self {
            all |= c as u8;
            code = (code << bits) | c as u8;
        }
        (all >> bits == 0).then_some(code)
    }
    #[inline(always)]
    fn unpack(slot: u8) -> [i8; D] {
        // (one load from a table, where shifting the digits out and gathering them into
        // an array cost 1 % of a 3D build and more of a 2D one)
        let table: &'static [[i8; D]; 256] = &Digits::<D>::OFFSETS;
        table[usize::from(slot)]
    }
}

/// The digits of every slot of a `D`-dimensional torus offset (see [`Packing`]).
struct Digits<const D: usize>;

impl<const D: usize> Digits<D> {
    const OFFSETS: [[i8; D]; 256] = {
        let bits = digit_bits(D);
        let mask = (1u32 << bits) - 1;
        let mut table = [[0i8; D]; 256];
        let mut code = 0;
        while code < 256 {
            let mut c = 0;
            while c < D {
                table[code][c] = ((code as u32 >> (bits * (D - 1 - c) as u32)) & mask) as i8;
                c += 1;
            }
            code += 1;
        }
        table
    };
}

/// The bits of a torus offset's coordinate in a slot (see [`Packing`] for `[i8; D]`).
const fn digit_bits(d: usize) -> u32 {
    (8 / d) as u32
}

/// A cell as the code works with it: vertex ids, neighbour ids and the element of each
/// vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cell<O, const N: usize> {
    pub v: [VertexId; N],
    pub n: [CellId; N],
    pub off: [O; N],
}

impl<O: Copy, const N: usize> Cell<O, N> {
    /// A cell with no neighbours yet.
    pub fn new(v: [VertexId; N], off: [O; N]) -> Self {
        Cell {
            v,
            n: [CellId::NONE; N],
            off,
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

    /// Index of neighbour `c` in this cell.
    #[inline]
    pub fn mirror(&self, c: CellId) -> Option<usize> {
        first_equal(&self.n, c)
    }
}

/// A cell as the store keeps it: vertex ids, neighbour ids, the packed elements (valid
/// while the store is packed, see [`Tds`]) and a visit stamp (kept in the cell so that a
/// visit touches one cache line).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stored<O: Packing, const N: usize> {
    pub v: [VertexId; N],
    pub n: [CellId; N],
    slots: [O::Slot; N],
    stamp: u32,
}

impl<O: Packing, const N: usize> Stored<O, N> {
    /// `cell` packed with stamp 0, if each of its elements fits in a slot.
    #[inline(always)]
    pub fn pack(cell: &Cell<O, N>) -> Option<Self> {
        Some(Stored {
            v: cell.v,
            n: cell.n,
            slots: O::pack_all(cell.off)?,
            stamp: 0,
        })
    }

    /// Overwrites the cell with `cell`, its stamp kept; false, with nothing written, when
    /// an element does not fit in a slot.
    #[inline(always)]
    pub fn set(&mut self, cell: &Cell<O, N>) -> bool {
        let Some(slots) = O::pack_all(cell.off) else {
            return false;
        };
        (self.v, self.n, self.slots) = (cell.v, cell.n, slots);
        true
    }

    /// The elements of the slots (those of the cell while the store is packed).
    #[inline(always)]
    pub fn packed_offsets(&self) -> [O; N] {
        self.slots.map(O::unpack)
    }

    /// This cell with vertex `x` in slot `i`, no neighbours and stamp 0, when `x`'s element
    /// `o` is the one there: the same elements, kept as they are packed (canonical already).
    #[inline(always)]
    pub fn with_same_elements(&self, i: usize, x: VertexId, o: O) -> Option<Self>
    where
        O: PartialEq,
    {
        (O::unpack(self.slots[i]) == o).then(|| Stored {
            v: replaced(self.v, i, x),
            n: [CellId::NONE; N],
            slots: self.slots,
            stamp: 0,
        })
    }

    /// Index of vertex `x` in this cell.
    #[inline]
    pub fn index_of(&self, x: VertexId) -> Option<usize> {
        first_equal(&self.v, x)
    }

    /// Index of neighbour `c` in this cell.
    #[inline]
    pub fn mirror(&self, c: CellId) -> Option<usize> {
        first_equal(&self.n, c)
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
}

/// The first slot of `a` holding `x`. All slots are compared at once, into a bit mask: the
/// compiler makes it one vector comparison, where a search stopping at the first match
/// mispredicts a branch about once a call (the slot is as good as random).
#[inline(always)]
pub(crate) fn first_equal<T: PartialEq + Copy, const N: usize>(a: &[T; N], x: T) -> Option<usize> {
    let mut mask = 0u32;
    for (k, &y) in a.iter().enumerate() {
        mask |= u32::from(y == x) << k;
    }
    (mask != 0).then(|| mask.trailing_zeros() as usize)
}

/// `a` with `x` in slot `i`, chosen slot by slot (where a store into a computed slot
/// followed by a copy of the whole cell waits for the store), without a branch: the slot
/// is as good as random.
#[inline(always)]
pub fn replaced<T: Copy, const N: usize>(a: [T; N], i: usize, x: T) -> [T; N] {
    std::array::from_fn(|k| std::hint::select_unpredictable(k == i, x, a[k]))
}

/// Asks the processor to start loading `x` into its caches, every line it spans (a
/// 40-byte cell straddles two lines one time in two): a hint, nothing on other
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

/// Cell storage with a free list and visit stamps. The store is **packed** while every
/// cell's elements fit in their slots ([`Packing`]); the first cell whose do not turns it
/// **wide**: from then on every cell's elements are kept beside the cells, by cell id,
/// until the store is emptied. (The 1-sheeted tori stay packed; a covering's larger
/// offsets can make it wide, 12 bytes a cell more.)
#[derive(Clone, Debug)]
pub struct Tds<O: Packing, const N: usize> {
    pub cells: Vec<Stored<O, N>>,
    /// Wide: the elements of each cell slot (`None` while packed).
    wide: Option<Vec<[O; N]>>,
    free: Vec<CellId>,
    generation: u32,
}

impl<O: Packing, const N: usize> Default for Tds<O, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<O: Packing, const N: usize> Tds<O, N> {
    /// An empty complex.
    pub fn new() -> Self {
        Tds {
            cells: Vec::new(),
            wide: None,
            free: Vec::new(),
            generation: 0,
        }
    }

    /// True while every cell's elements are in its slots.
    #[inline(always)]
    pub fn is_packed(&self) -> bool {
        self.wide.is_none()
    }

    /// The elements of cell `c`.
    #[inline(always)]
    pub fn off(&self, c: CellId) -> [O; N] {
        match &self.wide {
            None => self.cells[c.index()].packed_offsets(),
            Some(wide) => wide[c.index()],
        }
    }

    /// True when every element of cell `c` is `o` (compared packed, where they are).
    #[inline(always)]
    pub fn all_are(&self, c: CellId, o: O) -> bool
    where
        O: PartialEq,
    {
        match (&self.wide, o.pack()) {
            (None, Some(s)) => self.cells[c.index()].slots == [s; N],
            (None, None) => false,
            (Some(wide), _) => wide[c.index()] == [o; N],
        }
    }

    /// The element of vertex `i` of cell `c`.
    #[inline(always)]
    pub fn off_at(&self, c: CellId, i: usize) -> O {
        match &self.wide {
            None => O::unpack(self.cells[c.index()].slots[i]),
            Some(wide) => wide[c.index()][i],
        }
    }

    /// Cell `c` (a copy).
    #[inline(always)]
    pub fn cell(&self, c: CellId) -> Cell<O, N> {
        let s = &self.cells[c.index()];
        Cell {
            v: s.v,
            n: s.n,
            off: self.off(c),
        }
    }

    /// Overwrites slot `c` with `cell`, its stamp kept.
    #[inline(always)]
    pub fn put(&mut self, c: CellId, cell: Cell<O, N>) {
        let packed = O::pack_all(cell.off).filter(|_| self.is_packed());
        // (the fields only: the stamp is not read)
        let slot = &mut self.cells[c.index()];
        (slot.v, slot.n) = (cell.v, cell.n);
        match packed {
            Some(slots) => slot.slots = slots,
            // (the elements alone go out of line, so that the cell need not be built in
            // memory for the call: reading it back whole stalls on its narrower writes)
            None => self.put_wide(c, cell.off),
        }
    }

    /// Sets the elements of cell `c` in a wide store, or one that they turn wide.
    #[cold]
    fn put_wide(&mut self, c: CellId, off: [O; N]) {
        self.widen()[c.index()] = off;
    }

    /// Sets the elements of cell `c`.
    pub fn set_off(&mut self, c: CellId, off: [O; N]) {
        let cell = Cell {
            off,
            ..self.cell(c)
        };
        self.put(c, cell);
    }

    /// Turns the store wide (see [`Tds`]) if it is not, and returns the elements beside.
    #[cold]
    fn widen(&mut self) -> &mut Vec<[O; N]> {
        self.wide
            .get_or_insert_with(|| self.cells.iter().map(Stored::packed_offsets).collect())
    }

    /// Adds a cell, reusing a free slot when there is one.
    #[inline(always)]
    pub fn create(&mut self, c: Cell<O, N>) -> CellId {
        if let Some(packed) = Stored::pack(&c).filter(|_| self.is_packed()) {
            return self.add_packed(packed);
        }
        if let Some(id) = self.free.pop() {
            // keep the old stamp: it belongs to an earlier visit
            self.put(id, c);
            return id;
        }
        let id = CellId::new(self.cells.len());
        self.cells.push(Stored {
            v: c.v,
            n: c.n,
            slots: [O::Slot::default(); N],
            stamp: 0,
        });
        // (widened now: the new slot is among those read; wide already: one more)
        let wide = self.widen();
        wide.resize(id.index() + 1, c.off);
        wide[id.index()] = c.off;
        id
    }

    /// Adds a packed cell to a packed store, in a free slot (its old stamp kept: it belongs
    /// to an earlier visit) when there is one.
    #[inline(always)]
    fn add_packed(&mut self, cell: Stored<O, N>) -> CellId {
        match self.free.pop() {
            Some(id) => {
                let slot = &mut self.cells[id.index()];
                (slot.v, slot.n, slot.slots) = (cell.v, cell.n, cell.slots);
                id
            }
            None => {
                self.cells.push(cell);
                CellId::new(self.cells.len() - 1)
            }
        }
    }

    /// Adds a cell of vertices `v`, no neighbours yet, and the elements of the live cell
    /// `like` copied as they are stored (no unpacking, no packing: most new cells of a star
    /// have the elements of the conflict cell they replace), reusing a free slot when there
    /// is one.
    #[inline(always)]
    pub fn create_like(&mut self, v: [VertexId; N], like: CellId) -> CellId {
        if !self.is_packed() {
            return self.create(Cell::new(v, self.off(like)));
        }
        self.add_packed(Stored {
            v,
            n: [CellId::NONE; N],
            slots: self.cells[like.index()].slots,
            stamp: 0,
        })
    }

    /// Removes a cell (its slot goes to the free list).
    #[inline]
    pub fn delete(&mut self, id: CellId) {
        self.cells[id.index()].v[0] = VertexId::NONE;
        self.free.push(id);
    }

    /// Grows the store to `len` slots, each new one a copy of `dead` (its elements those
    /// of its slots), written on rayon's threads: fresh memory is first touched there (a
    /// parallel pass, on a packed store, reserves its new cells' slots at once, 3.4 million
    /// of them in the last wave of 10⁶ points in a cube, 0.1 s on one thread).
    pub fn grow(&mut self, len: usize, dead: Stored<O, N>)
    where
        O: Send + Sync,
    {
        if let Some(wide) = &mut self.wide {
            wide.resize(len.max(wide.len()), dead.packed_offsets());
        }
        let more = len.saturating_sub(self.cells.len());
        self.cells.reserve(more);
        self.cells.spare_capacity_mut()[..more]
            .par_chunks_mut(1 << 14)
            .for_each(|slots| slots.iter_mut().for_each(|c| _ = c.write(dead)));
        // SAFETY: the capacity holds `more` slots after the length, all written above
        unsafe { self.cells.set_len(self.cells.len() + more) };
    }

    /// Appends `len` cells, the one of id `k` made by `make(k)` on rayon's threads (a
    /// covering's lift writes tens of millions at once). `make` is called again for every
    /// new cell if one of them turns the store wide.
    pub fn extend_with<F>(&mut self, len: usize, make: F)
    where
        O: Send + Sync,
        F: Fn(usize) -> Cell<O, N> + Sync,
    {
        const BLOCK: usize = 1 << 14;
        let start = self.cells.len();
        let fits = std::sync::atomic::AtomicBool::new(true);
        self.cells.reserve(len);
        self.cells.spare_capacity_mut()[..len]
            .par_chunks_mut(BLOCK)
            .enumerate()
            .for_each(|(b, slots)| {
                for (k, slot) in slots.iter_mut().enumerate() {
                    let c = make(start + b * BLOCK + k);
                    let stored = Stored::pack(&c).unwrap_or_else(|| {
                        fits.store(false, std::sync::atomic::Ordering::Relaxed);
                        Stored {
                            v: c.v,
                            n: c.n,
                            slots: [O::Slot::default(); N],
                            stamp: 0,
                        }
                    });
                    slot.write(stored);
                }
            });
        // SAFETY: the capacity holds `len` slots after the length, all written above
        unsafe { self.cells.set_len(start + len) };
        if !fits.into_inner() || !self.is_packed() {
            let wide = self.widen();
            wide.truncate(start);
            wide.par_extend((start..start + len).into_par_iter().map(|k| make(k).off));
        }
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

    /// Drops every cell (the store is packed again).
    pub fn clear(&mut self) {
        self.cells.clear();
        self.wide = None;
        self.free.clear();
    }

    /// Reserves room for `n` more cells.
    pub fn reserve(&mut self, n: usize) {
        self.cells.reserve(n);
        if let Some(wide) = &mut self.wide {
            wide.reserve(n);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_offsets_keep_a_torus_cell_in_40_bytes_and_a_triangle_in_32() {
        assert_eq!(std::mem::size_of::<Stored<[i8; 3], 4>>(), 40);
        assert_eq!(std::mem::size_of::<Stored<[i8; 2], 3>>(), 32);
        assert_eq!(std::mem::size_of::<Stored<(), 3>>(), 28);
    }

    #[test]
    fn offsets_pack_exactly_within_their_digits() {
        assert_eq!((digit_bits(2), digit_bits(3)), (4, 2));
        for x in -2..20i8 {
            for y in -2..20i8 {
                let fits = (0..16).contains(&x) && (0..16).contains(&y);
                let slot = [x, y].pack();
                assert_eq!(slot.is_some(), fits, "{x} {y}");
                if let Some(s) = slot {
                    assert_eq!(<[i8; 2]>::unpack(s), [x, y]);
                }
                for z in -1..8i8 {
                    let fits = [x, y, z].iter().all(|c| (0..4).contains(c));
                    let slot = [x, y, z].pack();
                    assert_eq!(slot.is_some(), fits, "{x} {y} {z}");
                    if let Some(s) = slot {
                        assert_eq!(<[i8; 3]>::unpack(s), [x, y, z]);
                    }
                }
            }
        }
        // every slot value is one offset
        let all: std::collections::BTreeSet<_> = (0..64u8).map(<[i8; 3]>::unpack).collect();
        assert_eq!(all.len(), 64);
        let all: std::collections::BTreeSet<_> = (0..=255u8).map(<[i8; 2]>::unpack).collect();
        assert_eq!(all.len(), 256);
    }

    #[test]
    fn a_cell_that_does_not_pack_turns_the_store_wide_and_keeps_every_offset() {
        let mut tds: Tds<[i8; 3], 4> = Tds::new();
        let vs = |v: [u32; 4]| v.map(VertexId);
        let small = [[0, 0, 0], [1, 0, 0], [0, 1, 1], [3, 3, 3]];
        let a = tds.create(Cell::new(vs([0, 1, 2, 3]), small));
        let b = tds.create(Cell::new(vs([1, 2, 3, 4]), [[0, 0, 0]; 4]));
        assert!(tds.is_packed());
        assert_eq!(tds.off(a), small);
        tds.set_stamp(a, 9);
        // a covering's offset beyond the digits, and a negative one
        let large = [[0, 0, 0], [4, 0, 0], [0, 1, 7], [2, 0, 1]];
        let c = tds.create(Cell::new(vs([2, 3, 4, 5]), large));
        assert!(!tds.is_packed());
        assert_eq!(
            (tds.off(a), tds.off(b), tds.off(c)),
            (small, [[0, 0, 0]; 4], large)
        );
        assert_eq!(tds.off_at(c, 2), [0, 1, 7]);
        let negative = [[-1, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]];
        tds.set_off(b, negative);
        assert_eq!(tds.off(b), negative);
        // rewriting keeps the stamp; a freed slot reused keeps its own elements
        tds.put(a, Cell::new(vs([7, 8, 9, 10]), large));
        assert_eq!(
            (tds.cell(a).v, tds.off(a), tds.stamp(a)),
            (vs([7, 8, 9, 10]), large, 9)
        );
        tds.delete(c);
        let d = tds.create(Cell::new(vs([3, 4, 5, 6]), small));
        assert_eq!((d, tds.off(d)), (c, small));
        // grown while wide, the new slots' elements are the dead cell's
        let dead = Stored::pack(&Cell::new([VertexId::NONE; 4], [[1, 0, 0]; 4])).unwrap();
        tds.grow(10, dead);
        assert_eq!(tds.cells.len(), 10);
        assert_eq!(tds.off(CellId::new(9)), [[1, 0, 0]; 4]);
        assert_eq!(tds.off(c), small);
        // emptied, the store packs again
        tds.clear();
        tds.create(Cell::new(vs([0, 1, 2, 3]), small));
        assert!(tds.is_packed());
    }

    /// A cell made like another takes that one's elements, packed or wide, with no
    /// neighbours, in a free slot when there is one.
    #[test]
    fn a_cell_made_like_another_takes_its_elements() {
        let mut tds: Tds<[i8; 3], 4> = Tds::new();
        let vs = |v: [u32; 4]| v.map(VertexId);
        let small = [[0, 0, 0], [1, 0, 0], [0, 1, 1], [3, 3, 3]];
        let mut linked = Cell::new(vs([0, 1, 2, 3]), small);
        linked.n = [CellId::new(5); 4];
        let a = tds.create(linked);
        let b = tds.create_like(vs([4, 1, 2, 3]), a);
        assert!(tds.is_packed());
        assert_eq!(tds.cell(b), Cell::new(vs([4, 1, 2, 3]), small));
        // a freed slot is reused, its stamp kept
        tds.set_stamp(b, 7);
        tds.delete(b);
        assert_eq!(tds.create_like(vs([5, 1, 2, 3]), a), b);
        assert_eq!((tds.off(b), tds.stamp(b)), (small, 7));
        // wide: the elements beside the cells, for a new slot and a reused one
        let large = [[0, 0, 0], [4, 0, 0], [0, 1, 7], [2, 0, 1]];
        let c = tds.create(Cell::new(vs([2, 3, 4, 5]), large));
        assert!(!tds.is_packed());
        let d = tds.create_like(vs([9, 3, 4, 5]), c);
        assert_eq!(tds.cell(d), Cell::new(vs([9, 3, 4, 5]), large));
        tds.delete(b);
        assert_eq!(tds.create_like(vs([6, 3, 4, 5]), c), b);
        assert_eq!((tds.off(b), tds.off(a)), (large, small));
        assert_eq!(tds.create_like(vs([6, 1, 2, 3]), a), CellId::new(4));
        assert_eq!(tds.off(CellId::new(4)), small);
    }

    #[test]
    fn a_stored_cell_with_a_vertex_replaced_keeps_its_elements_only_when_they_are_the_same() {
        let small = [[0, 0, 0], [1, 0, 0], [0, 1, 1], [3, 3, 3]];
        let mut cell = Cell::new([0, 1, 2, 3].map(VertexId), small);
        cell.n = [CellId::new(5); 4];
        let mut stored = Stored::pack(&cell).unwrap();
        stored.set_stamp(9);
        let made = stored
            .with_same_elements(2, VertexId(7), [0, 1, 1])
            .unwrap();
        let want = Cell::new([0, 1, 7, 3].map(VertexId), small);
        assert_eq!(made, Stored::pack(&want).unwrap());
        assert_eq!(made.stamp(), 0);
        assert_eq!(stored.with_same_elements(2, VertexId(7), [0, 0, 0]), None);
        assert_eq!(stored.with_same_elements(1, VertexId(7), [0, 0, 0]), None);
    }

    #[test]
    fn growing_appends_copies_of_the_dead_cell_and_keeps_the_others() {
        let mut tds: Tds<u8, 3> = Tds::new();
        let live = Cell::new([1, 2, 3].map(VertexId), [0; 3]);
        let a = tds.create(live);
        let dead = Stored::pack(&Cell::new([VertexId::NONE; 3], [7; 3])).unwrap();
        // more slots than one of the parallel writers' pieces
        tds.grow(40_000, dead);
        assert_eq!(tds.cells.len(), 40_000);
        assert_eq!(tds.cell(a), live);
        assert!(tds.cells[1..].iter().all(|&c| c == dead));
        tds.grow(10, Stored::pack(&live).unwrap());
        assert_eq!(tds.cells.len(), 40_000);
    }

    /// Cells made on the threads land in order after the others, packed while they fit;
    /// one that does not turns the store wide with every element kept, the old ones too.
    #[test]
    fn extending_on_the_threads_appends_the_cells_in_order() {
        let cell = |k: usize| {
            let v = [0, 1, 2, 3].map(|i| VertexId::new(4 * k + i));
            let mut c = Cell::new(v, [[(k % 4) as i8, 0, 1], [0; 3], [1, 1, 1], [0; 3]]);
            c.n = [
                CellId::new(k + 1),
                CellId::NONE,
                CellId::new(k),
                CellId::new(2),
            ];
            c
        };
        let mut tds: Tds<[i8; 3], 4> = Tds::new();
        let first = tds.create(cell(0));
        // more cells than one of the threads' pieces
        tds.extend_with(40_000, cell);
        assert!(tds.is_packed());
        assert_eq!(tds.cells.len(), 40_001);
        assert_eq!(tds.cell(first), cell(0));
        assert!((0..40_001).all(|k| tds.cell(CellId::new(k)) == cell(k)));
        // a far offset among them: wide, each cell as made
        let far = |k: usize| {
            let mut c = cell(k);
            c.off[1] = [(k % 9) as i8, 0, 5];
            c
        };
        tds.extend_with(20_000, far);
        assert!(!tds.is_packed());
        assert!((0..40_001).all(|k| tds.cell(CellId::new(k)) == cell(k)));
        assert!((40_001..60_001).all(|k| tds.cell(CellId::new(k)) == far(k)));
        tds.extend_with(3, cell);
        assert_eq!(tds.cell(CellId::new(60_003)), cell(60_003));
        assert_eq!(tds.cell(CellId::new(60_000)), far(60_000));
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
