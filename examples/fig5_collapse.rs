//! Paper Fig. 5: rescaled precursor curves ℓ/Lx against F/(μF_N), averaged over 10 height
//! realizations (seeds 1-10), rod at the trailing edge (Δh = 2 mm), 1 mm cells.
//!
//! * 5a: Ly = 7 mm, Lz = 75 mm, h = 6 mm, Lx = 100, 140, 200 mm (the experimental range,
//!   where the paper finds an approximate collapse) and 280, 350 mm (its inset). The
//!   paper does not list its F_N per Lx; the nominal pressure is kept at that of the
//!   calibration scene (3.5 kN on 140 x 7 mm).
//! * 5b: Lx = 140 mm, Ly = 7 mm, Lz = 75 mm, F_N = 3 kN, h = 2, 4, 6, 8, 10 mm
//!   (experimental range) and 20, 40, 73 mm (inset).
//!
//! Writes `fig5a.csv` / `fig5b.csv` (force_over_mu_FN, then one column of ℓ/Lx per curve)
//! and `fig5a.png` / `fig5b.png` (one colour per curve, in the CSV's column order).
//! Prints, per curve, the load at which ℓ/Lx first reaches 0.1 and 0.5.
//! Run: `cargo run --release --example fig5_collapse [output directory]` (a few minutes).

#[path = "support/figures.rs"]
mod figures;
#[path = "support/plot.rs"]
mod plot;

use precursors::{Drive, Lateral, Scene, SceneBuilder};

fn rod(height: f64) -> Drive {
    Drive::Force(
        Lateral::Rod {
            height,
            half_width: 2e-3,
        }
        .into(),
    )
}

fn panel(
    dir: &str,
    name: &str,
    curves: &[(String, SceneBuilder)],
) -> Result<(), Box<dyn std::error::Error>> {
    let seeds: Vec<u64> = (1..=10).collect();
    let grid = figures::unit_grid(0.005);
    let mut columns = Vec::new();
    for (label, builder) in curves {
        let mean = figures::mean_precursor_curve(builder, &seeds, &grid)?;
        let reach = |level: f64| {
            grid.iter()
                .zip(&mean)
                .find(|(_, l)| **l >= level)
                .map_or(f64::NAN, |(f, _)| *f)
        };
        println!(
            "{name} {label:>10}: ℓ/Lx reaches 0.1 at F/(μF_N) = {:.3}, 0.5 at {:.3}",
            reach(0.1),
            reach(0.5)
        );
        columns.push(mean);
    }
    let header = std::iter::once("force_over_mu_FN".to_string())
        .chain(curves.iter().map(|(l, _)| format!("ell_over_Lx_{l}")))
        .collect::<Vec<_>>()
        .join(",");
    let rows: Vec<String> = grid
        .iter()
        .enumerate()
        .map(|(i, f)| {
            std::iter::once(format!("{f:.3}"))
                .chain(columns.iter().map(|c| format!("{:.5}", c[i])))
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect();
    figures::write_csv(&format!("{dir}/{name}.csv"), &header, &rows)?;
    let mut canvas = plot::Plot::new(640, 480, (0.0, 1.0), (0.0, 1.0));
    for (k, c) in columns.iter().enumerate() {
        let points: Vec<(f64, f64)> = grid.iter().copied().zip(c.iter().copied()).collect();
        canvas.line(&points, plot::COLOURS[k % plot::COLOURS.len()]);
    }
    canvas.save(&format!("{dir}/{name}.png"))?;
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = figures::out_dir();
    let pressure = 3.5e3 / (0.140 * 0.007);
    let a: Vec<(String, SceneBuilder)> = [0.100, 0.140, 0.200, 0.280, 0.350]
        .iter()
        .map(|&lx| {
            (
                format!("Lx{:.0}mm", lx * 1e3),
                Scene::builder()
                    .block(lx, 0.007, 0.075)
                    .normal_load(pressure * lx * 0.007)
                    .drive(rod(6e-3)),
            )
        })
        .collect();
    panel(&dir, "fig5a", &a)?;
    let b: Vec<(String, SceneBuilder)> = [2e-3, 4e-3, 6e-3, 8e-3, 10e-3, 20e-3, 40e-3, 73e-3]
        .iter()
        .map(|&h| {
            (
                format!("h{:.0}mm", h * 1e3),
                Scene::builder().normal_load(3.0e3).drive(rod(h)),
            )
        })
        .collect();
    panel(&dir, "fig5b", &b)?;
    println!("wrote {dir}/fig5a.csv, {dir}/fig5b.csv and the PNGs");
    Ok(())
}
