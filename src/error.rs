//! Typed errors: every reachable failure says what was wrong and why.

use thiserror::Error;

/// Convenient result alias of the crate. The error type defaults to [`enum@Error`] and can be
/// named, so `use precursors::*` leaves `Result<T, E>` usable for other errors.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in the crate.
///
/// Every variant carries the offending values so a caller can report them or recover.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// A length (block size, cell size, rod half-width, ...) is not finite and positive.
    #[error("{name} = {value} m is invalid: it must be finite and > 0")]
    InvalidLength {
        /// Which length.
        name: &'static str,
        /// The value given (m).
        value: f64,
    },
    /// A cell count is zero.
    #[error("the grid needs at least one cell along {axis}, got 0")]
    EmptyGrid {
        /// `"x"` or `"y"`.
        axis: &'static str,
    },
    /// The requested cell size does not divide the face into a whole number of cells.
    #[error(
        "cell size {cell} m does not divide L{axis} = {length} m (ratio {ratio}, not an integer)"
    )]
    GridDoesNotDivide {
        /// `"x"` or `"y"`.
        axis: &'static str,
        /// Face length along that axis (m).
        length: f64,
        /// Requested cell size (m).
        cell: f64,
        /// `length / cell`.
        ratio: f64,
    },
    /// A coordinate lies outside the block.
    #[error("{name} = {value} m lies outside the block, which spans [0, {max}] m")]
    OutsideBlock {
        /// Which coordinate (`"x"`, `"xi"`, `"z"`, ...).
        name: &'static str,
        /// The value given (m).
        value: f64,
        /// The block length along that axis (m).
        max: f64,
    },
    /// The rod band `[h - Δh, h + Δh]` is not inside the trailing face `[0, Lz]`.
    #[error(
        "rod band [h - dh, h + dh] = [{low}, {high}] m is not inside the trailing face [0, {lz}] m"
    )]
    RodBandOutsideFace {
        /// `h - Δh` (m).
        low: f64,
        /// `h + Δh` (m).
        high: f64,
        /// Block height (m).
        lz: f64,
    },
    /// A tolerance is not finite and positive.
    #[error("tolerance {value} is invalid: it must be finite and > 0")]
    InvalidTolerance {
        /// The value given.
        value: f64,
    },
    /// The target point coincides with the source point, where the Green function is infinite.
    #[error(
        "target and source coincide at ({x}, {y}, {z}) m: the Green function is singular there"
    )]
    SingularPoint {
        /// x (m).
        x: f64,
        /// y (m).
        y: f64,
        /// z (m).
        z: f64,
    },
    /// A series could not reach the requested tolerance within its term budget.
    #[error(
        "{what} did not reach tolerance {tolerance:e}: best value {value:e} with error estimate \
         {error:e} after {terms} terms (raise the budget or the tolerance)"
    )]
    NotConverged {
        /// Which series.
        what: &'static str,
        /// Best value reached.
        value: f64,
        /// Its error estimate (same units as `value`).
        error: f64,
        /// Requested tolerance.
        tolerance: f64,
        /// Terms summed.
        terms: u64,
    },
    /// A slice has the wrong length for the grid.
    #[error("{name} has {found} values, the grid needs {expected}")]
    LengthMismatch {
        /// Which argument.
        name: &'static str,
        /// Expected length.
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// A slice holds a NaN or an infinity.
    #[error("{name}[{index}] = {value} is not finite")]
    NonFinite {
        /// Which argument.
        name: &'static str,
        /// First offending index.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A dense matrix was requested for a grid too large to hold one sensibly.
    #[error("dense assembly of a {n} x {n} matrix refused: the limit is n <= {limit}; use the matrix-free operator")]
    TooLargeForDense {
        /// Number of cells.
        n: usize,
        /// The limit on the number of cells.
        limit: usize,
    },
    /// A parameter outside the values the model accepts (a term budget of zero, ...).
    #[error("{name} = {value} is invalid: {reason}")]
    InvalidParameter {
        /// Which parameter.
        name: &'static str,
        /// The value given.
        value: f64,
        /// Why it is refused.
        reason: &'static str,
    },
    /// The operating system refused the solver's threads.
    #[error("could not start a pool of {threads} solver threads: {reason}")]
    ThreadPool {
        /// Threads requested ([`crate::SolverOptions::parallelism`]).
        threads: usize,
        /// What the thread pool reported.
        reason: String,
    },
    /// A spring height is zero or negative.
    #[error("heights[{index}] = {value} m is invalid: spring heights must be > 0")]
    NonPositiveHeight {
        /// Cell index (paper order `iy * Nx + ix`).
        index: usize,
        /// The value given (m).
        value: f64,
    },
    /// A site index beyond the grid.
    #[error("site {index} does not exist: the interface has {sites} sites")]
    SiteOutOfRange {
        /// The index given.
        index: usize,
        /// Number of sites.
        sites: usize,
    },
    /// An input that must hold at least one item holds none (e.g. the target points of a
    /// fit).
    #[error("{what} is empty: {reason}")]
    EmptyInput {
        /// Which input.
        what: &'static str,
        /// Why it needs at least one item.
        reason: &'static str,
    },
    /// No site can carry the load (every site broken), or the load itself is zero.
    #[error("empty contact: {reason} ({available} sites can still carry force)")]
    EmptyContact {
        /// Sites neither broken nor excluded.
        available: usize,
        /// Why the contact is empty.
        reason: &'static str,
    },
    /// An iterative solver stopped before reaching its tolerance.
    #[error(
        "{what} did not converge: relative residual {residual:e} > tolerance {tolerance:e} \
         after {iterations} iterations"
    )]
    SolverNotConverged {
        /// Which solver.
        what: &'static str,
        /// Iterations spent.
        iterations: usize,
        /// Best relative residual reached.
        residual: f64,
        /// Requested tolerance.
        tolerance: f64,
    },
    /// A factorisation met a non-positive pivot (the system lost definiteness to rounding).
    #[error("LDLT factorisation of the {n} x {n} attached-set matrix failed: {reason}")]
    Factorization {
        /// Size of the matrix.
        n: usize,
        /// What faer reported.
        reason: String,
    },
    /// A file could not be read or written.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: String,
        /// What the operating system reported.
        reason: String,
    },
    /// A heights file has a line that is not a finite, positive height in metres.
    #[error("{path}, line {line}: {reason}")]
    HeightsFile {
        /// The file.
        path: String,
        /// Line number (1-based).
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A scene file is not valid JSON or does not follow `docs/scene-format.md`.
    #[error("scene file: {reason}")]
    SceneFile {
        /// What the parser reported (with line and column).
        reason: String,
    },
    /// A checkpoint does not fit the scene it is resumed on, or is inconsistent.
    #[error("checkpoint refused: {reason}")]
    InvalidCheckpoint {
        /// Why.
        reason: String,
    },
    /// A matrix has the wrong shape for the grid: a field on the grid is an `Ny x Nx`
    /// matrix (row `iy`, column `ix`); a transposed one is refused, not read sideways.
    #[error(
        "{name} is a {rows} x {columns} matrix, the grid needs {expected_rows} x \
         {expected_columns} (Ny rows by Nx columns: row iy, column ix)"
    )]
    ShapeMismatch {
        /// Which argument.
        name: &'static str,
        /// Rows given.
        rows: usize,
        /// Columns given.
        columns: usize,
        /// Rows needed (`Ny`).
        expected_rows: usize,
        /// Columns needed (`Nx`).
        expected_columns: usize,
    },
    /// A checkpoint belongs to another scene: the scene it is resumed on differs from the
    /// checkpoint's, or the scene stored in the checkpoint was edited after it was taken
    /// (its digest no longer matches).
    #[error("checkpoint refused: the scenes differ at `{key}`: {reason}")]
    CheckpointSceneMismatch {
        /// The first differing option, by its scene-file key path (`block.lx`,
        /// `normal_load`, `drive.lateral.height`, ...).
        key: String,
        /// Which scenes differ, and the values when they are known.
        reason: String,
    },
    /// A checkpoint file holds no valid checkpoint (a read or write failure of the file
    /// itself is [`Error::Io`]).
    #[error("{path}: not a checkpoint: {reason}")]
    CheckpointFile {
        /// The file.
        path: String,
        /// What the parser reported.
        reason: String,
    },
}

/// Checks that `value` is a finite, positive length.
pub(crate) fn check_length(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidLength { name, value })
    }
}

/// Checks that a tolerance is finite and positive.
pub(crate) fn check_tolerance(value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidTolerance { value })
    }
}

/// Checks a slice length and that every value is finite.
pub(crate) fn check_slice(name: &'static str, values: &[f64], expected: usize) -> Result<()> {
    if values.len() != expected {
        return Err(Error::LengthMismatch {
            name,
            expected,
            found: values.len(),
        });
    }
    if let Some((index, &value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(Error::NonFinite { name, index, value });
    }
    Ok(())
}
