//! A k-d tree over the positions of a large hole's candidates, for the gift wrapping's apex
//! search: the apex of a facet lies in the sphere of the facet and any candidate on its
//! side (the pencil of spheres through the facet is ordered), so once one such candidate
//! is known only the candidates in that sphere's ball need the exact tests. Positions are
//! rounded; the balls asked for are widened by a bound on that rounding, and the exact
//! predicates decide.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Points per leaf.
const LEAF: usize = 8;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    /// The node's points: `order[start..end]`.
    start: u32,
    end: u32,
    /// The children, or 0 for a leaf (the root is no one's child).
    children: [u32; 2],
}

/// The tree: the candidates' positions by candidate index.
#[derive(Clone, Debug)]
pub(super) struct BallIndex {
    pos: Vec<[f64; 3]>,
    order: Vec<u32>,
    nodes: Vec<Node>,
}

impl BallIndex {
    /// The tree of `pos` (finite coordinates).
    pub fn new(pos: Vec<[f64; 3]>) -> Self {
        let mut t = BallIndex {
            order: (0..pos.len() as u32).collect(),
            pos,
            nodes: Vec::new(),
        };
        t.split(0, t.pos.len());
        t
    }

    /// Adds the node of `order[start..end]` and the nodes below it; returns its index.
    fn split(&mut self, start: usize, end: usize) -> u32 {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for &i in &self.order[start..end] {
            for c in 0..3 {
                lo[c] = lo[c].min(self.pos[i as usize][c]);
                hi[c] = hi[c].max(self.pos[i as usize][c]);
            }
        }
        let at = self.nodes.len();
        self.nodes.push(Node {
            lo,
            hi,
            start: start as u32,
            end: end as u32,
            children: [0; 2],
        });
        if end - start > LEAF {
            // halves along the widest side
            let axis = (0..3)
                .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
                .unwrap_or(0);
            let mid = (start + end) / 2;
            let pos = &self.pos;
            self.order[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
                pos[a as usize][axis].total_cmp(&pos[b as usize][axis])
            });
            let left = self.split(start, mid);
            let right = self.split(mid, end);
            self.nodes[at].children = [left, right];
        }
        at as u32
    }

    /// The number of candidates.
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    /// The candidates within distance `r` of `c` (and maybe a few more), appended to `out`.
    pub fn within(&self, c: [f64; 3], r: f64, out: &mut Vec<u32>) {
        let r2 = r * r;
        let mut stack = vec![0u32];
        while let Some(k) = stack.pop() {
            let n = &self.nodes[k as usize];
            let mut d2 = 0.0;
            for a in 0..3 {
                let e = (n.lo[a] - c[a]).max(c[a] - n.hi[a]).max(0.0);
                d2 += e * e;
            }
            if d2 > r2 {
                continue;
            }
            if n.children[0] == 0 {
                out.extend(
                    self.order[n.start as usize..n.end as usize]
                        .iter()
                        .filter(|&&i| {
                            let p = self.pos[i as usize];
                            (0..3).map(|a| (p[a] - c[a]) * (p[a] - c[a])).sum::<f64>() <= r2
                        }),
                );
            } else {
                stack.extend(n.children);
            }
        }
    }

    /// The candidates in increasing order of `key` (those it gives one), until `accept`
    /// takes one, which is returned: a best-first search, `bound(lo, hi)` a lower bound of
    /// the key over a box (infinite when no point of the box has a key). With a bound that
    /// is only a guess somewhere, the order is only about that.
    pub fn first_by(
        &self,
        bound: impl Fn(&[f64; 3], &[f64; 3]) -> f64,
        key: impl Fn(&[f64; 3]) -> Option<f64>,
        mut accept: impl FnMut(u32) -> bool,
    ) -> Option<u32> {
        let root = self.nodes.first()?;
        let mut heap = BinaryHeap::new();
        heap.push(Next(bound(&root.lo, &root.hi), Item::Node(0)));
        while let Some(Next(_, item)) = heap.pop() {
            match item {
                Item::Point(i) if accept(i) => return Some(i),
                Item::Point(_) => {}
                Item::Node(k) => {
                    let n = &self.nodes[k as usize];
                    if n.children[0] == 0 {
                        for &i in &self.order[n.start as usize..n.end as usize] {
                            if let Some(t) = key(&self.pos[i as usize]) {
                                heap.push(Next(t, Item::Point(i)));
                            }
                        }
                    } else {
                        for c in n.children {
                            let b = bound(&self.nodes[c as usize].lo, &self.nodes[c as usize].hi);
                            if b < f64::INFINITY {
                                heap.push(Next(b, Item::Node(c)));
                            }
                        }
                    }
                }
            }
        }
        None
    }
}

/// A node or a candidate of the best-first search.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Item {
    Node(u32),
    Point(u32),
}

/// An item with its key: the heap's least key comes out first (then the least item).
#[derive(Clone, Copy, Debug)]
struct Next(f64, Item);

impl PartialEq for Next {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Next {}

impl PartialOrd for Next {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Next {
    fn cmp(&self, other: &Self) -> Ordering {
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sort::SplitMix;

    fn cloud(n: usize, seed: u64, flat: bool) -> Vec<[f64; 3]> {
        let mut r = SplitMix::new(seed);
        (0..n)
            .map(|i| {
                // a few repeated points, and in the flat case a plane of them
                let z = if flat { 0.0 } else { r.unit() };
                if i % 17 == 3 {
                    [0.5, 0.5, 0.0]
                } else {
                    [r.unit(), r.unit() * 3.0 - 1.0, z]
                }
            })
            .collect()
    }

    fn d2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
        (0..3).map(|c| (a[c] - b[c]) * (a[c] - b[c])).sum()
    }

    /// The points within a ball are those a scan of all finds, for balls of every size.
    #[test]
    fn within_finds_what_a_scan_finds() {
        for flat in [false, true] {
            for n in [1, 8, 9, 300] {
                let pos = cloud(n, n as u64, flat);
                let t = BallIndex::new(pos.clone());
                let mut r = SplitMix::new(3);
                for _ in 0..50 {
                    let c = [r.unit(), r.unit() * 2.0, r.unit() * 0.5];
                    let rad = r.unit() * 1.5;
                    let mut got = Vec::new();
                    t.within(c, rad, &mut got);
                    got.sort_unstable();
                    let want: Vec<u32> = (0..n as u32)
                        .filter(|&i| d2(&pos[i as usize], &c) <= rad * rad)
                        .collect();
                    assert_eq!(got, want, "n {n}, flat {flat}");
                }
            }
        }
    }

    /// The best-first search meets the points in increasing order of their key (here the
    /// distance to a point, bounded below by a box's distance), skipping those without one.
    #[test]
    fn first_by_goes_in_key_order() {
        let pos = cloud(500, 11, false);
        let t = BallIndex::new(pos.clone());
        let q = [0.3, 0.2, 0.9];
        let key = |p: &[f64; 3]| (p[0] > 0.25).then(|| d2(p, &q));
        let bound = |lo: &[f64; 3], hi: &[f64; 3]| {
            if hi[0] <= 0.25 {
                return f64::INFINITY;
            }
            (0..3)
                .map(|c| {
                    let e = (lo[c] - q[c]).max(q[c] - hi[c]).max(0.0);
                    e * e
                })
                .sum()
        };
        let mut met = Vec::new();
        assert_eq!(
            t.first_by(bound, key, |i| {
                met.push(i);
                false
            }),
            None
        );
        let mut want: Vec<u32> = (0..500)
            .filter(|&i| key(&pos[i as usize]).is_some())
            .collect();
        want.sort_by(|&a, &b| {
            key(&pos[a as usize])
                .unwrap()
                .total_cmp(&key(&pos[b as usize]).unwrap())
        });
        let keys = |v: &[u32]| {
            v.iter()
                .map(|&i| key(&pos[i as usize]).unwrap())
                .collect::<Vec<_>>()
        };
        assert_eq!(keys(&met), keys(&want));
        // the first accepted is returned
        let third = met[2];
        let mut seen = 0;
        assert_eq!(
            t.first_by(bound, key, |_| {
                seen += 1;
                seen == 3
            }),
            Some(third)
        );
    }
}
