//! The `orbitri` command.

mod rss;
mod sphere;

use std::ffi::OsString;
use std::io::{BufWriter, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::builder::PossibleValuesParser;
use clap::{Args, Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use orbitri::io::{Drawable, SpaceFormat, SvgOptions};
use orbitri::sort::SplitMix;
use orbitri::{BuildOptions, FlatManifold, FlatSpace, FlatTorus2, FlatTorus3, Triangulation};

/// The threads that `--threads` asked for.
static THREADS: std::sync::OnceLock<usize> = std::sync::OnceLock::new();

/// The threads of the parallel construction: `--threads`, else none (one by one).
fn threads() -> Option<usize> {
    THREADS.get().copied()
}

#[derive(Parser)]
#[command(
    name = "orbitri",
    version,
    about = "Exact Delaunay triangulations in orbit spaces (2D and 3D flat tori with any lattice, the Klein bottle, the flat 3-manifolds, the sphere, the projective plane)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Build the triangulation in parallel on N threads, and compute the cells on N
    /// threads (default: the triangulation one point at a time, the cells on all cores).
    /// Every file written is the same whatever N.
    #[arg(long, global = true, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=1024))]
    threads: Option<u16>,
}

#[derive(Subcommand)]
enum Command {
    /// Triangulate the points of INPUT in a periodic box or lattice, or in the closed flat
    /// manifold `--space`; the dimension is that of the box.
    ///
    /// Writes the cells (`SHEETS V C`, then per cell its D+1 input ids and their lattice
    /// offsets), JSON, or VTK for ParaView.
    ///
    /// Example: orbitri triangulate points.txt --box 10 10 10 -o cells.txt
    Triangulate {
        /// Points: text (one `x y z` or `x y` per line; blanks or commas; `#` comments; a
        /// header line such as pandas' `x,y,z` is skipped) or `.npy` (N×3 or N×2, float or
        /// integer)
        input: PathBuf,
        #[command(flatten)]
        domain: Domain,
        #[command(flatten)]
        weighting: Weighting,
        #[command(flatten)]
        out: Output,
    },
    /// Compute the periodic Voronoi cell of every point of INPUT.
    ///
    /// One row per input point (`id,volume,neighbours,surface_area,centroid_…,duplicate_of`,
    /// input order) as CSV, `.npy` or `.npz` (named arrays), or the whole cells as JSON or
    /// VTK (`.vtu`, binary, for ParaView).
    ///
    /// Example: orbitri voronoi points.txt --cellpar 10 10 10 90 90 120 -o cells.vtu
    Voronoi {
        /// Points: text (one `x y z` or `x y` per line; blanks or commas; `#` comments; a
        /// header line such as pandas' `x,y,z` is skipped) or `.npy` (N×3 or N×2, float or
        /// integer)
        input: PathBuf,
        #[command(flatten)]
        domain: Domain,
        #[command(flatten)]
        weighting: Weighting,
        /// Output file (default: the CSV table on standard output); its extension, .csv,
        /// .npy, .npz, .json or .vtu, picks the format, unless --format is given
        #[arg(short = 'o', long)]
        output: Option<PathBuf>,
        /// Output format (default: from the output's extension; csv on standard output)
        #[arg(long, value_enum)]
        format: Option<VoronoiFormat>,
        /// Also write the neighbour pairs `i,j,shift…,area` (each pair once) as CSV here
        #[arg(long)]
        neighbours: Option<PathBuf>,
        /// Also write the Delaunay edges `i,j,shift…,length` as CSV here
        #[arg(long)]
        edges: Option<PathBuf>,
        /// Print one line of key=value statistics to standard error
        #[arg(long)]
        stats: bool,
    },
    /// Draw the periodic Delaunay triangulation (blue) and Voronoi diagram (red) of 2D points
    /// over copies of the domain (in a Klein bottle: its images, every other column
    /// reflected), to SVG or PNG.
    ///
    /// Example: orbitri draw points.txt --box 1 1 -o picture.svg
    Draw {
        /// 2D points: text (one `x y` per line; blanks or commas; `#` comments; a header line
        /// is skipped) or `.npy` (N×2)
        input: PathBuf,
        #[command(flatten)]
        domain: Domain2,
        #[command(flatten)]
        weighting: Weighting,
        /// Output file: .svg or .png (the extension picks the format)
        #[arg(short = 'o', long)]
        output: PathBuf,
        /// Copies of the domain per lattice direction: at most 50, and at most 2000000 points
        /// drawn (copies² × points)
        #[arg(long, default_value_t = 3, allow_hyphen_values = true)]
        copies: u32,
        /// Picture width in pixels, 1 to 8192 (one rule for SVG and PNG); the height, from
        /// the domain's shape, must be at most 8192 too
        #[arg(long, default_value_t = 800.0, allow_hyphen_values = true)]
        width: f64,
        /// Leave out the Voronoi diagram
        #[arg(long)]
        no_voronoi: bool,
        /// Leave out the Delaunay edges
        #[arg(long)]
        no_delaunay: bool,
    },
    /// Triangulate built-in examples and check them exactly: uniform random points in the
    /// unit cube and an FCC crystal (every Delaunay sphere degenerate), then the unit square
    /// and a honeycomb in 2D. Reads and writes no file.
    Demo {
        /// Number of random points (in the cube, then in the square)
        #[arg(short = 'n', long, default_value_t = 100_000)]
        points: usize,
        /// Seed of the point generator
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Write N uniform random points of the unit cube or square, one `x y z` (`x y`) per
    /// line: the CGAL anchor harness's generator, bit for bit, for benchmarks and tests.
    ///
    /// Example: orbitri generate 1000 --dim 2 -o points.txt
    Generate {
        /// How many points
        #[arg(value_name = "N")]
        n: usize,
        /// Seed of the generator (SplitMix64): the same seed gives the same points
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Dimension: 3 (unit cube) or 2 (unit square)
        #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u8).range(2..=3))]
        dim: u8,
        /// Output file (default: standard output), text
        #[arg(short = 'o', long)]
        output: Option<PathBuf>,
    },
}

/// The names `--space` takes besides the closed flat 3-manifolds'
/// (`FlatManifold::PLATYCOSMS`).
const TORUS_AND_KLEIN: [&str; 2] = ["torus", "klein"];
/// The spaces without a box.
const SPHERES: [&str; 2] = ["sphere", "projective-plane"];

#[derive(Args)]
struct Domain {
    /// The orbit space: a flat torus (default), the Klein bottle (2D: --box L1 L2, the glide
    /// along the first axis), a closed flat 3-manifold (--box L1 L2 L3, the sides of its
    /// standard domain), the unit sphere or the real projective plane (the sphere with
    /// antipodes identified; no box: points are unit vectors `x y z`, or with --lonlat
    /// longitude and latitude in degrees)
    #[arg(long, value_name = "NAME", default_value = "torus", value_parser = PossibleValuesParser::new(TORUS_AND_KLEIN.into_iter().chain(FlatManifold::PLATYCOSMS).chain(SPHERES)))]
    space: String,
    #[command(flatten)]
    extent: Extent,
    #[command(flatten)]
    on_sphere: OnSphere,
}

/// How points on the sphere are given.
#[derive(Args)]
struct OnSphere {
    /// Sphere: each row is `longitude latitude` in degrees
    #[arg(long)]
    lonlat: bool,
    /// Sphere: move each `x y z` radially onto the unit sphere first (otherwise each must
    /// be a unit vector to within 1e-6)
    #[arg(long, conflicts_with = "lonlat")]
    normalize: bool,
}

/// The domain of `draw`: 2D only.
#[derive(Args)]
struct Domain2 {
    /// The orbit space: a flat torus (default), the Klein bottle (--box L1 L2, the glide
    /// along the first axis), the sphere or the projective plane (no box; drawn in an
    /// equal-area projection, RP² on its covering sphere)
    #[arg(long, value_name = "NAME", default_value = "torus", value_parser = PossibleValuesParser::new(TORUS_AND_KLEIN.into_iter().chain(SPHERES)))]
    space: String,
    #[command(flatten)]
    extent: Extent2,
    #[command(flatten)]
    on_sphere: OnSphere,
}

#[derive(Args)]
#[group(multiple = false)]
struct Extent {
    /// Box lengths, 3 or 2: the domain is [0,LX) × [0,LY) × [0,LZ), or [0,LX) × [0,LY)
    #[arg(long = "box", num_args = 2..=6, value_names = ["LX", "LY", "LZ"], value_parser = number, allow_negative_numbers = true)]
    box_lengths: Option<Vec<f64>>,
    /// Lattice vectors (rows): AX AY AZ BX BY BZ CX CY CZ in 3D, AX AY BX BY in 2D; the
    /// domain is {f·M : f ∈ [0,1)^D}
    #[arg(long, num_args = 4..=9, value_names = ["AX", "AY", "..."], value_parser = number, allow_negative_numbers = true)]
    lattice: Option<Vec<f64>>,
    /// Cell lengths and angles in degrees (a CIF's, ASE's cellpar, MDAnalysis's
    /// dimensions): A B C ALPHA BETA GAMMA in 3D, A B GAMMA in 2D; `a` along x, `b` in the
    /// xy-plane
    #[arg(long, num_args = 3..=6, value_names = ["A", "B", "C|GAMMA", "ALPHA", "BETA", "GAMMA"], value_parser = number, allow_negative_numbers = true)]
    cellpar: Option<Vec<f64>>,
}

/// The extent of a 2D domain (`draw`).
#[derive(Args)]
#[group(multiple = false)]
struct Extent2 {
    /// Box lengths: the domain is [0,LX) × [0,LY)
    #[arg(long = "box", num_args = 2, value_names = ["LX", "LY"], value_parser = number, allow_negative_numbers = true)]
    box_lengths: Option<Vec<f64>>,
    /// Lattice vectors (rows) AX AY BX BY; the domain is {f·M : f ∈ [0,1)²}
    #[arg(long, num_args = 4, value_names = ["AX", "AY", "BX", "BY"], value_parser = number, allow_negative_numbers = true)]
    lattice: Option<Vec<f64>>,
    /// Cell lengths and angle in degrees: A B GAMMA (`a` along x, `b` at GAMMA from it)
    #[arg(long, num_args = 3, value_names = ["A", "B", "GAMMA"], value_parser = number, allow_negative_numbers = true)]
    cellpar: Option<Vec<f64>>,
}

impl From<Domain2> for Domain {
    fn from(d: Domain2) -> Domain {
        let Extent2 {
            box_lengths,
            lattice,
            cellpar,
        } = d.extent;
        Domain {
            space: d.space,
            extent: Extent {
                box_lengths,
                lattice,
                cellpar,
            },
            on_sphere: d.on_sphere,
        }
    }
}

/// Weighted points: `--weights` or `--radii` (the power, or Laguerre, diagram).
#[derive(Args)]
#[group(multiple = false)]
struct Weighting {
    /// Each input row has one more number, the point's weight (a squared length): the
    /// regular triangulation and its power (Laguerre) cells; a point whose power cell is
    /// empty is hidden (no vertex, volume 0)
    #[arg(long)]
    weights: bool,
    /// Each input row has one more number, the point's radius r ≥ 0 (weight r²)
    #[arg(long)]
    radii: bool,
}

impl Weighting {
    fn column(&self) -> Option<orbitri::io::WeightColumn> {
        use orbitri::io::WeightColumn;
        match (self.weights, self.radii) {
            (true, _) => Some(WeightColumn::Weight),
            (_, true) => Some(WeightColumn::Radius),
            _ => None,
        }
    }
}

/// Points, and their weights when weighted.
type Input<const D: usize> = (Vec<[f64; D]>, Option<Vec<f64>>);

/// The points of `input`, and their weights when `weighting` asks for them.
fn read_input<const D: usize>(input: &Path, weighting: &Weighting) -> Result<Input<D>, CliError> {
    Ok(match weighting.column() {
        Some(column) => {
            let (p, w) = orbitri::io::read_weighted_points(input, column)?;
            (p, Some(w))
        }
        None => (orbitri::io::read_points(input)?, None),
    })
}

#[derive(Args)]
struct Output {
    /// Output file (default: standard output); its extension, .cells or .txt, .json or
    /// .vtu, picks the format, unless --format is given
    #[arg(short = 'o', long)]
    output: Option<PathBuf>,
    /// Output format (default: from the output's extension; cells on standard output)
    #[arg(long, value_enum)]
    format: Option<Format>,
    /// Print one line of key=value statistics to standard error
    #[arg(long)]
    stats: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    /// `SHEETS V C`, then per cell D+1 input ids and D+1 offsets (D integers each; in a
    /// manifold D+1 elements: coset and offset, 1+D integers each)
    Cells,
    /// JSON with lattice (manifold: space and group), wrapped points, first occurrences,
    /// cells and offsets (manifold: elements as isometries)
    Json,
    /// VTK UnstructuredGrid (ParaView), binary: one copy of each cell, drawn whole
    Vtu,
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum VoronoiFormat {
    /// One row per input point: id, volume, neighbours, surface area, centroid, duplicate_of
    Csv,
    /// The same columns as a float64 N×K array
    Npy,
    /// The same columns as named arrays (`numpy.load(f)["volume"]`): id, volume,
    /// neighbours, surface_area, centroid (N×D), duplicate_of (−1 for none)
    Npz,
    /// Every cell: vertices, faces (vertex cycles, neighbour, shift, area), volume, centroid
    Json,
    /// VTK UnstructuredGrid of the cells (polyhedra in 3D, polygons in 2D), drawn whole,
    /// binary, with id, volume, neighbours, surface_area and centroid as cell data
    Vtu,
}

#[derive(Debug, thiserror::Error)]
enum CliError {
    #[error(transparent)]
    Orbitri(#[from] orbitri::Error),
    #[error("{}: {source}", path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{0}")]
    Check(String),
    #[error("{0}")]
    Usage(String),
    #[error("{}: cannot render the PNG: {message}", path.display())]
    Render { path: PathBuf, message: String },
}

/// The space of the command line.
enum Space {
    Torus2(FlatTorus2),
    Torus3(FlatTorus3),
    Klein(FlatManifold<2>),
    Manifold3(FlatManifold<3>),
}

/// Calls the generic function `$f` with the space of either kind and dimension first.
macro_rules! with_space {
    ($space:expr, $f:ident($($arg:expr),*)) => {
        match $space {
            Space::Torus2(s) => $f::<2, 3, _>(s, $($arg),*),
            Space::Torus3(s) => $f::<3, 4, _>(s, $($arg),*),
            Space::Klein(s) => $f::<2, 3, _>(s, $($arg),*),
            Space::Manifold3(s) => $f::<3, 4, _>(s, $($arg),*),
        }
    };
}

fn space(domain: &Domain) -> Result<Space, CliError> {
    let e = &domain.extent;
    if e.box_lengths.is_none() && e.lattice.is_none() && e.cellpar.is_none() {
        return Err(CliError::Usage(format!(
            "--space {} needs its domain: --box, --lattice or --cellpar",
            domain.space
        )));
    }
    if domain.on_sphere.lonlat || domain.on_sphere.normalize {
        return Err(CliError::Usage(
            "--lonlat and --normalize are for --space sphere and projective-plane".into(),
        ));
    }
    match domain.space.as_str() {
        "torus" => torus(&domain.extent),
        name => manifold(name, &domain.extent),
    }
}

/// `--box` with more than 3 numbers: what the user may have meant.
fn box_usage(n: usize) -> CliError {
    CliError::Usage(format!(
        "--box takes the lengths LX LY [LZ], not {n} numbers: for lengths and angles (a b c α β γ) use --cellpar, for lattice vectors --lattice"
    ))
}

fn torus(extent: &Extent) -> Result<Space, CliError> {
    if let Some(b) = &extent.box_lengths {
        return Ok(match b.len() {
            2 => Space::Torus2(FlatTorus2::cuboid([b[0], b[1]])?),
            3 => Space::Torus3(FlatTorus3::cuboid([b[0], b[1], b[2]])?),
            n => return Err(box_usage(n)),
        });
    }
    if let Some(c) = &extent.cellpar {
        return match c.len() {
            3 => {
                let m = orbitri::io::lattice_from_cellpar2([c[0], c[1], c[2]])?;
                Ok(Space::Torus2(FlatTorus2::triclinic(m)?))
            }
            6 => {
                let m = orbitri::io::lattice_from_cellpar([c[0], c[1], c[2], c[3], c[4], c[5]])?;
                Ok(Space::Torus3(FlatTorus3::triclinic(m)?))
            }
            n => Err(CliError::Usage(format!(
                "--cellpar takes A B C ALPHA BETA GAMMA (3D) or A B GAMMA (2D), not {n} numbers"
            ))),
        };
    }
    let l = extent
        .lattice
        .as_ref()
        .expect("space() requires --box, --lattice or --cellpar");
    match l.len() {
        4 => Ok(Space::Torus2(FlatTorus2::triclinic([
            [l[0], l[1]],
            [l[2], l[3]],
        ])?)),
        9 => Ok(Space::Torus3(FlatTorus3::triclinic([
            [l[0], l[1], l[2]],
            [l[3], l[4], l[5]],
            [l[6], l[7], l[8]],
        ])?)),
        n => Err(CliError::Usage(format!(
            "--lattice takes 4 numbers (2D: AX AY BX BY) or 9 (3D), not {n}"
        ))),
    }
}

/// The Klein bottle or a flat 3-manifold of `--space`, from the sides of its domain.
fn manifold(name: &str, extent: &Extent) -> Result<Space, CliError> {
    let sides = if name == "klein" { "L1 L2" } else { "L1 L2 L3" };
    let Some(b) = &extent.box_lengths else {
        let flag = match extent.lattice {
            Some(_) => "--lattice",
            None => "--cellpar",
        };
        return Err(CliError::Usage(format!(
            "{flag} is for the torus only: --space {name} takes --box {sides}"
        )));
    };
    match (name, &b[..]) {
        ("klein", &[a, b]) => Ok(Space::Klein(FlatManifold::klein_bottle(a, b)?)),
        (_, &[a, b, c]) if name != "klein" => {
            Ok(Space::Manifold3(FlatManifold::platycosm(name, [a, b, c])?))
        }
        _ => Err(CliError::Usage(format!(
            "--space {name} takes --box {sides}, not {} lengths",
            b.len()
        ))),
    }
}

/// A progress bar on a terminal for the phase `what` of `points` points (none for small
/// inputs), `len` steps long.
fn progress_bar(points: usize, len: usize, what: &str) -> Option<ProgressBar> {
    if points < 200_000 || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::new(len as u64);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{elapsed_precise}} {what} [{{bar:40}}] {{percent}}% ({{eta}} left)"
        ))
        .unwrap(),
    );
    Some(bar)
}

/// What one construction cost: wall time of the build alone, and the process's peak
/// resident memory read right after it (as the CGAL anchor harness reads it).
struct Cost {
    seconds: f64,
    peak_rss_kb: Option<u64>,
}

fn build<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    space: S,
    pts: &[[f64; D]],
    weights: Option<&[f64]>,
) -> Result<(Triangulation<D, N, S>, Cost), orbitri::Error> {
    let bar = progress_bar(pts.len(), pts.len(), "triangulation");
    let start = Instant::now();
    let progress = |k: usize| {
        if let Some(b) = &bar {
            b.set_position(k as u64);
        }
        std::ops::ControlFlow::Continue(())
    };
    let opts = BuildOptions {
        threads: threads(),
        ..BuildOptions::default()
    };
    let tri = match weights {
        Some(w) => Triangulation::build_weighted_with(space, pts, w, opts, progress)?,
        None => Triangulation::build_with(space, pts, opts, progress)?,
    };
    let cost = Cost {
        seconds: start.elapsed().as_secs_f64(),
        peak_rss_kb: rss::peak_kb(),
    };
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    Ok((tri, cost))
}

fn stats_line<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    tri: &Triangulation<D, N, S>,
    input: usize,
    cost: &Cost,
) -> String {
    let hidden = if tri.is_weighted() {
        format!(" hidden={}", tri.hidden().len())
    } else {
        String::new()
    };
    format!(
        "input={input} vertices={} cells={} sheets={} duplicates={}{hidden} wrapped={} dummies={} build_seconds={:.6} peak_rss_kb={}",
        tri.number_of_vertices(),
        tri.number_of_cells(),
        tri.sheets(),
        tri.duplicates(),
        tri.wrapped(),
        tri.used_dummy_points(),
        cost.seconds,
        cost.peak_rss_kb.map_or("unknown".to_string(), |k| k.to_string())
    )
}

fn writer(path: &Option<PathBuf>) -> Result<Box<dyn Write>, CliError> {
    Ok(match path {
        Some(p) => Box::new(BufWriter::new(std::fs::File::create(p).map_err(
            |source| CliError::Write {
                path: p.clone(),
                source,
            },
        )?)),
        None => Box::new(BufWriter::new(std::io::stdout().lock())),
    })
}

fn triangulate(
    input: PathBuf,
    domain: Domain,
    weighting: Weighting,
    out: Output,
) -> Result<(), CliError> {
    if SPHERES.contains(&domain.space.as_str()) {
        return sphere::triangulate(&input, &domain, &weighting, out);
    }
    with_space!(space(&domain)?, triangulate_in(&input, &weighting, out))
}

/// The format of an output: `--format` if given, else the one its extension names (its
/// value name, or one of `aliases`), else `default` on standard output. An output whose
/// extension names no format (or that has none) is an error naming those that do.
fn output_format<F: ValueEnum + Copy>(
    format: Option<F>,
    output: &Option<PathBuf>,
    aliases: &[(&str, F)],
    default: F,
) -> Result<F, CliError> {
    let (Some(path), None) = (output, format) else {
        return Ok(format.unwrap_or(default));
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let known = ext.as_deref().and_then(|e| {
        let alias = aliases.iter().find(|(a, _)| *a == e).map(|(_, f)| *f);
        alias.or_else(|| F::from_str(e, true).ok())
    });
    known.ok_or_else(|| {
        let names: Vec<String> = F::value_variants()
            .iter()
            .filter_map(|f| f.to_possible_value())
            .map(|v| format!(".{}", v.get_name()))
            .chain(aliases.iter().map(|(a, _)| format!(".{a}")))
            .collect();
        CliError::Usage(format!(
            "{}: cannot tell the output format from {}: use {} or give --format",
            path.display(),
            ext.map_or("a name without extension".to_string(), |e| format!(
                "the extension .{e}"
            )),
            names.join(", ")
        ))
    })
}

fn triangulate_in<const D: usize, const N: usize, S: SpaceFormat<D, N>>(
    space: S,
    input: &Path,
    weighting: &Weighting,
    out: Output,
) -> Result<(), CliError> {
    let format = output_format(
        out.format,
        &out.output,
        &[("txt", Format::Cells)],
        Format::Cells,
    )?;
    let (pts, weights) = read_input::<D>(input, weighting)?;
    let (tri, cost) = build(space, &pts, weights.as_deref())?;
    write_with(&out.output, |w| match format {
        Format::Cells => orbitri::io::write_cells(w, &tri),
        Format::Json => orbitri::io::write_json(w, &tri),
        Format::Vtu => orbitri::io::write_delaunay_vtu(w, &tri),
    })?;
    if out.stats {
        eprintln!("{}", stats_line(&tri, pts.len(), &cost));
    }
    Ok(())
}

/// Options of `orbitri voronoi`.
struct VoronoiArgs {
    weighting: Weighting,
    output: Option<PathBuf>,
    format: Option<VoronoiFormat>,
    neighbours: Option<PathBuf>,
    edges: Option<PathBuf>,
    stats: bool,
}

fn voronoi(input: PathBuf, domain: Domain, args: VoronoiArgs) -> Result<(), CliError> {
    if SPHERES.contains(&domain.space.as_str()) {
        return sphere::voronoi(&input, &domain, args);
    }
    with_space!(space(&domain)?, voronoi_in(&input, args))
}

/// Writes a file (or standard output) with `f`, naming the path in errors.
fn write_with(
    path: &Option<PathBuf>,
    f: impl FnOnce(&mut Box<dyn Write>) -> std::io::Result<()>,
) -> Result<(), CliError> {
    let name = path.clone().unwrap_or_else(|| PathBuf::from("<stdout>"));
    let mut w = writer(path)?;
    f(&mut w)
        .and_then(|_| w.flush())
        .map_err(|source| CliError::Write { path: name, source })
}

fn voronoi_in<const D: usize, const N: usize, S: SpaceFormat<D, N>>(
    space: S,
    input: &Path,
    args: VoronoiArgs,
) -> Result<(), CliError> {
    space.check_volume_representable()?;
    let format = output_format(args.format, &args.output, &[], VoronoiFormat::Csv)?;
    let (pts, weights) = read_input::<D>(input, &args.weighting)?;
    let (tri, cost) = build(space, &pts, weights.as_deref())?;
    // whole cells only when an output needs their geometry; tables need their measures
    // (and the neighbour pairs their faces' areas)
    let whole = matches!(format, VoronoiFormat::Json | VoronoiFormat::Vtu);
    let start = Instant::now();
    // the Voronoi phase polls after about the same work each time: one step of the bar
    let n = tri.number_of_vertices();
    let bar = progress_bar(n, tri.voronoi_polls() as usize, "Voronoi cells");
    let tick = || {
        if let Some(b) = &bar {
            b.inc(1);
        }
        false
    };
    let cells = if whole {
        tri.voronoi_cells_until(&tick)?
    } else {
        Vec::new()
    };
    let (measures, pairs) = if whole {
        let pairs = match args.neighbours {
            Some(_) => tri.voronoi_neighbors_of(&cells),
            None => Vec::new(),
        };
        (
            cells.iter().map(orbitri::CellMeasures::from).collect(),
            pairs,
        )
    } else if args.neighbours.is_some() {
        tri.voronoi_measures_and_neighbors_until(&tick)?
    } else {
        (tri.voronoi_measures_until(&tick)?, Vec::new())
    };
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let seconds = start.elapsed().as_secs_f64();
    write_with(&args.output, |w| match format {
        VoronoiFormat::Csv => orbitri::io::point_table(&tri, &measures).write_csv(w),
        VoronoiFormat::Npy => w.write_all(&orbitri::io::point_table(&tri, &measures).npy()),
        VoronoiFormat::Npz => w.write_all(&orbitri::io::point_table(&tri, &measures).npz()?),
        VoronoiFormat::Json => orbitri::io::write_voronoi_json(w, &tri, &cells),
        VoronoiFormat::Vtu => orbitri::io::write_voronoi_vtu(w, &cells),
    })?;
    if args.neighbours.is_some() {
        write_with(&args.neighbours, |w| {
            orbitri::io::write_neighbors_csv::<D, N, S>(w, &pairs)
        })?;
    }
    if args.edges.is_some() {
        write_with(&args.edges, |w| orbitri::io::write_edges_csv(w, &tri))?;
    }
    if args.stats {
        let total: f64 = measures.iter().map(|c| c.volume).sum();
        eprintln!(
            "{} voronoi_seconds={seconds:.6} volume_sum={total:?} domain_volume={:?} voronoi_peak_rss_kb={}",
            stats_line(&tri, pts.len(), &cost),
            tri.space().volume(),
            rss::peak_kb().map_or("unknown".to_string(), |k| k.to_string())
        );
    }
    Ok(())
}

fn draw(
    input: PathBuf,
    domain: Domain,
    weighting: Weighting,
    output: PathBuf,
    opts: SvgOptions,
) -> Result<(), CliError> {
    let ext = output.extension().and_then(|e| e.to_str());
    if !ext.is_some_and(|e| e.eq_ignore_ascii_case("svg") || e.eq_ignore_ascii_case("png")) {
        return Err(CliError::Usage(format!(
            "{}: draw writes .svg or .png pictures, not {}",
            output.display(),
            ext.map_or("a name without extension".to_string(), |e| format!(".{e}"))
        )));
    }
    if SPHERES.contains(&domain.space.as_str()) {
        return sphere::draw(&input, &domain, &weighting, output, opts);
    }
    match space(&domain)? {
        Space::Torus2(s) => draw_in(s, &input, &weighting, output, opts),
        Space::Klein(s) => draw_in(s, &input, &weighting, output, opts),
        _ => Err(CliError::Usage(
            "draw renders 2D spaces: give --box LX LY, --lattice AX AY BX BY or --cellpar A B GAMMA (or --space klein --box L1 L2)".into(),
        )),
    }
}

fn draw_in<S: Drawable>(
    space: S,
    input: &Path,
    weighting: &Weighting,
    output: PathBuf,
    opts: SvgOptions,
) -> Result<(), CliError> {
    let (pts, weights) = read_input::<2>(input, weighting)?;
    opts.validate(pts.len()).map_err(option_error)?;
    let (tri, _) = build(space, &pts, weights.as_deref())?;
    let mut svg = Vec::new();
    orbitri::io::write_svg(&mut svg, &tri, &opts).map_err(|e| {
        // writing to memory fails only on options out of range (a picture too high)
        match e
            .get_ref()
            .and_then(|inner| inner.downcast_ref::<orbitri::Error>())
        {
            Some(orbitri::Error::InvalidOption { .. }) => {
                let inner = e.into_inner().expect("checked").downcast();
                option_error(*inner.expect("checked"))
            }
            _ => CliError::Write {
                path: output.clone(),
                source: e,
            },
        }
    })?;
    write_picture(output, svg)
}

/// Writes an SVG picture to `output`, rendered to PNG for a `.png` name.
fn write_picture(output: PathBuf, svg: Vec<u8>) -> Result<(), CliError> {
    let png = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    let bytes = if png {
        render_png(&svg).map_err(|message| CliError::Render {
            path: output.clone(),
            message,
        })?
    } else {
        svg
    };
    std::fs::write(&output, bytes).map_err(|source| CliError::Write {
        path: output,
        source,
    })
}

/// An option out of range, named as the flag the user typed.
fn option_error(e: orbitri::Error) -> CliError {
    match e {
        orbitri::Error::InvalidOption {
            option,
            value,
            limit,
        } => CliError::Usage(format!("--{option} {value} is out of range: {limit}")),
        e => e.into(),
    }
}

/// Rasterizes our SVG (no text, no images) with resvg.
fn render_png(svg: &[u8]) -> Result<Vec<u8>, String> {
    let tree = resvg::usvg::Tree::from_data(svg, &resvg::usvg::Options::default())
        .map_err(|e| e.to_string())?;
    let size = tree.size().to_int_size();
    let mut pixmap =
        resvg::tiny_skia::Pixmap::new(size.width(), size.height()).ok_or("empty picture")?;
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::default(),
        &mut pixmap.as_mut(),
    );
    pixmap.encode_png().map_err(|e| e.to_string())
}

fn uniform<const D: usize>(n: usize, seed: u64) -> Vec<[f64; D]> {
    let mut r = SplitMix::new(seed);
    (0..n).map(|_| std::array::from_fn(|_| r.unit())).collect()
}

fn demo(n: usize, seed: u64) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    let say = |out: &mut std::io::StdoutLock, s: String| {
        let _ = writeln!(out, "{s}");
    };
    let pts = uniform::<3>(n, seed);
    let (tri, cost) = build::<3, 4, _>(FlatTorus3::cuboid([1.0; 3])?, &pts, None)?;
    say(
        &mut out,
        format!("uniform random points in the unit cube (seed {seed}):"),
    );
    say(&mut out, format!("  {}", stats_line(&tri, n, &cost)));
    say(
        &mut out,
        format!(
            "  {:.2} µs per point; Euler check E = V + C: {}",
            cost.seconds * 1e6 / n as f64,
            tri.edges().len() == tri.number_of_vertices() + tri.number_of_cells()
        ),
    );
    let t = Instant::now();
    tri.is_valid().map_err(|e| CliError::Check(e.to_string()))?;
    say(
        &mut out,
        format!(
            "  exact validity check (orientation, local Delaunay, Euler) passed in {:.2} s",
            t.elapsed().as_secs_f64()
        ),
    );
    // FCC crystal, 6×6×6 conventional cells, lattice constant 0.1 (not a binary fraction)
    let mut fcc = Vec::new();
    for i in 0..6 {
        for j in 0..6 {
            for k in 0..6 {
                for b in [
                    [0.0, 0.0, 0.0],
                    [0.5, 0.5, 0.0],
                    [0.5, 0.0, 0.5],
                    [0.0, 0.5, 0.5],
                ] {
                    fcc.push([
                        (i as f64 + b[0]) * 0.1,
                        (j as f64 + b[1]) * 0.1,
                        (k as f64 + b[2]) * 0.1,
                    ]);
                }
            }
        }
    }
    let (tri, cost) = build::<3, 4, _>(FlatTorus3::cuboid([0.6; 3])?, &fcc, None)?;
    say(
        &mut out,
        "FCC crystal, 864 points, all octahedral holes cospherical:".to_string(),
    );
    say(
        &mut out,
        format!("  {}", stats_line(&tri, fcc.len(), &cost)),
    );
    tri.is_valid().map_err(|e| CliError::Check(e.to_string()))?;
    say(
        &mut out,
        format!(
            "  {} cells = 6 per point: every cospherical tie broken consistently; valid",
            tri.number_of_cells()
        ),
    );
    // 2D: the same engine on the unit square, then a honeycomb (6 cocircular points around
    // every hexagon) in its hexagonal cell
    let (tri, cost) =
        build::<2, 3, _>(FlatTorus2::cuboid([1.0; 2])?, &uniform::<2>(n, seed), None)?;
    say(
        &mut out,
        format!("uniform random points in the unit square (seed {seed}):"),
    );
    say(&mut out, format!("  {}", stats_line(&tri, n, &cost)));
    tri.is_valid().map_err(|e| CliError::Check(e.to_string()))?;
    let h = 3f64.sqrt() / 2.0;
    let hex = FlatTorus2::triclinic([[1.0, 0.0], [0.5, h]])?;
    let mut honey = Vec::new();
    for i in 0..20 {
        for j in 0..20 {
            for b in [1.0 / 3.0, 2.0 / 3.0] {
                let f = [(i as f64 + b) / 20.0, (j as f64 + b) / 20.0];
                honey.push(hex.lattice().cartesian(&f));
            }
        }
    }
    let (tri, cost) = build::<2, 3, _>(hex, &honey, None)?;
    say(
        &mut out,
        "honeycomb, 800 points in a hexagonal cell, 6 cocircular points per hexagon:".to_string(),
    );
    say(
        &mut out,
        format!("  {}", stats_line(&tri, honey.len(), &cost)),
    );
    tri.is_valid().map_err(|e| CliError::Check(e.to_string()))?;
    say(
        &mut out,
        format!(
            "  {} triangles = 2 per point; valid. Pictures: orbitri draw POINTS --box 1 1 -o t.svg",
            tri.number_of_cells()
        ),
    );
    Ok(())
}

fn generate(n: usize, seed: u64, dim: u8, output: Option<PathBuf>) -> Result<(), CliError> {
    write_with(&output, |w| {
        if dim == 2 {
            for p in uniform::<2>(n, seed) {
                writeln!(w, "{:?} {:?}", p[0], p[1])?;
            }
        } else {
            for p in uniform::<3>(n, seed) {
                writeln!(w, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
            }
        }
        Ok(())
    })
}

/// Marks the negative numbers that follow `--box` or `--lattice` (as many as
/// `str::parse::<f64>` reads, up to the most the option takes) as values, with a leading
/// blank that [`number`] drops.
///
/// clap reads a token that starts with `-` as a flag unless it is a plain negative number
/// (`-2`, `-2.5`, `-2e5`), so `-2e-301`, `-.5` or `-inf` were unknown flags; and
/// `allow_hyphen_values` would also take the `-o` of `--box 1 1 -o out` for a third length,
/// as clap stops only at the most values an option takes.
fn mark_negative_numbers(args: impl IntoIterator<Item = OsString>) -> Vec<OsString> {
    let mut out = Vec::new();
    let mut args = args.into_iter().peekable();
    while let Some(arg) = args.next() {
        let most = match arg.to_str() {
            Some("--box") | Some("--cellpar") => 6,
            Some("--lattice") => 9,
            Some("--") => {
                out.push(arg);
                out.extend(args);
                break;
            }
            _ => 0,
        };
        out.push(arg);
        for _ in 0..most {
            let Some(v) = args.next_if(|a| a.to_str().is_some_and(|v| v.parse::<f64>().is_ok()))
            else {
                break;
            };
            out.push(match v.to_str() {
                Some(n) if n.starts_with('-') => format!(" {n}").into(),
                _ => v,
            });
        }
    }
    out
}

/// A number as `str::parse::<f64>` reads it (after the blank of [`mark_negative_numbers`]).
fn number(s: &str) -> Result<f64, String> {
    s.strip_prefix(' ')
        .unwrap_or(s)
        .parse()
        .map_err(|e: std::num::ParseFloatError| e.to_string())
}

fn main() -> ExitCode {
    rss::keep_large_buffers_mapped();
    let cli = Cli::parse_from(mark_negative_numbers(std::env::args_os()));
    if let Some(n) = cli.threads {
        let _ = THREADS.set(n.into());
        // (the first pool of the process: it cannot exist yet)
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n.into())
            .build_global();
    }
    let result = match cli.command {
        Command::Triangulate {
            input,
            domain,
            weighting,
            out,
        } => triangulate(input, domain, weighting, out),
        Command::Demo { points, seed } => demo(points, seed),
        Command::Voronoi {
            input,
            domain,
            weighting,
            output,
            format,
            neighbours,
            edges,
            stats,
        } => voronoi(
            input,
            domain,
            VoronoiArgs {
                weighting,
                output,
                format,
                neighbours,
                edges,
                stats,
            },
        ),
        Command::Draw {
            input,
            domain,
            weighting,
            output,
            copies,
            width,
            no_voronoi,
            no_delaunay,
        } => draw(
            input,
            domain.into(),
            weighting,
            output,
            SvgOptions {
                copies,
                width,
                voronoi: !no_voronoi,
                delaunay: !no_delaunay,
                points: true,
            },
        ),
        Command::Generate {
            n,
            seed,
            dim,
            output,
        } => generate(n, seed, dim, output),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("orbitri: error: {e}");
            ExitCode::from(2)
        }
    }
}
