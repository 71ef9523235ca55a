//! The tables of a run, as written by the `precursors` program (`run`, `resume`, `sweep`)
//! and by `Sweep::run_one` (module `sweep`, feature `serde`): CSV files that survive a crash.
//!
//! * `events.csv`, one row per event ([`EVENTS_HEADER`]): `index,kind,ix,iy,force_N,
//!   drive_displacement_m,energy_J,ruptures,area_exceeds_nominal` (empty cells where a
//!   column does not apply);
//! * `curve.csv`, one row per stable state ([`CURVE_HEADER`]): `event,force_N,
//!   force_over_mu_FN,drive_displacement_m,real_contact_area_m2,precursor_length_m,
//!   precursor_over_Lx,broken,attached,area_exceeds_nominal`;
//! * `contact_map.csv` (header `event,force_over_mu_FN`, then `area_m2_ix0`, `area_m2_ix1`, ...): the map over x and F of the paper's
//!   Fig. 2b inset, one row per load level `F/(μF_N)` = 0, 0.005, 0.01, ...
//!   ([`CONTACT_MAP_STEP`]) from the first stable state up to global slip: the real
//!   contact area of each column `ix` (m², summed over y) in the stable state in effect
//!   at that load (the last one reached at or below it), and that state's event index:
//!   `event,force_over_mu_FN,area_m2_ix0,...`. At most about 200 rows whatever the
//!   number of stable states. Levels are passed in order: where the load drops (a
//!   driving spring's slip), a level's row is the state in effect when the load first
//!   passed it.
//!
//! * `fields.csv` ([`FIELDS_TABLE`]), only when the scene records fields
//!   ([`crate::SceneBuilder::record_fields`], scene-file key `fields`): the fields of the
//!   1st, `(1 + every)`-th, `(1 + 2·every)`-th, ... stable state, for the movies (`precursors
//!   movie`), header `event,force_over_mu_FN,precursor_over_Lx,field,row,z_m,value_ix0,
//!   ...,value_ix{Nx-1}`. Each recorded state has `Ny` rows of field `area_m2` (row `iy`,
//!   `z_m` 0: the real contact area of the cells `(ix, iy)`, m²), then one row of field
//!   `coulomb_Pa` per recorded plane (row `k`, `z_m` its height: the y-averaged Coulomb
//!   stress `τ_C(x, z) = |⟨τ⟩_y| - μ|⟨σ⟩_y|` of each column, Pa, as
//!   [`crate::Profile::coulomb_of_means`]). About `(Ny + planes)·Nx·20` bytes per recorded
//!   state: `every` bounds the size.
//!
//! `area_exceeds_nominal` is 1 when the total real contact area of the state after the
//! event exceeds the nominal area `Lx·Ly` (the paper's unbounded area law), 0 otherwise.
//! Numbers are written with 13 significant digits (`{:.12e}`), so the tables of two runs
//! compare equal exactly when their results do.
//!
//! **Complete or marked partial.** While a run is under way its tables are written as
//! `events.csv.partial`, `curve.csv.partial` and `contact_map.csv.partial`
//! ([`PARTIAL_SUFFIX`]); [`RunTables::finish`], once the run reached global slip, syncs
//! them to disk and renames them to their names. A crash, a kill or a full disk leaves
//! `.partial` files (or the tables of a complete run), never a table under its name that
//! is not complete. The directory is locked while the tables are written (an advisory lock
//! of the operating system, on the file `.precursors.lock`, that ends with the process): a
//! second writer is refused ([`Error::DirectoryLocked`], naming the holder). With the
//! `serde` feature the run's scene is recorded in the directory ([`SCENE_RECORD`]).
//!
//! **Resume.** [`RunTables::resume`] continues the tables of a run from a checkpoint taken
//! at a stable state: it checks, before it writes anything, that the directory's recorded
//! scene is the checkpoint's, that the three tables have their headers and whole rows
//! (a last row cut by a crash is dropped), that `events.csv` numbers its
//! rows 1, 2, 3, ... up to at least the checkpoint's event, and that `curve.csv` and
//! `contact_map.csv` hold the stable states and load levels reached by then; then it
//! rewrites the `.partial` tables with the rows up to the checkpoint's event. With fields
//! recorded, `fields.csv` must hold exactly the recorded states up to the checkpoint's
//! event (the same `every` and planes), and is cut back the same way.

pub(crate) mod check;
pub(crate) mod layout;

use crate::driver::{Driver, Event};
use crate::error::{Error, Result};
use crate::files::{check_replaceable, read_text_if_exists, sync_dir, write_atomically};
use crate::interface::SiteState;
use crate::lock::DirLock;
use crate::probe::{ProbeSpec, StressProbe};
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

/// The names of a run's tables, in the order of [`RunTables::paths`].
pub const TABLE_NAMES: [&str; 3] = ["events.csv", "curve.csv", "contact_map.csv"];

/// Appended to a table's name while its run is under way (`events.csv.partial`).
pub const PARTIAL_SUFFIX: &str = ".partial";

/// The record of a run's scene in its directory (feature `serde`: the scene file of
/// `SceneBuilder::to_json`), written when the run starts, checked on resume.
pub const SCENE_RECORD: &str = "scene.json";

/// The table of the fields a run records for the movies (written only when the scene
/// records fields: [`crate::SceneBuilder::record_fields`]; layout in the module's docs).
pub const FIELDS_TABLE: &str = "fields.csv";

/// The `field` of the rows of `fields.csv` that hold the real contact area of a row `iy`
/// of cells (m²), and of those that hold the y-averaged Coulomb stress on a plane (Pa).
pub(crate) const FIELD_AREA: &str = "area_m2";
pub(crate) const FIELD_COULOMB: &str = "coulomb_Pa";

/// The header of `fields.csv` for a grid of `nx` columns.
pub(crate) fn fields_header(nx: usize) -> String {
    let mut header = String::from("event,force_over_mu_FN,precursor_over_Lx,field,row,z_m");
    for ix in 0..nx {
        header.push_str(&format!(",value_ix{ix}"));
    }
    header
}

/// The header of `contact_map.csv` for a grid of `nx` columns.
pub(crate) fn contact_map_header(nx: usize) -> String {
    let mut header = String::from("event,force_over_mu_FN");
    for ix in 0..nx {
        header.push_str(&format!(",area_m2_ix{ix}"));
    }
    header
}

/// Refuses an output `path` a caller names beside a run writing into `dir` (a
/// checkpoint) that would replace a file of the run directory: a table, `NAME.partial`,
/// the scene record, the lock, a sweep's `done` or `meta.json`, a merged table, a figure
/// or a movie; and one that exists but is not a regular file (a FIFO, a device, a
/// directory, a symbolic link), which a checkpoint written atomically would replace.
/// `RunTables::run_to_slip` (feature `serde`) checks its checkpoint so; call it before
/// [`RunTables::create`] to refuse before anything is written.
///
/// ```
/// use precursors::output::check_output_path;
/// let dir = std::path::Path::new(".");
/// assert!(check_output_path(dir, &dir.join("curve.csv.partial")).is_err());
/// assert!(check_output_path(dir, &dir.join(".precursors.lock")).is_err());
/// assert!(check_output_path(dir, &dir.join("checkpoint.json")).is_ok());
/// ```
///
/// # Errors
/// [`Error::OutputCollision`]; [`Error::NotARegularFile`]; [`Error::Io`] when `path`
/// cannot be examined.
pub fn check_output_path(dir: &Path, path: &Path) -> Result<()> {
    layout::check_output(path, dir, "checkpoint")?;
    check_replaceable(path, "writing checkpoint")
}

/// The complete rows of a table's text (line number, row), its header checked: a last
/// row cut by a crash (no trailing newline, or not as many fields as the header) is left
/// out; the same damage on an earlier row is refused.
fn complete_rows<'a>(
    old: &'a str,
    header: &str,
) -> std::result::Result<Vec<(usize, &'a str)>, String> {
    let fields = header.split(',').count();
    let mut lines = old.split_inclusive('\n');
    let Some(first) = lines.next() else {
        return Ok(Vec::new());
    };
    if first.trim_end_matches(['\n', '\r']) != header {
        return Err(format!(
            "line 1 is not the header {header:?}: the table was written by another program"
        ));
    }
    let lines: Vec<&str> = lines.collect();
    let count = lines.len();
    let mut rows = Vec::with_capacity(count);
    for (k, line) in lines.into_iter().enumerate() {
        let row = line.trim_end_matches(['\n', '\r']);
        if !line.ends_with('\n') || row.split(',').count() != fields {
            if k + 1 == count {
                break; // cut by a crash
            }
            return Err(format!(
                "line {} has {} fields, the header {fields}",
                k + 2,
                row.split(',').count()
            ));
        }
        rows.push((k + 2, row));
    }
    Ok(rows)
}

/// The event index in the first column of a row.
fn index_of(line: usize, row: &str) -> std::result::Result<usize, String> {
    row.split(',')
        .next()
        .unwrap_or("")
        .parse()
        .map_err(|e| format!("line {line}: the event index is not a whole number ({e})"))
}

/// What a resumed run starts from: the three tables' texts up to the checkpoint's event,
/// the next level of the map, and whether a stable state is in effect.
#[derive(Debug)]
struct Continuation {
    texts: [String; 3],
    next_level: u64,
    in_effect: bool,
    /// The events of the stable states up to the checkpoint's.
    stable: Vec<usize>,
}

/// Checks the three tables (`old[t]`: the text of table `t` in [`TABLE_NAMES`] order,
/// `None` when missing; `paths` for the messages) against each other and against the
/// checkpoint's event `k`, and cuts them back to it. Nothing is written.
fn continuation(
    old: [Option<&str>; 3],
    paths: &[PathBuf; 3],
    k: usize,
    bounds: &check::Bounds,
    force_at_k: f64,
) -> Result<Continuation> {
    let corrupt = |t: usize, reason: String| Error::CorruptTable {
        path: Some(paths[t].clone()),
        reason,
    };
    let map_header = contact_map_header(bounds.nx);
    let headers = [EVENTS_HEADER, CURVE_HEADER, map_header.as_str()];
    // Every table's header and rows first, so a damaged third table refuses the resume
    // before anything is cut.
    let mut rows: [Vec<(usize, &str)>; 3] = Default::default();
    for t in 0..3 {
        rows[t] = complete_rows(old[t].unwrap_or(""), headers[t]).map_err(|r| corrupt(t, r))?;
    }
    let [events, curve, map] = rows;

    // events.csv: rows 1, 2, 3, ... (one run's), up to at least k.
    let mut last = 0;
    let mut stable = Vec::new();
    let mut stable_forces = Vec::new();
    let mut kind_at_k = "";
    for &(line, row) in &events {
        let index = index_of(line, row).map_err(|r| corrupt(0, r))?;
        if index != last + 1 {
            return Err(corrupt(
                0,
                format!(
                    "line {line}: event {index} follows event {last}: the rows are not those \
                     of one run (numbered 1, 2, 3, ...)"
                ),
            ));
        }
        last = index;
        if index > k {
            continue; // cut away below
        }
        // Every row kept is checked whole: a damaged cell must not pass into the
        // finished table.
        let e = check::event_row(line, row, bounds).map_err(|b| b.at(&paths[0]))?;
        if e.kind == "global_slip" {
            return Err(corrupt(
                0,
                format!(
                    "line {line}: global slip at event {index}, before the checkpoint's event {k}"
                ),
            ));
        }
        if e.kind == "stable" {
            stable.push(index);
            stable_forces.push(e.force_text);
        }
        if index == k {
            kind_at_k = e.kind;
        }
    }
    if last < k {
        let what = if old[0].is_none() {
            "the table is missing".to_string()
        } else {
            format!("the table ends at event {last}")
        };
        return Err(corrupt(
            0,
            format!(
                "{what}, the checkpoint is at event {k}: events {} to {k} are missing",
                last + 1
            ),
        ));
    }
    if k > 0 && kind_at_k != "stable" {
        return Err(Error::InvalidCheckpoint {
            reason: format!(
                "it was taken after event {k}, a {kind_at_k} inside an avalanche: tables are \
                 continued from a checkpoint at a stable state (as `precursors run \
                 --checkpoint` takes them)"
            ),
        });
    }

    // The checkpoint's load is the one the tables give its stable state (as written:
    // the same 13 digits), so neither was edited since.
    if let (true, Some(force)) = (k > 0, stable_forces.last()) {
        let checkpoint = format!("{force_at_k:.12e}");
        if *force != checkpoint {
            return Err(corrupt(
                0,
                format!(
                    "event {k} is at force_N {force}, the checkpoint's load is {checkpoint} N: \
                     the table or the checkpoint was edited"
                ),
            ));
        }
    }

    // curve.csv: one row per stable state of events.csv up to k, in order.
    let mut loads = Vec::with_capacity(stable.len());
    let mut previous = 0;
    for &(line, row) in &curve {
        let event = index_of(line, row).map_err(|r| corrupt(1, r))?;
        if event <= previous {
            return Err(corrupt(
                1,
                format!("line {line}: event {event} follows event {previous}"),
            ));
        }
        previous = event;
        if event > k {
            break;
        }
        match stable.get(loads.len()) {
            Some(&s) if s == event => {}
            Some(&s) => {
                return Err(corrupt(
                    1,
                    format!(
                        "line {line} holds the state of event {event}, but the stable state \
                         of events.csv there is event {s}"
                    ),
                ))
            }
            None => {
                return Err(corrupt(
                    1,
                    format!("line {line}: event {event} is not a stable state of events.csv"),
                ))
            }
        }
        let c = check::curve_row(line, row, bounds).map_err(|b| b.at(&paths[1]))?;
        let force = &stable_forces[loads.len()];
        if &c.force_text != force {
            return Err(corrupt(
                1,
                format!(
                    "line {line}: event {event} at force_N {}, events.csv has {force}",
                    c.force_text
                ),
            ));
        }
        loads.push(c.load);
    }
    if loads.len() < stable.len() {
        return Err(corrupt(
            1,
            format!(
                "it holds {} stable states up to the checkpoint's event {k}, events.csv {}: \
                 the rows from event {} on are missing",
                loads.len(),
                stable.len(),
                stable[loads.len()]
            ),
        ));
    }

    // contact_map.csv: consecutive levels from the first state's load, each row a stable
    // state, reaching the levels below the highest load of the states up to k.
    let mut kept_levels: Vec<u64> = Vec::new();
    let mut previous: Option<(u64, usize)> = None;
    let map_cells: Vec<&str> = map_header.split(',').collect();
    for &(line, row) in &map {
        let event = index_of(line, row).map_err(|r| corrupt(2, r))?;
        let level = row.split(',').nth(1).and_then(|f| f.parse::<f64>().ok());
        let step = level.map(|l| (l / CONTACT_MAP_STEP).round());
        let level = match (level, step) {
            (Some(l), Some(s))
                if l.is_finite() && s >= 0.0 && (s * CONTACT_MAP_STEP - l).abs() < 1e-9 =>
            {
                s as u64
            }
            _ => {
                return Err(corrupt(
                    2,
                    format!(
                        "line {line}: force_over_mu_FN is not a load level (a multiple of \
                         {CONTACT_MAP_STEP})"
                    ),
                ))
            }
        };
        if let Some((l, e)) = previous {
            if level != l + 1 || event < e {
                return Err(corrupt(
                    2,
                    format!(
                        "line {line}: level {} of event {event} follows level {} of event \
                         {e}: the rows are not those of one run",
                        level_text(level),
                        level_text(l)
                    ),
                ));
            }
        }
        previous = Some((level, event));
        if event > k {
            break;
        }
        check::map_row(line, &map_cells, row).map_err(|b| b.at(&paths[2]))?;
        if stable.binary_search(&event).is_err() {
            return Err(corrupt(
                2,
                format!("line {line}: event {event} is not a stable state of events.csv"),
            ));
        }
        kept_levels.push(level);
    }
    let first = loads.first().map_or(0, |&x| first_level_at_or_above(x));
    if let Some(&l) = kept_levels.first() {
        if l != first {
            return Err(corrupt(
                2,
                format!(
                    "the first row is level {}, the first stable state's load gives level {}",
                    level_text(l),
                    level_text(first)
                ),
            ));
        }
    }
    // Levels below the load of each state after the first were written when it was
    // reached (up to a load within 1e-9 of a step of a level).
    let needed = loads
        .iter()
        .enumerate()
        .skip(1)
        .map(|(i, &x)| (first_level_at_or_above(x), i))
        .filter(|&(above, _)| above > first)
        .max_by_key(|&(above, _)| above);
    if let Some((above, i)) = needed {
        let reached = kept_levels.last().map(|&l| l + 1).unwrap_or(first);
        if reached < above {
            return Err(corrupt(
                2,
                format!(
                    "it reaches level {} only, but the stable state of event {} reached \
                     F/(μF_N) = {}: the rows of the levels up to {} are missing",
                    if kept_levels.is_empty() {
                        "none".to_string()
                    } else {
                        level_text(reached - 1)
                    },
                    stable[i],
                    loads[i],
                    level_text(above - 1)
                ),
            ));
        }
    }
    let next_level = kept_levels.last().map_or(first, |&l| l + 1);

    let text = |header: &str, rows: &[(usize, &str)], count: usize| {
        let mut text = format!("{header}\n");
        for (_, row) in &rows[..count] {
            text.push_str(row);
            text.push('\n');
        }
        text
    };
    Ok(Continuation {
        texts: [
            text(EVENTS_HEADER, &events, k),
            text(CURVE_HEADER, &curve, loads.len()),
            text(&map_header, &map, kept_levels.len()),
        ],
        next_level,
        in_effect: k > 0,
        stable,
    })
}

/// What the fields of a resumed run start from: `fields.csv`'s text (`old`, `None` when
/// missing; `path` for the messages) checked against the states the scene records up to
/// the checkpoint's event (the `every`-th of the stable states `stable`, `ny` rows of
/// area and one per plane of `planes` each) and cut back to them. Nothing is written.
fn fields_continuation(
    old: Option<&str>,
    path: &Path,
    stable: &[usize],
    recording: (usize, &[f64]),
    (nx, ny): (usize, usize),
) -> Result<String> {
    let (every, planes) = recording;
    let corrupt = |reason: String| Error::CorruptTable {
        path: Some(path.to_path_buf()),
        reason,
    };
    let header = fields_header(nx);
    let expected: Vec<usize> = stable.iter().step_by(every).copied().collect();
    let rows = complete_rows(old.unwrap_or(""), &header).map_err(corrupt)?;
    let per_state = ny + planes.len();
    let last = stable.last().copied().unwrap_or(0);
    let header_cells: Vec<&str> = header.split(',').collect();
    let mut state_texts: Option<(&str, &str)> = None;
    let mut kept = 0;
    for (n, &(line, row)) in rows.iter().enumerate() {
        let event = index_of(line, row).map_err(corrupt)?;
        if event > last {
            break;
        }
        let (state, within) = (n / per_state, n % per_state);
        match expected.get(state) {
            Some(&e) if e == event => {}
            Some(&e) => {
                return Err(corrupt(format!(
                    "line {line} holds event {event}, but the scene records the stable state \
                     of event {e} there (every {every}-th stable state from the first): the \
                     table was recorded with another `fields.every`"
                )))
            }
            None => {
                return Err(corrupt(format!(
                    "line {line}: event {event} is not a stable state the scene records"
                )))
            }
        }
        let r = check::fields_row(line, &header_cells, row, within, ny, planes).map_err(
            |b| match b {
                check::Bad::Reason(r) => corrupt(format!(
                    "{r} (recorded with another grid or other `fields.planes`?)"
                )),
                b => b.at(path),
            },
        )?;
        // One state, one load: every row of it as its first.
        match state_texts {
            Some((load, ell)) if within > 0 && (r.load_text != load || r.precursor_text != ell) => {
                return Err(corrupt(format!(
                    "line {line}: event {event} at F/(μF_N) = {}, ℓ/Lx = {}, but its first row \
                     has {load}, {ell}",
                    r.load_text, r.precursor_text
                )))
            }
            _ if within == 0 => state_texts = Some((r.load_text, r.precursor_text)),
            _ => {}
        }
        kept += 1;
    }
    let states = kept / per_state;
    if kept % per_state != 0 || states < expected.len() {
        let missing = expected.get(states).copied().unwrap_or(last);
        return Err(corrupt(format!(
            "it holds {states} whole recorded states up to the checkpoint's event {last}, \
             the scene records {}: the fields from event {missing} on are missing (recorded \
             with another `fields.every`, or without fields: run the scene again to record \
             them)",
            expected.len()
        )));
    }
    let mut text = format!("{header}\n");
    for (_, row) in &rows[..kept] {
        text.push_str(row);
        text.push('\n');
    }
    Ok(text)
}

/// A map level as the table writes it.
fn level_text(k: u64) -> String {
    format!("{:.3}", level(k))
}

/// The three tables of a run in a directory: `events.csv`, `curve.csv` and
/// `contact_map.csv`, written as `NAME.partial` until [`RunTables::finish`].
///
/// ```
/// use precursors::output::{RunTables, CURVE_HEADER};
/// use precursors::Scene;
/// let dir = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// // 10 x 4 cells of 1 mm under 100 N, driven by the paper's rod to global slip.
/// let scene = Scene::builder().block(0.010, 0.004, 0.010).normal_load(100.0).build()?;
/// let mut driver = scene.driver()?;
/// let mut tables = RunTables::create(&dir, &driver)?;
/// while let Some(event) = driver.step()? {
///     tables.record(&driver, &event)?;
/// }
/// let stable_states = tables.stable_states();
/// assert!(!tables.paths()[1].exists());           // only curve.csv.partial until finish
/// let [events, curve, map] = tables.finish()?;
/// let text = std::fs::read_to_string(&curve)?;
/// assert_eq!(text.lines().next(), Some(CURVE_HEADER));
/// assert_eq!(text.lines().count(), 1 + stable_states); // one row per stable state
/// assert!(events.is_file() && map.is_file());
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct RunTables {
    events: BufWriter<File>,
    curve: BufWriter<File>,
    map: BufWriter<File>,
    dir: PathBuf,
    /// The tables' names (after [`RunTables::finish`]).
    paths: [PathBuf; 3],
    /// The files written until then.
    partials: [PathBuf; 3],
    stable_states: usize,
    /// The next level of `contact_map.csv`, in steps of [`CONTACT_MAP_STEP`].
    next_level: u64,
    /// The stable state in effect: the rows of the levels below the next state's load.
    in_effect: Option<MapState>,
    /// Global slip was recorded.
    slipped: bool,
    /// `fields.csv`, when the scene records fields.
    fields: Option<FieldsTable>,
    /// The directory's lock, `None` when the caller holds it (a sweep's run).
    _lock: Option<DirLock>,
}

/// `fields.csv` of a run that records fields ([`crate::SceneBuilder::record_fields`]).
#[derive(Debug)]
struct FieldsTable {
    file: BufWriter<File>,
    /// The table's name (after [`RunTables::finish`]) and the file written until then.
    path: PathBuf,
    partial: PathBuf,
    every: usize,
    planes: Vec<f64>,
    /// The recorded planes, planned on the scene's operator (`None` without planes).
    /// Asserted unwind-safe so that `RunTables` stays so (as in 1.0): the probe is only
    /// read after it is built (its transforms' plans are immutable), so a panic cannot
    /// leave it half changed.
    probe: Option<std::panic::AssertUnwindSafe<StressProbe>>,
    /// Stable states of the run so far (those kept on resume included).
    stable: usize,
}

impl FieldsTable {
    /// `dir/fields.csv` and `dir/fields.csv.partial`.
    fn paths(dir: &Path) -> (PathBuf, PathBuf) {
        (
            dir.join(FIELDS_TABLE),
            dir.join(format!("{FIELDS_TABLE}{PARTIAL_SUFFIX}")),
        )
    }

    /// The writer of `driver`'s fields into `file` (`stable`: the stable states before
    /// its first row); `None` when its scene records none.
    fn new(
        driver: &Driver,
        dir: &Path,
        file: impl FnOnce(&Path) -> Result<File>,
        stable: usize,
    ) -> Result<Option<Self>> {
        let scene = driver.scene();
        let every = scene.fields_every();
        if every == 0 {
            return Ok(None);
        }
        let planes = scene.field_planes().to_vec();
        let probe = if planes.is_empty() {
            None
        } else {
            let spec = planes.iter().fold(
                ProbeSpec::default().with_tolerance(scene.probes().tolerance())?,
                |spec, &z| spec.with_plane(z),
            );
            Some(std::panic::AssertUnwindSafe(StressProbe::new(
                scene.plan(),
                &spec,
                scene.lateral_load(),
            )?))
        };
        let (path, partial) = Self::paths(dir);
        Ok(Some(Self {
            file: BufWriter::new(file(&partial)?),
            path,
            partial,
            every,
            planes,
            probe,
            stable,
        }))
    }

    /// The rows of the stable state `index` just reached (load `x = F/(μF_N)`, precursor
    /// `ℓ/Lx`), when it is one the scene records.
    fn record(&mut self, driver: &Driver, index: usize, x: f64, ell: f64) -> Result<()> {
        self.stable += 1;
        if !(self.stable - 1).is_multiple_of(self.every) {
            return Ok(());
        }
        let mut text = String::new();
        let mut row = |field: &str, k: usize, z: f64, values: &[f64]| {
            text.push_str(&format!("{index},{x:.12e},{ell:.12e},{field},{k},{z:.12e}"));
            for v in values {
                text.push_str(&format!(",{v:.12e}"));
            }
            text.push('\n');
        };
        let area = driver.cell_contact_area()?;
        for (iy, cells) in area.chunks_exact(driver.grid().nx()).enumerate() {
            row(FIELD_AREA, iy, 0.0, cells);
        }
        if let Some(probe) = &self.probe {
            let stresses = driver.stresses_at(std::slice::from_ref(&probe.0))?;
            for (k, (plane, &z)) in stresses.planes.iter().zip(&self.planes).enumerate() {
                row(FIELD_COULOMB, k, z, &plane.profile().coulomb_of_means);
            }
        }
        self.file
            .write_all(text.as_bytes())
            .map_err(|e| Error::io("writing table", &self.partial, e))
    }
}

/// A stable state as `contact_map.csv` needs it.
#[derive(Debug)]
struct MapState {
    event: usize,
    columns: Vec<f64>,
}

/// `dir/NAME` and `dir/NAME.partial` of each table.
fn table_paths(dir: &Path) -> ([PathBuf; 3], [PathBuf; 3]) {
    (
        TABLE_NAMES.map(|n| dir.join(n)),
        TABLE_NAMES.map(|n| dir.join(format!("{n}{PARTIAL_SUFFIX}"))),
    )
}

impl RunTables {
    /// New tables in `dir` (which must exist), header only, for `driver`'s run: the
    /// directory is locked, the tables of an earlier run there removed, the scene
    /// recorded ([`SCENE_RECORD`], feature `serde`).
    ///
    /// # Errors
    /// [`Error::DirectoryLocked`] when another process writes the directory;
    /// [`Error::Io`] when a file cannot be written or removed.
    pub fn create(dir: &Path, driver: &Driver) -> Result<Self> {
        let lock = DirLock::lock(dir)?;
        layout::check_not_a_sweeps(dir)?;
        Self::start(dir, driver, Some(lock))
    }

    /// [`RunTables::create`] in a directory whose lock the caller holds (`lock: None`)
    /// or passes on.
    pub(crate) fn start(dir: &Path, driver: &Driver, lock: Option<DirLock>) -> Result<Self> {
        let (paths, partials) = table_paths(dir);
        remove_stale_temporaries(dir)?;
        remove_derived(dir)?;
        for path in &paths {
            match fs::remove_file(path) {
                Err(e) if e.kind() != io::ErrorKind::NotFound => {
                    return Err(Error::io("removing the earlier run's table", path, e))
                }
                _ => {}
            }
        }
        #[cfg(feature = "serde")]
        write_atomically(
            &dir.join(SCENE_RECORD),
            driver.scene().to_builder().to_json()?.as_bytes(),
            "recording the scene",
        )?;
        let headers = [
            EVENTS_HEADER.to_string(),
            CURVE_HEADER.to_string(),
            contact_map_header(driver.grid().nx()),
        ];
        let mut files = Vec::with_capacity(3);
        for (path, header) in partials.iter().zip(&headers) {
            // A FIFO there would block the open, a link would be written through.
            check_replaceable(path, "creating table")?;
            let file = File::create(path).map_err(|e| Error::io("creating table", path, e))?;
            let mut file = BufWriter::new(file);
            writeln!(file, "{header}").map_err(|e| Error::io("writing table", path, e))?;
            files.push(file);
        }
        let [events, curve, map]: [BufWriter<File>; 3] = files.try_into().expect("three tables");
        // An earlier run's fields never pass for this run's.
        remove_fields(dir)?;
        let nx = driver.grid().nx();
        let fields = FieldsTable::new(
            driver,
            dir,
            |path| {
                check_replaceable(path, "creating table")?;
                let mut file =
                    File::create(path).map_err(|e| Error::io("creating table", path, e))?;
                writeln!(file, "{}", fields_header(nx))
                    .map_err(|e| Error::io("writing table", path, e))?;
                Ok(file)
            },
            0,
        )?;
        Ok(Self {
            events,
            curve,
            map,
            dir: dir.to_path_buf(),
            paths,
            partials,
            stable_states: 0,
            next_level: 0,
            in_effect: None,
            slipped: false,
            fields,
            _lock: lock,
        })
    }

    /// The tables in `dir` continued after `driver` was resumed ([`crate::Scene::resume`])
    /// from a checkpoint taken at a stable state. The directory is locked; then, before
    /// anything is written, its recorded scene ([`SCENE_RECORD`], feature `serde`) must be
    /// the driver's, and the tables (each `NAME.partial` if present, else `NAME`) must
    /// hold whole rows under their headers, `events.csv` the events 1, 2, ... up to the
    /// checkpoint's (a last row cut by a crash is dropped), `curve.csv` and
    /// `contact_map.csv` the stable states and load levels reached by then. The `.partial`
    /// tables are then rewritten (atomically) with the rows up to the checkpoint's event;
    /// complete tables of a finished run stay until [`RunTables::finish`] replaces them.
    ///
    /// # Errors
    /// [`Error::RunDirectory`] for a missing directory or (feature `serde`) one without
    /// its scene record; [`Error::CheckpointSceneMismatch`], naming the first differing
    /// key, when the recorded scene is another; [`Error::CorruptTable`], naming the file
    /// and line, for a table that is damaged, too short or inconsistent with the others;
    /// [`Error::InvalidCheckpoint`] for a checkpoint inside an avalanche;
    /// [`Error::DirectoryLocked`]; [`Error::Io`].
    pub fn resume(dir: &Path, driver: &Driver) -> Result<Self> {
        if !dir.is_dir() {
            return Err(Error::RunDirectory {
                path: dir.to_path_buf(),
                reason: "no such directory: resume continues the run whose tables are there".into(),
            });
        }
        let lock = DirLock::lock(dir)?;
        layout::check_not_a_sweeps(dir)?;
        #[cfg(feature = "serde")]
        check_scene_record(dir, driver)?;
        let k = driver.event_count();
        let (paths, partials) = table_paths(dir);
        // The tables of the run under way (or cut), else those of a finished run.
        let mut old: [Option<String>; 3] = Default::default();
        let mut read = partials.clone();
        for t in 0..3 {
            for path in [&partials[t], &paths[t]] {
                if let Some(text) = read_text_if_exists(path, "reading table")? {
                    old[t] = Some(text);
                    read[t] = path.clone();
                    break;
                }
            }
        }
        let plan = continuation(
            [old[0].as_deref(), old[1].as_deref(), old[2].as_deref()],
            &read,
            k,
            &check::Bounds::of(driver),
            driver.force(),
        )?;
        let in_effect = if plan.in_effect {
            Some(MapState {
                event: k,
                columns: driver.column_contact_area()?,
            })
        } else {
            None
        };
        let scene = driver.scene();
        let fields_text = if scene.fields_every() > 0 {
            let (path, partial) = FieldsTable::paths(dir);
            let mut old = None;
            let mut read = partial.clone();
            for p in [&partial, &path] {
                if let Some(text) = read_text_if_exists(p, "reading table")? {
                    old = Some(text);
                    read = p.clone();
                    break;
                }
            }
            Some(fields_continuation(
                old.as_deref(),
                &read,
                &plan.stable,
                (scene.fields_every(), scene.field_planes()),
                (driver.grid().nx(), driver.grid().ny()),
            )?)
        } else {
            None
        };
        // Checked: now the directory is written.
        remove_stale_temporaries(dir)?;
        let mut files = Vec::with_capacity(3);
        for (path, text) in partials.iter().zip(&plan.texts) {
            write_atomically(path, text.as_bytes(), "writing table")?;
            let file = OpenOptions::new()
                .append(true)
                .open(path)
                .map_err(|e| Error::io("opening table", path, e))?;
            files.push(BufWriter::new(file));
        }
        let [events, curve, map]: [BufWriter<File>; 3] = files.try_into().expect("three tables");
        // Without fields recorded now, those of the run before the checkpoint would not
        // cover the run: removed.
        if fields_text.is_none() {
            remove_fields(dir)?;
        }
        let fields = match fields_text {
            Some(text) => FieldsTable::new(
                driver,
                dir,
                |path| {
                    write_atomically(path, text.as_bytes(), "writing table")?;
                    OpenOptions::new()
                        .append(true)
                        .open(path)
                        .map_err(|e| Error::io("opening table", path, e))
                },
                plan.stable.len(),
            )?,
            None => None,
        };
        Ok(Self {
            events,
            curve,
            map,
            dir: dir.to_path_buf(),
            paths,
            partials,
            stable_states: 0,
            next_level: plan.next_level,
            in_effect,
            slipped: false,
            fields,
            _lock: Some(lock),
        })
    }

    /// The paths of `events.csv`, `curve.csv` and `contact_map.csv` (their names once
    /// [`RunTables::finish`]ed; until then they are written with [`PARTIAL_SUFFIX`]).
    pub fn paths(&self) -> [&Path; 3] {
        [&self.paths[0], &self.paths[1], &self.paths[2]]
    }

    /// The path of `fields.csv` ([`FIELDS_TABLE`]; written as `fields.csv.partial` until
    /// [`RunTables::finish`]), `None` when the scene records no fields
    /// ([`crate::SceneBuilder::record_fields`]).
    pub fn fields_path(&self) -> Option<&Path> {
        self.fields.as_ref().map(|f| f.path.as_path())
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
            .map_err(|e| Error::io("writing table", &self.partials[0], e))?;
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
                driver.real_contact_area()?,
                ell,
                ell / driver.grid().block().lx(),
                u8::from(exceeds),
            )
            .map_err(|e| Error::io("writing table", &self.partials[1], e))?;
            let x = load.force / mu_fn;
            if let Some(fields) = &mut self.fields {
                fields.record(driver, index, x, ell / driver.grid().block().lx())?;
            }
            self.map_rows_below(x, true)?;
            self.in_effect = Some(MapState {
                event: index,
                columns: driver.column_contact_area()?,
            });
        }
        if let Event::GlobalSlip { load } = *event {
            let mu_fn = driver.friction_coefficient() * driver.normal_load();
            self.map_rows_below(load.force / mu_fn, false)?;
            self.slipped = true;
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
                .map_err(|e| Error::io("writing table", &self.partials[2], e))?;
            self.next_level += 1;
        }
        Ok(())
    }

    /// Writes the rows so far to disk (flushed and synced): call it before a checkpoint is
    /// written, so that the tables reach the checkpoint's event whatever happens next.
    ///
    /// # Errors
    /// [`Error::Io`] when a file cannot be written or synced.
    pub fn flush(&mut self) -> Result<()> {
        for (table, path) in [
            (&mut self.events, &self.partials[0]),
            (&mut self.curve, &self.partials[1]),
            (&mut self.map, &self.partials[2]),
        ] {
            table
                .flush()
                .and_then(|()| table.get_ref().sync_data())
                .map_err(|e| Error::io("writing table", path, e))?;
        }
        if let Some(fields) = &mut self.fields {
            fields
                .file
                .flush()
                .and_then(|()| fields.file.get_ref().sync_data())
                .map_err(|e| Error::io("writing table", &fields.partial, e))?;
        }
        Ok(())
    }

    /// Runs `driver` to global slip writing its tables (feature `serde`): each event
    /// [recorded](RunTables::record), then `observe` called with it and the driver in the
    /// state right after it; with `checkpoint = Some((path, every))`, at every `every`-th
    /// stable state recorded by this writer, the tables [flushed](RunTables::flush) and a
    /// checkpoint written over `path` ([`crate::Checkpoint::write_to`]), so a resume finds
    /// every row up to it; at global slip, the tables [finished](RunTables::finish).
    /// Returns the tables' paths. The one run loop of the program's `run` and `resume` and
    /// of a sweep's runs.
    ///
    /// ```
    /// use precursors::{output::RunTables, Event, Scene};
    /// let scene = Scene::builder()
    ///     .block(0.012, 0.002, 0.010)
    ///     .normal_load(50.0)
    ///     .seed(0)
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// # let out = std::env::temp_dir().join(format!("precursors-doc-run-{}", std::process::id()));
    /// # std::fs::create_dir_all(&out).unwrap();
    /// let tables = RunTables::create(&out, &driver)?;
    /// let mut ruptures = 0;
    /// let [events, _curve, _map] = tables.run_to_slip(&mut driver, None, |event, _| {
    ///     ruptures += matches!(event, Event::Rupture { .. }) as usize;
    /// })?;
    /// assert!(events.is_file() && ruptures > 0);
    /// # std::fs::remove_dir_all(&out).ok();
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// The first error of [`Driver::step`], [`RunTables::record`], [`RunTables::flush`],
    /// [`crate::Checkpoint::write_to`] or [`RunTables::finish`].
    #[cfg(feature = "serde")]
    pub fn run_to_slip(
        mut self,
        driver: &mut Driver,
        checkpoint: Option<(&Path, std::num::NonZeroU64)>,
        mut observe: impl FnMut(&Event, &Driver),
    ) -> Result<[PathBuf; 3]> {
        if let Some((path, _)) = checkpoint {
            check_output_path(&self.dir, path)?;
        }
        while let Some(event) = driver.step()? {
            self.record(driver, &event)?;
            if let (Event::Stable { .. }, Some((path, every))) = (&event, checkpoint) {
                if (self.stable_states() as u64).is_multiple_of(every.get()) {
                    self.flush()?;
                    driver.checkpoint().write_to(path)?;
                }
            }
            observe(&event, driver);
        }
        self.finish()
    }

    /// Ends a run that reached global slip: the tables are flushed, synced and renamed
    /// from `NAME.partial` to `NAME` (replacing those of an earlier run), and the
    /// directory's lock (if this writer took it) is released. Returns the tables' paths.
    ///
    /// # Errors
    /// [`Error::RunDirectory`] when global slip was not recorded (the tables stay
    /// `.partial`); [`Error::Io`] when a table cannot be written, synced or renamed.
    pub fn finish(mut self) -> Result<[PathBuf; 3]> {
        if !self.slipped {
            return Err(Error::RunDirectory {
                path: self.dir.clone(),
                reason: format!(
                    "the run has not reached global slip: its tables stay \
                     NAME{PARTIAL_SUFFIX}"
                ),
            });
        }
        self.flush()?;
        // events.csv last: a crash between the renames leaves it .partial, so a resume
        // or a rerun still sees the run as not finished.
        if let Some(fields) = &self.fields {
            fs::rename(&fields.partial, &fields.path)
                .map_err(|e| Error::io("renaming table", &fields.path, e))?;
        }
        for t in [2, 1, 0] {
            fs::rename(&self.partials[t], &self.paths[t])
                .map_err(|e| Error::io("renaming table", &self.paths[t], e))?;
        }
        sync_dir(&self.dir).map_err(|e| Error::io("syncing directory", &self.dir, e))?;
        Ok(self.paths.clone())
    }
}

/// Removes the temporary files of the tables and the scene record that a writer killed
/// while writing one left in `dir`; only the lock holder writes them.
fn remove_stale_temporaries(dir: &Path) -> Result<()> {
    let names: Vec<String> = TABLE_NAMES
        .iter()
        .map(|n| format!("{n}{PARTIAL_SUFFIX}"))
        .chain([
            SCENE_RECORD.to_string(),
            format!("{FIELDS_TABLE}{PARTIAL_SUFFIX}"),
        ])
        .collect();
    crate::files::remove_temporaries(dir, &names)
}

/// Removes the figures and movies of an earlier run from `dir` ([`layout::derived`]): they
/// would stand beside tables they were not drawn from.
fn remove_derived(dir: &Path) -> Result<()> {
    let entries = fs::read_dir(dir).map_err(|e| Error::io("reading directory", dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| Error::io("reading directory", dir, e))?;
        let is_file = entry.file_type().is_ok_and(|t| !t.is_dir());
        if is_file && entry.file_name().to_str().is_some_and(layout::derived) {
            match fs::remove_file(entry.path()) {
                Err(e) if e.kind() != io::ErrorKind::NotFound => {
                    return Err(Error::io(
                        "removing the earlier run's figure",
                        entry.path(),
                        e,
                    ))
                }
                _ => {}
            }
        }
    }
    Ok(())
}

/// Removes `fields.csv` and `fields.csv.partial` from `dir` (where they exist).
fn remove_fields(dir: &Path) -> Result<()> {
    let (path, partial) = FieldsTable::paths(dir);
    for path in [path, partial] {
        match fs::remove_file(&path) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => {
                return Err(Error::io("removing the earlier run's table", &path, e))
            }
            _ => {}
        }
    }
    Ok(())
}

/// Refuses a directory whose recorded scene is not `driver`'s, or that records none.
#[cfg(feature = "serde")]
fn check_scene_record(dir: &Path, driver: &Driver) -> Result<()> {
    let path = dir.join(SCENE_RECORD);
    let text = match read_text_if_exists(&path, "reading the scene record")? {
        Some(text) => text,
        None => {
            return Err(Error::RunDirectory {
                path: dir.to_path_buf(),
                reason: format!(
                    "it holds no {SCENE_RECORD}, the record of the scene its tables belong to \
                     (written when a run starts), so the checkpoint cannot be checked against \
                     them: run the scene again into this directory, or resume into a copy of \
                     the directory of the checkpoint's run"
                ),
            })
        }
    };
    let recorded = crate::SceneBuilder::from_json_str(&text).map_err(|e| Error::RunDirectory {
        path: path.clone(),
        reason: format!("not a scene file ({e})"),
    })?;
    match crate::driver::scene_mismatch(
        &driver.scene().to_builder(),
        "the checkpoint's scene",
        &recorded,
        &format!("the scene recorded in {}", path.display()),
    ) {
        Some(e) => Err(e),
        None => Ok(()),
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
pub(crate) fn counts(states: &[SiteState]) -> (usize, usize) {
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

/// The rows a resume reads back (`RunTables::resume`).
#[cfg(test)]
mod tests {
    use super::{complete_rows, index_of};

    const HEADER: &str = "index,kind,force_N";

    fn rows(text: &str) -> Result<Vec<&str>, String> {
        Ok(complete_rows(text, HEADER)?
            .into_iter()
            .map(|(_, r)| r)
            .collect())
    }

    #[test]
    fn a_row_cut_by_a_crash_is_dropped_and_other_damage_refused() {
        let full = "index,kind,force_N\n1,stable,0.0\n2,load_raised,1.5\n3,rupture,1.5\n";
        assert_eq!(
            rows(full).unwrap(),
            ["1,stable,0.0", "2,load_raised,1.5", "3,rupture,1.5"]
        );
        // A crash cut the last row: within its index ("12" of "1234"), within a field,
        // or after the last field but before the newline. Each is dropped.
        let kept = "index,kind,force_N\n1,stable,0.0\n2,load_raised,1.5\n";
        for cut in ["2", "2,load_r", "3,rupture,1.5", "3,rupture"] {
            let damaged = format!("{kept}{cut}");
            assert_eq!(rows(&damaged).unwrap().len(), 2, "cut {cut:?}");
        }
        // A complete last line with too few fields (a crash between two writes of a row).
        assert_eq!(rows(&format!("{kept}3,rupture\n")).unwrap().len(), 2);
        // The same damage before the last row, another header: refused.
        assert!(rows("index,kind,force_N\n1,stable\n2,stable,1.0\n").is_err());
        assert!(rows("event,force_N\n1,0.0\n").is_err());
        // A bad index is refused where the index is read.
        assert!(index_of(2, "x,stable,0.0").is_err());
        assert_eq!(index_of(2, "12,stable,0.0"), Ok(12));
        // An empty file has no rows.
        assert!(rows("").unwrap().is_empty());
    }
}
