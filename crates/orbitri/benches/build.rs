//! Criterion benchmarks of the bulk construction on the anchor harness's points, and of the
//! Hilbert keys that order them.

use criterion::{criterion_group, criterion_main, Criterion};
use orbitri::sort::{hilbert, SplitMix};
use orbitri::{FlatTorus3, PeriodicDelaunay3};

fn cube_points(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = SplitMix::new(seed);
    (0..n).map(|_| [r.unit(), r.unit(), r.unit()]).collect()
}

fn build(c: &mut Criterion) {
    let mut g = c.benchmark_group("build");
    g.sample_size(10);
    for n in [100usize, 10_000] {
        let pts = cube_points(n, 1);
        g.bench_function(format!("cube_{n}"), |b| {
            b.iter(|| {
                PeriodicDelaunay3::build(FlatTorus3::cuboid([1.0; 3]).unwrap(), &pts).unwrap()
            })
        });
    }
    g.finish();
}

/// 10⁴ keys of random grid cells at the tori's resolutions (21 bits in 3D, 16 in 2D).
fn keys(c: &mut Criterion) {
    let mut r = SplitMix::new(1);
    let cells3: Vec<[u32; 3]> = (0..10_000)
        .map(|_| [0, 1, 2].map(|_| r.below(1 << 21) as u32))
        .collect();
    let cells2: Vec<[u32; 2]> = (0..10_000)
        .map(|_| [0, 1].map(|_| r.below(1 << 16) as u32))
        .collect();
    let mut g = c.benchmark_group("hilbert_keys_10000");
    g.bench_function("3d_21_bits", |b| {
        b.iter(|| cells3.iter().fold(0, |a, &x| a ^ hilbert(x, 21)))
    });
    g.bench_function("2d_16_bits", |b| {
        b.iter(|| cells2.iter().fold(0, |a, &x| a ^ hilbert(x, 16)))
    });
    g.finish();
}

criterion_group!(benches, build, keys);
criterion_main!(benches);
