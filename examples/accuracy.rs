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
            &SeriesOptions::with_tolerance(tol).max_terms(400_000_000),
        )?;
        println!(
            "| {tol:e} | {:.1e} | {:.1e} |",
            e.error,
            (e.value - reference).abs()
        );
    }
    let grid = Grid::new(block, 140, 7)?;
    let tight = InfluencePlan::builder(grid).tolerance(1e-10).build()?;
    println!("\noperator_build_140x7 (reference: tolerance 1e-10)");
    println!("| tolerance (relative) | max estimate | max achieved relative error |");
    for tol in [1e-3, 1e-6, 1e-9] {
        let plan = InfluencePlan::builder(grid).tolerance(tol).build()?;
        let mut worst: f64 = 0.0;
        for m in 0..grid.ny() {
            for p in 0..grid.nx() {
                let (a, b) = (plan.lambda(p, m).unwrap(), tight.lambda(p, m).unwrap());
                worst = worst.max((a - b).abs() / b);
            }
        }
        println!(
            "| {tol:e} | {:.1e} | {worst:.1e} |",
            plan.max_relative_error()
        );
    }
    Ok(())
}
