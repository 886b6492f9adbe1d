//! The Python extension `orbitri._orbitri`: the triangulation and its Voronoi cells for numpy
//! arrays. The Python package (`python/orbitri`) parses boxes and documents the API; this
//! module converts arrays (one copy of the input), releases the interpreter during
//! construction, insertion and the Voronoi cells, and turns errors into `ValueError` with the
//! library's message.
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
use std::sync::{mpsc, Arc, Mutex, RwLock, RwLockReadGuard, RwLockWriteGuard};
use std::time::Duration;

use numpy::ndarray::{Array1, Array2, Array3, ArrayView2};
use numpy::{AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArrayLike2};
use orbitri::triangulation::Torus;
use orbitri::{
    BuildOptions, CellMeasures, FlatTorus, PeriodicDelaunay, PeriodicDelaunay2, PeriodicDelaunay3,
    VoronoiCell,
};
use pyo3::exceptions::{PyIndexError, PyOverflowError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::RwLockExt;
use pyo3::types::PyDict;

fn value_error(e: orbitri::Error) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// How often the main thread runs the signal handlers while a long computation runs.
const POLL: Duration = Duration::from_millis(50);

/// Inputs smaller than this (points, vertices) are computed on the calling thread: they end
/// sooner than a helper thread would be worth.
const SMALL: usize = 20_000;

/// Runs `work` (of `size` points) without the interpreter and answers Ctrl-C.
///
/// On the main thread (the only one that receives signals), unless the input is small,
/// `work` runs on a helper thread while this one waits detached and runs the signal handlers
/// every `POLL`. Once a handler raises (`KeyboardInterrupt`), the call returns that
/// exception at once: `work` sees `stop` raised at its next poll and ends in the background,
/// its result dropped. Elsewhere `work` runs here, and `stop` is never raised.
fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    size: usize,
    work: impl FnOnce(&AtomicBool) -> PyResult<T> + Send + 'static,
) -> PyResult<T> {
    let threading = py.import("threading")?;
    let main = threading
        .call_method0("main_thread")?
        .is(&threading.call_method0("current_thread")?);
    if !main || size < SMALL {
        return py.detach(|| work(&AtomicBool::new(false)));
    }
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let (tx, rx) = mpsc::channel();
    let worker = std::thread::Builder::new()
        .name("orbitri".into())
        // the main thread's size: the work would have run there
        .stack_size(8 << 20)
        .spawn(move || {
            let _ = tx.send(work(&flag));
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
    // a `Receiver` is not `Sync`: the lock (only ever taken here) lets the wait run detached
    let rx = Mutex::new(rx);
    loop {
        let next = py.detach(|| rx.lock().expect("one waiter").recv_timeout(POLL));
        match next {
            Ok(result) => return result,
            Err(mpsc::RecvTimeoutError::Timeout) => {
                if let Err(e) = py.check_signals() {
                    stop.store(true, Ordering::Relaxed);
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

fn matrix<const D: usize>(a: ArrayView2<'_, f64>) -> [[f64; D]; D] {
    std::array::from_fn(|i| std::array::from_fn(|j| a[[i, j]]))
}

enum Tri {
    Two(PeriodicDelaunay2),
    Three(PeriodicDelaunay3),
}

/// Runs `$body` with `$t` bound to the triangulation of either dimension.
macro_rules! with_tri {
    ($tri:expr, $t:ident => $body:expr) => {
        match $tri {
            Tri::Two($t) => $body,
            Tri::Three($t) => $body,
        }
    };
}

/// Runs `$body` with `$c` bound to the cells of either dimension and `$first` to the first
/// occurrences.
macro_rules! with_cells {
    ($cells:expr, $c:ident, $first:ident => $body:expr) => {
        match $cells {
            Cells::Two($c, $first) => $body,
            Cells::Three($c, $first) => $body,
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

/// A periodic Delaunay triangulation (use `orbitri.PeriodicDelaunay`), shareable between
/// threads.
#[pyclass(module = "orbitri._orbitri", frozen)]
struct Triangulation {
    /// Shared with a computation that may outlive an interrupted call (`voronoi`).
    tri: Arc<RwLock<Tri>>,
    /// 2 or 3 (never changes: read without the lock).
    dim: usize,
    /// Counts the modifications of the cells (for the Python side's cache of `cells()`).
    generation: AtomicU64,
}

fn poisoned<T>(_: T) -> PyErr {
    PyRuntimeError::new_err(
        "the triangulation is unusable: a call panicked while modifying it (please report)",
    )
}

impl Triangulation {
    /// Shared access; waits (detached) while another thread modifies the triangulation.
    fn read(&self, py: Python<'_>) -> PyResult<RwLockReadGuard<'_, Tri>> {
        self.tri.read_py_attached(py).map_err(poisoned)
    }

    /// Exclusive access; waits (detached) while other threads use the triangulation.
    fn write(&self, py: Python<'_>) -> PyResult<RwLockWriteGuard<'_, Tri>> {
        self.tri.write_py_attached(py).map_err(poisoned)
    }
}

fn build<const D: usize, const N: usize>(
    py: Python<'_>,
    points: Vec<[f64; D]>,
    lattice: [[f64; D]; D],
) -> PyResult<PeriodicDelaunay<D, N>>
where
    FlatTorus<D>: Torus<D, N>,
{
    interruptible(py, points.len(), move |stop| {
        let torus = FlatTorus::<D>::triclinic(lattice).map_err(value_error)?;
        PeriodicDelaunay::build_with(torus, &points, BuildOptions::default(), |_| {
            if stop.load(Ordering::Relaxed) {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        .map_err(value_error)
    })
}

/// Inserts row-major points of dimension `D`, all or nothing (the library checks every row
/// first); their input ids.
fn insert_all<const D: usize, const N: usize>(
    t: &mut PeriodicDelaunay<D, N>,
    flat: &[f64],
) -> orbitri::Result<Vec<i64>>
where
    FlatTorus<D>: Torus<D, N>,
{
    let points: Vec<[f64; D]> = flat
        .chunks_exact(D)
        .map(|q| std::array::from_fn(|c| q[c]))
        .collect();
    Ok(t.insert_all(&points)?
        .into_iter()
        .map(|r| {
            let (orbitri::Inserted::New(v) | orbitri::Inserted::Duplicate(v)) = r;
            i64::from(t.input_of_vertex(v))
        })
        .collect())
}

fn simplices<const D: usize, const N: usize>(
    py: Python<'_>,
    t: &PeriodicDelaunay<D, N>,
) -> (Py<PyAny>, Py<PyAny>, Py<PyAny>)
where
    FlatTorus<D>: Torus<D, N>,
{
    let (cells, nbrs) = t.cells_with_neighbors();
    let c = cells.len();
    let v: Vec<i64> = cells
        .iter()
        .flat_map(|x| x.vertices.map(i64::from))
        .collect();
    let o: Vec<i32> = cells
        .iter()
        .flat_map(|x| x.offsets.into_iter().flatten().map(i32::from))
        .collect();
    let n: Vec<i64> = nbrs.iter().flat_map(|x| x.map(i64::from)).collect();
    (
        array2(py, c, N, v).into_any().unbind(),
        Array3::from_shape_vec((c, N, D), o)
            .expect("shape matches")
            .into_pyarray(py)
            .into_any()
            .unbind(),
        array2(py, c, N, n).into_any().unbind(),
    )
}

#[pymethods]
impl Triangulation {
    #[new]
    fn new(
        py: Python<'_>,
        points: PyArrayLike2<'_, f64, AllowTypeChange>,
        lattice: PyArrayLike2<'_, f64, AllowTypeChange>,
    ) -> PyResult<Self> {
        let p = points.as_array();
        let l = lattice.as_array();
        let d = p.shape()[1];
        if l.shape() != [d, d] {
            return Err(PyValueError::new_err(format!(
                "the box of {d}-dimensional points must be a {d}×{d} lattice, not {:?}",
                l.shape()
            )));
        }
        let tri = match d {
            2 => Tri::Two(build::<2, 3>(py, rows(p), matrix(l))?),
            3 => Tri::Three(build::<3, 4>(py, rows(p), matrix(l))?),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "points must have 2 or 3 columns, not {d}"
                )))
            }
        };
        Ok(Triangulation {
            tri: Arc::new(RwLock::new(tri)),
            dim: d,
            generation: AtomicU64::new(0),
        })
    }

    /// 2 or 3.
    #[getter]
    fn dimension(&self) -> usize {
        self.dim
    }

    /// Counts the modifications of the cells (`insert`, `try_one_sheet`).
    #[getter]
    fn generation(&self) -> u64 {
        self.generation.load(Ordering::Acquire)
    }

    /// The lattice vectors (rows).
    #[getter]
    fn lattice<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(with_tri!(&*self.read(py)?, t => {
            let m = t.space().lattice().vectors();
            array2(py, m.len(), m.len(), m.iter().flatten().copied().collect())
        }))
    }

    /// The input points wrapped into the domain, in input order.
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let d = self.dim;
        Ok(with_tri!(&*self.read(py)?, t => {
            let n = t.number_of_input_points();
            let v: Vec<f64> = (0..n)
                .flat_map(|i| t.point(t.vertex_of_input(i)))
                .collect();
            array2(py, n, d, v)
        }))
    }

    /// (simplices, offsets, neighbors) of every stored cell.
    fn cells(&self, py: Python<'_>) -> PyResult<(Py<PyAny>, Py<PyAny>, Py<PyAny>)> {
        Ok(with_tri!(&*self.read(py)?, t => simplices(py, t)))
    }

    #[getter]
    fn sheets(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(with_tri!(&*self.read(py)?, t => t.sheets()))
    }

    #[getter]
    fn is_one_sheeted(&self, py: Python<'_>) -> PyResult<bool> {
        Ok(with_tri!(&*self.read(py)?, t => t.is_one_sheeted()))
    }

    /// Moves a triangulation still in a covering space to the 1-sheeted torus if its
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

    /// For every input point, the input id of its first occurrence.
    #[getter]
    fn duplicates<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let first = with_tri!(&*self.read(py)?, t => t.first_occurrences());
        Ok(first
            .into_iter()
            .map(i64::from)
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
    fn insert<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLike2<'_, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let p = points.as_array();
        let d = self.dim;
        if p.shape()[1] != d {
            return Err(PyValueError::new_err(format!(
                "points must have {d} columns, not {}",
                p.shape()[1]
            )));
        }
        let flat: Vec<f64> = p.iter().copied().collect();
        let mut guard = self.write(py)?;
        let tri = &mut *guard;
        let ids = py
            .detach(|| with_tri!(tri, t => insert_all(t, &flat)))
            .map_err(value_error)?;
        self.generation.fetch_add(1, Ordering::AcqRel);
        Ok(Array1::from(ids).into_pyarray(py))
    }

    /// (vertices, offsets, point offset) of the cell containing a point.
    fn locate(
        &self,
        py: Python<'_>,
        point: Vec<f64>,
    ) -> PyResult<(Py<PyAny>, Py<PyAny>, Py<PyAny>)> {
        with_tri!(&mut *self.write(py)?, t => {
            let d = t.space().lattice().vectors().len();
            if point.len() != d {
                return Err(PyValueError::new_err(format!(
                    "a point has {d} coordinates, not {}",
                    point.len()
                )));
            }
            let q = std::array::from_fn(|c| point[c]);
            let (cell, o) = t.locate(q).map_err(value_error)?;
            let n = cell.vertices.len();
            Ok((
                cell.vertices.map(i64::from).to_vec().into_pyarray(py).into_any().unbind(),
                array2(py, n, d, cell.offsets.iter().flatten().map(|&x| i32::from(x)).collect())
                    .into_any()
                    .unbind(),
                o.map(i32::from).to_vec().into_pyarray(py).into_any().unbind(),
            ))
        })
    }

    /// (pairs E×2, shifts E×D, lengths E) of the Delaunay edges, each once.
    fn edges(&self, py: Python<'_>) -> PyResult<(Py<PyAny>, Py<PyAny>, Py<PyAny>)> {
        Ok(with_tri!(&*self.read(py)?, t => {
            let e = t.delaunay_edges();
            let d = t.space().lattice().vectors().len();
            let ij: Vec<i64> = e.iter().flat_map(|x| [i64::from(x.i), i64::from(x.j)]).collect();
            let s: Vec<i32> = e.iter().flat_map(|x| x.shift.map(i32::from)).collect();
            let l: Vec<f64> = e.iter().map(|x| x.length).collect();
            (
                array2(py, e.len(), 2, ij).into_any().unbind(),
                array2(py, e.len(), d, s).into_any().unbind(),
                l.into_pyarray(py).into_any().unbind(),
            )
        }))
    }

    /// (ids, shifts) of the Delaunay neighbours of input point `i`: any integer (Python's
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
        with_tri!(&*guard, t => {
            let nb = t.vertex_neighbors(i);
            let d = t.space().lattice().vectors().len();
            let ids: Vec<i64> = nb.iter().map(|x| i64::from(x.0)).collect();
            let s: Vec<i32> = nb.iter().flat_map(|x| x.1.map(i32::from)).collect();
            Ok((
                ids.into_pyarray(py).into_any().unbind(),
                array2(py, nb.len(), d, s).into_any().unbind(),
            ))
        })
    }

    /// The Voronoi cells of the points (computed without holding the interpreter; Ctrl-C
    /// stops them).
    fn voronoi(&self, py: Python<'_>) -> PyResult<Voronoi> {
        let vertices = with_tri!(&*self.read(py)?, t => {
            t.space().lattice().check_volume_representable().map_err(value_error)?;
            t.number_of_vertices()
        });
        let shared = Arc::clone(&self.tri);
        let cells = interruptible(py, vertices, move |stop| {
            let interrupt = || stop.load(Ordering::Relaxed);
            Ok(match &*shared.read().map_err(poisoned)? {
                Tri::Two(t) => Cells::Two(
                    t.voronoi_cells_until(&interrupt).map_err(value_error)?,
                    t.first_occurrences(),
                ),
                Tri::Three(t) => Cells::Three(
                    t.voronoi_cells_until(&interrupt).map_err(value_error)?,
                    t.first_occurrences(),
                ),
            })
        })?;
        let per_point = with_cells!(&cells, c, first => PerPoint::of(c, first));
        Ok(Voronoi { cells, per_point })
    }
}

/// The cells of the distinct points (sorted by input id) and every input point's first
/// occurrence.
enum Cells {
    Two(Vec<VoronoiCell<2>>, Vec<u32>),
    Three(Vec<VoronoiCell<3>>, Vec<u32>),
}

/// The cell of every input point (a duplicate's is its first occurrence's).
fn per_input<const D: usize>(cells: &[VoronoiCell<D>], first: &[u32]) -> Vec<usize> {
    first
        .iter()
        .map(|f| {
            cells
                .binary_search_by_key(f, |c| c.point)
                .expect("every first occurrence has a cell")
        })
        .collect()
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
    fn of<const D: usize>(cells: &[VoronoiCell<D>], first: &[u32]) -> Self {
        let m: Vec<CellMeasures<D>> = per_input(cells, first)
            .into_iter()
            .map(|k| CellMeasures::from(&cells[k]))
            .collect();
        PerPoint {
            volumes: m.iter().map(|x| x.volume).collect(),
            counts: m.iter().map(|x| i64::from(x.faces)).collect(),
            surfaces: m.iter().map(|x| x.surface_area).collect(),
            centroids: m.iter().flat_map(|x| x.centroid).collect(),
            dimension: D,
        }
    }
}

/// The periodic Voronoi cells of a triangulation (use `PeriodicDelaunay.voronoi()`).
#[pyclass(module = "orbitri._orbitri")]
struct Voronoi {
    cells: Cells,
    per_point: PerPoint,
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

    /// (pairs E×2, shifts E×D, areas E): each pair of neighbouring images once.
    fn neighbors(&self, py: Python<'_>) -> (Py<PyAny>, Py<PyAny>, Py<PyAny>) {
        with_cells!(&self.cells, c, _first => {
            let pairs = orbitri::voronoi::neighbor_pairs(c);
            let d = c.first().map_or(0, |x| x.centroid.len());
            let ij: Vec<i64> = pairs.iter().flat_map(|p| [i64::from(p.i), i64::from(p.j)]).collect();
            let s: Vec<i32> = pairs.iter().flat_map(|p| p.shift.map(i32::from)).collect();
            let a: Vec<f64> = pairs.iter().map(|p| p.area).collect();
            (
                array2(py, pairs.len(), 2, ij).into_any().unbind(),
                array2(py, pairs.len(), d, s).into_any().unbind(),
                a.into_pyarray(py).into_any().unbind(),
            )
        })
    }

    /// Every distinct point's cell as a dict: id, position, volume, centroid, vertices
    /// (K×D) and faces (dicts of vertices, neighbor, shift, area).
    fn cells<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        with_cells!(&self.cells, c, _first => c.iter().map(|cell| {
            let d = PyDict::new(py);
            d.set_item("id", cell.point)?;
            d.set_item("position", cell.position.to_vec())?;
            d.set_item("volume", cell.volume)?;
            d.set_item("centroid", cell.centroid.to_vec())?;
            let dim = cell.position.len();
            d.set_item(
                "vertices",
                array2(py, cell.vertices.len(), dim, cell.vertices.iter().flatten().copied().collect()),
            )?;
            let faces = cell
                .faces
                .iter()
                .map(|f| {
                    let fd = PyDict::new(py);
                    fd.set_item("vertices", f.vertices.clone())?;
                    fd.set_item("neighbor", f.neighbor)?;
                    fd.set_item("shift", f.shift.to_vec())?;
                    fd.set_item("area", f.area)?;
                    Ok(fd)
                })
                .collect::<PyResult<Vec<_>>>()?;
            d.set_item("faces", faces)?;
            Ok(d)
        }).collect())
    }

    fn __len__(&self) -> usize {
        with_cells!(&self.cells, c, _first => c.len())
    }
}

#[pymodule]
fn _orbitri(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<Triangulation>()?;
    m.add_class::<Voronoi>()?;
    Ok(())
}
