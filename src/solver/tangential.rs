//! The tangential response: the shear tractions per newton of load at a fixed attached
//! set (linear in the load), and the response to the springs' anchors.
//!
//! With springs anchored at `a` (`φ_x = -k_x (u_x - a)` on the attached set `S`), the set
//! system is `(C + diag(1/k_x)) φ + U = a - F e`, `ΔA Σ φ = -F`. By superposition its
//! solution is `φ(F) = F g1 + g0`: `g1` is the response per newton
//! ([`EquilibriumSolver::solve_tangential`]: `b = -e`, `Σ = -1/ΔA`), `g0` the response to
//! the anchors at zero load ([`EquilibriumSolver::solve_tangential_anchor`]: `b = a`,
//! `Σ = 0`). The paper's springs are anchored at 0 and need only `g1`.

use super::options::{SolveReport, TangentialResponse};
use super::pcg::PcgOutcome;
use super::set::{SetProblem, SetSolve};
use super::{EquilibriumSolver, SolveKind};
use crate::error::{check_slice, Error, Result};
use crate::interface::{Interface, SiteState};

/// The shear state the springs' anchors cause at zero load (`g0`), on the attached set
/// of the solve: the tractions (Pa), the displacements (m) and the block's mean
/// displacement `U0` (m). Adds to `F` times [`TangentialResponse`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub(crate) struct AnchorResponse {
    /// `φ_x` (Pa) per cell; zero off the attached set.
    pub(crate) traction: Vec<f64>,
    /// `u_x` (m) per cell.
    pub(crate) displacement: Vec<f64>,
    /// The block's mean shear displacement `U0` (m).
    pub(crate) offset: f64,
    /// How the solve went.
    pub(crate) report: SolveReport,
}

/// Which of the solver's two tangential warm starts a solve uses.
#[derive(Clone, Copy, PartialEq)]
enum Warm {
    /// The response per newton's.
    Unit,
    /// The anchors' response's.
    Anchor,
}

impl EquilibriumSolver {
    /// Tangential response to one newton of shear at the interface's attached set.
    ///
    /// `normal_displacement` is `u_z` per cell (m), which sets `k_x = c_x exp(-u_z/u0)`;
    /// `unit_load_displacement` is the displacement `e` (m/N) one newton of the shear load
    /// produces on every cell in the absence of interface tractions: all zeros for a top
    /// shear (a constant), `RodLoad::influence_cells / M` for a rod or side load. The
    /// response to a load `F` is `F` times the returned one.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] for slices or an interface of the wrong size;
    /// [`Error::EmptyContact`] when no site is attached; [`Error::NonFinite`] when a
    /// tangential stiffness overflows; [`Error::SolverNotConverged`] /
    /// [`Error::Factorization`] when the linear algebra fails.
    pub fn solve_tangential(
        &mut self,
        interface: &Interface,
        normal_displacement: &[f64],
        unit_load_displacement: &[f64],
    ) -> Result<TangentialResponse> {
        self.check_interface(interface)?;
        let n = self.grid.len();
        check_slice("unit_load_displacement", unit_load_displacement, n)?;
        let total = -1.0 / self.grid.cell_area();
        let (traction, solved) = self.solve_tangential_set(
            interface,
            normal_displacement,
            |i| -unit_load_displacement[i],
            total,
            Warm::Unit,
        )?;
        let offset = solved.outcome.offset;
        let mut displacement = solved.grid_product;
        displacement
            .iter_mut()
            .zip(unit_load_displacement)
            .for_each(|(u, e)| *u += offset + e);
        let sum: f64 = solved.f.iter().sum();
        Ok(TangentialResponse {
            traction,
            displacement,
            offset_per_newton: offset - self.compliance.scale * self.compliance.shift * sum,
            report: self.set_report(&solved.outcome, (sum * self.grid.cell_area() + 1.0).abs()),
        })
    }

    /// The shear state at zero load of springs anchored at `anchors` (m per cell: `φ_x =
    /// -k_x (u_x - a)` on the attached sites; the anchors of other sites are not read):
    /// `g0` of the module docs, the same set system as
    /// [`EquilibriumSolver::solve_tangential`] with `b = a` and no net force, warm-started
    /// from its own previous solution. All anchors zero give exactly zero, unsolved.
    ///
    /// # Errors
    /// As [`EquilibriumSolver::solve_tangential`]; [`Error::NonFinite`] for an anchor that
    /// is not finite.
    pub(crate) fn solve_tangential_anchor(
        &mut self,
        interface: &Interface,
        normal_displacement: &[f64],
        anchors: &[f64],
    ) -> Result<AnchorResponse> {
        self.check_interface(interface)?;
        let n = self.grid.len();
        check_slice("anchors", anchors, n)?;
        let states = interface.states();
        if (0..n).all(|i| states[i] != SiteState::Attached || anchors[i] == 0.0) {
            check_slice("normal_displacement", normal_displacement, n)?;
            self.warm_anchor = vec![0.0; n];
            return Ok(AnchorResponse {
                traction: vec![0.0; n],
                displacement: vec![0.0; n],
                offset: 0.0,
                report: SolveReport {
                    backend: self.backend,
                    active_set_iterations: 0,
                    linear_iterations: 0,
                    flips: 0,
                    residual: 0.0,
                    force_balance_error: 0.0,
                    complementarity: 0.0,
                    fallback: false,
                },
            });
        }
        let (traction, solved) = self.solve_tangential_set(
            interface,
            normal_displacement,
            |i| anchors[i],
            0.0,
            Warm::Anchor,
        )?;
        let offset = solved.outcome.offset;
        let mut displacement = solved.grid_product;
        displacement.iter_mut().for_each(|u| *u += offset);
        let sum: f64 = solved.f.iter().sum();
        Ok(AnchorResponse {
            traction,
            displacement,
            offset: offset - self.compliance.scale * self.compliance.shift * sum,
            report: self.set_report(&solved.outcome, (sum * self.grid.cell_area()).abs()),
        })
    }

    /// The report of one linear set solve (no active-set iterations beyond the one set).
    fn set_report(&self, outcome: &PcgOutcome, force_balance_error: f64) -> SolveReport {
        SolveReport {
            backend: self.backend,
            active_set_iterations: 1,
            linear_iterations: outcome.iterations,
            flips: 0,
            residual: outcome.residual,
            force_balance_error,
            complementarity: 0.0,
            fallback: false,
        }
    }

    /// The set solve both tangential solves share (on an interface the caller checked):
    /// `(C_SS + diag(1/k_x)) f + U = b`, `Σ f = total` on the attached set, `b_i =
    /// rhs(i)`, warm-started from (and leaving its tractions in) the warm start `warm`.
    /// Returns the tractions per cell (zero off the set) and the solve.
    fn solve_tangential_set(
        &mut self,
        interface: &Interface,
        normal_displacement: &[f64],
        rhs: impl Fn(usize) -> f64,
        total: f64,
        warm: Warm,
    ) -> Result<(Vec<f64>, SetSolve)> {
        let n = self.grid.len();
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
        let b: Vec<f64> = set.iter().map(|&i| rhs(i)).collect();
        let slot = match warm {
            Warm::Unit => &mut self.warm_tangential,
            Warm::Anchor => &mut self.warm_anchor,
        };
        let mut warm_full = std::mem::take(slot);
        if warm_full.len() != n {
            warm_full = vec![0.0; n];
        }
        let start: Vec<f64> = set.iter().map(|&i| warm_full[i]).collect();
        let problem = SetProblem {
            set: &set,
            d: &diag,
            b: &b,
            total,
        };
        let kind = SolveKind {
            explore: false,
            tangential: true,
            cold: false,
        };
        let solved = self.solve_set(kind, problem, start)?;
        let mut traction = vec![0.0; n];
        for (a, &i) in set.iter().enumerate() {
            traction[i] = solved.f[a];
        }
        warm_full.copy_from_slice(&traction);
        match warm {
            Warm::Unit => self.warm_tangential = warm_full,
            Warm::Anchor => self.warm_anchor = warm_full,
        }
        Ok((traction, solved))
    }
}

#[cfg(test)]
mod tests;
