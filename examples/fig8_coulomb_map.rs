//! Paper Fig. 8: the y-averaged Coulomb stress τ_C(x, z) = |τ(x,z)| - μ|σ(x,z)| in the
//! x-z plane of the Fig. 7 block (200 x 7 x 100 mm, F_N = 6.25 kN, top and rod shear with
//! F_top = F_lat, seed 1) at four stages: just before the first precursor (the last
//! stable state before ℓ exceeds 5 mm, as in fig7_stresses) and at the stable states
//! reached at F/(μF_N) = 0.6, 0.8 and 0.95. Planes every 1 mm from z = 0.5 mm to 99.5 mm.
//!
//! Writes `fig8.csv` (stage, force_over_mu_FN, precursor_m, x_m, z_m, coulomb_Pa) and
//! `fig8_<stage>.png` (stage `before`, `0.6`, `0.8`, `0.95`): a map of τ_C (MPa) over x
//! (mm, right) and z (mm, up; the interface at the bottom), titled with the stage's load
//! and precursor length; red where τ_C > 0, blue where τ_C < 0, the colour bar from −2 to
//! 2 MPa (saturating).
//! Run: `cargo run --release --example fig8_coulomb_map [output directory]`.

#[path = "support/report.rs"]
mod report;

#[path = "support/figures.rs"]
mod figures;

use precursors::plot::{Map, Palette};
use precursors::Event;
use precursors::ProbeSpec;
use std::process::ExitCode;

const THRESHOLD: f64 = 5e-3;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let dir = figures::args(None)?.dir;
    let heights: Vec<f64> = (0..100).map(|k| (k as f64 + 0.5) * 1e-3).collect();
    let mut spec = ProbeSpec::default();
    for &z in &heights {
        spec = spec.with_plane(z);
    }
    let scene = figures::stress_block().probes(spec).seed(1).build()?;
    let mu = scene.material().friction_coefficient();
    let mu_fn = mu * scene.normal_load();
    let nx = scene.grid().nx();
    let lx_mm = scene.grid().block().lx() * 1e3;
    // τ_C(x, z) of the y-averages, rows = planes.
    let map = |d: &precursors::Driver| -> precursors::Result<Vec<f64>> {
        let s = d.stresses()?;
        Ok(s.planes
            .iter()
            .flat_map(|p| p.profile().coulomb_of_means().to_vec())
            .collect())
    };
    let mut stages: Vec<(String, f64, f64, Vec<f64>)> = Vec::new();
    let mut before: Option<(f64, f64, Vec<f64>)> = None;
    let mut targets = vec![0.6, 0.8, 0.95].into_iter().peekable();
    let mut driver = scene.driver()?;
    while let Some(event) = driver.step()? {
        let Event::Stable { load, .. } = event else {
            continue;
        };
        let f = load.force / mu_fn;
        let ell = driver.precursor_length()?;
        if stages.is_empty() {
            if ell > THRESHOLD {
                let (bf, bl, m) = before.take().ok_or("no state before the precursor")?;
                stages.push(("before".into(), bf, bl, m));
            } else {
                before = Some((f, ell, map(&driver)?));
            }
        }
        if let Some(&t) = targets.peek() {
            if f >= t && !stages.is_empty() {
                stages.push((format!("{t}"), f, ell, map(&driver)?));
                targets.next();
            }
        }
    }
    let mut rows = Vec::new();
    for (name, f, ell, values) in &stages {
        for (k, z) in heights.iter().enumerate() {
            for ix in 0..nx {
                rows.push(format!(
                    "{name},{f:.6},{ell:.4e},{:.4e},{z:.4e},{:.6e}",
                    (ix as f64 + 0.5) * 1e-3,
                    values[k * nx + ix]
                ));
            }
        }
        let stage = if name == "before" {
            format!("before the first precursor, F/(μF_N) = {f:.3}")
        } else {
            format!("at F/(μF_N) = {f:.3} (first state ≥ {name})")
        };
        let mpa: Vec<f64> = values.iter().map(|v| v / 1e6).collect();
        Map::new(nx, heights.len(), mpa)?
            .labels(
                &format!("Fig. 8: τ_C {stage}, ℓ = {:.0} mm, seed 1", ell * 1e3),
                "x (mm)",
                "z (mm)",
                "τ_C = |τ| − μ|σ| (MPa)",
            )
            .x_range(0.0, lx_mm)
            .y_range(0.0, heights.len() as f64) // planes 1 mm apart, to the top face
            .same_unit_axes() // 200 x 100 mm: the line under the map states the aspect
            .colour_scale(Palette::Diverging, Some((-2.0, 2.0)))
            .size(1000, 600)
            .save(format!("{dir}/fig8_{name}.png"))?;
        let positive = values.iter().filter(|v| **v > 0.0).count();
        println!(
            "stage {name:>6}: F/(μF_N) = {f:.3}, ℓ = {:.0} mm, τ_C > 0 on {:.1} % of the x-z plane",
            ell * 1e3,
            100.0 * positive as f64 / values.len() as f64
        );
    }
    figures::write_csv(
        &format!("{dir}/fig8.csv"),
        "stage,force_over_mu_FN,precursor_m,x_m,z_m,coulomb_Pa",
        &rows,
    )?;
    println!("wrote {dir}/fig8.csv and {dir}/fig8_<stage>.png");
    Ok(())
}
