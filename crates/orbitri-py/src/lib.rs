//! The Python extension `orbitri._orbitri`: the triangulation of a flat torus, a Klein bottle
//! or a flat 3-manifold and its Voronoi cells for numpy arrays. The Python package
//! (`python/orbitri`) parses boxes and documents the API; this module converts arrays (one
//! copy of the input), releases the interpreter during construction, insertion and the
//! Voronoi cells, and turns errors into `ValueError` with the library's message. One class
//! serves every space: group elements leave it as a coset (0 in a torus) and a lattice
//! offset.
//!
//! Threads: a triangulation is shared through a read–write lock (readers together, `insert`,
//! `locate` and `try_one_sheet` alone). No thread ever blocks on the lock while attached to
//! the interpreter (it waits detached, `RwLockExt`), so a holder that reattaches cannot
//! deadlock.
//!
//! Ctrl-C: the construction and the Voronoi cells run detached, on the main thread on a
//! helper thread while the main one runs the signal handlers every `POLL` (`interruptible`).
//! A handler's exception (`KeyboardInterrupt`) is raised at once; the computation sees its
//! stop flag at its next poll (the library's progress callback, `voronoi_cells_until`) and
//! ends in the background.

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, Arc, Mutex, OnceLock, RwLock, RwLockReadGuard, RwLockWriteGuard};
use std::time::Duration;

use numpy::ndarray::{Array1, Array2, Array3, ArrayD, ArrayView2, IxDyn};
use numpy::{AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArrayLike1, PyArrayLike2};
use orbitri::{
    BuildOptions, CellMeasures, FlatManifold, FlatSpace, FlatTorus, InputId, Motion, Neighbor,
    OrbitSpace, Triangulation as Tri_, VoronoiCell,
};
use pyo3::exceptions::{PyIndexError, PyOverflowError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::RwLockExt;
use pyo3::types::PyDict;

mod sphere;

fn value_error(e: orbitri::Error) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// How often the main thread runs the signal handlers while a long computation runs.
const POLL: Duration = Duration::from_millis(50);

/// Inputs smaller than this (points, vertices) are computed on the calling thread: they end
/// sooner than a helper thread would be worth.
const SMALL: usize = 20_000;

/// What a long computation shares with the thread that waits for it: the stop flag it
/// polls, and how far it is (`done` of `total` units, for the progress hook).
struct Control {
    stop: AtomicBool,
    done: AtomicU64,
}

impl Control {
    /// True once the computation should stop.
    fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// Counts one unit of progress, and says whether to stop (the Voronoi passes' poll).
    fn poll(&self) -> bool {
        self.done.fetch_add(1, Ordering::Relaxed);
        self.stopped()
    }
}

/// The Python callable shown the progress of long computations (`set_progress_hook`):
/// `hook(phase, done, total, finished)`, called on the main thread every `POLL`.
static PROGRESS: Mutex<Option<Py<PyAny>>> = Mutex::new(None);

/// Sets (or, with `None`, removes) the callable that shows the progress of long
/// computations: `hook(phase, done, total, finished)`, called with the interpreter held on
/// the thread that waits, about every 50 ms, and once with `finished` true at the end (also
/// when interrupted). The package's `orbitri.set_progress` installs one.
#[pyfunction]
fn set_progress_hook(hook: Option<Py<PyAny>>) {
    *PROGRESS.lock().unwrap_or_else(|e| e.into_inner()) = hook;
}

/// Shows the progress `(done, total)` of `phase` through the hook, if one is set.
fn report(py: Python<'_>, phase: &str, done: u64, total: u64, finished: bool) -> PyResult<()> {
    let hook = PROGRESS
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .as_ref()
        .map(|h| h.clone_ref(py));
    match hook {
        Some(h) => h
            .call1(py, (phase, done.min(total), total, finished))
            .map(drop),
        None => Ok(()),
    }
}

/// Runs `work` (of `size` points; `total` units of progress, named `phase`) without the
/// interpreter and answers Ctrl-C.
///
/// On the main thread (the only one that receives signals), unless the input is small,
/// `work` runs on a helper thread while this one waits detached and, every `POLL`, runs the
/// signal handlers and shows the progress `work` counts in `done` (`report`). Once a
/// handler raises (`KeyboardInterrupt`), the call returns that exception at once: `work`
/// sees `stop` raised at its next poll and ends in the background, its result dropped.
/// Elsewhere `work` runs here, and `stop` is never raised.
fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    size: usize,
    (phase, total): (&str, u64),
    work: impl FnOnce(&Control) -> PyResult<T> + Send + 'static,
) -> PyResult<T> {
    let threading = py.import("threading")?;
    let main = threading
        .call_method0("main_thread")?
        .is(&threading.call_method0("current_thread")?);
    let control = Arc::new(Control {
        stop: AtomicBool::new(false),
        done: AtomicU64::new(0),
    });
    if !main || size < SMALL {
        return py.detach(|| work(&control));
    }
    let shared = Arc::clone(&control);
    let (tx, rx) = mpsc::channel();
    let worker = std::thread::Builder::new()
        .name("orbitri".into())
        // the main thread's size: the work would have run there
        .stack_size(8 << 20)
        .spawn(move || {
            let _ = tx.send(work(&shared));
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
    // a `Receiver` is not `Sync`: the lock (only ever taken here) lets the wait run detached
    let rx = Mutex::new(rx);
    let finish = |py| report(py, phase, total, total, true);
    loop {
        let next = py.detach(|| rx.lock().expect("one waiter").recv_timeout(POLL));
        match next {
            Ok(result) => {
                // a failing hook must not lose the finished work: its error is reported
                if let Err(e) = finish(py) {
                    e.write_unraisable(py, None);
                }
                return result;
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {
                let shown = report(
                    py,
                    phase,
                    control.done.load(Ordering::Relaxed),
                    total,
                    false,
                );
                if let Err(e) = py.check_signals().and(shown) {
                    control.stop.store(true, Ordering::Relaxed);
                    let _ = finish(py);
                    return Err(e);
                }
            }
            // `work` panicked: raise its panic here
            Err(mpsc::RecvTimeoutError::Disconnected) => match worker.join() {
                Err(panic) => std::panic::resume_unwind(panic),
                Ok(()) => unreachable!("the worker sends its result before it ends"),
            },
        }
    }
}

/// The rows of an `(N, D)` array as points (the one copy of the input).
fn rows<const D: usize>(a: ArrayView2<'_, f64>) -> Vec<[f64; D]> {
    a.outer_iter()
        .map(|r| std::array::from_fn(|c| r[c]))
        .collect()
}

/// The torus of the lattice whose rows are those of `a` (`D × D`).
fn torus<const D: usize>(a: ArrayView2<'_, f64>) -> PyResult<FlatTorus<D>> {
    FlatTorus::triclinic(std::array::from_fn(|i| std::array::from_fn(|j| a[[i, j]])))
        .map_err(value_error)
}

/// A group element as the Python side sees it: a coset (0 in a torus) and a lattice offset.
trait Element<const D: usize>: Copy {
    fn coset(self) -> i32;
    fn offset(self) -> [i8; D];
}

impl<const D: usize> Element<D> for [i8; D] {
    fn coset(self) -> i32 {
        0
    }

    fn offset(self) -> [i8; D] {
        self
    }
}

impl<const D: usize> Element<D> for Motion<D> {
    fn coset(self) -> i32 {
        i32::from(self.coset)
    }

    fn offset(self) -> [i8; D] {
        self.offset
    }
}

/// A space the bindings serve: a flat torus or a closed flat manifold.
trait Served<const D: usize, const N: usize>:
    FlatSpace<D, N, Elem: Element<D>> + Send + Sync + 'static
{
    /// Whether its elements have cosets other than 0 (Python's dicts then name them).
    const COSETS: bool;
    /// The rows of its lattice of translations.
    fn lattice_rows(&self) -> [[f64; D]; D];
}

impl<const D: usize, const N: usize> Served<D, N> for FlatTorus<D>
where
    FlatTorus<D>: FlatSpace<D, N, Elem = [i8; D]>,
{
    const COSETS: bool = false;
    fn lattice_rows(&self) -> [[f64; D]; D] {
        self.lattice().vectors()
    }
}

impl<const D: usize, const N: usize> Served<D, N> for FlatManifold<D>
where
    FlatManifold<D>: FlatSpace<D, N, Elem = Motion<D>>,
{
    const COSETS: bool = true;
    fn lattice_rows(&self) -> [[f64; D]; D] {
        self.translations().vectors()
    }
}

/// The triangulation of any space the bindings serve.
enum Tri {
    Two(Tri_<2, 3, FlatTorus<2>>),
    Three(Tri_<3, 4, FlatTorus<3>>),
    Klein(Tri_<2, 3, FlatManifold<2>>),
    Manifold3(Tri_<3, 4, FlatManifold<3>>),
}

/// Runs `$body` with `$t` bound to the triangulation of any space and dimension.
macro_rules! with_tri {
    ($tri:expr, $t:ident => $body:expr) => {
        match $tri {
            Tri::Two($t) => $body,
            Tri::Three($t) => $body,
            Tri::Klein($t) => $body,
            Tri::Manifold3($t) => $body,
        }
    };
}

/// Runs `$body` with `$c` bound to the Voronoi cells of any space and dimension.
macro_rules! with_cells {
    ($cells:expr, $c:ident => $body:expr) => {
        match $cells {
            Cells::Two($c) => $body,
            Cells::Three($c) => $body,
            Cells::Klein($c) => $body,
            Cells::Manifold3($c) => $body,
        }
    };
}

fn array2<T: numpy::Element>(
    py: Python<'_>,
    rows: usize,
    cols: usize,
    v: Vec<T>,
) -> Bound<'_, PyArray2<T>> {
    Array2::from_shape_vec((rows, cols), v)
        .expect("shape matches")
        .into_pyarray(py)
}

/// The Delaunay triangulation of a flat torus or a closed flat manifold (use
/// `orbitri.PeriodicDelaunay` or `orbitri.Triangulation`), shareable between threads.
#[pyclass(module = "orbitri._orbitri", frozen)]
struct Triangulation {
    /// Shared with a computation that may outlive an interrupted call (`voronoi`).
    tri: Arc<RwLock<Tri>>,
    /// 2 or 3 (never changes: read without the lock).
    dim: usize,
    /// Counts the modifications of the cells (for the Python side's cache of `cells()`,
    /// and a `Voronoi`'s check that its triangulation is still the one it measured).
    generation: Arc<AtomicU64>,
    /// (last: runs once the triangulation is dropped)
    release: Release,
}

impl Drop for Triangulation {
    fn drop(&mut self) {
        self.release
            .arm_if_last(&self.tri, |t| with_tri!(t, t => t.number_of_input_points()));
    }
}

/// Gives the memory that dropping a large triangulation or Voronoi diagram freed back to
/// the system. glibc keeps freed memory in its arenas, one per thread that allocated (the
/// build and the cells allocate from every worker), so that a Python process would keep
/// the peak of a computation after `del`: 0.5 GB of 0.6 at 2·10⁵ points. The last field
/// of its owner, so that it runs after the others are dropped; the owner's `Drop` arms it.
#[derive(Default)]
struct Release {
    large: bool,
}

impl Release {
    /// Points from which a drop is worth the trim (a walk over the arenas).
    const LARGE: usize = 1 << 16;

    /// Arms the release for an owner of a shared triangulation of `points(t)` points, if
    /// the owner holds the last reference (a `Voronoi` still sharing it releases it later).
    fn arm_if_last<T>(&mut self, shared: &Arc<RwLock<T>>, points: impl Fn(&T) -> usize) {
        self.large = Arc::strong_count(shared) == 1
            && shared.read().is_ok_and(|t| points(&t) >= Self::LARGE);
    }
}

impl Drop for Release {
    fn drop(&mut self) {
        #[cfg(all(target_os = "linux", target_env = "gnu"))]
        if self.large {
            // SAFETY: `malloc_trim` only returns free memory to the system.
            unsafe {
                libc::malloc_trim(0);
            }
        }
    }
}

fn poisoned<T>(_: T) -> PyErr {
    PyRuntimeError::new_err(
        "the triangulation is unusable: a call panicked while modifying it (please report)",
    )
}

impl Triangulation {
    fn of(tri: Tri, dim: usize) -> Self {
        Triangulation {
            tri: Arc::new(RwLock::new(tri)),
            dim,
            generation: Arc::new(AtomicU64::new(0)),
            release: Release::default(),
        }
    }

    /// Shared access; waits (detached) while another thread modifies the triangulation.
    fn read(&self, py: Python<'_>) -> PyResult<RwLockReadGuard<'_, Tri>> {
        self.tri.read_py_attached(py).map_err(poisoned)
    }

    /// Exclusive access; waits (detached) while other threads use the triangulation.
    fn write(&self, py: Python<'_>) -> PyResult<RwLockWriteGuard<'_, Tri>> {
        self.tri.write_py_attached(py).map_err(poisoned)
    }
}

fn build<const D: usize, const N: usize, S: Served<D, N>>(
    py: Python<'_>,
    points: Vec<[f64; D]>,
    space: S,
    threads: Option<usize>,
) -> PyResult<Tri_<D, N, S>> {
    build_weighted(py, points, None, space, threads)
}

/// Runs `work` on a pool of `threads` threads, or on rayon's global pool (all cores) for
/// `None`.
fn in_pool<T: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> PyResult<T> + Send,
) -> PyResult<T> {
    match threads {
        None => work(),
        Some(n) if !(1..=1024).contains(&n) => Err(PyValueError::new_err(format!(
            "threads must be at least 1 and at most 1024, not {n}"
        ))),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start {n} threads: {e}")))?
            .install(work),
    }
}

/// [`build`] with weights (one per point) when given: the regular triangulation.
fn build_weighted<const D: usize, const N: usize, S: Served<D, N>>(
    py: Python<'_>,
    points: Vec<[f64; D]>,
    weights: Option<Vec<f64>>,
    space: S,
    threads: Option<usize>,
) -> PyResult<Tri_<D, N, S>> {
    let total = points.len() as u64;
    interruptible(py, points.len(), ("triangulating", total), move |control| {
        in_pool(threads, || {
            let progress = |k: usize| {
                control.done.store(k as u64, Ordering::Relaxed);
                if control.stopped() {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            };
            let opts = BuildOptions {
                threads,
                ..BuildOptions::default()
            };
            match weights {
                Some(w) => Tri_::build_weighted_with(space, &points, &w, opts, progress),
                None => Tri_::build_with(space, &points, opts, progress),
            }
            .map_err(value_error)
        })
    })
}

/// Inserts row-major points of dimension `D`, all or nothing (the library checks every row
/// first); their input ids.
fn insert_all<const D: usize, const N: usize, S: Served<D, N>>(
    t: &mut Tri_<D, N, S>,
    flat: &[f64],
    weights: &[f64],
) -> orbitri::Result<Vec<i64>> {
    let points: Vec<[f64; D]> = flat
        .chunks_exact(D)
        .map(|q| std::array::from_fn(|c| q[c]))
        .collect();
    Ok(t.insert_all_weighted(&points, weights)?
        .into_iter()
        .map(|r| match r {
            orbitri::Inserted::New(v) | orbitri::Inserted::Duplicate(v) => {
                i64::from(t.input_of_vertex(v).0)
            }
            orbitri::Inserted::Hidden => -1,
        })
        .collect())
}

/// The rows of the simplices containing the points of `flat` (rows of `D`).
fn find_simplex<const D: usize, const N: usize, S: Served<D, N>>(
    t: &Tri_<D, N, S>,
    flat: &[f64],
) -> orbitri::Result<Vec<usize>> {
    let q: Vec<[f64; D]> = flat
        .chunks_exact(D)
        .map(|q| std::array::from_fn(|c| q[c]))
        .collect();
    t.find_simplex(&q)
}

/// Moves every input of `ids` to its row of `flat`, all or nothing.
fn move_all<const D: usize, const N: usize, S: Served<D, N>>(
    t: &mut Tri_<D, N, S>,
    ids: &[InputId],
    flat: &[f64],
) -> orbitri::Result<Vec<bool>> {
    let to: Vec<[f64; D]> = flat
        .chunks_exact(D)
        .map(|q| std::array::from_fn(|c| q[c]))
        .collect();
    t.move_all(ids, &to)
}

/// Input ids from Python: one integer or a sequence of them (Python's or numpy's; a float
/// is a TypeError, a negative or huge one an IndexError).
fn input_ids(py: Python<'_>, ids: &Bound<'_, PyAny>) -> PyResult<Vec<InputId>> {
    let raw: Vec<i64> = match ids.extract::<i64>() {
        Ok(i) => vec![i],
        Err(e) if e.is_instance_of::<PyOverflowError>(py) => {
            return Err(PyIndexError::new_err(format!("point {ids} does not exist")))
        }
        Err(_) => ids.extract::<Vec<i64>>()?,
    };
    raw.into_iter()
        .map(|i| {
            u32::try_from(i)
                .ok()
                .filter(|&i| i != u32::MAX)
                .map(InputId)
                .ok_or_else(|| PyIndexError::new_err(format!("point {i} does not exist")))
        })
        .collect()
}

/// An unknown or removed input id is an IndexError, the rest a ValueError.
fn id_error(e: orbitri::Error) -> PyErr {
    match e {
        orbitri::Error::UnknownInput { .. } => PyIndexError::new_err(e.to_string()),
        e => value_error(e),
    }
}

/// Elements as Python sees them, for an array of shape `lead`: a torus's offsets
/// (`lead × D`), a manifold's `(cosets, offsets)` (`lead` and `lead × D`).
fn py_elements<const D: usize, const N: usize, S: Served<D, N>>(
    py: Python<'_>,
    lead: &[usize],
    elements: impl IntoIterator<Item = S::Elem>,
) -> Py<PyAny> {
    let mut cosets = Vec::new();
    let mut offsets = Vec::new();
    for g in elements {
        cosets.push(g.coset());
        offsets.extend(g.offset().map(i32::from));
    }
    let mut shape = lead.to_vec();
    shape.push(D);
    let offsets = ArrayD::from_shape_vec(IxDyn(&shape), offsets)
        .expect("shape matches")
        .into_pyarray(py)
        .into_any();
    if !S::COSETS {
        return offsets.unbind();
    }
    let cosets = ArrayD::from_shape_vec(IxDyn(lead), cosets)
        .expect("shape matches")
        .into_pyarray(py)
        .into_any();
    (cosets, offsets)
        .into_pyobject(py)
        .expect("a tuple")
        .into_any()
        .unbind()
}

/// The cells of the space, one per orbit (`Triangulation::complex`): simplices, their
/// elements, neighbors, mirrors and gluings.
type ComplexArrays = (Py<PyAny>, Py<PyAny>, Py<PyAny>, Py<PyAny>, Py<PyAny>);

fn simplices<const D: usize, const N: usize, S: Served<D, N>>(
    py: Python<'_>,
    t: &Tri_<D, N, S>,
) -> PyResult<ComplexArrays> {
    let complex = t.complex().map_err(value_error)?;
    let c = complex.cells.len();
    let v: Vec<i64> = complex
        .cells
        .iter()
        .flat_map(|x| x.vertices.map(|v| i64::from(v.0)))
        .collect();
    let n: Vec<i64> = complex
        .neighbors
        .iter()
        .flat_map(|x| x.map(i64::from))
        .collect();
    let m: Vec<i64> = complex
        .mirrors
        .iter()
        .flat_map(|x| x.map(i64::from))
        .collect();
    Ok((
        array2(py, c, N, v).into_any().unbind(),
        py_elements::<D, N, S>(py, &[c, N], complex.cells.iter().flat_map(|x| x.offsets)),
        array2(py, c, N, n).into_any().unbind(),
        array2(py, c, N, m).into_any().unbind(),
        py_elements::<D, N, S>(py, &[c, N], complex.gluings.into_iter().flatten()),
    ))
}

/// (vertices, their elements, the point's element) of the cell containing `point`.
fn locate<const D: usize, const N: usize, S: Served<D, N>>(
    py: Python<'_>,
    t: &Tri_<D, N, S>,
    point: &[f64],
) -> PyResult<(Py<PyAny>, Py<PyAny>, Py<PyAny>)> {
    if point.len() != D {
        return Err(PyValueError::new_err(format!(
            "a point has {D} coordinates, not {}",
            point.len()
        )));
    }
    let (cell, o) = t
        .locate(std::array::from_fn(|c| point[c]))
        .map_err(value_error)?;
    Ok((
        cell.vertices
            .map(|v| i64::from(v.0))
            .to_vec()
            .into_pyarray(py)
            .into_any()
            .unbind(),
        py_elements::<D, N, S>(py, &[N], cell.offsets),
        py_elements::<D, N, S>(py, &[], [o]),
    ))
}

/// (pairs E×2, elements, lengths E) of the Delaunay edges, each once.
fn edges<const D: usize, const N: usize, S: Served<D, N>>(
    py: Python<'_>,
    t: &Tri_<D, N, S>,
) -> (Py<PyAny>, Py<PyAny>, Py<PyAny>) {
    let e = t.delaunay_edges();
    pair_arrays::<_, D, N, S>(py, &e, |x| (x.i, x.j, x.shift, x.length))
}

/// (pairs E×2, elements, values E) of pairs of images, each `row` giving `(i, j, element,
/// value)`.
fn pair_arrays<T, const D: usize, const N: usize, S: Served<D, N>>(
    py: Python<'_>,
    rows: &[T],
    row: impl Fn(&T) -> (InputId, InputId, S::Elem, f64),
) -> (Py<PyAny>, Py<PyAny>, Py<PyAny>) {
    let ij: Vec<i64> = rows
        .iter()
        .flat_map(|x| {
            let (i, j, ..) = row(x);
            [i64::from(i.0), i64::from(j.0)]
        })
        .collect();
    let values: Vec<f64> = rows.iter().map(|x| row(x).3).collect();
    (
        array2(py, rows.len(), 2, ij).into_any().unbind(),
        py_elements::<D, N, S>(py, &[rows.len()], rows.iter().map(|x| row(x).2)),
        values.into_pyarray(py).into_any().unbind(),
    )
}

/// (ids, elements) of the Delaunay neighbours of input point `i`.
fn vertex_neighbors<const D: usize, const N: usize, S: Served<D, N>>(
    py: Python<'_>,
    t: &Tri_<D, N, S>,
    i: usize,
) -> (Py<PyAny>, Py<PyAny>) {
    let nb = t.vertex_neighbors(InputId::new(i));
    let ids: Vec<i64> = nb.iter().map(|x| i64::from(x.0 .0)).collect();
    (
        ids.into_pyarray(py).into_any().unbind(),
        py_elements::<D, N, S>(py, &[nb.len()], nb.iter().map(|x| x.1)),
    )
}

/// The neighbour pairs by pieces ([`Tri_::voronoi_measures_and_neighbors_until`]), stopping
/// once `interrupt` says so.
fn pairs_of<const D: usize, const N: usize, S: Served<D, N>>(
    t: &Tri_<D, N, S>,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> PyResult<Vec<Neighbor<D, S::Elem>>> {
    Ok(t.voronoi_measures_and_neighbors_until(interrupt)
        .map_err(value_error)?
        .1)
}

/// The Voronoi cells of a triangulation, stopping once `interrupt` says so.
fn cells_of<const D: usize, const N: usize, S: Served<D, N>>(
    t: &Tri_<D, N, S>,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> PyResult<CellsOf<D, N, S>> {
    Ok(CellsOf {
        cells: t.voronoi_cells_until(interrupt).map_err(value_error)?,
        space: t.space().clone(),
    })
}

impl Triangulation {
    /// Points of this triangulation's dimension (rows), flat; a ValueError otherwise.
    fn rows_of(&self, points: &PyArrayLike2<'_, f64, AllowTypeChange>) -> PyResult<Vec<f64>> {
        let p = points.as_array();
        let d = self.dim;
        if p.shape()[1] != d {
            return Err(PyValueError::new_err(format!(
                "points must have {d} columns, not {}",
                p.shape()[1]
            )));
        }
        Ok(p.iter().copied().collect())
    }
}

#[pymethods]
impl Triangulation {
    /// The triangulation of a flat torus given by its lattice (rows); with `weights` (one
    /// per point, squared lengths) the regular triangulation.
    #[new]
    #[pyo3(signature = (points, lattice, weights=None, threads=None))]
    fn new(
        py: Python<'_>,
        points: PyArrayLike2<'_, f64, AllowTypeChange>,
        lattice: PyArrayLike2<'_, f64, AllowTypeChange>,
        weights: Option<PyArrayLike1<'_, f64, AllowTypeChange>>,
        threads: Option<usize>,
    ) -> PyResult<Self> {
        let p = points.as_array();
        let l = lattice.as_array();
        let w = weights.map(|w| w.as_array().to_vec());
        let d = p.shape()[1];
        if l.shape() != [d, d] {
            return Err(PyValueError::new_err(format!(
                "the box of {d}-dimensional points must be a {d}×{d} lattice, not {:?}",
                l.shape()
            )));
        }
        let tri = match d {
            2 => Tri::Two(build_weighted(py, rows(p), w, torus(l)?, threads)?),
            3 => Tri::Three(build_weighted(py, rows(p), w, torus(l)?, threads)?),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "points must have 2 or 3 columns, not {d}"
                )))
            }
        };
        Ok(Self::of(tri, d))
    }

    /// The triangulation of a closed flat manifold (a Klein bottle, a flat 3-manifold).
    #[staticmethod]
    #[pyo3(signature = (points, space, threads=None))]
    fn in_manifold(
        py: Python<'_>,
        points: PyArrayLike2<'_, f64, AllowTypeChange>,
        space: &Space,
        threads: Option<usize>,
    ) -> PyResult<Self> {
        let p = points.as_array();
        let d = space.dimension();
        if p.shape()[1] != d {
            return Err(PyValueError::new_err(format!(
                "the {} is {d}-dimensional: points must have {d} columns, not {}",
                space.name(),
                p.shape()[1]
            )));
        }
        let tri = match &space.m {
            Manifold::Two(m) => Tri::Klein(build(py, rows(p), m.clone(), threads)?),
            Manifold::Three(m) => Tri::Manifold3(build(py, rows(p), m.clone(), threads)?),
        };
        Ok(Self::of(tri, d))
    }

    /// 2 or 3.
    #[getter]
    fn dimension(&self) -> usize {
        self.dim
    }

    /// Each input's weight (None when unweighted).
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray1<f64>>>> {
        Ok(with_tri!(&*self.read(py)?, t => {
            t.is_weighted().then(|| t.weights().to_vec().into_pyarray(py))
        }))
    }

    /// The hidden input ids, sorted (weighted points whose power cell is empty).
    #[getter]
    fn hidden<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i64>>> {
        Ok(with_tri!(&*self.read(py)?, t => {
            let ids: Vec<i64> = t.hidden().iter().map(|i| i64::from(i.0)).collect();
            ids.into_pyarray(py)
        }))
    }

    /// Counts the modifications of the cells (`insert`, `try_one_sheet`).
    #[getter]
    fn generation(&self) -> u64 {
        self.generation.load(Ordering::Acquire)
    }

    /// The lattice vectors (rows) of the translations.
    #[getter]
    fn lattice<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let d = self.dim;
        Ok(with_tri!(&*self.read(py)?, t => {
            array2(py, d, d, t.space().lattice_rows().iter().flatten().copied().collect())
        }))
    }

    /// The input points wrapped into the domain, in input order.
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let d = self.dim;
        Ok(with_tri!(&*self.read(py)?, t => {
            let n = t.number_of_input_points();
            // a removed input's row is NaN
            let v: Vec<f64> = (0..n)
                .map(InputId::new)
                .flat_map(|i| {
                    if t.contains(i) {
                        t.position(i, t.space().identity()).to_vec()
                    } else {
                        vec![f64::NAN; d]
                    }
                })
                .collect();
            array2(py, n, d, v)
        }))
    }

    /// The cells of the space, one per orbit also in a covering: (simplices, elements,
    /// neighbors, mirrors, gluings); a torus's elements are its offsets, a manifold's
    /// (cosets, offsets).
    fn cells(&self, py: Python<'_>) -> PyResult<ComplexArrays> {
        with_tri!(&*self.read(py)?, t => simplices(py, t))
    }

    #[getter]
    fn sheets(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(with_tri!(&*self.read(py)?, t => t.sheets()))
    }

    #[getter]
    fn is_one_sheeted(&self, py: Python<'_>) -> PyResult<bool> {
        Ok(with_tri!(&*self.read(py)?, t => t.is_one_sheeted()))
    }

    /// Checks combinatorics and geometry exactly (without the interpreter): true, or a
    /// ValueError with the reason.
    fn is_valid(&self, py: Python<'_>) -> PyResult<bool> {
        let guard = self.read(py)?;
        let tri = &*guard;
        py.detach(|| with_tri!(tri, t => t.is_valid()))
            .map(|()| true)
            .map_err(|e| PyValueError::new_err(format!("invalid triangulation: {e}")))
    }

    /// Moves a triangulation still in a covering space to the 1-sheeted quotient if its
    /// projection is a simplicial complex; whether it is 1-sheeted.
    fn try_one_sheet(&self, py: Python<'_>) -> PyResult<bool> {
        let mut guard = self.write(py)?;
        let tri = &mut *guard;
        let one = py.detach(|| with_tri!(tri, t => t.try_one_sheet()));
        self.generation.fetch_add(1, Ordering::AcqRel);
        Ok(one)
    }

    /// Number of input points given so far.
    #[getter]
    fn number_of_input_points(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(with_tri!(&*self.read(py)?, t => t.number_of_input_points()))
    }

    /// For every input point, the input id of its first occurrence (-1 once removed).
    #[getter]
    fn duplicates<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let first = with_tri!(&*self.read(py)?, t => t.first_occurrences());
        Ok(first
            .into_iter()
            .map(|f| {
                if f == InputId::NONE {
                    -1
                } else {
                    i64::from(f.0)
                }
            })
            .collect::<Array1<i64>>()
            .into_pyarray(py))
    }

    #[getter]
    fn number_of_duplicates(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(with_tri!(&*self.read(py)?, t => t.duplicates()))
    }

    #[getter]
    fn number_of_wrapped(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(with_tri!(&*self.read(py)?, t => t.wrapped()))
    }

    /// Inserts points, all or none: every coordinate is checked first (an error names the
    /// row of `points` and the axis); returns the input id each became or coincides with.
    #[pyo3(signature = (points, weights=None))]
    fn insert<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLike2<'_, f64, AllowTypeChange>,
        weights: Option<PyArrayLike1<'_, f64, AllowTypeChange>>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let flat = self.rows_of(&points)?;
        let w = weights.map_or_else(Vec::new, |w| w.as_array().to_vec());
        let mut guard = self.write(py)?;
        let tri = &mut *guard;
        let ids = py
            .detach(|| with_tri!(tri, t => insert_all(t, &flat, &w)))
            .map_err(value_error)?;
        self.generation.fetch_add(1, Ordering::AcqRel);
        Ok(Array1::from(ids).into_pyarray(py))
    }

    /// Removes input points (one id or a sequence of ids), all or none: an id never given,
    /// removed, negative or given twice is an IndexError naming it. Returns how many
    /// removals had to triangulate the remaining points again (0 or 1).
    fn remove(&self, py: Python<'_>, ids: &Bound<'_, PyAny>) -> PyResult<usize> {
        let ids = input_ids(py, ids)?;
        let mut guard = self.write(py)?;
        let tri = &mut *guard;
        let how = py
            .detach(|| with_tri!(tri, t => t.remove_all(&ids)))
            .map_err(id_error)?;
        self.generation.fetch_add(1, Ordering::AcqRel);
        Ok((how == orbitri::Removal::Rebuilt) as usize)
    }

    /// Moves input points `ids` to `points` (rows), keeping their ids, all or none: ids
    /// and coordinates are checked first (by the library's `move_all`). Returns per point whether the move changed its
    /// coordinates alone (the cells around it stayed Delaunay).
    #[pyo3(name = "move")]
    fn move_points<'py>(
        &self,
        py: Python<'py>,
        ids: &Bound<'_, PyAny>,
        points: PyArrayLike2<'_, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let ids = input_ids(py, ids)?;
        let p = points.as_array();
        let d = self.dim;
        if p.shape() != [ids.len(), d] {
            return Err(PyValueError::new_err(format!(
                "{} ids need {} points of {d} coordinates, not an array of shape {:?}",
                ids.len(),
                ids.len(),
                p.shape()
            )));
        }
        let flat: Vec<f64> = p.iter().copied().collect();
        let mut guard = self.write(py)?;
        let tri = &mut *guard;
        let fast = py
            .detach(|| with_tri!(tri, t => move_all(t, &ids, &flat)))
            .map_err(id_error)?;
        self.generation.fetch_add(1, Ordering::AcqRel);
        Ok(Array1::from(fast).into_pyarray(py))
    }

    /// For every query point (rows), the row of `cells()`'s simplices containing it,
    /// located in parallel without the interpreter.
    fn find_simplex<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLike2<'_, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let flat = self.rows_of(&points)?;
        let guard = self.read(py)?;
        let tri = &*guard;
        let rows = py
            .detach(|| with_tri!(tri, t => find_simplex(t, &flat)))
            .map_err(value_error)?;
        Ok(rows
            .into_iter()
            .map(|r| r as i64)
            .collect::<Array1<i64>>()
            .into_pyarray(py))
    }

    /// (vertices, their elements, the point's element) of the cell containing a point.
    fn locate(
        &self,
        py: Python<'_>,
        point: Vec<f64>,
    ) -> PyResult<(Py<PyAny>, Py<PyAny>, Py<PyAny>)> {
        // the walk only reads: concurrent readers may locate in parallel
        with_tri!(&*self.read(py)?, t => locate(py, t, &point))
    }

    /// (pairs E×2, elements, lengths E) of the Delaunay edges, each once.
    fn edges(&self, py: Python<'_>) -> PyResult<(Py<PyAny>, Py<PyAny>, Py<PyAny>)> {
        Ok(with_tri!(&*self.read(py)?, t => edges(py, t)))
    }

    /// (ids, elements) of the Delaunay neighbours of input point `i`: any integer (Python's
    /// or numpy's, not a float or a string), `0 <= i < number_of_input_points`.
    fn vertex_neighbors(
        &self,
        py: Python<'_>,
        i: &Bound<'_, PyAny>,
    ) -> PyResult<(Py<PyAny>, Py<PyAny>)> {
        let guard = self.read(py)?;
        let n = with_tri!(&*guard, t => t.number_of_input_points());
        let out_of_range = || {
            PyIndexError::new_err(format!(
                "point {} does not exist: the ids of the {n} input points are 0 to {}",
                i.str().map_or_else(|_| "?".into(), |s| s.to_string()),
                n as i64 - 1
            ))
        };
        // `__index__`: a float or a string is a TypeError, a huge int out of range
        let i = match i.extract::<i64>() {
            Ok(i) => i,
            Err(e) if e.is_instance_of::<PyOverflowError>(py) => return Err(out_of_range()),
            Err(e) => return Err(e),
        };
        let i = usize::try_from(i)
            .ok()
            .filter(|&i| i < n)
            .ok_or_else(out_of_range)?;
        if !with_tri!(&*guard, t => t.contains(InputId::new(i))) {
            return Err(PyIndexError::new_err(format!("point {i} was removed")));
        }
        Ok(with_tri!(&*guard, t => vertex_neighbors(py, t, i)))
    }

    /// The Voronoi cells of the points: their measures now (computed without holding the
    /// interpreter; Ctrl-C stops them), the cells themselves on first use.
    fn voronoi(&self, py: Python<'_>) -> PyResult<Voronoi> {
        let (vertices, total) = with_tri!(&*self.read(py)?, t => {
            t.space().check_volume_representable().map_err(value_error)?;
            (t.number_of_vertices(), t.voronoi_polls())
        });
        let shared = Arc::clone(&self.tri);
        let generation = Arc::clone(&self.generation);
        // each poll follows about the same work: one unit of progress
        let (per_point, cells, at) =
            interruptible(py, vertices, ("Voronoi cells", total), move |control| {
                let interrupt = || control.poll();
                let guard = shared.read().map_err(poisoned)?;
                let at = generation.load(Ordering::Acquire);
                let (per_point, cells) = with_tri!(&*guard, t => {
                    let m = t.voronoi_measures_until(&interrupt).map_err(value_error)?;
                    (PerPoint::of(&m, &t.first_occurrences()), m.len())
                });
                Ok((per_point, cells, at))
            })?;
        Ok(Voronoi {
            per_point,
            cells,
            tri: Arc::clone(&self.tri),
            generation: Arc::clone(&self.generation),
            at,
            geometry: OnceLock::new(),
            release: Release::default(),
        })
    }
}

/// The Voronoi cells of the distinct points (sorted by input id), and the space (for the
/// elements' inverses).
struct CellsOf<const D: usize, const N: usize, S: Served<D, N>> {
    cells: Vec<VoronoiCell<D, S::Elem>>,
    space: S,
}

/// The cells of any space.
enum Cells {
    Two(CellsOf<2, 3, FlatTorus<2>>),
    Three(CellsOf<3, 4, FlatTorus<3>>),
    Klein(CellsOf<2, 3, FlatManifold<2>>),
    Manifold3(CellsOf<3, 4, FlatManifold<3>>),
}

/// The neighbour pairs of any space (`Voronoi.neighbors()` without the cells' geometry).
enum Pairs {
    Two(Vec<Neighbor<2, <FlatTorus<2> as OrbitSpace<3>>::Elem>>),
    Three(Vec<Neighbor<3, <FlatTorus<3> as OrbitSpace<4>>::Elem>>),
    Klein(Vec<Neighbor<2, <FlatManifold<2> as OrbitSpace<3>>::Elem>>),
    Manifold3(Vec<Neighbor<3, <FlatManifold<3> as OrbitSpace<4>>::Elem>>),
}

/// (pairs E×2, elements, areas E) of neighbour pairs.
fn neighbor_arrays<const D: usize, const N: usize, S: Served<D, N>>(
    py: Python<'_>,
    pairs: &[Neighbor<D, S::Elem>],
) -> (Py<PyAny>, Py<PyAny>, Py<PyAny>) {
    pair_arrays::<_, D, N, S>(py, pairs, |p| (p.i, p.j, p.shift, p.area))
}

impl<const D: usize, const N: usize, S: Served<D, N>> CellsOf<D, N, S> {
    /// (pairs E×2, elements, areas E): each pair of neighbouring images once.
    fn neighbors(&self, py: Python<'_>) -> (Py<PyAny>, Py<PyAny>, Py<PyAny>) {
        let pairs = orbitri::voronoi::neighbor_pairs_by(&self.cells, |g| {
            OrbitSpace::<N>::inverse(&self.space, g)
        });
        neighbor_arrays::<D, N, S>(py, &pairs)
    }

    /// Every distinct point's cell as a dict.
    fn dicts<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.cells
            .iter()
            .map(|cell| {
                let d = PyDict::new(py);
                d.set_item("id", cell.point.0)?;
                d.set_item("position", cell.position.to_vec())?;
                d.set_item("volume", cell.volume)?;
                d.set_item("centroid", cell.centroid.to_vec())?;
                let v = cell.vertices.iter().flatten().copied().collect();
                d.set_item("vertices", array2(py, cell.vertices.len(), D, v))?;
                let faces = cell
                    .faces
                    .iter()
                    .map(|f| {
                        let fd = PyDict::new(py);
                        fd.set_item("vertices", f.vertices.clone())?;
                        fd.set_item("neighbor", f.neighbor.0)?;
                        let offset = f.shift.offset().to_vec();
                        match S::COSETS {
                            true => fd.set_item("element", (f.shift.coset(), offset))?,
                            false => fd.set_item("shift", offset)?,
                        }
                        fd.set_item("area", f.area)?;
                        Ok(fd)
                    })
                    .collect::<PyResult<Vec<_>>>()?;
                d.set_item("faces", faces)?;
                Ok(d)
            })
            .collect()
    }
}

/// Every input point's cell measures (a duplicate's are its first occurrence's).
struct PerPoint {
    volumes: Vec<f64>,
    counts: Vec<i64>,
    surfaces: Vec<f64>,
    /// N × D, flat.
    centroids: Vec<f64>,
    dimension: usize,
}

impl PerPoint {
    /// Per input, from the measures of the distinct points (sorted by input id) and every
    /// input's first occurrence: a duplicate gets its first occurrence's, a removed input
    /// NaN (and −1 faces).
    fn of<const D: usize>(measures: &[CellMeasures<D>], first: &[InputId]) -> Self {
        let gone = CellMeasures {
            point: InputId::NONE,
            volume: f64::NAN,
            faces: u32::MAX,
            surface_area: f64::NAN,
            centroid: [f64::NAN; D],
        };
        let m: Vec<CellMeasures<D>> = first
            .iter()
            .map(|f| {
                measures
                    .binary_search_by_key(f, |c| c.point)
                    .map_or(gone, |k| measures[k])
            })
            .collect();
        PerPoint {
            volumes: m.iter().map(|x| x.volume).collect(),
            counts: m
                .iter()
                .map(|x| {
                    if x.faces == u32::MAX {
                        -1
                    } else {
                        i64::from(x.faces)
                    }
                })
                .collect(),
            surfaces: m.iter().map(|x| x.surface_area).collect(),
            centroids: m.iter().flat_map(|x| x.centroid).collect(),
            dimension: D,
        }
    }
}

/// The Voronoi cells of a triangulation (use `PeriodicDelaunay.voronoi()` or
/// `Triangulation.voronoi()`).
///
/// The measures are computed at once; the cells' geometry (`cells()`, `neighbors()`) on
/// first use, from the same triangulation: it is an error once the triangulation has
/// changed (rather than the cells of another triangulation, or a copy of every cell kept
/// in case: three times the memory of the measures at 10⁶ points).
#[pyclass(module = "orbitri._orbitri")]
struct Voronoi {
    per_point: PerPoint,
    /// Number of distinct cells.
    cells: usize,
    tri: Arc<RwLock<Tri>>,
    generation: Arc<AtomicU64>,
    /// The triangulation's generation when measured.
    at: u64,
    geometry: OnceLock<Cells>,
    /// (last: runs once the cells, and the triangulation if no one else holds it, are
    /// dropped)
    release: Release,
}

impl Drop for Voronoi {
    fn drop(&mut self) {
        self.release.large = self.cells >= Release::LARGE;
    }
}

/// An error once the triangulation has changed since `voronoi()` measured it (at `at`).
fn unchanged(generation: &AtomicU64, at: u64) -> PyResult<()> {
    if generation.load(Ordering::Acquire) != at {
        return Err(PyValueError::new_err(
            "the triangulation has changed since voronoi() measured it: call voronoi() \
             again for the cells and neighbours of the triangulation as it is now",
        ));
    }
    Ok(())
}

impl Voronoi {
    /// The neighbour pairs by pieces, without the cells (a third of their memory); an
    /// error once the triangulation changed.
    fn pairs(&self, py: Python<'_>) -> PyResult<Pairs> {
        self.on_measured(py, "Voronoi neighbours", |tri, interrupt| {
            Ok(match tri {
                Tri::Two(t) => Pairs::Two(pairs_of(t, interrupt)?),
                Tri::Three(t) => Pairs::Three(pairs_of(t, interrupt)?),
                Tri::Klein(t) => Pairs::Klein(pairs_of(t, interrupt)?),
                Tri::Manifold3(t) => Pairs::Manifold3(pairs_of(t, interrupt)?),
            })
        })
    }

    /// `work` on the triangulation that `voronoi()` measured (interruptible, reported as
    /// `phase`); an error once it has changed.
    fn on_measured<T: Send + 'static>(
        &self,
        py: Python<'_>,
        phase: &str,
        work: impl FnOnce(&Tri, &(dyn Fn() -> bool + Sync)) -> PyResult<T> + Send + 'static,
    ) -> PyResult<T> {
        let shared = Arc::clone(&self.tri);
        let generation = Arc::clone(&self.generation);
        let at = self.at;
        let total =
            with_tri!(&*self.tri.read_py_attached(py).map_err(poisoned)?, t => t.voronoi_polls());
        interruptible(py, self.cells, (phase, total), move |control| {
            let interrupt = || control.poll();
            let guard = shared.read().map_err(poisoned)?;
            unchanged(&generation, at)?;
            work(&guard, &interrupt)
        })
    }

    /// The cells' geometry, computed on first use; an error once the triangulation changed.
    fn geometry(&self, py: Python<'_>) -> PyResult<&Cells> {
        if let Some(c) = self.geometry.get() {
            return Ok(c);
        }
        let cells = self.on_measured(py, "Voronoi cells", |tri, interrupt| {
            Ok(match tri {
                Tri::Two(t) => Cells::Two(cells_of(t, interrupt)?),
                Tri::Three(t) => Cells::Three(cells_of(t, interrupt)?),
                Tri::Klein(t) => Cells::Klein(cells_of(t, interrupt)?),
                Tri::Manifold3(t) => Cells::Manifold3(cells_of(t, interrupt)?),
            })
        })?;
        // (another thread may have set it meanwhile: the same cells)
        let _ = self.geometry.set(cells);
        Ok(self.geometry.get().expect("just set"))
    }
}

#[pymethods]
impl Voronoi {
    /// Volume (area in 2D) of every input point's cell.
    #[getter]
    fn volumes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.per_point.volumes.clone().into_pyarray(py)
    }

    /// Number of faces (neighbour images) of every input point's cell.
    #[getter]
    fn neighbor_counts<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        self.per_point.counts.clone().into_pyarray(py)
    }

    /// Surface area (perimeter in 2D) of every input point's cell.
    #[getter]
    fn surface_areas<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.per_point.surfaces.clone().into_pyarray(py)
    }

    /// Centroid of every input point's cell (Cartesian, near the point).
    #[getter]
    fn centroids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let p = &self.per_point;
        array2(py, p.volumes.len(), p.dimension, p.centroids.clone())
    }

    /// (pairs E×2, elements, areas E): each pair of neighbouring images once; a torus's
    /// elements are shifts (E×D), a manifold's (cosets E, offsets E×D).
    fn neighbors(&self, py: Python<'_>) -> PyResult<(Py<PyAny>, Py<PyAny>, Py<PyAny>)> {
        if let Some(cells) = self.geometry.get() {
            return Ok(with_cells!(cells, c => c.neighbors(py)));
        }
        Ok(match self.pairs(py)? {
            Pairs::Two(p) => neighbor_arrays::<2, 3, FlatTorus<2>>(py, &p),
            Pairs::Three(p) => neighbor_arrays::<3, 4, FlatTorus<3>>(py, &p),
            Pairs::Klein(p) => neighbor_arrays::<2, 3, FlatManifold<2>>(py, &p),
            Pairs::Manifold3(p) => neighbor_arrays::<3, 4, FlatManifold<3>>(py, &p),
        })
    }

    /// Every distinct point's cell as a dict: id, position, volume, centroid, vertices
    /// (K×D) and faces (dicts of vertices, neighbor, shift or element, area).
    fn cells<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        with_cells!(self.geometry(py)?, c => c.dicts(py))
    }

    fn __len__(&self) -> usize {
        self.cells
    }
}

/// A closed flat manifold of dimension 2 or 3.
#[derive(Clone)]
enum Manifold {
    Two(FlatManifold<2>),
    Three(FlatManifold<3>),
}

/// Runs `$body` with `$m` bound to the manifold of either dimension.
macro_rules! with_manifold {
    ($space:expr, $m:ident => $body:expr) => {
        match &$space.m {
            Manifold::Two($m) => $body,
            Manifold::Three($m) => $body,
        }
    };
}

/// An isometry `x ↦ A·x + t` as `(A, t)`.
type Isometry<const D: usize> = ([[f64; D]; D], [f64; D]);

/// Isometries as arrays: `A` (K×D×D), `t` (K×D).
fn isometry_arrays<const D: usize>(py: Python<'_>, list: &[Isometry<D>]) -> (Py<PyAny>, Py<PyAny>) {
    let a: Vec<f64> = list
        .iter()
        .flat_map(|x| x.0.into_iter().flatten())
        .collect();
    let t: Vec<f64> = list.iter().flat_map(|x| x.1).collect();
    (
        Array3::from_shape_vec((list.len(), D, D), a)
            .expect("shape matches")
            .into_pyarray(py)
            .into_any()
            .unbind(),
        array2(py, list.len(), D, t).into_any().unbind(),
    )
}

/// The isometries of the elements `(cosets[k], offsets[k])`; a `ValueError` names an element
/// that does not exist.
fn isometries<const D: usize>(
    m: &FlatManifold<D>,
    cosets: &[i64],
    offsets: ArrayView2<'_, i64>,
) -> PyResult<Vec<Isometry<D>>> {
    if offsets.shape() != [cosets.len(), D] {
        return Err(PyValueError::new_err(format!(
            "{} cosets need offsets of shape ({}, {D}), not {:?}",
            cosets.len(),
            cosets.len(),
            offsets.shape()
        )));
    }
    let k = m.index() as i64;
    cosets
        .iter()
        .zip(offsets.outer_iter())
        .map(|(&c, o)| {
            let coset = u8::try_from(c).ok().filter(|&c| i64::from(c) < k);
            let coset = coset.ok_or_else(|| {
                PyValueError::new_err(format!(
                    "coset {c} does not exist: the {} has cosets 0 to {}",
                    m.name(),
                    k - 1
                ))
            })?;
            let offset = o
                .iter()
                .map(|&x| i8::try_from(x))
                .collect::<Result<Vec<i8>, _>>()
                .map_err(|_| {
                    PyValueError::new_err(format!(
                        "offset {o} is out of range: its entries are -128 to 127"
                    ))
                })?;
            let offset = std::array::from_fn(|i| offset[i]);
            Ok(m.isometry(Motion { coset, offset }))
        })
        .collect()
}

/// A closed flat manifold (use `orbitri.FlatManifold` or `orbitri.KleinBottle`).
#[pyclass(module = "orbitri._orbitri", frozen)]
struct Space {
    m: Manifold,
}

#[pymethods]
impl Space {
    /// The Klein bottle `"klein"` of sides `[a, b]`, or the platycosm `name` of sides
    /// `[L1, L2, L3]`.
    #[new]
    fn new(name: &str, sides: Vec<f64>) -> PyResult<Self> {
        let n = sides.len();
        let m = match (name, &sides[..]) {
            ("klein", &[a, b]) => FlatManifold::klein_bottle(a, b).map(Manifold::Two),
            ("klein", _) => {
                return Err(PyValueError::new_err(format!(
                    "the Klein bottle takes 2 sides, [a, b], not {n}"
                )))
            }
            (_, &[a, b, c]) => FlatManifold::platycosm(name, [a, b, c]).map(Manifold::Three),
            // an unknown name: the library's error, which names the known ones
            _ if !FlatManifold::PLATYCOSMS.contains(&name) => {
                FlatManifold::platycosm(name, [1.0; 3]).map(Manifold::Three)
            }
            _ => {
                return Err(PyValueError::new_err(format!(
                    "the {name} takes 3 sides, [L1, L2, L3], not {n}"
                )))
            }
        };
        Ok(Space {
            m: m.map_err(value_error)?,
        })
    }

    #[getter]
    fn name(&self) -> &'static str {
        with_manifold!(self, m => m.name())
    }

    #[getter]
    fn dimension(&self) -> usize {
        match self.m {
            Manifold::Two(_) => 2,
            Manifold::Three(_) => 3,
        }
    }

    /// The number of cosets of the translations.
    #[getter]
    fn index(&self) -> usize {
        with_manifold!(self, m => m.index())
    }

    #[getter]
    fn volume(&self) -> f64 {
        with_manifold!(self, m => m.volume())
    }

    #[getter]
    fn is_orientable(&self) -> bool {
        with_manifold!(self, m => m.is_orientable())
    }

    #[getter]
    fn systole(&self) -> f64 {
        with_manifold!(self, m => m.systole())
    }

    /// The lattice vectors (rows) of the translations.
    #[getter]
    fn translations<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let d = self.dimension();
        with_manifold!(self, m => {
            array2(py, d, d, m.translations().vectors().iter().flatten().copied().collect())
        })
    }

    /// (A, t) of the generators: the translations, then the coset representatives 1….
    #[getter]
    fn generators(&self, py: Python<'_>) -> (Py<PyAny>, Py<PyAny>) {
        with_manifold!(self, m => isometry_arrays(py, &m.generators()))
    }

    /// (A, t) of the elements `(cosets[k], offsets[k])`.
    fn isometries(
        &self,
        py: Python<'_>,
        cosets: PyArrayLike1<'_, i64, AllowTypeChange>,
        offsets: PyArrayLike2<'_, i64, AllowTypeChange>,
    ) -> PyResult<(Py<PyAny>, Py<PyAny>)> {
        let c = cosets.as_array().to_vec();
        let o = offsets.as_array();
        with_manifold!(self, m => Ok(isometry_arrays(py, &isometries(m, &c, o)?)))
    }
}

/// The lattice vectors (rows) of a cell given by lengths and angles in degrees: `[a, b, c,
/// alpha, beta, gamma]` (3 × 3) or `[a, b, gamma]` (2 × 2); a ValueError for a cell that
/// does not exist.
#[pyfunction]
fn cellpar_matrix<'py>(py: Python<'py>, p: Vec<f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    match p[..] {
        [a, b, c, alpha, beta, gamma] => {
            let m = orbitri::io::lattice_from_cellpar([a, b, c, alpha, beta, gamma]);
            Ok(array2(py, 3, 3, m.map_err(value_error)?.as_flattened().to_vec()))
        }
        [a, b, gamma] => {
            let m = orbitri::io::lattice_from_cellpar2([a, b, gamma]);
            Ok(array2(py, 2, 2, m.map_err(value_error)?.as_flattened().to_vec()))
        }
        _ => Err(PyValueError::new_err(format!(
            "lengths and angles are [a, b, c, alpha, beta, gamma] (3D) or [a, b, gamma] (2D), not {} numbers",
            p.len()
        ))),
    }
}

#[pymodule]
fn _orbitri(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(cellpar_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(set_progress_hook, m)?)?;
    m.add_class::<Triangulation>()?;
    m.add_class::<Voronoi>()?;
    m.add_class::<Space>()?;
    m.add_class::<sphere::PySpherical>()?;
    m.add_class::<sphere::SphericalVoronoi>()?;
    m.add("PLATYCOSMS", FlatManifold::PLATYCOSMS.to_vec())?;
    Ok(())
}
