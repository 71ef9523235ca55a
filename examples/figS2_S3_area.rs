//! Paper Figs. S2 and S3: the real contact area during shearing.
//!
//! * S2: A_R(F)/A_R(0) against F/(μF_N) under uniform top shear, 100 x 7 x 75 mm,
//!   F_N = 4 kN, seed 1 (total area, one row per stable state).
//! * S3 (Amontons' first and second laws): A_R against F/(μF_N) at F_N = 4 kN for blocks
//!   of very different nominal areas: Lx x Ly = 50 x 7, 100 x 7, 140 x 14, 200 x 20 mm
//!   (Lz = 75 mm), uniform side shear and rod (h = 6 mm, Δh = 2 mm), averaged over 10
//!   realizations. A_R depends on F_N only, not on A0; every run slides at F = μF_N.
//!
//! Writes `figS2.csv` (force_over_mu_FN, area_ratio) + `figS2.png` (A_R/A_R(0) against
//! F/(μF_N) as a staircase over the stable states, shown up to A_R/A_R(0) = 2), and
//! `figS3.csv` (force_over_mu_FN, then A_R in mm² per sample and drive) + `figS3.png`
//! (A_R (mm²) against F/(μF_N) up to twice the largest A_R(0), one curve per drive and
//! sample, legend entries such as `side, 50 x 7 mm`). Prints, per sample, A_R(0), the spread of A_R(0) across samples
//! relative to its mean, and the slip load.
//! Run: `cargo run --release --example figS2_S3_area [output directory] [realizations]`.

#[path = "support/report.rs"]
mod report;

#[path = "support/figures.rs"]
mod figures;

use precursors::plot::{Chart, Corner};
use precursors::{Drive, Event, ForceLoad, Lateral, Scene, SceneBuilder};
use std::process::ExitCode;

/// `(F/(μF_N), A_R)` at every stable state, and the slip load F/(μF_N).
fn area_curve(builder: &SceneBuilder) -> precursors::Result<(Vec<(f64, f64)>, f64)> {
    let scene = builder.clone().build()?;
    let mu_fn = scene.material().friction_coefficient() * scene.normal_load();
    let mut driver = scene.driver()?;
    let mut curve = Vec::new();
    let mut slip = f64::NAN;
    while let Some(event) = driver.step()? {
        match event {
            Event::Stable { load, .. } => {
                curve.push((load.force / mu_fn, driver.real_contact_area()?))
            }
            Event::GlobalSlip { load } => slip = load.force / mu_fn,
            _ => {}
        }
    }
    Ok((curve, slip))
}

fn at(curve: &[(f64, f64)], f: f64) -> f64 {
    curve
        .iter()
        .take_while(|p| p.0 <= f)
        .last()
        .map_or(f64::NAN, |p| p.1)
}

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let figures::Args { dir, seeds } = figures::args(Some(1))?;
    // S2.
    let (curve, slip) = area_curve(
        &Scene::builder()
            .block(0.100, 0.007, 0.075)
            .normal_load(4e3)
            .drive(Drive::Force(ForceLoad::Top))
            .seed(1),
    )?;
    let a0 = curve[0].1;
    let rows: Vec<String> = curve
        .iter()
        .map(|(f, a)| format!("{f:.9},{:.9}", a / a0))
        .collect();
    figures::write_csv(
        &format!("{dir}/figS2.csv"),
        "force_over_mu_FN,area_ratio",
        &rows,
    )?;
    let points: Vec<(f64, f64)> = curve.iter().map(|(f, a)| (*f, a / a0)).collect();
    // The last few sites carry all of F_N before slip and the model's exponential area
    // law then grows without bound: the picture stops at twice the initial area (the CSV
    // has every state).
    const CAP: f64 = 2.0;
    let shown: Vec<(f64, f64)> = points.iter().copied().take_while(|p| p.1 <= CAP).collect();
    let low = points.iter().fold(1.0f64, |m, p| m.min(p.1)) * 0.98;
    let above = points.len() - shown.len();
    let label = match above {
        0 => "A_R/A_R(0) at the stable states".to_string(),
        k => format!("A_R/A_R(0) at the stable states ({k} later above {CAP}, not shown)"),
    };
    Chart::new(
        "Fig. S2: real contact area, top shear, 100 x 7 x 75 mm, F_N = 4 kN, seed 1",
        "F/(μF_N)",
        "A_R/A_R(0)",
    )
    .x_range(0.0, 1.0)
    .y_range(low, CAP)
    .steps(&label, &shown)
    .legend(Corner::UpperLeft)
    .save(format!("{dir}/figS2.png"))?;
    for target in [0.5, 0.75, 0.9, 0.95] {
        let r = points
            .iter()
            .take_while(|p| p.0 <= target)
            .last()
            .map_or(f64::NAN, |p| p.1);
        println!("S2: A_R/A_R(0) = {r:.4} at F/(μF_N) = {target}");
    }
    let last = points.last().map_or(f64::NAN, |p| p.1);
    println!(
        "S2: minimum A_R/A_R(0) = {:.4}; {last:.3e} at the last stable state; slip at \
         F/(μF_N) = {slip:.9}",
        low / 0.98
    );

    // S3.
    let grid = figures::unit_grid(0.01);
    let samples = [
        (0.050, 0.007),
        (0.100, 0.007),
        (0.140, 0.014),
        (0.200, 0.020),
    ];
    let drives = [
        ("side", Drive::Force(ForceLoad::Lateral(Lateral::Side))),
        (
            "rod",
            Drive::Force(ForceLoad::Lateral(Lateral::Rod {
                height: 6e-3,
                half_width: 2e-3,
            })),
        ),
    ];
    let mut columns = Vec::new();
    let mut header = vec!["force_over_mu_FN".to_string()];
    let mut legends = Vec::new();
    let mut initial = Vec::new();
    for (drive_name, drive) in drives {
        for &(lx, ly) in &samples {
            let mut mean = vec![0.0; grid.len()];
            let mut worst_slip: f64 = 0.0;
            for &seed in &seeds {
                let b = Scene::builder()
                    .block(lx, ly, 0.075)
                    .normal_load(4e3)
                    .drive(drive)
                    .seed(seed);
                let (curve, slip) = area_curve(&b)?;
                worst_slip = worst_slip.max((slip - 1.0).abs());
                for (m, f) in mean.iter_mut().zip(&grid) {
                    *m += at(&curve, *f) * 1e6 / seeds.len() as f64;
                }
            }
            println!(
                "S3 {drive_name:>4} {:>3.0} x {:>2.0} mm (A0 = {:>5.0} mm²): A_R(0) = {:.3} mm², \
                 max |F_slip/(μF_N) - 1| = {worst_slip:.1e}",
                lx * 1e3,
                ly * 1e3,
                lx * ly * 1e6,
                mean[0]
            );
            initial.push(mean[0]);
            legends.push(format!(
                "{drive_name}, {:.0} x {:.0} mm",
                lx * 1e3,
                ly * 1e3
            ));
            header.push(format!(
                "area_mm2_{drive_name}_{:.0}x{:.0}",
                lx * 1e3,
                ly * 1e3
            ));
            columns.push(mean);
        }
    }
    let avg = initial.iter().sum::<f64>() / initial.len() as f64;
    let spread = initial.iter().fold(0.0f64, |m, a| m.max((a - avg).abs())) / avg;
    println!(
        "S3: A_R(0) across samples: mean {avg:.3} mm², largest deviation {:.2} %",
        100.0 * spread
    );
    let rows: Vec<String> = grid
        .iter()
        .enumerate()
        .map(|(i, f)| {
            std::iter::once(format!("{f:.2}"))
                .chain(columns.iter().map(|c| format!("{:.6}", c[i])))
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect();
    figures::write_csv(&format!("{dir}/figS3.csv"), &header.join(","), &rows)?;
    // As in S2, the unbounded area law explodes just before slip: the picture shows A_R up
    // to twice the largest A_R(0), each curve until it leaves that range (the CSV has
    // every value).
    let top = CAP * initial.iter().fold(0.0f64, |m, a| m.max(*a));
    let mut chart = Chart::new(
        &format!(
            "Fig. S3: real contact area up to 2 A_R(0), Lz = 75 mm, F_N = 4 kN, {}",
            figures::realizations(seeds.len())
        ),
        "F/(μF_N)",
        "A_R (mm²)",
    )
    .x_range(0.0, 1.0)
    .y_range(0.0, top)
    .legend(Corner::UpperLeft)
    .size(900, 600);
    for (c, legend) in columns.iter().zip(&legends) {
        let points: Vec<(f64, f64)> = grid
            .iter()
            .copied()
            .zip(c.iter().copied())
            .take_while(|p| p.1.is_finite() && p.1 <= top)
            .collect();
        chart = chart.line(legend, &points);
    }
    chart.save(format!("{dir}/figS3.png"))?;
    println!("wrote {dir}/figS2.csv, {dir}/figS3.csv and the PNGs");
    Ok(())
}
