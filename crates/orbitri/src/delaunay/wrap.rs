//! Gift wrapping in the lifted space: closes open facets one by one with the Delaunay apex
//! among given candidates (the pencil of spheres through a facet is totally ordered by the
//! perturbed in-sphere test, so one pass finds the apex). It builds the first triangulation
//! of a space and fills the hole left by a removed vertex.

use std::borrow::Cow;

use rustc_hash::FxHashMap;

use super::{Candidate, Engine, LiftedCell};
use crate::ids::{CellId, VertexId};
use crate::predicates::Sign;
use crate::space::{Lifted, OrbitSpace};

/// A facet to close: vertex ids, lifted simplex, slot of the apex, side, owner.
pub(super) type Seed<S, const N: usize> = ([VertexId; N], LiftedCell<S, N>, usize, bool, Owner);

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
    /// The Delaunay apex for an open facet among `cands` (vertex id, lifted point).
    fn pivot(
        &self,
        f: &Open<S::Point, S::Elem, N>,
        cands: &[Candidate<S, N>],
    ) -> Option<(VertexId, LiftedCell<S, N>)> {
        let want = if f.toward {
            Sign::Positive
        } else {
            Sign::Negative
        };
        let mut best: Option<(VertexId, LiftedCell<S, N>, [VertexId; N])> = None;
        for &(vid, y) in cands {
            if f.vids
                .iter()
                .enumerate()
                .any(|(k, &v)| k != f.idx && v == vid)
            {
                continue;
            }
            let mut s = f.arr;
            s[f.idx] = y;
            if self.space.orient(&s) != want {
                continue;
            }
            let mut vids = f.vids;
            vids[f.idx] = vid;
            if !f.toward {
                s.swap((f.idx + 1) % N, (f.idx + 2) % N);
                vids.swap((f.idx + 1) % N, (f.idx + 2) % N);
            }
            match &best {
                Some((_, b, bv)) if !self.in_conflict(b, bv, y, self.vertex_weight(vid)) => {}
                _ => best = Some((vid, s, vids)),
            }
        }
        best.map(|(vid, s, _)| (vid, s))
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
            let (vid, mut arr) = self.pivot(&f, &cands)?;
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
