//! Times the bulk build of `n` random points on the sphere (or with `rp2`, the projective
//! plane): `cargo run --release --example sphere_timing 1000000 [rp2]`.
use orbitri::sort::SplitMix;
use orbitri::spherical::{ProjectiveDelaunay, SphericalDelaunay};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args[1].parse().unwrap();
    let mut r = SplitMix::new(1);
    let pts: Vec<[f64; 3]> = (0..n).map(|_| r.on_sphere()).collect();
    let t = std::time::Instant::now();
    let f = if args.get(2).map(|s| s == "rp2").unwrap_or(false) {
        ProjectiveDelaunay::build(&pts)
            .unwrap()
            .number_of_vertices()
    } else {
        SphericalDelaunay::build(&pts).unwrap().number_of_vertices()
    };
    println!("n={n} v={f} build={:.3}s", t.elapsed().as_secs_f64());
}
