//! [`SweepError`]: what a sweep's file, its size and its directory can get wrong, with the
//! core [`enum@Error`] of its runs, scenes, tables and locks nested.

use crate::error::{Bounded, Cause, Error};
use std::path::PathBuf;
use thiserror::Error;

/// Everything that can go wrong in a sweep (feature `serde`): reading a sweep file
/// ([`crate::sweep::Sweep::from_json_file`], [`crate::sweep::Sweep::from_json_str`]),
/// running it ([`crate::sweep::Sweep::execute`], [`crate::sweep::Sweep::run_one`]) and
/// merging its directory ([`crate::sweep::merge`]).
///
/// The failures that are not the sweep's own (a file that cannot be read or written, a
/// directory another process holds, a run's scene refused or its solve failed, a damaged
/// table) are the core [`enum@Error`], nested in [`SweepError::Core`]: `?` turns an [`enum@Error`]
/// into a `SweepError`. `SweepError::Core` is transparent: its `Display` and
/// [`std::error::Error::source`] are the core error's own, so a report of the cause chain
/// prints each cause once; match on the variant to reach the core error.
///
/// ```
/// use precursors::sweep::{Sweep, SweepError};
/// let e = Sweep::from_json_str("{ not json").unwrap_err();
/// assert!(matches!(e, SweepError::File { line: 1, .. }));
/// ```
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SweepError {
    /// A failure of the core library under the sweep: reading or writing a file
    /// ([`Error::Io`]), a directory locked by another process ([`Error::DirectoryLocked`]),
    /// a run's scene or solve ([`Error::InvalidCount`] for zero realizations or a bad
    /// shard, [`Error::SolverNotConverged`], ...), a run's damaged table when merging
    /// ([`Error::CorruptTable`], [`Error::NonFiniteCell`]).
    #[error(transparent)]
    Core(#[from] Error),
    /// A sweep file ([`crate::sweep::Sweep::from_json_file`], or the text given to
    /// [`crate::sweep::Sweep::from_json_str`], or a sweep directory's `sweep.json` read by
    /// [`crate::sweep::merge`]) is not valid JSON, not UTF-8 text, or does not follow
    /// `docs/sweep-format.md` outside its axes (an axis's key or values:
    /// [`SweepError::Axis`]); also its base scene when it is not a scene file.
    #[error(
        "invalid sweep file{}",
        path.as_ref().map(|p| format!(" {}", p.display())).unwrap_or_default()
    )]
    File {
        /// The file (`None` for JSON text given directly).
        path: Option<PathBuf>,
        /// Line of the error (1-based; 0 when the parser gave none).
        line: usize,
        /// Column of the error (1-based; 0 when the parser gave none).
        column: usize,
        /// What the parser reported (or what is wrong); `source()` returns it.
        #[source]
        source: Cause,
    },
    /// An axis of a sweep file ([`crate::sweep::Sweep::from_json_file`],
    /// [`crate::sweep::Sweep::from_json_str`]) names a key that is not a scene key (or the
    /// key twice, or the derived seed), or one of its values does not give a valid scene
    /// (the value's type, or the scene's own check of it).
    #[error("sweep axis `{}`: {}", Bounded(key), Bounded(reason))]
    Axis {
        /// The axis's key, a dotted scene-file path (`block.lx`, `drive.height`, ...;
        /// a linked axis's keys joined by `", "`).
        key: String,
        /// What is wrong, with the value when one is at fault.
        reason: String,
    },
    /// A sweep file ([`crate::sweep::Sweep::from_json_file`],
    /// [`crate::sweep::Sweep::from_json_str`]) whose axes and realizations make more runs
    /// than `1e5`; refused before any scene is built.
    #[error(
        "the sweep has {points} points x {realizations} realizations = {runs} runs, more than \
         the limit of {limit} runs per sweep: split it into several sweeps (fewer values per \
         axis or fewer realizations each, with other output directories)"
    )]
    TooLarge {
        /// Parameter points (the product of the axes' lengths, exact).
        points: u128,
        /// Realizations per point.
        realizations: usize,
        /// `points · realizations` (exact).
        runs: u128,
        /// The most runs per sweep.
        limit: usize,
    },
    /// A sweep's output directory cannot be used: [`crate::sweep::Sweep::execute`] into a
    /// directory that holds another sweep's `sweep.json`; [`crate::sweep::merge`] of a
    /// directory with no `sweep.json`, or with a run's files that do not belong to it.
    #[error("sweep directory {}: {}", path.display(), Bounded(reason))]
    Directory {
        /// The directory or the file at fault.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
}
