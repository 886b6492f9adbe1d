//! Spatial sorting: Hilbert curve keys in 2D and 3D (Skilling's curve, by state machines)
//! and the biased randomized insertion order (BRIO) of Amenta, Choi and Rote, with Hilbert
//! order per round.

use rayon::prelude::*;

/// The splitmix64 generator (the same stream as the CGAL anchor harness).
#[derive(Clone, Debug)]
pub struct SplitMix(u64);

impl SplitMix {
    pub fn new(seed: u64) -> Self {
        SplitMix(seed)
    }

    /// Next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A double in `[0, 1)` (53 random bits).
    #[inline]
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A point uniform on the unit sphere, as the CGAL anchor harness's `gens` draws it:
    /// `2u − 1` per coordinate until `0 < |v|² ≤ 1`, then `v/|v|`.
    pub fn on_sphere(&mut self) -> [f64; 3] {
        loop {
            let v = [0, 1, 2].map(|_| 2.0 * self.unit() - 1.0);
            let s = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            if s > 0.0 && s <= 1.0 {
                let r = s.sqrt();
                return v.map(|x| x / r);
            }
        }
    }

    /// An integer in `[0, n)`.
    #[inline]
    pub fn below(&mut self, n: usize) -> usize {
        (((self.next_u64() >> 32) * n as u64) >> 32) as usize
    }
}

/// The 2D Hilbert curve as a state machine, one level per step: entry `4·state + 2·bx + by`
/// holds the level's two digits (low bits) and the next state (4 states). It gives the same
/// index as Skilling's algorithm, in a quarter of the time.
const HILBERT2: [u8; 16] = [4, 1, 11, 2, 0, 15, 5, 6, 10, 9, 3, 12, 14, 7, 13, 8];

/// [`HILBERT2`] two levels at a time: entry `16·state + 4·(x's two bits) + (y's two bits)`
/// holds the four digits (low bits) and the next state.
const HILBERT2X2: [u8; 64] = {
    let mut t = [0u8; 64];
    let mut i = 0;
    while i < 64 {
        let (state, x, y) = (i / 16, (i / 4) % 4, i % 4);
        let hi = HILBERT2[4 * state + 2 * (x >> 1) + (y >> 1)];
        let lo = HILBERT2[4 * (hi >> 2) as usize + 2 * (x & 1) + (y & 1)];
        t[i] = ((hi & 3) << 2) | (lo & 3) | ((lo >> 2) << 4);
        i += 1;
    }
    t
};

fn hilbert2(x: u32, y: u32, bits: u32) -> u64 {
    let (mut h, mut state) = (0u64, 0usize);
    let mut b = bits;
    if b % 2 == 1 {
        b -= 1;
        let e = HILBERT2[2 * ((x >> b) & 1) as usize + ((y >> b) & 1) as usize];
        h = u64::from(e & 3);
        state = usize::from(e >> 2);
    }
    while b > 0 {
        b -= 2;
        let e = HILBERT2X2[16 * state + 4 * ((x >> b) & 3) as usize + ((y >> b) & 3) as usize];
        h = (h << 4) | u64::from(e & 15);
        state = usize::from(e >> 4);
    }
    h
}

/// The 3D Hilbert curve as a state machine, one level per step: entry `8·state + octant`
/// (the octant's bits `4·bx + 2·by + bz`) holds the level's three digits (low bits) and the
/// next state (24 states: the curve's sub-cubes are its copies turned by 24 of the cube's
/// symmetries). Derived from Skilling's algorithm, whose index it gives (the tests compare
/// the two).
const HILBERT3: [u8; 192] = [
    8, 17, 27, 2, 39, 46, 52, 5, 56, 71, 73, 86, 91, 20, 10, 13, 48, 1, 103, 110, 115, 18, 12, 21,
    126, 129, 29, 26, 79, 80, 140, 3, 148, 43, 37, 34, 127, 128, 78, 81, 156, 45, 35, 42, 31, 6,
    160, 105, 72, 87, 139, 4, 57, 70, 50, 53, 0, 171, 111, 76, 49, 58, 102, 61, 180, 143, 83, 184,
    69, 54, 66, 97, 16, 123, 9, 74, 47, 60, 38, 77, 132, 95, 85, 14, 67, 144, 82, 33, 142, 55, 185,
    96, 93, 116, 90, 11, 188, 107, 175, 176, 101, 98, 62, 65, 164, 109, 119, 22, 99, 106, 152, 41,
    174, 177, 63, 64, 117, 114, 92, 19, 30, 125, 161, 122, 7, 172, 104, 75, 130, 25, 133, 166, 179,
    136, 84, 191, 94, 15, 141, 28, 145, 32, 138, 51, 146, 155, 149, 36, 137, 24, 190, 167, 154,
    157, 147, 44, 169, 182, 120, 135, 162, 165, 121, 134, 187, 108, 168, 183, 118, 173, 23, 124,
    153, 170, 40, 59, 178, 113, 131, 88, 181, 158, 68, 151, 186, 163, 89, 112, 189, 100, 150, 159,
];

/// [`HILBERT3`] two levels at a time: entry `64·state + 8·(higher octant) + (lower octant)`
/// holds the six digits (low bits) and the next state.
const HILBERT3X2: [u16; 1536] = {
    let mut t = [0u16; 1536];
    let mut i = 0;
    while i < 1536 {
        let (state, hi, lo) = (i / 64, (i / 8) % 8, i % 8);
        let a = HILBERT3[8 * state + hi];
        let b = HILBERT3[8 * (a >> 3) as usize + lo];
        t[i] = ((a as u16 & 7) << 3) | (b as u16 & 7) | ((b as u16 >> 3) << 6);
        i += 1;
    }
    t
};

/// The low 21 bits of `v` spread to every third bit (bit `k` to bit `3k`).
fn spread3(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

fn hilbert3(x: u32, y: u32, z: u32, bits: u32) -> u64 {
    debug_assert!(bits <= 21, "a 3D Hilbert key of {bits} bits: at most 21");
    // the octants of every level at once: bits 3b..3b+3 hold level b's
    let octants = spread3(x) << 2 | spread3(y) << 1 | spread3(z);
    let (mut h, mut state) = (0u64, 0usize);
    let mut b = bits;
    if b % 2 == 1 {
        b -= 1;
        let e = HILBERT3[8 * state + (octants >> (3 * b)) as usize % 8];
        h = u64::from(e & 7);
        state = usize::from(e >> 3);
    }
    while b > 0 {
        b -= 2;
        let e = HILBERT3X2[64 * state + (octants >> (3 * b)) as usize % 64];
        h = (h << 6) | u64::from(e & 63);
        state = usize::from(e >> 6);
    }
    h
}

/// Index of the grid cell `x` (each coordinate below `2^bits`, `D·bits ≤ 64`) along the
/// `D`-dimensional Hilbert curve, in 2D or 3D (it panics in other dimensions).
pub fn hilbert<const D: usize>(x: [u32; D], bits: u32) -> u64 {
    match D {
        2 => hilbert2(x[0], x[1], bits),
        3 => hilbert3(x[0], x[1], x[2], bits),
        _ => panic!("a Hilbert curve in 2D or 3D, not {D}D"),
    }
}

/// A BRIO order: rounds drawn by a seed, each `2^growth` times larger than the one before
/// it (the last holds `1 − 2^−growth` of the items).
#[derive(Clone, Copy, Debug)]
pub struct Brio {
    seed: u64,
    growth: u32,
}

impl Brio {
    /// Rounds growing by `2^growth`, `growth` from 1 to 63 (it panics otherwise).
    pub fn new(seed: u64, growth: u32) -> Self {
        assert!(
            (1..64).contains(&growth),
            "BRIO growth {growth} not in 1..64"
        );
        Brio { seed, growth }
    }

    /// Rounds that double, each about as large as all before it (a parallel wave, at most
    /// doubling the triangulation, then takes about one round).
    pub fn doubling(seed: u64) -> Self {
        Brio::new(seed, 1)
    }
}

/// The BRIO rounds of `n` items: their indices grouped by round, in index order within
/// each, and where each round starts (one entry more: `n`). The rounds grow by `2^growth`
/// (the first holds at most about 64 items). An item's round is drawn from a hash of its index and
/// the seed (the tails before the first head of a fair coin, `growth` tosses a step,
/// counted back from the last round), so that the rounds are filled in one pass over the
/// items in memory order: no shuffle, no lookup at a random place.
pub fn brio_rounds(n: usize, Brio { seed, growth }: Brio) -> (Vec<u32>, Vec<usize>) {
    let mut last = 0;
    let mut m = n;
    while m > 64 {
        m >>= growth;
        last += 1;
    }
    let round: Vec<u8> = (0..n)
        .into_par_iter()
        .map(|i| {
            let h = SplitMix::new(seed ^ (i as u64).wrapping_mul(0xD6E8_FEB8_6659_FD93)).next_u64();
            (last - ((h.trailing_zeros() / growth) as usize).min(last)) as u8
        })
        .collect();
    let mut start = vec![0usize; last + 2];
    for &r in &round {
        start[r as usize + 1] += 1;
    }
    for r in 0..=last {
        start[r + 1] += start[r];
    }
    let mut at = start.clone();
    let mut idx = vec![0u32; n];
    for (i, &r) in round.iter().enumerate() {
        idx[at[r as usize]] = i as u32;
        at[r as usize] += 1;
    }
    (idx, start)
}

/// Feeds the BRIO rounds of `n` items ([`brio_rounds`] by `order`) to `consume` in order,
/// each as `(key, index)` pairs sorted by `key` and made ready by `prepare` (it gathers the
/// items). With `ahead`, each round is made ready on a helper thread while the round
/// before it is consumed: the insertion order, a tenth of a build when done up front,
/// hides behind an insertion one point at a time, which takes ten times longer a point.
/// Without, on the caller's thread, the keys and the sort on rayon's pool: for a parallel
/// insertion, whose threads the helper would slow (it took a tenth of the time of the
/// chunks it ran beside, on the sphere with two threads). Without an order, all items in
/// their order as one round, unsorted. Stops at `consume`'s first error. (Below 2¹⁴
/// items, all on the caller's thread.)
pub fn in_rounds<T: Send, E>(
    n: usize,
    (order, ahead): (Option<Brio>, bool),
    key: impl Fn(u32) -> u64 + Sync,
    prepare: impl Fn(Vec<(u64, u32)>) -> T + Sync,
    mut consume: impl FnMut(T) -> Result<(), E>,
) -> Result<(), E> {
    let (idx, start) = match order {
        Some(order) => brio_rounds(n, order),
        None => ((0..n as u32).collect(), vec![0, n]),
    };
    let ready = |round: &[u32]| {
        let mut pairs: Vec<(u64, u32)>;
        if ahead {
            pairs = round.iter().map(|&i| (key(i), i)).collect();
            if order.is_some() {
                pairs.sort_unstable();
            }
        } else {
            pairs = round.par_iter().map(|&i| (key(i), i)).collect();
            if order.is_some() {
                pairs.par_sort_unstable();
            }
        }
        prepare(pairs)
    };
    if n < 1 << 14 || !ahead {
        // (small: sorting takes less than starting a thread; with threads: on the pool)
        return start
            .windows(2)
            .try_for_each(|r| consume(ready(&idx[r[0]..r[1]])));
    }
    std::thread::scope(|s| {
        // (a round is made ready while the one before it is consumed, no further ahead:
        // each is as large as all before it; the helper owns the indices, freed once the
        // last round is ready)
        let (tx, rx) = std::sync::mpsc::sync_channel(0);
        let ready = &ready;
        s.spawn(move || {
            for r in start.windows(2) {
                if tx.send(ready(&idx[r[0]..r[1]])).is_err() {
                    return; // the consumer stopped
                }
            }
        });
        rx.into_iter().try_for_each(&mut consume)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Skilling's transpose algorithm, with a branch on each bit as he wrote it.
    fn skilling<const D: usize>(x: [u32; D], bits: u32) -> u64 {
        let mut y = x;
        let top = 1u32 << (bits - 1);
        let mut q = top;
        while q > 1 {
            let p = q - 1;
            for i in 0..D {
                if y[i] & q != 0 {
                    y[0] ^= p;
                } else {
                    let t = (y[0] ^ y[i]) & p;
                    y[0] ^= t;
                    y[i] ^= t;
                }
            }
            q >>= 1;
        }
        for i in 1..D {
            y[i] ^= y[i - 1];
        }
        let (mut t, mut q) = (0, top);
        while q > 1 {
            if y[D - 1] & q != 0 {
                t ^= q - 1;
            }
            q >>= 1;
        }
        let mut h = 0u64;
        for b in (0..bits).rev() {
            for v in &y {
                h = (h << 1) | u64::from(((v ^ t) >> b) & 1);
            }
        }
        h
    }

    #[test]
    fn the_state_machines_are_skillings_curve() {
        let mut r = SplitMix::new(4);
        for _ in 0..20_000 {
            let bits = 1 + r.below(16) as u32;
            let x = [0, 1].map(|_| r.below(1 << bits) as u32);
            assert_eq!(hilbert(x, bits), skilling(x, bits), "{x:?} {bits}");
            let bits = 1 + r.below(21) as u32;
            let x = [0, 1, 2].map(|_| r.below(1 << bits) as u32);
            assert_eq!(hilbert(x, bits), skilling(x, bits), "{x:?} {bits}");
        }
        // every cell of the small grids
        for bits in 1..=4 {
            for k in 0..1u32 << (3 * bits) {
                let x = [2, 1, 0].map(|c| (k >> (c * bits)) & ((1 << bits) - 1));
                assert_eq!(hilbert(x, bits), skilling(x, bits), "{x:?} {bits}");
            }
        }
    }

    #[test]
    fn sphere_points_match_the_anchor() {
        // the first two lines of `cgal_anchor gens N 1` (shortest round-trip digits)
        let mut r = SplitMix::new(1);
        assert_eq!(
            r.on_sphere(),
            [
                -0.20274504021579695,
                -0.20308944041506807,
                0.9579400439796791
            ]
        );
        assert_eq!(
            r.on_sphere(),
            [0.868143729616118, 0.05306929174520203, -0.49346744067048565]
        );
    }

    #[test]
    fn splitmix_matches_the_anchor_test_vectors() {
        let mut r = SplitMix::new(1);
        assert_eq!(r.next_u64(), 0x910a2dec89025cc1);
        assert_eq!(r.next_u64(), 0xbeeb8da1658eec67);
        assert_eq!(r.next_u64(), 0xf893a2eefb32555e);
        let mut r = SplitMix::new(1);
        assert_eq!(r.unit(), 0.5665615751722809);
    }

    #[test]
    fn hilbert_curve_is_a_bijection_with_unit_steps() {
        let bits = 3;
        let side = 1u32 << bits;
        let mut cells = vec![[0u32; 3]; (side * side * side) as usize];
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    cells[hilbert([x, y, z], bits) as usize] = [x, y, z];
                }
            }
        }
        for w in cells.windows(2) {
            let d: u32 = (0..3).map(|i| w[0][i].abs_diff(w[1][i])).sum();
            assert_eq!(d, 1, "{:?} -> {:?}", w[0], w[1]);
        }
    }

    #[test]
    fn hilbert_curve_in_2d() {
        let side = 1u32 << 4;
        let mut cells = vec![[0u32; 2]; (side * side) as usize];
        for x in 0..side {
            for y in 0..side {
                cells[hilbert([x, y], 4) as usize] = [x, y];
            }
        }
        assert!(cells
            .windows(2)
            .all(|w| w[0][0].abs_diff(w[1][0]) + w[0][1].abs_diff(w[1][1]) == 1));
    }

    /// The indices of `keys` in the order [`in_rounds`] feeds them, sorted ahead or not
    /// (the same order).
    fn fed_order(keys: &[u64], order: Brio, ahead: bool) -> Vec<u32> {
        let mut fed = Vec::new();
        let all: Result<(), ()> = in_rounds(
            keys.len(),
            (Some(order), ahead),
            |i| keys[i as usize],
            |round| round,
            |round| {
                fed.extend(round.iter().map(|&(_, i)| i));
                Ok(())
            },
        );
        assert!(all.is_ok());
        fed
    }

    #[test]
    fn brio_is_a_permutation_with_sorted_rounds_growing_as_asked() {
        let keys: Vec<u64> = (0..1000u64).map(|i| (i * 7919) % 1000).collect();
        // (growth, rounds, the last round's share in thousandths: 1 − 2^−growth)
        for (growth, rounds, last) in [(1, 5, 450..550), (3, 3, 830..920)] {
            let order = Brio::new(3, growth);
            let (idx, start) = brio_rounds(keys.len(), order);
            let sizes: Vec<usize> = start.windows(2).map(|r| r[1] - r[0]).collect();
            assert_eq!(sizes.len(), rounds, "growth {growth}: {sizes:?}");
            assert!(
                last.contains(&sizes[rounds - 1]),
                "growth {growth}: {sizes:?}"
            );
            // fed: a permutation, sorted by key within each round
            let fed = fed_order(&keys, order, true);
            assert_eq!(fed, fed_order(&keys, order, false));
            let mut seen = fed.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..1000).collect::<Vec<u32>>());
            let mut at = 0;
            for r in start.windows(2) {
                let mut round = idx[r[0]..r[1]].to_vec();
                round.sort_by_key(|&i| keys[i as usize]);
                assert_eq!(fed[at..at + round.len()], round[..], "growth {growth}");
                at += round.len();
            }
        }
    }

    #[test]
    #[should_panic(expected = "BRIO growth 0")]
    fn brio_growth_must_be_positive() {
        Brio::new(1, 0);
    }

    #[test]
    fn rounds_fed_in_order_are_the_sorted_rounds_and_an_error_stops_them() {
        // 5000 items: on the caller's thread; 40 000: on the helper thread
        for n in [5000u64, 40_000] {
            rounds_in_order(n);
        }
    }

    fn rounds_in_order(n: u64) {
        let keys: Vec<u64> = (0..n).map(|i| (i * 7919) % n).collect();
        // each round of `brio_rounds`, sorted by key here
        let (idx, start) = brio_rounds(keys.len(), Brio::doubling(9));
        let mut expected = Vec::new();
        for r in start.windows(2) {
            let mut round = idx[r[0]..r[1]].to_vec();
            round.sort_by_key(|&i| keys[i as usize]);
            expected.extend(round);
        }
        for ahead in [true, false] {
            assert_eq!(fed_order(&keys, Brio::doubling(9), ahead), expected);
        }
        // a consumer that stops after three rounds: the helper stops too (no hang)
        for ahead in [true, false] {
            let mut rounds = 0;
            let stopped = in_rounds(
                keys.len(),
                (Some(Brio::doubling(9)), ahead),
                |i| keys[i as usize],
                |round| round,
                |_| {
                    rounds += 1;
                    if rounds == 3 {
                        Err(rounds)
                    } else {
                        Ok(())
                    }
                },
            );
            assert_eq!((stopped, rounds), (Err(3), 3));
        }
        // without a seed: one round, in index order
        let mut fed = Vec::new();
        let plain: Result<(), ()> = in_rounds(
            keys.len(),
            (None, true),
            |i| keys[i as usize],
            |round| round,
            |round| {
                fed.push(round);
                Ok(())
            },
        );
        assert!(plain.is_ok());
        let one: Vec<(u64, u32)> = (0..n as u32).map(|i| (keys[i as usize], i)).collect();
        assert_eq!(fed, vec![one]);
    }
}
