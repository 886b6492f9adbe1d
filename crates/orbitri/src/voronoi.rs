//! Periodic Voronoi cells, the duals of the Delaunay triangulation: for every point, its cell
//! around the point (vertices = circumcenters of the cells of its star, faces = duals of its
//! Delaunay edges, each with the neighbour's id and lattice shift), volume (area in 2D), face
//! areas (lengths in 2D) and centroid. Computed from the triangulation's adjacency and the
//! periodic geometry, so a triangulation still in a covering space gives the same cells.
//!
//! Degenerate inputs are exact: adjacent Delaunay cells whose circumspheres coincide (decided
//! by the unperturbed in-sphere test) give one Voronoi vertex, and a Delaunay edge whose dual
//! has collapsed to fewer than `D` vertices is no face (a square grid's diagonals, for example).

use rayon::prelude::*;

use crate::periodic::{PeriodicDelaunay, Torus};
use crate::space::{FlatTorus, OrbitSpace};

/// A face of a Voronoi cell: the part of the bisector with one periodic image of a neighbour.
#[derive(Clone, Debug, PartialEq)]
pub struct VoronoiFace<const D: usize> {
    /// Indices into the cell's vertices: in 3D a cycle, counter-clockwise seen from outside
    /// the cell; in 2D the two ends of the edge.
    pub vertices: Vec<u32>,
    /// Input id of the neighbour (its first occurrence).
    pub neighbor: u32,
    /// The neighbour's image across this face is `points[neighbor] + shift·M`.
    pub shift: [i8; D],
    /// Area of the face (length in 2D).
    pub area: f64,
}

/// The Voronoi cell of one point, in Cartesian coordinates around the point's wrapped
/// position (vertices may lie outside the domain).
#[derive(Clone, Debug, PartialEq)]
pub struct VoronoiCell<const D: usize> {
    /// Input id of the point (its first occurrence).
    pub point: u32,
    /// The point's wrapped position.
    pub position: [f64; D],
    pub vertices: Vec<[f64; D]>,
    pub faces: Vec<VoronoiFace<D>>,
    /// Volume (area in 2D).
    pub volume: f64,
    pub centroid: [f64; D],
}

/// Two Voronoi neighbours: `j`'s image `points[j] + shift·M` shares a face of this area with
/// `i`. Each unordered pair of images is listed once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbor<const D: usize> {
    pub i: u32,
    pub j: u32,
    pub shift: [i8; D],
    pub area: f64,
}

/// Solves `A x = b` for small `D` by Gaussian elimination with partial pivoting.
fn solve<const D: usize>(mut a: [[f64; D]; D], mut b: [f64; D]) -> [f64; D] {
    for col in 0..D {
        let piv = (col..D)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        a.swap(piv, col);
        b.swap(piv, col);
        for r in col + 1..D {
            let f = a[r][col] / a[col][col];
            for k in col..D {
                a[r][k] -= f * a[col][k];
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = [0.0; D];
    for r in (0..D).rev() {
        let s: f64 = (r + 1..D).map(|k| a[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    x
}

fn cross(a: &[f64], b: &[f64]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Newell's normal of a polygon (twice its vector area).
fn newell(pts: &[&[f64]]) -> [f64; 3] {
    let mut n = [0.0; 3];
    for k in 0..pts.len() {
        let c = cross(pts[k], pts[(k + 1) % pts.len()]);
        for (nc, cc) in n.iter_mut().zip(c) {
            *nc += cc;
        }
    }
    n
}

/// Union–find root with path halving.
fn root(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

impl<const D: usize, const N: usize> PeriodicDelaunay<D, N>
where
    FlatTorus<D>: Torus<D, N>,
{
    /// The Voronoi cell of input point `i` (a duplicate gets its first occurrence's cell).
    pub fn voronoi_cell(&self, i: usize) -> VoronoiCell<D> {
        self.cell_of_point(self.vertex_of_input(i))
    }

    /// The Voronoi cells of the distinct points, in the order of their first occurrence
    /// (computed in parallel).
    pub fn voronoi_cells(&self) -> Vec<VoronoiCell<D>> {
        let mut points: Vec<u32> = (0..self.number_of_vertices() as u32).collect();
        points.sort_unstable_by_key(|&p| self.input_of_vertex(p));
        points.par_iter().map(|&p| self.cell_of_point(p)).collect()
    }

    /// The Voronoi neighbour pairs with their shared face areas, each unordered pair of
    /// images once (`i < j`, or `i == j` with the shift's first non-zero entry positive).
    pub fn voronoi_neighbors(&self) -> Vec<Neighbor<D>> {
        neighbor_pairs(&self.voronoi_cells())
    }

    /// The cell of point index `p`, from the star of one of its vertices.
    fn cell_of_point(&self, p: u32) -> VoronoiCell<D> {
        let e = self.engine();
        let torus = self.space();
        let v = e.vertex_of_point(p);
        let star = e.star(v);
        let position = self.points()[p as usize];
        // Voronoi vertices: circumcenters relative to the point, in each star cell's frame
        let centers: Vec<[f64; D]> = star
            .iter()
            .map(|&(c, k, _)| {
                let cell = e.cell(c);
                let base = torus.position((position, cell.off[k]));
                let mut a = [[0.0; D]; D];
                let mut b = [0.0; D];
                for (row, i) in (0..N).filter(|&i| i != k).enumerate() {
                    let q = torus.position(e.lifted(c, i));
                    let d: [f64; D] = std::array::from_fn(|x| q[x] - base[x]);
                    a[row] = d;
                    b[row] = 0.5 * dot(&d, &d);
                }
                solve(a, b)
            })
            .collect();
        // adjacent star cells with one circumsphere are one Voronoi vertex
        let mut parent: Vec<usize> = (0..star.len()).collect();
        for (s, &(c, k, _)) in star.iter().enumerate() {
            let cell = e.cell(c);
            let lifted = e.lifted_cell(c);
            for x in (0..N).filter(|&x| x != k) {
                let d = cell.n[x];
                let Some(t) = star.iter().position(|st| st.0 == d) else {
                    continue;
                };
                if t < s {
                    continue;
                }
                let dc = e.cell(d);
                let y = (0..N)
                    .find(|&y| dc.n[y] == c)
                    .expect("symmetric neighbours");
                let shift = e.translation(c, x, d);
                let opposite = (self.points()[e.point_of(dc.v[y]) as usize], {
                    torus.compose(dc.off[y], shift)
                });
                if torus.cospherical(&lifted, opposite) {
                    let (a, b) = (root(&mut parent, s), root(&mut parent, t));
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
        let mut vertex_of = vec![u32::MAX; star.len()];
        let mut vertices: Vec<[f64; D]> = Vec::new();
        for s in 0..star.len() {
            let r = root(&mut parent, s);
            if vertex_of[r] == u32::MAX {
                vertex_of[r] = vertices.len() as u32;
                vertices.push(centers[r]);
            }
            vertex_of[s] = vertex_of[r];
        }
        // faces: the ring of star cells around each Delaunay edge at the point
        let mut edges: Vec<(u32, [i8; D])> = Vec::new();
        let mut ring_of: Vec<Vec<usize>> = Vec::new();
        for (s, &(c, k, _)) in star.iter().enumerate() {
            let cell = e.cell(c);
            for j in (0..N).filter(|&j| j != k) {
                let key = (cell.v[j], torus.difference(cell.off[j], cell.off[k]));
                match edges.iter().position(|x| *x == key) {
                    Some(f) => ring_of[f].push(s),
                    None => {
                        edges.push(key);
                        ring_of.push(vec![s]);
                    }
                }
            }
        }
        let mut faces = Vec::with_capacity(edges.len());
        for (f, &(w, r)) in edges.iter().enumerate() {
            let cycle = self.ring_cycle(&star, &ring_of[f], w, r);
            let mut ids: Vec<u32> = cycle.iter().map(|&s| vertex_of[s]).collect();
            ids.dedup();
            while ids.len() > 1 && ids.first() == ids.last() {
                ids.pop();
            }
            if ids.len() < D {
                continue; // the dual of this Delaunay edge has collapsed: no face
            }
            let other = torus.position(([0.0; D], r));
            let wp = self.points()[e.point_of(w) as usize];
            let dir: [f64; D] = std::array::from_fn(|x| wp[x] + other[x] - position[x]);
            let pts: Vec<&[f64]> = ids.iter().map(|&i| &vertices[i as usize][..]).collect();
            let area = if D == 2 {
                let d: Vec<f64> = (0..2).map(|x| pts[1][x] - pts[0][x]).collect();
                dot(&d, &d).sqrt()
            } else {
                let n = newell(&pts);
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
        VoronoiCell {
            point: self.input_of_vertex(p),
            position,
            vertices: vertices
                .iter()
                .map(|x| std::array::from_fn(|c| position[c] + x[c]))
                .collect(),
            faces,
            volume,
            centroid: std::array::from_fn(|c| position[c] + centroid_rel[c]),
        }
    }

    /// The star cells around the Delaunay edge from the point to `(w, r)`, in cyclic order:
    /// consecutive cells share a facet holding both ends of the edge.
    fn ring_cycle(
        &self,
        star: &[(u32, usize, [i8; D])],
        ring: &[usize],
        w: u32,
        r: [i8; D],
    ) -> Vec<usize> {
        let e = self.engine();
        let mut cycle = vec![ring[0]];
        let mut prev = u32::MAX;
        loop {
            let (c, k, _) = star[*cycle.last().unwrap()];
            let cell = e.cell(c);
            let j = (0..N)
                .find(|&j| {
                    j != k && cell.v[j] == w && e.space().difference(cell.off[j], cell.off[k]) == r
                })
                .expect("the ring cell holds the edge");
            let next = (0..N)
                .filter(|&x| x != k && x != j)
                .map(|x| cell.n[x])
                .find(|&d| d != prev)
                .unwrap_or(prev);
            let s = ring
                .iter()
                .copied()
                .find(|&s| star[s].0 == next)
                .expect("the ring is closed");
            if s == cycle[0] {
                return cycle;
            }
            prev = c;
            cycle.push(s);
        }
    }
}

/// Volume and centroid (relative to the point) of a cell whose vertices are relative to the
/// point: in 3D the sum of the tetrahedra from the point to each face's fan triangles, in
/// 2D of the triangles from the point to each edge (signed by the orientation).
fn measure<const D: usize>(vertices: &[[f64; D]], faces: &[VoronoiFace<D>]) -> (f64, [f64; D]) {
    let mut vol = 0.0;
    let mut acc = [0.0; D];
    for f in faces {
        let v: Vec<&[f64; D]> = f.vertices.iter().map(|&i| &vertices[i as usize]).collect();
        if D == 2 {
            // orientation from the bisector side: the point (origin) and the neighbour are
            // on opposite sides, so |cross| is the triangle's doubled area
            let a = (v[0][0] * v[1][1] - v[0][1] * v[1][0]).abs() / 2.0;
            vol += a;
            for c in 0..D {
                acc[c] += a * (v[0][c] + v[1][c]) / 3.0;
            }
        } else {
            for t in 1..v.len() - 1 {
                let t6 = dot(&v[0][..], &cross(&v[t][..], &v[t + 1][..])) / 6.0;
                vol += t6;
                for c in 0..D {
                    acc[c] += t6 * (v[0][c] + v[t][c] + v[t + 1][c]) / 4.0;
                }
            }
        }
    }
    (vol, acc.map(|x| x / vol))
}

/// A 2D cell's vertices in counter-clockwise order (by angle around the point, which the
/// convex cell contains), with the faces' vertex indices renumbered.
fn order_polygon<const D: usize>(vertices: &mut Vec<[f64; D]>, faces: &mut [VoronoiFace<D>]) {
    let mut order: Vec<usize> = (0..vertices.len()).collect();
    order.sort_by(|&a, &b| {
        let (pa, pb) = (&vertices[a], &vertices[b]);
        pa[1].atan2(pa[0]).total_cmp(&pb[1].atan2(pb[0]))
    });
    let mut new_index = vec![0u32; vertices.len()];
    for (k, &o) in order.iter().enumerate() {
        new_index[o] = k as u32;
    }
    *vertices = order.iter().map(|&o| vertices[o]).collect();
    for f in faces.iter_mut() {
        for v in f.vertices.iter_mut() {
            *v = new_index[*v as usize];
        }
        f.vertices.sort_unstable();
        // counter-clockwise seen from the point: the edge from k to k+1 (or last to first)
        if f.vertices[0] == 0 && f.vertices[1] as usize == vertices.len() - 1 {
            f.vertices.reverse();
        }
    }
}

/// The neighbour pairs of a set of cells, each unordered pair of images once.
pub fn neighbor_pairs<const D: usize>(cells: &[VoronoiCell<D>]) -> Vec<Neighbor<D>> {
    let positive = |s: &[i8; D]| s.iter().find(|&&x| x != 0).is_some_and(|&x| x > 0);
    cells
        .iter()
        .flat_map(|c| {
            c.faces
                .iter()
                .filter(move |f| {
                    c.point < f.neighbor || (c.point == f.neighbor && positive(&f.shift))
                })
                .map(move |f| Neighbor {
                    i: c.point,
                    j: f.neighbor,
                    shift: f.shift,
                    area: f.area,
                })
        })
        .collect()
}
