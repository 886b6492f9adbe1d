//! The benchmark of issue "Orbit spaces beyond the torus": `n` uniform points in a manifold
//! against the torus of its translations with the unfolded points (each point and its images
//! under the coset representatives), in one run, medians of `reps` runs each, alternating.
//! Per-point cost: the manifold's time over `n`, the torus's over `k·n`.
//!
//! usage: cargo run --release --example manifolds [N] [REPS] [SPACE ...]
//!        SPACE: klein, or a name of FlatManifold::PLATYCOSMS (default: klein didicosm)

use std::time::Instant;

use orbitri::sort::SplitMix;
use orbitri::{FlatManifold, FlatSpace, FlatTorus, Motion, PeriodicDelaunay, Triangulation};

mod common;
use common::median;

fn run<const D: usize, const N: usize>(m: FlatManifold<D>, n: usize, reps: usize)
where
    FlatManifold<D>: FlatSpace<D, N, Elem = Motion<D>>,
    FlatTorus<D>: FlatSpace<D, N, Elem = [i8; D]>,
{
    let box_: [f64; D] = std::array::from_fn(|i| if i == D - 1 && D == 3 { 1.25 } else { 1.0 });
    let mut r = SplitMix::new(1);
    let pts: Vec<[f64; D]> = (0..n)
        .map(|_| std::array::from_fn(|i| r.unit() * box_[i]))
        .collect();
    let k = m.index();
    let torus = FlatTorus::new(m.translations().clone());
    let mut cover = Vec::with_capacity(k * n);
    for c in 0..k {
        let (a, t) = m.isometry(Motion {
            coset: c as u8,
            offset: [0; D],
        });
        for p in &pts {
            let x = std::array::from_fn(|i| (0..D).map(|j| a[i][j] * p[j]).sum::<f64>() + t[i]);
            cover.push(x);
        }
    }
    let (mut tm, mut tt) = (Vec::new(), Vec::new());
    for _ in 0..reps {
        let t = Instant::now();
        let tri = Triangulation::<D, N, _>::build(m.clone(), &pts).unwrap();
        tm.push(t.elapsed().as_secs_f64());
        assert!(tri.is_one_sheeted());
        drop(tri);
        let t = Instant::now();
        let tri = PeriodicDelaunay::<D, N>::build(torus.clone(), &cover).unwrap();
        tt.push(t.elapsed().as_secs_f64());
        drop(tri);
    }
    let (a, b) = (median(tm), median(tt));
    let (pa, pb) = (a / n as f64, b / (k * n) as f64);
    println!(
        "{:20} n={n} k={k} manifold {a:.3} s ({:.2} µs/pt)  torus of T, {} pts {b:.3} s ({:.2} µs/pt)  ratio {:.2}",
        m.name(),
        pa * 1e6,
        k * n,
        pb * 1e6,
        pa / pb
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(1_000_000, |s| s.parse().unwrap());
    let reps: usize = args.get(2).map_or(3, |s| s.parse().unwrap());
    let names: Vec<String> = if args.len() > 3 {
        args[3..].to_vec()
    } else {
        vec!["klein".into(), "didicosm".into()]
    };
    for name in names {
        if name == "klein" {
            run::<2, 3>(FlatManifold::klein_bottle(1.0, 1.0).unwrap(), n, reps);
        } else {
            run::<3, 4>(
                FlatManifold::platycosm(&name, [1.0, 1.0, 1.25]).unwrap(),
                n,
                reps,
            );
        }
    }
}
