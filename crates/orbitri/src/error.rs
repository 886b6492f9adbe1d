//! The typed errors of the library: each names the offending place and value.

use std::path::PathBuf;

/// Everything that can go wrong, with the place (point index, file and line) and the value.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("point {index}: coordinate {axis} is {value}, not a finite number")]
    NonFiniteCoordinate {
        index: usize,
        axis: usize,
        value: f64,
    },
    #[error(
        "point {index}: {coordinates} lies too far from the domain (beyond 2^50 periods) to be wrapped into it exactly"
    )]
    OutOfReach { index: usize, coordinates: String },
    #[error(
        "the domain's volume, about 2^{log2:.0}, is outside the range of doubles: its Voronoi volumes cannot be represented (rescale the coordinates)"
    )]
    UnrepresentableVolume { log2: f64 },
    #[error("the input holds no points")]
    EmptyInput,
    #[error("invalid box: {0}")]
    InvalidBox(String),
    #[error("singular lattice: the lattice vectors are linearly dependent (|det| = {det:e})")]
    SingularLattice { det: f64 },
    #[error(
        "lattice too skewed: orthogonality defect {defect:.3} > {limit} (reduce the basis, e.g. keep tilt factors within half a box length)"
    )]
    SkewedLattice { defect: f64, limit: f64 },
    #[error("expected points of dimension {expected}, got {found}")]
    DimensionMismatch { expected: usize, found: usize },
    #[error("{}:{line}: {message}", file.display())]
    Parse {
        file: PathBuf,
        line: usize,
        message: String,
    },
    #[error("{}: {source}", file.display())]
    Io {
        file: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// An input id the triangulation does not hold: never given, or removed.
    #[error("input id {id}: {why}")]
    UnknownInput { id: u64, why: String },
    /// The caller's progress or interrupt callback asked a long computation to stop.
    #[error("interrupted")]
    Interrupted,
    /// An option out of the range a function accepts (a picture too large to draw, say):
    /// the option's name, its value, and the limit it exceeds.
    #[error("{option} {value} is out of range: {limit}")]
    InvalidOption {
        option: &'static str,
        value: String,
        limit: String,
    },
}

/// The library's result type.
pub type Result<T> = std::result::Result<T, Error>;
