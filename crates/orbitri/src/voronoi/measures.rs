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

/// A cell of a point's star as its pieces see it: the point's lift in the cell, the cell's
/// vertices relative to the point (the point's own slot zero), the reciprocal lengths of
/// those edges (halved in 3D: a face's area is half its normal), its circumcenter relative
/// to the point, and its squared extent. (The square roots and divisions are taken here,
/// cell by cell, off the chain of each piece's products.)
struct Frame<const D: usize, const N: usize, E> {
    at: ([f64; D], E),
    rel: [[f64; D]; N],
    per_length: [f64; N],
    c: [f64; D],
    extent2: f64,
}

/// The buffers of the pieces' pass, reused from point to point by one worker: the star
/// (cells and the point's slot in each), each star cell's frame, the facets at the point
/// whose pieces it sums (star cell, slot), and the faces (with the neighbour pairs).
struct Scratch<const D: usize, const N: usize, E> {
    star: Vec<(CellId, u8)>,
    frames: Vec<Frame<D, N, E>>,
    facets: Vec<(u32, u8)>,
    faces: Faces<E, N>,
}

// (not derived: that would ask the group elements for a `Default`)
impl<const D: usize, const N: usize, E> Default for Scratch<D, N, E> {
    fn default() -> Self {
        Scratch {
            star: Vec::new(),
            frames: Vec::new(),
            facets: Vec::new(),
            faces: Faces::default(),
        }
    }
}

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

/// The sign of a piece: `SIGNS[N - 3][k][j][l]` is the parity (`+1.0` even, `-1.0` odd) of
/// the slots `(k, j, m, l)` in 3D (`m` the fourth), `(k, j, l)` in 2D. (Read from a table:
/// a sign computed in place is turned by the compiler into a branch on the parity, a coin
/// toss mispredicted at every other piece.)
static SIGNS: [[[[f64; 4]; 4]; 4]; 2] = signs();

const fn signs() -> [[[[f64; 4]; 4]; 4]; 2] {
    let mut out = [[[[0.0; 4]; 4]; 4]; 2];
    let mut x = 0;
    while x < 64 {
        let (k, j, l) = (x / 16, x / 4 % 4, x % 4);
        if k != j && j != l && k != l {
            out[1][k][j][l] = parity(&[k, j, 6 - k - j - l, l]);
            if k < 3 && j < 3 && l < 3 {
                out[0][k][j][l] = parity(&[k, j, l]);
            }
        }
        x += 1;
    }
    out
}

/// `+1.0` for an even permutation, `-1.0` for an odd one.
const fn parity(perm: &[usize]) -> f64 {
    let mut odd = false;
    let mut a = 0;
    while a < perm.len() {
        let mut b = a + 1;
        while b < perm.len() {
            odd ^= perm[a] > perm[b];
            b += 1;
        }
        a += 1;
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
            .map_init(Scratch::default, |scratch, b| {
                let ks = b * BLOCK..((b + 1) * BLOCK).min(order.len());
                let mut measured = Vec::with_capacity(ks.len());
                let mut found = Vec::new();
                for k in ks {
                    if k % POINTS_PER_POLL == 0 && interrupt() {
                        return Err(Error::Interrupted);
                    }
                    self.prefetch_stars(center, star_of, k);
                    let p = PointId(order[k].1);
                    self.slotted_star(stars, vertex_at(k), &mut scratch.star);
                    let m = self.pieces_of(center, scratch, p, pairs.then_some(&mut found));
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

    /// The measures of point `p`'s cell from its star (in `scratch`: cells and the point's
    /// slot in each); with a list of `pairs`, its neighbour pairs are pushed on it. `None`
    /// next to two cells of one circumsphere (nothing pushed).
    fn pieces_of(
        &self,
        center: &[[f64; D]],
        scratch: &mut Scratch<D, N, S::Elem>,
        p: PointId,
        pairs: Option<&mut Vec<Pair<S::Elem>>>,
    ) -> Option<CellMeasures<D>> {
        let e = self.engine();
        let space = self.space();
        let Scratch {
            star,
            frames,
            facets,
            faces,
        } = scratch;
        let star = &star[..];
        if pairs.is_some() {
            // the faces in the order the whole cell lists them: by first appearance in the star
            self.gather_edges(faces, star);
        }
        // each cell's frame, and the facets at the point taken from this side (each facet
        // from the smaller of its cells): listed first, without a branch on which (a coin
        // toss, mispredicted at every other facet)
        frames.clear();
        if facets.len() < star.len() * (N - 1) {
            facets.resize(star.len() * (N - 1), (0, 0));
        }
        let mut owned = 0;
        for (u, &(t, k)) in star.iter().enumerate() {
            let k = k as usize;
            let lifted = e.lifted_cell(t);
            let at = lifted[k];
            // the cell's vertices and circumcenter in its frame, relative to the point
            // (the point's own slot too, exactly zero: a branch on the slot is mispredicted
            // about once a cell)
            let rel: [[f64; D]; N] =
                std::array::from_fn(|a| space.lifted_difference(lifted[a], at));
            let c = sub(&center[t.index()], &space.lifted_difference(at, lifted[0]));
            let lengths2 = rel.map(|r| dot(&r, &r));
            let extent2 = lengths2.iter().fold(0.0, |a, &b| f64::max(a, b));
            // (the point's own slot gets 1/0 = ∞, never read)
            let half = if N == 4 { 0.5 } else { 1.0 };
            frames.push(Frame {
                at,
                rel,
                per_length: lengths2.map(|b| half / b.sqrt()),
                c,
                extent2,
            });
            let ns = e.adjacent(t);
            for l in slots_but::<N>(k) {
                facets[owned] = (u as u32, l as u8);
                owned += usize::from(ns[l] >= t);
            }
        }
        // sums of `D!` times the pieces' volumes, and of their moments times `D! (D + 1)`
        // (divided once, at the end)
        let mut volume = 0.0;
        let mut moment = [0.0; D];
        let mut surface = 0.0;
        for &(u, l) in &facets[..owned] {
            let (u, l) = (u as usize, l as usize);
            let (t, k) = star[u];
            let k = k as usize;
            let Frame {
                at,
                rel,
                per_length,
                c,
                extent2,
            } = &frames[u];
            let d = e.adjacent(t)[l];
            // the neighbour's circumcenter, carried into this cell's frame
            let g = e.translation(t, l, d);
            let (q, off) = e.lifted(d, 0);
            let d0 = (q, space.compose(g, off));
            let base = space.lifted_difference(d0, *at);
            let z = space.untwist(space.inverse(g), center[d.index()]);
            let c2: [f64; D] = std::array::from_fn(|x| base[x] + z[x]);
            if may_share_sphere(c, &c2, *extent2) && self.one_sphere(t, l, d) {
                return None;
            }
            let mut piece_moment = [0.0; D];
            for j in slots_but_two::<N>(k, l) {
                let s = SIGNS[N - 3][k][j][l];
                let b = &rel[j];
                let area;
                if N == 4 {
                    // the foot of the bisector (power bisector) on the edge
                    let lambda = if e.is_weighted() {
                        let vs = e.vertices(t);
                        let w = |a: usize| e.vertex_weight(vs[a]);
                        0.5 + (w(k) - w(j)) / (2.0 * dot(b, b))
                    } else {
                        0.5
                    };
                    let m = b.map(|x| lambda * x);
                    let x = cross(&sub(&c2, &m), &sub(c, &m)).map(|x| s * x);
                    let v6 = dot(&m, &x);
                    volume += v6;
                    area = dot(b, &x) * per_length[j];
                    for a in 0..D {
                        piece_moment[a] += v6 * (m[a] + c[a] + c2[a]);
                    }
                } else {
                    let v2 = s * (c2[0] * c[1] - c2[1] * c[0]);
                    volume += v2;
                    area = s * (b[0] * (c[1] - c2[1]) - b[1] * (c[0] - c2[0])) * per_length[j];
                    for a in 0..D {
                        piece_moment[a] += v2 * (c[a] + c2[a]);
                    }
                }
                surface += area;
                if pairs.is_some() {
                    faces.edges[faces.index[u][j] as usize].2 += area;
                }
            }
            let back = space.untwist(at.1, piece_moment);
            for a in 0..D {
                moment[a] += back[a];
            }
        }
        let factorial = if N == 4 { 6.0 } else { 2.0 };
        let volume = volume / factorial;
        let moment = moment.map(|x| x / (factorial * N as f64));
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
        if let Some(list) = pairs {
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

#[cfg(test)]
mod tests {
    use super::SIGNS;

    /// The parity of a permutation of `0..len` by its cycles (independent of the inversion
    /// count the table is built from): even when `len − cycles` is even.
    fn by_cycles(perm: &[usize]) -> f64 {
        let mut seen = vec![false; perm.len()];
        let mut cycles = 0;
        for start in 0..perm.len() {
            if !seen[start] {
                cycles += 1;
                let mut x = start;
                while !seen[x] {
                    seen[x] = true;
                    x = perm[x];
                }
            }
        }
        if (perm.len() - cycles).is_multiple_of(2) {
            1.0
        } else {
            -1.0
        }
    }

    #[test]
    fn the_piece_signs_are_the_parities_of_the_slots() {
        let mut checked = 0;
        for k in 0..4 {
            for j in (0..4).filter(|&j| j != k) {
                for l in (0..4).filter(|&l| l != k && l != j) {
                    let m = 6 - k - j - l;
                    assert_eq!(SIGNS[1][k][j][l], by_cycles(&[k, j, m, l]));
                    if k < 3 && j < 3 && l < 3 {
                        assert_eq!(SIGNS[0][k][j][l], by_cycles(&[k, j, l]));
                    }
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 24);
        // a swap of two slots flips the sign
        assert_eq!(SIGNS[1][0][1][2], -SIGNS[1][1][0][2]);
        assert_eq!(SIGNS[0][0][1][2], 1.0);
    }
}
