//! What a resume keeps of a run's tables (`RunTables::resume`): the rows up to the
//! checkpoint's event, each table checked whole and against the others and the
//! checkpoint before anything is cut, every kept row checked as `check` checks a
//! finished table's. Nothing here writes.

use super::{
    check, contact_map_header, fields_header, first_level_at_or_above, level, CURVE_COLUMNS_1_1,
    CURVE_HEADER, EVENTS_HEADER, MAP_STEP,
};
use crate::contact::{ContactRule, Replay, SiteChange};
use crate::driver::{Event, RowDifference, TableDigest};
use crate::error::{Error, Result};
use crate::interface::SiteState;
use std::path::{Path, PathBuf};

/// The complete rows of a table's text (line number, row), its header checked: a last
/// row cut by a crash (no trailing newline, or not as many fields as the header) is left
/// out; the same damage on an earlier row is refused.
pub(super) fn complete_rows<'a>(
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
pub(super) struct Continuation {
    pub(super) texts: [String; 3],
    pub(super) next_level: u64,
    pub(super) in_effect: bool,
    /// The events of the stable states up to the checkpoint's.
    pub(super) stable: Vec<usize>,
    /// Their loads `F/(μF_N)` as `curve.csv` writes them.
    pub(super) loads: Vec<f64>,
    /// The kept events that change a site's state (ruptures, detachments, attachments),
    /// with their lines in `events.csv`.
    pub(super) site_events: Vec<(usize, Event)>,
}

impl Continuation {
    /// The text table `t` is continued from: the kept text, with `curve.csv`'s rows of a
    /// run 1.1 began brought to [`CURVE_HEADER`] (their slip columns empty: the states
    /// are gone). The kept texts ([`Continuation::texts`]) are what checkpoints' digests
    /// cover.
    pub(super) fn written(&self, t: usize) -> std::borrow::Cow<'_, str> {
        let text = &self.texts[t];
        if t != 1 || check::curve_header_of(text) == CURVE_HEADER {
            return text.into();
        }
        let empty = ",".repeat(CURVE_HEADER.split(',').count() - CURVE_COLUMNS_1_1);
        let mut out = format!("{CURVE_HEADER}\n");
        for row in text.lines().skip(1) {
            out.push_str(row);
            out.push_str(&empty);
            out.push('\n');
        }
        out.into()
    }
}

/// Checks the three tables (`old[t]`: the text of table `t` (`events.csv`, `curve.csv`, `contact_map.csv`)
/// order, `None` when missing; `paths` for the messages) against each other and against
/// the checkpoint's event `k` and load `force_at_k`, and cuts them back to it: to the
/// rows of the events up to `k`, and `contact_map.csv` to the `map_rows` rows the
/// checkpoint covers where it records them (rows of the state at `k` written after it
/// are written again). Nothing is written.
pub(super) fn continuation(
    old: [Option<&str>; 3],
    paths: &[PathBuf; 3],
    (k, map_rows): (usize, Option<u64>),
    bounds: &check::Bounds,
    force_at_k: f64,
) -> Result<Continuation> {
    let map_header = contact_map_header(bounds.nx);
    // A run begun by 1.1 wrote `curve.csv` without the slip columns: it is continued
    // with them, empty on the kept rows (`Continuation::written`).
    let curve_header = old[1].map_or(CURVE_HEADER, check::curve_header_of);
    let headers = [EVENTS_HEADER, curve_header, map_header.as_str()];
    let cut = Cut {
        paths,
        k,
        map_rows,
        bounds,
        curve_header,
    };
    // Every table's header and rows first, so a damaged third table refuses the resume
    // before anything is cut.
    let mut rows: [Vec<(usize, &str)>; 3] = Default::default();
    for t in 0..3 {
        rows[t] = complete_rows(old[t].unwrap_or(""), headers[t]).map_err(|r| cut.corrupt(t, r))?;
    }
    let [events, curve, map] = rows;
    let (stable, forces, site_events) = cut.events(&events, old[0].is_none(), force_at_k)?;
    let loads = cut.curve(&curve, &stable, &forces)?;
    let (kept_levels, next_level) = cut.map(&map, &map_header, &stable, &loads)?;

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
            text(curve_header, &curve, loads.len()),
            text(&map_header, &map, kept_levels),
        ],
        next_level,
        in_effect: k > 0,
        stable,
        loads,
        site_events,
    })
}

/// The tables of a run cut back to a checkpoint's event `k`, one function per table.
struct Cut<'a> {
    paths: &'a [PathBuf; 3],
    k: usize,
    /// The rows of `contact_map.csv` the checkpoint covers, where it records them.
    map_rows: Option<u64>,
    bounds: &'a check::Bounds,
    /// The header `curve.csv` was written with.
    curve_header: &'a str,
}

impl Cut<'_> {
    fn corrupt(&self, t: usize, reason: String) -> Error {
        Error::CorruptTable {
            path: Some(self.paths[t].clone()),
            reason,
        }
    }

    /// `events.csv`: rows 1, 2, 3, ... (one run's), up to at least `k`, each kept row
    /// checked, `k` a stable state at the checkpoint's load. Returns the events of the
    /// stable states up to `k`, their `force_N` as written, and the kept events that
    /// change a site's state with their lines.
    #[allow(clippy::type_complexity)]
    fn events(
        &self,
        events: &[(usize, &str)],
        missing: bool,
        force_at_k: f64,
    ) -> Result<(Vec<usize>, Vec<String>, Vec<(usize, Event)>)> {
        let k = self.k;
        let mut last = 0;
        let mut stable = Vec::new();
        let mut stable_forces = Vec::new();
        let mut site_events = Vec::new();
        let mut kind_at_k = "";
        for &(line, row) in events {
            let index = index_of(line, row).map_err(|r| self.corrupt(0, r))?;
            if index != last + 1 {
                return Err(self.corrupt(
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
            let e = check::event_row(line, row, self.bounds).map_err(|b| b.at(&self.paths[0]))?;
            if e.kind == "global_slip" {
                return Err(self.corrupt(
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
            // The stable states keep the replay's clock (a re-forming rule's).
            if let Event::Rupture { .. }
            | Event::Detach { .. }
            | Event::Attach { .. }
            | Event::Stable { .. } = e.event
            {
                site_events.push((line, e.event));
            }
            if index == k {
                kind_at_k = e.kind;
            }
        }
        if last < k {
            let what = if missing {
                "the table is missing".to_string()
            } else {
                format!("the table ends at event {last}")
            };
            return Err(self.corrupt(
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
                return Err(self.corrupt(
                    0,
                    format!(
                        "event {k} is at force_N {force}, the checkpoint's load is {checkpoint} N: \
                         the table or the checkpoint was edited"
                    ),
                ));
            }
        }
        Ok((stable, stable_forces, site_events))
    }

    /// `curve.csv`: one row per stable state of `events.csv` up to `k`, in order, at the
    /// same `force_N`. Returns their loads `F/(μF_N)`.
    fn curve(
        &self,
        curve: &[(usize, &str)],
        stable: &[usize],
        stable_forces: &[String],
    ) -> Result<Vec<f64>> {
        let k = self.k;
        let mut loads = Vec::with_capacity(stable.len());
        let mut previous = 0;
        for &(line, row) in curve {
            let event = index_of(line, row).map_err(|r| self.corrupt(1, r))?;
            if event <= previous {
                return Err(self.corrupt(
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
                    return Err(self.corrupt(
                        1,
                        format!(
                            "line {line} holds the state of event {event}, but the stable state \
                             of events.csv there is event {s}"
                        ),
                    ))
                }
                None => {
                    return Err(self.corrupt(
                        1,
                        format!("line {line}: event {event} is not a stable state of events.csv"),
                    ))
                }
            }
            let c = check::curve_row(line, row, self.bounds, self.curve_header)
                .map_err(|b| b.at(&self.paths[1]))?;
            let force = &stable_forces[loads.len()];
            if &c.force_text != force {
                return Err(self.corrupt(
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
            return Err(self.corrupt(
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
        Ok(loads)
    }

    /// `contact_map.csv`: consecutive levels from the first state's load, each row a
    /// stable state, reaching the levels below the highest load of the states up to `k`.
    /// Returns the rows kept and the next level.
    fn map(
        &self,
        map: &[(usize, &str)],
        map_header: &str,
        stable: &[usize],
        loads: &[f64],
    ) -> Result<(usize, u64)> {
        let kept_levels = self.map_levels(map, map_header, stable)?;
        let first = self.map_reach(&kept_levels, stable, loads)?;
        let next_level = kept_levels.last().map_or(first, |&l| l + 1);
        Ok((kept_levels.len(), next_level))
    }

    /// The levels of the rows of `contact_map.csv` up to the event `k`: consecutive, in
    /// the order of the events, each row checked and a stable state's.
    fn map_levels(
        &self,
        map: &[(usize, &str)],
        map_header: &str,
        stable: &[usize],
    ) -> Result<Vec<u64>> {
        let mut kept_levels: Vec<u64> = Vec::new();
        let mut previous: Option<(u64, usize)> = None;
        let map_cells: Vec<&str> = map_header.split(',').collect();
        for &(line, row) in map {
            let event = index_of(line, row).map_err(|r| self.corrupt(2, r))?;
            let level = self.map_level(line, row)?;
            if let Some((l, e)) = previous {
                if level != l + 1 || event < e {
                    return Err(self.corrupt(
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
            // The first row past the checkpoint ends what is kept, once its level follows.
            if event > self.k || self.map_rows == Some(kept_levels.len() as u64) {
                break;
            }
            check::map_row(line, &map_cells, row).map_err(|b| b.at(&self.paths[2]))?;
            if stable.binary_search(&event).is_err() {
                return Err(self.corrupt(
                    2,
                    format!("line {line}: event {event} is not a stable state of events.csv"),
                ));
            }
            kept_levels.push(level);
        }
        Ok(kept_levels)
    }

    /// The level of the row `row` (line `line`) of `contact_map.csv`: its
    /// `force_over_mu_FN` as a whole number of [`MAP_STEP`]s.
    fn map_level(&self, line: usize, row: &str) -> Result<u64> {
        let level = row.split(',').nth(1).and_then(|f| f.parse::<f64>().ok());
        let step = level.map(|l| (l / MAP_STEP).round());
        match (level, step) {
            (Some(l), Some(s)) if l.is_finite() && s >= 0.0 && (s * MAP_STEP - l).abs() < 1e-9 => {
                Ok(s as u64)
            }
            _ => Err(self.corrupt(
                2,
                format!(
                    "line {line}: force_over_mu_FN is not a load level (a multiple of \
                     {MAP_STEP})"
                ),
            )),
        }
    }

    /// Checks that the kept levels of `contact_map.csv` start at the first stable state's
    /// load and reach the levels below the highest load of the states in `loads`; returns
    /// the first state's level.
    fn map_reach(&self, kept_levels: &[u64], stable: &[usize], loads: &[f64]) -> Result<u64> {
        let first = loads.first().map_or(0, |&x| first_level_at_or_above(x));
        if let Some(&l) = kept_levels.first() {
            if l != first {
                return Err(self.corrupt(
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
                return Err(self.corrupt(
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
        Ok(first)
    }
}

/// What the fields of a resumed run start from: `fields.csv`'s text (`old`, `None` when
/// missing; `path` for the messages) checked against the states the scene records up to
/// the checkpoint's event (the `every`-th of the stable states `stable`, `ny` rows of
/// area and one per plane of `planes` each) and cut back to them. Nothing is written.
pub(super) fn fields_continuation(
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

/// Refuses a resumed driver whose site states (`states`, from its checkpoint) are not
/// those the kept events of `events.csv` (`site_events`, read from `path`: the site
/// events and the stable states) leave under the run's contact rule (`rule`, [`Replay`];
/// `load_scale` is `μ F_N`, N): every site a rupture broke is broken and none broke
/// twice, no other site is broken, and a site's last detachment or attachment left it
/// detached or attached; under a re-forming rule a broken site attaches again, or is
/// detached, once its delay has passed, and only then. A checkpoint forged with a
/// recomputed digest (a broken site set back to attached) would otherwise run on and
/// break a site twice.
pub(super) fn check_site_states(
    rule: &ContactRule,
    load_scale: f64,
    site_events: &[(usize, Event)],
    states: &[SiteState],
    path: &Path,
) -> Result<()> {
    let mut replay = Replay::new(rule.clone(), states.len(), load_scale);
    for &(line, event) in site_events {
        let (site, change, force) = match event {
            Event::Rupture { site, load, .. } => (site, SiteChange::Rupture, load.force),
            Event::Detach { site } => (site, SiteChange::Detach, 0.0),
            Event::Attach { site } => (site, SiteChange::Attach, 0.0),
            Event::Stable { load, .. } => {
                replay.stable(load.force);
                continue;
            }
            _ => continue,
        };
        if let Err(broke) = replay.apply(site.index, change, line, force) {
            return Err(Error::CorruptTable {
                path: Some(path.to_path_buf()),
                reason: format!(
                    "line {line}: a {} of site ({}, {}), which broke on line {broke}: a broken \
                     site never changes again{}",
                    event.kind(),
                    site.ix,
                    site.iy,
                    match rule.delay() {
                        Some(_) => " but by attaching once its delay has passed",
                        None => "",
                    }
                ),
            });
        }
    }
    for (i, state) in states.iter().enumerate() {
        if let Some((expected, last)) = replay.mismatch(i, *state) {
            let since = match last {
                Some(line) => {
                    format!("line {line} of {} leaves it {expected:?}", path.display())
                }
                None => format!("no rupture of it is in {}", path.display()),
            };
            return Err(Error::InvalidCheckpoint {
                reason: format!(
                    "site {i} is {state:?} in the checkpoint, but {since}: the checkpoint or \
                     the table was edited"
                ),
            });
        }
    }
    Ok(())
}

/// Refuses kept rows that are not those a checkpoint covers (`covered`: its table
/// digests): `kept` names each table continued, the path it was read from and its kept
/// text (header first). A table the checkpoint covers and the resume does not continue,
/// or the reverse, is refused too (recorded with other observers).
pub(super) fn check_covered(covered: &[TableDigest], kept: &[(&str, &Path, &str)]) -> Result<()> {
    for digest in covered {
        if !kept.iter().any(|(name, _, _)| *name == digest.table()) {
            return Err(Error::InvalidCheckpoint {
                reason: format!(
                    "it covers {} rows of {}, a table this resume does not continue: the run \
                     recorded other observers (scene keys `fields`, `profiles`) than it is \
                     resumed with",
                    digest.rows(),
                    digest.table()
                ),
            });
        }
    }
    for &(name, path, text) in kept {
        let corrupt = |reason: String| Error::CorruptTable {
            path: Some(path.to_path_buf()),
            reason,
        };
        let Some(digest) = covered.iter().find(|d| d.table() == name) else {
            return Err(corrupt(
                "the checkpoint covers no rows of this table: it was recorded with other \
                 observers (scene keys `fields`, `profiles`) than the run is resumed with"
                    .into(),
            ));
        };
        let rows: Vec<&str> = text.lines().skip(1).collect();
        let line = |row: u64| row + 1; // the header is line 1
        let reason = match digest.difference(&rows) {
            None => continue,
            Some(RowDifference::Rows { first, last }) if first == last => format!(
                "line {}: the row differs from the one the checkpoint covers (its digest): \
                 the table was edited after the checkpoint was taken",
                line(first)
            ),
            Some(RowDifference::Rows { first, last }) => format!(
                "lines {} to {}: a row among them differs from those the checkpoint covers \
                 (its digests of the rows, one per {} rows): the table was edited after \
                 the checkpoint was taken",
                line(first),
                line(last),
                last + 1 - first
            ),
            Some(RowDifference::Missing { kept }) => format!(
                "it keeps {kept} rows, the checkpoint covers {}: rows were removed after it \
                 was taken",
                digest.rows()
            ),
            Some(RowDifference::Extra { covered }) => {
                format!("it keeps rows beyond the {covered} the checkpoint covers, up to its event")
            }
        };
        return Err(corrupt(reason));
    }
    Ok(())
}

/// A map level as the table writes it.
fn level_text(k: u64) -> String {
    format!("{:.3}", level(k))
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
