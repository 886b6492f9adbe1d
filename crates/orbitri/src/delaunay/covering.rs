//! Moving between the covering space and the 1-sheeted quotient: the first triangulation of
//! each, the conversion once the switch criterion holds (or once the 1-skeleton has no cycle of
//! length ≤ 2, Theorem 2.2.8), and the way back.

use std::collections::HashMap;

use super::{Candidate, Engine, LiftedOf};
use crate::space::OrbitSpace;
use crate::tds::{Cell, Tds, NONE};

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// Candidates for gift wrapping: the lifted copies of the points near `at`,
    /// with their vertex ids (`sheets` ids per point in the covering, one in the quotient).
    fn wrap_candidates(&self, at: LiftedOf<S, N>, radius: f64) -> Vec<Candidate<S, N>> {
        let mut near = Vec::new();
        self.space.near(at, &self.points, radius, &mut near);
        let sheets = if self.one_sheeted {
            1
        } else {
            self.space.sheets()
        };
        near.into_iter()
            .map(|(i, o)| {
                let vid = if self.one_sheeted {
                    i
                } else {
                    i * sheets as u32 + self.space.sheet_of(o) as u32
                };
                (vid, (self.points[i as usize], o))
            })
            .collect()
    }

    /// Triangulates the current points from scratch by gift wrapping (in the covering, or in
    /// the quotient when `one_sheeted` and the points satisfy the criterion).
    fn bootstrap(&mut self, one_sheeted: bool) {
        self.tds.clear();
        self.big.clear();
        self.big_count = 0;
        self.guaranteed = false;
        self.one_sheeted = one_sheeted;
        let sheets = if one_sheeted { 1 } else { self.space.sheets() };
        self.vpoint = (0..self.points.len() as u32)
            .flat_map(|p| std::iter::repeat_n(p, sheets))
            .collect();
        self.vcell = vec![NONE; self.vpoint.len()];
        let radius = self.space.edge_bound(one_sheeted);
        let a = (0u32, (self.points[0], S::Offset::default()));
        let cands = self.wrap_candidates(a.1, radius);
        let max_r2 = (radius / 2.0) * (radius / 2.0) * (1.0 + 1e-9);
        let first = self
            .first_cell(a, &cands, max_r2)
            .expect("the first Delaunay cell exists");
        let seeds = Self::seeds_of(&first);
        let cells = self
            .wrap(
                seeds,
                |arr, idx| self.wrap_candidates(arr[(idx + 1) % N], radius),
                vec![first],
            )
            .expect("gift wrapping closes the initial triangulation");
        self.commit(&cells);
    }

    /// The covering triangulation of the first point.
    pub(super) fn bootstrap_covering(&mut self) {
        self.bootstrap(false);
        if self.big_count == 0 {
            self.convert_to_one_sheet();
            self.set_guaranteed(true);
        }
    }

    /// The 1-sheeted triangulation of the current points, which must satisfy the criterion
    /// (the dummy point set does by construction).
    pub(crate) fn bootstrap_one_sheeted(&mut self) {
        self.bootstrap(true);
        self.set_guaranteed(true);
    }

    /// Rebuilds the triangulation of the current points in the covering space.
    pub(crate) fn rebuild_in_covering(&mut self) {
        let pts = std::mem::take(&mut self.points);
        self.one_sheeted = false;
        self.guaranteed = false;
        self.points.push(pts[0]);
        self.bootstrap_covering();
        for &p in &pts[1..] {
            self.insert(p);
        }
    }

    /// True when the projection of the covering triangulation to the quotient is a
    /// simplicial complex: no edge joins two copies of one point, and no two edges join the
    /// same two points with different relative offsets (no cycle of length ≤ 2).
    pub fn quotient_is_simplicial(&self) -> bool {
        if self.one_sheeted {
            return true;
        }
        let mut seen: HashMap<(u32, u32), S::Offset> = HashMap::new();
        for c in self.tds.ids() {
            let cell = &self.tds.cells[c as usize];
            for a in 0..N {
                for b in 0..N {
                    let (pa, pb) = (
                        self.vpoint[cell.v[a] as usize],
                        self.vpoint[cell.v[b] as usize],
                    );
                    if a == b {
                        continue;
                    }
                    if pa == pb {
                        return false;
                    }
                    let rel = self.space.difference(cell.off[b], cell.off[a]);
                    if *seen.entry((pa, pb)).or_insert(rel) != rel {
                        return false;
                    }
                }
            }
        }
        true
    }

    /// Replaces the covering triangulation by its quotient: one cell per orbit of cells,
    /// vertex ids become point ids. The caller guarantees the quotient is simplicial.
    pub(crate) fn convert_to_one_sheet(&mut self) {
        if self.one_sheeted {
            return;
        }
        let old = std::mem::replace(&mut self.tds, Tds::new());
        let mut orbit = vec![NONE; old.cells.len()];
        let mut reps: Vec<u32> = Vec::new();
        let mut index: HashMap<[(u32, S::Offset); N], u32> = HashMap::new();
        for c in old.ids() {
            let key = quotient_key(&self.space, &self.vpoint, &old.cells[c as usize]);
            orbit[c as usize] = *index.entry(key).or_insert_with(|| {
                reps.push(c);
                (reps.len() - 1) as u32
            });
        }
        self.one_sheeted = true;
        self.big.clear();
        self.big_count = 0;
        self.tds.reserve(reps.len());
        for &c in &reps {
            let cell = &old.cells[c as usize];
            let v = cell.v.map(|x| self.vpoint[x as usize]);
            self.make_cell(v, cell.off);
        }
        for (k, &c) in reps.iter().enumerate() {
            self.tds.cells[k].n = old.cells[c as usize].n.map(|d| orbit[d as usize]);
        }
        self.vpoint = (0..self.points.len() as u32).collect();
        self.vcell = vec![NONE; self.points.len()];
        for k in 0..reps.len() as u32 {
            self.attach(k);
        }
        self.hint = 0;
        self.hint_shift = S::Offset::default();
    }

    /// Drops the first `k` points (the dummies, once removed) and renumbers the rest.
    pub(crate) fn drop_leading_points(&mut self, k: u32) {
        debug_assert!(self.one_sheeted);
        self.points.drain(..k as usize);
        self.vpoint = (0..self.points.len() as u32).collect();
        self.vcell.drain(..k as usize);
        for c in 0..self.tds.cells.len() as u32 {
            if self.tds.is_alive(c) {
                for v in self.tds.cells[c as usize].v.iter_mut() {
                    *v -= k;
                }
            }
        }
    }

    /// At the end of a construction still in the covering: switch to the quotient if it is
    /// a triangulation even though the criterion does not guarantee it for more points.
    pub fn try_one_sheet(&mut self) -> bool {
        if !self.one_sheeted && !self.points.is_empty() && self.quotient_is_simplicial() {
            self.convert_to_one_sheet();
            if self.big_count == 0 {
                self.set_guaranteed(true);
            }
        }
        self.one_sheeted
    }
}

/// The canonical form of a covering cell in the quotient: offsets translated by the lattice
/// into normal form, then (point, offset) pairs sorted.
pub(super) fn quotient_key<S: OrbitSpace<N>, const N: usize>(
    space: &S,
    vpoint: &[u32],
    cell: &Cell<S::Offset, N>,
) -> [(u32, S::Offset); N] {
    let mut off = cell.off;
    space.normalize(&mut off, true);
    let mut pairs: [(u32, S::Offset); N] =
        std::array::from_fn(|i| (vpoint[cell.v[i] as usize], off[i]));
    pairs.sort_unstable();
    pairs
}
