//! The tangential response: the shear tractions per newton of load at a fixed attached
//! set (linear in the load).

use super::options::{SolveReport, TangentialResponse};
use super::set::SetProblem;
use super::{EquilibriumSolver, SolveKind};
use crate::error::{check_slice, Error, Result};
use crate::interface::{Interface, SiteState};

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
            d: &diag,
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
        let mut displacement = solved.grid_product;
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
            offset_per_newton: offset - self.compliance.scale * self.compliance.shift * sum,
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
}
