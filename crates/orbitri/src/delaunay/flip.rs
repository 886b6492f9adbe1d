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
    pub(super) fn split_and_flip(
        &mut self,
        c: CellId,
        (p, qo): LiftedOf<S, N>,
        x: VertexId,
        qoff: S::Elem,
    ) {
        let old = self.tds.cells[c.index()];
        let [v0, v1, v2] = [0, 1, 2].map(|k| old.v[k]);
        let [o0, o1, o2] = [0, 1, 2].map(|k| old.off[k]);
        // `x` in place of each vertex in turn, rotated to slot 0 (the first in `c`'s slot),
        // each linked to the neighbour across its edge and to the other two
        let b = self.make_cell(tri([x, v2, v0]), tri([qo, o2, o0]));
        let d = self.make_cell(tri([x, v0, v1]), tri([qo, o0, o1]));
        self.rewrite(c, [x, v1, v2], [qo, o1, o2], [old.n[0], b, d]);
        self.tds.cells[b.index()].n = tri([old.n[1], d, c]);
        self.tds.cells[d.index()].n = tri([old.n[2], c, b]);
        self.relink(b, 0, old.n[1], c);
        self.relink(d, 0, old.n[2], c);
        self.vcell[v0.index()] = b;
        // (the cells whose edge opposite `x` is still to test)
        let mut edges = std::mem::take(&mut self.scratch.created);
        edges.clear();
        edges.extend([c, b, d]);
        while let Some(t) = edges.pop() {
            if let Some(across) = self.flip(t, p) {
                edges.extend([t, across]);
            }
        }
        self.scratch.created = edges;
        self.vcell[x.index()] = c;
        self.hint = c;
        self.hint_shift = self.space.carry(qoff, self.tds.cells[c.index()].off[0]);
    }

    /// Flips the edge opposite the new vertex (point `p`, slot 0 of cell `t`) when the
    /// triangle across it is in conflict with the point: `t` becomes the triangle of the
    /// new vertex, the edge's first end and the far vertex, the cell across the one of the
    /// new vertex, the far vertex and the edge's second end (the new vertex at slot 0 of
    /// both). Returns the cell across, or `None` when nothing was flipped.
    #[inline(always)]
    fn flip(&mut self, t: CellId, p: S::Point) -> Option<CellId> {
        let s = 0;
        let tc = self.tds.cells[t.index()];
        let e = tc.n[s];
        // the new vertex's element in `e`'s frame, and back
        let to_e = self.translation(t, s, e);
        if !self.cell_conflicts(e, (p, self.space.relative(tc.off[s], to_e)), 0.0) {
            return None;
        }
        let ec = self.tds.cells[e.index()];
        let j = self.mirror_of(e, t);
        // `e` is (far, second end, first end) from slot `j`, as `t` is oriented alike
        let (s1, s2, j1, j2) = ((s + 1) % 3, (s + 2) % 3, (j + 1) % 3, (j + 2) % 3);
        let (first, second, far) = (tc.v[s1], tc.v[s2], ec.v[j]);
        let far_off = self.space.compose(to_e, ec.off[j]);
        self.rewrite(
            t,
            [tc.v[s], first, far],
            [tc.off[s], tc.off[s1], far_off],
            [ec.n[j1], e, tc.n[s2]],
        );
        self.rewrite(
            e,
            [tc.v[s], far, second],
            [tc.off[s], far_off, tc.off[s2]],
            [ec.n[j2], tc.n[s1], t],
        );
        self.relink(t, 0, ec.n[j1], e);
        self.relink(e, 1, tc.n[s1], t);
        self.vcell[first.index()] = t;
        self.vcell[second.index()] = e;
        Some(e)
    }

    /// Overwrites live cell `c` (keeping its stamp) with vertices `v`, elements `off`
    /// (canonicalized: in an orientable space, no slot moves) and neighbours `n` (2D).
    #[inline(always)]
    fn rewrite(&mut self, c: CellId, v: [VertexId; 3], off: [S::Elem; 3], n: [CellId; 3]) {
        let mut cell = Cell::new(tri(v), tri(off));
        self.canonicalize(&mut cell);
        let slot = &mut self.tds.cells[c.index()];
        (slot.v, slot.off, slot.n) = (cell.v, cell.off, tri(n));
    }

    /// Links facet `i` of `a` with the facet of `d` that was linked to `old`.
    #[inline(always)]
    fn relink(&mut self, a: CellId, i: usize, d: CellId, old: CellId) {
        let j = self.mirror_of(d, old);
        self.link(a, i, d, j);
    }
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
                let cell = &e.tds.cells[c.index()];
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
