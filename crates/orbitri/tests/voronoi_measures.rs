//! The Voronoi measures (volume, faces, surface area, centroid), computed by pieces without
//! the cells, against the measures of the whole cells (`voronoi_cells`, tested against
//! clipped cells in `voronoi.rs`), in every kind of flat space, weighted, with hidden points
//! and on degenerate grids; and their sums against the domain's volume.

use orbitri::sort::SplitMix;
use orbitri::{
    CellMeasures, FlatManifold, FlatSpace, FlatTorus, PeriodicDelaunay2, PeriodicDelaunay3,
    Triangulation,
};

fn random<const D: usize>(n: usize, seed: u64, scale: [f64; D]) -> Vec<[f64; D]> {
    let mut r = SplitMix::new(seed);
    (0..n)
        .map(|_| std::array::from_fn(|i| r.unit() * scale[i]))
        .collect()
}

/// The measures equal the whole cells' to rounding, and the volumes sum to `volume`.
fn same_measures<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    tri: &Triangulation<D, N, S>,
    volume: f64,
    what: &str,
) where
    S::Elem: Ord + std::fmt::Debug,
{
    assert_eq!(
        tri.engine().sheets(),
        1,
        "{what}: by pieces only when 1-sheeted"
    );
    let measures = tri.voronoi_measures();
    let whole = tri.voronoi_cells();
    let cells: Vec<CellMeasures<D>> = whole.iter().map(CellMeasures::from).collect();
    // the neighbour pairs too: the same pairs (in 3D in the same order), the same areas
    let (with_pairs, mut pairs) = tri.voronoi_measures_and_neighbors_until(&|| false).unwrap();
    assert_eq!(with_pairs, measures, "{what}");
    assert_eq!(pairs, tri.voronoi_neighbors(), "{what}");
    let mut expected = tri.voronoi_neighbors_of(&whole);
    if D == 2 {
        // (a 2D cell lists its faces counter-clockwise, the pairs by first appearance)
        pairs.sort_by_key(|p| (p.i, p.j, p.shift));
        expected.sort_by_key(|p| (p.i, p.j, p.shift));
    }
    assert_eq!(pairs.len(), expected.len(), "{what}");
    for (a, b) in pairs.iter().zip(&expected) {
        assert_eq!((a.i, a.j, a.shift), (b.i, b.j, b.shift), "{what}");
        let scale = (volume / cells.len() as f64).powf((D as f64 - 1.0) / D as f64);
        assert!(
            (a.area - b.area).abs() <= 1e-9 * scale.max(b.area),
            "{what}: face {:?}–{:?}: {} against {}",
            a.i,
            a.j,
            a.area,
            b.area
        );
    }
    assert_eq!(measures.len(), cells.len(), "{what}");
    let mut total = 0.0;
    for (m, c) in measures.iter().zip(&cells) {
        assert_eq!(m.point, c.point, "{what}");
        assert_eq!(m.faces, c.faces, "{what}: faces of {:?}", c.point);
        // (rounding scales with the cell and its neighbours: a tiny power cell's centroid
        // is a quotient of tiny sums)
        let size = c
            .volume
            .max(volume / cells.len() as f64)
            .powf(1.0 / D as f64);
        assert!(
            (m.volume - c.volume).abs() <= 1e-9 * size.powi(D as i32),
            "{what}: volume of {:?}: {} against {}",
            c.point,
            m.volume,
            c.volume
        );
        assert!(
            (m.surface_area - c.surface_area).abs() <= 1e-9 * size.powi(D as i32 - 1),
            "{what}: surface of {:?}: {} against {}",
            c.point,
            m.surface_area,
            c.surface_area
        );
        for x in 0..D {
            assert!(
                (m.centroid[x] - c.centroid[x]).abs() <= 1e-9 * size,
                "{what}: centroid of {:?}: {:?} against {:?}",
                c.point,
                m.centroid,
                c.centroid
            );
        }
        total += m.volume;
    }
    assert!(
        (total - volume).abs() <= 1e-12 * volume,
        "{what}: volumes sum to {total}, not {volume}"
    );
}

#[test]
fn tori_by_pieces_equal_the_cells() {
    let lattice = [[1.0, 0.0, 0.0], [0.31, 0.9, 0.0], [-0.22, 0.17, 1.1]];
    let space = FlatTorus::triclinic(lattice).unwrap();
    let pts: Vec<[f64; 3]> = random(3000, 1, [1.0; 3])
        .iter()
        .map(|f| std::array::from_fn(|x| (0..3).map(|k| f[k] * lattice[k][x]).sum()))
        .collect();
    let tri = PeriodicDelaunay3::build(space, &pts).unwrap();
    same_measures(&tri, 0.9 * 1.1, "triclinic torus");
    let tri = PeriodicDelaunay3::build(
        FlatTorus::cuboid([2.0, 1.0, 0.5]).unwrap(),
        &random(2000, 2, [2.0, 1.0, 0.5]),
    )
    .unwrap();
    same_measures(&tri, 1.0, "cuboid");
    let tri = PeriodicDelaunay2::build(
        FlatTorus::triclinic([[1.0, 0.0], [0.4, 0.8]]).unwrap(),
        &random(3000, 3, [1.0, 0.8]),
    )
    .unwrap();
    same_measures(&tri, 0.8, "oblique 2D torus");
}

#[test]
fn manifolds_by_pieces_equal_the_cells() {
    let klein = FlatManifold::klein_bottle(1.0, 0.75).unwrap();
    let tri = Triangulation::build(klein, &random(1500, 4, [1.0, 0.75])).unwrap();
    same_measures(&tri, 0.75, "Klein bottle");
    for name in FlatManifold::PLATYCOSMS {
        let m = FlatManifold::platycosm(name, [1.0, 1.0, 1.25]).unwrap();
        let volume = m.volume();
        let tri = Triangulation::build(m, &random(2000, 5, [1.0, 1.0, 1.25])).unwrap();
        same_measures(&tri, volume, name);
    }
}

/// Power cells: the foot of the power bisector moves along each edge, and a point may lie
/// outside its own cell; hidden points keep empty cells.
#[test]
fn power_cells_by_pieces_equal_the_cells() {
    let mut r = SplitMix::new(6);
    let pts = random(3000, 7, [1.0; 3]);
    let w: Vec<f64> = pts.iter().map(|_| r.unit() * 0.004).collect();
    let tri =
        PeriodicDelaunay3::build_weighted(FlatTorus::cuboid([1.0; 3]).unwrap(), &pts, &w).unwrap();
    assert!(!tri.hidden().is_empty());
    same_measures(&tri, 1.0, "weighted 3D");
    let pts = random(3000, 8, [1.0, 1.0]);
    let w: Vec<f64> = pts.iter().map(|_| r.unit() * 0.0005).collect();
    let tri =
        PeriodicDelaunay2::build_weighted(FlatTorus::cuboid([1.0; 2]).unwrap(), &pts, &w).unwrap();
    same_measures(&tri, 1.0, "weighted 2D");
}

/// A grid has cells of one circumsphere side by side (a Voronoi vertex of many Delaunay
/// cells, Delaunay edges without a face): those points are measured on their whole cells,
/// with or without other points around.
#[test]
fn grids_by_pieces_equal_the_cells() {
    let n = 8;
    let grid: Vec<[f64; 3]> = (0..n * n * n)
        .map(|i| [(i % n) as f64, (i / n % n) as f64, (i / n / n) as f64].map(|x| x / n as f64))
        .collect();
    let space = FlatTorus::cuboid([1.0; 3]).unwrap();
    let tri = PeriodicDelaunay3::build(space.clone(), &grid).unwrap();
    same_measures(&tri, 1.0, "cubic grid");
    assert!(tri.voronoi_measures().iter().all(|m| m.faces == 6));
    let mut mixed = grid.clone();
    mixed.extend(random(300, 9, [1.0; 3]));
    let tri = PeriodicDelaunay3::build(space, &mixed).unwrap();
    same_measures(&tri, 1.0, "grid and random points");
    let square: Vec<[f64; 2]> = (0..n * n)
        .map(|i| [(i % n) as f64, (i / n) as f64].map(|x| x / n as f64))
        .collect();
    let tri = PeriodicDelaunay2::build(FlatTorus::cuboid([1.0; 2]).unwrap(), &square).unwrap();
    same_measures(&tri, 1.0, "square grid");
    assert!(tri.voronoi_measures().iter().all(|m| m.faces == 4));
}

/// After removals (which leave dead cell slots among the live ones), the measures are those
/// of a fresh build of the points that stay, point for point.
#[test]
fn measures_after_removals_equal_a_fresh_build() {
    let space = FlatTorus::cuboid([1.0; 3]).unwrap();
    let pts = random(3000, 4, [1.0; 3]);
    let mut tri = PeriodicDelaunay3::build(space.clone(), &pts).unwrap();
    for i in (0..pts.len()).step_by(3) {
        tri.remove(orbitri::InputId(i as u32)).unwrap();
    }
    let kept: Vec<usize> = (0..pts.len()).filter(|i| i % 3 != 0).collect();
    let fresh_points: Vec<[f64; 3]> = kept.iter().map(|&i| pts[i]).collect();
    let fresh = PeriodicDelaunay3::build(space, &fresh_points)
        .unwrap()
        .voronoi_measures();
    let measures: Vec<CellMeasures<3>> = tri
        .voronoi_measures()
        .into_iter()
        .filter(|m| m.point.0 % 3 != 0)
        .collect();
    assert_eq!(measures.len(), kept.len());
    let mut total = 0.0;
    for m in &measures {
        let k = kept.binary_search(&(m.point.0 as usize)).unwrap();
        let f = &fresh[k];
        total += m.volume;
        assert!((m.volume - f.volume).abs() <= 1e-12, "{m:?} against {f:?}");
        assert!((m.surface_area - f.surface_area).abs() <= 1e-12, "{m:?}");
        assert_eq!(m.faces, f.faces);
        for c in 0..3 {
            assert!((m.centroid[c] - f.centroid[c]).abs() <= 1e-12, "{m:?}");
        }
    }
    assert!((total - 1.0).abs() <= 1e-12, "{total}");
}
