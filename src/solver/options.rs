//! What the solvers take and return: the backend, the options, the equilibria and the
//! report of a solve.

use super::parallel::Parallelism;
use crate::error::{check_tolerance, Error, Result};
use crate::interface::SiteState;

pub use crate::cost::AUTO_DENSE_LIMIT;

/// Which linear-algebra backend solves the equilibria.
///
/// ```
/// use precursors::solver::{Backend, SolverOptions, AUTO_DENSE_LIMIT};
/// use precursors::Scene;
/// let base = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 40 cells
///     .normal_load(40.0);               // F_N (N)
/// // Auto: dense up to AUTO_DENSE_LIMIT cells, spectral above.
/// assert!(40 <= AUTO_DENSE_LIMIT);
/// assert_eq!(base.clone().build()?.driver()?.backend(), Backend::Dense);
/// let spectral = SolverOptions::default().with_backend(Backend::Spectral)?;
/// let scene = base.solver_options(spectral).build()?;
/// assert_eq!(scene.driver()?.backend(), Backend::Spectral);
/// // As a scene file spells it (`solver.backend`).
/// assert_eq!(Backend::Spectral.to_string(), "spectral");
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum Backend {
    /// Dense up to [`AUTO_DENSE_LIMIT`] cells, spectral above.
    #[default]
    Auto,
    /// Assembled `C` (`N²` memory, up to [`crate::green::DENSE_LIMIT`] cells) and an LDLᵀ
    /// factor of the attached set, updated when sites leave or join.
    Dense,
    /// Matrix-free: the DCT operator in projected conjugate gradients, memory `O(N)`.
    Spectral,
    /// The spectral backend's rule on an NVIDIA GPU (feature `cuda`; docs/gpu.md): the
    /// DCT operator through cuFFT and the projected CG on the device, memory `O(N)` on the
    /// device. Its events are the spectral backend's within the solver tolerance, not
    /// bit for bit; a run repeats bit for bit on the same GPU. Without the feature, or
    /// without a usable GPU and its libraries, building a solver returns
    /// [`Error::CudaUnavailable`](crate::Error::CudaUnavailable).
    Cuda,
}

/// The backend as a scene file spells it (`solver.backend`): `auto`, `dense`, `spectral`,
/// `cuda`.
impl std::fmt::Display for Backend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Backend::Auto => "auto",
            Backend::Dense => "dense",
            Backend::Spectral => "spectral",
            Backend::Cuda => "cuda",
        })
    }
}

/// Options of the equilibrium solvers (scene-file object `solver`).
///
/// The fields are private: options are valid by construction (the defaults, then the
/// `with_` modifiers, each validating what it changes).
///
/// ```
/// use precursors::solver::{Backend, Parallelism, SolverOptions};
/// let options = SolverOptions::default()
///     .with_backend(Backend::Spectral)?
///     .with_tolerance(1e-12)?
///     .with_parallelism(Parallelism::Threads(2))?;
/// assert_eq!((options.backend(), options.tolerance()), (Backend::Spectral, 1e-12));
/// assert!(SolverOptions::default().with_tolerance(0.0).is_err());
/// assert!(SolverOptions::default().with_max_linear_iterations(0).is_err());
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "SolverOptionsFields", into = "SolverOptionsFields")
)]
#[non_exhaustive]
pub struct SolverOptions {
    backend: Backend,
    tolerance: f64,
    max_active_set_iterations: usize,
    max_linear_iterations: usize,
    parallelism: Parallelism,
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            backend: Backend::Auto,
            tolerance: 1e-13,
            max_active_set_iterations: 1000,
            max_linear_iterations: 20000,
            parallelism: Parallelism::Sequential,
        }
    }
}

impl SolverOptions {
    /// The backend (default [`Backend::Auto`]; scene-file key `solver.backend`).
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// The linear tolerance (dimensionless, default `1e-13`; scene-file key
    /// `solver.tolerance`): the normwise backward error
    /// `‖A f + U 1 - b‖∞ / (‖A‖ ‖f‖∞ + ‖b‖∞ + |U|)` at which a linear solve stops. (The
    /// influence operator's eigenvalues have their own tolerance, the scene's
    /// [`crate::SceneBuilder::plan_tolerance`].)
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// Active-set iterations allowed per normal equilibrium (default `1000`; scene-file key
    /// `solver.max_active_set_iterations`).
    pub fn max_active_set_iterations(&self) -> usize {
        self.max_active_set_iterations
    }

    /// Conjugate-gradient iterations allowed per linear solve (default `20000`; scene-file
    /// key `solver.max_linear_iterations`).
    pub fn max_linear_iterations(&self) -> usize {
        self.max_linear_iterations
    }

    /// The threads a solve may use (default [`Parallelism::Sequential`]; scene-file key
    /// `solver.threads`). The spectral backend shares each solve's work over the parts of
    /// the grid (fixed by the grid); the results are the same bit for bit for every choice
    /// (tested), only the wall time changes (docs/performance.md). The dense backend is
    /// one part: it runs on the calling thread. So an explicit [`Backend::Dense`] with
    /// [`Parallelism::Threads`]`(n > 1)` is refused ([`Error::DenseThreads`]: use the
    /// spectral backend for threads), while [`Backend::Auto`], which picks the dense
    /// backend up to [`AUTO_DENSE_LIMIT`] cells, accepts any parallelism and runs such
    /// small grids on the calling thread ([`crate::solver::EquilibriumSolver::threads`] and
    /// [`crate::Driver::threads`] tell the threads actually used). To run several scenes
    /// at once (seeds), give each [`Parallelism::Sequential`] and one scene per core.
    pub fn parallelism(&self) -> Parallelism {
        self.parallelism
    }

    /// The same options with another backend.
    ///
    /// # Errors
    /// [`Error::DenseThreads`] for [`Backend::Dense`] with a parallelism of more than one
    /// thread.
    pub fn with_backend(self, backend: Backend) -> Result<Self> {
        check_threads(backend, self.parallelism)?;
        Ok(Self { backend, ..self })
    }

    /// The same options with another linear tolerance (dimensionless, finite and `> 0`;
    /// see [`SolverOptions::tolerance`]).
    ///
    /// # Errors
    /// [`Error::InvalidTolerance`] for a tolerance that is not finite and `> 0`.
    pub fn with_tolerance(self, tolerance: f64) -> Result<Self> {
        check_tolerance(tolerance)?;
        Ok(Self { tolerance, ..self })
    }

    /// The same options with another active-set iteration budget (`≥ 1`).
    ///
    /// # Errors
    /// [`Error::InvalidCount`] for 0.
    pub fn with_max_active_set_iterations(self, iterations: usize) -> Result<Self> {
        check_iterations("max_active_set_iterations", iterations)?;
        Ok(Self {
            max_active_set_iterations: iterations,
            ..self
        })
    }

    /// The same options with another conjugate-gradient iteration budget (`≥ 1`).
    ///
    /// # Errors
    /// [`Error::InvalidCount`] for 0.
    pub fn with_max_linear_iterations(self, iterations: usize) -> Result<Self> {
        check_iterations("max_linear_iterations", iterations)?;
        Ok(Self {
            max_linear_iterations: iterations,
            ..self
        })
    }

    /// The same options with another parallelism (see [`SolverOptions::parallelism`]).
    ///
    /// # Errors
    /// [`Error::InvalidCount`] for `Threads(0)`; [`Error::DenseThreads`] for more than one
    /// thread with an explicit [`Backend::Dense`].
    pub fn with_parallelism(self, parallelism: Parallelism) -> Result<Self> {
        check_threads(self.backend, parallelism)?;
        Ok(Self {
            parallelism,
            ..self
        })
    }

    /// The same options with another parallelism, unchecked: for the solver and driver,
    /// whose `set_parallelism` checks it against the backend first.
    pub(crate) fn set_parallelism(&mut self, parallelism: Parallelism) {
        self.parallelism = parallelism;
    }
}

/// [`SolverOptions`] as serde sees them (feature `serde`): the scene file's `solver` keys
/// but `threads`, which is the [`Parallelism`] itself (a missing key takes the default),
/// read back through the `with_` modifiers.
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
struct SolverOptionsFields {
    backend: Backend,
    tolerance: f64,
    max_active_set_iterations: usize,
    max_linear_iterations: usize,
    parallelism: Parallelism,
}

#[cfg(feature = "serde")]
impl Default for SolverOptionsFields {
    fn default() -> Self {
        SolverOptions::default().into()
    }
}

#[cfg(feature = "serde")]
impl From<SolverOptions> for SolverOptionsFields {
    fn from(o: SolverOptions) -> Self {
        Self {
            backend: o.backend,
            tolerance: o.tolerance,
            max_active_set_iterations: o.max_active_set_iterations,
            max_linear_iterations: o.max_linear_iterations,
            parallelism: o.parallelism,
        }
    }
}

#[cfg(feature = "serde")]
impl TryFrom<SolverOptionsFields> for SolverOptions {
    type Error = Error;
    fn try_from(f: SolverOptionsFields) -> Result<Self> {
        SolverOptions::default()
            .with_parallelism(f.parallelism)?
            .with_backend(f.backend)?
            .with_tolerance(f.tolerance)?
            .with_max_active_set_iterations(f.max_active_set_iterations)?
            .with_max_linear_iterations(f.max_linear_iterations)
    }
}

/// An iteration budget of at least one.
fn check_iterations(name: &'static str, iterations: usize) -> Result<()> {
    if iterations == 0 {
        return Err(Error::InvalidCount {
            name,
            value: 0,
            reason: "a solve needs at least one iteration",
        });
    }
    Ok(())
}

/// Refuses a thread count the backend cannot honour: `Threads(0)`, and an explicit
/// [`Backend::Dense`] with `Threads(n > 1)`.
pub(crate) fn check_threads(backend: Backend, parallelism: Parallelism) -> Result<()> {
    parallelism.validate()?;
    match (backend, parallelism) {
        (Backend::Dense, Parallelism::Threads(threads)) if threads > 1 => {
            Err(Error::DenseThreads {
                threads,
                auto_limit: AUTO_DENSE_LIMIT,
            })
        }
        _ => Ok(()),
    }
}

/// How a solve went.
///
/// ```
/// use precursors::solver::{Backend, EquilibriumSolver};
/// use precursors::green::InfluencePlan;
/// use precursors::{Block, Grid, HeightDistribution, Heights, Interface, SpringLaw};
/// let grid = Grid::new(Block::new(0.010, 0.004, 0.010)?, 10, 4)?; // 1 mm cells: ΔA = 1 mm²
/// let plan = InfluencePlan::builder(grid).build()?;
/// let heights = Heights::truncated_gaussian(&grid, HeightDistribution::default(), 1)?;
/// let interface = Interface::new(grid, heights, SpringLaw::default())?;
/// let mut solver = EquilibriumSolver::builder(plan).build()?;
/// let report = solver.solve_normal(&interface, 40.0)?.report; // F_N = 40 N
/// assert_eq!(report.backend, Backend::Dense);                  // Auto, resolved
/// assert!(report.active_set_iterations >= 1);
/// assert!(report.force_balance_error < 1e-12);                 // |ΔA Σ φ_z - F_N| / F_N
/// assert!(report.complementarity < 1e-9);        // φ_z ≥ 0 on contact, u_z ≥ u0 off it
/// println!("{} flips, {} CG iterations", report.flips, report.linear_iterations);
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct SolveReport {
    /// The backend that ran (never `Auto`).
    pub backend: Backend,
    /// Active-set iterations (1 for the tangential solve).
    pub active_set_iterations: usize,
    /// Conjugate-gradient iterations, summed over the active-set iterations.
    pub linear_iterations: usize,
    /// Sites whose state changed between attached and detached.
    pub flips: usize,
    /// Normwise backward error of the last linear solve (dimensionless).
    pub residual: f64,
    /// `|ΔA Σ φ - F| / |F|` (dimensionless).
    pub force_balance_error: f64,
    /// Largest violation of the unilateral conditions, relative to the largest height:
    /// `max(-f_i)/max f` on attached sites and `max(u0_i - u_z,i)/max u0` on detached ones
    /// (0 for the tangential solve).
    pub complementarity: f64,
    /// Whether the monotone fallback ran (the primal-dual iteration revisited a set).
    pub fallback: bool,
}

/// The normal equilibrium at a given normal load.
///
/// ```
/// use precursors::solver::EquilibriumSolver;
/// use precursors::SiteState;
/// use precursors::green::InfluencePlan;
/// use precursors::{Block, Grid, HeightDistribution, Heights, Interface, SpringLaw};
/// let grid = Grid::new(Block::new(0.010, 0.004, 0.010)?, 10, 4)?; // 1 mm cells: ΔA = 1 mm²
/// let plan = InfluencePlan::builder(grid).build()?;
/// let heights = Heights::truncated_gaussian(&grid, HeightDistribution::default(), 1)?;
/// let mut interface = Interface::new(grid, heights, SpringLaw::default())?;
/// let mut solver = EquilibriumSolver::builder(plan).build()?;
/// let normal = solver.solve_normal(&interface, 40.0)?;           // F_N = 40 N
/// // The tractions carry the load: ΔA Σ φ_z = F_N (N).
/// let carried = normal.traction.iter().sum::<f64>() * grid.cell_area();
/// assert!((carried - normal.normal_load).abs() < 1e-9 * 40.0);
/// // The spring law on contact, φ_z = k_z (u0 - u_z); no traction off contact.
/// let k_z = interface.normal_stiffness();                        // N/m³
/// let largest = normal.traction.iter().fold(0.0f64, |m, p| m.max(*p));
/// for i in 0..grid.len() {
///     let (phi, u_z) = (normal.traction[i], normal.displacement[i]);
///     let u0 = interface.heights()[i];
///     match normal.states[i] {
///         SiteState::Attached => assert!((phi - k_z[i] * (u0 - u_z)).abs() <= 1e-6 * largest),
///         _ => assert_eq!(phi, 0.0),
///     }
/// }
/// interface.set_states(&normal.states)?;                         // the solver changes nothing
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct NormalEquilibrium {
    /// Normal traction `φ_z` per cell (Pa, `≥ 0`; 0 on detached and broken sites).
    pub traction: Vec<f64>,
    /// Normal displacement `u_z` of the bottom face per cell (m, cell averages).
    pub displacement: Vec<f64>,
    /// `U` (m): `u_z = U + (ΔA/M) Ĝ φ_z`, i.e. `⟨u_z⟩` plus the top load's constant. (The
    /// tangential response's is per newton: [`TangentialResponse::offset_per_newton`].)
    pub offset: f64,
    /// The state of every site at this equilibrium: attached or detached (broken sites
    /// stay broken). The solver does not change the interface: apply these with
    /// [`Interface::set_states`](crate::Interface::set_states).
    #[cfg_attr(feature = "serde", serde(default))]
    pub states: Vec<SiteState>,
    /// The normal load `F_N` (N).
    pub normal_load: f64,
    /// How the solve went.
    pub report: SolveReport,
}

/// The tangential response to one newton of shear at a fixed attached set.
///
/// ```
/// use precursors::solver::EquilibriumSolver;
/// use precursors::SiteState;
/// use precursors::green::InfluencePlan;
/// use precursors::{Block, Grid, HeightDistribution, Heights, Interface, SpringLaw};
/// let grid = Grid::new(Block::new(0.010, 0.004, 0.010)?, 10, 4)?; // 1 mm cells: ΔA = 1 mm²
/// let plan = InfluencePlan::builder(grid).build()?;
/// let heights = Heights::truncated_gaussian(&grid, HeightDistribution::default(), 1)?;
/// let mut interface = Interface::new(grid, heights, SpringLaw::default())?;
/// let mut solver = EquilibriumSolver::builder(plan).build()?;
/// let normal = solver.solve_normal(&interface, 40.0)?;           // F_N = 40 N
/// interface.set_states(&normal.states)?;
/// // A uniform top shear: no displacement without the springs, e = 0.
/// let e = vec![0.0; grid.len()];
/// let shear = solver.solve_tangential(&interface, &normal.displacement, &e)?;
/// // The springs resist the newton: ΔA Σ φ_x = -1 N.
/// let resisted = shear.traction.iter().sum::<f64>() * grid.cell_area();
/// assert!((resisted + 1.0).abs() < 1e-9);
/// // The spring law on contact, φ_x = -k_x u_x, per newton (Pa/N, m/N).
/// let k_x = interface.tangential_stiffness(&normal.displacement)?; // N/m³
/// let largest = shear.traction.iter().fold(0.0f64, |m, g| m.max(g.abs()));
/// for i in 0..grid.len() {
///     if interface.states()[i] == SiteState::Attached {
///         let (g, u) = (shear.traction[i], shear.displacement[i]);
///         assert!((g + k_x[i] * u).abs() <= 1e-6 * largest);
///     }
/// }
/// assert_eq!(shear.report.active_set_iterations, 1);             // a linear solve
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct TangentialResponse {
    /// Shear traction `φ_x` per cell per newton of load (Pa/N, `≤ 0` mostly: it resists).
    pub traction: Vec<f64>,
    /// Shear displacement `u_x` of the bottom face per cell per newton of load (m/N).
    pub displacement: Vec<f64>,
    /// `U` per newton of load (m/N): `u_x = U + e + (ΔA/M) Ĝ φ_x`, all per newton. (The
    /// normal equilibrium's [`NormalEquilibrium::offset`] is in m.)
    #[cfg_attr(feature = "serde", serde(alias = "offset"))]
    pub offset_per_newton: f64,
    /// How the solve went.
    pub report: SolveReport,
}
