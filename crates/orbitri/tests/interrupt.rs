//! The cancellation hooks: a progress callback that breaks stops the bulk construction on
//! both of its paths, and an interrupt flag stops the Voronoi cells.

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicUsize, Ordering};

use orbitri::sort::SplitMix;
use orbitri::{BuildOptions, Error, FlatTorus3, PeriodicDelaunay3};

fn points(n: usize) -> Vec<[f64; 3]> {
    let mut r = SplitMix::new(5);
    (0..n).map(|_| [r.unit(), r.unit(), r.unit()]).collect()
}

fn torus() -> FlatTorus3 {
    FlatTorus3::cuboid([1.0; 3]).unwrap()
}

#[test]
fn progress_counts_up_to_the_input_and_can_stop_either_path() {
    let pts = points(20_000);
    for dummy_threshold in [1000, usize::MAX] {
        let opts = BuildOptions {
            dummy_threshold,
            ..Default::default()
        };
        let mut seen = Vec::new();
        let tri = PeriodicDelaunay3::build_with(torus(), &pts, opts, |k| {
            seen.push(k);
            ControlFlow::Continue(())
        })
        .unwrap();
        assert_eq!(tri.used_dummy_points(), dummy_threshold == 1000);
        assert_eq!(seen.first(), Some(&0));
        assert_eq!(seen.last(), Some(&pts.len()));
        assert!(seen.windows(2).all(|w| w[0] < w[1]));

        let mut calls = 0;
        let r = PeriodicDelaunay3::build_with(torus(), &pts, opts, |k| {
            calls += 1;
            if k >= 8192 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        });
        assert!(matches!(r, Err(Error::Interrupted)));
        assert_eq!(calls, 3, "stopped at the first report of 8192 points");
    }
}

#[test]
fn voronoi_stops_once_interrupted_and_is_unchanged_otherwise() {
    let tri = PeriodicDelaunay3::build(torus(), &points(20_000)).unwrap();
    assert_eq!(
        tri.voronoi_cells_until(&|| false).unwrap(),
        tri.voronoi_cells()
    );
    assert_eq!(
        tri.voronoi_measures_until(&|| false).unwrap(),
        tri.voronoi_measures()
    );
    let polls = AtomicUsize::new(0);
    let r = tri.voronoi_cells_until(&|| polls.fetch_add(1, Ordering::Relaxed) >= 3);
    assert!(matches!(r, Err(Error::Interrupted)));
    // polled every 1024 cells: stopped long before the 20 000 cells were all polled for
    assert!(polls.load(Ordering::Relaxed) < 20);
    assert!(matches!(
        tri.voronoi_measures_until(&|| true),
        Err(Error::Interrupted)
    ));
}

/// The Voronoi cells poll exactly `voronoi_polls` times when not interrupted (a progress
/// bar's total), also in a covering and for the measures; a stop at any poll is honoured.
#[test]
fn voronoi_polls_are_counted_in_advance() {
    for n in [3, 5000, 20_000] {
        let tri = PeriodicDelaunay3::build(torus(), &points(n)).unwrap();
        let polls = AtomicUsize::new(0);
        let count = || {
            polls.fetch_add(1, Ordering::Relaxed);
            false
        };
        assert_eq!(tri.voronoi_cells_until(&count).unwrap().len(), n);
        assert_eq!(
            polls.swap(0, Ordering::Relaxed) as u64,
            tri.voronoi_polls(),
            "{n}"
        );
        tri.voronoi_measures_until(&count).unwrap();
        assert_eq!(
            polls.swap(0, Ordering::Relaxed) as u64,
            tri.voronoi_polls(),
            "{n}"
        );
        // a stop at the last poll (the cells' phase) and in the middle (the merges')
        for stop_at in [
            tri.voronoi_polls() as usize,
            tri.voronoi_polls() as usize / 2,
        ] {
            let late = || polls.fetch_add(1, Ordering::Relaxed) + 1 >= stop_at;
            assert!(matches!(
                tri.voronoi_cells_until(&late),
                Err(Error::Interrupted)
            ));
            polls.store(0, Ordering::Relaxed);
        }
    }
}
