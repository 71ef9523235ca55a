//! The backend's own launch code run on the host emulator (`emulator.rs`: kernels.cu
//! compiled by the C++ compiler, blocks of 1, 4 and the device's 256 threads, several
//! blocks at once, cuFFT's layout by direct DFTs). Each result is compared with an
//! independent one: the dense `Ĝ` (`InfluencePlan::dense`, explicit cosine sums), plain
//! sums, the host's own FSAI factor, coarse space and spectral backend.

use super::emulator::{Emulator, Step, VARIANTS};
use super::kernels::{Kernel, THREADS};
use super::phases::DevicePhases;
use super::seam::Device;
use super::CudaCore;
use crate::error::Error;
use crate::geometry::{Block, Grid};
use crate::green::{InfluencePlan, Partition};
use crate::solver::parallel::Parallelism;
use crate::solver::pcg::{Effort, Main, Phase, PhaseRunner, Pre};
use crate::solver::set::SetProblem;
use crate::solver::spectral::{Precond, SpectralCore};
use crate::solver::system::Compliance;

/// Deterministic values in (-1, 1).
fn values(count: usize, seed: u64) -> Vec<f64> {
    let mut state = seed;
    (0..count)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
        .collect()
}

fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs() / scale))
}

/// `nx x ny` cells of 1 mm under a block `lz` (m) tall, and its plan.
fn planned(nx: usize, ny: usize, lz: f64) -> (Grid, InfluencePlan) {
    let block = Block::new(nx as f64 * 1e-3, ny as f64 * 1e-3, lz).unwrap();
    let grid = Grid::new(block, nx, ny).unwrap();
    (grid, InfluencePlan::builder(grid).build().unwrap())
}

/// A core on a fresh emulator of `threads` threads per block.
fn core(threads: u32, plan: &InfluencePlan, compliance: Compliance) -> CudaCore<Emulator> {
    CudaCore::on(Emulator::new(threads), plan, compliance).unwrap()
}

/// The first `len` values of a device buffer.
fn read(
    core: &CudaCore<Emulator>,
    buffer: &<Emulator as Device>::Buffer<f64>,
    len: usize,
) -> Vec<f64> {
    let mut out = vec![0.0; len];
    core.device.dtoh("test", buffer, &mut out).unwrap();
    out
}

/// Runs one phase of a solve of `m` sites.
fn run(
    core: &mut CudaCore<Emulator>,
    precond: Precond,
    m: usize,
    pre: Pre,
    main: Main,
) -> [f64; 3] {
    let mut phases: DevicePhases<'_, Emulator> = core.phases(precond, m, 1.0);
    phases.run(Phase { pre, main }).unwrap()
}

/// `C_s x` on every cell by the dense matrix: `scale (Ĝ x - shift Σx)`.
fn dense_product(plan: &InfluencePlan, compliance: Compliance, x: &[f64]) -> Vec<f64> {
    let g = plan.dense().unwrap();
    let n = x.len();
    let sum: f64 = x.iter().sum();
    (0..n)
        .map(|i| {
            let gx: f64 = (0..n).map(|k| g[i * n + k] * x[k]).sum();
            compliance.scale * (gx - compliance.shift * sum)
        })
        .collect()
}

const GRIDS: [(usize, usize); 4] = [(7, 5), (8, 6), (6, 1), (5, 4)];

/// The residual `r = A f + U - b` (the product's FFTs and kernels, then residual_tail),
/// `q = A p` and `pᵀ q`, the grid product `C_s f`, Jacobi's `z = r / (diag_c + d)` and
/// `Σ z`, and the measure `[max |r|, max |f|, rᵀ z]`, as the phases run them, against the
/// dense `Ĝ` and plain sums.
#[test]
fn the_products_residual_and_jacobi_are_the_dense_ones() {
    let compliance = Compliance {
        scale: 2.5e-9,
        shift: 0.3,
        norm: 0.0,
    };
    for threads in VARIANTS {
        for (nx, ny) in GRIDS {
            let (grid, plan) = planned(nx, ny, 0.01);
            let n = grid.len();
            let mut core = core(threads, &plan, compliance);
            // Every other cell is in the set.
            let set: Vec<usize> = (0..n).step_by(2).collect();
            let m = set.len();
            let x_all = values(n, 1);
            let x: Vec<f64> = set.iter().map(|&i| x_all[i]).collect();
            let d: Vec<f64> = values(m, 2).iter().map(|v| v.abs() * 1e-9).collect();
            let b = values(m, 3);
            let problem = SetProblem {
                set: &set,
                d: &d,
                b: &b,
                total: 0.0,
            };
            core.upload_problem(problem, &x).unwrap();
            let offset = 0.37;
            run(
                &mut core,
                Precond::Jacobi,
                m,
                Pre::default(),
                Main::Residual {
                    stage: 0,
                    carry: 0.0,
                    offset,
                },
            );
            let mut on_grid = vec![0.0; n];
            for (&i, &xi) in set.iter().zip(&x) {
                on_grid[i] = xi;
            }
            let grid_ref = dense_product(&plan, compliance, &on_grid);
            let r_ref: Vec<f64> = (0..m)
                .map(|j| grid_ref[set[j]] + d[j] * x[j] + offset - b[j])
                .collect();
            let r = read(&core, &core.vectors.r, m);
            let e = max_rel(&r, &r_ref);
            assert!(e < 1e-12, "{threads} threads, {nx} x {ny}: r off by {e:e}");
            // The grid product of f.
            core.grid_product().unwrap();
            let e = max_rel(&read(&core, &core.grid, n), &grid_ref);
            assert!(
                e < 1e-12,
                "{threads} threads, {nx} x {ny}: C_s f off by {e:e}"
            );
            // q = A p, pᵀ q.
            let p = values(m, 4);
            core.device.htod("test", &p, &mut core.vectors.p).unwrap();
            let [pq, _, _] = run(
                &mut core,
                Precond::Jacobi,
                m,
                Pre::default(),
                Main::Direction {
                    stage: 0,
                    carry: 0.0,
                },
            );
            let mut p_grid = vec![0.0; n];
            for (&i, &pi) in set.iter().zip(&p) {
                p_grid[i] = pi;
            }
            let ap = dense_product(&plan, compliance, &p_grid);
            let q_ref: Vec<f64> = (0..m).map(|j| ap[set[j]] + d[j] * p[j]).collect();
            let q = read(&core, &core.vectors.q, m);
            assert!(max_rel(&q, &q_ref) < 1e-12, "{threads} threads: q");
            let pq_ref: f64 = p.iter().zip(&q_ref).map(|(a, b)| a * b).sum();
            assert!((pq - pq_ref).abs() <= 1e-12 * q_ref.iter().map(|v| v.abs()).sum::<f64>());
            // Jacobi on r, and Σ z.
            let [sum_z, _, _] = run(
                &mut core,
                Precond::Jacobi,
                m,
                Pre::default(),
                Main::Precondition {
                    stage: 0,
                    carry: 0.0,
                },
            );
            let z_ref: Vec<f64> = (0..m).map(|j| r_ref[j] / (core.diag_c + d[j])).collect();
            let z = read(&core, &core.vectors.z, m);
            assert!(max_rel(&z, &z_ref) < 1e-12, "{threads} threads: jacobi");
            let sum_ref: f64 = z_ref.iter().sum();
            let abs: f64 = z_ref.iter().map(|v| v.abs()).sum();
            assert!((sum_z - sum_ref).abs() <= 1e-12 * abs, "{sum_z} {sum_ref}");
            // [max |r|, max |f|, rᵀ z].
            let measure = run(&mut core, Precond::Jacobi, m, Pre::default(), Main::Measure);
            let max = |a: &[f64]| a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert_eq!((measure[0], measure[1]), (max(&r), max(&x)));
            let rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
            assert!((measure[2] - rz).abs() <= 1e-12 * rz.abs());
        }
    }
}

/// The reductions over many blocks (the first pass's grid of blocks, the final block's
/// tree), against plain sums and maxima; blocks run several at once.
#[test]
fn the_reductions_over_many_blocks_are_plain_sums() {
    let (grid, plan) = planned(50, 40, 0.02);
    let n = grid.len();
    let compliance = Compliance {
        scale: 1e-9,
        shift: 0.1,
        norm: 0.0,
    };
    for threads in VARIANTS {
        let mut core = core(threads, &plan, compliance);
        for m in [n, 1, 777] {
            let (f, r, z) = (values(m, 5), values(m, 6), values(m, 7));
            let v = &mut core.vectors;
            core.device.htod("test", &f, &mut v.f).unwrap();
            core.device.htod("test", &r, &mut v.r).unwrap();
            core.device.htod("test", &z, &mut v.z).unwrap();
            let [sum, _, _] = run(&mut core, Precond::Jacobi, m, Pre::default(), Main::SumF);
            let abs: f64 = f.iter().map(|v| v.abs()).sum();
            assert!((sum - f.iter().sum::<f64>()).abs() <= 1e-13 * abs);
            let measure = run(&mut core, Precond::Jacobi, m, Pre::default(), Main::Measure);
            let max = |a: &[f64]| a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert_eq!((measure[0], measure[1]), (max(&r), max(&f)));
            let rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
            assert!(
                (measure[2] - rz).abs() <= 1e-13 * m as f64,
                "{threads} threads, m {m}"
            );
        }
        if threads == 1 {
            // 1024 blocks of one thread ran on the emulator's lanes: some at once.
            assert!(
                core.device.most_in_flight() >= 2,
                "blocks ran one at a time"
            );
        }
    }
}

/// The spectral preconditioner's table applied to `(C_s + d̄ I) x` on the whole grid
/// gives `x` back (its own FFTs and kernels, through the phases' preconditioner).
#[test]
fn the_spectral_table_inverts_the_full_grid_system() {
    let compliance = Compliance {
        scale: 1e-9,
        shift: 0.1,
        norm: 0.0,
    };
    for threads in VARIANTS {
        for (nx, ny) in GRIDS {
            let (grid, plan) = planned(nx, ny, 0.02);
            let n = grid.len();
            let mean_d = 3e-10;
            let x = values(n, 3);
            let y: Vec<f64> = dense_product(&plan, compliance, &x)
                .iter()
                .zip(&x)
                .map(|(c, xi)| c + mean_d * xi)
                .collect();
            let mut core = core(threads, &plan, compliance);
            core.build_inverse(mean_d).unwrap();
            let set: Vec<usize> = (0..n).collect();
            let zeros = vec![0.0; n];
            let problem = SetProblem {
                set: &set,
                d: &zeros,
                b: &zeros,
                total: 0.0,
            };
            core.upload_problem(problem, &zeros).unwrap();
            core.device.htod("test", &y, &mut core.vectors.r).unwrap();
            run(
                &mut core,
                Precond::Spectral,
                n,
                Pre::default(),
                Main::Precondition {
                    stage: 0,
                    carry: 0.0,
                },
            );
            let e = max_rel(&read(&core, &core.vectors.z, n), &x);
            assert!(e < 1e-11, "{threads} threads, {nx} x {ny}: off by {e:e}");
        }
    }
}

/// Every phase's local updates as pcg.rs applies them on the host (`Pre::apply`, the
/// reference) and as the phases apply them on the device, for updates the CG combines.
#[test]
fn the_local_updates_are_the_hosts() {
    use crate::solver::pcg::apply_pre;
    let (_, plan) = planned(6, 5, 0.02);
    let compliance = Compliance {
        scale: 1e-9,
        shift: 0.1,
        norm: 0.0,
    };
    let m = 23;
    let combos = [
        Pre {
            keep_best: true,
            shift_f: Some(0.25),
            step: Some((0.7, true)),
            project: Some(-1.5),
            direction: Some(Some(0.3)),
            ..Pre::default()
        },
        Pre {
            restore_best: true,
            step: Some((-0.2, false)),
            w_from_z: true,
            direction: Some(None),
            ..Pre::default()
        },
        Pre {
            fill_r_one: true,
            project: Some(2.0),
            ..Pre::default()
        },
    ];
    for threads in VARIANTS {
        let mut core = core(threads, &plan, compliance);
        for (k, pre) in combos.into_iter().enumerate() {
            let mut host: Vec<Vec<f64>> = (0..7).map(|v| values(m, 10 * k as u64 + v)).collect();
            {
                let v = &mut core.vectors;
                let device = &core.device;
                for (vector, buffer) in host.iter().zip([
                    &mut v.f,
                    &mut v.r,
                    &mut v.z,
                    &mut v.p,
                    &mut v.q,
                    &mut v.w,
                    &mut v.best,
                ]) {
                    device.htod("test", vector, buffer).unwrap();
                }
            }
            run(&mut core, Precond::Jacobi, m, pre, Main::Nothing);
            apply_pre(pre, &mut host);
            let v = &core.vectors;
            for (name, (vector, buffer)) in ["f", "r", "z", "p", "q", "w", "best"].iter().zip(
                host.iter()
                    .zip([&v.f, &v.r, &v.z, &v.p, &v.q, &v.w, &v.best]),
            ) {
                let device = read(&core, buffer, m);
                for j in 0..m {
                    let (h, d) = (vector[j], device[j]);
                    assert!(
                        (h - d).abs() <= 1e-15 * h.abs().max(1.0),
                        "{threads} threads, combination {k}, {name}[{j}]: host {h}, device {d}"
                    );
                }
            }
        }
    }
}

/// FSAI on the device, as a solve prepares it: the host's factor for a first set (the
/// planes copied), then for a second set (only the refreshed rows copied and scattered),
/// applied by fsai_g and fsai_gt through the phases' preconditioner, against the host's
/// own `Fsai::apply` of a factor updated the same way (fsai.rs, tested against its dense
/// rows). A missed row makes the device's copy stale and fails it.
#[test]
fn the_fsai_kernels_apply_the_hosts_factor_after_its_updates() {
    use crate::solver::fsai::{Entries, Fsai};
    for threads in VARIANTS {
        for (nx, ny) in [(16, 12), (9, 7), (6, 1)] {
            let (grid, plan) = planned(nx, ny, 0.02);
            let n = grid.len();
            let compliance = Compliance {
                scale: 3.6e-16,
                shift: 1e-3,
                norm: 0.0,
            };
            let entries = Entries::new(
                &plan,
                compliance.scale,
                compliance.shift,
                Parallelism::Sequential,
            )
            .unwrap();
            let first: Vec<usize> = (0..n).filter(|i| (i * 7919 + 3) % 10 < 6).collect();
            let d_of = |set: &[usize], bump: usize| -> Vec<f64> {
                set.iter()
                    .map(|&i| 1e-13 * (1.0 + (i % 3) as f64) * if i == bump { 1.5 } else { 1.0 })
                    .collect()
            };
            // The second set: two sites leave, two join, one compliance changes.
            let mut second: Vec<usize> = first.clone();
            second.retain(|&i| i != first[1] && i != first[first.len() / 2]);
            second.extend((0..n).filter(|i| !first.contains(i)).take(2));
            second.sort_unstable();
            let bump = second[second.len() - 1];
            let (d1, d2) = (d_of(&first, n), d_of(&second, bump));
            let mut core = core(threads, &plan, compliance);
            let mut host = Fsai::new(nx, n, crate::solver::spectral::FSAI_RADIUS);
            for (set, d) in [(&first, &d1), (&second, &d2)] {
                let b = vec![0.0; set.len()];
                let problem = SetProblem {
                    set,
                    d,
                    b: &b,
                    total: 0.0,
                };
                core.prepare_fsai(problem, Parallelism::Sequential).unwrap();
                core.upload_problem(problem, &b).unwrap();
                host.update(&entries, set, d);
            }
            let m = second.len();
            let r = values(m, 21);
            let mut want = vec![0.0; m];
            host.apply(&r, &mut want);
            core.device.htod("test", &r, &mut core.vectors.r).unwrap();
            run(
                &mut core,
                Precond::Fsai,
                m,
                Pre::default(),
                Main::Precondition {
                    stage: 0,
                    carry: 0.0,
                },
            );
            let e = max_rel(&read(&core, &core.vectors.z, m), &want);
            assert!(
                e < 1e-14,
                "{threads} threads, {nx} x {ny}: Gᵀ G r off by {e:e}"
            );
        }
    }
}

/// The coarse space on the device over two sets, as a solve prepares it
/// (`DeviceCoarse::update`: the stale columns of `E` from operator products, the
/// factor, the inverse, the border), then a restriction, the bordered solve and the
/// prolongation through the phases. `E` is compared with the dense `Ĝ`'s sums over the
/// aggregates' sites, the solution with the host's `Coarse` built for the second set
/// alone. The second set empties an aggregate, moves sites and changes a compliance, so
/// a missed stale column fails it.
#[test]
fn the_coarse_kernels_solve_the_hosts_coarse_problem() {
    use crate::solver::coarse::{Aggregates, Coarse};
    use crate::solver::fsai::Entries;
    let (nx, ny) = (24, 17);
    let (grid, plan) = planned(nx, ny, 0.02);
    let n = grid.len();
    let compliance = Compliance {
        scale: 3.6e-16,
        shift: 1e-3,
        norm: 0.0,
    };
    let aggregates = Aggregates::new(nx, ny);
    let count = aggregates.count();
    assert_eq!(count, 9);
    let d_of = |set: &[usize], bump: usize| -> Vec<f64> {
        set.iter()
            .map(|&i| 1e-13 * (1.0 + (i % 3) as f64) * if i == bump { 2.0 } else { 1.0 })
            .collect()
    };
    let first: Vec<usize> = (0..n).filter(|&i| (i * 7919 + 5) % 10 < 6).collect();
    let mut second: Vec<usize> = first
        .iter()
        .copied()
        .filter(|&i| aggregates.aggregate(i) != 4)
        .collect();
    second.extend(
        (0..n)
            .filter(|&i| aggregates.aggregate(i) == 0 && !first.contains(&i))
            .take(2),
    );
    second.sort_unstable();
    let bump = second[second.len() - 1];
    let (d1, d2) = (d_of(&first, n), d_of(&second, bump));
    // E on the second set by the dense matrix.
    let dense = plan.dense().unwrap();
    let mut want = vec![0.0; count * count];
    for (p, &i) in second.iter().enumerate() {
        for (q, &j) in second.iter().enumerate() {
            let v = compliance.scale * (dense[i * n + j] - compliance.shift)
                + if p == q { d2[p] } else { 0.0 };
            want[aggregates.aggregate(i) * count + aggregates.aggregate(j)] += v;
        }
    }
    let entries = Entries::new(
        &plan,
        compliance.scale,
        compliance.shift,
        Parallelism::Sequential,
    )
    .unwrap();
    let mut host = Coarse::new(nx, ny, 1);
    host.update(&entries, &second, &d2, Parallelism::Sequential)
        .unwrap();
    assert!(host.valid());
    let m = second.len();
    let r = values(m, 31);
    host.restrict(0, &second, &r, None);
    host.solve();
    let mut prolonged = r.clone();
    host.prolong(&second, &mut prolonged, 1.0);
    for threads in VARIANTS {
        let mut core = core(threads, &plan, compliance);
        for (set, d) in [(&first, &d1), (&second, &d2)] {
            let b = vec![0.0; set.len()];
            let problem = SetProblem {
                set,
                d,
                b: &b,
                total: 0.0,
            };
            core.upload_problem(problem, &b).unwrap();
            core.prepare_coarse(problem).unwrap();
        }
        let coarse = core.coarse.as_ref().unwrap();
        assert!(coarse.valid(), "E is definite");
        let mut e = read(&core, &coarse.e, count * count);
        // The empty aggregate's row is the identity's; the others are compared on their
        // own scale.
        assert_eq!(e[4 * count + 4], 1.0);
        e[4 * count + 4] = 0.0;
        let err = max_rel(&e, &want);
        assert!(err < 1e-11, "{threads} threads: E off by {err:e}");
        // Restrict r, solve, and z = r + Z y.
        core.device.htod("test", &r, &mut core.vectors.r).unwrap();
        core.device.htod("test", &r, &mut core.vectors.z).unwrap();
        {
            let mut phases = core.phases(Precond::TwoLevel, m, 1.0);
            assert!(phases.has_coarse());
            phases
                .run(Phase {
                    pre: Pre::default(),
                    main: Main::Restrict,
                })
                .unwrap();
            phases.coarse_solve().unwrap();
            let pre = Pre {
                coarse_z: true,
                ..Pre::default()
            };
            phases
                .run(Phase {
                    pre,
                    main: Main::Nothing,
                })
                .unwrap();
        }
        let coarse = core.coarse.as_ref().unwrap();
        let solution = read(&core, &coarse.solution, count);
        let err = max_rel(&solution, &host.solution());
        assert!(
            err < 1e-9,
            "{threads} threads: coarse solution off by {err:e}"
        );
        assert_eq!(solution[4], 0.0);
        let err = max_rel(&read(&core, &core.vectors.z, m), &prolonged);
        assert!(
            err < 1e-12,
            "{threads} threads: prolongation off by {err:e}"
        );
    }
}

/// A compliance as the solver builds it (`solver/mod.rs`): `ΔA/M`, the mean mode lowered
/// to the largest other eigenvalue, the norm.
fn solver_compliance(plan: &InfluencePlan) -> Compliance {
    let grid = plan.grid();
    let (nx, ny, n) = (grid.nx(), grid.ny(), grid.len());
    let scale = grid.cell_area() / 3e9;
    let mean = plan.eigenvalue(0, 0).unwrap();
    let mut other: f64 = 0.0;
    for m in 0..ny {
        for p in 0..nx {
            if p + m > 0 {
                other = other.max(plan.eigenvalue(p, m).unwrap());
            }
        }
    }
    let lowered = mean.min(other);
    Compliance {
        scale,
        shift: (mean - lowered) / n as f64,
        norm: scale * lowered.max(other),
    }
}

/// A set problem's values: the set, `d`, `b`, the total.
type Problem = (Vec<usize>, Vec<f64>, Vec<f64>, f64);

/// Two set problems of one grid: the second drops some sites, adds others and changes a
/// compliance (FSAI's and the coarse space's updates).
fn problems(n: usize, scale: f64) -> Vec<Problem> {
    let first: Vec<usize> = (0..n).filter(|&i| (i * 7919 + 5) % 10 < 7).collect();
    let mut second: Vec<usize> = first.iter().copied().filter(|&i| i % 11 != 3).collect();
    second.extend((0..n).filter(|i| !first.contains(i)).take(3));
    second.sort_unstable();
    [first, second]
        .into_iter()
        .enumerate()
        .map(|(k, set)| {
            let d: Vec<f64> = set
                .iter()
                .map(|&i| {
                    scale
                        * 30.0
                        * (1.0 + (i % 4) as f64)
                        * if k == 1 && i == set[0] { 2.0 } else { 1.0 }
                })
                .collect();
            let b: Vec<f64> = values(set.len(), 40 + k as u64)
                .iter()
                .map(|v| 1e-6 * (1.0 + 0.3 * v))
                .collect();
            (set, d, b, 5.0)
        })
        .collect()
}

/// Whole set solves on the emulator, by each preconditioner, against the spectral
/// backend's own (the host's CG, operator and preconditioners): the same solution within
/// the solver's tolerance. Every phase of the CG, the upkeep of FSAI and of the coarse
/// space, the copies up and down: the backend's launch code as a GPU runs it.
#[test]
fn device_solves_are_the_spectral_backends() {
    let (nx, ny) = (12, 9);
    let (grid, plan) = planned(nx, ny, 0.02);
    let n = grid.len();
    let compliance = solver_compliance(&plan);
    let effort = Effort {
        tolerance: 1e-13,
        max_iterations: 400,
        parallelism: Parallelism::Sequential,
    };
    for threads in VARIANTS {
        let mut launched = Vec::new();
        for precond in [
            Precond::Jacobi,
            Precond::Spectral,
            Precond::Fsai,
            Precond::TwoLevel,
        ] {
            let mut host = SpectralCore::new(&plan, compliance, Partition::single(nx, ny));
            let mut device = core(threads, &plan, compliance);
            for (set, d, b, total) in problems(n, compliance.scale) {
                let problem = SetProblem {
                    set: &set,
                    d: &d,
                    b: &b,
                    total,
                };
                let warm = vec![total / set.len() as f64; set.len()];
                let want = host.solve(problem, precond, warm.clone(), effort).unwrap();
                let got = device.solve(problem, precond, warm, effort).unwrap();
                assert!(
                    want.outcome.converged && got.outcome.converged,
                    "{precond:?}"
                );
                let e = max_rel(&got.f, &want.f);
                assert!(e < 1e-9, "{threads} threads, {precond:?}: f off by {e:e}");
                let e = max_rel(&got.grid_product, &want.grid_product);
                assert!(
                    e < 1e-9,
                    "{threads} threads, {precond:?}: grid product off by {e:e}"
                );
                let offset = (got.outcome.offset - want.outcome.offset).abs();
                assert!(offset <= 1e-9 * want.outcome.offset.abs(), "{precond:?}: U");
                assert!(got.f.iter().all(|f| f.is_finite()));
            }
            launched.extend(device.device.launched());
        }
        // Every kernel of kernels.cu ran in these solves.
        let missing: Vec<&str> = Kernel::ALL
            .iter()
            .filter(|k| !launched.contains(k))
            .map(|k| k.name())
            .collect();
        assert!(
            missing.is_empty(),
            "{threads} threads: not launched: {missing:?}"
        );
    }
}

/// A failed step of each kind (allocation, launch, copy, cuFFT plan, synchronisation)
/// gives a typed error naming the step, never a panic or a NaN result; the core then
/// solves again as if nothing had failed. Faults are planted at the first, a middle and
/// the last step of each kind a solve takes.
#[test]
fn a_failed_device_step_is_an_error_naming_it() {
    let (nx, ny) = (12, 9);
    let (grid, plan) = planned(nx, ny, 0.02);
    let n = grid.len();
    let compliance = solver_compliance(&plan);
    let effort = Effort {
        tolerance: 1e-13,
        max_iterations: 400,
        parallelism: Parallelism::Sequential,
    };
    let sets = problems(n, compliance.scale);
    let (set, d, b, total) = &sets[0];
    let problem = SetProblem {
        set,
        d,
        b,
        total: *total,
    };
    let warm = vec![total / set.len() as f64; set.len()];
    for precond in [Precond::Spectral, Precond::TwoLevel] {
        // The steps of a construction and of a solve, counted on a clean run.
        let clean = core(1, &plan, compliance);
        let built: Vec<usize> = Step::ALL.iter().map(|&s| clean.device.count(s)).collect();
        let mut clean = clean;
        let want = clean.solve(problem, precond, warm.clone(), effort).unwrap();
        let solved: Vec<usize> = Step::ALL.iter().map(|&s| clean.device.count(s)).collect();
        for (k, &step) in Step::ALL.iter().enumerate() {
            // Construction steps: the first and the last.
            for nth in [0, built[k].saturating_sub(1)] {
                if built[k] == 0 {
                    continue;
                }
                let device = Emulator::new(1);
                device.fail(step, nth);
                let e = CudaCore::on(device, &plan, compliance).unwrap_err();
                let text = e.to_string();
                assert!(text.contains("planted fault"), "{step:?}: {text}");
                match step {
                    Step::Plan => assert!(
                        matches!(&e, Error::CudaUnavailable { reason, .. } if reason.contains("cufftPlanMany")),
                        "{e:?}"
                    ),
                    Step::Alloc => assert!(text.contains("cuMemAlloc"), "{e:?}"),
                    Step::Copy => assert!(text.contains("cuMemcpyHtoD"), "{e:?}"),
                    _ => panic!("{step:?} while building: {e:?}"),
                }
            }
            let during = solved[k] - built[k];
            if matches!(step, Step::Launch | Step::Copy | Step::Synchronize) {
                assert!(during > 0, "{precond:?}: no {step:?} step in a solve");
            }
            for nth in [0, during / 2, during.saturating_sub(1)] {
                if during == 0 {
                    continue;
                }
                let mut core = core(1, &plan, compliance);
                core.device.fail(step, built[k] + nth);
                let e = match core.solve(problem, precond, warm.clone(), effort) {
                    Ok(solve) => panic!(
                        "{precond:?}, {step:?} {nth}: solved despite the fault (f[0] = {})",
                        solve.f[0]
                    ),
                    Err(e) => e,
                };
                let Error::Cuda { call, message } = &e else {
                    panic!("{precond:?}, {step:?} {nth}: {e:?}");
                };
                assert!(message.contains("planted fault"), "{message}");
                let named = match step {
                    Step::Launch => {
                        call.starts_with("cufftExec")
                            || Kernel::ALL.iter().any(|k| k.name() == *call)
                    }
                    Step::Copy => call.starts_with("cuMemcpy"),
                    Step::Synchronize => call.starts_with("cuStreamSynchronize"),
                    Step::Alloc => *call == "cuMemAlloc",
                    Step::Plan => *call == "cufftPlanMany",
                };
                assert!(named, "{precond:?}, {step:?} {nth}: the error names {call}");
                // The same core solves again, as the clean one did.
                let again = core.solve(problem, precond, warm.clone(), effort).unwrap();
                let err = max_rel(&again.f, &want.f);
                assert!(
                    err < 1e-12,
                    "{precond:?}, {step:?} {nth}: off by {err:e} after the fault"
                );
            }
        }
    }
}

/// The emulator's launches are the device's: blocks of [`THREADS`] in its 256-thread
/// variant.
#[test]
fn the_device_variant_runs_blocks_of_the_devices_threads() {
    assert_eq!(VARIANTS[2], THREADS);
    let device = Emulator::new(THREADS);
    assert_eq!(device.threads(), 256);
    let cfg = device.over("test", 1000).unwrap().unwrap();
    assert_eq!((cfg.grid_dim.0, cfg.block_dim.0), (4, 256));
}
