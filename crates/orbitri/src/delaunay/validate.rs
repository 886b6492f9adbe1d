//! Validity of a stored triangulation: combinatorics (neighbour symmetry, shared facets,
//! consistent offsets, vertex pointers, Euler characteristic) and geometry (positive
//! orientation, local Delaunay property, exactly).

use super::Engine;
use crate::ids::{CellId, VertexId};
use crate::predicates::Sign;
use crate::space::OrbitSpace;

/// Why a triangulation is invalid.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("invalid triangulation: {0}")]
pub struct Invalid(pub String);

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// Checks combinatorics and geometry; `Err` names the first problem found.
    pub fn is_valid(&self) -> Result<(), Invalid> {
        let bad = |m: String| Err(Invalid(m));
        if self.points.is_empty() {
            return if self.tds.is_empty() {
                Ok(())
            } else {
                bad("cells without points".into())
            };
        }
        for c in self.tds.ids() {
            if self.orientation(c) != Sign::Positive {
                return bad(format!("cell {c} is not positively oriented"));
            }
            let cell = self.tds.cell(c);
            for i in 0..N {
                if (i + 1..N).any(|j| cell.v[i] == cell.v[j]) {
                    return bad(format!("cell {c} repeats vertex {}", cell.v[i]));
                }
                // (in a covering, a vertex is the copy of its point in its offset's sheet)
                if cell.v[i] != self.vertex_id(self.vpoint[cell.v[i].index()], cell.off[i]) {
                    return bad(format!(
                        "cell {c}: vertex {} is not in its sheet",
                        cell.v[i]
                    ));
                }
                let d = cell.n[i];
                if d == CellId::NONE || !self.tds.is_alive(d) {
                    return bad(format!("cell {c} has no neighbour {i}"));
                }
                let dc = self.tds.cell(d);
                let Some(j) = dc.mirror(c) else {
                    return bad(format!("cell {d} does not know its neighbour {c}"));
                };
                if dc.n.iter().filter(|&&x| x == c).count() != 1 {
                    return bad(format!("cells {c} and {d} share more than one facet"));
                }
                let mut t = None;
                for k in (0..N).filter(|&k| k != i) {
                    let Some(kk) = dc.index_of(cell.v[k]) else {
                        return bad(format!("cells {c} and {d} do not share facet {i}"));
                    };
                    if kk == j {
                        return bad(format!("cells {c} and {d}: facet mismatch"));
                    }
                    let tk = self.space.carry(dc.off[kk], cell.off[k]);
                    if *t.get_or_insert(tk) != tk {
                        return bad(format!(
                            "cells {c} and {d}: inconsistent offsets across the shared facet"
                        ));
                    }
                }
                let q = self.lifted(d, j);
                let q = (q.0, self.space.compose(t.unwrap(), q.1));
                if self.in_conflict(
                    &self.lifted_cell(c),
                    &cell.v,
                    q,
                    self.vertex_weight(dc.v[j]),
                ) {
                    return bad(format!(
                        "cell {c} is not locally Delaunay: vertex {} of cell {d} is inside",
                        dc.v[j]
                    ));
                }
            }
        }
        let sheets = self.sheets();
        let mut hidden = 0;
        for (v, &c) in self.vcell.iter().enumerate() {
            if c == CellId::NONE && v / sheets < self.anchors {
                hidden += 1;
                continue;
            }
            if c == CellId::NONE
                || !self.tds.is_alive(c)
                || self.tds.cells[c.index()]
                    .index_of(VertexId::new(v))
                    .is_none()
            {
                return bad(format!("vertex {v} has no incident cell"));
            }
        }
        // The Euler characteristic of the stored complex (hidden anchors aside): the space's,
        // times the sheets of a covering. Every facet is shared by two cells (checked above), so F = 2C in 3D and
        // the faces are the cells in 2D: in both, χ = V − E + C. Edges are counted from each vertex's star, towards larger ids (in
        // the covering, ids are unique per copy, so an edge is one (vertex, vertex) pair).
        let edges: usize = (0..self.vcell.len() as u32)
            .map(VertexId)
            .filter(|v| self.vcell[v.index()] != CellId::NONE)
            .map(|v| self.neighbours(v).iter().filter(|w| w.0 > v).count())
            .sum();
        let counts = [self.vcell.len() - hidden, edges, self.tds.len()];
        let euler = counts[0] as i64 - counts[1] as i64 + counts[2] as i64;
        let expected = self.sheets() as i64 * self.space.euler_characteristic();
        if euler != expected {
            return bad(format!(
                "Euler characteristic {euler}, expected {expected} (V, E, C = {:?})",
                counts
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::delaunay::uniform_cube;
    use crate::space::FlatTorus3;
    use crate::Engine;

    fn engine() -> Engine<FlatTorus3, 4> {
        let e = uniform_cube(400, 3);
        assert!(e.is_one_sheeted());
        e.is_valid().unwrap();
        e
    }

    #[test]
    fn detects_a_negatively_oriented_cell() {
        let mut e = engine();
        let c = e.tds.ids().next().unwrap();
        let mut cell = e.tds.cell(c);
        cell.swap_slots(0, 1);
        e.tds.put(c, cell);
        let msg = e.is_valid().unwrap_err().0;
        assert!(msg.contains("not positively oriented"), "{msg}");
    }

    #[test]
    fn detects_broken_neighbours_and_offsets() {
        let mut e = engine();
        let c = e.tds.ids().next().unwrap();
        let d = e.tds.cells[c.index()].n[0];
        let j = e.tds.cells[d.index()].mirror(c).unwrap();
        e.tds.cells[d.index()].n[j] = e.tds.cells[d.index()].n[(j + 1) % 4];
        assert!(e.is_valid().is_err());

        let mut e = engine();
        let c = e
            .tds
            .ids()
            .find(|&c| e.tds.off(c).iter().all(|o| *o == [0; 3]))
            .unwrap();
        let mut off = e.tds.off(c);
        off[2] = [1, 0, 0];
        e.tds.set_off(c, off);
        assert!(e.is_valid().is_err());
    }

    #[test]
    fn detects_a_non_delaunay_cell() {
        let mut e = engine();
        // moving a point off its place breaks the empty-sphere property somewhere nearby
        let p = e.points[7];
        e.points[7] = [(p[0] + 0.05) % 1.0, p[1], p[2]];
        let msg = e.is_valid().unwrap_err().0;
        assert!(
            msg.contains("locally Delaunay") || msg.contains("oriented"),
            "{msg}"
        );
    }

    /// A covering's offsets reach past what a slot holds, so its store turns wide and
    /// stays valid; the 1-sheeted torus starts a packed store again.
    #[test]
    fn a_covering_turns_the_cell_store_wide_and_the_quotient_packs_it_again() {
        let mut e = Engine::new(FlatTorus3::cuboid([1.0, 1.0, 3.0]).unwrap());
        let mut r = crate::sort::SplitMix::new(5);
        let mut wide = 0;
        for k in 0..600 {
            e.insert([r.unit(), r.unit(), 3.0 * r.unit()]);
            if !e.tds.is_packed() {
                wide += 1;
                assert!(!e.is_one_sheeted());
                if k % 32 == 0 {
                    e.is_valid().unwrap();
                }
            }
        }
        assert!(wide > 0, "never wide");
        assert!(e.is_one_sheeted() && e.tds.is_packed());
        e.is_valid().unwrap();
    }
}
