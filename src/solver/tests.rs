//! Unit tests of the solver core: the one projected CG against a direct KKT solve, and
//! the parts-and-phases model against thread counts.

use super::parallel::Parallelism;
use super::pcg::Effort;
use super::set::SetProblem;
use super::spectral::{Precond, SpectralCore};
use super::system::Compliance;
use crate::geometry::{Block, Grid};
use crate::green::{InfluencePlan, Partition};
use faer::prelude::*;

/// Every crew tested: the results must be the same bits for each.
const CREWS: [Parallelism; 6] = [
    Parallelism::Sequential,
    Parallelism::Threads(2),
    Parallelism::Threads(3),
    Parallelism::Threads(4),
    Parallelism::Threads(8),
    Parallelism::CurrentPool,
];

fn plan(nx: usize, ny: usize) -> InfluencePlan {
    let block = Block::new(nx as f64 * 1e-3, ny as f64 * 1e-3, 0.075).unwrap();
    InfluencePlan::builder(Grid::new(block, nx, ny).unwrap())
        .build()
        .unwrap()
}

fn largest_eigenvalue(plan: &InfluencePlan) -> f64 {
    let (nx, ny) = (plan.grid().nx(), plan.grid().ny());
    let mut top = 0.0f64;
    for m in 0..ny {
        for q in 0..nx {
            top = top.max(plan.eigenvalue(q, m).unwrap());
        }
    }
    top
}

/// The compliance constants of the tests' grids (`C_s = scale Ĝ`, no shift).
fn compliance(plan: &InfluencePlan) -> Compliance {
    let scale = 3.6e-16;
    Compliance {
        scale,
        shift: 0.0,
        norm: scale * largest_eigenvalue(plan),
    }
}

/// A cold solve of `(C_SS + diag(d)) f + U 1 = b`, `Σ f = total` with `precond`.
#[allow(clippy::too_many_arguments)]
fn solve_cold(
    core: &mut SpectralCore,
    set: &[usize],
    d: &[f64],
    b: &[f64],
    total: f64,
    precond: Precond,
    tolerance: f64,
    parallelism: Parallelism,
) -> super::set::SetSolve {
    let problem = SetProblem { set, d, b, total };
    let effort = Effort {
        tolerance,
        max_iterations: 5000,
        parallelism,
    };
    core.solve(problem, precond, vec![0.0; set.len()], effort)
        .unwrap()
}

/// The projected CG's solution of `(C_SS + D) f + U 1 = b`, `Σ f = total` equals the
/// solution of the bordered (KKT) system assembled from `InfluencePlan::dense` (explicit
/// cosine sums, not the DCT) and solved by faer's LU: an independent path.
#[test]
fn pcg_solution_equals_direct_kkt_solve() {
    let plan = plan(12, 10);
    let n = 120;
    let scale = 3.6e-16;
    let compliance = Compliance {
        scale,
        shift: 0.0,
        norm: scale * largest_eigenvalue(&plan),
    };
    let set: Vec<usize> = (0..n).filter(|i| (i * 7919 + 3) % 10 < 6).collect();
    let m = set.len();
    let mut core = SpectralCore::new(&plan, compliance, Partition::of(&plan));
    let d: Vec<f64> = set
        .iter()
        .map(|i| 0.05 * compliance.norm * (1.0 + (i % 3) as f64))
        .collect();
    let b: Vec<f64> = set.iter().map(|i| 1e-6 * (1.0 + (i % 7) as f64)).collect();
    let total = 1e-3;
    let g = plan.dense().unwrap();
    let kkt = faer::Mat::from_fn(m + 1, m + 1, |r, c| match (r < m, c < m) {
        (true, true) => scale * g[set[r] * n + set[c]] + if r == c { d[r] } else { 0.0 },
        (false, false) => 0.0,
        _ => 1.0,
    });
    let rhs = faer::Mat::from_fn(m + 1, 1, |r, _| if r < m { b[r] } else { total });
    let direct = kkt.full_piv_lu().solve(&rhs);
    for precond in [
        Precond::Jacobi,
        Precond::Fsai,
        Precond::Spectral,
        Precond::TwoLevel,
    ] {
        let solved = solve_cold(
            &mut core,
            &set,
            &d,
            &b,
            total,
            precond,
            1e-14,
            Parallelism::Sequential,
        );
        assert!(solved.outcome.converged, "{precond:?}");
        let fmax = (0..m).fold(0.0f64, |a, r| a.max(direct[(r, 0)].abs()));
        for r in 0..m {
            let err = (solved.f[r] - direct[(r, 0)]).abs();
            assert!(err <= 1e-9 * fmax, "{precond:?} site {r}: {err:e}");
        }
        let u = direct[(m, 0)];
        assert!(
            (solved.outcome.offset - u).abs() <= 1e-9 * u.abs(),
            "{precond:?}"
        );
    }
}

/// The CG gives the same bits for 1, 2, 3, 4, 8 threads and the current pool, on every
/// transform path (paired rows with matrix-product, paired-FFT and direct columns; rustdct
/// rows) and with every preconditioner; and its solution satisfies the equations when the
/// residual is recomputed with the whole-grid product (not the staged one).
#[test]
fn solves_are_thread_count_independent_and_solve() {
    for (nx, ny) in [
        (60, 40),
        (24, 70),
        (21, 30),
        (64, 130),
        (15, 67),
        (1, 20),
        (20, 1),
        (3, 3),
    ] {
        let plan = plan(nx, ny);
        let n = nx * ny;
        let scale = 3.6e-16;
        let compliance = Compliance {
            scale,
            shift: 0.0,
            norm: scale * largest_eigenvalue(&plan),
        };
        let set: Vec<usize> = (0..n).filter(|i| (i * 7919 + 3) % 10 < 6).collect();
        let b: Vec<f64> = set.iter().map(|i| 1e-6 * (1.0 + (i % 7) as f64)).collect();
        for precond in [
            Precond::Jacobi,
            Precond::Fsai,
            Precond::Spectral,
            Precond::TwoLevel,
        ] {
            let mut results = Vec::new();
            for par in CREWS {
                let mut core = SpectralCore::new(&plan, compliance, Partition::of(&plan));
                let d: Vec<f64> = set
                    .iter()
                    .map(|i| 0.05 * compliance.norm * (1.0 + (i % 3) as f64))
                    .collect();
                let solved = solve_cold(&mut core, &set, &d, &b, 1e-3, precond, 1e-13, par);
                let out = solved.outcome;
                assert!(out.converged, "{nx}x{ny} {precond:?}: {out:?}");
                let f = solved.f;
                // Independent residual: the whole-grid product.
                let mut u = vec![0.0; n];
                core.apply_full(&set, &f, &mut u);
                let norm = compliance.norm + d.iter().fold(0.0f64, |m, x| m.max(*x));
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
                // The grid product the solve hands out is C f.
                let worst = solved
                    .grid_product
                    .iter()
                    .zip(&u)
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                let umax = u.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                assert!(worst <= 1e-13 * umax, "{nx}x{ny} {precond:?}: {worst:e}");
                let bits: Vec<u64> = f.iter().map(|x| x.to_bits()).collect();
                results.push((par, out.iterations, out.offset.to_bits(), bits));
            }
            for r in &results[1..] {
                assert_eq!(results[0].1, r.1, "{nx}x{ny} {precond:?} {:?}", r.0);
                assert_eq!(results[0].2, r.2, "{nx}x{ny} {precond:?} {:?}", r.0);
                assert!(results[0].3 == r.3, "{nx}x{ny} {precond:?} {:?}", r.0);
            }
        }
    }
}

/// The coarse space removes the iterations a local preconditioner spends on the set's
/// slow modes: on a 256 x 64 grid with a porous set, the two-level solve needs well under
/// half of FSAI's iterations to the same tolerance (about 3x fewer when it works; a
/// coarse correction that is skipped or wrong leaves FSAI's count or fails to converge).
#[test]
fn two_level_needs_far_fewer_iterations_than_fsai() {
    let plan = plan(256, 64);
    let n = 256 * 64;
    let compliance = compliance(&plan);
    let set: Vec<usize> = (0..n).filter(|i| (i * 7919 + 3) % 10 < 4).collect();
    let b: Vec<f64> = set.iter().map(|i| 1e-6 * (1.0 + (i % 7) as f64)).collect();
    // Compliances as the springs' here: about 1/16 of C's diagonal.
    let d = vec![0.06 * compliance.norm; set.len()];
    let mut iterations = Vec::new();
    for precond in [Precond::Fsai, Precond::TwoLevel] {
        let mut core = SpectralCore::new(&plan, compliance, Partition::of(&plan));
        let solved = solve_cold(
            &mut core,
            &set,
            &d,
            &b,
            1e-3,
            precond,
            1e-13,
            Parallelism::Sequential,
        );
        assert!(solved.outcome.converged, "{precond:?}");
        iterations.push(solved.outcome.iterations);
    }
    assert!(2 * iterations[1] < iterations[0], "{iterations:?}");
}
