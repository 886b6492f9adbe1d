//! Writers for the sphere: the faces by input ids (the `cells` format), JSON, the per-point
//! Voronoi table and cells, and VTK files of the faces and of the Voronoi cells lying on the
//! sphere (arcs subdivided, so that ParaView draws them round).

use std::io::Write;

use super::tessellation::{PointTable, Values, Vtu};
use super::write::{json_f64, json_point};
use crate::ids::InputId;
use crate::spherical::{SphericalCell, SphericalSpace, SphericalTriangulation, Status};

/// Per input: the input id of its first occurrence (itself unless a duplicate), `None`
/// for a removed one.
fn first_occurrences<S: SphericalSpace>(tri: &SphericalTriangulation<S>) -> Vec<Option<InputId>> {
    (0..tri.number_of_input_points())
        .map(|i| {
            let i = InputId::new(i);
            tri.status(i).map(|s| match s {
                Status::Duplicate(j) => j,
                _ => i,
            })
        })
        .collect()
}

/// The `cells` format on the sphere: `1 V F` (one sheet, `V` vertices, `F` faces), then
/// per face its three input ids, counter-clockwise seen from outside. On the projective
/// plane each line adds the three vertices' signs (`1`, or `-1` for the antipode of the
/// stored point): the lifted face `(s₀p₀, s₁p₁, s₂p₂)` is counter-clockwise.
pub fn write_sphere_cells<S: SphericalSpace>(
    w: &mut impl Write,
    tri: &SphericalTriangulation<S>,
) -> std::io::Result<()> {
    let table = tri.face_table();
    writeln!(w, "1 {} {}", tri.number_of_vertices(), table.faces.len())?;
    for ([a, b, c], s) in table.faces.into_iter().zip(table.signs) {
        if S::ANTIPODAL {
            let [x, y, z] = s.map(|n| if n { -1 } else { 1 });
            writeln!(w, "{a} {b} {c} {x} {y} {z}")?;
        } else {
            writeln!(w, "{a} {b} {c}")?;
        }
    }
    Ok(())
}

/// JSON: `{"space": "sphere"` (or `"projective-plane"`), `"dimension"` (CGAL's, −2 to 2),
/// `"covers_sphere"`, `"points"` (input order as stored, `null` for removed ones),
/// `"first_occurrence"` (`-1` for removed), `"hidden"`, `"faces"` (input ids,
/// counter-clockwise from outside), `"signs"` (per face vertex, `-1` for an antipode) and
/// `"ghost_faces"` (CGAL's, for points in a closed hemisphere: the hull's faces that do not
/// hold the centre strictly inside) and `"neighbors"` (per face, then per ghost face, the
/// face across each edge `k` opposite vertex `k`, ghost faces numbered after the faces)`}`.
pub fn write_sphere_json<S: SphericalSpace>(
    w: &mut impl Write,
    tri: &SphericalTriangulation<S>,
) -> std::io::Result<()> {
    let n = tri.number_of_input_points();
    let points: Vec<String> = (0..n)
        .map(|i| {
            tri.point(InputId::new(i))
                .map_or("null".into(), |p| json_point(&p))
        })
        .collect();
    let firsts: Vec<String> = first_occurrences(tri)
        .iter()
        .map(|f| f.map_or("-1".into(), |j| j.to_string()))
        .collect();
    let ids = |v: &[InputId]| -> String {
        let s: Vec<String> = v.iter().map(|x| x.to_string()).collect();
        format!("[{}]", s.join(","))
    };
    let table = tri.face_table();
    let faces: Vec<String> = table.faces.iter().map(|f| ids(f)).collect();
    let ghosts: Vec<String> = table.ghosts.iter().map(|f| ids(f)).collect();
    let neighbors: Vec<String> = table
        .neighbors
        .iter()
        .map(|n| {
            let s: Vec<String> = n.iter().map(|k| k.to_string()).collect();
            format!("[{}]", s.join(","))
        })
        .collect();
    let signs: Vec<String> = table
        .signs
        .iter()
        .map(|s| format!("[{}]", s.map(|n| if n { "-1" } else { "1" }).join(",")))
        .collect();
    writeln!(
        w,
        "{{\"space\":\"{}\",\"dimension\":{},\"covers_sphere\":{},\"points\":[{}],\"first_occurrence\":[{}],\"hidden\":{},\"faces\":[{}],\"signs\":[{}],\"ghost_faces\":[{}],\"neighbors\":[{}]}}",
        S::NAME,
        tri.dimension(),
        tri.covers_sphere(),
        points.join(","),
        firsts.join(","),
        ids(&tri.hidden()),
        faces.join(","),
        signs.join(","),
        ghosts.join(","),
        neighbors.join(",")
    )
}

/// The per-point table on the sphere, one row per input in input order (removed ones
/// left out): `id, area, neighbours, perimeter, centroid_x, centroid_y, centroid_z, hidden,
/// duplicate_of` (a hidden point's cell is empty: area 0, no centroid).
pub fn sphere_point_table<S: SphericalSpace>(
    tri: &SphericalTriangulation<S>,
    cells: &[SphericalCell],
) -> PointTable {
    let mut by_site = vec![None; tri.number_of_input_points()];
    for c in cells {
        by_site[c.site.index()] = Some(c);
    }
    let columns = [
        "id",
        "area",
        "neighbours",
        "perimeter",
        "centroid_x",
        "centroid_y",
        "centroid_z",
        "hidden",
        "duplicate_of",
    ]
    .map(String::from)
    .to_vec();
    let rows = first_occurrences(tri)
        .into_iter()
        .enumerate()
        .filter_map(|(i, first)| {
            let first = first?;
            let mut row = vec![i as f64];
            match by_site[first.index()] {
                Some(c) => {
                    row.extend([c.area, c.neighbors.len() as f64]);
                    row.push(c.arc_lengths.iter().sum());
                    row.extend(c.centroid);
                    row.push(0.0);
                }
                None => row.extend([0.0, 0.0, 0.0, f64::NAN, f64::NAN, f64::NAN, 1.0]),
            }
            row.push(if first.index() == i {
                -1.0
            } else {
                f64::from(first.0)
            });
            Some(row)
        })
        .collect();
    PointTable { columns, rows }
}

/// Every Voronoi cell as JSON: `{"space": "sphere", "cells": [{"id", "position", "area",
/// "centroid", "vertices"` (counter-clockwise from outside), `"neighbors"` (across the arc
/// from vertex `k` to `k + 1`), `"arc_lengths"}…], "duplicate_of"}`.
pub fn write_spherical_voronoi_json<S: SphericalSpace>(
    w: &mut impl Write,
    tri: &SphericalTriangulation<S>,
    cells: &[SphericalCell],
) -> std::io::Result<()> {
    write!(w, "{{\"space\":\"{}\",\"cells\":[", S::NAME)?;
    for (k, c) in cells.iter().enumerate() {
        let vertices: Vec<String> = c.vertices.iter().map(|v| json_point(v)).collect();
        let neighbors: Vec<String> = c.neighbors.iter().map(|x| x.to_string()).collect();
        let position = tri.point(c.site).expect("a site is a live input");
        write!(
            w,
            "{}{{\"id\":{},\"position\":{},\"area\":{},\"centroid\":{},\"vertices\":[{}],\"neighbors\":[{}],\"arc_lengths\":{}}}",
            if k > 0 { "," } else { "" },
            c.site,
            json_point(&position),
            json_f64(c.area),
            json_point(&c.centroid),
            vertices.join(","),
            neighbors.join(","),
            json_point(&c.arc_lengths)
        )?;
    }
    let firsts: Vec<String> = first_occurrences(tri)
        .iter()
        .map(|f| f.map_or("-1".into(), |j| j.to_string()))
        .collect();
    writeln!(w, "],\"duplicate_of\":[{}]}}", firsts.join(","))
}

/// Points along the great-circle arc from `a` to `b` (unit vectors), `a` included and `b`
/// not, at most `step` radians apart.
pub(crate) fn arc_points(a: &[f64; 3], b: &[f64; 3], step: f64) -> Vec<[f64; 3]> {
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let theta = dot.clamp(-1.0, 1.0).acos();
    let pieces = ((theta / step).ceil() as usize).max(1);
    (0..pieces)
        .map(|k| {
            // spherical linear interpolation, renormalized
            let t = k as f64 / pieces as f64;
            let p: [f64; 3] = std::array::from_fn(|i| a[i] * (1.0 - t) + b[i] * t);
            let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            p.map(|x| x / n)
        })
        .collect()
}

/// The Voronoi cells on the sphere as a binary `.vtu` for ParaView: one polygon per cell,
/// its arcs subdivided every 0.05 rad, with cell data `id`, `area`, `neighbours`,
/// `perimeter` and `centroid`.
pub fn write_spherical_voronoi_vtu(
    w: &mut impl Write,
    cells: &[SphericalCell],
) -> std::io::Result<()> {
    let mut v = Vtu::default();
    let (mut ids, mut area, mut count, mut perimeter, mut centroid) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for c in cells {
        let m = c.vertices.len();
        for k in 0..m {
            for p in arc_points(&c.vertices[k], &c.vertices[(k + 1) % m], 0.05) {
                v.connectivity.push(v.points.len() as i64);
                v.points.push(p);
            }
        }
        v.offsets.push(v.connectivity.len() as i64);
        v.types.push(7); // VTK_POLYGON
        ids.push(i64::from(c.site.0));
        area.push(c.area);
        count.push(c.neighbors.len() as i64);
        perimeter.push(c.arc_lengths.iter().sum());
        centroid.extend(c.centroid);
    }
    v.cell_data.push(("id", Values::I64(ids)));
    v.cell_data.push(("area", Values::F64(area, 1)));
    v.cell_data.push(("neighbours", Values::I64(count)));
    v.cell_data.push(("perimeter", Values::F64(perimeter, 1)));
    v.cell_data.push(("centroid", Values::F64(centroid, 3)));
    v.write(w)
}

/// The faces as a binary `.vtu` of triangles on the vertices (flat triangles with their
/// corners on the sphere; on RP², each face lifted by its signs), with the input id of each
/// vertex as point data.
pub fn write_sphere_faces_vtu<S: SphericalSpace>(
    w: &mut impl Write,
    tri: &SphericalTriangulation<S>,
) -> std::io::Result<()> {
    let mut v = Vtu::default();
    // one point per (input, sign): a face of RP² may use a point's antipode
    let mut index: std::collections::HashMap<(InputId, bool), i64> = Default::default();
    let mut pid = Vec::new();
    let table = tri.face_table();
    for (f, signs) in table.faces.into_iter().zip(table.signs) {
        for (i, s) in f.into_iter().zip(signs) {
            let id = *index.entry((i, s)).or_insert_with(|| {
                let p = tri.point(i).expect("a vertex is live");
                v.points.push(if s { p.map(|x| -x) } else { p });
                pid.push(i64::from(i.0));
                v.points.len() as i64 - 1
            });
            v.connectivity.push(id);
        }
        v.offsets.push(v.connectivity.len() as i64);
        v.types.push(5); // VTK_TRIANGLE
    }
    v.point_data.push(("id", Values::I64(pid)));
    v.write(w)
}

/// The Hammer equal-area projection of a unit vector to `[-2√2, 2√2] × [-√2, √2]`, and
/// its longitude (to tell when an arc crosses the seam at ±180°).
fn hammer(p: &[f64; 3]) -> ([f64; 2], f64) {
    let [lon, lat] = crate::spherical::point_to_lonlat(p).map(f64::to_radians);
    let z = (1.0 + lat.cos() * (lon / 2.0).cos()).sqrt();
    let s = std::f64::consts::SQRT_2;
    (
        [
            2.0 * s * lat.cos() * (lon / 2.0).sin() / z,
            s * lat.sin() / z,
        ],
        lon,
    )
}

/// SVG path data of great-circle arcs in the Hammer projection: each arc subdivided every
/// 0.02 rad, a piece that crosses the seam at ±180° left out.
fn arcs_path(
    arcs: impl Iterator<Item = ([f64; 3], [f64; 3])>,
    px: impl Fn([f64; 2]) -> (f64, f64),
) -> String {
    use std::fmt::Write as _;
    let mut d = String::new();
    for (a, b) in arcs {
        let mut pts = arc_points(&a, &b, 0.02);
        pts.push(b);
        let mut pen = false;
        let mut last = f64::NAN;
        for p in pts {
            let (q, lon) = hammer(&p);
            let (x, y) = px(q);
            let jump = (lon - last).abs() > std::f64::consts::PI;
            let _ = write!(d, "{}{x:.2},{y:.2}", if pen && !jump { "L" } else { "M" });
            pen = true;
            last = lon;
        }
    }
    d
}

/// The triangulation (blue edges) and Voronoi diagram (red arcs) on the sphere as SVG, in
/// the Hammer equal-area projection of the whole sphere (an ellipse twice as wide as
/// high, longitude 0 in the middle); `opts.copies` does not apply. The projective plane is
/// drawn on its covering sphere: every face and cell with its antipode.
pub fn write_sphere_svg<S: SphericalSpace>(
    w: &mut impl Write,
    tri: &SphericalTriangulation<S>,
    opts: &super::SvgOptions,
) -> std::io::Result<()> {
    let (width, height) = (opts.width, opts.width / 2.0);
    let margin = 4.0;
    let scale = (width - 2.0 * margin) / (4.0 * std::f64::consts::SQRT_2);
    let px = |q: [f64; 2]| (width / 2.0 + q[0] * scale, height / 2.0 - q[1] * scale);
    let n = tri.number_of_vertices().max(1) as f64;
    let stroke = (width / n.sqrt() / 25.0).clamp(0.15, 1.5);
    // the copies drawn: the point itself, and on RP² its antipode
    let copies: &[f64] = if S::ANTIPODAL { &[1.0, -1.0] } else { &[1.0] };
    writeln!(
        w,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.2} {height:.2}">"#
    )?;
    writeln!(w, r#"<rect width="100%" height="100%" fill="white"/>"#)?;
    writeln!(
        w,
        r##"<ellipse id="sphere" cx="{:.2}" cy="{:.2}" rx="{:.2}" ry="{:.2}" fill="none" stroke="#000" stroke-width="{:.2}"/>"##,
        width / 2.0,
        height / 2.0,
        2.0 * std::f64::consts::SQRT_2 * scale,
        std::f64::consts::SQRT_2 * scale,
        stroke * 2.0
    )?;
    writeln!(w, r#"<g fill="none">"#)?;
    let point = |i: InputId| tri.point(i).expect("a vertex is live");
    let times = |p: [f64; 3], k: f64| p.map(|x| x * k);
    if opts.voronoi {
        if let Ok(cells) = tri.voronoi_cells() {
            let arcs = cells.iter().flat_map(|c| {
                let m = c.vertices.len();
                // each arc once: from the cell of the smaller site
                (0..m)
                    .filter(move |&k| c.site <= c.neighbors[k])
                    .flat_map(move |k| {
                        copies.iter().map(move |&s| {
                            (times(c.vertices[k], s), times(c.vertices[(k + 1) % m], s))
                        })
                    })
            });
            writeln!(
                w,
                r##"<path id="voronoi" stroke="#c8553d" stroke-width="{stroke:.2}" d="{}"/>"##,
                arcs_path(arcs, px)
            )?;
        }
    }
    if opts.delaunay {
        // each edge once (an edge of a hemisphere's rim has one face), by its lifted ends
        let mut all: Vec<[[u64; 3]; 2]> = Vec::new();
        let table = tri.face_table();
        for (f, signs) in table.faces.iter().zip(table.signs) {
            let q = std::array::from_fn::<_, 3, _>(|k| {
                times(point(f[k]), if signs[k] { -1.0 } else { 1.0 })
            });
            for k in 0..3 {
                for &s in copies {
                    let mut e =
                        [times(q[k], s), times(q[(k + 1) % 3], s)].map(|p| p.map(f64::to_bits));
                    e.sort_unstable();
                    all.push(e);
                }
            }
        }
        all.sort_unstable();
        all.dedup();
        let arcs = all
            .into_iter()
            .map(|e| (e[0].map(f64::from_bits), e[1].map(f64::from_bits)));
        writeln!(
            w,
            r##"<path id="delaunay" stroke="#2a6f97" stroke-width="{:.2}" d="{}"/>"##,
            stroke * 0.8,
            arcs_path(arcs, px)
        )?;
    }
    writeln!(w, "</g>")?;
    if opts.points {
        let r = (stroke * 2.0).max(0.8);
        writeln!(w, r##"<g id="points" fill="#111">"##)?;
        for i in tri.vertices() {
            for &s in copies {
                let (x, y) = px(hammer(&times(point(i), s)).0);
                writeln!(w, r#"<circle cx="{x:.2}" cy="{y:.2}" r="{r:.2}"/>"#)?;
            }
        }
        writeln!(w, "</g>")?;
    }
    writeln!(w, "</svg>")
}
