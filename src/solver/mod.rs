//! Normal and tangential equilibrium of the interface (docs/model.md section 4).
//!
//! With `C = (ΔA/M) Ĝ` (m/Pa) and the attached set `S`, the normal tractions `f = φ_z`
//! (Pa) solve the strictly convex quadratic programme
//!
//! ```text
//! minimise ½ fᵀ (C + diag(1/k_z)) f - u0ᵀ f   subject to  f ≥ 0,  ΔA Σ f = F_N,
//! ```
//!
//! whose optimality conditions are the spring laws: on `S`,
//! `(C_SS + diag(1/k_z)) f_S + U 1 = u0_S` (`u_z = U + C f`, `U` the multiplier of the
//! load), and off `S`, `f = 0` with `u_z ≥ u0` (detached). The solution, hence the final
//! attached set, is unique whatever order sites flip in. It is found by an active-set
//! iteration (`active_set.rs`); each step solves the equality-constrained system by the
//! projected conjugate gradients of `pcg.rs`, in traction form so that stiff springs
//! (`u0 → 0`) keep it well conditioned.
//!
//! The tangential equilibrium at fixed `S` is linear in the shear (`tangential.rs`): the
//! traction per newton of load `φ_x(1)` solves `(C_SS + diag(1/k_x)) φ_S + U 1 = -e_S`,
//! `ΔA Σ φ = -1 N`, where `e` is the displacement one newton of the load causes.
//!
//! The mean mode of `C` only shifts `U`; the solvers lower its eigenvalue to the largest
//! other one (the displacements are unchanged) so that tall blocks (`Lz ≫ Lx`) do not
//! drown `u0` in a huge common displacement.
//!
//! Where things live: `options.rs` (what a solve takes and returns), `active_set.rs` and
//! `tangential.rs` (the two equilibria), `pcg.rs` (the one projected CG), `system.rs` (the
//! set system: staged product and preconditioners), `spectral.rs` and `dense.rs` (the
//! backends), `fsai.rs` (the sparse approximate inverse), `coarse.rs` (the coarse space of
//! the two-level preconditioner on large grids), `parallel.rs` (threads); with the feature
//! `cuda`, `cuda/` (the spectral rule on a GPU, behind `spectral::SpectralRule`) and
//! `layout.rs` (what it reads of the host's preconditioners).

mod active_set;
mod coarse;
#[cfg(feature = "cuda")]
mod cuda;
mod dense;
mod fsai;
#[cfg(feature = "cuda")]
mod layout;
mod options;
mod parallel;
mod pcg;
mod set;
mod spectral;
mod system;
mod tangential;
pub(crate) use tangential::AnchorResponse;

#[cfg(feature = "cuda")]
pub use cuda::{cuda_device, record_cuda_phase_times, CudaDevice, CudaPhaseTimes};
pub use options::{
    Backend, NormalEquilibrium, SolveReport, SolverOptions, TangentialResponse, AUTO_DENSE_LIMIT,
};
pub use parallel::Parallelism;

use crate::error::{Error, Result};
use crate::geometry::Grid;
use crate::green::{InfluencePlan, Partition};
use crate::interface::{Interface, Material};
use dense::{DenseCore, FactorState};
use pcg::Effort;
use set::{SetProblem, SetSolve};
use spectral::{Precond, SpectralCore, SpectralRule};
use system::Compliance;

/// Backward error of the linear solves while a cold attached set is explored.
const EXPLORE_TOLERANCE: f64 = 1e-7;

/// Everything a solver carries from one solve to the next (warm starts, factors, the
/// spectral preconditioner's `d̄`): with it a restored solver repeats the original's
/// results bit for bit.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct SolverState {
    backend: Backend,
    warm_normal: Vec<f64>,
    warm_tangential: Vec<f64>,
    /// The anchors' tangential solve's warm start (`tangential.rs`): empty until one ran,
    /// and then left out of a checkpoint's JSON, which stays the one 1.x writes.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Vec::is_empty")
    )]
    warm_anchor: Vec<f64>,
    preconditioner_mean: Option<f64>,
    /// Dense backend: the normal factor.
    factor: Option<FactorState>,
}

enum Core {
    Dense(Box<DenseCore>),
    /// The spectral backend's rule on the host's threads or on a GPU (`SpectralRule`:
    /// the one seam between the solver and a machine).
    Spectral(Box<dyn SpectralRule>),
}

/// Builder of an [`EquilibriumSolver`].
///
/// ```
/// use precursors::green::InfluencePlan;
/// use precursors::solver::{Backend, EquilibriumSolver, Parallelism, SolverOptions};
/// use precursors::{Block, Grid, Material};
/// let grid = Grid::new(Block::new(0.010, 0.004, 0.010)?, 10, 4)?; // 1 mm cells
/// let plan = InfluencePlan::builder(grid).build()?;
/// let rubber = Material::new(5e6, 0.49, 1.0)?;                   // E (Pa), ν, μ
/// let options = SolverOptions::default()
///     .with_backend(Backend::Spectral)?
///     .with_parallelism(Parallelism::Threads(2))?;
/// let solver = EquilibriumSolver::builder(plan)
///     .material(rubber)
///     .solver_options(options)
///     .build()?;
/// assert_eq!(solver.backend(), Backend::Spectral);
/// assert!((solver.material().modulus() - 5e6 / 1.49).abs() < 1e-6); // M = E/(1+ν) (Pa)
/// // 40 cells are one part of the grid: the solves run on the calling thread.
/// assert_eq!(solver.threads(), 1);
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone)]
#[must_use]
pub struct EquilibriumSolverBuilder {
    plan: InfluencePlan,
    material: Material,
    options: SolverOptions,
}

impl EquilibriumSolverBuilder {
    /// The block's material (default PMMA); only `M = E/(1+ν)` enters the equilibria.
    pub fn material(mut self, material: Material) -> Self {
        self.material = material;
        self
    }

    /// Solver options (the same method name as
    /// [`crate::SceneBuilder::solver_options`]).
    pub fn solver_options(mut self, options: SolverOptions) -> Self {
        self.options = options;
        self
    }

    /// Validates and prepares the backend (assembles `C` for the dense one).
    ///
    /// # Errors
    /// [`Error::TooLargeForDense`] for the dense backend on a grid above
    /// [`crate::green::DENSE_LIMIT`] cells (the material and the options are valid by
    /// construction).
    pub fn build(self) -> Result<EquilibriumSolver> {
        let grid = *self.plan.grid();
        let n = grid.len();
        let backend = match self.options.backend() {
            Backend::Auto if n <= AUTO_DENSE_LIMIT => Backend::Dense,
            Backend::Auto => Backend::Spectral,
            b => b,
        };
        let scale = grid.cell_area() / self.material.modulus();
        let (nx, ny) = (grid.nx(), grid.ny());
        let mean = self.plan.eigenvalue(0, 0).unwrap_or(0.0);
        let mut largest_other: f64 = 0.0;
        for m in 0..ny {
            for p in 0..nx {
                if p + m > 0 {
                    largest_other = largest_other.max(self.plan.eigenvalue(p, m).unwrap_or(0.0));
                }
            }
        }
        // Lower the mean mode's eigenvalue to the largest other one (module docs).
        let lowered = if n > 1 { mean.min(largest_other) } else { mean };
        let shift = (mean - lowered) / n as f64;
        let compliance = Compliance {
            scale,
            shift,
            norm: scale * lowered.max(largest_other),
        };
        let core = match backend {
            Backend::Dense => {
                let g = self.plan.dense()?;
                let c = faer::Mat::from_fn(n, n, |i, j| scale * (g[i * n + j] - shift));
                // One part: the factor solve needs the whole set vector.
                let spectral = SpectralCore::new(&self.plan, compliance, Partition::single(nx, ny));
                Core::Dense(Box::new(DenseCore::new(c, spectral)))
            }
            Backend::Cuda => cuda_core(&self.plan, compliance)?,
            _ => Core::Spectral(Box::new(SpectralCore::new(
                &self.plan,
                compliance,
                Partition::of(&self.plan),
            ))),
        };
        Ok(EquilibriumSolver {
            grid,
            material: self.material,
            options: self.options,
            backend,
            compliance,
            core,
            warm_normal: Vec::new(),
            warm_tangential: Vec::new(),
            warm_anchor: Vec::new(),
        })
    }
}

/// The CUDA backend's core on the plan's grid.
#[cfg(feature = "cuda")]
fn cuda_core(plan: &InfluencePlan, compliance: Compliance) -> Result<Core> {
    Ok(Core::Spectral(Box::new(cuda::CudaCore::new(
        plan, compliance,
    )?)))
}

/// Without the feature `cuda` there is no CUDA backend to build.
#[cfg(not(feature = "cuda"))]
fn cuda_core(_: &InfluencePlan, _: Compliance) -> Result<Core> {
    Err(Error::CudaUnavailable {
        reason: "this build of precursors has no CUDA backend (feature `cuda` is off)".into(),
        hint: "rebuild with `--features cuda` (`cargo build --release --features cli,cuda`; \
               docs/gpu.md), or use backend \"spectral\""
            .into(),
    })
}

/// Solves the interface equilibria of one geometry; build once, reuse for every load
/// and every state (factors and warm starts are kept between solves).
///
/// The equilibria of a small interface under `F_N = 40 N`, then one newton of top shear:
///
/// ```
/// use precursors::green::InfluencePlan;
/// use precursors::solver::{Backend, EquilibriumSolver};
/// use precursors::{Block, Grid, HeightDistribution, Heights, Interface, SpringLaw};
/// let grid = Grid::new(Block::new(0.010, 0.004, 0.010)?, 10, 4)?; // 1 mm cells: ΔA = 1 mm²
/// let plan = InfluencePlan::builder(grid).build()?;
/// let heights = Heights::truncated_gaussian(&grid, HeightDistribution::default(), 1)?;
/// let mut interface = Interface::new(grid, heights, SpringLaw::default())?;
/// let mut solver = EquilibriumSolver::builder(plan).build()?;    // PMMA, default options
/// assert_eq!(solver.backend(), Backend::Dense);                  // Auto on 40 cells
/// let normal = solver.solve_normal(&interface, 40.0)?;
/// let carried = normal.traction.iter().sum::<f64>() * grid.cell_area();
/// assert!((carried - 40.0).abs() < 1e-9 * 40.0);                 // ΔA Σ φ_z = F_N (N)
/// interface.set_states(&normal.states)?;
/// let top = vec![0.0; grid.len()];                               // e = 0 (m/N): top shear
/// let shear = solver.solve_tangential(&interface, &normal.displacement, &top)?;
/// let resisted = shear.traction.iter().sum::<f64>() * grid.cell_area();
/// assert!((resisted + 1.0).abs() < 1e-9);                        // ΔA Σ φ_x = -1 N
/// // Solving again from the warm start gives the same equilibrium.
/// let again = solver.solve_normal(&interface, 40.0)?;
/// assert_eq!(again.states, normal.states);
/// # Ok::<(), precursors::Error>(())
/// ```
pub struct EquilibriumSolver {
    grid: Grid,
    material: Material,
    options: SolverOptions,
    backend: Backend,
    compliance: Compliance,
    core: Core,
    warm_normal: Vec<f64>,
    warm_tangential: Vec<f64>,
    warm_anchor: Vec<f64>,
}

impl std::fmt::Debug for EquilibriumSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EquilibriumSolver")
            .field("grid", &self.grid)
            .field("material", &self.material)
            .field("options", &self.options)
            .field("backend", &self.backend)
            .finish_non_exhaustive()
    }
}

/// Which solve: tangential or normal, and whether a cold normal set may be explored with
/// the spectral iteration before the dense factor is built.
#[derive(Clone, Copy)]
struct SolveKind {
    explore: bool,
    tangential: bool,
    /// A cold normal solve (spectral backend: use the spectral preconditioner).
    cold: bool,
}

impl EquilibriumSolver {
    /// A builder for the equilibria of `plan`'s grid.
    pub fn builder(plan: InfluencePlan) -> EquilibriumSolverBuilder {
        EquilibriumSolverBuilder {
            plan,
            material: Material::default(),
            options: SolverOptions::default(),
        }
    }

    /// The backend in use (`Dense`, `Spectral` or `Cuda`: never `Auto`).
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The material.
    pub fn material(&self) -> Material {
        self.material
    }

    /// The solver options ([`EquilibriumSolverBuilder::solver_options`]).
    pub fn solver_options(&self) -> SolverOptions {
        self.options
    }

    /// Uses `parallelism` from the next solve on (the results do not change).
    ///
    /// # Errors
    /// [`Error::InvalidCount`] for `Parallelism::Threads(0)`; [`Error::DenseThreads`] for
    /// `Parallelism::Threads(n > 1)` when the options ask for [`Backend::Dense`].
    pub fn set_parallelism(&mut self, parallelism: Parallelism) -> Result<()> {
        options::check_threads(self.options.backend(), parallelism)?;
        self.options.set_parallelism(parallelism);
        Ok(())
    }

    /// The threads a solve actually uses: 1 on the dense backend (one part, whatever
    /// the parallelism; [`SolverOptions::parallelism`]), at most the grid's parts on the
    /// spectral one (up to 16; grids below 2048 cells are one part).
    pub fn threads(&self) -> usize {
        let parts = match &self.core {
            Core::Dense(_) => 1,
            Core::Spectral(s) => s.parts(),
        };
        self.options.parallelism().threads().min(parts).max(1)
    }

    /// Forgets factors and warm starts (the next solve starts cold).
    pub fn reset(&mut self) {
        self.warm_normal.clear();
        self.warm_tangential.clear();
        self.warm_anchor.clear();
        if let Core::Dense(d) = &mut self.core {
            d.normal.clear();
        }
    }

    /// The state carried between solves.
    /// Whether a preconditioner is built (they are built on first use only).
    #[cfg(test)]
    pub(crate) fn holds_preconditioners(&self) -> bool {
        match &self.core {
            Core::Spectral(core) => core.built(),
            Core::Dense(core) => core.spectral.built(),
        }
    }

    pub(crate) fn state(&self) -> SolverState {
        let (preconditioner_mean, factor) = match &self.core {
            Core::Dense(d) => (d.spectral.preconditioner_mean(), Some(d.normal.state())),
            Core::Spectral(s) => (s.preconditioner_mean(), None),
        };
        SolverState {
            backend: self.backend,
            warm_normal: self.warm_normal.clone(),
            warm_tangential: self.warm_tangential.clone(),
            warm_anchor: self.warm_anchor.clone(),
            preconditioner_mean,
            factor,
        }
    }

    /// Restores a state taken by [`EquilibriumSolver::state`] on the same geometry.
    pub(crate) fn restore(&mut self, state: SolverState, solved: bool) -> Result<()> {
        let n = self.grid.len();
        let bad = |reason: String| Err(Error::InvalidCheckpoint { reason });
        // The spectral and CUDA backends solve one rule with one state (warm starts and
        // the spectral preconditioner's d̄): a checkpoint resumes across them.
        let rule = |b: Backend| match b {
            Backend::Cuda => Backend::Spectral,
            b => b,
        };
        if rule(state.backend) != rule(self.backend) {
            return bad(format!(
                "the checkpoint's solver ran backend \"{}\", this scene's runs backend \"{}\"",
                state.backend, self.backend
            ));
        }
        for (name, warm) in [
            ("normal", &state.warm_normal),
            ("tangential", &state.warm_tangential),
        ] {
            // Empty until the first solve, then one value per site ever after: an empty one
            // later would start the next solve cold, on another path to other digits.
            let expected = if solved { n } else { 0 };
            if warm.len() != expected || !warm.iter().all(|x| x.is_finite()) {
                return bad(format!(
                    "the {name} warm start has {} values (expected {expected}, all finite: \
                     {})",
                    warm.len(),
                    if solved {
                        "a solver that has solved keeps one per site"
                    } else {
                        "none before the first solve"
                    }
                ));
            }
        }
        // The anchors' warm start: none until an anchored rule solved, then one per site.
        let anchor = &state.warm_anchor;
        if !(anchor.is_empty() || (solved && anchor.len() == n))
            || !anchor.iter().all(|x| x.is_finite())
        {
            return bad(format!(
                "the anchor warm start has {} values (expected none, or {n} finite ones \
                 after the first solve)",
                anchor.len()
            ));
        }
        if let Some(d) = state.preconditioner_mean {
            if !(d.is_finite() && d >= 0.0) {
                return bad(format!(
                    "the preconditioner's mean compliance {d} is invalid"
                ));
            }
        }
        match (&mut self.core, state.factor) {
            (Core::Dense(core), Some(normal)) => {
                core.normal.restore(normal, n)?;
                core.spectral
                    .restore_preconditioner(state.preconditioner_mean);
            }
            (Core::Spectral(core), None) => {
                core.restore_preconditioner(state.preconditioner_mean)?
            }
            _ => return bad("the dense factor does not match the backend".into()),
        }
        self.warm_normal = state.warm_normal;
        self.warm_tangential = state.warm_tangential;
        self.warm_anchor = state.warm_anchor;
        Ok(())
    }

    fn check_interface(&self, interface: &Interface) -> Result<()> {
        if interface.grid() != &self.grid {
            return Err(Error::LengthMismatch {
                name: "interface sites (the interface was built on another grid)",
                expected: self.grid.len(),
                found: interface.grid().len(),
            });
        }
        Ok(())
    }

    /// Whether a normal solve on `set` would explore first: always on the spectral
    /// backend from a cold start; on the dense one when the factor needs rebuilding.
    fn explores(&self, set: &[usize]) -> bool {
        match &self.core {
            Core::Dense(c) => c.normal.needs_refactor(set, self.grid.len()),
            _ => true,
        }
    }

    /// Whether the backend explores cold sets at all (the dense one always may).
    fn explores_cold_only(&self) -> bool {
        !matches!(self.core, Core::Dense(_))
    }

    /// One equality-constrained solve on a set, whichever backend; `warm` is the start.
    fn solve_set(
        &mut self,
        kind: SolveKind,
        problem: SetProblem<'_>,
        warm: Vec<f64>,
    ) -> Result<SetSolve> {
        let SolveKind {
            explore,
            tangential,
            cold,
        } = kind;
        // Exploring a cold set only needs the signs of f and u0 - u_z right away from
        // zero: a loose tolerance, the final set is confirmed at the user's one.
        let tolerance = if explore {
            self.options.tolerance().max(EXPLORE_TOLERANCE)
        } else {
            self.options.tolerance()
        };
        let effort = Effort {
            tolerance,
            max_iterations: self.options.max_linear_iterations(),
            parallelism: self.options.parallelism(),
        };
        let solved = match &mut self.core {
            // A cold or much-changed set: find the attached set with the cheap spectral
            // iteration first; the factor confirms the final set.
            Core::Dense(core) if explore => {
                core.spectral
                    .solve(problem, Precond::Spectral, warm, effort)?
            }
            // The tangential system goes the spectral way on both backends (dense.rs).
            Core::Dense(core) if tangential => core.spectral.solve(
                problem,
                spectral::warm_precond(true, self.grid.len()),
                warm,
                effort,
            )?,
            Core::Dense(core) => core.solve(problem, warm, effort)?,
            Core::Spectral(core) => {
                let precond = if cold {
                    Precond::Spectral
                } else {
                    spectral::warm_precond(tangential, self.grid.len())
                };
                core.solve(problem, precond, warm, effort)?
            }
        };
        if !solved.outcome.converged {
            return Err(Error::SolverNotConverged {
                what: if tangential {
                    "tangential equilibrium (projected CG)"
                } else {
                    "normal equilibrium (projected CG)"
                },
                iterations: solved.outcome.iterations,
                residual: solved.outcome.residual,
                tolerance,
            });
        }
        Ok(solved)
    }
}

/// The poison-tolerant guards of the parts' buffers and the shared pools (their one copy
/// is in `lock.rs`).
pub(crate) use crate::lock::{lock, read, write};

#[cfg(test)]
mod tests;
