//! `Triangulation<D, N, S>`: the Delaunay triangulation of a point set in a flat orbit space
//! `S` of dimension `D` (cells of `N = D + 1` vertices), with input bookkeeping (wrapping into
//! the domain, duplicates), bulk construction and the access API, written once for every
//! space. `PeriodicDelaunay2` and `PeriodicDelaunay3` name the flat tori, `KleinBottle`
//! and `FlatManifold3` the other closed flat manifolds.

use std::collections::HashSet;
use std::ops::ControlFlow;

use crate::delaunay::{Engine, Inserted, Invalid};
use crate::error::{Error, Result};
use crate::ids::{CellId, PointId, VertexId};
use crate::space::{FlatManifold, FlatSpace, FlatTorus, OrbitSpace};

/// Marks an unset entry of the input ↔ point maps.
const NONE: u32 = u32::MAX;

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

/// Which copies an iterator yields in a multi-sheeted covering (CGAL's iterator types).
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
    pub vertices: [u32; N],
    pub offsets: [E; N],
}

/// A simplex of lower dimension (edge: 2 vertices, facet: `D`), canonical modulo the group:
/// for a torus, sorted by (vertex, offset) with the componentwise minimum offset translated
/// to zero.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Simplex<const D: usize = 3, E = Offset<D>> {
    pub vertices: Vec<u32>,
    pub offsets: Vec<E>,
}

/// A Delaunay edge: `j`'s image `shift·points[j]` (`points[j] + shift·M` in a torus) is
/// joined to point `i`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DelaunayEdge<const D: usize, E = Offset<D>> {
    pub i: u32,
    pub j: u32,
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
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            dummy_threshold: 1000,
            seed: 0x0b17,
            spatial_sort: true,
        }
    }
}

/// The Delaunay triangulation of a point set in the flat orbit space `S` of dimension `D`.
#[derive(Debug)]
pub struct Triangulation<const D: usize, const N: usize, S: FlatSpace<D, N> = FlatTorus<D>> {
    engine: Engine<S, N>,
    /// Input index → point (vertex) index.
    input_point: Vec<u32>,
    /// Point index → input index of its first occurrence.
    point_input: Vec<u32>,
    wrapped: usize,
    duplicates: usize,
    used_dummies: bool,
}

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
/// one by its index in `points`), and how many wrapping moved.
fn internal_points<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    space: &S,
    points: &[[f64; D]],
) -> Result<(Vec<[f64; D]>, usize)> {
    let mut out = Vec::with_capacity(points.len());
    let mut moved = 0;
    for (i, p) in points.iter().enumerate() {
        let (w, m) = internal_point(space, i, p)?;
        moved += m as usize;
        out.push(w);
    }
    Ok((out, moved))
}

/// The BRIO + Hilbert insertion order of internal points.
fn spatial_order<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    space: &S,
    points: &[[f64; D]],
    seed: u64,
) -> Vec<u32> {
    let keys: Vec<u64> = points.iter().map(|p| space.spatial_key(p)).collect();
    crate::sort::brio_order(&keys, seed)
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
        }
    }

    /// Builds the triangulation of `points` (wrapped into the domain first).
    pub fn build(space: S, points: &[[f64; D]]) -> Result<Self> {
        Self::build_with(space, points, BuildOptions::default(), |_| {
            ControlFlow::Continue(())
        })
    }

    /// Bulk construction: spatial sort (BRIO + Hilbert); for large inputs start from the
    /// dummy point set in the 1-sheeted torus and remove the dummies at the end, otherwise
    /// (or if removing a dummy would break the criterion) insert into the covering space.
    ///
    /// `progress` is called with the number of points inserted so far: before the first,
    /// every 4096 points and at the end. Returning [`ControlFlow::Break`] stops the
    /// construction, which then returns [`Error::Interrupted`] (a cancellation hook: keep
    /// the callback cheap, it runs between insertions).
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
        mut progress: impl FnMut(usize) -> ControlFlow<()>,
    ) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::EmptyInput);
        }
        let (wrapped_pts, wrapped) = internal_points(&space, points)?;
        let order: Vec<u32> = if opts.spatial_sort {
            spatial_order(&space, &wrapped_pts, opts.seed)
        } else {
            (0..points.len() as u32).collect()
        };
        let mut tri = Self::new(space.clone());
        tri.wrapped = wrapped;
        // a Delaunay triangulation of uniform points has about 6.77 cells per vertex in 3D,
        // exactly 2 in 2D
        let per_point = if D == 3 { 27 } else { 8 };
        tri.engine
            .reserve(points.len() + 128, points.len() * per_point / 4 + 4096);
        if points.len() >= opts.dummy_threshold
            && tri.build_from_dummies(&wrapped_pts, &order, &mut progress)?
        {
            tri.represent_first_occurrences(&wrapped_pts);
            return Ok(tri);
        }
        let mut tri = Self::new(space);
        tri.wrapped = wrapped;
        tri.input_point = vec![NONE; points.len()];
        for (k, &i) in order.iter().enumerate() {
            if k % 4096 == 0 {
                proceed(&mut progress, k)?;
            }
            tri.insert_wrapped(i as usize, wrapped_pts[i as usize]);
        }
        if !tri.engine.is_one_sheeted() {
            tri.engine.try_one_sheet();
        }
        tri.represent_first_occurrences(&wrapped_pts);
        proceed(&mut progress, points.len())?;
        Ok(tri)
    }

    /// After a build in spatial order: every point that met duplicates takes the wrapped
    /// coordinates of its first occurrence, as the output formats promise (offsets are
    /// relative to input `i`'s wrapped point). Duplicates can differ from it by an exact
    /// lattice translation, which the offsets of the point's star absorb.
    fn represent_first_occurrences(&mut self, wrapped: &[[f64; D]]) {
        for p in 0..self.point_input.len() {
            self.represent(p as u32, wrapped[self.point_input[p] as usize]);
        }
    }

    /// Gives point `p` the wrapped coordinates `want` of its first occurrence, when they
    /// differ from the current ones by an exact group element.
    fn represent(&mut self, p: u32, want: [f64; D]) {
        let have = self.engine.points()[p as usize];
        if want == have {
            return;
        }
        let g = self.space().relating(want, have);
        debug_assert!(g.is_some(), "a duplicate is an exact image");
        if let Some(g) = g {
            self.engine.move_representative(PointId(p), want, g);
        }
    }

    /// Dummy-point construction; false if it had to be abandoned (a point coincides with a
    /// dummy, or the points alone do not satisfy the criterion), `Err` if `progress` stopped
    /// it.
    fn build_from_dummies(
        &mut self,
        pts: &[[f64; D]],
        order: &[u32],
        progress: &mut impl FnMut(usize) -> ControlFlow<()>,
    ) -> Result<bool> {
        let dummies = self.engine.space().dummy_points();
        let k = dummies.len() as u32;
        self.engine.points = dummies;
        self.engine.bootstrap_one_sheeted();
        self.input_point = vec![NONE; pts.len()];
        // placeholders: point indices count the dummies until they are dropped
        self.point_input = vec![NONE; k as usize];
        for (n, &i) in order.iter().enumerate() {
            if n % 4096 == 0 {
                proceed(progress, n)?;
            }
            match self.engine.insert(pts[i as usize]) {
                Inserted::New(p) => {
                    self.input_point[i as usize] = p.0;
                    self.point_input.push(i);
                }
                Inserted::Duplicate(p) if p.0 < k => return Ok(false),
                Inserted::Duplicate(p) => self.record_duplicate(i as usize, p.0),
            }
        }
        // 1-sheeted: the vertex of dummy point `d` has its id
        for d in 0..k {
            if self.engine.remove_vertex(VertexId(d)).is_err() {
                return Ok(false);
            }
        }
        self.engine.drop_leading_points(k);
        self.point_input.drain(..k as usize);
        for p in self.input_point.iter_mut() {
            *p -= k;
        }
        self.used_dummies = true;
        proceed(progress, pts.len())?;
        Ok(true)
    }

    fn insert_wrapped(&mut self, i: usize, p: [f64; D]) -> Inserted {
        let r = self.engine.insert(p);
        match r {
            Inserted::New(v) => {
                self.input_point[i] = v.0;
                self.point_input.push(i as u32);
            }
            Inserted::Duplicate(v) => self.record_duplicate(i, v.0),
        }
        r
    }

    /// Input `i` coincides with point `p`; the point keeps the smallest input id.
    fn record_duplicate(&mut self, i: usize, p: u32) {
        self.input_point[i] = p;
        self.duplicates += 1;
        let first = &mut self.point_input[p as usize];
        *first = (*first).min(i as u32);
    }

    /// Inserts one more point (wrapped into the domain); its input id is the number of
    /// points given so far. Returns the vertex (point index) it became or coincides with.
    pub fn insert(&mut self, p: [f64; D]) -> Result<Inserted> {
        let i = self.input_point.len();
        let (w, moved) = internal_point(self.space(), i, &p)?;
        self.wrapped += moved as usize;
        self.input_point.push(NONE);
        Ok(self.insert_wrapped(i, w))
    }

    /// Inserts a batch of points, all or nothing: every point is checked and wrapped first,
    /// and an error, which names the point by its row in `points`, leaves the triangulation
    /// unchanged. The batch then goes in by BRIO + Hilbert order, so that each walk starts
    /// next to its target whatever the order of `points` (inserting points one by one in
    /// random order walks across the triangulation each time). Input ids follow the order of
    /// `points`, and a point met several times keeps the coordinates of its first
    /// occurrence, as in [`Self::build`]. Returns, per point, the vertex (point index) it
    /// became or coincides with.
    pub fn insert_all(&mut self, points: &[[f64; D]]) -> Result<Vec<Inserted>> {
        let (internal, moved) = internal_points(self.space(), points)?;
        let first = self.input_point.len();
        self.input_point.resize(first + points.len(), NONE);
        self.wrapped += moved;
        let seed = BuildOptions::default().seed ^ first as u64;
        let mut out = vec![Inserted::New(PointId(0)); points.len()];
        for k in spatial_order(self.space(), &internal, seed) {
            out[k as usize] = self.insert_wrapped(first + k as usize, internal[k as usize]);
        }
        // a duplicate inserted before its first occurrence lent the point its coordinates
        for (k, r) in out.iter().enumerate() {
            let (Inserted::New(p) | Inserted::Duplicate(p)) = *r;
            if self.point_input[p.index()] as usize == first + k {
                self.represent(p.0, internal[k]);
            }
        }
        Ok(out)
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

    /// Number of stored cells (in the covering: all copies).
    pub fn number_of_cells(&self) -> usize {
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

    /// The distinct points (wrapped), indexed by vertex.
    pub fn points(&self) -> Vec<[f64; D]> {
        (0..self.number_of_vertices() as u32)
            .map(|v| self.point(v))
            .collect()
    }

    /// The wrapped position of vertex `v` (a point index).
    pub fn point(&self, v: u32) -> [f64; D] {
        self.space().to_user(self.engine.points()[v as usize])
    }

    /// The position of input point `i`'s image under the group element `offset` (in a
    /// torus, `points[i] + offset·M`), in Cartesian coordinates.
    pub fn position(&self, i: u32, offset: S::Elem) -> [f64; D] {
        let p = self.engine.points()[self.vertex_of_input(i as usize) as usize];
        let space = self.space();
        space.to_user(space.lifted_position((p, offset)))
    }

    /// The vertex of input point `i`.
    pub fn vertex_of_input(&self, i: usize) -> u32 {
        self.input_point[i]
    }

    /// The input id of vertex `v` (its first occurrence).
    pub fn input_of_vertex(&self, v: u32) -> u32 {
        self.point_input[v as usize]
    }

    /// For every input point, the input id of its first occurrence (itself unless duplicate).
    pub fn first_occurrences(&self) -> Vec<u32> {
        self.input_point
            .iter()
            .map(|&v| self.point_input[v as usize])
            .collect()
    }

    /// The input id of a stored vertex's point.
    fn input_of(&self, v: VertexId) -> u32 {
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

    /// Every stored cell (as `stored_cells`) with its neighbours: `neighbors[k][i]` is the
    /// position in this list of the cell opposite vertex `i` of cell `k`.
    pub fn cells_with_neighbors(&self) -> (Vec<CellView<D, N, S::Elem>>, Vec<[u32; N]>) {
        let ids: Vec<CellId> = self.engine.cell_ids().collect();
        let slots = ids.iter().max().map_or(0, |m| m.index() + 1);
        let mut position = vec![u32::MAX; slots];
        for (k, &c) in ids.iter().enumerate() {
            position[c.index()] = k as u32;
        }
        let views = ids.iter().map(|&c| self.view(c)).collect();
        let neighbors = ids
            .iter()
            .map(|&c| self.engine.cell(c).n.map(|d| position[d.index()]))
            .collect();
        (views, neighbors)
    }

    /// The cells with input ids and offsets: every stored cell, or one per orbit.
    pub fn cells(&self, copies: Copies) -> Vec<CellView<D, N, S::Elem>> {
        if copies == Copies::Stored || self.is_one_sheeted() {
            return self.stored_cells().collect();
        }
        let mut seen = HashSet::new();
        self.stored_cells()
            .filter(|c| seen.insert(canonical(self.space(), &c.vertices, &c.offsets)))
            .collect()
    }

    /// A face of a stored cell (the slots in `idx`): its vertices as input ids (`Unique`)
    /// or stored vertex ids (`Stored`), in canonical form.
    fn face(&self, c: CellId, idx: &[usize], copies: Copies) -> Simplex<D, S::Elem> {
        let cell = self.engine.cell(c);
        let id = |x: VertexId| match copies {
            Copies::Unique => self.input_of(x),
            Copies::Stored => x.0,
        };
        let v: Vec<u32> = idx.iter().map(|&i| id(cell.v[i])).collect();
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

    /// The edges (input ids, offsets), each once; `Stored` lists covering copies by vertex
    /// id. Found from each vertex's neighbours, towards the larger vertex id.
    pub fn edges(&self, copies: Copies) -> Vec<Simplex<D, S::Elem>> {
        let id = move |x: VertexId| match copies {
            Copies::Unique => self.input_of(x),
            Copies::Stored => x.0,
        };
        let all = (0..self.engine.number_of_vertices() as u32)
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
            });
        if copies == Copies::Unique && !self.is_one_sheeted() {
            return self.unique_in_covering(all);
        }
        all.collect()
    }

    /// The Delaunay edges of the torus, each once, with input ids, shift and length.
    pub fn delaunay_edges(&self) -> Vec<DelaunayEdge<D, S::Elem>> {
        let space = self.space();
        self.edges(Copies::Unique)
            .into_iter()
            .map(|s| {
                let at = |k: usize| {
                    let p =
                        self.engine.points()[self.vertex_of_input(s.vertices[k] as usize) as usize];
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

    /// The facets, each once (from the cell with the smaller id); `Stored` lists covering
    /// copies by vertex id.
    pub fn facets(&self, copies: Copies) -> Vec<Simplex<D, S::Elem>> {
        let all = self.engine.cell_ids().flat_map(|c| {
            let n = self.engine.cell(c).n;
            (0..N).filter(move |&i| c < n[i]).map(move |i| (c, i))
        });
        let face = |(c, i): (CellId, usize)| {
            let idx: Vec<usize> = (0..N).filter(|&k| k != i).collect();
            self.face(c, &idx, copies)
        };
        if copies == Copies::Unique && !self.is_one_sheeted() {
            return self.unique_in_covering(all.map(face));
        }
        all.map(face).collect()
    }

    /// The neighbours of input point `i`: (input id, offset of the neighbour relative to
    /// the point), one entry per Delaunay edge at the point, from the point's star.
    pub fn vertex_neighbors(&self, i: usize) -> Vec<(u32, S::Elem)> {
        let v = self.engine.vertex_of_point(PointId(self.input_point[i]));
        let mut out: Vec<(u32, S::Elem)> = self
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

    /// Checks combinatorics and geometry exactly.
    pub fn is_valid(&self) -> std::result::Result<(), Invalid> {
        self.engine.is_valid()
    }
}

/// Canonical form modulo the group of a simplex given by vertices and elements.
fn canonical<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    space: &S,
    v: &[u32],
    o: &[S::Elem],
) -> (Vec<u32>, Vec<S::Elem>) {
    let mut pairs: Vec<(u32, S::Elem)> = v.iter().copied().zip(o.iter().copied()).collect();
    space.canonical_face(&mut pairs);
    pairs.into_iter().unzip()
}
