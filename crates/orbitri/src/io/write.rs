//! Writers: the `cells` format (for comparison with other programs) and JSON.

use std::io::Write;

use crate::periodic3::{Copies, PeriodicDelaunay3};

/// The `cells` format: `SHEETS V C`, then per stored cell the 4 input ids and the 4 offsets
/// (3 integers each, lattice units), positively oriented. `V` counts distinct points, `C`
/// the cell lines that follow (in a covering space: every stored copy).
pub fn write_cells(w: &mut impl Write, tri: &PeriodicDelaunay3) -> std::io::Result<()> {
    let cells = tri.cells(Copies::Stored);
    writeln!(
        w,
        "{} {} {}",
        tri.sheets(),
        tri.number_of_vertices(),
        cells.len()
    )?;
    for c in &cells {
        let v = c.vertices;
        let o = c.offsets;
        writeln!(
            w,
            "{} {} {} {} {} {} {} {} {} {} {} {} {} {} {} {}",
            v[0],
            v[1],
            v[2],
            v[3],
            o[0][0],
            o[0][1],
            o[0][2],
            o[1][0],
            o[1][1],
            o[1][2],
            o[2][0],
            o[2][1],
            o[2][2],
            o[3][0],
            o[3][1],
            o[3][2]
        )?;
    }
    Ok(())
}

fn json_f64(x: f64) -> String {
    // shortest representation that reads back to the same double
    format!("{x:?}")
}

/// JSON: `{"dimension", "sheets", "lattice", "points" (wrapped, input order),
/// "first_occurrence", "cells", "offsets"}`.
pub fn write_json(w: &mut impl Write, tri: &PeriodicDelaunay3) -> std::io::Result<()> {
    let lattice = tri.space().lattice().vectors();
    let row = |r: &[f64; 3]| format!("[{},{},{}]", json_f64(r[0]), json_f64(r[1]), json_f64(r[2]));
    write!(
        w,
        "{{\"dimension\":3,\"sheets\":{},\"lattice\":[",
        tri.sheets()
    )?;
    write!(
        w,
        "{}]",
        lattice.iter().map(row).collect::<Vec<_>>().join(",")
    )?;
    let first = tri.first_occurrences();
    let pts: Vec<String> = (0..tri.number_of_input_points())
        .map(|i| row(&tri.points()[tri.vertex_of_input(i) as usize]))
        .collect();
    write!(w, ",\"points\":[{}]", pts.join(","))?;
    write!(
        w,
        ",\"first_occurrence\":[{}]",
        first
            .iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(",")
    )?;
    let cells = tri.cells(Copies::Stored);
    let cv: Vec<String> = cells
        .iter()
        .map(|c| {
            format!(
                "[{},{},{},{}]",
                c.vertices[0], c.vertices[1], c.vertices[2], c.vertices[3]
            )
        })
        .collect();
    write!(w, ",\"cells\":[{}]", cv.join(","))?;
    let co: Vec<String> = cells
        .iter()
        .map(|c| {
            format!(
                "[{}]",
                c.offsets
                    .iter()
                    .map(|o| format!("[{},{},{}]", o[0], o[1], o[2]))
                    .collect::<Vec<_>>()
                    .join(",")
            )
        })
        .collect();
    writeln!(w, ",\"offsets\":[{}]}}", co.join(","))
}
