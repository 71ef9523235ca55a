//! The tables of a run, as written by the `precursors` program (`run`, `resume`, `sweep`)
//! and by `Sweep::run_one` (module `sweep`, feature `serde`): CSV files that survive a crash.
//!
//! * `events.csv`, one row per event ([`EVENTS_HEADER`]): `index,kind,ix,iy,force_N,
//!   drive_displacement_m,energy_J,ruptures,area_exceeds_nominal` (empty cells where a
//!   column does not apply);
//! * `curve.csv`, one row per stable state ([`CURVE_HEADER`]): `event,force_N,
//!   force_over_mu_FN,drive_displacement_m,real_contact_area_m2,precursor_length_m,
//!   precursor_over_Lx,broken,attached,area_exceeds_nominal`.
//!
//! `area_exceeds_nominal` is 1 when the total real contact area of the state after the
//! event exceeds the nominal area `Lx·Ly` (the paper's unbounded area law), 0 otherwise.
//! Numbers are written with 13 significant digits (`{:.12e}`), so the tables of two runs
//! compare equal exactly when their results do.
//!
//! On resume from a checkpoint a table keeps its complete rows up to the checkpoint's event
//! and drops the rest, including a last row cut by the crash ([`rows_to_keep`]).

use crate::driver::{Driver, Event};
use crate::error::{Error, Result};
use crate::interface::SiteState;
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// The header of `events.csv`.
pub const EVENTS_HEADER: &str =
    "index,kind,ix,iy,force_N,drive_displacement_m,energy_J,ruptures,area_exceeds_nominal";
/// The header of `curve.csv`.
pub const CURVE_HEADER: &str = "event,force_N,force_over_mu_FN,drive_displacement_m,\
                                real_contact_area_m2,precursor_length_m,precursor_over_Lx,\
                                broken,attached,area_exceeds_nominal";

/// The text a resumed table starts from: `header`, then the rows of `old` whose first
/// column (an event index) is at most `keep`. A last row cut by a crash (no trailing
/// newline, or not as many fields as the header) is dropped.
///
/// # Errors
/// [`Error::CorruptTable`] (with the line number) for the same damage on an earlier row,
/// an index that is not a whole number, or another header: the table was not written by
/// this run.
pub fn rows_to_keep(old: &str, header: &str, keep: usize) -> Result<String> {
    let corrupt = |reason: String| Error::CorruptTable { path: None, reason };
    let fields = header.split(',').count();
    let mut text = format!("{header}\n");
    let mut lines: Vec<&str> = old.split_inclusive('\n').collect();
    if lines.is_empty() {
        return Ok(text);
    }
    let first = lines.remove(0);
    if first.trim_end_matches(['\n', '\r']) != header {
        return Err(corrupt(format!(
            "line 1 is not the header {header:?}: the table was written by another program"
        )));
    }
    let count = lines.len();
    for (k, line) in lines.into_iter().enumerate() {
        let last = k + 1 == count;
        let complete = line.ends_with('\n');
        let row = line.trim_end_matches(['\n', '\r']);
        if !complete || row.split(',').count() != fields {
            if last {
                break; // cut by a crash
            }
            return Err(corrupt(format!(
                "line {} has {} fields, the header {fields}",
                k + 2,
                row.split(',').count()
            )));
        }
        let index: usize = row.split(',').next().unwrap_or("").parse().map_err(|e| {
            corrupt(format!(
                "line {}: the event index is not a whole number ({e})",
                k + 2
            ))
        })?;
        if index <= keep {
            text.push_str(row);
            text.push('\n');
        }
    }
    Ok(text)
}

/// A table ready for appending rows: new (the header only) with `keep = None`, or the
/// existing `path` cut back by [`rows_to_keep`] (a missing file starts empty).
///
/// # Errors
/// [`Error::Io`] when the file cannot be read or written; [`Error::CorruptTable`] (with
/// the path) as [`rows_to_keep`].
pub fn open_table(path: &Path, header: &str, keep: Option<usize>) -> Result<BufWriter<File>> {
    let text = match keep {
        None => format!("{header}\n"),
        Some(k) => match fs::read_to_string(path) {
            Ok(old) => rows_to_keep(&old, header, k).map_err(|e| match e {
                Error::CorruptTable { reason, .. } => Error::CorruptTable {
                    path: Some(path.to_path_buf()),
                    reason,
                },
                other => other,
            })?,
            Err(e) if e.kind() == io::ErrorKind::NotFound => format!("{header}\n"),
            Err(e) => return Err(Error::io("reading table", path, e)),
        },
    };
    fs::write(path, text).map_err(|e| Error::io("writing table", path, e))?;
    let file = OpenOptions::new()
        .append(true)
        .open(path)
        .map_err(|e| Error::io("opening table", path, e))?;
    Ok(BufWriter::new(file))
}

/// The two tables of a run in a directory: `events.csv` and `curve.csv`.
#[derive(Debug)]
pub struct RunTables {
    events: BufWriter<File>,
    curve: BufWriter<File>,
    events_path: PathBuf,
    curve_path: PathBuf,
    stable_states: usize,
}

impl RunTables {
    /// New tables in `dir` (which must exist), header only; `keep = Some(k)` continues
    /// existing ones after a checkpoint at event `k` instead ([`open_table`]).
    ///
    /// # Errors
    /// As [`open_table`].
    pub fn open(dir: &Path, keep: Option<usize>) -> Result<Self> {
        let events_path = dir.join("events.csv");
        let curve_path = dir.join("curve.csv");
        let events = open_table(&events_path, EVENTS_HEADER, keep)?;
        let curve = open_table(&curve_path, CURVE_HEADER, keep)?;
        Ok(Self {
            events,
            curve,
            events_path,
            curve_path,
            stable_states: 0,
        })
    }

    /// The paths of `events.csv` and `curve.csv`.
    pub fn paths(&self) -> (&Path, &Path) {
        (&self.events_path, &self.curve_path)
    }

    /// Stable states recorded by this writer (not counting rows kept on resume).
    pub fn stable_states(&self) -> usize {
        self.stable_states
    }

    /// Writes the row(s) of `event`, just returned by `driver.step()`: one row of
    /// `events.csv`, and one of `curve.csv` for a stable state.
    ///
    /// # Errors
    /// [`Error::Io`] when a row cannot be written; the driver's errors for the fields of
    /// the state (none after a successful step).
    pub fn record(&mut self, driver: &Driver, event: &Event) -> Result<()> {
        let index = driver.event_count();
        let exceeds = driver.area_exceeds_nominal()?;
        write_event(&mut self.events, index, event, exceeds)
            .map_err(|e| Error::io("writing table", &self.events_path, e))?;
        if let Event::Stable { load, .. } = *event {
            self.stable_states += 1;
            let mu_fn = driver.friction_coefficient() * driver.normal_load();
            let (broken, attached) = counts(driver.site_states());
            let ell = driver.precursor_length()?;
            writeln!(
                self.curve,
                "{index},{:.12e},{:.12e},{},{:.12e},{:.12e},{:.12e},{broken},{attached},{}",
                load.force,
                load.force / mu_fn,
                optional(load.drive_displacement),
                driver.total_contact_area()?,
                ell,
                ell / driver.grid().block().lx(),
                u8::from(exceeds),
            )
            .map_err(|e| Error::io("writing table", &self.curve_path, e))?;
        }
        Ok(())
    }

    /// Flushes both tables to their files (before a checkpoint is written, and at the end).
    ///
    /// # Errors
    /// [`Error::Io`] when a file cannot be written.
    pub fn flush(&mut self) -> Result<()> {
        self.events
            .flush()
            .map_err(|e| Error::io("writing table", &self.events_path, e))?;
        self.curve
            .flush()
            .map_err(|e| Error::io("writing table", &self.curve_path, e))
    }
}

/// Broken and attached sites of `states`.
pub fn counts(states: &[SiteState]) -> (usize, usize) {
    let broken = states.iter().filter(|s| **s == SiteState::Broken).count();
    let attached = states.iter().filter(|s| **s == SiteState::Attached).count();
    (broken, attached)
}

fn optional(x: Option<f64>) -> String {
    x.map(|v| format!("{v:.12e}")).unwrap_or_default()
}

fn write_event(out: &mut impl Write, index: usize, event: &Event, exceeds: bool) -> io::Result<()> {
    let (kind, site, load, energy, ruptures) = match *event {
        Event::LoadRaised { load } => ("load_raised", None, Some(load), None, None),
        Event::Rupture { site, load, energy } => {
            ("rupture", Some(site), Some(load), Some(energy), None)
        }
        Event::Detach { site } => ("detach", Some(site), None, None, None),
        Event::Attach { site } => ("attach", Some(site), None, None, None),
        Event::Stable { load, ruptures } => ("stable", None, Some(load), None, Some(ruptures)),
        Event::GlobalSlip { load } => ("global_slip", None, Some(load), None, None),
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
