//! Vertex removal in the 1-sheeted triangulation: the star of the vertex is replaced by the
//! Delaunay triangulation of its link, found by gift wrapping over the star's vertices.

use super::wrap::{Owner, Wrapped};
use super::{Candidate, Engine, LiftedCell};
use crate::ids::{CellId, VertexId};
use crate::space::OrbitSpace;

/// Why a removal was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RemoveError {
    /// Without the vertex, the 1-sheeted quotient would not be a triangulation (a cycle of
    /// length ≤ 2 in its 1-skeleton): the covering space is needed.
    NotSimplicial,
}

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// Removes vertex `v` of a 1-sheeted triangulation. When the new cells break the switch
    /// criterion, or it already does not hold, the removal goes ahead only if the quotient
    /// stays a simplicial complex (Theorem 2.2.8); otherwise nothing changes.
    pub(crate) fn remove_vertex(&mut self, v: VertexId) -> Result<(), RemoveError> {
        debug_assert!(self.one_sheeted);
        let star = self.star(v);
        let shifted = |e: &Self, c: CellId, shift: S::Elem| -> LiftedCell<S, N> {
            e.lifted_cell(c)
                .map(|(p, o)| (p, e.space.compose(shift, o)))
        };
        let mut hole: Vec<Candidate<S, N>> = Vec::new();
        let mut seeds = Vec::with_capacity(star.len());
        for &(c, i, shift) in &star {
            let mut arr = shifted(self, c, shift);
            let cell = self.tds.cells[c.index()];
            for k in 0..N {
                if k != i && !hole.iter().any(|h| h.0 == cell.v[k]) {
                    hole.push((cell.v[k], arr[k]));
                }
            }
            let d = cell.n[i];
            let j = self.tds.cells[d.index()]
                .mirror(c)
                .expect("symmetric neighbours");
            // a star cell moved by an orientation-reversing element is negatively oriented:
            // two of its facet's vertices change places
            let mut v = cell.v;
            if self.space.reverses_orientation(shift) {
                let (a, b) = ((i + 1) % N, (i + 2) % N);
                arr.swap(a, b);
                v.swap(a, b);
            }
            seeds.push((v, arr, i, true, Owner::Old(d, j)));
        }
        let cells = self
            .wrap(seeds, |_, _, _| hole.clone(), Vec::new(), false)
            .ok_or(RemoveError::NotSimplicial)?;
        let limit = self.space.criterion_radius2(self.last_level());
        let breaks = cells
            .iter()
            .any(|w| self.space.circumradius2(&w.arr) >= limit);
        if breaks || !self.guaranteed {
            let star_ids: Vec<CellId> = star.iter().map(|s| s.0).collect();
            if !self.removal_keeps_simplicial(&star_ids, &cells) {
                return Err(RemoveError::NotSimplicial);
            }
            self.set_guaranteed(false);
        }
        for &(c, _, _) in &star {
            self.kill_cell(c);
        }
        self.commit(&cells);
        self.vcell[v.index()] = CellId::NONE;
        if !self.guaranteed && self.big_count == 0 {
            self.set_guaranteed(true);
        }
        Ok(())
    }

    /// True when replacing the cells `star` by `cells` leaves no cycle of length ≤ 2: at every
    /// vertex of the new cells, the edges (kept old ones and new ones) reach each neighbour
    /// with a single offset and never the vertex itself.
    fn removal_keeps_simplicial(
        &mut self,
        star: &[CellId],
        cells: &[Wrapped<S::Point, S::Elem, N>],
    ) -> bool {
        let mut hole: Vec<VertexId> = cells.iter().flat_map(|w| w.vids).collect();
        hole.sort_unstable();
        hole.dedup();
        let mut edges: Vec<(VertexId, S::Elem)> = Vec::new();
        let mut stack: Vec<CellId> = Vec::new();
        for &a in &hole {
            edges.clear();
            for w in cells {
                if let Some(i) = w.vids.iter().position(|&x| x == a) {
                    for j in (0..N).filter(|&j| j != i) {
                        edges.push((w.vids[j], self.space.relative(w.arr[j].1, w.arr[i].1)));
                    }
                }
            }
            // the old cells around `a` that stay
            let (mark, _) = self.tds.new_visit();
            stack.clear();
            stack.push(self.vcell[a.index()]);
            self.tds.set_stamp(stack[0], mark);
            while let Some(c) = stack.pop() {
                let cell = self.tds.cells[c.index()];
                let i = cell.index_of(a).expect("the star of a vertex holds it");
                for k in (0..N).filter(|&k| k != i) {
                    if !star.contains(&c) {
                        edges.push((cell.v[k], self.space.relative(cell.off[k], cell.off[i])));
                    }
                    let d = cell.n[k];
                    if self.tds.stamp(d) != mark {
                        self.tds.set_stamp(d, mark);
                        stack.push(d);
                    }
                }
            }
            edges.sort_unstable();
            if edges.iter().any(|e| e.0 == a)
                || edges
                    .windows(2)
                    .any(|w| w[0].0 == w[1].0 && w[0].1 != w[1].1)
            {
                return false;
            }
        }
        true
    }
}
