//! The standard figures of a run directory (the tables of `precursors run` or of one run
//! of a sweep: module [`crate::output`]) or of a sweep directory (`precursors plot DIR`).
//!
//! A run: `precursor_length` (ℓ/Lx against `F/(μF_N)`, paper Fig. 2b), `contact_area`
//! (`A_R/A_R(0)` against `F/(μF_N)`) and, from `contact_map.csv`, `contact_map` (the real
//! contact area of each column relative to zero shear over `x/Lx` and `F/(μF_N)`, the
//! paper's Fig. 2b inset). A run and a sweep: the statistics figures of
//! `plot/distributions.rs` (`avalanche_sizes`, `force_drops` when the force drops,
//! `fronts` for a run). A sweep: the tables of [`crate::sweep::merge`] written first,
//! then `precursor_length` and `contact_area` with one curve per parameter point, on a
//! load grid of step 0.005: ℓ/Lx's mean over its realizations and its 95 % t-band;
//! `A_R/A_R(0)`'s median and the median's distribution-free 95 % interval (none below 6
//! runs), which a few realizations near slip, many times the others under the paper's
//! area law, do not stretch over the chart as they do the mean's t-band. The paper's
//! figures of `plot/paper.rs`: `stick_slip` for a spring-driven run, `archard` for a sweep
//! over the normal load. [`draw_with_options`] draws the figures named
//! ([`DrawOptions::figures`], names from `output/layout.rs`' `FIGURES`), after checking
//! that the directory allows them.

use super::distributions::draw_statistics;
use super::fronts::ensemble_fronts;
use super::paper::{draw_archard, draw_stick_slip};
use super::profiles::draw_profiles;
use super::relations::draw_relations;
use super::selection::{Selection, NORMAL_LOAD};
use super::PlotError;
use super::{point_order, short, Canvas, Chart, Colours, Corner, Map, Palette};
use crate::error::{Error, Result};
use crate::output::check::RunRecord;
use crate::output::derived::derive;
use crate::output::layout::{
    ARCHARD_FIGURE, AREA_FIGURE, FIGURES, FRONTS_FIGURE, MAP_FIGURE, PRECURSOR_FIGURE,
    STICK_SLIP_FIGURE,
};
use crate::output::MAP_STEP;
use crate::sweep::{merge, MergeSummary, MEDIAN_BAND_RUNS, SWEEP_FILE};
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
/// assert_eq!(drawn.files.len(), 10);                // five figures in each format
/// assert_eq!((extension(0), extension(9)), ("png".into(), "svg".into()));
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
/// assert_eq!(
///     names,
///     ["precursor_length.svg", "contact_area.svg", "contact_map.svg", "avalanche_sizes.svg",
///      "fronts.svg"]
/// );
/// // A run: no merge; under force control no force drops, so no figure of them.
/// assert!(drawn.merge.is_none() && drawn.notes[0].contains("no force_drops figure"));
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
/// `sweep.json`) or a run's (`dir` holds `curve.csv`); every figure the directory allows
/// ([`draw_with_options`] says which, and draws some of them only).
///
/// # Errors
/// [`PlotError::Figure`] when `dir` is neither, or a figure cannot be drawn; in
/// [`PlotError::Core`]: [`Error::Io`] for a directory that does not exist or cannot be
/// read (`NotFound` when missing), a table that cannot be read or a figure that
/// cannot be written (each figure is written atomically: none is left half written),
/// [`Error::CorruptTable`] for a damaged table, [`Error::NonFiniteCell`] for a `NaN`, an
/// infinity or an empty cell where a number belongs (with the file, line and column),
/// [`Error::DirectoryLocked`] while a run or a sweep writes the directory (its lock is
/// taken shared, as a reader's), [`Error::RunDirectory`] for a run directory holding a
/// `sweep.json`, [`Error::NotARegularFile`] for a symbolic link where a table is read or
/// a figure written; in [`PlotError::Sweep`]: a sweep's errors as
/// [`crate::sweep::merge`].
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
    draw_with_size(dir, formats, (800, 560))
}

/// [`draw`] with the figures' size `(width, height)` in 1/150 inch (pixels at the
/// default 150 dpi; [`draw`] uses 800 x 560, 5.33 x 3.73 inches). The SVG figures take
/// the size as their view box. For print, keep the size and raise the resolution
/// ([`DrawOptions::dpi`]).
///
/// ```
/// use precursors::{output::RunTables, plot::{draw_with_size, Format}, Scene};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-size-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let scene = Scene::builder().block(0.010, 0.004, 0.010).normal_load(100.0).build()?;
/// let mut driver = scene.driver()?;
/// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
/// let drawn = draw_with_size(&dir, &[Format::Svg], (1600, 1120))?;
/// let svg = std::fs::read_to_string(&drawn.files[0])?;
/// assert!(svg.contains("width=\"1600\"") && svg.contains("height=\"1120\""));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
/// As [`draw`]; [`PlotError::InvalidSize`] also for a side below 200 or above 16384 pixels.
pub fn draw_with_size(
    dir: &Path,
    formats: &[Format],
    size: (u32, u32),
) -> Result<Drawn, PlotError> {
    draw_with_options(
        dir,
        &DrawOptions::default().formats(formats).size(size.0, size.1),
    )
}

/// What [`draw_with_options`] draws: the formats, the size, the PNGs' resolution and
/// which figures. Setters never fail; [`draw_with_options`] checks the values.
///
/// A figure's size is in 1/150 inch: at the default 150 dpi its PNG has as many pixels
/// (800 x 560 for a figure of 5.33 x 3.73 inches); at `dpi` it has `size · dpi/150`
/// (1600 x 1120 at 300 dpi), with its text, lines and markers as large relative to the
/// figure as at 150 dpi. An SVG takes the size as its view box, whatever the resolution.
///
/// ```
/// use precursors::plot::{DrawOptions, Format};
/// let options = DrawOptions::default()
///     .formats(&[Format::Svg])
///     .size(1200, 840)
///     .dpi(300)
///     .figures(["precursor_length", "stick_slip"]);
/// assert_eq!((options.size, options.dpi), ((1200, 840), 300));
/// assert_eq!(options.figures, ["precursor_length", "stick_slip"]);
/// // The default: PNG, 800 x 560 at 150 dpi, every figure the directory allows.
/// let default = DrawOptions::default();
/// assert_eq!((default.formats, default.size), (vec![Format::Png], (800, 560)));
/// assert_eq!(default.dpi, 150);
/// assert!(default.figures.is_empty());
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct DrawOptions {
    /// The file formats, each figure written once in each (default PNG).
    pub formats: Vec<Format>,
    /// The figures' size `(width, height)` in 1/150 inch, each side from 200 to 16384
    /// (default 800 x 560: 5.33 x 3.73 inches; the PNG's pixels at 150 dpi).
    pub size: (u32, u32),
    /// The PNGs' resolution in dots per inch, 50 to 1200 (default 150): a PNG has
    /// `size · dpi/150` pixels (at most 16384 along a side).
    pub dpi: u32,
    /// The names of the figures to draw (`precursor_length`, `contact_area`,
    /// `contact_map`, `stick_slip`, `archard`, `fronts`, `avalanche_sizes`,
    /// `force_drops`, `slip_profiles`, `shear_profiles`, `normal_profiles`,
    /// `coulomb_profiles`, and from `precursors stats`' tables `drop_against_size`,
    /// `potency_against_size`, `collapse`); empty (the default): every figure the
    /// directory allows.
    pub figures: Vec<String>,
}

impl Default for DrawOptions {
    fn default() -> Self {
        Self {
            formats: vec![Format::Png],
            size: (800, 560),
            dpi: super::DEFAULT_DPI,
            figures: Vec::new(),
        }
    }
}

impl DrawOptions {
    /// The file formats.
    pub fn formats(mut self, formats: &[Format]) -> Self {
        self.formats = formats.to_vec();
        self
    }

    /// The size in 1/150 inch.
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.size = (width, height);
        self
    }

    /// The PNGs' resolution in dots per inch.
    pub fn dpi(mut self, dpi: u32) -> Self {
        self.dpi = dpi;
        self
    }

    /// The figures to draw, by name (none: every figure the directory allows).
    pub fn figures<S: Into<String>>(mut self, names: impl IntoIterator<Item = S>) -> Self {
        self.figures = names.into_iter().map(Into::into).collect();
        self
    }
}

/// Draws the figures of `dir` into `dir` as [`draw`] does, in the formats, at the size
/// and of the figures `options` gives. Besides [`draw`]'s figures: for a run driven
/// through a spring, `stick_slip` (the spring force `F/(μF_N)` against the drive
/// displacement `U_S` in µm at every load step, rupture, stable state and global slip,
/// from `events.csv`: the paper's Fig. 4); for a sweep with the axis `normal_load`,
/// `archard` (the real contact area of each complete run's first stable state, zero
/// shear, in % of the nominal area `Lx Ly`, against `F_N` in N: the mean over the runs
/// at each load with ± one standard deviation, and the least-squares line through the
/// origin `A_R = α F_N` over every run, `α` in m²/N in the legend; the paper's Fig. 2a;
/// points that differ in other keys than `normal_load` and the drive's are one series
/// each). A figure the directory does not allow and not named is left out, with a note
/// in [`Drawn::notes`] where one is useful (`stick_slip` of a run without a driving
/// spring or of a sweep, `archard` of a sweep without the axis).
///
/// ```
/// use precursors::{output::RunTables, plot::{draw_with_options, DrawOptions, Format, PlotError}, Scene};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-options-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let scene = Scene::builder().block(0.010, 0.004, 0.010).normal_load(100.0).build()?;
/// let mut driver = scene.driver()?;
/// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
/// let options = DrawOptions::default().formats(&[Format::Svg]).figures(["contact_area"]);
/// let drawn = draw_with_options(&dir, &options)?;
/// assert_eq!(drawn.files, [dir.join("contact_area.svg")]);
/// // A name that is no figure, and a figure this run (force control) cannot give.
/// let e = draw_with_options(&dir, &options.clone().figures(["area"])).unwrap_err();
/// assert!(matches!(e, PlotError::UnknownFigure { .. }));
/// assert!(e.to_string().contains("precursor_length, contact_area"));
/// let e = draw_with_options(&dir, &options.figures(["stick_slip"])).unwrap_err();
/// assert!(matches!(e, PlotError::FigureUnavailable { .. }));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
/// As [`draw`]; [`PlotError::InvalidSize`] for a side below 200 or above 16384, or a
/// PNG of more than 16384 pixels along a side at the resolution; [`PlotError::InvalidDpi`]
/// for a resolution outside 50 to 1200 dpi; [`PlotError::UnknownFigure`] for a name in [`DrawOptions::figures`] that is no figure;
/// [`PlotError::FigureUnavailable`] for a named figure the directory cannot give (a
/// run's figure of a sweep, `archard` of a run or of a sweep without the axis
/// `normal_load`, `stick_slip` without a driving spring, `force_drops` where the force
/// never drops, `contact_map` without `contact_map.csv`): found before any figure is
/// drawn, but for a spring's force that never drops and a contact map without rows.
pub fn draw_with_options(dir: &Path, options: &DrawOptions) -> Result<Drawn, PlotError> {
    let size = options.size;
    super::check_dpi(options.dpi)?;
    let pixels = super::png_pixels(size, options.dpi);
    let sides = 200..=super::LARGEST_SIDE;
    let png_fits =
        !options.formats.contains(&Format::Png) || pixels.0.max(pixels.1) <= super::LARGEST_SIDE;
    if !sides.contains(&size.0) || !sides.contains(&size.1) || !png_fits {
        return Err(PlotError::InvalidSize {
            size,
            dpi: options.dpi,
            pixels,
            largest: super::LARGEST_SIDE,
        });
    }
    let canvas = Canvas {
        size,
        dpi: options.dpi,
    };
    let mut named = Vec::new();
    for name in &options.figures {
        let Some(figure) = FIGURES.iter().find(|f| **f == name.trim()) else {
            return Err(PlotError::UnknownFigure {
                name: name.clone(),
                known: FIGURES.iter().map(|f| f.to_string()).collect(),
            });
        };
        if !named.contains(figure) {
            named.push(*figure);
        }
    }
    let formats = &options.formats;
    let extensions: Vec<&str> = formats.iter().map(|f| f.extension()).collect();
    // A directory that does not exist or cannot be read is a file error, not a figure's.
    std::fs::read_dir(dir).map_err(|e| Error::io("reading the run or sweep directory", dir, e))?;
    let sweep = crate::output::layout::is_sweep(dir)?;
    // A reader: no run or sweep writes the directory while its figures are drawn.
    let _lock = crate::lock::ReadLock::lock(dir)?;
    if !sweep && !dir.join("curve.csv").is_file() {
        return Err(
            if dir
                .join(format!("curve.csv{}", crate::output::PARTIAL))
                .is_file()
            {
                PlotError::Figure {
                    path: Some(dir.to_path_buf()),
                    reason: format!(
                        "a run that has not reached global slip: it is under way, or was cut (its \
                     tables are still named curve.csv{}); resume it from its checkpoint or \
                     run it again, then plot",
                        crate::output::PARTIAL
                    ),
                }
            } else {
                PlotError::Figure {
                    path: Some(dir.to_path_buf()),
                    reason: format!(
                        "neither a sweep directory ({SWEEP_FILE}) nor a run directory (curve.csv)"
                    ),
                }
            },
        );
    }
    let (selection, skipped) = Selection::of(dir, sweep, named)?;
    let (mut drawn, title) = if sweep {
        (
            draw_sweep(dir, formats, canvas, &selection)?,
            sweep_title(dir),
        )
    } else {
        (draw_run(dir, formats, canvas, &selection)?, run_title(dir))
    };
    let statistics = draw_statistics(dir, &extensions, canvas, (&title, point_label), &selection)?;
    drawn.files.extend(statistics.files);
    drawn.notes.extend(statistics.notes);
    if sweep && selection.wants(FRONTS_FIGURE) {
        // The fronts' medians and quartiles over each point's runs.
        let (_, points, _) = crate::sweep::stats::points(dir)?;
        let fronts = ensemble_fronts(dir, &extensions, canvas, (&title, point_label), &points)?;
        drawn.files.extend(fronts.files);
        drawn.notes.extend(fronts.notes);
    }
    let retitle = sweep.then_some(sweep_title_over as super::relations::Retitle);
    let relations = draw_relations(
        dir,
        &extensions,
        canvas,
        (&title, point_label, retitle),
        &selection,
    )?;
    drawn.files.extend(relations.files);
    drawn.notes.extend(relations.notes);
    drawn.notes.extend(skipped);
    Ok(drawn)
}

/// A sweep's point in a legend: its axes' values in the user's units, and its runs.
fn point_label(values: &[(String, String)], runs: usize) -> String {
    let mut text = values
        .iter()
        .map(|(k, v)| axis_value(k, v))
        .collect::<Vec<_>>()
        .join(", ");
    if text.is_empty() {
        text = "all runs".into();
    }
    format!("{text} ({runs} runs)")
}

/// The name figures give a directory: its last component.
pub(super) fn name(dir: &Path) -> String {
    dir.canonicalize()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| dir.display().to_string())
}

/// The scene of a run directory in a few words (block, `F_N`, drive, heights' seed), from
/// its `scene.json`; the directory's name when it has none.
pub(super) fn run_title(dir: &Path) -> String {
    match crate::scene::SceneBuilder::from_json_file(dir.join("scene.json")) {
        Ok(scene) => describe(&crate::scene::file::all_keys(&scene)),
        Err(_) => name(dir),
    }
}

/// The scene of a sweep in a few words: its first run's keys but the axes' and the seed,
/// and the realizations whose runs are complete ([`realizations`]); the directory's name
/// when the sweep file cannot be read.
fn sweep_title(dir: &Path) -> String {
    let complete: Vec<usize> = match crate::sweep::stats::points(dir) {
        Ok((_, points, _)) => points.iter().map(|p| p.runs()).collect(),
        Err(_) => Vec::new(),
    };
    sweep_title_over(dir, &complete)
}

/// [`sweep_title`] for a figure drawn over `runs[k]` runs of point `k` (the runs `stats`
/// pooled, for the figures of its tables).
fn sweep_title_over(dir: &Path, runs: &[usize]) -> String {
    let Ok(sweep) = crate::sweep::Sweep::from_json_file(dir.join(SWEEP_FILE)) else {
        return name(dir);
    };
    let Some(first) = sweep.runs().first() else {
        return name(dir);
    };
    let mut keys = crate::scene::file::all_keys(first.scene());
    keys.retain(|(key, _)| {
        key != "heights.seed" && !first.values().iter().any(|(axis, _)| axis == key)
    });
    let planned = sweep.runs().len() / sweep.points().max(1);
    format!("{}, {}", describe(&keys), realizations(runs, planned))
}

/// The realizations of a sweep's points in words, from each point's runs that enter a
/// figure (`complete`) and the realizations the sweep plans (`planned`): `50 realizations` when
/// every point has them all, `41 of 50 realizations` when every point has as many, and
/// `11-50 of 50 realizations per point` otherwise (each point's legend entry gives its
/// own).
fn realizations(complete: &[usize], planned: usize) -> String {
    match (complete.iter().min(), complete.iter().max()) {
        (Some(&low), Some(&high)) if low != high => {
            format!("{low}-{high} of {planned} realizations per point")
        }
        (Some(&n), _) if n != planned => format!("{n} of {planned} realizations"),
        _ => format!("{planned} realizations"),
    }
}

/// `v` clipped to `[low, high]`; a `NaN` (no band: fewer than two runs) stays `NaN`.
fn clip(v: f64, low: f64, high: f64) -> f64 {
    if v.is_nan() {
        v
    } else {
        v.clamp(low, high)
    }
}

/// A force in N or kN.
fn newtons(f: f64) -> String {
    if f.abs() >= 1e3 {
        format!("{} kN", short(f / 1e3))
    } else {
        format!("{} N", short(f))
    }
}

/// A scene's keys (the scene file's, `crate::scene::file::all_keys`) in a few words:
/// `140 x 7 x 75 mm, F_N = 3.5 kN, rod at h = 6 mm, seed 1`.
fn describe(keys: &[(String, String)]) -> String {
    let get = |k: &str| {
        keys.iter()
            .find(|(key, _)| key == k)
            .map(|(_, v)| v.as_str())
    };
    let num = |k: &str| get(k).and_then(|v| v.parse::<f64>().ok());
    let mm = |k: &str| num(k).map(|v| short(v * 1e3));
    let mut parts = Vec::new();
    match (mm("block.lx"), mm("block.ly"), mm("block.lz")) {
        (Some(lx), Some(ly), Some(lz)) => parts.push(format!("{lx} x {ly} x {lz} mm")),
        // A sweep's title leaves out its axes.
        (lx, ly, lz) => {
            for (symbol, value) in [("Lx", lx), ("Ly", ly), ("Lz", lz)] {
                if let Some(value) = value {
                    parts.push(format!("{symbol} = {value} mm"));
                }
            }
        }
    }
    if let Some(f) = num("normal_load") {
        parts.push(format!("F_N = {}", newtons(f)));
    }
    // A key that is a sweep's axis is left out of its title (the legend gives it): the
    // drive is then named without that value.
    let rod = |key: &str| match mm(key) {
        Some(h) => format!("rod at h = {h} mm"),
        None => "rod".to_string(),
    };
    let lateral = || match get("drive.lateral.kind") {
        Some("rod") => rod("drive.lateral.height"),
        _ => "side".to_string(),
    };
    match get("drive.kind") {
        Some("rod") => parts.push(rod("drive.height")),
        Some("top") => parts.push("top shear".into()),
        Some("side") => parts.push("side shear".into()),
        Some("mixed") => parts.push(match num("drive.ratio") {
            Some(n) => format!("top and {} shear, n = {}", lateral(), short(n)),
            None => format!("top and {} shear", lateral()),
        }),
        Some("spring") => parts.push(match num("drive.stiffness") {
            Some(k) => format!("spring K_S = {} N/m on the {}", short(k), lateral()),
            None => format!("spring on the {}", lateral()),
        }),
        _ => {}
    }
    if let Some(xi) = mm("heights.correlation_length") {
        parts.push(format!("ξ = {xi} mm"));
    }
    // A rule or a map other than the paper's scalars changes the physics: two studies that
    // differ only by them must not share a title.
    if let Some(rule) = get("contact.rule").filter(|&r| r != "paper") {
        parts.push(format!("{rule} rule"));
    }
    for (map, symbol) in [
        ("friction_coefficient", "μ"),
        ("c_x", "c_x"),
        ("c_z", "c_z"),
    ] {
        let key = |k: &str| format!("maps.{map}.{k}");
        if get(&key("kind")).is_none() {
            continue;
        }
        let mut text = format!("{symbol} map");
        let stats: Vec<String> = [("mean", "mean"), ("std_dev", "sd")]
            .iter()
            .filter_map(|(k, name)| num(&key(k)).map(|v| format!("{name} {}", short(v))))
            .collect();
        if !stats.is_empty() {
            text = format!("{text} ({})", stats.join(", "));
        }
        if let Some(xi) = mm(&key("correlation_length")) {
            let xi_of = match map {
                "friction_coefficient" => "ξ_μ".to_string(),
                _ => format!("ξ({symbol})"),
            };
            text = format!("{text}, {xi_of} = {xi} mm");
        }
        parts.push(text);
    }
    if let Some(seed) = get("heights.seed") {
        parts.push(format!("seed {seed}"));
    }
    if let Some(grid) = grid(keys) {
        parts.push(grid);
    }
    parts.join(", ")
}

/// A scene's grid in words, so that two scenes on different grids never share a title:
/// `140 x 7 cells of 1 mm` (`of 1 x 0.5 mm` for cells not square), `Δx = 0.5 mm` where
/// the block's length is a sweep's axis (and so left out of its title), `20 x 4 cells`
/// where the block is.
fn grid(keys: &[(String, String)]) -> Option<String> {
    let get = |k: &str| {
        keys.iter()
            .find(|(key, _)| key == k)
            .map(|(_, v)| v.as_str())
    };
    let num = |k: &str| get(k).and_then(|v| v.parse::<f64>().ok());
    let (lx, ly) = (num("block.lx"), num("block.ly"));
    let side = |dx: f64, dy: f64| {
        if (dx - dy).abs() <= 1e-9 * dx.abs().max(dy.abs()) {
            format!("{} mm", short(dx * 1e3))
        } else {
            format!("{} x {} mm", short(dx * 1e3), short(dy * 1e3))
        }
    };
    match get("cells.kind")? {
        "size" => {
            let (dx, dy) = (num("cells.dx")?, num("cells.dy").or(num("cells.dx"))?);
            Some(match (lx, ly) {
                (Some(lx), Some(ly)) => format!(
                    "{} x {} cells of {}",
                    (lx / dx).round(),
                    (ly / dy).round(),
                    side(dx, dy)
                ),
                _ if (dx - dy).abs() <= 1e-9 * dx => format!("Δx = {} mm", short(dx * 1e3)),
                _ => format!("Δx = {} mm, Δy = {} mm", short(dx * 1e3), short(dy * 1e3)),
            })
        }
        "count" => {
            let (nx, ny) = (num("cells.nx")?, num("cells.ny")?);
            Some(match (lx, ly) {
                (Some(lx), Some(ly)) => format!("{nx} x {ny} cells of {}", side(lx / nx, ly / ny)),
                _ => format!("{nx} x {ny} cells"),
            })
        }
        _ => None,
    }
}

/// A sweep axis's value in the user's words and units: `Ly = 7 mm` for `block.ly =
/// 0.007`, `F_N = 3.5 kN` for `normal_load = 3500`; other keys as written.
fn axis_value(key: &str, value: &str) -> String {
    // A key's underscores are its own, not the figures' subscript marks.
    let literal = |text: &str| text.replace('_', "\\_");
    let Ok(v) = value.parse::<f64>() else {
        return format!("{} = {}", literal(key), literal(value));
    };
    let length = |symbol: &str| format!("{symbol} = {} mm", short(v * 1e3));
    match key {
        "block.lx" => length("Lx"),
        "block.ly" => length("Ly"),
        "block.lz" => length("Lz"),
        "cells.dx" => length("Δx"),
        "cells.dy" => length("Δy"),
        "normal_load" => format!("F_N = {}", newtons(v)),
        "drive.height" | "drive.lateral.height" => length("h"),
        "drive.half_width" | "drive.lateral.half_width" => length("Δh"),
        "drive.ratio" => format!("n = {}", short(v)),
        "drive.stiffness" => format!("K_S = {} N/m", short(v)),
        "heights.correlation_length" => length("ξ"),
        "heights.mean" => format!("mean u0 = {} µm", short(v * 1e6)),
        "heights.std_dev" => format!("sd u0 = {} µm", short(v * 1e6)),
        "material.friction_coefficient" => format!("μ = {}", short(v)),
        "material.young_modulus" => format!("E = {} GPa", short(v / 1e9)),
        "material.poisson_ratio" => format!("ν = {}", short(v)),
        "springs.c_x" => format!("c_x = {} N/m³", short(v)),
        "springs.c_z" => format!("c_z = {} N/m²", short(v)),
        "maps.friction_coefficient.correlation_length" => length("ξ_μ"),
        "maps.friction_coefficient.mean" => format!("mean μ = {}", short(v)),
        "maps.friction_coefficient.std_dev" => format!("sd μ = {}", short(v)),
        "maps.c_x.correlation_length" => length("ξ(c_x)"),
        "maps.c_z.correlation_length" => length("ξ(c_z)"),
        _ => format!("{} = {value}", literal(key)),
    }
}

fn corrupt(path: &Path, reason: String) -> Error {
    Error::CorruptTable {
        path: Some(path.to_path_buf()),
        reason,
    }
}

/// The figures of one run directory.
fn draw_run(
    dir: &Path,
    formats: &[Format],
    canvas: Canvas,
    selection: &Selection,
) -> Result<Drawn, PlotError> {
    let title = run_title(dir);
    // The tables checked against the scene, each other and their bounds.
    let record = RunRecord::read(dir)?;
    let mut drawn = Drawn {
        files: Vec::new(),
        merge: None,
        notes: Vec::new(),
    };
    // Both staircases share the load axis, up to the highest force or the slip.
    let top = record
        .curve
        .iter()
        .map(|c| c.load)
        .chain(Some(record.slip))
        .filter(|f| f.is_finite())
        .fold(1.0, f64::max);
    let run = (dir, formats, canvas, title.as_str(), &record);
    if selection.wants(PRECURSOR_FIGURE) {
        drawn.files.extend(draw_precursor(run, top)?);
    }
    if selection.wants(AREA_FIGURE) {
        drawn.files.extend(draw_area(run, top)?);
    }
    if selection.wants(MAP_FIGURE) {
        draw_contact_map(
            dir,
            formats,
            canvas,
            (&title, &record),
            selection,
            &mut drawn,
        )?;
    }
    let extensions: Vec<&str> = formats.iter().map(|f| f.extension()).collect();
    if selection.wants(STICK_SLIP_FIGURE) {
        drawn
            .files
            .extend(draw_stick_slip(dir, &extensions, canvas, &title, &record)?);
    }
    let profiles = draw_profiles(dir, &extensions, canvas, (&title, &record), selection)?;
    drawn.files.extend(profiles.files);
    drawn.notes.extend(profiles.notes);
    Ok(drawn)
}

/// A run's directory, formats, canvas, title and checked tables: what each of its
/// figures is drawn from.
type Run<'a> = (&'a Path, &'a [Format], Canvas, &'a str, &'a RunRecord);

/// The precursor figure of a run: `ℓ/Lx` at the stable states against the load, up to
/// `top` (`F/(μF_N)`).
fn draw_precursor(
    (dir, formats, canvas, title, record): Run<'_>,
    top: f64,
) -> Result<Vec<PathBuf>, PlotError> {
    // The staircase ends at the last stable state; the run ends at global slip, where the
    // whole interface slides (ℓ = Lx): a marker there.
    let slip = Some(record.slip);
    let ell: Vec<(f64, f64)> = record
        .curve
        .iter()
        .map(|c| (c.load, c.precursor_over_lx))
        .collect();
    let mut files = Vec::new();
    for &format in formats {
        let path = dir.join(format!("{PRECURSOR_FIGURE}.{}", format.extension()));
        let mut chart = canvas
            .chart(&format!("Precursor length: {title}"), "F/(μF_N)", "ℓ/Lx")
            .x_range(0.0, top)
            .y_range(0.0, 1.0)
            .steps("ℓ/Lx at the stable states", &ell)
            .legend(Corner::UpperLeft);
        if let Some(slip) = slip {
            chart = chart.markers(
                &format!("global slip at F/(μF_N) = {slip:.3}"),
                &[(slip, 1.0)],
            );
        }
        chart.save(&path)?;
        files.push(path);
    }
    Ok(files)
}

/// The area figure of a run: `A_R/A_R(0)` at the stable states against the load, up to
/// `top` (`F/(μF_N)`).
fn draw_area(
    (dir, formats, canvas, title, record): Run<'_>,
    top: f64,
) -> Result<Vec<PathBuf>, PlotError> {
    let a0 = record.curve.first().map_or(f64::NAN, |c| c.area);
    let area: Vec<(f64, f64)> = record.curve.iter().map(|c| (c.load, c.area / a0)).collect();
    // Near slip the paper's unbounded area law can reach many times A_R(0) (flagged in
    // area_exceeds_nominal): the chart shows up to 2 and its legend says how many
    // states lie above.
    let area_top = area
        .iter()
        .map(|p| p.1)
        .filter(|a| a.is_finite())
        .fold(1.0, f64::max);
    let above = area.iter().filter(|p| p.1 > 2.0).count();
    let area_note = (above > 0).then(|| {
        format!(
            "{above} states above 2 (off the chart), up to {}",
            short(area_top)
        )
    });
    let mut files = Vec::new();
    for &format in formats {
        let path = dir.join(format!("{AREA_FIGURE}.{}", format.extension()));
        let mut chart = canvas
            .chart(
                &format!("Real contact area: {title}"),
                "F/(μF_N)",
                "A_R/A_R(0)",
            )
            .x_range(0.0, top)
            .y_range(0.0, (1.04 * area_top).min(2.0))
            .steps("A_R/A_R(0) at the stable states", &area)
            .legend(Corner::LowerLeft);
        if let Some(note) = &area_note {
            chart = chart.note(note);
        }
        chart.save(&path)?;
        files.push(path);
    }
    Ok(files)
}

/// The contact map of a run (`contact_map.csv`: each column's real contact area relative
/// to zero shear over `x/Lx` and the load), `ℓ` and the damage front over it; a note in
/// `drawn` when the run has no map.
fn draw_contact_map(
    dir: &Path,
    formats: &[Format],
    canvas: Canvas,
    (title, record): (&str, &RunRecord),
    selection: &Selection,
    drawn: &mut Drawn,
) -> Result<(), PlotError> {
    let map_path = dir.join("contact_map.csv");
    let Some(rows) = &record.map else {
        let reason = format!(
            "{} is missing (written by this version's `run`)",
            map_path.display()
        );
        return selection.skip(MAP_FIGURE, dir, reason, &mut drawn.notes);
    };
    // As the rows were: event, load, the columns' areas.
    let map: Vec<Vec<f64>> = rows
        .iter()
        .map(|r| {
            [r.event as f64, r.level as f64 * MAP_STEP]
                .into_iter()
                .chain(r.columns.iter().copied())
                .collect()
        })
        .collect();
    let nx = record.bounds.nx;
    let Some(first) = map.first() else {
        let reason = format!("{} has no rows", map_path.display());
        return selection.skip(MAP_FIGURE, dir, reason, &mut drawn.notes);
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
    let half = MAP_STEP / 2.0;
    // Rows at their loads, the axis up to 1 (a tick there: global slip under force
    // control) even when the last stable state lies below.
    let edges: Vec<f64> = (0..=map.len())
        .map(|r| {
            if r < map.len() {
                map[r][1] - half
            } else {
                high + half
            }
        })
        .collect();
    let y_top = (high + half).max(1.0 + half);
    let (ell_line, front_line) = front_lines(record, y_top)?;
    let reference_label = if low == 0.0 {
        "A_R(x, F)/A_R(x, 0)".to_string()
    } else {
        format!("A_R(x, F)/A_R(x) at F/(μF_N) = {low:.3}")
    };
    for &format in formats {
        let path = dir.join(format!("{MAP_FIGURE}.{}", format.extension()));
        let mut figure = Map::new(nx, map.len(), values.clone())?
            .labels(
                &format!("Contact area per column; ℓ solid, x_D dashed: {title}"),
                "x/Lx (trailing edge at 0)",
                "F/(μF_N)",
                &reference_label,
            )
            .size(canvas.size.0, canvas.size.1)
            .dpi(canvas.dpi)
            .x_range(0.0, 1.0)
            .y_range(low - half, y_top)
            .colour_scale(Palette::Diverging, Some((0.0, 2.0)));
        figure.row_edges = Some(edges.clone());
        figure.overlay = vec![ell_line.clone()];
        figure.dashed_overlay = vec![front_line.clone()];
        figure.notes = vec![
            "solid: ℓ(F)/Lx, the precursor length of curve.csv; dashed: x_D(F)/Lx, the \
             damage front of fronts.csv"
                .into(),
        ];
        figure.save(&path)?;
        drawn.files.push(path);
    }
    Ok(())
}

/// A polyline in a figure's axis units.
type Line = Vec<(f64, f64)>;

/// `ℓ/Lx` and the damage front `x_D/Lx` as lines over a contact map (x along the block,
/// y the load): each held from its stable state's load up to the next one's (global
/// slip's for the last), cut at `y_top`.
fn front_lines(record: &RunRecord, y_top: f64) -> Result<(Line, Line)> {
    let fronts = derive(&record.grid, &record.events)?.fronts;
    let vertical_steps = |x: &dyn Fn(usize) -> f64| {
        let mut line = Vec::with_capacity(2 * record.curve.len());
        for (k, c) in record.curve.iter().enumerate() {
            let next = record.curve.get(k + 1).map_or(record.slip, |n| n.load);
            line.push((x(k), c.load));
            line.push((x(k), next.min(y_top)));
        }
        line
    };
    Ok((
        vertical_steps(&|k| record.curve[k].precursor_over_lx),
        vertical_steps(&|k| fronts[k] / record.bounds.lx),
    ))
}

/// The figures of a sweep directory, after merging it.
fn draw_sweep(
    dir: &Path,
    formats: &[Format],
    canvas: Canvas,
    selection: &Selection,
) -> Result<Drawn, PlotError> {
    let summary = merge(dir)?;
    let grid: Vec<f64> = (0..=200).map(|k| k as f64 * 0.005).collect();
    let points = if selection.wants(PRECURSOR_FIGURE) || selection.wants(AREA_FIGURE) {
        crate::sweep::ensemble_curves(dir, &grid)?
    } else {
        Vec::new()
    };
    let title = sweep_title(dir);
    let label = point_label;
    let (colours, order) = point_order(&points.iter().map(|p| &p.values[..]).collect::<Vec<_>>());
    let mut drawn = Drawn {
        files: Vec::new(),
        merge: None,
        notes: Vec::new(),
    };
    for &format in formats.iter().filter(|_| selection.wants(PRECURSOR_FIGURE)) {
        let mut chart = canvas
            .chart(
                &format!("Precursor length: {title}, mean and 95 % band"),
                "F/(μF_N)",
                "ℓ/Lx",
            )
            .x_range(0.0, 1.0)
            .y_range(0.0, 1.0)
            .colours(colours)
            .legend(Corner::UpperLeft);
        for p in order.iter().map(|&k| &points[k]) {
            // ℓ/Lx lies in [0, 1]: so does its band (the t-band of few runs can reach out).
            let clipped: Vec<(f64, f64, f64, f64)> = p
                .precursor
                .iter()
                .map(|&(f, mean, low, high)| (f, mean, clip(low, 0.0, 1.0), clip(high, 0.0, 1.0)))
                .collect();
            chart = chart.band(&label(&p.values, p.runs), &clipped);
        }
        let path = dir.join(format!("{PRECURSOR_FIGURE}.{}", format.extension()));
        chart.save(&path)?;
        drawn.files.push(path);
    }
    if selection.wants(AREA_FIGURE) {
        let chart = area_chart(canvas, &title, (colours, &order), &points);
        for &format in formats {
            let path = dir.join(format!("{AREA_FIGURE}.{}", format.extension()));
            chart.save(&path)?;
            drawn.files.push(path);
        }
    }
    if selection.wants(ARCHARD_FIGURE) {
        let extensions: Vec<&str> = formats.iter().map(|f| f.extension()).collect();
        let archard = draw_archard(dir, &extensions, canvas, (&title, point_label), NORMAL_LOAD)?;
        drawn.files.extend(archard.files);
        drawn.notes.extend(archard.notes);
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

/// A sweep's `contact_area`: each point's median of `A_R/A_R(0)` and its interval, the
/// points in `order` coloured by `colours`; what holds for several curves (no interval
/// below [`MEDIAN_BAND_RUNS`] runs, values off the chart) said once, in notes.
fn area_chart(
    canvas: Canvas,
    title: &str,
    (colours, order): (Colours, &[usize]),
    points: &[crate::sweep::EnsembleCurves],
) -> Chart {
    // As for a run: near slip the unbounded area law can reach many times A_R(0).
    let area_top = points
        .iter()
        .flat_map(|p| p.area.iter().flat_map(|r| [r.1, r.3]))
        .filter(|a| a.is_finite())
        .fold(1.0, f64::max);
    // The median and its distribution-free interval, not the mean's t-band: near slip
    // the area law spreads the realizations over orders of magnitude, a few of them
    // carry the mean, and a t-band of it spans the whole chart.
    let mut chart = canvas
        .chart(
            &format!("Real contact area: {title}, median and 95 % interval"),
            "F/(μF_N)",
            "A_R/A_R(0)",
        )
        .x_range(0.0, 1.0)
        .y_range(0.0, (1.04 * area_top).min(2.0))
        .colours(colours)
        .legend(Corner::LowerLeft);
    for p in order.iter().map(|&k| &points[k]) {
        chart = chart.band(&point_label(&p.values, p.runs), &p.area);
    }
    if points.iter().any(|p| p.runs < MEDIAN_BAND_RUNS) {
        chart = chart.note(&format!(
            "below {MEDIAN_BAND_RUNS} runs: the median without an interval"
        ));
    }
    if area_top > 2.0 {
        chart = chart.note(&format!(
            "above 2 off the chart (up to {})",
            short(area_top)
        ));
    }
    chart
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweep_axes_are_named_in_the_users_units() {
        assert_eq!(axis_value("block.ly", "0.007"), "Ly = 7 mm");
        assert_eq!(axis_value("block.lz", "0.0194"), "Lz = 19.4 mm");
        assert_eq!(axis_value("normal_load", "3500.0"), "F_N = 3.5 kN");
        assert_eq!(axis_value("normal_load", "750"), "F_N = 750 N");
        assert_eq!(
            axis_value("heights.correlation_length", "0.003"),
            "ξ = 3 mm"
        );
        assert_eq!(axis_value("drive.ratio", "0.25"), "n = 0.25");
        assert_eq!(axis_value("drive.stiffness", "4000000"), "K_S = 4e6 N/m");
        assert_eq!(axis_value("springs.c_z", "2.5e10"), "c_z = 2.5e10 N/m²");
        // Keys without a symbol, and values that are not numbers, as written.
        assert_eq!(
            axis_value("solver.backend", "\"dense\""),
            "solver.backend = \"dense\""
        );
        assert_eq!(axis_value("heights.seed", "x"), "heights.seed = x");
    }

    /// A key that is a sweep's axis is not in the sweep's title: the drive is named
    /// without its value (not "rod at h =  mm", "K_S = NaN N/m").
    #[test]
    fn a_drive_without_its_swept_value_is_named_alone() {
        let keys = |pairs: &[(&str, &str)]| {
            pairs
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect::<Vec<_>>()
        };
        assert_eq!(describe(&keys(&[("drive.kind", "rod")])), "rod");
        assert_eq!(
            describe(&keys(&[
                ("drive.kind", "mixed"),
                ("drive.lateral.kind", "rod")
            ])),
            "top and rod shear"
        );
        assert_eq!(
            describe(&keys(&[
                ("drive.kind", "spring"),
                ("drive.lateral.kind", "side")
            ])),
            "spring on the side"
        );
    }

    #[test]
    fn a_scene_is_described_by_its_keys() {
        let keys = |pairs: &[(&str, &str)]| {
            pairs
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect::<Vec<_>>()
        };
        let calibration = keys(&[
            ("block.lx", "0.14"),
            ("block.ly", "0.007"),
            ("block.lz", "0.075"),
            ("normal_load", "3500.0"),
            ("drive.kind", "rod"),
            ("drive.height", "0.006"),
            ("heights.seed", "1"),
        ]);
        assert_eq!(
            describe(&calibration),
            "140 x 7 x 75 mm, F_N = 3.5 kN, rod at h = 6 mm, seed 1"
        );
        let spring = keys(&[
            ("block.lx", "0.03"),
            ("normal_load", "750"),
            ("drive.kind", "spring"),
            ("drive.stiffness", "4000000"),
            ("drive.lateral.kind", "side"),
        ]);
        assert_eq!(
            describe(&spring),
            "Lx = 30 mm, F_N = 750 N, spring K_S = 4e6 N/m on the side"
        );
    }

    /// docs/statistics.md's two surface studies differ in their cells alone: their titles
    /// say so (they were the same before the grid was named).
    #[test]
    fn scenes_on_different_grids_get_different_titles() {
        let keys = |dx: &str| -> Vec<(String, String)> {
            [
                ("block.lx", "0.14"),
                ("block.ly", "0.007"),
                ("block.lz", "0.075"),
                ("cells.kind", "size"),
                ("cells.dx", dx),
                ("cells.dy", dx),
                ("normal_load", "3500.0"),
                ("drive.kind", "rod"),
                ("drive.height", "0.006"),
                ("heights.correlation_length", "0.003"),
            ]
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect()
        };
        let coarse = describe(&keys("0.001"));
        let fine = describe(&keys("0.0005"));
        assert_eq!(
            coarse,
            "140 x 7 x 75 mm, F_N = 3.5 kN, rod at h = 6 mm, ξ = 3 mm, 140 x 7 cells of 1 mm"
        );
        assert_eq!(
            fine,
            "140 x 7 x 75 mm, F_N = 3.5 kN, rod at h = 6 mm, ξ = 3 mm, 280 x 14 cells of 0.5 mm"
        );
        // A sweep over the length: the cell size alone.
        let mut over_lx = keys("0.001");
        over_lx.retain(|(k, _)| k != "block.lx");
        assert!(
            describe(&over_lx).ends_with("ξ = 3 mm, Δx = 1 mm"),
            "{}",
            describe(&over_lx)
        );
        let count: Vec<(String, String)> = [
            ("block.lx", "0.02"),
            ("block.ly", "0.004"),
            ("block.lz", "0.01"),
            ("cells.kind", "count"),
            ("cells.nx", "20"),
            ("cells.ny", "8"),
        ]
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
        assert_eq!(
            describe(&count),
            "20 x 4 x 10 mm, 20 x 8 cells of 1 x 0.5 mm"
        );
    }

    /// The lx sweep of the finite-size study: 50 realizations planned, 11 complete at
    /// its longest block.
    #[test]
    fn a_title_counts_the_complete_runs_of_each_point() {
        assert_eq!(
            realizations(&[50, 50, 50, 50, 11], 50),
            "11-50 of 50 realizations per point"
        );
        assert_eq!(realizations(&[41, 41], 50), "41 of 50 realizations");
        assert_eq!(realizations(&[50, 50], 50), "50 realizations");
        assert_eq!(realizations(&[], 50), "50 realizations");
    }

    #[test]
    fn bands_are_clipped_and_a_missing_band_stays_missing() {
        assert_eq!(clip(-0.2, 0.0, 1.0), 0.0);
        assert_eq!(clip(1.3, 0.0, 1.0), 1.0);
        assert_eq!(clip(0.4, 0.0, 1.0), 0.4);
        assert!(clip(f64::NAN, 0.0, 1.0).is_nan());
    }

    #[test]
    fn axis_keys_keep_their_underscores_in_legends() {
        // Drawn as written: no piece of the label is a subscript.
        let plain = |label: String| {
            let pieces = super::super::subscripts(&label);
            assert!(pieces.iter().all(|(_, sub)| !sub), "{label}: {pieces:?}");
            pieces.into_iter().map(|(t, _)| t).collect::<String>()
        };
        assert_eq!(
            plain(axis_value("maps.friction_coefficient.seed", "7")),
            "maps.friction_coefficient.seed = 7"
        );
        assert_eq!(
            plain(axis_value("contact.rule", "\"anchored_x\"")),
            "contact.rule = \"anchored_x\""
        );
        assert_eq!(
            axis_value("maps.friction_coefficient.correlation_length", "0.005"),
            "ξ_μ = 5 mm"
        );
    }

    #[test]
    fn titles_name_the_contact_rule_and_the_maps() {
        let keys = |pairs: &[(&str, &str)]| -> Vec<(String, String)> {
            pairs
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect()
        };
        let base = [("drive.kind", "top"), ("contact.rule", "paper")];
        assert_eq!(describe(&keys(&base)), "top shear");
        let anchored = [("drive.kind", "top"), ("contact.rule", "anchored")];
        assert_eq!(describe(&keys(&anchored)), "top shear, anchored rule");
        let mapped = [
            ("drive.kind", "top"),
            ("maps.friction_coefficient.kind", "gaussian_surface"),
            ("maps.friction_coefficient.correlation_length", "0.005"),
            ("maps.friction_coefficient.mean", "0.5"),
            ("maps.friction_coefficient.std_dev", "0.2"),
            ("maps.c_z.kind", "values"),
        ];
        assert_eq!(
            describe(&keys(&mapped)),
            "top shear, μ map (mean 0.5, sd 0.2), ξ_μ = 5 mm, c_z map"
        );
    }
}
