//! Spatial sorting: a 3D Hilbert curve key (Skilling's transpose algorithm) and the biased
//! randomized insertion order (BRIO) of Amenta, Choi and Rote, with Hilbert order per round.

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

    /// An integer in `[0, n)`.
    #[inline]
    pub fn below(&mut self, n: usize) -> usize {
        (((self.next_u64() >> 32) * n as u64) >> 32) as usize
    }
}

/// Index of the grid cell `x` (each coordinate below `2^bits`, `D·bits ≤ 64`) along the
/// `D`-dimensional Hilbert curve.
pub fn hilbert<const D: usize>(mut x: [u32; D], bits: u32) -> u64 {
    let top = 1u32 << (bits - 1);
    let mut q = top;
    while q > 1 {
        let p = q - 1;
        for i in 0..D {
            if x[i] & q != 0 {
                x[0] ^= p;
            } else {
                let t = (x[0] ^ x[i]) & p;
                x[0] ^= t;
                x[i] ^= t;
            }
        }
        q >>= 1;
    }
    for i in 1..D {
        x[i] ^= x[i - 1];
    }
    let mut t = 0;
    let mut q = top;
    while q > 1 {
        if x[D - 1] & q != 0 {
            t ^= q - 1;
        }
        q >>= 1;
    }
    for v in x.iter_mut() {
        *v ^= t;
    }
    let mut h = 0u64;
    for b in (0..bits).rev() {
        for v in &x {
            h = (h << 1) | ((v >> b) & 1) as u64;
        }
    }
    h
}

/// The BRIO insertion order of `keys.len()` items: a random shuffle, split into rounds that
/// double in size (the last holds half the items), each round sorted by key.
pub fn brio_order(keys: &[u64], seed: u64) -> Vec<u32> {
    let n = keys.len();
    let mut idx: Vec<u32> = (0..n as u32).collect();
    let mut rng = SplitMix::new(seed);
    for i in (1..n).rev() {
        let j = rng.below(i + 1);
        idx.swap(i, j);
    }
    let mut ends = vec![n];
    let mut m = n;
    while m > 64 {
        m /= 2;
        ends.push(m);
    }
    ends.reverse();
    let mut start = 0;
    for end in ends {
        idx[start..end].sort_unstable_by_key(|&i| keys[i as usize]);
        start = end;
    }
    idx
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn brio_is_a_permutation_with_sorted_rounds() {
        let keys: Vec<u64> = (0..1000u64).map(|i| (i * 7919) % 1000).collect();
        let order = brio_order(&keys, 3);
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..1000).collect::<Vec<u32>>());
        // the last round (second half) is sorted by key
        assert!(order[500..]
            .windows(2)
            .all(|w| keys[w[0] as usize] <= keys[w[1] as usize]));
    }
}
