//! Inserting N random points into a triangulation of N: one by one in the given (random)
//! order, as one batch (`insert_all`: BRIO + Hilbert order), and, for reference, the bulk
//! build of all 2N. Medians of REPS runs; one line per N.
//!
//! usage: cargo run --release -p orbitri --example batch [REPS] [N ...]   (default 3, 10⁵)
use std::time::Instant;

use orbitri::{FlatTorus3, PeriodicDelaunay3};

mod common;
use common::{median, uniform};

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("numbers"))
        .collect();
    let reps = args.first().copied().unwrap_or(3);
    let ns = if args.len() > 1 {
        args[1..].to_vec()
    } else {
        vec![100_000]
    };
    let torus = FlatTorus3::cuboid([1.0; 3]).unwrap();
    println!("| N (into N) | one by one | insert_all | bulk build of 2N | one by one / bulk | insert_all / bulk |");
    println!("|---|---|---|---|---|---|");
    for n in ns {
        let (a, b) = (uniform(n, 1), uniform(n, 2));
        let all: Vec<[f64; 3]> = a.iter().chain(&b).copied().collect();
        let (mut single, mut batch, mut bulk) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..reps {
            let mut tri = PeriodicDelaunay3::build(torus.clone(), &a).unwrap();
            let t = Instant::now();
            for p in &b {
                tri.insert(*p).unwrap();
            }
            single.push(t.elapsed().as_secs_f64());
            let mut tri = PeriodicDelaunay3::build(torus.clone(), &a).unwrap();
            let t = Instant::now();
            tri.insert_all(&b).unwrap();
            batch.push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            let full = PeriodicDelaunay3::build(torus.clone(), &all).unwrap();
            bulk.push(t.elapsed().as_secs_f64());
            assert_eq!(full.number_of_vertices(), tri.number_of_vertices());
        }
        let (s, i, k) = (median(single), median(batch), median(bulk));
        println!(
            "| {n} | {s:.3} s | {i:.3} s | {k:.3} s | {:.2} | {:.2} |",
            s / k,
            i / k
        );
    }
}
