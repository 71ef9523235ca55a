//! `fronts` of a sweep: over the realizations of each point, the median and the
//! interquartile range of `ℓ/Lx` and of the damage front `x_D/Lx` against `F/(μF_N)`,
//! each run at its last stable state at or below the load (its whole length from its
//! global slip on), next to one run's staircases (the point's first complete run).

use super::distributions::{PointLabel, Statistics, ONE_CHART_POINTS};
use super::{point_order, series_colour, Canvas, Chart, Corner, Panels, PlotError, Style};
use crate::output::check::RunRecord;
use crate::output::derived::derive;
use crate::output::layout::FRONTS_FIGURE;
use crate::sweep::stats::Point;
use std::path::Path;

/// The loads of the ensemble curves: `F/(μF_N)` = 0, 0.005, ..., 1.
const GRID: usize = 200;

/// One run's fronts: `(F/(μF_N), ℓ/Lx, x_D/Lx)` at each stable state, and global slip's
/// load.
struct Fronts {
    states: Vec<(f64, f64, f64)>,
    slip: f64,
}

impl Fronts {
    fn of(record: &RunRecord) -> crate::error::Result<Fronts> {
        let derived = derive(&record.grid, &record.events)?;
        let lx = record.bounds.lx;
        let states = record
            .curve
            .iter()
            .zip(&derived.fronts)
            .map(|(c, x)| (c.load, c.precursor_over_lx, x / lx))
            .collect();
        Ok(Fronts {
            states,
            slip: record.slip,
        })
    }

    /// `(ℓ/Lx, x_D/Lx)` in effect at `load`: the last stable state's at or below it, 0
    /// before the first, the whole length from global slip on.
    fn at(&self, load: f64) -> (f64, f64) {
        if load >= self.slip {
            return (1.0, 1.0);
        }
        self.states
            .iter()
            .take_while(|s| s.0 <= load)
            .last()
            .map_or((0.0, 0.0), |s| (s.1, s.2))
    }
}

/// The `q`-quantile of sorted values (linear between order statistics).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let h = q * (sorted.len() - 1) as f64;
    let (k, t) = (h.floor() as usize, h - h.floor());
    let next = sorted[(k + 1).min(sorted.len() - 1)];
    sorted[k] + t * (next - sorted[k])
}

/// `(load, median, first quartile, third quartile)` of a front over the runs, on the grid.
type Band = Vec<(f64, f64, f64, f64)>;

/// The median and interquartile bands of `ℓ/Lx` and `x_D/Lx` over `runs`.
fn bands(runs: &[Fronts]) -> (Band, Band) {
    let mut ell = Vec::with_capacity(GRID + 1);
    let mut front = Vec::with_capacity(GRID + 1);
    for k in 0..=GRID {
        let load = k as f64 / GRID as f64;
        let (mut a, mut b): (Vec<f64>, Vec<f64>) = runs.iter().map(|r| r.at(load)).unzip();
        a.sort_by(f64::total_cmp);
        b.sort_by(f64::total_cmp);
        let row = |v: &[f64]| (load, quantile(v, 0.5), quantile(v, 0.25), quantile(v, 0.75));
        ell.push(row(&a));
        front.push(row(&b));
    }
    (ell, front)
}

/// Draws `fronts` of the sweep in `dir` from its `points`: each point's bands, and for a
/// sweep of one point its first run's staircases beside them. Up to
/// [`ONE_CHART_POINTS`] points share one chart; more are drawn one a panel ([`Panels`]),
/// titled by their points, so that the legend never outgrows the figure.
pub(super) fn ensemble_fronts(
    dir: &Path,
    extensions: &[&str],
    canvas: Canvas,
    (title, label): (&str, PointLabel),
    points: &[Point],
) -> Result<Statistics, PlotError> {
    let mut drawn = Statistics::default();
    let (colours, order) = point_order(&points.iter().map(|p| &p.values[..]).collect::<Vec<_>>());
    let heading = format!("Precursor and damage fronts: {title}, median and interquartile range");
    let empty = |title: &str| -> Chart {
        canvas
            .chart(title, "F/(μF_N)", "x/Lx")
            .x_range(0.0, 1.0)
            .y_range(0.0, 1.0)
            .legend(Corner::UpperLeft)
    };
    let panels = points.len() > ONE_CHART_POINTS;
    let mut chart = empty(&heading);
    let mut charts = Vec::new();
    let mut drew = false;
    for (k, point) in order.iter().map(|&k| &points[k]).enumerate() {
        let mut runs = Vec::with_capacity(point.runs());
        point.for_each_record(|_, record| {
            runs.push(Fronts::of(record)?);
            Ok(())
        })?;
        if runs.is_empty() {
            continue;
        }
        drew = true;
        let colour = series_colour(colours, k, points.len());
        let style = Style::new().colour(colour.0, colour.1, colour.2);
        let name = if points.len() == 1 && point.values.is_empty() {
            format!("{} runs", runs.len())
        } else {
            label(&point.values, point.runs())
        };
        let (ell, front) = bands(&runs);
        if panels {
            charts.push(
                empty(&name)
                    .band("ℓ/Lx, median and quartiles", &ell)
                    .style(style)
                    .band("x_D/Lx, median and quartiles", &front)
                    .style(style.dashed()),
            );
            continue;
        }
        chart = chart
            .band(&format!("ℓ/Lx, median and quartiles: {name}"), &ell)
            .style(style)
            .band(&format!("x_D/Lx, median and quartiles: {name}"), &front)
            .style(style.dashed());
        if points.len() == 1 {
            let one = &runs[0];
            let steps = |f: fn(&(f64, f64, f64)) -> f64| -> Vec<(f64, f64)> {
                one.states
                    .iter()
                    .map(|s| (s.0, f(s)))
                    .chain(std::iter::once((one.slip, 1.0)))
                    .collect()
            };
            let grey = Style::new().colour(60, 60, 60);
            chart = chart
                .steps("ℓ/Lx of one run (its first)", &steps(|s| s.1))
                .style(grey)
                .steps("x_D/Lx of one run", &steps(|s| s.2))
                .style(grey.dashed());
        }
    }
    if !drew {
        drawn.notes.push(format!(
            "no {FRONTS_FIGURE} figure: the sweep has no complete run"
        ));
        return Ok(drawn);
    }
    let note = "ℓ: columns below their zero-shear area; x_D: columns with half their contacts lost";
    let figure = Panels {
        title: heading,
        notes: vec![note.to_string()],
        charts,
        panel: canvas.size,
        dpi: canvas.dpi,
    };
    let chart = chart.note(note);
    for extension in extensions {
        let path = dir.join(format!("{FRONTS_FIGURE}.{extension}"));
        if panels {
            figure.save(&path)?;
        } else {
            chart.save(&path)?;
        }
        drawn.files.push(path);
    }
    Ok(drawn)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quartiles_interpolate_between_order_statistics() {
        let v = [0.0, 1.0, 2.0, 3.0, 4.0];
        assert_eq!(quantile(&v, 0.5), 2.0);
        assert_eq!(quantile(&v, 0.25), 1.0);
        assert_eq!(quantile(&[0.0, 1.0], 0.75), 0.75);
        let run = Fronts {
            states: vec![(0.0, 0.0, 0.0), (0.4, 0.1, 0.3), (0.8, 0.2, 0.6)],
            slip: 0.95,
        };
        assert_eq!(run.at(0.39), (0.0, 0.0));
        assert_eq!(run.at(0.4), (0.1, 0.3));
        assert_eq!(run.at(0.9), (0.2, 0.6));
        assert_eq!(run.at(0.95), (1.0, 1.0));
    }
}
