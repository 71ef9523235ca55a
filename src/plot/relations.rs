//! The figures of `precursors stats`' relations and finite-size collapse, drawn from its
//! tables (`plot/tables.rs` reads them): `drop_against_size` and `potency_against_size`
//! (the binned means of `binned_means.csv` with their intervals, the least-squares power
//! law of `scaling.csv` with its exponent and interval in the legend) and, for a sweep
//! over a block length, `collapse` (`P(S) S^τ` against `S/L^D` from `distributions.csv`
//! at `collapse.csv`'s `τ` and `D`, their intervals in the legend). Their legends and
//! titles count the runs `stats` pooled (`power_laws.csv`'s `runs`), not those complete
//! now.

use super::distributions::{PointLabel, Statistics};
use super::selection::Selection;
use super::tables::{runs_pooled, Table};
use super::{point_order, series_colour, short, Canvas, Corner, PlotError, Style};
use crate::output::layout::{
    BINNED_MEANS, COLLAPSE, COLLAPSE_FIGURE, DISTRIBUTIONS, DROP_SIZE_FIGURE, POTENCY_SIZE_FIGURE,
    POWER_LAWS, SCALING,
};
use crate::sweep::stats::points;
use std::path::Path;

/// The fewest avalanches a bin needs to enter the collapse (`fit_collapse`'s rule).
const COLLAPSE_MIN_COUNT: f64 = 3.0;

/// A sweep's title over `runs[k]` runs of each point `k` (the runs `stats` pooled).
pub(super) type Retitle = fn(&Path, &[usize]) -> String;

/// Draws the figures of `stats`' relations and collapse that `selection` wants, from the
/// tables `stats` wrote into `dir`; a figure whose table is missing or holds no rows for
/// it is left out (an error where it was named; a note where an earlier plot's file of it
/// is in the directory, [`Selection::skip_quietly`]). `retitle` gives a sweep's title
/// over the runs `stats` pooled (`None`: a run's, `title`).
pub(super) fn draw_relations(
    dir: &Path,
    extensions: &[&str],
    canvas: Canvas,
    (title, label, retitle): (&str, PointLabel, Option<Retitle>),
    selection: &Selection,
) -> Result<Statistics, PlotError> {
    let mut drawn = Statistics::default();
    let wanted = [DROP_SIZE_FIGURE, POTENCY_SIZE_FIGURE, COLLAPSE_FIGURE];
    if !wanted.iter().any(|f| selection.wants(f)) {
        return Ok(drawn);
    }
    let (_, points, _) = points(dir)?;
    let values: Vec<&[(String, String)]> = points.iter().map(|p| &p.values[..]).collect();
    let (colours, order) = point_order(&values);
    // The runs that entered `stats`' tables, which may be fewer than those complete now
    // (a sweep still running when `stats` ran): the legends and the title count those.
    let pooled = Table::read(&dir.join(POWER_LAWS))?;
    let mut entered = Vec::with_capacity(points.len());
    // A table written before its column `runs` cannot say which runs it pooled.
    let mut unknown = false;
    for (k, p) in points.iter().enumerate() {
        let runs = match &pooled {
            Some(table) => runs_pooled(table, k)?,
            None => None,
        };
        unknown |= pooled.is_some() && runs.is_none();
        entered.push(runs.unwrap_or(p.runs()));
    }
    let title = match retitle {
        Some(retitle) => retitle(dir, &entered),
        None => title.to_string(),
    };
    let title = title.as_str();
    let names: Vec<String> = points
        .iter()
        .zip(&entered)
        .map(|(p, &runs)| {
            if points.len() == 1 && p.values.is_empty() {
                String::new()
            } else {
                label(&p.values, runs)
            }
        })
        .collect();
    let family = Family {
        names: &names,
        order: &order,
        colours,
    };
    let relations = [
        (
            DROP_SIZE_FIGURE,
            "force_drop_N_against_ruptures",
            ("Force drop against avalanche size", "ΔF (N)", "ΔF"),
        ),
        (
            POTENCY_SIZE_FIGURE,
            "potency_m3_against_ruptures",
            ("Potency against avalanche size", "potency (m³)", "P"),
        ),
    ];
    for (figure, relation, words) in relations {
        if selection.wants(figure) {
            relation_figure(
                dir,
                extensions,
                canvas,
                (figure, relation, title, words),
                &family,
                selection,
                &mut drawn,
            )?;
        }
    }
    if selection.wants(COLLAPSE_FIGURE) {
        collapse_figure(
            dir, extensions, canvas, title, &family, selection, &mut drawn,
        )?;
    }
    if !drawn.files.is_empty() && unknown {
        drawn.notes.push(format!(
            "{POWER_LAWS} names no runs (written before its column `runs`): the figures of \
             stats' tables count the runs complete now, which may not be those it pooled; run \
             `precursors stats` again"
        ));
    }
    let now: Vec<usize> = points.iter().map(|p| p.runs()).collect();
    if !drawn.files.is_empty() && entered != now {
        let list = |runs: &[usize]| {
            runs.iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        drawn.notes.push(format!(
            "the figures of stats' tables are drawn over the runs it pooled ({} a point); {} \
             are complete now: run `precursors stats` again",
            list(&entered),
            list(&now)
        ));
    }
    Ok(drawn)
}

/// The points' names in a legend, the order they are drawn in and their colours.
struct Family<'a> {
    names: &'a [String],
    order: &'a [usize],
    colours: super::Colours,
}

impl Family<'_> {
    fn prefix(&self, point: usize) -> String {
        match self.names.get(point) {
            Some(n) if !n.is_empty() => format!("{n}: "),
            _ => String::new(),
        }
    }
}

/// A relation's figure: each point's binned means of `y` against the size with their
/// intervals as error bars, and its fitted power law `y = c S^β`.
fn relation_figure(
    dir: &Path,
    extensions: &[&str],
    canvas: Canvas,
    (figure, relation, title, (what, y_label, symbol)): (&str, &str, &str, (&str, &str, &str)),
    family: &Family<'_>,
    selection: &Selection,
    drawn: &mut Statistics,
) -> Result<(), PlotError> {
    let (means, fits) = (
        Table::read(&dir.join(BINNED_MEANS))?,
        Table::read(&dir.join(SCALING))?,
    );
    let missing = missing(&[(BINNED_MEANS, means.is_some()), (SCALING, fits.is_some())]);
    let (Some(means), Some(fits)) = (means, fits) else {
        let reason = format!("no {missing}: run `precursors stats` first");
        return selection.skip_quietly(figure, dir, reason, &mut drawn.notes);
    };
    let mut chart = canvas
        .chart(
            &format!("{what}: {title}, binned means"),
            "S (ruptures of an avalanche)",
            y_label,
        )
        .log_x()
        .log_y()
        .legend(Corner::UpperLeft);
    let mut any = false;
    for (k, &point) in family.order.iter().enumerate() {
        let rows = means.rows_of(point, ("relation", relation))?;
        if rows.is_empty() {
            continue;
        }
        any = true;
        let colour = series_colour(family.colours, k, family.order.len());
        let style = Style::new().colour(colour.0, colour.1, colour.2);
        let mut bars = Vec::new();
        let mut avalanches = 0;
        for row in &rows {
            let number = |name: &str| means.number(row, name).map(|v| v.unwrap_or(f64::NAN));
            avalanches += number("count")? as usize;
            bars.push((
                number("x_mean")?,
                number("mean")?,
                number("mean_low")?,
                number("mean_high")?,
            ));
        }
        let prefix = family.prefix(point);
        // One entry a point: its markers, named with its fit (the dashed line in its
        // colour, unlabelled), to keep the legend small enough to leave the data clear.
        let fit = fits.rows_of(point, ("relation", relation))?;
        let law = match fit.first() {
            Some(row) => {
                let number = |name: &str| fits.number(row, name);
                match (
                    number("exponent")?,
                    number("exponent_low")?,
                    number("exponent_high")?,
                    number("prefactor")?,
                ) {
                    (Some(beta), Some(low), Some(high), Some(c)) => {
                        Some((beta, low, high, c, row[fits.column("pairs")?].clone()))
                    }
                    _ => None,
                }
            }
            None => None,
        };
        let label = match &law {
            Some((beta, low, high, _, pairs)) => {
                format!("{prefix}β = {beta:.2} [{low:.2}, {high:.2}] (95 %), {pairs} avalanches")
            }
            None => format!("{prefix}no fit, {avalanches} avalanches"),
        };
        chart = chart.error_bars(&label, &bars).style(style);
        if let Some((beta, _, _, c, _)) = law {
            let xs = bars
                .iter()
                .map(|b| b.0)
                .filter(|x| x.is_finite() && *x > 0.0);
            let (lo, hi) = xs.fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
            let line: Vec<(f64, f64)> = (0..=20)
                .map(|i| lo * (hi / lo).powf(f64::from(i) / 20.0))
                .map(|x| (x, c * x.powf(beta)))
                .collect();
            chart = chart.line("", &line).style(style.dashed());
        }
    }
    if !any {
        let reason = format!("{BINNED_MEANS} has no rows of {relation}");
        return selection.skip_quietly(figure, dir, reason, &mut drawn.notes);
    }
    chart = chart
        .note("markers: the mean of each bin of S, its 95 % interval")
        .note(&format!(
            "dashed: {symbol} = c S^β, least squares of ln {symbol} on ln S over every"
        ))
        .note("avalanche (scaling.csv): the geometric mean, below the arithmetic one");
    for extension in extensions {
        let path = dir.join(format!("{figure}.{extension}"));
        chart.save(&path)?;
        drawn.files.push(path);
    }
    Ok(())
}

/// The names of the tables not found among `tables` (name, found), joined by `and`.
fn missing(tables: &[(&str, bool)]) -> String {
    let names: Vec<&str> = tables.iter().filter(|t| !t.1).map(|t| t.0).collect();
    names.join(" and ")
}

/// The collapse figure of a sweep over a block length: each length's log-binned sizes
/// (bins of at least 3 avalanches, as the fit) as `P(S) S^τ` against `S/L^D`, `L` in mm,
/// with their counting error bars.
fn collapse_figure(
    dir: &Path,
    extensions: &[&str],
    canvas: Canvas,
    title: &str,
    family: &Family<'_>,
    selection: &Selection,
    drawn: &mut Statistics,
) -> Result<(), PlotError> {
    let (collapse, bins) = (
        Table::read(&dir.join(COLLAPSE))?,
        Table::read(&dir.join(DISTRIBUTIONS))?,
    );
    let missing = missing(&[
        (COLLAPSE, collapse.is_some()),
        (DISTRIBUTIONS, bins.is_some()),
    ]);
    let (Some(collapse), Some(bins)) = (collapse, bins) else {
        let reason = format!(
            "no {missing}: `precursors stats` writes {COLLAPSE} and {DISTRIBUTIONS} for a sweep \
             over block.lx or block.ly"
        );
        return selection.skip_quietly(COLLAPSE_FIGURE, dir, reason, &mut drawn.notes);
    };
    let observable = "avalanche_ruptures";
    let row = collapse
        .rows
        .iter()
        .find(|r| r.get(collapse.column("observable").unwrap_or(0)) == Some(&observable.into()));
    let fit = match row {
        Some(row) => {
            let n = |name: &str| collapse.number(row, name);
            match (n("tau")?, n("d")?) {
                (Some(tau), Some(d)) => Some((row, tau, d)),
                _ => None,
            }
        }
        None => None,
    };
    let Some((row, tau, d)) = fit else {
        let reason = format!("{COLLAPSE} holds no collapse of {observable} (too few samples)");
        return selection.skip_quietly(COLLAPSE_FIGURE, dir, reason, &mut drawn.notes);
    };
    let axis = row[collapse.column("axis")?].clone();
    let n = |name: &str| collapse.number(row, name).map(|v| v.unwrap_or(f64::NAN));
    let symbol = if axis == "block.ly" { "Ly" } else { "Lx" };
    let mut chart = canvas
        .chart(
            &format!("Collapse of avalanche sizes over {symbol}: {title}"),
            &format!("S/({symbol}/mm)^D"),
            "P(S) S^τ",
        )
        .log_x()
        .log_y()
        .legend(Corner::LowerLeft);
    for (k, &point) in family.order.iter().enumerate() {
        let rows = bins.rows_of(point, ("observable", observable))?;
        let Some(first) = rows.first() else { continue };
        let length_mm = 1e3 * bins.number(first, &axis)?.unwrap_or(f64::NAN);
        let mut points = Vec::new();
        for row in &rows {
            let number = |name: &str| bins.number(row, name).map(|v| v.unwrap_or(f64::NAN));
            let (s, count, density) = (number("bin_center")?, number("count")?, number("density")?);
            if count < COLLAPSE_MIN_COUNT {
                continue;
            }
            let y = density * s.powf(tau);
            let relative = 1.0 / count.sqrt();
            points.push((
                s / length_mm.powf(d),
                y,
                y * (1.0 - relative),
                y * (1.0 + relative),
            ));
        }
        let colour = series_colour(family.colours, k, family.order.len());
        let label = family.prefix(point);
        let label = label.trim_end_matches(": ");
        chart = chart
            .error_bars(
                if label.is_empty() {
                    "one length"
                } else {
                    label
                },
                &points,
            )
            .style(Style::new().colour(colour.0, colour.1, colour.2));
    }
    chart = chart
        .note(&format!(
            "τ = {:.2} [{:.2}, {:.2}], D = {:.2} [{:.2}, {:.2}] ({} %, collapse.csv)",
            tau,
            n("tau_low")?,
            n("tau_high")?,
            d,
            n("d_low")?,
            n("d_high")?,
            short(100.0 * n("confidence")?)
        ))
        .note("bins of 3 avalanches or more; error bars: 1 ± 1/√count");
    for extension in extensions {
        let path = dir.join(format!("{COLLAPSE_FIGURE}.{extension}"));
        chart.save(&path)?;
        drawn.files.push(path);
    }
    Ok(())
}
