//! The parallel bulk insertion, by spatial ownership.
//!
//! The points arrive in BRIO + Hilbert order. After a short sequential start they go in
//! waves, each of the next up to eight times as many points as there are: a whole BRIO
//! round, eightfold in a space without reflections (consecutive points then land in the
//! cells just made, which halved the chunks' cost a point where they flip, and took a
//! tenth off two threads on the sphere), doubling elsewhere (a wave of the next as many
//! points as there are); when fewer than a 32nd of the points are left in the call, they
//! go one at a time. A wave is in order along the Hilbert curve (a round is: it is read in
//! place; other items are copied and sorted) and cut into
//! [`CHUNKS`] chunks of consecutive points, and each chunk **owns** the cells of its stretch
//! of the curve: a cell belongs to the chunk whose range holds the spatial key of its
//! vertex 0, and a new cell to the chunk that made it. A chunk inserts its points one after
//! another, as a sequential insertion would (each walk starts from its last insertion, or
//! every 64th, and in the group passes below every one, from a cell located before the
//! pass), but only where it owns everything it reads or writes: the walk, the conflict
//! region and the cells across its boundary. Where the sequential code splits and flips
//! ([`Engine::flips`]: the flat 2D tori), a chunk does too, for a point strictly inside a
//! triangle: every cell it flips, and every cell next to one it changes, must be its own,
//! and its writes are journaled and undone when a flip meets another chunk's cell. A point
//! that needs another chunk's cell, or whose 3D star the ridge table refuses, is deferred.
//! The chunks run on the threads in any order and at once, with no lock: a cell next to a
//! chunk's own cell cannot change while it is, since a chunk changes only cells whose
//! neighbours are all its own.
//!
//! The deferred points lie on the chunks' borders (a fifth of the last wave of 10⁶ uniform
//! points in a cube). Each remembers the chunk whose cell stopped it; those stopped on the
//! border between chunks `2j` and `2j + 1` then go in by groups of two chunks, which own
//! their chunks' cells (the border now inside one of them), those between chunks of one
//! aligned group of four by groups of four, and so on while there are two groups (in that
//! cube, a third of the deferred points at each level). Those left between the two halves
//! go in by two groups of half the chunks turned by a quarter along the curve, which hold
//! the chunks that face each other across that border. The rest, and every level with
//! fewer than [`GROUPED_FEWEST`] points, go in one after another by the sequential code
//! (that cube's last wave: 100 000 → 36 000 → 4 000 points). Each point of
//! the wave had its id reserved at the start, in curve order; the ids of points that did
//! not become vertices (duplicates, and the sphere's points that would hide others,
//! inserted last by the sequential code) are filled by the last points.
//!
//! Nothing depends on the number of threads or on timing: a chunk's work depends only on
//! its own cells, its points and its reserved cell slots, so every thread count stores the
//! same triangulation, slot for slot, and writes the same files. (Since the perturbed
//! Delaunay triangulation is unique, its cells are those of a sequential build.) Weighted
//! triangulations, and triangulations still in a covering or without the switch criterion,
//! insert sequentially.

use std::borrow::Cow;
use std::ops::{ControlFlow, Range};
use std::sync::atomic::Ordering::Relaxed;
use std::sync::atomic::{AtomicU32, AtomicUsize};

use rayon::prelude::*;

use super::flip::{split_and_flip, Flipper, Triangle};
use super::insert::{closes, edge_ends, enter, next_edge, slot_in, Frame, Refused};
use super::ridges::Ridges;
use super::{Engine, HiddenPoint, Inserted};
use crate::ids::{CellId, InputId, PointId, VertexId};
use crate::sort::SplitMix;
use crate::space::OrbitSpace;
use crate::tds::{replaced, Cell, Packing, Stored};

/// Points inserted one by one before the waves.
const SEQUENTIAL_START: usize = 2048;
/// Chunks of a wave, whatever the number of threads (the schedule, and so the stored
/// triangulation, must not depend on it): as many threads can be busy, and their borders
/// defer a quarter of a wave (44 % with 16 chunks, 16 % with 4; 10⁶ points in a cube).
const CHUNKS: usize = 8;
/// The fewest points a wave holds, as a fraction of the triangulation's (`1/FEWEST`): a pass
/// stamps every cell first (20 ms at 10⁶ points in a square, 30 ms in a cube), which a
/// smaller wave (the tail of a BRIO round, a small batch) saves by going one at a time.
const FEWEST: usize = 32;
/// Visit marks a chunk has room for, per point of its share: two (an inside and an outside
/// one) each time a point is tried, in its chunk and in the groups of 2, 4, … chunks that
/// take the points left on their inner borders (at most `2·(1 + 2 + 4)` for 8 chunks).
const MARKS: usize = 16;
/// The fewest points left on the chunks' borders that go in by groups of chunks: fewer go
/// in one at a time, which costs less than setting up the groups (on a surface, where
/// the borders are curves, they are 3 % of a wave of 10⁶ points, and grouping them made
/// the sphere 5 % slower). (The unit tests group every level of 64 or more, so that their
/// builds of thousands of points take the group passes.)
#[cfg(not(test))]
const GROUPED_FEWEST: usize = 8192;
#[cfg(test)]
const GROUPED_FEWEST: usize = 64;
// the groups halve the chunks down to two, and a chunk's marks hold two a point at each
// level: `2·(1 + 2 + … + CHUNKS/2)`
const _: () = assert!(CHUNKS.is_power_of_two() && MARKS >= 2 * (CHUNKS - 1));
/// Cell slots reserved for a chunk beyond its points' share.
const MARGIN: usize = 64;

/// Every this many points of a chunk, one is located before the pass, to walk from (the
/// others walk from the chunk's last insertion): walks that keep failing, from cells of the
/// chunk cut off by others', start afresh there.
const STRIDE: usize = 64;

/// One point to insert: a tag for the caller, the point, its weight (ignored unless the
/// triangulation is weighted) and its spatial key.
pub type Item<P> = (u32, P, f64, u64);

/// What became of the items: `(index of the item, result, end of its hidden points in
/// `hidden`)`. New points appear in the order of their ids, a duplicate after the point it
/// coincides with, and each point's hidden points (those its insertion hid, as in
/// [`Engine::insert_weighted`]) follow the previous event's.
#[derive(Debug)]
pub struct Log<P> {
    pub events: Vec<(u32, Inserted, u32)>,
    pub hidden: Vec<HiddenPoint<P>>,
}

impl<P> Log<P> {
    /// The events with their hidden points: `(index of the item, result, the points it hid)`.
    pub fn iter(&self) -> impl Iterator<Item = (u32, Inserted, &[HiddenPoint<P>])> + '_ {
        let mut from = 0;
        self.events.iter().map(move |&(tag, r, end)| {
            let hid = &self.hidden[from..end as usize];
            from = end as usize;
            (tag, r, hid)
        })
    }

    /// When every event is a new point, nothing hidden, and `keep` accepts each (most
    /// rounds): records them in a facade's tables, `point_input` and `input_point`, each
    /// item tagged with its input id, and returns true; else records nothing, false.
    pub(crate) fn record_if_all_new(
        &self,
        items: &[Item<P>],
        tables: (&mut Vec<InputId>, &mut [PointId]),
        keep: impl Fn(Inserted) -> bool + Sync,
    ) -> bool
    where
        P: Sync,
    {
        let all_new = self.hidden.is_empty()
            && (self.events.par_iter()).all(|&(_, r, _)| matches!(r, Inserted::New(_)) && keep(r));
        if !all_new {
            return false;
        }
        let first = tables.0.len();
        debug_assert!((self.events.iter().enumerate())
            .all(|(n, e)| e.1 == Inserted::New(PointId::new(first + n))));
        let input = |n: usize| InputId(items[self.events[n].0 as usize].0);
        crate::ids::record_new_inputs(tables, self.events.len(), input);
        true
    }
}

/// What a chunk's probe found for its next point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Found {
    /// The point coincides with this one.
    Duplicate(PointId),
    /// Its power cell is empty.
    Hidden,
    /// Its insertion would hide vertices: the sequential code inserts it after the wave.
    Alone,
    /// It needs a cell the chunk does not own, or the chunk's slots or marks ran out, or
    /// a new cell's elements do not pack (2D flips).
    Foreign,
    /// Its conflict region is collected, and the chunk owns it.
    Region,
    /// 2D: inserted already, by splitting its triangle and flipping.
    Flipped,
}

/// What became of a point of the wave.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Outcome {
    /// Not yet inserted.
    Deferred,
    /// A vertex, with the id reserved for it.
    New,
    Duplicate(PointId),
    Hidden,
    /// Left for the sequential code, after the wave.
    Alone,
}

/// A chunk of a pass: its points (`range`, indices into the pass's `active` positions),
/// the cell slots it may fill, its last insertion, and what the probe found for its
/// current point.
#[derive(Debug)]
#[repr(align(128))]
struct Chunk<O: Packing, const N: usize> {
    id: u32,
    range: Range<usize>,
    /// The cell of the chunk's last insertion, its vertices (a reused slot fails the check)
    /// and the shift that lifts a point near it into its frame.
    hint: Option<(CellId, [VertexId; N], O)>,
    /// For every `stride`-th point: the cell that held it before the pass, as `hint`,
    /// when the chunk owned it.
    starts: Vec<Option<(CellId, [VertexId; N], O)>>,
    found: Found,
    /// Its cell slots or visit marks ran out: its other points are deferred.
    full: bool,
    /// The region: cells with the point's offset in each one's frame, in search order.
    conflict: Vec<(CellId, O)>,
    /// Its boundary facets: (index into `conflict`, facet).
    boundary: Vec<(u32, u8)>,
    /// Per boundary facet: the cell across and the facet's index there.
    across: Vec<(CellId, u8)>,
    /// The visit marks taken so far from the chunk's stamps ([`Ownership::mark`]).
    marks: u32,
    /// The chunk of the pass whose stamps hold the stamp of the cell that stopped the
    /// current probe, if known (its owner, or in a group pass possibly the first chunk of
    /// the group that owns it and marked it meanwhile: the same group, see `need`).
    foreign: Option<u32>,
    /// The points it left: (position in the wave, `foreign` then).
    left: Vec<(u32, Option<u32>)>,
    /// 2D: the boundary edges' ends in the order of a walk around the region with the
    /// facet across, and the search's stack (see [`Engine::probe_around`]).
    rim: Vec<(VertexId, VertexId, u8)>,
    stack: Vec<Frame>,
    /// Free slots for the chunk's new cells: freed ones first (its regions' leftovers),
    /// then `fresh`.
    spare: Vec<CellId>,
    fresh: Range<usize>,
    /// What became of its points: (position in the wave, outcome), deferred ones omitted.
    outcomes: Vec<(u32, Outcome)>,
    /// Buffers of `commit`: the region's cells as they were, the new cells, their slots,
    /// and the vertices whose cell dies.
    old: Vec<Stored<O, N>>,
    new: Vec<Stored<O, N>>,
    ids: Vec<CellId>,
    orphans: Vec<VertexId>,
    /// 3D: the boundary edges of its region, to pair the new cells.
    ridges: Ridges,
    /// 2D flips: the cells whose edge opposite the new vertex is still to test, and what
    /// was overwritten (cells, then vertices' cells), to undo a point stopped halfway.
    edges: Vec<CellId>,
    journal: Vec<(CellId, Stored<O, N>)>,
    moved: Vec<(VertexId, u32)>,
}

impl<O: Packing, const N: usize> Chunk<O, N> {
    fn new(id: u32, range: Range<usize>, spare: Vec<CellId>, fresh: Range<usize>) -> Self {
        Chunk {
            id,
            range,
            hint: None,
            starts: Vec::new(),
            found: Found::Foreign,
            full: false,
            conflict: Vec::new(),
            boundary: Vec::new(),
            across: Vec::new(),
            marks: 0,
            foreign: None,
            left: Vec::new(),
            rim: Vec::new(),
            stack: Vec::new(),
            spare,
            fresh,
            outcomes: Vec::new(),
            old: Vec::new(),
            new: Vec::new(),
            ids: Vec::new(),
            orphans: Vec::new(),
            ridges: Ridges::default(),
            edges: Vec::new(),
            journal: Vec::new(),
            moved: Vec::new(),
        }
    }

    /// Undoes the journaled writes, last first, and gives back the slots `new`.
    ///
    /// # Safety
    /// The journal's cells are still the chunk's.
    unsafe fn undo(&mut self, cells: &SharedCells<O, N>, vcell: &[AtomicU32], new: [CellId; 2]) {
        for &(c, cell) in self.journal.iter().rev() {
            *cells.get(c) = cell;
        }
        for &(v, was) in self.moved.iter().rev() {
            vcell[v.index()].store(was, Relaxed);
        }
        self.spare.extend(new.into_iter().rev());
    }

    /// The chunk's next visit mark, taken; `None` when it has none left.
    #[inline(always)]
    fn take_mark(&mut self, own: &Ownership) -> Option<u32> {
        let mark = own.mark(self.id, self.marks + 1)?;
        self.marks += 1;
        Some(mark)
    }

    /// The chunk's cell slots that no cell took.
    fn leftover(&mut self) -> impl Iterator<Item = CellId> {
        let fresh = std::mem::replace(&mut self.fresh, 0..0);
        std::mem::take(&mut self.spare)
            .into_iter()
            .chain(fresh.map(CellId::new))
    }
}

/// The state kept across the waves of parallel insertions (in [`Engine`] between the calls
/// of one batch, until [`Engine::end_batch`]).
#[derive(Debug, Default)]
struct Shared {
    /// Per point: its spatial key (stale for points renumbered by a hiding insertion, which
    /// only moves chunk borders).
    keys: Vec<u64>,
}

impl Shared {
    /// The keys of `points[..base]`: those not computed yet (the others as they were), on
    /// rayon's threads (the caller's pool, as the pass's; the first wave of a batch into a
    /// large triangulation computes them all: at 10⁶ points in a cube, 150 ms on one
    /// thread, 75 ms on two).
    fn sync<S: OrbitSpace<N>, const N: usize>(&mut self, space: &S, points: &[S::Point]) {
        let base = points.len();
        self.keys.truncate(base);
        let from = self.keys.len();
        let fresh = points[from..].par_iter().with_min_len(4096);
        self.keys.par_extend(fresh.map(|p| space.spatial_key(p)));
    }
}

/// Which chunk of the current pass owns a cell, kept in the cell's stamp (read with the
/// cell: no other memory to wait for): the one that made it in this pass, else the one
/// whose key range holds the key of its vertex 0 (stamped before the pass). Chunk `j` owns
/// the stamps `first + (j << shift)` and the `2^shift − 1` after it: the first marks its
/// cells, the others its visits (an inside and an outside mark a point), so that a visited
/// cell stays its own and no table of visited cells is needed.
#[derive(Clone, Copy, Debug)]
struct Ownership {
    /// The stamp of chunk 0 (values that no other visit takes, from
    /// [`crate::tds::Tds::reserve_stamps`]).
    first: u32,
    shift: u32,
    /// The chunks merge in aligned groups of `2^level` (0 for the pass's own chunks):
    /// a group owns every cell of its chunks.
    level: u32,
    /// The chunks of the pass.
    count: u32,
    /// Each group starts `turn` chunks back along the curve, wrapping around (0, or a
    /// quarter of the chunks for the groups across the halves' border: see `pass`).
    turn: u32,
}

impl Ownership {
    /// The shift that leaves room for `per` marks a point in chunks of `len` points, `count`
    /// of them (capped: a chunk out of marks defers its other points).
    fn shift_for(count: usize, len: usize, per: usize) -> u32 {
        let shift = len
            .saturating_mul(per)
            .saturating_add(1)
            .checked_next_power_of_two()
            .map_or(usize::BITS, |x| x.trailing_zeros());
        shift.min(30 - count.next_power_of_two().trailing_zeros())
    }

    /// The chunk of the pass that stamped a cell with `s` (`count` or more for none).
    #[inline(always)]
    fn chunk(self, s: u32) -> u32 {
        s.wrapping_sub(self.first) >> self.shift
    }

    /// The group owning a cell of stamp `s` (`count >> level` or more for none).
    #[inline(always)]
    fn owner(self, s: u32) -> u32 {
        self.turned(self.chunk(s)) >> self.level
    }

    /// Chunk `c`'s place in the turned order of the groups (`c` itself when it is no
    /// chunk of the pass).
    #[inline(always)]
    fn turned(self, c: u32) -> u32 {
        let t = c.wrapping_add(self.turn);
        if c >= self.count {
            c
        } else if t >= self.count {
            t - self.count
        } else {
            t
        }
    }

    /// The first chunk of group `j`.
    #[inline(always)]
    fn first_chunk(self, j: u32) -> u32 {
        let c = (j << self.level) + self.count - self.turn;
        if c >= self.count {
            c - self.count
        } else {
            c
        }
    }

    /// The stamp of group `j`'s cells: its first chunk's.
    #[inline(always)]
    fn stamp(self, j: u32) -> u32 {
        self.first + (self.first_chunk(j) << self.shift)
    }

    /// Chunk `j`'s visit mark `k` (from 1), if it has that many.
    #[inline(always)]
    fn mark(self, j: u32, k: u32) -> Option<u32> {
        (k < 1 << self.shift).then(|| self.stamp(j) + k)
    }
}

/// The cell store, written by several chunks at once, each only in the cells it owns and
/// its own slots.
struct SharedCells<O: Packing, const N: usize> {
    base: *mut Stored<O, N>,
    len: usize,
}

impl<O: Packing, const N: usize> SharedCells<O, N> {
    /// # Safety
    /// No other thread accesses slot `c` meanwhile.
    #[inline]
    unsafe fn get(&self, c: CellId) -> *mut Stored<O, N> {
        assert!(c.index() < self.len);
        self.base.add(c.index())
    }
}

/// What the threads of a pass share: the engine, read (each chunk only where it owns or
/// next to it), and the means to write the cells and vertices it owns.
struct Pass<'a, S: OrbitSpace<N>, const N: usize> {
    engine: &'a Engine<S, N>,
    cells: SharedCells<S::Elem, N>,
    vcell: &'a [AtomicU32],
    own: Ownership,
    wave: &'a [Item<S::Point>],
    /// The positions in the wave of the points to insert, chunk after chunk.
    active: &'a [u32],
    /// Every this many points of a chunk (a power of two), one was located before the pass.
    stride: usize,
    /// The id of the wave's first point.
    base: usize,
    chunks: *mut Chunk<S::Elem, N>,
    count: usize,
    next: AtomicUsize,
}

// SAFETY: each chunk is taken by one thread (`next`), and writes only the cells it owns
// and its own slots, which no other chunk reads (see the module's comment).
unsafe impl<S: OrbitSpace<N>, const N: usize> Sync for Pass<'_, S, N> {}

impl<S: OrbitSpace<N>, const N: usize> Pass<'_, S, N> {
    /// Runs chunks until none is left.
    fn work(&self) {
        loop {
            let j = self.next.fetch_add(1, Relaxed);
            if j >= self.count {
                return;
            }
            // SAFETY: chunk `j` is this thread's alone (`next`).
            let ch = unsafe { &mut *self.chunks.add(j) };
            unsafe { self.run(ch) };
        }
    }

    /// A chunk's points, one after another.
    ///
    /// # Safety
    /// The chunk is this thread's alone.
    unsafe fn run(&self, ch: &mut Chunk<S::Elem, N>) {
        let stamp = self.own.stamp(ch.id);
        for t in ch.range.clone() {
            let s = self.active[t] as usize;
            if ch.full {
                ch.left.push((s as u32, None));
                continue;
            }
            let k = t - ch.range.start;
            if k & (self.stride - 1) == 0 {
                // (the chunk owned the cell, so only it may have changed it since)
                if let Some(start) = ch.starts[k >> self.stride.trailing_zeros()] {
                    if self.engine.still_there(start) {
                        ch.hint = Some(start);
                    }
                }
            }
            let x = VertexId::new(self.base + s);
            let at = (&self.cells, self.vcell, stamp);
            self.engine.probe(self.wave[s], x, ch, &self.own, at);
            let outcome = match ch.found {
                Found::Flipped => Outcome::New,
                Found::Region => {
                    let e = self.engine;
                    match commit(&e.space, e.level, &self.cells, self.vcell, stamp, ch, x) {
                        Commit::Starred => Outcome::New,
                        Commit::OutOfSlots => {
                            ch.full = true;
                            ch.left.push((s as u32, None));
                            continue;
                        }
                        Commit::NotSimplicial | Commit::Unpacked => {
                            ch.left.push((s as u32, None));
                            continue;
                        }
                    }
                }
                Found::Duplicate(p) => Outcome::Duplicate(p),
                Found::Hidden => Outcome::Hidden,
                Found::Alone => Outcome::Alone,
                Found::Foreign => {
                    ch.left.push((s as u32, ch.foreign));
                    continue;
                }
            };
            ch.outcomes.push((s as u32, outcome));
        }
    }
}

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// Bulk insertions ([`Self::insert_parallel`]) run in parallel on `threads` threads
    /// (at least one), or one by one for `None` (the default).
    pub fn set_threads(&mut self, threads: Option<usize>) {
        self.threads = threads.map_or(0, |n| n.max(1));
    }

    /// Ends a batch of [`Self::insert_parallel`] calls (the rounds of one build or one
    /// `insert_all`): the points' keys kept between them are dropped, so that removals and
    /// moves before the next batch cannot leave them stale.
    pub fn end_batch(&mut self) {
        self.wave_keys = Vec::new();
    }

    /// The threads of the parallel bulk insertion, if any ([`Self::set_threads`]).
    pub fn threads(&self) -> Option<usize> {
        (self.threads > 0).then_some(self.threads)
    }

    /// True when a bulk insertion with threads should go in BRIO rounds that grow
    /// eightfold, each one wave (see the module's comment): with threads, in a space
    /// without reflections (where the waves double otherwise, untried).
    pub(crate) fn eightfold_rounds(&self) -> bool {
        self.threads > 0 && !S::MAY_REVERSE
    }

    /// True when the next `left` insertions may run in parallel: a 1-sheeted, unweighted
    /// triangulation whose switch criterion holds, large enough that chunks seldom meet,
    /// and enough of them for a wave ([`FEWEST`]).
    fn wave_ready(&self, left: usize) -> bool {
        self.threads > 0
            && self.one_sheeted
            && self.guaranteed
            && !self.weighted
            && self.tds.is_packed()
            && self.points.len() >= SEQUENTIAL_START
            && left.saturating_mul(FEWEST) >= self.points.len()
    }

    /// Inserts `items`: one by one in their order, or once [`Self::set_threads`] asked for
    /// threads, in parallel waves where the triangulation allows (see the module's
    /// comment). The triangulation is that of inserting them one by one; with threads, it
    /// is stored the same, slot for slot, whatever their number. `progress` is called with
    /// the number of items done: with 0 first, then every 4096 items one by one and after
    /// each wave (not at the end); [`ControlFlow::Break`] stops the insertion (the items
    /// not yet done are not in the log). The points' keys are kept for the next call until
    /// [`Self::end_batch`].
    pub fn insert_parallel(
        &mut self,
        items: &[Item<S::Point>],
        mut progress: impl FnMut(usize) -> ControlFlow<()>,
    ) -> (Log<S::Point>, ControlFlow<()>) {
        let mut log = Log {
            events: Vec::with_capacity(items.len()),
            hidden: Vec::new(),
        };
        let mut shared = Shared {
            keys: std::mem::take(&mut self.wave_keys),
        };
        let (mut k, mut flow) = (0, ControlFlow::Continue(()));
        while k < items.len() {
            if progress(k).is_break() {
                flow = ControlFlow::Break(());
                break;
            }
            if self.wave_ready(items.len() - k) {
                // (a whole round, up to eightfold: see the module's comment)
                let grow = if self.eightfold_rounds() { 8 } else { 1 };
                let m = (items.len() - k).min(grow * self.points.len());
                self.wave(items, k..k + m, &mut shared, &mut log);
                k += m;
                continue;
            }
            let end = (k + 4096).min(items.len());
            while k < end && !self.wave_ready(items.len() - k) {
                self.insert_alone(items, k, &mut log);
                k += 1;
            }
        }
        self.wave_keys = shared.keys;
        (log, flow)
    }

    /// Inserts item `k` with the sequential code and logs it.
    fn insert_alone(&mut self, items: &[Item<S::Point>], k: usize, log: &mut Log<S::Point>) {
        let (_, p, w, key) = items[k];
        let r = self.insert_keyed(p, w, key);
        log.hidden.append(&mut self.hidden_log);
        log.events.push((k as u32, r, log.hidden.len() as u32));
    }

    /// One wave: `items[range]`, sorted along the curve, their ids reserved in that order;
    /// a pass of [`CHUNKS`] chunks on the threads, the points they deferred one at a time,
    /// then the ids of the points that did not become vertices filled, the log written and
    /// the points that would hide others inserted by the sequential code.
    fn wave(
        &mut self,
        items: &[Item<S::Point>],
        range: Range<usize>,
        shared: &mut Shared,
        log: &mut Log<S::Point>,
    ) {
        // in curve order: a stretch of a BRIO round, sorted already, read in place (a copy
        // cost two threads 8 ms at 10⁶ points in a square, most of it the first touch of
        // its pages); else a copy tagged with the items' indices, sorted (stable)
        let sorted = items[range.clone()]
            .par_windows(2)
            .all(|w| w[0].3 <= w[1].3);
        let wave: Cow<[Item<S::Point>]> = if sorted {
            Cow::Borrowed(&items[range.clone()])
        } else {
            let mut wave = Vec::with_capacity(range.len());
            items[range.clone()]
                .par_iter()
                .enumerate()
                .map(|(i, &(_, p, w, key))| ((range.start + i) as u32, p, w, key))
                .collect_into_vec(&mut wave);
            wave.sort_by_key(|&(k, .., key)| (key, k));
            Cow::Owned(wave)
        };
        // the index in `items` of the wave's point at position `s`
        let item_of = |s: usize| match &wave {
            Cow::Borrowed(_) => (range.start + s) as u32,
            Cow::Owned(wave) => wave[s].0,
        };
        let base = self.points.len();
        let m = wave.len();
        shared.sync(&self.space, &self.points);
        // (1-sheeted: a point's vertex has its id)
        debug_assert!(self.vpoint.len() == base && self.vcell.len() == base);
        // (on the threads: 14 ms one by one at 10⁶ points in a square)
        self.points.par_extend(wave.par_iter().map(|item| item.1));
        self.vpoint
            .par_extend((base..base + m).into_par_iter().map(PointId::new));
        self.vcell
            .par_extend(rayon::iter::repeat_n(CellId::NONE, m));
        shared.keys.par_extend(wave.par_iter().map(|item| item.3));
        let mut outcome = vec![Outcome::Deferred; m];
        // the chunks along the curve, then the points on their borders one at a time
        self.pass(&wave, base, shared, &mut outcome);
        self.insert_deferred(&wave, base, &mut outcome);
        // the ids of points that are not vertices, filled by the last points (most waves
        // have none: then a point's id is `base` + its position)
        let hole = |s: usize| outcome[s] != Outcome::New;
        let holes = (0..m).into_par_iter().any(hole);
        let mut id = Vec::new();
        let mut slot = Vec::new();
        if holes {
            id = (base..base + m).collect::<Vec<usize>>();
            for h in (0..m).filter(|&s| hole(s)) {
                // (the holes at the end, down to `h` itself, are dropped)
                while self.points.len() > base + h && hole(self.points.len() - 1 - base) {
                    self.unpush_point();
                }
                if self.points.len() <= base + h {
                    break;
                }
                let last = self.points.len() - 1;
                id[last - base] = base + h;
                self.renumber_last_point(PointId::new(base + h));
                shared.keys[base + h] = shared.keys[last];
            }
            shared.keys.truncate(self.points.len());
            // the position of each new vertex: the filled ids are `base..` with no gap
            slot = vec![0u32; self.points.len() - base];
            for s in (0..m).filter(|&s| !hole(s)) {
                slot[id[s] - base] = s as u32;
            }
        }
        let id_of = |s: usize| if holes { id[s] } else { base + s };
        let position = |v: usize| if holes { slot[v] as usize } else { v };
        // the new vertices in id order, in the grid and the log (on the threads: 13 ms one
        // by one at 10⁶ points in a square)
        let count = self.points.len() - base;
        self.note_vertices(base, count, |v| wave[position(v)].3);
        let hidden = log.hidden.len() as u32;
        log.events.par_extend((0..count).into_par_iter().map(|v| {
            let event = Inserted::New(PointId::new(base + v));
            (item_of(position(v)), event, hidden)
        }));
        let mut alone = Vec::new();
        for (s, &o) in outcome.iter().enumerate() {
            let r = match o {
                Outcome::New => continue,
                Outcome::Duplicate(q) if q.index() >= base => {
                    Inserted::Duplicate(PointId::new(id_of(q.index() - base)))
                }
                Outcome::Duplicate(q) => Inserted::Duplicate(q),
                Outcome::Hidden => Inserted::Hidden,
                Outcome::Alone | Outcome::Deferred => {
                    alone.push(item_of(s) as usize);
                    continue;
                }
            };
            log.events.push((item_of(s), r, log.hidden.len() as u32));
        }
        alone.sort_unstable();
        for k in alone {
            self.insert_alone(items, k, log);
        }
    }

    /// The points of the wave that its chunks deferred (on their borders), one after
    /// another by the sequential code, each as its reserved vertex; a point that would hide
    /// vertices is left for after the wave.
    fn insert_deferred(&mut self, wave: &[Item<S::Point>], base: usize, outcome: &mut [Outcome]) {
        for (s, &(_, p, _, key)) in wave.iter().enumerate() {
            if outcome[s] != Outcome::Deferred {
                continue;
            }
            // (along the borders the next point may be far: from the grid when it is)
            let from = self.insertion_start(key);
            let x = VertexId::new(base + s);
            let q = (p, self.space.identity());
            let placed = if self.hides() {
                self.conflict_region(q, x, true, from).map(|()| {
                    if self.scratch_hides() {
                        return Outcome::Alone;
                    }
                    self.star_hole(x, q.1);
                    Outcome::New
                })
            } else {
                self.insert_lifted(q, x, true, from).map(|()| Outcome::New)
            };
            outcome[s] = match placed {
                Ok(outcome) => outcome,
                Err(Refused::Duplicate(v)) => Outcome::Duplicate(self.vpoint[v.index()]),
                Err(Refused::Hidden) => Outcome::Hidden,
                Err(Refused::NotSimplicial) => unreachable!("the criterion holds"),
            };
        }
    }

    /// True when starring the conflict region in the scratch would hide vertices.
    fn scratch_hides(&self) -> bool {
        self.hides_vertices(&self.scratch.conflict, &self.scratch.boundary)
    }

    /// The pass of the wave's points (the point at position `s` has id `base + s`) in
    /// [`CHUNKS`] chunks, on the engine's threads: the chunks own the ranges of the
    /// spatial keys that their points span. Then the points left on the borders between
    /// chunks `2j` and `2j + 1` go in by [`CHUNKS`]` / 2` groups of two chunks, each
    /// owning its chunks' cells (the border inside it), those on the borders within
    /// aligned groups of four by groups of four, and so on while there are two groups.
    fn pass(
        &mut self,
        wave: &[Item<S::Point>],
        base: usize,
        shared: &mut Shared,
        outcome: &mut [Outcome],
    ) {
        let n = wave.len();
        let count = CHUNKS.min(n.max(1));
        // every live cell stamped with its owner: the chunk whose keys hold its vertex 0's
        // (a point takes two marks, an inside and an outside one, in each pass it is tried)
        let shift = Ownership::shift_for(count, n.div_ceil(count), MARKS);
        let mut own = Ownership {
            first: self.tds.reserve_stamps((count as u32) << shift),
            shift,
            level: 0,
            count: count as u32,
            turn: 0,
        };
        let bounds: Vec<u64> = (1..count).map(|j| wave[j * n / count].3).collect();
        let keys = &shared.keys;
        self.tds
            .cells
            .par_iter_mut()
            .with_min_len(4096)
            .for_each(|c| {
                if c.v[0] != VertexId::NONE {
                    let key = keys[c.v[0].index()];
                    c.set_stamp(own.stamp(bounds.partition_point(|&b| b <= key) as u32));
                }
            });
        let all: Vec<u32> = (0..n as u32).collect();
        let groups = (0..count).map(|j| (j * n / count..(j + 1) * n / count, 0));
        let (mut left, mut marks) =
            self.run_chunks((wave, &all), groups, (own, STRIDE, base), outcome);
        // the chunk of each position, and the level of the group that holds a point and
        // the chunk whose cell stopped it (unknown: the next level). In a group pass of
        // level `L` that chunk may read as the first chunk of the group owning the cell
        // (which marked it meanwhile): both lie in that group, outside the point's, so
        // the bit that sets the level (at or above `L`) is the same, and so is the result
        // whatever the timing.
        let chunk_of = |s: u32| ((s as usize + 1) * count - 1) / n;
        let need = |level: u32, s: u32, met: Option<u32>| {
            met.map_or(level + 1, |o| {
                u32::BITS - (chunk_of(s) as u32 ^ o).leading_zeros()
            })
            .max(level + 1)
        };
        let mut pending: Vec<(u32, u32)> = left.iter().map(|&(s, o)| (s, need(0, s, o))).collect();
        for level in 1..count.trailing_zeros() {
            own.level = level;
            // (in curve order within each group)
            pending.sort_unstable();
            let mut active: Vec<u32> = Vec::new();
            let mut groups = Vec::new();
            for g in 0..count >> level {
                let from = active.len();
                active.extend(
                    pending.iter().filter_map(|&(s, l)| {
                        (l == level && chunk_of(s) >> level == g).then_some(s)
                    }),
                );
                groups.push((from..active.len(), marks[g << level]));
            }
            if active.len() < GROUPED_FEWEST {
                continue;
            }
            pending.retain(|&(_, l)| l != level);
            let used;
            (left, used) =
                self.run_chunks((wave, &active), groups.into_iter(), (own, 1, base), outcome);
            for (g, m) in used.into_iter().enumerate() {
                marks[g << level] = m;
            }
            pending.extend(left.iter().map(|&(s, o)| (s, need(level, s, o))));
        }
        // the points left on the border between the two halves: along the curve the halves
        // meet chunk `i` against chunk `count − 1 − i` (the octants' Gray code), so two
        // groups of half the chunks turned by a quarter (6, 7, 0, 1 and 2, 3, 4, 5 of 8)
        // hold each such pair inside one of them; what they leave goes one at a time. (All
        // are tried, whatever chunk stopped them: which one did can depend on timing, the
        // level not.)
        let top = count.trailing_zeros();
        let across = |&&(_, l): &&(u32, u32)| l == top;
        if !count.is_power_of_two()
            || count < 4
            || pending.iter().filter(across).count() < GROUPED_FEWEST
        {
            return;
        }
        own.level = top - 1;
        own.turn = count as u32 / 4;
        let turned = |s: u32| own.turned(chunk_of(s) as u32);
        let mut active: Vec<u32> = pending.iter().filter(across).map(|&(s, _)| s).collect();
        // (in curve order within each group: the first starts at chunk `count − turn`)
        active.sort_unstable_by_key(|&s| (turned(s), s));
        let mut groups = Vec::new();
        for g in 0..2 {
            let from = active.partition_point(|&s| turned(s) >> own.level < g);
            let to = active.partition_point(|&s| turned(s) >> own.level <= g);
            groups.push((from..to, marks[own.first_chunk(g) as usize]));
        }
        // (each walk from the group's last insertion, every 64th from a cell located before:
        // one located for every point cost a one-thread build 4 % more, against 2.5 %)
        let (_, used) = self.run_chunks(
            (wave, &active),
            groups.into_iter(),
            (own, STRIDE, base),
            outcome,
        );
        for (g, m) in used.into_iter().enumerate() {
            marks[own.first_chunk(g as u32) as usize] = m;
        }
    }

    /// Runs the chunks `groups` (each its range in `active` and the visit marks it took
    /// before) on the engine's threads, ownership by `own`, every `stride`-th point of a
    /// chunk located before: writes the outcomes, and returns the points left (with the
    /// chunk whose cell stopped each, if known) and the marks each chunk has taken.
    fn run_chunks(
        &mut self,
        (wave, active): (&[Item<S::Point>], &[u32]),
        groups: impl Iterator<Item = (Range<usize>, u32)>,
        (own, stride, base): (Ownership, usize, usize),
        outcome: &mut [Outcome],
    ) -> (Vec<(u32, Option<u32>)>, Vec<u32>) {
        debug_assert!(stride.is_power_of_two());
        // cell slots for each chunk: free ones, then new ones (a vertex makes `2` more
        // triangles on a surface, some 6.8 more tetrahedra in a volume)
        let per = if N == 3 { 2 } else { 8 };
        let mut free = self.tds.take_free();
        let mut slots = self.tds.cells.len();
        let mut chunks: Vec<Chunk<S::Elem, N>> = groups
            .enumerate()
            .map(|(j, (range, marks))| {
                let need = range.len() * per + MARGIN;
                let spare = free.split_off(free.len() - need.min(free.len()));
                let fresh = slots..slots + need - spare.len();
                slots = fresh.end;
                let mut ch = Chunk::new(j as u32, range, spare, fresh);
                ch.marks = marks;
                ch
            })
            .collect();
        for d in free {
            self.tds.delete(d);
        }
        let dead = Cell::new([VertexId::NONE; N], [self.space.identity(); N]);
        let dead = Stored::pack(&dead).expect("the identity packs");
        self.tds.grow(slots, dead);
        chunks
            .par_iter_mut()
            .for_each(|ch| self.locate_starts(ch, (wave, active), &own, stride));
        let cells = SharedCells {
            base: self.tds.cells.as_mut_ptr(),
            len: slots,
        };
        let vcell_len = self.vcell.len();
        // SAFETY: `AtomicU32` has the layout of `u32`, and so of `CellId`; the pointer
        // comes from a mutable borrow, and during the pass the vertices' cells are read and
        // written only through it.
        let vcell: &[AtomicU32] =
            unsafe { std::slice::from_raw_parts(self.vcell.as_mut_ptr().cast(), vcell_len) };
        let count = chunks.len();
        let threads = self.threads.clamp(1, count);
        let pass = Pass {
            engine: &*self,
            cells,
            vcell,
            own,
            wave,
            active,
            stride,
            base,
            chunks: chunks.as_mut_ptr(),
            count,
            next: AtomicUsize::new(0),
        };
        if threads == 1 {
            pass.work();
        } else {
            std::thread::scope(|s| {
                for _ in 1..threads {
                    s.spawn(|| pass.work());
                }
                pass.work();
            });
        }
        let mut left = Vec::new();
        let mut marks = Vec::with_capacity(count);
        for ch in &mut chunks {
            for &(s, o) in &ch.outcomes {
                outcome[s as usize] = o;
            }
            left.append(&mut ch.left);
            marks.push(ch.marks);
            for d in ch.leftover() {
                self.tds.delete(d);
            }
        }
        (left, marks)
    }

    /// Locates every `stride`-th point of chunk `ch`, only reading, before the pass: its
    /// `starts`.
    fn locate_starts(
        &self,
        ch: &mut Chunk<S::Elem, N>,
        (wave, active): (&[Item<S::Point>], &[u32]),
        own: &Ownership,
        stride: usize,
    ) {
        let mut last = None;
        let starts = ch.range.clone().step_by(stride).map(|t| {
            let (_, p, _, key) = wave[active[t] as usize];
            let (c, shift) = self.jump(key).or(last).unwrap_or_else(|| self.start_cell());
            let (c, q) = self.walk((p, shift), c, &mut SplitMix::new(key));
            last = Some((c, q));
            (self.owner_of(own, c) == ch.id).then(|| (c, self.tds.cells[c.index()].v, q))
        });
        ch.starts = starts.collect();
    }

    /// True when cell `c` still holds the vertices `v` (a hint: a freed and reused slot
    /// fails).
    #[inline]
    fn still_there(&self, (c, v, _): (CellId, [VertexId; N], S::Elem)) -> bool {
        self.tds.is_alive(c) && self.tds.cells[c.index()].v == v
    }

    /// The chunk that owns live cell `c` in the current pass.
    #[inline(always)]
    fn owner_of(&self, own: &Ownership, c: CellId) -> u32 {
        own.owner(self.tds.cells[c.index()].stamp())
    }

    /// The probe of a chunk's next point: locates it (walking from the chunk's last
    /// insertion) and collects its conflict region, reading only cells the chunk owns and
    /// their neighbours; in 2D strictly inside a triangle where [`Engine::flips`], inserts
    /// it by flips instead ([`Self::split_in_chunk`]).
    fn probe(
        &self,
        (_, p, _, key): Item<S::Point>,
        x: VertexId,
        ch: &mut Chunk<S::Elem, N>,
        own: &Ownership,
        (cells, vcell, stamp): (&SharedCells<S::Elem, N>, &[AtomicU32], u32),
    ) {
        let me = ch.id;
        let met = std::cell::Cell::new(None);
        let owned = |c: CellId| {
            let s = self.tds.stamp(c);
            let mine = own.owner(s) == me;
            if !mine {
                met.set(Some(own.chunk(s)));
            }
            mine
        };
        ch.found = Found::Foreign;
        ch.foreign = None;
        let Some((c, _, shift)) = ch.hint.filter(|&h| self.still_there(h)) else {
            return;
        };
        let mut rng = SplitMix::new(key);
        let Some((c0, q0, strict)) = self.walk_within((p, shift), c, &mut rng, owned) else {
            ch.foreign = met.get();
            return;
        };
        if strict && self.flips() {
            // SAFETY: the pass's cells; the chunk writes only cells it owns and its slots.
            let at = (cells, vcell, stamp);
            ch.found = unsafe { self.split_in_chunk(p, (c0, q0), x, ch, own, at) };
            return;
        }
        if let Some(v) = self.coincident_vertex(c0, (p, q0), 0.0) {
            ch.found = Found::Duplicate(self.vpoint[v.index()]);
            ch.hint = Some((c0, self.tds.cells[c0.index()].v, q0));
            return;
        }
        if self.hides() && !self.cell_conflicts(c0, (p, q0), 0.0) {
            ch.found = Found::Hidden;
            return;
        }
        // SAFETY: the pass's cells; the chunk writes only the stamps of cells it owns.
        let found = if N == 3 {
            unsafe { self.probe_around(p, (c0, q0), ch, own, (cells, vcell)) }
        } else {
            unsafe { self.probe_breadth(p, (c0, q0), ch, own, cells) }
        };
        if found {
            ch.found = if self.hides() && self.hides_vertices(&ch.conflict, &ch.boundary) {
                Found::Alone
            } else {
                Found::Region
            };
        }
    }

    /// 2D, where [`Engine::flips`]: inserts `x` at `p`, strictly inside the chunk's cell
    /// `c0` lifted by `q0`, by splitting it and flipping as one at a time does
    /// ([`split_and_flip`] on an [`InChunk`]), reading only cells the chunk owns and the
    /// stamps of their neighbours, and writing only cells it owns (new ones stamped
    /// `stamp`). Each write is journaled and all are undone when a flip needs another
    /// chunk's cell (`Foreign`, with `ch.foreign`), a new triangle's elements do not pack,
    /// or the chunk has no two slots left (`Foreign`, `ch.full`).
    ///
    /// # Safety
    /// `cells` is the pass's store, in which no other chunk writes the cells this one owns.
    unsafe fn split_in_chunk(
        &self,
        p: S::Point,
        (c0, q0): (CellId, S::Elem),
        x: VertexId,
        ch: &mut Chunk<S::Elem, N>,
        own: &Ownership,
        (cells, vcell, stamp): (&SharedCells<S::Elem, N>, &[AtomicU32], u32),
    ) -> Found {
        if ch.spare.len() + ch.fresh.len() < 2 {
            ch.full = true;
            return Found::Foreign;
        }
        let mut f = InChunk {
            engine: self,
            ch,
            own,
            cells,
            vcell,
            stamp,
        };
        let old = self.tds.cell(c0);
        // (every cell next to one the chunk changes must be its own: here all three)
        if let Err(k) = old.n.iter().try_for_each(|&n| f.may_change(n)) {
            f.ch.foreign = k;
            return Found::Foreign;
        }
        f.ch.journal.clear();
        f.ch.moved.clear();
        let (b, d) = (
            take_slot(&mut f.ch.spare, &mut f.ch.fresh),
            take_slot(&mut f.ch.spare, &mut f.ch.fresh),
        );
        let mut edges = std::mem::take(&mut f.ch.edges);
        let flipped = split_and_flip(&mut f, &old, [c0, b, d], (p, q0), x, &mut edges);
        ch.edges = edges;
        if let Err(k) = flipped {
            ch.undo(cells, vcell, [b, d]);
            #[cfg(test)]
            tests::UNDONE.with(|n| n.set(n.get() + 1));
            ch.foreign = k;
            return Found::Foreign;
        }
        vcell[x.index()].store(c0.0, Relaxed);
        let shift = self
            .space
            .carry(self.space.identity(), self.tds.off_at(c0, 0));
        ch.hint = Some((c0, self.tds.cells[c0.index()].v, shift));
        #[cfg(test)]
        tests::FLIPPED.with(|n| n.set(n.get() + 1));
        Found::Flipped
    }

    /// 2D: the conflict region of `p` from cell `c0` (holding it lifted by `q0`) by
    /// depth-first search, as [`Engine::conflict_region`] finds it, its boundary edges in
    /// the order of a walk around it (`rim`), the visit's marks stamps of the chunk (a
    /// visited cell stays its own). False when the search meets a cell the chunk does not
    /// own, or the chunk has no marks left.
    ///
    /// # Safety
    /// `cells` is the pass's store, in which no other chunk writes the cells this one owns.
    unsafe fn probe_around(
        &self,
        p: S::Point,
        (c0, q0): (CellId, S::Elem),
        ch: &mut Chunk<S::Elem, N>,
        own: &Ownership,
        (cells, vcell): (&SharedCells<S::Elem, N>, &[AtomicU32]),
    ) -> bool {
        let (Some(inside), Some(outside)) = (ch.take_mark(own), ch.take_mark(own)) else {
            ch.full = true;
            return false;
        };
        ch.conflict.clear();
        ch.boundary.clear();
        ch.across.clear();
        ch.rim.clear();
        ch.stack.clear();
        ch.conflict.push((c0, q0));
        (*cells.get(c0)).set_stamp(inside);
        ch.orphans.clear();
        orphans_of(vcell, c0, &self.tds.cells[c0.index()].v, &mut ch.orphans);
        ch.stack.push((0, 0, 1, 3));
        while let Some((ci, i, step)) = next_edge(&mut ch.stack) {
            let (c, qo) = ch.conflict[ci as usize];
            let cell = &self.tds.cells[c.index()];
            let d = cell.n[i];
            let st = self.tds.cells[d.index()].stamp();
            if st == inside {
                continue;
            }
            if own.owner(st) != ch.id {
                ch.foreign = Some(own.chunk(st));
                return false;
            }
            let (a, b) = edge_ends(&cell.v, i, step);
            let j = self.mirror_of(d, c);
            if st != outside {
                if let Some(qd) = self.conflict_across((c, i, d), (p, qo), 0.0) {
                    (*cells.get(d)).set_stamp(inside);
                    self.tds.prefetch_neighbours(d);
                    orphans_of(vcell, d, &self.tds.cells[d.index()].v, &mut ch.orphans);
                    ch.conflict.push((d, qd));
                    let k = ch.conflict.len() - 1;
                    enter(&mut ch.stack, k, &self.tds.cells[d.index()].v, j, b);
                    continue;
                }
                (*cells.get(d)).set_stamp(outside);
            }
            ch.boundary.push((ci, i as u8));
            ch.across.push((d, j as u8));
            ch.rim.push((a, b, j as u8));
        }
        closes(&ch.rim, ch.boundary.len())
    }

    /// 3D: the conflict region of `p` from cell `c0` (holding it lifted by `q0`) by
    /// breadth-first search, as [`Engine::conflict_region`] finds it, the visit's inside
    /// and outside marks stamps of the chunk (a visited cell stays its own). False when the
    /// search meets a cell the chunk does not own, or the chunk has no marks left.
    ///
    /// # Safety
    /// `cells` is the pass's store, in which no other chunk writes the cells this one owns.
    unsafe fn probe_breadth(
        &self,
        p: S::Point,
        (c0, q0): (CellId, S::Elem),
        ch: &mut Chunk<S::Elem, N>,
        own: &Ownership,
        cells: &SharedCells<S::Elem, N>,
    ) -> bool {
        ch.conflict.clear();
        ch.boundary.clear();
        ch.across.clear();
        let (Some(inside), Some(outside)) = (ch.take_mark(own), ch.take_mark(own)) else {
            ch.full = true;
            return false;
        };
        ch.conflict.push((c0, q0));
        (*cells.get(c0)).set_stamp(inside);
        let mut next = 0;
        while next < ch.conflict.len() {
            let (c, qo) = ch.conflict[next];
            for i in 0..N {
                let d = self.tds.cells[c.index()].n[i];
                let st = self.tds.cells[d.index()].stamp();
                if st == inside {
                    continue;
                }
                if st != outside {
                    if own.owner(st) != ch.id {
                        ch.foreign = Some(own.chunk(st));
                        return false;
                    }
                    if let Some(qd) = self.conflict_across((c, i, d), (p, qo), 0.0) {
                        (*cells.get(d)).set_stamp(inside);
                        self.tds.prefetch_neighbours(d);
                        ch.conflict.push((d, qd));
                        continue;
                    }
                    (*cells.get(d)).set_stamp(outside);
                }
                let j = self.mirror_of(d, c);
                ch.boundary.push((next as u32, i as u8));
                ch.across.push((d, j as u8));
            }
            next += 1;
        }
        true
    }
}

/// What a chunk's [`commit`] did.
enum Commit {
    Starred,
    /// Nothing: the chunk has too few cell slots left.
    OutOfSlots,
    /// Nothing: the 3D star is not simplicial (a boundary edge not under exactly two new
    /// cells, see [`Ridges::pair`]); the sequential code, which links such stars by
    /// rotation, inserts the point.
    NotSimplicial,
    /// Nothing: a new cell's elements do not pack ([`crate::tds::Packing`]); the sequential
    /// code, which can store them beside the cells, inserts the point.
    Unpacked,
}

/// Stars a chunk's region from its new vertex `x`: the new cells take the region's slots
/// (those left over become the chunk's spares), then spares and fresh slots of the chunk,
/// and are stamped its own; they are linked to the cells across the boundary and to each
/// other (2D as a fan, 3D by their boundary edges). Vertices whose cell was in the region
/// point at a new cell.
///
/// # Safety
/// The chunk owns its region and the cells across it, and its slots; no other thread
/// touches them.
#[allow(clippy::too_many_arguments)]
unsafe fn commit<S: OrbitSpace<N>, const N: usize>(
    space: &S,
    level: usize,
    cells: &SharedCells<S::Elem, N>,
    vcell: &[AtomicU32],
    stamp: u32,
    ch: &mut Chunk<S::Elem, N>,
    x: VertexId,
) -> Commit {
    let extra = ch.boundary.len().saturating_sub(ch.conflict.len());
    if ch.spare.len() + ch.fresh.len() < extra {
        return Commit::OutOfSlots;
    }
    let (old, new, ids) = (&mut ch.old, &mut ch.new, &mut ch.ids);
    old.clear();
    old.extend(ch.conflict.iter().map(|&(c, _)| *cells.get(c)));
    new.clear();
    for (k, &(ci, i)) in ch.boundary.iter().enumerate() {
        let (ci, i) = (ci as usize, i as usize);
        let (was, qo) = (&old[ci], ch.conflict[ci].1);
        // (inside the domain, the conflict cell's elements as they are packed)
        let cell = match was.with_same_elements(i, x, qo) {
            Some(mut cell) => {
                cell.n[i] = ch.across[k].0;
                cell
            }
            None => {
                let mut cell =
                    Cell::new(replaced(was.v, i, x), replaced(was.packed_offsets(), i, qo));
                if space.normalize(&mut cell.off, level) && S::MAY_REVERSE {
                    cell.swap_slots(0, 1);
                }
                let slot = cell.index_of(x).expect("the new vertex");
                cell.n = replaced(cell.n, slot, ch.across[k].0);
                let Some(cell) = Stored::pack(&cell) else {
                    return Commit::Unpacked;
                };
                cell
            }
        };
        new.push(cell);
    }
    // 3D: paired by the boundary edges (as [`Engine::link_by_ridges`] pairs them)
    let pairs = if N == 4 {
        let cells = new.iter().enumerate();
        let pairs = ch
            .ridges
            .pair(cells.map(|(k, c)| (k as u32, c.v, c.index_of(x).expect("the new vertex"))));
        let Some(pairs) = pairs else {
            return Commit::NotSimplicial;
        };
        pairs
    } else {
        &[]
    };
    // (a vertex whose cell is in the region is the chunk's to point elsewhere: no other
    // chunk writes it meanwhile, since it points at none of their regions)
    if N != 3 {
        // (2D: found by the probe)
        ch.orphans.clear();
        for (cell, &(c, _)) in old.iter().zip(&ch.conflict) {
            orphans_of(vcell, c, &cell.v, &mut ch.orphans);
        }
    }
    ids.clear();
    ids.extend(ch.conflict.iter().map(|&(c, _)| c).take(ch.boundary.len()));
    while ids.len() < ch.boundary.len() {
        ids.push(take_slot(&mut ch.spare, &mut ch.fresh));
    }
    for &(a, i, b, j) in pairs {
        new[a as usize].n[i as usize] = ids[b as usize];
        new[b as usize].n[j as usize] = ids[a as usize];
    }
    if N == 3 {
        // 2D: a fan, in the order of the rim (as [`Engine::star_around`] links it)
        let m = new.len();
        for k in 0..m {
            let next = if k + 1 == m { 0 } else { k + 1 };
            let sa = slot_in(&new[k].v, ch.rim[k].0, ch.boundary[k].1 as usize);
            let sb = slot_in(&new[next].v, ch.rim[next].1, ch.boundary[next].1 as usize);
            new[k].n[sa] = ids[next];
            new[next].n[sb] = ids[k];
        }
    }
    for (k, cell) in new.iter().enumerate() {
        let mut cell = *cell;
        cell.set_stamp(stamp);
        *cells.get(ids[k]) = cell;
        let (d, jd) = ch.across[k];
        (*cells.get(d)).n[jd as usize] = ids[k];
        for &v in &cell.v {
            if v == x || ch.orphans.contains(&v) {
                vcell[v.index()].store(ids[k].0, Relaxed);
            }
        }
    }
    for &(spare, _) in ch.conflict.iter().skip(new.len()) {
        (*cells.get(spare)).v[0] = VertexId::NONE;
        ch.spare.push(spare);
    }
    let k = new[0].index_of(x).expect("new cells hold the new vertex");
    ch.hint = Some((
        ids[0],
        new[0].v,
        space.carry(space.identity(), new[0].packed_offsets()[k]),
    ));
    Commit::Starred
}

/// A chunk's share of the pass's store, as the flips see it ([`Engine::split_in_chunk`]):
/// only cells it owns may change, new cells are stamped `stamp`, and each write is
/// journaled for [`Chunk::undo`]. Stops with the chunk that owns a cell it needs, if any.
struct InChunk<'a, S: OrbitSpace<N>, const N: usize> {
    engine: &'a Engine<S, N>,
    ch: &'a mut Chunk<S::Elem, N>,
    own: &'a Ownership,
    /// The pass's store, in which no other chunk writes the cells `ch` owns (the
    /// promise of `split_in_chunk`'s caller, the only place one is made). Its writes are
    /// safe by [`split_and_flip`]'s contract: to cells checked by `may_change` first, or
    /// to the chunk's slots.
    cells: &'a SharedCells<S::Elem, N>,
    vcell: &'a [AtomicU32],
    stamp: u32,
}

impl<S: OrbitSpace<N>, const N: usize> Flipper<S, N> for InChunk<'_, S, N> {
    type Stop = Option<u32>;

    #[inline(always)]
    fn engine(&self) -> &Engine<S, N> {
        self.engine
    }

    #[inline(always)]
    fn may_change(&self, c: CellId) -> Result<(), Self::Stop> {
        // SAFETY: a stamp is read, of a cell next to the chunk's own, which cannot change
        // while it is (see the module's comment)
        let st = unsafe { (*self.cells.get(c)).stamp() };
        if self.own.owner(st) == self.ch.id {
            Ok(())
        } else {
            Err(Some(self.own.chunk(st)))
        }
    }

    #[inline(always)]
    fn rewrite(&mut self, c: CellId, t: Triangle<S::Elem>, new: bool) -> Result<(), Self::Stop> {
        let cell = self.engine.canonical_triangle(t);
        // SAFETY: `c` is the chunk's, checked or one of its slots (see `cells`), and the
        // reference is the only one to it
        let slot = unsafe { &mut *self.cells.get(c) };
        let was = *slot;
        if !slot.set(&cell) {
            return Err(None);
        }
        if new {
            slot.set_stamp(self.stamp);
        }
        self.ch.journal.push((c, was));
        Ok(())
    }

    #[inline(always)]
    fn relink(&mut self, (a, i): (CellId, usize), d: CellId, old: CellId) {
        // SAFETY: `d` is the chunk's (see `cells`); the reference ends before `a`'s write
        let cell = unsafe { &mut *self.cells.get(d) };
        let j = cell.mirror(old).expect("symmetric neighbours");
        self.ch.journal.push((d, *cell));
        cell.n[j] = a;
        // SAFETY: `a` is the chunk's, written already (see `cells`)
        unsafe { (*self.cells.get(a)).n[i] = d };
    }

    /// Points `v` at `to` only if it points at `from`: `from` is the chunk's, so no other
    /// chunk moves `v` meanwhile, and the outcome does not depend on timing.
    #[inline(always)]
    fn move_vertex(&mut self, v: VertexId, from: CellId, to: CellId) {
        let cell = &self.vcell[v.index()];
        if cell.load(Relaxed) == from.0 {
            self.ch.moved.push((v, from.0));
            cell.store(to.0, Relaxed);
        }
    }
}

/// A slot for a new cell: a spare one, else a fresh one (the caller checked that there
/// is one).
#[inline(always)]
fn take_slot(spare: &mut Vec<CellId>, fresh: &mut Range<usize>) -> CellId {
    spare.pop().unwrap_or_else(|| {
        fresh.start += 1;
        CellId::new(fresh.start - 1)
    })
}

/// Adds to `orphans` the vertices `v` of region cell `c` whose cell it is (the commit
/// points them at a new cell; no other chunk writes their cells meanwhile, since they
/// point at none of their regions).
#[inline(always)]
fn orphans_of<const N: usize>(
    vcell: &[AtomicU32],
    c: CellId,
    v: &[VertexId; N],
    orphans: &mut Vec<VertexId>,
) {
    orphans.extend(v.iter().filter(|&&x| vcell[x.index()].load(Relaxed) == c.0));
}

#[cfg(test)]
mod tests {
    use super::{Ownership, FEWEST};
    use crate::delaunay::{uniform_cube, Engine};
    use crate::sort::SplitMix;
    use crate::space::{FlatTorus2, FlatTorus3, OrbitSpace};
    use std::cell::Cell;
    use std::collections::{BTreeSet, HashMap};

    thread_local! {
        /// Points the 2D chunks that ran on this thread inserted by flips, and flips they
        /// undid.
        pub(super) static FLIPPED: Cell<usize> = const { Cell::new(0) };
        pub(super) static UNDONE: Cell<usize> = const { Cell::new(0) };
    }

    /// `items` inserted in one call on `threads`, checked valid.
    fn built<S: OrbitSpace<N>, const N: usize>(
        space: &S,
        items: &[super::Item<S::Point>],
        threads: Option<usize>,
    ) -> Engine<S, N> {
        let mut e = Engine::new(space.clone());
        e.set_threads(threads);
        let (log, flow) = e.insert_parallel(items, |_| std::ops::ControlFlow::Continue(()));
        assert!(flow.is_continue());
        assert_eq!(log.events.len(), items.len());
        e.end_batch();
        assert!(e.is_valid().is_ok(), "{threads:?} threads");
        e
    }

    #[test]
    fn chunks_flip_undo_at_their_borders_and_store_the_same_on_any_thread_count() {
        // 28 000 points into the first 2048, in two waves (16 384, then the rest): dense,
        // so the chunks' flips meet each other's cells (and undo) thousands of times
        let mut r = SplitMix::new(23);
        let space = FlatTorus2::cuboid([1.0, 0.8]).unwrap();
        let mut items: Vec<super::Item<[f64; 2]>> = (0..30_000u32)
            .map(|k| {
                let p = [r.unit(), 0.8 * r.unit()];
                (k, p, 0.0, space.spatial_key(&p))
            })
            .collect();
        items[..2048].sort_by_key(|it| it.3);
        items[2048..].sort_by_key(|it| it.3);
        let build = |threads| built(&space, &items, threads);
        // (by input tag: the parallel build numbers vertices in curve order)
        let tag: HashMap<[u64; 2], u32> = items
            .iter()
            .map(|it| (it.1.map(f64::to_bits), it.0))
            .collect();
        let triangles = |e: &Engine<FlatTorus2, 3>| -> BTreeSet<[u32; 3]> {
            e.tds
                .ids()
                .map(|c| {
                    let cell = e.tds.cell(c);
                    let mut t = cell
                        .v
                        .map(|v| e.points[v.index()])
                        .map(|p| tag[&p.map(f64::to_bits)]);
                    t.sort_unstable();
                    t
                })
                .collect()
        };
        let alone = build(None);
        // (one thread runs the chunks on this one)
        let (flipped, undone) = (FLIPPED.get(), UNDONE.get());
        let one = build(Some(1));
        assert!(FLIPPED.get() >= flipped + 20_000, "the chunks flip");
        assert!(UNDONE.get() >= undone + 100, "and undo at their borders");
        assert_eq!(one.tds.len(), 2 * 30_000);
        assert_eq!(triangles(&one), triangles(&alone));
        for threads in [2, 3] {
            assert!(
                build(Some(threads)).tds.cells == one.tds.cells,
                "{threads} threads"
            );
        }
    }

    #[test]
    fn a_wave_needs_threads_a_guaranteed_quotient_and_a_32nd_of_the_points() {
        let mut e = uniform_cube(4000, 3);
        assert!(e.is_one_sheeted() && e.guaranteed);
        let n = e.points.len();
        let fewest = n.div_ceil(FEWEST);
        assert!(!e.wave_ready(n), "no threads asked for");
        e.set_threads(Some(2));
        assert!(e.wave_ready(n) && e.wave_ready(fewest) && e.wave_ready(usize::MAX));
        assert!(!e.wave_ready(fewest - 1) && !e.wave_ready(0));
        e.set_threads(None);
        assert!(!e.wave_ready(fewest));
    }

    #[test]
    fn the_keys_stay_from_call_to_call_until_the_batch_ends() {
        let mut e = Engine::new(FlatTorus3::cuboid([1.0; 3]).unwrap());
        e.set_threads(Some(2));
        let mut r = SplitMix::new(5);
        let mut batch = |n: usize, e: &Engine<FlatTorus3, 4>| -> Vec<super::Item<[f64; 3]>> {
            let mut items: Vec<_> = (0..n as u32)
                .map(|k| {
                    let p = [r.unit(), r.unit(), r.unit()];
                    (k, p, 0.0, e.space.spatial_key(&p))
                })
                .collect();
            items.sort_by_key(|it| it.3);
            items
        };
        let go = |_| std::ops::ControlFlow::Continue(());
        // 2048 one at a time, then a wave: every point's key is kept
        let items = batch(5000, &e);
        assert!(e.insert_parallel(&items, go).1.is_continue());
        assert_eq!(e.wave_keys.len(), e.points.len());
        let keys: Vec<u64> = e.points.iter().map(|p| e.space.spatial_key(p)).collect();
        assert_eq!(e.wave_keys, keys);
        // too few for a wave: nothing computed, nothing dropped
        let items = batch(100, &e);
        assert!(e.insert_parallel(&items, go).1.is_continue());
        assert_eq!(e.wave_keys.len(), 5000);
        e.end_batch();
        assert!(e.wave_keys.is_empty());
        assert!(e.is_valid().is_ok());
    }

    /// The group passes (every level of 64 or more points here) keep the result: every
    /// thread count stores the same valid triangulation, slot for slot, with the cells of
    /// one at a time.
    #[test]
    fn the_border_points_go_in_by_groups_the_same_on_any_thread_count() {
        let mut r = SplitMix::new(11);
        let mut items: Vec<super::Item<[f64; 3]>> = (0..30_000u32)
            .map(|k| (k, [r.unit(), r.unit(), r.unit()], 0.0, 0))
            .collect();
        let space = FlatTorus3::cuboid([1.0; 3]).unwrap();
        for it in &mut items {
            it.3 = space.spatial_key(&it.1);
        }
        items.sort_by_key(|it| it.3);
        let build = |threads| built(&space, &items, threads);
        let alone = build(None);
        let one = build(Some(1));
        assert_eq!(one.points.len(), 30_000);
        assert_eq!(one.tds.len(), alone.tds.len());
        for threads in [2, 3] {
            assert!(
                build(Some(threads)).tds.cells == one.tds.cells,
                "{threads} threads"
            );
        }
    }

    #[test]
    fn each_chunk_owns_its_cell_stamp_and_visit_marks_and_nothing_else() {
        let shift = Ownership::shift_for(8, 100, 2);
        assert_eq!(shift, 8, "201 stamps a chunk round up to 256");
        assert_eq!(Ownership::shift_for(8, 100, 5), 9, "501 round up to 512");
        let own = Ownership {
            first: 1000,
            shift,
            level: 0,
            count: 8,
            turn: 0,
        };
        for j in 0..8 {
            assert_eq!(own.owner(own.stamp(j)), j);
            let marks: Vec<u32> = (1..).map_while(|k| own.mark(j, k)).collect();
            // every mark but the cells' stamp, all distinct and the chunk's own
            assert_eq!(marks.len(), (1 << shift) - 1);
            for (k, &m) in marks.iter().enumerate() {
                assert_eq!(own.owner(m), j);
                assert_eq!(m, own.stamp(j) + 1 + k as u32);
            }
        }
        // older stamps (visits before the pass) and stamps after the last chunk: no owner
        for s in [0, 1, 999, 1000 + (8 << shift), u32::MAX] {
            assert!(own.owner(s) >= 8, "stamp {s}");
        }
        // merged in groups of 2 and 4: a group owns its chunks' cells and marks, and its
        // own stamps and marks are its first chunk's
        for level in 1..3 {
            let group = Ownership { level, ..own };
            for j in 0..8 {
                assert_eq!(group.owner(own.stamp(j)), j >> level);
                assert_eq!(group.owner(own.mark(j, 5).unwrap()), j >> level);
                assert_eq!(group.chunk(own.stamp(j)), j);
            }
            for g in 0..8 >> level {
                assert_eq!(group.stamp(g), own.stamp(g << level));
                assert_eq!(group.mark(g, 3), own.mark(g << level, 3));
            }
            assert!(group.owner(u32::MAX) >= 8 >> level);
        }
        // two groups of four turned by a quarter (across the halves' border): chunks 6, 7,
        // 0, 1 and 2, 3, 4, 5, each group's stamps and marks its first chunk's (6 and 2)
        let turned = Ownership {
            level: 2,
            turn: 2,
            ..own
        };
        for (j, g) in [0, 0, 1, 1, 1, 1, 0, 0].into_iter().enumerate() {
            assert_eq!(turned.owner(own.stamp(j as u32)), g, "chunk {j}");
            assert_eq!(turned.owner(own.mark(j as u32, 5).unwrap()), g);
            assert_eq!(turned.chunk(own.stamp(j as u32)), j as u32);
        }
        assert_eq!(turned.stamp(0), own.stamp(6));
        assert_eq!(turned.stamp(1), own.stamp(2));
        assert_eq!(turned.mark(0, 3), own.mark(6, 3));
        for s in [0, 999, 1000 + (8 << shift), u32::MAX] {
            assert!(turned.owner(s) >= 2, "stamp {s}");
        }
        // huge chunks: capped so that the 8 chunks' stamps fit
        assert!(8u64 << Ownership::shift_for(8, usize::MAX / 4, 64) <= 1 << 30);
    }
}
