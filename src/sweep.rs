//! Sweeps: a base scene, axes over scene keys and realizations, run in parallel, sharded
//! across machines, merged into ensemble statistics (feature `serde`; the file format:
//! `docs/sweep-format.md`; the program: `precursors sweep`, `precursors merge`).
//!
//! ```
//! use precursors::sweep::{Sweep, SweepOptions};
//!
//! let sweep = Sweep::from_json_str(r#"{
//!     "base": { "block": { "lx": 0.02, "ly": 0.004, "lz": 0.02 },
//!               "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
//!               "normal_load": 300.0 },
//!     "axes": [ { "key": "normal_load", "values": [300.0, 400.0] } ],
//!     "realizations": 2,
//!     "seed": 7
//! }"#)?;
//! assert_eq!(sweep.runs().len(), 4);                 // 2 points x 2 realizations
//! assert_eq!(sweep.shard(1, 2)?.len(), 2);           // runs 1 and 3
//! # let out = std::env::temp_dir().join(format!("precursors-doc-sweep-{}", std::process::id()));
//! let summary = sweep.execute(&out, &SweepOptions::new().with_jobs(2)?, |_| {})?;
//! assert_eq!(summary.completed, 4);
//! let merged = precursors::sweep::merge(&out)?;
//! assert_eq!(merged.runs_missing, 0);
//! # std::fs::remove_dir_all(&out).ok();
//! # Ok::<(), precursors::sweep::SweepError>(())
//! ```

mod error;
mod merge;
pub(crate) mod stats;

pub use error::SweepError;
pub(crate) use merge::GRID_LOADS;
#[cfg(feature = "plot")]
pub(crate) use merge::{ensemble_curves, EnsembleCurves, MEDIAN_BAND_RUNS};
pub use merge::{mean_band, merge, Band, MergeSummary};
pub use stats::{statistics, statistics_with_progress, StatsOptions, StatsProgress, StatsSummary};

/// The results of this module: its errors are [`SweepError`]s.
type Result<T, E = SweepError> = std::result::Result<T, E>;

use crate::error::{Chain, Error};
use crate::files::write_atomically;
use crate::lock::{Attempt, DirLock, LOCK_FILE};
use crate::output::RunTables;
use crate::scene::file::{check_shape, read_json_text, scene_shape, SceneFile, Shape};
use crate::scene::schema::KeyError;
use crate::scene::{HeightSource, SceneBuilder};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// The name of a sweep's own copy of its file in the output directory.
pub const SWEEP_FILE: &str = crate::output::layout::SWEEP;
/// The completion marker of a run, written last (atomically) into its directory.
pub(crate) const DONE: &str = crate::output::layout::DONE;
/// The most runs a sweep may have (points times realizations): `1e5` runs are a day of
/// the calibration scene on 64 cores, a run directory of four files each, and a merge
/// that reads them all; a larger study is several sweeps (each its own directory).
pub(crate) const RUN_LIMIT: usize = 100_000;

/// The completion marker of a run (`done`).
#[deprecated(
    since = "1.1.0",
    note = "a directory-layout detail (docs/sweep-format.md gives it); removed in 2.0"
)]
pub const DONE_FILE: &str = DONE;
/// The most runs a sweep may have (1e5; docs/sweep-format.md).
#[deprecated(
    since = "1.1.0",
    note = "a limit the docs give (docs/sweep-format.md); removed in 2.0"
)]
pub const MAX_RUNS: usize = RUN_LIMIT;
/// The loads `F/(μF_N)` of `merge`'s `curves.csv`: 0.05, 0.10, ..., 0.95.
#[deprecated(
    since = "1.1.0",
    note = "a file-format detail (docs/sweep-format.md gives the grid); removed in 2.0"
)]
pub const LOAD_GRID: [f64; 19] = GRID_LOADS;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SweepSpec {
    #[serde(default = "empty_object")]
    base: Value,
    #[serde(default)]
    axes: Vec<AxisSpec>,
    #[serde(default = "one")]
    realizations: usize,
    #[serde(default)]
    seed: u64,
    /// Drawn maps whose seed each realization derives too (`docs/sweep-format.md`); not
    /// written when empty, so the copy of an older sweep is unchanged.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    reseed_maps: Vec<String>,
}

/// The maps a sweep may reseed, in the order their seeds are derived.
const MAP_KEYS: [&str; 3] = ["friction_coefficient", "c_x", "c_z"];

fn empty_object() -> Value {
    Value::Object(serde_json::Map::new())
}

fn one() -> usize {
    1
}

/// An axis as written: one `key` and its values, or linked `keys` (several scene keys that
/// change together) and one array of values per step. `None` fields are not written, so
/// the copy of a sweep with plain axes ([`SWEEP_FILE`]) is as before linked axes existed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct AxisSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    key: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    keys: Option<Vec<String>>,
    values: Vec<Value>,
}

/// An axis read: its keys (one for a plain axis) and, per step, one value per key.
#[derive(Debug, Clone, PartialEq)]
struct Axis {
    keys: Vec<String>,
    steps: Vec<Vec<Value>>,
}

impl Axis {
    /// The keys joined, as errors name an axis.
    fn name(&self) -> String {
        self.keys.join(", ")
    }
}

/// The objects of a sweep file: the top level, `base` (a scene: [`scene_shape`]) and each
/// axis (serde would take an array for each, by position).
fn sweep_shape(path: &str) -> Shape {
    match path {
        "" | "base" | "axes.#" => Shape::Object,
        "axes" => Shape::Objects,
        _ => match path.strip_prefix("base.") {
            Some(key) => scene_shape(key),
            None => Shape::Any,
        },
    }
}

/// The axes of `spec` in one shape: a linked axis's values must be arrays of one value
/// per key.
fn read_axes(spec: &SweepSpec, file_error: impl Fn(String) -> SweepError) -> Result<Vec<Axis>> {
    let mut axes = Vec::with_capacity(spec.axes.len());
    for (a, axis) in spec.axes.iter().enumerate() {
        let read = match (&axis.key, &axis.keys) {
            (Some(key), None) => Axis {
                keys: vec![key.clone()],
                steps: axis.values.iter().map(|v| vec![v.clone()]).collect(),
            },
            (None, Some(keys)) if !keys.is_empty() => {
                let name = keys.join(", ");
                let mut steps = Vec::with_capacity(axis.values.len());
                for (i, value) in axis.values.iter().enumerate() {
                    match value.as_array() {
                        Some(tuple) if tuple.len() == keys.len() => steps.push(tuple.clone()),
                        _ => {
                            return Err(key_error(
                                &name,
                                format!(
                                    "value {value} (#{i}) is not an array of {} values, one \
                                     per key",
                                    keys.len()
                                ),
                            ))
                        }
                    }
                }
                Axis {
                    keys: keys.clone(),
                    steps,
                }
            }
            (None, Some(_)) => return Err(file_error(format!("axis #{a}: `keys` is empty"))),
            _ => {
                return Err(file_error(format!(
                    "axis #{a}: give either `key` (one scene key) or `keys` (linked keys)"
                )))
            }
        };
        axes.push(read);
    }
    Ok(axes)
}

/// One run of a sweep: a parameter point, a realization, its seed and its scene.
///
/// Read-only: [`Sweep::run_one`] runs the scene in the directory `dir_name` under the
/// sweep's output directory, and the seed, the values and the directory name belong to
/// the scene (a run is taken from [`Sweep::runs`] or [`Sweep::shard`]).
///
/// ```
/// use precursors::sweep::{derive_seed, Sweep};
/// // Two normal loads F_N (N) on a 10 x 4 grid of 1 mm cells, two realizations each.
/// let sweep = Sweep::from_json_str(r#"{
///     "base": { "block": { "lx": 0.01, "ly": 0.004, "lz": 0.01 },
///               "cells": { "kind": "count", "nx": 10, "ny": 4 } },
///     "axes": [ { "key": "normal_load", "values": [40.0, 60.0] } ],
///     "realizations": 2,
///     "seed": 7
/// }"#)?;
/// let run = &sweep.runs()[3];                  // the second load's second realization
/// assert_eq!((run.point(), run.realization()), (1, 1));
/// assert_eq!(run.index(), run.point() * sweep.realizations() + run.realization());
/// assert_eq!(run.coordinates(), [1]);
/// assert_eq!(run.values(), [("normal_load".to_string(), "60.0".to_string())]);
/// assert_eq!(run.seed(), derive_seed(7, run.coordinates(), run.realization()));
/// assert_eq!(run.dir_name(), "p0001-r0001");
/// assert_eq!(run.scene().clone().build()?.normal_load(), 60.0); // F_N (N)
/// # Ok::<(), precursors::sweep::SweepError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct SweepRun {
    /// Position in the sweep's run order (points in axis order, the last axis fastest;
    /// realizations innermost): `point · realizations + realization`.
    index: usize,
    /// The parameter point (row-major over the axes).
    point: usize,
    /// The index of the value on each axis.
    coordinates: Vec<usize>,
    /// The realization (`0 .. realizations`).
    realization: usize,
    /// The heights' seed ([`derive_seed`]).
    seed: u64,
    /// Each key and its value, the value as JSON text (`"0.02"`, `"{\"kind\":\"side\"}"`),
    /// in the order of [`Sweep::keys`] (a linked axis gives one pair per key).
    values: Vec<(String, String)>,
    /// The run's scene.
    scene: SceneBuilder,
    /// The run's directory under the sweep's output directory: `p{point:04}-r{realization:04}`.
    dir_name: String,
}

impl SweepRun {
    /// Position in the sweep's run order (points in axis order, the last axis fastest;
    /// realizations innermost): `point · realizations + realization`.
    pub fn index(&self) -> usize {
        self.index
    }

    /// The parameter point (row-major over the axes).
    pub fn point(&self) -> usize {
        self.point
    }

    /// The index of the value on each axis.
    pub fn coordinates(&self) -> &[usize] {
        &self.coordinates
    }

    /// The realization (`0 .. realizations`).
    pub fn realization(&self) -> usize {
        self.realization
    }

    /// The heights' seed ([`derive_seed`]).
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Each key and its value, the value as JSON text (`"0.02"`, `"{\"kind\":\"side\"}"`),
    /// in the order of [`Sweep::keys`] (a linked axis gives one pair per key).
    pub fn values(&self) -> &[(String, String)] {
        &self.values
    }

    /// The run's scene.
    pub fn scene(&self) -> &SceneBuilder {
        &self.scene
    }

    /// The run's directory under the sweep's output directory:
    /// `p{point:04}-r{realization:04}`.
    pub fn dir_name(&self) -> &str {
        &self.dir_name
    }
}

/// A sweep, validated: every run's scene passed the checks [`SceneBuilder::build`] makes
/// before planning.
///
/// A sweep over two normal loads `F_N` (N) of a 10 x 4 grid of 1 mm cells, run into a
/// directory and merged into ensemble tables:
///
/// ```
/// use precursors::sweep::{merge, Sweep, SweepOptions};
/// let sweep = Sweep::from_json_str(r#"{
///     "base": { "block": { "lx": 0.01, "ly": 0.004, "lz": 0.01 },
///               "cells": { "kind": "count", "nx": 10, "ny": 4 },
///               "normal_load": 40.0 },
///     "axes": [ { "key": "normal_load", "values": [40.0, 60.0] } ],
///     "seed": 7
/// }"#)?;
/// assert_eq!((sweep.points(), sweep.realizations()), (2, 1));
/// assert_eq!(sweep.keys(), ["normal_load"]);
/// // Its JSON form (the directory's copy, sweep.json) reads back as the same sweep.
/// assert_eq!(Sweep::from_json_str(&sweep.to_json()?)?.runs(), sweep.runs());
/// let out = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// let summary = sweep.execute(&out, &SweepOptions::new(), |run| {
///     println!("run {} done: {} events in {:.3} s", run.index, run.events, run.seconds)
/// })?;
/// assert_eq!(summary.completed, 2);
/// let merged = merge(&out)?;
/// assert_eq!((merged.points, merged.runs_merged), (2, 2));
/// std::fs::remove_dir_all(&out).ok();
/// # Ok::<(), precursors::sweep::SweepError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Sweep {
    spec: SweepSpec,
    axes: Vec<Axis>,
    points: usize,
    runs: Vec<SweepRun>,
    /// One plan per geometry for all the runs (the jobs share it; a plan is read-only).
    planner: crate::green::Planner,
}

/// How [`Sweep::execute`] runs its share.
///
/// Two shares of a sweep run one after the other (or on two machines) into one directory:
///
/// ```
/// use precursors::sweep::{merge, Sweep, SweepOptions};
/// use precursors::Error;
/// let options = SweepOptions::new();
/// assert_eq!((options.jobs(), options.shard()), (1, (0, 1)));     // one job, everything
/// assert!(matches!(options.with_jobs(0), Err(Error::InvalidCount { .. })));
/// assert!(matches!(options.with_shard(2, 2), Err(Error::InvalidCount { .. })));
/// let sweep = Sweep::from_json_str(r#"{
///     "base": { "block": { "lx": 0.01, "ly": 0.004, "lz": 0.01 },
///               "cells": { "kind": "count", "nx": 10, "ny": 4 },
///               "normal_load": 40.0 },
///     "axes": [ { "key": "normal_load", "values": [40.0, 60.0] } ],
///     "seed": 7
/// }"#)?;
/// let out = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// for k in 0..2 {
///     let share = SweepOptions::new().with_jobs(2)?.with_shard(k, 2)?;
///     assert_eq!(sweep.execute(&out, &share, |_| {})?.runs, 1);  // run k of 2
/// }
/// assert_eq!(merge(&out)?.runs_merged, 2);
/// std::fs::remove_dir_all(&out).ok();
/// # Ok::<(), precursors::sweep::SweepError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct SweepOptions {
    jobs: usize,
    shard: (usize, usize),
}

impl Default for SweepOptions {
    fn default() -> Self {
        Self {
            jobs: 1,
            shard: (0, 1),
        }
    }
}

impl SweepOptions {
    /// One job, the whole sweep.
    pub fn new() -> Self {
        Self::default()
    }

    /// Runs at the same time (`≥ 1`; each on its scene's solver threads, one by default).
    pub fn jobs(&self) -> usize {
        self.jobs
    }

    /// This share `(k, n)`: runs `k, k + n, k + 2n, ...` ([`Sweep::shard`]); `(0, 1)`: the
    /// whole sweep.
    pub fn shard(&self) -> (usize, usize) {
        self.shard
    }

    /// The same options with `jobs` runs at the same time (`≥ 1`).
    ///
    /// # Errors
    /// [`Error::InvalidCount`] for 0.
    pub fn with_jobs(self, jobs: usize) -> crate::error::Result<Self> {
        if jobs == 0 {
            return Err(Error::InvalidCount {
                name: "jobs",
                value: 0,
                reason: "a sweep runs at least one job at a time",
            });
        }
        Ok(Self { jobs, ..self })
    }

    /// The same options with share `k` of `n` (`n ≥ 1`, `k < n`).
    ///
    /// # Errors
    /// [`Error::InvalidCount`] for `n = 0` or `k >= n`.
    pub fn with_shard(self, k: usize, n: usize) -> crate::error::Result<Self> {
        check_shard(k, n)?;
        Ok(Self {
            shard: (k, n),
            ..self
        })
    }
}

/// A share `k` of `n`: `n ≥ 1`, `k < n`.
fn check_shard(k: usize, n: usize) -> crate::error::Result<()> {
    if n == 0 {
        return Err(Error::InvalidCount {
            name: "shard count",
            value: 0,
            reason: "a sweep is shared among at least one shard",
        });
    }
    if k >= n {
        return Err(Error::InvalidCount {
            name: "shard index",
            value: k as u64,
            reason: "the shard index must be below the shard count (shards 0 .. n-1)",
        });
    }
    Ok(())
}

/// What one run did ([`Sweep::run_one`]).
///
/// ```
/// use precursors::sweep::Sweep;
/// let sweep = Sweep::from_json_str(r#"{
///     "base": { "block": { "lx": 0.01, "ly": 0.004, "lz": 0.01 },
///               "cells": { "kind": "count", "nx": 10, "ny": 4 },
///               "normal_load": 40.0 },
///     "axes": [ { "key": "normal_load", "values": [40.0, 60.0] } ],
///     "seed": 7
/// }"#)?;
/// let out = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// let run = &sweep.runs()[1];                                    // F_N = 60 N
/// let report = sweep.run_one(run, &out)?;
/// assert!(!report.skipped && !report.held_elsewhere && report.events > 0);
/// assert!(out.join(run.dir_name()).join("done").is_file());   // marked complete
/// // A complete run is not run again.
/// let again = sweep.run_one(run, &out)?;
/// assert!(again.skipped && again.events == 0 && again.index == 1);
/// std::fs::remove_dir_all(&out).ok();
/// # Ok::<(), precursors::sweep::SweepError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct RunReport {
    /// [`SweepRun::index`].
    pub index: usize,
    /// It was complete already (its marker found) and was not run again.
    pub skipped: bool,
    /// Another process holds its directory (it is running it): left to that process,
    /// neither run nor marked complete here.
    pub held_elsewhere: bool,
    /// It was stopped before global slip ([`Sweep::execute_until`]): left without its
    /// marker, redone from the start by a later execution.
    pub stopped: bool,
    /// Events of the run (0 when skipped or held elsewhere).
    pub events: usize,
    /// Wall time of the run (s; 0 when skipped).
    pub seconds: f64,
}

/// What [`Sweep::execute`] did.
///
/// ```
/// use precursors::sweep::{Sweep, SweepOptions};
/// let sweep = Sweep::from_json_str(r#"{
///     "base": { "block": { "lx": 0.01, "ly": 0.004, "lz": 0.01 },
///               "cells": { "kind": "count", "nx": 10, "ny": 4 },
///               "normal_load": 40.0 },
///     "axes": [ { "key": "normal_load", "values": [40.0, 60.0] } ],
///     "seed": 7
/// }"#)?;
/// let out = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// let first = sweep.execute(&out, &SweepOptions::new(), |_| {})?;
/// assert_eq!((first.runs, first.completed, first.skipped), (2, 2, 0));
/// // Executed again (say after a crash), complete runs are skipped.
/// let second = sweep.execute(&out, &SweepOptions::new(), |_| {})?;
/// assert_eq!((second.completed, second.skipped, second.held_elsewhere), (0, 2, 0));
/// assert!(second.seconds >= 0.0);                                 // wall time (s)
/// std::fs::remove_dir_all(&out).ok();
/// # Ok::<(), precursors::sweep::SweepError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SweepSummary {
    /// Runs in this share.
    pub runs: usize,
    /// Runs of the share run now.
    pub completed: usize,
    /// Runs of the share found complete and skipped.
    pub skipped: usize,
    /// Runs of the share that another process was running (their directories locked):
    /// left to it, not complete as far as this call knows.
    pub held_elsewhere: usize,
    /// Runs of the share stopped before global slip ([`Sweep::execute_until`]); the runs
    /// not counted anywhere were not started.
    pub stopped: usize,
    /// Wall time (s).
    pub seconds: f64,
}

/// The seed of a run, from the sweep's `seed` and the run's coordinates: with
/// SplitMix64's finaliser `mix`, `s = seed`, then `s = mix(s ^ mix(c))` for each axis
/// coordinate `c` (the value's index on the axis) in axis order and then for the
/// realization. Stable across versions (a test pins its values): a sweep re-run later,
/// or extended by realizations, draws the same heights for the same runs.
///
/// ```
/// use precursors::sweep::derive_seed;
/// let a = derive_seed(7, &[1, 0], 0);
/// assert_eq!(a, derive_seed(7, &[1, 0], 0));                 // the same run, the same seed
/// assert_ne!(a, derive_seed(7, &[1, 0], 1));                 // another realization
/// assert_ne!(a, derive_seed(7, &[0, 1], 0));                 // another point
/// assert_ne!(a, derive_seed(8, &[1, 0], 0));                 // another sweep seed
/// ```
pub fn derive_seed(seed: u64, coordinates: &[usize], realization: usize) -> u64 {
    let mut s = seed;
    for &c in coordinates.iter().chain(std::iter::once(&realization)) {
        s = splitmix64(s ^ splitmix64(c as u64));
    }
    s
}

fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn sweep_json_error(path: Option<&Path>, e: serde_json::Error) -> SweepError {
    SweepError::File {
        path: path.map(Path::to_path_buf),
        line: e.line(),
        column: e.column(),
        source: Box::new(e),
    }
}

fn key_error(key: &str, reason: impl Into<String>) -> SweepError {
    SweepError::Axis {
        key: key.to_string(),
        reason: reason.into(),
    }
}

/// Sets the scene key `key` to `value` in `scene` (typed, through the scene's schema): a
/// key that is not the scene's is [`SweepError::Axis`] naming `key`; a value the key does
/// not take is `invalid`'s error, given the reason.
fn set_key(
    scene: &mut SceneFile,
    key: &str,
    value: &Value,
    invalid: impl FnOnce(String) -> SweepError,
) -> Result<()> {
    match scene.set(key, value) {
        Ok(()) => Ok(()),
        Err(e @ KeyError::Value(_)) => Err(invalid(e.to_string())),
        Err(e) => Err(key_error(key, e.to_string())),
    }
}

/// An error and its causes as one text, for a reason that keeps it (its `Display` leaves
/// the causes out).
fn chain(e: &(dyn std::error::Error + 'static)) -> String {
    Chain(e).to_string()
}

/// The error of a sweep file at `path` (`None`: text given directly) without a position.
fn file_error(path: Option<&Path>, reason: String) -> SweepError {
    SweepError::File {
        path: path.map(Path::to_path_buf),
        line: 0,
        column: 0,
        source: reason.into(),
    }
}

impl Sweep {
    /// Reads a sweep from JSON text (`docs/sweep-format.md`). A heights file of the base
    /// scene is read relative to the current directory.
    ///
    /// # Errors
    /// [`SweepError::File`] for invalid JSON or a key outside the format, an axis without
    /// exactly one of `key` and `keys`, or a base scene that is not a scene file;
    /// [`SweepError::Axis`] (naming the key, or a linked axis's keys) for an axis whose key
    /// is not a scene key or whose value gives no valid scene; [`Error::InvalidCount`] (in
    /// [`SweepError::Core`]) for
    /// zero realizations, or several with heights that are not random.
    pub fn from_json_str(text: &str) -> Result<Sweep> {
        check_shape(text, &sweep_shape).map_err(|e| sweep_json_error(None, e))?;
        let spec: SweepSpec = serde_json::from_str(text).map_err(|e| sweep_json_error(None, e))?;
        Self::from_spec(spec, None, Path::new("."))
    }

    /// Reads a sweep file (`docs/sweep-format.md`). A heights file of the base scene is
    /// read relative to the sweep file's directory.
    ///
    /// # Errors
    /// [`Error::Io`] (in [`SweepError::Core`]) when the file cannot be read; the others as [`Sweep::from_json_str`].
    pub fn from_json_file(path: impl AsRef<Path>) -> Result<Sweep> {
        let path = path.as_ref();
        let text = read_json_text(path, "reading sweep file", |line, column, reason| {
            SweepError::File {
                path: Some(path.to_path_buf()),
                line,
                column,
                source: reason.into(),
            }
        })?;
        check_shape(&text, &sweep_shape).map_err(|e| sweep_json_error(Some(path), e))?;
        let spec: SweepSpec =
            serde_json::from_str(&text).map_err(|e| sweep_json_error(Some(path), e))?;
        Self::from_spec(spec, Some(path), path.parent().unwrap_or(Path::new(".")))
    }

    /// The sweep of a read file: its base scene with every key, its counts and size
    /// checked, each axis's steps checked alone on the base scene, then every run's scene.
    fn from_spec(mut spec: SweepSpec, path: Option<&Path>, base_dir: &Path) -> Result<Sweep> {
        let base_error = |reason: String| file_error(path, format!("base scene: {reason}"));
        let base =
            SceneFile::from_value(&spec.base, base_dir).map_err(|e| base_error(chain(&e)))?;
        spec.base = base.to_value().map_err(|e| base_error(chain(&e)))?;
        let base_builder = base.to_builder().map_err(|e| base_error(chain(&e)))?;
        let random = check_realizations(spec.realizations, &base_builder, &spec.reseed_maps)?;
        let axes = read_axes(&spec, |reason| file_error(path, reason))?;
        check_size(&axes, spec.realizations, &base_builder)?;
        check_axes(&axes, &base)?;
        check_reseed_maps(&spec, &axes, |reason| file_error(path, reason))?;
        let points = axes.iter().map(|a| a.steps.len()).product::<usize>();
        let runs = runs_of(&spec, &axes, &base, random)?;
        Ok(Sweep {
            spec,
            axes,
            points,
            runs,
            planner: crate::green::Planner::new(),
        })
    }

    /// The sweep as JSON, its base scene with every key (heights files as values): the
    /// copy [`Sweep::execute`] keeps in the output directory ([`SWEEP_FILE`]).
    ///
    /// # Errors
    /// [`SweepError::File`] if serialisation fails (it does not for a read sweep).
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(&self.spec).map_err(|e| sweep_json_error(None, e))
    }

    /// Every run, in run order.
    pub fn runs(&self) -> &[SweepRun] {
        &self.runs
    }

    /// Number of parameter points (the product of the axes' lengths; 1 without axes).
    pub fn points(&self) -> usize {
        self.points
    }

    /// Realizations per point.
    pub fn realizations(&self) -> usize {
        self.spec.realizations
    }

    /// The axes' keys, in order (a linked axis's keys in their order): the value columns
    /// of [`SweepRun::values`] and of the merged tables.
    pub fn keys(&self) -> Vec<&str> {
        self.axes
            .iter()
            .flat_map(|a| a.keys.iter().map(String::as_str))
            .collect()
    }

    /// Share `k` of `n` (`0 <= k < n`): the runs whose index is `k` modulo `n`. The shares
    /// of `0..n` are disjoint and cover the sweep.
    ///
    /// # Errors
    /// [`Error::InvalidCount`] (in [`SweepError::Core`]) for `n = 0` or `k >= n`.
    pub fn shard(&self, k: usize, n: usize) -> Result<Vec<&SweepRun>> {
        check_shard(k, n)?;
        Ok(self.runs.iter().filter(|r| r.index % n == k).collect())
    }

    /// Runs `run` into `out/run.dir_name` unless it is complete (its `done`
    /// exists) or another process holds the directory's lock (it is running it). The
    /// directory is locked (an advisory lock of the operating system, which ends with the
    /// process) and emptied, then `events.csv`, `curve.csv` and `contact_map.csv` are
    /// written ([`crate::output`]: as `NAME.partial` until global slip), then `meta.json`
    /// (the scene, the crate version, the run's coordinates and seed, its counts and
    /// timings), then the marker, both atomically. A run cut before its marker is redone
    /// from the start.
    ///
    /// # Errors
    /// [`Error::Io`] (in [`SweepError::Core`], as every core error) for a file or directory
    /// that cannot be written; the scene's and the
    /// driver's errors.
    pub fn run_one(&self, run: &SweepRun, out: &Path) -> Result<RunReport> {
        self.run_one_until(run, out, &AtomicBool::new(false))
    }

    /// [`Sweep::run_one`], stopped at the next event once `stop` is raised: the run is
    /// then left without its marker (redone from the start by a later call), and its
    /// report says so ([`RunReport::stopped`]).
    fn run_one_until(&self, run: &SweepRun, out: &Path, stop: &AtomicBool) -> Result<RunReport> {
        let dir = out.join(&run.dir_name);
        let report = |skipped, held_elsewhere| RunReport {
            index: run.index,
            skipped,
            held_elsewhere,
            stopped: false,
            events: 0,
            seconds: 0.0,
        };
        if crate::files::is_file(&dir.join(DONE), "examining the run directory")? {
            return Ok(report(true, false));
        }
        std::fs::create_dir_all(&dir)
            .map_err(|e| Error::io("creating the run directory", &dir, e))?;
        let _lock = match DirLock::try_lock(&dir)? {
            Attempt::Locked(lock) => lock,
            Attempt::Held(_) => return Ok(report(false, true)),
        };
        // Complete by a process that held the lock since the first look.
        if crate::files::is_file(&dir.join(DONE), "examining the run directory")? {
            return Ok(report(true, false));
        }
        empty_but_lock(&dir)?;
        let started = Instant::now();
        let scene = run.scene.clone().build_with_planner(&self.planner)?;
        let built = started.elapsed().as_secs_f64();
        let mut driver = scene.driver()?;
        let mut tables = RunTables::start(&dir, &driver, driver.scene().run_options(), None)?;
        let (mut slip, mut ruptures, mut stable_states) = (None, 0usize, 0usize);
        let stopped = tables.run_until(&mut driver, None, |event, _| {
            match event {
                crate::driver::Event::GlobalSlip { load } => slip = Some(load.force),
                crate::driver::Event::Rupture { .. } => ruptures += 1,
                crate::driver::Event::Stable { .. } => stable_states += 1,
                _ => {}
            }
            match stop.load(Ordering::SeqCst) {
                true => std::ops::ControlFlow::Break(()),
                false => std::ops::ControlFlow::Continue(()),
            }
        })?;
        if stopped.is_some() {
            return Ok(RunReport {
                stopped: true,
                events: driver.event_count(),
                seconds: started.elapsed().as_secs_f64(),
                ..report(false, false)
            });
        }
        tables.finish()?;
        let seconds = started.elapsed().as_secs_f64();
        let mu_fn = driver.friction_limit();
        let meta = serde_json::json!({
            "crate_version": env!("CARGO_PKG_VERSION"),
            "run": run.index,
            "point": run.point,
            "coordinates": run.coordinates,
            "realization": run.realization,
            "seed": run.seed,
            "values": run.values.iter().map(|(k, v)| {
                (k.clone(), serde_json::from_str::<Value>(v).unwrap_or(Value::Null))
            }).collect::<serde_json::Map<String, Value>>(),
            "events": driver.event_count(),
            "stable_states": stable_states,
            "ruptures": ruptures,
            "mu_FN_N": mu_fn,
            "slip_force_N": slip,
            "slip_over_mu_FN": slip.map(|f| f / mu_fn),
            "backend": driver.backend().to_string(),
            "contact_rule": driver.scene().contact_rule().name(),
            "seconds": { "build": built, "total": seconds },
            "scene": &run.scene,
        });
        let text = serde_json::to_string_pretty(&meta).map_err(|e| SweepError::File {
            path: None,
            line: 0,
            column: 0,
            source: Box::new(e),
        })?;
        write_atomically(
            &dir.join(crate::output::layout::META),
            text.as_bytes(),
            "writing",
        )?;
        write_atomically(&dir.join(DONE), b"complete\n", "writing")?;
        Ok(RunReport {
            events: driver.event_count(),
            seconds,
            ..report(false, false)
        })
    }

    /// Runs share `options.shard` of the sweep into `out` on `options.jobs` threads,
    /// skipping complete runs and leaving runs that another process is running to it
    /// ([`Sweep::run_one`]), so two processes on one directory share its runs; `progress`
    /// is called after each run (from the thread that ran it). `out` keeps a copy of the
    /// sweep ([`SWEEP_FILE`], checked or written under the directory's lock); a directory
    /// holding another sweep is refused. The tables do not depend on the jobs, the shards
    /// or the processes.
    ///
    /// On a failed run no new run starts; the runs under way finish and the first error
    /// (in run order) is returned.
    ///
    /// # Errors
    /// [`SweepError::Directory`] for a directory of another sweep; [`Error::InvalidCount`]
    /// for a bad shard, [`Error::Io`] (both in [`SweepError::Core`]); the first run's error.
    pub fn execute(
        &self,
        out: &Path,
        options: &SweepOptions,
        progress: impl Fn(&RunReport) + Sync,
    ) -> Result<SweepSummary> {
        self.execute_until(out, options, progress, &AtomicBool::new(false))
    }

    /// [`Sweep::execute`], stopped once `stop` is raised (by another thread: a signal
    /// handler, a user interface): no new run starts, and the runs under way stop at
    /// their next event, left without their marker, so that only complete runs are
    /// marked done. Executed again, the sweep redoes the stopped runs from the start and
    /// ends with the tables of an uninterrupted execution. [`SweepSummary::stopped`]
    /// counts the runs stopped.
    ///
    /// ```
    /// use precursors::sweep::{Sweep, SweepOptions};
    /// use std::sync::atomic::AtomicBool;
    /// let sweep = Sweep::from_json_str(r#"{
    ///     "base": {"block": {"lx": 0.012, "ly": 0.002, "lz": 0.01}, "normal_load": 50.0},
    ///     "axes": [{"key": "normal_load", "values": [50.0, 60.0]}]
    /// }"#)?;
    /// let out = std::env::temp_dir().join(format!("precursors-doc-stop-{}", std::process::id()));
    /// // Raised before it starts: nothing runs, nothing is marked done.
    /// let summary = sweep.execute_until(&out, &SweepOptions::new(), |_| {}, &AtomicBool::new(true))?;
    /// assert_eq!((summary.completed, summary.runs), (0, 2));
    /// let summary = sweep.execute(&out, &SweepOptions::new(), |_| {})?;
    /// assert_eq!(summary.completed, 2);
    /// std::fs::remove_dir_all(&out).ok();
    /// # Ok::<(), precursors::sweep::SweepError>(())
    /// ```
    ///
    /// # Errors
    /// As [`Sweep::execute`].
    pub fn execute_until(
        &self,
        out: &Path,
        options: &SweepOptions,
        progress: impl Fn(&RunReport) + Sync,
        stop: &AtomicBool,
    ) -> Result<SweepSummary> {
        let started = Instant::now();
        let (k, n) = options.shard;
        let share = self.shard(k, n)?;
        self.prepare(out)?;
        let next = AtomicUsize::new(0);
        let failed = AtomicBool::new(false);
        let reports: Mutex<Vec<RunReport>> = Mutex::new(Vec::new());
        let errors: Mutex<Vec<(usize, SweepError)>> = Mutex::new(Vec::new());
        let jobs = options.jobs.clamp(1, share.len().max(1));
        std::thread::scope(|scope| {
            for _ in 0..jobs {
                scope.spawn(|| loop {
                    if failed.load(Ordering::SeqCst) || stop.load(Ordering::SeqCst) {
                        break;
                    }
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(run) = share.get(i) else { break };
                    match self.run_one_until(run, out, stop) {
                        Ok(report) => {
                            progress(&report);
                            if let Ok(mut r) = reports.lock() {
                                r.push(report);
                            }
                        }
                        Err(e) => {
                            failed.store(true, Ordering::SeqCst);
                            if let Ok(mut errs) = errors.lock() {
                                errs.push((run.index, e));
                            }
                        }
                    }
                });
            }
        });
        let mut errors = crate::lock::into_inner(errors);
        errors.sort_by_key(|(i, _)| *i);
        if let Some((_, e)) = errors.into_iter().next() {
            return Err(e);
        }
        let reports = crate::lock::into_inner(reports);
        let skipped = reports.iter().filter(|r| r.skipped).count();
        let held_elsewhere = reports.iter().filter(|r| r.held_elsewhere).count();
        let stopped = reports.iter().filter(|r| r.stopped).count();
        Ok(SweepSummary {
            runs: share.len(),
            completed: reports.len() - skipped - held_elsewhere - stopped,
            skipped,
            held_elsewhere,
            stopped,
            seconds: started.elapsed().as_secs_f64(),
        })
    }

    /// Creates `out` and writes (or checks) its copy of the sweep, under the directory's
    /// lock: of two processes starting on a new directory, the second sees the first's
    /// copy.
    fn prepare(&self, out: &Path) -> Result<()> {
        std::fs::create_dir_all(out)
            .map_err(|e| Error::io("creating the sweep directory", out, e))?;
        // Held for a file's read or write; longer only by a process misusing the directory.
        let _lock = DirLock::lock_waiting(out, std::time::Duration::from_secs(30))?;
        let path = out.join(SWEEP_FILE);
        let text = self.to_json()?;
        let existing = crate::files::read_text_if_exists(&path, "reading")?;
        if existing.is_none() {
            if let Some(name) = crate::output::layout::holds_a_run(out)? {
                return Err(SweepError::Directory {
                    path: out.to_path_buf(),
                    reason: format!(
                        "the directory holds a run's files ({name}), not a sweep's: a \
                         sweep's figures and merged tables would mix with the run's; choose \
                         another output directory"
                    ),
                });
            }
        }
        match existing {
            Some(old) if old == text => Ok(()),
            Some(_) => Err(SweepError::Directory {
                path,
                reason: "the directory holds another sweep (its sweep.json differs): \
                         choose another output directory"
                    .into(),
            }),
            None => Ok(write_atomically(&path, text.as_bytes(), "writing")?),
        }
    }
}

/// Removes everything in `dir` but its lock file (whose lock this process holds); a
/// symbolic link or a special file there is refused and stays.
fn empty_but_lock(dir: &Path) -> Result<()> {
    let entries =
        std::fs::read_dir(dir).map_err(|e| Error::io("emptying the cut run directory", dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| Error::io("emptying the cut run directory", dir, e))?;
        if entry.file_name() == LOCK_FILE {
            continue;
        }
        let path = entry.path();
        match entry.file_type() {
            Ok(t) if t.is_dir() => std::fs::remove_dir_all(&path)
                .map_err(|e| Error::io("removing from the cut run directory", &path, e))?,
            // A link is no file of a run: refused, as everywhere in a run directory.
            _ => crate::files::remove_if_exists(&path, "removing from the cut run directory")?,
        }
    }
    Ok(())
}

/// Whether the base scene's heights are random (realizations differ by their seed).
///
/// # Errors
/// [`Error::InvalidCount`] for zero realizations, or several with heights that are not
/// random and no map reseeded.
fn check_realizations(
    realizations: usize,
    base: &SceneBuilder,
    reseed_maps: &[String],
) -> Result<bool> {
    if realizations == 0 {
        return Err(Error::InvalidCount {
            name: "realizations",
            value: 0,
            reason: "a sweep needs at least one realization per point",
        }
        .into());
    }
    let random = base.current_heights().is_random();
    if realizations > 1 && !random && reseed_maps.is_empty() {
        return Err(Error::InvalidCount {
            name: "realizations",
            value: realizations as u64,
            reason: "realizations differ by the seed of random heights (or of the maps in \
                     `reseed_maps`), but the base scene's heights are values (give one \
                     realization)",
        }
        .into());
    }
    Ok(random)
}

/// `reseed_maps` names each of `MAP_KEYS` at most once, each a map of the base scene drawn
/// from a seed (`gaussian_surface`, `self_affine_surface`), whose seed no axis sets.
///
/// # Errors
/// [`SweepError::File`] naming the map and why.
fn check_reseed_maps(
    spec: &SweepSpec,
    axes: &[Axis],
    file_error: impl Fn(String) -> SweepError,
) -> Result<()> {
    for (i, name) in spec.reseed_maps.iter().enumerate() {
        let refuse = |reason: String| Err(file_error(format!("reseed_maps: `{name}` {reason}")));
        if !MAP_KEYS.contains(&name.as_str()) {
            return refuse(format!(
                "is not a map (the maps are {})",
                MAP_KEYS.join(", ")
            ));
        }
        if spec.reseed_maps[..i].contains(name) {
            return refuse("is named twice".to_string());
        }
        let kind = spec.base["maps"][name.as_str()]["kind"].as_str();
        if !matches!(kind, Some("gaussian_surface" | "self_affine_surface")) {
            return refuse(match kind {
                None => format!("is not in the base scene (give `maps.{name}`)"),
                Some(kind) => format!(
                    "is a `{kind}` map: only a map drawn from a seed (`gaussian_surface`, \
                     `self_affine_surface`) can be reseeded"
                ),
            });
        }
        let seed_key = format!("maps.{name}.seed");
        if let Some(key) = axes
            .iter()
            .flat_map(|a| &a.keys)
            .find(|k| overlap(k, &seed_key))
        {
            return refuse(format!(
                "has its seed set by the axis `{key}`: either the axis or the realizations \
                 choose it"
            ));
        }
    }
    Ok(())
}

/// The seed of map `MAP_KEYS[map]` in the run whose heights' seed is `seed`: derived
/// from both, so that it differs from the heights' (a map with the heights' spectrum and
/// seed would be their field) and from the other maps'.
fn map_seed(seed: u64, map: usize) -> u64 {
    splitmix64(seed ^ splitmix64(0x6d61_7073_0000_0000 | map as u64))
}

/// The size of the sweep, before any scene is checked or any run built: at most
/// `1e5` runs, whose list fits in the memory available.
///
/// # Errors
/// [`SweepError::TooLarge`]; [`Error::OutOfMemory`].
fn check_size(axes: &[Axis], realizations: usize, base: &SceneBuilder) -> Result<()> {
    let points = axes
        .iter()
        .try_fold(1u128, |p, a| p.checked_mul(a.steps.len() as u128));
    let runs = points.and_then(|p| p.checked_mul(realizations as u128));
    let runs = match (points, runs) {
        (Some(_), Some(runs)) if runs <= RUN_LIMIT as u128 => runs,
        _ => {
            return Err(SweepError::TooLarge {
                points: axes
                    .iter()
                    .fold(1u128, |p, a| p.saturating_mul(a.steps.len() as u128)),
                realizations,
                runs: points.map_or(u128::MAX, |p| p.saturating_mul(realizations as u128)),
                limit: RUN_LIMIT,
            })
        }
    };
    let values = |v: &[f64]| 8 * v.len();
    let heights = match base.current_heights() {
        HeightSource::Values(v) => values(v),
        _ => 0,
    } + base
        .current_maps()
        .0
        .iter()
        .map(|m| match m {
            Some(crate::scene::SiteMap::Values(v)) => values(v),
            _ => 0,
        })
        .sum::<usize>();
    // Each run holds its scene, heights included, its values as text and its
    // coordinates; twice that while it is built.
    let text: usize = axes
        .iter()
        .map(|a| {
            let longest = a.steps.iter().map(|s| describe_step(s).len()).max();
            a.keys.iter().map(|k| k.len() + 48).sum::<usize>() + longest.unwrap_or(0)
        })
        .sum();
    let per_run = std::mem::size_of::<SweepRun>() + heights + text + 64;
    crate::green::check_memory(
        || format!("the list of the sweep's {runs} runs"),
        2.0 * runs as f64 * per_run as f64,
        "split the sweep into several sweeps, or give the heights as random",
    )?;
    Ok(())
}

/// Whether two dotted keys set a common value: equal, or one an object holding the other
/// (`block` and `block.lx`; not `drive.height` and `drive.height_m`).
fn overlap(a: &str, b: &str) -> bool {
    let holds = |outer: &str, inner: &str| {
        inner
            .strip_prefix(outer)
            .is_some_and(|rest| rest.is_empty() || rest.starts_with('.'))
    };
    holds(a, b) || holds(b, a)
}

/// Each axis on its own: its keys are scene keys, on no other axis and not the heights'
/// seed; it has values; each step gives a valid scene when set on the base scene.
///
/// # Errors
/// [`Error::SweepKey`] naming the key (or the axis's keys).
fn check_axes(axes: &[Axis], base: &SceneFile) -> Result<()> {
    for (a, axis) in axes.iter().enumerate() {
        let name = axis.name();
        for (k, key) in axis.keys.iter().enumerate() {
            let earlier = axes[..a].iter().flat_map(|b| &b.keys);
            if let Some(other) = earlier.chain(&axis.keys[..k]).find(|b| overlap(b, key)) {
                let reason = if other == key {
                    "the key is on two axes, or twice on one".to_string()
                } else {
                    // `block` sets `block.lx` too: the later key would silently win, and
                    // the tables would label points with values that never ran.
                    format!(
                        "the key overlaps `{other}` of an axis (one holds the other): each \
                         scene value may be set by one axis only"
                    )
                };
                return Err(key_error(key, reason));
            }
            if key == "heights" || key.starts_with("heights.seed") {
                return Err(key_error(
                    key,
                    "the sweep derives the heights' seeds from `seed` and the run's \
                     coordinates (give `realizations`); sweep `heights.mean` or \
                     `heights.std_dev` instead",
                ));
            }
        }
        if axis.steps.is_empty() {
            return Err(key_error(&name, "the axis has no values"));
        }
        for (i, step) in axis.steps.iter().enumerate() {
            let value = describe_step(step);
            let invalid = |reason: String| {
                key_error(
                    &name,
                    format!("value {value} (#{i}) is not valid here: {reason}"),
                )
            };
            let mut scene = base.clone();
            for (key, value) in axis.keys.iter().zip(step) {
                set_key(&mut scene, key, value, invalid)?;
            }
            let builder = scene.to_builder().map_err(|e| invalid(chain(&e)))?;
            builder.check().map_err(|e| {
                key_error(
                    &name,
                    format!("value {value} (#{i}) gives an invalid scene: {}", Chain(&e)),
                )
            })?;
        }
    }
    Ok(())
}

/// The index of the value on each axis of the point `point` (row-major: the last axis
/// fastest).
fn coordinates_of(axes: &[Axis], point: usize) -> Vec<usize> {
    let mut coordinates = vec![0; axes.len()];
    let mut rest = point;
    for (a, axis) in axes.iter().enumerate().rev() {
        let n = axis.steps.len();
        coordinates[a] = rest % n;
        rest /= n;
    }
    coordinates
}

/// Every run of the sweep, in run order: the points' scenes (each checked once), their
/// realizations' seeds.
///
/// # Errors
/// [`Error::SweepKey`] naming all the axes' keys for a point whose combination of values
/// is not a valid scene.
fn runs_of(
    spec: &SweepSpec,
    axes: &[Axis],
    base: &SceneFile,
    random: bool,
) -> Result<Vec<SweepRun>> {
    let points = axes.iter().map(|a| a.steps.len()).product::<usize>();
    let mut runs = Vec::with_capacity(points * spec.realizations);
    let keys = || axes.iter().map(Axis::name).collect::<Vec<_>>().join(", ");
    for point in 0..points {
        let coordinates = coordinates_of(axes, point);
        let mut scene = base.clone();
        let mut values = Vec::with_capacity(axes.len());
        let describe = |values: &[(String, String)]| {
            values
                .iter()
                .map(|(k, v)| format!("{k} = {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        for (axis, &c) in axes.iter().zip(&coordinates) {
            for (key, value) in axis.keys.iter().zip(&axis.steps[c]) {
                values.push((key.clone(), value.to_string()));
                set_key(&mut scene, key, value, |reason| {
                    key_error(
                        &keys(),
                        format!("the point {} is not valid: {reason}", describe(&values)),
                    )
                })?;
            }
        }
        for realization in 0..spec.realizations {
            let seed = derive_seed(spec.seed, &coordinates, realization);
            let mut scene = scene.clone();
            let invalid = |reason: String| {
                key_error(
                    &keys(),
                    format!("the point {} is not valid: {reason}", describe(&values)),
                )
            };
            if random {
                set_key(&mut scene, "heights.seed", &Value::from(seed), invalid)?;
            }
            for name in &spec.reseed_maps {
                let map = MAP_KEYS.iter().position(|k| k == name).unwrap_or(0);
                let key = format!("maps.{name}.seed");
                set_key(&mut scene, &key, &Value::from(map_seed(seed, map)), invalid)?;
            }
            let builder = scene.to_builder().map_err(|e| invalid(chain(&e)))?;
            if realization == 0 {
                builder.check().map_err(|e| {
                    key_error(
                        &keys(),
                        format!(
                            "the point {} gives an invalid scene: {}",
                            describe(&values),
                            Chain(&e)
                        ),
                    )
                })?;
            }
            runs.push(SweepRun {
                index: runs.len(),
                point,
                coordinates: coordinates.clone(),
                realization,
                seed,
                values: values.clone(),
                scene: builder,
                dir_name: format!("p{point:04}-r{realization:04}"),
            });
        }
    }
    Ok(runs)
}

/// A step of an axis as errors show it: the value of a plain axis, the array of a linked one.
fn describe_step(step: &[Value]) -> String {
    match step {
        [one] => one.to_string(),
        many => Value::Array(many.to_vec()).to_string(),
    }
}
