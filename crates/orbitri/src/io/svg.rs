//! Pictures of a 2D triangulation in a flat torus or a Klein bottle: the Delaunay edges, the
//! Voronoi diagram and the points over `K × K` images of the domain, the original domain
//! outlined, as SVG. In a Klein bottle every other column of images is a glide image
//! (reflected), and a flag in each image shows its orientation.

use std::fmt::Write as _;
use std::io::Write;

use crate::error::{Error, Result};
use crate::ids::InputId;
use crate::space::{FlatManifold, FlatSpace, FlatTorus, Lattice, Motion};
use crate::triangulation::Triangulation;

/// How a picture tiles the plane with images of the domain (see [`Drawable`]).
pub struct Tiling<'a> {
    frame: Frame<'a>,
    glide: bool,
}

/// The domain `{f·B : f ∈ [0,1)²}` and its translates by integer `f`, the tiles.
#[derive(Clone, Copy)]
enum Frame<'a> {
    /// `B` a lattice (a torus: the tiles are the domain's translates).
    Lattice(&'a Lattice<2>),
    /// `B = diag(a, b)` (a Klein bottle's rectangle).
    Rectangle([f64; 2]),
}

impl Frame<'_> {
    fn cartesian(&self, f: [f64; 2]) -> [f64; 2] {
        match self {
            Frame::Lattice(l) => l.cartesian(&f),
            Frame::Rectangle(s) => [f[0] * s[0], f[1] * s[1]],
        }
    }

    fn fractional(&self, p: &[f64; 2]) -> [f64; 2] {
        match self {
            Frame::Lattice(l) => l.fractional(p),
            Frame::Rectangle(s) => [p[0] / s[0], p[1] / s[1]],
        }
    }
}

/// A 2D space that [`write_svg`] draws: its domain tiles the plane in a grid of images under
/// the group.
pub trait Drawable: FlatSpace<2, 3> {
    /// The tiling; an error for a space the pictures do not cover.
    fn tiling(&self) -> Result<Tiling<'_>>;
    /// The image `g·p` of a point, in user units.
    fn apply(&self, g: Self::Elem, p: [f64; 2]) -> [f64; 2];
}

impl Drawable for FlatTorus<2> {
    fn tiling(&self) -> Result<Tiling<'_>> {
        Ok(Tiling {
            frame: Frame::Lattice(self.lattice()),
            glide: false,
        })
    }

    fn apply(&self, g: [i8; 2], p: [f64; 2]) -> [f64; 2] {
        let t = self.lattice().cartesian(&g.map(f64::from));
        [p[0] + t[0], p[1] + t[1]]
    }
}

/// A Klein bottle as [`FlatManifold::klein_bottle`] makes it: the tiles of the rectangle
/// `a × b` are its images `(x, y) ↦ (x + i·a, (−1)^i·y + j·b)`. A manifold of index 1 is a
/// torus.
impl Drawable for FlatManifold<2> {
    fn tiling(&self) -> Result<Tiling<'_>> {
        let m = self.translations().vectors();
        if self.index() == 1 {
            return Ok(Tiling {
                frame: Frame::Lattice(self.translations()),
                glide: false,
            });
        }
        let (a, b) = (m[0][0] / 2.0, m[1][1]);
        let glide = self.isometry(Motion {
            coset: 1,
            offset: [0, 0],
        });
        if self.index() != 2
            || m[0][1] != 0.0
            || m[1][0] != 0.0
            || glide != ([[1.0, 0.0], [0.0, -1.0]], [a, 0.0])
        {
            return Err(Error::InvalidBox(format!(
                "{}: pictures show flat tori and Klein bottles gliding along the first axis",
                self.name()
            )));
        }
        Ok(Tiling {
            frame: Frame::Rectangle([a, b]),
            glide: true,
        })
    }

    fn apply(&self, g: Motion<2>, p: [f64; 2]) -> [f64; 2] {
        let (a, t) = self.isometry(g);
        std::array::from_fn(|i| a[i][0] * p[0] + a[i][1] * p[1] + t[i])
    }
}

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
/// every tile's isometry that brings it into the window.
struct Shape {
    pts: Vec<[f64; 2]>,
    fmin: [f64; 2],
    fmax: [f64; 2],
}

/// An isometry that maps the domain onto a tile: `(x, y) ↦ (x + t_x, ±y + t_y)`, the sign
/// negative for a glide image.
#[derive(Clone, Copy, PartialEq)]
struct Place {
    t: [f64; 2],
    flip: bool,
}

impl Place {
    fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        let y = if self.flip { -p[1] } else { p[1] };
        [p[0] + self.t[0], y + self.t[1]]
    }

    fn is_identity(&self) -> bool {
        self.t == [0.0, 0.0] && !self.flip
    }
}

/// The page: the window in fractional coordinates `[lo, hi)²`, the frame of the tiles (and
/// whether odd columns are glide images), and the map from Cartesian coordinates to pixels
/// (y up).
struct Page<'a> {
    lo: f64,
    hi: f64,
    frame: Frame<'a>,
    glide: bool,
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
        self.frame.cartesian(f)
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
            let f = self.frame.fractional(p);
            for c in 0..2 {
                fmin[c] = fmin[c].min(f[c]);
                fmax[c] = fmax[c].max(f[c]);
            }
        }
        Shape { pts, fmin, fmax }
    }

    /// Every tile's isometry that brings the shape into the window: the shifts `u` of the
    /// fractional extent `[fmin, fmax]` (reflected, `[u − fmax, u − fmin]`, along the second
    /// axis in a glide column) that meet the window.
    fn places(&self, s: &Shape) -> impl Iterator<Item = Place> + '_ {
        let (lo, hi, fmin, fmax) = (self.lo, self.hi, s.fmin, s.fmax);
        let range = move |c: usize, flip: bool| {
            let (a, b) = match flip {
                false => ((lo - fmax[c]).ceil(), (hi - fmin[c]).floor()),
                true => ((lo + fmin[c]).ceil(), (hi + fmax[c]).floor()),
            };
            a as i64..=b as i64
        };
        range(0, false).flat_map(move |i| {
            let flip = self.glide && i.rem_euclid(2) == 1;
            range(1, flip).map(move |j| Place {
                t: self.frame.cartesian([i as f64, j as f64]),
                flip,
            })
        })
    }

    /// SVG path data of the shapes as polylines, at every tile's isometry into the window.
    fn path(&self, shapes: &[Shape]) -> String {
        let mut d = String::new();
        for s in shapes {
            for t in self.places(s) {
                for (k, p) in s.pts.iter().enumerate() {
                    let (x, y) = self.px(t.apply(*p));
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
        frame: Frame::Lattice(&lattice),
        glide: false,
        origin: [0.0; 2],
        top: 0.0,
        scale: 100.0,
    };
    let good = page.shape(vec![[0.1, 0.2], [0.3, 0.4]]);
    assert_eq!(page.places(&good).count(), 9);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let s = page.shape(vec![[0.1, 0.2], [bad, 0.4], [0.5, 0.6]]);
        assert_eq!(page.places(&s).count(), 0);
        let d = page.path(&[s, page.shape(vec![[0.1, 0.2], [0.3, 0.4]])]);
        assert!(!d.contains("NaN") && !d.contains("inf"), "{d}");
        assert_eq!(d, page.path(&[page.shape(vec![[0.1, 0.2], [0.3, 0.4]])]));
    }
}

#[cfg(test)]
#[test]
fn glide_columns_reflect_and_stay_in_their_tiles() {
    let page = Page {
        lo: -1.0,
        hi: 2.0,
        frame: Frame::Rectangle([2.0, 1.0]),
        glide: true,
        origin: [0.0; 2],
        top: 0.0,
        scale: 100.0,
    };
    let p = [0.5, 0.25];
    let images: Vec<(Place, [f64; 2])> = page
        .places(&page.shape(vec![p]))
        .map(|t| (t, t.apply(p)))
        .collect();
    assert_eq!(images.len(), 9);
    for (t, x) in images {
        let tile = page.frame.fractional(&x).map(f64::floor);
        // a point at a quarter of the domain's height: three quarters in a glide image
        let within = page.frame.fractional(&x)[1] - tile[1];
        assert_eq!(t.flip, tile[0] as i64 % 2 != 0, "{x:?}");
        assert_eq!(within, if t.flip { 0.75 } else { 0.25 }, "{x:?}");
        assert!((-1.0..2.0).contains(&tile[0]) && (-1.0..2.0).contains(&tile[1]));
    }
}

/// The Delaunay edges (one per orbit) as segments from the library's edge list.
fn delaunay_edges<S: Drawable>(page: &Page, tri: &Triangulation<2, 3, S>) -> Vec<Shape> {
    let at = |i: InputId| tri.point(tri.vertex_of_input(i));
    tri.delaunay_edges()
        .into_iter()
        .map(|e| page.shape(vec![at(e.i), tri.space().apply(e.shift, at(e.j))]))
        .collect()
}

/// The Voronoi cells as closed polygons (the library's exact cells: every edge is drawn
/// from both of its cells).
fn voronoi_cells<S: Drawable>(page: &Page, tri: &Triangulation<2, 3, S>) -> Vec<Shape> {
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

/// Weighted points: each input's circle of radius `√w` (none for `w ≤ 0`) at every place
/// of the picture, dashed for a hidden point.
fn weight_circles<S: Drawable>(page: &Page, tri: &Triangulation<2, 3, S>) -> String {
    let mut out = String::new();
    let first = tri.first_occurrences();
    for (i, &w) in tri.weights().iter().enumerate() {
        let id = crate::ids::InputId::new(i);
        if w <= 0.0 || first[i] != id {
            continue;
        }
        let p = tri.position(id, tri.space().identity());
        let r = w.sqrt() * page.scale;
        let dash = if tri.is_hidden(id) {
            r#" stroke-dasharray="2,2""#
        } else {
            ""
        };
        let s = page.shape(vec![p]);
        for t in page.places(&s) {
            let (x, y) = page.px(t.apply(p));
            let _ = writeln!(out, r#"<circle cx="{x:.2}" cy="{y:.2}" r="{r:.2}"{dash}/>"#);
        }
    }
    out
}

/// Writes the picture as SVG. Options out of range (see [`SvgOptions::validate`]) give an
/// error of kind `InvalidInput` whose inner error is the typed [`Error::InvalidOption`],
/// before anything is written.
pub fn write_svg<S: Drawable>(
    w: &mut impl Write,
    tri: &Triangulation<2, 3, S>,
    opts: &SvgOptions,
) -> std::io::Result<()> {
    let out_of_range = |e: Error| std::io::Error::new(std::io::ErrorKind::InvalidInput, e);
    opts.validate(tri.number_of_vertices())
        .map_err(out_of_range)?;
    let tiling = tri.space().tiling().map_err(out_of_range)?;
    let k = opts.copies.max(1) as f64;
    let lo = -f64::from((opts.copies.max(1) - 1) / 2);
    let mut page = Page {
        lo,
        hi: lo + k,
        frame: tiling.frame,
        glide: tiling.glide,
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
            for t in page.places(&s) {
                let (x, y) = page.px(t.apply(p));
                let fill = if t.is_identity() { "#111" } else { "#777" };
                let _ = writeln!(
                    pts,
                    r#"<circle cx="{x:.2}" cy="{y:.2}" r="{r:.2}" fill="{fill}"/>"#
                );
            }
        }
        write!(w, "<g id=\"points\">\n{pts}</g>\n")?;
    }
    if tri.is_weighted() {
        writeln!(
            w,
            r##"<g id="weights" stroke="#555" stroke-width="{:.2}">{}</g>"##,
            stroke * 0.6,
            weight_circles(&page, tri)
        )?;
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
    if page.glide {
        writeln!(
            w,
            r##"<path id="glides" fill="none" stroke="#2b9348" stroke-width="{:.2}" d="{}"/>"##,
            stroke * 2.0,
            page.path(&flag(&page))
        )?;
    }
    writeln!(w, "</svg>")
}

/// The letter F in a corner of the domain: drawn in every tile, it reads reflected in the
/// glide images.
fn flag(page: &Page) -> [Shape; 2] {
    let shape = |f: &[[f64; 2]]| page.shape(f.iter().map(|&x| page.cart(x)).collect());
    [
        shape(&[[0.08, 0.08], [0.08, 0.32], [0.2, 0.32]]),
        shape(&[[0.08, 0.2], [0.16, 0.2]]),
    ]
}
