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
