//! The benchmarks of issue "Dynamic triangulations", one line each (medians of REPS runs):
//!
//! * `remove N`: build N uniform points in the unit cube (the CGAL anchor's generator, seed
//!   1), remove input points 0, 2, 4, … in that order, time the removals alone (the
//!   anchor's `dt3rm` and `p3dt3rm` do the same): one `remove` per point, and one
//!   `remove_all` of them all;
//! * `move N`: N points, every point moved by 1% of the mean spacing, 10 steps: one
//!   `move_point` per point in input order, and one `move_all` per step (Hilbert order),
//!   against building from scratch at every step.
//!
//! usage: cargo run --release -p orbitri --example dynamic remove|move [REPS] [N ...]
use std::time::Instant;

use orbitri::sort::SplitMix;
use orbitri::{FlatTorus3, InputId, PeriodicDelaunay3, Removal};

mod common;
use common::{median, uniform};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let what = args.first().map(String::as_str).unwrap_or("remove");
    let reps: usize = args.get(1).map_or(3, |a| a.parse().expect("REPS"));
    let ns: Vec<usize> = if args.len() > 2 {
        args[2..].iter().map(|a| a.parse().expect("N")).collect()
    } else {
        vec![100_000]
    };
    let torus = FlatTorus3::cuboid([1.0; 3]).unwrap();
    for n in ns {
        let pts = uniform(n, 1);
        match what {
            "remove" => {
                let (mut build, mut remove, mut rebuilt) = (Vec::new(), Vec::new(), 0);
                let mut batch = Vec::new();
                let evens: Vec<InputId> = (0..n).step_by(2).map(InputId::new).collect();
                for _ in 0..reps {
                    let t = Instant::now();
                    let mut tri = PeriodicDelaunay3::build(torus.clone(), &pts).unwrap();
                    build.push(t.elapsed().as_secs_f64());
                    let t = Instant::now();
                    for i in (0..n).step_by(2) {
                        rebuilt +=
                            (tri.remove(InputId::new(i)).unwrap() == Removal::Rebuilt) as usize;
                    }
                    remove.push(t.elapsed().as_secs_f64());
                    assert_eq!(tri.number_of_vertices(), n / 2);
                    let mut tri = PeriodicDelaunay3::build(torus.clone(), &pts).unwrap();
                    let t = Instant::now();
                    tri.remove_all(&evens).unwrap();
                    batch.push(t.elapsed().as_secs_f64());
                    assert_eq!(tri.number_of_vertices(), n / 2);
                }
                println!(
                    "remove N={n} removed={} build_s={:.3} remove_s={:.3} remove_all_s={:.3} rebuilt={rebuilt}",
                    n.div_ceil(2),
                    median(build),
                    median(remove),
                    median(batch)
                );
            }
            "move" => {
                let spacing = (1.0 / n as f64).cbrt();
                let ids: Vec<InputId> = (0..n).map(InputId::new).collect();
                let (mut one, mut all, mut scratch, mut fast) =
                    (Vec::new(), Vec::new(), Vec::new(), 0);
                for _ in 0..reps {
                    let mut r = SplitMix::new(2);
                    let mut now = pts.clone();
                    let mut by_one = PeriodicDelaunay3::build(torus.clone(), &now).unwrap();
                    let mut by_all = PeriodicDelaunay3::build(torus.clone(), &now).unwrap();
                    let (mut t1, mut ta, mut ts) = (0.0, 0.0, 0.0);
                    for _ in 0..10 {
                        for p in now.iter_mut() {
                            // a random direction, 1% of the spacing
                            let d = [r.unit() - 0.5, r.unit() - 0.5, r.unit() - 0.5];
                            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                            for c in 0..3 {
                                p[c] += 0.01 * spacing * d[c] / l;
                            }
                        }
                        let t = Instant::now();
                        for (i, p) in now.iter().enumerate() {
                            by_one.move_point(InputId::new(i), *p).unwrap();
                        }
                        t1 += t.elapsed().as_secs_f64();
                        let t = Instant::now();
                        let moved = by_all.move_all(&ids, &now).unwrap();
                        ta += t.elapsed().as_secs_f64();
                        fast += moved.iter().filter(|&&m| m).count();
                        let t = Instant::now();
                        let fresh = PeriodicDelaunay3::build(torus.clone(), &now).unwrap();
                        ts += t.elapsed().as_secs_f64();
                        assert_eq!(fresh.number_of_cells(), by_one.number_of_cells());
                        assert_eq!(fresh.number_of_cells(), by_all.number_of_cells());
                    }
                    one.push(t1);
                    all.push(ta);
                    scratch.push(ts);
                }
                println!(
                    "move N={n} steps=10 move_point_s={:.3} move_all_s={:.3} rebuild_s={:.3} coordinates_only={:.4}",
                    median(one),
                    median(all),
                    median(scratch),
                    fast as f64 / (10 * n * reps) as f64
                );
            }
            _ => panic!("remove or move"),
        }
    }
}
