//! Counterparts of two of the paper's figures, drawn by [`super::draw_with_options`]
//! beside the standard ones: `stick_slip` (Fig. 4: a driving spring's force against the
//! drive displacement, from a run's `events.csv`) and `archard` (Fig. 2a: the real
//! contact area at zero shear against the normal load, over a sweep's points).

use super::distributions::{PointLabel, Statistics};
use super::{point_order, series_colour, Canvas, Chart, Corner, PlotError, Style};
use crate::driver::Event;
use crate::error::Error;
use crate::output::check::RunRecord;
use crate::output::derived::derive;
use crate::output::layout::{ARCHARD_FIGURE, STICK_SLIP_FIGURE};
use crate::sweep::stats::points;
use std::path::{Path, PathBuf};

/// Draws `stick_slip` of a run driven through a spring (`record`, read from `dir`) into
/// `dir`: `F/(μF_N)` against `U_S` (µm) at every event with a load, in order (a load step
/// raises both; the ruptures of an avalanche and its stable state drop the force at the
/// same `U_S`).
///
/// # Errors
/// [`Error::CorruptTable`] for an event with a load but no drive displacement.
pub(super) fn draw_stick_slip(
    dir: &Path,
    extensions: &[&str],
    canvas: Canvas,
    title: &str,
    record: &RunRecord,
) -> Result<Vec<PathBuf>, PlotError> {
    let mu_fn = record.bounds.mu_fn;
    let mut points = Vec::with_capacity(record.events.len());
    for (k, event) in record.events.iter().enumerate() {
        let load = match event {
            Event::LoadRaised { load }
            | Event::Rupture { load, .. }
            | Event::Stable { load, .. }
            | Event::GlobalSlip { load } => load,
            _ => continue,
        };
        let Some(u) = load.drive_displacement else {
            return Err(Error::CorruptTable {
                path: Some(dir.join(crate::output::TABLES[0])),
                reason: format!(
                    "event {}: a {} of a run driven through a spring without its \
                     drive_displacement_m",
                    k + 1,
                    event.kind()
                ),
            }
            .into());
        };
        points.push((u * 1e6, load.force / mu_fn));
    }
    let drops = derive(&record.grid, &record.events)?
        .avalanches
        .iter()
        .filter(|a| !a.global_slip && a.force_drop() > 0.0)
        .count();
    let u_top = points.iter().map(|p| p.0).fold(0.0, f64::max);
    let f_top = points.iter().map(|p| p.1).fold(1.0, f64::max);
    let slip = points.last().copied();
    let mut files = Vec::new();
    for extension in extensions {
        let path = dir.join(format!("{STICK_SLIP_FIGURE}.{extension}"));
        let mut chart = canvas
            .chart(&format!("Stick-slip: {title}"), "U_S (µm)", "F/(μF_N)")
            .x_range(0.0, if u_top > 0.0 { 1.05 * u_top } else { 1.0 })
            .y_range(0.0, 1.1 * f_top)
            .line(
                &format!(
                    "spring force K_S (U_S − ⟨u_x⟩) at each load step and rupture: {drops} \
                     force drops"
                ),
                &points,
            )
            .legend(Corner::LowerRight);
        if let Some((u, f)) = slip {
            chart = chart.markers(
                &format!("global slip at U_S = {u:.4} µm, F/(μF_N) = {f:.3}"),
                &[(u, f)],
            );
        }
        chart.save(&path)?;
        files.push(path);
    }
    Ok(files)
}

/// One series of `archard`: the points that share every axis value but the load's and
/// the drive's (the drive does not act at zero shear).
struct Series {
    rest: Vec<(String, String)>,
    /// `F_N` (N) and the real contact area at zero shear of each complete run (m²).
    loads: Vec<(f64, Vec<f64>)>,
    /// `Lx Ly` (m²).
    nominal: f64,
}

/// Draws `archard` of the sweep in `dir` (whose axes include `key`, the normal load)
/// into `dir`: `A_R(0)` (the first stable state's real contact area) of each complete
/// run in % of `Lx Ly` against `F_N`: the mean at each load with ± one sample standard
/// deviation (none of one run), and the least-squares line through the origin over every
/// run, `α = Σ F_N A_R / Σ F_N²` (m²/N).
///
/// # Errors
/// A run's damaged tables ([`PlotError::Core`]), the sweep's ([`PlotError::Sweep`]);
/// [`PlotError::Figure`] for a load that is not a number.
pub(super) fn draw_archard(
    dir: &Path,
    extensions: &[&str],
    canvas: Canvas,
    (title, label): (&str, PointLabel),
    key: &str,
) -> Result<Statistics, PlotError> {
    let mut drawn = Statistics::default();
    let all = archard_series(dir, key)?;
    if all.is_empty() {
        drawn.notes.push(format!(
            "no {ARCHARD_FIGURE} figure: the sweep has no complete run"
        ));
        return Ok(drawn);
    }
    let f_top = all
        .iter()
        .flat_map(|s| s.loads.iter().map(|l| l.0))
        .fold(0.0, f64::max)
        * 1.05;
    let mut chart = canvas
        .chart(
            &format!("Real contact area at zero shear: {title}"),
            "F_N (N)",
            "A_R(0)/(Lx Ly) (%)",
        )
        .legend(Corner::UpperLeft);
    let mut y_top: f64 = 0.0;
    let single = all.len() == 1 && all[0].rest.is_empty();
    // The series differ in the other axes: ordered along them where they are numbers.
    let (colours, order) = point_order(&all.iter().map(|s| &s.rest[..]).collect::<Vec<_>>());
    for (k, series) in order.iter().map(|&k| &all[k]).enumerate() {
        let colour = series_colour(colours, k, all.len());
        let style = Style::new().colour(colour.0, colour.1, colour.2);
        let prefix = (!single).then_some(label);
        let top;
        (chart, top) = archard_curves(chart, series, style, prefix, f_top);
        y_top = y_top.max(top);
    }
    let chart = chart
        .x_range(0.0, if f_top > 0.0 { f_top } else { 1.0 })
        .y_range(0.0, if y_top > 0.0 { 1.15 * y_top } else { 1.0 });
    for extension in extensions {
        let path = dir.join(format!("{ARCHARD_FIGURE}.{extension}"));
        chart.save(&path)?;
        drawn.files.push(path);
    }
    Ok(drawn)
}

/// The series of `archard`: every complete run's `A_R(0)` of the sweep in `dir`, grouped
/// by the axes other than `key` (the load) and the drive's, then by load.
///
/// # Errors
/// As [`draw_archard`].
fn archard_series(dir: &Path, key: &str) -> Result<Vec<Series>, PlotError> {
    let (_, points, _) = points(dir)?;
    let mut all: Vec<Series> = Vec::new();
    for point in &points {
        let Some((_, value)) = point.values.iter().find(|(k, _)| k == key) else {
            continue;
        };
        let f_n: f64 = match value.parse() {
            Ok(f) if f64::is_finite(f) => f,
            _ => {
                return Err(PlotError::Figure {
                    path: Some(dir.to_path_buf()),
                    reason: format!("the sweep's {key} {value} is not a number of newtons"),
                })
            }
        };
        let rest: Vec<(String, String)> = point
            .values
            .iter()
            .filter(|(k, _)| k != key && !k.starts_with("drive."))
            .cloned()
            .collect();
        let mut areas = Vec::new();
        let mut nominal = f64::NAN;
        point.for_each_record(|run_dir, record| {
            let first = record.curve.first().ok_or_else(|| Error::CorruptTable {
                path: Some(run_dir.join(crate::output::TABLES[1])),
                reason: "no stable state: the zero-shear state is missing".into(),
            })?;
            areas.push(first.area);
            let block = record.grid.block();
            nominal = block.lx() * block.ly();
            Ok(())
        })?;
        if areas.is_empty() {
            continue;
        }
        let k = match all.iter().position(|s| s.rest == rest) {
            Some(k) => k,
            None => {
                all.push(Series {
                    rest,
                    loads: Vec::new(),
                    nominal,
                });
                all.len() - 1
            }
        };
        match all[k].loads.iter_mut().find(|(f, _)| *f == f_n) {
            Some((_, a)) => a.extend(areas),
            None => all[k].loads.push((f_n, areas)),
        }
    }
    Ok(all)
}

/// Adds one series of `archard` to `chart` in `style`: its means, their error bars and its
/// least-squares line up to `f_top` (N), the labels prefixed by `label` of its axes where
/// there are several series. Returns the chart and the highest value drawn (%).
fn archard_curves(
    mut chart: Chart,
    series: &Series,
    style: Style,
    label: Option<PointLabel>,
    f_top: f64,
) -> (Chart, f64) {
    let percent = 100.0 / series.nominal;
    let runs: usize = series.loads.iter().map(|l| l.1.len()).sum();
    let (means, bars, mut y_top) = archard_means(series, percent);
    let alpha = archard_slope(series);
    y_top = y_top.max(alpha * f_top * percent);
    let prefix = match label {
        None => String::new(),
        Some(label) => format!("{}: ", label(&series.rest, runs)),
    };
    let mean_label = if label.is_none() {
        format!("mean at each load ({runs} runs)")
    } else {
        format!("{prefix}mean at each load")
    };
    chart = chart.markers(&mean_label, &means).style(style);
    if !bars.is_empty() {
        chart = chart
            .line(&format!("{prefix}± one standard deviation"), &bars)
            .style(style);
    }
    chart = chart
        .line(
            &format!("{prefix}least squares A_R = α F_N, α = {alpha:.4e} m²/N"),
            &[(0.0, 0.0), (f_top, alpha * f_top * percent)],
        )
        .style(style.dashed());
    (chart, y_top)
}

/// The mean `A_R(0)` at each load of `series` in % of `Lx Ly` (`percent` = 100 / `Lx Ly`),
/// the ± one sample standard deviation bars of the loads with several runs (segments cut
/// by a non-finite point), and the top of the highest bar or mean (%).
fn archard_means(series: &Series, percent: f64) -> (Points, Points, f64) {
    let mut y_top: f64 = 0.0;
    let mut means = Vec::new();
    let mut bars = Vec::new();
    for (f_n, areas) in &series.loads {
        let n = areas.len() as f64;
        let mean = areas.iter().sum::<f64>() / n;
        let sd = if areas.len() > 1 {
            (areas.iter().map(|a| (a - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
        } else {
            f64::NAN
        };
        means.push((*f_n, mean * percent));
        y_top = y_top.max((mean + if sd.is_nan() { 0.0 } else { sd }) * percent);
        if sd.is_finite() {
            bars.extend([
                (*f_n, (mean - sd) * percent),
                (*f_n, (mean + sd) * percent),
                (f64::NAN, f64::NAN),
            ]);
        }
    }
    (means, bars, y_top)
}

/// The `(F_N, %)` points of a curve of `archard`.
type Points = Vec<(f64, f64)>;

/// `α = Σ F_N A_R / Σ F_N²` (m²/N): the least-squares line through the origin over every
/// run of `series`.
fn archard_slope(series: &Series) -> f64 {
    let (fa, ff) = series
        .loads
        .iter()
        .flat_map(|(f, areas)| areas.iter().map(move |a| (f * a, f * f)))
        .fold((0.0, 0.0), |(x, y), (a, b)| (x + a, y + b));
    fa / ff
}
