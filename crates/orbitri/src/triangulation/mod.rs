//! `Triangulation<D, N, S>`: the Delaunay triangulation of a point set in a flat orbit space
//! `S` of dimension `D` (cells of `N = D + 1` vertices), with input bookkeeping (wrapping into
//! the domain, duplicates), bulk construction and the access API, written once for every
//! space. `PeriodicDelaunay2` and `PeriodicDelaunay3` name the flat tori, `KleinBottle`
//! and `FlatManifold3` the other closed flat manifolds.

mod complex;
mod weighted;

pub use complex::Complex;

use std::borrow::Cow;
use std::collections::{BTreeMap, HashSet};
use std::ops::ControlFlow;

use rayon::prelude::*;

use crate::delaunay::{Engine, HiddenPoint, Inserted, Invalid, Item, Moved, Removal};
use crate::error::{Error, Result};
use crate::ids::{CellId, InputId, PointId, VertexId};
use crate::sort::Brio;
use crate::space::{FlatManifold, FlatSpace, FlatTorus, OrbitSpace};

/// Offset of a vertex in lattice-vector units.
pub type Offset<const D: usize = 3> = [i8; D];

/// The flat tori the facade serves: `FlatTorus<D>` as an orbit space with cells of `N`
/// vertices, points `[f64; D]` and offsets `[i8; D]`.
pub trait Torus<const D: usize, const N: usize>:
    OrbitSpace<N, Point = [f64; D], Elem = [i8; D]> + Clone
{
}

impl<const D: usize, const N: usize> Torus<D, N> for FlatTorus<D> where
    FlatTorus<D>: OrbitSpace<N, Point = [f64; D], Elem = [i8; D]>
{
}

/// Which copies [`Triangulation::cells`] yields in a multi-sheeted covering (CGAL's iterator
/// types). Edges and facets have a method for each instead ([`Triangulation::edges`],
/// [`Triangulation::stored_edges`]), since their vertices are ids of different types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Copies {
    /// One copy per simplex of the quotient.
    Unique,
    /// Every stored simplex of the covering space.
    Stored,
}

/// A cell: input ids of its vertices and their group elements (a torus's offsets), the
/// vertex `k` lying at `offsets[k]·points[vertices[k]]`; positively oriented
/// (counter-clockwise in 2D).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CellView<const D: usize = 3, const N: usize = 4, E = Offset<D>> {
    pub vertices: [InputId; N],
    pub offsets: [E; N],
}

/// A simplex of lower dimension (edge: 2 vertices, facet: `D`), canonical modulo the group:
/// for a torus, sorted by (vertex, offset) with the componentwise minimum offset translated
/// to zero. Its vertices are input ids ([`Triangulation::edges`]), or the stored vertices of
/// a covering space (`I = VertexId`, [`Triangulation::stored_edges`]).
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Simplex<const D: usize = 3, E = Offset<D>, I = InputId> {
    pub vertices: Vec<I>,
    pub offsets: Vec<E>,
}

/// A Delaunay edge: `j`'s image `shift·points[j]` (`points[j] + shift·M` in a torus) is
/// joined to point `i`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DelaunayEdge<const D: usize, E = Offset<D>> {
    pub i: InputId,
    pub j: InputId,
    pub shift: E,
    pub length: f64,
}

/// Options of the bulk construction.
#[derive(Clone, Copy, Debug)]
pub struct BuildOptions {
    /// Start from the dummy point set when there are at least this many points.
    pub dummy_threshold: usize,
    /// Seed of the BRIO shuffle.
    pub seed: u64,
    /// Sort the points spatially (BRIO + Hilbert); otherwise insert in input order.
    pub spatial_sort: bool,
    /// Insert in parallel on this many threads (the triangulation is stored the
    /// same, slot for slot, whatever their number); `None`: one by one.
    pub threads: Option<usize>,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            dummy_threshold: 1000,
            seed: 0x0b17,
            spatial_sort: true,
            threads: None,
        }
    }
}

/// The Delaunay triangulation of a point set in the flat orbit space `S` of dimension `D`.
#[derive(Debug)]
pub struct Triangulation<const D: usize, const N: usize, S: FlatSpace<D, N> = FlatTorus<D>> {
    engine: Engine<S, N>,
    /// Input → its point (a vertex of the quotient).
    input_point: Vec<PointId>,
    /// Point → the input id of its first occurrence.
    point_input: Vec<InputId>,
    wrapped: usize,
    duplicates: usize,
    used_dummies: bool,
    /// Removals that had to triangulate the remaining points again (see [`Removal`]).
    rebuilds: usize,
    /// Weighted: each input's weight, in user units (empty when unweighted).
    input_weight: Vec<f64>,
    /// Weighted: the hidden inputs (their `input_point` is [`HIDDEN`]), each with its
    /// wrapped point and weight in the internal frame, to come back when uncovered.
    hidden: BTreeMap<InputId, ([f64; D], f64)>,
    /// Weighted: the least and largest internal weight given; the space's coverings are
    /// for their spread (see [`Self::widen`]).
    weight_range: (f64, f64),
}

/// `input_point` of a hidden input.
const HIDDEN: PointId = PointId(u32::MAX - 1);

/// The periodic Delaunay triangulation of a flat torus of dimension `D`.
pub type PeriodicDelaunay<const D: usize, const N: usize> = Triangulation<D, N, FlatTorus<D>>;
/// The periodic Delaunay triangulation of a 2D flat torus.
pub type PeriodicDelaunay2 = PeriodicDelaunay<2, 3>;
/// The periodic Delaunay triangulation of a 3D flat torus.
pub type PeriodicDelaunay3 = PeriodicDelaunay<3, 4>;
/// The Delaunay triangulation of a Klein bottle (a 2D flat manifold).
pub type KleinTriangulation = Triangulation<2, 3, FlatManifold<2>>;
/// The Delaunay triangulation of a closed flat 3-manifold.
pub type ManifoldTriangulation3 = Triangulation<3, 4, FlatManifold<3>>;

/// Input point `i` in the internal frame of the lattice, wrapped into the domain, and whether
/// wrapping moved it; an error names a non-finite coordinate or a point out of reach.
fn internal_point<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    space: &S,
    i: usize,
    p: &[f64; D],
) -> Result<([f64; D], bool)> {
    for (axis, v) in p.iter().enumerate() {
        if !v.is_finite() {
            return Err(Error::NonFiniteCoordinate {
                index: i,
                axis,
                value: *v,
            });
        }
    }
    space.canonical_point(p).ok_or_else(|| Error::OutOfReach {
        index: i,
        coordinates: format!("{p:?}"),
    })
}

/// Every point of `points` in the internal frame, wrapped (an error names the first bad
/// one by its index in `points`), and how many wrapping moved. Borrowed when every point is
/// already internal and in place (a unit box's points inside it): a copy of 10⁶ points in
/// 3D is 24 MB of a build's peak. (Checked on rayon's pool: 13 ms of a build of 10⁶ points
/// in a square on one thread.)
fn internal_points<'a, const D: usize, const N: usize, S: FlatSpace<D, N>>(
    space: &S,
    points: &'a [[f64; D]],
) -> Result<(Cow<'a, [[f64; D]]>, usize)> {
    let same =
        |a: &[f64; D], b: &[f64; D]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    // (how many moved, the first bad point, the first one not in place)
    let none = usize::MAX;
    let (moved, bad, changed) = points
        .par_iter()
        .enumerate()
        .with_min_len(1 << 12)
        .map(|(i, p)| match internal_point(space, i, p) {
            Ok((w, m)) => (usize::from(m), none, if same(&w, p) { none } else { i }),
            Err(_) => (0, i, none),
        })
        .reduce(
            || (0, none, none),
            |a, b| (a.0 + b.0, a.1.min(b.1), a.2.min(b.2)),
        );
    if bad != none {
        return Err(internal_point(space, bad, &points[bad]).expect_err("a bad point"));
    }
    if changed == none {
        return Ok((Cow::Borrowed(points), moved));
    }
    let copy = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| internal_point(space, i, p).map(|(w, _)| w))
        .collect::<Result<Vec<_>>>()?;
    Ok((Cow::Owned(copy), moved))
}

/// The indices of internal points in Hilbert order (a batch of moves or queries: each
/// next one near the previous).
fn hilbert_order<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    space: &S,
    points: &[[f64; D]],
) -> Vec<u32> {
    let keys: Vec<u64> = points.par_iter().map(|p| space.spatial_key(p)).collect();
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.par_sort_unstable_by_key(|&k| keys[k as usize]);
    order
}

/// The dummy points of a bulk build (points `0..k`) of `n` points leave as soon as their
/// removal keeps the switch criterion, tried after each BRIO round from `8k` points on,
/// while their stars are small, but not after the last (the build's end removes them);
/// after a try that removes none from `64k` points on, they wait for the end (points in a
/// slab beside a vacuum, whose dummies there never leave the quotient).
struct Leaving {
    k: usize,
    n: usize,
    trying: bool,
}

impl Leaving {
    fn new(k: usize, n: usize) -> Self {
        Leaving {
            k,
            n,
            trying: k > 0,
        }
    }

    /// After a round, `done` points inserted.
    fn after_round<S: OrbitSpace<N>, const N: usize>(&mut self, e: &mut Engine<S, N>, done: usize) {
        if self.trying && done >= 8 * self.k && done < self.n {
            let gone = e.dummies_leave(self.k);
            self.trying = gone > 0 || done < 64 * self.k;
        }
    }
}

/// Reports progress `k` to the build's callback: `Err(Interrupted)` if it asks to stop.
fn proceed(progress: &mut impl FnMut(usize) -> ControlFlow<()>, k: usize) -> Result<()> {
    match progress(k) {
        ControlFlow::Continue(()) => Ok(()),
        ControlFlow::Break(()) => Err(Error::Interrupted),
    }
}

impl<const D: usize, const N: usize, S: FlatSpace<D, N>> Triangulation<D, N, S> {
    /// An empty triangulation of the space.
    pub fn new(space: S) -> Self {
        Triangulation {
            engine: Engine::new(space),
            input_point: Vec::new(),
            point_input: Vec::new(),
            wrapped: 0,
            duplicates: 0,
            used_dummies: false,
            rebuilds: 0,
            input_weight: Vec::new(),
            hidden: BTreeMap::new(),
            weight_range: (f64::INFINITY, f64::NEG_INFINITY),
        }
    }

    /// Builds the triangulation of `points` (wrapped into the domain first).
    pub fn build(space: S, points: &[[f64; D]]) -> Result<Self> {
        Self::build_with(space, points, BuildOptions::default(), |_| {
            ControlFlow::Continue(())
        })
    }

    /// Bulk construction: spatial sort (BRIO + Hilbert); for large inputs start from the
    /// dummy point set in the 1-sheeted torus and remove the dummies as soon as the points
    /// keep the switch criterion without them (after a round) or at the end, otherwise (or
    /// if removing a dummy would break the criterion) insert into the covering space.
    ///
    /// `progress` is called with the number of points inserted so far: before the first,
    /// every 4096 points (with threads: after each wave, the
    /// next as many points as there are) and at the end. Returning
    /// [`ControlFlow::Break`] stops the construction, which then returns
    /// [`Error::Interrupted`] (a cancellation hook: keep the callback cheap, it runs between
    /// insertions).
    ///
    /// ```
    /// use std::ops::ControlFlow;
    /// use orbitri::{BuildOptions, Error, FlatTorus2, PeriodicDelaunay2};
    /// let pts: Vec<[f64; 2]> = (0..10_000)
    ///     .map(|i| [(i as f64 * 0.618034) % 1.0, (i as f64 * 0.414214) % 1.0])
    ///     .collect();
    /// let torus = FlatTorus2::cuboid([1.0, 1.0]).unwrap();
    /// let stop_after_half = |k: usize| {
    ///     if k >= 5_000 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
    /// };
    /// let r = PeriodicDelaunay2::build_with(torus, &pts, BuildOptions::default(), stop_after_half);
    /// assert!(matches!(r, Err(Error::Interrupted)));
    /// ```
    pub fn build_with(
        space: S,
        points: &[[f64; D]],
        opts: BuildOptions,
        progress: impl FnMut(usize) -> ControlFlow<()>,
    ) -> Result<Self> {
        Self::build_inner(Self::new(space), points, &[], opts, progress)
    }

    /// The bulk construction of `points` with `weights` (internal frame, one per point, or
    /// none when unweighted) into the empty `tri`, whose space and engine are set up.
    fn build_inner(
        empty: Self,
        points: &[[f64; D]],
        weights: &[f64],
        opts: BuildOptions,
        mut progress: impl FnMut(usize) -> ControlFlow<()>,
    ) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::EmptyInput);
        }
        let space = empty.space().clone();
        let (wrapped_pts, wrapped) = internal_points(&space, points)?;
        let seed = opts.spatial_sort.then_some(opts.seed);
        let fresh = || {
            let mut tri = empty.emptied();
            tri.wrapped = wrapped;
            tri
        };
        let mut tri = fresh();
        tri.engine.set_threads(opts.threads);
        // a Delaunay triangulation of uniform points has about 6.77 cells per vertex in 3D,
        // exactly 2 in 2D
        let per_point = if D == 3 { 27 } else { 8 };
        tri.engine
            .reserve(points.len() + 128, points.len() * per_point / 4 + 4096);
        if points.len() < opts.dummy_threshold
            || !tri.build_from_dummies(&wrapped_pts, weights, seed, &mut progress)?
        {
            tri = fresh();
            tri.engine.set_threads(opts.threads);
            tri.input_point = vec![PointId::NONE; points.len()];
            tri.insert_ordered(
                (&wrapped_pts, weights),
                seed,
                (0, 0),
                &mut progress,
                |_, _| true,
            )?;
        }
        // (a covering: the points' own, or where the last dummy points left)
        tri.engine.try_one_sheet();
        tri.represent_first_occurrences(&wrapped_pts);
        proceed(&mut progress, points.len())?;
        Ok(tri)
    }

    /// After a build in spatial order: every point that met duplicates takes the wrapped
    /// coordinates of its first occurrence, as the output formats promise (offsets are
    /// relative to input `i`'s wrapped point). Duplicates can differ from it by an exact
    /// lattice translation, which the offsets of the point's star absorb.
    fn represent_first_occurrences(&mut self, wrapped: &[[f64; D]]) {
        if self.duplicates == 0 {
            // (every point holds its only input's wrapped coordinates)
            return;
        }
        for p in 0..self.point_input.len() {
            // (the inputs in a random order: loaded ahead)
            let ahead = self.point_input.get(p + Self::AHEAD);
            if let Some(w) = ahead.and_then(|i| wrapped.get(i.index())) {
                crate::tds::prefetch(w);
            }
            self.represent(PointId::new(p), wrapped[self.point_input[p].index()]);
        }
    }

    /// Gives point `p` the wrapped coordinates `want` of its first occurrence, when they
    /// differ from the current ones by an exact group element.
    fn represent(&mut self, p: PointId, want: [f64; D]) {
        let have = self.engine.points()[p.index()];
        if want == have {
            return;
        }
        let g = self.space().relating(want, have);
        debug_assert!(g.is_some(), "a duplicate is an exact image");
        if let Some(g) = g {
            self.engine.move_representative(p, want, g);
        }
    }

    /// Dummy-point construction; false if it had to be abandoned (a point coincides with a
    /// dummy, or the last dummies cannot leave the quotient of a space with rotations or
    /// reflections), `Err` if `progress` stopped it.
    fn build_from_dummies(
        &mut self,
        pts: &[[f64; D]],
        weights: &[f64],
        seed: Option<u64>,
        progress: &mut impl FnMut(usize) -> ControlFlow<()>,
    ) -> Result<bool> {
        let dummies = self.engine.space().dummy_points();
        if dummies.is_empty() {
            return Ok(false);
        }
        let k = dummies.len() as u32;
        if self.engine.is_weighted() {
            // the largest weight: no point hides a dummy (unless one of that weight lies on
            // it), and the dummies' cells keep their unweighted criterion; the points the
            // dummies hide come back once they leave
            self.engine.weights = vec![self.weight_range.1; dummies.len()];
        }
        self.engine.points = dummies;
        self.engine.bootstrap_one_sheeted();
        self.input_point = vec![PointId::NONE; pts.len()];
        // placeholders: point ids count the dummies until they are dropped
        self.point_input = vec![InputId::NONE; k as usize];
        // (a dummy hidden by a point on it, of a larger weight, or a point on a dummy: start
        // again without)
        let kept = self.insert_ordered(
            (pts, weights),
            seed,
            (0, k as usize),
            progress,
            |r, hid| match r {
                Inserted::Duplicate(p) => p.0 >= k,
                _ => hid.iter().all(|h| h.id.0 >= k),
            },
        )?;
        if !kept {
            return Ok(false);
        }
        // the last points take the dummies' ids, the others keep theirs
        let Some(moved) = self.engine.remove_first_points(k as usize) else {
            return Ok(false);
        };
        for d in (0..k as usize).rev() {
            self.point_input.swap_remove(d);
        }
        let n = self.point_input.len() as u32;
        for p in self.input_point.iter_mut().filter(|p| p.0 >= n) {
            if let Some(d) = moved.iter().position(|m| m == p) {
                *p = PointId::new(d);
            }
        }
        self.used_dummies = true;
        // points hidden with the dummies' help come back
        self.uncover();
        Ok(true)
    }

    /// Inserts input `i` at the internal point `p` of internal weight `w` (ignored when
    /// unweighted).
    fn insert_wrapped(&mut self, i: InputId, p: [f64; D], w: f64) -> Inserted {
        let key = self.space().spatial_key(&p);
        self.insert_keyed(i, p, w, key)
    }

    /// [`Self::insert_wrapped`] with the point's spatial key computed already.
    fn insert_keyed(&mut self, i: InputId, p: [f64; D], w: f64, key: u64) -> Inserted {
        let r = self.engine.insert_keyed(p, w, key);
        self.record(i, p, w, r);
        r
    }

    /// Records what became of input `i` at `p` of weight `w`.
    fn record(&mut self, i: InputId, p: [f64; D], w: f64, r: Inserted) {
        match r {
            Inserted::New(v) => self.record_new(i, v),
            Inserted::Duplicate(v) => self.record_duplicate(i, v),
            Inserted::Hidden => self.record_hidden(i, p, w),
        }
    }

    /// Inserts internal `points` (with `weights`, none when unweighted), point `k` as
    /// input `first + k`, in BRIO + Hilbert order by `seed` (without one, in their order), a
    /// round at a time, each sorted on a helper thread while the ones before it are
    /// inserted one at a time, or with threads on them before it
    /// ([`crate::sort::in_rounds`]); records each in the engine's order while
    /// `keep(result, points it hid)` holds: false when one does not (the rest unrecorded),
    /// `Err` if `progress` stopped it. The first `dummies` points of the engine are a
    /// build's dummy points, which leave between rounds when they can ([`Leaving`]).
    fn insert_ordered(
        &mut self,
        (points, weights): (&[[f64; D]], &[f64]),
        seed: Option<u64>,
        (first, dummies): (usize, usize),
        progress: &mut impl FnMut(usize) -> ControlFlow<()>,
        keep: impl Fn(Inserted, &[HiddenPoint<[f64; D]>]) -> bool + Sync,
    ) -> Result<bool> {
        let space = self.space().clone();
        let key = |k: u32| space.spatial_key(&points[k as usize]);
        // in 2D, rounds that grow eightfold (the last holds seven eighths of the points)
        // keep consecutive points in the cells just made: 8 % off a build of 10⁶ points in
        // a square one at a time (none in a cube or on the sphere; BENCHMARKS.md); with
        // threads, in any dimension in a space without reflections, each such round is
        // one wave ([`Engine::eightfold_rounds`]: a fifth off two threads in a square)
        let one_at_a_time = D == 2 && self.engine.threads().is_none();
        let growth = if one_at_a_time || self.engine.eightfold_rounds() {
            3
        } else {
            1
        };
        let order = seed.map(|seed| Brio::new(seed, growth));
        let mut done = 0;
        let mut leaving = Leaving::new(dummies, points.len());
        // (sorted ahead on a helper thread one at a time; with threads, on them)
        let ahead = self.engine.threads().is_none();
        let outcome = crate::sort::in_rounds(
            points.len(),
            (order, ahead),
            key,
            |round| round,
            |round| {
                let at = (first, done);
                match self.insert_round((points, weights), &round, at, progress, &keep) {
                    Ok(true) => {
                        done += round.len();
                        leaving.after_round(&mut self.engine, done);
                        Ok(())
                    }
                    Ok(false) => Err(None),
                    Err(e) => Err(Some(e)),
                }
            },
        );
        self.engine.end_batch();
        match outcome {
            Ok(()) => Ok(true),
            Err(None) => Ok(false),
            Err(Some(e)) => Err(e),
        }
    }

    /// How many points ahead of the insertion their data are loaded.
    const AHEAD: usize = 8;
    /// How many points of a round one at a time gathers from the input at once.
    const BLOCK: usize = 256;

    /// [`Self::insert_ordered`] of one round, `(spatial key, index)` pairs in insertion
    /// order, after `done` points. One at a time unless the engine has threads: the
    /// parallel insertion's items and log cost 56 bytes a point more at the peak (435 →
    /// 498 MB for 10⁶ points in a cube), which one at a time need not pay.
    fn insert_round(
        &mut self,
        (points, weights): (&[[f64; D]], &[f64]),
        round: &[(u64, u32)],
        (first, done): (usize, usize),
        progress: &mut impl FnMut(usize) -> ControlFlow<()>,
        keep: &(impl Fn(Inserted, &[HiddenPoint<[f64; D]>]) -> bool + Sync),
    ) -> Result<bool> {
        let weight = |k: usize| weights.get(k).copied().unwrap_or(0.0);
        if self.engine.threads().is_none() {
            let mut block: Vec<[f64; D]> = Vec::with_capacity(Self::BLOCK);
            for (n, &(key, k)) in round.iter().enumerate() {
                if n % Self::BLOCK == 0 {
                    let end = (n + Self::BLOCK).min(round.len());
                    block.clear();
                    block.extend(round[n..end].iter().map(|&(_, k)| points[k as usize]));
                }
                if (done + n) % 4096 == 0 {
                    proceed(progress, done + n)?;
                }
                // (the points come in a random order: gathered a block at a time, whose
                // loads overlap, where a prefetch in this loop waited for its page walk;
                // the entries of the input table that `record` writes, loaded ahead)
                if let Some(&(_, ahead)) = round.get(n + Self::AHEAD) {
                    self.prefetch_input(first + ahead as usize);
                }
                let k = k as usize;
                let (p, w) = (block[n % Self::BLOCK], weight(k));
                let r = self.engine.insert_keyed(p, w, key);
                if !keep(r, &self.engine.hidden_log) {
                    return Ok(false);
                }
                self.record(InputId::new(first + k), p, w, r);
            }
            return Ok(true);
        }
        let items: Vec<Item<[f64; D]>> = round
            .par_iter()
            .map(|&(key, k)| {
                let k = k as usize;
                ((first + k) as u32, points[k], weight(k), key)
            })
            .collect();
        let (log, flow) = self
            .engine
            .insert_parallel(&items, &mut |n| progress(done + n));
        if flow.is_break() {
            return Err(Error::Interrupted);
        }
        let tables = (&mut self.point_input, &mut self.input_point[..]);
        if log.record_if_all_new(&items, tables, |r| keep(r, &[])) {
            return Ok(true);
        }
        for (n, (k, r, hid)) in log.iter().enumerate() {
            if let Some(&(ahead, ..)) = log.events.get(n + Self::AHEAD) {
                self.prefetch_input(items[ahead as usize].0 as usize);
            }
            if !keep(r, hid) {
                return Ok(false);
            }
            self.engine.hidden_log.extend_from_slice(hid);
            let (i, p, w, _) = items[k as usize];
            self.record(InputId(i), p, w, r);
        }
        Ok(true)
    }

    /// Loads the entry of input `i` in the input table, which [`Self::record`] will write:
    /// the inputs come in a random order, and loading each entry ahead took 16 % off a
    /// build of 10⁶ points in a square (3 % in a cube).
    #[inline(always)]
    fn prefetch_input(&self, i: usize) {
        if let Some(entry) = self.input_point.get(i) {
            crate::tds::prefetch(entry);
        }
    }

    /// Input `i` became point `p`, after the points it hid left (each renumbering the last
    /// point, first of all the new one, into its id: followed here in the same order).
    fn record_new(&mut self, i: InputId, p: PointId) {
        self.input_point[i.index()] = PointId::new(self.point_input.len());
        self.point_input.push(i);
        self.absorb_hidden();
        debug_assert_eq!(self.input_point[i.index()], p);
    }

    /// Input `i` coincides with point `p`; the point keeps the smallest input id.
    fn record_duplicate(&mut self, i: InputId, p: PointId) {
        self.input_point[i.index()] = p;
        self.duplicates += 1;
        let first = &mut self.point_input[p.index()];
        *first = (*first).min(i);
    }

    /// Inserts one more point (wrapped into the domain); its input id is the number of
    /// points given so far. Returns the point (vertex of the quotient) it became or
    /// coincides with. (In a weighted triangulation its weight is 0: see
    /// [`Self::insert_weighted`].)
    pub fn insert(&mut self, p: [f64; D]) -> Result<Inserted> {
        self.insert_weighted(p, 0.0)
    }

    /// Inserts a batch of points, all or nothing: every point is checked and wrapped first,
    /// and an error, which names the point by its row in `points`, leaves the triangulation
    /// unchanged. The batch then goes in by BRIO + Hilbert order, so that each walk starts
    /// next to its target whatever the order of `points` (inserting points one by one in
    /// random order walks across the triangulation each time). Input ids follow the order of
    /// `points`, and a point met several times keeps the coordinates of its first
    /// occurrence, as in [`Self::build`]. Returns, per point, the point (vertex of the
    /// quotient) it became or coincides with.
    ///
    /// (In a weighted triangulation their weights are 0: see
    /// [`Self::insert_all_weighted`].)
    pub fn insert_all(&mut self, points: &[[f64; D]]) -> Result<Vec<Inserted>> {
        self.insert_all_weighted(points, &[])
    }

    /// [`Self::insert_all`] of checked internal points and weights (internal frame; none
    /// when unweighted).
    fn insert_all_internal(&mut self, internal: &[[f64; D]], weights: &[f64]) -> Vec<Inserted> {
        let first = self.input_point.len();
        self.input_point
            .resize(first + internal.len(), PointId::NONE);
        let seed = BuildOptions::default().seed ^ first as u64;
        let unstoppable = &mut |_| ControlFlow::Continue(());
        let done = self.insert_ordered(
            (internal, weights),
            Some(seed),
            (first, 0),
            unstoppable,
            |_, _| true,
        );
        debug_assert!(matches!(done, Ok(true)));
        // a duplicate inserted before its first occurrence lent the point its coordinates;
        // (hidden points, and points a later one hid, have no point; ids as they are now: a
        // later point may have hidden one before)
        (0..internal.len())
            .map(|k| {
                let p = self.input_point[first + k];
                if p == HIDDEN {
                    Inserted::Hidden
                } else if self.point_input[p.index()].index() == first + k {
                    self.represent(p, internal[k]);
                    Inserted::New(p)
                } else {
                    Inserted::Duplicate(p)
                }
            })
            .collect()
    }

    /// Removes input point `i`: afterwards the triangulation is the Delaunay triangulation
    /// of the remaining points, equal cell for cell to a fresh build of them (whenever both
    /// are in the same space, see [`Self::sheets`]). When other input ids are duplicates of
    /// `i`'s point, the point stays, with its coordinates, and the least of those ids becomes
    /// its first occurrence. Other input ids never change; point ids do (the last point
    /// takes the removed one's). An id never given or already removed is an error that
    /// changes nothing.
    ///
    /// ```
    /// use orbitri::{FlatTorus3, InputId, PeriodicDelaunay3};
    /// let pts: Vec<[f64; 3]> = (0..200)
    ///     .map(|i| {
    ///         let f = i as f64;
    ///         [(f * 0.618034) % 1.0, (f * 0.414214) % 1.0, (f * 0.732051) % 1.0]
    ///     })
    ///     .collect();
    /// let torus = FlatTorus3::cuboid([1.0; 3]).unwrap();
    /// let mut tri = PeriodicDelaunay3::build(torus.clone(), &pts).unwrap();
    /// tri.remove(InputId(7)).unwrap();
    /// assert!(tri.remove(InputId(7)).is_err());
    /// assert_eq!(tri.number_of_vertices(), 199);
    /// assert!(tri.is_valid().is_ok());
    /// ```
    pub fn remove(&mut self, i: InputId) -> Result<Removal> {
        let p = self.live_point(i)?;
        self.input_point[i.index()] = PointId::NONE;
        if p == HIDDEN {
            self.hidden.remove(&i);
            return Ok(Removal::InPlace);
        }
        if self.detach_duplicate(i, p) {
            return Ok(Removal::InPlace);
        }
        let near = self.hidden_near(p);
        let how = self.engine.remove_point(p);
        self.rebuilds += (how == Removal::Rebuilt) as usize;
        self.forget_point(p);
        self.uncover_among(near);
        Ok(how)
    }

    /// After the engine dropped point `p` and moved the last point into its slot: the
    /// inputs of the last point now map to `p`.
    fn forget_point(&mut self, p: PointId) {
        let last = PointId(self.point_input.len() as u32 - 1);
        self.point_input.swap_remove(p.index());
        if p != last {
            if self.duplicates == 0 {
                self.input_point[self.point_input[p.index()].index()] = p;
            } else {
                for x in self.input_point.iter_mut().filter(|x| **x == last) {
                    *x = p;
                }
            }
        }
    }

    /// Removes the input points `ids`, in that order, all or nothing: an unknown, removed or
    /// repeated id is an error that changes nothing. The result is that of removing them
    /// one by one ([`Self::remove`]), but the points left are renumbered once, at the end,
    /// instead of once per removal. Returns whether the remaining points had to be
    /// triangulated again (see [`Removal`]).
    pub fn remove_all(&mut self, ids: &[InputId]) -> Result<Removal> {
        self.check_distinct_live(ids)?;
        let mut gone = Vec::with_capacity(ids.len());
        for &i in ids {
            let p = self.input_point[i.index()];
            self.input_point[i.index()] = PointId::NONE;
            if p == HIDDEN {
                self.hidden.remove(&i);
            } else if !self.detach_duplicate(i, p) {
                gone.push(p);
            }
        }
        if gone.is_empty() {
            return Ok(Removal::InPlace);
        }
        let (map, rebuilt) = self.engine.remove_points(&gone);
        for p in self
            .input_point
            .iter_mut()
            .filter(|p| **p != PointId::NONE && **p != HIDDEN)
        {
            *p = map[p.index()];
        }
        let mut k = 0;
        self.point_input.retain(|_| {
            k += 1;
            map[k - 1] != PointId::NONE
        });
        self.rebuilds += rebuilt as usize;
        self.uncover();
        Ok(if rebuilt {
            Removal::Rebuilt
        } else {
            Removal::InPlace
        })
    }

    /// Moves input point `i` to `to`, keeping its id. A move that leaves the cells around
    /// it positively oriented and Delaunay changes its coordinates alone and returns true;
    /// otherwise its vertex is removed and inserted again, starting from the cells that
    /// filled its hole (false). A move onto another point makes `i` its duplicate, as an
    /// insertion does. A non-finite coordinate or an unknown id is an error that changes
    /// nothing.
    pub fn move_point(&mut self, i: InputId, to: [f64; D]) -> Result<bool> {
        self.live_point(i)?;
        let (w, _) = internal_point(self.space(), i.index(), &to)?;
        Ok(self.move_internal(i, w))
    }

    /// Moves live input `i` to the internal point `w`.
    fn move_internal(&mut self, i: InputId, w: [f64; D]) -> bool {
        let p = self.input_point[i.index()];
        let shared = self.duplicates > 0
            && self
                .input_point
                .iter()
                .enumerate()
                .any(|(j, &x)| x == p && j != i.index());
        if !shared && !self.engine.is_weighted() {
            match self.engine.move_point(p, w) {
                Moved::Coordinates => return true,
                Moved::Reinserted => return false,
                Moved::Rebuilt => {
                    self.rebuilds += 1;
                    return false;
                }
                Moved::Duplicate(q) => {
                    self.forget_point(p);
                    self.record_duplicate(i, q);
                    self.represent_if_first(q, i, w);
                    return false;
                }
                Moved::Refused => {}
            }
        }
        let weight = self.internal_weight(i);
        self.remove(i).expect("a live input");
        if let Inserted::Duplicate(q) = self.insert_wrapped(i, w, weight) {
            self.represent_if_first(q, i, w);
        }
        false
    }

    /// Input `i`, moved to `w`, became a duplicate of point `q`: when `i` is now `q`'s
    /// first occurrence, `q` takes `i`'s coordinates.
    fn represent_if_first(&mut self, q: PointId, i: InputId, w: [f64; D]) {
        if self.point_input[q.index()] == i {
            self.represent(q, w);
        }
    }

    /// True when input id `i` was given and not removed.
    pub fn contains(&self, i: InputId) -> bool {
        self.live_point(i).is_ok()
    }

    /// Moves every input of `ids` to its point of `to` ([`Self::move_point`]), all or
    /// nothing: an unknown, removed or repeated id, a non-finite coordinate, or `to` of
    /// another length than `ids`, is an error naming the input id, and nothing moves. The
    /// points move in Hilbert order of their targets, so that consecutive moves touch
    /// neighbouring cells; the result does not depend on the order. Returns per point
    /// whether only its coordinates changed.
    pub fn move_all(&mut self, ids: &[InputId], to: &[[f64; D]]) -> Result<Vec<bool>> {
        if ids.len() != to.len() {
            return Err(Error::InvalidOption {
                option: "number of target points",
                value: to.len().to_string(),
                limit: format!("must equal the number of ids, {}", ids.len()),
            });
        }
        self.check_distinct_live(ids)?;
        let targets = ids
            .iter()
            .zip(to)
            .map(|(&i, p)| Ok(internal_point(self.space(), i.index(), p)?.0))
            .collect::<Result<Vec<_>>>()?;
        let mut fast = vec![false; ids.len()];
        for k in hilbert_order(self.space(), &targets) {
            let k = k as usize;
            fast[k] = self.move_internal(ids[k], targets[k]);
        }
        Ok(fast)
    }

    /// Ok when every id of `ids` is live and none is repeated, else the error naming the
    /// first that is not.
    fn check_distinct_live(&self, ids: &[InputId]) -> Result<()> {
        let mut seen = HashSet::with_capacity(ids.len());
        for &i in ids {
            self.live_point(i)?;
            if !seen.insert(i) {
                return Err(Error::UnknownInput {
                    id: i.0 as u64,
                    why: "is given twice".into(),
                });
            }
        }
        Ok(())
    }

    /// The point of a live input id, or the error naming it.
    fn live_point(&self, i: InputId) -> Result<PointId> {
        let unknown = |why: String| Error::UnknownInput {
            id: i.0 as u64,
            why,
        };
        match self.input_point.get(i.index()) {
            None => Err(unknown(format!(
                "out of range ({} input points were given)",
                self.input_point.len()
            ))),
            Some(&p) if p == PointId::NONE => Err(unknown("was removed".into())),
            Some(&p) => Ok(p),
        }
    }

    /// When other inputs still share point `p` with the removed input `i`: `i` leaves
    /// without the point, whose first occurrence becomes the least of them. True then.
    fn detach_duplicate(&mut self, i: InputId, p: PointId) -> bool {
        if self.duplicates == 0 {
            return false;
        }
        let Some(next) = self.input_point.iter().position(|&x| x == p) else {
            return false;
        };
        self.duplicates -= 1;
        if self.point_input[p.index()] == i {
            self.point_input[p.index()] = InputId::new(next);
        }
        true
    }

    /// How many removals had to triangulate the remaining points again (their quotient
    /// would not have been a simplicial complex, or the triangulation was in a covering).
    pub fn removal_rebuilds(&self) -> usize {
        self.rebuilds
    }

    /// The orbit space.
    pub fn space(&self) -> &S {
        self.engine.space()
    }

    /// The engine (for generic algorithms).
    pub fn engine(&self) -> &Engine<S, N> {
        &self.engine
    }

    /// Sheets of the stored triangulation: 1 once it is a triangulation of the torus.
    pub fn sheets(&self) -> usize {
        self.engine.sheets()
    }

    /// Moves a triangulation still in a covering space to the 1-sheeted torus if its
    /// projection there is a simplicial complex (no cycle of length ≤ 2), even though the
    /// criterion does not yet guarantee it for more points; later insertions check that the
    /// quotient stays simplicial and go back to the covering when it would not. `build` does
    /// this at its end; after `insert` calls it is the caller's choice (CGAL's
    /// `convert_to_1_sheeted_covering`). Returns whether the triangulation is 1-sheeted.
    pub fn try_one_sheet(&mut self) -> bool {
        self.engine.try_one_sheet()
    }

    /// True when the stored triangulation is the 1-sheeted quotient.
    pub fn is_one_sheeted(&self) -> bool {
        self.engine.is_one_sheeted()
    }

    /// True if the bulk construction started from the dummy point set.
    pub fn used_dummy_points(&self) -> bool {
        self.used_dummies
    }

    /// Number of input points given.
    pub fn number_of_input_points(&self) -> usize {
        self.input_point.len()
    }

    /// Number of distinct points (vertices of the quotient).
    pub fn number_of_vertices(&self) -> usize {
        self.engine.points().len()
    }

    /// Number of cells of the space: one per orbit (the rows of [`Self::complex`]), also
    /// while the triangulation is stored in a covering.
    pub fn number_of_cells(&self) -> usize {
        if self.is_one_sheeted() {
            self.engine.number_of_cells()
        } else {
            self.orbits().representatives.len()
        }
    }

    /// Number of stored cells: in a covering space, every copy (`sheets` ×
    /// [`Self::number_of_cells`] when the covering is the lift of a triangulation of the
    /// space, see [`Self::complex`]).
    pub fn number_of_stored_cells(&self) -> usize {
        self.engine.number_of_cells()
    }

    /// Number of input points that coincided with an earlier one.
    pub fn duplicates(&self) -> usize {
        self.duplicates
    }

    /// Number of input points that were wrapped into the domain.
    pub fn wrapped(&self) -> usize {
        self.wrapped
    }

    /// The distinct points (wrapped), indexed by [`PointId`].
    pub fn points(&self) -> Vec<[f64; D]> {
        (0..self.number_of_vertices() as u32)
            .map(|v| self.point(PointId(v)))
            .collect()
    }

    /// The wrapped position of point (vertex) `v`.
    pub fn point(&self, v: PointId) -> [f64; D] {
        let space = self.space();
        let p = self.engine.points()[v.index()];
        space.to_user(space.lifted_position((p, space.identity())))
    }

    /// The position of input point `i`'s image under the group element `offset` (in a
    /// torus, `points[i] + offset·M`), in Cartesian coordinates.
    pub fn position(&self, i: InputId, offset: S::Elem) -> [f64; D] {
        let p = match self.hidden.get(&i) {
            Some(&(x, _)) => x,
            None => self.engine.points()[self.vertex_of_input(i).index()],
        };
        let space = self.space();
        space.to_user(space.lifted_position((p, offset)))
    }

    /// The point (vertex of the quotient) of input point `i` ([`PointId::NONE`] once
    /// removed, `PointId(u32::MAX - 1)` while hidden).
    pub fn vertex_of_input(&self, i: InputId) -> PointId {
        self.input_point[i.index()]
    }

    /// The input id of point (vertex) `v`: its first occurrence.
    pub fn input_of_vertex(&self, v: PointId) -> InputId {
        self.point_input[v.index()]
    }

    /// For every input point, the input id of its first occurrence (itself unless
    /// duplicate, or hidden; [`InputId::NONE`] once removed).
    pub fn first_occurrences(&self) -> Vec<InputId> {
        self.input_point
            .iter()
            .enumerate()
            .map(|(i, &v)| self.first_occurrence(i, v))
            .collect()
    }

    /// The input id of the first occurrence of input `i`, whose point is `v`.
    fn first_occurrence(&self, i: usize, v: PointId) -> InputId {
        match v {
            PointId::NONE => InputId::NONE,
            HIDDEN => InputId::new(i),
            _ => self.point_input[v.index()],
        }
    }

    /// Each point with the input id of its first occurrence, and each hidden input with
    /// [`PointId::NONE`], in input order: one pass over the inputs, not a sort (an input
    /// whose point has an earlier first occurrence is a duplicate; a removed one has none).
    pub(crate) fn input_order(&self) -> Vec<(InputId, PointId)> {
        let order: Vec<(InputId, PointId)> = self
            .input_point
            .iter()
            .enumerate()
            .filter(|&(i, &p)| self.first_occurrence(i, p) == InputId::new(i))
            .map(|(i, &p)| (InputId::new(i), if p == HIDDEN { PointId::NONE } else { p }))
            .collect();
        debug_assert_eq!(order.len(), self.point_input.len() + self.hidden.len());
        order
    }

    /// The input id of a stored vertex's point.
    fn input_of(&self, v: VertexId) -> InputId {
        self.point_input[self.engine.point_of(v).index()]
    }

    fn view(&self, c: CellId) -> CellView<D, N, S::Elem> {
        let cell = self.engine.cell(c);
        CellView {
            vertices: cell.v.map(|x| self.input_of(x)),
            offsets: cell.off,
        }
    }

    /// Every stored cell, lazily (for writers of large triangulations).
    pub fn stored_cells(&self) -> impl Iterator<Item = CellView<D, N, S::Elem>> + '_ {
        self.engine.cell_ids().map(|c| self.view(c))
    }

    /// The cells with input ids and elements: every stored cell, or one per orbit (the
    /// cells of [`Self::complex`]).
    pub fn cells(&self, copies: Copies) -> Vec<CellView<D, N, S::Elem>> {
        if copies == Copies::Stored || self.is_one_sheeted() {
            return self.stored_cells().collect();
        }
        let orbits = self.orbits();
        orbits
            .representatives
            .iter()
            .map(|&c| self.view(c))
            .collect()
    }

    /// A face of a stored cell (the slots in `idx`), its vertices labelled by `id`, in
    /// canonical form.
    fn face<I: Copy + Into<u32> + From<u32>>(
        &self,
        c: CellId,
        idx: &[usize],
        id: impl Fn(VertexId) -> I,
    ) -> Simplex<D, S::Elem, I> {
        let cell = self.engine.cell(c);
        let v: Vec<I> = idx.iter().map(|&i| id(cell.v[i])).collect();
        let o: Vec<S::Elem> = idx.iter().map(|&i| cell.off[i]).collect();
        let (vertices, offsets) = canonical(self.space(), &v, &o);
        Simplex { vertices, offsets }
    }

    /// In a covering space, one copy per orbit of faces (canonical forms deduplicated).
    fn unique_in_covering(
        &self,
        faces: impl Iterator<Item = Simplex<D, S::Elem>>,
    ) -> Vec<Simplex<D, S::Elem>> {
        let mut out: Vec<Simplex<D, S::Elem>> = faces.collect::<HashSet<_>>().into_iter().collect();
        out.sort_unstable();
        out
    }

    /// Every stored edge, its vertices labelled by `id`: found from each vertex's
    /// neighbours, towards the larger vertex id.
    fn edges_labelled<'a, I: Copy + Into<u32> + From<u32> + 'a>(
        &'a self,
        id: impl Fn(VertexId) -> I + Copy + 'a,
    ) -> impl Iterator<Item = Simplex<D, S::Elem, I>> + 'a {
        (0..self.engine.number_of_vertices() as u32)
            .map(VertexId)
            .flat_map(move |v| {
                self.engine
                    .neighbours(v)
                    .into_iter()
                    .filter(move |w| w.0 > v)
                    .map(move |(w, rel)| {
                        let (vertices, offsets) = canonical(
                            self.space(),
                            &[id(v), id(w)],
                            &[self.space().identity(), rel],
                        );
                        Simplex { vertices, offsets }
                    })
            })
    }

    /// The edges (input ids, offsets), one per edge of the quotient (CGAL's unique
    /// iterators).
    pub fn edges(&self) -> Vec<Simplex<D, S::Elem>> {
        let all = self.edges_labelled(|v| self.input_of(v));
        if self.is_one_sheeted() {
            return all.collect();
        }
        self.unique_in_covering(all)
    }

    /// Every stored edge (in a covering space, every copy), its vertices the stored ones:
    /// [`VertexId`]s, which tell the copies of a point apart.
    pub fn stored_edges(&self) -> Vec<Simplex<D, S::Elem, VertexId>> {
        self.edges_labelled(|v| v).collect()
    }

    /// The Delaunay edges of the torus, each once, with input ids, shift and length.
    pub fn delaunay_edges(&self) -> Vec<DelaunayEdge<D, S::Elem>> {
        let space = self.space();
        self.edges()
            .into_iter()
            .map(|s| {
                let at = |k: usize| {
                    let p = self.engine.points()[self.vertex_of_input(s.vertices[k]).index()];
                    (p, s.offsets[k])
                };
                let d = space.lifted_difference(at(1), at(0));
                let length = d.iter().map(|x| x * x).sum::<f64>().sqrt();
                DelaunayEdge {
                    i: s.vertices[0],
                    j: s.vertices[1],
                    shift: space.relative(s.offsets[1], s.offsets[0]),
                    length: space.measure_to_user(length, 1),
                }
            })
            .collect()
    }

    /// Every stored facet, once (from the cell with the smaller id), its vertices labelled by
    /// `id`.
    fn facets_labelled<'a, I: Copy + Into<u32> + From<u32> + 'a>(
        &'a self,
        id: impl Fn(VertexId) -> I + Copy + 'a,
    ) -> impl Iterator<Item = Simplex<D, S::Elem, I>> + 'a {
        self.engine.cell_ids().flat_map(move |c| {
            let n = self.engine.cell(c).n;
            (0..N).filter(move |&i| c < n[i]).map(move |i| {
                let idx: Vec<usize> = (0..N).filter(|&k| k != i).collect();
                self.face(c, &idx, id)
            })
        })
    }

    /// The facets (input ids, offsets), one per facet of the quotient.
    pub fn facets(&self) -> Vec<Simplex<D, S::Elem>> {
        let all = self.facets_labelled(|v| self.input_of(v));
        if self.is_one_sheeted() {
            return all.collect();
        }
        self.unique_in_covering(all)
    }

    /// Every stored facet, by stored vertex (as [`Self::stored_edges`]).
    pub fn stored_facets(&self) -> Vec<Simplex<D, S::Elem, VertexId>> {
        self.facets_labelled(|v| v).collect()
    }

    /// The neighbours of input point `i`: (input id, offset of the neighbour relative to
    /// the point), one entry per Delaunay edge at the point, from the point's star.
    pub fn vertex_neighbors(&self, i: InputId) -> Vec<(InputId, S::Elem)> {
        if self.hidden.contains_key(&i) {
            return Vec::new();
        }
        let v = self.engine.vertex_of_point(self.vertex_of_input(i));
        let mut out: Vec<(InputId, S::Elem)> = self
            .engine
            .neighbours(v)
            .into_iter()
            .map(|(w, rel)| (self.input_of(w), rel))
            .collect();
        out.sort_unstable();
        out
    }

    /// The cell containing `p` (wrapped into the domain) and the offset of `p` in its frame.
    pub fn locate(&self, p: [f64; D]) -> Result<(CellView<D, N, S::Elem>, S::Elem)> {
        if self.number_of_vertices() == 0 {
            return Err(Error::EmptyInput);
        }
        let (w, _) = internal_point(self.space(), 0, &p)?;
        let (c, o) = self.engine.locate(w);
        Ok((self.view(c), o))
    }

    /// For every query point, the row of the cell containing it in [`Self::complex`] (and
    /// [`Self::cells`]`(Copies::Unique)`; scipy's `find_simplex`). The queries are taken in
    /// Hilbert order, in parallel chunks, each query walking from the previous one's cell,
    /// and each chunk's first from the jump-and-walk grid: the cost per query does not
    /// grow with the triangulation. An error names the first non-finite query by its row.
    pub fn find_simplex(&self, points: &[[f64; D]]) -> Result<Vec<usize>> {
        if self.number_of_vertices() == 0 {
            return Err(Error::EmptyInput);
        }
        let (internal, _) = internal_points(self.space(), points)?;
        let row: Vec<usize> = self.orbits().of.iter().map(|o| o.0 as usize).collect();
        let (internal, row) = (&internal, &row);
        let found: Vec<(u32, usize)> = hilbert_order(self.space(), internal)
            .par_chunks(4096)
            .flat_map_iter(|chunk| {
                let mut from = None;
                chunk.iter().map(move |&k| {
                    let w = internal[k as usize];
                    let at = match from {
                        Some(f) => self.engine.locate_from_cell(w, f),
                        None => self.engine.locate(w),
                    };
                    from = Some(at);
                    (k, row[at.0.index()])
                })
            })
            .collect();
        let mut out = vec![0; points.len()];
        for (k, r) in found {
            out[k as usize] = r;
        }
        Ok(out)
    }

    /// Checks combinatorics and geometry exactly.
    pub fn is_valid(&self) -> std::result::Result<(), Invalid> {
        self.engine.is_valid()
    }
}

/// Canonical form modulo the group of a simplex given by vertices and elements.
/// (The space orders plain numbers: an id orders as its number.)
fn canonical<
    const D: usize,
    const N: usize,
    S: FlatSpace<D, N>,
    I: Copy + Into<u32> + From<u32>,
>(
    space: &S,
    v: &[I],
    o: &[S::Elem],
) -> (Vec<I>, Vec<S::Elem>) {
    let mut pairs: Vec<(u32, S::Elem)> =
        v.iter().map(|&x| x.into()).zip(o.iter().copied()).collect();
    space.canonical_face(&mut pairs);
    pairs.into_iter().map(|(x, g)| (I::from(x), g)).unzip()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dummy points try to leave after a round only from `8k` points on and not after
    /// the last; on four planes all leave at the first try; beside a vacuum, where some
    /// stay, a try that removes none ends the tries only from `64k` points on.
    #[test]
    fn dummy_points_leave_after_the_rounds_the_policy_names() {
        use crate::delaunay::from_dummies;
        let (mut e, _) = from_dummies(None);
        let k = e.space().dummy_points().len();
        let there = |e: &Engine<FlatTorus<3>, 4>| (0..k).filter(|&d| e.has_vertex(d)).count();
        Leaving::new(k, 2000).after_round(&mut e, 2000);
        assert_eq!(there(&e), k, "after the last round");
        let mut planes = Leaving::new(k, 10_000);
        planes.after_round(&mut e, 8 * k - 1);
        assert_eq!(there(&e), k, "before 8k points");
        planes.after_round(&mut e, 8 * k);
        assert_eq!(there(&e), 0, "planes");
        let (mut e, _) = from_dummies(Some(0.05));
        let mut slab = Leaving::new(k, 100_000);
        slab.after_round(&mut e, 8 * k);
        let stay = there(&e);
        assert!(0 < stay && stay < k && slab.trying, "slab: {stay} stay");
        slab.after_round(&mut e, 64 * k - 1);
        assert!(slab.trying, "a try that removes none before 64k points");
        slab.after_round(&mut e, 64 * k);
        assert!(!slab.trying && there(&e) == stay, "slab");
    }

    /// Each point at its first occurrence and each hidden input, in input order: the same
    /// list as sorting the points by their first occurrence with the hidden inputs, after
    /// duplicates, hidden points and removals.
    #[test]
    fn input_order_is_the_sorted_first_occurrences_and_hidden_inputs() {
        let mut r = crate::sort::SplitMix::new(5);
        let mut pts: Vec<[f64; 2]> = (0..300).map(|_| [r.unit(), r.unit()]).collect();
        let mut w: Vec<f64> = (0..300).map(|_| 0.002 * r.unit()).collect();
        // duplicates of earlier points, and points on others, lighter (hidden)
        for k in 0..20 {
            pts.push(pts[7 * k]);
            w.push(if k % 2 == 0 { w[7 * k] } else { w[7 * k] - 0.5 });
        }
        let space = FlatTorus::<2>::cuboid([1.0, 1.0]).unwrap();
        let mut tri = PeriodicDelaunay2::build_weighted(space, &pts, &w).unwrap();
        for i in [3, 14, 150, 301, 303] {
            tri.remove(InputId::new(i)).unwrap();
        }
        assert!(tri.duplicates > 0 && !tri.hidden.is_empty());
        let mut want: Vec<(InputId, PointId)> = (0..tri.number_of_vertices() as u32)
            .map(|p| (tri.input_of_vertex(PointId(p)), PointId(p)))
            .chain(tri.hidden().into_iter().map(|i| (i, PointId::NONE)))
            .collect();
        want.sort_unstable();
        assert_eq!(tri.input_order(), want);
    }

    #[test]
    fn internal_points_are_borrowed_only_when_every_one_is_in_place() {
        let unit = FlatTorus::<2>::cuboid([1.0, 1.0]).unwrap();
        let inside = [[0.25, 0.5], [0.0, 0.75]];
        let (p, moved) = internal_points(&unit, &inside).unwrap();
        assert!(matches!(p, Cow::Borrowed(_)) && moved == 0);
        assert_eq!(&*p, &inside);
        // wrapped, or -0.0 made +0.0: a copy, the points before it included
        for (bad, want) in [([1.25, 0.5], [0.25, 0.5]), ([-0.0, 0.5], [0.0, 0.5])] {
            let pts = [[0.25, 0.5], bad, [0.0, 0.75]];
            let (p, _) = internal_points(&unit, &pts).unwrap();
            assert!(matches!(p, Cow::Owned(_)));
            assert_eq!(&*p, &[[0.25, 0.5], want, [0.0, 0.75]]);
            assert_eq!(p[1][0].to_bits(), want[0].to_bits());
        }
        // another box scales into the internal frame: a copy
        let ten = FlatTorus::<2>::cuboid([10.0, 10.0]).unwrap();
        let (p, _) = internal_points(&ten, &inside).unwrap();
        assert!(matches!(p, Cow::Owned(_)));
        assert_eq!(p[0], [0.25 / 8.0, 0.5 / 8.0]);
        let err = internal_points(&unit, &[[0.5, 0.5], [f64::NAN, 0.5]]).unwrap_err();
        assert!(matches!(err, Error::NonFiniteCoordinate { index: 1, .. }));
        // many points, checked in pieces on the threads: the first bad one named, and
        // how many moved counted over all
        let mut many = vec![[0.5, 0.5]; 100_000];
        many[70_000] = [1.5, 0.5];
        many[90_000] = [-0.5, 0.5];
        let (p, moved) = internal_points(&unit, &many).unwrap();
        assert!(matches!(p, Cow::Owned(_)) && moved == 2);
        assert_eq!(
            (p[70_000], p[90_000], p[99_999]),
            ([0.5; 2], [0.5; 2], [0.5; 2])
        );
        many[80_000] = [0.5, f64::INFINITY];
        many[60_000] = [f64::NAN, 0.5];
        let err = internal_points(&unit, &many).unwrap_err();
        assert!(matches!(
            err,
            Error::NonFiniteCoordinate {
                index: 60_000,
                axis: 0,
                ..
            }
        ));
    }
}
