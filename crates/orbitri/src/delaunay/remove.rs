//! Removing and moving points. In the 1-sheeted triangulation the star of the vertex is
//! replaced by the Delaunay triangulation of its link, found by gift wrapping over the
//! star's vertices (thesis §3.3.6); when the quotient would stop being a simplicial complex,
//! or in a covering space, the remaining points are triangulated again from the covering of
//! level 0 (§3.3.7), which descends the ladder as far as their criterion allows. A move
//! that keeps the star positively oriented and locally Delaunay only changes coordinates.

use std::borrow::Cow;

use super::covering::{drop_gone, renumbering, single_edges};
use super::insert::Refused;
use super::wrap::{facet_key, Owner, Wrapped};
use super::{Candidate, Engine, Lift, LiftedCell};
use crate::ids::{CellId, PointId, VertexId};
use crate::predicates::Sign;
use crate::space::OrbitSpace;
use rayon::prelude::*;
use rustc_hash::FxHashMap;

/// The cells that fill a hole, as gift wrapping gives them.
type Filling<S, const N: usize> =
    Vec<Wrapped<<S as OrbitSpace<N>>::Point, <S as OrbitSpace<N>>::Elem, N>>;

/// How a point left the triangulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Removal {
    /// Its star was triangulated again in place (or it was the last point).
    InPlace,
    /// The quotient would not have stayed a simplicial complex, or the triangulation was
    /// in a covering: the remaining points were triangulated again from the covering.
    Rebuilt,
}

/// How a point moved ([`Engine::move_point`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Moved {
    /// Only its coordinates changed: the cells around it stayed Delaunay.
    Coordinates,
    /// Its vertex was removed and inserted again at the new place, keeping its id.
    Reinserted,
    /// It landed on another point: it left the triangulation (the last point took its id,
    /// as in [`Engine::remove_point`]), and this is the id of the point it coincides with.
    Duplicate(PointId),
    /// Its star became too large for the quotient without the criterion: every point was
    /// triangulated again from the covering, the moved one with its id.
    Rebuilt,
    /// Not moved in place (the triangulation lives in a covering, or removing the vertex
    /// would break the quotient): nothing changed; remove and insert instead.
    Refused,
}

/// Why a removal was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RemoveError {
    /// Without the vertex, the 1-sheeted quotient would not be a triangulation (a cycle of
    /// length ≤ 2 in its 1-skeleton): the covering space is needed.
    NotSimplicial,
}

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// Removes point `p`. The last point then takes its id (`p`'s storage is reused), so
    /// point ids stay `0..n`; the result is the Delaunay triangulation of the remaining
    /// points, the same whatever the history (the perturbation makes it unique).
    pub fn remove_point(&mut self, p: PointId) -> Removal {
        if self.points.len() == self.anchors + 1 {
            self.clear();
            return Removal::InPlace;
        }
        if self.remove_copies(p) {
            // (the walk hint stays on the new cells, where a moved point comes back)
            self.renumber_last_point(p);
            return Removal::InPlace;
        }
        self.points.swap_remove(p.index());
        if self.weighted {
            self.weights.swap_remove(p.index());
        }
        self.rebuild_in_covering();
        Removal::Rebuilt
    }

    /// Removes the points `ps` (distinct), in that order: in place while the space allows,
    /// then, if one would break it, from the covering with the rest. The points left are
    /// renumbered in order once at the end (one pass over the cells, instead of one star per
    /// removal); returns each old point's new id ([`PointId::NONE`] for the removed) and
    /// whether the remaining points had to be triangulated again.
    pub fn remove_points(&mut self, ps: &[PointId]) -> (Vec<PointId>, bool) {
        let n = self.points.len();
        if ps.len() == n - self.anchors {
            self.clear();
            return (vec![PointId::NONE; n], false);
        }
        let mut gone = vec![false; n];
        let mut rebuild = false;
        for &p in ps {
            gone[p.index()] = true;
            if !rebuild && !self.remove_copies(p) {
                rebuild = true;
            }
        }
        if !rebuild {
            return (self.compact(&gone), false);
        }
        // (removed vertices and the one refused are all dropped with the others)
        let map = renumbering(&gone);
        drop_gone(&mut self.points, &gone);
        if self.weighted {
            drop_gone(&mut self.weights, &gone);
        }
        self.rebuild_in_covering();
        (map, true)
    }

    /// Removes points `0..k` (a bulk build's dummy points), largest id first, those refused
    /// again after the others; when a round removes none, a torus goes on in a covering
    /// ([`Self::unfold`]): first that of its lift level, where the removals keep its
    /// criterion while they can (then the covering stays a triangulation for every
    /// superset), and once a round removes none that way, or at once if the quotient's
    /// cells break it, each is checked instead to keep the covering simplicial, and the
    /// points left must then reach the quotient ([`Self::try_one_sheet`]). Else, or when
    /// one cannot leave there after all, the points go on in the covering of level 0 (from
    /// the quotient as it was), where every removal goes in place. Then the last point
    /// takes each one's id, largest first: the other points keep theirs, so only the cells
    /// around the `k` moved points are rewritten, where renumbering all in order
    /// ([`Self::compact`]) rewrites every cell.
    /// Returns, for each id `d < k`, the first id of the point last moved into it (a point
    /// moves again when fewer than `k` others remain; its new id is the smallest that lists
    /// it), or `None` when a round removes none in the quotient of another space (the
    /// triangulation is then half done: the caller starts again).
    pub(crate) fn remove_first_points(&mut self, k: usize) -> Option<Vec<PointId>> {
        // a point whose removal would break the quotient (points in a slab beside a vacuum,
        // whose dummy points link across it) may go once others have; those that left
        // early (`Self::dummies_leave`) are gone
        let mut left: Vec<usize> = (0..k).rev().filter(|&d| self.has_vertex(d)).collect();
        // the quotient and the points left as they were when lifted to the space's lift
        // level: if they cannot leave there, level 0 takes them from it
        type Kept<E> = Option<(Box<E>, Vec<usize>)>;
        let mut before_lift: Kept<Self> = None;
        let from_level_0 = |e: &mut Self, left: &mut Vec<usize>, kept: &mut Kept<Self>| {
            if let Some((quotient, was_left)) = kept.take() {
                (*e, *left) = (*quotient, was_left);
            }
            // (in the covering of level 0 every removal goes in place)
            e.unfold(0);
        };
        loop {
            while !left.is_empty() {
                let before = left.len();
                let mut refused = Vec::new();
                // (a refusal at the lift level changes nothing, unless it removed some
                // copies or lost the quotient: then level 0 takes over)
                let mut half_done = false;
                for &d in &left {
                    if !self.remove_copies(PointId::new(d)) {
                        if !self.one_sheeted && !self.at_lift_level() {
                            // (some of its copies may be gone)
                            return None;
                        }
                        half_done |=
                            !self.has_vertex(d) || self.at_lift_level() && self.lift == Lift::Lost;
                        refused.push(d);
                        if half_done {
                            break;
                        }
                    }
                }
                left = refused;
                if half_done {
                    from_level_0(self, &mut left, &mut before_lift);
                } else if left.len() == before {
                    if !self.space.translations_only() {
                        return None;
                    }
                    match self.space.lift_level() {
                        Some(lift) if self.one_sheeted => {
                            let holds = self.lift_criterion_holds(lift);
                            before_lift = Some((Box::new(self.clone()), left.clone()));
                            self.unfold(lift);
                            self.lift = if holds {
                                Lift::Criterion
                            } else {
                                Lift::Checked { stays: k }
                            };
                        }
                        Some(_) if self.at_lift_level() && self.lift == Lift::Criterion => {
                            self.lift = Lift::Checked { stays: k };
                        }
                        _ => from_level_0(self, &mut left, &mut before_lift),
                    }
                }
            }
            // (without its criterion the lift level is no triangulation for supersets)
            if self.unchecked_lift().is_some() && !self.try_one_sheet() {
                from_level_0(self, &mut left, &mut before_lift);
                continue;
            }
            break;
        }
        drop(before_lift);
        // down the ladder as far as the criterion allows (the quotient is tried after)
        self.descend();
        let mut moved = vec![PointId::NONE; k];
        for d in (0..k).rev() {
            let last = self.points.len() - 1;
            self.renumber_last_point(PointId::new(d));
            moved[d] = moved.get(last).copied().unwrap_or(PointId::new(last));
        }
        Some(moved)
    }

    /// During a bulk build from the dummy points `0..k`: those still there whose removal
    /// keeps the switch criterion leave now, while their stars are small (points on a few
    /// planes give each dummy, alone in the slab between two, a star that grows with the
    /// planes: wrapped at the end, its hole holds thousands of vertices). Nothing happens
    /// unless the criterion holds in the quotient, and it still holds after: each removal
    /// whose new cells would be too large for it is refused. Returns how many left.
    pub(crate) fn dummies_leave(&mut self, k: usize) -> usize {
        if !(self.one_sheeted && self.guaranteed) {
            return 0;
        }
        let mut gone = 0;
        for d in (0..k).rev() {
            if self.has_vertex(d) && self.remove_vertex_keeping(VertexId::new(d), true).is_ok() {
                gone += 1;
            }
        }
        gone
    }

    /// True in the covering of the space's lift level ([`OrbitSpace::lift_level`]).
    fn at_lift_level(&self) -> bool {
        self.level > self.last_level()
    }

    /// Whether every cell of the quotient keeps the criterion of `lift` (known when the
    /// quotient's holds, checked otherwise: removals in the quotient may have left larger
    /// cells), so that the covering of `lift` is triangulated for the points and every
    /// superset.
    fn lift_criterion_holds(&self, lift: usize) -> bool {
        if self.guaranteed {
            return true;
        }
        let limit = self.space.criterion_radius2(lift);
        let ids: Vec<CellId> = self.tds.ids().collect();
        ids.par_iter().all(|&c| self.cell_radius2(c) < limit)
    }

    /// True when point `d` of the 1-sheeted triangulation has a vertex (a dummy point that
    /// has not left).
    pub(crate) fn has_vertex(&self, d: usize) -> bool {
        self.vcell[self.vertex_of_point(PointId::new(d)).index()] != CellId::NONE
    }

    /// Removes every vertex of point `p` (one per sheet), which must not be the only point.
    /// False when the space does not allow it in place: the quotient would stop being a
    /// simplicial complex, a covering above level 0 would lose its criterion, or the lift
    /// level without it its simplicial complex ([`Self::remove_first_points`]). Then the
    /// triangulation is left unchanged (1-sheeted; mostly at the lift level) or half done
    /// (a covering): the caller triangulates the remaining points again.
    fn remove_copies(&mut self, p: PointId) -> bool {
        // (the quotient has one sheet: its vertex is the point's id)
        let sheets = self.space.sheets(self.level) as u32;
        if sheets > 1 && self.space.translations_only() {
            if let Some(done) = self.remove_congruent_copies(p) {
                return done;
            }
            if self.at_lift_level() && self.lift == Lift::Criterion {
                // (copies that are neighbours break the level's criterion)
                return false;
            }
        }
        (0..sheets).all(|s| self.remove_vertex(VertexId(p.0 * sheets + s)).is_ok())
    }

    /// In a covering whose sheets are translations, the triangulation is invariant under
    /// the group of its sheets, so the copies of `p` have congruent stars and their holes
    /// congruent Delaunay triangulations (the perturbation is the same for every copy).
    /// When no copy of `p` is in the star of another (then removing one leaves the others'
    /// stars as they were), the hole of the first is wrapped once and its cells are moved
    /// to each other copy's hole: a covering of level 0 wraps one hole instead of 27.
    /// `None` when copies are neighbours (the caller removes them one by one, or refuses at
    /// the lift level while its criterion holds).
    fn remove_congruent_copies(&mut self, p: PointId) -> Option<bool> {
        let sheets = self.space.sheets(self.level);
        let first = VertexId::new(p.index() * sheets);
        let star = self.star(first);
        let neighbours = star.iter().any(|&(c, _, _)| {
            let cell = self.tds.cells[c.index()];
            cell.v
                .iter()
                .any(|&u| u != first && self.vpoint[u.index()] == p)
        });
        if neighbours {
            return None;
        }
        let Ok(cells) = self.hole_cells(&star, false) else {
            return Some(false);
        };
        let (by_sheet, sum) = self.sheet_group();
        let moved = |g: usize, u: VertexId| {
            let (q, a) = (u.index() / sheets, u.index() % sheets);
            VertexId::new(q * sheets + sum[g * sheets + a])
        };
        // at the lift level without its criterion, the holes together (each alone was
        // checked) must leave the covering simplicial: checked before any changes
        if let Some(k) = self.unchecked_lift() {
            let mut stars = Vec::new();
            let mut filled = Vec::new();
            for (g, &t) in by_sheet.iter().enumerate() {
                stars.extend(self.star(moved(g, first)).iter().map(|s| s.0));
                filled.extend(cells.iter().map(|w| self.moved_cell(w, t, |u| moved(g, u))));
            }
            stars.sort_unstable();
            if !self.removal_keeps_simplicial(&stars, &filled, Some(k)) {
                return Some(false);
            }
        }
        let first_star = star.len();
        self.replace_star(first, &star, &cells);
        let home = first.index() % sheets;
        for (g, &t) in by_sheet.iter().enumerate() {
            let moved = |u: VertexId| moved(g, u);
            let copy = moved(first);
            if copy.index() % sheets == home {
                continue;
            }
            let star = self.star(copy);
            // the facets of the copy's hole, by their vertices: who is across each
            let mut across: FxHashMap<[VertexId; N], (CellId, usize)> = FxHashMap::default();
            for &(c, i, _) in &star {
                let cell = self.tds.cells[c.index()];
                let d = cell.n[i];
                across.insert(facet_key(&cell.v, i), (d, self.mirror_of(d, c)));
            }
            // (congruent stars: as many cells, each outer facet found below)
            let mut ok = star.len() == first_star;
            let copied: Filling<S, N> = cells
                .iter()
                .map(|w| {
                    let mut w = self.moved_cell(w, t, moved);
                    for (m, link) in w.links.iter_mut().enumerate() {
                        if let Some(Owner::Old(..)) = link {
                            let old = across.get(&facet_key(&w.vids, m)).copied();
                            ok &= old.is_some();
                            *link = old.map(|(d, j)| Owner::Old(d, j));
                        }
                    }
                    w
                })
                .collect();
            debug_assert!(ok, "the copies' stars are congruent");
            if ok {
                self.replace_star(copy, &star, &copied);
            } else if self.remove_vertex(copy).is_err() {
                return Some(false);
            }
        }
        Some(true)
    }

    /// A cell of a hole's filling moved by the element `t` of the sheets' group, its
    /// vertices renamed by `moved`, its links as they were.
    fn moved_cell(
        &self,
        w: &Wrapped<S::Point, S::Elem, N>,
        t: S::Elem,
        moved: impl Fn(VertexId) -> VertexId,
    ) -> Wrapped<S::Point, S::Elem, N> {
        Wrapped {
            vids: w.vids.map(moved),
            arr: w.arr.map(|(x, o)| (x, self.space.compose(t, o))),
            links: w.links,
        }
    }

    /// At the lift level without its criterion: the points below this id are leaving, each
    /// removal checked to keep the covering simplicial instead ([`Self::remove_first_points`]).
    fn unchecked_lift(&self) -> Option<usize> {
        match self.lift {
            Lift::Checked { stays } if self.at_lift_level() => Some(stays),
            _ => None,
        }
    }

    /// After the vertices of point `p` were removed: the last point moves into its slot,
    /// each of its vertices (one per sheet) renamed in the cells around it.
    pub(super) fn renumber_last_point(&mut self, p: PointId) {
        let last = self.points.len() - 1;
        let sheets = self.space.sheets(self.level);
        if p.index() != last {
            for k in 0..sheets {
                let from = VertexId::new(last * sheets + k);
                let to = VertexId::new(p.index() * sheets + k);
                for (c, i, _) in self.star(from) {
                    self.tds.cells[c.index()].v[i] = to;
                }
                self.vcell[to.index()] = self.vcell[from.index()];
            }
            self.points[p.index()] = self.points[last];
            if self.weighted {
                self.weights[p.index()] = self.weights[last];
            }
            self.relocate(p.index());
        }
        self.pop_point();
        self.vpoint.truncate(last * sheets);
        self.vcell.truncate(last * sheets);
    }

    /// Moves point `p` to `to` (a canonical point of the domain), keeping its id: by
    /// changing its coordinates alone when the cells around it stay Delaunay
    /// ([`Self::try_move`]), else in the 1-sheeted triangulation by removing its vertex and
    /// inserting it again from the cells that filled the hole, where the walk is short.
    pub fn move_point(&mut self, p: PointId, to: S::Point) -> Moved {
        if self.try_move(p, to) {
            self.note_vertex(self.vertex_of_point(p), self.space.spatial_key(&to));
            return Moved::Coordinates;
        }
        let v = self.vertex_of_point(p);
        // (a move that may hide points or uncover hidden ones is left to the caller, who
        // removes and inserts)
        if self.hides()
            || !self.one_sheeted
            || self.points.len() == self.anchors + 1
            || self.remove_vertex(v).is_err()
        {
            return Moved::Refused;
        }
        self.points[p.index()] = to;
        // (the walk starts from the cells that filled the hole)
        match self.insert_lifted((to, self.space.identity()), v, true, None) {
            Ok(()) => {
                if !self.guaranteed && self.big_count == 0 {
                    self.set_guaranteed(true);
                }
                self.note_vertex(v, self.space.spatial_key(&to));
                Moved::Reinserted
            }
            Err(Refused::Duplicate(w)) => {
                let last = PointId::new(self.points.len() - 1);
                let q = self.point_of(w);
                self.renumber_last_point(p);
                Moved::Duplicate(if q == last { p } else { q })
            }
            Err(Refused::NotSimplicial) => {
                self.rebuild_in_covering();
                Moved::Rebuilt
            }
            Err(Refused::Hidden) => unreachable!("a space that hides points never gets here"),
        }
    }

    /// Moves point `p` to `to` (a canonical point of the domain) by changing its
    /// coordinates alone, when that leaves a Delaunay triangulation: every cell around it
    /// positively oriented and every facet of those cells locally Delaunay (CGAL's
    /// `move_if_no_collision` test), and the criterion of the quotient still holding. The
    /// star then stays a star-shaped triangulation around `to`, so `to` meets no other
    /// point. Returns false, with nothing changed, otherwise (then remove and insert).
    pub fn try_move(&mut self, p: PointId, to: S::Point) -> bool {
        if !(self.one_sheeted && self.guaranteed) || self.hides() {
            return false;
        }
        let v = self.vertex_of_point(p);
        let star = self.star(v);
        let old = std::mem::replace(&mut self.points[p.index()], to);
        let limit = self.space.criterion_radius2(self.last_level());
        let cells: Vec<LiftedCell<S, N>> = star.iter().map(|s| self.lifted_cell(s.0)).collect();
        let shaped = cells.iter().all(|cell| {
            self.space.orient(cell) == Sign::Positive && self.space.circumradius2(cell) < limit
        });
        let ids: Vec<CellId> = star.iter().map(|s| s.0).collect();
        let delaunay = shaped
            && star.iter().zip(&cells).all(|(&(c, i, _), cell)| {
                (0..N).all(|k| {
                    let d = self.tds.cells[c.index()].n[k];
                    // a facet between two star cells is tested from one side
                    if k != i && d < c && ids.contains(&d) {
                        return true;
                    }
                    let dc = self.tds.cell(d);
                    let j = dc.mirror(c).expect("symmetric neighbours");
                    let opposite = (
                        self.points[self.point_of(dc.v[j]).index()],
                        self.space.compose(self.translation(c, k, d), dc.off[j]),
                    );
                    self.space.in_sphere(cell, opposite) == Sign::Negative
                })
            });
        if !delaunay {
            self.points[p.index()] = old;
        }
        delaunay
    }

    /// Removes vertex `v`. In the quotient, when the new cells break the switch criterion,
    /// or it already does not hold, the removal goes ahead only if the quotient stays a
    /// simplicial complex (Theorem 2.2.8); in a covering above level 0, only if they keep
    /// the criterion of its level (level 0 is a triangulation for every point set that
    /// keeps a copy of each other point), or at the lift level without its criterion if
    /// the covering stays a simplicial complex. Otherwise nothing changes.
    pub(crate) fn remove_vertex(&mut self, v: VertexId) -> Result<(), RemoveError> {
        self.remove_vertex_keeping(v, false)
    }

    /// [`Self::remove_vertex`]; with `criterion`, refused also in the quotient when the new
    /// cells break the switch criterion.
    fn remove_vertex_keeping(&mut self, v: VertexId, criterion: bool) -> Result<(), RemoveError> {
        let star = self.star(v);
        let cells = self.hole_cells(&star, criterion)?;
        self.replace_star(v, &star, &cells);
        Ok(())
    }

    /// The Delaunay triangulation of the hole that removing the vertex whose star is `star`
    /// leaves, found by gift wrapping, when the space allows it (see
    /// [`Self::remove_vertex_keeping`]; the cells are not changed).
    fn hole_cells(
        &mut self,
        star: &[(CellId, usize, S::Elem)],
        criterion: bool,
    ) -> Result<Filling<S, N>, RemoveError> {
        let shifted = |e: &Self, c: CellId, shift: S::Elem| -> LiftedCell<S, N> {
            e.lifted_cell(c)
                .map(|(p, o)| (p, e.space.compose(shift, o)))
        };
        let mut hole: Vec<Candidate<S, N>> = Vec::new();
        let mut seeds = Vec::with_capacity(star.len());
        for &(c, i, shift) in star {
            let mut arr = shifted(self, c, shift);
            let cell = self.tds.cells[c.index()];
            for k in (0..N).filter(|&k| k != i) {
                hole.push((cell.v[k], arr[k]));
            }
            let d = cell.n[i];
            let j = self.mirror_of(d, c);
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
        // each vertex once, as the first cell that holds it lifts it
        let mut keep: Vec<u32> = (0..hole.len() as u32).collect();
        keep.sort_unstable_by_key(|&k| (hole[k as usize].0, k));
        keep.dedup_by_key(|k| hole[*k as usize].0);
        keep.sort_unstable();
        let hole: Vec<Candidate<S, N>> = keep.iter().map(|&k| hole[k as usize]).collect();
        let near = self.near(&hole);
        let cells = self
            .wrap(
                seeds,
                |_, _, _| Cow::Borrowed(&hole[..]),
                Vec::new(),
                false,
                near.as_ref(),
            )
            .ok_or(RemoveError::NotSimplicial)?;
        let limit = self.space.criterion_radius2(self.level);
        let breaks =
            limit.is_finite() && cells.iter().any(|w| self.radius2(&w.arr, &w.vids) >= limit);
        // (at the lift level without its criterion, checked as the quotient without its own)
        let unchecked = self.unchecked_lift().is_some();
        if (!self.one_sheeted || criterion) && !unchecked {
            if breaks {
                return Err(RemoveError::NotSimplicial);
            }
        } else if breaks || !self.guaranteed || unchecked {
            let mut star_ids: Vec<CellId> = star.iter().map(|s| s.0).collect();
            star_ids.sort_unstable();
            if !self.removal_keeps_simplicial(&star_ids, &cells, self.unchecked_lift()) {
                return Err(RemoveError::NotSimplicial);
            }
            if self.one_sheeted {
                self.set_guaranteed(false);
            }
        }
        Ok(cells)
    }

    /// Replaces the star of `v` by the cells of its hole.
    fn replace_star(
        &mut self,
        v: VertexId,
        star: &[(CellId, usize, S::Elem)],
        cells: &[Wrapped<S::Point, S::Elem, N>],
    ) {
        for &(c, _, _) in star {
            self.kill_cell(c);
        }
        self.commit(cells);
        self.vcell[v.index()] = CellId::NONE;
        // (in a covering, the criterion's count goes on: `descend` uses it)
        if self.one_sheeted && !self.guaranteed && self.big_count == 0 {
            self.set_guaranteed(true);
        }
    }

    /// True when replacing the cells `star` (sorted) by `cells` leaves no cycle of length
    /// ≤ 2: at every vertex of the new cells, the edges (kept old ones and new ones) reach
    /// each neighbour with a single offset and never the vertex itself. With `Some(k)`,
    /// also none in the quotient between points `k` and more (the points that stay while
    /// those below `k` leave), whose edges every later removal keeps: at such a point, its
    /// edges to such points reach each by a single element and never the point itself.
    fn removal_keeps_simplicial(
        &mut self,
        star: &[CellId],
        cells: &[Wrapped<S::Point, S::Elem, N>],
        stays: Option<usize>,
    ) -> bool {
        // the new cells' edges, by their first vertex
        let mut new: Vec<(VertexId, VertexId, S::Elem)> = Vec::new();
        for w in cells {
            for i in 0..N {
                for j in (0..N).filter(|&j| j != i) {
                    let e = self.space.relative(w.arr[j].1, w.arr[i].1);
                    new.push((w.vids[i], w.vids[j], e));
                }
            }
        }
        new.sort_unstable_by_key(|e| e.0);
        let mut edges: Vec<(VertexId, S::Elem)> = Vec::new();
        let mut points: Vec<(PointId, S::Elem)> = Vec::new();
        let mut stack: Vec<CellId> = Vec::new();
        for at in new.chunk_by(|x, y| x.0 == y.0) {
            let a = at[0].0;
            edges.clear();
            edges.extend(at.iter().map(|&(_, u, e)| (u, e)));
            // the old cells around `a` that stay
            let (mark, _) = self.tds.new_visit();
            stack.clear();
            stack.push(self.vcell[a.index()]);
            self.tds.set_stamp(stack[0], mark);
            while let Some(c) = stack.pop() {
                let cell = self.tds.cell(c);
                let i = cell.index_of(a).expect("the star of a vertex holds it");
                for k in (0..N).filter(|&k| k != i) {
                    if star.binary_search(&c).is_err() {
                        edges.push((cell.v[k], self.space.relative(cell.off[k], cell.off[i])));
                    }
                    let d = cell.n[k];
                    if self.tds.stamp(d) != mark {
                        self.tds.set_stamp(d, mark);
                        stack.push(d);
                    }
                }
            }
            if !single_edges(a, &mut edges) {
                return false;
            }
            let point = |u: VertexId| self.vpoint[u.index()];
            if let Some(k) = stays.filter(|&k| point(a).index() >= k) {
                points.clear();
                let kept = edges.iter().filter(|&&(u, _)| point(u).index() >= k);
                points.extend(kept.map(|&(u, e)| (point(u), e)));
                if !single_edges(point(a), &mut points) {
                    self.lift = Lift::Lost;
                    return false;
                }
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;

    use crate::delaunay::{from_dummies, uniform_cube, Engine};
    use crate::ids::{PointId, VertexId};
    use crate::sort::SplitMix;
    use crate::space::{FlatTorus3, OrbitSpace};

    /// Every cell as its points' coordinates (bits) and offsets, sorted, the first offset
    /// translated to zero: comparable whatever the point ids and the cells' storage.
    fn geometry(e: &Engine<FlatTorus3, 4>) -> BTreeSet<Vec<([u64; 3], [i8; 3])>> {
        e.tds
            .ids()
            .map(|c| {
                let mut cell: Vec<([u64; 3], [i8; 3])> = e
                    .lifted_cell(c)
                    .iter()
                    .map(|(p, o)| (p.map(f64::to_bits), *o))
                    .collect();
                cell.sort_unstable();
                let o = cell[0].1;
                cell.iter()
                    .map(|&(p, q)| (p, [0, 1, 2].map(|i| q[i] - o[i])))
                    .collect()
            })
            .collect()
    }

    /// Dummy points leave a bulk build early only when the switch criterion still holds
    /// after: on four planes, dense enough, all of them; in a slab beside a vacuum, not
    /// those alone in the vacuum (a second try removes none and changes nothing). Every
    /// cell is then within the criterion, and the dummies' removal at the end skips those
    /// gone and gives the triangulation of the points alone.
    #[test]
    fn dummy_points_leave_early_only_when_the_criterion_stays() {
        for (name, slab) in [("planes", None), ("slab", Some(0.05))] {
            let (mut e, pts) = from_dummies(slab);
            let k = e.space.dummy_points().len();
            let gone = e.dummies_leave(k);
            match slab {
                None => assert_eq!(gone, k, "{name}"),
                Some(_) => assert!(0 < gone && gone < k, "{name}: {gone} of {k} left"),
            }
            assert!(e.one_sheeted && e.guaranteed, "{name}");
            let limit = e.space.criterion_radius2(e.level);
            assert!(e.tds.ids().all(|c| e.cell_radius2(c) < limit), "{name}");
            let cells = geometry(&e);
            assert_eq!(e.dummies_leave(k), 0, "{name}");
            assert!(geometry(&e) == cells, "{name}");
            assert!(e.remove_first_points(k).is_some(), "{name}");
            e.is_valid().unwrap();
            let mut fresh = Engine::new(e.space.clone());
            for &p in &pts {
                fresh.insert(p);
            }
            assert!(geometry(&e) == geometry(&fresh), "{name}");
        }
    }

    /// The dummy points left in the quotient leave in the covering of 8 sheets (twice the
    /// systole): a slab beside a vacuum keeps that level's criterion, and stays there. A
    /// ball and a hollow shell break it, but each removal keeps the covering simplicial,
    /// and the points reach the quotient. A bar beside a vacuum and a tiny cube keep
    /// edges that make the quotient no triangulation: the quotient as it was goes to level
    /// 0. Each time the quotient alone could not take them all, and the result has the
    /// cells of the points inserted one by one, valid on the way.
    #[test]
    fn the_last_dummy_points_leave_in_the_lift_covering_when_it_allows() {
        // (name, the level they left from: 2 is the lift level)
        let cases = [
            ("slab", 2),
            ("ball", 1),
            ("shell", 1),
            ("bar", 0),
            ("tiny", 0),
        ];
        for (name, from) in cases {
            let space = FlatTorus3::cuboid([1.0; 3]).unwrap();
            let mut e = Engine::new(space.clone());
            e.points = space.dummy_points();
            let k = e.points.len();
            e.bootstrap_one_sheeted();
            let mut r = SplitMix::new(7);
            let pts: Vec<[f64; 3]> = std::iter::repeat_with(|| {
                let u = [r.unit(), r.unit(), r.unit()];
                let c = u.map(|x| 2.0 * x - 1.0);
                let d2: f64 = c.iter().map(|x| x * x).sum();
                match name {
                    "slab" => Some([u[0], u[1], 0.1 * u[2]]),
                    "bar" => Some([0.6 * u[0], u[1], 0.1 * u[2]]),
                    "tiny" => Some(u.map(|x| 0.5 + 0.002 * x)),
                    "ball" => (d2 <= 1.0).then(|| c.map(|x| 0.5 + 0.2 * x)),
                    _ => (d2 <= 1.0 && d2 > 0.9).then(|| c.map(|x| 0.5 + 0.3 * x / d2.sqrt())),
                }
            })
            .flatten()
            .take(3000)
            .collect();
            for &p in &pts {
                e.insert(p);
            }
            e.dummies_leave(k);
            // the quotient alone, round after round, cannot take them all: they leave from
            // a covering (so ending in the quotient means the lift level checked them)
            let mut quotient = e.clone();
            let mut left: Vec<usize> = (0..k).filter(|&d| e.has_vertex(d)).collect();
            loop {
                let before = left.len();
                left.retain(|&d| quotient.remove_vertex(VertexId::new(d)).is_err());
                if left.len() == before {
                    break;
                }
            }
            assert!(!left.is_empty(), "{name}: the quotient keeps dummies");
            assert!(e.remove_first_points(k).is_some(), "{name}");
            e.is_valid().unwrap();
            let lift = e.space.lift_level().expect("a 3D grid has a lift level");
            assert_eq!(lift, 2);
            assert_eq!(e.level, from, "{name}");
            let mut fresh = Engine::new(space.clone());
            for &p in &pts {
                fresh.insert(p);
            }
            assert_eq!(e.try_one_sheet(), fresh.try_one_sheet(), "{name}");
            e.is_valid().unwrap();
            assert_eq!(e.level, fresh.level, "{name}");
            assert!(geometry(&e) == geometry(&fresh), "{name}");
        }
    }

    /// In a covering, the copies of a point leave as one hole wrapped and moved to the
    /// others: the same cells as removing each copy's vertex in turn. A point whose copies
    /// are neighbours is left to that way, unchanged.
    #[test]
    fn copies_leave_a_covering_as_congruent_holes() {
        let (mut moved, mut declined) = (0, 0);
        for (n, seed) in [(3, 1), (5, 2), (24, 3), (40, 4)] {
            for p in [0, n / 2, n - 1].map(PointId::new) {
                let (mut a, mut b) = (uniform_cube(n, seed), uniform_cube(n, seed));
                let sheets = a.space.sheets(a.level);
                assert!(sheets > 1, "{n} points stay in a covering");
                let before = geometry(&a);
                match a.remove_congruent_copies(p) {
                    None => {
                        declined += 1;
                        assert!(geometry(&a) == before, "{n} points, point {p:?}");
                    }
                    Some(done) => {
                        moved += 1;
                        let one_by_one = (0..sheets).all(|s| {
                            b.remove_vertex(VertexId::new(p.index() * sheets + s))
                                .is_ok()
                        });
                        assert_eq!(done, one_by_one, "{n} points, point {p:?}");
                        a.renumber_last_point(p);
                        b.renumber_last_point(p);
                        a.is_valid().unwrap();
                        assert!(geometry(&a) == geometry(&b), "{n} points, point {p:?}");
                        assert!(geometry(&a) != before, "{n} points, point {p:?}");
                    }
                }
            }
        }
        assert!(
            moved > 0 && declined > 0,
            "{moved} moved, {declined} declined"
        );
    }

    /// The first `k` points leave and the last take their ids, the others keep theirs; the
    /// map names each moved point's first id, also when points move twice (fewer than `k`
    /// stay), and the triangulation is that of the points left.
    #[test]
    fn removing_the_first_points_moves_the_last_into_their_ids() {
        for (n, k) in [(400, 36), (400, 300)] {
            let mut e = uniform_cube(n, 5);
            let before = e.points.clone();
            let moved = e.remove_first_points(k).expect("in place");
            assert_eq!(e.points.len(), n - k);
            e.is_valid().unwrap();
            assert!(e.is_one_sheeted());
            for (q, p) in e.points.iter().enumerate() {
                let first = if q < k { moved[q].index() } else { q };
                assert!(first >= k, "point {q} came from a removed id {first}");
                assert_eq!(*p, before[first], "point {q}");
            }
            let mut left: Vec<_> = e.points.clone();
            let mut want = before[k..].to_vec();
            left.sort_by(|a, b| a.partial_cmp(b).unwrap());
            want.sort_by(|a, b| a.partial_cmp(b).unwrap());
            assert_eq!(left, want);
        }
    }
}
