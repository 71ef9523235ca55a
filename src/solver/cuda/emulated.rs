//! kernels.cu checked without a GPU: emulated.cpp compiles the kernels' own source for
//! the host (the C++ compiler every Rust toolchain's machine here has; one thread per
//! block, naive DFTs for cuFFT) and runs operator.rs's launch sequence. The products are
//! compared with the dense `Ĝ` (`InfluencePlan::dense`, explicit cosine sums: independent
//! of any DCT) and the reductions with plain sums.

use super::kernels::{threads_define, THREADS};
use super::operator::table;
use crate::geometry::{Block, Grid};
use crate::green::InfluencePlan;
use crate::solver::system::Compliance;
use std::path::PathBuf;
use std::process::{Command, Stdio};

/// Threads per block of the emulators: one (the sequential reference), then four and the
/// device's [`THREADS`] run as real threads meeting at a barrier for `__syncthreads` (a
/// missing barrier or a race in a block's cooperation shows as a wrong or varying
/// result; the device's count runs its trees at their full depth).
const EMULATED_THREADS: [u32; 3] = [1, 4, THREADS];

/// Compiles emulated.cpp with `threads` threads per block, once per version of its
/// sources: the program sits beside the test binary (under `target/`), named by a hash of
/// emulated.cpp and kernels.cu, so later test processes reuse it and nothing is left in
/// the system's temporary directory. Written under a name of this process's, then
/// renamed: two test processes never see half a program.
fn program(threads: u32) -> PathBuf {
    use std::hash::{Hash, Hasher};
    static PROGRAMS: std::sync::Mutex<Vec<(u32, PathBuf)>> = std::sync::Mutex::new(Vec::new());
    let mut programs = PROGRAMS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, path)) = programs.iter().find(|(t, _)| *t == threads) {
        return path.clone();
    }
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src/solver/cuda");
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    for file in ["emulated.cpp", "kernels.cu"] {
        std::fs::read(here.join(file))
            .expect("the emulator's sources")
            .hash(&mut hasher);
    }
    let dir = std::env::current_exe()
        .ok()
        .and_then(|exe| exe.parent().map(PathBuf::from))
        .unwrap_or_else(std::env::temp_dir);
    let out = dir.join(format!(
        "precursors-emulated-{threads}-{:016x}",
        hasher.finish()
    ));
    if !out.exists() {
        let partial = dir.join(format!(
            "precursors-emulated-{threads}-{}.partial",
            std::process::id()
        ));
        let status = Command::new("c++")
            .args(["-O2", "-std=c++20", "-pthread"])
            .arg(threads_define(threads))
            .arg("-o")
            .arg(&partial)
            .arg(here.join("emulated.cpp"))
            .arg("-I")
            .arg(&here)
            .status()
            .expect("a C++ compiler (c++) runs kernels.cu on the host");
        assert!(status.success(), "emulated.cpp does not compile");
        std::fs::rename(&partial, &out).expect("the emulator renamed into place");
    }
    programs.push((threads, out.clone()));
    out
}

/// What emulated.cpp prints.
struct Emulated {
    set_product: Vec<f64>,
    grid_product: Vec<f64>,
    reductions: Vec<[f64; 3]>,
}

/// Runs the emulators on `input`, each thread count of [`EMULATED_THREADS`]; their
/// outputs as numbers, in that order.
fn emulate_all(input: &str) -> Vec<Vec<f64>> {
    EMULATED_THREADS
        .iter()
        .map(|&threads| emulate_with(threads, input))
        .collect()
}

/// Runs the emulators on `input`; the one-thread output, after checking that the
/// threaded one agrees with it (within rounding: its reductions add in another order).
fn emulate(input: &str) -> Vec<f64> {
    let mut outputs = emulate_all(input).into_iter();
    let reference = outputs.next().expect("a one-thread emulator");
    for (other, threads) in outputs.zip(&EMULATED_THREADS[1..]) {
        assert_eq!(other.len(), reference.len());
        let scale = reference.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for (k, (a, b)) in reference.iter().zip(&other).enumerate() {
            let tolerance = 1e-12 * scale.max(f64::MIN_POSITIVE) + 1e-9 * a.abs();
            assert!(
                (a - b).abs() <= tolerance,
                "value {k}: {a} with one thread per block, {b} with {threads}"
            );
        }
    }
    reference
}

/// Runs the emulator of `threads` threads per block on `input`. A run that does not end
/// within a minute is killed and fails the test: threads that disagree on a barrier
/// (one leaves a loop the others stay in) wait for each other forever.
fn emulate_with(threads: u32, input: &str) -> Vec<f64> {
    use std::io::{Read, Write};
    use std::time::{Duration, Instant};
    let mut child = Command::new(program(threads))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("the emulator runs");
    let mut stdout = child.stdout.take().expect("stdout");
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        stdout.read_to_string(&mut text).map(|_| text)
    });
    // Written from a thread too: a hung emulator may stop reading its input.
    let mut stdin = child.stdin.take().expect("stdin");
    let input = input.to_string();
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let deadline = Instant::now() + Duration::from_secs(60);
    let status = loop {
        if let Some(status) = child.try_wait().expect("the emulator's status") {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the emulator with {threads} threads per block hangs (a barrier not reached by every thread?)");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    assert!(status.success());
    writer
        .join()
        .expect("the writer ends")
        .expect("input written");
    reader
        .join()
        .expect("the reader ends")
        .expect("text")
        .split_whitespace()
        .map(|v| v.parse().expect("a number"))
        .collect()
}

fn run(grid: &Grid, w: &[f64], sites: &[(usize, f64, f64)], with_d: bool) -> Emulated {
    let mut input = format!(
        "operator {} {} {} {}\n",
        grid.nx(),
        grid.ny(),
        sites.len(),
        i32::from(with_d)
    );
    for v in w {
        input += &format!("{v:e}\n");
    }
    for (i, x, d) in sites {
        input += &format!("{i} {x:e} {d:e}\n");
    }
    let values = emulate(&input);
    let (m, n) = (sites.len(), grid.len());
    assert_eq!(values.len(), m + n + 9);
    let r = &values[m + n..];
    Emulated {
        set_product: values[..m].to_vec(),
        grid_product: values[m..m + n].to_vec(),
        reductions: (0..3)
            .map(|k| [r[3 * k], r[3 * k + 1], r[3 * k + 2]])
            .collect(),
    }
}

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

/// Odd and even lengths on both axes, and a grid of one row (a length-1 transform).
const GRIDS: [(usize, usize); 4] = [(7, 5), (8, 6), (6, 1), (5, 4)];

#[test]
fn the_kernels_apply_the_set_system_as_the_dense_matrix_does() {
    for (nx, ny) in GRIDS {
        let (grid, plan) = planned(nx, ny, 0.01);
        let compliance = Compliance {
            scale: 2.5e-9,
            shift: 0.3,
            norm: 0.0,
        };
        let w = table(&plan, compliance, |e| e);
        // Every other cell is in the set.
        let x = values(grid.len(), 1);
        let d = values(grid.len(), 2);
        let sites: Vec<(usize, f64, f64)> = (0..grid.len())
            .step_by(2)
            .map(|i| (i, x[i], d[i].abs() * 1e-9))
            .collect();
        let emulated = run(&grid, &w, &sites, true);
        // C_s x = scale (Ĝ x - shift Σx) on every cell, x zero off the set.
        let g = plan.dense().unwrap();
        let n = grid.len();
        let sum: f64 = sites.iter().map(|s| s.1).sum();
        let grid_ref: Vec<f64> = (0..n)
            .map(|i| {
                let gx: f64 = sites.iter().map(|&(k, xk, _)| g[i * n + k] * xk).sum();
                compliance.scale * (gx - compliance.shift * sum)
            })
            .collect();
        let set_ref: Vec<f64> = sites
            .iter()
            .map(|&(i, xi, di)| grid_ref[i] + di * xi)
            .collect();
        let (e_grid, e_set) = (
            max_rel(&emulated.grid_product, &grid_ref),
            max_rel(&emulated.set_product, &set_ref),
        );
        assert!(
            e_grid < 1e-12,
            "{nx} x {ny}: grid product off by {e_grid:e}"
        );
        assert!(e_set < 1e-12, "{nx} x {ny}: set product off by {e_set:e}");
        // The reductions: Σ y, yᵀx, [max |y|, max |x|, yᵀy].
        let y = &emulated.set_product;
        let xs: Vec<f64> = sites.iter().map(|s| s.1).collect();
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
        let max = |a: &[f64]| a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let r = &emulated.reductions;
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1e-300);
        assert!(close(r[0][0], y.iter().sum::<f64>()));
        assert!(close(r[1][0], dot(y, &xs)));
        assert_eq!((r[2][0], r[2][1]), (max(y), max(&xs)));
        assert!(close(r[2][2], dot(y, y)));
    }
}

#[test]
fn the_spectral_table_inverts_the_full_grid_system() {
    for (nx, ny) in GRIDS {
        let (grid, plan) = planned(nx, ny, 0.02);
        let compliance = Compliance {
            scale: 1e-9,
            shift: 0.1,
            norm: 0.0,
        };
        let mean_d = 3e-10;
        // y = (C_s + d̄ I) x on every cell, by the dense matrix.
        let g = plan.dense().unwrap();
        let n = grid.len();
        let x = values(n, 3);
        let sum: f64 = x.iter().sum();
        let y: Vec<f64> = (0..n)
            .map(|i| {
                let gx: f64 = (0..n).map(|k| g[i * n + k] * x[k]).sum();
                compliance.scale * (gx - compliance.shift * sum) + mean_d * x[i]
            })
            .collect();
        let w = table(&plan, compliance, |e| 1.0 / (e + mean_d));
        let sites: Vec<(usize, f64, f64)> = (0..n).map(|i| (i, y[i], 0.0)).collect();
        let back = run(&grid, &w, &sites, false).set_product;
        let e = max_rel(&back, &x);
        assert!(e < 1e-11, "{nx} x {ny}: the inverse is off by {e:e}");
    }
}

/// Every phase's local updates as pcg.rs applies them on the host (`Pre::apply`, the
/// reference) and as pre_updates applies them, for updates the CG combines.
#[test]
fn the_local_updates_are_the_hosts() {
    use crate::solver::pcg::{apply_pre, Pre};
    let m = 11;
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
    for (k, pre) in combos.into_iter().enumerate() {
        let mut host: Vec<Vec<f64>> = (0..7).map(|v| values(m, 10 * k as u64 + v)).collect();
        let mut flags = 0;
        for (set, bit) in [
            (pre.keep_best, 1),
            (pre.restore_best, 2),
            (pre.shift_f.is_some(), 4),
            (pre.step.is_some(), 8),
            (pre.step.is_some_and(|s| s.1), 16),
            (pre.project.is_some(), 32),
            (pre.w_from_z, 64),
            (pre.direction == Some(None), 128),
            (matches!(pre.direction, Some(Some(_))), 256),
            (pre.fill_r_one, 512),
        ] {
            if set {
                flags |= bit;
            }
        }
        let beta = match pre.direction {
            Some(Some(b)) => b,
            _ => 0.0,
        };
        let mut input = format!(
            "pre {m} {flags} {:e} {:e} {:e} {beta:e}\n",
            pre.shift_f.unwrap_or(0.0),
            pre.step.map_or(0.0, |s| s.0),
            pre.project.unwrap_or(0.0)
        );
        for j in 0..m {
            for v in &host {
                input += &format!("{:e} ", v[j]);
            }
            input += "\n";
        }
        let device = emulate(&input);
        apply_pre(pre, &mut host);
        for j in 0..m {
            for (v, vector) in host.iter().enumerate() {
                let (h, d) = (vector[j], device[7 * j + v]);
                assert!(
                    (h - d).abs() <= 1e-15 * h.abs().max(1.0),
                    "combination {k}, vector {v}, site {j}: host {h}, kernel {d}"
                );
            }
        }
    }
}

/// FSAI on the device: the host's factor copied as the backend copies it (the planes for
/// the first set, then only the rows the update of a second set refreshed) and applied by
/// fsai_g and fsai_gt, against the host's own `Fsai::apply` on the second set (fsai.rs,
/// itself tested against the factor's dense rows).
#[test]
fn the_fsai_kernels_apply_the_hosts_factor_after_its_updates() {
    use super::fsai::rows_to_copy;
    use crate::solver::fsai::{Entries, Fsai};
    use crate::solver::parallel::Parallelism;
    for (nx, ny) in [(16, 12), (9, 7), (6, 1)] {
        let (grid, plan) = planned(nx, ny, 0.02);
        let n = grid.len();
        let entries = Entries::new(&plan, 3.6e-16, 1e-3, Parallelism::Sequential).unwrap();
        let first: Vec<usize> = (0..n).filter(|i| (i * 7919 + 3) % 10 < 6).collect();
        let d_of = |set: &[usize], bump: usize| -> Vec<f64> {
            set.iter()
                .map(|&i| 1e-13 * (1.0 + (i % 3) as f64) * if i == bump { 1.5 } else { 1.0 })
                .collect()
        };
        let mut fsai = Fsai::new(nx, n, crate::solver::spectral::FSAI_RADIUS);
        fsai.update(&entries, &first, &d_of(&first, n));
        // The first copy is the planes as they are: every cell's row.
        let all: (Vec<i32>, Vec<f64>) = {
            let layout = fsai.layout();
            let (stride, planes) = (layout.stride, layout.planes);
            let weights = (0..n)
                .flat_map(|i| (0..stride).map(move |k| planes[k * n + i]))
                .collect();
            ((0..n as i32).collect(), weights)
        };
        // The second set: two sites leave, two join, one compliance changes.
        let mut second: Vec<usize> = first.clone();
        second.retain(|&i| i != first[1] && i != first[first.len() / 2]);
        second.extend((0..n).filter(|i| !first.contains(i)).take(2));
        second.sort_unstable();
        let bump = second[second.len() - 1];
        fsai.update(&entries, &second, &d_of(&second, bump));
        let refreshed = rows_to_copy(&fsai);
        // Five changed sites: at most their 3 x 3 boxes of rows.
        assert!(
            refreshed.0.len() <= 45.min(n),
            "only the rows around the changes"
        );
        let r = values(second.len(), 21);
        let mut host = vec![0.0; second.len()];
        fsai.apply(&r, &mut host);
        let device = |rounds: &[&(Vec<i32>, Vec<f64>)]| -> Vec<f64> {
            let stride = fsai.layout().stride;
            let mut input = format!("fsai {nx} {ny} {stride}\n");
            for o in fsai.layout().offsets {
                input += &format!("{o} ");
            }
            input += &format!("\nrounds {}\n", rounds.len());
            for (cells, weights) in rounds {
                input += &format!("{}\n", cells.len());
                for (c, cell) in cells.iter().enumerate() {
                    input += &format!("{cell}");
                    for w in &weights[c * stride..(c + 1) * stride] {
                        input += &format!(" {w:e}");
                    }
                    input += "\n";
                }
            }
            input += &format!("{}\n", second.len());
            for (i, ri) in second.iter().zip(&r) {
                input += &format!("{i} {ri:e}\n");
            }
            emulate(&input)
        };
        let synced = device(&[&all, &refreshed]);
        let e = max_rel(&synced, &host);
        assert!(
            e < 1e-14,
            "{nx} x {ny}: the device's Gᵀ G r is off by {e:e}"
        );
        // Without the refreshed rows the copy is stale and the product differs: the test
        // sees a missed update.
        let stale = device(&[&all]);
        assert!(max_rel(&stale, &host) > 1e-6, "{nx} x {ny}");
    }
}

/// The coarse space on the device over two sets, as `DeviceCoarse::update` runs it: the
/// columns of `E` the host finds stale (`stale_columns`) from the products of their
/// aggregates' indicators, then the factor, the inverse and the border; then a bordered
/// solve and the prolongation on the second set. `E` is compared with the dense `Ĝ`'s
/// sums over the aggregates' sites (`InfluencePlan::dense`), the solution with the
/// host's `Coarse` built for the second set alone (its `E` from FSAI's exact entries,
/// faer's Cholesky factor). The second set empties an aggregate, moves sites and changes
/// a compliance; without its stale columns `E` is wrong, so a missed column fails.
#[test]
fn the_coarse_kernels_solve_the_hosts_coarse_problem() {
    use super::coarse::stale_columns;
    use crate::solver::coarse::{Aggregates, Coarse};
    use crate::solver::fsai::Entries;
    use crate::solver::parallel::Parallelism;
    let (nx, ny) = (24, 17);
    let (grid, plan) = planned(nx, ny, 0.02);
    let n = grid.len();
    let compliance = Compliance {
        scale: 3.6e-16,
        shift: 1e-3,
        norm: 0.0,
    };
    let mut aggregates = Aggregates::new(nx, ny);
    let (block, count) = (aggregates.block(), aggregates.count());
    let bx = nx.div_ceil(block);
    assert_eq!(count, 9);
    let d_of = |set: &[usize], bump: usize| -> Vec<f64> {
        set.iter()
            .map(|&i| 1e-13 * (1.0 + (i % 3) as f64) * if i == bump { 2.0 } else { 1.0 })
            .collect()
    };
    // About 60 % of the sites; the second set has none in the middle aggregate, two more
    // sites in the first and one compliance changed in the last.
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
    let mut rounds = Vec::new();
    for (set, d) in [(&first, &d1), (&second, &d2)] {
        aggregates.enter(set, d);
        rounds.push((set, d, stale_columns(&aggregates)));
    }
    assert_eq!(rounds[0].2.len(), count, "the first set: every column");
    assert_eq!(
        rounds[1].2,
        vec![0, 4, 8],
        "the changed aggregates' columns"
    );
    let r = values(second.len(), 31);
    let emulate_rounds = |columns_of_second: &[usize]| -> Vec<f64> {
        let mut input = format!("coarse {nx} {ny} {block} {bx} {count}\n");
        for v in table(&plan, compliance, |e| e) {
            input += &format!("{v:e}\n");
        }
        input += &format!("rounds {}\n", rounds.len());
        for (k, (set, d, columns)) in rounds.iter().enumerate() {
            input += &format!("{}\n", set.len());
            for (i, di) in set.iter().zip(d.iter()) {
                input += &format!("{i} {di:e}\n");
            }
            let columns = if k == 1 { columns_of_second } else { columns };
            input += &format!("columns {}", columns.len());
            for a in columns {
                input += &format!(" {a}");
            }
            input += "\n";
        }
        for ri in &r {
            input += &format!("{ri:e}\n");
        }
        emulate(&input)
    };
    let out = emulate_rounds(&rounds[1].2);
    assert_eq!(out.len(), 2 + count * count + count + second.len());
    let (info, rest) = out.split_at(2);
    let (e, rest) = rest.split_at(count * count);
    let (solution, prolonged) = rest.split_at(count);
    assert_eq!(info[0], 1.0, "E is definite");
    // E against the dense sums on the second set.
    let dense = plan.dense().unwrap();
    let mut want = vec![0.0; count * count];
    for (p, &i) in second.iter().enumerate() {
        for (q, &j) in second.iter().enumerate() {
            let v = compliance.scale * (dense[i * n + j] - compliance.shift)
                + if p == q { d2[p] } else { 0.0 };
            want[aggregates.aggregate(i) * count + aggregates.aggregate(j)] += v;
        }
    }
    // The empty aggregate's row is the identity's; the others are compared on their
    // own scale.
    assert_eq!(e[4 * count + 4], 1.0);
    let off_identity = |e: &[f64]| -> Vec<f64> {
        let mut e = e.to_vec();
        e[4 * count + 4] = 0.0;
        e
    };
    let err = max_rel(&off_identity(e), &want);
    assert!(err < 1e-11, "E off by {err:e}");
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
    host.restrict(0, &second, &r, None);
    host.solve();
    let err = max_rel(solution, &host.solution());
    assert!(err < 1e-9, "coarse solution off by {err:e}");
    assert_eq!(solution[4], 0.0);
    let mut x = r.clone();
    host.prolong(&second, &mut x, 1.0);
    let err = max_rel(prolonged, &x);
    assert!(err < 1e-12, "prolongation off by {err:e}");
    // Without the second set's columns E is stale.
    let stale = emulate_rounds(&[]);
    let err = max_rel(&off_identity(&stale[2..2 + count * count]), &want);
    assert!(err > 1e-3, "stale E off by only {err:e}");
}
