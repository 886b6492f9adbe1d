//! Batches into a large triangulation, one at a time and on threads: N uniform random points
//! (seed 1) built in bulk, then REPS batches of B more (seeds 2, 3, …) inserted with
//! `insert_all`, with the triangulation's threads as built (`None`: one at a time, or 2).
//! Prints the median time of a batch for each, side by side in one run.
//!
//! usage: cargo run --release -p orbitri --example batches [REPS] [N] [B ...]
//!        (default 9, 10⁶, 10⁴ and 10⁵)
use std::ops::ControlFlow;
use std::time::Instant;

use orbitri::{BuildOptions, FlatTorus3, PeriodicDelaunay3};

mod common;
use common::{median, numbers, uniform};

fn main() {
    let args = numbers();
    let reps = args.first().copied().unwrap_or(9);
    let n = args.get(1).copied().unwrap_or(1_000_000);
    let sizes = if args.len() > 2 {
        args[2..].to_vec()
    } else {
        vec![10_000, 100_000]
    };
    let torus = FlatTorus3::cuboid([1.0; 3]).unwrap();
    let points = uniform(n, 1);
    println!("| N | batch | one at a time | 2 threads | ratio |");
    println!("|---|---|---|---|---|");
    for b in sizes {
        let mut times = [Vec::new(), Vec::new()];
        for (k, threads) in [None, Some(2)].into_iter().enumerate() {
            let opts = BuildOptions {
                threads,
                ..BuildOptions::default()
            };
            let go = |_| ControlFlow::Continue(());
            let mut tri = PeriodicDelaunay3::build_with(torus.clone(), &points, opts, go).unwrap();
            for rep in 0..reps {
                let batch = uniform(b, 2 + rep as u64);
                let t = Instant::now();
                tri.insert_all(&batch).unwrap();
                times[k].push(t.elapsed().as_secs_f64());
            }
        }
        let [one, two] = times.map(median);
        println!("| {n} | {b} | {one:.4} s | {two:.4} s | {:.2} |", two / one);
    }
}
