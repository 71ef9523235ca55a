//! Paper Fig. S10: the quasi-static evolution of the y-averaged normal and shear stresses
//! |σ(x, z_P)| and |τ(x, z_P)| on the plane z_P = 2 mm, block 200 x 7 x 100 mm, F_N =
//! 6.25 kN, rod (h = 6 mm, Δh = 2 mm) plus top shear with F_top = F_lat (as in
//! fig7_stresses), averaged over 10 realizations, at F/(μF_N) = 0, 0.1, ..., 0.9 (the
//! stable state reached at each load).
//!
//! Writes `figS10.csv` (force_over_mu_FN, x_m, abs_sigma_Pa, abs_tau_Pa) and
//! `figS10_sigma.png`, `figS10_tau.png`: |σ_zz(x, z_P)| and |τ_xz(x, z_P)| (MPa) against
//! x (mm), one colour per load along a sequential map (viridis, dark to green) as the load grows, with legend
//! entries `F/(μF_N) = 0.0`, ..., `0.9`.
//! Run: `cargo run --release --example figS10_stress_evolution [output directory] [realizations]`.

#[path = "support/report.rs"]
mod report;

#[path = "support/figures.rs"]
mod figures;

use precursors::plot::{Chart, Colours, Corner};
use precursors::Event;
use precursors::ProbeSpec;
use std::process::ExitCode;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let figures::Args { dir, seeds } = figures::args(Some(1))?;
    let levels: Vec<f64> = (0..10).map(|k| 0.1 * k as f64).collect();
    let nx = 200;
    let mut sigma = vec![vec![0.0; nx]; levels.len()];
    let mut tau = vec![vec![0.0; nx]; levels.len()];
    for &seed in &seeds {
        let scene = figures::stress_block()
            .probes(ProbeSpec::default().with_plane(2e-3))
            .seed(seed)
            .build()?;
        let mu = scene.material().friction_coefficient();
        let mu_fn = mu * scene.normal_load();
        let mut driver = scene.driver()?;
        let mut next = 0;
        while let Some(event) = driver.step()? {
            let Event::Stable { load, .. } = event else {
                continue;
            };
            while next < levels.len() && load.force / mu_fn >= levels[next] {
                let p = driver.stresses()?.planes[0].profile();
                for ix in 0..nx {
                    sigma[next][ix] += p.normal()[ix].abs() / seeds.len() as f64;
                    tau[next][ix] += p.shear()[ix].abs() / seeds.len() as f64;
                }
                next += 1;
            }
            if next == levels.len() {
                break;
            }
        }
    }
    let mut rows = Vec::new();
    for (k, f) in levels.iter().enumerate() {
        for ix in 0..nx {
            rows.push(format!(
                "{f:.1},{:.4e},{:.6e},{:.6e}",
                (ix as f64 + 0.5) * 1e-3,
                sigma[k][ix],
                tau[k][ix]
            ));
        }
    }
    figures::write_csv(
        &format!("{dir}/figS10.csv"),
        "force_over_mu_FN,x_m,abs_sigma_Pa,abs_tau_Pa",
        &rows,
    )?;
    let figures = [
        ("sigma", "normal stress", "|σ_{zz}(x, z_P)| (MPa)", &sigma),
        ("tau", "shear stress", "|τ_{xz}(x, z_P)| (MPa)", &tau),
    ];
    for (name, what, y_label, data) in figures {
        let top = data.iter().flatten().fold(0.0f64, |m, v| m.max(*v)) / 1e6;
        let mut chart = Chart::new(
            &format!(
                "Fig. S10: {what} at z_P = 2 mm as the load grows, {}",
                figures::realizations(seeds.len())
            ),
            "x (mm)",
            y_label,
        )
        .x_range(0.0, nx as f64)
        .y_range(0.0, top * 1.1)
        .legend(Corner::UpperRight)
        .colours(Colours::Ordered)
        .size(1000, 600);
        for (k, profile) in data.iter().enumerate() {
            // Cells of 1 mm.
            let points: Vec<(f64, f64)> = profile
                .iter()
                .enumerate()
                .map(|(ix, v)| (ix as f64 + 0.5, v / 1e6))
                .collect();
            chart = chart.line(&format!("F/(μF_N) = {:.1}", levels[k]), &points);
        }
        chart.save(format!("{dir}/figS10_{name}.png"))?;
    }
    let edge = |d: &Vec<Vec<f64>>, k: usize| d[k][0] / 1e6;
    println!(
        "|τ(0, z_P)| grows from {:.3} to {:.3} MPa and |σ(0, z_P)| goes from {:.3} to {:.3} MPa \
         between F/(μF_N) = 0 and 0.9",
        edge(&tau, 0),
        edge(&tau, levels.len() - 1),
        edge(&sigma, 0),
        edge(&sigma, levels.len() - 1)
    );
    println!("wrote {dir}/figS10.csv and the PNGs");
    Ok(())
}
