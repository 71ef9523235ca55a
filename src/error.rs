//! Typed errors: every reachable failure says what was wrong and why.

mod bounded;

pub(crate) use crate::format::{format_bytes, format_seconds};
#[cfg(test)]
use bounded::bounded;
pub(crate) use bounded::Bounded;
use std::path::PathBuf;
use thiserror::Error;

/// The cause of an [`enum@Error`] that wraps another library's error (a JSON parser's, a
/// factorisation's, the thread pool's), type-erased so that no dependency's type enters
/// the crate's API. [`std::error::Error::source`] returns the cause itself, so
/// `downcast_ref` reaches its concrete type.
pub(crate) type Cause = Box<dyn std::error::Error + Send + Sync + 'static>;

/// Convenient result alias of the crate. The error type defaults to [`enum@Error`] and can be
/// named, so `use precursors::*` leaves `Result<T, E>` usable for other errors.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in the core library: geometry, Green function, interface,
/// solver, scene, driver, checkpoints, and a run's tables, directory and lock (module
/// `output`). A sweep's own failures are `sweep::SweepError` (feature `serde`), a
/// figure's `plot::PlotError` (feature `plot`); each nests this type for the
/// failures of the runs, scenes and tables under it. A variant that only a feature's code
/// can return exists only with that feature (`ShapeMismatch`: `nalgebra`).
///
/// Every variant carries the offending values so a caller can report them or recover.
/// Variants that wrap another error (I/O, JSON, factorisation, thread pool) return it from
/// [`std::error::Error::source`] and leave its message out of their own `Display` (the
/// file and the operation), so a report of the cause chain (`anyhow`'s `{:#}`, the
/// program's `caused by:` lines) prints each cause once.
///
/// `Error` is neither `Clone` nor `PartialEq`, as the `std::io::Error` it keeps: match on
/// the variant, e.g. `matches!(e, Error::GridDoesNotDivide { axis: "x", .. })`.
///
/// ```
/// use precursors::{Block, Error, Grid};
/// // A negative block length (m) is refused with its name and value.
/// let e = Block::new(0.14, -0.007, 0.075).unwrap_err();
/// match &e {
///     Error::InvalidLength { name, value } => assert_eq!((*name, *value), ("Ly", -0.007)),
///     other => panic!("another error: {other}"),
/// }
/// assert!(e.to_string().starts_with("Ly = -0.007 m is invalid"));
/// // 4 mm cells do not divide Lx = 140 mm into whole cells: 35 do, 140 / 3 does not.
/// let block = Block::new(0.14, 0.007, 0.075)?;
/// assert!(Grid::from_cell_size(block, 4e-3, 1e-3).is_ok());
/// let e = Grid::from_cell_size(block, 3e-3, 1e-3).unwrap_err();
/// let Error::GridDoesNotDivide { axis, ratio, .. } = &e else { panic!("another error: {e}") };
/// assert!(*axis == "x" && (ratio - 140.0 / 3.0).abs() < 1e-9);  // Lx / Δx = 46.67 cells
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// A length (block size, cell size, rod half-width, ...) is not finite and positive:
    /// `Block::new`, `Grid::from_cell_size`, `RodLoad::new`, a scene's block or cells.
    #[error("{name} = {} m is invalid: it must be finite and > 0", Num(*value))]
    InvalidLength {
        /// Which length.
        name: &'static str,
        /// The value given (m).
        value: f64,
    },
    /// A cell count is zero: `Grid::new(block, 0, ny)`, a scene's `cells`.
    #[error("the grid needs at least one cell along {axis}, got 0")]
    EmptyGrid {
        /// `"x"` or `"y"`.
        axis: &'static str,
    },
    /// The requested cell size does not divide the face into a whole number of cells:
    /// `Grid::from_cell_size`, a scene's `cells` of kind `size`.
    #[error(
        "cell size {} m does not divide L{axis} = {} m (ratio {}, not an integer)",
        Num(*cell),
        Num(*length),
        Num(*ratio)
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
    /// A coordinate lies outside the block: a point of `GreenFunction`, a load's or a plane
    /// transfer's height `z`, a probe's plane or point.
    #[error("{name} = {} m lies outside the block, which spans [0, {}] m", Num(*value), Num(*max))]
    OutsideBlock {
        /// Which coordinate (`"x"`, `"xi"`, `"z"`, ...).
        name: &'static str,
        /// The value given (m).
        value: f64,
        /// The block length along that axis (m).
        max: f64,
    },
    /// The rod band `[h - Δh, h + Δh]` is not inside the trailing face `[0, Lz]`:
    /// `RodLoad::new`, a scene's rod drive (`SceneBuilder::build`).
    #[error(
        "rod band [h - dh, h + dh] = [{}, {}] m is not inside the trailing face [0, {}] m",
        Num(*low),
        Num(*high),
        Num(*lz)
    )]
    RodBandOutsideFace {
        /// `h - Δh` (m).
        low: f64,
        /// `h + Δh` (m).
        high: f64,
        /// Block height (m).
        lz: f64,
    },
    /// A tolerance is not finite and positive: of a series or plan (`SeriesOptions`,
    /// `InfluencePlanBuilder`, `Planner`, a probe), of the solver (`SolverOptions`), of a
    /// fit (`FitOptions`), or a scene's `plan_tolerance` / `solver.tolerance`.
    #[error("tolerance {} is invalid: it must be finite and > 0", Num(*value))]
    InvalidTolerance {
        /// The value given.
        value: f64,
    },
    /// The target point coincides with the source point, where the Green function is
    /// infinite: `GreenFunction::value` and its kin at `target == source`.
    #[error(
        "target and source coincide at ({}, {}, {}) m: the Green function is singular there",
        Num(*x),
        Num(*y),
        Num(*z)
    )]
    SingularPoint {
        /// x (m).
        x: f64,
        /// y (m).
        y: f64,
        /// z (m).
        z: f64,
    },
    /// A series of the Green function reached its term budget before its truncation
    /// tolerance (the plan's `plan_tolerance`, a point evaluation's or a probe's tolerance):
    /// a point value of `G` or `∂G/∂z` ([`crate::green::GreenFunction`]), a load's series
    /// ([`crate::green::RodLoad`]), an eigenvalue of the influence operator
    /// ([`crate::green::InfluencePlanBuilder::build`], [`crate::SceneBuilder::build`]), an
    /// alias sum of a plane transfer or a point probe (a plane or point too close to
    /// `z = 0`). Not a linear solve: that is [`Error::SolverNotConverged`].
    #[error(
        "{what} did not reach tolerance {tolerance:e}: best value {value:e} with error estimate \
         {error:e} after {terms} terms (raise the budget or the tolerance)"
    )]
    SeriesNotConverged {
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
    /// A slice has the wrong length for the grid: tractions, heights, states or loads given
    /// to a plan, interface, solver or driver of another grid.
    #[error("{name} has {found} values, the grid needs {expected}")]
    LengthMismatch {
        /// Which argument.
        name: &'static str,
        /// Expected length.
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// A slice holds a NaN or an infinity: the same inputs as [`Error::LengthMismatch`],
    /// or a tangential stiffness that overflows in a solve.
    #[error("{name}[{index}] = {value} is not finite")]
    NonFinite {
        /// Which argument.
        name: &'static str,
        /// First offending index.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A dense matrix was requested for a grid too large to hold one sensibly:
    /// `InfluencePlan::dense`, `Backend::Dense` above its cell limit.
    #[error("dense assembly of a {n} x {n} matrix refused: the limit is n <= {limit}; use the matrix-free operator")]
    TooLargeForDense {
        /// Number of cells.
        n: usize,
        /// The limit on the number of cells.
        limit: usize,
    },
    /// A real-valued parameter outside the values the model accepts (a normal load of
    /// zero, a negative stiffness, ...). Integer parameters are reported by
    /// [`Error::InvalidCount`].
    #[error("{name} = {} is invalid: {reason}", Num(*value))]
    InvalidParameter {
        /// Which parameter.
        name: &'static str,
        /// The value given.
        value: f64,
        /// Why it is refused.
        reason: &'static str,
    },
    /// An integer parameter (a count of cells, threads, terms, ...) outside the values the
    /// model accepts.
    #[error("{name} = {value} is invalid: {reason}")]
    InvalidCount {
        /// Which parameter.
        name: &'static str,
        /// The value given.
        value: u64,
        /// Why it is refused.
        reason: &'static str,
    },
    /// A choice among named options that does not apply here: a summation axis of
    /// `SeriesOptions` the evaluation cannot use.
    #[error("{name} = {value} is invalid: {reason}")]
    InvalidChoice {
        /// Which parameter.
        name: &'static str,
        /// The option given.
        value: &'static str,
        /// Why it is refused and what to choose instead.
        reason: &'static str,
    },
    /// The grid has more cells than the limit a plan or scene is built with
    /// ([`crate::green::InfluencePlanBuilder::max_cells`], [`crate::SceneBuilder::max_cells`],
    /// default [`crate::green::DEFAULT_MAX_CELLS`]): refused before anything is allocated,
    /// with the estimated cost ([`crate::GridCost`], docs/performance.md). A scene whose
    /// block length of 1 m or more may be millimetres meant as metres reports it as the
    /// source of [`Error::LengthInMillimetres`].
    #[error(
        "a grid of {nx} x {ny} = {cells} cells exceeds the limit of {limit} cells: it would \
         need about {memory} of memory, about {plan} to plan and about {solve} per cold \
         equilibrium (estimates, docs/performance.md); raise the limit with max_cells(n) \
         (\"max_cells\" in a scene file) if that is intended",
        memory = format_bytes(*memory_bytes),
        plan = format_seconds(*plan_seconds),
        solve = format_seconds(*solve_seconds)
    )]
    GridTooLarge {
        /// Cells along x.
        nx: usize,
        /// Cells along y.
        ny: usize,
        /// `Nx·Ny` (exact, even when it overflows `usize`).
        cells: u128,
        /// The limit on the number of cells.
        limit: usize,
        /// Estimated peak memory of a scene and its driver (bytes).
        memory_bytes: f64,
        /// Estimated time to plan the operator (s, one thread, release build).
        plan_seconds: f64,
        /// Estimated time of one cold normal and tangential equilibrium (s, one thread,
        /// release build).
        solve_seconds: f64,
    },
    /// A scene's grid above the cell limit ([`Error::GridTooLarge`], the source) whose cells
    /// are given by size and whose block has a length of 1 m or more
    /// ([`crate::SceneBuilder::grid`], `check`, `build`): most likely lengths typed in
    /// millimetres (`"lx": 140` for 140 mm makes 140 000 cells of 1 mm along x).
    #[error(
        "{key} = {} m makes the grid too large: lengths are in metres: did you mean {} m?",
        Num(*value),
        Num(*value / 1e3)
    )]
    LengthInMillimetres {
        /// The scene-file key of the first such length (`block.lx`, `block.ly`,
        /// `block.lz`).
        key: &'static str,
        /// The length given (m).
        value: f64,
        /// The [`Error::GridTooLarge`] of the grid, with its size and cost.
        #[source]
        source: Box<Error>,
    },
    /// The tables a run would record beside its three (`fields.csv`, `profiles.csv`) are
    /// estimated above the run's limit ([`crate::RunOptions::max_output_bytes`], scene-file
    /// key `max_output_bytes`, default 10 GB; [`crate::RunOptions::cost`]): refused before
    /// anything is planned or written.
    #[error(
        "the recorded tables would take up to {} (fields.csv {}, profiles.csv {}; every \
         site breaks at most once, so a run has at most N + 1 stable states), above the \
         limit of {}: record less (the keys fields.every, fields.planes, profiles.loads, \
         profiles.planes) or raise max_output_bytes (RunOptions::max_output_bytes) if that \
         is intended",
        format_bytes(fields_bytes + profiles_bytes),
        format_bytes(*fields_bytes),
        format_bytes(*profiles_bytes),
        format_bytes(*limit)
    )]
    OutputTooLarge {
        /// The most bytes of `fields.csv` (B).
        fields_bytes: f64,
        /// The most bytes of `profiles.csv` (B).
        profiles_bytes: f64,
        /// The limit (B).
        limit: f64,
    },
    /// A scene with a block length of 1 m or more under a mean normal pressure
    /// `F_N/(Lx Ly)` below `1e-6 E` ([`crate::SceneBuilder::check`], `build`): most likely
    /// lengths typed in millimetres (`"lx": 140` for 140 mm makes a 140 m block, and the
    /// calibration's 3.5 kN a pressure of a few pascals, with almost no site in contact).
    /// A block meant so confirms it with [`crate::SceneBuilder::confirm_metres`] (scene-file
    /// key `"confirm_metres": true`).
    #[error(
        "the block is {} x {} x {} m ({} x {} x {} mm) under a mean normal pressure of {} Pa, \
         {} of Young's modulus: lengths are in metres, did you mean {} x {} x {} mm? If the \
         block is meant, confirm it with \"confirm_metres\": true (SceneBuilder::confirm_metres)",
        Num(block.0), Num(block.1), Num(block.2),
        Num(block.0 * 1e3), Num(block.1 * 1e3), Num(block.2 * 1e3),
        Num(*pressure), Num(*pressure / *young_modulus),
        Num(block.0), Num(block.1), Num(block.2)
    )]
    LikelyMillimetres {
        /// The block's lengths `(Lx, Ly, Lz)` (m).
        block: (f64, f64, f64),
        /// The mean normal pressure `F_N/(Lx Ly)` (Pa).
        pressure: f64,
        /// Young's modulus `E` (Pa).
        young_modulus: f64,
    },
    /// An explicit thread count above one with the dense backend, which runs on one
    /// thread (its factor solve needs the whole attached set): `SolverOptions`, a scene's
    /// `solver` (`SceneBuilder::build`), `Driver::set_parallelism`,
    /// `EquilibriumSolver::set_parallelism`.
    // Spelled as the scene file spells them (`solver.backend`, `solver.threads`): most
    // users meet this message from a scene file.
    #[error(
        "backend \"dense\" runs on one thread, but threads {threads} was asked for \
         (solver.threads 0 and \"all\" ask for one per core): use \
         backend \"spectral\" (or \"auto\" above {auto_limit} cells) to solve on several \
         threads, or threads 1 with backend \"dense\" (scene file: solver.backend, \
         solver.threads)"
    )]
    DenseThreads {
        /// Threads asked for.
        threads: usize,
        /// Cells above which `Backend::Auto` picks the spectral backend
        /// ([`crate::solver::AUTO_DENSE_LIMIT`]).
        auto_limit: usize,
    },
    /// The operating system refused the solver's threads: the first solve with
    /// `Parallelism::Threads(n)` (`Driver::step`, `EquilibriumSolver`).
    #[error("could not start a pool of {threads} solver threads")]
    ThreadPool {
        /// Threads requested ([`crate::solver::SolverOptions::parallelism`]).
        threads: usize,
        /// What the thread pool reported.
        #[source]
        source: Cause,
    },
    /// A spring height is zero or negative: heights given as values (`Interface`,
    /// `HeightSource::Values`, a scene's `heights`, `Heights::from_dmatrix`).
    #[error("heights[{index}] = {} m is invalid: spring heights must be > 0", Num(*value))]
    NonPositiveHeight {
        /// Cell index (paper order `iy * Nx + ix`).
        index: usize,
        /// The value given (m).
        value: f64,
    },
    /// A broken site was given another state (`Interface::set_states`): broken sites stay
    /// broken until the interface is healed.
    #[error(
        "site {index} is broken and cannot be set to another state (heal the interface first)"
    )]
    BrokenSite {
        /// Cell index (paper order `iy * Nx + ix`).
        index: usize,
    },
    /// A driver whose step failed was stepped again (`Driver::step` after an error): the
    /// run cannot go on; `reason` is the first error's message. Before 1.1 such a step
    /// returned `Ok(None)`, as after global slip.
    #[error("the driver failed earlier and cannot go on: {}", Bounded(reason))]
    DriverFailed {
        /// The message of the error that failed the driver.
        reason: String,
    },
    /// A driver was asked for a field of its equilibrium before it solved one
    /// (`Driver::normal_traction`, `shear_traction`, ... before the first `step`).
    #[error("the driver has not solved {what} yet: call step() first")]
    NotSolved {
        /// Which equilibrium (`"the normal equilibrium"`, `"the tangential equilibrium"`).
        what: &'static str,
    },
    /// Stresses were asked of a driver whose scene has no stress probes (`Driver::stresses`).
    #[error(
        "no stress probes: the scene was built without them (add them with SceneBuilder::probes)"
    )]
    NoProbes,
    /// A site index beyond the grid: `Interface::break_site`.
    #[error("site {index} does not exist: the interface has {sites} sites")]
    SiteOutOfRange {
        /// The index given.
        index: usize,
        /// Number of sites.
        sites: usize,
    },
    /// An input that must hold at least one item holds none: the target points of
    /// `fit_tangential_stiffness`, an interface of no sites.
    #[error("{what} is empty: {reason}")]
    EmptyInput {
        /// Which input.
        what: &'static str,
        /// Why it needs at least one item.
        reason: &'static str,
    },
    /// No site can carry the load: every site broken, or none attached, in a solve
    /// (`EquilibriumSolver::solve_normal`, `solve_tangential`, `Driver::step`). A physical
    /// state of the interface, not a misuse (see [`Error::NotSolved`]).
    #[error("empty contact: {reason} ({available} sites can still carry force)")]
    EmptyContact {
        /// Sites neither broken nor excluded.
        available: usize,
        /// Why the contact is empty.
        reason: &'static str,
    },
    /// An equilibrium solve stopped before reaching the solver's tolerance
    /// ([`crate::solver::SolverOptions`]): the projected CG of a normal or tangential set solve past
    /// its iteration limit, or the active set of the normal equilibrium past
    /// `max_active_set_iterations` (residual `inf`). Returned by
    /// [`crate::solver::EquilibriumSolver::solve_normal`], [`crate::solver::EquilibriumSolver::solve_tangential`],
    /// [`crate::Driver::step`] and the calibration's area. Not a series of the Green function:
    /// that is [`Error::SeriesNotConverged`].
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
    /// [`crate::calibration::fit_normal_stiffness`] spent `max_evaluations` scenes
    /// ([`crate::calibration::FitOptions`]) before its bracket on `ln c_z` narrowed to the
    /// fit's tolerance.
    #[error(
        "c_z fit (regula falsi in ln c_z) did not reach tolerance {tolerance:e}: best value \
         {value:e} N/m² with bracket width {width:e} in ln c_z after {evaluations} evaluations \
         (raise max_evaluations or the tolerance)"
    )]
    FitNotConverged {
        /// The best `c_z` (N/m²).
        value: f64,
        /// The width of the bracket on `ln c_z` left (dimensionless).
        width: f64,
        /// The fit's tolerance on `ln c_z`.
        tolerance: f64,
        /// Scenes evaluated.
        evaluations: usize,
    },
    /// A factorisation met a non-positive pivot (the system lost definiteness to rounding):
    /// the dense backend's LDLᵀ in a solve (`Driver::step`, `EquilibriumSolver`).
    #[error(
        "LDLT factorisation of the {n} x {n} attached-set matrix failed: {}",
        Bounded(reason)
    )]
    Factorization {
        /// Size of the matrix.
        n: usize,
        /// What went wrong, in words (the pivot and its value).
        reason: String,
        /// Another library's error behind it, when it has a message a user can read
        /// (`None` for faer's pivot errors: their text is a Rust debug dump, and `reason`
        /// says the same in words).
        #[source]
        source: Option<Cause>,
    },
    /// A file could not be read or written: the operation, the file and the operating
    /// system's error (its [`std::io::ErrorKind`] through `source.kind()`), which only
    /// `source()` gives: the message is the operation and the file.
    #[error("{operation} {}", path.display())]
    Io {
        /// What was being done (`"reading scene file"`, `"reading heights file"`, ...).
        operation: &'static str,
        /// The file.
        path: PathBuf,
        /// What the operating system reported.
        #[source]
        source: std::io::Error,
    },
    /// A heights file has a line that is not a finite, positive height in metres
    /// (`HeightSource::from_file`, a scene file's `heights.file`).
    #[error("{path}, line {line}: {}", Bounded(reason))]
    HeightsFile {
        /// The file.
        path: String,
        /// Line number (1-based).
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A map's file has a line that is not a value of its key in range
    /// (`SiteMap::from_file`, a scene file's `maps.KEY` of kind `file`).
    #[error("{key}: {}, line {line}: {}", path.display(), Bounded(reason))]
    MapFile {
        /// The scene-file key of the map (`maps.friction_coefficient`, `maps.c_x`,
        /// `maps.c_z`; `maps` for [`crate::SiteMap::from_file`]).
        key: &'static str,
        /// The file.
        path: PathBuf,
        /// Line number (1-based; 0 for the file as a whole).
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A site's value of a map is not finite or outside its key's range (a scene's
    /// `maps`, `Interface::with_friction_map`, `with_c_x_map`, `with_c_z_map`).
    #[error("{key}[{index}] = {} is out of range: the valid range is {range}", Num(*value))]
    MapValue {
        /// The scene-file key of the map (`maps.friction_coefficient`, `maps.c_x`,
        /// `maps.c_z`).
        key: &'static str,
        /// Cell index (paper order `iy * Nx + ix`).
        index: usize,
        /// The value given or generated.
        value: f64,
        /// The valid range, with its unit.
        range: String,
    },
    /// A scene file is not valid JSON, not UTF-8 text, or does not follow
    /// `docs/scene-format.md` (feature `serde`: `SceneBuilder::from_json_file`,
    /// `from_json_str`).
    #[error(
        "invalid scene file{}",
        path.as_ref().map(|p| format!(" {}", p.display())).unwrap_or_default()
    )]
    SceneFile {
        /// The file (`None` for JSON text given directly).
        path: Option<PathBuf>,
        /// Line of the error (1-based; 0 when the parser gave none).
        line: usize,
        /// Column of the error (1-based; 0 when the parser gave none).
        column: usize,
        /// What the parser reported (its message names the line and column); `source()`
        /// returns it.
        #[source]
        source: Cause,
    },
    /// A checkpoint does not fit the scene it is resumed on, or is inconsistent
    /// (`Scene::resume`, `RunTables::resume`).
    #[error("checkpoint refused: {}", Bounded(reason))]
    InvalidCheckpoint {
        /// Why.
        reason: String,
    },
    #[cfg(feature = "nalgebra")]
    /// (Feature `nalgebra`.) A matrix has the wrong shape for the grid
    /// ([`crate::Heights::from_dmatrix`]): a field on the grid is an `Ny x Nx` matrix (row
    /// `iy`, column `ix`); a transposed one is refused, not read sideways.
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
    /// A checkpoint belongs to another scene (`Scene::resume`, `RunTables::resume`,
    /// `Checkpoint::read_from`): the scene it is resumed on differs from the
    /// checkpoint's, or the scene stored in the checkpoint was edited after it was taken
    /// (its digest no longer matches).
    #[error(
        "checkpoint refused: the scenes differ at `{key}`: {}",
        Bounded(reason)
    )]
    CheckpointSceneMismatch {
        /// The first differing option, by its scene-file key path (`block.lx`,
        /// `normal_load`, `drive.lateral.height`, ...).
        key: String,
        /// Which scenes differ, and the values when they are known.
        reason: String,
    },
    /// A checkpoint file holds no valid checkpoint (feature `serde`: `Checkpoint::read_from`,
    /// `Checkpoint::from_json_str`; a read or write failure of the file itself is
    /// [`Error::Io`]).
    #[error("{path}: not a checkpoint: {}", Bounded(reason))]
    CheckpointFile {
        /// The file.
        path: String,
        /// What the parser reported.
        reason: String,
    },
    /// A path named as an input or an output is not a regular file: a FIFO, a device, a
    /// socket, a directory or a symbolic link. Refused before anything is read or
    /// written: a FIFO would block, a device would be read without end or replaced by a
    /// file, and a link is never followed (one in a run directory, such as its lock file,
    /// would have the program write, empty or read a file elsewhere; as root, any file),
    /// nor replaced.
    #[error("{operation} {}: it is {kind}, not a regular file", path.display())]
    NotARegularFile {
        /// What was being done (`"reading scene file"`, `"writing checkpoint"`, ...).
        operation: &'static str,
        /// The path.
        path: PathBuf,
        /// What it is (`"a FIFO (named pipe)"`, `"a character device"`, `"a directory"`, ...).
        kind: &'static str,
    },
    /// An output the caller names (a checkpoint) would take the name of a file its run
    /// directory holds: a table, `NAME.partial`, the scene record, the lock, a sweep's
    /// markers, a figure or a movie (`RunTables::run_to_slip`), or the file a command
    /// reads (the program's `run`: the scene file). Refused before anything is written.
    #[error("{what} {}: {}", path.display(), Bounded(reason))]
    OutputCollision {
        /// The output (`"checkpoint"`).
        what: &'static str,
        /// Its path.
        path: PathBuf,
        /// Which file it would replace, and what to do.
        reason: String,
    },
    /// A run's CSV table (`events.csv`, `curve.csv`, `contact_map.csv`) cannot be
    /// continued: a damaged row before the last one, another header, an index that is not
    /// a whole number, or rows that do not reach the
    /// checkpoint's event or do not agree with the other tables
    /// ([`crate::output::RunTables::resume`]).
    #[error(
        "table{}: {}",
        path.as_ref().map(|p| format!(" {}", p.display())).unwrap_or_default(),
        Bounded(reason)
    )]
    CorruptTable {
        /// The file (`None` for text given directly).
        path: Option<PathBuf>,
        /// What is wrong, with the line number.
        reason: String,
    },
    /// Another process holds the directory's lock (`RunTables::create`, `RunTables::resume`,
    /// a sweep's `execute` waiting 30 s for `sweep.json`): it is writing a run there (`run`,
    /// `resume`, a sweep's run), checking a sweep's `sweep.json`, or reading the directory
    /// (`plot::draw_with_options`, `plot::Movie`, `sweep::statistics` take the lock
    /// shared, and are refused so while a writer holds it). The lock is the operating
    /// system's and ends with that process, also when it is killed.
    #[error(
        "{} is in use by another process ({holder}): wait until it ends or choose another \
         directory (the lock ends with that process, also if it is killed)",
        path.display()
    )]
    DirectoryLocked {
        /// The directory.
        path: PathBuf,
        /// Who holds the lock, as it wrote it: pid, host, start time (UTC), command.
        holder: String,
    },
    /// A run directory cannot be continued or finished (`RunTables::resume`,
    /// `RunTables::finish`): it has no record of its scene
    /// (`scene.json`), or a checkpoint taken inside an avalanche, or the run did not reach
    /// global slip.
    #[error("run directory {}: {}", path.display(), Bounded(reason))]
    RunDirectory {
        /// The directory, or its file at fault.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A run's table that `RunTables::resume`, `sweep::merge` (feature `serde`), the
    /// figures or the movies of a directory (feature `plot`) read holds, where a number belongs, a value that is not a
    /// finite number (`NaN`, `inf`, an empty cell): a damaged or edited table, which
    /// would turn every statistic and figure made from it into NaN.
    #[error(
        "table {}, line {line}, column {column}: {} is not a finite number",
        path.display(),
        Bounded(&format!("{value:?}"))
    )]
    NonFiniteCell {
        /// The file.
        path: PathBuf,
        /// Line number (1-based; the header is line 1).
        line: usize,
        /// The column's name in the header.
        column: String,
        /// The cell's text.
        value: String,
    },
    /// A scene value that is finite and of the right sign but outside the range the
    /// computation can honour (`docs/scene-format.md`, "Valid ranges"): named by its
    /// scene-file key, with the range.
    #[error("{key} = {} is out of range: {reason}; the valid range is {range}", Num(*value))]
    OutOfRange {
        /// The scene-file key (`block.ly`, `solver.tolerance`, `drive.stiffness`, ...).
        key: &'static str,
        /// The value given (in the key's unit).
        value: f64,
        /// The valid range, with its unit (it may depend on other keys of the scene).
        range: String,
        /// Why values outside it are refused.
        reason: &'static str,
    },
    /// A random surface whose synthesis would exceed the crate's limits
    /// (`Heights::random_surface`; a scene's heights of kind `gaussian_surface` or
    /// `self_affine_surface`, refused by `SceneBuilder::check`/`build`): too many Fourier
    /// modes (a correlation length or short cut-off tiny against the block), cells so large
    /// against the shortest wavelength that their averages need more Gauss-Legendre points
    /// than the limit, or too much work in all; or a band of the spectrum that holds no
    /// mode at all.
    #[error("the random surface needs {} {what}, the limit is {}: {hint}", Num(*needed), Num(*limit))]
    SurfaceTooLarge {
        /// What is counted.
        what: &'static str,
        /// How many the surface needs.
        needed: f64,
        /// The limit.
        limit: f64,
        /// What to change.
        hint: &'static str,
    },
    /// The memory a scene or sweep would need exceeds what the machine has available
    /// (Linux: `MemAvailable` of `/proc/meminfo`), refused before anything is allocated:
    /// `SceneBuilder::check`/`build`, a file too large to read (scene, checkpoint, sweep,
    /// table), a sweep's list of runs.
    #[error(
        "{what} would need about {needed} of memory, but only {available} is available: {hint}",
        needed = format_bytes(*needed_bytes),
        available = format_bytes(*available_bytes)
    )]
    OutOfMemory {
        /// What would be allocated.
        what: String,
        /// Estimated bytes needed.
        needed_bytes: f64,
        /// Bytes available.
        available_bytes: f64,
        /// What to change.
        hint: &'static str,
    },
    /// The CUDA backend ([`crate::solver::Backend::Cuda`]) cannot run here: this build has
    /// no feature `cuda`, or no NVIDIA driver or GPU answers, or a library it needs
    /// (`libcuda`, `libcufft`, `libnvrtc`) is missing or too old, or its kernels do not
    /// compile for the GPU (`EquilibriumSolverBuilder::build`, `Scene::driver`,
    /// `solver::cuda_device`). The reason names what was searched or what failed, the hint
    /// what to install or set (docs/gpu.md).
    #[error("the CUDA backend is unavailable: {}; {hint}", Bounded(reason))]
    CudaUnavailable {
        /// What is missing or failed (the libraries searched, the driver's answer).
        reason: String,
        /// What to install, build or set.
        hint: String,
    },
    /// The device memory a CUDA solver would need exceeds what its GPU has free, refused
    /// before anything is allocated (`EquilibriumSolverBuilder::build` with
    /// [`crate::solver::Backend::Cuda`]).
    #[cfg(feature = "cuda")]
    #[error(
        "the CUDA backend would need about {needed} on {device}, which has {free} free: use \
         a smaller grid, a GPU with more memory, or backend \"spectral\"",
        needed = format_bytes(*needed_bytes),
        free = format_bytes(*free_bytes)
    )]
    DeviceOutOfMemory {
        /// The GPU (its name and ordinal).
        device: String,
        /// Estimated bytes needed.
        needed_bytes: f64,
        /// Bytes free on the device.
        free_bytes: f64,
    },
    /// A size the CUDA backend's kernels or launches hold in a 32-bit integer (a grid's
    /// cells, a set's sites, a launch's blocks) exceeds it: refused before the launch
    /// rather than wrapped (`EquilibriumSolverBuilder::build` with
    /// [`crate::solver::Backend::Cuda`], a solve).
    #[cfg(feature = "cuda")]
    #[error(
        "the CUDA backend cannot take {what} = {value}: its kernels hold it in a 32-bit \
         integer (at most {limit}); use backend \"spectral\""
    )]
    DeviceLimit {
        /// Which size.
        what: &'static str,
        /// Its value.
        value: u64,
        /// The largest value accepted.
        limit: u64,
    },
    /// A CUDA call failed during a solve (a launch, a copy, an FFT): the device, its
    /// driver or its memory failed after the backend was set up. The solver's state is
    /// the one before the failing solve.
    #[cfg(feature = "cuda")]
    #[error("CUDA call {call} failed: {}", Bounded(message))]
    Cuda {
        /// The call and the step it served (`cuMemcpyDtoH (reduction)`, `cufftExecD2Z
        /// (rows)`, a kernel's name).
        call: &'static str,
        /// What the driver or library reported.
        message: String,
    },
    /// A statistic asked of fewer samples than it needs: a power-law fit
    /// ([`crate::statistics::fit_power_law`]) of fewer than its options' `min_tail` samples
    /// (after the non-positive ones, which a power law cannot hold, are counted out).
    #[error("{what}: {count} samples, at least {needed} are needed")]
    TooFewSamples {
        /// Which statistic, of what.
        what: &'static str,
        /// The samples available.
        count: usize,
        /// The samples it needs.
        needed: usize,
    },
    /// A load `F/(μF_N)` beyond the friction limit at a stable state or at global slip:
    /// no stable state carries more than `μF_N` (every site holds `|φ_x| ≤ μ φ_z`), so
    /// the computation went wrong; refused rather than written to a table
    /// (`RunTables::record`).
    #[error(
        "F/(μF_N) = {} exceeds the friction limit {limit}: no stable state carries more than \
         μF_N, so the result is wrong (a solver tolerance too loose, or a degenerate scene); \
         nothing beyond it was written",
        Num(*ratio)
    )]
    LoadBeyondFriction {
        /// The load ratio reached (NaN or infinite when the computation overflowed).
        ratio: f64,
        /// The largest ratio accepted.
        limit: f64,
    },
    /// A custom contact rule (`ContactRule::Custom`, a downstream crate's `ContactLaw`)
    /// where only a built-in rule goes: what records a scene by its scene-file keys (a
    /// scene's JSON, a checkpoint written or resumed, a run directory's tables) cannot
    /// name Rust code. Run such a scene with `Scene::driver` alone.
    #[error(
        "{operation} refused: the contact rule \"{}\" is a custom one (Rust code), which \
         scene files, checkpoints and run directories cannot record; only the built-in rules \
         (paper, anchored, rejuvenation) can",
        Bounded(rule)
    )]
    CustomContactRule {
        /// The custom law's name (`ContactLaw::name`).
        rule: String,
        /// What was refused (`"writing a checkpoint"`, ...).
        operation: &'static str,
    },
    /// A custom contact law (`ContactLaw::threshold`) gave a site a Coulomb threshold that
    /// is negative or not finite; the driver fails at that step.
    #[error(
        "the contact rule \"{}\" gave site {site} the threshold {} Pa: a threshold is finite \
         and >= 0",
        Bounded(rule),
        Num(*value)
    )]
    InvalidThreshold {
        /// The custom law's name.
        rule: String,
        /// The site's index (cell order `iy·Nx + ix`).
        site: usize,
        /// The threshold given (Pa).
        value: f64,
    },
}

/// `error` and its causes ([`std::error::Error::source`]) joined by ": ", as `anyhow`
/// prints `{:#}`: for a message that keeps another error as text (a driver's failure, a
/// sweep's reason), since an error's own `Display` leaves its cause out.
pub(crate) struct Chain<'a>(pub(crate) &'a (dyn std::error::Error + 'static));

impl std::fmt::Display for Chain<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)?;
        let mut source = self.0.source();
        while let Some(cause) = source {
            write!(f, ": {cause}")?;
            source = cause.source();
        }
        Ok(())
    }
}

impl Error {
    /// An [`Error::Io`] for `operation` (`"reading scene file"`, ...) on `path`.
    pub(crate) fn io(
        operation: &'static str,
        path: impl Into<PathBuf>,
        source: std::io::Error,
    ) -> Self {
        Error::Io {
            operation,
            path: path.into(),
            source,
        }
    }
}

/// A number in a message: plain from `1e-4` to `1e6` in magnitude (and 0, NaN, ±inf),
/// scientific otherwise, so that `1e-300` does not print as 300 zeros.
pub(crate) struct Num(pub(crate) f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-4..1e6).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
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

#[cfg(test)]
mod tests {
    use super::bounded;

    #[test]
    fn long_quoted_values_are_cut_once_and_prose_is_kept() {
        let long = "y".repeat(1000);
        let cut = format!("{}... (1000 bytes)", "y".repeat(80));
        let text = format!("unknown field `{long}`, expected one of `lx`, `ly` at line 1");
        let once = bounded(&text).into_owned();
        assert_eq!(
            once,
            format!("unknown field `{cut}`, expected one of `lx`, `ly` at line 1")
        );
        assert_eq!(bounded(&once), once);
        // `{:?}` quoting: an escaped quote does not end the value.
        let text = format!(
            "invalid type: string {:?}, expected f64",
            format!("a\"{long}")
        );
        let once = bounded(&text).into_owned();
        assert!(once.ends_with("(1003 bytes)\", expected f64"), "{once}");
        // Short messages, quotes and all, are left alone.
        let short = "cell \"1e400\" of `curve.csv` is not finite";
        assert_eq!(bounded(short), short);
    }

    #[test]
    fn a_value_full_of_quotes_is_bounded_as_a_whole() {
        let text = format!(
            "unknown variant `{}`, expected `auto`",
            "`a".repeat(100_000)
        );
        let once = bounded(&text);
        assert!(once.len() < 200, "{} bytes", once.len());
        assert!(once.ends_with(" bytes)"), "{once}");
    }
}
