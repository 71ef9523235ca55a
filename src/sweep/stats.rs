//! The statistics of avalanches, stress drops and front leaps over the realizations of a
//! run or a sweep (`precursors stats DIR`; docs/statistics.md): log-binned distributions
//! and maximum-likelihood power-law fits (`crate::statistics`), pooled per parameter
//! point. Every sample is derived from the checked `events.csv` and `curve.csv` of each
//! complete run (`RunRecord`), never from the derived tables a run leaves beside them.

use super::merge::{cell, checked_record, num, read_sweep};
use super::{SweepError, SweepRun, DONE, SWEEP_FILE};
use crate::error::{Error, Result};
use crate::files::write_atomically;
use crate::output::check::RunRecord;
use crate::output::derived::{derive, Slip};
use crate::output::layout::{BINNED_MEANS, COLLAPSE, DISTRIBUTIONS, POWER_LAWS, SCALING};
use crate::statistics::{
    binned_means, classes_excluded, compare_alternatives_with, fit_collapse, fit_cutoff_scaling,
    fit_power_law, fit_scaling, log_binned, whole_fits, Comparison, CutoffFit, LikelihoodRatio,
    PowerLawFit, PowerLawOptions, Support,
};

/// A row's fit: with its alternatives, or the power law alone where they cannot be
/// evaluated.
enum Fit {
    Compared(Box<Comparison>),
    PowerLaw(PowerLawFit),
}
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Options of [`statistics`]: the power-law fits' and the bins of the distributions.
/// Setters never fail; [`statistics`] checks the values.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct StatsOptions {
    /// The options of every power-law fit.
    pub fit: PowerLawOptions,
    /// Bins per decade of the log-binned distributions (default 5).
    pub bins_per_decade: usize,
    /// Whether the samples include the spanning avalanche and the regime after it
    /// ([`crate::Avalanche::spanning`]; default `false`: left out, with the stable states
    /// from the spanning avalanche's on for the front leaps).
    pub include_spanning: bool,
}

impl Default for StatsOptions {
    fn default() -> Self {
        Self {
            fit: PowerLawOptions::default(),
            bins_per_decade: 5,
            include_spanning: false,
        }
    }
}

impl StatsOptions {
    /// The options of the power-law fits.
    pub fn fit(mut self, fit: PowerLawOptions) -> Self {
        self.fit = fit;
        self
    }

    /// Bins per decade of the distributions.
    ///
    /// ```
    /// use precursors::sweep::{statistics, StatsOptions};
    /// assert_eq!(StatsOptions::default().bins_per_decade(10).bins_per_decade, 10);
    /// // Zero bins is refused by `statistics` before any directory is read.
    /// let zero = StatsOptions::default().bins_per_decade(0);
    /// let error = statistics(std::path::Path::new("."), &zero).unwrap_err();
    /// assert!(error.to_string().contains("bins_per_decade"), "{error}");
    /// ```
    pub fn bins_per_decade(mut self, bins: usize) -> Self {
        self.bins_per_decade = bins;
        self
    }

    /// Whether to pool the spanning avalanche and those after it too.
    ///
    /// ```
    /// use precursors::sweep::StatsOptions;
    /// assert!(!StatsOptions::default().include_spanning);
    /// assert!(StatsOptions::default().include_spanning(true).include_spanning);
    /// ```
    pub fn include_spanning(mut self, include: bool) -> Self {
        self.include_spanning = include;
        self
    }
}

/// What [`statistics`] wrote (its example reads one: points, runs and the files).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct StatsSummary {
    /// Parameter points (1 for a run directory).
    pub points: usize,
    /// Complete runs whose samples were pooled.
    pub runs: usize,
    /// Runs left out: not complete (no completion marker).
    pub runs_missing: usize,
    /// The files written: `power_laws.csv`, `distributions.csv`, `binned_means.csv`,
    /// `scaling.csv`, and `collapse.csv` for a sweep over a block length.
    pub files: Vec<PathBuf>,
    /// Each fit's verdict (`Comparison::verdict`), as `point <index>, <observable>:
    /// <verdict>`, in the order of `power_laws.csv`'s rows; none for an empty fit.
    pub verdicts: Vec<String>,
    /// For each fit, the universality classes its exponents' intervals exclude
    /// ([`crate::statistics::classes_excluded`]), as `point <index>, <observable>: α
    /// [low, high] excludes …; cut-off α [low, high] excludes …`.
    pub classes: Vec<String>,
    /// The fitted relations (`scaling.csv`) and collapses (`collapse.csv`) in words.
    pub scaling: Vec<String>,
}

/// Where [`statistics_with_progress`] stands, after each whole fit (the `x_min` search on
/// the pooled samples, each bootstrap resample, each synthetic set).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct StatsProgress {
    /// The parameter point being fitted (from 0).
    pub point: usize,
    /// Parameter points in all.
    pub points: usize,
    /// The observable being fitted (`power_laws.csv`'s `observable`).
    pub observable: &'static str,
    /// Whole fits done at this point, over its observables.
    pub fits_done: usize,
    /// Whole fits at this point: `1 + bootstrap + goodness_samples` per observable with
    /// enough samples.
    pub fits: usize,
}

/// The observables [`statistics`] pools and fits, in the order of its tables: the name
/// (the `observable` column), whether the samples are counts, and what they are
/// (docs/statistics.md has the list).
pub(crate) const OBSERVABLES: [(&str, Support, &str); 14] = [
    (
        "avalanche_ruptures",
        Support::Discrete,
        "ruptures of each avalanche before the spanning one",
    ),
    (
        "force_drop_N",
        Support::Continuous,
        "drop of the shear force over each avalanche before the spanning one (N): a \
         driving spring's stress drops; none under force control",
    ),
    (
        "energy_J",
        Support::Continuous,
        "stored elastic energy ½ k_x u_x² ΔA of the springs broken in each avalanche before \
         the spanning one, summed (J)",
    ),
    (
        "precursor_leap_cells",
        Support::Discrete,
        "each advance of the running maximum of ℓ from one stable state to the next, before \
         the spanning avalanche, in cells Δx",
    ),
    (
        "damage_front_leap_cells",
        Support::Discrete,
        "each advance of the running maximum of the damage front from one stable state to \
         the next, before the spanning avalanche, in cells Δx",
    ),
    (
        "load_between_precursor_leaps",
        Support::Continuous,
        "the increase of F/(μF_N) between two advances of ℓ",
    ),
    (
        "load_between_front_leaps",
        Support::Continuous,
        "the increase of F/(μF_N) between two advances of the damage front",
    ),
    (
        "avalanche_ruptures_without_flash",
        Support::Discrete,
        "ruptures of each avalanche before the spanning one, its flash ruptures left out \
         (docs/model.md section 5)",
    ),
    (
        "avalanche_extent_cells",
        Support::Discrete,
        "extent along x of each avalanche before the spanning one, in cells Δx",
    ),
    (
        "avalanche_ruptures_load_below_0.5",
        Support::Discrete,
        "ruptures of each avalanche before the spanning one that starts below F/(μF_N) = 0.5",
    ),
    (
        "avalanche_ruptures_load_0.5_to_0.8",
        Support::Discrete,
        "ruptures of each avalanche before the spanning one that starts at F/(μF_N) from 0.5 \
         to below 0.8",
    ),
    (
        "avalanche_ruptures_load_from_0.8",
        Support::Discrete,
        "ruptures of each avalanche before the spanning one that starts at F/(μF_N) 0.8 or \
         above",
    ),
    (
        "avalanche_potency_m3",
        Support::Continuous,
        "potency Σ Δu_x ΔA of each avalanche before the spanning one (m³), where positive",
    ),
    (
        "avalanche_released_energy_J",
        Support::Continuous,
        "energy released by each avalanche before the spanning one (J): the work of the load \
         less the change of the elastic energy, under force control; where positive",
    ),
];

/// The samples of every observable of one run, in the order of [`OBSERVABLES`].
type Samples = [Vec<f64>; OBSERVABLES.len()];

/// The values of one avalanche that enter the relations between observables
/// ([`RELATIONS`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct AvalancheValues {
    /// `1 - F/(μF_N)` at its start (the load of its first rupture).
    pub load_gap: f64,
    /// Its ruptures.
    pub ruptures: f64,
    /// Its ruptures without the flash ones.
    pub without_flash: f64,
    /// Its force drop (N).
    pub drop: f64,
    /// Its potency (m³; 0 where not known).
    pub potency: f64,
}

/// A relation between two observables of the same avalanches: its name (the `relation`
/// column of `binned_means.csv` and `scaling.csv`), `x` and `y` of an avalanche, and what
/// it is (docs/statistics.md).
pub(crate) type Relation = (
    &'static str,
    fn(&AvalancheValues) -> (f64, f64),
    &'static str,
);

/// The relations [`statistics`] bins and fits, over the avalanches before the spanning one
/// whose `x` and `y` are both positive.
pub(crate) const RELATIONS: [Relation; 4] = [
    (
        "ruptures_against_load_gap",
        |a| (a.load_gap, a.ruptures),
        "the size against 1 - F/(μF_N) at the avalanche's start",
    ),
    (
        "ruptures_without_flash_against_load_gap",
        |a| (a.load_gap, a.without_flash),
        "the size without flash ruptures against 1 - F/(μF_N) at the avalanche's start",
    ),
    (
        "force_drop_N_against_ruptures",
        |a| (a.ruptures, a.drop),
        "the force drop (N) against the size, over the avalanches whose force drops",
    ),
    (
        "potency_m3_against_ruptures",
        |a| (a.ruptures, a.potency),
        "the potency (m³) against the size, over the avalanches whose potency is known and \
         positive",
    ),
];

/// The `(x, y)` of a relation over avalanches, both positive.
pub(crate) fn relation_pairs(
    relation: &Relation,
    avalanches: &[AvalancheValues],
) -> (Vec<f64>, Vec<f64>) {
    avalanches
        .iter()
        .map(relation.1)
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .unzip()
}

/// The samples of one run: of each observable, and the values of each avalanche kept.
pub(crate) struct RunSamples {
    /// The samples of each of [`OBSERVABLES`].
    pub observables: Samples,
    /// The avalanches kept, in order.
    pub avalanches: Vec<AvalancheValues>,
}

/// The samples of each of [`OBSERVABLES`] in one complete run: from the avalanches before
/// the spanning one and the stable states before its end, or (`include_spanning`) from
/// every avalanche but global slip and every stable state. Front leaps are the advances of
/// the running maximum of `ℓ` and of `x_D`: a front that recedes and regains ground makes
/// no leap.
///
/// # Errors
/// [`Error::CorruptTable`] when its events are not the whole run of its grid.
pub(crate) fn samples(
    record: &RunRecord,
    dir: &Path,
    include_spanning: bool,
) -> Result<RunSamples> {
    let derived = derive(&record.grid, &record.events).map_err(|e| Error::CorruptTable {
        path: Some(dir.join(crate::output::TABLES[0])),
        reason: format!("not the whole run of its scene: {e}"),
    })?;
    let mut out: Samples = Default::default();
    let mut avalanches = Vec::new();
    let kept = |a: &&crate::avalanche::Avalanche| {
        !a.global_slip && (include_spanning || !(a.spanning || a.after_spanning))
    };
    let dx = record.grid.dx();
    for a in derived.avalanches.iter().filter(kept) {
        out[0].push(a.ruptures as f64);
        out[1].push(a.force_drop());
        out[2].push(a.energy);
        out[7].push((a.ruptures - a.flash_ruptures) as f64);
        out[8].push((a.extent / dx).round());
        // The load windows of issue 54: the mean size grows as the load nears μF_N, so
        // sizes pooled over the whole run mix regimes.
        let load = a.load_before.force / record.bounds.mu_fn;
        let slip = Slip::in_run(a, &record.curve);
        let positive = |x: Option<f64>| x.filter(|x| *x > 0.0);
        out[12].extend(positive(slip.potency));
        out[13].extend(positive(slip.released));
        avalanches.push(AvalancheValues {
            load_gap: 1.0 - load,
            ruptures: a.ruptures as f64,
            without_flash: (a.ruptures - a.flash_ruptures) as f64,
            drop: a.force_drop(),
            potency: slip.potency.unwrap_or(0.0),
        });
        let window = if load < 0.5 {
            9
        } else if load < 0.8 {
            10
        } else {
            11
        };
        out[window].push(a.ruptures as f64);
    }
    let nx = record.bounds.nx as f64;
    let loads: Vec<f64> = record.curve.iter().map(|c| c.load).collect();
    let ell: Vec<f64> = record
        .curve
        .iter()
        .map(|c| (c.precursor_over_lx * nx).round())
        .collect();
    let front: Vec<f64> = derived
        .fronts
        .iter()
        .map(|x| (x / record.grid.dx()).round())
        .collect();
    // The stable states before the one that ends the spanning avalanche.
    let states = match derived.avalanches.iter().find(|a| a.spanning) {
        Some(spanning) if !include_spanning => record
            .curve
            .iter()
            .take_while(|c| c.event < spanning.end_event)
            .count(),
        _ => record.curve.len(),
    };
    for (k, cells) in [(3, &ell), (4, &front)] {
        let mut last_leap: Option<f64> = None;
        let mut reached = cells.first().copied().unwrap_or(0.0);
        for s in 1..cells.len().min(loads.len()).min(states) {
            let step = cells[s] - reached;
            reached = reached.max(cells[s]);
            if step > 0.0 {
                out[k].push(step);
                if let Some(at) = last_leap {
                    out[k + 2].push(loads[s] - at);
                }
                last_leap = Some(loads[s]);
            }
        }
    }
    Ok(RunSamples {
        observables: out,
        avalanches,
    })
}

/// Whether the positive samples are all one value (one avalanche extent on a narrow
/// grid, say): no power law fits them, and the observable is reported without a fit, as
/// one with too few samples.
fn all_equal(x: &[f64]) -> bool {
    let mut positive = x.iter().filter(|v| **v > 0.0);
    positive
        .next()
        .is_some_and(|first| positive.all(|v| v == first))
}

/// A parameter point of a run or sweep directory: its axes' values (none for a run
/// directory) and its complete runs, read one at a time ([`Point::for_each_record`]) so
/// that a sweep of many runs never holds more than one run's events.
pub(crate) struct Point {
    pub values: Vec<(String, String)>,
    /// Each complete run's directory, and the sweep's run it must be (`None`: a run
    /// directory of its own).
    runs: Vec<(PathBuf, Option<SweepRun>)>,
}

impl Point {
    /// The complete runs.
    pub(crate) fn runs(&self) -> usize {
        self.runs.len()
    }

    /// Calls `f` with each complete run's directory and its record, read and checked
    /// ([`RunRecord::read`]; a sweep's run against the sweep's scene), in run order.
    pub(crate) fn for_each_record(
        &self,
        mut f: impl FnMut(&Path, &RunRecord) -> Result<()>,
    ) -> Result<()> {
        for (dir, run) in &self.runs {
            let record = match run {
                Some(run) => checked_record(dir, run)?,
                None => RunRecord::read(dir)?,
            };
            f(dir, &record)?;
        }
        Ok(())
    }
}

/// The points of `dir` with their complete runs, the axes' keys (none for a run
/// directory), and the runs of a sweep that are not complete (no completion marker).
///
/// # Errors
/// [`SweepError::Directory`] for a directory that is neither a run's nor a sweep's; a
/// sweep file's errors.
pub(crate) fn points(dir: &Path) -> Result<(Vec<String>, Vec<Point>, usize), SweepError> {
    if !crate::output::layout::is_sweep(dir)? {
        if !dir.join(crate::output::RUN_SCENE).is_file() {
            return Err(SweepError::Directory {
                path: dir.to_path_buf(),
                reason: format!(
                    "neither a run directory (no {}) nor a sweep's (no {SWEEP_FILE})",
                    crate::output::RUN_SCENE
                ),
            });
        }
        let point = Point {
            values: Vec::new(),
            runs: vec![(dir.to_path_buf(), None)],
        };
        return Ok((Vec::new(), vec![point], 0));
    }
    let sweep = read_sweep(dir)?;
    let keys = sweep.keys().iter().map(|k| k.to_string()).collect();
    let mut out = Vec::new();
    let mut missing = 0;
    for point in 0..sweep.points() {
        let runs: Vec<&SweepRun> = sweep.runs().iter().filter(|r| r.point == point).collect();
        let Some(first) = runs.first() else { continue };
        let mut complete = Vec::new();
        for run in &runs {
            let run_dir = dir.join(&run.dir_name);
            if crate::files::is_file(&run_dir.join(DONE), "examining the run directory")? {
                complete.push((run_dir, Some((*run).clone())));
            } else {
                missing += 1;
            }
        }
        out.push(Point {
            values: first.values.clone(),
            runs: complete,
        });
    }
    Ok((keys, out, missing))
}

/// Pools, over the complete runs of each parameter point of the run or sweep directory
/// `dir`, the samples of seven observables (each derived from the run's checked
/// `events.csv` and `curve.csv`; docs/statistics.md defines them):
/// `avalanche_ruptures` (counts), `force_drop_N`, `energy_J` (of each avalanche before
/// global slip), `precursor_leap_cells`, `damage_front_leap_cells` (counts: the advances
/// of ℓ and of the damage front from one stable state to the next, in cells),
/// `load_between_precursor_leaps` and `load_between_front_leaps` (the increase of
/// `F/(μF_N)` between two advances); and writes into `dir`:
///
/// * `power_laws.csv`: per point and observable, the maximum-likelihood power-law fit and
///   its alternatives
///   ([`compare_alternatives`](crate::statistics::compare_alternatives): `x_min` by the
///   Kolmogorov-Smirnov distance, the exponent with its bootstrap interval, the goodness-of-fit p-value; on
///   the same tail the cut-off law with its interval, the exponential, the log-normal and
///   the likelihood-ratio tests), header `point,<axis
///   keys>,observable,support,samples,tail,x_min,alpha,alpha_std_error,alpha_low,
///   alpha_high,x_min_low,x_min_high,ks_distance,p_value,confidence,cutoff_alpha,
///   cutoff_alpha_low,cutoff_alpha_high,cutoff_scale,cutoff_scale_low,cutoff_scale_high,
///   exponential_lambda,lognormal_mu,lognormal_sigma,lr_exponential,
///   lr_exponential_normalized,lr_exponential_p,lr_lognormal,lr_lognormal_normalized,
///   lr_lognormal_p,lr_cutoff,lr_cutoff_normalized,lr_cutoff_p,lr_cutoff_vs_lognormal,
///   lr_cutoff_vs_lognormal_normalized,lr_cutoff_vs_lognormal_p,verdict,classes_excluded,
///   cutoff_classes_excluded,runs` (docs/statistics.md defines them; `runs` is the
///   complete runs pooled at the point, which the figures of these tables name; an
///   infinite value, such as the cut-off scale `1/λ` at `λ = 0`, is an empty cell); the
///   fit's cells are empty where the samples are too few (fewer than `min_tail` positive
///   ones);
/// * `distributions.csv`: per point and observable, the log-binned density
///   ([`log_binned`]), header `point,<axis keys>,observable,bin_low,bin_high,
///   bin_center,count,density`.
///
/// Both are written atomically. Runs of a sweep without their completion marker are left
/// out and counted.
///
/// ```
/// use precursors::statistics::PowerLawOptions;
/// use precursors::sweep::{statistics, StatsOptions, Sweep, SweepOptions};
/// let sweep = Sweep::from_json_str(r#"{
///     "base": { "block": { "lx": 0.02, "ly": 0.004, "lz": 0.01 },
///               "cells": { "kind": "count", "nx": 20, "ny": 4 },
///               "normal_load": 100.0 },
///     "axes": [], "realizations": 3, "seed": 2
/// }"#)?;
/// let out = std::env::temp_dir().join(format!("precursors-doc-stats-{}", std::process::id()));
/// sweep.execute(&out, &SweepOptions::new(), |_| {})?;
/// let options = StatsOptions::default().fit(PowerLawOptions::default().bootstrap(20));
/// let summary = statistics(&out, &options)?;
/// assert_eq!((summary.points, summary.runs, summary.runs_missing), (1, 3, 0));
/// let fits = std::fs::read_to_string(&summary.files[0])?;
/// assert!(fits.lines().nth(1).unwrap().starts_with("0,avalanche_ruptures,discrete,"));
/// std::fs::remove_dir_all(&out).ok();
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
/// [`SweepError::Directory`] for a directory that is neither a run's nor a sweep's;
/// as [`super::merge`] for the runs' tables; in [`SweepError::Core`]:
/// [`Error::InvalidParameter`]/[`Error::InvalidCount`] for bad options,
/// [`Error::DirectoryLocked`] while a run or a sweep writes the directory (its lock is
/// taken shared, as a reader's), [`Error::RunDirectory`] for a run directory holding a
/// `sweep.json`.
pub fn statistics(dir: &Path, options: &StatsOptions) -> Result<StatsSummary, SweepError> {
    statistics_with_progress(dir, options, |_| {})
}

/// [`statistics`], calling `progress` after each whole fit (from the threads that make
/// them: the bootstrap resamples and synthetic sets of a fit run on the current rayon
/// pool; the tables do not depend on its threads).
///
/// ```
/// use precursors::sweep::{statistics_with_progress, StatsOptions};
/// let dir = std::env::temp_dir().join("precursors-no-such-directory");
/// let seen = std::sync::atomic::AtomicUsize::new(0);
/// let options = StatsOptions::default();
/// assert!(statistics_with_progress(&dir, &options, |p| {
///     seen.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
///     assert!(p.fits_done <= p.fits);
/// })
/// .is_err());
/// ```
///
/// # Errors
/// Those of [`statistics`].
pub fn statistics_with_progress(
    dir: &Path,
    options: &StatsOptions,
    progress: impl Fn(&StatsProgress) + Sync,
) -> Result<StatsSummary, SweepError> {
    if options.bins_per_decade == 0 {
        return Err(Error::InvalidCount {
            name: "bins_per_decade",
            value: 0,
            reason: "the distributions need at least one bin per decade",
        }
        .into());
    }
    // A reader: no run or sweep writes the directory while its statistics are derived.
    let _lock = crate::lock::ReadLock::lock(dir)?;
    let (keys, points, missing) = points(dir)?;
    let key_header: String = keys.iter().map(|k| format!("{},", cell(k))).collect();
    let mut fits = format!(
        "point,{key_header}observable,support,samples,tail,x_min,alpha,alpha_std_error,\
         alpha_low,alpha_high,x_min_low,x_min_high,ks_distance,p_value,confidence,\
         {ALTERNATIVES_HEADER},classes_excluded,cutoff_classes_excluded,runs\n"
    );
    let mut verdicts = Vec::new();
    let mut classes = Vec::new();
    let mut scaling_lines = Vec::new();
    let mut bins =
        format!("point,{key_header}observable,bin_low,bin_high,bin_center,count,density\n");
    let mut means = format!(
        "point,{key_header}relation,x_low,x_high,x_center,x_mean,count,mean,mean_low,\
         mean_high,confidence\n"
    );
    let mut scaling = format!(
        "point,{key_header}relation,pairs,exponent,exponent_low,exponent_high,prefactor,\
         confidence\n"
    );
    // A sweep over one block length (linked keys, a normal load at fixed pressure, may
    // vary with it): each point's sizes per run, for the collapse.
    let length_axis = length_axis(&keys, &points);
    let mut sizes_by_length: Vec<(f64, [Vec<Vec<f64>>; 2])> = Vec::new();
    // Each length's cut-off law of the two size observables (None where not compared).
    let mut cutoffs_by_length: Vec<[Option<CutoffFit>; 2]> = Vec::new();
    let mut runs = 0;
    for (index, point) in points.iter().enumerate() {
        let values: String = point
            .values
            .iter()
            .map(|(_, v)| format!("{},", cell(v)))
            .collect();
        let mut pooled: Samples = Default::default();
        let mut avalanches = Vec::new();
        let mut per_run: [Vec<Vec<f64>>; 2] = Default::default();
        point.for_each_record(|run_dir, record| {
            let run = samples(record, run_dir, options.include_spanning)?;
            if length_axis.is_some() {
                per_run[0].push(run.observables[0].clone());
                per_run[1].push(run.observables[7].clone());
            }
            for (all, s) in pooled.iter_mut().zip(run.observables) {
                all.extend(s);
            }
            avalanches.extend(run.avalanches);
            Ok(())
        })?;
        if let Some((_, k)) = &length_axis {
            // The axis' value is a length in metres (the scene's unit).
            let length = point.values[*k].1.parse::<f64>().unwrap_or(f64::NAN);
            sizes_by_length.push((length, per_run));
            cutoffs_by_length.push([None, None]);
        }
        runs += point.runs();
        let enough = |x: &Vec<f64>| {
            x.iter().filter(|v| **v > 0.0).count() >= options.fit.min_tail && !all_equal(x)
        };
        let total = pooled.iter().filter(|x| enough(x)).count() * whole_fits(&options.fit);
        let done = std::sync::atomic::AtomicUsize::new(0);
        for ((name, support, _), x) in OBSERVABLES.iter().zip(&pooled) {
            let positive = x.iter().filter(|v| **v > 0.0).count();
            let step = || {
                let fits_done = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(&StatsProgress {
                    point: index,
                    points: points.len(),
                    observable: name,
                    fits_done: fits_done.min(total),
                    fits: total,
                });
            };
            let fit = if positive >= options.fit.min_tail && !all_equal(x) {
                match compare_alternatives_with(x, *support, &options.fit, &step) {
                    Ok(c) => Some(Fit::Compared(Box::new(c))),
                    // Samples spanning more than f64's range have a power law but no
                    // alternatives: the power law alone, its errors as before.
                    Err(_) => Some(Fit::PowerLaw(fit_power_law(x, *support, &options.fit)?)),
                }
            } else {
                // Checked all the same: bad options are an error whatever the samples.
                match fit_power_law(x, *support, &options.fit) {
                    Err(Error::TooFewSamples { .. }) | Ok(_) => None,
                    Err(Error::InvalidParameter {
                        name: "samples", ..
                    }) if all_equal(x) => None,
                    Err(e) => return Err(e.into()),
                }
            };
            let support_name = match support {
                Support::Discrete => "discrete",
                _ => "continuous",
            };
            let excluded = class_cells(fit.as_ref());
            let _ = writeln!(
                fits,
                "{index},{values}{name},{support_name},{positive},{},{},{},{},{}",
                fit_cells(fit.as_ref(), options.fit.confidence),
                alternative_cells(fit.as_ref()),
                cell(&excluded[0]),
                cell(&excluded[1]),
                point.runs(),
            );
            if let Some(Fit::Compared(c)) = &fit {
                verdicts.push(format!("point {index}, {name}: {}", c.verdict()));
                let slot = [0, 7].iter().position(|o| OBSERVABLES[*o].0 == *name);
                if let (Some(k), Some(last)) = (slot, cutoffs_by_length.last_mut()) {
                    if length_axis.is_some() {
                        last[k] = Some(c.cutoff.clone());
                    }
                }
            }
            if let Some(f) = &fit {
                let pl = match f {
                    Fit::Compared(c) => &c.power_law,
                    Fit::PowerLaw(p) => p,
                };
                let mut line = format!(
                    "point {index}, {name}: α = {:.2} [{:.2}, {:.2}] excludes {}",
                    pl.alpha, pl.alpha_low, pl.alpha_high, excluded[0]
                );
                if let Fit::Compared(c) = f {
                    let k = &c.cutoff;
                    let _ = write!(
                        line,
                        "; cut-off α = {:.2} [{:.2}, {:.2}] excludes {}",
                        k.alpha, k.alpha_low, k.alpha_high, excluded[1]
                    );
                }
                classes.push(line);
            }
            if positive > 0 {
                for b in log_binned(x, *support, options.bins_per_decade)? {
                    let _ = writeln!(
                        bins,
                        "{index},{values}{name},{},{},{},{},{}",
                        num(b.low),
                        num(b.high),
                        num(b.center),
                        b.count,
                        num(b.density)
                    );
                }
            }
        }
        for relation in &RELATIONS {
            let name = relation.0;
            let (x, y) = relation_pairs(relation, &avalanches);
            for b in binned_means(&x, &y, options.bins_per_decade, options.fit.confidence)? {
                let _ = writeln!(
                    means,
                    "{index},{values}{name},{},{},{},{},{},{},{},{},{}",
                    num(b.low),
                    num(b.high),
                    num(b.center),
                    num(b.x_mean),
                    b.count,
                    num(b.mean),
                    b.mean_low.map(num).unwrap_or_default(),
                    b.mean_high.map(num).unwrap_or_default(),
                    num(options.fit.confidence),
                );
            }
            let fit = match fit_scaling(&x, &y, &options.fit) {
                Ok(f) => Some(f),
                Err(
                    Error::TooFewSamples { .. }
                    | Error::InvalidParameter {
                        name: "samples", ..
                    },
                ) => None,
                Err(e) => return Err(e.into()),
            };
            let cells = fit.as_ref().map_or_else(
                || ",,,".to_string(),
                |f| {
                    scaling_lines.push(format!(
                        "point {index}, {name}: exponent {:.2} [{:.2}, {:.2}] over {} avalanches",
                        f.exponent, f.exponent_low, f.exponent_high, f.pairs
                    ));
                    format!(
                        "{},{},{},{}",
                        num(f.exponent),
                        num(f.exponent_low),
                        num(f.exponent_high),
                        num(f.prefactor)
                    )
                },
            );
            let _ = writeln!(
                scaling,
                "{index},{values}{name},{},{cells},{}",
                x.len(),
                num(options.fit.confidence)
            );
        }
    }
    let mut files = vec![
        dir.join(POWER_LAWS),
        dir.join(DISTRIBUTIONS),
        dir.join(BINNED_MEANS),
        dir.join(SCALING),
    ];
    write_atomically(&files[0], fits.as_bytes(), "writing table")?;
    write_atomically(&files[1], bins.as_bytes(), "writing table")?;
    write_atomically(&files[2], means.as_bytes(), "writing table")?;
    write_atomically(&files[3], scaling.as_bytes(), "writing table")?;
    if let Some((axis, _)) = &length_axis {
        let table = collapse_table(
            axis,
            &sizes_by_length,
            &cutoffs_by_length,
            options,
            &mut scaling_lines,
        )?;
        files.push(dir.join(COLLAPSE));
        write_atomically(&files[4], table.as_bytes(), "writing table")?;
    }
    Ok(StatsSummary {
        points: points.len(),
        runs,
        runs_missing: missing,
        files,
        verdicts,
        classes,
        scaling: scaling_lines,
    })
}

/// The length axis of a sweep, and its place among the keys: the one key that is
/// `block.lx` or `block.ly`, its value distinct at each of at least two points (so no other
/// axis crosses it; linked keys may vary with it).
fn length_axis(keys: &[String], points: &[Point]) -> Option<(String, usize)> {
    let mut lengths = keys
        .iter()
        .enumerate()
        .filter(|(_, k)| *k == "block.lx" || *k == "block.ly");
    let (k, key) = lengths.next()?;
    if lengths.next().is_some() || points.len() < 2 {
        return None;
    }
    let mut values: Vec<&str> = points.iter().map(|p| p.values[k].1.as_str()).collect();
    values.sort_unstable();
    values.dedup();
    (values.len() == points.len()).then(|| (key.clone(), k))
}

/// `collapse.csv`: for the sizes with and without flash ruptures, the finite-size
/// collapse over the points of a sweep along `axis` (`block.lx` or `block.ly`), from each
/// point's sizes per run, and the growth of each point's cut-off scale with the length
/// (`cutoffs`, per point); their lines in words pushed onto `lines`.
fn collapse_table(
    axis: &str,
    sets: &[(f64, [Vec<Vec<f64>>; 2])],
    cutoffs: &[[Option<CutoffFit>; 2]],
    options: &StatsOptions,
    lines: &mut Vec<String>,
) -> Result<String> {
    let mut table = "axis,observable,lengths,tau,tau_low,tau_high,d,d_low,d_high,spread,\
                     overlaps,cutoff_lengths,cutoff_exponent,cutoff_exponent_low,\
                     cutoff_exponent_high,cutoff_prefactor,cutoff_chi2_per_dof,confidence\n"
        .to_string();
    for (k, name) in [(0, OBSERVABLES[0].0), (1, OBSERVABLES[7].0)] {
        let by_length: Vec<(f64, Vec<Vec<f64>>)> =
            sets.iter().map(|(l, s)| (*l, s[k].clone())).collect();
        let cells = match fit_collapse(
            &by_length,
            Support::Discrete,
            options.bins_per_decade,
            &options.fit,
        ) {
            Ok(c) => {
                lines.push(format!(
                    "{name} against {axis}: τ = {:.2} [{:.2}, {:.2}], D = {:.2} [{:.2}, {:.2}] \
                     (spread {:.2} over {} points)",
                    c.tau, c.tau_low, c.tau_high, c.d, c.d_low, c.d_high, c.spread, c.overlaps
                ));
                [
                    c.tau, c.tau_low, c.tau_high, c.d, c.d_low, c.d_high, c.spread,
                ]
                .map(num)
                .join(",")
                    + &format!(",{}", c.overlaps)
            }
            Err(Error::TooFewSamples { .. }) => ",,,,,,,".to_string(),
            Err(e) => return Err(e),
        };
        // The lengths whose cut-off law was fitted, and those fits.
        let (lengths, fits): (Vec<f64>, Vec<CutoffFit>) = sets
            .iter()
            .zip(cutoffs)
            .filter_map(|((l, _), c)| c[k].clone().map(|c| (*l, c)))
            .unzip();
        let growth = match fit_cutoff_scaling(&lengths, &fits, options.fit.confidence) {
            Ok(g) => {
                lines.push(format!(
                    "{name} cut-off against {axis}: s_c ∝ L^{:.2} [{:.2}, {:.2}] over {} lengths",
                    g.exponent, g.exponent_low, g.exponent_high, g.lengths
                ));
                format!(
                    "{},{},{},{},{},{}",
                    g.lengths,
                    num(g.exponent),
                    num(g.exponent_low),
                    num(g.exponent_high),
                    num(g.prefactor),
                    g.chi2_per_dof.map(num).unwrap_or_default()
                )
            }
            Err(Error::TooFewSamples { count, .. }) => format!("{count},,,,,"),
            Err(e) => return Err(e),
        };
        let _ = writeln!(
            table,
            "{},{name},{},{cells},{growth},{}",
            cell(axis),
            sets.len(),
            num(options.fit.confidence)
        );
    }
    Ok(table)
}

/// The universality classes the intervals of the power law's `α` and of the cut-off
/// law's exclude ([`classes_excluded`]): names `; `-separated, `none`, or empty without
/// the fit.
fn class_cells(fit: Option<&Fit>) -> [String; 2] {
    let names = |low: f64, high: f64| match classes_excluded(low, high) {
        Ok(c) if c.is_empty() => "none".to_string(),
        Ok(c) => c.iter().map(|c| c.name).collect::<Vec<_>>().join("; "),
        Err(_) => String::new(),
    };
    match fit {
        None => [String::new(), String::new()],
        Some(Fit::PowerLaw(p)) => [names(p.alpha_low, p.alpha_high), String::new()],
        Some(Fit::Compared(c)) => [
            names(c.power_law.alpha_low, c.power_law.alpha_high),
            names(c.cutoff.alpha_low, c.cutoff.alpha_high),
        ],
    }
}

/// The header of the alternatives' cells ([`alternative_cells`]).
const ALTERNATIVES_HEADER: &str = "cutoff_alpha,cutoff_alpha_low,cutoff_alpha_high,\
    cutoff_scale,cutoff_scale_low,cutoff_scale_high,exponential_lambda,lognormal_mu,\
    lognormal_sigma,lr_exponential,lr_exponential_normalized,lr_exponential_p,\
    lr_lognormal,lr_lognormal_normalized,lr_lognormal_p,lr_cutoff,lr_cutoff_normalized,\
    lr_cutoff_p,lr_cutoff_vs_lognormal,lr_cutoff_vs_lognormal_normalized,\
    lr_cutoff_vs_lognormal_p,verdict";

/// The cells of the alternatives and their tests (all empty without a fit).
fn alternative_cells(fit: Option<&Fit>) -> String {
    let Some(Fit::Compared(c)) = fit else {
        return ",".repeat(ALTERNATIVES_HEADER.matches(',').count());
    };
    let k = &c.cutoff;
    let mut cells: Vec<String> = [
        k.alpha,
        k.alpha_low,
        k.alpha_high,
        k.cutoff,
        k.cutoff_low,
        k.cutoff_high,
        c.exponential.lambda,
        c.lognormal.mu,
        c.lognormal.sigma,
    ]
    .into_iter()
    .map(num)
    .collect();
    let tests: [&LikelihoodRatio; 4] = [
        &c.vs_exponential,
        &c.vs_lognormal,
        &c.vs_cutoff,
        &c.cutoff_vs_lognormal,
    ];
    for t in tests {
        cells.extend([num(t.log_ratio), num(t.normalized), num(t.p_value)]);
    }
    cells.push(cell(&c.verdict()));
    cells.join(",")
}

/// The cells of a fit from `tail` on (empty without one).
fn fit_cells(fit: Option<&Fit>, confidence: f64) -> String {
    let Some(f) = fit.map(|f| match f {
        Fit::Compared(c) => &c.power_law,
        Fit::PowerLaw(p) => p,
    }) else {
        return ",,,,,,,,,,".to_string();
    };
    format!(
        "{},{},{},{},{},{},{},{},{},{},{}",
        f.tail,
        num(f.x_min),
        num(f.alpha),
        num(f.alpha_std_error),
        num(f.alpha_low),
        num(f.alpha_high),
        num(f.x_min_low),
        num(f.x_min_high),
        num(f.ks_distance),
        f.p_value.map(num).unwrap_or_default(),
        num(confidence),
    )
}
