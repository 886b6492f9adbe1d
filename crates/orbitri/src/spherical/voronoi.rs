//! Spherical Voronoi cells, dual to the faces: a cell is the spherical polygon whose
//! vertices are the poles of the faces around its site (their circumcentres on the sphere)
//! and whose edges are great-circle arcs. Faces whose four points lie on one circle share
//! one pole, found exactly (the unperturbed in-circle test), so the cells tile the sphere
//! with no zero-length arc; areas sum to 4π to within rounding.

use rayon::prelude::*;

use super::ghost::Ghosts;
use super::{SphericalSpace, SphericalTriangulation};
use crate::error::{Error, Result};
use crate::ids::{CellId, InputId, PointId, VertexId};
use crate::predicates::spherical::side_of_circle;
use crate::predicates::Sign;
use crate::space::pole;

/// The Voronoi cell of one vertex on the sphere.
#[derive(Clone, Debug, PartialEq)]
pub struct SphericalCell {
    /// The input id of the site (the first occurrence of its point).
    pub site: InputId,
    /// The polygon's vertices on the unit sphere, counter-clockwise seen from outside.
    pub vertices: Vec<[f64; 3]>,
    /// `neighbors[k]`: the site across the arc from `vertices[k]` to `vertices[k + 1]`.
    pub neighbors: Vec<InputId>,
    /// The length (angle in radians) of each arc, in the same order.
    pub arc_lengths: Vec<f64>,
    /// The area (solid angle in steradians); the cells' areas sum to 4π.
    pub area: f64,
    /// The centroid: the unit vector along the integral of the position over the cell.
    pub centroid: [f64; 3],
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = dot(&a, &a).sqrt();
    a.map(|x| x / n)
}

/// The signed area of the spherical triangle of unit vectors `s, a, b` (Van Oosterom and
/// Strackee), positive when counter-clockwise seen from outside.
fn triangle_area(s: &[f64; 3], a: &[f64; 3], b: &[f64; 3]) -> f64 {
    // det[s; a; b] through differences: no cancellation for a small triangle
    let u = [a[0] - s[0], a[1] - s[1], a[2] - s[2]];
    let v = [b[0] - s[0], b[1] - s[1], b[2] - s[2]];
    let det = dot(s, &cross(&u, &v));
    2.0 * det.atan2(1.0 + dot(s, a) + dot(a, b) + dot(b, s))
}

/// The root of `x` in a union-find forest, halving paths on the way.
fn root(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let up = parent[parent[x as usize] as usize];
        parent[x as usize] = up;
        x = up;
    }
    x
}

impl<S: SphericalSpace> SphericalTriangulation<S> {
    /// The Voronoi cell of every vertex, in the order of [`Self::vertices`] (in RP², around
    /// the stored representative of each point; the areas sum to 2π). For points in a
    /// closed hemisphere the cells pass through the poles of the ghost faces
    /// ([`Self::ghost_faces`]), whose empty caps are a hemisphere or more. Below dimension
    /// 2 (at most two points, or all on one circle) there are no faces to be dual to:
    /// [`Error::NoFaces`].
    ///
    /// ```
    /// use orbitri::spherical::SphericalDelaunay;
    /// let cube: Vec<[f64; 3]> = (0..8)
    ///     .map(|k| [0, 1, 2].map(|b| if k >> b & 1 == 1 { 1.0 } else { -1.0 } / 3f64.sqrt()))
    ///     .collect();
    /// let tri = SphericalDelaunay::build(&cube).unwrap();
    /// let cells = tri.voronoi_cells().unwrap();
    /// // the cube's square faces are cocircular: each cell is a spherical triangle
    /// assert!(cells.iter().all(|c| c.vertices.len() == 3));
    /// let total: f64 = cells.iter().map(|c| c.area).sum();
    /// assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-12);
    /// ```
    pub fn voronoi_cells(&self) -> Result<Vec<SphericalCell>> {
        let dimension = self.dimension();
        if dimension < 2 {
            return Err(Error::NoFaces {
                points: self.number_of_vertices(),
                dimension,
            });
        }
        let e = self.engine();
        let sp = e.space();
        let ghosts = self.ghosts();
        // faces: the engine's cells (those without an anchor), then the ghost faces
        let slots = e.cell_slots();
        let ids: Vec<CellId> = e.cell_ids().filter(|&c| self.is_face(c)).collect();
        let at = |p: PointId| e.points()[p.index()];
        let ghost_at = |f: usize| ghosts.faces[f].map(at);
        // faces on one circle: one class, one pole
        let mut parent: Vec<u32> = (0..(slots + ghosts.faces.len()) as u32).collect();
        let mut merges: Vec<(u32, u32)> = ids
            .par_iter()
            .flat_map_iter(|&c| {
                let cell = e.cell(c);
                let s = e.lifted_cell(c);
                (0..3).filter_map(move |k| {
                    let d = cell.n[k];
                    if d < c || !self.is_face(d) {
                        return None;
                    }
                    let j = e.cell(d).mirror(c).expect("symmetric neighbours");
                    // the opposite vertex carried into this cell's frame
                    let (q, g) = e.lifted(d, j);
                    let q = (q, sp.compose(e.translation(c, k, d), g));
                    sp.cospherical(&s, q).then_some((c.0, d.0))
                })
            })
            .collect();
        for f in 0..ghosts.faces.len() {
            let [a, b, c] = ghost_at(f);
            for k in 0..3 {
                let (other, q) = match ghosts.across(f, k) {
                    Ok(h) if h < f => continue,
                    Ok(h) => (slots + h, ghosts.faces[h]),
                    Err(d) => (d.index(), e.cell(d).v.map(|v| e.point_of(v))),
                };
                let edge = [ghosts.faces[f][(k + 1) % 3], ghosts.faces[f][(k + 2) % 3]];
                let opposite = q
                    .into_iter()
                    .find(|p| !edge.contains(p))
                    .expect("a triangle");
                if side_of_circle(&a, &b, &c, &at(opposite)) == Sign::Zero {
                    merges.push(((slots + f) as u32, other as u32));
                }
            }
        }
        for (a, b) in merges {
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            parent[ra.max(rb) as usize] = ra.min(rb);
        }
        for c in 0..parent.len() as u32 {
            root(&mut parent, c);
        }
        // each face's pole in its own frame; a class shares its root's, up to the antipode
        // between frames (the one of the two that the face's own pole is near)
        let own = |f: usize| {
            let [a, b, d] = if f < slots {
                e.lifted_cell(CellId::new(f))
                    .map(|(p, g)| S::position(p, g))
            } else {
                ghost_at(f - slots)
            };
            pole(&a, &b, &d)
        };
        let faces: Vec<usize> = ids
            .iter()
            .map(|c| c.index())
            .chain(slots..parent.len())
            .collect();
        let computed: Vec<(usize, [f64; 3])> = faces
            .par_iter()
            .map(|&f| {
                let mine = own(f);
                let r = parent[f] as usize;
                if r == f {
                    return (f, mine);
                }
                let theirs = own(r);
                let flip = dot(&mine, &theirs) < 0.0;
                (f, theirs.map(|x| if flip { -x } else { x }))
            })
            .collect();
        let mut poles = vec![[0.0; 3]; parent.len()];
        for (f, p) in computed {
            poles[f] = p;
        }
        let star = Star {
            tri: self,
            ghosts: &ghosts,
            class: &parent,
            poles: &poles,
        };
        let anchors = self.point_input.len() - self.number_of_vertices();
        Ok((anchors..self.point_input.len())
            .into_par_iter()
            .map(|p| star.cell_of(e.vertex_of_point(PointId::new(p))))
            .collect())
    }
}

/// The faces around the vertices: the engine's cells, and the ghost faces where the
/// engine has anchor cells; with each face's class and pole.
struct Star<'a, S: SphericalSpace> {
    tri: &'a SphericalTriangulation<S>,
    ghosts: &'a Ghosts,
    class: &'a [u32],
    poles: &'a [[f64; 3]],
}

impl<S: SphericalSpace> Star<'_, S> {
    /// Around vertex `v` from face `f` (an engine cell below the cell slots, a ghost face
    /// above): the site across the arc to the next face counter-clockwise seen from
    /// outside in `v`'s frame, the next face, and whether `f`'s frame is the antipode of
    /// `v`'s (there, its turn around `v` goes the other way).
    fn step(&self, v: VertexId, f: usize) -> (PointId, usize, bool) {
        let e = self.tri.engine();
        let slots = e.cell_slots();
        if f >= slots {
            let g = self.ghosts.faces[f - slots];
            let p = e.point_of(v);
            let j = g
                .iter()
                .position(|&x| x == p)
                .expect("the star holds its vertex");
            let x = g[(j + 2) % 3];
            let next = match self.ghosts.by_edge.get(&(p, x)) {
                Some(&h) => slots + h,
                None => self.ghosts.rim[&(p, x)].index(),
            };
            return (x, next, false);
        }
        let c = CellId::new(f);
        let cell = e.cell(c);
        let i = cell.index_of(v).expect("the star holds its vertex");
        let flip = S::is_antipode(cell.off[i]);
        let (a, b) = if flip {
            ((i + 2) % 3, (i + 1) % 3)
        } else {
            ((i + 1) % 3, (i + 2) % 3)
        };
        // the next face counter-clockwise shares the edge to `b`
        let x = e.point_of(cell.v[b]);
        let next = cell.n[a];
        let next = if self.tri.is_face(next) {
            next.index()
        } else {
            slots + self.ghosts.by_edge[&(e.point_of(v), x)]
        };
        (x, next, flip)
    }

    /// The cell of vertex `v`: the classes of the faces around it, counter-clockwise seen
    /// from outside in `v`'s frame. A face whose frame is the antipode of `v`'s is
    /// reflected there: its pole negated.
    fn cell_of(&self, v: VertexId) -> SphericalCell {
        let tri = self.tri;
        let e = tri.engine();
        // start at a face (a rim vertex's cell may hold an anchor)
        let mut c = e.vcell[v.index()];
        while !tri.is_face(c) {
            let cell = e.cell(c);
            c = cell.n[(cell.index_of(v).expect("the star holds its vertex") + 1) % 3];
        }
        let start = c.index();
        // (class, the site across the arc to the next, the pole in v's frame)
        let mut ring: Vec<(u32, InputId, [f64; 3])> = Vec::new();
        let mut f = start;
        loop {
            let (x, next, flip) = self.step(v, f);
            let x = tri.point_input[x.index()];
            let k = self.class[f];
            if ring.last().map(|r| r.0) == Some(k) {
                ring.last_mut().expect("non-empty").1 = x;
            } else {
                let p = self.poles[f];
                ring.push((k, x, if flip { p.map(|y| -y) } else { p }));
            }
            f = next;
            if f == start {
                break;
            }
        }
        // (the arc from the last class back to the first is degenerate when they are one)
        if ring.len() > 1 && ring[0].0 == ring[ring.len() - 1].0 {
            ring.pop();
        }
        let site = unit(e.points()[e.point_of(v).index()]);
        let vertices: Vec<[f64; 3]> = ring.iter().map(|r| r.2).collect();
        let m = vertices.len();
        let mut moment = [0.0; 3];
        let mut arc_lengths = Vec::with_capacity(m);
        for k in 0..m {
            let (a, b) = (&vertices[k], &vertices[(k + 1) % m]);
            let n = cross(a, b);
            let len = dot(&n, &n).sqrt();
            let theta = len.atan2(dot(a, b));
            arc_lengths.push(theta);
            if len > 0.0 {
                for (mk, nk) in moment.iter_mut().zip(n) {
                    *mk += theta * nk / len;
                }
            }
        }
        let centroid = unit(moment);
        // the area as a fan of triangles from the site, or from the centroid when a vertex
        // is more than a quarter turn from the site (a long cell of a hemisphere set: the
        // triangles' formula loses its accuracy near the antipode of their apex)
        let apex = if vertices.iter().any(|w| dot(w, &site) < 0.0) {
            &centroid
        } else {
            &site
        };
        let area = (0..m)
            .map(|k| triangle_area(apex, &vertices[k], &vertices[(k + 1) % m]))
            .sum();
        SphericalCell {
            site: tri.point_input[e.point_of(v).index()],
            neighbors: ring.iter().map(|r| r.1).collect(),
            vertices,
            arc_lengths,
            area,
            centroid,
        }
    }
}
