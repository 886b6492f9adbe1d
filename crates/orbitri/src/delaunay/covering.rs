//! Moving along the covering ladder: the first triangulation of a level, the conversion to
//! the next level once its criterion holds (to the quotient also once the 1-skeleton has no
//! cycle of length ≤ 2, Theorem 2.2.8), and the way back to level 0.

use std::borrow::Cow;

use rayon::prelude::*;
use rustc_hash::FxHashMap;

use super::{Candidate, Engine};
use crate::ids::{CellId, PointId, VertexId};
use crate::space::OrbitSpace;
use crate::tds::Cell;

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// The vertex id of the lifted copy `(p, o)` at the current level: `sheets` ids per
    /// point, sheet by sheet (the point id itself in the quotient).
    pub(super) fn vertex_id(&self, p: PointId, o: S::Elem) -> VertexId {
        let sheets = self.space.sheets(self.level) as u32;
        VertexId(p.0 * sheets + self.space.sheet_of(o, self.level) as u32)
    }

    /// For every point `p`, the lifted copies within `radius` of it (at the identity): the
    /// copies near its image `g·p` are their images by `g`, so gift wrapping asks the
    /// space once per point, not once per facet. (The space names a point by its index in
    /// the slice of points it is given: its id.)
    fn copies_around(&self, radius: f64) -> Vec<Vec<(u32, S::Elem)>> {
        let one = self.space.identity();
        (0..self.points.len())
            .into_par_iter()
            .map(|i| {
                let mut near = Vec::new();
                self.space
                    .near((self.points[i], one), &self.points, radius, &mut near);
                near
            })
            .collect()
    }

    /// Candidates for gift wrapping around the lifted copy `(p, g)` of point `p`: the
    /// copies near `p` moved by `g`, with their vertex ids.
    fn wrap_candidates(
        &self,
        around: &[Vec<(u32, S::Elem)>],
        p: PointId,
        g: S::Elem,
    ) -> Vec<Candidate<S, N>> {
        around[p.index()]
            .iter()
            .map(|&(i, h)| {
                let o = self.space.compose(g, h);
                (self.vertex_id(PointId(i), o), (self.points[i as usize], o))
            })
            .collect()
    }

    /// Moves to `level` with an empty triangulation: vertex maps and the copies and
    /// large-cell limit of the level.
    fn enter_level(&mut self, level: usize) {
        self.level = level;
        self.one_sheeted = level == self.last_level();
        self.copies = self.space.covering_copies(level);
        let sheets = self.copies.len();
        self.vpoint = (0..self.points.len() as u32)
            .flat_map(|p| std::iter::repeat_n(PointId(p), sheets))
            .collect();
        self.vcell = vec![CellId::NONE; self.vpoint.len()];
        self.big_limit = self.next_limit();
        self.big.clear();
        self.big_count = 0;
        self.hint = CellId::NONE;
        self.hint_shift = self.space.identity();
        self.copy_hints.clear();
        if self.one_sheeted {
            self.refill_locator();
        }
    }

    /// Triangulates the current points from scratch by gift wrapping in the space of
    /// `level` (level 0, or a level whose criterion the points satisfy).
    fn bootstrap(&mut self, level: usize) {
        self.tds.clear();
        self.guaranteed = false;
        self.enter_level(level);
        let radius = self.space.edge_bound(level);
        let one = self.space.identity();
        let around = self.copies_around(radius);
        let a = (self.vertex_id(PointId(0), one), (self.points[0], one));
        let cands = self.wrap_candidates(&around, PointId(0), one);
        let max_r2 = (radius / 2.0) * (radius / 2.0) * (1.0 + 1e-9);
        let first = self
            .first_cell(a, &cands, max_r2)
            .expect("the first Delaunay cell exists");
        let seeds = Self::seeds_of(&first);
        let cells = self
            .wrap(
                seeds,
                |vids, arr, idx| {
                    let k = (idx + 1) % N;
                    Cow::Owned(self.wrap_candidates(
                        &around,
                        self.vpoint[vids[k].index()],
                        arr[k].1,
                    ))
                },
                vec![first],
                true,
                None,
            )
            .expect("gift wrapping closes the initial triangulation");
        self.commit(&cells);
    }

    /// The level-0 triangulation of the anchors alone ([`OrbitSpace::anchor_cells`]), then
    /// down the ladder as far as it goes.
    pub(super) fn install_anchors(&mut self) {
        self.points = self.space.anchors();
        self.tds.clear();
        self.guaranteed = false;
        self.enter_level(0);
        let mut facets: FxHashMap<[VertexId; N], (CellId, usize)> = FxHashMap::default();
        for lifted in self.space.anchor_cells() {
            let mut v = lifted.map(|(p, o)| self.vertex_id(PointId(p), o));
            let mut off = lifted.map(|(_, o)| o);
            let arr = lifted.map(|(p, o)| (self.points[p as usize], o));
            if self.space.orient(&arr) == crate::predicates::Sign::Negative {
                v.swap(0, 1);
                off.swap(0, 1);
            }
            let c = self.make_cell(v, off);
            for i in 0..N {
                let cell = self.tds.cells[c.index()];
                let key = super::wrap::facet_key(&cell.v, i);
                match facets.remove(&key) {
                    Some((d, j)) => self.link(c, i, d, j),
                    None => {
                        facets.insert(key, (c, i));
                    }
                }
            }
            self.attach(c);
        }
        assert!(facets.is_empty(), "the anchor cells close up");
        self.hint = CellId(0);
        self.descend();
    }

    /// The level-0 triangulation of the first point.
    pub(super) fn bootstrap_covering(&mut self) {
        self.bootstrap(0);
        self.descend();
    }

    /// While the criterion of the next level holds (no big cell), moves to that level; once
    /// in the quotient the criterion is guaranteed for every later insertion.
    pub(super) fn descend(&mut self) {
        while !self.one_sheeted && self.big_count == 0 {
            // (the new cells are tracked against the criterion of the level after)
            self.convert((self.level + 1).min(self.last_level()));
        }
        if self.one_sheeted && self.big_count == 0 {
            self.set_guaranteed(true);
        }
    }

    /// The 1-sheeted triangulation of the current points, which must satisfy the criterion
    /// (the dummy point set does by construction).
    pub(crate) fn bootstrap_one_sheeted(&mut self) {
        self.bootstrap(self.last_level());
        self.set_guaranteed(true);
    }

    /// Takes a space with other coverings (weighted points spread further): a quotient
    /// stays where it is, its criterion examined again; a covering is rebuilt from the new
    /// level 0.
    pub(crate) fn replace_space(&mut self, space: S) {
        self.space = space;
        if self.points.is_empty() {
            let w = self.weight_max;
            self.clear();
            self.weight_max = w;
        } else if self.one_sheeted {
            self.level = self.last_level();
            self.guaranteed = false;
            self.recount_big();
        } else {
            self.rebuild_in_covering();
        }
    }

    /// Rebuilds the triangulation of the current points at level 0.
    pub(crate) fn rebuild_in_covering(&mut self) {
        if self.anchors > 0 {
            // from the anchors again; the points keep their ids (each was a vertex of a
            // superset's triangulation: none is hidden)
            let pts = self.points.split_off(self.anchors);
            self.clear();
            for p in pts {
                self.insert_weighted(p, 0.0);
            }
            return;
        }
        let pts = std::mem::take(&mut self.points);
        let ws = std::mem::take(&mut self.weights);
        let weight = |i: usize| ws.get(i).copied().unwrap_or(0.0);
        self.guaranteed = false;
        self.push_point(pts[0], weight(0));
        self.bootstrap_covering();
        // (no point is hidden: each was a vertex of a superset's triangulation)
        for (i, &p) in pts.iter().enumerate().skip(1) {
            self.insert_weighted(p, weight(i));
        }
    }

    /// True when the projection of the covering triangulation to the quotient is a
    /// simplicial complex: no edge joins two copies of one point, and no two edges join the
    /// same two points with different relative offsets (no cycle of length ≤ 2). The
    /// covering triangulation is invariant under the group of its sheets, so the star of
    /// one copy of each point tells (not every cell of every sheet). Points without a
    /// vertex are skipped.
    pub fn quotient_is_simplicial(&self) -> bool {
        if self.one_sheeted {
            return true;
        }
        let sheets = self.space.sheets(self.level) as u32;
        (0..self.points.len() as u32)
            .into_par_iter()
            .with_min_len(1024)
            .map_init(Vec::new, |edges: &mut Vec<(PointId, S::Elem)>, p| {
                edges.clear();
                // (a point without a vertex, gone or hidden, has no edge)
                let v = VertexId(p * sheets);
                if self.vcell[v.index()] == CellId::NONE {
                    return true;
                }
                for (c, i, _) in self.star(v) {
                    let cell = self.tds.cell(c);
                    for k in (0..N).filter(|&k| k != i) {
                        let rel = self.space.relative(cell.off[k], cell.off[i]);
                        edges.push((self.vpoint[cell.v[k].index()], rel));
                    }
                }
                single_edges(PointId(p), edges)
            })
            .all(|single| single)
    }

    /// Replaces the covering triangulation by its projection to the space of a later
    /// `level` (from the lift level, the quotient): one cell per orbit of cells under that
    /// space's group, vertex ids renumbered for its sheets. The caller guarantees the
    /// projection is simplicial.
    pub(crate) fn convert(&mut self, level: usize) {
        // (from the lift level, after the ladder's, to the quotient)
        if level <= self.level && self.level <= self.last_level() {
            return;
        }
        let old = std::mem::take(&mut self.tds);
        let old_vpoint = std::mem::take(&mut self.vpoint);
        // the new cells are created in the order of `reps`: the `k`-th has id `k`
        let mut orbit = vec![CellId::NONE; old.cells.len()];
        // Into the quotient of a torus, the group of the sheets moves each cell onto one
        // cell for each sheet of its vertex of least point (two copies of a point share no
        // cell when the quotient is simplicial): the one with that vertex in sheet 0 stands
        // for its orbit, which its vertex ids moved that way name. Only those are hashed,
        // and only the neighbours that do not stand for their own orbit are looked up.
        let free = level == self.last_level() && self.space.translations_only();
        let sheets = self.space.sheets(self.level) as u32;
        let sum = if free {
            self.sheet_group().1
        } else {
            Vec::new()
        };
        // (`to[a]`: the sheet whose translation takes sheet `a` to sheet 0)
        let to = taking(&sum, sheets as usize);
        let least = |v: &[VertexId; N]| v[(0..N).min_by_key(|&i| v[i].0 / sheets).unwrap_or(0)];
        let class = |c: CellId| {
            let v = old.cells[c.index()].v;
            let g = to[(least(&v).0 % sheets) as usize] as u32 * sheets;
            let mut k = v.map(|u| u.0 - u.0 % sheets + sum[(g + u.0 % sheets) as usize] as u32);
            k.sort_unstable();
            k
        };
        let mut named: FxHashMap<[u32; N], CellId> = FxHashMap::default();
        let reps: Vec<CellId> = if free {
            // (found and named on the threads, in the order of their ids)
            let reps: Vec<CellId> = (0..old.cells.len() as u32)
                .into_par_iter()
                .map(CellId)
                .filter(|&c| old.is_alive(c) && least(&old.cells[c.index()].v).0 % sheets == 0)
                .collect();
            let names: Vec<[u32; N]> = reps.par_iter().map(|&c| class(c)).collect();
            named.reserve(reps.len());
            for (k, (&c, name)) in reps.iter().zip(names).enumerate() {
                let fresh = named.insert(name, CellId::new(k)).is_none();
                debug_assert!(
                    fresh,
                    "one cell of an orbit has its least vertex in sheet 0"
                );
                orbit[c.index()] = CellId::new(k);
            }
            reps
        } else {
            let mut reps = Vec::new();
            let mut index: FxHashMap<[(PointId, S::Elem); N], CellId> = FxHashMap::default();
            for c in old.ids() {
                let key = quotient_key(&self.space, &old_vpoint, &old.cell(c), level);
                orbit[c.index()] = *index.entry(key).or_insert_with(|| {
                    reps.push(c);
                    CellId::new(reps.len() - 1)
                });
            }
            reps
        };
        let orbit_of = |d: CellId| match orbit[d.index()] {
            CellId::NONE => named[&class(d)],
            k => k,
        };
        let cells: Vec<Cell<S::Elem, N>> = reps
            .par_iter()
            .map(|&c| {
                let was = old.cell(c);
                let mut cell = Cell::new(was.v, was.off);
                cell.n = was.n.map(orbit_of);
                cell
            })
            .collect();
        self.enter_level(level);
        self.tds.reserve(reps.len());
        for mut cell in cells {
            // in the new level's canonical form, then renumbered for its sheets
            self.canonicalize(&mut cell);
            cell.v =
                std::array::from_fn(|i| self.vertex_id(old_vpoint[cell.v[i].index()], cell.off[i]));
            self.add_cell(cell);
        }
        for k in 0..reps.len() as u32 {
            self.attach(CellId(k));
        }
        self.hint = CellId(0);
    }

    /// Replaces the 1-sheeted triangulation of a torus by its lift to the covering of
    /// `level`, each cell once per sheet: level 0, where every point set has a
    /// triangulation, so that the points whose removal would break the quotient can go
    /// (thesis §2.3.1: the dummy points left are removed after a conversion to the
    /// 27-sheeted covering, not by triangulating every point again), or the space's lift
    /// level ([`OrbitSpace::lift_level`]), where they can while its criterion or its
    /// simplicial complex holds (see `Engine::remove_first_points`). The
    /// copy of a cell by `t` meets, across each facet, the copy of that neighbour by `t`
    /// composed with the element between their frames; a copy is large for the next
    /// level's criterion when its cell is.
    pub(crate) fn unfold(&mut self, level: usize) {
        debug_assert!(self.one_sheeted && self.space.translations_only());
        let ids: Vec<CellId> = self.tds.ids().collect();
        let mut dense = vec![u32::MAX; self.tds.cells.len()];
        for (k, c) in ids.iter().enumerate() {
            dense[c.index()] = k as u32;
        }
        // each cell's criterion for the level after (its copies are congruent), each facet's
        // neighbour and the sheet of the element from its frame to the cell's
        let limit = self
            .space
            .criterion_radius2((level + 1).min(self.last_level()));
        let big: Vec<bool> = ids
            .par_iter()
            .map(|&c| self.cell_radius2(c) >= limit)
            .collect();
        let across: Vec<[(u32, usize); N]> = ids
            .par_iter()
            .map(|&c| {
                std::array::from_fn(|i| {
                    let d = self.tds.cells[c.index()].n[i];
                    let g = self.translation(c, i, d);
                    (dense[d.index()], self.space.sheet_of(g, level))
                })
            })
            .collect();
        // and the sheet of each vertex's element
        let at: Vec<[u32; N]> = ids
            .par_iter()
            .map(|&c| {
                self.tds
                    .off(c)
                    .map(|o| self.space.sheet_of(o, level) as u32)
            })
            .collect();
        let old = std::mem::take(&mut self.tds);
        let home = std::mem::take(&mut self.vcell);
        self.enter_level(level);
        let sheets = self.copies.len();
        let (by_sheet, sum) = self.sheet_group();
        let mut tds = std::mem::take(&mut self.tds);
        // the copy of cell `a` by sheet `s` has id `a·sheets + s`
        let copy = |k: usize| {
            let (a, s) = (k / sheets, k % sheets);
            let was = old.cell(ids[a]);
            let mut cell = Cell::new(was.v, was.off.map(|o| self.space.compose(by_sheet[s], o)));
            cell.n = std::array::from_fn(|i| {
                let (b, g) = across[a][i];
                CellId::new(b as usize * sheets + sum[s * sheets + g])
            });
            cell.v = std::array::from_fn(|i| {
                VertexId::new(was.v[i].index() * sheets + sum[s * sheets + at[a][i] as usize])
            });
            // (a shift by the group of the level keeps every sheet)
            self.canonicalize(&mut cell);
            debug_assert!(
                (0..N).all(|i| { cell.v[i] == self.vertex_id(PointId(was.v[i].0), cell.off[i]) })
            );
            cell
        };
        tds.extend_with(ids.len() * sheets, copy);
        // the copy of vertex `p` in sheet `t` is in the copy of `p`'s cell by the sheet
        // that takes `p`'s own sheet there
        let to = taking(&sum, sheets);
        let vcell = (0..self.vpoint.len())
            .into_par_iter()
            .map(|v| {
                let (p, t) = (v / sheets, v % sheets);
                let c = home[p];
                if c == CellId::NONE {
                    return c;
                }
                let a = dense[c.index()] as usize;
                let i = old.cells[c.index()].index_of(VertexId::new(p)).unwrap_or(0);
                CellId::new(a * sheets + to[t * sheets + at[a][i] as usize])
            })
            .collect();
        (self.tds, self.vcell) = (tds, vcell);
        self.guaranteed = false;
        self.big = big
            .iter()
            .flat_map(|&b| std::iter::repeat_n(b, sheets))
            .collect();
        self.big_count = self.big.iter().filter(|&&b| b).count();
        self.hint = CellId(0);
    }

    /// The copies of the current level by sheet, and the group of the sheets: of
    /// translations, the sheet of a sum is a function of the sheets (`sum[a·sheets + b]`).
    pub(super) fn sheet_group(&self) -> (Vec<S::Elem>, Vec<usize>) {
        let sheets = self.copies.len();
        let mut by_sheet = vec![self.space.identity(); sheets];
        for &t in &self.copies {
            by_sheet[self.space.sheet_of(t, self.level)] = t;
        }
        let sum = (0..sheets * sheets)
            .map(|k| {
                let (a, b) = (by_sheet[k / sheets], by_sheet[k % sheets]);
                self.space.sheet_of(self.space.compose(a, b), self.level)
            })
            .collect();
        (by_sheet, sum)
    }

    /// Drops the points whose vertices were removed (`gone`) and renumbers the rest in
    /// order, in one pass over the cells. Returns each old point's new id
    /// ([`PointId::NONE`] for the dropped ones).
    pub(crate) fn compact(&mut self, gone: &[bool]) -> Vec<PointId> {
        let map = renumbering(gone);
        let sheets = self.space.sheets(self.level) as u32;
        let vertex_gone: Vec<bool> = gone
            .iter()
            .flat_map(|&g| std::iter::repeat_n(g, sheets as usize))
            .collect();
        drop_gone(&mut self.points, gone);
        if self.weighted {
            drop_gone(&mut self.weights, gone);
        }
        drop_gone(&mut self.vcell, &vertex_gone);
        self.vpoint = (0..self.points.len() as u32)
            .flat_map(|p| std::iter::repeat_n(PointId(p), sheets as usize))
            .collect();
        for c in 0..self.tds.cells.len() as u32 {
            let c = CellId(c);
            if self.tds.is_alive(c) {
                for v in self.tds.cells[c.index()].v.iter_mut() {
                    *v = VertexId(map[(v.0 / sheets) as usize].0 * sheets + v.0 % sheets);
                }
            }
        }
        self.hint = CellId::NONE;
        self.copy_hints.clear();
        // (renumbered: computed again by the next parallel insertion)
        self.wave_keys = Vec::new();
        if self.one_sheeted {
            self.renumber_locator(&map);
        }
        map
    }

    /// At the end of a construction still in the covering: switch to the quotient if it is
    /// a triangulation even though the criterion does not guarantee it for more points (a
    /// torus only: see [`OrbitSpace::translations_only`]).
    pub fn try_one_sheet(&mut self) -> bool {
        if !self.one_sheeted
            && !self.points.is_empty()
            && self.space.translations_only()
            && self.quotient_is_simplicial()
        {
            self.convert(self.last_level());
            if self.big_count == 0 {
                self.set_guaranteed(true);
            }
        }
        self.one_sheeted
    }
}

/// For a table of sheet sums (`sum[a·sheets + b]`, see `Engine::sheet_group`), the
/// sheet whose translation takes sheet `a` to sheet `t`, at `t·sheets + a`.
fn taking(sum: &[usize], sheets: usize) -> Vec<usize> {
    let mut to = vec![0; sum.len()];
    for (k, &t) in sum.iter().enumerate() {
        to[t * sheets + k % sheets] = k / sheets;
    }
    to
}

/// True when the edges `(neighbour, relative element)` at `own` never reach `own` and reach
/// each neighbour by a single element: no cycle of length ≤ 2 through it. Sorts `edges`.
pub(super) fn single_edges<V: Ord, E: Ord>(own: V, edges: &mut [(V, E)]) -> bool {
    edges.sort_unstable();
    !edges.iter().any(|e| e.0 == own)
        && !edges
            .windows(2)
            .any(|w| w[0].0 == w[1].0 && w[0].1 != w[1].1)
}

/// The new ids of the points that stay, in order ([`PointId::NONE`] for the others).
pub(super) fn renumbering(gone: &[bool]) -> Vec<PointId> {
    let mut next = 0u32;
    gone.iter()
        .map(|&g| {
            next += !g as u32;
            if g {
                PointId::NONE
            } else {
                PointId(next - 1)
            }
        })
        .collect()
}

/// Keeps the entries of `v` that are not `gone`.
pub(super) fn drop_gone<T>(v: &mut Vec<T>, gone: &[bool]) {
    let mut k = 0;
    v.retain(|_| {
        k += 1;
        !gone[k - 1]
    });
}

/// The canonical form of a covering cell in the space of `level`: offsets translated by that
/// space's group into normal form, then (point, offset) pairs sorted.
pub(super) fn quotient_key<S: OrbitSpace<N>, const N: usize>(
    space: &S,
    vpoint: &[PointId],
    cell: &Cell<S::Elem, N>,
    level: usize,
) -> [(PointId, S::Elem); N] {
    let mut off = cell.off;
    space.normalize(&mut off, level);
    let mut pairs: [(PointId, S::Elem); N] =
        std::array::from_fn(|i| (vpoint[cell.v[i].index()], off[i]));
    pairs.sort_unstable();
    pairs
}
