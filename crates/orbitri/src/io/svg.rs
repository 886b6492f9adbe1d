//! Pictures of a 2D periodic triangulation: the Delaunay edges, the Voronoi diagram and the
//! points over `K × K` periodic copies of the domain, the original domain outlined, as SVG.

use std::fmt::Write as _;
use std::io::Write;

use crate::error::{Error, Result};
use crate::space::Lattice;
use crate::triangulation::PeriodicDelaunay2;

/// What to draw.
#[derive(Clone, Copy, Debug)]
pub struct SvgOptions {
    /// Copies of the domain per lattice direction (the window is `K × K` domains, the
    /// original one in the middle for odd `K`).
    pub copies: u32,
    /// Width of the picture in pixels.
    pub width: f64,
    pub delaunay: bool,
    pub voronoi: bool,
    pub points: bool,
}

impl SvgOptions {
    /// The largest width and height of a picture, in pixels: a PNG of 8192² pixels takes
    /// about 0.8 GB of memory to render and encode (16384² took 3.2 GB and 45 s).
    pub const MAX_SIZE: f64 = 8192.0;
    /// The most copies of the domain per lattice direction.
    pub const MAX_COPIES: u32 = 50;
    /// The most points drawn, copies included (`copies² × points`): about 240 bytes of SVG
    /// each, so at most about 500 MB.
    pub const MAX_DRAWN_POINTS: u64 = 2_000_000;

    /// Checks the options for a picture of `points` points: a width from 1 to
    /// [`MAX_SIZE`](Self::MAX_SIZE) pixels, at most [`MAX_COPIES`](Self::MAX_COPIES) copies
    /// and [`MAX_DRAWN_POINTS`](Self::MAX_DRAWN_POINTS) points drawn. [`write_svg`] also
    /// checks that the height, from the domain's aspect ratio, is at most `MAX_SIZE`.
    pub fn validate(&self, points: usize) -> Result<()> {
        let invalid = |option, value: String, limit: String| {
            Err(Error::InvalidOption {
                option,
                value,
                limit,
            })
        };
        if !(1.0..=Self::MAX_SIZE).contains(&self.width) {
            return invalid(
                "width",
                self.width.to_string(),
                format!("a picture is 1 to {} pixels wide", Self::MAX_SIZE),
            );
        }
        if self.copies > Self::MAX_COPIES {
            return invalid(
                "copies",
                self.copies.to_string(),
                format!("at most {} per lattice direction", Self::MAX_COPIES),
            );
        }
        let k = u64::from(self.copies.max(1));
        let drawn = k * k * points as u64;
        if drawn > Self::MAX_DRAWN_POINTS {
            return invalid(
                "copies",
                self.copies.to_string(),
                format!(
                    "{k}² copies of {points} points make {drawn} points to draw, more than {}",
                    Self::MAX_DRAWN_POINTS
                ),
            );
        }
        Ok(())
    }
}

impl Default for SvgOptions {
    fn default() -> Self {
        SvgOptions {
            copies: 3,
            width: 800.0,
            delaunay: true,
            voronoi: true,
            points: true,
        }
    }
}

/// A Cartesian polyline or point with its extent in fractional coordinates, to be drawn at
/// every lattice translation that brings it into the window.
struct Shape {
    pts: Vec<[f64; 2]>,
    fmin: [f64; 2],
    fmax: [f64; 2],
}

/// The page: the window in fractional coordinates `[lo, hi)²`, the lattice, and the map
/// from Cartesian coordinates to pixels (y up).
struct Page<'a> {
    lo: f64,
    hi: f64,
    lattice: &'a Lattice<2>,
    origin: [f64; 2],
    top: f64,
    scale: f64,
}

impl Page<'_> {
    fn px(&self, p: [f64; 2]) -> (f64, f64) {
        (
            (p[0] - self.origin[0]) * self.scale,
            (self.top - p[1]) * self.scale,
        )
    }

    fn cart(&self, f: [f64; 2]) -> [f64; 2] {
        self.lattice.cartesian(&f)
    }

    /// A polyline or point, with its extent in fractional coordinates. A shape with a
    /// non-finite coordinate is left out (empty, at no translation): no `NaN` in the SVG.
    fn shape(&self, mut pts: Vec<[f64; 2]>) -> Shape {
        let mut fmin = [f64::INFINITY; 2];
        let mut fmax = [f64::NEG_INFINITY; 2];
        if !pts.as_flattened().iter().all(|x| x.is_finite()) {
            pts.clear();
        }
        for p in &pts {
            let f = self.lattice.fractional(p);
            for c in 0..2 {
                fmin[c] = fmin[c].min(f[c]);
                fmax[c] = fmax[c].max(f[c]);
            }
        }
        Shape { pts, fmin, fmax }
    }

    /// Every translation `t` with `[fmin + t, fmax + t]` meeting the window.
    fn translations(&self, s: &Shape) -> impl Iterator<Item = [f64; 2]> + '_ {
        let range = |c: usize| {
            let a = (self.lo - s.fmax[c]).ceil() as i64;
            let b = (self.hi - s.fmin[c]).floor() as i64;
            a..=b
        };
        let (rx, ry) = (range(0), range(1));
        let lattice = self.lattice;
        rx.flat_map(move |i| {
            ry.clone()
                .map(move |j| lattice.cartesian(&[i as f64, j as f64]))
        })
    }

    /// SVG path data of the shapes as polylines, at every translation into the window.
    fn path(&self, shapes: &[Shape]) -> String {
        let mut d = String::new();
        for s in shapes {
            for t in self.translations(s) {
                for (k, p) in s.pts.iter().enumerate() {
                    let (x, y) = self.px([p[0] + t[0], p[1] + t[1]]);
                    let _ = write!(d, "{}{x:.2} {y:.2}", if k == 0 { "M" } else { "L" });
                }
            }
        }
        d
    }
}

#[cfg(test)]
#[test]
fn a_shape_with_a_non_finite_coordinate_is_not_drawn() {
    let lattice = Lattice::new([[1.0, 0.0], [0.0, 1.0]]).unwrap();
    let page = Page {
        lo: -1.0,
        hi: 2.0,
        lattice: &lattice,
        origin: [0.0; 2],
        top: 0.0,
        scale: 100.0,
    };
    let good = page.shape(vec![[0.1, 0.2], [0.3, 0.4]]);
    assert_eq!(page.translations(&good).count(), 9);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let s = page.shape(vec![[0.1, 0.2], [bad, 0.4], [0.5, 0.6]]);
        assert_eq!(page.translations(&s).count(), 0);
        let d = page.path(&[s, page.shape(vec![[0.1, 0.2], [0.3, 0.4]])]);
        assert!(!d.contains("NaN") && !d.contains("inf"), "{d}");
        assert_eq!(d, page.path(&[page.shape(vec![[0.1, 0.2], [0.3, 0.4]])]));
    }
}

/// The Delaunay edges (one per orbit) as segments from the library's edge list.
fn delaunay_edges(page: &Page, tri: &PeriodicDelaunay2) -> Vec<Shape> {
    let at = |i: u32| tri.point(tri.vertex_of_input(i as usize));
    tri.delaunay_edges()
        .into_iter()
        .map(|e| {
            let (a, b) = (at(e.i), at(e.j));
            let t = page.lattice.cartesian(&e.shift.map(f64::from));
            page.shape(vec![a, [b[0] + t[0], b[1] + t[1]]])
        })
        .collect()
}

/// The Voronoi cells as closed polygons (the library's exact cells: every edge is drawn
/// from both of its cells).
fn voronoi_cells(page: &Page, tri: &PeriodicDelaunay2) -> Vec<Shape> {
    tri.voronoi_cells()
        .into_iter()
        .filter(|c| !c.vertices.is_empty())
        .map(|c| {
            let mut pts = c.vertices;
            pts.push(pts[0]);
            page.shape(pts)
        })
        .collect()
}

/// Writes the picture as SVG. Options out of range (see [`SvgOptions::validate`]) give an
/// error of kind `InvalidInput` whose inner error is the typed [`Error::InvalidOption`],
/// before anything is written.
pub fn write_svg(
    w: &mut impl Write,
    tri: &PeriodicDelaunay2,
    opts: &SvgOptions,
) -> std::io::Result<()> {
    let out_of_range = |e: Error| std::io::Error::new(std::io::ErrorKind::InvalidInput, e);
    opts.validate(tri.number_of_vertices())
        .map_err(out_of_range)?;
    let k = opts.copies.max(1) as f64;
    let lo = -f64::from((opts.copies.max(1) - 1) / 2);
    let mut page = Page {
        lo,
        hi: lo + k,
        lattice: tri.space().lattice(),
        origin: [0.0; 2],
        top: 0.0,
        scale: 1.0,
    };
    let corners = [[lo, lo], [lo + k, lo], [lo + k, lo + k], [lo, lo + k]].map(|f| page.cart(f));
    let (xmin, xmax, ymin, ymax) = corners.iter().fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |(a, b, c, d), p| (a.min(p[0]), b.max(p[0]), c.min(p[1]), d.max(p[1])),
    );
    let pad = 0.02 * (xmax - xmin).max(ymax - ymin);
    page.origin = [xmin - pad, 0.0];
    page.top = ymax + pad;
    page.scale = opts.width / (xmax - xmin + 2.0 * pad);
    let height = (ymax - ymin + 2.0 * pad) * page.scale;
    if height.is_nan() || height > SvgOptions::MAX_SIZE {
        return Err(out_of_range(Error::InvalidOption {
            option: "width",
            value: opts.width.to_string(),
            limit: format!(
                "the picture would be {height:.0} pixels high (the domain's aspect ratio), more than {}",
                SvgOptions::MAX_SIZE
            ),
        }));
    }
    // strokes scale with the density of the picture
    let n = tri.number_of_vertices().max(1) as f64;
    let stroke = (opts.width / (k * n.sqrt()) / 25.0).clamp(0.15, 1.5);
    let polygon = |ps: &[[f64; 2]]| -> String {
        ps.iter()
            .map(|p| {
                let (x, y) = page.px(*p);
                format!("{x:.2},{y:.2}")
            })
            .collect::<Vec<_>>()
            .join(" ")
    };
    writeln!(
        w,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{:.0}" height="{height:.0}" viewBox="0 0 {:.2} {height:.2}">"#,
        opts.width, opts.width
    )?;
    writeln!(
        w,
        r#"<defs><clipPath id="window"><polygon points="{}"/></clipPath></defs>"#,
        polygon(&corners)
    )?;
    writeln!(w, r#"<rect width="100%" height="100%" fill="white"/>"#)?;
    writeln!(w, r#"<g clip-path="url(#window)" fill="none">"#)?;
    if opts.voronoi {
        writeln!(
            w,
            r##"<path id="voronoi" stroke="#c8553d" stroke-width="{stroke:.2}" d="{}"/>"##,
            page.path(&voronoi_cells(&page, tri))
        )?;
    }
    if opts.delaunay {
        writeln!(
            w,
            r##"<path id="delaunay" stroke="#2a6f97" stroke-width="{:.2}" d="{}"/>"##,
            stroke * 0.8,
            page.path(&delaunay_edges(&page, tri))
        )?;
    }
    if opts.points {
        let r = (stroke * 2.0).max(0.8);
        let mut pts = String::new();
        for p in tri.points() {
            let s = page.shape(vec![p]);
            for t in page.translations(&s) {
                let (x, y) = page.px([p[0] + t[0], p[1] + t[1]]);
                let fill = if t == [0.0, 0.0] { "#111" } else { "#777" };
                let _ = writeln!(
                    pts,
                    r#"<circle cx="{x:.2}" cy="{y:.2}" r="{r:.2}" fill="{fill}"/>"#
                );
            }
        }
        write!(w, "<g id=\"points\">\n{pts}</g>\n")?;
    }
    writeln!(w, "</g>")?;
    // domain copies dashed, the original domain solid
    let mut copies = String::new();
    let steps = opts.copies.max(1) as i64;
    for i in 0..steps {
        for j in 0..steps {
            let (fi, fj) = (lo + i as f64, lo + j as f64);
            let cell = [
                [fi, fj],
                [fi + 1.0, fj],
                [fi + 1.0, fj + 1.0],
                [fi, fj + 1.0],
            ];
            let _ = writeln!(
                copies,
                r#"<polygon points="{}"/>"#,
                polygon(&cell.map(|f| page.cart(f)))
            );
        }
    }
    writeln!(
        w,
        r##"<g id="domains" fill="none" stroke="#555" stroke-width="{:.2}" stroke-dasharray="6 4">
{copies}</g>"##,
        stroke
    )?;
    let domain = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]].map(|f| page.cart(f));
    writeln!(
        w,
        r##"<polygon id="domain" points="{}" fill="none" stroke="#000" stroke-width="{:.2}"/>"##,
        polygon(&domain),
        stroke * 3.0
    )?;
    writeln!(w, "</svg>")
}
