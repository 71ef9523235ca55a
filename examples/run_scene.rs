//! Runs a scene file (docs/scene-format.md) to global slip and writes two tables:
//!
//! * `events.csv`: one row per event: `index,kind,ix,iy,force_N,drive_displacement_m,
//!   energy_J,ruptures,area_exceeds_nominal` (empty cells where a column does not apply);
//! * `curve.csv`: one row per stable state: `event,force_N,force_over_mu_FN,
//!   drive_displacement_m,real_contact_area_m2,precursor_length_m,precursor_over_Lx,
//!   broken,attached,area_exceeds_nominal`.
//!
//! `area_exceeds_nominal` is 1 when the total real contact area of the state after the
//! event exceeds the nominal area `Lx·Ly` (the paper's unbounded area law), 0 otherwise.
//!
//! A progress line goes to stderr about once a second. With `--checkpoint FILE` a
//! checkpoint is written every `--every K` stable states (default 100); `--resume FILE`
//! continues from one (the scene comes from the checkpoint, whose digest must match it)
//! and the tables end exactly as those of an uninterrupted run (rows after the
//! checkpoint, and a last row cut by a crash, are dropped).
//!
//! ```sh
//! cargo run --release --features serde --example run_scene -- examples/scenes/calibration.json --out out
//! cargo run --release --features serde --example run_scene -- --resume out/checkpoint.json --out out
//! ```

#[path = "support/report.rs"]
mod report;

#[path = "support/table.rs"]
mod table;

use precursors::{Checkpoint, Driver, Event, SceneBuilder, SiteState};
use report::AtPath;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

const EVENTS_HEADER: &str =
    "index,kind,ix,iy,force_N,drive_displacement_m,energy_J,ruptures,area_exceeds_nominal";
const CURVE_HEADER: &str = "event,force_N,force_over_mu_FN,drive_displacement_m,\
                            real_contact_area_m2,precursor_length_m,precursor_over_Lx,broken,\
                            attached,area_exceeds_nominal";

struct Args {
    scene: Option<PathBuf>,
    resume: Option<PathBuf>,
    out: PathBuf,
    checkpoint: Option<PathBuf>,
    every: usize,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        scene: None,
        resume: None,
        out: PathBuf::from("."),
        checkpoint: None,
        every: 100,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--out" => args.out = value("--out")?.into(),
            "--resume" => args.resume = Some(value("--resume")?.into()),
            "--checkpoint" => args.checkpoint = Some(value("--checkpoint")?.into()),
            "--every" => {
                args.every = value("--every")?
                    .parse()
                    .map_err(|e| format!("--every: {e}"))?;
                if args.every == 0 {
                    return Err("--every must be at least 1".into());
                }
            }
            "-h" | "--help" => return Err(String::new()),
            s if s.starts_with("--") => return Err(format!("unknown option {s}")),
            s => args.scene = Some(s.into()),
        }
    }
    if args.scene.is_none() == args.resume.is_none() {
        return Err("give a scene file or --resume CHECKPOINT (one of them)".into());
    }
    Ok(args)
}

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!(
                "{e}\nusage: run_scene SCENE.json [--out DIR] [--checkpoint FILE [--every K]]\n       \
                 run_scene --resume CHECKPOINT.json [--out DIR] [--checkpoint FILE [--every K]]"
            );
            std::process::exit(2);
        }
    };
    report::writable_dir(&args.out)?;
    let events_path = args.out.join("events.csv");
    let curve_path = args.out.join("curve.csv");
    let started = Instant::now();

    let (scene, mut driver, mut events, mut curve) = match &args.resume {
        None => {
            let builder = SceneBuilder::from_json_file(args.scene.as_ref().unwrap())?;
            let scene = builder.build()?;
            let driver = scene.driver()?;
            let events = table(&events_path, EVENTS_HEADER, None)?;
            let curve = table(&curve_path, CURVE_HEADER, None)?;
            (scene, driver, events, curve)
        }
        Some(path) => {
            let checkpoint = Checkpoint::read_from(path)?;
            let scene = checkpoint.scene().clone().build()?;
            let driver = scene.resume(&checkpoint)?;
            // Keep the rows up to the checkpoint (a crashed run may have written more).
            let k = checkpoint.event_count();
            let events = table(&events_path, EVENTS_HEADER, Some(k))?;
            let curve = table(&curve_path, CURVE_HEADER, Some(k))?;
            eprintln!("resumed at event {k} from {}", path.display());
            (scene, driver, events, curve)
        }
    };
    let grid = *scene.grid();
    let mu_fn = scene.material().friction_coefficient * scene.normal_load();
    eprintln!(
        "{} x {} cells ({:?} backend), F_N = {} N",
        grid.nx(),
        grid.ny(),
        driver.backend(),
        scene.normal_load()
    );

    let mut stable_states = 0usize;
    let mut last_progress = Instant::now();
    while let Some(event) = driver.step()? {
        let index = driver.event_count();
        let exceeds = driver.area_exceeds_nominal()?;
        write_event(&mut events, index, &event, exceeds).at("write", &events_path)?;
        if let Event::Stable { load, .. } = event {
            stable_states += 1;
            let (broken, attached) = counts(driver.site_states());
            let ell = driver.precursor_length()?;
            writeln!(
                curve,
                "{index},{:.12e},{:.12e},{},{:.12e},{:.12e},{:.12e},{broken},{attached},{}",
                load.force,
                load.force / mu_fn,
                optional(load.drive_displacement),
                driver.total_contact_area()?,
                ell,
                ell / grid.block().lx(),
                u8::from(exceeds),
            )
            .at("write", &curve_path)?;
            if let Some(path) = &args.checkpoint {
                if stable_states.is_multiple_of(args.every) {
                    events.flush().at("write", &events_path)?;
                    curve.flush().at("write", &curve_path)?;
                    driver.checkpoint().write_to(path)?;
                }
            }
        }
        if last_progress.elapsed().as_secs_f64() >= 1.0 {
            progress(&driver, mu_fn, started);
            last_progress = Instant::now();
        }
    }
    events.flush().at("write", &events_path)?;
    curve.flush().at("write", &curve_path)?;
    progress(&driver, mu_fn, started);
    eprintln!(
        "\nglobal slip after {} events; wrote {} and {}",
        driver.event_count(),
        events_path.display(),
        curve_path.display()
    );
    Ok(())
}

/// A CSV table: new (header only), or an existing one cut after the rows whose first
/// column (an event index) is at most `keep` (`support/table.rs`).
fn table(
    path: &Path,
    header: &str,
    keep: Option<usize>,
) -> Result<BufWriter<File>, report::FileError> {
    table::open(path, header, keep).at("resume the table", path)
}

fn optional(x: Option<f64>) -> String {
    x.map(|v| format!("{v:.12e}")).unwrap_or_default()
}

fn write_event(
    out: &mut impl Write,
    index: usize,
    event: &Event,
    exceeds: bool,
) -> std::io::Result<()> {
    let (kind, site, load, energy, ruptures) = match *event {
        Event::LoadRaised { load } => ("load_raised", None, Some(load), None, None),
        Event::Rupture { site, load, energy } => {
            ("rupture", Some(site), Some(load), Some(energy), None)
        }
        Event::Detach { site } => ("detach", Some(site), None, None, None),
        Event::Attach { site } => ("attach", Some(site), None, None, None),
        Event::Stable { load, ruptures } => ("stable", None, Some(load), None, Some(ruptures)),
        Event::GlobalSlip { load } => ("global_slip", None, Some(load), None, None),
        _ => ("other", None, None, None, None),
    };
    let (ix, iy) = site.map_or((String::new(), String::new()), |s| {
        (s.ix.to_string(), s.iy.to_string())
    });
    writeln!(
        out,
        "{index},{kind},{ix},{iy},{},{},{},{},{}",
        optional(load.map(|l| l.force)),
        optional(load.and_then(|l| l.drive_displacement)),
        optional(energy),
        ruptures.map(|r| r.to_string()).unwrap_or_default(),
        u8::from(exceeds)
    )
}

fn counts(states: &[SiteState]) -> (usize, usize) {
    let broken = states.iter().filter(|s| **s == SiteState::Broken).count();
    let attached = states.iter().filter(|s| **s == SiteState::Attached).count();
    (broken, attached)
}

fn progress(driver: &Driver, mu_fn: f64, started: Instant) {
    let (broken, _) = counts(driver.site_states());
    eprint!(
        "\r{:>9} events  {broken:>7}/{} broken  F/(μF_N) = {:.6}  {:.1} s   ",
        driver.event_count(),
        driver.site_states().len(),
        driver.force() / mu_fn,
        started.elapsed().as_secs_f64()
    );
}
