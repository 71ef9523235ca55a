//! The figures of a run's or a sweep's statistics (docs/statistics.md), drawn by
//! [`super::draw`] beside the curves: `avalanche_sizes` (the log-binned `P(S)` of the
//! avalanche sizes on log-log axes, with each point's maximum-likelihood power law and
//! its exponent), `force_drops` (the same for a driving spring's force drops, when there
//! are any) and, for a run, `fronts` (`ℓ/Lx` and the damage front `x_D/Lx` against the
//! load). The samples are derived from the checked tables, as `precursors stats` derives
//! them; the fits are `stats`' (`power_laws.csv`, read by `plot/tables.rs`), or computed
//! here as `stats` would where the directory has none of these samples.

use super::selection::Selection;
use super::tables::{p_text, preferred, Fits, Table};
use super::{
    point_order, series_colour, short, Canvas, Chart, Colours, Corner, Panels, PlotError, Style,
};
use crate::error::Error;
use crate::output::derived::derive;
use crate::output::layout::POWER_LAWS;
use crate::output::layout::{DROPS_FIGURE, FRONTS_FIGURE, SIZES_FIGURE};
use crate::statistics::{compare_alternatives, cutoff_density, fit_power_law, log_binned, Support};
use crate::sweep::stats::{points, samples};
use crate::sweep::StatsOptions;
use std::path::{Path, PathBuf};

/// What [`draw_statistics`] drew, and what it left out and why.
#[derive(Debug, Default)]
pub(super) struct Statistics {
    pub files: Vec<PathBuf>,
    pub notes: Vec<String>,
}

/// A sweep point's name in a legend, from its axes' values and its runs.
pub(super) type PointLabel = fn(&[(String, String)], usize) -> String;

/// One point's series of a distribution: its place among the directory's points (the
/// `point` column of `stats`' tables), its label and samples.
struct Pooled {
    point: usize,
    label: String,
    samples: Vec<f64>,
}

/// The points' series of a distribution, in the order they are drawn, and their colours
/// ([`point_order`]).
struct Family {
    pooled: Vec<Pooled>,
    colours: Colours,
}

/// Draws `avalanche_sizes`, `force_drops` and (for a run) `fronts` of `dir` (a run's or a
/// sweep's directory) into it, as files of each of `extensions` (`png`, `svg`); `label`
/// names each point of a sweep; only the figures `selection` wants.
pub(super) fn draw_statistics(
    dir: &Path,
    extensions: &[&str],
    canvas: Canvas,
    (title, label): (&str, PointLabel),
    selection: &Selection,
) -> Result<Statistics, PlotError> {
    let mut drawn = Statistics::default();
    let run = !crate::output::layout::is_sweep(dir)?;
    let pooled = selection.wants(SIZES_FIGURE) || selection.wants(DROPS_FIGURE);
    let fronts_wanted = run && selection.wants(FRONTS_FIGURE);
    if !pooled && !fronts_wanted {
        return Ok(drawn);
    }
    let (_, points, _) = points(dir)?;
    let (colours, order) = point_order(&points.iter().map(|p| &p.values[..]).collect::<Vec<_>>());
    let mut sizes = Vec::new();
    let mut drops = Vec::new();
    for (index, point) in order.iter().map(|&k| (k, &points[k])).filter(|_| pooled) {
        let (mut s, mut d) = (Vec::new(), Vec::new());
        point.for_each_record(|run_dir, record| {
            // The samples `stats` pools by default (the spanning avalanche left out).
            let [ruptures, drop, ..] = samples(record, run_dir, false)?.observables;
            s.extend(ruptures);
            d.extend(drop.into_iter().filter(|x| *x > 0.0));
            Ok(())
        })?;
        let name = if points.len() == 1 && point.values.is_empty() {
            String::new()
        } else {
            label(&point.values, point.runs())
        };
        sizes.push(Pooled {
            point: index,
            label: name.clone(),
            samples: s,
        });
        drops.push(Pooled {
            point: index,
            label: name,
            samples: d,
        });
    }
    let sizes_axes = ("S (ruptures of an avalanche)", "P(S)", "avalanche sizes");
    if selection.wants(SIZES_FIGURE) {
        let sizes = Family {
            pooled: sizes,
            colours,
        };
        distribution(
            dir,
            extensions,
            canvas,
            (SIZES_FIGURE, title, sizes_axes),
            (&sizes, Support::Discrete, "avalanche_ruptures"),
            &mut drawn,
        )?;
    }
    let no_drops = drops.iter().all(|p| p.samples.is_empty());
    if selection.wants(DROPS_FIGURE) && no_drops {
        let reason = "the force never drops (force control; a driving spring drops it)";
        selection.skip(DROPS_FIGURE, dir, reason.into(), &mut drawn.notes)?;
    } else if selection.wants(DROPS_FIGURE) {
        let drops_axes = ("ΔF (N)", "P(ΔF) (1/N)", "force drops");
        let drops = Family {
            pooled: drops,
            colours,
        };
        distribution(
            dir,
            extensions,
            canvas,
            (DROPS_FIGURE, title, drops_axes),
            (&drops, Support::Continuous, "force_drop_N"),
            &mut drawn,
        )?;
    }
    // A run directory: its fronts.
    if fronts_wanted {
        let mut figure = Ok(());
        for point in &points {
            point.for_each_record(|_, record| {
                figure = fronts(dir, extensions, canvas, title, record, &mut drawn);
                Ok(())
            })?;
        }
        figure?;
    }
    Ok(drawn)
}

/// The most points a distribution figure, or a sweep's fronts, draws on one chart: above,
/// one panel a point ([`Panels`]), each with its own legend (docs/statistics.md).
pub(super) const ONE_CHART_POINTS: usize = 4;

/// A log-log figure of the log-binned density of each point's samples with its counting
/// error bars, and its fits: `power_laws.csv`'s row for the point and observable (the
/// fits `precursors stats` wrote), or where the directory has none of these samples
/// the same fits computed here with `stats`' default options. The power law is drawn
/// solid, dashed and marked "rejected" where its goodness test rules it out; the cut-off
/// law where the tests leave it unbeaten ([`preferred`]); the legend gives `n_tail`, the
/// goodness p and the tests' verdict (which law they prefer, over which, at which p).
/// Up to [`ONE_CHART_POINTS`] points share one chart, their legend entries named by
/// their points; more are drawn one a panel, titled by their points.
fn distribution(
    dir: &Path,
    extensions: &[&str],
    canvas: Canvas,
    (name, title, (x_label, y_label, what)): (&str, &str, (&str, &str, &str)),
    (family, support, observable): (&Family, Support, &str),
    drawn: &mut Statistics,
) -> Result<(), PlotError> {
    let table = Table::read(&dir.join(POWER_LAWS))?;
    let heading = format!("Distribution of {what}: {title}");
    let empty = |title: &str| {
        canvas
            .chart(title, x_label, y_label)
            .log_x()
            .log_y()
            .legend(Corner::LowerLeft)
    };
    let fitting = Fitting {
        table: table.as_ref(),
        support,
        observable,
        what,
        symbol: x_label.split_whitespace().next().unwrap_or("x"),
        figure: name,
    };
    let pooled = &family.pooled;
    let panels = pooled.len() > ONE_CHART_POINTS;
    let mut chart = empty(&heading);
    let mut charts = Vec::new();
    let mut computed = false;
    for (k, p) in pooled.iter().enumerate() {
        // The markers and the fits of a point in one colour.
        let colour = series_colour(family.colours, k, pooled.len());
        let style = Style::new().colour(colour.0, colour.1, colour.2);
        if panels {
            let panel = fitting.point(empty(&p.label), p, (false, style), drawn)?;
            computed |= panel.1;
            charts.push(panel.0);
        } else {
            let one = fitting.point(chart, p, (true, style), drawn)?;
            computed |= one.1;
            chart = one.0;
        }
    }
    let mut notes =
        vec!["error bars: P (1 ± 1/√count), the Poisson counting error of each bin".to_string()];
    if computed {
        notes.push(
            "fits computed here with the defaults of stats (it wrote none of these samples)".into(),
        );
    }
    let figure = Panels {
        title: heading,
        notes: notes.clone(),
        charts,
        panel: canvas.size,
        dpi: canvas.dpi,
    };
    for note in &notes {
        chart = chart.note(note);
    }
    for extension in extensions {
        let path = dir.join(format!("{name}.{extension}"));
        if panels {
            figure.save(&path)?;
        } else {
            chart.save(&path)?;
        }
        drawn.files.push(path);
    }
    Ok(())
}

/// What the fits of one figure's points are drawn from.
struct Fitting<'a> {
    /// `power_laws.csv`, where the directory has it.
    table: Option<&'a Table>,
    support: Support,
    /// The observable's name in `power_laws.csv`.
    observable: &'a str,
    /// The samples, in words (`avalanche sizes`).
    what: &'a str,
    /// The samples' symbol in the legend (`S`).
    symbol: &'a str,
    /// The figure's name, in notes.
    figure: &'a str,
}

impl Fitting<'_> {
    /// `chart` with the point `p`'s binned density (markers with error bars), its fits and
    /// the tests' verdict in `style`, its legend entries named by the point where `named`
    /// (a chart of several points); and whether the fits were computed here (`stats`
    /// wrote none of these samples). A point without a fit is said in `drawn`'s notes.
    fn point(
        &self,
        mut chart: Chart,
        p: &Pooled,
        (named, style): (bool, Style),
        drawn: &mut Statistics,
    ) -> Result<(Chart, bool), PlotError> {
        let (support, what, symbol) = (self.support, self.what, self.symbol);
        let prefix = if p.label.is_empty() {
            String::new()
        } else {
            format!("{}: ", p.label)
        };
        let entry = if named { prefix.as_str() } else { "" };
        let positive = p.samples.iter().filter(|x| **x > 0.0).count();
        if positive == 0 {
            // A panel says why it is empty; a shared chart has the others' series.
            let chart = if named {
                chart
            } else {
                chart.note(&format!("no {what}"))
            };
            return Ok((chart, false));
        }
        let bins: Vec<(f64, f64, f64, f64)> = log_binned(&p.samples, support, 5)?
            .iter()
            .filter(|b| b.count > 0)
            .map(|b| {
                let relative = 1.0 / (b.count as f64).sqrt();
                (
                    b.center,
                    b.density,
                    b.density * (1.0 - relative),
                    b.density * (1.0 + relative),
                )
            })
            .collect();
        chart = chart
            .error_bars(&format!("{entry}{positive} {what}"), &bins)
            .style(style);
        let row = match self.table {
            Some(t) => Fits::read(t, p.point, self.observable)?,
            None => None,
        };
        let (fits, computed) = match row {
            Some((n, fits)) if n == positive => (fits, false),
            _ => (fits_here(&p.samples, support)?, true),
        };
        let Some(fits) = fits else {
            drawn.notes.push(format!(
                "{}: {prefix}no power law fitted ({positive} samples)",
                self.figure
            ));
            return Ok((chart, computed));
        };
        let top = p.samples.iter().copied().fold(fits.x_min, f64::max);
        let share = fits.tail as f64 / fits.samples.max(1) as f64;
        let curve = |law: (f64, f64, f64)| -> Vec<(f64, f64)> {
            (0..=40)
                .map(|i| fits.x_min * (top / fits.x_min).powf(f64::from(i) / 40.0))
                .map(|x| (x, cutoff_density(support, law, share, x)))
                .collect()
        };
        let (alpha, low, high) = fits.alpha;
        let verdict = match fits.p {
            Some(p) if fits.rejected() => format!(" (rejected, p = {})", p_text(p)),
            Some(p) => format!(", p = {}", p_text(p)),
            None => " (goodness not tested)".to_string(),
        };
        let label = format!(
            "{entry}power law, {symbol} ≥ {}: α = {alpha:.2} [{low:.2}, {high:.2}], n_{{tail}} = \
             {}{verdict}",
            short(fits.x_min),
            fits.tail
        );
        let line_style = if fits.p.is_some() && !fits.rejected() {
            style
        } else {
            style.dashed()
        };
        chart = chart
            .line(&label, &curve((alpha, 0.0, fits.x_min)))
            .style(line_style);
        let verdict = preferred(&fits);
        if let Some(((a, a_low, a_high), [Some(scale), scale_low, scale_high])) = fits.cutoff {
            if verdict.preferred.contains(&"cut-off law") {
                let end = |v: Option<f64>| v.map_or("∞".to_string(), short);
                chart = chart
                    .line(
                        &format!(
                            "{entry}cut-off law: α = {a:.2} [{a_low:.2}, {a_high:.2}], scale {} \
                             [{}, {}]",
                            short(scale),
                            end(scale_low),
                            end(scale_high)
                        ),
                        &curve((a, 1.0 / scale, fits.x_min)),
                    )
                    .style(style);
            }
        }
        // The verdict a clause a line, the point's name on the first.
        for (k, clause) in verdict.clauses.iter().enumerate() {
            chart = chart.note(&if k == 0 {
                format!("{entry}{clause}")
            } else {
                format!("  {clause}")
            });
        }
        Ok((chart, computed))
    }
}

/// The fits `precursors stats` would write for `samples` with its default options: the
/// power law and its alternatives, the power law alone where the alternatives fail (as
/// `stats` does), none where the samples are too few.
fn fits_here(samples: &[f64], support: Support) -> Result<Option<Fits>, PlotError> {
    let options = StatsOptions::default().fit;
    match compare_alternatives(samples, support, &options) {
        Ok(c) => return Ok(Some(Fits::of(&c))),
        Err(Error::TooFewSamples { .. }) => return Ok(None),
        Err(_) => {}
    }
    match fit_power_law(samples, support, &options) {
        Ok(f) => Ok(Some(Fits::of_power_law(&f))),
        Err(
            Error::TooFewSamples { .. }
            | Error::InvalidParameter {
                name: "samples", ..
            },
        ) => Ok(None),
        Err(e) => Err(e.into()),
    }
}

/// `ℓ/Lx` and the damage front `x_D/Lx` of a run against the load, as staircases.
fn fronts(
    dir: &Path,
    extensions: &[&str],
    canvas: Canvas,
    title: &str,
    record: &crate::output::check::RunRecord,
    drawn: &mut Statistics,
) -> Result<(), PlotError> {
    let derived = derive(&record.grid, &record.events)?;
    let lx = record.bounds.lx;
    let ell: Vec<(f64, f64)> = record
        .curve
        .iter()
        .map(|c| (c.load, c.precursor_over_lx))
        .collect();
    let front: Vec<(f64, f64)> = record
        .curve
        .iter()
        .zip(&derived.fronts)
        .map(|(c, x)| (c.load, x / lx))
        .collect();
    let top = record.slip.max(1.0);
    for extension in extensions {
        let path = dir.join(format!("{FRONTS_FIGURE}.{extension}"));
        canvas
            .chart(
                &format!("Precursor and damage fronts: {title}"),
                "F/(μF_N)",
                "x/Lx",
            )
            .x_range(0.0, top)
            .y_range(0.0, 1.0)
            .steps("ℓ/Lx: columns below their zero-shear area", &ell)
            .steps("x_D/Lx: columns with half their contacts lost", &front)
            .legend(Corner::UpperLeft)
            .save(&path)?;
        drawn.files.push(path);
    }
    Ok(())
}
