use orbitri::sort::SplitMix;
use orbitri::{BuildOptions, FlatTorus3, PeriodicDelaunay3};
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(100);
    let thr: usize = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1000);
    let mut r = SplitMix::new(1);
    let pts: Vec<[f64; 3]> = (0..n).map(|_| [r.unit(), r.unit(), r.unit()]).collect();
    let t = std::time::Instant::now();
    let opts = BuildOptions {
        dummy_threshold: thr,
        ..Default::default()
    };
    let tri =
        PeriodicDelaunay3::build_with(FlatTorus3::cuboid([1.0; 3]).unwrap(), &pts, opts, |_| {
            std::ops::ControlFlow::Continue(())
        })
        .unwrap();
    let dt = t.elapsed().as_secs_f64();
    println!(
        "n={n} V={} C={} sheets={} dummies={} time={dt:.3}",
        tri.number_of_vertices(),
        tri.number_of_cells(),
        tri.sheets(),
        tri.used_dummy_points()
    );
    if n <= 20000 {
        println!("valid={:?}", tri.is_valid());
    }
}
