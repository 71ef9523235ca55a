//! The tables of a run, as written by the `precursors` program (`run`, `resume`, `sweep`)
//! and by `Sweep::run_one` (module `sweep`, feature `serde`): CSV files that survive a crash.
//!
//! * `events.csv`, one row per event ([`EVENTS_HEADER`]): `index,kind,ix,iy,force_N,
//!   drive_displacement_m,energy_J,ruptures,area_exceeds_nominal` (empty cells where a
//!   column does not apply);
//! * `curve.csv`, one row per stable state ([`CURVE_HEADER`]): `event,force_N,
//!   force_over_mu_FN,drive_displacement_m,real_contact_area_m2,precursor_length_m,
//!   precursor_over_Lx,broken,attached,area_exceeds_nominal`;
//! * `contact_map.csv` ([`contact_map_header`]): the map over x and F of the paper's
//!   Fig. 2b inset, one row per load level `F/(μF_N)` = 0, 0.005, 0.01, ...
//!   ([`CONTACT_MAP_STEP`]) from the first stable state up to global slip: the real
//!   contact area of each column `ix` (m², summed over y) in the stable state in effect
//!   at that load (the last one reached at or below it), and that state's event index:
//!   `event,force_over_mu_FN,area_m2_ix0,...`. At most about 200 rows whatever the
//!   number of stable states. Levels are passed in order: where the load drops (a
//!   driving spring's slip), a level's row is the state in effect when the load first
//!   passed it.
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

/// The spacing in `F/(μF_N)` of the rows of `contact_map.csv`.
pub const CONTACT_MAP_STEP: f64 = 0.005;

/// The header of `contact_map.csv` for a grid of `nx` columns.
pub fn contact_map_header(nx: usize) -> String {
    let mut header = String::from("event,force_over_mu_FN");
    for ix in 0..nx {
        header.push_str(&format!(",area_m2_ix{ix}"));
    }
    header
}

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

/// The three tables of a run in a directory: `events.csv`, `curve.csv` and
/// `contact_map.csv`.
#[derive(Debug)]
pub struct RunTables {
    events: BufWriter<File>,
    curve: BufWriter<File>,
    map: BufWriter<File>,
    events_path: PathBuf,
    curve_path: PathBuf,
    map_path: PathBuf,
    stable_states: usize,
    /// The next level of `contact_map.csv`, in steps of [`CONTACT_MAP_STEP`].
    next_level: u64,
    /// The stable state in effect: the rows of the levels below the next state's load.
    in_effect: Option<MapState>,
}

/// A stable state as `contact_map.csv` needs it.
#[derive(Debug)]
struct MapState {
    event: usize,
    columns: Vec<f64>,
}

impl RunTables {
    /// New tables in `dir` (which must exist), header only, for `driver`'s run.
    ///
    /// # Errors
    /// As [`open_table`].
    pub fn create(dir: &Path, driver: &Driver) -> Result<Self> {
        Self::open(dir, driver, None)
    }

    /// The tables in `dir` continued after `driver` was resumed from a checkpoint: rows
    /// after the checkpoint's event are dropped ([`open_table`]), missing tables start
    /// empty.
    ///
    /// # Errors
    /// As [`open_table`].
    pub fn resume(dir: &Path, driver: &Driver) -> Result<Self> {
        Self::open(dir, driver, Some(driver.event_count()))
    }

    fn open(dir: &Path, driver: &Driver, keep: Option<usize>) -> Result<Self> {
        let events_path = dir.join("events.csv");
        let curve_path = dir.join("curve.csv");
        let map_path = dir.join("contact_map.csv");
        let events = open_table(&events_path, EVENTS_HEADER, keep)?;
        let curve = open_table(&curve_path, CURVE_HEADER, keep)?;
        let map = open_table(&map_path, &contact_map_header(driver.grid().nx()), keep)?;
        // The level after the last row kept (the table was just written back); the
        // state in effect is the driver's: a resumed run is at a stable state.
        let text =
            fs::read_to_string(&map_path).map_err(|e| Error::io("reading table", &map_path, e))?;
        let x = driver.force() / (driver.friction_coefficient() * driver.normal_load());
        let (next_level, in_effect) = match (keep, text.lines().nth(1).and(text.lines().last())) {
            (None, _) => (0, None),
            (Some(_), None) => (first_level_at_or_above(x), None),
            (Some(_), Some(row)) => {
                let level = row.split(',').nth(1).and_then(|f| f.parse::<f64>().ok());
                let Some(level) = level.filter(|l| l.is_finite() && *l >= 0.0) else {
                    return Err(Error::CorruptTable {
                        path: Some(map_path),
                        reason: "the last row's force_over_mu_FN is not a load level".into(),
                    });
                };
                (first_level_at_or_above(level) + 1, None)
            }
        };
        let in_effect = match keep {
            Some(k) if k > 0 => Some(MapState {
                event: k,
                columns: driver.column_contact_area()?,
            }),
            _ => in_effect,
        };
        Ok(Self {
            events,
            curve,
            map,
            events_path,
            curve_path,
            map_path,
            stable_states: 0,
            next_level,
            in_effect,
        })
    }

    /// The paths of `events.csv`, `curve.csv` and `contact_map.csv`.
    pub fn paths(&self) -> [&Path; 3] {
        [&self.events_path, &self.curve_path, &self.map_path]
    }

    /// Stable states recorded by this writer (not counting rows kept on resume).
    pub fn stable_states(&self) -> usize {
        self.stable_states
    }

    /// Writes the row(s) of `event`, just returned by `driver.step()`: one row of
    /// `events.csv`, and one of `curve.csv` for a stable state (and one of
    /// `contact_map.csv` when it reaches the map's next level).
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
            let x = load.force / mu_fn;
            self.map_rows_below(x, true)?;
            self.in_effect = Some(MapState {
                event: index,
                columns: driver.column_contact_area()?,
            });
        }
        if let Event::GlobalSlip { load } = *event {
            let mu_fn = driver.friction_coefficient() * driver.normal_load();
            self.map_rows_below(load.force / mu_fn, false)?;
        }
        Ok(())
    }

    /// The rows of `contact_map.csv` for the levels below the load `x = F/(μF_N)` of a new
    /// state (`stable`) or of global slip: the state in effect until now held there.
    /// Before the first stable state there is none: the map starts at the first level at
    /// or above its load. The levels stop at the friction limit.
    fn map_rows_below(&mut self, x: f64, stable: bool) -> Result<()> {
        // No stable state carries more than μF_N (every site holds |φ_x| ≤ μφ_z): in the
        // tests' scenes it stays below 0.999 (1 + 2.2e-16 at global slip), the
        // margin covers the loosest solver tolerance (1e-6). Beyond, the driver's result
        // is wrong; an infinite load made the loop below endless. Global slip under a
        // driving spring may overshoot μF_N (sites re-attach in the last avalanche): its
        // levels stop at the limit, so the map has at most 201 rows.
        const LIMIT: f64 = 1.0 + 1e-5;
        if !(x.is_finite() && (x <= LIMIT || !stable)) {
            return Err(Error::LoadBeyondFriction {
                ratio: x,
                limit: LIMIT,
            });
        }
        let x = x.min(LIMIT);
        let Some(state) = &self.in_effect else {
            self.next_level = first_level_at_or_above(x);
            return Ok(());
        };
        while level(self.next_level) < x {
            let mut row = format!("{},{:.3}", state.event, level(self.next_level));
            for a in &state.columns {
                row.push_str(&format!(",{a:.12e}"));
            }
            writeln!(self.map, "{row}")
                .map_err(|e| Error::io("writing table", &self.map_path, e))?;
            self.next_level += 1;
        }
        Ok(())
    }

    /// Flushes the tables to their files (before a checkpoint is written, and at the end).
    ///
    /// # Errors
    /// [`Error::Io`] when a file cannot be written.
    pub fn flush(&mut self) -> Result<()> {
        for (table, path) in [
            (&mut self.events, &self.events_path),
            (&mut self.curve, &self.curve_path),
            (&mut self.map, &self.map_path),
        ] {
            table
                .flush()
                .map_err(|e| Error::io("writing table", path, e))?;
        }
        Ok(())
    }
}

/// Map level `k`: `F/(μF_N) = k·`[`CONTACT_MAP_STEP`].
fn level(k: u64) -> f64 {
    k as f64 * CONTACT_MAP_STEP
}

/// The first map level at or above the load `x = F/(μF_N)` (0 for `x <= 0`). Rounded to
/// 1e-9 of a step first, so that a load on a level up to rounding counts as on it.
fn first_level_at_or_above(x: f64) -> u64 {
    ((x / CONTACT_MAP_STEP * 1e9).round() / 1e9).max(0.0).ceil() as u64
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
