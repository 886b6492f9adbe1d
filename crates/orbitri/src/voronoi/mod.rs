//! Periodic Voronoi cells, the duals of the Delaunay triangulation (power, or Laguerre,
//! cells of the regular triangulation for weighted points: orthocenters for circumcenters,
//! hidden points with empty cells): for every point, its cell
//! around the point (vertices = circumcenters of the cells of its star, faces = duals of its
//! Delaunay edges, each with the neighbour's id and lattice shift), volume (area in 2D), face
//! areas (lengths in 2D) and centroid. Computed from the triangulation's adjacency and the
//! periodic geometry, so a triangulation still in a covering space gives the same cells.
//!
//! Degenerate inputs are exact: adjacent Delaunay cells whose circumspheres coincide (decided
//! by the unperturbed in-sphere test) give one Voronoi vertex, and a Delaunay edge whose dual
//! has collapsed to fewer than `D` vertices is no face (a square grid's diagonals, for example).

mod measures;

use std::sync::atomic::AtomicBool;
use std::sync::atomic::Ordering::Relaxed;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::ids::{CellId, InputId, PointId, VertexId};
use crate::space::FlatSpace;
use crate::tds::{first_equal, prefetch};
use crate::triangulation::Triangulation;

/// A face of a Voronoi cell: the part of the bisector with one periodic image of a neighbour.
#[derive(Clone, Debug, PartialEq)]
pub struct VoronoiFace<const D: usize, E = [i8; D]> {
    /// Indices into the cell's vertices: in 3D a cycle, counter-clockwise seen from outside
    /// the cell; in 2D the two ends of the edge.
    pub vertices: Vec<u32>,
    /// Input id of the neighbour (its first occurrence).
    pub neighbor: InputId,
    /// The neighbour's image across this face is `shift·points[neighbor]` (in a torus
    /// `points[neighbor] + shift·M`).
    pub shift: E,
    /// Area of the face (length in 2D).
    pub area: f64,
}

/// The Voronoi cell of one point, in Cartesian coordinates around the point's wrapped
/// position (vertices may lie outside the domain).
#[derive(Clone, Debug, PartialEq)]
pub struct VoronoiCell<const D: usize, E = [i8; D]> {
    /// Input id of the point (its first occurrence).
    pub point: InputId,
    /// The point's wrapped position.
    pub position: [f64; D],
    pub vertices: Vec<[f64; D]>,
    pub faces: Vec<VoronoiFace<D, E>>,
    /// Volume (area in 2D).
    pub volume: f64,
    pub centroid: [f64; D],
}

/// What most users need of a cell, without its geometry (memory O(1) per point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellMeasures<const D: usize> {
    /// Input id of the point (its first occurrence).
    pub point: InputId,
    /// Volume (area in 2D).
    pub volume: f64,
    /// Number of faces (of neighbours, counting each image).
    pub faces: u32,
    /// Sum of the face areas (perimeter in 2D).
    pub surface_area: f64,
    pub centroid: [f64; D],
}

/// Triangulation cells between two polls of `interrupt` (a circumcenter each, then the
/// exact tests of their facets).
const CELLS_PER_POLL: usize = 1024;
/// Voronoi cells between two polls: a cell costs about 16 circumcenters (3.5 µs against
/// 0.2 µs at 10⁶ points, two threads), so that every poll follows about the same work.
const POINTS_PER_POLL: usize = 64;

impl<const D: usize, E> From<&VoronoiCell<D, E>> for CellMeasures<D> {
    fn from(c: &VoronoiCell<D, E>) -> Self {
        CellMeasures {
            point: c.point,
            volume: c.volume,
            faces: c.faces.len() as u32,
            surface_area: c.faces.iter().map(|f| f.area).sum(),
            centroid: c.centroid,
        }
    }
}

/// Every cell's measures (in the order of first occurrence) and the neighbour pairs.
pub type MeasuresAndNeighbors<const D: usize, E> = (Vec<CellMeasures<D>>, Vec<Neighbor<D, E>>);

/// Two Voronoi neighbours: `j`'s image `shift·points[j]` (in a torus `points[j] + shift·M`)
/// shares a face of this area with `i`. Each unordered pair of images is listed once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbor<const D: usize, E = [i8; D]> {
    pub i: InputId,
    pub j: InputId,
    pub shift: E,
    pub area: f64,
}

pub(crate) fn cross(a: &[f64], b: &[f64]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub(crate) fn sub<const D: usize>(a: &[f64; D], b: &[f64; D]) -> [f64; D] {
    std::array::from_fn(|x| a[x] - b[x])
}

/// Newell's normal of the polygon `vertices[ids]` (twice its vector area; 3D).
fn newell<const D: usize>(vertices: &[[f64; D]], ids: &[u32]) -> [f64; 3] {
    let mut n = [0.0; 3];
    for k in 0..ids.len() {
        let a = &vertices[ids[k] as usize];
        let b = &vertices[ids[(k + 1) % ids.len()] as usize];
        let c = cross(&a[..], &b[..]);
        for (nc, cc) in n.iter_mut().zip(c) {
            *nc += cc;
        }
    }
    n
}

/// The Delaunay edges at a point, each the dual of a face of its cell, in the order of
/// first appearance in its star (buffers reused from point to point).
struct Faces<E, const N: usize> {
    /// Each Delaunay edge at the point (the far vertex, its element relative to the point)
    /// and the area of its face so far (summed by pieces), in order of first appearance.
    edges: Vec<(VertexId, E, f64)>,
    /// `index[u][j]`: the edge from the point to slot `j` of the star's cell `u`.
    index: Vec<[u32; N]>,
    /// Open addressing on the far vertex: an edge's position, or `u32::MAX`.
    table: Vec<u32>,
}

impl<E, const N: usize> Default for Faces<E, N> {
    fn default() -> Self {
        Faces {
            edges: Vec::new(),
            index: Vec::new(),
            table: Vec::new(),
        }
    }
}

impl<E: Copy + PartialEq, const N: usize> Faces<E, N> {
    /// Lists the Delaunay edges of a `star` (`element(cell, k, j)`: of the edge from the
    /// point at slot `k` to slot `j`, the far vertex's element), in the order of first
    /// appearance, each found again by hashing its far vertex. With `simplicial` (the
    /// triangulation is a simplicial complex: two vertices share at most one edge) the far
    /// vertex alone names an edge, and its element is computed once, when the edge is first
    /// seen; otherwise a far vertex seen before is the same edge only with the same element.
    fn gather(
        &mut self,
        star: &[(CellId, u8)],
        simplicial: bool,
        vertices: impl Fn(CellId) -> [VertexId; N],
        element: impl Fn(CellId, usize, usize) -> E,
    ) {
        self.edges.clear();
        self.index.clear();
        // (at most N − 1 edges a cell: the table stays at most half full)
        let size = (2 * (N - 1) * star.len()).next_power_of_two();
        self.table.clear();
        self.table.resize(size, u32::MAX);
        for &(t, k) in star {
            let k = k as usize;
            let vs = vertices(t);
            // (written in place: an array built on the stack and pushed whole is read back
            // in one load from several stores, a store-forwarding stall)
            let u = self.index.len();
            self.index.push([0; N]);
            for j in slots_but::<N>(k) {
                let v = vs[j];
                let mut h = (v.0.wrapping_mul(0x9E37_79B1) >> 7) as usize & (size - 1);
                self.index[u][j] = loop {
                    let f = self.table[h];
                    if f == u32::MAX {
                        self.table[h] = self.edges.len() as u32;
                        self.edges.push((v, element(t, k, j), 0.0));
                        break self.table[h];
                    }
                    let x = &self.edges[f as usize];
                    if x.0 == v && (simplicial || x.1 == element(t, k, j)) {
                        debug_assert!(x.1 == element(t, k, j), "one edge between two vertices");
                        break f;
                    }
                    h = (h + 1) & (size - 1);
                };
            }
        }
    }
}

/// The buffers of [`Triangulation::cell_of_point`], reused from cell to cell by one worker
/// (a cell needed some sixty small allocations: a tenth of the Voronoi pass in malloc).
pub(crate) struct CellScratch<E, const N: usize> {
    star: Vec<(CellId, u8)>,
    parent: Vec<usize>,
    vertex_of_root: Vec<u32>,
    vertex_of: Vec<u32>,
    faces: Faces<E, N>,
    member: Vec<(u32, u32)>,
    ring: Vec<usize>,
    cycle: Vec<usize>,
}

// (not derived: that would ask the group elements for a `Default`)
impl<E, const N: usize> Default for CellScratch<E, N> {
    fn default() -> Self {
        CellScratch {
            star: Vec::new(),
            parent: Vec::new(),
            vertex_of_root: Vec::new(),
            vertex_of: Vec::new(),
            faces: Faces::default(),
            member: Vec::new(),
            ring: Vec::new(),
            cycle: Vec::new(),
        }
    }
}

/// How many cells ahead the passes over every cell ask for the memory they will read.
const AHEAD: usize = 16;

/// Union–find root with path halving.
fn root(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// What every Voronoi cell reads from the triangulation, computed once: each stored cell's
/// circumcenter (certified, relative to its lifted vertex 0, in the lattice's internal
/// frame), the facets across which two cells share their circumsphere (their Voronoi
/// vertices coincide), and the cells around each vertex.
struct Duals<const D: usize> {
    /// Indexed by stored cell id.
    center: Vec<[f64; D]>,
    /// Bit `x` of `cospherical[c]`: cell `c` and its neighbour across facet `x` have one
    /// circumsphere (decided exactly), so they give one Voronoi vertex.
    cospherical: Vec<u8>,
    stars: Stars,
}

/// The incident cells of every vertex, in one array (a counting sort). The vertex's slot in
/// each is found again in the cell ([`Triangulation::slotted_star`]): the array is half as
/// large as with the slots, and the cells are read anyway.
struct Stars {
    /// The cells of vertex `v` are `incident[start[v]..start[v + 1]]`.
    start: Vec<u32>,
    incident: Vec<CellId>,
}

impl Stars {
    /// The cells around vertex `v`.
    fn of(&self, v: VertexId) -> &[CellId] {
        &self.incident[self.start[v.index()] as usize..self.start[v.index() + 1] as usize]
    }
}

impl<const D: usize, const N: usize, S: FlatSpace<D, N>> Triangulation<D, N, S> {
    /// The Voronoi cell of input point `i` (a duplicate gets its first occurrence's cell).
    /// It computes the circumcenters and cospherical classes of the whole triangulation
    /// first: for many cells, call [`Self::voronoi_cells`] once.
    pub fn voronoi_cell(&self, i: InputId) -> VoronoiCell<D, S::Elem> {
        if self.is_hidden(i) {
            return self.hidden_cell(i);
        }
        let duals = self.duals(&|| false).expect("never interrupted");
        self.cell_of_point(&duals, self.vertex_of_input(i), &mut CellScratch::default())
    }

    /// The Voronoi cells of the distinct points, in the order of their first occurrence
    /// (computed in parallel); weighted, the power cells, hidden inputs' (empty) included.
    pub fn voronoi_cells(&self) -> Vec<VoronoiCell<D, S::Elem>> {
        self.per_cell(|c| c)
    }

    /// The measures of every distinct point's cell, in the order of first occurrence; the
    /// cells themselves are dropped as soon as measured (for tables of millions of points).
    pub fn voronoi_measures(&self) -> Vec<CellMeasures<D>> {
        self.voronoi_measures_until(&|| false)
            .expect("never interrupted")
    }

    /// How many times [`Self::voronoi_cells_until`] and [`Self::voronoi_measures_until`]
    /// poll `interrupt` when not interrupted, each after about the same work: the total of a
    /// progress bar that counts polls.
    pub fn voronoi_polls(&self) -> u64 {
        let cells = self.number_of_stored_cells();
        (2 + 2 * cells.div_ceil(CELLS_PER_POLL)
            + self.number_of_vertices().div_ceil(POINTS_PER_POLL)) as u64
    }

    /// The Voronoi cells as [`Self::voronoi_cells`], stopping early with
    /// [`Error::Interrupted`] once `interrupt` returns true. `interrupt` is polled from the
    /// worker threads (keep it cheap: an atomic load) after about the same work each time
    /// ([`Self::voronoi_polls`] times in all): every 1024 triangulation cells while their
    /// circumcenters and cospherical neighbours are found, then every 64 Voronoi cells.
    ///
    /// ```
    /// use orbitri::{Error, FlatTorus2, PeriodicDelaunay2};
    /// let pts: Vec<[f64; 2]> = (0..5000)
    ///     .map(|i| [(i as f64 * 0.618034) % 1.0, (i as f64 * 0.414214) % 1.0])
    ///     .collect();
    /// let tri = PeriodicDelaunay2::build(FlatTorus2::cuboid([1.0, 1.0]).unwrap(), &pts).unwrap();
    /// assert_eq!(tri.voronoi_cells_until(&|| false).unwrap().len(), 5000);
    /// assert!(matches!(tri.voronoi_cells_until(&|| true), Err(Error::Interrupted)));
    /// ```
    pub fn voronoi_cells_until(
        &self,
        interrupt: &(dyn Fn() -> bool + Sync),
    ) -> Result<Vec<VoronoiCell<D, S::Elem>>> {
        self.per_cell_until(|c| c, interrupt)
    }

    /// The measures as [`Self::voronoi_measures`], stopping early with
    /// [`Error::Interrupted`] once `interrupt` returns true (polled as by
    /// [`Self::voronoi_cells_until`]).
    pub fn voronoi_measures_until(
        &self,
        interrupt: &(dyn Fn() -> bool + Sync),
    ) -> Result<Vec<CellMeasures<D>>> {
        Ok(self.measures_until(interrupt, false)?.0)
    }

    /// The measures as [`Self::voronoi_measures_until`], and the neighbour pairs as
    /// [`Self::voronoi_neighbors`] lists them, without building the cells (when 1-sheeted).
    pub fn voronoi_measures_and_neighbors_until(
        &self,
        interrupt: &(dyn Fn() -> bool + Sync),
    ) -> Result<MeasuresAndNeighbors<D, S::Elem>> {
        self.measures_until(interrupt, true)
    }

    /// The measures, and with `pairs` the neighbour pairs: by pieces when 1-sheeted
    /// (`measures.rs`, from the circumcenters and stars computed here), the few points next
    /// to two cells of one circumsphere from their whole cells (the same circumcenters and
    /// stars); from the whole cells in a covering.
    fn measures_until(
        &self,
        interrupt: &(dyn Fn() -> bool + Sync),
        pairs: bool,
    ) -> Result<MeasuresAndNeighbors<D, S::Elem>> {
        let inverse = |g| self.space().inverse(g);
        if self.engine().sheets() > 1 {
            let cells = self.voronoi_cells_until(interrupt)?;
            let found = if pairs {
                neighbor_pairs_by(&cells, inverse)
            } else {
                Vec::new()
            };
            return Ok((cells.iter().map(CellMeasures::from).collect(), found));
        }
        if interrupt() {
            return Err(Error::Interrupted);
        }
        let ids: Vec<CellId> = self.engine().cell_ids().collect();
        let center = self.centers(&ids, interrupt)?;
        if interrupt() {
            return Err(Error::Interrupted);
        }
        let stars = self.stars(&ids, interrupt)?;
        let mut pieces = self.measures_by_pieces(&center, &stars, interrupt, pairs)?;
        // the few points next to two cells of one circumsphere, on their whole cells
        let mut whole: Vec<(PointId, Vec<Neighbor<D, S::Elem>>)> = Vec::new();
        if pieces.measures.iter().any(Option::is_none) {
            // (not polled: degenerate inputs only)
            let cospherical = self.cospherical(&ids, center.len(), &|| false)?;
            let duals = Duals {
                center,
                cospherical,
                stars,
            };
            let found: Vec<(PointId, CellMeasures<D>, Vec<_>)> = (0..pieces.measures.len())
                .into_par_iter()
                .filter(|&p| pieces.measures[p].is_none())
                .map_init(CellScratch::default, |scratch, p| {
                    let p = PointId(p as u32);
                    let cell = self.cell_of_point(&duals, p, scratch);
                    let found = if pairs {
                        neighbor_pairs_by(std::slice::from_ref(&cell), inverse)
                    } else {
                        Vec::new()
                    };
                    (p, CellMeasures::from(&cell), found)
                })
                .collect();
            for (p, m, found) in found {
                pieces.measures[p.index()] = Some(m);
                whole.push((p, found));
            }
        } else {
            // (the duals' memory back before the pairs are gathered)
            drop((center, stars));
        }
        let order = self.input_order();
        let measures = self.in_order(&order, std::mem::take(&mut pieces.measures), |i| {
            CellMeasures::from(&self.hidden_cell(i))
        });
        let mut all = Vec::new();
        if pairs {
            all.reserve_exact(
                pieces.number_of_pairs() + whole.iter().map(|w| w.1.len()).sum::<usize>(),
            );
            for (k, &(i, p)) in order.iter().enumerate() {
                if p == PointId::NONE {
                    continue;
                }
                // (the lists lie at random: their places asked for 16 points ahead, the
                // lists themselves 4 ahead, halve the time)
                pieces.prefetch(
                    order.get(k + 16).map(|o| o.1),
                    order.get(k + 4).map(|o| o.1),
                );
                all.extend(pieces.pairs_of(p).iter().map(|&(j, shift, area)| Neighbor {
                    i,
                    j,
                    shift,
                    area,
                }));
                // (`whole` is in point order, as the filter above found them)
                if let Ok(k) = whole.binary_search_by_key(&p, |w| w.0) {
                    all.extend_from_slice(&whole[k].1);
                }
            }
        }
        Ok((measures, all))
    }

    /// `f` of every cell, computed in parallel in point order (the spatially sorted
    /// insertion order: neighbouring points share triangulation cells in cache), returned in
    /// the order of first occurrence.
    fn per_cell<T: Send>(&self, f: impl Fn(VoronoiCell<D, S::Elem>) -> T + Sync) -> Vec<T> {
        self.per_cell_until(f, &|| false)
            .expect("never interrupted")
    }

    /// `per_cell`, polling `interrupt` as [`Self::voronoi_polls`] says.
    fn per_cell_until<T: Send>(
        &self,
        f: impl Fn(VoronoiCell<D, S::Elem>) -> T + Sync,
        interrupt: &(dyn Fn() -> bool + Sync),
    ) -> Result<Vec<T>> {
        if interrupt() {
            return Err(Error::Interrupted);
        }
        let duals = self.duals(interrupt)?;
        let out: Vec<Option<T>> = (0..self.number_of_vertices() as u32)
            .into_par_iter()
            .map_init(CellScratch::default, |scratch, p| {
                if p % POINTS_PER_POLL as u32 == 0 && interrupt() {
                    return Err(Error::Interrupted);
                }
                Ok(Some(f(self.cell_of_point(&duals, PointId(p), scratch))))
            })
            .collect::<Result<_>>()?;
        Ok(self.in_input_order(out, |i| f(self.hidden_cell(i))))
    }

    /// The values of the points (`out`, indexed by point, each `Some`) and of the hidden
    /// inputs (`hidden`), in the order of first occurrence.
    fn in_input_order<T>(&self, out: Vec<Option<T>>, hidden: impl Fn(InputId) -> T) -> Vec<T> {
        debug_assert_eq!(out.len(), self.number_of_vertices());
        self.in_order(&self.input_order(), out, hidden)
    }

    /// [`Self::in_input_order`] along an `order` that `input_order` gave.
    fn in_order<T>(
        &self,
        order: &[(InputId, PointId)],
        mut out: Vec<Option<T>>,
        hidden: impl Fn(InputId) -> T,
    ) -> Vec<T> {
        order
            .iter()
            .map(|&(i, p)| match p {
                PointId::NONE => hidden(i),
                p => out[p.index()].take().expect("each point once"),
            })
            .collect()
    }

    /// The empty power cell of hidden input `i`: no vertices or faces, volume 0, its
    /// centroid at the point.
    fn hidden_cell(&self, i: InputId) -> VoronoiCell<D, S::Elem> {
        let position = self.position(i, self.space().identity());
        VoronoiCell {
            point: i,
            position,
            vertices: Vec::new(),
            faces: Vec::new(),
            volume: 0.0,
            centroid: position,
        }
    }

    /// The Voronoi neighbour pairs with their shared face areas, each unordered pair of
    /// images once (`i < j`, or `i == j` with the shift greater than its inverse: for a
    /// torus, its first non-zero entry positive).
    pub fn voronoi_neighbors(&self) -> Vec<Neighbor<D, S::Elem>> {
        self.voronoi_measures_and_neighbors_until(&|| false)
            .expect("never interrupted")
            .1
    }

    /// The neighbour pairs of cells already computed (by [`Self::voronoi_cells`]), as
    /// [`Self::voronoi_neighbors`] lists them.
    pub fn voronoi_neighbors_of(
        &self,
        cells: &[VoronoiCell<D, S::Elem>],
    ) -> Vec<Neighbor<D, S::Elem>> {
        neighbor_pairs_by(cells, |g| self.space().inverse(g))
    }

    /// The shared duals, polling `interrupt` every `CELLS_PER_POLL` cells, twice.
    fn duals(&self, interrupt: &(dyn Fn() -> bool + Sync)) -> Result<Duals<D>> {
        let ids: Vec<CellId> = self.engine().cell_ids().collect();
        let center = self.centers(&ids, interrupt)?;
        if interrupt() {
            return Err(Error::Interrupted);
        }
        let cospherical = self.cospherical(&ids, center.len(), interrupt)?;
        let stars = self.stars(&ids, &|| false)?;
        Ok(Duals {
            center,
            cospherical,
            stars,
        })
    }

    /// Bit `x` of entry `c`: cell `c` and its neighbour across facet `x` have one
    /// circumsphere (decided exactly, each facet once), for the cells `ids` (`slots` entries,
    /// indexed by cell id), polling `interrupt` every `CELLS_PER_POLL` cells.
    fn cospherical(
        &self,
        ids: &[CellId],
        slots: usize,
        interrupt: &(dyn Fn() -> bool + Sync),
    ) -> Result<Vec<u8>> {
        let e = self.engine();
        let stopped = std::sync::atomic::AtomicBool::new(false);
        let merges: Vec<(CellId, usize, CellId)> = ids
            .par_iter()
            .enumerate()
            .flat_map_iter(|(k, &c)| {
                if k % CELLS_PER_POLL == 0 && interrupt() {
                    stopped.store(true, std::sync::atomic::Ordering::Relaxed);
                }
                let cell = e.cell(c);
                (0..N).filter_map(move |x| {
                    let d = cell.n[x];
                    (d > c && self.one_sphere(c, x, d)).then_some((c, x, d))
                })
            })
            .collect();
        if stopped.into_inner() {
            return Err(Error::Interrupted);
        }
        let mut cospherical = vec![0u8; slots];
        for (c, x, d) in merges {
            let y = e.cell(d).mirror(c).expect("symmetric neighbours");
            cospherical[c.index()] |= 1 << x;
            cospherical[d.index()] |= 1 << y;
        }
        Ok(cospherical)
    }

    /// Each stored cell's circumcenter (orthocenter), indexed by cell id (the points of the
    /// cell `AHEAD` later asked for: they lie at random, a sixth of the time), polling
    /// `interrupt` every `CELLS_PER_POLL` cells. Written in place by the threads (a
    /// collection into a `Result` would gather pieces and copy them).
    fn centers(
        &self,
        ids: &[CellId],
        interrupt: &(dyn Fn() -> bool + Sync),
    ) -> Result<Vec<[f64; D]>> {
        let e = self.engine();
        let slots = ids.iter().max().map_or(0, |m| m.index() + 1);
        let stopped = AtomicBool::new(false);
        let mut center = Vec::new();
        ids.par_iter()
            .enumerate()
            .map(|(k, &c)| {
                if k % CELLS_PER_POLL == 0 && !stopped.load(Relaxed) && interrupt() {
                    stopped.store(true, Relaxed);
                }
                if stopped.load(Relaxed) {
                    return [0.0; D];
                }
                if let Some(&ahead) = ids.get(k + AHEAD) {
                    e.prefetch_points(ahead);
                }
                // (the circumcenter is the orthocenter of the zero weights unweighted cells have)
                self.space()
                    .orthocenter(&e.lifted_cell(c), &e.cell_weights(c))
            })
            .collect_into_vec(&mut center);
        if stopped.into_inner() {
            return Err(Error::Interrupted);
        }
        if ids.len() < slots {
            // dead slots between (ids ascend): each center moved up to its cell's slot,
            // from the last, and the dead slots zeroed
            center.resize(slots, [0.0; D]);
            let mut end = slots;
            for (k, &c) in ids.iter().enumerate().rev() {
                center[c.index() + 1..end].fill([0.0; D]);
                center[c.index()] = center[k];
                end = c.index();
            }
            center[..end].fill([0.0; D]);
        }
        Ok(center)
    }

    /// True when cell `c` and its neighbour `d` across facet `x` have one circumsphere
    /// (orthogonal sphere), decided exactly.
    fn one_sphere(&self, c: CellId, x: usize, d: CellId) -> bool {
        let e = self.engine();
        let space = self.space();
        let dc = e.cell(d);
        let y = dc.mirror(c).expect("symmetric neighbours");
        let opposite = (
            e.points()[e.point_of(dc.v[y]).index()],
            space.compose(e.translation(c, x, d), dc.off[y]),
        );
        let lifted = e.lifted_cell(c);
        if e.is_weighted() {
            let w = e.vertex_weight(dc.v[y]);
            space.orthogonal(&lifted, &e.cell_weights(c), opposite, w)
        } else {
            space.cospherical(&lifted, opposite)
        }
    }

    /// The stars of the vertices of the cells `ids`, polling `interrupt` every
    /// `CELLS_PER_POLL` cells.
    fn stars(&self, ids: &[CellId], interrupt: &(dyn Fn() -> bool + Sync)) -> Result<Stars> {
        let e = self.engine();
        let vertices = e.number_of_vertices();
        let mut start = vec![0u32; vertices + 1];
        for (k, &c) in ids.iter().enumerate() {
            if k % CELLS_PER_POLL == 0 && interrupt() {
                return Err(Error::Interrupted);
            }
            for v in e.vertices(c) {
                start[v.index() + 1] += 1;
            }
        }
        for v in 0..vertices {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut incident = vec![CellId(0); start[vertices] as usize];
        // (a cell's places in its vertices' lists lie at random: asked for `AHEAD` cells
        // before they are written, a third of the time)
        for (k, &c) in ids.iter().enumerate() {
            if let Some(&later) = ids.get(k + AHEAD) {
                for v in e.vertices(later) {
                    prefetch(&incident[fill[v.index()] as usize]);
                }
            }
            for v in e.vertices(c) {
                incident[fill[v.index()] as usize] = c;
                fill[v.index()] += 1;
            }
        }
        Ok(Stars { start, incident })
    }

    /// The star of vertex `v` (from `stars`) with the vertex's slot in each cell, into `out`
    /// (a vertex is in a cell once: the triangulation is a simplicial complex).
    fn slotted_star(&self, stars: &Stars, v: VertexId, out: &mut Vec<(CellId, u8)>) {
        let e = self.engine();
        out.clear();
        out.extend(stars.of(v).iter().map(|&c| {
            let k = first_equal(&e.vertices(c), v).expect("a cell of a star holds its vertex");
            (c, k as u8)
        }));
    }

    /// The cell of point `p`, from the cells around one of its vertices.
    fn cell_of_point(
        &self,
        duals: &Duals<D>,
        p: PointId,
        scratch: &mut CellScratch<S::Elem, N>,
    ) -> VoronoiCell<D, S::Elem> {
        let CellScratch {
            star,
            parent,
            vertex_of_root,
            vertex_of,
            faces: edges,
            member,
            ring,
            cycle,
        } = scratch;
        let e = self.engine();
        let space = self.space();
        self.slotted_star(&duals.stars, e.vertex_of_point(p), star);
        let star = &star[..];
        let position = e.points()[p.index()];
        // one Voronoi vertex per group of star cells joined, through facets at the point, by
        // a shared circumsphere (so in one lift around the point: a sphere met again around
        // the torus at another lift of the point is another vertex)
        parent.clear();
        parent.extend(0..star.len());
        for (s, &(c, k)) in star.iter().enumerate() {
            let cell = e.cell(c);
            for x in
                slots_but::<N>(k as usize).filter(|&x| duals.cospherical[c.index()] >> x & 1 == 1)
            {
                let d = cell.n[x];
                let t = star
                    .iter()
                    .position(|&(sc, _)| sc == d)
                    .expect("a neighbour across a facet at the point is in its star");
                let (a, b) = (root(parent, s), root(parent, t));
                parent[a.max(b)] = a.min(b);
            }
        }
        let mut vertices: Vec<[f64; D]> = Vec::with_capacity(star.len());
        vertex_of_root.clear();
        vertex_of_root.resize(star.len(), u32::MAX);
        vertex_of.clear();
        vertex_of.extend((0..star.len()).map(|s| {
            let r = root(parent, s);
            if vertex_of_root[r] == u32::MAX {
                let (c, k) = star[r];
                // the center is relative to the cell's vertex 0, in the cell's frame;
                // the point's own frame is that of its element in the cell
                let at = e.lifted(c, k as usize);
                let to_point = space.lifted_difference(at, e.lifted(c, 0));
                let z = duals.center[c.index()];
                vertices.push(space.untwist(at.1, std::array::from_fn(|x| z[x] - to_point[x])));
                vertex_of_root[r] = vertices.len() as u32 - 1;
            }
            vertex_of_root[r]
        }));
        // faces: the ring of star cells around each Delaunay edge at the point
        self.gather_edges(edges, star);
        member.clear();
        for (s, at) in edges.index.iter().enumerate() {
            let k = star[s].1 as usize;
            member.extend(slots_but::<N>(k).map(|j| (at[j], s as u32)));
        }
        member.sort_unstable();
        let mut faces = Vec::with_capacity(edges.edges.len());
        for (f, members) in member.chunk_by(|a, b| a.0 == b.0).enumerate() {
            let (w, r, _) = edges.edges[f];
            ring.clear();
            ring.extend(members.iter().map(|m| m.1 as usize));
            self.ring_cycle(star, ring, (w, r), cycle);
            let mut ids: Vec<u32> = cycle.iter().map(|&s| vertex_of[s]).collect();
            ids.dedup();
            while ids.len() > 1 && ids.first() == ids.last() {
                ids.pop();
            }
            if ids.len() < D {
                continue; // the dual of this Delaunay edge has collapsed: no face
            }
            let wp = e.points()[e.point_of(w).index()];
            let dir = space.lifted_difference((wp, r), (position, space.identity()));
            let area = if D == 2 {
                let (a, b) = (&vertices[ids[0] as usize], &vertices[ids[1] as usize]);
                let d: [f64; 2] = std::array::from_fn(|x| b[x] - a[x]);
                // counter-clockwise around the cell: the outward normal (d_y, −d_x) points
                // to the neighbour
                if d[1] * dir[0] - d[0] * dir[1] < 0.0 {
                    ids.reverse();
                }
                dot(&d, &d).sqrt()
            } else {
                let n = newell(&vertices, &ids);
                if dot(&n, &dir) < 0.0 {
                    ids.reverse();
                }
                0.5 * dot(&n, &n).sqrt()
            };
            faces.push(VoronoiFace {
                vertices: ids,
                neighbor: self.input_of_vertex(e.point_of(w)),
                shift: r,
                area,
            });
        }
        let (volume, centroid_rel) = measure(&vertices, &faces);
        if D == 2 {
            order_polygon(&mut vertices, &mut faces);
        }
        // into the user's units: exact scalings by powers of two
        for f in faces.iter_mut() {
            f.area = space.measure_to_user(f.area, D as i32 - 1);
        }
        // the stored point may be in another frame (lattice coordinates): its position
        let here = space.lifted_position((position, space.identity()));
        let around = |x: &[f64; D]| space.to_user(std::array::from_fn(|c| here[c] + x[c]));
        VoronoiCell {
            point: self.input_of_vertex(p),
            position: space.to_user(here),
            vertices: vertices.iter().map(around).collect(),
            faces,
            volume: space.measure_to_user(volume, D as i32),
            centroid: around(&centroid_rel),
        }
    }

    /// Lists the Delaunay edges of a `star` into `faces` ([`Faces::gather`]): by far vertex
    /// alone once the triangulation is 1-sheeted (a simplicial complex).
    fn gather_edges(&self, faces: &mut Faces<S::Elem, N>, star: &[(CellId, u8)]) {
        let e = self.engine();
        faces.gather(
            star,
            e.sheets() == 1,
            |c| e.vertices(c),
            |c, k, j| self.edge_at(c, k, j).1,
        );
    }

    /// The Delaunay edge of cell `c` from its slot `k` to its slot `j`: the far vertex and
    /// its element relative to the near one's.
    #[inline(always)]
    fn edge_at(&self, c: CellId, k: usize, j: usize) -> (VertexId, S::Elem) {
        let e = self.engine();
        let g = self.space().relative(e.element(c, j), e.element(c, k));
        (e.vertices(c)[j], g)
    }

    /// The star cells around the Delaunay edge from the point to `(w, r)`, in cyclic order:
    /// consecutive cells share a facet holding both ends of the edge.
    fn ring_cycle(
        &self,
        star: &[(CellId, u8)],
        ring: &[usize],
        (w, r): (VertexId, S::Elem),
        cycle: &mut Vec<usize>,
    ) {
        let e = self.engine();
        cycle.clear();
        cycle.push(ring[0]);
        let mut prev = CellId::NONE;
        loop {
            let (c, k) = star[*cycle.last().unwrap()];
            let k = k as usize;
            let cell = e.cell(c);
            let j = slots_but::<N>(k)
                .find(|&j| self.edge_at(c, k, j) == (w, r))
                .expect("the ring cell holds the edge");
            let next = slots_but_two::<N>(k, j)
                .map(|x| cell.n[x])
                .find(|&d| d != prev)
                .unwrap_or(prev);
            let s = ring
                .iter()
                .copied()
                .find(|&s| star[s].0 == next)
                .expect("the ring is closed");
            if s == cycle[0] {
                return;
            }
            prev = c;
            cycle.push(s);
        }
    }
}

/// Volume and centroid (relative to the point) of a cell whose vertices are relative to the
/// point: in 3D the sum of the tetrahedra from the point to each face's fan triangles, in
/// 2D of the triangles from the point to each edge, signed by the faces' outward
/// orientation (a power cell may leave its point outside).
fn measure<const D: usize, E>(
    vertices: &[[f64; D]],
    faces: &[VoronoiFace<D, E>],
) -> (f64, [f64; D]) {
    let mut vol = 0.0;
    let mut acc = [0.0; D];
    for f in faces {
        let v = |k: usize| &vertices[f.vertices[k] as usize];
        if D == 2 {
            // the edge runs counter-clockwise: the signed triangles from the point sum to
            // the area even when the point lies outside its cell (a power cell)
            let a = (v(0)[0] * v(1)[1] - v(0)[1] * v(1)[0]) / 2.0;
            vol += a;
            for c in 0..D {
                acc[c] += a * (v(0)[c] + v(1)[c]) / 3.0;
            }
        } else {
            for t in 1..f.vertices.len() - 1 {
                let t6 = dot(&v(0)[..], &cross(&v(t)[..], &v(t + 1)[..])) / 6.0;
                vol += t6;
                for c in 0..D {
                    acc[c] += t6 * (v(0)[c] + v(t)[c] + v(t + 1)[c]) / 4.0;
                }
            }
        }
    }
    (vol, acc.map(|x| x / vol))
}

/// A 2D cell's vertices in counter-clockwise order, with the faces' vertex indices
/// renumbered and each face running counter-clockwise (from `k` to `k + 1`). The order
/// follows the faces around the cell, so it is exact however close two vertices are; the
/// turning sense comes from the polygon's signed area.
fn order_polygon<const D: usize, E>(vertices: &mut Vec<[f64; D]>, faces: &mut [VoronoiFace<D, E>]) {
    let n = vertices.len();
    let mut ends: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (f, face) in faces.iter().enumerate() {
        for &v in &face.vertices {
            ends[v as usize].push(f);
        }
    }
    if n < 2 || n != faces.len() || ends.iter().any(|e| e.len() != 2) {
        debug_assert!(false, "a Voronoi polygon is a cycle of edges");
        return;
    }
    // walk the cycle from vertex 0 along face 0
    let mut cycle = Vec::with_capacity(n);
    let (mut v, mut f) = (0usize, ends[0][0]);
    for _ in 0..n {
        cycle.push(v);
        let face = &faces[f].vertices;
        v = if face[0] as usize == v {
            face[1]
        } else {
            face[0]
        } as usize;
        f = if ends[v][0] == f {
            ends[v][1]
        } else {
            ends[v][0]
        };
    }
    let area2: f64 = (0..n)
        .map(|k| {
            let (a, b) = (&vertices[cycle[k]], &vertices[cycle[(k + 1) % n]]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum();
    if area2 < 0.0 {
        cycle.reverse();
    }
    let mut new_index = vec![0u32; n];
    for (k, &o) in cycle.iter().enumerate() {
        new_index[o] = k as u32;
    }
    *vertices = cycle.iter().map(|&o| vertices[o]).collect();
    for face in faces.iter_mut() {
        let (a, b) = (
            new_index[face.vertices[0] as usize],
            new_index[face.vertices[1] as usize],
        );
        face.vertices = if (a + 1) % n as u32 == b {
            vec![a, b]
        } else {
            vec![b, a]
        };
    }
}

/// The neighbour pairs of a torus's cells, each unordered pair of images once: `i < j`, or
/// `i == j` with the shift's first non-zero entry positive.
pub fn neighbor_pairs<const D: usize>(cells: &[VoronoiCell<D>]) -> Vec<Neighbor<D>> {
    neighbor_pairs_by(cells, |s| s.map(|x| -x))
}

/// The neighbour pairs of any space's cells, each unordered pair of images once: `i < j`, or
/// `i == j` with the shift greater than its `inverse` (the space's).
pub fn neighbor_pairs_by<const D: usize, E: Copy + Ord>(
    cells: &[VoronoiCell<D, E>],
    inverse: impl Fn(E) -> E,
) -> Vec<Neighbor<D, E>> {
    cells
        .iter()
        .flat_map(|c| {
            c.faces
                .iter()
                .filter(|f| listed_once(c.point, f.neighbor, f.shift, &inverse))
                .map(move |f| Neighbor {
                    i: c.point,
                    j: f.neighbor,
                    shift: f.shift,
                    area: f.area,
                })
        })
        .collect()
}

/// True for the one side of a face that lists it as a neighbour pair: `i < j`, or `i == j`
/// with the element greater than its inverse.
fn listed_once<E: Copy + Ord>(i: InputId, j: InputId, g: E, inverse: impl Fn(E) -> E) -> bool {
    i < j || (i == j && g > inverse(g))
}

/// The slots `0..N` other than `k`, ascending, computed without a branch on `k`: a loop
/// that skips `k` takes a branch the processor mispredicts about once a cell (a sixth of
/// the pieces' time with the neighbour pairs).
fn slots_but<const N: usize>(k: usize) -> impl Iterator<Item = usize> {
    (0..N - 1).map(move |i| i + usize::from(i >= k))
}

/// The slots `0..N` other than `k` and `l` (distinct), ascending, without a branch on them.
fn slots_but_two<const N: usize>(k: usize, l: usize) -> impl Iterator<Item = usize> {
    let (low, high) = (k.min(l), k.max(l));
    (0..N - 2).map(move |i| {
        let j = i + usize::from(i >= low);
        j + usize::from(j >= high)
    })
}

#[cfg(test)]
mod tests {
    use super::{slots_but, slots_but_two};

    fn check<const N: usize>() {
        for k in 0..N {
            let want: Vec<usize> = (0..N).filter(|&j| j != k).collect();
            assert_eq!(slots_but::<N>(k).collect::<Vec<_>>(), want);
            for l in (0..N).filter(|&l| l != k) {
                let want: Vec<usize> = (0..N).filter(|&j| j != k && j != l).collect();
                assert_eq!(slots_but_two::<N>(k, l).collect::<Vec<_>>(), want);
            }
        }
    }

    #[test]
    fn the_other_slots_ascend_without_the_skipped_ones() {
        check::<3>();
        check::<4>();
    }
}
