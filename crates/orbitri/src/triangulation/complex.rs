//! The triangulation of the space itself, whatever the engine stores: one cell per orbit of
//! stored cells, glued to its neighbours across the boundary of the domain. While few points
//! keep the triangulation in a covering space, the projection of the covering's cells is
//! in general not a simplicial complex: a cell may meet the same neighbour through two of its
//! facets, or itself, and a vertex may appear in it twice (two images of one point). It is a
//! Δ-complex (the thesis §5.1), told by cells, neighbours, mirror indices and gluing elements.

use std::collections::HashMap;

use rayon::prelude::*;

use super::{CellView, Triangulation};
use crate::error::{Error, Result};
use crate::ids::CellId;
use crate::space::FlatSpace;

/// The triangulation of the space as a Δ-complex: `cells[k]` is one stored cell of each
/// orbit (input ids and elements, positively oriented), and its facet opposite vertex `i`
/// is glued to the facet of `cells[neighbors[k][i]]` opposite vertex `mirrors[k][i]`, moved
/// by `gluings[k][i]`: the neighbour's vertex `(p, g)` on that facet is this cell's vertex
/// `(p, gluings[k][i]∘g)` (in a torus, its offset plus the gluing's). In a 1-sheeted
/// triangulation this is the stored complex itself.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Complex<const D: usize, const N: usize, E> {
    pub cells: Vec<CellView<D, N, E>>,
    pub neighbors: Vec<[u32; N]>,
    pub mirrors: Vec<[u8; N]>,
    pub gluings: Vec<[E; N]>,
}

/// A cell's vertices as (point, element) pairs.
type Pairs<E, const N: usize> = [(u32, E); N];

/// An orbit met so far: its row, its representative's canonical frame, and the
/// representative's pairs moved into that frame.
type Row<E, const N: usize> = (u32, E, Pairs<E, N>);

/// Each stored cell's orbit: the orbit's row, the element `g` with `stored = g·representative`
/// and, for each vertex slot of the stored cell, the slot of the same vertex in the
/// representative. Indexed by cell slot.
pub(super) struct Orbits<E, const N: usize> {
    pub(super) representatives: Vec<CellId>,
    pub(super) of: Vec<(u32, E, [u8; N])>,
    /// Whether every orbit has one stored cell per sheet: the stored triangulation is
    /// invariant under the group, the lift of a triangulation of the space.
    pub(super) invariant: bool,
}

impl<const D: usize, const N: usize, S: FlatSpace<D, N>> Triangulation<D, N, S> {
    /// The orbits of the stored cells under the group, in the order of their first stored
    /// cell (every stored cell is its own orbit once the triangulation is 1-sheeted).
    pub(super) fn orbits(&self) -> Orbits<S::Elem, N> {
        let engine = &self.engine;
        let space = self.space();
        let one = space.identity();
        let same: [u8; N] = std::array::from_fn(|i| i as u8);
        let mut of = vec![(u32::MAX, one, same); engine.cell_slots()];
        let mut representatives = Vec::with_capacity(engine.number_of_cells() / self.sheets());
        if self.is_one_sheeted() {
            for (k, c) in engine.cell_ids().enumerate() {
                of[c.index()] = (k as u32, one, same);
                representatives.push(c);
            }
            return Orbits {
                representatives,
                of,
                invariant: true,
            };
        }
        // the key of an orbit: the cell's (point, element) pairs in its canonical frame
        // (unique: the group acts freely, and two pairs of one cell are never equal)
        let mut rows: HashMap<Pairs<S::Elem, N>, Row<S::Elem, N>> = HashMap::new();
        for c in engine.cell_ids() {
            let cell = engine.cell(c);
            let pairs: [(u32, S::Elem); N] =
                std::array::from_fn(|i| (engine.point_of(cell.v[i]).0, cell.off[i]));
            let h = space.face_frame(&pairs);
            let moved = pairs.map(|(p, g)| (p, space.compose(h, g)));
            let mut key = moved;
            key.sort_unstable();
            let next = representatives.len() as u32;
            let &mut (row, frame, at) = rows.entry(key).or_insert_with(|| {
                representatives.push(c);
                (next, h, moved)
            });
            // moved[i] = h∘gᵢ = frame∘g'ⱼ for the representative's slot j: gᵢ = h⁻¹∘frame∘g'ⱼ
            let slots = moved.map(|x| at.iter().position(|&y| y == x).expect("one orbit") as u8);
            of[c.index()] = (row, space.compose(space.inverse(h), frame), slots);
        }
        let mut copies = vec![0; representatives.len()];
        for c in engine.cell_ids() {
            copies[of[c.index()].0 as usize] += 1;
        }
        Orbits {
            invariant: copies.iter().all(|&k| k == self.sheets()),
            representatives,
            of,
        }
    }

    /// The triangulation of the space: one cell per orbit, with its neighbours across the
    /// boundary (a Δ-complex while the points are too few for a simplicial one); see
    /// [`Complex`]. [`Self::cells`]`(Copies::Unique)` lists the same cells in the same order.
    ///
    /// A covering's triangulation is the lift of one of the space when the perturbation
    /// of ties is the same for every copy: always on the tori, the Klein bottle and the
    /// flat 3-manifolds but one. The didicosm's group has no order that every element
    /// respects, so a tie among images of one point in different cosets (a point at a
    /// special position, with too few points for the manifold itself) can be broken
    /// differently for different copies: that is [`Error::NotInvariant`], checked here
    /// (every orbit must have one stored cell per sheet), never a wrong complex.
    pub fn complex(&self) -> Result<Complex<D, N, S::Elem>> {
        let engine = &self.engine;
        let space = self.space();
        let orbits = self.orbits();
        if !orbits.invariant {
            return Err(Error::NotInvariant {
                points: self.number_of_vertices(),
                sheets: self.sheets(),
            });
        }
        // one row per representative, independent of the others: in parallel, in order
        let rows: Vec<_> = orbits
            .representatives
            .par_iter()
            .map(|&c| {
                let cell = engine.cell(c);
                let mut neighbors = [0; N];
                let mut mirrors = [0; N];
                let mut gluings = [space.identity(); N];
                for i in 0..N {
                    let d = cell.n[i];
                    let (row, g, slots) = orbits.of[d.index()];
                    let j = engine.cell(d).mirror(c).expect("neighbours see each other");
                    neighbors[i] = row;
                    mirrors[i] = slots[j];
                    // d's frame onto c's, after the representative's onto d's
                    gluings[i] = space.compose(engine.translation(c, i, d), g);
                }
                (self.view(c), neighbors, mirrors, gluings)
            })
            .collect();
        let mut out = Complex {
            cells: Vec::with_capacity(rows.len()),
            neighbors: Vec::with_capacity(rows.len()),
            mirrors: Vec::with_capacity(rows.len()),
            gluings: Vec::with_capacity(rows.len()),
        };
        for (cell, neighbors, mirrors, gluings) in rows {
            out.cells.push(cell);
            out.neighbors.push(neighbors);
            out.mirrors.push(mirrors);
            out.gluings.push(gluings);
        }
        Ok(out)
    }
}
