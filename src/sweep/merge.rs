//! Ensemble statistics of a sweep's runs (`precursors merge DIR`; docs/sweep-format.md).

use super::{Sweep, SweepError, SweepRun, DONE, SWEEP_FILE};
use crate::error::{Error, Result};
use crate::files::write_atomically;
use crate::output::check::RunRecord;
use crate::output::layout::MERGED;
use crate::output::RUN_SCENE;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The loads `F/(μF_N)` at which [`merge`] reports ℓ/Lx and `A_R/A_R(0)`:
/// 0.05, 0.10, ..., 0.95.
pub(crate) const GRID_LOADS: [f64; 19] = [
    0.05, 0.10, 0.15, 0.20, 0.25, 0.30, 0.35, 0.40, 0.45, 0.50, 0.55, 0.60, 0.65, 0.70, 0.75, 0.80,
    0.85, 0.90, 0.95,
];

/// What [`merge`] wrote.
///
/// ```
/// use precursors::sweep::{merge, Sweep, SweepOptions};
/// let sweep = Sweep::from_json_str(r#"{
///     "base": { "block": { "lx": 0.01, "ly": 0.004, "lz": 0.01 },
///               "cells": { "kind": "count", "nx": 10, "ny": 4 },
///               "normal_load": 40.0 },
///     "axes": [ { "key": "normal_load", "values": [40.0, 60.0] } ],
///     "seed": 7
/// }"#)?;
/// let out = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// // Half the sweep (share 0 of 2: the run at F_N = 40 N), merged so far.
/// sweep.execute(&out, &SweepOptions::new().with_shard(0, 2)?, |_| {})?;
/// let partial = merge(&out)?;
/// assert_eq!((partial.points, partial.runs_merged, partial.runs_missing), (2, 1, 1));
/// // The other half, and the merge again.
/// sweep.execute(&out, &SweepOptions::new().with_shard(1, 2)?, |_| {})?;
/// let full = merge(&out)?;
/// assert_eq!((full.runs_merged, full.runs_missing), (2, 0));
/// let names: Vec<_> = full.files.iter().filter_map(|f| f.file_name()?.to_str()).collect();
/// assert_eq!(names, ["curves.csv", "slip.csv", "avalanches.csv", "runs.csv"]);
/// std::fs::remove_dir_all(&out).ok();
/// # Ok::<(), precursors::sweep::SweepError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct MergeSummary {
    /// Parameter points.
    pub points: usize,
    /// Complete runs merged.
    pub runs_merged: usize,
    /// Runs without their completion marker (not run yet, or cut): left out.
    pub runs_missing: usize,
    /// The files written: `curves.csv`, `slip.csv`, `avalanches.csv`, `runs.csv`.
    pub files: Vec<PathBuf>,
}

/// The 97.5 % quantile of Student's t distribution with `df` degrees of freedom (the
/// half-width of a two-sided 95 % band is `t · s/√n`, `df = n - 1`): tabulated for
/// `df <= 30`, above by the Cornish-Fisher expansion `z + (z³ + z)/(4 df)` (error below
/// 3e-3); `NaN` for `df = 0`.
fn t_quantile_975(df: usize) -> f64 {
    const TABLE: [f64; 30] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
        2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
        2.052, 2.048, 2.045, 2.042,
    ];
    match df {
        0 => f64::NAN,
        1..=30 => TABLE[df - 1],
        _ => {
            let z = 1.959_963_984_540_054;
            z + (z * z * z + z) / (4.0 * df as f64)
        }
    }
}

/// The mean of a sample and the two-sided 95 % Student-t band of the mean
/// ([`mean_band`]), in the units of the sample.
///
/// ```
/// use precursors::sweep::mean_band;
/// let band = mean_band(&[2.0, 4.0]); // t(1) = 12.706, s/√n = 1
/// assert_eq!(band.mean, 3.0);
/// assert!((band.hi - band.mean - 12.706).abs() < 1e-3 && band.mean - band.lo == band.hi - band.mean);
/// assert!(mean_band(&[2.0]).lo.is_nan()); // no band from one value
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Band {
    /// The sample mean (`NaN` for an empty sample).
    pub mean: f64,
    /// `mean - t(n-1) s/√n` (`NaN` below two values).
    pub lo: f64,
    /// `mean + t(n-1) s/√n` (`NaN` below two values).
    pub hi: f64,
}

/// The mean of `x` and its 95 % Student-t band, `mean ± t(n-1) · s/√n` (`s` the sample
/// standard deviation, `t` the 97.5 % quantile: tabulated to 30 degrees of freedom,
/// Cornish-Fisher above, error below 3e-3): the bands of [`merge`]'s tables, for a
/// study's own statistics over a quantity `merge` does not report (e.g.
/// `examples/convergence_figures.rs`).
///
/// ```
/// use precursors::sweep::mean_band;
/// // 1, 2, 3, 4: mean 2.5, s² = 5/3, t(3) = 3.182.
/// let band = mean_band(&[1.0, 2.0, 3.0, 4.0]);
/// let half = 3.182 * (5.0f64 / 3.0 / 4.0).sqrt();
/// assert_eq!(band.mean, 2.5);
/// assert!((band.hi - 2.5 - half).abs() < 1e-12 && (2.5 - band.lo - half).abs() < 1e-12);
/// assert!(mean_band(&[0.7]).lo.is_nan());                 // one value: no band
/// assert!(mean_band(&[]).mean.is_nan());
/// ```
pub fn mean_band(x: &[f64]) -> Band {
    let n = x.len();
    let nan = f64::NAN;
    if n == 0 {
        return Band {
            mean: nan,
            lo: nan,
            hi: nan,
        };
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    if n < 2 {
        return Band {
            mean,
            lo: nan,
            hi: nan,
        };
    }
    let var = x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1) as f64;
    let half = t_quantile_975(n - 1) * (var / n as f64).sqrt();
    Band {
        mean,
        lo: mean - half,
        hi: mean + half,
    }
}

/// [`mean_band`] as `(mean, lo, hi)`.
fn band(x: &[f64]) -> (f64, f64, f64) {
    let b = mean_band(x);
    (b.mean, b.lo, b.hi)
}

/// `mean,lo,hi,min,max` of `x` as CSV cells.
fn stats(x: &[f64]) -> String {
    let (m, lo, hi) = band(x);
    let min = x.iter().copied().fold(f64::INFINITY, f64::min);
    let max = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    [m, lo, hi, min, max].map(num).join(",")
}

pub(super) fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.12e}")
    } else {
        String::new()
    }
}

/// A CSV cell: quoted when it holds a comma or a quote.
pub(super) fn cell(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// One complete run's data.
struct RunData {
    /// `(F/(μF_N), ℓ/Lx, A_R)` per stable state.
    curve: Vec<(f64, f64, f64)>,
    /// Ruptures of each stable state.
    avalanches: Vec<usize>,
    /// `F/(μF_N)` of global slip.
    slip: Option<f64>,
    /// The name of its contact rule (its scene record's key `contact.rule`).
    contact_rule: String,
}

/// The complete run in `dir`, read and checked ([`RunRecord::read`]): its tables whole,
/// within their bounds and consistent with each other, and its recorded scene the one
/// the sweep gives `run` (a directory swapped with another point's, a `scene.json` from
/// elsewhere, or a `sweep.json` edited since the run are refused).
fn read_run(dir: &Path, run: &SweepRun) -> Result<RunData> {
    let record = checked_record(dir, run)?;
    Ok(RunData {
        curve: record
            .curve
            .iter()
            .map(|c| (c.load, c.precursor_over_lx, c.area))
            .collect(),
        avalanches: record.ruptures,
        slip: Some(record.slip),
        contact_rule: record.contact.name().to_string(),
    })
}

/// The complete run in `dir` as [`read_run`] checks it, whole.
pub(super) fn checked_record(dir: &Path, run: &SweepRun) -> Result<RunRecord> {
    // The scene first: tables checked against another point's scene would be refused
    // for their numbers, not for what is wrong.
    let record_path = dir.join(RUN_SCENE);
    if record_path.is_file() {
        let recorded = crate::scene::SceneBuilder::from_json_file(&record_path)?;
        if let Some(e) = crate::driver::scene_mismatch(
            &run.scene,
            &format!("the sweep's run {} ({})", run.index, run.dir_name),
            &recorded,
            &format!("the scene recorded in {}", dir.join(RUN_SCENE).display()),
        ) {
            return Err(Error::RunDirectory {
                path: dir.to_path_buf(),
                reason: format!(
                    "its tables are not the sweep's run: {e} (a run directory moved, or {SWEEP_FILE} \
                     edited since the run: run the sweep again into a new directory)"
                ),
            });
        }
    }
    RunRecord::read(dir)
}

/// The values of ℓ/Lx and of `A_R/A_R(0)` of the runs of `data` at the load
/// `f = F/(μF_N)`, each run at its last stable state at or below `f` (a run with none yet
/// is left out).
fn values_at(data: &[RunData], f: f64) -> (Vec<f64>, Vec<f64>) {
    let mut ell = Vec::new();
    let mut area = Vec::new();
    for d in data {
        let a0 = d.curve.first().map_or(f64::NAN, |c| c.2);
        if let Some(c) = d.curve.iter().rev().find(|c| c.0 <= f + 1e-12) {
            ell.push(c.1);
            area.push(c.2 / a0);
        }
    }
    (ell, area)
}

/// The mean and 95 % band `(mean, lo, hi)` of ℓ/Lx and of `A_R/A_R(0)` over the runs of
/// `data` at the load `f = F/(μF_N)` ([`values_at`]), and the number of runs counted.
fn bands_at(data: &[RunData], f: f64) -> (usize, (f64, f64, f64), (f64, f64, f64)) {
    let (ell, area) = values_at(data, f);
    (ell.len(), band(&ell), band(&area))
}

/// The fewest values whose median has a distribution-free 95 % interval (below six, even
/// the smallest and largest value cover the median with less than 95 %).
#[cfg(feature = "plot")]
pub(crate) const MEDIAN_BAND_RUNS: usize = 6;

/// The median of `x` and its distribution-free 95 % confidence interval `(median, lo,
/// hi)`: the order statistics `x_(j)` and `x_(n+1-j)` (1-based, sorted), `j` the largest
/// with `2·P(B ≤ j−1) ≤ 0.05` for `B` binomial(n, ½), so that the interval covers the
/// median of the distribution with at least 95 % whatever its shape (no normality
/// assumed: a few realizations many times the others move neither end). The interval is
/// `NaN` below [`MEDIAN_BAND_RUNS`] values, everything `NaN` for none or for a value that
/// is not finite.
#[cfg(feature = "plot")]
fn median_band(x: &[f64]) -> (f64, f64, f64) {
    let n = x.len();
    if n == 0 || x.iter().any(|v| !v.is_finite()) {
        return (f64::NAN, f64::NAN, f64::NAN);
    }
    let mut sorted = x.to_vec();
    sorted.sort_by(f64::total_cmp);
    let median = if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    };
    // The binomial(n, ½) tail P(B ≤ k), its terms in logarithms (2^-n underflows for
    // large n).
    let mut log_term = -(n as f64) * std::f64::consts::LN_2;
    let mut tail = log_term.exp();
    let mut j = 0;
    for k in 1..=n / 2 {
        if 2.0 * tail > 0.05 {
            break;
        }
        j = k;
        log_term += ((n - k + 1) as f64 / k as f64).ln();
        tail += log_term.exp();
    }
    if j == 0 {
        return (median, f64::NAN, f64::NAN);
    }
    (median, sorted[j - 1], sorted[n - j])
}

/// The ensemble curves of one parameter point (what `plot::figures` draws).
#[cfg(feature = "plot")]
pub(crate) struct EnsembleCurves {
    /// Each key and its value (JSON text).
    pub values: Vec<(String, String)>,
    /// Complete runs.
    pub runs: usize,
    /// `(F/(μF_N), mean, lo, hi)` of ℓ/Lx on the load grid.
    pub precursor: Vec<(f64, f64, f64, f64)>,
    /// `(F/(μF_N), median, lo, hi)` of `A_R/A_R(0)`: its median and the median's
    /// distribution-free 95 % interval ([`median_band`]; the area law spreads the
    /// realizations over orders of magnitude near slip, where a t-band of the mean spans
    /// the whole chart).
    pub area: Vec<(f64, f64, f64, f64)>,
}

/// The ensemble curves of each parameter point of the sweep in `dir` on `grid` (loads
/// `F/(μF_N)`), as [`merge`] computes them, from the complete runs.
///
/// # Errors
/// As [`merge`].
#[cfg(feature = "plot")]
pub(crate) fn ensemble_curves(dir: &Path, grid: &[f64]) -> Result<Vec<EnsembleCurves>, SweepError> {
    let sweep = Sweep::from_json_file(dir.join(SWEEP_FILE))?;
    let mut out = Vec::new();
    for point in 0..sweep.points() {
        let runs: Vec<&SweepRun> = sweep.runs().iter().filter(|r| r.point == point).collect();
        let Some(first) = runs.first() else { continue };
        let mut data = Vec::new();
        for run in &runs {
            let run_dir = dir.join(&run.dir_name);
            if crate::files::is_file(&run_dir.join(DONE), "examining the run directory")? {
                data.push(read_run(&run_dir, run)?);
            }
        }
        let (mut precursor, mut area) = (Vec::new(), Vec::new());
        for &f in grid {
            let (ell, area_ratio) = values_at(&data, f);
            let (e, a) = (band(&ell), median_band(&area_ratio));
            precursor.push((f, e.0, e.1, e.2));
            area.push((f, a.0, a.1, a.2));
        }
        out.push(EnsembleCurves {
            values: first.values.clone(),
            runs: data.len(),
            precursor,
            area,
        });
    }
    Ok(out)
}

/// Merges the runs of the sweep in `dir` (written by [`Sweep::execute`], all shards into
/// one directory) into four CSV files in `dir`, one block of rows per parameter point
/// (the axes' values as columns, named by their keys):
///
/// * `curves.csv`: on 0.05, 0.10, ..., 0.95, the mean and 95 % band of ℓ/Lx and of `A_R/A_R(0)`
///   over the realizations, each taking the value of its last stable state at or below
///   the load (a realization with none yet is left out; `runs` counts those in). `A_R(0)`
///   is the real contact area of the run's first stable state (zero shear). The band is
///   Student's t: `mean ± t(0.975, n-1)·s/√n` (the tabulated quantile up to 30 degrees
///   of freedom), empty below two runs;
/// * `slip.csv`: the global-slip load `F/(μF_N)` and the load of the last stable state
///   before it: mean, band, min, max of each;
/// * `avalanches.csv`: the distribution of the ruptures per stable state (avalanche
///   size ≥ 1; stable states reached without a rupture are not counted), pooled over the
///   realizations: size, count, fraction;
/// * `runs.csv`: one row per run: its point, realization, seed, stable states and slip
///   load (empty for a run not complete), and the name of its contact rule.
///
/// Runs without their completion marker are left out and counted.
///
/// Each file is written atomically (a temporary file renamed over it): a full disk or a
/// kill leaves the previous file or the new one.
///
/// # Errors
/// [`SweepError::Directory`] when `dir` holds no `sweep.json`; its errors as a sweep file
/// ([`Sweep::from_json_file`]); in [`SweepError::Core`]: [`Error::Io`] for a file that
/// cannot be read or written, [`Error::CorruptTable`] for a run's damaged table,
/// [`Error::NonFiniteCell`] for a `NaN`, an infinity or an empty cell where a number
/// belongs in one (with the file, line and column).
///
/// [`Sweep`]'s example runs a sweep and merges it; a directory without `sweep.json` is
/// refused:
///
/// ```
/// use precursors::sweep::{merge, SweepError};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-merge-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// assert!(matches!(merge(&dir), Err(SweepError::Directory { .. })));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn merge(dir: &Path) -> Result<MergeSummary, SweepError> {
    let sweep = read_sweep(dir)?;
    let mut tables = Tables::new(&sweep.keys());
    let (mut merged, mut missing) = (0, 0);
    for point in 0..sweep.points() {
        let runs: Vec<&SweepRun> = sweep.runs().iter().filter(|r| r.point == point).collect();
        let Some(first) = runs.first() else { continue };
        let values: String = first
            .values
            .iter()
            .map(|(_, v)| format!("{},", cell(v)))
            .collect();
        let data = tables.read_runs(dir, &runs, &values)?;
        merged += data.len();
        missing += runs.len() - data.len();
        tables.add_point(point, &values, &data);
    }
    Ok(MergeSummary {
        points: sweep.points(),
        runs_merged: merged,
        runs_missing: missing,
        files: tables.write(dir)?,
    })
}

/// The sweep of the output directory `dir` (its copy [`SWEEP_FILE`]).
///
/// # Errors
/// [`SweepError::Directory`] when `dir` holds no `sweep.json`; its errors as a sweep file.
pub(super) fn read_sweep(dir: &Path) -> Result<Sweep, SweepError> {
    let sweep_path = dir.join(SWEEP_FILE);
    if !crate::output::layout::is_sweep(dir)? {
        return Err(SweepError::Directory {
            path: dir.to_path_buf(),
            reason: format!("no {SWEEP_FILE}: not the output directory of a sweep"),
        });
    }
    Sweep::from_json_file(&sweep_path)
}

/// The text of the four merged tables, row by row.
struct Tables {
    curves: String,
    slips: String,
    avalanches: String,
    runs: String,
}

impl Tables {
    /// The tables with their headers (the axes' `keys` as columns).
    fn new(keys: &[&str]) -> Tables {
        let key_header = keys
            .iter()
            .map(|k| format!("{},", cell(k)))
            .collect::<String>();
        Tables {
            curves: format!(
                "point,{key_header}force_over_mu_FN,runs,precursor_over_Lx_mean,\
                 precursor_over_Lx_lo,precursor_over_Lx_hi,area_ratio_mean,area_ratio_lo,\
                 area_ratio_hi\n"
            ),
            slips: format!(
                "point,{key_header}runs,slip_over_mu_FN_mean,slip_over_mu_FN_lo,\
                 slip_over_mu_FN_hi,slip_over_mu_FN_min,slip_over_mu_FN_max,\
                 last_stable_over_mu_FN_mean,last_stable_over_mu_FN_lo,\
                 last_stable_over_mu_FN_hi,last_stable_over_mu_FN_min,\
                 last_stable_over_mu_FN_max\n"
            ),
            avalanches: format!("point,{key_header}ruptures,count,fraction\n"),
            runs: format!(
                "run,point,realization,seed,{key_header}stable_states,slip_over_mu_FN,\
                 contact_rule\n"
            ),
        }
    }

    /// The data of the complete runs of one point (`values`: its axes' cells), each run's
    /// row of `runs.csv` written (empty counts for a run not complete).
    fn read_runs(&mut self, dir: &Path, runs: &[&SweepRun], values: &str) -> Result<Vec<RunData>> {
        let mut data = Vec::new();
        for run in runs {
            let run_dir = dir.join(&run.dir_name);
            let (point, realization, seed) = (run.point, run.realization, run.seed);
            if !crate::files::is_file(&run_dir.join(DONE), "examining the run directory")? {
                // Its rule as the sweep gives it (no scene record to read yet).
                let _ = writeln!(
                    self.runs,
                    "{},{point},{realization},{seed},{values},,{}",
                    run.index,
                    run.scene.contact().name()
                );
                continue;
            }
            let d = read_run(&run_dir, run)?;
            let _ = writeln!(
                self.runs,
                "{},{point},{realization},{seed},{values}{},{},{}",
                run.index,
                d.curve.len(),
                d.slip.map(num).unwrap_or_default(),
                d.contact_rule
            );
            data.push(d);
        }
        Ok(data)
    }

    /// The rows of one point in `curves.csv`, `slip.csv` and `avalanches.csv`.
    fn add_point(&mut self, point: usize, values: &str, data: &[RunData]) {
        for &f in &GRID_LOADS {
            let (runs, (em, el, eh), (am, al, ah)) = bands_at(data, f);
            let _ = writeln!(
                self.curves,
                "{point},{values}{f:.2},{runs},{},{},{},{},{},{}",
                num(em),
                num(el),
                num(eh),
                num(am),
                num(al),
                num(ah)
            );
        }
        let s: Vec<f64> = data.iter().filter_map(|d| d.slip).collect();
        let last: Vec<f64> = data
            .iter()
            .filter_map(|d| d.curve.last().map(|c| c.0))
            .collect();
        let _ = writeln!(
            self.slips,
            "{point},{values}{},{},{}",
            s.len(),
            stats(&s),
            stats(&last)
        );
        let sizes: Vec<usize> = data
            .iter()
            .flat_map(|d| d.avalanches.iter().copied())
            .filter(|&s| s >= 1)
            .collect();
        // A map, not a vector indexed by size: an edited table's size of 1e18 must not
        // allocate 8e18 bytes.
        let mut counts = std::collections::BTreeMap::<usize, usize>::new();
        for &s in &sizes {
            *counts.entry(s).or_default() += 1;
        }
        for (size, count) in counts {
            let _ = writeln!(
                self.avalanches,
                "{point},{values}{size},{count},{}",
                num(count as f64 / sizes.len() as f64)
            );
        }
    }

    /// Writes the four tables into `dir`; returns their paths.
    fn write(self, dir: &Path) -> Result<Vec<PathBuf>> {
        let mut files = Vec::new();
        for (name, text) in [
            (MERGED[0], self.curves),
            (MERGED[1], self.slips),
            (MERGED[2], self.avalanches),
            (MERGED[3], self.runs),
        ] {
            // Atomically: a full disk or a kill leaves the old table or the new one, never
            // an empty or half one that looks complete.
            let path = dir.join(name);
            write_atomically(&path, text.as_bytes(), "writing")?;
            files.push(path);
        }
        Ok(files)
    }
}

#[cfg(test)]
mod tests {
    use super::t_quantile_975;

    /// The interval's ends against the binomial(n, ½) table (e.g. Conover, Practical
    /// Nonparametric Statistics, table A3): n = 20: P(B ≤ 5) = 0.0207, P(B ≤ 6) = 0.0577,
    /// so j = 6, the 6th and 15th values; n = 6: 2·(1/64) = 0.031: the smallest and the
    /// largest; n = 5: 2·(1/32) = 0.0625 > 0.05: none. Two realizations a thousand times
    /// the others (the area law near slip) move neither end: the mean's t-band of these
    /// values spans 0 to above 200.
    #[cfg(feature = "plot")]
    #[test]
    fn the_medians_interval_is_set_by_order_statistics() {
        use super::median_band;
        let value = |k: usize| 1.0 + 0.01 * k as f64;
        let mut x: Vec<f64> = (1..=18).map(value).collect();
        x.extend([1000.0, 2000.0]);
        x.reverse();
        let (median, lo, hi) = median_band(&x);
        assert_eq!(
            (median, lo, hi),
            (0.5 * (value(10) + value(11)), value(6), value(15))
        );
        let (mean, t_lo, t_hi) = super::band(&x);
        assert!(
            mean > 100.0 && t_lo < 0.0 && t_hi > 200.0,
            "{mean} {t_lo} {t_hi}"
        );
        assert_eq!(
            median_band(&[6.0, 1.0, 5.0, 2.0, 4.0, 3.0]),
            (3.5, 1.0, 6.0)
        );
        let (median, lo, hi) = median_band(&[5.0, 1.0, 4.0, 2.0, 3.0]);
        assert_eq!(median, 3.0);
        assert!(lo.is_nan() && hi.is_nan());
        assert!(median_band(&[]).0.is_nan());
        assert!(median_band(&[1.0, f64::NAN]).0.is_nan());
        // Large n: no underflow; the ends near n/2 ∓ 1.96·√n/2 (normal approximation).
        let x: Vec<f64> = (0..4000).map(|k| k as f64).collect();
        let (_, lo, hi) = median_band(&x);
        assert!(
            (lo - (2000.0 - 62.0)).abs() <= 2.0 && (hi - (2000.0 + 61.0)).abs() <= 2.0,
            "{lo} {hi}"
        );
    }

    /// Against the table of Student's t (two-sided 95 %; e.g. NIST/SEMATECH e-Handbook,
    /// table 1.3.6.7.2) and the normal quantile 1.95996 for large samples.
    #[test]
    fn student_t_quantiles_match_the_table() {
        assert_eq!(t_quantile_975(1), 12.706);
        assert_eq!(t_quantile_975(9), 2.262);
        assert_eq!(t_quantile_975(30), 2.042);
        assert!((t_quantile_975(60) - 2.000).abs() < 3e-3);
        assert!((t_quantile_975(1_000_000) - 1.95996).abs() < 1e-4);
        assert!(t_quantile_975(0).is_nan());
    }
}
