//! Validity of a stored triangulation: combinatorics (neighbour symmetry, shared facets,
//! consistent offsets, vertex pointers, Euler characteristic) and geometry (positive
//! orientation, local Delaunay property, exactly).

use std::collections::HashSet;

use super::Engine;
use crate::predicates::Sign;
use crate::space::OrbitSpace;
use crate::tds::NONE;

/// A face as sorted (vertex, offset) pairs.
type FaceKey<O> = Vec<(u32, O)>;

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
            let cell = &self.tds.cells[c as usize];
            for i in 0..N {
                if (i + 1..N).any(|j| cell.v[i] == cell.v[j]) {
                    return bad(format!("cell {c} repeats vertex {}", cell.v[i]));
                }
                let d = cell.n[i];
                if d == NONE || !self.tds.is_alive(d) {
                    return bad(format!("cell {c} has no neighbour {i}"));
                }
                let dc = &self.tds.cells[d as usize];
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
                    let tk = self.space.difference(cell.off[k], dc.off[kk]);
                    if *t.get_or_insert(tk) != tk {
                        return bad(format!(
                            "cells {c} and {d}: inconsistent offsets across the shared facet"
                        ));
                    }
                }
                let q = self.lifted(d, j);
                let q = (q.0, self.space.compose(q.1, t.unwrap()));
                if self.space.in_sphere(&self.lifted_cell(c), q) == Sign::Positive {
                    return bad(format!(
                        "cell {c} is not locally Delaunay: vertex {} of cell {d} is inside",
                        dc.v[j]
                    ));
                }
            }
            if self.orientation(c) != Sign::Positive {
                return bad(format!("cell {c} is not positively oriented"));
            }
        }
        for (v, &c) in self.vcell.iter().enumerate() {
            if c == NONE
                || !self.tds.is_alive(c)
                || self.tds.cells[c as usize].index_of(v as u32).is_none()
            {
                return bad(format!("vertex {v} has no incident cell"));
            }
        }
        // Euler characteristic of a closed 3-manifold (or of a torus) is 0
        let mut faces: Vec<HashSet<FaceKey<S::Offset>>> = vec![HashSet::new(); N];
        for c in self.tds.ids() {
            let cell = &self.tds.cells[c as usize];
            for mask in 1u32..(1 << N) {
                let members: Vec<usize> = (0..N).filter(|i| mask >> i & 1 == 1).collect();
                let mut face: Vec<(u32, S::Offset)> = members
                    .iter()
                    .map(|&i| {
                        (
                            cell.v[i],
                            self.space.difference(cell.off[i], cell.off[members[0]]),
                        )
                    })
                    .collect();
                // translate so that the smallest vertex sits at offset 0
                face.sort_unstable();
                let base = face[0].1;
                for f in face.iter_mut() {
                    f.1 = self.space.difference(f.1, base);
                }
                if self.one_sheeted {
                    faces[members.len() - 1].insert(face);
                } else {
                    // covering: vertex ids are unique per copy, offsets are implied
                    faces[members.len() - 1]
                        .insert(face.iter().map(|f| (f.0, S::Offset::default())).collect());
                }
            }
        }
        let euler: i64 = faces
            .iter()
            .enumerate()
            .map(|(k, f)| {
                if k % 2 == 0 {
                    f.len() as i64
                } else {
                    -(f.len() as i64)
                }
            })
            .sum();
        if euler != 0 {
            return bad(format!(
                "Euler characteristic {euler}, expected 0 (counts {:?})",
                faces.iter().map(|f| f.len()).collect::<Vec<_>>()
            ));
        }
        Ok(())
    }
}
