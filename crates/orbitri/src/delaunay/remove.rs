//! Vertex removal in the 1-sheeted triangulation: the star of the vertex is replaced by the
//! Delaunay triangulation of its link, found by gift wrapping over the star's vertices.

use super::wrap::Owner;
use super::{Candidate, Engine, LiftedCell};
use crate::space::OrbitSpace;
use crate::tds::NONE;

/// Why a removal was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RemoveError {
    /// Without the vertex, the switch criterion would fail: the 1-sheeted quotient is no
    /// longer guaranteed to be a triangulation.
    CriterionFails,
}

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// Removes vertex `v` of a 1-sheeted triangulation that satisfies the criterion, if the
    /// criterion still holds afterwards; otherwise leaves the triangulation unchanged.
    pub(crate) fn remove_vertex(&mut self, v: u32) -> Result<(), RemoveError> {
        debug_assert!(self.one_sheeted);
        // the star, each cell with the shift from its frame to the frame of the first one
        let c0 = self.vcell[v as usize];
        let mut star: Vec<(u32, usize, S::Offset)> = vec![(
            c0,
            self.tds.cells[c0 as usize].index_of(v).unwrap(),
            S::Offset::default(),
        )];
        let (mark, _) = self.tds.new_visit();
        self.tds.set_stamp(c0, mark);
        let mut next = 0;
        while next < star.len() {
            let (c, i, shift) = star[next];
            for k in 0..N {
                if k == i {
                    continue;
                }
                let d = self.tds.cells[c as usize].n[k];
                if self.tds.stamp(d) == mark {
                    continue;
                }
                self.tds.set_stamp(d, mark);
                let t = self.space.compose(self.translation(c, k, d), shift);
                let j = self.tds.cells[d as usize]
                    .index_of(v)
                    .expect("a neighbour through a facet holding v holds v");
                star.push((d, j, t));
            }
            next += 1;
        }
        let shifted = |e: &Self, c: u32, shift: S::Offset| -> LiftedCell<S, N> {
            e.lifted_cell(c)
                .map(|(p, o)| (p, e.space.compose(o, shift)))
        };
        let mut hole: Vec<Candidate<S, N>> = Vec::new();
        let mut seeds = Vec::with_capacity(star.len());
        for &(c, i, shift) in &star {
            let arr = shifted(self, c, shift);
            let cell = self.tds.cells[c as usize];
            for k in 0..N {
                if k != i && !hole.iter().any(|h| h.0 == cell.v[k]) {
                    hole.push((cell.v[k], arr[k]));
                }
            }
            let d = cell.n[i];
            let j = self.tds.cells[d as usize]
                .mirror(c)
                .expect("symmetric neighbours");
            seeds.push((cell.v, arr, i, true, Owner::Old(d, j)));
        }
        let cells = self
            .wrap(seeds, |_, _| hole.clone(), Vec::new())
            .ok_or(RemoveError::CriterionFails)?;
        let limit = self.space.criterion_radius2();
        if cells
            .iter()
            .any(|w| self.space.circumradius2(&w.arr) >= limit)
        {
            return Err(RemoveError::CriterionFails);
        }
        for &(c, _, _) in &star {
            self.kill_cell(c);
        }
        self.commit(&cells);
        self.vcell[v as usize] = NONE;
        Ok(())
    }
}
