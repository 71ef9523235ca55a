//! The cost of an event and of a CG iteration on a backend, for docs/gpu.md's
//! measurements (scripts/gpu-check.sh runs it): `Nx x Ny` cells of 1 mm, `Lz = 75 mm`,
//! 3.5 MPa normal pressure, rod drive, seed 1. Prints the first equilibrium's time, then
//! the time per event and per CG iteration over the next `EVENTS` events.
//!
//! With a fifth argument `PHASE_EVENTS` (backend `cuda`), it then runs that many more
//! events with the backend's per-part timing on (`record_cuda_phase_times`: a
//! synchronisation around each part, so not during the measurement above) and prints one
//! `phases` line of `key=value` fields (seconds), which scripts/gpu-check.sh tabulates.
//!
//! Run: `cargo run --release --features cuda --example gpu_timings -- BACKEND NX NY
//! EVENTS [PHASE_EVENTS]` (`BACKEND`: `cuda` or `spectral`). Both run on 16 threads at most: the
//! spectral backend its solves, the CUDA backend its host-side upkeep (the table of exact
//! entries FSAI's rows are built from, `4 Nx² Ny` terms once: 4e11 at
//! 10 000 x 1 000).

#[path = "support/report.rs"]
mod report;

use precursors::solver::{Backend, Parallelism, SolverOptions};
use precursors::Scene;
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let args: Vec<String> = std::env::args().skip(1).collect();
    const USAGE: &str = "the arguments are BACKEND (cuda or spectral) NX NY EVENTS [PHASE_EVENTS]";
    if !(4..=5).contains(&args.len()) {
        return Err(USAGE.into());
    }
    let backend = match args[0].as_str() {
        "cuda" => Backend::Cuda,
        "spectral" => Backend::Spectral,
        other => return Err(format!("unknown backend '{other}': {USAGE}").into()),
    };
    let count = |i: usize| -> Result<usize, String> {
        args[i]
            .parse()
            .map_err(|_| format!("invalid count '{}' ({USAGE})", args[i]))
    };
    let (nx, ny, events) = (count(1)?, count(2)?, count(3)?);
    let phase_events = if args.len() == 5 { count(4)? } else { 0 };
    if phase_events > 0 && backend != Backend::Cuda {
        return Err(format!("PHASE_EVENTS is for backend cuda only ({USAGE})").into());
    }
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get().min(16));
    let parallelism = Parallelism::from_count(threads);
    let options = SolverOptions::default()
        .with_backend(backend)?
        .with_parallelism(parallelism)?;
    let (lx, ly) = (nx as f64 * 1e-3, ny as f64 * 1e-3);
    let scene = Scene::builder()
        .block(lx, ly, 0.075)
        .cells(nx, ny)
        .normal_load(3.5e6 * lx * ly)
        .seed(1)
        .max_cells(nx * ny)
        .solver_options(options)
        .build()?;
    let mut driver = scene.driver()?;
    let start = Instant::now();
    driver.step()?;
    let first = start.elapsed().as_secs_f64();
    let before = driver.solve_stats();
    let start = Instant::now();
    let mut done = 0;
    while done < events {
        match driver.step()? {
            Some(_) => done += 1,
            None => break,
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    let after = driver.solve_stats();
    let iterations = (after.normal_iterations + after.tangential_iterations)
        - (before.normal_iterations + before.tangential_iterations);
    let solving = (after.normal_seconds + after.tangential_seconds)
        - (before.normal_seconds + before.tangential_seconds);
    println!(
        "backend {backend} N = {} ({nx} x {ny}): first equilibrium {first:.3} s; {done} events \
         in {seconds:.3} s ({:.3} ms per event); {iterations} CG iterations ({:.4} ms each)",
        nx * ny,
        1e3 * seconds / done.max(1) as f64,
        1e3 * solving / iterations.max(1) as f64
    );
    if phase_events > 0 {
        phases(&mut driver, nx * ny, phase_events)?;
    }
    Ok(())
}

/// `events` more events with the CUDA backend's per-part timing on, then one line.
fn phases(driver: &mut precursors::Driver, n: usize, events: usize) -> report::Outcome {
    let before = driver.solve_stats();
    precursors::solver::record_cuda_phase_times(true);
    let mut done = 0;
    while done < events {
        match driver.step()? {
            Some(_) => done += 1,
            None => break,
        }
    }
    let t = precursors::solver::record_cuda_phase_times(false);
    let after = driver.solve_stats();
    let iterations = (after.normal_iterations + after.tangential_iterations)
        - (before.normal_iterations + before.tangential_iterations);
    println!(
        "phases n={n} events={done} iterations={iterations} solves={} solve={:.6} \
         operator={:.6} preconditioner={:.6} coarse_upkeep={:.6} preconditioner_upkeep={:.6} \
         reductions={:.6} updates={:.6} copies={:.6}",
        t.solves,
        t.solve_seconds,
        t.operator_seconds,
        t.preconditioner_seconds,
        t.coarse_upkeep_seconds,
        t.preconditioner_upkeep_seconds,
        t.reduction_seconds,
        t.update_seconds,
        t.copy_seconds
    );
    Ok(())
}
