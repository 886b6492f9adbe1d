//! The real projective plane through its facade: the faces and Voronoi cells against the
//! sphere's of the centrally symmetric set ±P (an independent computation in the other
//! space), χ = 1, antipodal duplicates, small sets and great circles, removals against
//! fresh builds.

use std::collections::BTreeSet;
use std::f64::consts::PI;

use orbitri::predicates::spherical::orient_origin;
use orbitri::predicates::Sign;
use orbitri::sort::SplitMix;
use orbitri::spherical::{ProjectiveDelaunay, SphericalDelaunay, Status};
use orbitri::{Error, InputId};

fn random_points(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = SplitMix::new(seed);
    (0..n).map(|_| r.on_sphere()).collect()
}

fn neg(p: [f64; 3]) -> [f64; 3] {
    p.map(|x| -x)
}

/// A face by the bits of its three positions (−0 as 0: duplicates may differ in the sign
/// of a zero), the same for a face and its antipode.
fn key(f: [[f64; 3]; 3]) -> [[u64; 3]; 3] {
    let sorted = |f: [[f64; 3]; 3]| {
        let mut b = f.map(|p| p.map(|x| (x + 0.0).to_bits()));
        b.sort_unstable();
        b
    };
    sorted(f).min(sorted(f.map(neg)))
}

/// The lifted faces of the projective plane: each vertex's point, negated where its sign
/// says, counter-clockwise seen from outside.
fn lifted_faces(tri: &ProjectiveDelaunay) -> Vec<[[f64; 3]; 3]> {
    tri.faces()
        .iter()
        .zip(tri.face_signs())
        .map(|(f, s)| {
            std::array::from_fn(|k| {
                let p = tri.point(f[k]).unwrap();
                if s[k] {
                    neg(p)
                } else {
                    p
                }
            })
        })
        .collect()
}

#[test]
fn faces_and_cells_are_the_spheres_of_both_copies() {
    for (n, seed) in [(3, 1), (7, 2), (40, 3), (2000, 4)] {
        let pts = random_points(n, seed);
        let tri = ProjectiveDelaunay::build(&pts).unwrap();
        tri.is_valid().unwrap();
        assert_eq!(tri.dimension(), 2);
        assert!(tri.covers_sphere());
        // χ = 1: F = 2V − 2, one face per face of RP² whether or not it is stored in its
        // covering sphere
        let faces = lifted_faces(&tri);
        assert_eq!(faces.len(), 2 * n - 2, "{n} points");
        for f in &faces {
            assert_eq!(orient_origin(&f[0], &f[1], &f[2]), Sign::Positive);
        }
        assert!(tri
            .face_signs()
            .iter()
            .all(|s| s.iter().filter(|&&x| x).count() <= 1));
        let both: Vec<[f64; 3]> = pts.iter().flat_map(|&p| [p, neg(p)]).collect();
        let sphere = SphericalDelaunay::build(&both).unwrap();
        let theirs: BTreeSet<_> = sphere
            .faces()
            .iter()
            .map(|f| key(f.map(|i| both[i.index()])))
            .collect();
        let ours: BTreeSet<_> = faces.iter().map(|&f| key(f)).collect();
        assert_eq!(ours, theirs, "{n} points");
        // the Voronoi cell of p in RP² is that of p in the sphere's diagram of ±P
        let cells = tri.voronoi_cells().unwrap();
        let total: f64 = cells.iter().map(|c| c.area).sum();
        assert!((total - 2.0 * PI).abs() < 1e-12, "{total}");
        let on_sphere = sphere.voronoi_cells().unwrap();
        for c in &cells {
            let p = pts[c.site.index()];
            let twin = on_sphere
                .iter()
                .find(|s| both[s.site.index()] == p || both[s.site.index()] == neg(p))
                .unwrap();
            assert!((c.area - twin.area).abs() < 1e-12);
            assert_eq!(c.vertices.len(), twin.vertices.len());
        }
    }
}

#[test]
fn antipodes_are_one_point_and_small_sets_have_their_dimension() {
    let mut tri = ProjectiveDelaunay::new();
    assert_eq!(tri.dimension(), -2);
    assert_eq!(tri.insert([1.0, 0.0, 0.0]).unwrap(), Status::Vertex);
    assert_eq!(
        tri.insert([-1.0, 0.0, 0.0]).unwrap(),
        Status::Duplicate(InputId(0))
    );
    assert_eq!(tri.dimension(), -1);
    tri.insert([0.0, 1.0, 0.0]).unwrap();
    assert_eq!(tri.dimension(), 0);
    // a third point on the same great circle: a projective line
    tri.insert([0.6, -0.8, 0.0]).unwrap();
    assert_eq!(tri.dimension(), 1);
    assert!(tri.faces().is_empty());
    assert!(matches!(
        tri.voronoi_cells(),
        Err(Error::NoFaces { dimension: 1, .. })
    ));
    tri.is_valid().unwrap();
    tri.insert([0.0, 0.0, -1.0]).unwrap();
    assert_eq!(tri.dimension(), 2);
    assert!(tri.covers_sphere());
    tri.is_valid().unwrap();
    assert_eq!(tri.faces().len(), 2 * 4 - 2);
    let total: f64 = tri.voronoi_cells().unwrap().iter().map(|c| c.area).sum();
    assert!((total - 2.0 * PI).abs() < 1e-12);
}

#[test]
fn removals_equal_fresh_builds() {
    let pts = random_points(300, 9);
    let mut tri = ProjectiveDelaunay::build(&pts).unwrap();
    let mut r = SplitMix::new(4);
    let mut alive: Vec<usize> = (0..pts.len()).collect();
    for step in 0..297 {
        let k = alive.swap_remove(r.below(alive.len()));
        tri.remove(InputId::new(k)).unwrap();
        if step % 31 == 0 || alive.len() < 8 {
            tri.is_valid().unwrap();
            let kept: Vec<[f64; 3]> = alive.iter().map(|&i| pts[i]).collect();
            let fresh = ProjectiveDelaunay::build(&kept).unwrap();
            let a: BTreeSet<_> = lifted_faces(&tri).into_iter().map(key).collect();
            let b: BTreeSet<_> = lifted_faces(&fresh).into_iter().map(key).collect();
            assert_eq!(a, b, "after {} removals", step + 1);
        }
    }
}

#[test]
fn a_lonlat_grid_of_the_projective_plane() {
    // both hemispheres of a grid: every point meets its antipode
    let mut lonlat = Vec::new();
    for i in 0..24 {
        for j in -6..=6 {
            lonlat.push([i as f64 * 15.0, j as f64 * 15.0]);
        }
    }
    let tri = ProjectiveDelaunay::build_lonlat(&lonlat).unwrap();
    tri.is_valid().unwrap();
    // 24·10 points off the poles and the equator, half of them antipodes of the others;
    // 24 on the equator, likewise; both poles one point
    assert_eq!(tri.number_of_vertices(), 120 + 12 + 1);
    assert_eq!(tri.faces().len(), 2 * tri.number_of_vertices() - 2);
    let total: f64 = tri.voronoi_cells().unwrap().iter().map(|c| c.area).sum();
    assert!((total - 2.0 * PI).abs() < 1e-12);
}

mod properties {
    use super::*;
    use orbitri::spherical::{lonlat_to_point, SphericalSpace, SphericalTriangulation};
    use proptest::prelude::*;

    /// Points on a 30° lon/lat grid: duplicates, antipodes, poles and cocircular sets.
    fn grid_point() -> impl Strategy<Value = [f64; 3]> {
        (0i32..12, -3i32..=3)
            .prop_map(|(i, j)| lonlat_to_point(0, f64::from(i * 30), f64::from(j * 30)).unwrap())
    }

    #[derive(Clone, Debug)]
    enum Op {
        Insert([f64; 3]),
        Remove(usize),
    }

    fn op() -> impl Strategy<Value = Op> {
        prop_oneof![
            3 => grid_point().prop_map(Op::Insert),
            1 => any::<usize>().prop_map(Op::Remove),
        ]
    }

    /// The faces of `tri` as sets of lifted positions, the same for a face and its antipode.
    fn faces_of<S: SphericalSpace>(tri: &SphericalTriangulation<S>) -> BTreeSet<[[u64; 3]; 3]> {
        tri.faces()
            .iter()
            .zip(tri.face_signs())
            .map(|(f, s)| {
                key(std::array::from_fn(|k| {
                    let p = tri.point(f[k]).unwrap();
                    if s[k] {
                        neg(p)
                    } else {
                        p
                    }
                }))
            })
            .collect()
    }

    /// Runs `ops`: valid after every step, every live input a vertex or a duplicate, and at
    /// the end the faces of a fresh build of the live points.
    fn run<S: SphericalSpace>(ops: &[Op]) -> Result<(), TestCaseError> {
        let mut tri = SphericalTriangulation::<S>::new();
        let mut given: Vec<[f64; 3]> = Vec::new();
        let mut live: Vec<usize> = Vec::new();
        for (step, op) in ops.iter().enumerate() {
            match *op {
                Op::Insert(p) => {
                    tri.insert(p).unwrap();
                    live.push(given.len());
                    given.push(p);
                }
                Op::Remove(k) if !live.is_empty() => {
                    let i = live.swap_remove(k % live.len());
                    tri.remove(InputId::new(i)).unwrap();
                }
                Op::Remove(_) => prop_assert!(tri.remove(InputId(0)).is_err() || !given.is_empty()),
            }
            prop_assert!(
                tri.is_valid().is_ok(),
                "step {step} {op:?}: {:?}",
                tri.is_valid()
            );
            prop_assert!(tri.hidden().is_empty());
        }
        let kept: Vec<[f64; 3]> = live.iter().map(|&i| given[i]).collect();
        if !kept.is_empty() {
            let fresh = SphericalTriangulation::<S>::build(&kept).unwrap();
            prop_assert_eq!(fresh.dimension(), tri.dimension());
            prop_assert_eq!(faces_of(&fresh), faces_of(&tri));
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(40),
            ..ProptestConfig::default()
        })]

        /// Random insertions and removals on a lon/lat grid, on the sphere and on RP².
        #[test]
        fn random_sequences_stay_delaunay(ops in proptest::collection::vec(op(), 1..60)) {
            run::<orbitri::Sphere>(&ops)?;
            run::<orbitri::ProjectivePlane>(&ops)?;
        }
    }
}
