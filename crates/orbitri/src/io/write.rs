//! Writers: the `cells` format (for comparison with other programs) and JSON.

use std::io::Write;

use super::format::SpaceFormat;
use crate::ids::InputId;
use crate::space::FlatSpace;
use crate::triangulation::{CellView, Triangulation};

/// The `cells` format: `SHEETS V C`, then per cell of the space (one per orbit:
/// [`Triangulation::complex`], also while the triangulation is stored in a covering of
/// `SHEETS` sheets) its `D + 1` input ids and their elements' integers
/// ([`SpaceFormat::element_integers`]: a torus's offsets, `D` integers each in lattice
/// units; a manifold's coset and offset, `1 + D` each), positively oriented
/// (counter-clockwise in 2D). `V` counts distinct points, `C` the cell lines that follow.
pub fn write_cells<const D: usize, const N: usize, S: SpaceFormat<D, N>>(
    w: &mut impl Write,
    tri: &Triangulation<D, N, S>,
) -> std::io::Result<()> {
    let (count, cells) = cells_of(tri)?;
    writeln!(w, "{} {} {}", tri.sheets(), tri.number_of_vertices(), count)?;
    // integers through `itoa` into one reused line buffer: `write!` formatting took longer
    // than the triangulation itself
    let mut num = itoa::Buffer::new();
    let mut line: Vec<u8> = Vec::with_capacity(96);
    for c in cells {
        line.clear();
        for v in c.vertices {
            line.extend_from_slice(num.format(v.0).as_bytes());
            line.push(b' ');
        }
        for x in c.offsets.into_iter().flat_map(S::element_integers) {
            line.extend_from_slice(num.format(x).as_bytes());
            line.push(b' ');
        }
        line.pop();
        line.push(b'\n');
        w.write_all(&line)?;
    }
    Ok(())
}

/// The triangulation of the space, or the reason there is none as an I/O error (see
/// [`Triangulation::complex`]).
pub(super) fn complex_of<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    tri: &Triangulation<D, N, S>,
) -> std::io::Result<crate::Complex<D, N, S::Elem>> {
    tri.complex()
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e.to_string()))
}

/// The cells of the space.
type Cells<'a, const D: usize, const N: usize, E> =
    Box<dyn Iterator<Item = CellView<D, N, E>> + 'a>;

/// How many cells [`Triangulation::complex`] has, and its cells in its order without its
/// neighbour tables: read one at a time from the stored cells once the triangulation is
/// 1-sheeted (a copy of the complex of 10⁶ points in a cube would take ~0.9 GB), else from
/// the complex.
pub(super) fn cells_of<'a, const D: usize, const N: usize, S: FlatSpace<D, N>>(
    tri: &'a Triangulation<D, N, S>,
) -> std::io::Result<(usize, Cells<'a, D, N, S::Elem>)> {
    Ok(if tri.is_one_sheeted() {
        (tri.number_of_cells(), Box::new(tri.stored_cells()))
    } else {
        let cells = complex_of(tri)?.cells;
        (cells.len(), Box::new(cells.into_iter()))
    })
}

/// A JSON number: the shortest representation that reads back to the same double, or
/// `null` for NaN and ±inf, which JSON cannot hold (a bare `NaN` makes the file invalid).
pub(super) fn json_f64(x: f64) -> String {
    if x.is_finite() {
        format!("{x:?}")
    } else {
        "null".into()
    }
}

/// A vector as a JSON array of numbers.
pub(super) fn json_point(p: &[f64]) -> String {
    let v: Vec<String> = p.iter().map(|&x| json_f64(x)).collect();
    format!("[{}]", v.join(","))
}

#[cfg(test)]
#[test]
fn json_f64_writes_null_for_non_finite_numbers() {
    assert_eq!(json_f64(0.1), "0.1");
    assert_eq!(json_f64(-1e-300), "-1e-300");
    assert_eq!(json_f64(-0.0), "-0.0");
    for x in [f64::NAN, -f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(json_f64(x), "null");
    }
}

/// JSON: `{"dimension", "sheets"`, the space ([`SpaceFormat::json_space`]: a torus's
/// `"lattice"`, a manifold's `"space"` and `"group"`), `"points"` (wrapped, input order),
/// `"first_occurrence"`, for weighted points `"weights"` and `"hidden"` (sorted input ids),
/// then the triangulation of the space ([`Triangulation::complex`], one cell per orbit):
/// `"cells"`, the cells' elements (a torus's `"offsets"`, a manifold's `"elements"`, one
/// `[A, t]` per vertex), `"neighbors"`, `"mirrors"` and `"gluings"` (elements)`}`, written
/// as it is produced.
pub fn write_json<const D: usize, const N: usize, S: SpaceFormat<D, N>>(
    w: &mut impl Write,
    tri: &Triangulation<D, N, S>,
) -> std::io::Result<()> {
    let space = tri.space();
    write!(
        w,
        "{{\"dimension\":{D},\"sheets\":{},{},\"points\":[",
        tri.sheets(),
        space.json_space()
    )?;
    write_list(
        w,
        (0..tri.number_of_input_points())
            .map(|i| json_point(&tri.position(InputId::new(i), space.identity()))),
    )?;
    write!(w, "],\"first_occurrence\":[")?;
    write_list(w, tri.first_occurrences().iter().map(|x| x.to_string()))?;
    if tri.is_weighted() {
        write!(w, "],\"weights\":[")?;
        write_list(w, tri.weights().iter().map(|&x| json_f64(x)))?;
        write!(w, "],\"hidden\":[")?;
        write_list(w, tri.hidden().iter().map(|x| x.to_string()))?;
    }
    let complex = complex_of(tri)?;
    let elements = |row: &[S::Elem]| {
        let elements: Vec<String> = row.iter().map(|&g| space.json_element(g)).collect();
        format!("[{}]", elements.join(","))
    };
    let numbers = |row: &[u32]| format!("{row:?}").replace(' ', "");
    write!(w, "],\"cells\":[")?;
    write_list(
        w,
        complex
            .cells
            .iter()
            .map(|c| numbers(&c.vertices.map(u32::from))),
    )?;
    write!(w, "],\"{}\":[", S::CELL_ELEMENTS)?;
    write_list(w, complex.cells.iter().map(|c| elements(&c.offsets)))?;
    write!(w, "],\"neighbors\":[")?;
    write_list(w, complex.neighbors.iter().map(|n| numbers(n)))?;
    write!(w, "],\"mirrors\":[")?;
    write_list(
        w,
        complex.mirrors.iter().map(|m| numbers(&m.map(u32::from))),
    )?;
    write!(w, "],\"gluings\":[")?;
    write_list(w, complex.gluings.iter().map(|g| elements(g)))?;
    writeln!(w, "]}}")
}

/// Writes the items separated by commas.
fn write_list(w: &mut impl Write, items: impl Iterator<Item = String>) -> std::io::Result<()> {
    for (k, item) in items.enumerate() {
        if k > 0 {
            w.write_all(b",")?;
        }
        w.write_all(item.as_bytes())?;
    }
    Ok(())
}
