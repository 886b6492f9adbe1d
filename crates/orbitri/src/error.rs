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
    /// A point given as on the unit sphere that is not, within
    /// [`crate::spherical::NORM_TOLERANCE`] (or a zero vector to normalize).
    #[error(
        "point {index}: its norm is {norm}, not 1: points on the sphere must be unit vectors (to within 1e-6), or give them as longitude and latitude, or normalize them"
    )]
    OffSphere { index: usize, norm: f64 },
    /// A spherical Voronoi diagram asked of points with no faces (below dimension 2).
    #[error(
        "the {points} points have no faces (dimension {dimension}: at most two points, or all on one circle): spherical Voronoi cells are dual to faces and need three points off one circle"
    )]
    NoFaces { points: usize, dimension: i32 },
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
    /// A weight (or radius) that is not a finite number, a negative radius, or a weight
    /// beyond what the box's internal frame holds.
    #[error("point {index}: {what} {value} {why}")]
    BadWeight {
        index: usize,
        what: &'static str,
        value: f64,
        why: String,
    },
    /// Weights given for a number of points other than the points'.
    #[error("{weights} weights for {points} points: give one weight (or radius) per point")]
    WeightCount { points: usize, weights: usize },
    /// The weights spread wider than any covering space of the box is proven safe for.
    #[error(
        "point {index}: weight {value:e} spreads the weights over {spread:e} (largest − least), more than this box allows ({limit:e}: the covering space would need more than 24 copies along a lattice vector); weights are squared lengths, compare them with the squared box size"
    )]
    WeightSpread {
        index: usize,
        value: f64,
        spread: f64,
        limit: f64,
    },
    /// An input id the triangulation does not hold: never given, or removed.
    #[error("input id {id}: {why}")]
    UnknownInput { id: u64, why: String },
    /// A triangulation stored in a covering space that the space's group does not map onto
    /// itself, so that it describes no triangulation of the space (see
    /// [`crate::Triangulation::complex`]).
    #[error(
        "{points} points are too few for a triangulation of the space itself, and the triangulation of its {sheets}-sheeted covering breaks a tie among images of one point under different screw motions differently for different copies (the space's group has no order that every element respects, as the didicosm's), so it describes no triangulation of the space; add points (the Voronoi cells are exact either way)"
    )]
    NotInvariant { points: usize, sheets: usize },
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
