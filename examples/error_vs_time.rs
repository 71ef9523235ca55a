//! The whole run's error against its run time (docs/accuracy.md, "Error of a run against
//! its run time"): one scene run to global slip over solver tolerances (backward error of
//! every linear solve), each compared with a converged reference run (solver `1e-14`) on
//! what users read (the plan's eigenvalues are computed to about 1e-13 whatever its
//! tolerance, so it is not a knob any more):
//!
//! * `loads`: the largest relative error of the first 100 rupture loads (of the ruptures
//!   before the event sequences part, when they part earlier);
//! * `same events`: how many events agree (kind and site) before the first difference;
//! * `ℓ/Lx`: the largest `|Δℓ/Lx|` on the grid `F/(μF_N) = 0.05, 0.10, ..., 0.95`
//!   (`ℓ` of the last stable state at or below each load);
//! * `slip`: the relative error of the global-slip force;
//! * `A_R(0)`: the relative error of the real contact area at zero shear.
//!
//! Run: `cargo run --release --example error_vs_time [calibration|large] [threads]`
//! (`calibration`: 140 x 7 cells, dense backend, default; `large`: the N = 1e4 scene of
//! `examples/large_run`, spectral backend). Prints a Markdown table and writes
//! `out/error_vs_time_<scene>.csv`.

#[path = "support/report.rs"]
mod report;

use precursors::solver::{Parallelism, SolverOptions};
use precursors::{Drive, Event, ForceLoad, Lateral, Scene, SceneBuilder};
use report::AtPath;
use std::io::Write;
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    report::report(run())
}

/// What one run gives.
struct Run {
    seconds: f64,
    events: Vec<(u8, usize)>,
    ruptures: Vec<f64>,
    /// `(F/(μF_N), ℓ/Lx)` at every stable state.
    curve: Vec<(f64, f64)>,
    slip: f64,
    area0: f64,
}

fn scene(name: &str) -> Result<SceneBuilder, String> {
    let rod = Drive::Force(ForceLoad::Lateral(Lateral::Rod {
        height: 0.006,
        half_width: 0.002,
    }));
    match name {
        "calibration" => Ok(Scene::builder()
            .block(0.140, 0.007, 0.075)
            .cell_size(1e-3, 1e-3)
            .seed(1)
            .normal_load(3500.0)
            .drive(rod)),
        "large" => Ok(Scene::builder()
            .block(0.200, 0.050, 0.075)
            .cell_size(1e-3, 1e-3)
            .seed(1)
            .normal_load(35000.0)
            .drive(rod)),
        other => Err(format!(
            "unknown scene '{other}': the arguments are [calibration|large] [threads]"
        )),
    }
}

fn one(base: &SceneBuilder, solver: f64, threads: Parallelism) -> Result<Run, precursors::Error> {
    let started = Instant::now();
    let scene = base
        .clone()
        .solver_options(
            SolverOptions::default()
                .with_tolerance(solver)?
                .with_parallelism(threads)?,
        )
        .build()?;
    let mu_fn = scene.material().friction_coefficient() * scene.normal_load();
    let lx = scene.grid().block().lx();
    let mut driver = scene.driver()?;
    let mut run = Run {
        seconds: 0.0,
        events: Vec::new(),
        ruptures: Vec::new(),
        curve: Vec::new(),
        slip: f64::NAN,
        area0: f64::NAN,
    };
    while let Some(event) = driver.step()? {
        let (kind, site) = match event {
            Event::Rupture { site, load, .. } => {
                run.ruptures.push(load.force);
                (0, site.index)
            }
            Event::Detach { site } => (1, site.index),
            Event::Attach { site } => (2, site.index),
            Event::Stable { load, .. } => {
                if run.curve.is_empty() {
                    run.area0 = driver.real_contact_area()?;
                }
                run.curve
                    .push((load.force / mu_fn, driver.precursor_length()? / lx));
                (3, 0)
            }
            Event::GlobalSlip { load } => {
                run.slip = load.force;
                (4, 0)
            }
            _ => (5, 0),
        };
        run.events.push((kind, site));
    }
    run.seconds = started.elapsed().as_secs_f64();
    Ok(run)
}

/// `ℓ/Lx` of the last stable state at or below `x = F/(μF_N)`.
fn length_at(curve: &[(f64, f64)], x: f64) -> f64 {
    curve
        .iter()
        .take_while(|(f, _)| *f <= x)
        .last()
        .map_or(0.0, |(_, l)| *l)
}

fn run() -> report::Outcome {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("calibration", |s| s.as_str());
    let base = scene(name)?;
    let threads = match args.get(1) {
        None => Parallelism::Sequential,
        Some(t) => match t.parse::<usize>() {
            Ok(0) => Parallelism::all_cores(),
            Ok(1) => Parallelism::Sequential,
            Ok(n) => Parallelism::Threads(n),
            Err(_) => return Err(format!("invalid thread count '{t}'").into()),
        },
    };
    report::writable_dir("out")?;
    let path = format!("out/error_vs_time_{name}.csv");
    let mut csv = std::fs::File::create(&path).at("create", &path)?;
    eprintln!("reference run (solver 1e-14) ...");
    let reference = one(&base, 1e-14, threads)?;
    eprintln!(
        "  {:.2} s, {} events",
        reference.seconds,
        reference.events.len()
    );
    writeln!(
        csv,
        "solver_tolerance,seconds,events,load_error_first100,same_events,\
         length_error,slip_error,area0_error"
    )?;
    println!(
        "| solver tol | time (s) | loads (first 100) | same events | max Δℓ/Lx | slip | A_R(0) |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- |");
    let grid: Vec<f64> = (1..=19).map(|k| 0.05 * k as f64).collect();
    for solver in [1e-6, 1e-8, 1e-10, 1e-11, 1e-13] {
        let run = one(&base, solver, threads)?;
        let same = run
            .events
            .iter()
            .zip(&reference.events)
            .take_while(|(a, b)| a == b)
            .count();
        // Loads of the same ruptures only: those before the sequences part.
        let common = reference.events[..same]
            .iter()
            .filter(|(kind, _)| *kind == 0)
            .count()
            .min(100);
        let loads = run
            .ruptures
            .iter()
            .zip(&reference.ruptures)
            .take(common)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs() / b.abs()));
        let loads = if common == 100 {
            format!("{loads:.1e}")
        } else {
            format!("{loads:.1e} (first {common})")
        };
        let length = grid.iter().fold(0.0f64, |m, &x| {
            m.max((length_at(&run.curve, x) - length_at(&reference.curve, x)).abs())
        });
        let slip = (run.slip - reference.slip).abs() / reference.slip;
        let area0 = (run.area0 - reference.area0).abs() / reference.area0;
        let all = if same == reference.events.len() && same == run.events.len() {
            format!("all {same}")
        } else {
            format!("{same} of {}", reference.events.len())
        };
        println!(
            "| {solver:.0e} | {:.2} | {loads} | {all} | {length:.4} | {slip:.1e} | {area0:.1e} |",
            run.seconds
        );
        writeln!(
            csv,
            "{solver:e},{:.4},{},{loads},{same},{length:e},{slip:e},{area0:e}",
            run.seconds,
            run.events.len()
        )?;
    }
    eprintln!("wrote {path}");
    Ok(())
}
