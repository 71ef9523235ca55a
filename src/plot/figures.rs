//! The standard figures of a run directory (the tables of `precursors run` or of one run
//! of a sweep: module [`crate::output`]) or of a sweep directory (`precursors plot DIR`).
//!
//! A run: `precursor_length` (ℓ/Lx against `F/(μF_N)`, paper Fig. 2b), `contact_area`
//! (`A_R/A_R(0)` against `F/(μF_N)`) and, from `contact_map.csv`, `contact_map` (the real
//! contact area of each column relative to zero shear over `x/Lx` and `F/(μF_N)`, the
//! paper's Fig. 2b inset). A sweep: the tables of [`crate::sweep::merge`] written first,
//! then `precursor_length` and `contact_area` with one curve per parameter point, the
//! mean over its realizations and the 95 % band, on a load grid of step 0.005.

use super::PlotError;
use super::{Chart, Corner, Map, Palette};
use crate::error::{table_number, Error, Result};
use crate::output::{CONTACT_MAP_STEP, CURVE_HEADER};
use crate::sweep::{merge, MergeSummary, SWEEP_FILE};
use std::path::{Path, PathBuf};

/// A file format for the figures.
///
/// ```
/// use precursors::plot::{draw, Format};
/// use precursors::{output::RunTables, Scene};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// // A run to global slip (10 x 4 cells of 1 mm, 100 N) writes its tables into `dir`.
/// let scene = Scene::builder().block(0.010, 0.004, 0.010).normal_load(100.0).build()?;
/// let mut driver = scene.driver()?;
/// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
/// let drawn = draw(&dir, &[Format::Png, Format::Svg])?;
/// let extension = |k: usize| drawn.files[k].extension().unwrap().to_owned();
/// assert_eq!(drawn.files.len(), 6);                 // three figures in each format
/// assert_eq!((extension(0), extension(5)), ("png".into(), "svg".into()));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Format {
    /// PNG, 8-bit RGB.
    Png,
    /// SVG (text as text: the viewer's sans-serif font draws it).
    Svg,
}

impl Format {
    fn extension(self) -> &'static str {
        match self {
            Format::Png => "png",
            Format::Svg => "svg",
        }
    }
}

/// What [`draw`] did.
///
/// ```
/// use precursors::plot::{draw, Format, PlotError};
/// use precursors::{output::RunTables, Scene};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// // A run to global slip (10 x 4 cells of 1 mm, 100 N) writes its tables into `dir`.
/// let scene = Scene::builder().block(0.010, 0.004, 0.010).normal_load(100.0).build()?;
/// let mut driver = scene.driver()?;
/// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
/// let drawn = draw(&dir, &[Format::Svg])?;
/// let names: Vec<_> = drawn.files.iter().map(|f| f.file_name().unwrap().to_owned()).collect();
/// assert_eq!(names, ["precursor_length.svg", "contact_area.svg", "contact_map.svg"]);
/// assert!(drawn.merge.is_none() && drawn.notes.is_empty());  // a run: no merge, nothing left out
/// // A directory that is neither a run's nor a sweep's.
/// let empty = dir.join("empty");
/// std::fs::create_dir(&empty)?;
/// assert!(matches!(draw(&empty, &[Format::Svg]), Err(PlotError::Figure { .. })));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Drawn {
    /// The figures written.
    pub files: Vec<PathBuf>,
    /// For a sweep: what the merge wrote first (its tables and the runs not complete).
    pub merge: Option<MergeSummary>,
    /// What was left out and why (e.g. a run without `contact_map.csv`).
    pub notes: Vec<String>,
}

/// Draws the figures of `dir` in each of `formats` into `dir`: a sweep's (`dir` holds
/// `sweep.json`) or a run's (`dir` holds `curve.csv`).
///
/// # Errors
/// [`PlotError::Figure`] when `dir` is neither, or a figure cannot be drawn; in
/// [`PlotError::Core`]: [`Error::Io`] for a table that cannot be read or a figure that
/// cannot be written (each figure is written atomically: none is left half written),
/// [`Error::CorruptTable`] for a damaged table, [`Error::NonFiniteCell`] for a `NaN`, an
/// infinity or an empty cell where a number belongs (with the file, line and column); in
/// [`PlotError::Sweep`]: a sweep's errors as [`crate::sweep::merge`].
///
/// [`Drawn`]'s example draws a run's figures as SVG; here as PNG:
///
/// ```
/// use precursors::{output::RunTables, plot::{draw, Format}, Scene};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-draw-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let scene = Scene::builder().block(0.010, 0.004, 0.010).normal_load(100.0).build()?;
/// let mut driver = scene.driver()?;
/// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
/// let drawn = draw(&dir, &[Format::Png])?;
/// assert!(drawn.files.iter().all(|f| f.extension().unwrap() == "png" && f.is_file()));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn draw(dir: &Path, formats: &[Format]) -> Result<Drawn, PlotError> {
    if dir.join(SWEEP_FILE).is_file() {
        draw_sweep(dir, formats)
    } else if dir.join("curve.csv").is_file() {
        draw_run(dir, formats)
    } else if dir
        .join(format!("curve.csv{}", crate::output::PARTIAL_SUFFIX))
        .is_file()
    {
        Err(PlotError::Figure {
            path: Some(dir.to_path_buf()),
            reason: format!(
                "a run that has not reached global slip: it is under way, or was cut (its \
                 tables are still named curve.csv{}); resume it from its checkpoint or run \
                 it again, then plot",
                crate::output::PARTIAL_SUFFIX
            ),
        })
    } else {
        Err(PlotError::Figure {
            path: Some(dir.to_path_buf()),
            reason: format!(
                "neither a sweep directory ({SWEEP_FILE}) nor a run directory (curve.csv)"
            ),
        })
    }
}

/// The name figures give a directory: its last component.
fn name(dir: &Path) -> String {
    dir.canonicalize()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| dir.display().to_string())
}

fn read(path: &Path) -> Result<String> {
    crate::cost::check_file_size(path)?;
    std::fs::read_to_string(path).map_err(|e| Error::io("reading table", path, e))
}

fn corrupt(path: &Path, reason: String) -> Error {
    Error::CorruptTable {
        path: Some(path.to_path_buf()),
        reason,
    }
}

/// The columns `wanted` (named as in `header`) of the rows of a CSV table with that
/// header, as finite numbers: a `NaN`, an infinity or an empty cell in them is refused
/// with its line ([`crate::error::table_number`]), not drawn as a gap.
fn numbers(path: &Path, header: &str, wanted: &[&str]) -> Result<Vec<Vec<f64>>> {
    let text = read(path)?;
    let mut lines = text.lines();
    if lines.next() != Some(header) {
        return Err(corrupt(
            path,
            format!("line 1 is not the header {header:?}"),
        ));
    }
    let names: Vec<&str> = header.split(',').collect();
    let columns = wanted
        .iter()
        .map(|w| {
            names
                .iter()
                .position(|n| n == w)
                .ok_or_else(|| corrupt(path, format!("the header has no column {w}")))
        })
        .collect::<Result<Vec<usize>>>()?;
    let mut rows = Vec::new();
    for (i, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != names.len() {
            return Err(corrupt(
                path,
                format!(
                    "line {} has {} fields, the header {}",
                    i + 2,
                    cells.len(),
                    names.len()
                ),
            ));
        }
        let row = columns
            .iter()
            .map(|&k| table_number(path, i + 2, names[k], cells[k]))
            .collect::<Result<Vec<f64>>>()?;
        rows.push(row);
    }
    Ok(rows)
}

/// The figures of one run directory.
fn draw_run(dir: &Path, formats: &[Format]) -> Result<Drawn, PlotError> {
    let title = name(dir);
    let curve_path = dir.join("curve.csv");
    let rows = numbers(
        &curve_path,
        CURVE_HEADER,
        &[
            "force_over_mu_FN",
            "precursor_over_Lx",
            "real_contact_area_m2",
        ],
    )?;
    let force: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let ell: Vec<(f64, f64)> = rows.iter().map(|r| (r[0], r[1])).collect();
    let a0 = rows.first().map_or(f64::NAN, |r| r[2]);
    let area: Vec<(f64, f64)> = rows.iter().map(|r| (r[0], r[2] / a0)).collect();
    // Near slip the paper's unbounded area law can reach many times A_R(0) (flagged in
    // area_exceeds_nominal): the chart shows up to 2 and its legend says how many
    // states lie above.
    let area_top = area
        .iter()
        .map(|p| p.1)
        .filter(|a| a.is_finite())
        .fold(1.0, f64::max);
    let above = area.iter().filter(|p| p.1 > 2.0).count();
    let area_label = match above {
        0 => "A_R/A_R(0) at the stable states".to_string(),
        k => format!("A_R/A_R(0) at the stable states ({k} above 2, up to {area_top:.3e})"),
    };
    let top = force
        .iter()
        .copied()
        .filter(|f| f.is_finite())
        .fold(1.0, f64::max);
    let mut drawn = Drawn {
        files: Vec::new(),
        merge: None,
        notes: Vec::new(),
    };
    for &format in formats {
        let path = dir.join(format!("precursor_length.{}", format.extension()));
        Chart::new(&format!("Precursor length, {title}"), "F/(μF_N)", "ℓ/Lx")
            .x_range(0.0, top)
            .y_range(0.0, 1.0)
            .steps("ℓ/Lx at the stable states", &ell)
            .legend(Corner::UpperLeft)
            .save(&path)?;
        drawn.files.push(path);
        let path = dir.join(format!("contact_area.{}", format.extension()));
        Chart::new(
            &format!("Real contact area, {title}"),
            "F/(μF_N)",
            "A_R/A_R(0)",
        )
        .x_range(0.0, top)
        .y_range(0.0, (1.04 * area_top).min(2.0))
        .steps(&area_label, &area)
        .legend(Corner::LowerLeft)
        .save(&path)?;
        drawn.files.push(path);
    }
    let map_path = dir.join("contact_map.csv");
    if !map_path.is_file() {
        drawn.notes.push(format!(
            "no contact map: {} is missing (written by this version's `run`)",
            map_path.display()
        ));
        return Ok(drawn);
    }
    let text = read(&map_path)?;
    let header = text.lines().next().unwrap_or("");
    let columns: Vec<&str> = header.split(',').collect();
    let map = numbers(&map_path, header, &columns)?;
    let nx = columns.len().saturating_sub(2);
    let Some(first) = map.first() else {
        drawn.notes.push(format!(
            "no contact map: {} has no rows",
            map_path.display()
        ));
        return Ok(drawn);
    };
    if nx == 0 {
        return Err(corrupt(&map_path, "no area columns in the header".into()).into());
    }
    // Each column relative to the map's first row (zero shear for a run from rest).
    let reference = first[2..].to_vec();
    let mut values = Vec::with_capacity(map.len() * nx);
    for row in &map {
        for (a, r) in row[2..].iter().zip(&reference) {
            values.push(if *r > 0.0 { a / r } else { f64::NAN });
        }
    }
    let (low, high) = (map[0][1], map[map.len() - 1][1]);
    let half = CONTACT_MAP_STEP / 2.0;
    let reference_label = if low == 0.0 {
        "A_R(x, F)/A_R(x, 0)".to_string()
    } else {
        format!("A_R(x, F)/A_R(x) at F/(μF_N) = {low:.3}")
    };
    for &format in formats {
        let path = dir.join(format!("contact_map.{}", format.extension()));
        Map::new(nx, map.len(), values.clone())?
            .labels(
                &format!("Real contact area per column, {title}"),
                "x/Lx (trailing edge at 0)",
                "F/(μF_N)",
                &reference_label,
            )
            .x_range(0.0, 1.0)
            .y_range(low - half, high + half)
            .colour_scale(Palette::Diverging, Some((0.0, 2.0)))
            .save(&path)?;
        drawn.files.push(path);
    }
    Ok(drawn)
}

/// The figures of a sweep directory, after merging it.
fn draw_sweep(dir: &Path, formats: &[Format]) -> Result<Drawn, PlotError> {
    let summary = merge(dir)?;
    let grid: Vec<f64> = (0..=200).map(|k| k as f64 * 0.005).collect();
    let points = crate::sweep::ensemble_curves(dir, &grid)?;
    let title = name(dir);
    let label = |values: &[(String, String)], runs: usize| {
        let mut text = values
            .iter()
            .map(|(k, v)| format!("{k} = {v}"))
            .collect::<Vec<_>>()
            .join(", ");
        if text.is_empty() {
            text = "all runs".into();
        }
        format!("{text} ({runs} runs)")
    };
    // As for a run: near slip the unbounded area law can reach many times A_R(0).
    let area_top = points
        .iter()
        .flat_map(|p| p.area.iter().flat_map(|r| [r.1, r.3]))
        .filter(|a| a.is_finite())
        .fold(1.0, f64::max);
    let area_note = if area_top > 2.0 {
        format!(" (up to {area_top:.2e}: above 2 off the chart)")
    } else {
        String::new()
    };
    let mut drawn = Drawn {
        files: Vec::new(),
        merge: None,
        notes: Vec::new(),
    };
    for &format in formats {
        let mut chart = Chart::new(
            &format!("Precursor length, {title}: mean and 95 % band"),
            "F/(μF_N)",
            "ℓ/Lx",
        )
        .x_range(0.0, 1.0)
        .y_range(0.0, 1.0)
        .legend(Corner::UpperLeft);
        for p in &points {
            chart = chart.band(&label(&p.values, p.runs), &p.precursor);
        }
        let path = dir.join(format!("precursor_length.{}", format.extension()));
        chart.save(&path)?;
        drawn.files.push(path);
        let mut chart = Chart::new(
            &format!("Real contact area, {title}: mean and 95 % band{area_note}"),
            "F/(μF_N)",
            "A_R/A_R(0)",
        )
        .x_range(0.0, 1.0)
        .y_range(0.0, (1.04 * area_top).min(2.0))
        .legend(Corner::LowerLeft);
        for p in &points {
            chart = chart.band(&label(&p.values, p.runs), &p.area);
        }
        let path = dir.join(format!("contact_area.{}", format.extension()));
        chart.save(&path)?;
        drawn.files.push(path);
    }
    if summary.runs_missing > 0 {
        drawn.notes.push(format!(
            "{} runs are not complete: the curves hold the {} complete ones",
            summary.runs_missing, summary.runs_merged
        ));
    }
    drawn.merge = Some(summary);
    Ok(drawn)
}
