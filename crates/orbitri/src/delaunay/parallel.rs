//! The parallel bulk insertion, by deterministic reservations (Blelloch, Gu, Shun and Sun,
//! *Parallelism in randomized incremental algorithms*, 2016).
//!
//! The points arrive in BRIO + Hilbert order. After a short sequential start they go in
//! waves (the next as many points as there are, so that each wave at most doubles the
//! triangulation). A wave is cut into chunks of consecutive points along the curve, and
//! works in rounds that take the next point of every chunk, points far apart from each
//! other. A round has three parallel steps, over the chunks:
//!
//! 1. **probe**: each point locates itself (walking from its chunk's last insertion) and
//!    collects its conflict region and the cells across its boundary, only reading the
//!    triangulation; then it reserves every cell it would change (an atomic minimum of its
//!    chunk's number, per cell);
//! 2. **check**: a point wins when it holds all its reservations;
//! 3. **commit**: winners star their regions at once, each writing only cells it reserved;
//!    the others try again in the next round.
//!
//! Between the steps one thread gives the winners their point ids and new cell slots, in
//! chunk order. Nothing depends on the number of threads or on timing: the same points win
//! in the same rounds and get the same ids and cells, so every thread count builds the same
//! stored triangulation, slot for slot, and writes the same files. (And since the perturbed
//! Delaunay triangulation is unique, it has the cells of a sequential build.)
//!
//! A point that would hide vertices (on the sphere, a point inside the hull of others) is
//! inserted alone after its round, by the sequential code. Weighted triangulations, and
//! triangulations still in a covering or without the switch criterion, insert sequentially.

use std::ops::ControlFlow;
use std::sync::atomic::Ordering::{AcqRel, Acquire, Relaxed, Release};
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicU32, AtomicUsize};

use super::{Engine, HiddenPoint, Inserted};
use crate::ids::{CellId, PointId, VertexId};
use crate::sort::SplitMix;
use crate::space::OrbitSpace;
use crate::tds::Cell;

/// Points inserted one by one before the waves (their regions would overlap).
const SEQUENTIAL_START: usize = 2048;
/// Points per chunk of a wave, at least.
const CHUNK: usize = 32;
/// Chunks per wave, at most, whatever the number of threads (the schedule, and so the
/// stored triangulation, must not depend on it): few enough that the cells, points and
/// buffers of each thread's chunks stay in its caches from one round to the next (one
/// thread took 1.2× longer with 1024 chunks than with 64), enough to keep some 16 threads
/// busy.
const MAX_CHUNKS: usize = 64;
/// Points per segment with threads (one at a time: 4096): `progress` is called between
/// segments, and waves end with them.
const SEGMENT: usize = 1 << 16;
/// Cell slots given to a chunk at a time for its new cells.
const BLOCK: usize = 64;
/// A free reservation.
const FREE: u32 = u32::MAX;

/// One point to insert: a tag for the caller, the point, its weight (ignored unless the
/// triangulation is weighted) and its spatial key.
pub type Item<P> = (u32, P, f64, u64);

/// What became of the items, in the order in which a sequential insertion would have told
/// it: `(index of the item, result, end of its hidden points in `hidden`)`. New points appear in the order
/// of their ids, and each point's hidden points (those its insertion hid, as in
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
}

/// What a round's probe found for a chunk's point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Found {
    /// The point coincides with this one.
    Duplicate(PointId),
    /// Its power cell is empty.
    Hidden,
    /// Its insertion would hide vertices: the sequential code inserts it after the round.
    Alone,
    /// Its conflict region is collected and reserved.
    Region,
}

/// A small hash map from cell ids to their place in the region (`OUTSIDE` for a cell across
/// its boundary), cleared in time proportional to its entries.
#[derive(Debug)]
struct Marks {
    keys: Vec<CellId>,
    values: Vec<u32>,
    used: Vec<u32>,
}

const OUTSIDE: u32 = u32::MAX;

impl Marks {
    fn new() -> Self {
        Marks {
            keys: vec![CellId::NONE; 256],
            values: vec![0; 256],
            used: Vec::new(),
        }
    }

    #[inline]
    fn slot_of(&self, c: CellId) -> usize {
        let mask = self.keys.len() - 1;
        let mut h = (c.0.wrapping_mul(0x9E37_79B1) >> 7) as usize & mask;
        while self.keys[h] != c && self.keys[h] != CellId::NONE {
            h = (h + 1) & mask;
        }
        h
    }

    #[inline]
    fn get(&self, c: CellId) -> Option<u32> {
        let h = self.slot_of(c);
        (self.keys[h] == c).then(|| self.values[h])
    }

    fn insert(&mut self, c: CellId, value: u32) {
        if 2 * (self.used.len() + 1) > self.keys.len() {
            let entries: Vec<(CellId, u32)> = self
                .used
                .iter()
                .map(|&h| (self.keys[h as usize], self.values[h as usize]))
                .collect();
            let size = 2 * self.keys.len();
            *self = Marks {
                keys: vec![CellId::NONE; size],
                values: vec![0; size],
                used: Vec::new(),
            };
            for (k, v) in entries {
                self.insert(k, v);
            }
        }
        let h = self.slot_of(c);
        self.keys[h] = c;
        self.values[h] = value;
        self.used.push(h as u32);
    }

    fn clear(&mut self) {
        for &h in &self.used {
            self.keys[h as usize] = CellId::NONE;
        }
        self.used.clear();
    }
}

/// A chunk of a wave: its items `next..end`, its last insertion, and what the current
/// round found for its next point.
#[derive(Debug)]
struct Chunk<O, const N: usize> {
    next: usize,
    end: usize,
    /// The cell of the chunk's last insertion, its vertices (a reused slot fails the check)
    /// and the shift that lifts a point near it into its frame.
    hint: Option<(CellId, [VertexId; N], O)>,
    found: Found,
    won: bool,
    /// The region: cells with the point's offset in each one's frame, in search order.
    conflict: Vec<(CellId, O)>,
    /// Its boundary facets: (index into `conflict`, facet).
    boundary: Vec<(u32, u8)>,
    /// Per boundary facet: the cell across and the facet's index there.
    across: Vec<(CellId, u8)>,
    marks: Marks,
    /// Winners: the point's id and the first of its new cell slots past the region's own.
    point: PointId,
    extra: usize,
    /// Free slots kept for the chunk's new cells (so that its cells lie together in
    /// memory, as a sequential insertion's do).
    block: std::ops::Range<usize>,
    /// Buffers of `commit`: the region's cells as they were, the new cells, their slots and,
    /// per region cell and facet, the new cell on it.
    old: Vec<Cell<O, N>>,
    fresh: Vec<Cell<O, N>>,
    ids: Vec<CellId>,
    on_facet: Vec<[u32; N]>,
}

impl<O, const N: usize> Chunk<O, N> {
    /// The chunk of items `range`.
    fn new(range: std::ops::Range<usize>) -> Self {
        Chunk {
            next: range.start,
            end: range.end,
            hint: None,
            found: Found::Hidden,
            won: false,
            conflict: Vec::new(),
            boundary: Vec::new(),
            across: Vec::new(),
            marks: Marks::new(),
            point: PointId::NONE,
            extra: 0,
            block: 0..0,
            old: Vec::new(),
            fresh: Vec::new(),
            ids: Vec::new(),
            on_facet: Vec::new(),
        }
    }
}

/// The cell store, written by several winners at once, each only in the slots it reserved.
struct SharedCells<O, const N: usize> {
    base: *mut Cell<O, N>,
    len: usize,
}

// SAFETY: winners write disjoint slots (their reservations) and read only those.
unsafe impl<O: Send, const N: usize> Sync for SharedCells<O, N> {}

impl<O: Copy, const N: usize> SharedCells<O, N> {
    /// # Safety
    /// No other thread accesses slot `c` meanwhile.
    #[inline]
    unsafe fn get(&self, c: CellId) -> *mut Cell<O, N> {
        assert!(c.index() < self.len);
        self.base.add(c.index())
    }
}

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// Bulk insertions ([`Self::insert_parallel`]) run in parallel rounds on `threads`
    /// threads (at least one), or one by one for `None` (the default).
    pub fn set_threads(&mut self, threads: Option<usize>) {
        self.threads = threads.map_or(0, |n| n.max(1));
    }

    /// The threads of the parallel bulk insertion, if any ([`Self::set_threads`]).
    pub fn threads(&self) -> Option<usize> {
        (self.threads > 0).then_some(self.threads)
    }

    /// True when the next insertions may run in parallel: a 1-sheeted, unweighted
    /// triangulation whose switch criterion holds, large enough that regions seldom meet.
    fn parallel_ready(&self) -> bool {
        self.threads > 0
            && self.one_sheeted
            && self.guaranteed
            && !self.weighted
            && self.points.len() >= SEQUENTIAL_START
    }

    /// Inserts `items` in their order: one by one, or once [`Self::set_threads`] asked
    /// for threads, in parallel rounds where the triangulation allows (see the module's
    /// comment). The triangulation is that of inserting them one by one; with threads, it
    /// is stored the same, slot for slot, whatever their number. `progress` is called with
    /// the number of items done: with 0 first, then every 4096 items (65 536 with threads;
    /// not at the end); [`ControlFlow::Break`] stops the insertion (the items not yet done
    /// are not in the log).
    pub fn insert_parallel(
        &mut self,
        items: &[Item<S::Point>],
        mut progress: impl FnMut(usize) -> ControlFlow<()>,
    ) -> (Log<S::Point>, ControlFlow<()>) {
        let mut log = Log {
            events: Vec::with_capacity(items.len()),
            hidden: Vec::new(),
        };
        let mut owner: Vec<AtomicU32> = Vec::new();
        let threads = self.threads;
        let mut k = 0;
        while k < items.len() {
            if progress(k).is_break() {
                return (log, ControlFlow::Break(()));
            }
            let segment = if threads > 0 { SEGMENT } else { 4096 };
            let end = (k + segment).min(items.len());
            while k < end {
                if !self.parallel_ready() {
                    self.insert_alone(items, k, &mut log);
                    k += 1;
                    continue;
                }
                let m = (end - k).min(self.points.len());
                self.wave(&items[..k + m], k, threads, &mut owner, &mut log);
                k += m;
            }
        }
        (log, ControlFlow::Continue(()))
    }

    /// Inserts item `k` with the sequential code and logs it.
    fn insert_alone(&mut self, items: &[Item<S::Point>], k: usize, log: &mut Log<S::Point>) {
        let (_, p, w, key) = items[k];
        let r = self.insert_keyed(p, w, key);
        log.hidden.append(&mut self.hidden_log);
        log.events.push((k as u32, r, log.hidden.len() as u32));
    }

    /// One wave: `items[first..]` in rounds over its chunks, by `threads` threads, each
    /// with its own run of chunks (their cells stay in its caches), meeting at a spinning
    /// barrier between the steps (a round takes some ten microseconds per thread: handing
    /// each step to a pool would cost more).
    fn wave(
        &mut self,
        items: &[Item<S::Point>],
        first: usize,
        threads: usize,
        owner: &mut Vec<AtomicU32>,
        log: &mut Log<S::Point>,
    ) {
        let m = items.len() - first;
        let k = (m / CHUNK).clamp(1, MAX_CHUNKS);
        let mut chunks: Vec<Chunk<S::Elem, N>> = (0..k)
            .map(|j| Chunk::new(first + j * m / k..first + (j + 1) * m / k))
            .collect();
        let threads = threads.min(k);
        let mut spares = Vec::new();
        owner.resize_with(self.tds.cells.len(), || AtomicU32::new(FREE));
        let wave = Wave {
            engine: self,
            chunks: chunks.as_mut_ptr(),
            owner,
            log,
            items,
            runs: (0..=threads).map(|t| t * k / threads).collect(),
            barrier: SpinBarrier::new(threads),
            stop: AtomicBool::new(false),
            alone: AtomicBool::new(false),
            cells: AtomicPtr::new(std::ptr::null_mut()),
            vcell: AtomicPtr::new(std::ptr::null_mut()),
            spares: &mut spares,
            poisoned: AtomicBool::new(false),
        };
        std::thread::scope(|s| {
            for t in 1..threads {
                let wave = &wave;
                s.spawn(move || wave.run(t));
            }
            wave.run(0);
        });
        let unused = chunks.iter_mut().flat_map(|c| std::mem::take(&mut c.block));
        for d in spares.into_iter().chain(unused.map(CellId::new)) {
            self.tds.delete(d);
        }
        // (a sequential insertion lost the criterion: the rest one by one)
        for c in &chunks {
            for k in c.next..c.end {
                self.insert_alone(items, k, log);
            }
        }
    }

    /// The probe of a round: locates the chunk's next point and collects its region (only
    /// reading the triangulation).
    fn probe(&self, (_, p, _, key): Item<S::Point>, ch: &mut Chunk<S::Elem, N>) {
        let start = ch
            .hint
            .filter(|&(c, v, _)| self.tds.is_alive(c) && self.tds.cells[c.index()].v == v)
            .map(|(c, _, shift)| (c, shift))
            .or_else(|| self.jump(key))
            .unwrap_or_else(|| self.start_cell());
        let mut rng = SplitMix::new(key);
        let (c0, q0) = self.walk((p, start.1), start.0, &mut rng);
        for i in 0..N {
            let v = self.tds.cells[c0.index()].v[i];
            if self.space.coincide(self.lifted(c0, i), (p, q0)) {
                ch.found = Found::Duplicate(self.vpoint[v.index()]);
                return;
            }
        }
        if self.hides() && !self.cell_conflicts(c0, (p, q0), 0.0) {
            ch.found = Found::Hidden;
            return;
        }
        ch.marks.clear();
        ch.conflict.clear();
        ch.boundary.clear();
        ch.across.clear();
        ch.conflict.push((c0, q0));
        ch.marks.insert(c0, 0);
        let mut next = 0;
        while next < ch.conflict.len() {
            let (c, qo) = ch.conflict[next];
            for i in 0..N {
                let d = self.tds.cells[c.index()].n[i];
                match ch.marks.get(d) {
                    Some(OUTSIDE) => {}
                    Some(_) => continue,
                    None => {
                        let qd = self.space.relative(qo, self.translation(c, i, d));
                        if self.cell_conflicts(d, (p, qd), 0.0) {
                            ch.marks.insert(d, ch.conflict.len() as u32);
                            ch.conflict.push((d, qd));
                            continue;
                        }
                        ch.marks.insert(d, OUTSIDE);
                    }
                }
                let j = self.tds.cells[d.index()]
                    .mirror(c)
                    .expect("symmetric neighbours");
                ch.boundary.push((next as u32, i as u8));
                ch.across.push((d, j as u8));
            }
            next += 1;
        }
        ch.found = if self.hides() && self.region_hides(ch) {
            Found::Alone
        } else {
            Found::Region
        };
    }

    /// True when a vertex of the region lies on none of its boundary facets (starring it
    /// would hide that vertex).
    fn region_hides(&self, ch: &Chunk<S::Elem, N>) -> bool {
        if N == 3 {
            // a disk of `C` triangles and `B` boundary edges has `1 + (C − B)/2` inner
            // vertices
            return ch.conflict.len() + 2 != ch.boundary.len();
        }
        let on_boundary = |v: VertexId| {
            ch.boundary.iter().any(|&(ci, i)| {
                let cell = &self.tds.cells[ch.conflict[ci as usize].0.index()];
                cell.v
                    .iter()
                    .enumerate()
                    .any(|(k, &w)| k != i as usize && w == v)
            })
        };
        ch.conflict
            .iter()
            .any(|&(c, _)| self.tds.cells[c.index()].v.iter().any(|&v| !on_boundary(v)))
    }
}

/// The state of a wave shared by its threads. Between barriers, either every thread reads
/// the engine and works on its own run of chunks (`runs[t]..runs[t + 1]`), or thread 0
/// alone changes the engine, the chunks, the reservations and the log.
struct Wave<'a, S: OrbitSpace<N>, const N: usize> {
    engine: *mut Engine<S, N>,
    chunks: *mut Chunk<S::Elem, N>,
    owner: *mut Vec<AtomicU32>,
    log: *mut Log<S::Point>,
    items: &'a [Item<S::Point>],
    runs: Vec<usize>,
    barrier: SpinBarrier,
    /// Set by thread 0: the wave is over (every chunk done, or the triangulation no
    /// longer allows parallel insertion).
    stop: AtomicBool,
    /// Set by thread 0: some point of the round is inserted alone after the commits.
    alone: AtomicBool,
    /// The cell store and the vertices' cells, as thread 0 left them for the commits.
    cells: AtomicPtr<Cell<S::Elem, N>>,
    vcell: AtomicPtr<CellId>,
    /// The slots of the round's regions that no new cell took, for the free list.
    spares: *mut Vec<CellId>,
    /// Set when a thread panics: the others stop waiting for it.
    poisoned: AtomicBool,
}

// SAFETY: the barrier separates the steps in which the threads share the state read-only
// (or write disjoint parts of it) from those in which thread 0 alone changes it.
unsafe impl<S: OrbitSpace<N>, const N: usize> Sync for Wave<'_, S, N> {}

impl<S: OrbitSpace<N>, const N: usize> Wave<'_, S, N> {
    /// Thread `t`'s rounds.
    fn run(&self, t: usize) {
        /// Marks the wave poisoned when its thread unwinds.
        struct Poison<'a>(&'a AtomicBool);
        impl Drop for Poison<'_> {
            fn drop(&mut self) {
                if std::thread::panicking() {
                    self.0.store(true, Relaxed);
                }
            }
        }
        let _poison = Poison(&self.poisoned);
        let (lo, hi) = (self.runs[t], self.runs[t + 1]);
        while !self.stop.load(Relaxed) {
            // 1. probe and reserve
            {
                // SAFETY: the engine and reservations are only read here, and the chunks
                // `lo..hi` are this thread's.
                let (engine, owner) = unsafe { (&*self.engine, &*self.owner) };
                let chunks =
                    unsafe { std::slice::from_raw_parts_mut(self.chunks.add(lo), hi - lo) };
                for (j, c) in (lo..).zip(chunks.iter_mut()) {
                    if c.next == c.end {
                        continue;
                    }
                    engine.probe(self.items[c.next], c);
                    if c.found == Found::Region {
                        for &(d, _) in &c.conflict {
                            owner[d.index()].fetch_min(j as u32, Relaxed);
                        }
                        for &(d, _) in &c.across {
                            owner[d.index()].fetch_min(j as u32, Relaxed);
                        }
                    }
                }
            }
            self.barrier.wait(&self.poisoned);
            // 2. check, ids and slots
            if t == 0 {
                // SAFETY: the other threads wait at the barrier.
                unsafe { self.settle() };
            }
            self.barrier.wait(&self.poisoned);
            if self.stop.load(Relaxed) {
                return;
            }
            // 3. commit
            {
                // SAFETY: `settle` sized the store; winners touch only what they reserved.
                let engine = unsafe { &*self.engine };
                let owner = unsafe { &*self.owner };
                let cells = SharedCells {
                    base: self.cells.load(Relaxed),
                    len: owner.len(),
                };
                // SAFETY: `AtomicU32` has the layout of `u32`, and so of `CellId`; the
                // pointer comes from a mutable borrow (`settle`).
                let vcell: &[AtomicU32] = unsafe {
                    std::slice::from_raw_parts(self.vcell.load(Relaxed).cast(), engine.vcell.len())
                };
                let chunks =
                    unsafe { std::slice::from_raw_parts_mut(self.chunks.add(lo), hi - lo) };
                for (j, c) in (lo..).zip(chunks.iter_mut()) {
                    if c.next == c.end {
                        continue;
                    }
                    if c.won {
                        unsafe { commit(&engine.space, engine.level, &cells, vcell, c) };
                    }
                    if c.found == Found::Region {
                        let free = |d: &CellId| {
                            let _ =
                                owner[d.index()].compare_exchange(j as u32, FREE, Relaxed, Relaxed);
                        };
                        c.conflict.iter().for_each(|(d, _)| free(d));
                        c.across.iter().for_each(|(d, _)| free(d));
                    }
                    if c.won || matches!(c.found, Found::Duplicate(_) | Found::Hidden) {
                        c.next += 1;
                    }
                }
            }
            self.barrier.wait(&self.poisoned);
            // 4. the points inserted alone
            if self.alone.load(Relaxed) {
                if t == 0 {
                    // SAFETY: the other threads wait at the barrier.
                    unsafe { self.insert_alone() };
                }
                self.barrier.wait(&self.poisoned);
            }
        }
    }

    /// Thread 0 between the probes and the commits: decides the winners, gives them point
    /// ids and cell slots in chunk order, logs the round and notes the new vertices in the
    /// grid.
    ///
    /// # Safety
    /// The other threads wait at the barrier.
    unsafe fn settle(&self) {
        let engine = &mut *self.engine;
        let owner = &mut *self.owner;
        let log = &mut *self.log;
        let spares = &mut *self.spares;
        // (the last round's spare slots, which its winners marked dead)
        for d in spares.drain(..) {
            engine.tds.delete(d);
        }
        let chunks = std::slice::from_raw_parts_mut(self.chunks, self.runs[self.runs.len() - 1]);
        let mut active = false;
        let mut alone = false;
        for (j, c) in chunks.iter_mut().enumerate() {
            let live = c.next < c.end;
            active |= live;
            let mine = |d: &CellId| owner[d.index()].load(Relaxed) == j as u32;
            c.won = live
                && c.found == Found::Region
                && c.conflict.iter().all(|(d, _)| mine(d))
                && c.across.iter().all(|(d, _)| mine(d));
            alone |= live && c.found == Found::Alone;
        }
        if !active {
            self.stop.store(true, Relaxed);
        }
        self.alone.store(alone, Relaxed);
        let mut slots = engine.tds.cells.len();
        for c in chunks.iter_mut().filter(|c| c.won) {
            let (_, p, _, key) = self.items[c.next];
            c.point = PointId::new(engine.points.len());
            engine.push_point(p, 0.0);
            engine.vpoint.push(c.point);
            engine.vcell.push(CellId::NONE);
            engine.note_vertex(VertexId(c.point.0), key);
            log.events.push((
                c.next as u32,
                Inserted::New(c.point),
                log.hidden.len() as u32,
            ));
            // (in 3D a ball of `C` cells around `E` inner edges has `2C + 2 − 2E` boundary
            // facets: the new cells may be fewer than the old, whose spare slots are freed)
            let extra = c.boundary.len().saturating_sub(c.conflict.len());
            if c.block.len() < extra {
                spares.extend(c.block.clone().map(CellId::new));
                c.block = slots..slots + extra.max(BLOCK);
                slots = c.block.end;
            }
            c.extra = c.block.start;
            c.block.start += extra;
            spares.extend(c.conflict.iter().skip(c.boundary.len()).map(|&(d, _)| d));
        }
        for c in chunks.iter().filter(|c| c.next < c.end) {
            let r = match c.found {
                Found::Duplicate(p) => Inserted::Duplicate(p),
                Found::Hidden => Inserted::Hidden,
                _ => continue,
            };
            log.events.push((c.next as u32, r, log.hidden.len() as u32));
        }
        let dead = Cell::new([VertexId::NONE; N], [engine.space.identity(); N]);
        engine.tds.cells.resize(slots, dead);
        owner.resize_with(slots, || AtomicU32::new(FREE));
        self.cells.store(engine.tds.cells.as_mut_ptr(), Relaxed);
        self.vcell.store(engine.vcell.as_mut_ptr(), Relaxed);
    }

    /// Thread 0 after the commits: inserts the round's points that would hide vertices,
    /// one by one, and stops the wave if the triangulation no longer allows parallel
    /// insertion.
    ///
    /// # Safety
    /// The other threads wait at the barrier.
    unsafe fn insert_alone(&self) {
        let engine = &mut *self.engine;
        let chunks = std::slice::from_raw_parts_mut(self.chunks, self.runs[self.runs.len() - 1]);
        for c in chunks.iter_mut() {
            if c.next < c.end && c.found == Found::Alone {
                engine.insert_alone(self.items, c.next, &mut *self.log);
                c.next += 1;
                c.hint = None;
            }
        }
        if !engine.parallel_ready() {
            self.stop.store(true, Relaxed);
        }
    }
}

/// A barrier for the threads of a wave that spins (its steps are short), yielding the
/// processor after a while (when threads outnumber free cores).
struct SpinBarrier {
    threads: usize,
    count: AtomicUsize,
    generation: AtomicUsize,
}

impl SpinBarrier {
    fn new(threads: usize) -> Self {
        SpinBarrier {
            threads,
            count: AtomicUsize::new(0),
            generation: AtomicUsize::new(0),
        }
    }

    /// Waits for every thread; what each did before is visible to all after. Panics when
    /// `poisoned` is set (a thread that will never come panicked).
    fn wait(&self, poisoned: &AtomicBool) {
        let generation = self.generation.load(Acquire);
        if self.count.fetch_add(1, AcqRel) + 1 == self.threads {
            self.count.store(0, Relaxed);
            self.generation.store(generation + 1, Release);
            return;
        }
        let mut spins = 0u32;
        while self.generation.load(Acquire) == generation {
            assert!(
                !poisoned.load(Relaxed),
                "another thread of the wave panicked"
            );
            if spins < 1 << 12 {
                std::hint::spin_loop();
                spins += 1;
            } else {
                std::thread::yield_now();
            }
        }
    }
}

/// Stars a winner's region from its new vertex: the new cells take the region's slots
/// (those left over are marked dead here, and freed by the next `settle`), then slots
/// `extra..`; they are linked to the cells across the boundary and, around each
/// new ridge, to each other by rotating through the region (read from local copies, since
/// the slots are overwritten). Vertices whose cell was in the region point at a new cell.
///
/// # Safety
/// The chunk won its reservations: no other thread touches its region, the cells across
/// it, or its extra slots.
unsafe fn commit<S: OrbitSpace<N>, const N: usize>(
    space: &S,
    level: usize,
    cells: &SharedCells<S::Elem, N>,
    vcell: &[AtomicU32],
    ch: &mut Chunk<S::Elem, N>,
) {
    let x = VertexId(ch.point.0);
    let (mut old, mut fresh, mut ids, mut on_facet) = (
        std::mem::take(&mut ch.old),
        std::mem::take(&mut ch.fresh),
        std::mem::take(&mut ch.ids),
        std::mem::take(&mut ch.on_facet),
    );
    old.clear();
    old.extend(ch.conflict.iter().map(|&(c, _)| *cells.get(c)));
    ids.clear();
    ids.extend(
        ch.conflict
            .iter()
            .map(|&(c, _)| c)
            .chain((ch.extra..).map(CellId::new))
            .take(ch.boundary.len()),
    );
    on_facet.clear();
    on_facet.resize(old.len(), [u32::MAX; N]);
    fresh.clear();
    for (k, &(ci, i)) in ch.boundary.iter().enumerate() {
        let (ci, i) = (ci as usize, i as usize);
        on_facet[ci][i] = k as u32;
        let mut cell = old[ci];
        cell.v[i] = x;
        cell.off[i] = ch.conflict[ci].1;
        let mut cell = Cell::new(cell.v, cell.off);
        if space.normalize(&mut cell.off, level) && S::MAY_REVERSE {
            cell.swap_slots(0, 1);
        }
        let slot = cell.index_of(x).expect("the new vertex");
        cell.n[slot] = ch.across[k].0;
        fresh.push(cell);
    }
    for k in 0..fresh.len() {
        let (ci, i) = ch.boundary[k];
        for j in 0..N {
            if fresh[k].n[j] != CellId::NONE {
                continue;
            }
            let (mut u, mut w) = (old[ci as usize].v[i as usize], fresh[k].v[j]);
            let mut cur = ci as usize;
            loop {
                let cc = &old[cur];
                let kw = cc.index_of(w).expect("ridge rotation");
                match ch.marks.get(cc.n[kw]) {
                    Some(next) if next != OUTSIDE => {
                        let nb = &old[next as usize];
                        let m = nb.mirror(ch.conflict[cur].0).expect("symmetric neighbours");
                        (w, u) = (u, nb.v[m]);
                        cur = next as usize;
                    }
                    _ => {
                        let k2 = on_facet[cur][kw] as usize;
                        let ku = fresh[k2].index_of(u).expect("ridge rotation");
                        fresh[k].n[j] = ids[k2];
                        fresh[k2].n[ku] = ids[k];
                        break;
                    }
                }
            }
        }
    }
    for (k, cell) in fresh.iter().enumerate() {
        *cells.get(ids[k]) = *cell;
        let (d, jd) = ch.across[k];
        (*cells.get(d)).n[jd as usize] = ids[k];
        for &v in &cell.v {
            let was = CellId(vcell[v.index()].load(Relaxed));
            if v == x || matches!(ch.marks.get(was), Some(l) if l != OUTSIDE) {
                vcell[v.index()].store(ids[k].0, Relaxed);
            }
        }
    }
    for &(spare, _) in ch.conflict.iter().skip(fresh.len()) {
        (*cells.get(spare)).v[0] = VertexId::NONE;
    }
    let k = fresh[0].index_of(x).expect("new cells hold the new vertex");
    ch.hint = Some((
        ids[0],
        fresh[0].v,
        space.carry(space.identity(), fresh[0].off[k]),
    ));
    (ch.old, ch.fresh, ch.ids, ch.on_facet) = (old, fresh, ids, on_facet);
}
