//! What the benchmark examples share: the CGAL anchor's uniform points and medians.
#![allow(dead_code)]

use orbitri::sort::SplitMix;

/// `n` uniform points in the unit cube: the anchor's `gen3` points for `seed`.
pub fn uniform(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = SplitMix::new(seed);
    (0..n).map(|_| [r.unit(), r.unit(), r.unit()]).collect()
}

/// The median of some timings (the upper one of an even count).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The command line's arguments, all numbers.
pub fn numbers() -> Vec<usize> {
    std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("numbers"))
        .collect()
}
