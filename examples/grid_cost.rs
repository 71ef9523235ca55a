//! What a grid costs: the time to build its scene (the plan's `O(N)` eigenvalues and the
//! rod load table), the time of its first equilibrium (cold normal and tangential
//! solves) and the process's peak memory, for `Nx x Ny` cells of 1 mm, `Lz = 75 mm`,
//! 3.5 MPa normal pressure, rod drive, seed 1, one thread. The numbers behind
//! [`precursors::GridCost`]'s estimates (docs/performance.md, "Grid-size guard").
//!
//! Run: `cargo run --release --example grid_cost [Nx] [Ny] [max_cells]` (default 1000 x
//! 100 and the default limit, `1e6` cells: 10000 x 10000 is refused at once with the
//! estimates); the peak memory is read from `/proc/self/status` (Linux; `n/a` elsewhere).

#[path = "support/memory.rs"]
mod memory;
#[path = "support/report.rs"]
mod report;

use memory::peak_memory;
use precursors::{GridCost, Scene};
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let args: Vec<String> = std::env::args().skip(1).collect();
    const USAGE: &str = "the arguments are [Nx] [Ny] [max_cells]";
    if args.len() > 3 {
        return Err(format!("unexpected argument '{}': {USAGE}", args[3]).into());
    }
    let parse = |i: usize, default: usize| -> Result<usize, String> {
        args.get(i).map_or(Ok(default), |t| {
            t.parse()
                .map_err(|_| format!("invalid cell count '{t}' ({USAGE})"))
        })
    };
    let (nx, ny) = (parse(0, 1000)?, parse(1, 100)?);
    let max_cells = parse(2, precursors::green::DEFAULT_MAX_CELLS)?;
    let (lx, ly) = (nx as f64 * 1e-3, ny as f64 * 1e-3);
    let base = peak_memory();
    let start = Instant::now();
    let scene = Scene::builder()
        .block(lx, ly, 0.075)
        .cells(nx, ny)
        .normal_load(3.5e6 * lx * ly)
        .seed(1)
        .max_cells(max_cells)
        .build()?;
    let built = start.elapsed().as_secs_f64();
    let mut driver = scene.driver()?;
    let start = Instant::now();
    driver.step()?;
    let solved = start.elapsed().as_secs_f64();
    let peak = peak_memory();
    let n = nx * ny;
    let estimate = GridCost::of(nx, ny);
    println!("N = {n} ({nx} x {ny}), backend {:?}", driver.backend());
    println!(
        "scene build (plan + rod table): {built:.3} s   (estimate {:.3} s)",
        estimate.plan_seconds
    );
    println!(
        "first equilibrium (cold normal + tangential): {solved:.3} s   (estimate {:.3} s)",
        estimate.solve_seconds
    );
    match (base, peak) {
        (Some(base), Some(peak)) => println!(
            "peak memory: {:.1} MB, {:.0} B per cell above the start's {:.1} MB   \
             (estimate {:.1} MB)",
            peak / 1e6,
            (peak - base) / n as f64,
            base / 1e6,
            estimate.memory_bytes / 1e6
        ),
        _ => println!("peak memory: n/a"),
    }
    Ok(())
}
