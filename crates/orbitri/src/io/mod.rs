//! Readers (points from text or `.npy`) and writers (the `cells` format, JSON, SVG, the
//! Voronoi tables, and VTK) for every flat space ([`SpaceFormat`] says how a space writes
//! its group elements).

mod format;
mod npy;
mod svg;
mod tessellation;
mod text;
mod write;

pub use format::SpaceFormat;
pub use npy::{encode_npy, encode_npy_matrix, parse_npy, read_npy};
pub use svg::{write_svg, Drawable, SvgOptions, Tiling};
pub use tessellation::{
    point_table, write_delaunay_vtu, write_edges_csv, write_neighbors_csv, write_voronoi_json,
    write_voronoi_vtu, PointTable,
};
pub use text::{parse_text, read_text};
pub use write::{write_cells, write_json};

use std::path::Path;

use crate::error::Result;

/// Reads `D`-dimensional points from a text file or, for a `.npy` name, a float64 array
/// of shape `(N, D)`.
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
