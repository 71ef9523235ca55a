//! Paper Fig. 3b-d: the y-averaged real contact area `A_R(x, F)/A_R(x, 0)` during the
//! quasi-static loading of a 200 x 7 x 75 mm block (1 mm cells, F_N = 2.7 kN, seed 1),
//! for a rod (h = 6 mm, Δh = 2 mm), a uniform side load and a uniform top load.
//!
//! Writes `fig3_<drive>.csv` (one row per stable state and column: force_over_mu_FN, x_m,
//! area_ratio) and `fig3_<drive>.png`: a map over x (mm) along the block (trailing edge
//! left) and F/(μF_N) from 0 (bottom) to 1 (top), each load showing the last stable state
//! at or below it; the colour bar gives log₁₀(A_R(x)/A_R(x, 0)): blue where the area fell
//! (the precursor), red where it grew, white unchanged, saturating at a factor 10 (the
//! colour bar's triangles and the line under the map give the share beyond it); a column
//! that lost all contact is grey. Prints the precursor length ℓ/Lx at
//! a few loads.
//! Run: `cargo run --release --example fig3_contact_maps [output directory]`.

#[path = "support/report.rs"]
mod report;

#[path = "support/figures.rs"]
mod figures;

use precursors::plot::{Map, Palette};
use precursors::{Drive, Event, ForceLoad, Lateral, Scene};
use std::ops::ControlFlow;
use std::process::ExitCode;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let dir = figures::args(None)?.dir;
    let drives = [
        (
            "rod",
            "rod at h = 6 mm",
            Drive::Force(ForceLoad::Lateral(Lateral::Rod {
                height: 6e-3,
                half_width: 2e-3,
            })),
        ),
        (
            "side",
            "uniform side load",
            Drive::Force(ForceLoad::Lateral(Lateral::Side)),
        ),
        ("top", "uniform top load", Drive::Force(ForceLoad::Top)),
    ];
    for (name, what, drive) in drives {
        let scene = Scene::builder()
            .block(0.200, 0.007, 0.075)
            .normal_load(2.7e3)
            .drive(drive)
            .seed(1)
            .build()?;
        let nx = scene.grid().nx();
        let dx = scene.grid().dx();
        let mu_fn = scene.material().friction_coefficient() * scene.normal_load();
        let mut driver = scene.driver()?;
        let mut states: Vec<(f64, Vec<f64>, f64)> = Vec::new();
        driver.run(|event, d| {
            if let Event::Stable { load, .. } = event {
                let now = d.column_contact_area().unwrap_or_default();
                let ratio = now
                    .iter()
                    .zip(d.initial_column_contact_area())
                    .map(|(a, b)| a / b)
                    .collect();
                states.push((
                    load.force / mu_fn,
                    ratio,
                    d.precursor_length().unwrap_or(0.0),
                ));
            }
            ControlFlow::<()>::Continue(())
        })?;
        let mut rows = Vec::new();
        for (f, ratio, _) in &states {
            for (ix, r) in ratio.iter().enumerate() {
                rows.push(format!("{f:.9},{:.4e},{r:.6e}", (ix as f64 + 0.5) * dx));
            }
        }
        figures::write_csv(
            &format!("{dir}/fig3_{name}.csv"),
            "force_over_mu_FN,x_m,area_ratio",
            &rows,
        )?;
        // Raster: 400 load rows; each shows the last stable state at or below its load.
        let load_rows = 400;
        let mut map = vec![f64::NAN; nx * load_rows];
        for r in 0..load_rows {
            let f = (r as f64 + 0.5) / load_rows as f64;
            if let Some((_, ratio, _)) = states.iter().take_while(|s| s.0 <= f).last() {
                for (ix, v) in ratio.iter().enumerate() {
                    // Beyond a factor 10 the map saturates and marks it on its colour
                    // bar; a column without contact (log10(0) = -inf) is drawn grey.
                    map[r * nx + ix] = if *v > 0.0 { v.log10() } else { f64::NAN };
                }
            }
        }
        let lx_mm = scene.grid().block().lx() * 1e3;
        Map::new(nx, load_rows, map)?
            .labels(
                &format!(
                    "Fig. 3: real contact area, {what}, 200 x 7 x 75 mm, F_N = 2.7 kN, seed 1"
                ),
                "x (mm)",
                "F/(μF_N)",
                "log₁₀(A_R(x)/A_R(x, 0)); grey: no contact",
            )
            .x_range(0.0, lx_mm)
            .y_range(0.0, 1.0)
            .colour_scale(Palette::Diverging, Some((-1.0, 1.0)))
            .size(1000, 600)
            .save(format!("{dir}/fig3_{name}.png"))?;
        let ell = |target: f64| {
            states
                .iter()
                .take_while(|s| s.0 <= target)
                .last()
                .map_or(0.0, |s| s.2 / scene.grid().block().lx())
        };
        println!(
            "{name:>4}: {} stable states; ℓ/Lx = {:.3}, {:.3}, {:.3} at F/(μF_N) = 0.5, 0.8, 0.95",
            states.len(),
            ell(0.5),
            ell(0.8),
            ell(0.95)
        );
    }
    println!("wrote {dir}/fig3_{{rod,side,top}}.csv and .png");
    Ok(())
}
