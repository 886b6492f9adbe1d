//! The `orbitri` command.

mod rss;

use std::io::{BufWriter, IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::{Args, Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use orbitri::sort::SplitMix;
use orbitri::{BuildOptions, FlatTorus3, PeriodicDelaunay3};

#[derive(Parser)]
#[command(
    name = "orbitri",
    version,
    about = "Exact periodic Delaunay triangulations (flat tori with any lattice)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Triangulate the points of INPUT (text: one `x y z` per line, `#` comments, commas or
    /// blanks; or `.npy`: float64, N×3) in a periodic box or lattice.
    Triangulate {
        /// Input file (text or .npy)
        input: PathBuf,
        #[command(flatten)]
        domain: Domain,
        #[command(flatten)]
        out: Output,
    },
    /// Triangulate a built-in example: uniform random points in the unit cube and an FCC
    /// crystal (every Delaunay sphere degenerate), with exact validity checks.
    Demo {
        /// Number of random points
        #[arg(short = 'n', long, default_value_t = 100_000)]
        points: usize,
        /// Seed of the point generator
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Write N uniform random points of the unit cube (the CGAL anchor harness's generator).
    Generate {
        n: usize,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        #[arg(short = 'o', long)]
        output: Option<PathBuf>,
    },
}

#[derive(Args)]
#[group(required = true, multiple = false)]
struct Domain {
    /// Box lengths: the domain is [0,LX) × [0,LY) × [0,LZ)
    #[arg(long = "box", num_args = 3, value_names = ["LX", "LY", "LZ"], allow_negative_numbers = true)]
    box_lengths: Option<Vec<f64>>,
    /// Lattice vectors a, b, c (rows); the domain is {f·M : f ∈ [0,1)³}
    #[arg(long, num_args = 9, value_names = ["AX", "AY", "AZ", "BX", "BY", "BZ", "CX", "CY", "CZ"], allow_negative_numbers = true)]
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
    /// `SHEETS V C`, then per cell 4 input ids and 4 offsets (3 integers each)
    Cells,
    /// JSON with lattice, wrapped points, first occurrences, cells and offsets
    Json,
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
}

fn space(domain: &Domain) -> Result<FlatTorus3, orbitri::Error> {
    if let Some(b) = &domain.box_lengths {
        FlatTorus3::cuboid([b[0], b[1], b[2]])
    } else {
        let l = domain
            .lattice
            .as_ref()
            .expect("clap requires --box or --lattice");
        FlatTorus3::triclinic([[l[0], l[1], l[2]], [l[3], l[4], l[5]], [l[6], l[7], l[8]]])
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

fn build(space: FlatTorus3, pts: &[[f64; 3]]) -> Result<(PeriodicDelaunay3, Cost), orbitri::Error> {
    let bar = progress_bar(pts.len());
    let start = Instant::now();
    let tri = PeriodicDelaunay3::build_with(space, pts, BuildOptions::default(), |k| {
        if let Some(b) = &bar {
            b.set_position(k as u64);
        }
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

fn stats_line(tri: &PeriodicDelaunay3, input: usize, cost: &Cost) -> String {
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
    let space = space(&domain)?;
    let pts: Vec<[f64; 3]> = orbitri::io::read_points(&input)?;
    let (tri, cost) = build(space, &pts)?;
    let path = out
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from("<stdout>"));
    let mut w = writer(&out.output)?;
    let res = match out.format {
        Format::Cells => orbitri::io::write_cells(&mut w, &tri),
        Format::Json => orbitri::io::write_json(&mut w, &tri),
    };
    res.and_then(|_| w.flush())
        .map_err(|source| CliError::Write { path, source })?;
    if out.stats {
        eprintln!("{}", stats_line(&tri, pts.len(), &cost));
    }
    Ok(())
}

fn uniform(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = SplitMix::new(seed);
    (0..n).map(|_| [r.unit(), r.unit(), r.unit()]).collect()
}

fn demo(n: usize, seed: u64) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    let say = |out: &mut std::io::StdoutLock, s: String| {
        let _ = writeln!(out, "{s}");
    };
    let pts = uniform(n, seed);
    let (tri, cost) = build(FlatTorus3::cuboid([1.0; 3])?, &pts)?;
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
            tri.edges(orbitri::Copies::Unique).len()
                == tri.number_of_vertices() + tri.number_of_cells()
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
    let (tri, cost) = build(FlatTorus3::cuboid([0.6; 3])?, &fcc)?;
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
    Ok(())
}

fn generate(n: usize, seed: u64, output: Option<PathBuf>) -> Result<(), CliError> {
    let path = output.clone().unwrap_or_else(|| PathBuf::from("<stdout>"));
    let mut w = writer(&output)?;
    let res = (|| {
        for p in uniform(n, seed) {
            writeln!(w, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
        }
        w.flush()
    })();
    res.map_err(|source| CliError::Write { path, source })
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Triangulate { input, domain, out } => triangulate(input, domain, out),
        Command::Demo { points, seed } => demo(points, seed),
        Command::Generate { n, seed, output } => generate(n, seed, output),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("orbitri: error: {e}");
            ExitCode::from(2)
        }
    }
}
