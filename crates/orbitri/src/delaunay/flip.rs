//! 2D insertion by flips (Lawson): the triangle that holds the new point strictly inside
//! is split in three, then each edge opposite the new vertex is flipped while the triangle
//! across it is in conflict with the point.
//!
//! In a 1-sheeted triangulation of an orientable space whose criterion holds, every
//! triangle tested is one of the triangulation before the insertion, tested exactly as
//! the conflict search tests it, and the triangles flipped are its conflict region: the
//! result is the star of that region, the same triangulation. It needs no visit stamps
//! and no lists, and makes two new cells a point where starring makes six (and frees
//! four).

use super::{Engine, LiftedOf};
use crate::ids::{CellId, VertexId};
use crate::space::OrbitSpace;
use crate::tds::Cell;

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// True when an insertion strictly inside a triangle may split it and flip: 2D,
    /// orientable (a neighbour never lists its vertices the other way round), unweighted
    /// and without hiding, 1-sheeted with the criterion holding (every intermediate
    /// triangulation is then a simplicial complex: its edges are old edges or the new
    /// vertex's final ones).
    #[inline(always)]
    pub(super) fn flips(&self) -> bool {
        N == 3 && !S::MAY_REVERSE && !self.hides() && self.one_sheeted && self.guaranteed
    }

    /// Inserts vertex `x` at the point `q`, which lies strictly inside cell `c` lifted by
    /// `q.1` in `c`'s frame (`qoff`: its element as inserted), by splitting `c` and
    /// flipping (see the module). `x` is at slot 0 of `c` afterwards, which is the next
    /// walk's start.
    pub(super) fn insert_by_flips(
        &mut self,
        c: CellId,
        (p, qo): LiftedOf<S, N>,
        x: VertexId,
        qoff: S::Elem,
    ) {
        let old = self.tds.cell(c);
        // (two more slots; guaranteed, so no criterion bookkeeping)
        let (b, d) = (self.tds.create(old), self.tds.create(old));
        let mut edges = std::mem::take(&mut self.scratch.created);
        let Ok(()) = split_and_flip(self, &old, [c, b, d], (p, qo), x, &mut edges);
        self.scratch.created = edges;
        self.vcell[x.index()] = c;
        self.hint = c;
        self.hint_shift = self.space.carry(qoff, self.tds.off_at(c, 0));
    }

    /// The element, in the frame of cell `t` (contents `tc`, the new vertex at slot 0), of
    /// the vertex of its neighbour `e` across from the new vertex, and that vertex's slot,
    /// when `e` is in conflict with the new point `p`: the edge between them is to flip.
    #[inline(always)]
    fn far_in_conflict(
        &self,
        t: CellId,
        tc: &Cell<S::Elem, N>,
        e: CellId,
        p: S::Point,
    ) -> Option<(S::Elem, usize)> {
        // the new vertex's element in `e`'s frame, and back
        let to_e = self.translation(t, 0, e);
        if !self.cell_conflicts(e, (p, self.space.relative(tc.off[0], to_e)), 0.0) {
            return None;
        }
        let ec = &self.tds.cells[e.index()];
        let j = ec.mirror(t).expect("symmetric neighbours");
        Some((self.space.compose(to_e, self.tds.off_at(e, j)), j))
    }

    /// A triangle in canonical form (see [`Self::canonicalize`]: in an orientable space, no
    /// slot moves), as a cell.
    #[inline(always)]
    pub(super) fn canonical_triangle(&self, (v, off, n): Triangle<S::Elem>) -> Cell<S::Elem, N> {
        let mut cell = Cell::new(tri(v), tri(off));
        self.canonicalize(&mut cell);
        cell.n = tri(n);
        cell
    }
}

/// Where the flips of one insertion read and write: the engine's own store (one at a time),
/// or a parallel chunk's share of it, which checks that it owns each cell it changes and
/// journals each write. A chunk's soundness rests on [`split_and_flip`]'s contract.
pub(super) trait Flipper<S: OrbitSpace<N>, const N: usize> {
    /// Why the flips stopped halfway (never, one at a time).
    type Stop;
    /// The triangulation read.
    fn engine(&self) -> &Engine<S, N>;
    /// Ok when the flips may change cells next to `c`, and `c` itself (a chunk: it owns
    /// `c`).
    fn may_change(&self, c: CellId) -> Result<(), Self::Stop>;
    /// Overwrites cell `c` with triangle `t` in canonical form: a new slot when `new` (a
    /// chunk stamps it), else its stamp kept.
    fn rewrite(&mut self, c: CellId, t: Triangle<S::Elem>, new: bool) -> Result<(), Self::Stop>;
    /// Links facet `i` of `a` (written already) with the facet of `d` that was linked to
    /// `old`.
    fn relink(&mut self, a: (CellId, usize), d: CellId, old: CellId);
    /// Vertex `v` left cell `from` for cell `to`.
    fn move_vertex(&mut self, v: VertexId, from: CellId, to: CellId);
}

impl<S: OrbitSpace<N>, const N: usize> Flipper<S, N> for Engine<S, N> {
    type Stop = std::convert::Infallible;

    #[inline(always)]
    fn engine(&self) -> &Engine<S, N> {
        self
    }

    #[inline(always)]
    fn may_change(&self, _: CellId) -> Result<(), Self::Stop> {
        Ok(())
    }

    #[inline(always)]
    fn rewrite(&mut self, c: CellId, t: Triangle<S::Elem>, _: bool) -> Result<(), Self::Stop> {
        let cell = self.canonical_triangle(t);
        self.tds.put(c, cell);
        Ok(())
    }

    #[inline(always)]
    fn relink(&mut self, (a, i): (CellId, usize), d: CellId, old: CellId) {
        let j = self.mirror_of(d, old);
        self.link(a, i, d, j);
    }

    #[inline(always)]
    fn move_vertex(&mut self, v: VertexId, _: CellId, to: CellId) {
        self.vcell[v.index()] = to;
    }
}

/// Splits cell `c` (contents `old`) into the slots `[c, b, d]` at vertex `x`, the point
/// `p` lifted by `qo` in `c`'s frame strictly inside it, then flips each edge opposite `x`
/// while the triangle across is in conflict with `p` (see the module); `x` is at slot 0 of
/// `c`, `b` and `d`, and of every cell flipped. `edges` holds the cells whose edge opposite
/// `x` is still to test (kept apart from `f`, so that its length stays in a register).
///
/// Its contract, on which a chunk's unsafe writes rely ([`Flipper`]): it reads and writes
/// only `c`, `b`, `d`, cells it wrote already and cells that [`Flipper::may_change`]
/// accepted first (the caller checks `c`'s neighbours), and reads other cells' stamps only
/// through `may_change`.
#[inline(always)]
pub(super) fn split_and_flip<S: OrbitSpace<N>, const N: usize, F: Flipper<S, N>>(
    f: &mut F,
    old: &Cell<S::Elem, N>,
    [c, b, d]: [CellId; 3],
    (p, qo): LiftedOf<S, N>,
    x: VertexId,
    edges: &mut Vec<CellId>,
) -> Result<(), F::Stop> {
    let [tc, tb, td] = split(old, x, qo, [c, b, d]);
    f.rewrite(c, tc, false)?;
    f.rewrite(b, tb, true)?;
    f.rewrite(d, td, true)?;
    f.relink((b, 0), old.n[1], c);
    f.relink((d, 0), old.n[2], c);
    f.move_vertex(old.v[0], c, b);
    edges.clear();
    edges.extend([c, b, d]);
    while let Some(t) = edges.pop() {
        let tc = f.engine().tds.cell(t);
        let e = tc.n[0];
        f.may_change(e)?;
        let Some((far, j)) = f.engine().far_in_conflict(t, &tc, e, p) else {
            continue;
        };
        let ec = f.engine().tds.cell(e);
        let ([nt, ne], [(first, o1), (second, o2)]) = flipped(&tc, (e, &ec, j), far, t);
        // (`e`'s other neighbours, `o1` and the one below; `t`'s other neighbours hold `x`, so
        // this insertion made them and, in a chunk, they are its own)
        f.may_change(o1)?;
        f.may_change(ec.n[(j + 2) % 3])?;
        f.rewrite(t, nt, false)?;
        f.rewrite(e, ne, false)?;
        f.relink((t, 0), o1, e);
        f.relink((e, 1), o2, t);
        f.move_vertex(first, e, t);
        f.move_vertex(second, t, e);
        edges.extend([t, e]);
    }
    Ok(())
}

/// A triangle as the flips build it: vertices, elements, neighbours.
pub(super) type Triangle<O> = ([VertexId; 3], [O; 3], [CellId; 3]);

/// The triangles that splitting cell `old` at vertex `x` (element `qo`) makes, for the
/// slots `[c, b, d]` (`c` is `old`'s): `x` in place of each vertex in turn, rotated to
/// slot 0, each linked to the neighbour across its edge and to the other two.
fn split<O: Copy, const N: usize>(
    old: &Cell<O, N>,
    x: VertexId,
    qo: O,
    [c, b, d]: [CellId; 3],
) -> [Triangle<O>; 3] {
    let ([v0, v1, v2], [o0, o1, o2], [n0, n1, n2]) = (
        [0, 1, 2].map(|k| old.v[k]),
        [0, 1, 2].map(|k| old.off[k]),
        [0, 1, 2].map(|k| old.n[k]),
    );
    [
        ([x, v1, v2], [qo, o1, o2], [n0, b, d]),
        ([x, v2, v0], [qo, o2, o0], [n1, d, c]),
        ([x, v0, v1], [qo, o0, o1], [n2, c, b]),
    ]
}

/// Flips the edge opposite the new vertex (slot 0 of cell `t`, contents `tc`) with the
/// neighbour `e` across it (contents `ec`, `t` at its slot `j`; its far vertex at element
/// `far` in `t`'s frame): `t` becomes the triangle of the new vertex, the edge's first end
/// and the far vertex, `e` the one of the new vertex, the far vertex and the edge's second
/// end (the new vertex at slot 0 of both). Also returns the edge's first end, which
/// left `e`, with the outside cell now across from the new vertex in `t` (it was linked to
/// `e`), and the second end, which left `t`, with the outside cell now at slot 1 of `e`
/// (it was linked to `t`).
fn flipped<O: Copy, const N: usize>(
    tc: &Cell<O, N>,
    (e, ec, j): (CellId, &Cell<O, N>, usize),
    far: O,
    t: CellId,
) -> ([Triangle<O>; 2], [(VertexId, CellId); 2]) {
    // `e` is (far, second end, first end) from slot `j`, as `t` is oriented alike
    let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
    let (x, first, second, fv) = (tc.v[0], tc.v[1], tc.v[2], ec.v[j]);
    let (ox, o1, o2) = (tc.off[0], tc.off[1], tc.off[2]);
    (
        [
            ([x, first, fv], [ox, o1, far], [ec.n[j1], e, tc.n[2]]),
            ([x, fv, second], [ox, far, o2], [ec.n[j2], tc.n[1], t]),
        ],
        [(first, ec.n[j1]), (second, tc.n[1])],
    )
}

/// A triangle's three entries as the engine's `N` slots (`N` is 3 wherever it flips).
#[inline(always)]
fn tri<T: Copy, const N: usize>(t: [T; 3]) -> [T; N] {
    std::array::from_fn(|k| t[k])
}

#[cfg(test)]
mod tests {
    use crate::ids::VertexId;
    use crate::sort::SplitMix;
    use crate::space::FlatTorus2;
    use crate::Engine;
    use std::collections::BTreeSet;

    type Triangle = ([VertexId; 3], [[i8; 2]; 3]);

    /// Every cell, rotated to start at its least vertex id.
    fn triangles(e: &Engine<FlatTorus2, 3>) -> BTreeSet<Triangle> {
        e.tds
            .ids()
            .map(|c| {
                let cell = e.tds.cell(c);
                let k = (0..3).min_by_key(|&k| cell.v[k]).unwrap();
                let r = |i: usize| (k + i) % 3;
                (
                    [0, 1, 2].map(|i| cell.v[r(i)]),
                    [0, 1, 2].map(|i| cell.off[r(i)]),
                )
            })
            .collect()
    }

    /// The same points one at a time by flips and, in a weighted triangulation of zero
    /// weights (which always stars the conflict region), by the other path.
    fn both(torus: &FlatTorus2, points: &[[f64; 2]]) -> [Engine<FlatTorus2, 3>; 2] {
        let mut flipped = Engine::new(torus.clone());
        let mut starred = Engine::new_weighted(torus.clone());
        for &p in points {
            flipped.insert(p);
            starred.insert_weighted(p, 0.0);
        }
        assert!(flipped.flips() && !starred.flips());
        [flipped, starred]
    }

    #[test]
    fn flips_make_the_triangulation_that_starring_makes() {
        let torus = FlatTorus2::cuboid([1.0, 0.7]).unwrap();
        let mut r = SplitMix::new(5);
        let points: Vec<[f64; 2]> = (0..3000).map(|_| [r.unit(), 0.7 * r.unit()]).collect();
        let [flipped, starred] = both(&torus, &points);
        flipped.is_valid().unwrap();
        starred.is_valid().unwrap();
        assert_eq!(flipped.tds.len(), 2 * 3000);
        assert_eq!(triangles(&flipped), triangles(&starred));
    }

    #[test]
    fn points_on_edges_and_cocircular_points_agree_with_starring() {
        // a grid: four points on every empty circle, new points on old edges, in a
        // shuffled order
        let torus = FlatTorus2::cuboid([1.0, 1.0]).unwrap();
        let mut points: Vec<[f64; 2]> = (0..24 * 24)
            .map(|k| [(k % 24) as f64 / 24.0, (k / 24) as f64 / 24.0])
            .collect();
        let mut r = SplitMix::new(9);
        for k in (1..points.len()).rev() {
            points.swap(k, r.below(k + 1));
        }
        let [flipped, starred] = both(&torus, &points);
        flipped.is_valid().unwrap();
        assert_eq!(triangles(&flipped), triangles(&starred));
    }
}
