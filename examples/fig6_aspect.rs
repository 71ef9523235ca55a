//! Paper Fig. 6: rescaled precursor curves ℓ/Lx against F/(μF_N) (averaged over 10 height
//! realizations, 1 mm cells).
//!
//! Uniform side load:
//! * 6a: Lx/Ly ≈ 6.1 with F_N = 4 kN, Lz = 10 mm: (Lx, Ly) = (43, 7), (61, 10), (92, 15),
//!   (122, 20) mm;
//! * 6b: Lx/Lz = 2 with Ly = 7 mm, F_N = 4 kN: (Lx, Lz) = (40, 20), (80, 40), (140, 70),
//!   (200, 100) mm;
//! * 6c: Ly/Lz ≈ 0.36 with Lx = 40 mm, F_N = 4 kN: (Ly, Lz) = (7, 19.4), (14, 38.9),
//!   (29, 80.6), (50, 138.9) mm.
//!
//! Mixed loading, rod (h = 6 mm, Δh = 2 mm) plus top with F_top = n F_lat:
//! * 6d: n = 0, 0.5, 1, 2, 5, F_N = 2.7 kN, Lx = 201 mm, Ly = 7 mm, Lz = 132 mm.
//!
//! The paper gives the ratios and the fixed sizes; the individual sizes are chosen here.
//! The claim: (a) and (b) collapse (the interface shear depends on R = Lx/(Ly Lz)),
//! (c) does not and the precursors fade as Ly, Lz grow, (d) precursors are suppressed for
//! large n.
//! Writes `fig6{a,b,c,d}.csv` and `.png`: ℓ/Lx against F/(μF_N), one curve per size (or
//! per n in 6d) with legend entries such as `Lx = 43 mm, Ly = 7 mm` and `n = 0.5` (see
//! `figures::precursor_panel`).
//! Run: `cargo run --release --example fig6_aspect [output directory] [realizations]`.

#[path = "support/report.rs"]
mod report;

#[path = "support/figures.rs"]
mod figures;

use figures::Curve;
use precursors::{Drive, ForceLoad, Lateral, Scene, SceneBuilder};
use std::process::ExitCode;

fn side(lx: f64, ly: f64, lz: f64, f_n: f64) -> SceneBuilder {
    Scene::builder()
        .block(lx, ly, lz)
        .normal_load(f_n)
        .drive(Drive::Force(ForceLoad::Lateral(Lateral::Side)))
}

fn mm(v: f64) -> f64 {
    v * 1e-3
}

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let figures::Args { dir, seeds } = figures::args(Some(1))?;
    let a: Vec<_> = [(43.0, 7.0), (61.0, 10.0), (92.0, 15.0), (122.0, 20.0)]
        .iter()
        .map(|&(lx, ly)| {
            Curve::new(
                format!("Lx{lx}Ly{ly}"),
                format!("Lx = {lx} mm, Ly = {ly} mm"),
                side(mm(lx), mm(ly), mm(10.0), 4e3),
            )
        })
        .collect();
    figures::precursor_panel(
        &dir,
        "fig6a",
        "Fig. 6a: side load, Lx/Ly ≈ 6.1, Lz = 10 mm, F_N = 4 kN",
        &a,
        &seeds,
    )?;
    let b: Vec<_> = [(40.0, 20.0), (80.0, 40.0), (140.0, 70.0), (200.0, 100.0)]
        .iter()
        .map(|&(lx, lz)| {
            Curve::new(
                format!("Lx{lx}Lz{lz}"),
                format!("Lx = {lx} mm, Lz = {lz} mm"),
                side(mm(lx), mm(7.0), mm(lz), 4e3),
            )
        })
        .collect();
    figures::precursor_panel(
        &dir,
        "fig6b",
        "Fig. 6b: side load, Lx/Lz = 2, Ly = 7 mm, F_N = 4 kN",
        &b,
        &seeds,
    )?;
    let c: Vec<_> = [7.0, 14.0, 29.0, 50.0]
        .iter()
        .map(|&ly| {
            let lz = ly / 0.36;
            Curve::new(
                format!("Ly{ly}Lz{lz:.1}"),
                format!("Ly = {ly} mm, Lz = {lz:.1} mm"),
                side(mm(40.0), mm(ly), mm(lz), 4e3),
            )
        })
        .collect();
    figures::precursor_panel(
        &dir,
        "fig6c",
        "Fig. 6c: side load, Ly/Lz ≈ 0.36, Lx = 40 mm, F_N = 4 kN",
        &c,
        &seeds,
    )?;
    let d: Vec<_> = [0.0, 0.5, 1.0, 2.0, 5.0]
        .iter()
        .map(|&n| {
            Curve::new(
                format!("n{n}"),
                format!("n = {n}"),
                Scene::builder()
                    .block(mm(201.0), mm(7.0), mm(132.0))
                    .cells(201, 7)
                    .normal_load(2.7e3)
                    .drive(Drive::Force(ForceLoad::Mixed {
                        ratio: n,
                        lateral: Lateral::Rod {
                            height: 6e-3,
                            half_width: 2e-3,
                        },
                    })),
            )
        })
        .collect();
    figures::precursor_panel(
        &dir,
        "fig6d",
        "Fig. 6d: rod (h = 6 mm) + top, F_{top} = n·F_{lat}, 201 x 7 x 132 mm, F_N = 2.7 kN",
        &d,
        &seeds,
    )?;
    println!("wrote {dir}/fig6{{a,b,c,d}}.csv and .png");
    Ok(())
}
