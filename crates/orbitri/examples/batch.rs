//! Insertion and location in any order, per point against the bulk build (which sorts):
//! N uniform random points (seed 1) built in bulk; the same N inserted one at a time in
//! their (random) order into an empty triangulation; N more (seed 2) inserted into the
//! first N as one batch (`insert_all`: BRIO + Hilbert order); N random queries (seed 3)
//! located with `find_simplex` (on all threads; set `RAYON_NUM_THREADS=1` for one). Medians
//! of REPS runs; one line per N.
//!
//! usage: cargo run --release -p orbitri --example batch [REPS] [N ...]   (default 3, 10⁵)
use std::time::Instant;

use orbitri::{FlatTorus3, PeriodicDelaunay3};

mod common;
use common::{median, numbers, uniform};

fn main() {
    let args = numbers();
    let reps = args.first().copied().unwrap_or(3);
    let ns = if args.len() > 1 {
        args[1..].to_vec()
    } else {
        vec![100_000]
    };
    let torus = FlatTorus3::cuboid([1.0; 3]).unwrap();
    println!(
        "| N | bulk build | one at a time, random order | per point / bulk | insert_all of N into N | per point / bulk | find_simplex, N queries | per query / bulk per point |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for n in ns {
        let (a, b, q) = (uniform(n, 1), uniform(n, 2), uniform(n, 3));
        let (mut bulk, mut single, mut batch, mut find) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for _ in 0..reps {
            let t = Instant::now();
            let mut tri = PeriodicDelaunay3::build(torus.clone(), &a).unwrap();
            bulk.push(t.elapsed().as_secs_f64());
            let cells = tri.number_of_cells();
            let t = Instant::now();
            let rows = tri.find_simplex(&q).unwrap();
            find.push(t.elapsed().as_secs_f64());
            assert_eq!(rows.len(), n);
            let t = Instant::now();
            tri.insert_all(&b).unwrap();
            batch.push(t.elapsed().as_secs_f64());
            let mut one = PeriodicDelaunay3::new(torus.clone());
            let t = Instant::now();
            for p in &a {
                one.insert(*p).unwrap();
            }
            single.push(t.elapsed().as_secs_f64());
            assert_eq!(one.number_of_cells(), cells);
        }
        let (k, s, i, f) = (median(bulk), median(single), median(batch), median(find));
        let us = |t: f64| 1e6 * t / n as f64;
        println!(
            "| {n} | {k:.3} s ({:.2} µs) | {s:.3} s ({:.2} µs) | {:.2} | {i:.3} s ({:.2} µs) | {:.2} | {f:.3} s ({:.2} µs) | {:.2} |",
            us(k),
            us(s),
            s / k,
            us(i),
            i / k,
            us(f),
            f / k
        );
    }
}
