//! Paper Fig. 2a (Archard / Amontons' second law): the real contact area at zero shear in
//! % of the nominal area `A0 = Lx Ly` against the normal load, for a 30 x 6 x 150 mm block
//! (1 mm cells), averaged over height realizations (seeds 1-10; the second argument
//! changes the count, at least 2). The model's `A_R` grows linearly
//! with `F_N` (`A_R = α F_N`); the least-squares slope and intercept are printed.
//!
//! Writes `fig2a.csv` (normal_load_N, area_percent_mean, area_percent_sd, alpha_m2_per_N)
//! and `fig2a.png`: A_R/A0 (%) against F_N (N) from 0 to 4.2 kN, the realizations' mean
//! at each load (markers) and the least-squares line.
//! Run: `cargo run --release --example fig2a_archard [output directory] [realizations]`.

#[path = "support/report.rs"]
mod report;

#[path = "support/figures.rs"]
mod figures;

use precursors::plot::{Chart, Corner};
use precursors::Scene;
use std::process::ExitCode;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    // The sample standard deviation needs two realizations.
    let figures::Args { dir, seeds } = figures::args(Some(2))?;
    let loads: Vec<f64> = (1..=8).map(|k| 500.0 * k as f64).collect();
    let a0 = 0.030 * 0.006;
    let mut rows = Vec::new();
    let mut points = Vec::new();
    for &f_n in &loads {
        let mut values = Vec::new();
        for &seed in &seeds {
            let scene = Scene::builder()
                .block(0.030, 0.006, 0.150)
                .normal_load(f_n)
                .seed(seed)
                .build()?;
            let mut driver = scene.driver()?;
            driver.step()?; // the normal equilibrium at zero shear
            values.push(100.0 * driver.real_contact_area()? / a0);
        }
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>()
            / (values.len() - 1) as f64)
            .sqrt();
        rows.push(format!(
            "{f_n},{mean:.6},{sd:.6},{:.6e}",
            mean / 100.0 * a0 / f_n
        ));
        points.push((f_n, mean));
        println!("F_N = {f_n:6.0} N: A_R/A0 = {mean:.4} % (sd {sd:.4} %)");
    }
    // Least squares A = a F_N + b.
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let sxx: f64 = points.iter().map(|(x, _)| x * x).sum();
    let sxy: f64 = points.iter().map(|(x, y)| x * y).sum();
    let slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    let intercept = (sy - slope * sx) / n;
    println!(
        "linear fit: A_R/A0 = {slope:.4e} %/N · F_N + {intercept:.4} %  (α = {:.4e} m²/N)",
        slope / 100.0 * a0
    );
    figures::write_csv(
        &format!("{dir}/fig2a.csv"),
        "normal_load_N,area_percent_mean,area_percent_sd,alpha_m2_per_N",
        &rows,
    )?;
    let top = points.iter().fold(0.0f64, |m, p| m.max(p.1)) * 1.15;
    Chart::new(
        &format!(
            "Fig. 2a: real contact area at zero shear, 30 x 6 x 150 mm, {}",
            figures::realizations(seeds.len())
        ),
        "F_N (N)",
        "A_R/A0 (%)",
    )
    .x_range(0.0, 4200.0)
    .y_range(0.0, top)
    .markers("mean of the realizations", &points)
    .line(
        &format!(
            "least squares: {:.4} %/kN · F_N {} {:.3} %",
            slope * 1e3,
            if intercept < 0.0 { "−" } else { "+" },
            intercept.abs()
        ),
        &[(0.0, intercept), (4200.0, intercept + slope * 4200.0)],
    )
    .legend(Corner::UpperLeft)
    .save(format!("{dir}/fig2a.png"))?;
    println!("wrote {dir}/fig2a.csv and {dir}/fig2a.png");
    Ok(())
}
