//! Writers of the Voronoi tessellation and of the triangulation for other programs: per-point
//! CSV and `.npy` tables, neighbour and edge lists, JSON cells, and VTK UnstructuredGrid
//! (`.vtu`) files that ParaView opens.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::Write;

use super::format::SpaceFormat;
use super::npy::encode_npy_matrix;
use super::write::{json_f64, json_point};
use crate::ids::InputId;
use crate::space::FlatSpace;
use crate::triangulation::Triangulation;
use crate::voronoi::{CellMeasures, VoronoiCell};
use crate::Copies;

const AXES: [&str; 3] = ["x", "y", "z"];

/// The per-point table, one row per *input* point in input order: its cell's volume (area in
/// 2D), number of faces, surface area (perimeter in 2D), centroid, and the input id of the
/// first occurrence for a duplicate (which shares that cell), else `-1`.
pub struct PointTable {
    pub columns: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

/// Builds the per-point table of a triangulation from its cells' measures (any order).
pub fn point_table<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    tri: &Triangulation<D, N, S>,
    cells: &[CellMeasures<D>],
) -> PointTable {
    let by_point: HashMap<InputId, &CellMeasures<D>> = cells.iter().map(|c| (c.point, c)).collect();
    let first = tri.first_occurrences();
    let mut columns: Vec<String> = ["id", "volume", "neighbours", "surface_area"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    columns.extend((0..D).map(|k| format!("centroid_{}", AXES[k])));
    columns.push("duplicate_of".into());
    let rows = (0..tri.number_of_input_points())
        .map(|i| {
            let c = by_point[&first[i]];
            let mut row = vec![i as f64, c.volume, c.faces as f64, c.surface_area];
            row.extend_from_slice(&c.centroid);
            row.push(if first[i].index() == i {
                -1.0
            } else {
                f64::from(first[i].0)
            });
            row
        })
        .collect();
    PointTable { columns, rows }
}

impl PointTable {
    /// CSV with a header line; integer columns are written as integers, an absent
    /// `duplicate_of` as an empty field.
    pub fn write_csv(&self, w: &mut impl Write) -> std::io::Result<()> {
        writeln!(w, "{}", self.columns.join(","))?;
        let last = self.columns.len() - 1;
        let mut line = String::new();
        for r in &self.rows {
            line.clear();
            for (k, v) in r.iter().enumerate() {
                if k > 0 {
                    line.push(',');
                }
                match k {
                    0 | 2 => write!(line, "{}", *v as u64),
                    _ if k == last => match *v < 0.0 {
                        true => Ok(()),
                        false => write!(line, "{}", *v as u64),
                    },
                    _ => write!(line, "{v:?}"),
                }
                .expect("writing to a string");
            }
            writeln!(w, "{line}")?;
        }
        Ok(())
    }

    /// A float64 `.npy` array of shape `(N, columns)`, the CSV's columns in order
    /// (`duplicate_of` is −1 for none).
    pub fn npy(&self) -> Vec<u8> {
        let flat: Vec<f64> = self.rows.iter().flatten().copied().collect();
        encode_npy_matrix(&flat, self.columns.len())
    }
}

/// The Voronoi neighbour pairs of `cells` (as [`Triangulation::voronoi_cells`] gives them)
/// as CSV, each pair of images once: `i,j,ELEMENT…,area`, the element's columns as
/// [`SpaceFormat::element_columns`] names them (a torus's `shift_x,shift_y[,shift_z]`).
pub fn write_neighbors_csv<const D: usize, const N: usize, S: SpaceFormat<D, N>>(
    w: &mut impl Write,
    tri: &Triangulation<D, N, S>,
    cells: &[VoronoiCell<D, S::Elem>],
) -> std::io::Result<()> {
    let rows = tri
        .voronoi_neighbors_of(cells)
        .into_iter()
        .map(|p| (p.i, p.j, p.shift, p.area));
    write_pairs_csv::<D, N, S>(w, "area", rows)
}

/// Rows `i,j,ELEMENT…,VALUE` under a header naming the element's and the value's columns.
fn write_pairs_csv<const D: usize, const N: usize, S: SpaceFormat<D, N>>(
    w: &mut impl Write,
    value: &str,
    rows: impl Iterator<Item = (InputId, InputId, S::Elem, f64)>,
) -> std::io::Result<()> {
    writeln!(w, "i,j,{},{value}", S::element_columns().join(","))?;
    for (i, j, g, x) in rows {
        let s: Vec<String> = S::element_integers(g).map(|x| x.to_string()).collect();
        writeln!(w, "{i},{j},{},{x:?}", s.join(","))?;
    }
    Ok(())
}

/// The Delaunay edges as CSV: `i,j,ELEMENT…,length`, `j`'s image at `g·points[j]` (in a
/// torus `points[j] + shift·M`).
pub fn write_edges_csv<const D: usize, const N: usize, S: SpaceFormat<D, N>>(
    w: &mut impl Write,
    tri: &Triangulation<D, N, S>,
) -> std::io::Result<()> {
    let rows = tri
        .delaunay_edges()
        .into_iter()
        .map(|e| (e.i, e.j, e.shift, e.length));
    write_pairs_csv::<D, N, S>(w, "length", rows)
}

/// JSON: `{"dimension"`, the space ([`SpaceFormat::json_space`]), `"cells": [{"id",
/// "position", "volume", "centroid", "vertices", "faces": [{"vertices", "neighbor", ELEMENT,
/// "area"}]}], "duplicate_of"}`, cells in order of their first occurrence;
/// `duplicate_of[i]` is the first occurrence's id. A face's element is a torus's `"shift"`,
/// a manifold's `"element"` `[A, t]`: the neighbour's image across the face.
pub fn write_voronoi_json<const D: usize, const N: usize, S: SpaceFormat<D, N>>(
    w: &mut impl Write,
    tri: &Triangulation<D, N, S>,
    cells: &[VoronoiCell<D, S::Elem>],
) -> std::io::Result<()> {
    let space = tri.space();
    write!(w, "{{\"dimension\":{D},{},\"cells\":[", space.json_space())?;
    for (k, c) in cells.iter().enumerate() {
        let vertices: Vec<String> = c.vertices.iter().map(|v| json_point(v)).collect();
        let faces: Vec<String> = c
            .faces
            .iter()
            .map(|f| {
                format!(
                    "{{\"vertices\":{},\"neighbor\":{},\"{}\":{},\"area\":{}}}",
                    format!("{:?}", f.vertices).replace(' ', ""),
                    f.neighbor,
                    S::FACE_ELEMENT,
                    space.json_element(f.shift),
                    json_f64(f.area)
                )
            })
            .collect();
        write!(
            w,
            "{}{{\"id\":{},\"position\":{},\"volume\":{},\"centroid\":{},\"vertices\":[{}],\"faces\":[{}]}}",
            if k > 0 { "," } else { "" },
            c.point,
            json_point(&c.position),
            json_f64(c.volume),
            json_point(&c.centroid),
            vertices.join(","),
            faces.join(",")
        )?;
    }
    let firsts: Vec<String> = tri
        .first_occurrences()
        .iter()
        .map(|x| x.to_string())
        .collect();
    writeln!(w, "],\"duplicate_of\":[{}]}}", firsts.join(","))
}

/// A VTK UnstructuredGrid in ASCII: 3D points (2D padded with z = 0), cells by VTK type,
/// optional polyhedron face streams, and point and cell data arrays.
#[derive(Default)]
struct Vtu {
    points: Vec<[f64; 3]>,
    connectivity: Vec<u64>,
    offsets: Vec<u64>,
    types: Vec<u8>,
    /// For polyhedra: per cell `[n_faces, (n, ids…)…]`, and the running end offsets.
    faces: Vec<u64>,
    face_offsets: Vec<u64>,
    point_data: Vec<(&'static str, Vec<f64>)>,
    cell_data: Vec<(&'static str, Vec<f64>)>,
}

fn pad<const D: usize>(p: &[f64; D]) -> [f64; 3] {
    std::array::from_fn(|k| if k < D { p[k] } else { 0.0 })
}

fn data_array(out: &mut String, name: &str, kind: &str, comps: usize, values: &[String]) {
    let _ = writeln!(
        out,
        r#"<DataArray type="{kind}" Name="{name}" NumberOfComponents="{comps}" format="ascii">"#
    );
    for chunk in values.chunks(12) {
        let _ = writeln!(out, "{}", chunk.join(" "));
    }
    let _ = writeln!(out, "</DataArray>");
}

impl Vtu {
    fn write(&self, w: &mut impl Write) -> std::io::Result<()> {
        let mut s = String::new();
        let _ = writeln!(
            s,
            r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">
<UnstructuredGrid>
<Piece NumberOfPoints="{}" NumberOfCells="{}">"#,
            self.points.len(),
            self.types.len()
        );
        let fmt = |v: &[f64]| v.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>();
        let ints = |v: &[u64]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        let _ = writeln!(s, "<Points>");
        data_array(
            &mut s,
            "Points",
            "Float64",
            3,
            &fmt(self.points.as_flattened()),
        );
        let _ = writeln!(s, "</Points>\n<Cells>");
        data_array(
            &mut s,
            "connectivity",
            "Int64",
            1,
            &ints(&self.connectivity),
        );
        data_array(&mut s, "offsets", "Int64", 1, &ints(&self.offsets));
        let types: Vec<String> = self.types.iter().map(|t| t.to_string()).collect();
        data_array(&mut s, "types", "UInt8", 1, &types);
        if !self.faces.is_empty() {
            data_array(&mut s, "faces", "Int64", 1, &ints(&self.faces));
            data_array(&mut s, "faceoffsets", "Int64", 1, &ints(&self.face_offsets));
        }
        let _ = writeln!(s, "</Cells>\n<PointData>");
        for (name, v) in &self.point_data {
            data_array(&mut s, name, "Float64", 1, &fmt(v));
        }
        let _ = writeln!(s, "</PointData>\n<CellData>");
        for (name, v) in &self.cell_data {
            data_array(&mut s, name, "Float64", 1, &fmt(v));
        }
        let _ = writeln!(s, "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>");
        w.write_all(s.as_bytes())
    }
}

/// The Voronoi cells as a `.vtu`: each cell whole around its point (cells that cross the
/// domain boundary are not cut), polyhedra in 3D, polygons in 2D, with the input id and the
/// volume as cell data and the id as point data.
pub fn write_voronoi_vtu<const D: usize, E>(
    w: &mut impl Write,
    cells: &[VoronoiCell<D, E>],
) -> std::io::Result<()> {
    let mut v = Vtu::default();
    let (mut ids, mut pid, mut vol) = (Vec::new(), Vec::new(), Vec::new());
    for c in cells {
        let base = v.points.len() as u64;
        v.points.extend(c.vertices.iter().map(pad));
        pid.extend(std::iter::repeat_n(f64::from(c.point.0), c.vertices.len()));
        v.connectivity
            .extend((0..c.vertices.len() as u64).map(|k| base + k));
        v.offsets.push(v.connectivity.len() as u64);
        if D == 2 {
            v.types.push(7); // VTK_POLYGON, vertices counter-clockwise
        } else {
            v.types.push(42); // VTK_POLYHEDRON
            v.faces.push(c.faces.len() as u64);
            for f in &c.faces {
                v.faces.push(f.vertices.len() as u64);
                v.faces.extend(f.vertices.iter().map(|&k| base + k as u64));
            }
            v.face_offsets.push(v.faces.len() as u64);
        }
        ids.push(f64::from(c.point.0));
        vol.push(c.volume);
    }
    v.point_data.push(("id", pid));
    v.cell_data.push(("id", ids));
    v.cell_data.push(("volume", vol));
    v.write(w)
}

/// The triangulation as a `.vtu`: one copy of each cell of the space, drawn whole at its
/// stored elements (cells crossing the boundary stick out of the domain), vertex positions
/// `g·p` (in a torus `p + o·M`) shared between cells, and the input id of each vertex as
/// point data.
pub fn write_delaunay_vtu<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    w: &mut impl Write,
    tri: &Triangulation<D, N, S>,
) -> std::io::Result<()> {
    let mut v = Vtu::default();
    let mut index: HashMap<(InputId, S::Elem), u64> = HashMap::new();
    let mut pid = Vec::new();
    for c in tri.cells(Copies::Unique) {
        for k in 0..N {
            let key = (c.vertices[k], c.offsets[k]);
            let id = *index.entry(key).or_insert_with(|| {
                v.points.push(pad(&tri.position(key.0, key.1)));
                pid.push(f64::from(key.0 .0));
                v.points.len() as u64 - 1
            });
            v.connectivity.push(id);
        }
        v.offsets.push(v.connectivity.len() as u64);
        v.types.push(if D == 2 { 5 } else { 10 }); // VTK_TRIANGLE, VTK_TETRA
    }
    v.point_data.push(("id", pid));
    v.write(w)
}
