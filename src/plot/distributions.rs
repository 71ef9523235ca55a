//! The figures of a run's or a sweep's statistics (docs/statistics.md), drawn by
//! [`super::draw`] beside the curves: `avalanche_sizes` (the log-binned `P(S)` of the
//! avalanche sizes on log-log axes, with each point's maximum-likelihood power law and
//! its exponent), `force_drops` (the same for a driving spring's force drops, when there
//! are any) and, for a run, `fronts` (`ℓ/Lx` and the damage front `x_D/Lx` against the
//! load). The samples are derived from the checked tables, as `precursors stats` derives
//! them; the goodness of fit is `stats`' (it is not drawn).

use super::selection::Selection;
use super::{point_order, series_colour, short, Canvas, Colours, Corner, PlotError, Style};
use crate::output::derived::derive;
use crate::output::layout::{DROPS_FIGURE, FRONTS_FIGURE, SIZES_FIGURE};
use crate::statistics::{fit_power_law, log_binned, PowerLawOptions, Support};
use crate::sweep::stats::{points, samples};
use std::path::{Path, PathBuf};

/// What [`draw_statistics`] drew, and what it left out and why.
#[derive(Debug, Default)]
pub(super) struct Statistics {
    pub files: Vec<PathBuf>,
    pub notes: Vec<String>,
}

/// A sweep point's name in a legend, from its axes' values and its runs.
pub(super) type PointLabel = fn(&[(String, String)], usize) -> String;

/// One point's series of a distribution: its label and samples.
struct Pooled {
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
    for point in order.iter().map(|&k| &points[k]).filter(|_| pooled) {
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
            label: name.clone(),
            samples: s,
        });
        drops.push(Pooled {
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
            (&sizes, Support::Discrete),
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
            (&drops, Support::Continuous),
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

/// A log-log figure of the log-binned density of each point's samples, with its fit.
fn distribution(
    dir: &Path,
    extensions: &[&str],
    canvas: Canvas,
    (name, title, (x_label, y_label, what)): (&str, &str, (&str, &str, &str)),
    (family, support): (&Family, Support),
    drawn: &mut Statistics,
) -> Result<(), PlotError> {
    // The interval from the bootstrap; the goodness of fit is `stats`' to compute.
    let options = PowerLawOptions::default().goodness_samples(0);
    let mut chart = canvas
        .chart(
            &format!("Distribution of {what}: {title}"),
            x_label,
            y_label,
        )
        .log_x()
        .log_y()
        .legend(Corner::LowerLeft);
    let pooled = &family.pooled;
    for (k, p) in pooled.iter().enumerate() {
        // The markers and the fit of a point in one colour.
        let colour = series_colour(family.colours, k, pooled.len());
        let style = Style::new().colour(colour.0, colour.1, colour.2);
        let positive = p.samples.iter().filter(|x| **x > 0.0).count();
        if positive == 0 {
            continue;
        }
        let bins: Vec<(f64, f64)> = log_binned(&p.samples, support, 5)?
            .iter()
            .filter(|b| b.count > 0)
            .map(|b| (b.center, b.density))
            .collect();
        let prefix = if p.label.is_empty() {
            String::new()
        } else {
            format!("{}: ", p.label)
        };
        chart = chart
            .markers(&format!("{prefix}{positive} {what}"), &bins)
            .style(style);
        match fit_power_law(&p.samples, support, &options) {
            Ok(fit) => {
                let top = p.samples.iter().copied().fold(fit.x_min, f64::max);
                let line: Vec<(f64, f64)> = (0..=40)
                    .map(|i| fit.x_min * (top / fit.x_min).powf(f64::from(i) / 40.0))
                    .map(|x| (x, fit.density(x)))
                    .collect();
                chart = chart
                    .line(
                        &format!(
                            "power law above {}: α = {:.2} [{:.2}, {:.2}] (95 %)",
                            short(fit.x_min),
                            fit.alpha,
                            fit.alpha_low,
                            fit.alpha_high
                        ),
                        &line,
                    )
                    .style(style.dashed());
            }
            Err(crate::error::Error::TooFewSamples { count, needed, .. }) => {
                drawn.notes.push(format!(
                    "{name}: {prefix}no power law fitted ({count} samples, {needed} needed)"
                ));
            }
            Err(e) => return Err(e.into()),
        }
    }
    for extension in extensions {
        let path = dir.join(format!("{name}.{extension}"));
        chart.save(&path)?;
        drawn.files.push(path);
    }
    Ok(())
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
