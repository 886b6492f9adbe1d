//! `--space sphere` and `--space projective-plane`: the commands on the unit sphere and on
//! RP² (points as unit vectors or, with `--lonlat`, longitude and latitude in degrees).

use std::path::{Path, PathBuf};
use std::time::Instant;

use orbitri::io::SvgOptions;
use orbitri::spherical::{lonlat_to_point, normalized, SphericalSpace, SphericalTriangulation};

use super::{
    output_format, progress_bar, rss, write_with, CliError, Domain, Format, Output, VoronoiArgs,
    VoronoiFormat, Weighting,
};

/// The points of `input` on the sphere, as the domain's flags say they are given.
fn read(input: &Path, domain: &Domain, weighting: &Weighting) -> Result<Vec<[f64; 3]>, CliError> {
    if weighting.column().is_some() {
        return Err(CliError::Usage(
            "--weights and --radii are for the flat spaces: points on the sphere are unweighted"
                .into(),
        ));
    }
    let e = &domain.extent;
    if e.box_lengths.is_some() || e.lattice.is_some() || e.cellpar.is_some() {
        return Err(CliError::Usage(format!(
            "--space {} has no box: drop --box, --lattice and --cellpar",
            domain.space
        )));
    }
    if domain.on_sphere.lonlat {
        let ll = orbitri::io::read_points::<2>(input)?;
        return ll
            .iter()
            .enumerate()
            .map(|(i, l)| Ok(lonlat_to_point(i, l[0], l[1])?))
            .collect();
    }
    let pts = orbitri::io::read_points::<3>(input)?;
    Ok(if domain.on_sphere.normalize {
        normalized(&pts)?
    } else {
        pts
    })
}

/// Builds with a progress bar; the build's seconds and the peak memory after it.
fn build<S: SphericalSpace>(
    pts: &[[f64; 3]],
) -> Result<(SphericalTriangulation<S>, super::Cost), CliError> {
    let bar = progress_bar(pts.len(), pts.len(), "triangulation");
    let start = Instant::now();
    let tri = SphericalTriangulation::build_with_threads(pts, super::threads(), |k| {
        if let Some(b) = &bar {
            b.set_position(k as u64);
        }
        std::ops::ControlFlow::Continue(())
    })?;
    let cost = super::Cost {
        seconds: start.elapsed().as_secs_f64(),
        peak_rss_kb: rss::peak_kb(),
    };
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    Ok((tri, cost))
}

fn stats_line<S: SphericalSpace>(
    tri: &SphericalTriangulation<S>,
    input: usize,
    cost: &super::Cost,
) -> String {
    format!(
        "input={input} vertices={} faces={} dimension={} covers_sphere={} duplicates={} hidden={} build_seconds={:.6} peak_rss_kb={}",
        tri.number_of_vertices(),
        tri.faces().len(),
        tri.dimension(),
        tri.covers_sphere(),
        tri.duplicates(),
        tri.hidden().len(),
        cost.seconds,
        cost.peak_rss_kb.map_or("unknown".to_string(), |k| k.to_string())
    )
}

/// Runs `$f::<S>(args)` with the space `--space` names.
macro_rules! on {
    ($domain:expr, $f:ident($($arg:expr),*)) => {
        if $domain.space == "projective-plane" {
            $f::<orbitri::ProjectivePlane>($($arg),*)
        } else {
            $f::<orbitri::Sphere>($($arg),*)
        }
    };
}

pub(super) fn triangulate(
    input: &Path,
    domain: &Domain,
    weighting: &Weighting,
    out: Output,
) -> Result<(), CliError> {
    on!(domain, triangulate_in(input, domain, weighting, out))
}

fn triangulate_in<S: SphericalSpace>(
    input: &Path,
    domain: &Domain,
    weighting: &Weighting,
    out: Output,
) -> Result<(), CliError> {
    let format = output_format(
        out.format,
        &out.output,
        &[("txt", Format::Cells)],
        Format::Cells,
    )?;
    let pts = read(input, domain, weighting)?;
    let (tri, cost) = build::<S>(&pts)?;
    write_with(&out.output, |w| match format {
        Format::Cells => orbitri::io::write_sphere_cells(w, &tri),
        Format::Json => orbitri::io::write_sphere_json(w, &tri),
        Format::Vtu => orbitri::io::write_sphere_faces_vtu(w, &tri),
    })?;
    if out.stats {
        eprintln!("{}", stats_line(&tri, pts.len(), &cost));
    }
    Ok(())
}

pub(super) fn voronoi(input: &Path, domain: &Domain, args: VoronoiArgs) -> Result<(), CliError> {
    on!(domain, voronoi_in(input, domain, args))
}

fn voronoi_in<S: SphericalSpace>(
    input: &Path,
    domain: &Domain,
    args: VoronoiArgs,
) -> Result<(), CliError> {
    let format = output_format(args.format, &args.output, &[], VoronoiFormat::Csv)?;
    if args.edges.is_some() || args.neighbours.is_some() {
        return Err(CliError::Usage(
            "--neighbours and --edges are for the flat spaces: on the sphere and RP² the JSON cells list each cell's neighbours".into(),
        ));
    }
    let pts = read(input, domain, &args.weighting)?;
    let (tri, cost) = build::<S>(&pts)?;
    let start = Instant::now();
    let cells = tri.voronoi_cells()?;
    let seconds = start.elapsed().as_secs_f64();
    let table = || orbitri::io::sphere_point_table(&tri, &cells);
    write_with(&args.output, |w| match format {
        VoronoiFormat::Csv => table().write_csv(w),
        VoronoiFormat::Npy => w.write_all(&table().npy()),
        VoronoiFormat::Npz => w.write_all(&table().npz()?),
        VoronoiFormat::Json => orbitri::io::write_spherical_voronoi_json(w, &tri, &cells),
        VoronoiFormat::Vtu => orbitri::io::write_spherical_voronoi_vtu(w, &cells),
    })?;
    if args.stats {
        let total: f64 = cells.iter().map(|c| c.area).sum();
        eprintln!(
            "{} voronoi_seconds={seconds:.6} area_sum={total:?} space_area={:?} voronoi_peak_rss_kb={}",
            stats_line(&tri, pts.len(), &cost),
            S::AREA,
            rss::peak_kb().map_or("unknown".to_string(), |k| k.to_string())
        );
    }
    Ok(())
}

pub(super) fn draw(
    input: &Path,
    domain: &Domain,
    weighting: &Weighting,
    output: PathBuf,
    opts: SvgOptions,
) -> Result<(), CliError> {
    on!(domain, draw_in(input, domain, weighting, output, opts))
}

fn draw_in<S: SphericalSpace>(
    input: &Path,
    domain: &Domain,
    weighting: &Weighting,
    output: PathBuf,
    opts: SvgOptions,
) -> Result<(), CliError> {
    let pts = read(input, domain, weighting)?;
    opts.validate(pts.len()).map_err(super::option_error)?;
    let (tri, _) = build::<S>(&pts)?;
    let mut svg = Vec::new();
    orbitri::io::write_sphere_svg(&mut svg, &tri, &opts).map_err(|source| CliError::Write {
        path: output.clone(),
        source,
    })?;
    super::write_picture(output, svg)
}
