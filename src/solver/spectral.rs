//! The spectral backend: `C` applied through the plan's staged 2-D DCT product, projected
//! CG preconditioned by Jacobi, FSAI or the restricted full-grid inverse. Memory `O(N)`:
//! no `N x N` matrix is ever formed. The dense backend uses the same product.

use super::coarse::Coarse;
use super::fsai::{Entries, Fsai};
use super::parallel::Parallelism;
use super::pcg::{projected_pcg, Effort, PcgVectors};
use super::set::{SetProblem, SetSolve};
use super::system::{Compliance, FsaiBuffers, Preconditioner, StagedSystem};
use crate::error::Result;
use crate::green::{InfluencePlan, Partition, SpectralTable, Staging};

/// Pattern radius (cells) of the FSAI preconditioner. Measured on the N = 1e4 run (first
/// 1000 ruptures, warm normal solves): Jacobi 68.3 CG iterations, 13.3 ms per solve;
/// radius 1: 37.6, 9.6 ms; radius 2: 27.4, 9.9 ms (its `Gᵀ G` costs 2.2x radius 1's).
pub(crate) const FSAI_RADIUS: usize = 1;

/// Fewest cells for the two-level preconditioner of the normal equilibrium. Measured on
/// the rod-driven runs of `examples/large_run` (docs/performance.md, "A two-level
/// preconditioner"): at N = 1e4 it cuts the CG iterations per normal solve from 32 to 13,
/// but each costs two operator products and the coarse matrix is rebuilt as the set
/// changes, so the solve is about 10 % slower; at N = 1e5 the iterations fall from 57 to
/// 14 and the solve is 1.18x faster.
const TWO_LEVEL_MIN_CELLS: usize = 32_768;

/// The preconditioner of a warm solve on a grid of `cells` cells: for the normal
/// equilibrium FSAI (the compliances `1/k_z` and most of the set are unchanged between
/// solves, so few rows are rebuilt), with a coarse space of aggregates on large grids
/// where FSAI's iteration count grows with `N`; Jacobi for the tangential one (every
/// `k_x` follows `u_z`, so every row would be rebuilt per solve, and the larger `1/k_x`
/// leaves Jacobi at about 20 iterations: FSAI radius 2 gave 16.8 iterations but 9.1 ms
/// against 4.2 ms per solve).
pub(crate) fn warm_precond(tangential: bool, cells: usize) -> Precond {
    if tangential {
        Precond::Jacobi
    } else if cells >= TWO_LEVEL_MIN_CELLS {
        Precond::TwoLevel
    } else {
        Precond::Fsai
    }
}

/// The mean compliance `d̄` to rebuild the spectral preconditioner's table for, when the
/// table built for `built` (`None`: none yet) is stale for the set's compliances `d`:
/// when `d̄` moved by more than 5 %. The one rule of both machines (`SpectralCore`,
/// `cuda::CudaCore`): the table is a function of `d̄` alone, so the same `d̄` gives the
/// same preconditioner on either.
pub(crate) fn stale_mean(built: Option<f64>, d: &[f64]) -> Option<f64> {
    let mean_d = d.iter().sum::<f64>() / d.len().max(1) as f64;
    let stale = match built {
        Some(old) => (old - mean_d).abs() > 0.05 * mean_d.abs().max(f64::MIN_POSITIVE),
        None => true,
    };
    stale.then_some(mean_d)
}

/// The spectral backend's rule (its preconditioner choices, their state kept between
/// solves, the set solve) as one machine runs it: [`SpectralCore`] on the host's
/// threads, `cuda::CudaCore` on a GPU. The solver holds either behind this one seam
/// (`Core::Spectral`), so `solver/mod.rs` has no code of its own per machine.
pub(crate) trait SpectralRule: Send + Sync {
    /// Solves `problem` with `precond`; `f` holds the warm start.
    fn solve(
        &mut self,
        problem: SetProblem<'_>,
        precond: Precond,
        f: Vec<f64>,
        effort: Effort,
    ) -> Result<SetSolve>;
    /// The `d̄` of the spectral preconditioner's table, if one was built (checkpoints).
    fn preconditioner_mean(&self) -> Option<f64>;
    /// Rebuilds the spectral preconditioner's table for `d̄` (or drops it): a restored
    /// solver preconditions as before.
    fn restore_preconditioner(&mut self, mean: Option<f64>) -> Result<()>;
    /// The parts of the grid a solve runs over (the threads it may use).
    fn parts(&self) -> usize;
    /// Whether a preconditioner is built (they are built on first use only).
    #[cfg(test)]
    fn built(&self) -> bool;
}

impl SpectralRule for SpectralCore {
    fn solve(
        &mut self,
        problem: SetProblem<'_>,
        precond: Precond,
        f: Vec<f64>,
        effort: Effort,
    ) -> Result<SetSolve> {
        SpectralCore::solve(self, problem, precond, f, effort)
    }
    fn preconditioner_mean(&self) -> Option<f64> {
        SpectralCore::preconditioner_mean(self)
    }
    fn restore_preconditioner(&mut self, mean: Option<f64>) -> Result<()> {
        SpectralCore::restore_preconditioner(self, mean);
        Ok(())
    }
    fn parts(&self) -> usize {
        SpectralCore::parts(self)
    }
    #[cfg(test)]
    fn built(&self) -> bool {
        SpectralCore::built(self)
    }
}

/// Preconditioner of a spectral solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Precond {
    /// The mean diagonal of `C` plus `d`.
    Jacobi,
    /// The restricted full-grid inverse `(C_s + d̄ I)⁻¹`.
    Spectral,
    /// The factorised sparse approximate inverse ([`Fsai`], cached between solves).
    Fsai,
    /// FSAI and a coarse space of aggregates ([`Coarse`]).
    TwoLevel,
}

/// Buffers and preconditioners of the spectral product, kept between solves.
#[derive(Debug)]
pub(crate) struct SpectralCore {
    plan: InfluencePlan,
    compliance: Compliance,
    /// Mean diagonal of `C_s` (m/Pa): the Jacobi preconditioner's elastic part.
    diag_c: f64,
    staging: Staging,
    /// The spectral preconditioner's buffers, its table and the `d̄` it was built for.
    inverse: Option<(Staging, f64, SpectralTable)>,
    /// Exact local entries of `C_s` (built on first use), the FSAI factor and buffers.
    entries: Option<Entries>,
    fsai: Option<(Fsai, FsaiBuffers)>,
    /// The coarse space and the buffers of its products.
    coarse: Option<(Coarse, Staging)>,
    /// The CG's vectors (a lock: the dense backend solves through `&self`).
    vectors: std::sync::Mutex<PcgVectors>,
}

impl SpectralCore {
    /// Whether a preconditioner (FSAI, its local entries, the spectral inverse) is built.
    #[cfg(test)]
    pub(crate) fn built(&self) -> bool {
        self.inverse.is_some() || self.entries.is_some() || self.fsai.is_some()
    }

    /// On `partition` (the plan's own for the spectral backend, one part for the dense).
    pub(crate) fn new(plan: &InfluencePlan, compliance: Compliance, partition: Partition) -> Self {
        let diag_c = compliance.mean_diagonal(plan);
        Self {
            staging: Staging::new(plan, partition),
            plan: plan.clone(),
            compliance,
            diag_c,
            inverse: None,
            entries: None,
            fsai: None,
            coarse: None,
            vectors: Default::default(),
        }
    }

    /// `out = C_s x` over every cell, `x` given on `set` (a whole-grid product: the
    /// tests' independent check of the staged one).
    #[cfg(test)]
    pub(crate) fn apply_full(&self, set: &[usize], x: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        let mut sum = 0.0;
        for (&i, &xi) in set.iter().zip(x) {
            out[i] = xi;
            sum += xi;
        }
        let mut scratch = vec![0.0; self.plan.scratch_len()];
        self.plan
            .filter_in_place(self.plan.operator_table(), out, &mut scratch);
        let (s, c) = (self.compliance.scale, self.compliance.shift * sum);
        out.iter_mut().for_each(|o| *o = s * (*o - c));
    }

    /// Builds the table of `(C_s + d̄ I)⁻¹` for `d̄ = mean_d`.
    fn build_inverse(&mut self, mean_d: f64) {
        let (compliance, n) = (self.compliance, self.plan.grid().len());
        let table = self
            .plan
            .spectral_table(|p, m, eigen| 1.0 / (compliance.eigenvalue(n, p, m, eigen) + mean_d));
        let staging = match self.inverse.take() {
            Some((staging, _, _)) => staging,
            None => Staging::new(&self.plan, self.staging.partition().clone()),
        };
        self.inverse = Some((staging, mean_d, table));
    }

    /// The parts of the grid a solve runs over.
    pub(crate) fn parts(&self) -> usize {
        self.staging.partition().parts()
    }

    /// The `d̄` of the spectral preconditioner's table, if one was built (checkpoints).
    pub(crate) fn preconditioner_mean(&self) -> Option<f64> {
        self.inverse.as_ref().map(|(_, d, _)| *d)
    }

    /// Rebuilds the spectral preconditioner's table for `d̄` (or drops it): the table is a
    /// function of `d̄` alone, so a restored solver preconditions bit for bit as before.
    pub(crate) fn restore_preconditioner(&mut self, mean: Option<f64>) {
        match mean {
            Some(d) => self.build_inverse(d),
            None => self.inverse = None,
        }
    }

    /// Brings the preconditioner `precond` up to date for `set` with compliances `d`:
    /// FSAI rows around changed sites; the spectral table when the mean compliance moved
    /// by more than 5 %. `C` is diagonal in the DCT basis, so the spectral preconditioner
    /// costs a second staged product per iteration and halves the iterations: it pays on
    /// cold, far-from-solution solves of large grids (docs/performance.md). The coarse
    /// space's upkeep runs on `parallelism`'s threads.
    fn prepare(
        &mut self,
        set: &[usize],
        d: &[f64],
        precond: Precond,
        parallelism: Parallelism,
    ) -> Result<()> {
        match precond {
            Precond::Fsai | Precond::TwoLevel => {
                let Compliance { scale, shift, .. } = self.compliance;
                let entries = match &mut self.entries {
                    Some(entries) => entries,
                    slot => slot.insert(Entries::new(&self.plan, scale, shift, parallelism)?),
                };
                let grid = self.plan.grid();
                let partition = self.staging.partition();
                let (fsai, _) = self.fsai.get_or_insert_with(|| {
                    let fsai = Fsai::new(grid.nx(), grid.len(), FSAI_RADIUS);
                    let buffers = FsaiBuffers::new(partition, fsai.halo());
                    (fsai, buffers)
                });
                fsai.update(entries, set, d);
                if precond == Precond::TwoLevel {
                    let (coarse, _) = self.coarse.get_or_insert_with(|| {
                        let coarse = Coarse::new(grid.nx(), grid.ny(), partition.parts());
                        (coarse, Staging::new(&self.plan, partition.clone()))
                    });
                    // A failed update may leave `E` half built: dropped, rebuilt next time.
                    if let Err(e) = coarse.update(entries, set, d, parallelism) {
                        self.coarse = None;
                        return Err(e);
                    }
                }
            }
            Precond::Spectral => {
                if let Some(mean_d) = stale_mean(self.preconditioner_mean(), d) {
                    self.build_inverse(mean_d);
                }
            }
            Precond::Jacobi => {}
        }
        Ok(())
    }

    /// Solves `problem` with `precond`; `f` holds the warm start.
    pub(crate) fn solve(
        &mut self,
        problem: SetProblem<'_>,
        precond: Precond,
        f: Vec<f64>,
        effort: Effort,
    ) -> Result<SetSolve> {
        self.prepare(problem.set, problem.d, precond, effort.parallelism)?;
        let precond = match (precond, &self.fsai, &self.inverse) {
            (Precond::TwoLevel, Some((fsai, buffers)), _) => match &self.coarse {
                Some((coarse, staging)) => Preconditioner::TwoLevel {
                    fsai,
                    buffers,
                    coarse,
                    staging,
                },
                None => Preconditioner::Fsai { fsai, buffers },
            },
            (Precond::Fsai, Some((fsai, buffers)), _) => Preconditioner::Fsai { fsai, buffers },
            (Precond::Spectral, _, Some((staging, _, table))) => {
                Preconditioner::Spectral { staging, table }
            }
            _ => Preconditioner::Jacobi {
                diag_c: self.diag_c,
            },
        };
        self.solve_with(problem, precond, f, effort)
    }

    /// Solves `problem` with a given preconditioner (the dense backend's factor).
    pub(crate) fn solve_with(
        &self,
        problem: SetProblem<'_>,
        precond: Preconditioner<'_>,
        mut f: Vec<f64>,
        effort: Effort,
    ) -> Result<SetSolve> {
        let system = StagedSystem::new(
            &self.staging,
            self.plan.operator_table(),
            self.compliance,
            problem.set,
            problem.d,
            precond,
        );
        let mut vectors = super::lock(&self.vectors);
        let outcome = projected_pcg(
            &system,
            problem.b,
            &mut f,
            problem.total,
            effort,
            &mut vectors,
        )?;
        let mut grid_product = vec![0.0; self.plan.grid().len()];
        system.grid_product(system.input_sum(&f), &mut grid_product);
        Ok(SetSolve {
            f,
            outcome,
            grid_product,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::stale_mean;

    /// The 5 % rule at its edges: `|d̄ - built| > 0.05 |d̄|` (values by hand).
    #[test]
    fn the_table_is_stale_past_five_percent_of_the_mean() {
        // No table yet: always built, for the mean of d.
        assert_eq!(stale_mean(None, &[1.0, 3.0]), Some(2.0));
        // d̄ = 1.04: |1 - 1.04| = 0.04 <= 0.052, kept.
        assert_eq!(stale_mean(Some(1.0), &[1.0, 1.08]), None);
        // d̄ = 1.06: 0.06 > 0.053, rebuilt for 1.06.
        assert_eq!(stale_mean(Some(1.0), &[1.06, 1.06]), Some(1.06));
        // Downward: d̄ = 0.9: 0.1 > 0.045.
        assert_eq!(stale_mean(Some(1.0), &[0.9]), Some(0.9));
        // An empty set has d̄ = 0: a table for 0 is kept, another one rebuilt.
        assert_eq!(stale_mean(Some(0.0), &[]), None);
        assert_eq!(stale_mean(Some(1e-300), &[]), Some(0.0));
    }
}
