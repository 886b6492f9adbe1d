//! orbitri: exact Delaunay triangulations of point sets in orbit spaces.
//!
//! The orbit spaces so far are the 2D and 3D flat tori of any lattice (square, rectangle,
//! hexagonal or oblique cells; cubes, cuboids, triclinic boxes), with their periodic Voronoi
//! cells.
//!
//! ```
//! use orbitri::{FlatTorus2, FlatTorus3, PeriodicDelaunay2, PeriodicDelaunay3};
//! let torus = FlatTorus3::cuboid([1.0, 1.0, 1.0]).unwrap();
//! let pts: Vec<[f64; 3]> = (0..200).map(|i| {
//!     let f = i as f64;
//!     [(f * 0.618034) % 1.0, (f * 0.414214) % 1.0, (f * 0.732051) % 1.0]
//! }).collect();
//! let tri = PeriodicDelaunay3::build(torus, &pts).unwrap();
//! assert!(tri.is_valid().is_ok());
//! assert_eq!(tri.number_of_vertices(), 200);
//! let volume: f64 = tri.voronoi_cells().iter().map(|c| c.volume).sum();
//! assert!((volume - 1.0).abs() < 1e-12);
//!
//! let hex = FlatTorus2::triclinic([[1.0, 0.0], [0.5, 0.75f64.sqrt()]]).unwrap();
//! let tri2 = PeriodicDelaunay2::build(hex, &[[0.1, 0.2], [0.7, 0.4], [0.3, 0.8]]).unwrap();
//! assert!(tri2.sheets() > 1); // three points: still in a covering space
//! ```

// Geometry code indexes coordinates and cell slots by number, as the formulas do.
#![allow(clippy::needless_range_loop)]

pub mod delaunay;
pub mod error;
pub mod ids;
pub mod io;
pub mod predicates;
pub mod sort;
pub mod space;
pub mod spherical;
pub mod tds;
pub mod triangulation;
pub mod voronoi;

pub use delaunay::{Engine, Inserted, Invalid, Moved, Removal};
pub use error::{Error, Result};
pub use ids::{CellId, InputId, PointId, VertexId};
pub use space::{
    Coset, FlatManifold, FlatSpace, FlatTorus, FlatTorus2, FlatTorus3, Ladder, Lattice, Motion,
    OrbitSpace, ProjectivePlane, Sphere,
};
pub use spherical::{ProjectiveDelaunay, SphericalCell, SphericalDelaunay};
pub use triangulation::{
    BuildOptions, CellView, Complex, Copies, DelaunayEdge, KleinTriangulation,
    ManifoldTriangulation3, PeriodicDelaunay, PeriodicDelaunay2, PeriodicDelaunay3, Simplex,
    Triangulation,
};
pub use voronoi::{CellMeasures, MeasuresAndNeighbors, Neighbor, VoronoiCell, VoronoiFace};
