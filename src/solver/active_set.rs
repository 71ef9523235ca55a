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

use super::options::{NormalEquilibrium, SolveReport};
use super::set::SetProblem;
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
        let mut seen = HashSet::new();
        let mut linear_iterations = 0;
        let mut iteration = 0;
        let cold = warm_full.iter().all(|x| *x == 0.0);
        let mut mode = if cold || !self.explores_cold_only() {
            Mode::Explore
        } else {
            Mode::Exact
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
                d: &diag,
                b: &b,
                total,
            };
            let explored = matches!(mode, Mode::Explore) && self.explores(&set);
            let kind = SolveKind {
                explore: explored,
                tangential: false,
                cold,
            };
            let solved = self.solve_set(kind, problem, warm)?;
            linear_iterations += solved.outcome.iterations;
            let f = solved.f;
            let offset = solved.outcome.offset;

            if let Mode::Fallback { primal } = &mut mode {
                if let Some(prev) = primal.take() {
                    // Monotone fallback: step from the feasible iterate towards the
                    // solution, stopping where the first traction reaches zero.
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
                        warm_full = full.clone();
                        *primal = Some(full);
                        continue;
                    }
                }
            }

            let mut u = solved.grid_product;
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
            let satisfied = negative.is_empty() && violated.is_empty();
            if satisfied && explored {
                mode = Mode::Exact; // confirm the set at full tolerance (dense: the factor)
                continue;
            }
            if satisfied {
                let mut traction = vec![0.0; n];
                for (a, &i) in set.iter().enumerate() {
                    traction[i] = f[a];
                }
                let mut new_states = states.to_vec();
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
                    new_states[i] = new;
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
                let scale = self.compliance.scale * self.compliance.shift;
                return Ok(NormalEquilibrium {
                    traction,
                    displacement: u,
                    offset: offset - scale * sum,
                    states: new_states,
                    normal_load,
                    report: SolveReport {
                        backend: self.backend,
                        active_set_iterations: iteration,
                        linear_iterations,
                        flips,
                        residual: solved.outcome.residual,
                        force_balance_error,
                        complementarity,
                        fallback: matches!(mode, Mode::Fallback { .. }),
                    },
                });
            }
            let key = set_key(&in_set);
            match &mut mode {
                Mode::Explore if seen.contains(&key) => {
                    // Cycling at the loose tolerance: rounding noise, not the method. Go
                    // on at full tolerance from here.
                    mode = Mode::Exact;
                    seen.clear();
                    seen.insert(key);
                }
                Mode::Explore => {
                    seen.insert(key);
                }
                Mode::Exact => {
                    if !seen.insert(key) {
                        // The primal-dual iteration cycles: switch to the monotone method
                        // from a feasible point.
                        mode = Mode::Fallback { primal: None };
                    }
                }
                Mode::Fallback { .. } => {}
            }
            if let Mode::Fallback { primal } = &mut mode {
                let mut full = vec![0.0; n];
                if !negative.is_empty() {
                    // Start (or restart) from the uniform feasible traction on the set.
                    let share = total / set.len() as f64;
                    set.iter().for_each(|&i| full[i] = share);
                } else {
                    for (a, &i) in set.iter().enumerate() {
                        full[i] = f[a];
                    }
                    for &i in &violated {
                        in_set[i] = true;
                    }
                }
                *primal = Some(full);
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

    /// `‖A‖ ‖f‖∞`, the scale of rounding in `u = U + C f`.
    fn norm_scale(&self, f: &[f64], diag: &[f64]) -> f64 {
        let d = diag.iter().fold(0.0f64, |m, x| m.max(*x));
        let fm = f.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        (self.compliance.norm + d) * fm
    }
}

/// A hash of the attached set, to detect a cycling primal-dual iteration.
fn set_key(in_set: &[bool]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    in_set.hash(&mut h);
    h.finish()
}
