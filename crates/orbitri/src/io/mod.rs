//! Readers (points from text or `.npy`, boxes from lengths and angles) and writers (the `cells` format, JSON, SVG, the
//! Voronoi tables, and VTK) for every flat space ([`SpaceFormat`] says how a space writes
//! its group elements).

mod cellpar;
mod format;
mod npy;
mod svg;
mod tessellation;
mod text;
mod write;

pub use cellpar::{lattice_from_cellpar, lattice_from_cellpar2};
pub use format::SpaceFormat;
pub use npy::{
    encode_npy, encode_npy_array, encode_npy_matrix, encode_npz, parse_npy, read_npy, NpyArray,
    NpyData,
};
pub use svg::{write_svg, Drawable, SvgOptions, Tiling};
pub use tessellation::{
    point_table, write_delaunay_vtu, write_edges_csv, write_neighbors_csv, write_voronoi_json,
    write_voronoi_vtu, PointTable,
};
pub use text::{parse_text, read_text};
pub use write::{write_cells, write_json};

use std::path::Path;

use crate::error::Result;

/// Reads `D`-dimensional points from a text file or, for a `.npy` name, an array of shape
/// `(N, D)` (float64, float32 or integers).
pub fn read_points<const D: usize>(path: &Path) -> Result<Vec<[f64; D]>> {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
    {
        read_npy(path)
    } else {
        read_text(path)
    }
}
