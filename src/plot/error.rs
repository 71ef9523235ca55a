//! [`PlotError`]: what a figure can get wrong, with the core [`enum@Error`] (files, tables) and
//! the [`SweepError`] (the merge before a sweep's figures) nested.

use crate::error::{Bounded, Error};
use crate::sweep::SweepError;
use std::path::PathBuf;
use thiserror::Error;

/// Everything that can go wrong drawing figures (feature `plot`): [`crate::plot::Chart`],
/// [`crate::plot::Map`] and the figures of a directory ([`crate::plot::figures::draw`]).
///
/// The figure's own failures are [`PlotError::Figure`]; the rest is nested: the core
/// [`enum@Error`] in [`PlotError::Core`] (a figure or table that cannot be written or read, a
/// damaged table, a map of the wrong size), the merge of a sweep directory in
/// [`PlotError::Sweep`]. `?` turns either into a `PlotError`. Both are transparent: their
/// `Display` and [`std::error::Error::source`] are the nested error's own, so a report of
/// the cause chain prints each cause once; match on the variant to reach the nested error.
///
/// ```
/// use precursors::plot::{Chart, PlotError};
/// let e = Chart::new("title", "x", "y").save("figure.gif").unwrap_err();
/// assert!(matches!(e, PlotError::Figure { .. }));
/// ```
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum PlotError {
    /// A failure of the core library under a figure: a figure that cannot be written or a
    /// table that cannot be read ([`Error::Io`]), a run's damaged table
    /// ([`Error::CorruptTable`], [`Error::NonFiniteCell`]: file, line and column), map
    /// values that do not fit its size ([`Error::LengthMismatch`], [`Error::InvalidCount`]
    /// from [`crate::plot::Map::new`]).
    #[error(transparent)]
    Core(#[from] Error),
    /// The merge of a sweep directory that [`crate::plot::figures::draw`] does before its
    /// figures failed ([`crate::sweep::merge`]: a damaged `sweep.json`, a run's files that
    /// do not belong to the sweep, ...).
    #[error(transparent)]
    Sweep(#[from] SweepError),
    /// A figure cannot be drawn: [`crate::plot::Chart::save`] or [`crate::plot::Map::save`]
    /// to a file name that does not end in `.png` or `.svg`, with an axis range that is not
    /// finite and increasing, a size outside 200 x 150 to 16384 x 16384, a style given
    /// before any series, or a drawing backend that fails;
    /// [`crate::plot::figures::draw`] on a directory that is neither a run's nor a
    /// sweep's. A figure that cannot be written to its file is [`Error::Io`] (in
    /// [`PlotError::Core`]).
    #[error(
        "figure{}: {}",
        path.as_ref().map(|p| format!(" {}", p.display())).unwrap_or_default(),
        Bounded(reason)
    )]
    Figure {
        /// The figure's file (or the directory of [`crate::plot::figures::draw`]), when
        /// known.
        path: Option<PathBuf>,
        /// What is wrong.
        reason: String,
    },
    /// A PNG's resolution ([`crate::plot::Chart::dpi`], [`crate::plot::Map::dpi`],
    /// [`crate::plot::DrawOptions::dpi`], `precursors plot --dpi`) outside `low` to
    /// `high` dots per inch: coarser draws the text too few pixels to read, finer makes
    /// pictures of hundreds of megabytes for no print that resolves them.
    #[error(
        "a resolution of {dpi} dpi: a figure is drawn at {low} to {high} dots per inch \
         (150, the default, for the screen; 300 or 600 for print)"
    )]
    InvalidDpi {
        /// The resolution given (dots per inch).
        dpi: u32,
        /// The lowest resolution allowed (dots per inch).
        low: u32,
        /// The highest resolution allowed (dots per inch).
        high: u32,
    },
    /// A figure size ([`crate::plot::DrawOptions::size`], `precursors plot --width
    /// --height`) with a side outside 200 to `largest` (in 1/150 inch), or one that at
    /// [`crate::plot::DrawOptions::dpi`] makes a PNG of more than `largest` pixels along a
    /// side: found before any figure is drawn.
    #[error(
        "a figure of {} x {} at {dpi} dpi ({} x {} pixels as a PNG): each side must lie in \
         [200, {largest}], and a PNG's pixels, size · dpi/150, at most {largest} along a side",
        size.0, size.1, pixels.0, pixels.1
    )]
    InvalidSize {
        /// The size given (width, height in 1/150 inch).
        size: (u32, u32),
        /// The resolution given (dots per inch).
        dpi: u32,
        /// The PNG's pixels at that resolution (width, height).
        pixels: (u32, u32),
        /// The largest side allowed (pixels, and 1/150 inch).
        largest: u32,
    },
    /// A figure name ([`crate::plot::DrawOptions::figures`], `precursors plot --figure`)
    /// that is not one of the figures `plot` draws; the message lists them.
    #[error(
        "no figure is named \"{}\": the figures are {}",
        Bounded(name),
        known.join(", ")
    )]
    UnknownFigure {
        /// The name given.
        name: String,
        /// The figures' names.
        known: Vec<String>,
    },
    /// A figure named in [`crate::plot::DrawOptions::figures`] that the directory cannot
    /// give: a run's figure of a sweep, `archard` of a run or of a sweep without the axis
    /// `normal_load`, `stick_slip` of a run without a driving spring, `force_drops` where
    /// the force never drops, `contact_map` without `contact_map.csv`. Figures not named
    /// are left out with a note instead.
    #[error("{}: no {figure} figure: {}", dir.display(), Bounded(reason))]
    FigureUnavailable {
        /// The figure's name.
        figure: String,
        /// The run or sweep directory.
        dir: PathBuf,
        /// Why it cannot be drawn.
        reason: String,
    },
    /// A movie ([`crate::plot::Movie`], `precursors movie`) of a run directory that holds
    /// no recorded fields (no `fields.csv`, or no planes for the Coulomb stress movie):
    /// the message says how to record them.
    #[error(
        "{}: no recorded fields to draw a movie from: {}. Record them with the scene-file \
         key \"fields\" (e.g. \"fields\": {{\"every\": 1, \"planes\": [0.0, 0.005]}}: \
         every stable state, τ_C on planes at z = 0 and 5 mm; docs/scene-format.md) or \
         RunOptions::record_fields, then run the scene again into the directory \
         (`precursors run SCENE --out DIR`)",
        dir.display(),
        Bounded(reason)
    )]
    NoFields {
        /// The run directory.
        dir: PathBuf,
        /// What it lacks.
        reason: String,
    },
}
