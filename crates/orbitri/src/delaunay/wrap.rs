//! Gift wrapping in the lifted space: closes open facets one by one with the Delaunay apex
//! among given candidates (the pencil of spheres through a facet is totally ordered by the
//! perturbed in-sphere test, so one pass finds the apex). It builds the first triangulation
//! of a space and fills the hole left by a removed vertex.

use std::borrow::Cow;

use rustc_hash::FxHashMap;

use super::ball_index::BallIndex;
use super::{Candidate, Engine, LiftedCell};
use crate::ids::{CellId, VertexId};
use crate::predicates::filter::{HUGE, TINY};
use crate::predicates::Sign;
use crate::space::{Lifted, OrbitSpace};
use crate::voronoi::{cross, dot, sub};

/// A facet's best apex so far: vertex id, the cell it makes (positively oriented) and its
/// vertex ids.
type Apex<S, const N: usize> = (VertexId, LiftedCell<S, N>, [VertexId; N]);

/// The fewest candidates that [`Engine::near`] indexes: below, trying them all is cheaper.
const NEAR_FEWEST: usize = 64;

/// The candidates of a large hole indexed by position (in their order), a bound on the
/// rounding of every position, and their largest weight.
pub(super) struct Near {
    index: BallIndex,
    eps: f64,
    wmax: f64,
}

/// A facet to close: vertex ids, lifted simplex, slot of the apex, side, owner.
pub(super) type Seed<S, const N: usize> = ([VertexId; N], LiftedCell<S, N>, usize, bool, Owner);

fn norm(a: &[f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Who is on the other side of an open facet.
#[derive(Clone, Copy, Debug)]
pub(super) enum Owner {
    /// An existing cell and its facet index.
    Old(CellId, usize),
    /// A new cell (index into the result) and its facet index.
    New(usize, usize),
}

/// A facet waiting for its cell: the lifted simplex `arr` whose slot `idx` is to be
/// replaced by the apex, on the side of `arr[idx]` when `toward`, else on the other side.
struct Open<P, O, const N: usize> {
    vids: [VertexId; N],
    arr: [Lifted<P, O>; N],
    idx: usize,
    toward: bool,
    owner: Owner,
}

/// A cell produced by wrapping, in the common frame of the candidates.
#[derive(Clone, Debug)]
pub(super) struct Wrapped<P, O, const N: usize> {
    pub vids: [VertexId; N],
    pub arr: [Lifted<P, O>; N],
    pub links: [Option<Owner>; N],
}

pub(super) fn facet_key<const N: usize>(vids: &[VertexId; N], skip: usize) -> [VertexId; N] {
    let mut k = *vids;
    k[skip] = VertexId::NONE;
    k.sort_unstable();
    k
}

impl<S: OrbitSpace<N>, const N: usize> Engine<S, N> {
    /// The candidates indexed by position, when there are many and the space places them.
    pub(super) fn near(&self, cands: &[Candidate<S, N>]) -> Option<Near> {
        if cands.len() < NEAR_FEWEST {
            return None;
        }
        let mut eps = 0.0f64;
        let pos = cands
            .iter()
            .map(|c| {
                let (x, e) = self.space.ball_position(c.1)?;
                eps = eps.max(e);
                x.iter().all(|v| v.is_finite()).then_some(x)
            })
            .collect::<Option<Vec<_>>>()?;
        let wmax = cands
            .iter()
            .map(|c| self.vertex_weight(c.0))
            .fold(f64::NEG_INFINITY, f64::max);
        (eps.is_finite() && wmax.is_finite()).then(|| Near {
            index: BallIndex::new(pos),
            eps,
            wmax,
        })
    }

    /// The Delaunay apex for an open facet among `cands` (vertex id, lifted point), the
    /// candidates near its sphere only when `near` indexes them (see [`Near`]).
    fn pivot(
        &self,
        f: &Open<S::Point, S::Elem, N>,
        cands: &[Candidate<S, N>],
        near: Option<&Near>,
    ) -> Option<(VertexId, LiftedCell<S, N>)> {
        if let Some(apex) = near.and_then(|near| self.pivot_near(f, cands, near)) {
            debug_assert!(
                apex == self.pivot(f, cands, None),
                "the index misses the apex"
            );
            return apex;
        }
        let mut best = None;
        for (vid, y) in cands {
            self.contest(f, (*vid, *y), &mut best);
        }
        best.map(|(vid, s, _)| (vid, s))
    }

    /// The candidate `c` against the facet's best apex so far: it takes its place when it
    /// lies on the facet's side and in the best's sphere (or there is none yet). Returns
    /// whether it lies on that side.
    fn contest(
        &self,
        f: &Open<S::Point, S::Elem, N>,
        (vid, y): Candidate<S, N>,
        best: &mut Option<Apex<S, N>>,
    ) -> bool {
        if f.vids
            .iter()
            .enumerate()
            .any(|(k, &v)| k != f.idx && v == vid)
        {
            return false;
        }
        let mut s = f.arr;
        s[f.idx] = y;
        let want = if f.toward {
            Sign::Positive
        } else {
            Sign::Negative
        };
        if self.space.orient(&s) != want {
            return false;
        }
        let mut vids = f.vids;
        vids[f.idx] = vid;
        if !f.toward {
            s.swap((f.idx + 1) % N, (f.idx + 2) % N);
            vids.swap((f.idx + 1) % N, (f.idx + 2) % N);
        }
        match best {
            Some((_, b, bv)) if !self.in_conflict(b, bv, y, self.vertex_weight(vid)) => {}
            _ => *best = Some((vid, s, vids)),
        }
        true
    }

    /// [`Self::pivot`] through the index. First a candidate on the facet's side, likely
    /// the apex or near it: the spheres through the facet's circle are ordered by the
    /// height of their center over it, the apex's the lowest, and a best-first search of
    /// the index meets the candidates clearly off the facet's plane about in that order,
    /// at rounded positions, until one is on the side (points on the plane, whose
    /// orientation takes the exact arithmetic, are not tried). Then only the candidates in
    /// the ball of its sphere: every candidate that beats it lies in that sphere, so the
    /// answer does not depend on the first step's guesses. `None` when rounded positions
    /// cannot be trusted here (no position, a flat facet or first cell, no candidate found
    /// clearly off the plane): the caller then tries them all.
    fn pivot_near(
        &self,
        f: &Open<S::Point, S::Elem, N>,
        cands: &[Candidate<S, N>],
        near: &Near,
    ) -> Option<Option<(VertexId, LiftedCell<S, N>)>> {
        debug_assert_eq!(
            near.index.len(),
            cands.len(),
            "the index is of these candidates"
        );
        let mut at = [[0.0; 3]; N];
        for (k, p) in at.iter_mut().enumerate() {
            *p = self.space.ball_position(f.arr[k])?.0;
        }
        let rest: Vec<[f64; 3]> = (0..N).filter(|&k| k != f.idx).map(|k| at[k]).collect();
        // the facet's normal and its circle (center `o`, squared radius `rr`)
        let e: [[f64; 3]; 2] = std::array::from_fn(|i| {
            std::array::from_fn(|c| rest[(i + 1).min(N - 2)][c] - rest[0][c])
        });
        let (n, o) = if N == 4 {
            let n = cross(&e[0], &e[1]);
            let w: [f64; 3] =
                std::array::from_fn(|c| dot(&e[0], &e[0]) * e[1][c] - dot(&e[1], &e[1]) * e[0][c]);
            let m = cross(&w, &n);
            let k = 2.0 * dot(&n, &n);
            (n, std::array::from_fn(|c| rest[0][c] + m[c] / k))
        } else {
            let n = [-e[0][1], e[0][0], 0.0];
            (n, std::array::from_fn(|c| rest[0][c] + e[0][c] / 2.0))
        };
        let rr = dot(&sub(&rest[0], &o), &sub(&rest[0], &o));
        // toward the side of the point the apex replaces when `toward`, away otherwise
        let to_replaced = sub(&at[f.idx], &o);
        let h = dot(&n, &to_replaced);
        // (NaN fails too)
        let clear = h.abs() > 1e-9 * norm(&n) * norm(&to_replaced);
        if !clear || !rr.is_finite() {
            return None;
        }
        let unit = (if (h > 0.0) == f.toward { 1.0 } else { -1.0 }) / norm(&n);
        let n = n.map(|x| x * unit);
        // the spheres through the facet's circle, by the height of their center over it:
        // that of a candidate clearly on the side, and a box's priority (a lower bound
        // outside the facet's ball, a guess inside it)
        let height = |y: &[f64; 3]| {
            let v = sub(y, &o);
            let h = dot(&n, &v);
            (h > 1e-9 * norm(&v)).then(|| (dot(&v, &v) - rr) / (2.0 * h))
        };
        let bound = |lo: &[f64; 3], hi: &[f64; 3]| {
            let (mut d2, mut high) = (0.0, 0.0);
            for c in 0..3 {
                let e = (lo[c] - o[c]).max(o[c] - hi[c]).max(0.0);
                d2 += e * e;
                high += (n[c] * (lo[c] - o[c])).max(n[c] * (hi[c] - o[c]));
            }
            if high <= 0.0 {
                f64::INFINITY
            } else {
                (d2 - rr) / (2.0 * high)
            }
        };
        let mut best = None;
        let first = near.index.first_by(bound, height, |j| {
            self.contest(f, cands[j as usize], &mut best)
        })?;
        let (vid, s, vids) = best?;
        let ball = self.ball(&s, &vids, near)?;
        let mut list = Vec::new();
        near.index.within(ball.0, ball.1, &mut list);
        best = Some((vid, s, vids));
        for &j in list.iter().filter(|&&j| j != first) {
            self.contest(f, cands[j as usize], &mut best);
        }
        Some(best.map(|(vid, s, _)| (vid, s)))
    }

    /// A ball (center, radius) that holds the rounded position of every candidate of
    /// `near` in conflict with the cell `s` (vertex ids `vids`), whatever the rounding of
    /// the positions; `None` when the rounding could make the cell flat, or its edges are
    /// so short or long that products of them could underflow or overflow.
    ///
    /// The center `c` is solved from the rounded positions. With the exact ones `x̃_i`,
    /// `g_i(c) = |x̃_i − c|² − w_i − |x̃_0 − c|² + w_0` is `−2(x̃_i − x̃_0)·(c − c*)` for
    /// the exact orthocenter `c*`, so `|c − c*| ≤ ‖D̃⁻¹‖·|g|/2`, where `D̃`'s rows are the
    /// exact edge vectors; `g` is evaluated at the rounded positions with the rounding's
    /// effect added, and `‖D̃⁻¹‖ ≤ 2·‖adj D‖/|det D|` for the rounded `D` while the
    /// difference of the two, `η`, keeps `η·‖adj D‖/|det D| ≤ 1/2`.
    fn ball(
        &self,
        s: &LiftedCell<S, N>,
        vids: &[VertexId; N],
        near: &Near,
    ) -> Option<([f64; 3], f64)> {
        const U: f64 = f64::EPSILON;
        let mut x = [[0.0; 3]; N];
        let mut eps = near.eps;
        for (xi, si) in x.iter_mut().zip(s) {
            let (p, e) = self.space.ball_position(*si)?;
            (*xi, eps) = (p, eps.max(e));
        }
        let w: [f64; N] = std::array::from_fn(|i| self.vertex_weight(vids[i]));
        let mut d = [[0.0; 3]; 3];
        let mut rhs = [0.0; 3];
        for i in 1..N {
            d[i - 1] = sub(&x[i], &x[0]);
            rhs[i - 1] = (dot(&d[i - 1], &d[i - 1]) - (w[i] - w[0])) / 2.0;
        }
        let len: [f64; 3] = std::array::from_fn(|i| norm(&d[i]));
        // (edges in [2⁻²⁰⁰, 2²⁰⁰]: no product below keeps or loses a subnormal that matters
        // against the error terms, and none overflows)
        let tame = TINY..=HUGE;
        if !len[..N - 1].iter().all(|l| tame.contains(l)) {
            return None;
        }
        // the center `x_0 + z`, `d_i·z = rhs_i` by Cramer's rule; the adjugate's norm and
        // the determinant's rounding error (a multiple of the product of the rows' norms)
        let (z, det, adj, det_err) = if N == 4 {
            let (c12, c20, c01) = (
                cross(&d[1], &d[2]),
                cross(&d[2], &d[0]),
                cross(&d[0], &d[1]),
            );
            let det = dot(&d[0], &c12);
            let z = std::array::from_fn(|c| {
                (rhs[0] * c12[c] + rhs[1] * c20[c] + rhs[2] * c01[c]) / det
            });
            let adj = (dot(&c12, &c12) + dot(&c20, &c20) + dot(&c01, &c01)).sqrt()
                + 8.0 * U * (len[1] * len[2] + len[2] * len[0] + len[0] * len[1]);
            (z, det, adj, 16.0 * U * len[0] * len[1] * len[2])
        } else {
            let det = d[0][0] * d[1][1] - d[0][1] * d[1][0];
            let z = [
                (rhs[0] * d[1][1] - rhs[1] * d[0][1]) / det,
                (d[0][0] * rhs[1] - d[1][0] * rhs[0]) / det,
                0.0,
            ];
            let adj = (len[0] * len[0] + len[1] * len[1]).sqrt() * (1.0 + 4.0 * U);
            (z, det, adj, 8.0 * U * len[0] * len[1])
        };
        let certain = det.abs() > 2.0 * det_err;
        let inverse = adj / (det.abs() - det_err);
        // the rounded edge vectors against the exact ones (Frobenius norm); (NaN fails)
        let eta: f64 = (0..N - 1).map(|i| U * len[i] + 2.0 * eps).sum();
        let close = inverse * eta <= 0.5;
        if !certain || !close {
            return None;
        }
        let c: [f64; 3] = std::array::from_fn(|k| x[0][k] + z[k]);
        let rho: [f64; N] = std::array::from_fn(|i| norm(&sub(&x[i], &c)));
        // |g| ≤ Σ|g_i| (no square to underflow)
        let g: f64 = (1..N)
            .map(|i| {
                let r = rho[i] * rho[i] - rho[0] * rho[0] - (w[i] - w[0]);
                r.abs()
                    + 8.0 * U * (rho[i] * rho[i] + rho[0] * rho[0] + (w[i] - w[0]).abs())
                    + 2.0 * eps * (rho[i] + rho[0] + 2.0 * eps)
            })
            .sum();
        let off = 2.0 * inverse * g / 2.0;
        // a conflict at `y`: |y − c*|² − w_y < |x̃_0 − c*|² − w_0, and w_y ≤ wmax
        let reach = rho[0] * (1.0 + 2.0 * U) + eps + off;
        let spread = near.wmax - w[0];
        let r2 = reach * reach + spread + 8.0 * U * (reach * reach + spread.abs());
        let r = (r2.max(0.0).sqrt() + off + eps) * (1.0 + 8.0 * U);
        (r.is_finite() && c.iter().all(|v| v.is_finite())).then_some((c, r))
    }

    /// Closes every facet of `open` (and every facet the new cells leave open); the apex of
    /// a facet is taken from `candidates(vertex ids, simplex, slot to replace)`. Returns the new cells
    /// with their links, or `None` if some facet found no apex.
    ///
    /// With `recenter`, each new cell is moved into the canonical form of the current level
    /// (candidates are then searched around it): wrapping a whole covering visits its cells
    /// in a snake that may wander many periods away, and the group elements must stay small.
    pub(super) fn wrap<'c>(
        &self,
        seeds: Vec<Seed<S, N>>,
        mut candidates: impl FnMut(
            &[VertexId; N],
            &LiftedCell<S, N>,
            usize,
        ) -> Cow<'c, [Candidate<S, N>]>,
        mut first: Vec<Wrapped<S::Point, S::Elem, N>>,
        recenter: bool,
        near: Option<&Near>,
    ) -> Option<Vec<Wrapped<S::Point, S::Elem, N>>>
    where
        S::Point: 'c,
        S::Elem: 'c,
    {
        // a fast non-cryptographic hash: the keys are small vertex ids of our own
        let mut open: FxHashMap<[VertexId; N], Open<S::Point, S::Elem, N>> = FxHashMap::default();
        let mut queue: Vec<[VertexId; N]> = Vec::new();
        for (vids, arr, idx, toward, owner) in seeds {
            let key = facet_key(&vids, idx);
            queue.push(key);
            open.insert(
                key,
                Open {
                    vids,
                    arr,
                    idx,
                    toward,
                    owner,
                },
            );
        }
        while let Some(key) = queue.pop() {
            let Some(f) = open.remove(&key) else { continue };
            let cands = candidates(&f.vids, &f.arr, f.idx);
            let (vid, mut arr) = self.pivot(&f, &cands, near)?;
            let mut vids = f.vids;
            vids[f.idx] = vid;
            if !f.toward {
                vids.swap((f.idx + 1) % N, (f.idx + 2) % N);
            }
            // the slot of the facet just closed
            let mut idx = f.idx;
            if recenter {
                let mut off = arr.map(|x| x.1);
                let reversed = self.space.normalize(&mut off, self.level);
                for (a, o) in arr.iter_mut().zip(off) {
                    a.1 = o;
                }
                if reversed {
                    arr.swap(0, 1);
                    vids.swap(0, 1);
                    idx = [1, 0].get(idx).copied().unwrap_or(idx);
                }
            }
            let k = first.len();
            let mut links = [None; N];
            links[idx] = Some(f.owner);
            if let Owner::New(o, m) = f.owner {
                first[o].links[m] = Some(Owner::New(k, idx));
            }
            for (m, link) in links.iter_mut().enumerate() {
                if m == idx {
                    continue;
                }
                let fk = facet_key(&vids, m);
                if let Some(other) = open.remove(&fk) {
                    *link = Some(other.owner);
                    if let Owner::New(o, mm) = other.owner {
                        first[o].links[mm] = Some(Owner::New(k, m));
                    }
                } else {
                    queue.push(fk);
                    open.insert(
                        fk,
                        Open {
                            vids,
                            arr,
                            idx: m,
                            toward: false,
                            owner: Owner::New(k, m),
                        },
                    );
                }
            }
            first.push(Wrapped { vids, arr, links });
        }
        Some(first)
    }

    /// Creates the wrapped cells and links them; returns their ids.
    pub(super) fn commit(&mut self, cells: &[Wrapped<S::Point, S::Elem, N>]) -> Vec<CellId> {
        let ids: Vec<CellId> = cells
            .iter()
            .map(|w| self.make_cell(w.vids, w.arr.map(|(_, o)| o)))
            .collect();
        for (k, w) in cells.iter().enumerate() {
            for (m, link) in w.links.iter().enumerate() {
                let a = self.slot(ids[k], w.vids[m], m);
                match link.expect("every facet is closed") {
                    Owner::Old(d, j) => self.link(ids[k], a, d, j),
                    Owner::New(o, j) => {
                        let b = self.slot(ids[o], cells[o].vids[j], j);
                        self.link(ids[k], a, ids[o], b)
                    }
                }
            }
        }
        for &id in &ids {
            self.attach(id);
        }
        self.hint = ids[0];
        self.hint_shift = self.space.identity();
        ids
    }

    /// The first Delaunay cell with vertex `a`: the nearest candidates are tried first, and a
    /// cell is accepted when it is positively oriented, small enough for the candidates to
    /// cover its circumsphere, and empty.
    pub(super) fn first_cell(
        &self,
        a: Candidate<S, N>,
        cands: &[Candidate<S, N>],
        max_r2: f64,
    ) -> Option<Wrapped<S::Point, S::Elem, N>> {
        let others: Vec<Candidate<S, N>> = cands.iter().copied().filter(|c| c.0 != a.0).collect();
        let k = others.len();
        let mut pick = vec![0usize; N - 1];
        // enumerate (N−1)-subsets in colexicographic order: nearest candidates first
        for (i, p) in pick.iter_mut().enumerate() {
            *p = i;
        }
        if k < N - 1 {
            return None;
        }
        loop {
            let mut vids = [a.0; N];
            let mut s = [a.1; N];
            for (slot, &i) in pick.iter().enumerate() {
                vids[slot + 1] = others[i].0;
                s[slot + 1] = others[i].1;
            }
            let distinct = (0..N).all(|i| (i + 1..N).all(|j| vids[i] != vids[j]));
            let o = if distinct {
                self.space.orient(&s)
            } else {
                Sign::Zero
            };
            if o != Sign::Zero {
                if o == Sign::Negative {
                    s.swap(1, 2);
                    vids.swap(1, 2);
                }
                if self.space.circumradius2(&s) <= max_r2
                    && others.iter().all(|&(v, y)| {
                        vids.contains(&v) || !self.in_conflict(&s, &vids, y, self.vertex_weight(v))
                    })
                {
                    return Some(Wrapped {
                        vids,
                        arr: s,
                        links: [None; N],
                    });
                }
            }
            // next subset in colex order
            let mut i = 0;
            while i < N - 1 {
                let limit = if i + 1 < N - 1 { pick[i + 1] } else { k };
                if pick[i] + 1 < limit {
                    pick[i] += 1;
                    for (j, p) in pick.iter_mut().enumerate().take(i) {
                        *p = j;
                    }
                    break;
                }
                i += 1;
            }
            if i == N - 1 {
                return None;
            }
        }
    }

    /// Seeds for wrapping outward from a first cell: its facets, owned by itself.
    pub(super) fn seeds_of(w: &Wrapped<S::Point, S::Elem, N>) -> Vec<Seed<S, N>> {
        (0..N)
            .map(|m| (w.vids, w.arr, m, false, Owner::New(0, m)))
            .collect()
    }
}
