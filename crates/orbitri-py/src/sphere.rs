//! The sphere and the projective plane for Python: `orbitri._orbitri.SphericalTriangulation`
//! (use `orbitri.SphericalDelaunay` or `orbitri.ProjectivePlane`) and its Voronoi cells,
//! with the same threading and Ctrl-C rules as the flat spaces' class (`interruptible`, a
//! read–write lock).

use std::collections::HashMap;
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, RwLock, RwLockReadGuard, RwLockWriteGuard};

use numpy::ndarray::Array1;
use numpy::{AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArrayLike2};
use orbitri::spherical::{
    lonlat_to_point, ProjectiveDelaunay, SphericalDelaunay, SphericalSpace, SphericalTriangulation,
    Status,
};
use orbitri::{InputId, SphericalCell};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::sync::RwLockExt;
use pyo3::types::PyDict;

use super::{array2, id_error, in_pool, input_ids, interruptible, poisoned, value_error, Release};

/// The rows of an `(N, K)` array as points of `K` coordinates, or the error naming the
/// expected shape.
fn rows<const K: usize>(a: &PyArrayLike2<'_, f64, AllowTypeChange>) -> PyResult<Vec<[f64; K]>> {
    let a = a.as_array();
    if a.ncols() != K {
        return Err(PyValueError::new_err(format!(
            "expected an array of shape (N, {K}), got {:?}",
            a.shape()
        )));
    }
    Ok(a.outer_iter()
        .map(|r| std::array::from_fn(|c| r[c]))
        .collect())
}

/// Unit vectors from `(N, 3)` points or, with `lonlat`, `(N, 2)` degrees.
fn unit_vectors(
    points: &PyArrayLike2<'_, f64, AllowTypeChange>,
    lonlat: bool,
) -> PyResult<Vec<[f64; 3]>> {
    if !lonlat {
        return rows::<3>(points);
    }
    rows::<2>(points)?
        .iter()
        .enumerate()
        .map(|(i, l)| lonlat_to_point(i, l[0], l[1]).map_err(value_error))
        .collect()
}

/// The triangulation of either space.
enum Spherical {
    Sphere(SphericalDelaunay),
    Projective(ProjectiveDelaunay),
}

/// Runs `$body` with `$t` bound to the triangulation of either space.
macro_rules! with_s {
    ($tri:expr, $t:ident => $body:expr) => {
        match $tri {
            Spherical::Sphere($t) => $body,
            Spherical::Projective($t) => $body,
        }
    };
}

/// Builds in space `S`, answering Ctrl-C and showing progress.
fn build<S: SphericalSpace>(
    py: Python<'_>,
    pts: Vec<[f64; 3]>,
    threads: Option<usize>,
) -> PyResult<SphericalTriangulation<S>>
where
    SphericalTriangulation<S>: Send,
{
    let total = pts.len() as u64;
    interruptible(py, pts.len(), ("triangulating", total), move |control| {
        in_pool(threads, || {
            SphericalTriangulation::<S>::build_with_threads(&pts, threads, |k| {
                control.done.store(k as u64, Ordering::Relaxed);
                if control.stopped() {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            })
            .map_err(value_error)
        })
    })
}

/// The Delaunay triangulation of points on the unit sphere or of the projective plane
/// (use `orbitri.SphericalDelaunay`, `orbitri.ProjectivePlane`), shareable between threads.
#[pyclass(module = "orbitri._orbitri", frozen, name = "SphericalTriangulation")]
pub(super) struct PySpherical {
    tri: Arc<RwLock<Spherical>>,
    /// Counts the modifications (for the Python side's cache of the faces).
    generation: AtomicU64,
    /// (last: runs once the triangulation is dropped)
    release: Release,
}

impl Drop for PySpherical {
    fn drop(&mut self) {
        self.release
            .arm_if_last(&self.tri, |t| with_s!(t, t => t.number_of_input_points()));
    }
}

impl PySpherical {
    fn read(&self, py: Python<'_>) -> PyResult<RwLockReadGuard<'_, Spherical>> {
        self.tri.read_py_attached(py).map_err(poisoned)
    }

    fn write(&self, py: Python<'_>) -> PyResult<RwLockWriteGuard<'_, Spherical>> {
        self.tri.write_py_attached(py).map_err(poisoned)
    }
}

/// Faces, their neighbours, their vertices' signs, and the ghost faces.
type Faces<'py> = (
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray2<i64>>,
);
/// Areas, neighbour counts, perimeters and centroids.
type Measures<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
);
/// scipy's vertices and regions.
type Regions<'py> = (Bound<'py, PyArray2<f64>>, Vec<Bound<'py, PyArray1<i64>>>);

/// Per input, its first occurrence (`None` once removed).
fn first_occurrences<S: SphericalSpace>(t: &SphericalTriangulation<S>) -> Vec<Option<InputId>> {
    (0..t.number_of_input_points())
        .map(|i| {
            let i = InputId::new(i);
            t.status(i).map(|s| match s {
                Status::Duplicate(j) => j,
                _ => i,
            })
        })
        .collect()
}

#[pymethods]
impl PySpherical {
    /// Triangulates `points`: unit vectors `(N, 3)` or, with `lonlat`, longitudes and
    /// latitudes in degrees `(N, 2)`; on the projective plane with `projective`.
    #[new]
    #[pyo3(signature = (points, lonlat = false, projective = false, threads = None))]
    fn new(
        py: Python<'_>,
        points: PyArrayLike2<'_, f64, AllowTypeChange>,
        lonlat: bool,
        projective: bool,
        threads: Option<usize>,
    ) -> PyResult<Self> {
        let pts = unit_vectors(&points, lonlat)?;
        let tri = if projective {
            Spherical::Projective(build(py, pts, threads)?)
        } else {
            Spherical::Sphere(build(py, pts, threads)?)
        };
        Ok(PySpherical {
            tri: Arc::new(RwLock::new(tri)),
            generation: AtomicU64::new(0),
            release: Release::default(),
        })
    }

    /// Counts the modifications (`insert`, `remove`).
    #[getter]
    fn generation(&self) -> u64 {
        self.generation.load(Ordering::Acquire)
    }

    /// The points as stored (N × 3, input order; NaN rows for removed inputs).
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        with_s!(&*self.read(py)?, t => {
            let n = t.number_of_input_points();
            let v: Vec<f64> = (0..n)
                .flat_map(|i| t.point(InputId::new(i)).unwrap_or([f64::NAN; 3]))
                .collect();
            Ok(array2(py, n, 3, v))
        })
    }

    /// CGAL's dimension: −2 (empty) to 2.
    #[getter]
    fn dimension(&self, py: Python<'_>) -> PyResult<i32> {
        Ok(with_s!(&*self.read(py)?, t => t.dimension()))
    }

    /// True when the points enclose the centre (the faces cover the sphere).
    #[getter]
    fn covers_sphere(&self, py: Python<'_>) -> PyResult<bool> {
        Ok(with_s!(&*self.read(py)?, t => t.covers_sphere()))
    }

    /// The hidden input ids, sorted.
    #[getter]
    fn hidden<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let h: Vec<i64> = with_s!(&*self.read(py)?, t => t.hidden())
            .iter()
            .map(|i| i64::from(i.0))
            .collect();
        Ok(h.into_pyarray(py))
    }

    /// Per input, the input id of its first occurrence (itself unless a duplicate; −1 once
    /// removed).
    #[getter]
    fn duplicates<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let first = with_s!(&*self.read(py)?, t => first_occurrences(t));
        Ok(first
            .into_iter()
            .map(|f| f.map_or(-1, |j| i64::from(j.0)))
            .collect::<Array1<i64>>()
            .into_pyarray(py))
    }

    /// Number of distinct, visible points.
    #[getter]
    fn number_of_vertices(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(with_s!(&*self.read(py)?, t => t.number_of_vertices()))
    }

    /// `(faces F × 3, neighbours (F + G) × 3, signs F × 3, ghost faces G × 3)`: input ids
    /// counter-clockwise seen from outside; per face, then per ghost face, the face across
    /// the edge opposite each vertex (ghost faces numbered from F); each vertex's sign (−1:
    /// the antipode of its point, in RP²); CGAL's ghost faces (points in a hemisphere).
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Faces<'py>> {
        let orbitri::spherical::FaceTable {
            faces,
            signs,
            ghosts,
            neighbors,
        } = with_s!(&*self.read(py)?, t => t.face_table());
        let ids = |f: &[[orbitri::InputId; 3]]| -> Vec<i64> {
            f.iter().flatten().map(|i| i64::from(i.0)).collect()
        };
        let n: Vec<i64> = neighbors.iter().flatten().map(|&k| k as i64).collect();
        let s: Vec<i64> = signs
            .iter()
            .flatten()
            .map(|&x| if x { -1 } else { 1 })
            .collect();
        let k = faces.len();
        Ok((
            array2(py, k, 3, ids(&faces)),
            array2(py, neighbors.len(), 3, n),
            array2(py, k, 3, s),
            array2(py, ghosts.len(), 3, ids(&ghosts)),
        ))
    }

    /// Inserts `points` (rows, or lon/lat with `lonlat`), all or nothing; per point the
    /// input id of its first occurrence (itself when new), −1 when hidden.
    #[pyo3(signature = (points, lonlat = false))]
    fn insert<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLike2<'_, f64, AllowTypeChange>,
        lonlat: bool,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let pts = unit_vectors(&points, lonlat)?;
        let mut guard = self.write(py)?;
        let tri = &mut *guard;
        let first = with_s!(&*tri, t => t.number_of_input_points());
        let status = py
            .detach(|| with_s!(tri, t => t.insert_all(&pts)))
            .map_err(value_error)?;
        self.generation.fetch_add(1, Ordering::AcqRel);
        Ok(status
            .iter()
            .enumerate()
            .map(|(k, s)| match s {
                Status::Vertex => (first + k) as i64,
                Status::Duplicate(j) => i64::from(j.0),
                Status::Hidden => -1,
            })
            .collect::<Array1<i64>>()
            .into_pyarray(py))
    }

    /// Removes input ids (one or a sequence), all or nothing.
    fn remove(&self, py: Python<'_>, ids: &Bound<'_, PyAny>) -> PyResult<()> {
        let ids = input_ids(py, ids)?;
        let mut guard = self.write(py)?;
        let tri = &mut *guard;
        py.detach(|| with_s!(tri, t => t.remove_all(&ids)))
            .map_err(id_error)?;
        self.generation.fetch_add(1, Ordering::AcqRel);
        Ok(())
    }

    /// The face (input ids) whose cone from the centre holds the direction `point`, or None
    /// outside the faces.
    fn locate(&self, py: Python<'_>, point: [f64; 3]) -> PyResult<Option<[i64; 3]>> {
        let f = with_s!(&*self.read(py)?, t => t.locate(point)).map_err(value_error)?;
        Ok(f.map(|f| f.map(|i| i64::from(i.0))))
    }

    /// The Delaunay neighbours of input `i`, sorted.
    fn vertex_neighbors<'py>(
        &self,
        py: Python<'py>,
        i: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let i = input_ids(py, i)?;
        let [i] = i[..] else {
            return Err(PyValueError::new_err("one input id"));
        };
        let nb = with_s!(&*self.read(py)?, t => t.vertex_neighbors(i)).map_err(id_error)?;
        Ok(nb
            .iter()
            .map(|x| i64::from(x.0))
            .collect::<Array1<i64>>()
            .into_pyarray(py))
    }

    /// Checks the triangulation exactly; raises ValueError naming the first problem.
    fn is_valid(&self, py: Python<'_>) -> PyResult<bool> {
        let guard = self.read(py)?;
        let tri = &*guard;
        py.detach(|| with_s!(tri, t => t.is_valid()))
            .map(|()| true)
            .map_err(|e| PyValueError::new_err(format!("invalid triangulation: {e}")))
    }

    /// The Voronoi cells.
    fn voronoi(&self, py: Python<'_>) -> PyResult<SphericalVoronoi> {
        let tri = Arc::clone(&self.tri);
        let n = with_s!(&*self.read(py)?, t => t.number_of_vertices());
        interruptible(py, n, ("Voronoi cells", 1), move |_| {
            let guard = tri.read().map_err(poisoned)?;
            with_s!(&*guard, t => {
                let cells = t.voronoi_cells().map_err(value_error)?;
                let hidden = t.hidden().iter().map(|i| i.index()).collect();
                Ok(SphericalVoronoi {
                    cells,
                    first: first_occurrences(t),
                    hidden,
                    release: Release::default(),
                })
            })
        })
    }
}

/// The Voronoi cells of a `SphericalTriangulation`, per input point.
#[pyclass(module = "orbitri._orbitri", frozen)]
pub(super) struct SphericalVoronoi {
    cells: Vec<SphericalCell>,
    /// Per input: its first occurrence (`None` once removed).
    first: Vec<Option<InputId>>,
    /// The hidden inputs.
    hidden: Vec<usize>,
    /// (last: runs once the cells are dropped)
    release: Release,
}

impl Drop for SphericalVoronoi {
    fn drop(&mut self) {
        self.release.large = self.cells.len() >= Release::LARGE;
    }
}

impl SphericalVoronoi {
    /// Per input, its cell (`None` for a hidden or removed input).
    fn per_input(&self) -> Vec<Option<&SphericalCell>> {
        let mut by_site = vec![None; self.first.len()];
        for c in &self.cells {
            by_site[c.site.index()] = Some(c);
        }
        self.first
            .iter()
            .map(|f| f.and_then(|j| by_site[j.index()]))
            .collect()
    }
}

#[pymethods]
impl SphericalVoronoi {
    /// `(areas N, neighbour counts N, perimeters N, centroids N × 3)` per input: a
    /// duplicate's are its first occurrence's; a hidden input's area is 0, a removed one's
    /// NaN (counts −1), their centroids NaN.
    fn measures<'py>(&self, py: Python<'py>) -> PyResult<Measures<'py>> {
        let cells = self.per_input();
        let n = cells.len();
        let mut area = vec![f64::NAN; n];
        let mut count = vec![-1i64; n];
        let mut perimeter = vec![f64::NAN; n];
        let mut centroid = vec![f64::NAN; 3 * n];
        for (i, c) in cells.iter().enumerate() {
            if let Some(c) = c {
                area[i] = c.area;
                count[i] = c.neighbors.len() as i64;
                perimeter[i] = c.arc_lengths.iter().sum();
                centroid[3 * i..3 * i + 3].copy_from_slice(&c.centroid);
            }
        }
        for &h in &self.hidden {
            (area[h], count[h], perimeter[h]) = (0.0, 0, 0.0);
        }
        Ok((
            area.into_pyarray(py),
            count.into_pyarray(py),
            perimeter.into_pyarray(py),
            array2(py, n, 3, centroid),
        ))
    }

    /// scipy's `SphericalVoronoi` shape: `(vertices V × 3, regions)`, the distinct Voronoi
    /// vertices and, per input, the indices of its cell's vertices counter-clockwise seen
    /// from outside (empty for a hidden or removed input).
    fn regions<'py>(&self, py: Python<'py>) -> PyResult<Regions<'py>> {
        // the cells share their vertices bit for bit (one pole per class of faces)
        let mut index: HashMap<[u64; 3], i64> = HashMap::new();
        let mut vertices: Vec<f64> = Vec::new();
        let mut of_cell: HashMap<InputId, Vec<i64>> = HashMap::new();
        for c in &self.cells {
            let ids = c
                .vertices
                .iter()
                .map(|v| {
                    *index.entry(v.map(f64::to_bits)).or_insert_with(|| {
                        vertices.extend_from_slice(v);
                        (vertices.len() / 3 - 1) as i64
                    })
                })
                .collect();
            of_cell.insert(c.site, ids);
        }
        let regions = self
            .first
            .iter()
            .map(|f| {
                f.and_then(|j| of_cell.get(&j).cloned())
                    .unwrap_or_default()
                    .into_pyarray(py)
            })
            .collect();
        Ok((array2(py, vertices.len() / 3, 3, vertices), regions))
    }

    /// Every cell as a dict: `id`, `area`, `centroid`, `vertices` (K × 3,
    /// counter-clockwise), `neighbors` (K: across the arc from vertex k to k + 1) and
    /// `arc_lengths` (K).
    fn cells<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.cells
            .iter()
            .map(|c| {
                let d = PyDict::new(py);
                d.set_item("id", c.site.0)?;
                d.set_item("area", c.area)?;
                d.set_item("centroid", c.centroid.to_vec().into_pyarray(py))?;
                let v: Vec<f64> = c.vertices.iter().flatten().copied().collect();
                d.set_item("vertices", array2(py, c.vertices.len(), 3, v))?;
                let nb: Vec<i64> = c.neighbors.iter().map(|x| i64::from(x.0)).collect();
                d.set_item("neighbors", nb.into_pyarray(py))?;
                d.set_item("arc_lengths", c.arc_lengths.clone().into_pyarray(py))?;
                Ok(d)
            })
            .collect()
    }

    fn __len__(&self) -> usize {
        self.cells.len()
    }
}
