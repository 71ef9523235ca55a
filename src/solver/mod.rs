//! Normal and tangential equilibrium of the interface (MODEL.md section 4).
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
//! attached set, is unique whatever order sites flip in. It is found by a primal-dual
//! active-set iteration (all sites with `f < 0` leave, all sites with `u_z < u0` join, at
//! once) that falls back to a monotone primal active-set method if a set repeats. Each
//! step solves the equality-constrained system by projected conjugate gradients, in
//! traction form so that stiff springs (`u0 → 0`) keep it well conditioned.
//!
//! The tangential equilibrium at fixed `S` is linear in the shear: the traction per
//! newton of load `φ_x(1)` solves `(C_SS + diag(1/k_x)) φ_S + U 1 = -e_S`,
//! `ΔA Σ φ = -1 N`, where `e` is the displacement one newton of the load causes.
//!
//! The mean mode of `C` only shifts `U`; the solvers lower its eigenvalue to the largest
//! other one (the displacements are unchanged) so that tall blocks (`Lz ≫ Lx`) do not
//! drown `u0` in a huge common displacement.

mod dense;
mod fsai;
mod pcg;
mod spectral;
mod team;

use crate::error::{check_slice, check_tolerance, Error, Result};
use crate::geometry::Grid;
use crate::green::InfluencePlan;
use crate::interface::{Interface, Material, SiteState};
use dense::{DenseCore, FactorState};
use pcg::{projected_pcg, PcgOutcome};
use spectral::{Precond, SpectralCore};
use std::collections::HashSet;
use std::sync::Arc;

/// Backward error of the linear solves while a cold attached set is explored.
const EXPLORE_TOLERANCE: f64 = 1e-7;

/// Largest grid the [`Backend::Auto`] choice solves densely.
pub const AUTO_DENSE_LIMIT: usize = 2500;

/// Which linear-algebra backend solves the equilibria.
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
}

/// Most threads a solver uses ([`SolverOptions::threads`]).
pub const MAX_THREADS: usize = 2;

/// Options of the equilibrium solvers.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SolverOptions {
    /// Backend (default [`Backend::Auto`]).
    pub backend: Backend,
    /// Normwise backward error `‖A f + U 1 - b‖∞ / (‖A‖ ‖f‖∞ + ‖b‖∞ + |U|)` at which a
    /// linear solve stops (default `1e-13`).
    pub tolerance: f64,
    /// Active-set iterations allowed per normal equilibrium (default `1000`).
    pub max_active_set_iterations: usize,
    /// Conjugate-gradient iterations allowed per linear solve (default `20000`).
    pub max_linear_iterations: usize,
    /// Threads of the spectral backend's conjugate gradients, `1` (default: no thread is
    /// started) or `2`. The spectral CG always splits the grid in two fixed halves
    /// (`solver/team.rs`); with two threads the solver owns a pool of two and runs one
    /// half on each, in step. The arithmetic is the same either way: results are bit for
    /// bit those of one thread (tested), only the wall time changes (docs/performance.md).
    /// The dense backend's factor solves stay on one thread. Two threads pay when two
    /// cores are free: to run several scenes at once (seeds), give each one thread.
    pub threads: usize,
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            backend: Backend::Auto,
            tolerance: 1e-13,
            max_active_set_iterations: 1000,
            max_linear_iterations: 20000,
            threads: 1,
        }
    }
}

impl SolverOptions {
    /// With the given backend.
    #[must_use]
    pub fn with_backend(mut self, backend: Backend) -> Self {
        self.backend = backend;
        self
    }

    /// With the given linear tolerance (dimensionless).
    #[must_use]
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }

    /// With the given number of threads, 1 or 2 (see [`SolverOptions::threads`]).
    #[must_use]
    pub fn with_threads(mut self, threads: usize) -> Self {
        self.threads = threads;
        self
    }
}

/// How a solve went.
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
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct NormalEquilibrium {
    /// Normal traction `φ_z` per cell (Pa, `≥ 0`; 0 on detached and broken sites).
    pub traction: Vec<f64>,
    /// Normal displacement `u_z` of the bottom face per cell (m, cell averages).
    pub displacement: Vec<f64>,
    /// `U` (m): `u_z = U + (ΔA/M) Ĝ φ_z`, i.e. `⟨u_z⟩` plus the top load's constant.
    pub offset: f64,
    /// The normal load `F_N` (N).
    pub normal_load: f64,
    /// How the solve went.
    pub report: SolveReport,
}

/// The tangential response to one newton of shear at a fixed attached set.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct TangentialResponse {
    /// Shear traction `φ_x` per cell per newton of load (Pa/N, `≤ 0` mostly: it resists).
    pub traction: Vec<f64>,
    /// Shear displacement `u_x` of the bottom face per cell per newton of load (m/N).
    pub displacement: Vec<f64>,
    /// `U` (m/N): `u_x = U + e + (ΔA/M) Ĝ φ_x`.
    pub offset: f64,
    /// How the solve went.
    pub report: SolveReport,
}

impl TangentialResponse {
    /// Load (N) at which each site reaches the Coulomb threshold `|φ_x| = μ φ_z`:
    /// `λ_i = μ φ_z,i / |φ_x,i(1)|` (paper Eq. lambda_Amonton_dscrt). `+∞` for sites that
    /// carry no shear (detached, broken, or exactly unloaded).
    pub fn breaking_loads(
        &self,
        normal_traction: &[f64],
        friction_coefficient: f64,
    ) -> Result<Vec<f64>> {
        check_slice("normal_traction", normal_traction, self.traction.len())?;
        if !(friction_coefficient.is_finite() && friction_coefficient >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "friction_coefficient",
                value: friction_coefficient,
                reason: "the friction coefficient must be finite and >= 0",
            });
        }
        Ok(self
            .traction
            .iter()
            .zip(normal_traction)
            .map(|(g, f)| {
                if *g == 0.0 {
                    f64::INFINITY
                } else {
                    friction_coefficient * f / g.abs()
                }
            })
            .collect())
    }
}

/// Everything a solver carries from one solve to the next (warm starts, factors, the
/// spectral preconditioner's `d̄`): with it a restored solver repeats the original's
/// results bit for bit.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct SolverState {
    backend: Backend,
    warm_normal: Vec<f64>,
    warm_tangential: Vec<f64>,
    preconditioner_mean: Option<f64>,
    /// Dense backend: the normal and tangential factors.
    factors: Option<(FactorState, FactorState)>,
}

enum Core {
    Dense(Box<DenseCore>),
    Spectral(Box<SpectralCore>),
}

/// Builder of an [`EquilibriumSolver`].
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

    /// Solver options.
    pub fn options(mut self, options: SolverOptions) -> Self {
        self.options = options;
        self
    }

    /// Validates and prepares the backend (assembles `C` for the dense one).
    pub fn build(self) -> Result<EquilibriumSolver> {
        self.material.validate()?;
        check_tolerance(self.options.tolerance)?;
        let threads = self.options.threads;
        if !(1..=MAX_THREADS).contains(&threads) {
            return Err(Error::InvalidParameter {
                name: "threads",
                value: threads as f64,
                reason: "the spectral solver splits its work in two halves: 1 or 2 threads",
            });
        }
        let pool = if threads > 1 {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .thread_name(|i| format!("precursors-solver-{i}"))
                .build()
                .map_err(|e| Error::ThreadPool {
                    threads,
                    reason: e.to_string(),
                })?;
            Some(Arc::new(pool))
        } else {
            None
        };
        let grid = *self.plan.grid();
        let n = grid.len();
        let backend = match self.options.backend {
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
        let norm_c = scale * lowered.max(largest_other);
        let core = match backend {
            Backend::Dense => {
                let g = self.plan.dense()?;
                let c = faer::Mat::from_fn(n, n, |i, j| scale * (g[i * n + j] - shift));
                let spectral = SpectralCore::new(self.plan, scale, shift, norm_c, pool.clone());
                Core::Dense(Box::new(DenseCore::new(c, norm_c, spectral)))
            }
            _ => Core::Spectral(Box::new(SpectralCore::new(
                self.plan,
                scale,
                shift,
                norm_c,
                pool.clone(),
            ))),
        };
        Ok(EquilibriumSolver {
            grid,
            material: self.material,
            options: self.options,
            backend,
            scale,
            shift,
            norm_c,
            core,
            pool,
            warm_normal: Vec::new(),
            warm_tangential: Vec::new(),
        })
    }
}

/// Solves the interface equilibria of one geometry; build once, reuse for every load
/// and every state (factors and warm starts are kept between solves).
pub struct EquilibriumSolver {
    grid: Grid,
    material: Material,
    options: SolverOptions,
    backend: Backend,
    scale: f64,
    shift: f64,
    norm_c: f64,
    core: Core,
    /// The threads of [`SolverOptions::threads`] (`None` for one thread).
    pool: Option<Arc<rayon::ThreadPool>>,
    warm_normal: Vec<f64>,
    warm_tangential: Vec<f64>,
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

/// `(C_SS + diag(diag)) f + U 1 = b`, `Σ f = total` on the sites `set`.
#[derive(Clone, Copy)]
struct SetProblem<'a> {
    set: &'a [usize],
    diag: &'a [f64],
    b: &'a [f64],
    total: f64,
}

/// One equality-constrained solve on a set, whichever backend.
struct SetSolve {
    f: Vec<f64>,
    outcome: PcgOutcome,
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

    /// The backend in use (`Dense` or `Spectral`).
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

    /// The options.
    pub fn options(&self) -> SolverOptions {
        self.options
    }

    /// Forgets factors and warm starts (the next solve starts cold).
    pub fn reset(&mut self) {
        self.warm_normal.clear();
        self.warm_tangential.clear();
        if let Core::Dense(d) = &mut self.core {
            d.normal.clear();
            d.tangential.clear();
        }
    }

    /// The state carried between solves.
    pub(crate) fn state(&self) -> SolverState {
        let (preconditioner_mean, factors) = match &self.core {
            Core::Dense(d) => (
                d.spectral.preconditioner_mean(),
                Some((d.normal.state(), d.tangential.state())),
            ),
            Core::Spectral(s) => (s.preconditioner_mean(), None),
        };
        SolverState {
            backend: self.backend,
            warm_normal: self.warm_normal.clone(),
            warm_tangential: self.warm_tangential.clone(),
            preconditioner_mean,
            factors,
        }
    }

    /// Restores a state taken by [`EquilibriumSolver::state`] on the same geometry.
    pub(crate) fn restore(&mut self, state: SolverState) -> Result<()> {
        let n = self.grid.len();
        let bad = |reason: String| Err(Error::InvalidCheckpoint { reason });
        if state.backend != self.backend {
            return bad(format!(
                "the checkpoint's solver ran the {:?} backend, this scene's runs {:?}",
                state.backend, self.backend
            ));
        }
        for (name, warm) in [
            ("normal", &state.warm_normal),
            ("tangential", &state.warm_tangential),
        ] {
            if !(warm.is_empty() || warm.len() == n) || !warm.iter().all(|x| x.is_finite()) {
                return bad(format!(
                    "the {name} warm start has {} values (expected 0 or {n}, all finite)",
                    warm.len()
                ));
            }
        }
        if let Some(d) = state.preconditioner_mean {
            if !(d.is_finite() && d >= 0.0) {
                return bad(format!(
                    "the preconditioner's mean compliance {d} is invalid"
                ));
            }
        }
        match (&mut self.core, state.factors) {
            (Core::Dense(core), Some((normal, tangential))) => {
                core.normal.restore(normal, n)?;
                core.tangential.restore(tangential, n)?;
                core.spectral
                    .restore_preconditioner(state.preconditioner_mean);
            }
            (Core::Spectral(core), None) => core.restore_preconditioner(state.preconditioner_mean),
            _ => return bad("the dense factors do not match the backend".into()),
        }
        self.warm_normal = state.warm_normal;
        self.warm_tangential = state.warm_tangential;
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
        let SetProblem {
            set,
            diag,
            b,
            total,
        } = problem;
        let mut f = warm;
        // Exploring a cold set only needs the signs of f and u0 - u_z right away from
        // zero: a loose tolerance, the final set is confirmed at the user's one.
        let tol = if explore {
            self.options.tolerance.max(EXPLORE_TOLERANCE)
        } else {
            self.options.tolerance
        };
        let max_it = self.options.max_linear_iterations;

        let outcome = match &mut self.core {
            Core::Dense(core) if explore => {
                // A cold or much-changed set: find the attached set with the cheap
                // spectral iteration first; the factor confirms the final set.
                let precond = Precond::Spectral;
                core.spectral
                    .solve(set, diag, precond, b, total, &mut f, tol, max_it)
            }
            Core::Dense(core) => {
                let mut sys = core.system(tangential, set, diag)?;
                let mut outcome = projected_pcg(&mut sys, b, total, &mut f, tol, max_it.min(50));
                sys.record(outcome.iterations);
                if !outcome.converged {
                    // The factor was too stale: refactorise and finish.
                    drop(sys);
                    let cache = if tangential {
                        &mut core.tangential
                    } else {
                        &mut core.normal
                    };
                    cache.clear();
                    let mut sys = core.system(tangential, set, diag)?;
                    let again = projected_pcg(&mut sys, b, total, &mut f, tol, max_it);
                    sys.record(again.iterations);
                    outcome = PcgOutcome {
                        iterations: outcome.iterations + again.iterations,
                        ..again
                    };
                }
                outcome
            }
            Core::Spectral(core) => {
                let precond = if cold {
                    Precond::Spectral
                } else {
                    spectral::warm_precond(tangential)
                };
                core.solve(set, diag, precond, b, total, &mut f, tol, max_it)
            }
        };
        if !outcome.converged {
            return Err(Error::SolverNotConverged {
                what: if tangential {
                    "tangential equilibrium (projected CG)"
                } else {
                    "normal equilibrium (projected CG)"
                },
                iterations: outcome.iterations,
                residual: outcome.residual,
                tolerance: tol,
            });
        }
        Ok(SetSolve { f, outcome })
    }

    fn apply_full(&mut self, set: &[usize], x: &[f64], out: &mut [f64]) {
        match &mut self.core {
            Core::Dense(core) => core.apply_full(set, x, out),
            Core::Spectral(core) => core.apply_full(set, x, out),
        }
    }

    /// Normal equilibrium at the normal load `normal_load` (N, finite and > 0).
    ///
    /// Starts from the interface's attached sites (all available sites if none is
    /// attached), updates every non-broken site to attached or detached, and returns the
    /// tractions and displacements. Errors: [`Error::EmptyContact`] when every site is
    /// broken, [`Error::SolverNotConverged`] / [`Error::Factorization`] when the linear
    /// algebra fails (with its diagnostics).
    pub fn solve_normal(
        &mut self,
        interface: &mut Interface,
        normal_load: f64,
    ) -> Result<NormalEquilibrium> {
        match self.pool.clone() {
            Some(pool) => pool.install(|| self.normal_here(interface, normal_load)),
            None => self.normal_here(interface, normal_load),
        }
    }

    /// [`EquilibriumSolver::solve_normal`] on the calling thread (inside the pool if any).
    fn normal_here(
        &mut self,
        interface: &mut Interface,
        normal_load: f64,
    ) -> Result<NormalEquilibrium> {
        self.check_interface(interface)?;
        if !(normal_load.is_finite() && normal_load > 0.0) {
            return Err(Error::InvalidParameter {
                name: "normal_load",
                value: normal_load,
                reason:
                    "the normal load must be finite and > 0 N (the block presses on the substrate)",
            });
        }
        let n = self.grid.len();
        let heights = interface.heights().to_vec();
        let compliance = interface.normal_compliance();
        let states = interface.states().to_vec();
        let available: Vec<usize> = (0..n).filter(|&i| states[i] != SiteState::Broken).collect();
        if available.is_empty() {
            return Err(Error::EmptyContact {
                available: 0,
                reason: "every site is broken, nothing can carry the normal load",
            });
        }
        let total = normal_load / self.grid.cell_area();
        let mut in_set: Vec<bool> = (0..n).map(|i| states[i] == SiteState::Attached).collect();
        if !available.iter().any(|&i| in_set[i]) {
            available.iter().for_each(|&i| in_set[i] = true);
        }
        let mut warm_full = std::mem::take(&mut self.warm_normal);
        if warm_full.len() != n {
            warm_full = vec![0.0; n];
        }
        let u0_max = heights.iter().fold(0.0f64, |m, h| m.max(*h));
        let mut seen = HashSet::new();
        let mut fallback = false;
        let mut primal_f: Option<Vec<f64>> = None; // feasible iterate of the fallback
        let mut linear_iterations = 0;
        let mut u = vec![0.0; n];
        let mut iteration = 0;
        // Explore (loose tolerance; dense: spectral iteration) from a cold start only.
        let cold = warm_full.iter().all(|x| *x == 0.0);
        let mut explore = match &self.core {
            Core::Dense(_) => true,
            Core::Spectral(_) => cold,
        };
        loop {
            iteration += 1;
            if iteration > self.options.max_active_set_iterations {
                return Err(Error::SolverNotConverged {
                    what: "normal equilibrium (active set)",
                    iterations: iteration - 1,
                    residual: f64::INFINITY,
                    tolerance: self.options.tolerance,
                });
            }
            let set: Vec<usize> = (0..n).filter(|&i| in_set[i]).collect();
            let diag: Vec<f64> = set.iter().map(|&i| compliance[i]).collect();
            let b: Vec<f64> = set.iter().map(|&i| heights[i]).collect();
            let warm: Vec<f64> = set.iter().map(|&i| warm_full[i]).collect();
            let problem = SetProblem {
                set: &set,
                diag: &diag,
                b: &b,
                total,
            };
            let explored = explore
                && match &self.core {
                    Core::Dense(c) => c.normal.needs_refactor(&set, n),
                    Core::Spectral(_) => true,
                };
            let kind = SolveKind {
                explore: explored,
                tangential: false,
                cold,
            };
            let solved = self.solve_set(kind, problem, warm)?;
            linear_iterations += solved.outcome.iterations;
            let f = solved.f;
            let offset = solved.outcome.offset;

            if let Some(prev) = primal_f.take() {
                // Monotone fallback: step from the feasible iterate towards the solution,
                // stopping where the first traction reaches zero.
                let prev: Vec<f64> = set.iter().map(|&i| prev[i]).collect();
                let mut alpha = 1.0f64;
                let mut blocking = None;
                for a in 0..set.len() {
                    if f[a] < 0.0 {
                        let t = prev[a] / (prev[a] - f[a]);
                        if t < alpha {
                            alpha = t;
                            blocking = Some(a);
                        }
                    }
                }
                if let Some(block) = blocking {
                    let mut full = vec![0.0; n];
                    for a in 0..set.len() {
                        let v = prev[a] + alpha * (f[a] - prev[a]);
                        full[set[a]] = if a == block { 0.0 } else { v.max(0.0) };
                        if full[set[a]] == 0.0 {
                            in_set[set[a]] = false;
                        }
                    }
                    // The removed sites carried (rounding-level) force: restore the total.
                    warm_full = full.clone();
                    primal_f = Some(full);
                    continue;
                }
            }

            self.apply_full(&set, &f, &mut u);
            u.iter_mut().for_each(|x| *x += offset);
            let scale_u = self.norm_scale(&f, &diag) + u0_max + offset.abs();
            let eps_u = 10.0 * self.options.tolerance * scale_u;
            let negative: Vec<usize> = (0..set.len()).filter(|&a| f[a] < 0.0).collect();
            let violated: Vec<usize> = available
                .iter()
                .copied()
                .filter(|&i| !in_set[i] && heights[i] - u[i] > eps_u)
                .collect();
            warm_full.fill(0.0);
            for (a, &i) in set.iter().enumerate() {
                warm_full[i] = f[a];
            }
            if negative.is_empty() && violated.is_empty() && explored {
                explore = false; // confirm the set at full tolerance (dense: the factor)
                continue;
            }
            if negative.is_empty() && violated.is_empty() {
                let mut traction = vec![0.0; n];
                for (a, &i) in set.iter().enumerate() {
                    traction[i] = f[a];
                }
                let mut flips = 0;
                for &i in &available {
                    let new = if in_set[i] {
                        SiteState::Attached
                    } else {
                        SiteState::Detached
                    };
                    if new != states[i] {
                        flips += 1;
                    }
                    interface.set_state(i, new);
                }
                let detached_gap = available
                    .iter()
                    .filter(|&&i| !in_set[i])
                    .fold(0.0f64, |m, &i| m.max(heights[i] - u[i]));
                let complementarity = if u0_max > 0.0 {
                    detached_gap / u0_max
                } else {
                    0.0
                };
                let sum: f64 = f.iter().sum();
                let force_balance_error =
                    (sum * self.grid.cell_area() - normal_load).abs() / normal_load;
                self.warm_normal = warm_full;
                return Ok(NormalEquilibrium {
                    traction,
                    displacement: u,
                    offset: offset - self.scale * self.shift * sum,
                    normal_load,
                    report: SolveReport {
                        backend: self.backend,
                        active_set_iterations: iteration,
                        linear_iterations,
                        flips,
                        residual: solved.outcome.residual,
                        force_balance_error,
                        complementarity,
                        fallback,
                    },
                });
            }
            let key = set_key(&in_set);
            if explore && seen.contains(&key) {
                // Cycling at the loose tolerance: rounding noise, not the method. Go on at
                // full tolerance from here.
                explore = false;
                seen.clear();
            }
            if !fallback && !seen.insert(key) {
                // The primal-dual iteration cycles: switch to the monotone method from a
                // feasible point (uniform traction on the current set).
                fallback = true;
            }
            if fallback {
                if !negative.is_empty() {
                    // Start (or restart) from the uniform feasible traction on the set.
                    let mut full = vec![0.0; n];
                    let share = total / set.len() as f64;
                    set.iter().for_each(|&i| full[i] = share);
                    primal_f = Some(full);
                } else {
                    let mut full = vec![0.0; n];
                    for (a, &i) in set.iter().enumerate() {
                        full[i] = f[a];
                    }
                    for &i in &violated {
                        in_set[i] = true;
                    }
                    primal_f = Some(full);
                }
                continue;
            }
            for &a in &negative {
                in_set[set[a]] = false;
            }
            for &i in &violated {
                in_set[i] = true;
            }
            if !in_set.iter().any(|x| *x) {
                // Every site wanted to leave: keep the least negative one.
                let a = (0..set.len())
                    .max_by(|&x, &y| f[x].total_cmp(&f[y]))
                    .unwrap_or(0);
                in_set[set[a]] = true;
            }
        }
    }

    /// Tangential response to one newton of shear at the interface's attached set.
    ///
    /// `normal_displacement` is `u_z` per cell (m), which sets `k_x = c_x exp(-u_z/u0)`;
    /// `unit_load_displacement` is the displacement `e` (m/N) one newton of the shear load
    /// produces on every cell in the absence of interface tractions: all zeros for a top
    /// shear (a constant), `RodLoad::influence_cells / M` for a rod or side load. The
    /// response to a load `F` is `F` times the returned one.
    pub fn solve_tangential(
        &mut self,
        interface: &Interface,
        normal_displacement: &[f64],
        unit_load_displacement: &[f64],
    ) -> Result<TangentialResponse> {
        let (u_z, e) = (normal_displacement, unit_load_displacement);
        match self.pool.clone() {
            Some(pool) => pool.install(|| self.tangential_here(interface, u_z, e)),
            None => self.tangential_here(interface, u_z, e),
        }
    }

    /// [`EquilibriumSolver::solve_tangential`] on the calling thread (inside the pool if
    /// any).
    fn tangential_here(
        &mut self,
        interface: &Interface,
        normal_displacement: &[f64],
        unit_load_displacement: &[f64],
    ) -> Result<TangentialResponse> {
        self.check_interface(interface)?;
        let n = self.grid.len();
        check_slice("unit_load_displacement", unit_load_displacement, n)?;
        check_slice("normal_displacement", normal_displacement, n)?;
        let set: Vec<usize> = (0..n)
            .filter(|&i| interface.states()[i] == SiteState::Attached)
            .collect();
        if set.is_empty() {
            return Err(Error::EmptyContact {
                available: 0,
                reason: "no attached site can resist the shear",
            });
        }
        let diag = set
            .iter()
            .map(|&i| interface.tangential_compliance_at(i, normal_displacement[i]))
            .collect::<Result<Vec<f64>>>()?;
        let b: Vec<f64> = set.iter().map(|&i| -unit_load_displacement[i]).collect();
        let total = -1.0 / self.grid.cell_area();
        let mut warm_full = std::mem::take(&mut self.warm_tangential);
        if warm_full.len() != n {
            warm_full = vec![0.0; n];
        }
        let warm: Vec<f64> = set.iter().map(|&i| warm_full[i]).collect();
        let problem = SetProblem {
            set: &set,
            diag: &diag,
            b: &b,
            total,
        };
        let kind = SolveKind {
            explore: false,
            tangential: true,
            cold: false,
        };
        let solved = self.solve_set(kind, problem, warm)?;
        let offset = solved.outcome.offset;
        let mut displacement = vec![0.0; n];
        self.apply_full(&set, &solved.f, &mut displacement);
        displacement
            .iter_mut()
            .zip(unit_load_displacement)
            .for_each(|(u, e)| *u += offset + e);
        let mut traction = vec![0.0; n];
        for (a, &i) in set.iter().enumerate() {
            traction[i] = solved.f[a];
        }
        let sum: f64 = solved.f.iter().sum();
        warm_full.copy_from_slice(&traction);
        self.warm_tangential = warm_full;
        Ok(TangentialResponse {
            traction,
            displacement,
            offset: offset - self.scale * self.shift * sum,
            report: SolveReport {
                backend: self.backend,
                active_set_iterations: 1,
                linear_iterations: solved.outcome.iterations,
                flips: 0,
                residual: solved.outcome.residual,
                force_balance_error: (sum * self.grid.cell_area() + 1.0).abs(),
                complementarity: 0.0,
                fallback: false,
            },
        })
    }

    /// `‖A‖ ‖f‖∞`, the scale of rounding in `u = U + C f`.
    fn norm_scale(&self, f: &[f64], diag: &[f64]) -> f64 {
        let d = diag.iter().fold(0.0f64, |m, x| m.max(*x));
        let fm = f.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        (self.norm_c + d) * fm
    }
}

/// A hash of the attached set, to detect a cycling primal-dual iteration.
fn set_key(in_set: &[bool]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    in_set.hash(&mut h);
    h.finish()
}
