//! Paper Figs. S4-S9: how the precursor curves ℓ/Lx against F/(μF_N) depend on the sample
//! sizes, rod at h = 6 mm (Δh = 2 mm), F_N = 4 kN, averaged over 10 realizations, 1 mm
//! cells. The captions give the fixed sizes; the varied ones are chosen here.
//!
//! * S4: Ly = 4, 7, 14, 28 mm (Lx = 41 mm, Lz = 132 mm);
//! * S5: Lz = 20, 40, 75, 132 mm (Lx = 141 mm, Ly = 7 mm);
//! * S6: Lx/Ly ≈ 6 (Lz = 100 mm): (Lx, Ly) = (42, 7), (84, 14), (126, 21) mm;
//! * S7: Lx/Lz ≈ 4 (Ly = 7 mm): (Lx, Lz) = (80, 20), (160, 40), (240, 60) mm;
//! * S8: Ly/Lz ≈ 0.36 (Lx = 141 mm): (Ly, Lz) = (7, 19.4), (14, 38.9), (28, 77.8) mm;
//! * S9: h/Lz ≈ 0.46 (Lx = 141 mm, Ly = 7 mm): (h, Lz) = (6, 13), (12, 26), (24, 52),
//!   (35, 76) mm.
//!
//! The paper's claim: the curves depend on each size (no collapse in S4-S9), and
//! precursors fade as a size grows (a larger force is needed for a given ℓ/Lx).
//! Writes `figS4.csv` ... `figS9.csv` and `.png`: ℓ/Lx against F/(μF_N), one curve per
//! size with legend entries such as `Ly = 4 mm` or `h = 6 mm, Lz = 13 mm` (see
//! `figures::precursor_panel`).
//! Run: `cargo run --release --example figS_sizes [output directory] [realizations]`.

#[path = "support/report.rs"]
mod report;

#[path = "support/figures.rs"]
mod figures;

use figures::Curve;
use precursors::{Drive, Lateral, Scene, SceneBuilder};
use std::process::ExitCode;

fn rod(lx: f64, ly: f64, lz: f64, h: f64) -> SceneBuilder {
    Scene::builder()
        .block(lx * 1e-3, ly * 1e-3, lz * 1e-3)
        .normal_load(4e3)
        .drive(Drive::Force(
            Lateral::Rod {
                height: h * 1e-3,
                half_width: 2e-3,
            }
            .into(),
        ))
}

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let figures::Args { dir, seeds } = figures::args(Some(1))?;
    let panels: Vec<(&str, &str, Vec<Curve>)> = vec![
        (
            "figS4",
            "Fig. S4: Lx = 41 mm, Lz = 132 mm, rod h = 6 mm, F_N = 4 kN",
            [4.0, 7.0, 14.0, 28.0]
                .iter()
                .map(|&ly| {
                    Curve::new(
                        format!("Ly{ly}"),
                        format!("Ly = {ly} mm"),
                        rod(41.0, ly, 132.0, 6.0),
                    )
                })
                .collect(),
        ),
        (
            "figS5",
            "Fig. S5: Lx = 141 mm, Ly = 7 mm, rod h = 6 mm, F_N = 4 kN",
            [20.0, 40.0, 75.0, 132.0]
                .iter()
                .map(|&lz| {
                    Curve::new(
                        format!("Lz{lz}"),
                        format!("Lz = {lz} mm"),
                        rod(141.0, 7.0, lz, 6.0),
                    )
                })
                .collect(),
        ),
        (
            "figS6",
            "Fig. S6: Lx/Ly ≈ 6, Lz = 100 mm, rod h = 6 mm, F_N = 4 kN",
            [(42.0, 7.0), (84.0, 14.0), (126.0, 21.0)]
                .iter()
                .map(|&(lx, ly)| {
                    Curve::new(
                        format!("Lx{lx}Ly{ly}"),
                        format!("Lx = {lx} mm, Ly = {ly} mm"),
                        rod(lx, ly, 100.0, 6.0),
                    )
                })
                .collect(),
        ),
        (
            "figS7",
            "Fig. S7: Lx/Lz ≈ 4, Ly = 7 mm, rod h = 6 mm, F_N = 4 kN",
            [(80.0, 20.0), (160.0, 40.0), (240.0, 60.0)]
                .iter()
                .map(|&(lx, lz)| {
                    Curve::new(
                        format!("Lx{lx}Lz{lz}"),
                        format!("Lx = {lx} mm, Lz = {lz} mm"),
                        rod(lx, 7.0, lz, 6.0),
                    )
                })
                .collect(),
        ),
        (
            "figS8",
            "Fig. S8: Ly/Lz ≈ 0.36, Lx = 141 mm, rod h = 6 mm, F_N = 4 kN",
            [7.0, 14.0, 28.0]
                .iter()
                .map(|&ly| {
                    let lz = ly / 0.36;
                    Curve::new(
                        format!("Ly{ly}Lz{lz:.1}"),
                        format!("Ly = {ly} mm, Lz = {lz:.1} mm"),
                        rod(141.0, ly, lz, 6.0),
                    )
                })
                .collect(),
        ),
        (
            "figS9",
            "Fig. S9: h/Lz ≈ 0.46, Lx = 141 mm, Ly = 7 mm, F_N = 4 kN",
            [(6.0, 13.0), (12.0, 26.0), (24.0, 52.0), (35.0, 76.0)]
                .iter()
                .map(|&(h, lz)| {
                    Curve::new(
                        format!("h{h}Lz{lz}"),
                        format!("h = {h} mm, Lz = {lz} mm"),
                        rod(141.0, 7.0, lz, h),
                    )
                })
                .collect(),
        ),
    ];
    for (name, title, curves) in &panels {
        figures::precursor_panel(&dir, name, title, curves, &seeds)?;
    }
    println!("wrote {dir}/figS4.csv ... figS9.csv and the PNGs");
    Ok(())
}
