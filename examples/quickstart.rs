//! The paper's calibration scene (Fig. 2b): a 140 x 7 x 75 mm PMMA block on 1 mm cells,
//! F_N = 3.5 kN, sheared by a rod at h = 6 mm (Δh = 2 mm) on the trailing edge, driven
//! quasi-statically to global slip.
//!
//! Writes `quickstart.csv` (one row per stable state: F/(μF_N), ℓ/Lx, the total real
//! contact area, the ruptures of the avalanche that ended there, and 1 where that area
//! exceeds the nominal area Lx·Ly: the paper's area law has no cap, see
//! `precursors::AreaLaw`) and `quickstart.png`: the precursor length ℓ/Lx against the
//! load F/(μF_N) at the stable states, as a staircase (both axes from 0 to 1; title with
//! the scene and the seed), drawn by `precursors::plot`.
//!
//! Run: `cargo run --release --example quickstart [seed] [output directory]`.

#[path = "support/report.rs"]
mod report;

use precursors::plot::{Chart, Corner};
use precursors::{Event, Scene};
use report::AtPath;
use std::io::Write;
use std::ops::ControlFlow;
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() > 2 {
        return Err(format!(
            "unexpected argument '{}': the arguments are [seed] [output directory]",
            args[2]
        )
        .into());
    }
    let seed: u64 = match args.first() {
        None => 1,
        Some(text) => text
            .parse()
            .map_err(|_| format!("the seed must be a whole number >= 0, got '{text}'"))?,
    };
    let dir = args.get(1).cloned().unwrap_or_else(|| ".".into());
    report::writable_dir(&dir)?;
    let start = Instant::now();
    // The builder's defaults are the calibration scene; only the seed is chosen here.
    let scene = Scene::builder().seed(seed).build()?;
    let lx = scene.grid().block().lx();
    let scale = scene.material().friction_coefficient() * scene.normal_load();
    let mut driver = scene.driver()?;
    let mut rows = Vec::new();
    let mut slip = None;
    let mut ruptures = 0usize;
    driver.run(|event, d| {
        match event {
            Event::Stable { load, ruptures } => rows.push((
                load.force / scale,
                d.precursor_length().unwrap_or(f64::NAN) / lx,
                d.real_contact_area().unwrap_or(f64::NAN),
                *ruptures,
                d.area_exceeds_nominal().unwrap_or(false),
            )),
            Event::GlobalSlip { load } => slip = Some(load.force / scale),
            // Every rupture, the last avalanche's (which ends in slip) included.
            Event::Rupture { .. } => ruptures += 1,
            _ => {}
        }
        ControlFlow::<()>::Continue(())
    })?;
    let elapsed = start.elapsed();

    let csv = format!("{dir}/quickstart.csv");
    let write = || -> std::io::Result<()> {
        let mut out = std::io::BufWriter::new(std::fs::File::create(&csv)?);
        writeln!(
            out,
            "force_over_mu_FN,precursor_over_Lx,real_contact_area_m2,ruptures,\
             area_exceeds_nominal"
        )?;
        for (f, l, a, r, x) in &rows {
            writeln!(out, "{f:.9},{l:.6},{a:.9e},{r},{}", u8::from(*x))?;
        }
        out.flush()
    };
    write().at("write", &csv)?;

    // The envelope as the paper draws it: ℓ at each stable state, as a staircase.
    let points: Vec<(f64, f64)> = rows.iter().map(|(f, l, ..)| (*f, *l)).collect();
    let png = format!("{dir}/quickstart.png");
    Chart::new(
        &format!(
            "Precursor length, calibration scene (140 x 7 x 75 mm, F_N = 3.5 kN), seed {seed}"
        ),
        "F/(μF_N)",
        "ℓ/Lx",
    )
    .x_range(0.0, 1.0)
    .y_range(0.0, 1.0)
    .steps("ℓ/Lx at the stable states (rod, h = 6 mm)", &points)
    .legend(Corner::UpperLeft)
    .save(&png)?;

    println!(
        "calibration scene, seed {seed}: {} stable states, {ruptures} ruptures, global slip at \
         F/(μF_N) = {:.12}, in {:.2} s",
        rows.len(),
        slip.unwrap_or(f64::NAN),
        elapsed.as_secs_f64()
    );
    for target in [0.5, 0.8, 0.9, 0.95] {
        if let Some((f, l, ..)) = rows.iter().rev().find(|r| r.0 <= target) {
            println!("  ℓ/Lx = {l:.3} at F/(μF_N) = {f:.3}");
        }
    }
    let flagged = rows.iter().filter(|r| r.4).count();
    if flagged > 0 {
        println!(
            "  {flagged} of {} stable states have a real contact area above the nominal \
             Lx·Ly (the paper's area law has no cap; AreaLaw::Capped caps it at each cell's)",
            rows.len()
        );
    }
    println!("wrote {csv} and {png}");
    Ok(())
}
