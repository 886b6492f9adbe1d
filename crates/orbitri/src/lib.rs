//! orbitri: exact Delaunay triangulations of point sets in orbit spaces.
//!
//! The first orbit space is the 3D flat torus of any lattice (cube, cuboid, triclinic).
//!
//! ```
//! use orbitri::{FlatTorus3, PeriodicDelaunay3};
//! let torus = FlatTorus3::cuboid([1.0, 1.0, 1.0]).unwrap();
//! let pts: Vec<[f64; 3]> = (0..200).map(|i| {
//!     let f = i as f64;
//!     [(f * 0.618034) % 1.0, (f * 0.414214) % 1.0, (f * 0.732051) % 1.0]
//! }).collect();
//! let tri = PeriodicDelaunay3::build(torus, &pts).unwrap();
//! assert!(tri.is_valid().is_ok());
//! assert_eq!(tri.number_of_vertices(), 200);
//! ```

// Geometry code indexes coordinates and cell slots by number, as the formulas do.
#![allow(clippy::needless_range_loop)]

pub mod delaunay;
pub mod error;
pub mod io;
pub mod periodic;
pub mod predicates;
pub mod sort;
pub mod space;
pub mod tds;
pub mod voronoi;

pub use delaunay::{Engine, Inserted, Invalid};
pub use error::{Error, Result};
pub use periodic::{
    BuildOptions, CellView, Copies, DelaunayEdge, PeriodicDelaunay, PeriodicDelaunay2,
    PeriodicDelaunay3, Simplex,
};
pub use space::{FlatTorus, FlatTorus2, FlatTorus3, Ladder, Lattice, OrbitSpace};
pub use voronoi::{CellMeasures, Neighbor, VoronoiCell, VoronoiFace};
