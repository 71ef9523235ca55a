//! Scaling relations between observables and with the system's size (issue 54): the
//! universality classes an exponent's interval excludes, means of one observable in
//! log-spaced bins of another with a standard-error interval, a power-law slope between
//! two observables with a bootstrap interval, and the finite-size data collapse
//! `P(S) S^τ` against `S / L^D`.

use super::{
    check_fit_options, log_binned, percentile_interval, positive_sorted, replica_rng, replicas,
    Support,
};
use crate::error::{Error, Result};
use rand::RngExt;

/// A universality class of avalanches under a slowly rising load, by its size exponent
/// `τ` of `P(S) ∝ S^(-τ)` (dimensionless).
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct UniversalityClass {
    /// Its name, as `power_laws.csv` and `stats` print it.
    pub name: &'static str,
    /// Its size exponent `τ` (dimensionless).
    pub exponent: f64,
}

/// The classes a referee compares an avalanche-size exponent with (docs/statistics.md):
/// mean-field depinning (`τ = 3/2`; a 2-D interface with 3-D elasticity sits at its upper
/// critical dimension), the equal-load-sharing fibre bundle near failure (`3/2`) and far
/// from it (`5/2`, the burst distribution integrated over the load), and the long-range
/// elastic line (`τ ≈ 1.28`).
pub const UNIVERSALITY_CLASSES: [UniversalityClass; 4] = [
    UniversalityClass {
        name: "mean-field depinning 3/2",
        exponent: 1.5,
    },
    UniversalityClass {
        name: "fibre bundle near failure 3/2",
        exponent: 1.5,
    },
    UniversalityClass {
        name: "fibre bundle far from failure 5/2",
        exponent: 2.5,
    },
    UniversalityClass {
        name: "long-range elastic line 1.28",
        exponent: 1.28,
    },
];

/// The classes of [`UNIVERSALITY_CLASSES`] whose exponent lies outside the interval
/// `[low, high]` (an exponent's bootstrap interval at 95 %, say): the classes the interval
/// excludes at its level.
///
/// ```
/// use precursors::statistics::classes_excluded;
/// let names: Vec<_> = classes_excluded(1.4, 1.7)?.iter().map(|c| c.name).collect();
/// assert_eq!(names, ["fibre bundle far from failure 5/2", "long-range elastic line 1.28"]);
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
/// [`Error::InvalidParameter`] (`"interval"`) when an end is NaN or `low > high`.
pub fn classes_excluded(low: f64, high: f64) -> Result<Vec<UniversalityClass>> {
    if low.is_nan() || high.is_nan() || low > high {
        return Err(Error::InvalidParameter {
            name: "interval",
            value: if low.is_nan() { low } else { high },
            reason: "an interval needs two numbers, the lower first",
        });
    }
    Ok(UNIVERSALITY_CLASSES
        .iter()
        .filter(|c| c.exponent < low || c.exponent > high)
        .copied()
        .collect())
}

/// The mean of `y` over the pairs whose `x` falls in one log-spaced bin ([`binned_means`]).
/// `x` values are in `x`'s unit, means in `y`'s.
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct BinnedMean {
    /// Lower edge of the bin (included), `10^(k / bins_per_decade)`.
    pub low: f64,
    /// Upper edge (excluded).
    pub high: f64,
    /// Geometric centre of the edges.
    pub center: f64,
    /// The mean of the `x` values in the bin.
    pub x_mean: f64,
    /// Pairs in the bin (at least 1: empty bins are not listed).
    pub count: usize,
    /// The mean of their `y`.
    pub mean: f64,
    /// Lower end of the interval `mean - z s / √count` (`s` the sample standard deviation,
    /// `z` the normal quantile of the confidence level); `None` for a single pair.
    pub mean_low: Option<f64>,
    /// Upper end `mean + z s / √count`; `None` for a single pair.
    pub mean_high: Option<f64>,
}

/// The quantile `z` of the standard normal law with `P(|N| ≤ z) = confidence`, by bisection
/// on the two-sided tail (to 1e-12).
fn normal_quantile(confidence: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 40.0f64);
    while hi - lo > 1e-12 {
        let mid = 0.5 * (lo + hi);
        if super::special::normal_two_sided(mid) > 1.0 - confidence {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Checks the pairs `(x, y)` of two observables: as many of each, all finite.
fn checked_pairs(x: &[f64], y: &[f64]) -> Result<()> {
    if x.len() != y.len() {
        return Err(Error::InvalidCount {
            name: "y",
            value: y.len() as u64,
            reason: "the two observables must have one value per pair",
        });
    }
    if let Some(&v) = x.iter().chain(y).find(|v| !v.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "samples",
            value: v,
            reason: "samples must be finite",
        });
    }
    Ok(())
}

/// The mean of `y` in log-spaced bins of `x`, with a standard-error interval: the mean
/// avalanche size against `1 - F/(μF_N)`, the mean force drop against the size.
///
/// Pairs whose `x` is zero or negative are left out. The bins are `[10^(k/b),
/// 10^((k+1)/b))`, `b = bins_per_decade` and `k` any integer, so that the bins of two sets
/// align; only bins holding a pair are listed, in increasing `x`. The interval is
/// `mean ± z s/√n` with `s` the sample standard deviation of the bin's `y` and `z` the
/// normal quantile of `confidence` (1.96 at 0.95): it treats the pairs as independent.
///
/// ```
/// use precursors::statistics::binned_means;
/// let x = [0.011, 0.012, 0.5, 0.6, 0.7];
/// let y = [10.0, 14.0, 1.0, 2.0, 3.0];
/// let bins = binned_means(&x, &y, 1, 0.95)?;
/// assert_eq!(bins.len(), 2);
/// assert_eq!((bins[0].low, bins[0].high, bins[0].count, bins[0].mean), (0.01, 0.1, 2, 12.0));
/// // s = 1 over 3 pairs: 2 ± 1.96/√3.
/// let half = bins[1].mean_high.unwrap() - bins[1].mean;
/// assert!((half - 1.959964 / 3f64.sqrt()).abs() < 1e-5);
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
/// [`Error::InvalidCount`] (`"y"`) when `x` and `y` differ in length,
/// (`"bins_per_decade"`) when it is 0 or above a million; [`Error::InvalidParameter`]
/// (`"samples"`) for a value that is not finite, (`"confidence"`) for a level not strictly
/// between 0 and 1.
pub fn binned_means(
    x: &[f64],
    y: &[f64],
    bins_per_decade: usize,
    confidence: f64,
) -> Result<Vec<BinnedMean>> {
    checked_pairs(x, y)?;
    if bins_per_decade == 0 || bins_per_decade > 1_000_000 {
        return Err(Error::InvalidCount {
            name: "bins_per_decade",
            value: bins_per_decade as u64,
            reason: "binned means take 1 to a million bins per decade",
        });
    }
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(Error::InvalidParameter {
            name: "confidence",
            value: confidence,
            reason: "a confidence level lies strictly between 0 and 1",
        });
    }
    let b = bins_per_decade as f64;
    let edge = |k: i64| 10f64.powf(k as f64 / b);
    // The bin of each positive x: floor(b log10 x), corrected for rounding at the edges.
    let bin_of = |v: f64| {
        let mut k = (b * v.log10()).floor() as i64;
        while edge(k) > v {
            k -= 1;
        }
        while edge(k + 1) <= v {
            k += 1;
        }
        k
    };
    let mut pairs: Vec<(i64, f64, f64)> = x
        .iter()
        .zip(y)
        .filter(|(x, _)| **x > 0.0)
        .map(|(&x, &y)| (bin_of(x), x, y))
        .collect();
    pairs.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let z = normal_quantile(confidence);
    let mut out = Vec::new();
    for group in pairs.chunk_by(|a, b| a.0 == b.0) {
        let n = group.len() as f64;
        let mean = group.iter().map(|p| p.2).sum::<f64>() / n;
        let x_mean = group.iter().map(|p| p.1).sum::<f64>() / n;
        let half = (group.len() > 1).then(|| {
            let var = group.iter().map(|p| (p.2 - mean).powi(2)).sum::<f64>() / (n - 1.0);
            z * (var / n).sqrt()
        });
        let (low, high) = (edge(group[0].0), edge(group[0].0 + 1));
        out.push(BinnedMean {
            low,
            high,
            center: (low * high).sqrt(),
            x_mean,
            count: group.len(),
            mean,
            mean_low: half.map(|h| mean - h),
            mean_high: half.map(|h| mean + h),
        });
    }
    Ok(out)
}

/// The fit `y ≈ c x^β` between two observables ([`fit_scaling`]).
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ScalingFit {
    /// The pairs fitted: those with `x > 0` and `y > 0`.
    pub pairs: usize,
    /// The exponent `β` (dimensionless): the least-squares slope of `ln y` on `ln x`.
    pub exponent: f64,
    /// The prefactor `c` (`y`'s unit over `x`'s unit to the power `β`): `e` to the
    /// intercept.
    pub prefactor: f64,
    /// Lower end of the percentile bootstrap interval of `β` (pairs resampled with
    /// replacement) at the options' `confidence`; equal to `exponent` without resamples.
    pub exponent_low: f64,
    /// Upper end of that interval.
    pub exponent_high: f64,
}

/// Bootstrap stream of [`fit_scaling`] (apart from the power law's).
const SCALING_STREAM: u64 = 3;
/// Bootstrap stream of [`fit_collapse`].
const COLLAPSE_STREAM: u64 = 4;

/// Least squares of `ln y` on `ln x`: `(slope, intercept)`, `None` when the `ln x` are
/// all equal.
fn least_squares(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| (sxy / sxx, my - sxy / sxx * mx))
}

/// Fits `y ≈ c x^β` to pairs of two observables of the same avalanches (the force drop,
/// or the potency, against the size): `β` and `ln c` by least squares of `ln y` on
/// `ln x` over the pairs with both positive (so the fit follows the geometric mean of `y`
/// at given `x`), and a percentile bootstrap interval of `β` from
/// [`PowerLawOptions::bootstrap`](super::PowerLawOptions::bootstrap) resamples of the
/// pairs (seeded by its `seed`; resamples whose `x` are all equal are left out).
///
/// ```
/// use precursors::statistics::{fit_scaling, PowerLawOptions};
/// let sizes: Vec<f64> = (1..=50).map(f64::from).collect();
/// let drops: Vec<f64> = sizes.iter().map(|s| 0.3 * s.powf(1.8)).collect();
/// let fit = fit_scaling(&sizes, &drops, &PowerLawOptions::default().bootstrap(50))?;
/// assert!((fit.exponent - 1.8).abs() < 1e-12 && (fit.prefactor - 0.3).abs() < 1e-12);
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
/// [`Error::InvalidCount`] (`"y"`) when `x` and `y` differ in length;
/// [`Error::InvalidParameter`] (`"samples"`) for a value that is not finite or positive
/// `x` that are all equal; [`Error::TooFewSamples`] (`"scaling fit"`) for fewer than 3
/// pairs with both positive; the options' errors as [`super::fit_power_law`]'s.
pub fn fit_scaling(x: &[f64], y: &[f64], options: &super::PowerLawOptions) -> Result<ScalingFit> {
    checked_pairs(x, y)?;
    check_fit_options(options)?;
    let points: Vec<(f64, f64)> = x
        .iter()
        .zip(y)
        .filter(|(x, y)| **x > 0.0 && **y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if points.len() < 3 {
        return Err(Error::TooFewSamples {
            what: "scaling fit",
            count: points.len(),
            needed: 3,
        });
    }
    let Some((slope, intercept)) = least_squares(&points) else {
        return Err(Error::InvalidParameter {
            name: "samples",
            value: x.iter().copied().find(|v| *v > 0.0).unwrap_or(0.0),
            reason: "the positive x are all equal: no slope",
        });
    };
    let mut slopes: Vec<f64> = replicas(options.bootstrap, &|| {}, |i, _| {
        let mut rng = replica_rng(options.seed, SCALING_STREAM, i);
        let resample: Vec<(f64, f64)> = (0..points.len())
            .map(|_| points[rng.random_range(0..points.len())])
            .collect();
        least_squares(&resample).map(|(s, _)| s)
    })
    .into_iter()
    .flatten()
    .collect();
    let (low, high) =
        percentile_interval(&mut slopes, options.confidence).unwrap_or((slope, slope));
    Ok(ScalingFit {
        pairs: points.len(),
        exponent: slope,
        prefactor: intercept.exp(),
        exponent_low: low,
        exponent_high: high,
    })
}

/// The data collapse of the size distributions of several system sizes ([`fit_collapse`]).
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Collapse {
    /// The exponent `τ` of `P(S) = S^(-τ) f(S / L^D)` (dimensionless).
    pub tau: f64,
    /// Lower end of its percentile bootstrap interval over realizations.
    pub tau_low: f64,
    /// Upper end.
    pub tau_high: f64,
    /// The exponent `D` of the cut-off size `L^D` (dimensionless; `L` in metres).
    pub d: f64,
    /// Lower end of its bootstrap interval.
    pub d_low: f64,
    /// Upper end.
    pub d_high: f64,
    /// The spread at the optimum: the mean over overlapping points of the squared
    /// difference between one curve's `ln(P S^τ)` and another's, interpolated, each over
    /// its Poisson variance `1/count` (about 1 when the curves agree within their counts).
    pub spread: f64,
    /// Overlapping points the spread averages over.
    pub overlaps: usize,
}

/// One size's collapsed curve: `(ln S - D ln L, ln P + τ ln S, count)` per bin.
type Curve = Vec<(f64, f64, f64)>;

/// The fewest samples in a bin for it to enter the collapse: with fewer, `ln P` is too
/// noisy (its variance `1/count` above 1/3).
const COLLAPSE_MIN_COUNT: usize = 3;

/// The log-binned `(ln centre, ln density, count)` of the bins with enough samples.
fn binned(samples: &[f64], support: Support, bins_per_decade: usize) -> Result<Vec<[f64; 3]>> {
    Ok(log_binned(samples, support, bins_per_decade)?
        .into_iter()
        .filter(|b| b.count >= COLLAPSE_MIN_COUNT && b.density > 0.0)
        .map(|b| [b.center.ln(), b.density.ln(), b.count as f64])
        .collect())
}

/// The spread of the curves of `sets` (`ln L`, binned) collapsed with `(τ, D)`, and the
/// overlapping points: for each pair of curves, each point of one inside the other's
/// range of `ln S - D ln L` against the other's linear interpolation there.
fn spread(sets: &[(f64, Vec<[f64; 3]>)], tau: f64, d: f64) -> (f64, usize) {
    let curves: Vec<Curve> = sets
        .iter()
        .map(|(ln_l, bins)| {
            bins.iter()
                .map(|[u, p, c]| (u - d * ln_l, p + tau * u, *c))
                .collect()
        })
        .collect();
    let (mut sum, mut n) = (0.0, 0usize);
    for (i, a) in curves.iter().enumerate() {
        for (j, b) in curves.iter().enumerate() {
            if i == j || b.len() < 2 {
                continue;
            }
            for &(u, v, c) in a {
                let k = b.partition_point(|p| p.0 <= u);
                if k == 0 || k == b.len() {
                    continue;
                }
                let (p, q) = (b[k - 1], b[k]);
                let t = (u - p.0) / (q.0 - p.0);
                let w = p.1 + t * (q.1 - p.1);
                let cw = p.2 + t * (q.2 - p.2);
                sum += (v - w).powi(2) / (1.0 / c + 1.0 / cw);
                n += 1;
            }
        }
    }
    (
        if n == 0 {
            f64::INFINITY
        } else {
            sum / n as f64
        },
        n,
    )
}

/// The box the collapse searches: `τ` and `D` in `[0, 4]`.
const COLLAPSE_BOX: ([f64; 2], [f64; 2]) = ([0.0, 0.0], [4.0, 4.0]);
/// Steps of the grid the search starts from.
const COLLAPSE_GRID: usize = 40;

/// The `(τ, D)` of least spread: the best point of a 41 x 41 grid over the box, refined by
/// Nelder–Mead; `None` when no `(τ, D)` makes two curves overlap.
fn best_collapse(sets: &[(f64, Vec<[f64; 3]>)]) -> Option<([f64; 2], f64, usize)> {
    let (lo, hi) = COLLAPSE_BOX;
    // A small overlap gives a small spread by chance (two points may agree exactly): only
    // the (τ, D) whose curves overlap in at least half the points they overlap at D = 0
    // (which does not depend on τ) are considered.
    let least = spread(sets, 0.0, 0.0).1.div_ceil(2).max(1);
    let objective = |t: f64, d: f64| match spread(sets, t, d) {
        (s, n) if n >= least => s,
        _ => f64::INFINITY,
    };
    let mut best = ([0.0; 2], f64::INFINITY);
    for i in 0..=COLLAPSE_GRID {
        for j in 0..=COLLAPSE_GRID {
            let t = lo[0] + (hi[0] - lo[0]) * i as f64 / COLLAPSE_GRID as f64;
            let d = lo[1] + (hi[1] - lo[1]) * j as f64 / COLLAPSE_GRID as f64;
            let s = objective(t, d);
            if s < best.1 {
                best = ([t, d], s);
            }
        }
    }
    if !best.1.is_finite() {
        return None;
    }
    let step = (hi[0] - lo[0]) / COLLAPSE_GRID as f64;
    let (x, s) =
        super::alternatives::nelder_mead(|x| objective(x[0], x[1]), best.0, [step, step], lo, hi);
    Some((x, s, spread(sets, x[0], x[1]).1))
}

/// Fits the finite-size scaling form `P(S) = S^(-τ) f(S / L^D)` to the samples of several
/// system sizes: `sets` holds, per size `L` (m, > 0, all distinct), the samples of each
/// realization (avalanche sizes, say).
///
/// Each size's pooled samples are log-binned ([`log_binned`], `bins_per_decade`; bins of
/// fewer than 3 samples left out); on log axes a bin is the point `(ln S - D ln L,
/// ln P(S) + τ ln S)`. The spread of the curves is the mean, over every point of one curve
/// inside another's range, of the squared difference from the other's linear
/// interpolation, over the two Poisson variances `1/count`; `(τ, D)` minimise it: the best
/// point of a 41 x 41 grid over `τ, D ∈ [0, 4]`, refined by Nelder–Mead, among the pairs
/// whose curves overlap in at least half the points they overlap at `D = 0` (a small
/// overlap would give a small spread by chance). The intervals:
/// the whole fit repeated on [`PowerLawOptions::bootstrap`](super::PowerLawOptions)
/// resamples, each drawing each size's realizations with replacement (seeded by the
/// options' `seed`), percentile intervals at their `confidence`.
///
/// ```
/// use precursors::statistics::{fit_collapse, PowerLawOptions, Support};
/// // Per length L (m), two realizations of sizes spread as S^-2 between 1 and 1000 L.
/// let set = |l: f64| -> Vec<Vec<f64>> {
///     (0..2).map(|r| (0..2000).map(|i| {
///         let u = (i as f64 + 0.5 * r as f64 + 0.25) / 2000.0;
///         1.0 / (1.0 - u * (1.0 - 1.0 / (1000.0 * l)))
///     }).collect()).collect()
/// };
/// let sets = [(0.035, set(0.035)), (0.07, set(0.07)), (0.14, set(0.14))];
/// let options = PowerLawOptions::default().bootstrap(0);
/// let c = fit_collapse(&sets, Support::Continuous, 5, &options)?;
/// assert!(c.spread.is_finite() && c.overlaps > 0);
/// assert_eq!((c.tau_low, c.tau_high), (c.tau, c.tau)); // no resamples, no interval
/// // One length is no collapse.
/// assert!(fit_collapse(&sets[..1], Support::Continuous, 5, &options).is_err());
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
/// [`Error::TooFewSamples`] (`"finite-size collapse"`) for fewer than two sizes, or when
/// no `(τ, D)` makes two sizes' curves overlap; [`Error::InvalidParameter`] (`"length"`)
/// for a size that is not finite and positive or that repeats; the samples', the bins'
/// and the options' errors as [`log_binned`]'s and [`super::fit_power_law`]'s.
pub fn fit_collapse(
    sets: &[(f64, Vec<Vec<f64>>)],
    support: Support,
    bins_per_decade: usize,
    options: &super::PowerLawOptions,
) -> Result<Collapse> {
    check_fit_options(options)?;
    if sets.len() < 2 {
        return Err(Error::TooFewSamples {
            what: "finite-size collapse",
            count: sets.len(),
            needed: 2,
        });
    }
    for (k, (l, runs)) in sets.iter().enumerate() {
        if !(l.is_finite() && *l > 0.0) || sets[..k].iter().any(|(m, _)| m == l) {
            return Err(Error::InvalidParameter {
                name: "length",
                value: *l,
                reason: "the sizes of a collapse must be finite, positive and distinct",
            });
        }
        for run in runs {
            positive_sorted(run, support)?;
        }
    }
    let pooled = |pick: &dyn Fn(usize, usize) -> usize| -> Result<Vec<(f64, Vec<[f64; 3]>)>> {
        sets.iter()
            .enumerate()
            .map(|(k, (l, runs))| {
                let all: Vec<f64> = (0..runs.len())
                    .flat_map(|r| runs[pick(k, r)].iter().copied())
                    .collect();
                Ok((l.ln(), binned(&all, support, bins_per_decade)?))
            })
            .collect()
    };
    let data = pooled(&|_, r| r)?;
    let Some((best, spread, overlaps)) = best_collapse(&data) else {
        return Err(Error::TooFewSamples {
            what: "finite-size collapse",
            count: 0,
            needed: 2,
        });
    };
    let fits: Vec<Option<[f64; 2]>> = replicas(options.bootstrap, &|| {}, |i, _| {
        let mut rng = replica_rng(options.seed, COLLAPSE_STREAM, i);
        let picks: Vec<Vec<usize>> = sets
            .iter()
            .map(|(_, runs)| {
                (0..runs.len())
                    .map(|_| rng.random_range(0..runs.len()))
                    .collect()
            })
            .collect();
        let resample = pooled(&|k, r| picks[k][r]).ok()?;
        best_collapse(&resample).map(|(x, _, _)| x)
    });
    let mut taus: Vec<f64> = fits.iter().flatten().map(|x| x[0]).collect();
    let mut ds: Vec<f64> = fits.iter().flatten().map(|x| x[1]).collect();
    let (tau_low, tau_high) =
        percentile_interval(&mut taus, options.confidence).unwrap_or((best[0], best[0]));
    let (d_low, d_high) =
        percentile_interval(&mut ds, options.confidence).unwrap_or((best[1], best[1]));
    Ok(Collapse {
        tau: best[0],
        tau_low,
        tau_high,
        d: best[1],
        d_low,
        d_high,
        spread,
        overlaps,
    })
}

/// How the cut-off scale of the size distribution grows with the system's size
/// ([`fit_cutoff_scaling`]): `s_c ≈ c L^β`.
///
/// ```
/// use precursors::statistics::{compare_alternatives, fit_cutoff_scaling, PowerLawOptions, Support};
/// // Sizes spread as S^-1.5 e^(-S/s_c), s_c = 2000 L^1.5 (37 and 296 ruptures).
/// let draw = |s_c: f64| -> Vec<f64> {
///     let mut out = Vec::new();
///     for i in 1..3000u32 {
///         let u = ((i as f64) * 0.618034).fract();
///         let x = (1.0 - u).powf(-1.0 / 0.5); // Pareto with τ = 1.5
///         if ((i as f64) * 0.414214).fract() < (-x / s_c).exp() { out.push(x.floor()); }
///     }
///     out
/// };
/// // No bootstrap: the cut-offs' intervals are degenerate, the lengths weigh alike.
/// let options = PowerLawOptions::default().bootstrap(0).goodness_samples(0);
/// let lengths = [0.07f64, 0.28];
/// let fits: Vec<_> = lengths.iter()
///     .map(|&l| compare_alternatives(&draw(2000.0 * l * l.sqrt()), Support::Discrete, &options)
///         .map(|c| c.cutoff))
///     .collect::<Result<_, _>>()?;
/// let s = fit_cutoff_scaling(&lengths, &fits, 0.95)?;
/// // Two lengths: the line through both cut-offs, slope ln(s_c2/s_c1) / ln 4.
/// let slope = (fits[1].cutoff / fits[0].cutoff).ln() / 4f64.ln();
/// assert_eq!(s.lengths, 2);
/// assert!((s.exponent - slope).abs() < 1e-9, "{s:?}");
/// assert_eq!((s.exponent_low, s.exponent_high), (s.exponent, s.exponent));
/// assert!((s.prefactor * 0.07f64.powf(s.exponent) / fits[0].cutoff - 1.0).abs() < 1e-9);
/// assert!(s.chi2_per_dof.is_none()); // no degree of freedom left
/// # Ok::<(), precursors::Error>(())
/// ```
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct CutoffScaling {
    /// The lengths fitted: those whose cut-off and interval are finite and positive.
    pub lengths: usize,
    /// The exponent `β` (dimensionless; `L` in metres): the weighted least-squares slope of
    /// `ln s_c` on `ln L`. The collapse's `D` estimates the same exponent.
    pub exponent: f64,
    /// Lower end of its interval `β - z σ_β` at the confidence given (see
    /// [`fit_cutoff_scaling`] for `σ_β`); equal to `exponent` with two lengths whose
    /// intervals are degenerate.
    pub exponent_low: f64,
    /// Upper end `β + z σ_β`.
    pub exponent_high: f64,
    /// The prefactor `c` (the samples' unit over metres to the `β`).
    pub prefactor: f64,
    /// `χ²` per degree of freedom of the weighted fit (dimensionless; about 1 when the
    /// lengths' intervals account for their scatter); `None` with two lengths.
    pub chi2_per_dof: Option<f64>,
}

/// Fits `s_c ≈ c L^β` to the cut-off scales of one size observable at several system
/// sizes `L` (m): `fits[k]` is the cut-off law fitted at `lengths[k]` (from
/// [`compare_alternatives`](super::compare_alternatives)), with its percentile bootstrap
/// interval `[cutoff_low, cutoff_high]` at level `confidence`.
///
/// Each interval is read as a normal error on `ln s_c`, `σ_k = (ln high - ln low)/(2z)`
/// with `z` the normal quantile of `confidence` (1.96 at 0.95); `β` and `ln c` are the
/// weighted least-squares line through `(ln L, ln s_c)` with weights `1/σ_k²`, and
/// `σ_β = (Σ w (ln L - mean)²)^(-1/2)`, multiplied by `√(χ²/dof)` when that exceeds 1
/// (the intervals then understate the scatter). Lengths whose cut-off or interval is not
/// finite and positive (a pure power law as likely as any cut-off, `λ = 0`) are left out;
/// a degenerate interval (`low = high`, no resamples) gives every length weight 1.
///
/// ```
/// use precursors::statistics::{compare_alternatives, fit_cutoff_scaling, PowerLawOptions, Support};
/// // Sizes spread as S^-1.5 e^(-S/s_c) with s_c = 2000 L^1.5: 37, 105, 296 ruptures.
/// let draw = |s_c: f64| -> Vec<f64> {
///     let (mut x, mut out) = (1.0f64, Vec::new());
///     for i in 1..3000u32 {
///         let u = ((i as f64) * 0.618034).fract();
///         x = (1.0 - u).powf(-1.0 / 0.5); // Pareto with τ = 1.5
///         if ((i as f64) * 0.414214).fract() < (-x / s_c).exp() { out.push(x.floor()); }
///     }
///     out
/// };
/// let options = PowerLawOptions::default().bootstrap(20).goodness_samples(0);
/// let lengths = [0.07f64, 0.14, 0.28];
/// let fits: Vec<_> = lengths.iter()
///     .map(|&l| compare_alternatives(&draw(2000.0 * l * l.sqrt()), Support::Discrete, &options)
///         .map(|c| c.cutoff))
///     .collect::<Result<_, _>>()?;
/// let s = fit_cutoff_scaling(&lengths, &fits, 0.95)?;
/// assert!(s.lengths <= 3 && s.exponent_low <= s.exponent && s.exponent <= s.exponent_high);
/// assert!((s.exponent - 1.5).abs() < 0.05, "{s:?}");
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
/// [`Error::InvalidCount`] (`"fits"`) when `lengths` and `fits` differ in length;
/// [`Error::InvalidParameter`] (`"length"`) for a length that is not finite and positive
/// or that repeats, (`"confidence"`) for a level not strictly between 0 and 1;
/// [`Error::TooFewSamples`] (`"cut-off scaling"`) for fewer than two lengths with a
/// finite cut-off.
pub fn fit_cutoff_scaling(
    lengths: &[f64],
    fits: &[super::CutoffFit],
    confidence: f64,
) -> Result<CutoffScaling> {
    if lengths.len() != fits.len() {
        return Err(Error::InvalidCount {
            name: "fits",
            value: fits.len() as u64,
            reason: "one cut-off fit per length",
        });
    }
    for (k, l) in lengths.iter().enumerate() {
        if !(l.is_finite() && *l > 0.0) || lengths[..k].contains(l) {
            return Err(Error::InvalidParameter {
                name: "length",
                value: *l,
                reason: "the sizes of a cut-off scaling must be finite, positive and distinct",
            });
        }
    }
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(Error::InvalidParameter {
            name: "confidence",
            value: confidence,
            reason: "a confidence level lies strictly between 0 and 1",
        });
    }
    let z = normal_quantile(confidence);
    let usable = |v: f64| v.is_finite() && v > 0.0;
    // (ln L, ln s_c, σ of ln s_c)
    let points: Vec<(f64, f64, f64)> = lengths
        .iter()
        .zip(fits)
        .filter(|(_, f)| usable(f.cutoff) && usable(f.cutoff_low) && usable(f.cutoff_high))
        .map(|(l, f)| {
            let sigma = (f.cutoff_high.ln() - f.cutoff_low.ln()) / (2.0 * z);
            (l.ln(), f.cutoff.ln(), sigma)
        })
        .collect();
    if points.len() < 2 {
        return Err(Error::TooFewSamples {
            what: "cut-off scaling",
            count: points.len(),
            needed: 2,
        });
    }
    let degenerate = points.iter().any(|p| p.2 <= 0.0);
    let w: Vec<f64> = points
        .iter()
        .map(|p| if degenerate { 1.0 } else { p.2.powi(-2) })
        .collect();
    let sw: f64 = w.iter().sum();
    let mx = points.iter().zip(&w).map(|(p, w)| w * p.0).sum::<f64>() / sw;
    let my = points.iter().zip(&w).map(|(p, w)| w * p.1).sum::<f64>() / sw;
    let sxx: f64 = points
        .iter()
        .zip(&w)
        .map(|(p, w)| w * (p.0 - mx).powi(2))
        .sum();
    let sxy: f64 = points
        .iter()
        .zip(&w)
        .map(|(p, w)| w * (p.0 - mx) * (p.1 - my))
        .sum();
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let dof = points.len() - 2;
    let chi2: f64 = points
        .iter()
        .zip(&w)
        .map(|(p, w)| w * (p.1 - intercept - slope * p.0).powi(2))
        .sum();
    let chi2_per_dof = (dof > 0).then(|| chi2 / dof as f64);
    let half = if degenerate && dof == 0 {
        0.0
    } else {
        let birge = chi2_per_dof.map_or(1.0, |c| if degenerate { c } else { c.max(1.0) });
        z * (birge / sxx).sqrt()
    };
    Ok(CutoffScaling {
        lengths: points.len(),
        exponent: slope,
        exponent_low: slope - half,
        exponent_high: slope + half,
        prefactor: intercept.exp(),
        chi2_per_dof,
    })
}

#[cfg(test)]
mod tests {
    use super::super::{fit_power_law, PowerLawOptions};
    use super::*;
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal, Pareto};

    fn rng(seed: u64) -> Xoshiro256PlusPlus {
        Xoshiro256PlusPlus::seed_from_u64(seed)
    }

    /// Samples of `x^(-τ) e^(-x/s)`, `x ≥ 1`: a Pareto draw (rand_distr's sampler) kept with
    /// probability `e^(-x/s)`.
    fn cutoff_law(tau: f64, s: f64, n: usize, r: &mut Xoshiro256PlusPlus) -> Vec<f64> {
        let pareto = Pareto::new(1.0, tau - 1.0).unwrap();
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            let x: f64 = pareto.sample(r);
            if r.random::<f64>() < (-x / s).exp() {
                out.push(x);
            }
        }
        out
    }

    #[test]
    fn an_interval_excludes_the_classes_away_from_the_exponent_drawn() {
        // Pure power laws of known exponent (rand_distr's Pareto), fitted with their
        // bootstrap interval: the classes at other exponents are excluded, the one drawn
        // is not.
        let options = PowerLawOptions::default()
            .bootstrap(100)
            .goodness_samples(0);
        for (alpha, kept) in [
            (2.5, vec!["fibre bundle far from failure 5/2"]),
            (
                1.5,
                vec!["mean-field depinning 3/2", "fibre bundle near failure 3/2"],
            ),
        ] {
            let law = Pareto::new(1.0, alpha - 1.0).unwrap();
            let mut r = rng(11);
            let xs: Vec<f64> = (0..4000).map(|_| law.sample(&mut r)).collect();
            let fit = fit_power_law(&xs, Support::Continuous, &options).unwrap();
            assert!(fit.alpha_low <= alpha && alpha <= fit.alpha_high, "{fit:?}");
            let excluded = classes_excluded(fit.alpha_low, fit.alpha_high).unwrap();
            let names: Vec<_> = excluded.iter().map(|c| c.name).collect();
            assert_eq!(
                names.len(),
                UNIVERSALITY_CLASSES.len() - kept.len(),
                "{names:?}"
            );
            assert!(kept.iter().all(|k| !names.contains(k)), "{names:?}");
        }
        // Ends are included; a reversed or NaN interval is refused.
        assert!(classes_excluded(1.28, 1.5).unwrap().len() == 1);
        for (low, high) in [(2.0, 1.0), (f64::NAN, 1.0), (1.0, f64::NAN)] {
            assert!(matches!(
                classes_excluded(low, high),
                Err(Error::InvalidParameter {
                    name: "interval",
                    ..
                })
            ));
        }
    }

    #[test]
    fn binned_means_are_the_means_of_their_bins() {
        // Against a brute-force pass over the bins [10^(k/4), 10^((k+1)/4)).
        let mut r = rng(3);
        let x: Vec<f64> = (0..3000)
            .map(|_| 10f64.powf(-3.0 * r.random::<f64>()))
            .collect();
        let y: Vec<f64> = x
            .iter()
            .map(|x| 1.0 / x.sqrt() + r.random::<f64>())
            .collect();
        let bins = binned_means(&x, &y, 4, 0.9).unwrap();
        let z = 1.644_853_626_951_472_2; // the normal quantile at 0.95 (scipy.stats.norm.ppf)
        let mut seen = 0;
        for k in -12..0 {
            let (lo, hi) = (10f64.powf(k as f64 / 4.0), 10f64.powf((k + 1) as f64 / 4.0));
            let inside: Vec<f64> = x
                .iter()
                .zip(&y)
                .filter(|(x, _)| **x >= lo && **x < hi)
                .map(|(_, y)| *y)
                .collect();
            if inside.is_empty() {
                continue;
            }
            let b = bins
                .iter()
                .find(|b| (b.low / lo - 1.0).abs() < 1e-12)
                .unwrap();
            let n = inside.len() as f64;
            let mean = inside.iter().sum::<f64>() / n;
            let sd = (inside.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            assert_eq!(b.count, inside.len());
            assert!((b.mean - mean).abs() < 1e-12 * mean);
            assert!((b.mean_high.unwrap() - mean - z * sd / n.sqrt()).abs() < 1e-9);
            assert!((b.high / hi - 1.0).abs() < 1e-12);
            seen += inside.len();
        }
        assert_eq!(seen, x.len());
        // Bad input.
        assert!(matches!(
            binned_means(&x, &y[1..], 4, 0.9),
            Err(Error::InvalidCount { name: "y", .. })
        ));
        assert!(binned_means(&[f64::NAN], &[1.0], 4, 0.9).is_err());
        assert!(binned_means(&x, &y, 0, 0.9).is_err());
        assert!(binned_means(&x, &y, 4, 1.0).is_err());
    }

    #[test]
    fn a_scaling_fit_recovers_its_exponent_within_its_interval() {
        // y = 0.2 x^1.8 times log-normal noise, x log-uniform over three decades: the
        // interval covers 1.8 in at least 17 of 20 sets at 95 %.
        let noise = Normal::new(0.0, 0.5).unwrap();
        let options = PowerLawOptions::default().bootstrap(200);
        let mut covered = 0;
        for seed in 0..20 {
            let mut r = rng(seed);
            let x: Vec<f64> = (0..300)
                .map(|_| 10f64.powf(3.0 * r.random::<f64>()).ceil())
                .collect();
            let y: Vec<f64> = x
                .iter()
                .map(|x| {
                    let e: f64 = noise.sample(&mut r);
                    0.2 * x.powf(1.8) * e.exp()
                })
                .collect();
            let fit = fit_scaling(&x, &y, &options.clone().seed(seed)).unwrap();
            assert_eq!(fit.pairs, 300);
            assert!((fit.exponent - 1.8).abs() < 0.1, "{fit:?}");
            covered += usize::from(fit.exponent_low <= 1.8 && 1.8 <= fit.exponent_high);
        }
        assert!(covered >= 17, "{covered} of 20");
        assert!(matches!(
            fit_scaling(&[1.0, 2.0], &[1.0, 2.0], &PowerLawOptions::default()),
            Err(Error::TooFewSamples { .. })
        ));
        assert!(matches!(
            fit_scaling(
                &[2.0; 4],
                &[1.0, 2.0, 3.0, 4.0],
                &PowerLawOptions::default()
            ),
            Err(Error::InvalidParameter {
                name: "samples",
                ..
            })
        ));
    }

    #[test]
    fn a_collapse_recovers_tau_and_d_of_a_known_scaling_form() {
        // P(S) ∝ S^-τ e^(-S/L^D) with τ = 1.5, D = 1.5 at L = 100 to 800 (cut-offs 1e3 to
        // 2.3e4, so the normalisation over S ≥ 1 changes by a few per cent only), 8
        // realizations of 1500 samples each.
        let (tau, d) = (1.5, 1.5);
        let mut r = rng(5);
        let sets: Vec<(f64, Vec<Vec<f64>>)> = [100.0, 200.0, 400.0, 800.0f64]
            .iter()
            .map(|&l| {
                let runs = (0..8)
                    .map(|_| cutoff_law(tau, l.powf(d), 1500, &mut r))
                    .collect();
                (l, runs)
            })
            .collect();
        let options = PowerLawOptions::default().bootstrap(40);
        let c = fit_collapse(&sets, Support::Continuous, 5, &options).unwrap();
        // The normalisation over S ≥ 1, 2 - 3.545 s^(-1/2), differs by 5 % from the
        // shortest to the longest: a bias of about 0.01 in τ, beyond its statistical
        // interval (0.015 wide), which a finite study shares. So τ within 0.03, and D
        // inside its interval.
        assert!((c.tau - tau).abs() < 0.03, "{c:?}");
        assert!(c.d_low <= d && d <= c.d_high, "{c:?}");
        assert!((c.d - d).abs() < 0.3, "{c:?}");
        assert!(
            c.tau_high - c.tau_low < 0.3 && c.d_high - c.d_low < 1.0,
            "{c:?}"
        );
        // Curves at the wrong (τ, D) spread more.
        let data: Vec<_> = sets
            .iter()
            .map(|(l, runs)| {
                (
                    l.ln(),
                    binned(&runs.concat(), Support::Continuous, 5).unwrap(),
                )
            })
            .collect();
        assert!(spread(&data, tau, d).0 < 0.5 * spread(&data, tau, 0.5).0);
        assert!(spread(&data, tau, d).0 < 0.5 * spread(&data, 2.0, d).0);
        // Bad input.
        assert!(matches!(
            fit_collapse(&sets[..1], Support::Continuous, 5, &options),
            Err(Error::TooFewSamples { .. })
        ));
        let mut twice = sets[..2].to_vec();
        twice[1].0 = twice[0].0;
        assert!(matches!(
            fit_collapse(&twice, Support::Continuous, 5, &options),
            Err(Error::InvalidParameter { name: "length", .. })
        ));
    }

    /// A cut-off law fit with only the fields [`fit_cutoff_scaling`] reads set.
    fn cutoff_fit(cutoff: f64, low: f64, high: f64) -> super::super::CutoffFit {
        super::super::CutoffFit {
            alpha: 1.5,
            lambda: 1.0 / cutoff,
            cutoff,
            alpha_low: 1.5,
            alpha_high: 1.5,
            cutoff_low: low,
            cutoff_high: high,
            log_likelihood: 0.0,
        }
    }

    #[test]
    fn the_cutoff_scaling_is_the_weighted_line_through_the_lengths() {
        // s_c = 3 (L/0.035)^1.2 e^noise with log-normal intervals of σ 0.3, 0.2, 0.25,
        // 0.4. Reference: the normal equations solved by Cramer's rule in plain Python
        // (statistics.NormalDist for z), not this module's centred sums.
        let lengths = [0.035, 0.07, 0.14, 0.28];
        let fits = [
            cutoff_fit(3.315512754226943, 1.8415785166101493, 5.96913176619588),
            cutoff_fit(5.932163019913744, 4.008415830124776, 8.7791685259702),
            cutoff_fit(16.64592633642069, 10.197825648772747, 27.17117090846614),
            cutoff_fit(44.431209478196706, 20.2865183527516, 97.31252753026651),
        ];
        let s = fit_cutoff_scaling(&lengths, &fits, 0.95).unwrap();
        let close = |a: f64, b: f64| (a - b).abs() < 1e-9 * b.abs().max(1.0);
        assert_eq!(s.lengths, 4);
        assert!(close(s.exponent, 1.2726834443774477), "{s:?}");
        assert!(close(s.prefactor, 198.28070104165008), "{s:?}");
        assert!(close(s.chi2_per_dof.unwrap(), 0.4192761156186608), "{s:?}");
        // χ²/dof < 1: the intervals alone.
        assert!(close(s.exponent_low, 0.8599238293658017), "{s:?}");
        assert!(close(s.exponent_high, 1.685443059389094), "{s:?}");
        // The same cut-offs with σ = 0.05 each: χ²/dof = 10.5 widens the interval.
        let z: f64 = 1.959963984540054;
        let tight: Vec<_> = fits
            .iter()
            .map(|f| {
                cutoff_fit(
                    f.cutoff,
                    f.cutoff * (-0.05 * z).exp(),
                    f.cutoff * (0.05 * z).exp(),
                )
            })
            .collect();
        let t = fit_cutoff_scaling(&lengths, &tight, 0.95).unwrap();
        assert!(close(t.exponent, 1.2721347520444508), "{t:?}");
        assert!((t.chi2_per_dof.unwrap() - 10.5).abs() < 1e-6, "{t:?}");
        assert!((t.exponent_low - 1.0672534706549188).abs() < 1e-6, "{t:?}");
        assert!((t.exponent_high - 1.4770160334339828).abs() < 1e-6, "{t:?}");
        // A length without a cut-off (λ = 0) is left out; one left is too few.
        let mut open = fits.clone();
        open[1] = cutoff_fit(f64::INFINITY, 10.0, f64::INFINITY);
        assert_eq!(
            fit_cutoff_scaling(&lengths, &open, 0.95).unwrap().lengths,
            3
        );
        assert!(matches!(
            fit_cutoff_scaling(&lengths[..2], &open[..2], 0.95),
            Err(Error::TooFewSamples { .. })
        ));
        assert!(matches!(
            fit_cutoff_scaling(&[0.1, 0.1], &fits[..2], 0.95),
            Err(Error::InvalidParameter { name: "length", .. })
        ));
        assert!(matches!(
            fit_cutoff_scaling(&lengths, &fits[..3], 0.95),
            Err(Error::InvalidCount { name: "fits", .. })
        ));
    }
}
