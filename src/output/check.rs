//! What a run's tables may hold, row by row, and the whole of a finished run as the
//! readers take it (`merge`, `plot`, `movie`; `RunTables::resume` checks the rows it
//! keeps with the same row checks): every cell parsed, finite and within its physical
//! bounds, the tables consistent with the run's scene (`scene.json`) and with each other.
//! A violation names the file, the line and the column.
//!
//! Why: a table cut short, edited, shuffled, or from another run was read as if whole
//! and turned into statistics and figures with exit 0.

#[cfg(feature = "serde")]
use super::{contact_map_header, first_level_at_or_above, level, TABLES};
use super::{curve_header_1_1, CURVE_COLUMNS_1_1, CURVE_HEADER, EVENTS_HEADER, MAP_STEP};
use crate::driver::{Event, Load, Site};
use crate::error::Error;
#[cfg(feature = "serde")]
use crate::error::Result;
use std::path::Path;

/// What is wrong with a row: a cell that is not a finite number (typed, as
/// [`Error::NonFiniteCell`]), or another reason (with its line and column).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Bad {
    NonFinite {
        line: usize,
        column: String,
        value: String,
    },
    Reason(String),
}

impl From<String> for Bad {
    fn from(reason: String) -> Self {
        Bad::Reason(reason)
    }
}

impl Bad {
    /// The error of the table `path`.
    pub(crate) fn at(self, path: &Path) -> Error {
        match self {
            Bad::NonFinite {
                line,
                column,
                value,
            } => Error::NonFiniteCell {
                path: path.to_path_buf(),
                line,
                column,
                value,
            },
            Bad::Reason(reason) => Error::CorruptTable {
                path: Some(path.to_path_buf()),
                reason,
            },
        }
    }
}

impl std::fmt::Display for Bad {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Bad::NonFinite {
                line,
                column,
                value,
            } => {
                write!(
                    f,
                    "line {line}, column {column}: {value:?} is not a finite number"
                )
            }
            Bad::Reason(reason) => f.write_str(reason),
        }
    }
}

/// A row's check.
pub(super) type Row<T> = std::result::Result<T, Bad>;

/// The largest `|F|/(μF_N)` of a stable state (the writer's limit, `map_rows_below`):
/// no stable state carries more than the friction limit.
pub(crate) const LOAD_LIMIT: f64 = 1.0 + 1e-5;

/// What the rows of a run's tables are checked against: its grid and friction limit.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Bounds {
    pub nx: usize,
    pub ny: usize,
    /// The block's length (m).
    pub lx: f64,
    /// `μF_N` (N): the friction limit (`Driver::friction_limit`).
    pub mu_fn: f64,
}

impl Bounds {
    /// The bounds of `driver`'s run.
    pub(crate) fn of(driver: &crate::driver::Driver) -> Bounds {
        let grid = driver.grid();
        Bounds {
            nx: grid.nx(),
            ny: grid.ny(),
            lx: grid.block().lx(),
            mu_fn: driver.friction_limit(),
        }
    }
}

/// The kinds of `events.csv`.
const KINDS: [&str; 6] = Event::KINDS;

/// A row of `events.csv`, checked.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct EventRow {
    pub index: usize,
    pub kind: &'static str,
    /// `force_N` as written (for the cross-check with `curve.csv`), and its value.
    pub force_text: String,
    pub force: Option<f64>,
    /// Ruptures of the avalanche that a stable state ends.
    pub ruptures: Option<usize>,
    /// The event the row records.
    pub event: Event,
}

/// A row of `curve.csv`, checked.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CurveRow {
    pub event: usize,
    pub force_text: String,
    /// `F/(μF_N)` as written (for the cross-check with `fields.csv`), and its value.
    pub load_text: String,
    pub load: f64,
    pub precursor_text: String,
    pub precursor_over_lx: f64,
    /// The real contact area (m²).
    pub area: f64,
    /// The slip per newton of load (`potency_m3_per_N`, `potency_moment_m4_per_N`,
    /// `load_compliance_m_per_N`); `None` on a row written by 1.1.
    pub slip: Option<[f64; 3]>,
}

/// A row of `contact_map.csv`, checked.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MapRow {
    pub event: usize,
    /// The level's index (`F/(μF_N)` = index · `0.005`).
    pub level: u64,
    /// The real contact area of each column (m²).
    pub columns: Vec<f64>,
}

/// A cell's problem as `line L, column NAME: ...`.
pub(super) fn at(line: usize, column: &str, what: impl std::fmt::Display) -> Bad {
    Bad::Reason(format!("line {line}, column {column}: {what}"))
}

/// The cell `k` (named by `header`'s `k`-th column) as a finite number.
pub(super) fn number(line: usize, header: &[&str], cells: &[&str], k: usize) -> Row<f64> {
    let text = cells[k];
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(Bad::NonFinite {
            line,
            column: header[k].to_string(),
            value: text.to_string(),
        }),
        Err(_) if text.is_empty() => Err(Bad::NonFinite {
            line,
            column: header[k].to_string(),
            value: String::new(),
        }),
        Err(e) => Err(at(
            line,
            header[k],
            format!("{text:?} is not a number ({e})"),
        )),
    }
}

/// The cell `k` as a whole number.
pub(super) fn count(line: usize, header: &[&str], cells: &[&str], k: usize) -> Row<usize> {
    cells[k].parse().map_err(|e| {
        at(
            line,
            header[k],
            format!("{:?} is not a whole number ({e})", cells[k]),
        )
    })
}

/// The cell `k` empty or a finite number.
fn optional(line: usize, header: &[&str], cells: &[&str], k: usize) -> Row<Option<f64>> {
    if cells[k].is_empty() {
        Ok(None)
    } else {
        number(line, header, cells, k).map(Some)
    }
}

/// The cells of `row` under `header`, as many as it has columns.
pub(super) fn cells<'a>(line: usize, header: &[&str], row: &'a str) -> Row<Vec<&'a str>> {
    let cells: Vec<&str> = row.split(',').collect();
    if cells.len() != header.len() {
        return Err(format!(
            "line {line} has {} fields, the header {}",
            cells.len(),
            header.len()
        )
        .into());
    }
    Ok(cells)
}

/// A 0/1 flag.
fn flag(line: usize, header: &[&str], cells: &[&str], k: usize) -> Row<()> {
    match cells[k] {
        "0" | "1" => Ok(()),
        other => Err(at(line, header[k], format!("{other:?} is not 0 or 1"))),
    }
}

/// Checks a row of `events.csv` (line `line`).
pub(crate) fn event_row(line: usize, row: &str, b: &Bounds) -> Row<EventRow> {
    let header: Vec<&str> = EVENTS_HEADER.split(',').collect();
    let c = cells(line, &header, row)?;
    let index = count(line, &header, &c, 0)?;
    let kind = KINDS.iter().find(|k| **k == c[1]).copied().ok_or_else(|| {
        at(
            line,
            "kind",
            format!("{:?} is not an event kind ({})", c[1], KINDS.join(", ")),
        )
    })?;
    let site = event_site(line, (&header, &c), kind, b)?;
    let force = event_force(line, (&header, &c), kind, b)?;
    let drive_displacement = optional(line, &header, &c, 5)?;
    let energy = optional(line, &header, &c, 6)?;
    if energy.is_some() != (kind == "rupture") {
        return Err(at(
            line,
            "energy_J",
            format!(
                "a {kind} has {}",
                if energy.is_some() {
                    "an energy"
                } else {
                    "none"
                }
            ),
        ));
    }
    let ruptures = if kind == "stable" {
        Some(count(line, &header, &c, 7)?)
    } else if c[7].is_empty() {
        None
    } else {
        return Err(at(line, "ruptures", format!("a {kind} counts no ruptures")));
    };
    flag(line, &header, &c, 8)?;
    let load = Load {
        force: force.unwrap_or(0.0),
        drive_displacement,
    };
    let event = match kind {
        "load_raised" => Event::LoadRaised { load },
        "rupture" => Event::Rupture {
            site,
            load,
            energy: energy.unwrap_or(0.0),
        },
        "detach" => Event::Detach { site },
        "attach" => Event::Attach { site },
        "stable" => Event::Stable {
            load,
            ruptures: ruptures.unwrap_or(0),
        },
        _ => Event::GlobalSlip { load },
    };
    Ok(EventRow {
        index,
        kind,
        force_text: c[4].to_string(),
        force,
        ruptures,
        event,
    })
}

/// The site of an event row (`ix`, `iy` within the grid for a rupture, a detachment or
/// an attachment; both cells empty, and site 0, for the other kinds).
fn event_site(line: usize, (header, c): (&[&str], &[&str]), kind: &str, b: &Bounds) -> Row<Site> {
    let site = matches!(kind, "rupture" | "detach" | "attach");
    let mut at_site = [0; 2];
    for (k, n) in [(2, b.nx), (3, b.ny)] {
        if site {
            let v = count(line, header, c, k)?;
            if v >= n {
                return Err(at(
                    line,
                    header[k],
                    format!("{v} is outside the grid's 0 to {}", n - 1),
                ));
            }
            at_site[k - 2] = v;
        } else if !c[k].is_empty() {
            return Err(at(
                line,
                header[k],
                format!("a {kind} has no site, the cell holds {:?}", c[k]),
            ));
        }
    }
    let [ix, iy] = at_site;
    Ok(Site {
        index: iy * b.nx + ix,
        ix,
        iy,
    })
}

/// The force of an event row (N): a number for every kind but a detachment or an
/// attachment (which carry none), a stable state's within the friction limit.
fn event_force(
    line: usize,
    (header, c): (&[&str], &[&str]),
    kind: &str,
    b: &Bounds,
) -> Row<Option<f64>> {
    let loaded = !matches!(kind, "detach" | "attach");
    let force = if loaded {
        Some(number(line, header, c, 4)?)
    } else {
        optional(line, header, c, 4)?.map_or(Ok(None), |_| {
            Err(at(line, "force_N", format!("a {kind} carries no load")))
        })?
    };
    // The writer refuses a stable state beyond the limit (`map_rows_below`).
    if let (Some(f), "stable") = (force, kind) {
        if f.abs() > LOAD_LIMIT * b.mu_fn {
            return Err(at(
                line,
                "force_N",
                format!(
                    "{f:?} N is beyond the friction limit μF_N = {:?} N",
                    b.mu_fn
                ),
            ));
        }
    }
    Ok(force)
}

/// Checks a row of `curve.csv` (line `line`) under `header`: [`CURVE_HEADER`], or the header 1.1 wrote (without the slip columns,
/// [`curve_header_of`]).
pub(crate) fn curve_row(line: usize, row: &str, b: &Bounds, header: &str) -> Row<CurveRow> {
    let header: Vec<&str> = header.split(',').collect();
    let c = cells(line, &header, row)?;
    let event = count(line, &header, &c, 0)?;
    let force = number(line, &header, &c, 1)?;
    let load = number(line, &header, &c, 2)?;
    if load.abs() > LOAD_LIMIT {
        return Err(at(
            line,
            header[2],
            format!("{load:?} is beyond the friction limit 1"),
        ));
    }
    if (force / b.mu_fn - load).abs() > 1e-9 * (1.0 + load.abs()) {
        return Err(at(
            line,
            header[2],
            format!(
                "{load:?} is not force_N / μF_N = {force:?} / {:?} N",
                b.mu_fn
            ),
        ));
    }
    optional(line, &header, &c, 3)?;
    let area = number(line, &header, &c, 4)?;
    // A stable state carries F_N > 0 on its attached sites, each with an area growing
    // with its force: its real contact area is positive (and `A_R(0)` divides the area
    // figures).
    if area <= 0.0 {
        return Err(at(
            line,
            header[4],
            format!("{area:?} m² is not positive: a stable state carries F_N on its contacts"),
        ));
    }
    let length = number(line, &header, &c, 5)?;
    let ratio = number(line, &header, &c, 6)?;
    if !(0.0..=1.0).contains(&ratio) {
        return Err(at(line, header[6], format!("{ratio:?} is outside 0 to 1")));
    }
    if (length / b.lx - ratio).abs() > 1e-9 {
        return Err(at(
            line,
            header[5],
            format!(
                "{length} m is not precursor_over_Lx · Lx = {ratio} · {} m",
                b.lx
            ),
        ));
    }
    let broken = count(line, &header, &c, 7)?;
    let attached = count(line, &header, &c, 8)?;
    let sites = b.nx * b.ny;
    if attached == 0 {
        return Err(at(
            line,
            "attached",
            "no site is attached: a stable state carries F_N on its contacts",
        ));
    }
    if broken + attached > sites {
        return Err(at(
            line,
            "attached",
            format!("{broken} broken and {attached} attached sites, the grid has {sites}"),
        ));
    }
    flag(line, &header, &c, 9)?;
    let slip = if c.len() == CURVE_COLUMNS_1_1 {
        None
    } else {
        let k = CURVE_COLUMNS_1_1;
        match [k, k + 1, k + 2].map(|k| optional(line, &header, &c, k)) {
            [Ok(None), Ok(None), Ok(None)] => None,
            [Ok(Some(p)), Ok(Some(m)), Ok(Some(c))] => Some([p, m, c]),
            [p, m, c] => {
                p?;
                m?;
                c?;
                return Err(at(
                    line,
                    header[k],
                    "the three slip columns are either all empty (a row kept from a run 1.1 \
                     began) or all numbers",
                ));
            }
        }
    };
    Ok(CurveRow {
        event,
        force_text: c[1].to_string(),
        load_text: c[2].to_string(),
        load,
        precursor_text: c[6].to_string(),
        precursor_over_lx: ratio,
        area,
        slip,
    })
}

/// The header of a `curve.csv` text: [`CURVE_HEADER`], or the one 1.1 wrote (without the
/// slip columns) when the text starts with it.
pub(crate) fn curve_header_of(text: &str) -> &'static str {
    let first = text.split_inclusive('\n').next().unwrap_or("");
    if first.trim_end_matches(['\n', '\r']) == curve_header_1_1() {
        curve_header_1_1()
    } else {
        CURVE_HEADER
    }
}

/// Checks a row of `contact_map.csv` (line `line`; its header has `b.nx` area columns).
pub(crate) fn map_row(line: usize, header: &[&str], row: &str) -> Row<MapRow> {
    let c = cells(line, header, row)?;
    let event = count(line, header, &c, 0)?;
    let x = number(line, header, &c, 1)?;
    let steps = (x / MAP_STEP).round();
    if !(0.0..=(LOAD_LIMIT / MAP_STEP).ceil()).contains(&steps)
        || (steps * MAP_STEP - x).abs() > 1e-9
    {
        return Err(at(
            line,
            header[1],
            format!("{x:?} is not a load level (a multiple of {MAP_STEP} from 0 to 1)"),
        ));
    }
    let mut columns = Vec::with_capacity(c.len() - 2);
    for k in 2..c.len() {
        let a = number(line, header, &c, k)?;
        if a < 0.0 {
            return Err(at(line, header[k], format!("{a:?} m² is negative")));
        }
        columns.push(a);
    }
    Ok(MapRow {
        event,
        level: steps as u64,
        columns,
    })
}

/// The rows of a table's text (line number, row) under `header`, every one whole: a
/// finished table has no row cut by a crash.
pub(super) fn rows<'a>(text: &'a str, header: &str) -> Row<Vec<(usize, &'a str)>> {
    let mut lines = text.split_inclusive('\n');
    match lines.next() {
        Some(first) if first.trim_end_matches(['\n', '\r']) == header => {}
        Some(_) => return Err(format!("line 1 is not the header {header:?}").into()),
        None => return Err(Bad::from("the table is empty (no header)".to_string())),
    }
    let mut out = Vec::new();
    for (k, line) in lines.enumerate() {
        if !line.ends_with('\n') {
            return Err(format!(
                "line {} is cut (no end of line): the table is not whole",
                k + 2
            )
            .into());
        }
        out.push((k + 2, line.trim_end_matches(['\n', '\r'])));
    }
    Ok(out)
}

/// A whole run's `events.csv`, checked ([`whole_events`]).
#[derive(Debug, Clone)]
pub(crate) struct WholeEvents {
    /// The rows of the stable states, in order.
    pub stable: Vec<EventRow>,
    /// The force of global slip (N).
    #[cfg_attr(not(feature = "serde"), allow(dead_code))]
    pub slip_force: f64,
    /// Every event, in order.
    pub events: Vec<Event>,
}

/// Checks the text of a whole `events.csv`: events 1, 2, 3, ..., one global slip, last.
pub(crate) fn whole_events(text: &str, bounds: &Bounds) -> Row<WholeEvents> {
    let mut stable = Vec::new();
    let mut events = Vec::new();
    let mut slip = None;
    let mut last = 0;
    for (line, row) in rows(text, EVENTS_HEADER)? {
        let e = event_row(line, row, bounds)?;
        if e.index != last + 1 {
            let reason = format!(
                "line {line}: event {} follows event {last}: the rows are not those of \
                 one run (1, 2, 3, ...)",
                e.index
            );
            return Err(Bad::Reason(reason));
        }
        last = e.index;
        events.push(e.event);
        if slip.is_some() {
            return Err(Bad::Reason(format!(
                "line {line}: event {} follows global slip, the run's last",
                e.index
            )));
        }
        match e.kind {
            "stable" => stable.push(e),
            "global_slip" => slip = e.force,
            _ => {}
        }
    }
    let Some(slip_force) = slip else {
        return Err(Bad::Reason(format!(
            "it ends at event {last} without global slip: the table is not a whole run"
        )));
    };

    Ok(WholeEvents {
        stable,
        slip_force,
        events,
    })
}

/// Checks the text of a whole `curve.csv`: exactly the stable states of `events.csv`, in order, at the
/// same `force_N`.
pub(crate) fn whole_curve(text: &str, stable: &[EventRow], bounds: &Bounds) -> Row<Vec<CurveRow>> {
    let mut curve = Vec::with_capacity(stable.len());
    let header = curve_header_of(text);
    for (line, row) in rows(text, header)? {
        let c = curve_row(line, row, bounds, header)?;
        let Some(s) = stable.get(curve.len()) else {
            return Err(Bad::Reason(format!(
                "line {line}: event {}: events.csv has {} stable states, this table more",
                c.event,
                stable.len()
            )));
        };
        if c.event != s.index || c.force_text != s.force_text {
            return Err(Bad::Reason(format!(
                "line {line} holds event {} at force_N {}, but the stable state there in \
                 events.csv is event {} at {}",
                c.event, c.force_text, s.index, s.force_text
            )));
        }
        curve.push(c);
    }
    if curve.len() < stable.len() {
        return Err(Bad::Reason(format!(
            "it holds {} stable states, events.csv {}: the rows from event {} on are missing",
            curve.len(),
            stable.len(),
            stable[curve.len()].index
        )));
    }

    Ok(curve)
}

/// A finished run read from its directory and checked ([`RunRecord::read`]).
#[cfg(feature = "serde")]
#[derive(Debug, Clone)]
pub(crate) struct RunRecord {
    pub bounds: Bounds,
    /// The run's grid (from its scene record).
    pub grid: crate::geometry::Grid,
    /// Every event of `events.csv`, in order.
    pub events: Vec<Event>,
    /// The stable states (`curve.csv`), in order.
    pub curve: Vec<CurveRow>,
    /// The ruptures of each stable state's avalanche (`events.csv`), as `curve`.
    pub ruptures: Vec<usize>,
    /// `F/(μF_N)` of global slip.
    pub slip: f64,
    /// `contact_map.csv` (`None` for a directory without it).
    #[cfg_attr(not(feature = "plot"), allow(dead_code))] // the figures read it
    pub map: Option<Vec<MapRow>>,
    /// What the run recorded beside its tables (from its scene record).
    #[cfg_attr(not(feature = "plot"), allow(dead_code))] // the figures read it
    pub options: crate::recording::RunOptions,
    /// The run's contact rule (from its scene record, key `contact`).
    pub contact: crate::contact::ContactRule,
}

#[cfg(feature = "serde")]
impl RunRecord {
    /// Reads and checks the finished run in `dir`: its scene record, `events.csv` (events
    /// 1, 2, 3, ..., one global slip, last), `curve.csv` (exactly the stable states of
    /// `events.csv`, in order, at the same loads) and, when present, `contact_map.csv`
    /// (Nx area columns, consecutive levels from the first state's load to global slip,
    /// at stable states in order); every cell within its bounds.
    ///
    /// # Errors
    /// [`Error::RunDirectory`] for a directory without its scene record;
    /// [`Error::CorruptTable`] naming the file, line and column; [`Error::Io`].
    pub(crate) fn read(dir: &Path) -> Result<RunRecord> {
        let record = dir.join(super::RUN_SCENE);
        if !record.is_file() {
            return Err(Error::RunDirectory {
                path: dir.to_path_buf(),
                reason: format!(
                    "it holds no {}, the record of the scene its tables belong to (written \
                     when a run starts): the tables cannot be checked; run the scene again",
                    super::RUN_SCENE
                ),
            });
        }
        let scene = crate::scene::SceneBuilder::from_json_file(&record)?;
        let grid = scene.grid()?;
        let bounds = Bounds {
            nx: grid.nx(),
            ny: grid.ny(),
            lx: grid.block().lx(),
            mu_fn: scene.limit_friction_coefficient()? * scene.current_normal_load(),
        };
        let path = |t: usize| dir.join(TABLES[t]);
        let corrupt = |t: usize, bad: Bad| bad.at(&path(t));
        let read = |t: usize| crate::files::read_text(&path(t), "reading table");

        let WholeEvents {
            stable,
            slip_force,
            events,
        } = whole_events(&read(0)?, &bounds).map_err(|r| corrupt(0, r))?;
        let curve = whole_curve(&read(1)?, &stable, &bounds).map_err(|r| corrupt(1, r))?;
        let map = if path(2).is_file() {
            Some(
                Self::map(&read(2)?, &curve, slip_force / bounds.mu_fn, &bounds)
                    .map_err(|r| corrupt(2, r))?,
            )
        } else {
            None
        };
        let options = scene.current_run().clone();
        let contact = scene.contact().clone();
        Ok(RunRecord {
            contact,
            bounds,
            grid,
            events,
            ruptures: stable.iter().map(|s| s.ruptures.unwrap_or(0)).collect(),
            curve,
            slip: slip_force / bounds.mu_fn,
            map,
            options,
        })
    }

    /// Checks `contact_map.csv` against the stable states and the slip load.
    fn map(text: &str, curve: &[CurveRow], slip: f64, b: &Bounds) -> Row<Vec<MapRow>> {
        let header_text = contact_map_header(b.nx);
        let header: Vec<&str> = header_text.split(',').collect();
        let first_line = text.lines().next().unwrap_or("");
        let found = first_line.split(',').count().saturating_sub(2);
        if found != b.nx {
            return Err(format!(
                "line 1 has {found} area columns, the scene's grid {} (Nx)",
                b.nx
            )
            .into());
        }
        let mut out: Vec<MapRow> = Vec::new();
        let mut states = curve.iter().map(|c| c.event).peekable();
        for (line, row) in rows(text, &header_text)? {
            let r = map_row(line, &header, row)?;
            // The state in effect at a level is a stable state, never an earlier one than
            // the row before's.
            while states.peek().is_some_and(|&e| e < r.event) {
                states.next();
            }
            if states.peek() != Some(&r.event) {
                return Err(format!(
                    "line {line}: event {} is not a stable state of curve.csv (or the rows \
                     are out of order)",
                    r.event
                )
                .into());
            }
            if let Some(p) = out.last() {
                if r.level != p.level + 1 {
                    return Err(format!(
                        "line {line}: level {:.3} follows level {:.3}: the levels are not \
                         consecutive",
                        level(r.level),
                        level(p.level)
                    )
                    .into());
                }
            }
            out.push(r);
        }
        // The levels from the first state's load up to the highest load reached after it
        // (global slip's capped at the friction limit), each once.
        let Some(first) = curve.first() else {
            return Ok(out);
        };
        let start = first_level_at_or_above(first.load);
        let reached = curve[1..]
            .iter()
            .map(|c| c.load)
            .chain([slip.min(LOAD_LIMIT)])
            .fold(f64::NEG_INFINITY, f64::max);
        // Loads are written to 13 digits: a load within 1e-9 of a level may count either way.
        let lo = first_level_at_or_above(reached - 1e-9).max(start) - start;
        let hi = first_level_at_or_above(reached + 1e-9).max(start) - start;
        let rows = out.len() as u64;
        if out.first().is_some_and(|r| r.level != start) || rows < lo || rows > hi {
            return Err(format!(
                "it holds {rows} levels from {}, but the run's loads give {lo} levels from \
                 {:.3} (up to F/(μF_N) = {reached})",
                out.first()
                    .map_or("none".to_string(), |r| format!("{:.3}", level(r.level))),
                level(start)
            )
            .into());
        }
        Ok(out)
    }
}

/// A row of `fields.csv`, checked.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FieldsRow<'a> {
    pub event: usize,
    /// `F/(μF_N)` and `ℓ/Lx` as written (equal on every row of a state and to the
    /// state's row of `curve.csv`), and their values.
    pub load_text: &'a str,
    pub load: f64,
    pub precursor_text: &'a str,
    pub precursor_over_lx: f64,
    pub values: Vec<f64>,
}

/// Checks the row `within` of a recorded state in `fields.csv` (line `line`; `header`
/// [`super::fields_header`]'s cells): the state's `ny` rows of area (at `z = 0`, values
/// `>= 0`), then one of Coulomb stress per plane of `planes`, at its height.
pub(crate) fn fields_row<'a>(
    line: usize,
    header: &[&str],
    row: &'a str,
    within: usize,
    ny: usize,
    planes: &[f64],
) -> Row<FieldsRow<'a>> {
    let c = cells(line, header, row)?;
    let event = count(line, header, &c, 0)?;
    let load = number(line, header, &c, 1)?;
    if load.abs() > LOAD_LIMIT {
        return Err(at(
            line,
            header[1],
            format!("{load:?} is beyond the friction limit 1"),
        ));
    }
    let precursor = number(line, header, &c, 2)?;
    if !(0.0..=1.0).contains(&precursor) {
        return Err(at(
            line,
            header[2],
            format!("{precursor:?} is outside 0 to 1"),
        ));
    }
    let (field, index, z) = if within < ny {
        (super::FIELD_AREA, within, 0.0)
    } else {
        let k = within - ny;
        (super::FIELD_COULOMB, k, planes[k])
    };
    if c[3] != field || c[4] != index.to_string() {
        return Err(format!(
            "line {line}: a state's rows are {ny} of {} (rows 0 to {}), then one of {} per \
             recorded plane ({}): row {index} of {field} belongs here",
            super::FIELD_AREA,
            ny.saturating_sub(1),
            super::FIELD_COULOMB,
            planes.len()
        )
        .into());
    }
    let found = number(line, header, &c, 5)?;
    if (found - z).abs() > 1e-12 * z.abs() {
        return Err(at(
            line,
            header[5],
            format!(
                "{:?}: row {index} of {field} lies at z = {z} m (the scene's `fields.planes`)",
                c[5]
            ),
        ));
    }
    let mut values = Vec::with_capacity(c.len() - 6);
    for k in 6..c.len() {
        let v = number(line, header, &c, k)?;
        if field == super::FIELD_AREA && v < 0.0 {
            return Err(at(line, header[k], format!("{v:?} m² is negative")));
        }
        values.push(v);
    }
    Ok(FieldsRow {
        event,
        load_text: c[1],
        load,
        precursor_text: c[2],
        precursor_over_lx: precursor,
        values,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A huge value in a cell is echoed in exponent form: `{}` wrote 1e308 as its 309
    /// digits, a 310-character message (issue 53).
    #[test]
    fn messages_echo_huge_values_briefly() {
        let b = Bounds {
            nx: 4,
            ny: 2,
            lx: 0.004,
            mu_fn: 10.0,
        };
        let rows = [
            "2,1e308,1e308,,1e-6,0,0,0,8,0,,,",
            "2,1.0,0.1,,-1e308,0,0,0,8,0,,,",
            "2,1e300,0.1,,1e-6,0,0,0,8,0,,,",
        ];
        for row in rows {
            let message = match curve_row(2, row, &b, CURVE_HEADER) {
                Err(Bad::Reason(m)) => m,
                other => panic!("{row}: {other:?}"),
            };
            assert!(message.len() < 120, "{row}: {message}");
            assert!(message.contains("e30"), "{row}: {message}");
        }
    }
}
