//! Paper Fig. 5: rescaled precursor curves ℓ/Lx against F/(μF_N), averaged over 10 height
//! realizations (seeds 1-10; the second argument changes the count), rod at the trailing edge (Δh = 2 mm), 1 mm cells.
//!
//! * 5a: Ly = 7 mm, Lz = 75 mm, h = 6 mm, Lx = 100, 140, 200 mm (the experimental range,
//!   where the paper finds an approximate collapse) and 280, 350 mm (its inset). The
//!   paper does not list its F_N per Lx; the nominal pressure is kept at that of the
//!   calibration scene (3.5 kN on 140 x 7 mm).
//! * 5b: Lx = 140 mm, Ly = 7 mm, Lz = 75 mm, F_N = 3 kN, h = 2, 4, 6, 8, 10 mm
//!   (experimental range) and 20, 40, 73 mm (inset).
//!
//! Writes `fig5a.csv` / `fig5b.csv` (force_over_mu_FN, then one column of ℓ/Lx per curve)
//! and `fig5a.png` / `fig5b.png`: ℓ/Lx against F/(μF_N), one colour per curve in the
//! CSV's column order, legend entries `Lx = 100 mm`, ... and `h = 2 mm`, ... (see
//! `figures::precursor_panel`).
//! Prints, per curve, the load at which ℓ/Lx first reaches 0.1 and 0.5.
//! Run: `cargo run --release --example fig5_collapse [output directory] [realizations]`
//! (about 10 minutes with 10 realizations).

#[path = "support/report.rs"]
mod report;

#[path = "support/figures.rs"]
mod figures;

use figures::Curve;
use precursors::{Drive, Lateral, Scene};
use std::process::ExitCode;

fn rod(height: f64) -> Drive {
    Drive::Force(
        Lateral::Rod {
            height,
            half_width: 2e-3,
        }
        .into(),
    )
}

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let figures::Args { dir, seeds } = figures::args(Some(1))?;
    let pressure = 3.5e3 / (0.140 * 0.007);
    let a: Vec<Curve> = [0.100, 0.140, 0.200, 0.280, 0.350]
        .iter()
        .map(|&lx| {
            Curve::new(
                format!("Lx{:.0}mm", lx * 1e3),
                format!("Lx = {:.0} mm", lx * 1e3),
                Scene::builder()
                    .block(lx, 0.007, 0.075)
                    .normal_load(pressure * lx * 0.007)
                    .drive(rod(6e-3)),
            )
        })
        .collect();
    figures::precursor_panel(
        &dir,
        "fig5a",
        &format!(
            "Fig. 5a: Ly = 7 mm, Lz = 75 mm, h = 6 mm, F_N/(Lx·Ly) = {:.2} MPa",
            pressure / 1e6
        ),
        &a,
        &seeds,
    )?;
    let b: Vec<Curve> = [2e-3, 4e-3, 6e-3, 8e-3, 10e-3, 20e-3, 40e-3, 73e-3]
        .iter()
        .map(|&h| {
            Curve::new(
                format!("h{:.0}mm", h * 1e3),
                format!("h = {:.0} mm", h * 1e3),
                Scene::builder().normal_load(3.0e3).drive(rod(h)),
            )
        })
        .collect();
    figures::precursor_panel(
        &dir,
        "fig5b",
        "Fig. 5b: 140 x 7 x 75 mm, F_N = 3 kN, rod height h",
        &b,
        &seeds,
    )?;
    println!("wrote {dir}/fig5a.csv, {dir}/fig5b.csv and the PNGs");
    Ok(())
}
