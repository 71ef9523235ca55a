//! Achieved errors of the point series and the grid operator against tight references;
//! the timings of the same configurations come from `cargo bench --bench accuracy`.
//!
//! Run: `cargo run --release --example accuracy`

#[path = "support/report.rs"]
mod report;

use precursors::green::{GreenFunction, InfluencePlan, SeriesOptions};
use precursors::{Block, Grid, Point};
use std::process::ExitCode;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let block = Block::new(0.14, 0.007, 0.075)?;
    let gf = GreenFunction::new(block);
    let (r, s) = (
        Point::new(0.04, 0.0035, 0.0),
        Point::new(0.043, 0.0045, 0.0),
    );
    let reference = gf.value(r, s, 1e-14)?.value;
    println!("point_rapid (G = {reference:.12} m^-1)");
    println!("| tolerance (m^-1) | error estimate | achieved error |");
    for tol in [1e-4, 1e-8, 1e-12] {
        let e = gf.value(r, s, tol)?;
        println!(
            "| {tol:e} | {:.1e} | {:.1e} |",
            e.error,
            (e.value - reference).abs()
        );
    }
    let small = GreenFunction::new(Block::new(0.03, 0.02, 0.025)?);
    let (r, s) = (
        Point::new(0.007, 0.004, 0.003),
        Point::new(0.021, 0.013, 0.017),
    );
    let reference = small.value(r, s, 1e-14)?.value;
    println!("\npoint_raw (G = {reference:.12} m^-1)");
    println!("| tolerance (m^-1) | error estimate | achieved error |");
    for tol in [1e-1, 1e-2] {
        let e = small.raw_series(
            r,
            s,
            &SeriesOptions::default()
                .with_tolerance(tol)
                .unwrap()
                .with_max_terms(400_000_000)
                .unwrap(),
        )?;
        println!(
            "| {tol:e} | {:.1e} | {:.1e} |",
            e.error,
            (e.value - reference).abs()
        );
    }
    // The operator's eigenvalues cost the same at every tolerance (docs/accuracy.md); their
    // achieved accuracy is checked against the alias sums summed term by term in
    // tests/operator.rs.
    println!("\noperator_build (default tolerance)");
    println!("| grid | max error estimate (relative) | build time |");
    println!("|---|---|---|");
    for (lx, ly, nx, ny) in [
        (0.14, 0.007, 140, 7),
        (0.2, 0.05, 200, 50),
        (1.0, 0.1, 1000, 100),
    ] {
        let grid = Grid::new(Block::new(lx, ly, block.lz())?, nx, ny)?;
        let started = std::time::Instant::now();
        let plan = InfluencePlan::builder(grid).build()?;
        println!(
            "| {nx} x {ny} | {:.1e} | {:.1} ms |",
            plan.max_relative_error(),
            started.elapsed().as_secs_f64() * 1e3
        );
    }
    Ok(())
}
