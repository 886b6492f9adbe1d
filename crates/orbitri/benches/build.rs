//! Criterion benchmark of the bulk construction on the anchor harness's points.

use criterion::{criterion_group, criterion_main, Criterion};
use orbitri::sort::SplitMix;
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

criterion_group!(benches, build);
criterion_main!(benches);
