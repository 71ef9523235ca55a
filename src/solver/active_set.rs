//! The normal equilibrium: which sites are attached, by an active-set iteration.
//!
//! A primal-dual active-set iteration (all sites with `f < 0` leave, all sites with
//! `u_z < u0` join, at once) in three modes, each a step towards the next:
//!
//! * [`Mode::Explore`]: from a cold start (or, on the dense backend, a much-changed set),
//!   the sets are explored with loose solves (backward error [`super::EXPLORE_TOLERANCE`];
//!   the spectral iteration on the dense backend); a set that satisfies the conditions,
//!   or one seen before, moves to
//! * [`Mode::Exact`]: solves at the user's tolerance; a set seen before (the primal-dual
//!   iteration cycles) moves to
//! * [`Mode::Fallback`]: a monotone primal active-set method from a feasible point, which
//!   cannot cycle.
//!
//! The solution, hence the final attached set, is unique whatever order sites flip in.
//!
//! [`EquilibriumSolver::solve_normal`] is the loop; each job of an iteration is one
//! function: [`EquilibriumSolver::start_normal`] (the problem and the first set),
//! [`NormalIteration::count`] (the iteration limit), [`EquilibriumSolver::solve_attached`]
//! (the set's equality-constrained solve), [`NormalIteration::monotone_step`] (the
//! fallback's step), [`EquilibriumSolver::check_conditions`] (which sites violate the
//! contact conditions), [`EquilibriumSolver::finish_normal`] (the equilibrium and its
//! report), [`NormalIteration::note_cycles`] (the mode transitions),
//! [`NormalIteration::restart_fallback`] and [`NormalIteration::primal_dual_step`] (the
//! next set).

use super::options::{NormalEquilibrium, SolveReport, SolverOptions};
use super::set::{SetProblem, SetSolve};
use super::{EquilibriumSolver, SolveKind};
use crate::error::{Error, Result};
use crate::interface::{Interface, SiteState};
use std::collections::HashSet;

/// The mode of the active-set iteration (module docs).
enum Mode {
    Explore,
    Exact,
    /// The feasible iterate (tractions on every cell) the next monotone step starts from.
    Fallback {
        primal: Option<Vec<f64>>,
    },
}

/// One normal solve under way: the problem (fixed) and the iterate.
struct NormalIteration<'a> {
    /// The normal load (N).
    normal_load: f64,
    /// The tractions' sum the set solves must meet: the normal load over the cell area.
    total: f64,
    /// The sites' heights `u0` (m).
    heights: &'a [f64],
    /// The sites' normal compliances (the diagonal added to `C` on the set).
    compliance: Vec<f64>,
    /// The sites' states when the solve started.
    states: &'a [SiteState],
    /// The sites that are not broken.
    available: Vec<usize>,
    /// The largest height (m), the scale of the gaps.
    u0_max: f64,
    /// Whether the solve started without a warm start.
    cold: bool,
    /// The attached set being tried.
    in_set: Vec<bool>,
    /// Tractions on every cell: the next set solve's start.
    warm_full: Vec<f64>,
    /// The sets rejected so far in this mode (hashes), to detect cycling.
    seen: HashSet<u64>,
    mode: Mode,
    /// Active-set iterations so far.
    iteration: usize,
    /// Linear (CG) iterations so far.
    linear_iterations: usize,
}

/// A set's solution checked against the contact conditions.
struct Checked {
    /// The tractions on the set, in set order.
    f: Vec<f64>,
    /// The normal displacements `u_z` on every cell, offset included (m).
    u: Vec<f64>,
    /// The multiplier `U` of the set solve.
    offset: f64,
    /// The set solve's backward error.
    residual: f64,
    /// The set positions whose traction pulls (`f < 0`).
    negative: Vec<usize>,
    /// The detached available sites the surface passes through (`u0 - u_z > ε`).
    violated: Vec<usize>,
}

impl Checked {
    /// Whether the set satisfies the contact conditions (it is the solution).
    fn satisfied(&self) -> bool {
        self.negative.is_empty() && self.violated.is_empty()
    }
}

impl EquilibriumSolver {
    /// Normal equilibrium at the normal load `normal_load` (N, finite and > 0).
    ///
    /// Starts from the interface's attached sites (all available sites if none is
    /// attached) and returns the tractions, the displacements and the state every
    /// non-broken site takes (attached or detached) in
    /// [`NormalEquilibrium::states`]; the interface is not changed (apply the states
    /// with [`Interface::set_states`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a normal load that is not finite and positive;
    /// [`Error::LengthMismatch`] for an interface of another grid;
    /// [`Error::EmptyContact`] when every site is broken; [`Error::SolverNotConverged`] /
    /// [`Error::Factorization`] when the linear algebra fails (with its diagnostics).
    pub fn solve_normal(
        &mut self,
        interface: &Interface,
        normal_load: f64,
    ) -> Result<NormalEquilibrium> {
        let mut it = self.start_normal(interface, normal_load)?;
        loop {
            it.count(&self.options)?;
            let set: Vec<usize> = (0..it.in_set.len()).filter(|&i| it.in_set[i]).collect();
            let diag: Vec<f64> = set.iter().map(|&i| it.compliance[i]).collect();
            let (solved, explored) = self.solve_attached(&mut it, &set, &diag)?;
            if it.monotone_step(&set, &solved.f) {
                continue;
            }
            let checked = self.check_conditions(&mut it, &set, &diag, solved);
            if checked.satisfied() && explored {
                it.mode = Mode::Exact; // confirm the set at full tolerance (dense: the factor)
                continue;
            }
            if checked.satisfied() {
                return Ok(self.finish_normal(it, &set, checked));
            }
            it.note_cycles();
            if !it.restart_fallback(&set, &checked) {
                it.primal_dual_step(&set, &checked);
            }
        }
    }

    /// Checks the input and sets the problem up: the available sites, the first set (the
    /// attached sites, or all available ones if none is), the warm start (taken from the
    /// solver) and the first mode.
    fn start_normal<'a>(
        &mut self,
        interface: &'a Interface,
        normal_load: f64,
    ) -> Result<NormalIteration<'a>> {
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
        let heights = interface.heights();
        let compliance = interface.normal_compliance();
        let states = interface.states();
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
        let cold = warm_full.iter().all(|x| *x == 0.0);
        let mode = if cold || !self.explores_cold_only() {
            Mode::Explore
        } else {
            Mode::Exact
        };
        Ok(NormalIteration {
            normal_load,
            total,
            heights,
            compliance,
            states,
            available,
            u0_max,
            cold,
            in_set,
            warm_full,
            seen: HashSet::new(),
            mode,
            iteration: 0,
            linear_iterations: 0,
        })
    }

    /// The equality-constrained solve on the attached set `set` (compliances `diag`),
    /// loose while exploring; returns it and whether it explored.
    fn solve_attached(
        &mut self,
        it: &mut NormalIteration<'_>,
        set: &[usize],
        diag: &[f64],
    ) -> Result<(SetSolve, bool)> {
        let b: Vec<f64> = set.iter().map(|&i| it.heights[i]).collect();
        let warm: Vec<f64> = set.iter().map(|&i| it.warm_full[i]).collect();
        let problem = SetProblem {
            set,
            d: diag,
            b: &b,
            total: it.total,
        };
        let explored = matches!(it.mode, Mode::Explore) && self.explores(set);
        let kind = SolveKind {
            explore: explored,
            tangential: false,
            cold: it.cold,
        };
        let solved = self.solve_set(kind, problem, warm)?;
        it.linear_iterations += solved.outcome.iterations;
        Ok((solved, explored))
    }

    /// Checks the set's solution against the contact conditions (which tractions pull,
    /// which detached sites the surface passes through, within rounding) and keeps the
    /// tractions as the next warm start.
    fn check_conditions(
        &self,
        it: &mut NormalIteration<'_>,
        set: &[usize],
        diag: &[f64],
        solved: SetSolve,
    ) -> Checked {
        let f = solved.f;
        let offset = solved.outcome.offset;
        let mut u = solved.grid_product;
        u.iter_mut().for_each(|x| *x += offset);
        let scale_u = self.norm_scale(&f, diag) + it.u0_max + offset.abs();
        let eps_u = 10.0 * self.options.tolerance() * scale_u;
        let negative: Vec<usize> = (0..set.len()).filter(|&a| f[a] < 0.0).collect();
        let violated: Vec<usize> = it
            .available
            .iter()
            .copied()
            .filter(|&i| !it.in_set[i] && it.heights[i] - u[i] > eps_u)
            .collect();
        it.warm_full.fill(0.0);
        for (a, &i) in set.iter().enumerate() {
            it.warm_full[i] = f[a];
        }
        Checked {
            f,
            u,
            offset,
            residual: solved.outcome.residual,
            negative,
            violated,
        }
    }

    /// The equilibrium of the satisfied set `set`: tractions and states on every cell,
    /// the report; the tractions stay in the solver as the next solve's warm start.
    fn finish_normal(
        &mut self,
        it: NormalIteration<'_>,
        set: &[usize],
        checked: Checked,
    ) -> NormalEquilibrium {
        let Checked {
            f,
            u,
            offset,
            residual,
            ..
        } = checked;
        let n = it.in_set.len();
        let mut traction = vec![0.0; n];
        for (a, &i) in set.iter().enumerate() {
            traction[i] = f[a];
        }
        let mut new_states = it.states.to_vec();
        let mut flips = 0;
        for &i in &it.available {
            let new = if it.in_set[i] {
                SiteState::Attached
            } else {
                SiteState::Detached
            };
            if new != it.states[i] {
                flips += 1;
            }
            new_states[i] = new;
        }
        let detached_gap = it
            .available
            .iter()
            .filter(|&&i| !it.in_set[i])
            .fold(0.0f64, |m, &i| m.max(it.heights[i] - u[i]));
        let complementarity = if it.u0_max > 0.0 {
            detached_gap / it.u0_max
        } else {
            0.0
        };
        let normal_load = it.normal_load;
        let sum: f64 = f.iter().sum();
        let force_balance_error = (sum * self.grid.cell_area() - normal_load).abs() / normal_load;
        self.warm_normal = it.warm_full;
        let scale = self.compliance.scale * self.compliance.shift;
        NormalEquilibrium {
            traction,
            displacement: u,
            offset: offset - scale * sum,
            states: new_states,
            normal_load,
            report: SolveReport {
                backend: self.backend,
                active_set_iterations: it.iteration,
                linear_iterations: it.linear_iterations,
                flips,
                residual,
                force_balance_error,
                complementarity,
                fallback: matches!(it.mode, Mode::Fallback { .. }),
            },
        }
    }

    /// `‖A‖ ‖f‖∞`, the scale of rounding in `u = U + C f`.
    fn norm_scale(&self, f: &[f64], diag: &[f64]) -> f64 {
        let d = diag.iter().fold(0.0f64, |m, x| m.max(*x));
        let fm = f.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        (self.compliance.norm + d) * fm
    }
}

impl NormalIteration<'_> {
    /// Counts one more iteration.
    ///
    /// # Errors
    /// [`Error::SolverNotConverged`] past `options.max_active_set_iterations()`.
    fn count(&mut self, options: &SolverOptions) -> Result<()> {
        self.iteration += 1;
        if self.iteration > options.max_active_set_iterations() {
            return Err(Error::SolverNotConverged {
                what: "normal equilibrium (active set)",
                iterations: self.iteration - 1,
                residual: f64::INFINITY,
                tolerance: options.tolerance(),
            });
        }
        Ok(())
    }

    /// Fallback mode: steps from the feasible iterate towards the set's solution `f`,
    /// stopping where the first traction reaches zero (that site leaves the set).
    /// Returns whether it stopped short (solve the smaller set next); otherwise, or
    /// outside the fallback, `f` is checked as it is.
    fn monotone_step(&mut self, set: &[usize], f: &[f64]) -> bool {
        let Mode::Fallback { primal } = &mut self.mode else {
            return false;
        };
        let Some(prev) = primal.take() else {
            return false;
        };
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
        let Some(block) = blocking else {
            return false;
        };
        let mut full = vec![0.0; self.in_set.len()];
        for a in 0..set.len() {
            let v = prev[a] + alpha * (f[a] - prev[a]);
            full[set[a]] = if a == block { 0.0 } else { v.max(0.0) };
            if full[set[a]] == 0.0 {
                self.in_set[set[a]] = false;
            }
        }
        self.warm_full = full.clone();
        *primal = Some(full);
        true
    }

    /// Notes the rejected set and changes mode when the iteration cycles: a set seen
    /// again while exploring goes on at full tolerance; one seen again at full
    /// tolerance switches to the fallback.
    fn note_cycles(&mut self) {
        let key = set_key(&self.in_set);
        match self.mode {
            Mode::Explore if self.seen.contains(&key) => {
                // Cycling at the loose tolerance: rounding noise, not the method. Go
                // on at full tolerance from here.
                self.mode = Mode::Exact;
                self.seen.clear();
                self.seen.insert(key);
            }
            Mode::Explore => {
                self.seen.insert(key);
            }
            Mode::Exact => {
                if !self.seen.insert(key) {
                    // The primal-dual iteration cycles: switch to the monotone method
                    // from a feasible point.
                    self.mode = Mode::Fallback { primal: None };
                }
            }
            Mode::Fallback { .. } => {}
        }
    }

    /// Fallback mode: the feasible iterate the next monotone step starts from (the
    /// uniform traction on the set if a traction pulls, else the set's solution with
    /// the violated sites added). Returns whether it is in the fallback.
    fn restart_fallback(&mut self, set: &[usize], checked: &Checked) -> bool {
        let Mode::Fallback { primal } = &mut self.mode else {
            return false;
        };
        let mut full = vec![0.0; self.in_set.len()];
        if !checked.negative.is_empty() {
            // Start (or restart) from the uniform feasible traction on the set.
            let share = self.total / set.len() as f64;
            set.iter().for_each(|&i| full[i] = share);
        } else {
            for (a, &i) in set.iter().enumerate() {
                full[i] = checked.f[a];
            }
            for &i in &checked.violated {
                self.in_set[i] = true;
            }
        }
        *primal = Some(full);
        true
    }

    /// The primal-dual step: every site whose traction pulls leaves and every violated
    /// site joins, at once (if every site would leave, the least pulling one stays).
    fn primal_dual_step(&mut self, set: &[usize], checked: &Checked) {
        let f = &checked.f;
        for &a in &checked.negative {
            self.in_set[set[a]] = false;
        }
        for &i in &checked.violated {
            self.in_set[i] = true;
        }
        if !self.in_set.iter().any(|x| *x) {
            // Every site wanted to leave: keep the least negative one.
            let a = (0..set.len())
                .max_by(|&x, &y| f[x].total_cmp(&f[y]))
                .unwrap_or(0);
            self.in_set[set[a]] = true;
        }
    }
}

/// A hash of the attached set, to detect a cycling primal-dual iteration.
fn set_key(in_set: &[bool]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    in_set.hash(&mut h);
    h.finish()
}
