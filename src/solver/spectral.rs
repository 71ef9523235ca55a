//! Matrix-free spectral backend: `C` applied through the 2-D DCT of the
//! [`InfluencePlan`], projected CG with a diagonal (Jacobi) preconditioner. Memory `O(N)`:
//! no `N x N` matrix is ever formed.

use super::fsai::{Entries, Fsai};
use super::pcg::PcgOutcome;
use super::team::{SplitPrecond, Team};
use crate::green::InfluencePlan;
use std::sync::Arc;

/// Pattern radius (cells) of the FSAI preconditioner. Measured on the N = 1e4 run (first
/// 1000 ruptures, warm normal solves): Jacobi 68.3 CG iterations, 13.3 ms per solve;
/// radius 1: 37.6, 9.6 ms; radius 2: 27.4, 9.9 ms (its `Gᵀ G` costs 2.2x radius 1's).
const FSAI_RADIUS: usize = 1;

/// The preconditioner of a warm solve: FSAI for the normal equilibrium (the compliances
/// `1/k_z` and most of the set are unchanged between solves, so few rows are rebuilt);
/// Jacobi for the tangential one (every `k_x` follows `u_z`, so every row would be rebuilt
/// per solve, and the larger `1/k_x` leaves Jacobi at about 20 iterations: FSAI radius 2
/// gave 16.8 iterations but 9.1 ms against 4.2 ms per solve).
pub(crate) fn warm_precond(tangential: bool) -> Precond {
    if tangential {
        Precond::Jacobi
    } else {
        Precond::Fsai
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
}

/// Scratch and constants of the spectral backend.
#[derive(Debug)]
pub(crate) struct SpectralCore {
    plan: InfluencePlan,
    /// `C_s = scale (Ĝ - shift 11ᵀ)`.
    scale: f64,
    shift: f64,
    /// Mean diagonal of `C_s` (m/Pa): the preconditioner's elastic part.
    diag_c: f64,
    norm_c: f64,
    buf: Vec<f64>,
    /// DCT scratch.
    work: Vec<f64>,
    /// Filter table of `(C_s + d̄ I)⁻¹` and the `d̄` it was built for.
    inverse: Option<(f64, Vec<f64>)>,
    /// Exact local entries of `C_s` (built on first use) and the FSAI factors.
    entries: Option<Entries>,
    fsai: Option<Fsai>,
    /// The split CG (one or two threads, the same results).
    team: Team,
}

impl SpectralCore {
    pub(crate) fn new(
        plan: InfluencePlan,
        scale: f64,
        shift: f64,
        norm_c: f64,
        pool: Option<Arc<rayon::ThreadPool>>,
    ) -> Self {
        let n = plan.grid().len();
        let (nx, ny) = (plan.grid().nx(), plan.grid().ny());
        // trace(Ĝ) = Σ eigenvalues; the diagonal varies only near the edges.
        let mut trace = 0.0;
        for m in 0..ny {
            for p in 0..nx {
                trace += plan.eigenvalue(p, m).unwrap_or(0.0);
            }
        }
        let diag_c = scale * (trace / n as f64 - shift);
        Self {
            scale,
            shift,
            diag_c,
            norm_c,
            buf: vec![0.0; n],
            work: Vec::new(),
            inverse: None,
            entries: None,
            fsai: None,
            team: Team::new(&plan, pool),
            plan,
        }
    }

    /// `out = C_s x` over every site, `x` given on `set`.
    /// After a solve, `x` its solution, the transform is the one of the solve's last
    /// product (no product of its own).
    pub(crate) fn apply_full(&mut self, set: &[usize], x: &[f64], out: &mut [f64]) {
        let sum = match self.team.last_transform(set, x, out) {
            Some(sum) => sum,
            None => {
                out.fill(0.0);
                let mut sum = 0.0;
                for (&i, &xi) in set.iter().zip(x) {
                    out[i] = xi;
                    sum += xi;
                }
                self.plan.apply_in_place(out, &mut self.work);
                sum
            }
        };
        let s = self.scale;
        let c = self.shift * sum;
        out.iter_mut().for_each(|o| *o = s * (*o - c));
    }

    /// `y = (C_SS + diag(d)) x` on `set`.
    pub(crate) fn apply_set(&mut self, set: &[usize], diag: &[f64], x: &[f64], y: &mut [f64]) {
        let mut buf = std::mem::take(&mut self.buf);
        self.apply_full(set, x, &mut buf);
        for (a, &i) in set.iter().enumerate() {
            y[a] = buf[i] + diag[a] * x[a];
        }
        self.buf = buf;
    }

    /// Builds the filter table of `(C_s + d̄ I)⁻¹` for `d̄ = mean_d`.
    fn build_inverse(&mut self, mean_d: f64) {
        let (scale, shift, n) = (self.scale, self.shift, self.buf.len() as f64);
        let table = self.plan.spectral_table(|p, m, eigen| {
            let e = if p == 0 && m == 0 {
                eigen - shift * n
            } else {
                eigen
            };
            1.0 / (scale * e + mean_d)
        });
        self.inverse = Some((mean_d, table));
    }

    /// The `d̄` of the spectral preconditioner's table, if one was built (checkpoints).
    pub(crate) fn preconditioner_mean(&self) -> Option<f64> {
        self.inverse.as_ref().map(|(d, _)| *d)
    }

    /// Rebuilds the spectral preconditioner's table for `d̄` (or drops it): the table is a
    /// function of `d̄` alone, so a restored solver preconditions bit for bit as before.
    pub(crate) fn restore_preconditioner(&mut self, mean: Option<f64>) {
        match mean {
            Some(d) => self.build_inverse(d),
            None => self.inverse = None,
        }
    }

    /// Prepares the preconditioner of a solve on `set` with compliances `diag` and returns
    /// `‖A‖`'s bound. Jacobi (the mean diagonal of `C` plus `d`), FSAI (updated here for
    /// the set), or the full-grid inverse `(C_s + d̄ I)⁻¹` restricted to the set (`d̄` the
    /// mean compliance). `C` is diagonal in the DCT basis, so the latter costs a second
    /// transform pair per iteration and halves the iterations: it pays on cold,
    /// far-from-solution solves of large grids (measured in docs/performance.md).
    fn prepare(&mut self, set: &[usize], diag: &[f64], precond: Precond) -> f64 {
        let norm = self.norm_c + diag.iter().fold(0.0f64, |m, d| m.max(*d));
        if precond == Precond::Fsai {
            if self.entries.is_none() {
                self.entries = Some(Entries::new(&self.plan, self.scale, self.shift));
            }
            let (n, nx) = (self.buf.len(), self.plan.grid().nx());
            let fsai = self
                .fsai
                .get_or_insert_with(|| Fsai::new(nx, n, FSAI_RADIUS));
            if let Some(entries) = &self.entries {
                fsai.update(entries, set, diag);
            }
        }
        if precond == Precond::Spectral {
            let mean_d = diag.iter().sum::<f64>() / diag.len().max(1) as f64;
            let stale = match &self.inverse {
                Some((d, _)) => (d - mean_d).abs() > 0.05 * mean_d.abs().max(f64::MIN_POSITIVE),
                None => true,
            };
            if stale {
                self.build_inverse(mean_d);
            }
        }
        norm
    }

    /// Solves `A f + U 1 = b`, `1ᵀ f = total` on `set` with `A = C_SS + diag(diag)` by
    /// the split projected CG ([`Team`]); `f` holds the warm start on entry. The
    /// preconditioner is prepared by [`SpectralCore::prepare`].
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn solve(
        &mut self,
        set: &[usize],
        diag: &[f64],
        precond: Precond,
        b: &[f64],
        total: f64,
        f: &mut [f64],
        tol: f64,
        max_iterations: usize,
    ) -> PcgOutcome {
        let norm = self.prepare(set, diag, precond);
        let split = match (precond, &self.fsai, &self.inverse) {
            (Precond::Fsai, Some(fsai), _) => SplitPrecond::Fsai(fsai),
            (Precond::Spectral, _, Some((_, table))) => SplitPrecond::Spectral(table),
            _ => SplitPrecond::Jacobi {
                diag_c: self.diag_c,
            },
        };
        let constants = (self.scale, self.shift, norm);
        self.team.solve(
            &self.plan,
            constants,
            split,
            set,
            diag,
            b,
            total,
            f,
            tol,
            max_iterations,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Block, Grid};
    #[test]
    fn restricted_operator_is_symmetric() {
        let grid = Grid::new(Block::new(0.14, 0.007, 0.075).unwrap(), 140, 7).unwrap();
        let plan = InfluencePlan::builder(grid).build().unwrap();
        let mut core = SpectralCore::new(plan, 3.6e-16, 0.0, 1.0, None);
        let set: Vec<usize> = (0..980).filter(|i| i % 3 != 0).collect();
        let diag: Vec<f64> = set.iter().map(|i| 1e-15 * (*i as f64)).collect();
        let n = set.len();
        let x: Vec<f64> = (0..n).map(|i| ((i * 7919) % 101) as f64 - 50.0).collect();
        let y: Vec<f64> = (0..n).map(|i| ((i * 104729) % 97) as f64 - 48.0).collect();
        let mut ax = vec![0.0; n];
        let mut ay = vec![0.0; n];
        core.apply_set(&set, &diag, &x, &mut ax);
        core.apply_set(&set, &diag, &y, &mut ay);
        let a: f64 = y.iter().zip(&ax).map(|(p, q)| p * q).sum();
        let b: f64 = x.iter().zip(&ay).map(|(p, q)| p * q).sum();
        let xx: f64 = x.iter().zip(&ax).map(|(p, q)| p * q).sum();
        eprintln!("{a:e} {b:e} {xx:e}");
        assert!((a - b).abs() < 1e-12 * a.abs());
    }

    /// The split CG gives the same bits on one thread and on two, on every transform path
    /// (paired rows with matrix-product, paired-FFT and direct columns; rustdct rows), for
    /// every preconditioner; and its solution satisfies the equations when the residual is
    /// recomputed with the unsplit product (`apply_full`, an independent path).
    #[test]
    fn split_solve_is_thread_count_independent_and_solves() {
        let pool = Some(Arc::new(
            rayon::ThreadPoolBuilder::new()
                .num_threads(2)
                .build()
                .unwrap(),
        ));
        for (nx, ny) in [
            (60, 40),
            (24, 70),
            (21, 30),
            (30, 10),
            (15, 67),
            (1, 20),
            (20, 1),
            (3, 3),
        ] {
            let block = Block::new(nx as f64 * 1e-3, ny as f64 * 1e-3, 0.075).unwrap();
            let plan = InfluencePlan::builder(Grid::new(block, nx, ny).unwrap())
                .build()
                .unwrap();
            let n = nx * ny;
            let scale = 3.6e-16;
            let mut top = 0.0f64;
            for m in 0..ny {
                for q in 0..nx {
                    top = top.max(plan.eigenvalue(q, m).unwrap());
                }
            }
            let set: Vec<usize> = (0..n).filter(|i| (i * 7919 + 3) % 10 < 6).collect();
            let b: Vec<f64> = set.iter().map(|i| 1e-6 * (1.0 + (i % 7) as f64)).collect();
            for precond in [Precond::Jacobi, Precond::Fsai, Precond::Spectral] {
                let mut results = Vec::new();
                for pool in [None, pool.clone()] {
                    let mut core = SpectralCore::new(plan.clone(), scale, 0.0, scale * top, pool);
                    let d: Vec<f64> = set
                        .iter()
                        .map(|i| 0.05 * core.diag_c * (1.0 + (i % 3) as f64))
                        .collect();
                    let mut f = vec![0.0; set.len()];
                    let out = core.solve(&set, &d, precond, &b, 1e-3, &mut f, 1e-13, 5000);
                    assert!(out.converged, "{nx}x{ny} {precond:?}: {out:?}");
                    // Independent residual: the unsplit product.
                    let mut u = vec![0.0; n];
                    core.team.forget_last(); // the unsplit product, not the reuse
                    core.apply_full(&set, &f, &mut u);
                    let norm = core.norm_c + d.iter().fold(0.0f64, |m, x| m.max(*x));
                    let fmax = f.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    let bmax = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    let r = set
                        .iter()
                        .enumerate()
                        .map(|(a, &i)| (u[i] + d[a] * f[a] + out.offset - b[a]).abs())
                        .fold(0.0f64, f64::max);
                    let backward = r / (norm * fmax + bmax + out.offset.abs());
                    assert!(backward < 1e-12, "{nx}x{ny} {precond:?}: {backward:e}");
                    let mass: f64 = f.iter().map(|x| x.abs()).sum();
                    assert!((f.iter().sum::<f64>() - 1e-3).abs() < 1e-13 * mass);
                    results.push((out.iterations, out.offset.to_bits(), f));
                }
                let bits = |f: &[f64]| f.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(results[0].0, results[1].0, "{nx}x{ny} {precond:?}");
                assert_eq!(results[0].1, results[1].1, "{nx}x{ny} {precond:?}");
                assert_eq!(
                    bits(&results[0].2),
                    bits(&results[1].2),
                    "{nx}x{ny} {precond:?}"
                );
            }
        }
    }
}
