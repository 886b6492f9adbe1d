//! The `orbitri` command.

mod rss;

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

#[derive(Parser)]
#[command(
    name = "orbitri",
    version,
    about = "Exact periodic Delaunay triangulations (2D and 3D flat tori with any lattice, the Klein bottle, the flat 3-manifolds)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Triangulate the points of INPUT (text: one `x y z` or `x y` per line, `#` comments,
    /// commas or blanks; or `.npy`: float64, N×3 or N×2) in a periodic box or lattice, or in
    /// the closed flat manifold `--space`; the dimension is that of the box.
    Triangulate {
        /// Input file (text or .npy)
        input: PathBuf,
        #[command(flatten)]
        domain: Domain,
        #[command(flatten)]
        out: Output,
    },
    /// Compute the periodic Voronoi cell of every point of INPUT: one row per input point
    /// (`id,volume,neighbours,surface_area,centroid_…,duplicate_of`, input order) as CSV or
    /// `.npy`, or the whole cells as JSON or VTK (`.vtu`, for ParaView).
    Voronoi {
        /// Input file (text or .npy)
        input: PathBuf,
        #[command(flatten)]
        domain: Domain,
        /// Output file (default: standard output); its extension picks the format
        #[arg(short = 'o', long)]
        output: Option<PathBuf>,
        /// Output format (default: from the output's extension, else csv)
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
    /// Draw the periodic Delaunay triangulation and Voronoi diagram of 2D points over copies
    /// of the domain (in a Klein bottle: its images, every other column reflected), to SVG
    /// (or PNG for a `.png` output name).
    Draw {
        /// Input file (text or .npy, 2 coordinates per point)
        input: PathBuf,
        #[command(flatten)]
        domain: Domain,
        /// Output file: .svg or .png
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
    /// Triangulate built-in examples: uniform random points in the unit cube and an FCC
    /// crystal (every Delaunay sphere degenerate), then the unit square and a hexagonal
    /// crystal in 2D, with exact validity checks.
    Demo {
        /// Number of random points
        #[arg(short = 'n', long, default_value_t = 100_000)]
        points: usize,
        /// Seed of the point generator
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Write N uniform random points of the unit cube or square (the CGAL anchor harness's
    /// generator).
    Generate {
        n: usize,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Dimension: 3 (unit cube) or 2 (unit square)
        #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u8).range(2..=3))]
        dim: u8,
        #[arg(short = 'o', long)]
        output: Option<PathBuf>,
    },
}

/// The names `--space` takes besides the closed flat 3-manifolds'
/// (`FlatManifold::PLATYCOSMS`).
const TORUS_AND_KLEIN: [&str; 2] = ["torus", "klein"];

#[derive(Args)]
struct Domain {
    /// The orbit space: a flat torus (default), the Klein bottle (2D: --box L1 L2, the glide
    /// along the first axis) or a closed flat 3-manifold (--box L1 L2 L3, the sides of its
    /// standard domain)
    #[arg(long, value_name = "NAME", default_value = "torus", value_parser = PossibleValuesParser::new(TORUS_AND_KLEIN.into_iter().chain(FlatManifold::PLATYCOSMS)))]
    space: String,
    #[command(flatten)]
    extent: Extent,
}

#[derive(Args)]
#[group(required = true, multiple = false)]
struct Extent {
    /// Box lengths: the domain is [0,LX) × [0,LY) × [0,LZ), or [0,LX) × [0,LY) in 2D
    #[arg(long = "box", num_args = 2..=3, value_names = ["LX", "LY", "LZ"], value_parser = number, allow_negative_numbers = true)]
    box_lengths: Option<Vec<f64>>,
    /// Lattice vectors (rows): AX AY AZ BX BY BZ CX CY CZ in 3D, AX AY BX BY in 2D; the
    /// domain is {f·M : f ∈ [0,1)^D}
    #[arg(long, num_args = 4..=9, value_names = ["AX", "AY", "..."], value_parser = number, allow_negative_numbers = true)]
    lattice: Option<Vec<f64>>,
}

#[derive(Args)]
struct Output {
    /// Output file (default: standard output)
    #[arg(short = 'o', long)]
    output: Option<PathBuf>,
    /// Output format
    #[arg(long, value_enum, default_value_t = Format::Cells)]
    format: Format,
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
    /// VTK UnstructuredGrid (ParaView): one copy of each cell, drawn whole
    Vtu,
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum VoronoiFormat {
    /// One row per input point: id, volume, neighbours, surface area, centroid, duplicate_of
    Csv,
    /// The same columns as a float64 N×K array
    Npy,
    /// Every cell: vertices, faces (vertex cycles, neighbour, shift, area), volume, centroid
    Json,
    /// VTK UnstructuredGrid of the cells (polyhedra in 3D, polygons in 2D), drawn whole
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
    match domain.space.as_str() {
        "torus" => torus(&domain.extent),
        name => manifold(name, &domain.extent),
    }
}

fn torus(extent: &Extent) -> Result<Space, CliError> {
    if let Some(b) = &extent.box_lengths {
        return Ok(match b.len() {
            2 => Space::Torus2(FlatTorus2::cuboid([b[0], b[1]])?),
            _ => Space::Torus3(FlatTorus3::cuboid([b[0], b[1], b[2]])?),
        });
    }
    let l = extent
        .lattice
        .as_ref()
        .expect("clap requires --box or --lattice");
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
        return Err(CliError::Usage(format!(
            "--lattice is for the torus only: --space {name} takes --box {sides}"
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

fn progress_bar(n: usize) -> Option<ProgressBar> {
    if n < 200_000 || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::new(n as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} points ({eta} left)",
        )
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
) -> Result<(Triangulation<D, N, S>, Cost), orbitri::Error> {
    let bar = progress_bar(pts.len());
    let start = Instant::now();
    let tri = Triangulation::build_with(space, pts, BuildOptions::default(), |k| {
        if let Some(b) = &bar {
            b.set_position(k as u64);
        }
        std::ops::ControlFlow::Continue(())
    })?;
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
    format!(
        "input={input} vertices={} cells={} sheets={} duplicates={} wrapped={} dummies={} build_seconds={:.6} peak_rss_kb={}",
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

fn triangulate(input: PathBuf, domain: Domain, out: Output) -> Result<(), CliError> {
    with_space!(space(&domain)?, triangulate_in(&input, out))
}

fn triangulate_in<const D: usize, const N: usize, S: SpaceFormat<D, N>>(
    space: S,
    input: &Path,
    out: Output,
) -> Result<(), CliError> {
    let pts: Vec<[f64; D]> = orbitri::io::read_points(input)?;
    let (tri, cost) = build(space, &pts)?;
    write_with(&out.output, |w| match out.format {
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
    output: Option<PathBuf>,
    format: Option<VoronoiFormat>,
    neighbours: Option<PathBuf>,
    edges: Option<PathBuf>,
    stats: bool,
}

fn voronoi(input: PathBuf, domain: Domain, args: VoronoiArgs) -> Result<(), CliError> {
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
    let pts: Vec<[f64; D]> = orbitri::io::read_points(input)?;
    let (tri, cost) = build(space, &pts)?;
    let by_extension = args.output.as_ref().and_then(|p| {
        let ext = p.extension()?.to_str()?.to_ascii_lowercase();
        VoronoiFormat::from_str(&ext, true).ok()
    });
    let format = args.format.or(by_extension).unwrap_or(VoronoiFormat::Csv);
    // whole cells only when an output needs their geometry; tables need their measures
    let whole =
        matches!(format, VoronoiFormat::Json | VoronoiFormat::Vtu) || args.neighbours.is_some();
    let start = Instant::now();
    let cells = if whole {
        tri.voronoi_cells()
    } else {
        Vec::new()
    };
    let measures: Vec<orbitri::CellMeasures<D>> = if whole {
        cells.iter().map(orbitri::CellMeasures::from).collect()
    } else {
        tri.voronoi_measures()
    };
    let seconds = start.elapsed().as_secs_f64();
    write_with(&args.output, |w| match format {
        VoronoiFormat::Csv => orbitri::io::point_table(&tri, &measures).write_csv(w),
        VoronoiFormat::Npy => w.write_all(&orbitri::io::point_table(&tri, &measures).npy()),
        VoronoiFormat::Json => orbitri::io::write_voronoi_json(w, &tri, &cells),
        VoronoiFormat::Vtu => orbitri::io::write_voronoi_vtu(w, &cells),
    })?;
    if args.neighbours.is_some() {
        write_with(&args.neighbours, |w| {
            orbitri::io::write_neighbors_csv(w, &tri, &cells)
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

fn draw(input: PathBuf, domain: Domain, output: PathBuf, opts: SvgOptions) -> Result<(), CliError> {
    match space(&domain)? {
        Space::Torus2(s) => draw_in(s, &input, output, opts),
        Space::Klein(s) => draw_in(s, &input, output, opts),
        _ => Err(CliError::Usage(
            "draw renders 2D spaces: give --box LX LY or --lattice AX AY BX BY (or --space klein --box L1 L2)".into(),
        )),
    }
}

fn draw_in<S: Drawable>(
    space: S,
    input: &Path,
    output: PathBuf,
    opts: SvgOptions,
) -> Result<(), CliError> {
    let pts: Vec<[f64; 2]> = orbitri::io::read_points(input)?;
    opts.validate(pts.len()).map_err(option_error)?;
    let (tri, _) = build(space, &pts)?;
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
    let (tri, cost) = build::<3, 4, _>(FlatTorus3::cuboid([1.0; 3])?, &pts)?;
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
    let (tri, cost) = build::<3, 4, _>(FlatTorus3::cuboid([0.6; 3])?, &fcc)?;
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
    let (tri, cost) = build::<2, 3, _>(FlatTorus2::cuboid([1.0; 2])?, &uniform::<2>(n, seed))?;
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
    let (tri, cost) = build::<2, 3, _>(hex, &honey)?;
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
            Some("--box") => 3,
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
    let cli = Cli::parse_from(mark_negative_numbers(std::env::args_os()));
    let result = match cli.command {
        Command::Triangulate { input, domain, out } => triangulate(input, domain, out),
        Command::Demo { points, seed } => demo(points, seed),
        Command::Voronoi {
            input,
            domain,
            output,
            format,
            neighbours,
            edges,
            stats,
        } => voronoi(
            input,
            domain,
            VoronoiArgs {
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
            output,
            copies,
            width,
            no_voronoi,
            no_delaunay,
        } => draw(
            input,
            domain,
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
