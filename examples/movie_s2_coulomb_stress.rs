//! Paper Movie S2: the y-averaged Coulomb stress `τ_C(x, z) = |τ| − μ|σ|` over the x-z
//! slab of the Fig. 8 block (200 x 7 x 100 mm, F_N = 6.25 kN, rod and top shear with
//! F_top = F_lat, seed 1) as the shear grows: where `τ_C > 0` opens inside the bulk, and
//! the interface's precursor `ℓ`.
//!
//! The run records its fields (`RunOptions::record_fields`) every 2nd stable state on
//! 50 planes, z = 1, 3, ..., 99 mm, into `movie_s2/` (the run tables, `scene.json`,
//! `fields.csv`), then `plot::Movie` draws `movie_s2.gif` (at most 150 frames): τ_C in MPa
//! on one diverging scale for the whole movie (symmetric, to the 98th percentile of |τ_C|,
//! saturating beyond), the `τ_C = 0` contour along the cells' edges and `ℓ` as a black bar
//! along the bottom. From the command line: `precursors movie movie_s2 --field
//! coulomb-stress`.
//! Run: `cargo run --release --example movie_s2_coulomb_stress [output directory]`.

#[path = "support/report.rs"]
mod report;

#[path = "support/figures.rs"]
mod figures;

use precursors::output::RunTables;
use precursors::plot::{Movie, MovieKind};
use precursors::RunOptions;
use std::process::ExitCode;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let dir = figures::args(None)?.dir;
    let planes: Vec<f64> = (0..50).map(|k| (2 * k + 1) as f64 * 1e-3).collect();
    let scene = figures::stress_block()
        .seed(1)
        .run_options(RunOptions::new().record_fields(2, &planes))
        .build()?;
    let run_dir = format!("{dir}/movie_s2");
    std::fs::create_dir_all(&run_dir)?;
    let mut driver = scene.driver()?;
    RunTables::create(run_dir.as_ref(), &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
    let gif = format!("{dir}/movie_s2.gif");
    let report = Movie::new(&run_dir, MovieKind::CoulombStress)
        .max_frames(150)?
        .save(&gif)?;
    let movie = Movie::new(&run_dir, MovieKind::CoulombStress).max_frames(150)?;
    for k in [0, report.frames / 2, report.frames - 2] {
        movie.save_frame(k, format!("{dir}/movie_s2_frame{k}.png"))?;
    }
    println!(
        "wrote {gif}: {} frames of {} recorded states (one in {} and the last), τ_C from \
         {:.2} to {:.2} MPa",
        report.frames, report.states, report.stride, report.colour_range.0, report.colour_range.1
    );
    Ok(())
}
