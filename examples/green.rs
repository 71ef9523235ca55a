//! The Green-function module on the paper's calibration block (140 x 7 x 75 mm, 1 mm
//! cells): the influence of one loaded cell on the interface, and the rod load profile.
//!
//! Run: `cargo run --release --example green`

#[path = "support/report.rs"]
mod report;

use precursors::green::{InfluencePlan, RodLoad};
use precursors::{Block, Grid};
use std::process::ExitCode;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let block = Block::new(0.140, 0.007, 0.075)?;
    let grid = Grid::from_cell_size(block, 1e-3, 1e-3)?;
    let t = std::time::Instant::now();
    let plan = InfluencePlan::builder(grid).plan_tolerance(1e-8).build()?;
    println!(
        "influence operator of {} x {} cells planned in {:.1} ms (max relative alias error {:.1e})",
        grid.nx(),
        grid.ny(),
        t.elapsed().as_secs_f64() * 1e3,
        plan.max_relative_error()
    );

    // A 1 MPa traction on the cell (20, 3): displacement times M (m·Pa) along the row iy = 3.
    let cell = |ix, iy| {
        grid.index(ix, iy)
            .ok_or(format!("no cell ({ix}, {iy}) in the grid"))
    };
    let mut phi = vec![0.0; grid.len()];
    phi[cell(20, 3)?] = 1e6;
    let mut u = vec![0.0; grid.len()];
    plan.apply(&phi, &mut u)?;
    println!(
        "\nM·u (N/m) along y = 3.5 mm from a 1 MPa load on cell (20, 3), relative to the far end:"
    );
    let far = u[cell(139, 3)?] * grid.cell_area();
    for ix in [18, 19, 20, 21, 22, 25, 30, 40, 60, 100] {
        let v = u[cell(ix, 3)?] * grid.cell_area() - far;
        println!("  x = {:5.1} mm   {:10.4}", (ix as f64 + 0.5), v);
    }

    // The rod of the calibration experiment: h = 6 mm, Δh = 2 mm.
    let rod = RodLoad::new(&block, 6e-3, 2e-3)?;
    let profile = rod.influence_cells(&grid, 1e-10)?;
    let side = RodLoad::uniform_side(&block).influence_cells(&grid, 1e-10)?;
    println!("\nLateral load per unit force on the interface (m⁻¹), minus its value at the leading edge:");
    println!("  x (mm)      rod        uniform side");
    for ix in [0, 1, 2, 5, 10, 20, 40, 80, 139] {
        println!(
            "  {:6.1}  {:10.4}  {:10.4}",
            ix as f64 + 0.5,
            profile[ix] - profile[139],
            side[ix] - side[139]
        );
    }
    Ok(())
}
