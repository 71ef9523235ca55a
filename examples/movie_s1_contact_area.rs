//! Paper Movie S1: the real contact area `A_R` of each cell of the interface (x right, y
//! up) as the shear grows, for the three loading conditions of Fig. 3 (the 200 x 7 x 75 mm
//! block, 1 mm cells, F_N = 2.7 kN, seed 1): a rod (h = 6 mm, Δh = 2 mm), a uniform side
//! load and a uniform top load.
//!
//! Each run records its fields (`RunOptions::record_fields`: the cells' contact area of
//! every stable state) into `movie_s1_<drive>/` (the run tables, `scene.json` and
//! `fields.csv`, as `precursors run` writes them), then `plot::Movie` draws
//! `movie_s1_<drive>.gif`: at most 150 frames, one colour scale per movie (mm² per cell),
//! the precursor front `x = ℓ` as a black line, each frame titled with `F/(μF_N)` and
//! `ℓ/Lx`. The same movie from the command line: `precursors movie movie_s1_<drive>`.
//! Run: `cargo run --release --example movie_s1_contact_area [output directory]`.

#[path = "support/report.rs"]
mod report;

#[path = "support/figures.rs"]
mod figures;

use precursors::output::RunTables;
use precursors::plot::{Movie, MovieKind};
use precursors::{Drive, ForceLoad, Lateral, RunOptions, Scene};
use std::process::ExitCode;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let dir = figures::args(None)?.dir;
    let drives = [
        (
            "rod",
            Drive::Force(ForceLoad::Lateral(Lateral::Rod {
                height: 6e-3,
                half_width: 2e-3,
            })),
        ),
        ("side", Drive::Force(ForceLoad::Lateral(Lateral::Side))),
        ("top", Drive::Force(ForceLoad::Top)),
    ];
    for (name, drive) in drives {
        let scene = Scene::builder()
            .block(0.200, 0.007, 0.075)
            .normal_load(2.7e3)
            .drive(drive)
            .seed(1)
            .run_options(RunOptions::new().record_fields(1, &[]))
            .build()?;
        let run_dir = format!("{dir}/movie_s1_{name}");
        std::fs::create_dir_all(&run_dir)?;
        let mut driver = scene.driver()?;
        RunTables::create(run_dir.as_ref(), &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
        let gif = format!("{dir}/movie_s1_{name}.gif");
        let report = Movie::new(&run_dir, MovieKind::ContactArea)
            .max_frames(150)?
            .save(&gif)?;
        // Three stills of the rod's movie (docs/cli.md shows them).
        if name == "rod" {
            let movie = Movie::new(&run_dir, MovieKind::ContactArea).max_frames(150)?;
            for k in [0, report.frames / 2, report.frames - 2] {
                movie.save_frame(k, format!("{dir}/movie_s1_rod_frame{k}.png"))?;
            }
        }
        println!(
            "{name:>4}: wrote {gif}: {} frames of {} stable states (one in {} and the last), \
             A_R per cell from 0 to {:.3} mm² (saturating)",
            report.frames, report.states, report.stride, report.colour_range.1
        );
    }
    Ok(())
}
