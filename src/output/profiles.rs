//! `profiles.csv`: the interface and stress profiles along `x`, averaged over `y`, in the
//! stable state in effect at each load a run records ([`crate::RunOptions::record_profiles`]).
//! One job: the table's rule, its writer, its row check, what a resume keeps of it and
//! the check of a finished run's table.
//!
//! **The rule.** Levels (loads `F/(μF_N)`, increasing) are passed in order. When a stable
//! state at load `x` is reached, every level not yet passed and below `x` gets a row group
//! of the state in effect until then (the last stable state before it); at global slip,
//! every level below its load does. Levels below the first stable state's load, and those
//! the run never passes, have no rows. Where the load drops (a driving spring's slip), a
//! level's rows are the state in effect when the load first passed it, as in
//! `contact_map.csv`. Loads are compared as written (13 significant digits), so that a
//! resume and the check of a finished run apply the rule to the same numbers.

use super::check::{self, Bad, Row};
use super::layout::PROFILES_TABLE;
use super::PARTIAL;
use crate::driver::Driver;
use crate::error::{Error, Result};
use crate::probe::{ProbeSpec, StressProbe};
use crate::recording::RunOptions;
use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The fields of a level's rows at the interface (`z_m` 0), in order: `⟨u_x⟩_y` (m),
/// `⟨φ_x⟩_y` and `⟨φ_z⟩_y` (Pa; [`crate::SlipProfile`]).
pub(crate) const INTERFACE_FIELDS: [&str; 3] =
    ["slip_m", "shear_traction_Pa", "normal_traction_Pa"];
/// Then per recorded plane (`z_m` its height), the fields of [`crate::Profile`] (Pa).
pub(crate) const PLANE_FIELDS: [&str; 4] = [
    "shear_Pa",
    "normal_Pa",
    "coulomb_of_means_Pa",
    "mean_coulomb_Pa",
];

/// The header of `profiles.csv` for a grid of `nx` columns.
pub(crate) fn header(nx: usize) -> String {
    let mut header = String::from("level,event,force_over_mu_FN,field,z_m");
    for ix in 0..nx {
        header.push_str(&format!(",value_ix{ix}"));
    }
    header
}

/// A number as the tables write it, and the value read back from that text.
fn written(x: f64) -> (String, f64) {
    let text = format!("{x:.12e}");
    let value = text.parse().unwrap_or(x);
    (text, value)
}

/// The rows of a level group: interface fields, then each plane's.
fn group_len(planes: usize) -> usize {
    INTERFACE_FIELDS.len() + PLANE_FIELDS.len() * planes
}

/// The field and height of row `within` of a level group.
fn field_of(within: usize, planes: &[f64]) -> (&'static str, f64) {
    match within.checked_sub(INTERFACE_FIELDS.len()) {
        None => (INTERFACE_FIELDS[within], 0.0),
        Some(k) => (
            PLANE_FIELDS[k % PLANE_FIELDS.len()],
            planes[k / PLANE_FIELDS.len()],
        ),
    }
}

/// Which levels the states of a run pass (module docs, "The rule").
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Levels {
    levels: Vec<f64>,
    /// The first level not yet passed.
    next: usize,
    /// A stable state was reached.
    started: bool,
}

impl Levels {
    pub(crate) fn new(levels: &[f64]) -> Self {
        Self {
            levels: levels.to_vec(),
            next: 0,
            started: false,
        }
    }

    /// The levels the state in effect until now covers when a load `x` is reached (a new
    /// stable state, `stable`, or global slip); none before the first state.
    pub(crate) fn pass(&mut self, x: f64, stable: bool) -> Range<usize> {
        let start = self.next;
        while self.levels.get(self.next).is_some_and(|&l| l < x) {
            self.next += 1;
        }
        if !self.started {
            self.started = stable;
            return self.next..self.next;
        }
        start..self.next
    }

    /// Levels are left to pass.
    pub(crate) fn pending(&self) -> bool {
        self.next < self.levels.len()
    }
}

/// The row groups the rule gives for stable states `(event, F/(μF_N))`, in order, then
/// global slip at `slip`: `(level index, event of the state in effect)`.
pub(crate) fn groups(
    levels: &[f64],
    states: &[(usize, f64)],
    slip: Option<f64>,
) -> (Vec<(usize, usize)>, Levels) {
    let mut rule = Levels::new(levels);
    let mut out = Vec::new();
    let mut in_effect = None;
    for &(event, x) in states {
        if let Some(e) = in_effect {
            out.extend(rule.pass(x, true).map(|l| (l, e)));
        } else {
            rule.pass(x, true);
        }
        in_effect = Some(event);
    }
    if let (Some(x), Some(e)) = (slip, in_effect) {
        out.extend(rule.pass(x, false).map(|l| (l, e)));
    }
    (out, rule)
}

/// The stresses on the recorded `planes`, planned on `driver`'s scene operator at its
/// probes' tolerance (`None` without planes); `fields.csv`'s writer takes it too.
/// Asserted unwind-safe so that the tables stay so: the probe is only read after it is
/// built (its transforms' plans are immutable), so a panic cannot leave it half changed.
pub(super) fn planes_probe(
    driver: &Driver,
    planes: &[f64],
) -> Result<Option<std::panic::AssertUnwindSafe<StressProbe>>> {
    if planes.is_empty() {
        return Ok(None);
    }
    let scene = driver.scene();
    let spec = planes.iter().fold(
        ProbeSpec::default().with_tolerance(scene.probes().tolerance())?,
        |spec, &z| spec.with_plane(z),
    );
    let probe = crate::scene::plan_probes(scene.plan(), &spec, scene.lateral_load())?;
    Ok(probe.map(std::panic::AssertUnwindSafe))
}

/// A stable state's profiles, rendered (all but the level column).
#[derive(Debug)]
struct State {
    /// `event,force_over_mu_FN,` of its rows.
    prefix: String,
    /// `field,z_m,values` of each row.
    rows: Vec<String>,
}

/// `profiles.csv` of a run that records profiles.
#[derive(Debug)]
pub(super) struct ProfilesTable {
    file: super::TableFile,
    path: PathBuf,
    partial: PathBuf,
    rule: Levels,
    /// The levels as written.
    level_texts: Vec<String>,
    planes: Vec<f64>,
    /// The recorded planes, planned on the scene's operator (`None` without planes);
    /// unwind-safe as `FieldsTable`'s.
    probe: Option<std::panic::AssertUnwindSafe<StressProbe>>,
    in_effect: Option<State>,
}

impl ProfilesTable {
    /// `dir/profiles.csv` and `dir/profiles.csv.partial`.
    pub(super) fn paths(dir: &Path) -> (PathBuf, PathBuf) {
        (
            dir.join(PROFILES_TABLE),
            dir.join(format!("{PROFILES_TABLE}{PARTIAL}")),
        )
    }

    /// The writer of `driver`'s profiles into `file`, the rule at `rule` (a new run's, or
    /// a resumed one's with the state in effect `driver`'s); `None` when `options` record
    /// none.
    pub(super) fn new(
        driver: &Driver,
        options: &RunOptions,
        dir: &Path,
        file: impl FnOnce(&Path) -> Result<super::TableFile>,
        rule: Levels,
    ) -> Result<Option<Self>> {
        let loads = options.profile_loads();
        if loads.is_empty() {
            return Ok(None);
        }
        let planes = options.profile_planes().to_vec();
        let probe = planes_probe(driver, &planes)?;
        let (path, partial) = Self::paths(dir);
        let resumed = rule.started;
        let mut table = Self {
            file: file(&partial)?,
            path,
            partial,
            level_texts: loads.iter().map(|&l| written(l).0).collect(),
            rule,
            planes,
            probe,
            in_effect: None,
        };
        if resumed && table.rule.pending() {
            table.in_effect = Some(table.state(driver, driver.event_count(), driver.force())?);
        }
        Ok(Some(table))
    }

    /// The profiles of `driver`'s state (event `event`, load `force` N).
    fn state(&self, driver: &Driver, event: usize, force: f64) -> Result<State> {
        let mu_fn = driver.friction_limit();
        let mut rows = Vec::with_capacity(group_len(self.planes.len()));
        let mut row = |field: &str, z: f64, values: &[f64]| {
            let mut text = format!("{field},{z:.12e}");
            for v in values {
                text.push_str(&format!(",{v:.12e}"));
            }
            rows.push(text);
        };
        let slip = driver.slip_profile()?;
        row(INTERFACE_FIELDS[0], 0.0, slip.slip());
        row(INTERFACE_FIELDS[1], 0.0, slip.shear_traction());
        row(INTERFACE_FIELDS[2], 0.0, slip.normal_traction());
        if let Some(probe) = &self.probe {
            let stresses = driver.stresses_at(std::slice::from_ref(&probe.0))?;
            for (plane, &z) in stresses.planes.iter().zip(&self.planes) {
                let p = plane.profile();
                for (field, values) in PLANE_FIELDS.iter().zip([
                    p.shear(),
                    p.normal(),
                    p.coulomb_of_means(),
                    p.mean_coulomb(),
                ]) {
                    row(field, z, values);
                }
            }
        }
        Ok(State {
            prefix: format!("{event},{}", written(force / mu_fn).0),
            rows,
        })
    }

    /// The rows of the levels a new stable state (event `event`, load `force` N) or
    /// global slip (`stable` false) passes, from the state in effect until then; then the
    /// new state's profiles, while levels are left.
    pub(super) fn reach(
        &mut self,
        driver: &Driver,
        event: usize,
        force: f64,
        stable: bool,
    ) -> Result<()> {
        let mu_fn = driver.friction_limit();
        // As `events.csv` and `curve.csv` write it, so that a check reads the same load.
        let x = if stable {
            written(force / mu_fn).1
        } else {
            written(force).1 / mu_fn
        };
        let passed = self.rule.pass(x, stable);
        if let Some(state) = &self.in_effect {
            let mut text = String::new();
            for level in &self.level_texts[passed] {
                for row in &state.rows {
                    text.push_str(&format!("{level},{},{row}\n", state.prefix));
                }
            }
            self.file
                .write_all(text.as_bytes())
                .map_err(|e| Error::io("writing table", &self.partial, e))?;
        }
        self.in_effect = if stable && self.rule.pending() {
            Some(self.state(driver, event, force)?)
        } else {
            None
        };
        Ok(())
    }

    /// Flushes and syncs the table.
    pub(super) fn flush(&mut self) -> Result<()> {
        self.file
            .sync()
            .map_err(|e| Error::io("writing table", &self.partial, e))
    }

    /// What a checkpoint records of the rows written so far.
    pub(super) fn digest(&self) -> crate::driver::TableDigest {
        self.file.digest(PROFILES_TABLE)
    }

    /// Renames the table to its name.
    pub(super) fn rename(&self) -> Result<()> {
        super::rename_table(&self.partial, &self.path)
    }
}

/// A row of `profiles.csv`, checked.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ProfileRow {
    /// The level's index among the recorded loads.
    pub level: usize,
    pub event: usize,
    /// `F/(μF_N)` of the state (as written, and its value).
    pub load_text: String,
    pub load: f64,
    pub field: &'static str,
    pub z: f64,
    pub values: Vec<f64>,
}

/// Checks row `within` of a level group (line `line`, `header`'s cells): the level among
/// `levels` (as written), the field and height the group's order gives, finite values.
pub(crate) fn row(
    line: usize,
    header: &[&str],
    row: &str,
    within: usize,
    levels: &[String],
    planes: &[f64],
) -> Row<ProfileRow> {
    let c = check::cells(line, header, row)?;
    let Some(level) = levels.iter().position(|l| l == c[0]) else {
        return Err(check::at(
            line,
            header[0],
            format!(
                "{:?} is not one of the recorded loads `profiles.loads`",
                c[0]
            ),
        ));
    };
    let event = check::count(line, header, &c, 1)?;
    let load = check::number(line, header, &c, 2)?;
    if load.abs() > check::LOAD_LIMIT {
        return Err(check::at(
            line,
            header[2],
            format!("{load} is beyond the friction limit 1"),
        ));
    }
    let (field, z) = field_of(within, planes);
    if c[3] != field {
        return Err(format!(
            "line {line}: a level's rows are {} at the interface, then {} per recorded plane \
             ({}): {field} belongs here, not {:?}",
            INTERFACE_FIELDS.join(", "),
            PLANE_FIELDS.join(", "),
            planes.len(),
            c[3]
        )
        .into());
    }
    let found = check::number(line, header, &c, 4)?;
    if (found - z).abs() > 1e-12 * z.abs() {
        return Err(check::at(
            line,
            header[4],
            format!("{:?}: this row lies at z = {z} m (`profiles.planes`)", c[4]),
        ));
    }
    let values = (5..c.len())
        .map(|k| check::number(line, header, &c, k))
        .collect::<Row<Vec<f64>>>()?;
    Ok(ProfileRow {
        level,
        event,
        load_text: c[2].to_string(),
        load,
        field,
        z,
        values,
    })
}

/// The `rows` (line, text) of a whole `profiles.csv` under its header, or of the part a
/// resume keeps, checked one by one and against `expected` row groups (`(level, event)`
/// from [`groups`]; `partial`: the table may go on beyond them, the rows that do are not
/// returned) and the loads of the stable states (`load_text(event)`, as `curve.csv`
/// writes it).
pub(crate) fn check_rows(
    rows: &[(usize, &str)],
    options: &RunOptions,
    nx: usize,
    expected: &[(usize, usize)],
    load_text: impl Fn(usize) -> Option<String>,
    partial: bool,
) -> Row<Vec<ProfileRow>> {
    let header_text = header(nx);
    let header: Vec<&str> = header_text.split(',').collect();
    let levels: Vec<String> = options
        .profile_loads()
        .iter()
        .map(|&l| written(l).0)
        .collect();
    let planes = options.profile_planes();
    let per_group = group_len(planes.len());
    let mut out = Vec::with_capacity(expected.len() * per_group);
    for (n, &(line, text)) in rows.iter().enumerate() {
        let (group, within) = (n / per_group, n % per_group);
        let Some(&(level, event)) = expected.get(group) else {
            if partial {
                break;
            }
            return Err(format!(
                "line {line}: the run passes {} of the recorded loads, this row is beyond them",
                expected.len()
            )
            .into());
        };
        let r = row(line, &header, text, within, &levels, planes)?;
        if (r.level, r.event) != (level, event) {
            return Err(format!(
                "line {line}: level {} holds the state of event {}, but the state in effect \
                 there is event {event} at level {} (`profiles.loads` {}: the stable state \
                 reached last at or below each load)",
                levels[r.level],
                r.event,
                levels[level],
                levels.join(", ")
            )
            .into());
        }
        if load_text(event).as_deref() != Some(r.load_text.as_str()) {
            return Err(format!(
                "line {line}: event {event} at F/(μF_N) = {}, but curve.csv has {}",
                r.load_text,
                load_text(event).unwrap_or_else(|| "no such state".into())
            )
            .into());
        }
        out.push(r);
    }
    if out.len() < expected.len() * per_group {
        let group = out.len() / per_group;
        return Err(Bad::Reason(format!(
            "it holds {group} whole level groups, the run passes {} of the recorded loads \
             (`profiles.loads`): the rows of level {} are missing",
            expected.len(),
            levels[expected[group].0]
        )));
    }
    Ok(out)
}

/// What a resumed run keeps of `profiles.csv` (`old`, read from `path`; `None` when
/// missing): the header and the row groups the stable states up to the checkpoint's
/// (`states`: `(event, F/(μF_N))` as written, `load_text` their loads' text) passed,
/// every row checked; a last row cut by a crash dropped. Returns the text and the rule
/// where it stands, the checkpoint's state in effect.
pub(super) fn continuation(
    old: Option<&str>,
    path: &Path,
    options: &RunOptions,
    nx: usize,
    states: &[(usize, f64)],
    load_text: impl Fn(usize) -> Option<String>,
) -> Result<(String, Levels)> {
    let header_text = header(nx);
    let rows = super::resume::complete_rows(old.unwrap_or(""), &header_text).map_err(|r| {
        Error::CorruptTable {
            path: Some(path.to_path_buf()),
            reason: r,
        }
    })?;
    let (expected, rule) = groups(options.profile_loads(), states, None);
    let kept = check_rows(&rows, options, nx, &expected, load_text, true).map_err(|b| match b {
        Bad::Reason(r) => Error::CorruptTable {
            path: Some(path.to_path_buf()),
            reason: format!(
                "{r} (recorded with other `profiles`, or without them: run the scene again \
                 to record them)"
            ),
        },
        b => b.at(path),
    })?;
    let mut text = format!("{header_text}\n");
    for (_, row) in &rows[..kept.len()] {
        text.push_str(row);
        text.push('\n');
    }
    Ok((text, rule))
}

/// Reads and checks `profiles.csv` of the finished run `record` read from `dir` (present
/// exactly when the run records profiles: `None` when it records none): every row, and
/// every level the run passes, each the state in effect there (the module's rule).
///
/// # Errors
/// [`Error::CorruptTable`] naming the file, line and column; [`Error::NonFiniteCell`];
/// [`Error::Io`].
#[cfg(feature = "serde")]
#[cfg_attr(not(feature = "plot"), allow(dead_code))] // the figures read it
pub(crate) fn read(dir: &Path, record: &check::RunRecord) -> Result<Option<Vec<ProfileRow>>> {
    let path = dir.join(PROFILES_TABLE);
    let options = &record.options;
    if options.profile_loads().is_empty() {
        return match path.is_file() {
            false => Ok(None),
            true => Err(Error::CorruptTable {
                path: Some(path),
                reason: format!(
                    "the run's scene ({}) records no profiles: the table is another run's",
                    super::RUN_SCENE
                ),
            }),
        };
    }
    let text = crate::files::read_text(&path, "reading table")?;
    let curve = &record.curve;
    let states: Vec<(usize, f64)> = curve.iter().map(|c| (c.event, c.load)).collect();
    let (expected, _) = groups(options.profile_loads(), &states, Some(record.slip));
    let load_text = |event: usize| {
        curve
            .binary_search_by_key(&event, |c| c.event)
            .ok()
            .map(|k| curve[k].load_text.clone())
    };
    check::rows(&text, &header(record.bounds.nx))
        .and_then(|rows| {
            check_rows(
                &rows,
                options,
                record.bounds.nx,
                &expected,
                load_text,
                false,
            )
        })
        .map(Some)
        .map_err(|bad| bad.at(&path))
}
