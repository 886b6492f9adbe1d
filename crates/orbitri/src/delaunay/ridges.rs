//! 3D: pairing the new cells of a star across their facets through the new vertex.
//!
//! Each such facet stands on an edge of the hole's boundary, and in a simplicial complex
//! exactly two new cells stand on each boundary edge (the boundary of a ball is a closed
//! surface): the two cells across that facet. So the cells pair by the edge's two vertex
//! ids, through a small open-addressing hash table, where rotating around each edge through
//! the conflict cells loads cells and takes a branch the processor cannot predict at each
//! step. A third cell on an edge means the star is not simplicial (two edges with the same
//! ends); the table then says so, and the sequential code rotates instead (a parallel chunk
//! leaves the point to it).

use std::hint::select_unpredictable;

use crate::ids::VertexId;

/// One edge seen so far: its ends (the smaller id in the high half; 0 marks an empty
/// entry, since the ends differ), the new cell's tag and its slot opposite the facet on
/// the edge.
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    key: u64,
    tag: u32,
    slot: u8,
}

/// The slot of an entry whose edge has met its second cell.
const PAIRED: u8 = u8::MAX;

/// The hash table of one star's boundary edges (kept between insertions, emptied entry by
/// entry), and the pairs found.
#[derive(Clone, Debug, Default)]
pub(super) struct Ridges {
    table: Vec<Entry>,
    /// `64 − log2(table size)`: the hash keeps the top bits.
    shift: u32,
    /// The entries filled by the current star.
    filled: Vec<u32>,
    /// Two new cells meet across a facet: `(tag, slot, tag, slot)`.
    pairs: Vec<(u32, u8, u32, u8)>,
    /// An edge met a third cell, or had equal ends.
    broken: bool,
}

impl Ridges {
    /// Starts a star of `edges` boundary edges (each seen twice).
    fn start(&mut self, edges: usize) {
        for &h in &self.filled {
            self.table[h as usize].key = 0;
        }
        self.filled.clear();
        // at most a quarter full: most edges land on an empty entry at once
        let size = (4 * edges).next_power_of_two().max(64);
        if size > self.table.len() {
            self.table = vec![Entry::default(); size];
            self.shift = 64 - size.trailing_zeros();
        }
        self.pairs.clear();
        self.broken = false;
    }

    /// Notes that the new cell tagged `tag` stands on the boundary edge `(a, b)` with the
    /// facet opposite its `slot`: the second cell on an edge makes a pair with the first.
    /// Written without a branch on the outcome: whether an edge is met for the first or the
    /// second time is as good as random, and a mispredicted branch each time cost more than
    /// the rest of the work.
    #[inline(always)]
    fn meet(&mut self, (a, b): (VertexId, VertexId), tag: u32, slot: usize) {
        let key = (u64::from(a.0.min(b.0)) << 32) | u64::from(a.0.max(b.0));
        self.broken |= a == b;
        let mask = self.table.len() - 1;
        let mut h = (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> self.shift) as usize & mask;
        // on while the entry holds another edge (one test of one value: a branch taken
        // only on a collision)
        while self.table[h].key.min(self.table[h].key ^ key) != 0 {
            h = (h + 1) & mask;
        }
        let e = &mut self.table[h];
        let seen = e.key == key;
        self.broken |= seen & (e.slot == PAIRED);
        // a pair with the first cell, or the first cell: pushed both, one kept
        self.pairs.push((tag, slot as u8, e.tag, e.slot));
        self.pairs.truncate(self.pairs.len() - usize::from(!seen));
        self.filled.push(h as u32);
        self.filled.truncate(self.filled.len() - usize::from(seen));
        e.key = key;
        e.tag = select_unpredictable(seen, e.tag, tag);
        e.slot = select_unpredictable(seen, PAIRED, slot as u8);
    }

    /// Pairs the new cells of a 3D star across their facets through the new vertex: each
    /// cell given as (a tag for the caller, its vertices, the slot of the new vertex).
    /// Returns `(tag, slot, tag, slot)` for every two cells that meet, or `None` when the
    /// cells are not tetrahedra or an edge had other than two (the star is not simplicial).
    pub(super) fn pair<const N: usize>(
        &mut self,
        cells: impl ExactSizeIterator<Item = (u32, [VertexId; N], usize)>,
    ) -> Option<&[(u32, u8, u32, u8)]> {
        if N != 4 {
            return None;
        }
        let count = cells.len();
        self.start(3 * count / 2);
        for (tag, v, x) in cells {
            for t in 1..4 {
                let j = (x + t) % 4;
                let (a, b) = OTHER_TWO[4 * j + x];
                self.meet((v[a as usize], v[b as usize]), tag, j);
            }
        }
        (!self.broken && 2 * self.pairs.len() == 3 * count).then_some(&self.pairs[..])
    }
}

/// The two slots of a tetrahedron other than `j` and `x`, by `4·j + x` (`j ≠ x`).
const OTHER_TWO: [(u8, u8); 16] = {
    let mut t = [(0, 0); 16];
    let mut k = 0;
    while k < 16 {
        let (j, x) = (k / 4, k % 4);
        let mut rest = [0u8; 2];
        let (mut s, mut n) = (0, 0);
        while s < 4 {
            if s != j && s != x && n < 2 {
                rest[n] = s as u8;
                n += 1;
            }
            s += 1;
        }
        t[k] = (rest[0], rest[1]);
        k += 1;
    }
    t
};

#[cfg(test)]
mod tests {
    use super::*;

    /// The cone from vertex 0 over the boundary triangles `faces`, `0` at slot `x` of each.
    fn cone(faces: &[[u32; 3]], x: usize) -> Vec<(u32, [VertexId; 4], usize)> {
        faces
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let mut v = [0; 4];
                let mut rest = f.iter();
                for (s, slot) in v.iter_mut().enumerate() {
                    if s != x {
                        *slot = *rest.next().unwrap();
                    }
                }
                (k as u32, v.map(VertexId), x)
            })
            .collect()
    }

    /// Pairs the cells of a simplicial star and checks that every facet through the new
    /// vertex is paired once, with the cell across it.
    fn pair_and_check(r: &mut Ridges, cells: &[(u32, [VertexId; 4], usize)]) {
        let pairs = r
            .pair(cells.iter().copied())
            .expect("a simplicial star")
            .to_vec();
        assert_eq!(2 * pairs.len(), 3 * cells.len());
        let mut seen = std::collections::HashSet::new();
        for (a, i, b, j) in pairs {
            let facet = |c: u32, s: u8| {
                let mut f: Vec<_> = (0..4)
                    .filter(|&k| k != s as usize)
                    .map(|k| cells[c as usize].1[k])
                    .collect();
                f.sort();
                f
            };
            assert_ne!(a, b);
            assert_eq!(facet(a, i), facet(b, j));
            assert!(facet(a, i).contains(&VertexId(0)));
            assert!(seen.insert((a, i)) && seen.insert((b, j)));
        }
    }

    #[test]
    fn the_cells_of_a_star_pair_across_their_facets_through_the_new_vertex() {
        let mut r = Ridges::default();
        // the hole is a tetrahedron: four cells, six pairs; the new vertex in any slot
        for x in 0..4 {
            let cells = cone(&[[2, 3, 4], [1, 3, 4], [1, 2, 4], [1, 2, 3]], x);
            pair_and_check(&mut r, &cells);
        }
        // a bipyramid over a 1000-gon: 2000 cells, a table grown past its first size,
        // collisions, and the entries of the stars before emptied
        let n = 1000;
        let faces: Vec<[u32; 3]> = (0..n)
            .flat_map(|k| {
                let (a, b) = (3 + k, 3 + (k + 1) % n);
                [[1, a, b], [2, a, b]]
            })
            .collect();
        for x in [1, 3] {
            let cells = cone(&faces, x);
            pair_and_check(&mut r, &cells);
        }
    }

    #[test]
    fn a_star_that_is_not_simplicial_is_refused() {
        let mut r = Ridges::default();
        // the edge (1, 2) under three cells
        let cells = cone(&[[1, 2, 3], [1, 2, 4], [1, 2, 5]], 0);
        assert_eq!(r.pair(cells.iter().copied()), None);
        // an edge with equal ends
        let cells = cone(&[[1, 1, 3], [1, 1, 3]], 0);
        assert_eq!(r.pair(cells.iter().copied()), None);
        // an open surface: edges under one cell
        let cells = cone(&[[1, 2, 3], [1, 2, 4]], 0);
        assert_eq!(r.pair(cells.iter().copied()), None);
        // triangles (2D) are not paired here
        assert_eq!(r.pair([(0, [VertexId(0); 3], 0)].into_iter()), None);
        // and the table is clean for the next star
        let cells = cone(&[[2, 3, 4], [1, 3, 4], [1, 2, 4], [1, 2, 3]], 2);
        pair_and_check(&mut r, &cells);
    }

    #[test]
    fn the_other_two_slots_complete_each_pair() {
        for j in 0..4 {
            for x in (0..4).filter(|&x| x != j) {
                let (a, b) = OTHER_TWO[4 * j + x];
                let mut all = [j as u8, x as u8, a, b];
                all.sort();
                assert_eq!(all, [0, 1, 2, 3]);
                assert!(a < b);
            }
        }
    }
}
