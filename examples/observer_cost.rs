//! What recorded planes cost: the time to plan a plane's stresses (its transfer and the
//! rod's stress table at its height), the time to evaluate one plane in one stable
//! state, the time to plan a probe point, and the memory a planned plane keeps, for `Nx x Ny` cells of 1 mm,
//! `Lz = 75 mm`, 3.5 MPa normal pressure, rod drive, seed 1, one thread. The numbers
//! behind [`precursors::ObserverCost`]'s estimates (docs/performance.md, "Observer
//! costs"): a run evaluates its field planes in every recorded stable state and its
//! profile planes at every requested load, as here.
//!
//! Run: `cargo run --release --example observer_cost [Nx] [Ny] [planes]` (default
//! 140 x 7 and 100 planes, evenly between `0.1 Lz` and `0.9 Lz`); the peak memory is read
//! from `/proc/self/status` (Linux; `n/a` elsewhere).

#[path = "support/memory.rs"]
mod memory;
#[path = "support/report.rs"]
mod report;

use memory::peak_memory;
use precursors::{Event, Point, ProbeSpec, Scene};
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let args: Vec<String> = std::env::args().skip(1).collect();
    const USAGE: &str = "the arguments are [Nx] [Ny] [planes]";
    if args.len() > 3 {
        return Err(format!("unexpected argument '{}': {USAGE}", args[3]).into());
    }
    let parse = |i: usize, default: usize| -> Result<usize, String> {
        args.get(i).map_or(Ok(default), |t| {
            t.parse()
                .map_err(|_| format!("invalid count '{t}' ({USAGE})"))
        })
    };
    let (nx, ny, planes) = (parse(0, 140)?, parse(1, 7)?, parse(2, 100)?.max(1));
    let (lx, ly, lz) = (nx as f64 * 1e-3, ny as f64 * 1e-3, 0.075);
    let scene = Scene::builder()
        .block(lx, ly, lz)
        .cells(nx, ny)
        .normal_load(3.5e6 * lx * ly)
        .seed(1)
        .build()?;
    let mut driver = scene.driver()?;
    // The first stable state under shear: every field of the stresses is non-zero.
    while let Some(event) = driver.step()? {
        if matches!(event, Event::Stable { load, .. } if load.force > 0.0) {
            break;
        }
    }
    let mut spec = ProbeSpec::default();
    for k in 0..planes {
        spec = spec.with_plane(lz * (0.1 + 0.8 * k as f64 / planes as f64));
    }
    let base = peak_memory();
    let start = Instant::now();
    driver.add_probes(&spec)?;
    let planned = start.elapsed().as_secs_f64() / planes as f64;
    let peak = peak_memory();
    let start = Instant::now();
    let stresses = driver.stresses()?;
    let evaluated = start.elapsed().as_secs_f64() / planes as f64;
    // As many points, on the plane's diagonal (x, y and z rising together).
    let mut points = ProbeSpec::default();
    for k in 0..planes {
        let t = (k as f64 + 0.5) / planes as f64;
        points = points.with_point(Point::new(lx * t, ly * t, lz * (0.1 + 0.8 * t)));
    }
    let start = Instant::now();
    driver.add_probes(&points)?;
    let points_planned = start.elapsed().as_secs_f64() / planes as f64;
    let n = nx * ny;
    println!("N = {n} ({nx} x {ny}), {} planes", stresses.planes.len());
    println!(
        "plan:     {planned:.3e} s per plane ({:.3e} s per plane and cell)",
        planned / n as f64
    );
    println!(
        "evaluate: {evaluated:.3e} s per plane and state ({:.3e} s per plane and cell)",
        evaluated / n as f64
    );
    println!(
        "points:   {points_planned:.3e} s per point to plan ({:.3e} s per point and cell)",
        points_planned / n as f64
    );
    match (base, peak) {
        (Some(base), Some(peak)) => println!(
            "memory:   {:.0} B per plane and cell",
            (peak - base) / (n * planes) as f64
        ),
        _ => println!("memory:   n/a"),
    }
    Ok(())
}
