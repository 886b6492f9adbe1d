//! Writers of the Voronoi tessellation and of the triangulation for other programs: per-point
//! CSV and `.npy` tables, neighbour and edge lists, JSON cells, and VTK UnstructuredGrid
//! (`.vtu`) files that ParaView opens.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::Write;

use super::format::SpaceFormat;
use super::npy::{encode_npy_matrix, encode_npz, NpyArray, NpyData};
use super::write::{json_f64, json_point};
use crate::ids::InputId;
use crate::space::FlatSpace;
use crate::triangulation::Triangulation;
use crate::voronoi::{CellMeasures, Neighbor, VoronoiCell};

const AXES: [&str; 3] = ["x", "y", "z"];

/// The per-point table, one row per *input* point in input order: its cell's volume (area in
/// 2D), number of faces, surface area (perimeter in 2D), centroid, for weighted points
/// whether it is hidden (1: its power cell is empty), and the input id of the first
/// occurrence for a duplicate (which shares that cell), else `-1`.
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
    let weighted = tri.is_weighted();
    if weighted {
        columns.push("hidden".into());
    }
    columns.push("duplicate_of".into());
    let rows = (0..tri.number_of_input_points())
        .map(|i| {
            let c = by_point[&first[i]];
            let mut row = vec![i as f64, c.volume, c.faces as f64, c.surface_area];
            row.extend_from_slice(&c.centroid);
            if weighted {
                row.push(f64::from(u8::from(tri.is_hidden(InputId::new(i)))));
            }
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
                    _ if self.columns[k] == "hidden" => write!(line, "{}", *v as u64),
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

    /// An `.npz` archive of the columns as named arrays (`numpy.load(f)["volume"]`): `id`,
    /// `neighbours` and `duplicate_of` (−1 for none) as int64, `volume` and `surface_area`
    /// as float64 (N), and `centroid` as float64 N × D.
    pub fn npz(&self) -> std::io::Result<Vec<u8>> {
        let column = |k: usize| self.rows.iter().map(move |r| r[k]);
        let ints = |k: usize| NpyData::I64(column(k).map(|v| v as i64).collect());
        let floats = |k: usize| NpyData::F64(column(k).collect());
        let last = self.columns.len() - 1;
        let hidden = self.columns.iter().position(|c| c == "hidden");
        let dim = hidden.unwrap_or(last) - 4;
        let centroid = self
            .rows
            .iter()
            .flat_map(|r| r[4..4 + dim].to_vec())
            .collect();
        let named = |name: &str, data: NpyData, cols: Option<usize>| NpyArray {
            name: name.to_string(),
            data,
            cols,
        };
        let mut arrays = vec![
            named("id", ints(0), None),
            named(&self.columns[1], floats(1), None),
            named("neighbours", ints(2), None),
            named(&self.columns[3], floats(3), None),
            named("centroid", NpyData::F64(centroid), Some(dim)),
        ];
        if let Some(k) = hidden {
            arrays.push(named("hidden", ints(k), None));
        }
        arrays.push(named("duplicate_of", ints(last), None));
        encode_npz(&arrays)
    }
}

/// The Voronoi neighbour pairs (as [`Triangulation::voronoi_neighbors`] gives them, each
/// pair of images once) as CSV: `i,j,ELEMENT…,area`, the element's columns as
/// [`SpaceFormat::element_columns`] names them (a torus's `shift_x,shift_y[,shift_z]`).
pub fn write_neighbors_csv<const D: usize, const N: usize, S: SpaceFormat<D, N>>(
    w: &mut impl Write,
    pairs: &[Neighbor<D, S::Elem>],
) -> std::io::Result<()> {
    let rows = pairs.iter().map(|p| (p.i, p.j, p.shift, p.area));
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
        // (written piece by piece: a string an entry, joined, put about a fifth of the
        // writing in the allocator)
        write!(w, "{i},{j}")?;
        for a in S::element_integers(g) {
            write!(w, ",{a}")?;
        }
        writeln!(w, ",{x:?}")?;
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

/// A VTK UnstructuredGrid: 3D points (2D padded with z = 0), cells by VTK type, optional
/// polyhedron face streams, and point and cell data arrays; written binary (see
/// [`Vtu::write`]).
#[derive(Default)]
pub(super) struct Vtu {
    pub(super) points: Vec<[f64; 3]>,
    pub(super) connectivity: Vec<i64>,
    pub(super) offsets: Vec<i64>,
    pub(super) types: Vec<u8>,
    /// For polyhedra: per cell `[n_faces, (n, ids…)…]`, and the running end offsets.
    faces: Vec<i64>,
    face_offsets: Vec<i64>,
    pub(super) point_data: Vec<(&'static str, Values)>,
    pub(super) cell_data: Vec<(&'static str, Values)>,
}

/// The values of one VTK data array, and their number of components.
pub(super) enum Values {
    F64(Vec<f64>, usize),
    I64(Vec<i64>),
    U8(Vec<u8>),
}

impl Values {
    /// The zlib level: doubles (coordinates, measures) barely compress (by about 6 %, at
    /// 5 s for the 65 MB of points of 10⁵ cells), so they are stored; integers (ids, face
    /// streams) shrink about fivefold at the fastest level.
    fn compression(&self) -> flate2::Compression {
        match self {
            Values::F64(..) => flate2::Compression::none(),
            _ => flate2::Compression::fast(),
        }
    }

    /// VTK's type name, the components, and the little-endian bytes.
    fn parts(&self) -> (&'static str, usize, Vec<u8>) {
        match self {
            Values::F64(v, k) => (
                "Float64",
                *k,
                v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            ),
            Values::I64(v) => ("Int64", 1, v.iter().flat_map(|x| x.to_le_bytes()).collect()),
            Values::U8(v) => ("UInt8", 1, v.clone()),
        }
    }
}

/// The uncompressed size of a block of a compressed VTK array.
const VTU_BLOCK: usize = 1 << 20;

/// `bytes` as VTK's zlib-compressed binary: the header `[blocks, block size, size of the
/// last block (0 if full), compressed size of each block]` (UInt64), then the blocks,
/// compressed in parallel at `level`.
fn vtk_zlib(bytes: &[u8], level: flate2::Compression) -> Vec<u8> {
    use rayon::prelude::*;
    let blocks: Vec<Vec<u8>> = bytes
        .par_chunks(VTU_BLOCK)
        .map(|b| {
            let mut z = flate2::write::ZlibEncoder::new(Vec::new(), level);
            z.write_all(b).expect("writing to memory");
            z.finish().expect("writing to memory")
        })
        .collect();
    let mut out = Vec::new();
    let last = bytes.len() % VTU_BLOCK;
    let header = [blocks.len(), VTU_BLOCK, last]
        .into_iter()
        .chain(blocks.iter().map(Vec::len));
    for x in header {
        out.extend_from_slice(&(x as u64).to_le_bytes());
    }
    for b in blocks {
        out.extend_from_slice(&b);
    }
    out
}

impl Vtu {
    /// The XML header, every array `format="appended"` at its offset, then the raw
    /// appended data (each array zlib-compressed: [`vtk_zlib`]).
    pub(super) fn write(&self, w: &mut impl Write) -> std::io::Result<()> {
        let mut xml = String::new();
        let mut data: Vec<u8> = Vec::new();
        let mut array = |xml: &mut String, name: &str, values: &Values| {
            let (kind, comps, bytes) = values.parts();
            let _ = writeln!(
                xml,
                r#"<DataArray type="{kind}" Name="{name}" NumberOfComponents="{comps}" format="appended" offset="{}"/>"#,
                data.len()
            );
            data.extend_from_slice(&vtk_zlib(&bytes, values.compression()));
        };
        let _ = writeln!(
            xml,
            r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64" compressor="vtkZLibDataCompressor">
<UnstructuredGrid>
<Piece NumberOfPoints="{}" NumberOfCells="{}">
<Points>"#,
            self.points.len(),
            self.types.len()
        );
        let points = Values::F64(self.points.as_flattened().to_vec(), 3);
        array(&mut xml, "Points", &points);
        let _ = writeln!(xml, "</Points>\n<Cells>");
        array(
            &mut xml,
            "connectivity",
            &Values::I64(self.connectivity.clone()),
        );
        array(&mut xml, "offsets", &Values::I64(self.offsets.clone()));
        array(&mut xml, "types", &Values::U8(self.types.clone()));
        if !self.faces.is_empty() {
            array(&mut xml, "faces", &Values::I64(self.faces.clone()));
            array(
                &mut xml,
                "faceoffsets",
                &Values::I64(self.face_offsets.clone()),
            );
        }
        let _ = writeln!(xml, "</Cells>\n<PointData>");
        for (name, v) in &self.point_data {
            array(&mut xml, name, v);
        }
        let _ = writeln!(xml, "</PointData>\n<CellData>");
        for (name, v) in &self.cell_data {
            array(&mut xml, name, v);
        }
        let _ = write!(
            xml,
            "</CellData>\n</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_"
        );
        w.write_all(xml.as_bytes())?;
        w.write_all(&data)?;
        w.write_all(b"\n</AppendedData>\n</VTKFile>\n")
    }
}

fn pad<const D: usize>(p: &[f64; D]) -> [f64; 3] {
    std::array::from_fn(|k| if k < D { p[k] } else { 0.0 })
}

/// The Voronoi cells as a binary, zlib-compressed `.vtu`: each cell whole around its point
/// (cells that cross the domain boundary are not cut), polyhedra in 3D, polygons in 2D, with
/// cell data `id` (Int64), `volume`, `neighbours` (the number of faces, Int64),
/// `surface_area` and `centroid` (3 components), and the id as point data.
pub fn write_voronoi_vtu<const D: usize, E>(
    w: &mut impl Write,
    cells: &[VoronoiCell<D, E>],
) -> std::io::Result<()> {
    let mut v = Vtu::default();
    let (mut ids, mut pid, mut vol) = (Vec::new(), Vec::new(), Vec::new());
    let (mut counts, mut surface, mut centroid) = (Vec::new(), Vec::new(), Vec::new());
    for c in cells {
        let base = v.points.len() as i64;
        v.points.extend(c.vertices.iter().map(pad));
        pid.extend(std::iter::repeat_n(i64::from(c.point.0), c.vertices.len()));
        v.connectivity
            .extend((0..c.vertices.len() as i64).map(|k| base + k));
        v.offsets.push(v.connectivity.len() as i64);
        if D == 2 {
            v.types.push(7); // VTK_POLYGON, vertices counter-clockwise
        } else {
            v.types.push(42); // VTK_POLYHEDRON
            v.faces.push(c.faces.len() as i64);
            for f in &c.faces {
                v.faces.push(f.vertices.len() as i64);
                v.faces.extend(f.vertices.iter().map(|&k| base + k as i64));
            }
            v.face_offsets.push(v.faces.len() as i64);
        }
        let m = CellMeasures::from(c);
        ids.push(i64::from(c.point.0));
        vol.push(m.volume);
        counts.push(i64::from(m.faces));
        surface.push(m.surface_area);
        centroid.extend(pad(&m.centroid));
    }
    v.point_data.push(("id", Values::I64(pid)));
    v.cell_data.push(("id", Values::I64(ids)));
    v.cell_data.push(("volume", Values::F64(vol, 1)));
    v.cell_data.push(("neighbours", Values::I64(counts)));
    v.cell_data.push(("surface_area", Values::F64(surface, 1)));
    v.cell_data.push(("centroid", Values::F64(centroid, 3)));
    v.write(w)
}

/// The triangulation as a binary, zlib-compressed `.vtu`: one copy of each cell of the space, drawn whole at its
/// stored elements (cells crossing the boundary stick out of the domain), vertex positions
/// `g·p` (in a torus `p + o·M`) shared between cells, and the input id of each vertex as
/// point data.
pub fn write_delaunay_vtu<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    w: &mut impl Write,
    tri: &Triangulation<D, N, S>,
) -> std::io::Result<()> {
    let mut v = Vtu::default();
    let mut index: HashMap<(InputId, S::Elem), i64> = HashMap::new();
    let mut pid = Vec::new();
    for c in super::write::cells_of(tri)?.1 {
        for k in 0..N {
            let key = (c.vertices[k], c.offsets[k]);
            let id = *index.entry(key).or_insert_with(|| {
                v.points.push(pad(&tri.position(key.0, key.1)));
                pid.push(i64::from(key.0 .0));
                v.points.len() as i64 - 1
            });
            v.connectivity.push(id);
        }
        v.offsets.push(v.connectivity.len() as i64);
        v.types.push(if D == 2 { 5 } else { 10 }); // VTK_TRIANGLE, VTK_TETRA
    }
    v.point_data.push(("id", Values::I64(pid)));
    v.write(w)
}
