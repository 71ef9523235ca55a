//! The N = 1e4 scene of the performance target (issue 4: zero shear to global slip in
//! under a minute; docs/performance.md's table at the top, last measured 2026-11-29 on a
//! 2-core VM: 78-86 s with two solver threads, 90-114 s with one, the target not met
//! there): a 200 x 50 x 75 mm block on 1 mm cells, 3.5 MPa normal
//! pressure, rod drive (defaults), force control, seed 1. Spectral backend (Auto).
//!
//! Prints progress every 500 ruptures (elapsed time, ruptures, F/(μF_N)) and at the end
//! the wall time, the event counts and the solver work split between the normal and the
//! tangential equilibria.
//!
//! Run: `cargo run --release --example large_run [seed] [solver tolerance] [threads] [size]`
//! (the tolerance defaults to the solver's, `1e-13`; threads to 1, `0` for every core,
//! see `SolverOptions::parallelism`: the events are the same for every thread count;
//! size `1e4`, the default, or `1e5`: a 1000 x 100 x 75 mm block on 1 mm cells at 1 MPa
//! (100 kN). Not the 3.5 MPa of the smaller scene: the last site attached before global
//! slip carries the whole normal load, and the scene refuses a load above `650 ΔA c_z`
//! (107 kN on 1 mm cells) whose area law would overflow (docs/scene-format.md).
//! `LARGE_RUN_MAX_RUPTURES=k` stops after `k` ruptures. The last line is a digest of the
//! event sequence (kind and site of every rupture, detachment and attachment, FNV-1a):
//! two programs ran the same events when their digests agree (docs/performance.md).
//!
//! A run longer than a sitting (the N = 1e5 scene takes hours): `LARGE_RUN_CHECKPOINT=FILE`
//! writes the driver's checkpoint to FILE at the first stable state after every
//! `LARGE_RUN_CHECKPOINT_SECONDS` (default 600) and this program's totals (event counts,
//! digest, solver work, wall time) to FILE.progress; started again with the same
//! arguments and FILE, it resumes from there and ends with the totals and digest of an
//! uninterrupted run. The wall time it prints is the sum over the sittings up to their
//! last checkpoints (work redone after a stop is not counted, each resume's set-up is).

#[path = "support/report.rs"]
mod report;

use precursors::solver::{Parallelism, SolverOptions};
use precursors::{Checkpoint, Driver, Event, Scene, SolveStats};
use report::AtPath;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let args: Vec<String> = std::env::args().skip(1).collect();
    const USAGE: &str = "the arguments are [seed] [solver tolerance] [threads] [size: 1e4 or 1e5]";
    if args.len() > 4 {
        return Err(format!("unexpected argument '{}': {USAGE}", args[4]).into());
    }
    // A bad argument is refused by name rather than replaced by its default.
    fn parse<T: std::str::FromStr>(
        arg: Option<&String>,
        name: &str,
        default: T,
    ) -> Result<T, String> {
        arg.map_or(Ok(default), |text| {
            text.parse()
                .map_err(|_| format!("invalid {name} '{text}' ({USAGE})"))
        })
    }
    let seed: u64 = parse(args.first(), "seed", 1)?;
    let tolerance: f64 = parse(
        args.get(1),
        "solver tolerance",
        SolverOptions::default().tolerance(),
    )?;
    let threads: usize = parse(args.get(2), "thread count", 1)?;
    // Block (m) and normal pressure (Pa).
    let (lx, ly, pressure) = match args.get(3).map(String::as_str) {
        None | Some("1e4") => (0.200, 0.050, 3.5e6),
        Some("1e5") => (1.000, 0.100, 1.0e6),
        Some(other) => return Err(format!("invalid size '{other}' ({USAGE})").into()),
    };
    let start = Instant::now();
    let scene = Scene::builder()
        .solver_options(
            SolverOptions::default()
                .with_tolerance(tolerance)?
                .with_parallelism(match threads {
                    0 => Parallelism::all_cores(),
                    1 => Parallelism::Sequential,
                    n => Parallelism::Threads(n),
                })?,
        )
        .block(lx, ly, 0.075)
        .cell_size(1e-3, 1e-3)
        .seed(seed)
        .normal_load(pressure * lx * ly)
        .build()?;
    let built = start.elapsed();
    let scale = scene.material().friction_coefficient() * scene.normal_load();
    // Optional early stop (for quick comparisons) and checkpoints (for long runs).
    let max_ruptures: usize = env("LARGE_RUN_MAX_RUPTURES", usize::MAX)?;
    let checkpoint = std::env::var_os("LARGE_RUN_CHECKPOINT").map(PathBuf::from);
    let every = Duration::from_secs_f64(env("LARGE_RUN_CHECKPOINT_SECONDS", 600.0_f64)?);
    let (mut driver, before) = match &checkpoint {
        Some(path) if path.exists() => {
            let saved = Checkpoint::read_from(path)?;
            let totals = Totals::read(&progress_path(path), saved.event_count())?;
            let driver = scene.resume(&saved)?;
            eprintln!(
                "resuming from {} ({} ruptures, {:.2} s so far)",
                path.display(),
                totals.ruptures,
                totals.seconds
            );
            (driver, totals)
        }
        _ => (scene.driver()?, Totals::default()),
    };
    let mut now = before;
    let mut last_checkpoint = Instant::now();
    let mut slip = None;
    while let Some(event) = driver.step()? {
        now.event(&event);
        match event {
            Event::Rupture { load, .. } if now.ruptures % 500 == 0 => {
                now.solver(&before, &driver, start);
                eprintln!(
                    "{:8.2} s  {:6} ruptures  {:5} stable  F/(μF_N) = {:.6}  \
                     normal {:.2} s / {} it, tangential {:.2} s / {} it",
                    now.seconds,
                    now.ruptures,
                    now.stable,
                    load.force / scale,
                    now.stats.normal_seconds,
                    now.stats.normal_iterations,
                    now.stats.tangential_seconds,
                    now.stats.tangential_iterations,
                );
            }
            Event::Stable { .. } => {
                if let Some(path) = checkpoint.as_deref() {
                    if last_checkpoint.elapsed() >= every {
                        now.solver(&before, &driver, start);
                        save(path, &driver, &now)?;
                        last_checkpoint = Instant::now();
                    }
                }
            }
            Event::GlobalSlip { load } => slip = Some(load.force / scale),
            _ => {}
        }
        if now.ruptures >= max_ruptures {
            break;
        }
    }
    now.solver(&before, &driver, start);
    let s = now.stats;
    println!(
        "N = {} ({} x {}), seed {seed}, backend {:?}",
        driver.grid().len(),
        driver.grid().nx(),
        driver.grid().ny(),
        precursors::solver::SolverOptions::default().backend()
    );
    println!(
        "wall {:.2} s (scene build {:.3} s{}); {} events: {} ruptures, {} stable states, \
         {} detachments, {} attachments; {}",
        now.seconds,
        built.as_secs_f64(),
        match now.sittings {
            0 => String::new(),
            k => format!(", {} sittings", k + 1),
        },
        now.events,
        now.ruptures,
        now.stable,
        now.detach,
        now.attach,
        match slip {
            Some(load) => format!("global slip at F/(μF_N) = {load:.12}"),
            None => "stopped before global slip".to_string(),
        }
    );
    let per = |t: f64, k: usize| 1e3 * t / k.max(1) as f64;
    let avg = |i: usize, k: usize| i as f64 / k.max(1) as f64;
    println!(
        "normal:     {} solves, {:.2} s ({:.2} ms/solve), {} CG iterations ({:.1}/solve), \
         {} active-set iterations",
        s.normal_solves,
        s.normal_seconds,
        per(s.normal_seconds, s.normal_solves),
        s.normal_iterations,
        avg(s.normal_iterations, s.normal_solves),
        s.normal_active_set_iterations
    );
    println!(
        "tangential: {} solves, {:.2} s ({:.2} ms/solve), {} CG iterations ({:.1}/solve)",
        s.tangential_solves,
        s.tangential_seconds,
        per(s.tangential_seconds, s.tangential_solves),
        s.tangential_iterations,
        avg(s.tangential_iterations, s.tangential_solves)
    );
    println!(
        "event digest {:016x} (kind and site of every event)",
        now.digest.0
    );
    Ok(())
}

/// The value of the environment variable `name`, `default` when it is unset; a value
/// that does not parse is refused rather than replaced by the default.
fn env<T: std::str::FromStr>(name: &str, default: T) -> Result<T, String> {
    match std::env::var(name) {
        Err(std::env::VarError::NotPresent) => Ok(default),
        Ok(text) => text.parse().map_err(|_| format!("invalid {name} '{text}'")),
        Err(e) => Err(format!("invalid {name}: {e}")),
    }
}

/// Where the totals of a checkpointed run are kept, next to its checkpoint.
fn progress_path(checkpoint: &Path) -> PathBuf {
    let mut name = checkpoint.as_os_str().to_owned();
    name.push(".progress");
    PathBuf::from(name)
}

/// Writes the checkpoint, then the totals at it (each atomically). A stop between the two
/// leaves totals that do not match the checkpoint, refused on resume.
fn save(path: &Path, driver: &Driver, totals: &Totals) -> report::Outcome {
    driver.checkpoint().write_to(path)?;
    let progress = progress_path(path);
    let temporary = progress.with_extension("progress.tmp");
    std::fs::write(&temporary, totals.to_text(driver.event_count())).at("write", &temporary)?;
    std::fs::rename(&temporary, &progress).at("rename into place", &progress)?;
    Ok(())
}

/// What this program counts, summed over the sittings of a checkpointed run.
#[derive(Clone, Copy, Default)]
struct Totals {
    events: usize,
    ruptures: usize,
    stable: usize,
    detach: usize,
    attach: usize,
    digest: Digest,
    /// Wall time (s), this sitting's included once `solver` is called.
    seconds: f64,
    /// Earlier sittings.
    sittings: usize,
    stats: SolveStats,
}

impl Totals {
    fn event(&mut self, event: &Event) {
        self.events += 1;
        self.digest.event(event);
        match event {
            Event::Rupture { .. } => self.ruptures += 1,
            Event::Stable { .. } => self.stable += 1,
            Event::Detach { .. } => self.detach += 1,
            Event::Attach { .. } => self.attach += 1,
            _ => {}
        }
    }

    /// The wall time and solver work of the earlier sittings `before` plus this one's.
    fn solver(&mut self, before: &Totals, driver: &Driver, start: Instant) {
        let (a, b) = (before.stats, driver.solve_stats());
        self.seconds = before.seconds + start.elapsed().as_secs_f64();
        self.stats.normal_solves = a.normal_solves + b.normal_solves;
        self.stats.normal_active_set_iterations =
            a.normal_active_set_iterations + b.normal_active_set_iterations;
        self.stats.normal_iterations = a.normal_iterations + b.normal_iterations;
        self.stats.normal_seconds = a.normal_seconds + b.normal_seconds;
        self.stats.tangential_solves = a.tangential_solves + b.tangential_solves;
        self.stats.tangential_iterations = a.tangential_iterations + b.tangential_iterations;
        self.stats.tangential_seconds = a.tangential_seconds + b.tangential_seconds;
    }

    /// One `key value` line per total; the times as the bits of their f64, so a resumed
    /// run adds exactly what was measured.
    fn to_text(self, checkpoint_events: usize) -> String {
        let s = self.stats;
        [
            ("checkpoint_events", checkpoint_events as u64),
            ("events", self.events as u64),
            ("ruptures", self.ruptures as u64),
            ("stable", self.stable as u64),
            ("detach", self.detach as u64),
            ("attach", self.attach as u64),
            ("digest", self.digest.0),
            ("seconds_bits", self.seconds.to_bits()),
            ("sittings", self.sittings as u64 + 1),
            ("normal_solves", s.normal_solves as u64),
            (
                "normal_active_set_iterations",
                s.normal_active_set_iterations as u64,
            ),
            ("normal_iterations", s.normal_iterations as u64),
            ("normal_seconds_bits", s.normal_seconds.to_bits()),
            ("tangential_solves", s.tangential_solves as u64),
            ("tangential_iterations", s.tangential_iterations as u64),
            ("tangential_seconds_bits", s.tangential_seconds.to_bits()),
        ]
        .iter()
        .map(|(key, value)| format!("{key} {value}\n"))
        .collect()
    }

    /// The totals written by `to_text` at the checkpoint of `checkpoint_events` events.
    fn read(path: &Path, checkpoint_events: usize) -> Result<Totals, Box<dyn std::error::Error>> {
        let text = std::fs::read_to_string(path).at("read", path)?;
        let mut values = std::collections::HashMap::new();
        for line in text.lines() {
            let parsed = line
                .split_once(' ')
                .and_then(|(key, value)| Some((key, value.parse::<u64>().ok()?)));
            let (key, value) = parsed
                .ok_or_else(|| format!("{}: not a `key value` line: '{line}'", path.display()))?;
            values.insert(key.to_string(), value);
        }
        let get = |key: &str| {
            values
                .get(key)
                .copied()
                .ok_or_else(|| format!("{}: no value for '{key}'", path.display()))
        };
        let count = |key: &str| get(key).map(|v| v as usize);
        let seconds = |key: &str| get(key).map(f64::from_bits);
        if count("checkpoint_events")? != checkpoint_events || count("events")? != checkpoint_events
        {
            return Err(format!(
                "{} does not belong to the checkpoint next to it (of {checkpoint_events} events): \
                 the run stopped between writing the two; remove both to start again",
                path.display()
            )
            .into());
        }
        let mut stats = SolveStats::default();
        stats.normal_solves = count("normal_solves")?;
        stats.normal_active_set_iterations = count("normal_active_set_iterations")?;
        stats.normal_iterations = count("normal_iterations")?;
        stats.normal_seconds = seconds("normal_seconds_bits")?;
        stats.tangential_solves = count("tangential_solves")?;
        stats.tangential_iterations = count("tangential_iterations")?;
        stats.tangential_seconds = seconds("tangential_seconds_bits")?;
        Ok(Totals {
            events: count("events")?,
            ruptures: count("ruptures")?,
            stable: count("stable")?,
            detach: count("detach")?,
            attach: count("attach")?,
            digest: Digest(get("digest")?),
            seconds: seconds("seconds_bits")?,
            sittings: count("sittings")?,
            stats,
        })
    }
}

/// FNV-1a over the kind and site of the events that change the set.
#[derive(Clone, Copy)]
struct Digest(u64);

impl Default for Digest {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Digest {
    fn event(&mut self, event: &Event) {
        let (kind, site) = match event {
            Event::Rupture { site, .. } => (1u8, site.index),
            Event::Detach { site, .. } => (2, site.index),
            Event::Attach { site, .. } => (3, site.index),
            _ => return,
        };
        for byte in std::iter::once(kind).chain(site.to_le_bytes()) {
            self.0 = (self.0 ^ u64::from(byte)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}
