//! Readers (points from text or `.npy`, boxes from lengths and angles) and writers (the `cells` format, JSON, SVG, the
//! Voronoi tables, and VTK) for every flat space ([`SpaceFormat`] says how a space writes
//! its group elements).

mod cellpar;
mod format;
mod npy;
mod sphere;
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
pub use sphere::{
    sphere_point_table, write_sphere_cells, write_sphere_faces_vtu, write_sphere_json,
    write_sphere_svg, write_spherical_voronoi_json, write_spherical_voronoi_vtu,
};
pub use svg::{write_svg, Drawable, SvgOptions, Tiling};
pub use tessellation::{
    point_table, write_delaunay_vtu, write_edges_csv, write_neighbors_csv, write_voronoi_json,
    write_voronoi_vtu, PointTable,
};
pub use text::{parse_text, read_text};
pub use write::{write_cells, write_json};

use std::path::Path;

use crate::error::{Error, Result};

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

/// What the extra last column of weighted points holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WeightColumn {
    /// The weight itself (a squared length).
    Weight,
    /// A radius `r ≥ 0`: the weight is `r²`.
    Radius,
}

/// Reads `D`-dimensional points with one more number per row (as [`read_points`]), a
/// weight or a radius, and returns the points and their weights. A radius that is negative
/// or not finite is an error naming its row.
pub fn read_weighted_points<const D: usize>(
    path: &Path,
    column: WeightColumn,
) -> Result<(Vec<[f64; D]>, Vec<f64>)> {
    let rows: Vec<Vec<f64>> = match D {
        2 => read_points::<3>(path)?.iter().map(|r| r.to_vec()).collect(),
        3 => read_points::<4>(path)?.iter().map(|r| r.to_vec()).collect(),
        _ => unreachable!("points are 2D or 3D"),
    };
    let points = rows.iter().map(|r| std::array::from_fn(|c| r[c])).collect();
    let weights = rows
        .iter()
        .enumerate()
        .map(|(i, r)| match column {
            WeightColumn::Weight => Ok(r[D]),
            WeightColumn::Radius if r[D].is_finite() && r[D] >= 0.0 => Ok(r[D] * r[D]),
            WeightColumn::Radius => Err(Error::BadWeight {
                index: i,
                what: "radius",
                value: r[D],
                why: format!("in {} is not a finite number ≥ 0", path.display()),
            }),
        })
        .collect::<Result<_>>()?;
    Ok((points, weights))
}
