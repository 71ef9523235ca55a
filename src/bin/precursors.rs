//! The `precursors` program (feature `cli`; docs/cli.md): runs a scene file, resumes a
//! checkpoint, estimates a scene's cost, runs and merges sweeps, draws figures.
//!
//! ```sh
//! cargo install --path . --features cli
//! precursors run examples/scenes/calibration.json --out out
//! precursors --help
//! ```

use clap::{Parser, Subcommand};
// The crate's byte and second formatters, compiled in from their one file (they are not
// part of the library's API).
#[path = "../format.rs"]
mod format;
use format::{format_bytes, format_seconds};
use precursors::output::RunTables;
use precursors::plot::PlotError;
use precursors::statistics::PowerLawOptions;
use precursors::sweep::{StatsOptions, Sweep, SweepError, SweepOptions};
use precursors::{
    Checkpoint, Driver, Error, GridCost, ProbeSpec, RunOptions, SceneBuilder, SiteState,
};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Writes a line to stderr. An error (stderr a closed pipe, `precursors run ... 2>&1 |
/// head -1`, or a full disk) is ignored, where `eprintln!` would panic: a message or a
/// progress line must never end a run that is writing its tables.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// Raised by SIGINT or SIGTERM ([`catch_stop_signals`]): the run, sweep or movie under
/// way stops at its next event, run or frame and says what it kept; the signal's number.
static STOP: std::sync::atomic::AtomicI32 = std::sync::atomic::AtomicI32::new(0);

/// Catches the first SIGINT (Ctrl-C) and SIGTERM; a second one ends the process at once
/// (the handler restores the default action).
#[cfg(unix)]
fn catch_stop_signals() {
    extern "C" fn raise(signal: libc::c_int) {
        STOP.store(signal, std::sync::atomic::Ordering::SeqCst);
        // SAFETY: signal(2) is async-signal-safe.
        unsafe { libc::signal(signal, libc::SIG_DFL) };
    }
    for signal in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: the handler only stores to an atomic and calls signal(2), both
        // async-signal-safe.
        unsafe { libc::signal(signal, raise as *const () as libc::sighandler_t) };
    }
}

#[cfg(not(unix))]
fn catch_stop_signals() {}

/// The signal [`catch_stop_signals`] caught, if any.
fn stopped() -> Option<i32> {
    match STOP.load(std::sync::atomic::Ordering::SeqCst) {
        0 => None,
        signal => Some(signal),
    }
}

/// A run, sweep or movie stopped by a signal: what it kept and how to go on (one line),
/// exit code `128 + signal` as a shell reports a process the signal ended.
#[derive(Debug)]
struct Interrupted {
    signal: i32,
    what: String,
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let name = match self.signal {
            2 => "SIGINT".to_string(),
            15 => "SIGTERM".to_string(),
            n => format!("signal {n}"),
        };
        write!(f, "stopped by {name}: {}", self.what)
    }
}

impl std::error::Error for Interrupted {}

fn interrupted(signal: i32, what: String) -> Failure {
    Failure {
        error: Box::new(Interrupted { signal, what }),
        code: u8::try_from(128 + signal).unwrap_or(130),
    }
}

const EXIT_CODES: &str = "\
Exit codes:
  0  success: every table and figure written is complete
  1  run, resume, sweep: the computation failed (a solver did not converge, the contact
     emptied, ...)
  2  bad command line (unknown option, missing argument, --every without --checkpoint,
     bad --shard or SLURM variables, a checkpoint named as a file of the run directory,
     plot --figure naming no figure or one the directory cannot give)
  3  invalid input: a scene, sweep or checkpoint file that is not UTF-8 text or not valid
     JSON, names an unknown key, holds an invalid value, or does not fit; a damaged table
     or one with NaN, inf or an empty cell where a number belongs, or a value out of its
     bounds or inconsistent with the scene or the other tables; a run and a sweep in one
     directory
  4  a file or directory could not be read or written (none is left half written), a
     path that is not a regular file (a FIFO, a device, a directory) named as a file, or
     another process is writing the directory (run, resume: the holder is named)
  5  merge, stats, plot: some runs of the sweep are not complete (the tables and figures
     of the others written)
  6  run, resume, info, sweep: the scene asks for backend \"cuda\" and it cannot run here
     (no feature cuda in this build, no NVIDIA driver or GPU, a CUDA library missing:
     docs/gpu.md)
  130, 143  run, resume, sweep, movie: stopped by SIGINT (Ctrl-C) or SIGTERM; the last
     line says what was kept and the command that continues";

/// Quasi-static friction precursors: runs scene files and sweeps (docs/cli.md).
#[derive(Debug, Parser)]
#[command(name = "precursors", version, after_help = EXIT_CODES)]
struct Cli {
    /// No progress line on stderr (it is also off when stderr is not a terminal).
    #[arg(short, long, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Runs a scene file (docs/scene-format.md) to global slip; writes DIR/events.csv,
    /// DIR/curve.csv and DIR/contact_map.csv (NAME.partial until global slip).
    Run {
        /// The scene file.
        scene: PathBuf,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Writes a checkpoint to FILE every N stable states.
        #[arg(long, value_name = "FILE")]
        checkpoint: Option<PathBuf>,
        /// Stable states between checkpoints (needs --checkpoint).
        #[arg(long, value_name = "N", default_value_t = 100, requires = "checkpoint",
              value_parser = clap::value_parser!(u64).range(1..))]
        every: u64,
    },
    /// Continues a run from a checkpoint; the tables in DIR are cut back to it and end as
    /// those of an uninterrupted run.
    Resume {
        /// The checkpoint file (written by `run --checkpoint`).
        checkpoint: PathBuf,
        /// Output directory of the run.
        #[arg(long)]
        out: PathBuf,
        /// Stable states between checkpoints (written over CHECKPOINT).
        #[arg(long, value_name = "N", default_value_t = 100,
              value_parser = clap::value_parser!(u64).range(1..))]
        every: u64,
    },
    /// Prints a scene's cells, backend and estimated memory and time.
    Info {
        /// The scene file.
        scene: PathBuf,
    },
    /// Runs a sweep file (docs/sweep-format.md): one directory per run under DIR;
    /// complete runs are skipped, cut ones redone.
    Sweep {
        /// The sweep file.
        sweep: PathBuf,
        /// Output directory (created if missing; shards share it).
        #[arg(long)]
        out: PathBuf,
        /// Runs at the same time [default: the number of cores].
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
        jobs: Option<u64>,
        /// Runs share K of N (runs whose index is K modulo N) [default: in a SLURM array
        /// task, K = (SLURM_ARRAY_TASK_ID - _MIN) / _STEP of N = SLURM_ARRAY_TASK_COUNT
        /// (docs/cluster.md); else 0/1].
        #[arg(long, value_name = "K/N", value_parser = parse_shard)]
        shard: Option<(usize, usize)>,
    },
    /// Merges a sweep's runs into DIR/curves.csv, slip.csv, avalanches.csv and runs.csv.
    Merge {
        /// The sweep's output directory.
        dir: PathBuf,
    },
    /// Fits the statistics of a run's or a sweep's avalanches, stress drops and front
    /// leaps (pooled per point; docs/statistics.md) into DIR/power_laws.csv,
    /// distributions.csv, binned_means.csv, scaling.csv, and collapse.csv for a sweep over
    /// a block length.
    Stats {
        /// A run's or a sweep's output directory.
        dir: PathBuf,
        /// Bootstrap resamples of each fit's confidence interval (0 to 10000).
        #[arg(long, default_value_t = 200,
              value_parser = clap::value_parser!(u64).range(0..=10_000))]
        bootstrap: u64,
        /// Synthetic data sets of each goodness-of-fit test (0 to 10000; 0: no p-value).
        #[arg(long, default_value_t = 200,
              value_parser = clap::value_parser!(u64).range(0..=10_000))]
        goodness: u64,
        /// Confidence level of the intervals (between 0 and 1).
        #[arg(long, default_value_t = 0.95, value_parser = parse_confidence)]
        confidence: f64,
        /// Fewest samples a fitted tail may hold (2 to 1000000).
        #[arg(long, default_value_t = 10,
              value_parser = clap::value_parser!(u64).range(2..=1_000_000))]
        min_tail: u64,
        /// Bins per decade of the distributions (1 to 100).
        #[arg(long, default_value_t = 5,
              value_parser = clap::value_parser!(u64).range(1..=100))]
        bins_per_decade: u64,
        /// Seed of the bootstrap and of the synthetic data sets.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Pool the spanning avalanche and those after it too (left out by default;
        /// docs/statistics.md).
        #[arg(long)]
        include_spanning: bool,
    },
    /// Draws the figures of a run (precursor_length, contact_area, contact_map, stick_slip
    /// under a driving spring, the statistics) or of a sweep (merged first; ensemble
    /// curves with 95 % bands, archard over a normal_load axis, the statistics) into DIR.
    Plot {
        /// A run's or a sweep's output directory.
        dir: PathBuf,
        /// Draws only the figure NAME (repeatable, or comma separated: precursor_length,
        /// contact_area, contact_map, stick_slip, archard, fronts, avalanche_sizes,
        /// force_drops, slip_profiles, shear_profiles, normal_profiles, coulomb_profiles)
        /// [default: every figure the directory allows].
        #[arg(long = "figure", value_name = "NAME", value_delimiter = ',')]
        figures: Vec<String>,
        /// File format(s).
        #[arg(long, value_enum, default_value_t = FormatArg::Png)]
        format: FormatArg,
        /// Figure width in 1/150 inch: pixels at 150 dpi (200 to 16384; 800 is 5.33 in).
        #[arg(long, default_value_t = 800,
              value_parser = clap::value_parser!(u32).range(200..=16384))]
        width: u32,
        /// Figure height in 1/150 inch (200 to 16384).
        #[arg(long, default_value_t = 560,
              value_parser = clap::value_parser!(u32).range(200..=16384))]
        height: u32,
        /// Resolution of the PNGs in dots per inch (50 to 1200): the same figure, drawn
        /// with dpi/150 times the pixels along each side (300 for print).
        #[arg(long, default_value_t = 150)]
        dpi: u32,
    },
    /// Draws a run's recorded fields (the scene key "fields") as an animated GIF:
    /// the real contact area per cell (Movie S1, DIR/contact_area.gif) or the y-averaged
    /// Coulomb stress over the recorded planes (Movie S2, DIR/coulomb_stress.gif).
    Movie {
        /// A run's output directory (with fields.csv).
        dir: PathBuf,
        /// Which movie(s).
        #[arg(long, value_enum, default_value_t = MovieArg::All)]
        field: MovieArg,
        /// Draws every K-th recorded state (and the last).
        #[arg(long, value_name = "K", default_value_t = 1,
              value_parser = clap::value_parser!(u64).range(1..))]
        every: u64,
        /// At most N frames (K is raised until they fit).
        #[arg(long, value_name = "N", default_value_t = 200,
              value_parser = clap::value_parser!(u64).range(2..100_000))]
        max_frames: u64,
        /// Frame width in pixels (200 to 16384).
        #[arg(long, default_value_t = 900,
              value_parser = clap::value_parser!(u32).range(200..=16384))]
        width: u32,
        /// Frame height in pixels (150 to 16384).
        #[arg(long, default_value_t = 560,
              value_parser = clap::value_parser!(u32).range(150..=16384))]
        height: u32,
        /// Seconds per frame (0.01 to 655; GIF counts hundredths).
        #[arg(long, value_name = "SECONDS", default_value_t = 0.1, value_parser = parse_frame_duration)]
        frame_duration: f64,
        /// The output file (one movie only) [default: DIR/contact_area.gif,
        /// DIR/coulomb_stress.gif].
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
        /// Also writes every frame as a numbered PNG into FRAMES (made if missing):
        /// contact_area_0000.png, ... (the GIF's name, then the frame's number), for a
        /// video encoder of your choice.
        #[arg(long, value_name = "FRAMES")]
        png_frames: Option<PathBuf>,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, clap::ValueEnum)]
enum MovieArg {
    /// Movie S1: the real contact area per cell.
    ContactArea,
    /// Movie S2: the y-averaged Coulomb stress over the recorded planes.
    CoulombStress,
    /// Both (S2 only when planes were recorded).
    All,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum FormatArg {
    Png,
    Svg,
    Both,
}

/// A frame duration a GIF can hold: 0.01 to 655.35 s, in hundredths (bad values are a bad
/// command line, code 2, as every other option's).
fn parse_frame_duration(text: &str) -> Result<f64, String> {
    let seconds: f64 = text
        .trim()
        .parse()
        .map_err(|e| format!("{text:?} is not a number of seconds ({e})"))?;
    let hundredths = (seconds * 100.0).round();
    if !(1.0..=65535.0).contains(&hundredths) {
        return Err(format!(
            "{text:?}: a frame is shown 0.01 to 655 s (GIF counts hundredths of a second)"
        ));
    }
    Ok(seconds)
}

fn parse_shard(text: &str) -> Result<(usize, usize), String> {
    let (k, n) = text
        .split_once('/')
        .ok_or_else(|| format!("{text:?} is not K/N (e.g. 0/4)"))?;
    let k: usize = k
        .trim()
        .parse()
        .map_err(|e| format!("K in {text:?}: {e}"))?;
    let n: usize = n
        .trim()
        .parse()
        .map_err(|e| format!("N in {text:?}: {e}"))?;
    if n == 0 || k >= n {
        return Err(format!("{text:?}: need 0 <= K < N"));
    }
    Ok((k, n))
}

/// The shard from SLURM's job-array variables (`SLURM_ARRAY_TASK_*`), if this is an array
/// task. Task ids need not start at 0 nor be contiguous: `--array=10-16:2` gives ids 10,
/// 12, 14, 16 with MIN 10 and STEP 2, so shard K = (ID - MIN) / STEP of COUNT. Older SLURM
/// releases set no COUNT, only MIN and MAX: N is then (MAX - MIN) / STEP + 1. A list such as
/// `--array=1,3,8` (COUNT 3, MIN 1, MAX 8, STEP 1 on SLURM 22.05) has no such rank and is
/// refused, as is an ID without COUNT or MAX: each task would run the whole sweep.
fn slurm_shard(var: impl Fn(&str) -> Option<String>) -> Result<Option<(usize, usize)>, String> {
    let var = |name: &str| var(name).filter(|v| !v.trim().is_empty());
    let number = |name: &str| -> Result<Option<usize>, String> {
        var(name)
            .map(|v| {
                v.trim()
                    .parse::<usize>()
                    .map_err(|e| format!("{name}={v:?}: {e}"))
            })
            .transpose()
    };
    let Some(id) = number("SLURM_ARRAY_TASK_ID")? else {
        return Ok(None);
    };
    let count = number("SLURM_ARRAY_TASK_COUNT")?;
    let min = number("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
    let max = number("SLURM_ARRAY_TASK_MAX")?;
    let step = number("SLURM_ARRAY_TASK_STEP")?.unwrap_or(1);
    let give = "give the shard with --shard K/N";
    if step == 0 {
        return Err(format!("SLURM_ARRAY_TASK_STEP=0: {give}"));
    }
    // The number of ids MIN, MIN + STEP, ..., MAX.
    let span = match max {
        Some(max) if max >= min && (max - min) % step == 0 => Some((max - min) / step + 1),
        Some(max) => {
            return Err(format!(
                "SLURM_ARRAY_TASK_MAX={max} is not SLURM_ARRAY_TASK_MIN={min} plus a multiple \
                 of SLURM_ARRAY_TASK_STEP={step}: {give}"
            ))
        }
        None => None,
    };
    let n = match (count, span) {
        (Some(count), Some(span)) if count != span => {
            let max = max.unwrap_or_default();
            return Err(format!(
                "the array's task ids are not evenly spaced: SLURM_ARRAY_TASK_COUNT={count}, but \
                 MIN={min} to MAX={max} by STEP={step} are {span} ids (an --array list?): {give}"
            ));
        }
        (Some(n), _) | (None, Some(n)) => n,
        (None, None) => {
            return Err(format!(
                "SLURM_ARRAY_TASK_ID={id} is set but neither SLURM_ARRAY_TASK_COUNT nor \
                 SLURM_ARRAY_TASK_MAX: {give}"
            ))
        }
    };
    let offset = id
        .checked_sub(min)
        .filter(|o| o % step == 0)
        .ok_or_else(|| {
            format!(
                "SLURM_ARRAY_TASK_ID={id} is not SLURM_ARRAY_TASK_MIN={min} plus a multiple of \
                 SLURM_ARRAY_TASK_STEP={step}: {give}"
            )
        })?;
    parse_shard(&format!("{}/{n}", offset / step))
        .map(Some)
        .map_err(|e| format!("the shard from SLURM's variables, {e}: {give}"))
}

/// The library's bounding of values echoed in messages (one source, compiled here too):
/// a cause's message is cut as the library's own messages are.
#[allow(dead_code)] // the program uses `bounded`, not the `Display` wrapper
#[path = "../error/bounded.rs"]
mod bounded;

/// A failure and its exit code.
struct Failure {
    error: Box<dyn std::error::Error>,
    code: u8,
}

/// The exit code of a core error (docs/cli.md): 1 a computation that failed, 4 a file or
/// directory that could not be read or written (or is locked by another process), 3
/// invalid input (bytes that are not UTF-8 text included: a binary given as a scene file
/// is bad input, not a failure to read), 6 the CUDA backend unavailable here (no feature
/// `cuda`, driver, GPU or library).
fn core_code(e: &Error) -> u8 {
    match e {
        Error::Io { source, .. } if source.kind() == std::io::ErrorKind::InvalidData => 3,
        Error::Io { .. } | Error::NotARegularFile { .. } | Error::DirectoryLocked { .. } => 4,
        Error::SolverNotConverged { .. }
        | Error::Factorization { .. }
        | Error::EmptyContact { .. }
        | Error::ThreadPool { .. }
        | Error::NotSolved { .. }
        | Error::DriverFailed { .. }
        | Error::LoadBeyondFriction { .. } => 1,
        // An output option naming a file the command writes or reads: a bad command line.
        Error::OutputCollision { .. } => 2,
        // The scene asks for the CUDA backend and this machine or build cannot give it: the
        // same scene runs elsewhere (or with backend "spectral").
        Error::CudaUnavailable { .. } => 6,
        // A CUDA call that failed during the solves: the computation failed.
        #[cfg(feature = "cuda")]
        Error::Cuda { .. } => 1,
        // A scene too large for the GPU's memory does not fit, as one too large for the
        // machine's (`OutOfMemory`).
        #[cfg(feature = "cuda")]
        Error::DeviceOutOfMemory { .. } => 3,
        _ => 3,
    }
}

/// The exit code of a sweep's error: its core error's, else 3 (a sweep file, an axis, a
/// sweep too large, a directory of another sweep: invalid input).
fn sweep_code(e: &SweepError) -> u8 {
    match e {
        SweepError::Core(e) => core_code(e),
        _ => 3,
    }
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        Failure {
            code: core_code(&e),
            error: Box::new(e),
        }
    }
}

impl From<SweepError> for Failure {
    fn from(e: SweepError) -> Self {
        Failure {
            code: sweep_code(&e),
            error: Box::new(e),
        }
    }
}

impl From<PlotError> for Failure {
    fn from(e: PlotError) -> Self {
        let code = match &e {
            PlotError::Core(e) => core_code(e),
            PlotError::Sweep(e) => sweep_code(e),
            // --figure naming no figure, or one the directory cannot give; --dpi out of
            // range, or a --width, --height and --dpi whose PNG is too large.
            PlotError::UnknownFigure { .. }
            | PlotError::FigureUnavailable { .. }
            | PlotError::InvalidDpi { .. }
            | PlotError::InvalidSize { .. } => 2,
            // A figure that cannot be drawn (a directory neither a run's nor a sweep's).
            _ => 3,
        };
        Failure {
            code,
            error: Box::new(e),
        }
    }
}

fn usage(message: String) -> Failure {
    Failure {
        error: message.into(),
        code: 2,
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let progress = !cli.quiet && std::io::stderr().is_terminal();
    let outcome = match cli.command {
        Command::Run {
            scene,
            out,
            checkpoint,
            every,
        } => run(
            Start::Scene(&scene),
            &out,
            checkpoint.as_deref(),
            every,
            progress,
        ),
        Command::Resume {
            checkpoint,
            out,
            every,
        } => run(
            Start::Checkpoint(&checkpoint),
            &out,
            Some(&checkpoint),
            every,
            progress,
        ),
        Command::Info { scene } => info(&scene),
        Command::Sweep {
            sweep,
            out,
            jobs,
            shard,
        } => run_sweep(&sweep, &out, jobs, shard, progress),
        Command::Merge { dir } => merge(&dir),
        Command::Stats {
            dir,
            bootstrap,
            goodness,
            confidence,
            min_tail,
            bins_per_decade,
            seed,
            include_spanning,
        } => stats(
            &dir,
            &StatsOptions::default()
                .fit(
                    PowerLawOptions::default()
                        .bootstrap(bootstrap as usize)
                        .goodness_samples(goodness as usize)
                        .confidence(confidence)
                        .min_tail(min_tail as usize)
                        .seed(seed),
                )
                .bins_per_decade(bins_per_decade as usize)
                .include_spanning(include_spanning),
            progress,
        ),
        Command::Plot {
            dir,
            figures,
            format,
            width,
            height,
            dpi,
        } => plot(&dir, format, ((width, height), dpi), &figures),
        Command::Movie {
            dir,
            field,
            every,
            max_frames,
            width,
            height,
            frame_duration,
            out,
            png_frames,
        } => movie(
            &dir,
            field,
            MovieOptions {
                every,
                max_frames,
                size: (width, height),
                frame_duration,
                png_frames,
            },
            out.as_deref(),
            progress,
        ),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => {
            report(&*failure.error);
            ExitCode::from(failure.code)
        }
    }
}

/// The messages of `error` and of its causes ([`std::error::Error::source`]), outermost
/// first, each with its echoed values cut ([`bounded::bounded`]). The library's errors
/// leave their cause out of their message (`Error::Io` says "reading scene file `<path>`",
/// its source the system's message); a cause whose message already ends the one before it
/// (another library's error that repeats its own) is left out, so each is printed once.
fn messages(error: &(dyn std::error::Error + 'static)) -> Vec<String> {
    let mut out = vec![bounded::bounded(&error.to_string()).into_owned()];
    let mut source = error.source();
    while let Some(cause) = source {
        let text = bounded::bounded(&cause.to_string()).into_owned();
        if !out.last().is_some_and(|previous| previous.ends_with(&text)) {
            out.push(text);
        }
        source = cause.source();
    }
    out
}

/// Prints `error: <message>` and one `caused by: <message>` per source ([`messages`]).
fn report(e: &(dyn std::error::Error + 'static)) {
    for (k, text) in messages(e).iter().enumerate() {
        if k == 0 {
            say!("error: {text}");
        } else {
            say!("  caused by: {text}");
        }
    }
}

/// A one-line progress display on stderr, redrawn at most four times a second.
struct Progress {
    enabled: bool,
    started: Instant,
    last: Option<Instant>,
}

impl Progress {
    fn new(enabled: bool) -> Self {
        Self {
            enabled,
            started: Instant::now(),
            last: None,
        }
    }

    /// Redraws with `line(elapsed seconds)` if due (or `force`).
    fn show(&mut self, force: bool, line: impl FnOnce(f64) -> String) {
        if !self.enabled {
            return;
        }
        let due = self
            .last
            .is_none_or(|t| t.elapsed() >= Duration::from_millis(250));
        if due || force {
            self.last = Some(Instant::now());
            use std::io::Write as _;
            let line = line(self.started.elapsed().as_secs_f64());
            let _ = write!(std::io::stderr(), "\r{line}\x1b[K");
        }
    }

    fn finish(&self) {
        if self.enabled && self.last.is_some() {
            say!();
        }
    }
}

fn eta(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "?".into();
    }
    let s = seconds.round() as u64;
    if s >= 3600 {
        format!("{}h{:02}m", s / 3600, (s % 3600) / 60)
    } else {
        format!("{}m{:02}s", s / 60, s % 60)
    }
}

enum Start<'a> {
    Scene(&'a Path),
    Checkpoint(&'a Path),
}

fn writable_dir(dir: &Path) -> Result<(), Failure> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        operation: "creating the output directory",
        path: dir.to_path_buf(),
        source,
    })?;
    Ok(())
}

/// Refuses, before anything is written, a checkpoint that would replace a file of the run
/// directory or the scene file the run reads.
fn refuse_colliding_checkpoint(
    start: &Start<'_>,
    out: &Path,
    checkpoint: &Path,
) -> Result<(), Failure> {
    precursors::output::check_output_path(out, checkpoint)?;
    if let Start::Scene(scene) = start {
        if let (Ok(a), Ok(b)) = (scene.canonicalize(), checkpoint.canonicalize()) {
            if a == b {
                return Err(usage(format!(
                    "--checkpoint {} names the scene file the run reads: the checkpoint \
                     would replace it; name another file",
                    checkpoint.display()
                )));
            }
        }
    }
    Ok(())
}

/// `x` with at most six decimals and no trailing zeros (`140`, `0.5`, `7.25`).
fn digits(x: f64) -> String {
    let text = format!("{x:.6}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn run(
    start: Start<'_>,
    out: &Path,
    checkpoint: Option<&Path>,
    every: u64,
    progress: bool,
) -> Result<(), Failure> {
    let (scene, mut driver, tables) = match start {
        Start::Scene(path) => {
            writable_dir(out)?;
            // Once the directory exists, so that any spelling of it is resolved.
            if let Some(checkpoint) = checkpoint {
                refuse_colliding_checkpoint(&start, out, checkpoint)?;
            }
            let scene = SceneBuilder::from_json_file(path)?.build()?;
            let driver = scene.driver()?;
            let tables = RunTables::create(out, &driver)?;
            (scene, driver, tables)
        }
        Start::Checkpoint(path) => {
            refuse_colliding_checkpoint(&start, out, path)?;
            let checkpoint = Checkpoint::read_from(path)?;
            let scene = checkpoint.scene().clone().build()?;
            let driver = scene.resume(&checkpoint)?;
            // Keep the rows up to the checkpoint (a crashed run may have written more),
            // once the directory's scene and tables are checked against it.
            let k = checkpoint.event_count();
            let tables = RunTables::resume(out, &driver)?;
            say!("resumed at event {k} from {}", path.display());
            (scene, driver, tables)
        }
    };
    let grid = *scene.grid();
    let block = grid.block();
    // The lengths in mm beside metres and the mean pressure: a scene typed in the wrong
    // unit shows at once (docs/scene-format.md).
    say!(
        "{} x {} cells ({} backend), block {} x {} x {} mm ({} x {} x {} m), F_N = {} N, \
         mean pressure {:.4e} Pa",
        grid.nx(),
        grid.ny(),
        driver.backend(),
        digits(block.lx() * 1e3),
        digits(block.ly() * 1e3),
        digits(block.lz() * 1e3),
        block.lx(),
        block.ly(),
        block.lz(),
        scene.normal_load(),
        scene.normal_load() / (block.lx() * block.ly())
    );
    let mu_fn = driver.friction_limit();
    let first_event = driver.event_count();
    let mut bar = Progress::new(progress);
    let line = |driver: &Driver, elapsed: f64| {
        let broken = driver.interface().broken_count();
        let x = driver.force() / mu_fn;
        let done = (driver.event_count() - first_event) as f64;
        format!(
            "{:>9} events  {:>8.0} events/s  {broken:>7}/{} broken  F/(μF_N) = {x:.4}  \
             {elapsed:.0} s, ETA ~{} (from the load)",
            driver.event_count(),
            done / elapsed.max(1e-9),
            driver.site_states().len(),
            eta(elapsed * (1.0 - x) / x.max(1e-9)),
        )
    };
    // clap takes N >= 1 only.
    let every =
        std::num::NonZeroU64::new(every).ok_or_else(|| usage("--every must be >= 1".into()))?;
    let checkpoint = checkpoint.map(|path| (path, every));
    let fields_path = tables.fields_path().map(Path::to_path_buf);
    // The sites in contact at zero shear, seen when the run starts from its first event.
    let mut zero_shear = None;
    let mut tables = tables;
    catch_stop_signals();
    let signal = tables.run_until(&mut driver, checkpoint, |event, driver| {
        if driver.event_count() == 1 {
            let attached = driver
                .site_states()
                .iter()
                .filter(|s| **s == SiteState::Attached)
                .count();
            zero_shear = Some(attached);
        }
        bar.show(false, |elapsed| line(driver, elapsed));
        // At the next stable state: the tables continue from a checkpoint taken there.
        match (stopped(), event) {
            (Some(signal), precursors::Event::Stable { .. }) => {
                std::ops::ControlFlow::Break(signal)
            }
            _ => std::ops::ControlFlow::Continue(()),
        }
    })?;
    bar.finish();
    if let Some(signal) = signal {
        let at = driver.event_count();
        let what = match checkpoint {
            Some((path, _)) => {
                // The checkpoint at this stable state, so that nothing done is lost.
                tables.checkpoint(&driver)?.write_to(path)?;
                format!(
                    "kept the tables in {} as *.partial and the checkpoint {} at event {at}; \
                     continue with: precursors resume {} --out {}",
                    out.display(),
                    path.display(),
                    path.display(),
                    out.display()
                )
            }
            None => format!(
                "kept the tables in {} as *.partial up to event {at}, but without \
                 --checkpoint the run cannot continue: run it again (with --checkpoint FILE \
                 to be able to stop and resume)",
                out.display()
            ),
        };
        return Err(interrupted(signal, what));
    }
    bar.show(true, |elapsed| line(&driver, elapsed));
    let [events_path, curve_path, map_path] = tables.finish()?;
    say!(
        "global slip after {} events at F/(μF_N) = {:.6}; wrote {}, {} and {}",
        driver.event_count(),
        driver.force() / mu_fn,
        events_path.display(),
        curve_path.display(),
        map_path.display()
    );
    if let Some(attached) = zero_shear {
        let sites = grid.len();
        say!(
            "{attached} of {sites} sites ({:.1} %) were in contact at zero shear",
            100.0 * attached as f64 / sites as f64
        );
    }
    if let Some(path) = fields_path {
        say!(
            "recorded the fields in {} (`precursors movie`)",
            path.display()
        );
    }
    Ok(())
}

/// The largest grid (cells) for which `info` builds the whole scene to check it as `run`
/// does: planning is about 1.5 µs a cell (docs/performance.md), so 0.15 s here.
const INFO_BUILDS_BELOW: usize = 100_000;

fn info(path: &Path) -> Result<(), Failure> {
    let builder = SceneBuilder::from_json_file(path)?;
    let file: serde_json::Value = serde_json::from_str(&builder.to_json()?).unwrap_or_default();
    // The file as written, for what the builder's JSON does not keep (a map file's path).
    let raw: serde_json::Value = std::fs::read_to_string(path)
        .ok()
        .and_then(|text| serde_json::from_str(&text).ok())
        .unwrap_or_default();
    // What `run` refuses, `info` refuses: every check of `build` but the plan (memory
    // included); and the whole scene is built when that is quick, which also plans.
    let grid = builder.check()?;
    let n = grid.len();
    if n < INFO_BUILDS_BELOW {
        // Without its probes and recording, which `check` has checked: their planning
        // (milliseconds a plane) is estimated below, not done.
        builder
            .clone()
            .probes(ProbeSpec::default())
            .run_options(RunOptions::new())
            .build()?;
    }
    let observers = builder.observer_cost()?;
    let limit = file["max_output_bytes"]
        .as_f64()
        .unwrap_or(RunOptions::DEFAULT_MAX_OUTPUT_BYTES);
    let cost = GridCost::of(grid.nx(), grid.ny());
    let backend = file["solver"]["backend"].as_str().unwrap_or("auto");
    if backend == "cuda" {
        check_cuda()?;
    }
    let resolved = match backend {
        "auto" if n <= precursors::solver::AUTO_DENSE_LIMIT => "dense (auto)",
        "auto" => "spectral (auto)",
        other => other,
    };
    let block = grid.block();
    let contact = match (file["contact"]["rule"].as_str(), &file["contact"]["delay"]) {
        (Some(rule), serde_json::Value::Object(delay)) => format!(
            "{rule} (delay {} stable states and {} μF_N)",
            delay
                .get("stable_states")
                .unwrap_or(&serde_json::Value::Null),
            delay.get("load").unwrap_or(&serde_json::Value::Null)
        ),
        (Some(rule), _) => rule.to_string(),
        (None, _) => "paper".to_string(),
    };
    // Fitted to documented runs to global slip on one thread (release build,
    // docs/performance.md): the calibration scene, 980 cells, 0.84 s; N = 1e4, about 70 s;
    // above, the growth from N = 1e4 to 1e5 measured on one machine (115 s to about
    // 15 000 s: exponent 2.1, the iterations flat but each dearer).
    let run = if (n as f64) <= 1e4 {
        0.84 * (n as f64 / 980.0).powf(1.9)
    } else {
        0.84 * (1e4_f64 / 980.0).powf(1.9) * (n as f64 / 1e4).powf(2.1)
    };
    let maps = map_lines(&raw, &file, &grid)?;
    let text = format!(
        "scene      {}\n\
         block      {} x {} x {} m\n\
         cells      {} x {} = {n} (cell {} x {} m)\n\
         backend    {resolved}, solver threads {}\n\
         contact    {contact} (the rules of key contact.rule: paper, anchored, \
         rejuvenation)\n\
         {maps}\
         memory     ~{} (estimate)\n\
         plan       ~{} (estimate, one thread)\n\
         equilibrium ~{} per cold normal + tangential solve (estimate, one thread)\n\
         run        ~{} to global slip (rough: 0.84 s·(N/980)^1.9 up to N = 1e4, then \
         growing as N^2.1; fitted to the calibration scene, N = 1e4 and 1e5; the events \
         depend on the scene)\n\
         output     ~{} at most beside the three tables (fields.csv {}, profiles.csv {}; \
         limit {}, key max_output_bytes)\n\
         observers  ~{} to plan, ~{} at most to record, ~{} of memory (estimates, one \
         thread; docs/performance.md, \"Observer costs\")\n\
         gpu        {}\n",
        path.display(),
        metres(block.lx()),
        metres(block.ly()),
        metres(block.lz()),
        grid.nx(),
        grid.ny(),
        metres(grid.dx()),
        metres(grid.dy()),
        file["solver"]["threads"],
        format_bytes(cost.memory_bytes),
        format_seconds(cost.plan_seconds),
        format_seconds(cost.solve_seconds),
        format_seconds(run),
        format_bytes(observers.output_bytes()),
        format_bytes(observers.fields_bytes),
        format_bytes(observers.profiles_bytes),
        format_bytes(limit),
        format_seconds(observers.plan_seconds),
        format_seconds(observers.record_seconds),
        format_bytes(observers.memory_bytes),
        gpu(),
    );
    print_out(&text)
}

/// A scene for the CUDA backend: `info` refuses it where `run` would, with the same
/// error (no usable GPU, a library missing).
#[cfg(feature = "cuda")]
fn check_cuda() -> Result<(), Failure> {
    precursors::solver::cuda_device()?;
    Ok(())
}

/// Without the feature `cuda`: the library's own refusal (its words, not a copy), from the
/// solver of a tiny scene with the backend `cuda`.
#[cfg(not(feature = "cuda"))]
fn check_cuda() -> Result<(), Failure> {
    use precursors::solver::{Backend, SolverOptions};
    let options = SolverOptions::default().with_backend(Backend::Cuda)?;
    SceneBuilder::default()
        .cells(4, 2)
        .solver_options(options)
        .build()?
        .driver()?;
    Ok(())
}

/// The GPU the CUDA backend would run on (`precursors::solver::cuda_device`), or why
/// there is none usable.
#[cfg(feature = "cuda")]
fn gpu() -> String {
    match precursors::solver::cuda_device() {
        Ok(device) => device.to_string(),
        Err(e) => format!("none usable: {e}"),
    }
}

/// Without the feature `cuda` no GPU is looked for.
#[cfg(not(feature = "cuda"))]
fn gpu() -> String {
    "this build has no CUDA backend (feature cuda)".into()
}

/// Writes `text` to stdout. A reader that went away (`precursors info x | head -1`) has
/// all it wanted: the program ends quietly with code 0; any other failure is code 4.
fn print_out(text: &str) -> Result<(), Failure> {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Failure {
            error: format!("writing to standard output: {e}").into(),
            code: 4,
        }),
        _ => Ok(()),
    }
}

/// A length with six significant digits, as a person writes it: `0.0007`, not the
/// `0.0007000000000000001` that `0.007 / 10` is in binary; `1e-9`, not 0.000000001.
fn metres(m: f64) -> String {
    significant(m, 6)
}

/// `x` with `digits` significant digits (at least 1), as a person writes it: `0.5012`,
/// `1.65e12`, `1e-9`; plainly from 1e-4 to 1e6, else with an exponent.
fn significant(x: f64, digits: usize) -> String {
    let rounded: f64 = format!("{:.*e}", digits.max(1) - 1, x).parse().unwrap_or(x);
    if rounded == 0.0 || (1e-4..1e6).contains(&rounded.abs()) {
        format!("{rounded}")
    } else {
        format!("{rounded:e}")
    }
}

/// The scene file's maps (key `maps`), one line each: the key and the unit of its
/// values, the map's kind (a file's path; a random map's correlation length in mm where
/// its spectrum has one, and its seed) and its values over the sites, drawn for a random
/// map: their mean, standard deviation (over the `N` sites, `1/N`), smallest and
/// largest, four significant digits. `raw` is the file as written (a map file's path),
/// `file` the scene as the builder reads it (a map file's values).
fn map_lines(
    raw: &serde_json::Value,
    file: &serde_json::Value,
    grid: &precursors::Grid,
) -> Result<String, Failure> {
    const MAPS: [(&str, &str); 3] = [
        ("friction_coefficient", "dimensionless"),
        ("c_x", "N/m³"),
        ("c_z", "N/m²"),
    ];
    let mut lines = String::new();
    for (key, unit) in MAPS {
        let spec = &file["maps"][key];
        if spec.is_null() {
            continue;
        }
        let written = &raw["maps"][key];
        let mut kind = written["kind"]
            .as_str()
            .or(spec["kind"].as_str())
            .unwrap_or("values")
            .to_string();
        if let Some(path) = written["path"].as_str() {
            kind = format!("{kind} {path}");
        }
        let mut about = Vec::new();
        if let Some(xi) = spec["correlation_length"].as_f64() {
            about.push(format!("ξ = {} mm", significant(1e3 * xi, 4)));
        }
        if let Some(seed) = spec["seed"].as_u64() {
            about.push(format!("seed {seed}"));
        }
        if !about.is_empty() {
            kind = format!("{kind} ({})", about.join(", "));
        }
        // The builder's own JSON of the map: it reads back (a file's as its values).
        let map: precursors::SiteMap =
            serde_json::from_value(spec.clone()).map_err(|e| Failure {
                error: format!("reading back the map maps.{key}: {e}").into(),
                code: 1,
            })?;
        let values = map.values(grid)?;
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let std = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
        let (min, max) = values
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        lines.push_str(&format!(
            "map        {key} ({unit}): {kind}; over {} sites mean {}, std {}, min {}, max {}\n",
            values.len(),
            significant(mean, 4),
            significant(std, 4),
            significant(min, 4),
            significant(max, 4),
        ));
    }
    Ok(lines)
}

fn run_sweep(
    path: &Path,
    out: &Path,
    jobs: Option<u64>,
    shard: Option<(usize, usize)>,
    progress: bool,
) -> Result<(), Failure> {
    let shard = match shard {
        Some(s) => s,
        None => slurm_shard(|name| std::env::var(name).ok())
            .map_err(usage)?
            .unwrap_or((0, 1)),
    };
    let jobs = match jobs {
        Some(j) => usize::try_from(j).unwrap_or(usize::MAX),
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let sweep = Sweep::from_json_file(path)?;
    let share = sweep.shard(shard.0, shard.1)?.len();
    say!(
        "{} points x {} realizations = {} runs; shard {}/{}: {share} runs on {jobs} jobs",
        sweep.points(),
        sweep.realizations(),
        sweep.runs().len(),
        shard.0,
        shard.1
    );
    let bar = std::sync::Mutex::new(Progress::new(progress));
    let done = std::sync::atomic::AtomicUsize::new(0);
    let ran = std::sync::atomic::AtomicUsize::new(0);
    let options = SweepOptions::new()
        .with_jobs(jobs)?
        .with_shard(shard.0, shard.1)?;
    catch_stop_signals();
    let stop = std::sync::atomic::AtomicBool::new(false);
    let finished = std::sync::atomic::AtomicBool::new(false);
    let summary = std::thread::scope(|scope| {
        // Raises the sweep's flag when a signal comes: its runs stop at their next event.
        scope.spawn(|| {
            while !finished.load(std::sync::atomic::Ordering::SeqCst) {
                if stopped().is_some() {
                    stop.store(true, std::sync::atomic::Ordering::SeqCst);
                    return;
                }
                std::thread::sleep(Duration::from_millis(20));
            }
        });
        let summary = sweep.execute_until(
            out,
            &options,
            |report| {
                let d = done.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1;
                let here = usize::from(!report.skipped && !report.held_elsewhere);
                let r = ran.fetch_add(here, std::sync::atomic::Ordering::SeqCst) + here;
                if let Ok(mut bar) = bar.lock() {
                    bar.show(d == share, |elapsed| {
                        let rate = r as f64 / elapsed.max(1e-9);
                        format!(
                            "{d}/{share} runs ({} skipped)  {:.2} runs/min  {elapsed:.0} s, ETA {}",
                            d - r,
                            60.0 * rate,
                            eta((share - d) as f64 / rate)
                        )
                    });
                }
            },
            &stop,
        );
        finished.store(true, std::sync::atomic::Ordering::SeqCst);
        summary
    })?;
    if let Ok(bar) = bar.lock() {
        bar.finish();
    }
    if let Some(signal) = stopped() {
        return Err(interrupted(
            signal,
            format!(
                "{} runs of this shard complete in {} (marked done), the others stopped or \
                 not started; continue with: precursors sweep {} --out {}{} (complete runs \
                 are skipped)",
                summary.completed + summary.skipped,
                out.display(),
                path.display(),
                out.display(),
                match shard {
                    (0, 1) => String::new(),
                    (k, n) => format!(" --shard {k}/{n}"),
                }
            ),
        ));
    }
    let held = match summary.held_elsewhere {
        0 => String::new(),
        h => format!(", {h} left to another process running them (merge once it ends)"),
    };
    say!(
        "{} runs done, {} skipped (complete already){held}, in {:.1} s; results in {}",
        summary.completed,
        summary.skipped,
        summary.seconds,
        out.display()
    );
    Ok(())
}

fn plot(
    dir: &Path,
    format: FormatArg,
    (size, dpi): ((u32, u32), u32),
    figures: &[String],
) -> Result<(), Failure> {
    use precursors::plot::{draw_with_options, DrawOptions, Format};
    let formats: &[Format] = match format {
        FormatArg::Png => &[Format::Png],
        FormatArg::Svg => &[Format::Svg],
        FormatArg::Both => &[Format::Png, Format::Svg],
    };
    let options = DrawOptions::default()
        .formats(formats)
        .size(size.0, size.1)
        .dpi(dpi)
        .figures(figures);
    let drawn = draw_with_options(dir, &options)?;
    if let Some(summary) = &drawn.merge {
        for file in &summary.files {
            say!("wrote {}", file.display());
        }
    }
    for file in &drawn.files {
        say!("wrote {}", file.display());
    }
    for note in &drawn.notes {
        say!("note: {note}");
    }
    match &drawn.merge {
        Some(summary) if summary.runs_missing > 0 => Err(incomplete(summary, dir)),
        _ => Ok(()),
    }
}

/// The options of `precursors movie` shared by its movies.
struct MovieOptions {
    every: u64,
    max_frames: u64,
    size: (u32, u32),
    frame_duration: f64,
    png_frames: Option<PathBuf>,
}

fn movie(
    dir: &Path,
    field: MovieArg,
    options: MovieOptions,
    out: Option<&Path>,
    progress: bool,
) -> Result<(), Failure> {
    use precursors::plot::{Movie, MovieKind};
    let kinds: Vec<(MovieKind, &str)> = match field {
        MovieArg::ContactArea => vec![(MovieKind::ContactArea, "contact_area.gif")],
        MovieArg::CoulombStress => vec![(MovieKind::CoulombStress, "coulomb_stress.gif")],
        MovieArg::All => vec![
            (MovieKind::ContactArea, "contact_area.gif"),
            (MovieKind::CoulombStress, "coulomb_stress.gif"),
        ],
    };
    if out.is_some() && kinds.len() > 1 {
        return Err(usage(
            "--out names one movie: give --field contact-area or --field coulomb-stress".into(),
        ));
    }
    for (kind, name) in kinds {
        let path = out.map_or_else(|| dir.join(name), Path::to_path_buf);
        let mut movie = Movie::new(dir, kind)
            .every(usize::try_from(options.every).unwrap_or(usize::MAX))?
            .max_frames(usize::try_from(options.max_frames).unwrap_or(usize::MAX))?
            .size(options.size.0, options.size.1)
            .frame_duration(options.frame_duration)?;
        if let Some(frames) = &options.png_frames {
            movie = movie.png_frames(frames);
        }
        let mut bar = Progress::new(progress);
        catch_stop_signals();
        let outcome = movie.save_until(&path, |drawn, frames| {
            bar.show(drawn == frames, |elapsed| {
                let left = elapsed / drawn as f64 * (frames - drawn) as f64;
                format!(
                    "{name}: frame {drawn}/{frames}, {elapsed:.0} s, about {} left",
                    eta(left)
                )
            });
            match stopped() {
                Some(_) => std::ops::ControlFlow::Break(()),
                None => std::ops::ControlFlow::Continue(()),
            }
        });
        bar.finish();
        if let (Some(signal), Ok(None)) = (stopped(), &outcome) {
            return Err(interrupted(
                signal,
                format!(
                    "{} was not written (the movies before it were); run the command again \
                     to draw it",
                    path.display()
                ),
            ));
        }
        let outcome = outcome.and_then(|report| {
            report.ok_or_else(|| precursors::plot::PlotError::Figure {
                path: Some(path.clone()),
                reason: "the movie was stopped".into(),
            })
        });
        match outcome {
            Ok(report) => {
                say!(
                    "wrote {} ({:.1} MB): {} frames of {} recorded states (one in {} and the \
                 last), colour scale {:.4} to {:.4} {}{}",
                    path.display(),
                    std::fs::metadata(&path).map_or(0.0, |m| m.len() as f64 / 1e6),
                    report.frames,
                    report.states,
                    report.stride,
                    report.colour_range.0,
                    report.colour_range.1,
                    if kind == MovieKind::ContactArea {
                        "mm²"
                    } else {
                        "MPa"
                    },
                    options
                        .png_frames
                        .as_ref()
                        .map_or_else(String::new, |d| format!(
                            "; its frames as PNGs in {}",
                            d.display()
                        ))
                );
                // The frames' directory is the movie's: an older movie's frames beyond
                // these would be encoded after them.
                if let (Some(first), Some(last)) = (
                    report.stale_frames_removed.first(),
                    report.stale_frames_removed.last(),
                ) {
                    say!(
                        "removed {} PNG frames of an older movie that these did not \
                         overwrite ({} to {})",
                        report.stale_frames_removed.len(),
                        first.display(),
                        last.display()
                    );
                }
            }
            // `all`: the Coulomb stress movie of a run that recorded no planes is skipped.
            Err(precursors::plot::PlotError::NoFields { reason, .. })
                if field == MovieArg::All && kind == MovieKind::CoulombStress =>
            {
                say!("note: no {name}: {reason}");
            }
            Err(e) => return Err(e.into()),
        }
    }
    Ok(())
}

/// The failure of a merge or plot of a sweep with runs not complete.
fn incomplete(summary: &precursors::sweep::MergeSummary, dir: &Path) -> Failure {
    Failure {
        error: format!(
            "{} runs of the sweep in {} are not complete: run the sweep (or its missing \
             shards) again, then merge",
            summary.runs_missing,
            dir.display()
        )
        .into(),
        code: 5,
    }
}

fn stats(dir: &Path, options: &StatsOptions, progress: bool) -> Result<(), Failure> {
    let bar = std::sync::Mutex::new(Progress::new(progress));
    let summary = precursors::sweep::statistics_with_progress(dir, options, |p| {
        let Ok(mut bar) = bar.lock() else { return };
        // Only a `stats` that lasts: a short one prints its lines alone.
        if bar.started.elapsed() < Duration::from_secs(1) {
            return;
        }
        let last = p.fits_done == p.fits && p.point + 1 == p.points;
        bar.show(last, |elapsed| {
            let filled = (20 * p.fits_done).checked_div(p.fits).unwrap_or(20);
            format!(
                "stats: point {}/{} [{}{}] {}/{} fits ({}), {:.0} s",
                p.point + 1,
                p.points,
                "#".repeat(filled),
                " ".repeat(20 - filled),
                p.fits_done,
                p.fits,
                p.observable,
                elapsed
            )
        });
    });
    if let Ok(bar) = bar.lock() {
        bar.finish();
    }
    let summary = summary?;
    for verdict in &summary.verdicts {
        say!("{verdict}");
    }
    for line in summary.classes.iter().chain(&summary.scaling) {
        say!("{line}");
    }
    for file in &summary.files {
        say!("wrote {}", file.display());
    }
    say!(
        "{} points, {} runs pooled, {} missing",
        summary.points,
        summary.runs,
        summary.runs_missing
    );
    if summary.runs_missing > 0 {
        return Err(Failure {
            error: format!(
                "{} runs of the sweep in {} are not complete: run the sweep (or its missing \
                 shards) again, then stats",
                summary.runs_missing,
                dir.display()
            )
            .into(),
            code: 5,
        });
    }
    Ok(())
}

/// A confidence level: a number strictly between 0 and 1.
fn parse_confidence(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(c) if c > 0.0 && c < 1.0 => Ok(c),
        _ => Err(format!("{text:?} is not a number strictly between 0 and 1")),
    }
}

fn merge(dir: &Path) -> Result<(), Failure> {
    let summary = precursors::sweep::merge(dir)?;
    for file in &summary.files {
        say!("wrote {}", file.display());
    }
    say!(
        "{} points, {} runs merged, {} missing",
        summary.points,
        summary.runs_merged,
        summary.runs_missing
    );
    if summary.runs_missing > 0 {
        return Err(incomplete(&summary, dir));
    }
    Ok(())
}
