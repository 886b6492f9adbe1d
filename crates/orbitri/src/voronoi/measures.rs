//! The measures of every Voronoi cell (volume, faces, surface area, centroid) without
//! building the cells. Around a point, each Delaunay facet at the point, shared by cells `t`
//! and `t'`, and each Delaunay edge `pq` of that facet give one piece of the point's cell:
//! in 3D the tetrahedron from `p` to the foot `m` of the edge's bisector and the two
//! circumcenters `c`, `c'` (two consecutive vertices of the edge's dual face), in 2D the
//! triangle `p c c'`. Signed by the orientation of `t`, the pieces sum to the cell even
//! when circumcenters lie outside their Delaunay cells, or the point outside its power
//! cell; the face of edge `pq` is the signed sum of the triangles `m c c'`. Each facet is
//! taken from the smaller of its two cells, so every point sums its own pieces in a fixed
//! order: the same numbers whatever the number of threads.

use rayon::prelude::*;

use super::{
    cross, dot, listed_once, slots_but, slots_but_two, sub, CellMeasures, Faces, Stars,
    POINTS_PER_POLL,
};
use crate::error::{Error, Result};
use crate::ids::{CellId, InputId, PointId};
use crate::space::FlatSpace;
use crate::tds::prefetch;
use crate::triangulation::Triangulation;

/// A neighbour pair as its block keeps it: `j`, the shift and the area (`i` is the point
/// whose pairs these are; a third less memory to fill and to read back than a
/// [`Neighbor`](super::Neighbor)).
pub(super) type Pair<E> = (InputId, E, f64);

/// Where a point's neighbour pairs go: the buffers of its faces, and its block's list.
type PairsOut<'a, const N: usize, E> = (&'a mut Faces<E, N>, &'a mut Vec<Pair<E>>);

/// Points of the curve per block of the pieces' pass: each block lists its points' pairs in
/// one buffer (no allocation per point).
const BLOCK: usize = 2048;

/// A block's points (their measures and the end of their pairs), and its pairs.
type Block<const D: usize, E> = (Vec<(Option<CellMeasures<D>>, u32)>, Vec<Pair<E>>);

/// The measures by pieces of every point (indexed by point; `None` for a point measured on
/// its whole cell) and, when asked for, each point's neighbour pairs (those where it is
/// `i`), kept by blocks of the curve.
pub(super) struct Pieces<const D: usize, E> {
    pub(super) measures: Vec<Option<CellMeasures<D>>>,
    /// Per point: its block, and the range of its pairs there.
    at: Vec<(u32, u32, u32)>,
    blocks: Vec<Vec<Pair<E>>>,
}

impl<const D: usize, E> Pieces<D, E> {
    /// The neighbour pairs of point `p` (empty unless asked for), where it is `i`.
    pub(super) fn pairs_of(&self, p: PointId) -> &[Pair<E>] {
        match self.at.get(p.index()) {
            Some(&(b, from, to)) => &self.blocks[b as usize][from as usize..to as usize],
            None => &[],
        }
    }

    /// Starts loading where the pairs of point `far` are listed, and the first of the
    /// pairs of point `near` (whose place was asked for some points before).
    pub(super) fn prefetch(&self, far: Option<PointId>, near: Option<PointId>) {
        if let Some(at) = far.and_then(|p| self.at.get(p.index())) {
            prefetch(at);
        }
        if let Some(first) = near.and_then(|p| self.pairs_of(p).first()) {
            prefetch(first);
        }
    }

    /// The number of pairs.
    pub(super) fn number_of_pairs(&self) -> usize {
        self.blocks.iter().map(Vec::len).sum()
    }
}

/// `+1.0` for an even permutation of `0..len`, `-1.0` for an odd one.
fn parity(perm: &[usize]) -> f64 {
    let mut odd = false;
    for a in 0..perm.len() {
        for b in a + 1..perm.len() {
            odd ^= perm[a] > perm[b];
        }
    }
    if odd {
        -1.0
    } else {
        1.0
    }
}

impl<const D: usize, const N: usize, S: FlatSpace<D, N>> Triangulation<D, N, S> {
    /// The measures of every point's cell by pieces (see the module) from the cells'
    /// circumcenters and the vertices' stars, indexed by point; `None` for a point with a
    /// facet between two cells of one circumsphere (one Voronoi vertex: which of its edges
    /// keep a face is counted on the whole cell). 1-sheeted only. Polls `interrupt` every
    /// `POINTS_PER_POLL` points.
    pub(super) fn measures_by_pieces(
        &self,
        center: &[[f64; D]],
        stars: &Stars,
        interrupt: &(dyn Fn() -> bool + Sync),
        pairs: bool,
    ) -> Result<Pieces<D, S::Elem>> {
        debug_assert_eq!(self.engine().sheets(), 1);
        // the points along the curve, not in insertion order: the next point's cells are
        // mostly the last one's, still in cache (a sixth of the time)
        let e = self.engine();
        let mut order: Vec<(u64, u32)> = e
            .points()
            .par_iter()
            .enumerate()
            .map(|(p, x)| (self.space().spatial_key(x), p as u32))
            .collect();
        order.par_sort_unstable();
        let vertex_at = |k: usize| e.vertex_of_point(PointId(order[k].1));
        let star_of = |k: usize| stars.of(vertex_at(k));
        // per block: each point's measures and the end of its pairs, and the pairs
        let found: Vec<Block<D, S::Elem>> = (0..order.len().div_ceil(BLOCK))
            .into_par_iter()
            .map_init(<(Faces<_, N>, Vec<_>)>::default, |(faces, star), b| {
                let ks = b * BLOCK..((b + 1) * BLOCK).min(order.len());
                let mut measured = Vec::with_capacity(ks.len());
                let mut found = Vec::new();
                for k in ks {
                    if k % POINTS_PER_POLL == 0 && interrupt() {
                        return Err(Error::Interrupted);
                    }
                    self.prefetch_stars(center, star_of, k);
                    let p = PointId(order[k].1);
                    let out = pairs.then_some((&mut *faces, &mut found));
                    self.slotted_star(stars, vertex_at(k), star);
                    let m = self.pieces_of(center, star, p, out);
                    measured.push((m, found.len() as u32));
                }
                Ok((measured, found))
            })
            .collect::<Result<_>>()?;
        let n = order.len();
        let mut measures = vec![None; n];
        let mut at = vec![(0, 0, 0); if pairs { n } else { 0 }];
        let mut blocks = Vec::with_capacity(found.len());
        for (b, (measured, list)) in found.into_iter().enumerate() {
            let mut from = 0;
            for (k, (m, to)) in measured.into_iter().enumerate() {
                let p = order[b * BLOCK + k].1 as usize;
                measures[p] = m;
                if pairs {
                    at[p] = (b as u32, from, to);
                }
                from = to;
            }
            blocks.push(list);
        }
        Ok(Pieces {
            measures,
            at,
            blocks,
        })
    }

    /// Starts loading the cells of the star `star_of(k + 2)`, and the centers and vertices
    /// of `star_of(k + 1)` (whose cells were asked for one point ago): the cells are far
    /// apart in memory, and these loads overlap the work on point `k` (a fifth of the time).
    fn prefetch_stars<'a>(
        &self,
        center: &[[f64; D]],
        star_of: impl Fn(usize) -> &'a [CellId],
        k: usize,
    ) {
        let e = self.engine();
        let n = self.number_of_vertices();
        if k + 2 < n {
            for &t in star_of(k + 2) {
                e.prefetch_cell(t);
            }
        }
        if k + 1 < n {
            for &t in star_of(k + 1) {
                prefetch(&center[t.index()]);
                e.prefetch_points(t);
            }
        }
    }

    /// The measures of point `p`'s cell from its `star` (cells and the point's slot in
    /// each); with `pairs` (buffers, and the list), its neighbour pairs are pushed on the
    /// list. `None` next to two cells of one circumsphere (nothing pushed).
    fn pieces_of(
        &self,
        center: &[[f64; D]],
        star: &[(CellId, u8)],
        p: PointId,
        pairs: Option<PairsOut<'_, N, S::Elem>>,
    ) -> Option<CellMeasures<D>> {
        let e = self.engine();
        let space = self.space();
        let (mut faces, list) = pairs.unzip();
        if let Some(faces) = faces.as_deref_mut() {
            // the faces in the order the whole cell lists them: by first appearance in the star
            self.gather_edges(faces, star);
        }
        let mut volume = 0.0;
        let mut surface = 0.0;
        let mut moment = [0.0; D];
        for (u, &(t, k)) in star.iter().enumerate() {
            let k = k as usize;
            let (vs, ns) = (e.vertices(t), e.adjacent(t));
            let at = e.lifted(t, k);
            // the cell's vertices and circumcenter in its frame, relative to the point
            let rel: [[f64; D]; N] = std::array::from_fn(|a| {
                if a == k {
                    [0.0; D]
                } else {
                    space.lifted_difference(e.lifted(t, a), at)
                }
            });
            let c = sub(
                &center[t.index()],
                &space.lifted_difference(at, e.lifted(t, 0)),
            );
            let extent2 = rel.iter().map(|r| dot(r, r)).fold(0.0, f64::max);
            let mut piece_moment = [0.0; D];
            for l in slots_but::<N>(k) {
                let d = ns[l];
                if d < t {
                    continue; // taken from `d`
                }
                // the neighbour's circumcenter, carried into this cell's frame
                let g = e.translation(t, l, d);
                let (q, off) = e.lifted(d, 0);
                let d0 = (q, space.compose(g, off));
                let base = space.lifted_difference(d0, at);
                let z = space.untwist(space.inverse(g), center[d.index()]);
                let c2: [f64; D] = std::array::from_fn(|x| base[x] + z[x]);
                if may_share_sphere(&c, &c2, extent2) && self.one_sphere(t, l, d) {
                    return None;
                }
                for j in slots_but_two::<N>(k, l) {
                    let s = if N == 4 {
                        parity(&[k, j, 6 - k - j - l, l])
                    } else {
                        parity(&[k, j, l])
                    };
                    let b = &rel[j];
                    let bb = dot(b, b);
                    let area;
                    if N == 4 {
                        // the foot of the bisector (power bisector) on the edge
                        let lambda = if e.is_weighted() {
                            let w = |a: usize| e.vertex_weight(vs[a]);
                            0.5 + (w(k) - w(j)) / (2.0 * bb)
                        } else {
                            0.5
                        };
                        let m = b.map(|x| lambda * x);
                        let x = cross(&sub(&c2, &m), &sub(&c, &m)).map(|x| s * x);
                        let v = dot(&m, &x) / 6.0;
                        volume += v;
                        area = 0.5 * dot(b, &x) / bb.sqrt();
                        for a in 0..D {
                            piece_moment[a] += v * (m[a] + c[a] + c2[a]) / 4.0;
                        }
                    } else {
                        let v = 0.5 * s * (c2[0] * c[1] - c2[1] * c[0]);
                        volume += v;
                        area = s * (b[0] * (c[1] - c2[1]) - b[1] * (c[0] - c2[0])) / bb.sqrt();
                        for a in 0..D {
                            piece_moment[a] += v * (c[a] + c2[a]) / 3.0;
                        }
                    }
                    surface += area;
                    if let Some(f) = faces.as_deref_mut() {
                        f.edges[f.index[u][j] as usize].2 += area;
                    }
                }
            }
            let back = space.untwist(at.1, piece_moment);
            for a in 0..D {
                moment[a] += back[a];
            }
        }
        // the link of a vertex is a triangulated sphere (a circle in 2D): 3D, `T` triangles
        // have `T/2 + 2` vertices, one per Delaunay edge at the point
        let count = if N == 4 {
            star.len() / 2 + 2
        } else {
            star.len()
        };
        let position = e.points()[p.index()];
        let here = space.lifted_position((position, space.identity()));
        let i = self.input_of_vertex(p);
        // each unordered pair of images once, as `neighbor_pairs_by` lists them: every
        // edge written, then dropped unless listed here (`i < j` is a coin toss, a branch
        // mispredicted every other edge)
        if let (Some(faces), Some(list)) = (faces, list) {
            for &(w, g, area) in &faces.edges {
                let j = self.input_of_vertex(e.point_of(w));
                list.push((j, g, space.measure_to_user(area, D as i32 - 1)));
                let listed = listed_once(i, j, g, |g| space.inverse(g));
                list.truncate(list.len() - usize::from(!listed));
            }
        }
        Some(CellMeasures {
            point: i,
            volume: space.measure_to_user(volume, D as i32),
            faces: count as u32,
            surface_area: space.measure_to_user(surface, D as i32 - 1),
            centroid: space.to_user(std::array::from_fn(|a| here[a] + moment[a] / volume)),
        })
    }
}

/// False when the circumcenters `c` and `c2` of two cells of squared extent at least
/// `extent2` are too far apart for one sphere: each is certified to `2⁻³⁶` of its magnitude
/// and its cell's extent, and this allows `2⁻³⁰` of them.
fn may_share_sphere<const D: usize>(c: &[f64; D], c2: &[f64; D], extent2: f64) -> bool {
    let d = sub(c, c2);
    dot(&d, &d) <= (dot(c, c) + dot(c2, c2) + extent2) * 2f64.powi(-60)
}
