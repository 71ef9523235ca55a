//! Paper Fig. 4: stick-slip under displacement control. The calibration block (140 x 7 x
//! 75 mm, 1 mm cells, F_N = 3.5 kN, seed 1) is driven through a spring of stiffness
//! K_S = 4e6 N/m acting on the trailing edge as the paper's rod (h = 6 mm, Δh = 2 mm):
//! the drive displacement U_S grows, the spring force K_S (U_S - ⟨u_x⟩) rises while the
//! interface sticks and drops at each slip.
//!
//! Writes `fig4.csv` (one row per load step and per rupture: event, drive_displacement_m,
//! spring_force_N, force_over_mu_FN) and `fig4.png`: the spring force F_S/(μF_N)
//! against the drive displacement U_S (μm), one point per load step and per rupture.
//! Prints the number of drops and the largest one.
//! Run: `cargo run --release --example fig4_stick_slip [output directory]`.

#[path = "support/report.rs"]
mod report;

#[path = "support/figures.rs"]
mod figures;

use precursors::plot::{Chart, Corner};
use precursors::{Drive, Event, Lateral, Scene};
use std::ops::ControlFlow;
use std::process::ExitCode;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let dir = figures::args(None)?.dir;
    let scene = Scene::builder()
        .drive(Drive::Spring {
            stiffness: 4e6,
            lateral: Lateral::Rod {
                height: 6e-3,
                half_width: 2e-3,
            },
        })
        .seed(1)
        .build()?;
    let mu_fn = scene.material().friction_coefficient() * scene.normal_load();
    let mut driver = scene.driver()?;
    let mut rows = Vec::new();
    let mut points = Vec::new();
    driver.run(|event, d| {
        let (kind, load) = match event {
            Event::LoadRaised { load } => ("load_raised", *load),
            Event::Stable { load, .. } => ("stable", *load),
            Event::GlobalSlip { load } => ("global_slip", *load),
            _ => return ControlFlow::Continue(()),
        };
        // After the event: the spring force of the current state.
        let u = load.drive_displacement.unwrap_or(f64::NAN);
        let f = d.spring_force().unwrap_or(f64::NAN);
        rows.push(format!("{kind},{u:.9e},{f:.9e},{:.9e}", f / mu_fn));
        points.push((u, f / mu_fn));
        ControlFlow::<()>::Continue(())
    })?;
    figures::write_csv(
        &format!("{dir}/fig4.csv"),
        "event,drive_displacement_m,spring_force_N,force_over_mu_FN",
        &rows,
    )?;
    let drops: Vec<f64> = points
        .windows(2)
        .map(|w| w[0].1 - w[1].1)
        .filter(|d| *d > 1e-12)
        .collect();
    let largest = drops.iter().fold(0.0f64, |m, d| m.max(*d));
    let u_max = points.iter().fold(0.0f64, |m, p| m.max(p.0));
    let microns: Vec<(f64, f64)> = points.iter().map(|(u, f)| (u * 1e6, *f)).collect();
    Chart::new(
        "Fig. 4: stick-slip, 140 x 7 x 75 mm, F_N = 3.5 kN, spring K_S = 4 MN/m on a rod \
         (h = 6 mm), seed 1",
        "U_S (μm)",
        "F_S/(μF_N)",
    )
    .x_range(0.0, u_max * 1e6 * 1.05)
    .y_range(0.0, 1.1)
    .line("spring force K_S (U_S − ⟨u_x⟩)", &microns)
    .legend(Corner::LowerRight)
    .size(1000, 600)
    .save(format!("{dir}/fig4.png"))?;
    println!(
        "{} force drops (stick-slip), largest {:.4} μF_N; global slip at U_S = {:.4e} m",
        drops.len(),
        largest,
        u_max
    );
    println!("wrote {dir}/fig4.csv and {dir}/fig4.png");
    Ok(())
}
