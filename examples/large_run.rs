//! The N = 1e4 scene of the performance target (issue 4: zero shear to global slip in
//! under a minute; docs/performance.md: about 50 s on this 2-core machine with two
//! solver threads, 70 s with one): a 200 x 50 x 75 mm block on 1 mm cells, 3.5 MPa normal
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

#[path = "support/report.rs"]
mod report;

use precursors::solver::{Parallelism, SolverOptions};
use precursors::{Event, Scene};
use std::process::ExitCode;
use std::time::Instant;

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
    let mut driver = scene.driver()?;
    let (mut events, mut ruptures, mut stable, mut detach, mut attach) = (0, 0, 0, 0, 0);
    let mut slip = None;
    let mut digest = Digest::default();
    // Optional early stop (for quick comparisons): LARGE_RUN_MAX_RUPTURES.
    let max_ruptures: usize = std::env::var("LARGE_RUN_MAX_RUPTURES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(usize::MAX);
    while let Some(event) = driver.step()? {
        let (event, d) = (&event, &driver);
        events += 1;
        digest.event(event);
        match event {
            Event::Rupture { load, .. } => {
                ruptures += 1;
                if ruptures % 500 == 0 {
                    let s = d.solve_stats();
                    eprintln!(
                        "{:8.2} s  {ruptures:6} ruptures  {stable:5} stable  F/(μF_N) = {:.6}  \
                         normal {:.2} s / {} it, tangential {:.2} s / {} it",
                        start.elapsed().as_secs_f64(),
                        load.force / scale,
                        s.normal_seconds,
                        s.normal_iterations,
                        s.tangential_seconds,
                        s.tangential_iterations,
                    );
                }
            }
            Event::Stable { .. } => stable += 1,
            Event::Detach { .. } => detach += 1,
            Event::Attach { .. } => attach += 1,
            Event::GlobalSlip { load } => slip = Some(load.force / scale),
            _ => {}
        }
        if ruptures >= max_ruptures {
            break;
        }
    }
    let elapsed = start.elapsed().as_secs_f64();
    let s = driver.solve_stats();
    println!(
        "N = {} ({} x {}), seed {seed}, backend {:?}",
        driver.grid().len(),
        driver.grid().nx(),
        driver.grid().ny(),
        precursors::solver::SolverOptions::default().backend()
    );
    println!(
        "wall {elapsed:.2} s (scene build {:.3} s); {events} events: {ruptures} ruptures, \
         {stable} stable states, {detach} detachments, {attach} attachments; {}",
        built.as_secs_f64(),
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
        digest.0
    );
    Ok(())
}

/// FNV-1a over the kind and site of the events that change the set.
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
