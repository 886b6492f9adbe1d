use orbitri::sort::SplitMix;
use orbitri::{FlatManifold, Triangulation};
fn main() {
    let n: usize = std::env::args().nth(1).map_or(1500, |s| s.parse().unwrap());
    let b = [1.0, 1.0, 1.25];
    let only = std::env::args().nth(2);
    for name in FlatManifold::PLATYCOSMS
        .into_iter()
        .filter(|n| only.as_deref().is_none_or(|o| o == *n))
    {
        let m = FlatManifold::platycosm(name, b).unwrap();
        let mut r = SplitMix::new(9);
        let pts: Vec<[f64; 3]> = (0..n)
            .map(|_| [r.unit(), r.unit(), r.unit() * 1.25])
            .collect();
        let t = std::time::Instant::now();
        let tri = Triangulation::<3, 4, _>::build(m.clone(), &pts).unwrap();
        let build = t.elapsed();
        let t = std::time::Instant::now();
        tri.is_valid().unwrap();
        let valid = t.elapsed();
        let t = std::time::Instant::now();
        let v: f64 = tri.voronoi_cells().iter().map(|c| c.volume).sum();
        eprintln!(
            "{name:20} build {build:?} valid {valid:?} voronoi {:?} dummies {} sheets {} v {v}",
            t.elapsed(),
            tri.used_dummy_points(),
            tri.sheets()
        );
    }
}
