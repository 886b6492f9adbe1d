//! CGAL's *ghost faces*: for points in a closed hemisphere, the faces of the convex hull
//! that do not have the centre strictly inside (their empty cap is a hemisphere or more).
//! The engine covers that part of the hull with anchor cells; the ghost faces triangulate
//! the disk those cells bound, the *rim*, with the rim's vertices only (any other vertex
//! there would be inside the hull of the points and the centre: hidden).
//!
//! They come from gift wrapping over the rim's vertices, `O(k²)` for `k` of them, with the
//! exact and perturbed side test [`beyond`]: one consistent perturbation of the points, so
//! the faces close up into the hull of the perturbed points. A rim on one plane (a circle:
//! the common case of a cap, or a hemisphere with points on its great circle) is a convex
//! polygon; it is fanned from its greatest vertex, in `O(k)`.

use std::collections::{HashMap, HashSet};

use super::{collinear, SphericalSpace, SphericalTriangulation};
use crate::ids::{CellId, PointId};
use crate::predicates::spherical::{beyond, side_of_circle};
use crate::predicates::Sign;

/// The ghost faces and their adjacency.
#[derive(Debug, Default)]
pub(super) struct Ghosts {
    /// Engine points, counter-clockwise seen from outside the hull.
    pub faces: Vec<[PointId; 3]>,
    /// The ghost face holding each of its directed edges.
    pub by_edge: HashMap<(PointId, PointId), usize>,
    /// The solid face holding each directed edge of the rim.
    pub rim: HashMap<(PointId, PointId), CellId>,
}

impl Ghosts {
    /// The face across the edge opposite corner `k` of ghost face `f`: a ghost face, or
    /// the solid cell across the rim.
    pub fn across(&self, f: usize, k: usize) -> Result<usize, CellId> {
        let g = self.faces[f];
        let edge = (g[(k + 2) % 3], g[(k + 1) % 3]);
        match self.by_edge.get(&edge) {
            Some(&h) => Ok(h),
            None => Err(self.rim[&edge]),
        }
    }
}

impl<S: SphericalSpace> SphericalTriangulation<S> {
    /// The ghost faces: none when the faces cover the sphere (always on the projective
    /// plane, whose points come with their antipodes) or below dimension 2.
    pub(super) fn ghosts(&self) -> Ghosts {
        let e = &self.engine;
        let mut g = Ghosts::default();
        // (the dimension, a scan of every point, last)
        if S::ANTIPODAL || self.covers_sphere() || self.dimension() < 2 {
            return g;
        }
        for c in e.cell_ids().filter(|&c| self.is_face(c)) {
            let cell = e.cell(c);
            for k in (0..3).filter(|&k| !self.is_face(cell.n[k])) {
                let edge = (cell.v[(k + 1) % 3], cell.v[(k + 2) % 3]);
                g.rim.insert((e.point_of(edge.0), e.point_of(edge.1)), c);
            }
        }
        // each ghost face holds a reversed rim edge, or a ghost edge reversed
        let open: Vec<(PointId, PointId)> = g.rim.keys().map(|&(a, b)| (b, a)).collect();
        let at = |p: PointId| e.points()[p.index()];
        g.faces = fan(&open, at).unwrap_or_else(|| gift_wrap(open, at));
        for (f, face) in g.faces.iter().enumerate() {
            for k in 0..3 {
                g.by_edge.insert((face[k], face[(k + 1) % 3]), f);
            }
        }
        g
    }
}

/// The order of the tie-break: the lexicographic order of coordinates (as on the solid
/// faces).
fn later(a: &[f64; 3], b: &[f64; 3]) -> Sign {
    Sign::from(a.partial_cmp(b).expect("finite coordinates"))
}

/// The faces when the rim is one convex polygon on one plane: the fan from its greatest
/// vertex (counter-clockwise along the open edges). `None` otherwise.
fn fan(open: &[(PointId, PointId)], at: impl Fn(PointId) -> [f64; 3]) -> Option<Vec<[PointId; 3]>> {
    let next: HashMap<PointId, PointId> = open.iter().copied().collect();
    let (&first, _) = next.iter().next()?;
    // one cycle through every rim vertex
    let mut cycle = vec![first];
    while let Some(&w) = next.get(cycle.last()?) {
        if w == first {
            break;
        }
        if cycle.len() >= next.len() {
            return None;
        }
        cycle.push(w);
    }
    if cycle.len() != next.len() || next.len() != open.len() || cycle.len() < 3 {
        return None;
    }
    let pts: Vec<[f64; 3]> = cycle.iter().map(|&p| at(p)).collect();
    let c = pts[2..].iter().find(|c| !collinear(&pts[0], &pts[1], c))?;
    if pts
        .iter()
        .any(|q| side_of_circle(&pts[0], &pts[1], c, q) != Sign::Zero)
    {
        return None;
    }
    let m = (1..pts.len()).fold(0, |m, k| {
        if later(&pts[k], &pts[m]) == Sign::Positive {
            k
        } else {
            m
        }
    });
    let k = cycle.len();
    Some(
        (1..k - 1)
            .map(|i| [cycle[(m + i) % k], cycle[(m + i + 1) % k], cycle[m]])
            .collect(),
    )
}

/// The faces by gift wrapping: each open edge `u → w` gets the apex `c` among the rim's
/// vertices with none of them beyond the plane of `(u, w, c)`; the new face's other edges
/// close an open edge or open their reverse.
fn gift_wrap(open: Vec<(PointId, PointId)>, at: impl Fn(PointId) -> [f64; 3]) -> Vec<[PointId; 3]> {
    let mut ring: Vec<PointId> = open.iter().flat_map(|&(a, b)| [a, b]).collect();
    ring.sort_unstable();
    ring.dedup();
    // a disk bounded by `b` edges, no vertex inside: `b − 2` faces (a bound on the loop)
    let bound = open.len();
    let mut stack = open;
    stack.sort_unstable();
    let mut pending: HashSet<(PointId, PointId)> = stack.iter().copied().collect();
    let mut faces = Vec::new();
    while let Some((u, w)) = stack.pop() {
        if !pending.remove(&(u, w)) {
            continue;
        }
        let (pu, pw) = (at(u), at(w));
        let mut best: Option<(PointId, [f64; 3])> = None;
        for &q in ring.iter().filter(|&&q| q != u && q != w) {
            let pq = at(q);
            let better = best.is_none_or(|(_, pc)| {
                let pts = [pu, pw, pc, pq];
                beyond(&[pu, pw, pc], pq, |i, j| later(&pts[i], &pts[j])) == Sign::Positive
            });
            if better {
                best = Some((q, pq));
            }
        }
        let Some((c, _)) = best else { break };
        faces.push([u, w, c]);
        if faces.len() > bound {
            break;
        }
        for (x, y) in [(w, c), (c, u)] {
            if !pending.remove(&(x, y)) {
                pending.insert((y, x));
                stack.push((y, x));
            }
        }
    }
    faces
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ids(n: usize) -> Vec<PointId> {
        (0..n).map(PointId::new).collect()
    }

    /// Gift wrapping a convex polygon on a plane that has the centre on its outer side
    /// gives the fan from the greatest vertex (the perturbation pulls it out the most);
    /// through the centre, some triangulation of the polygon.
    #[test]
    fn gift_wrapping_a_flat_ring_gives_a_triangulation_of_it() {
        for (z, scale) in [(0.6, 0.8), (0.0, 1.0)] {
            // a circle at height z, counter-clockwise seen from above; the ghost faces
            // face down (the hull is above), so the open edges run clockwise from above
            let k = 12;
            let pts: Vec<[f64; 3]> = (0..k)
                .map(|i| {
                    let t = std::f64::consts::TAU * i as f64 / k as f64;
                    [scale * t.cos(), scale * t.sin(), z]
                })
                .collect();
            let at = |p: PointId| pts[p.index()];
            let v = ids(k);
            let open: Vec<(PointId, PointId)> = (0..k).map(|i| (v[(i + 1) % k], v[i])).collect();
            let wrapped = gift_wrap(open.clone(), at);
            let fanned = fan(&open, at).expect("one plane");
            assert_eq!(wrapped.len(), k - 2);
            assert_eq!(fanned.len(), k - 2);
            for faces in [&wrapped, &fanned] {
                // every face facing down, the areas summing to the polygon's
                let mut area = 0.0;
                for f in faces.iter() {
                    let [a, b, c] = f.map(at);
                    let n = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
                    assert!(n < 0.0, "{f:?}");
                    area -= n / 2.0;
                }
                let polygon =
                    k as f64 / 2.0 * scale * scale * (std::f64::consts::TAU / k as f64).sin();
                assert!((area - polygon).abs() < 1e-12, "{area} {polygon}");
            }
            if z != 0.0 {
                let key = |f: &[PointId; 3]| {
                    let m = (0..3).min_by_key(|&i| f[i]).expect("three");
                    [f[m], f[(m + 1) % 3], f[(m + 2) % 3]]
                };
                let mut a: Vec<_> = wrapped.iter().map(key).collect();
                let mut b: Vec<_> = fanned.iter().map(key).collect();
                a.sort_unstable();
                b.sort_unstable();
                assert_eq!(a, b);
            }
        }
    }
}
