//! Statistics of avalanches: maximum-likelihood power-law fits in the manner of A. Clauset,
//! C. R. Shalizi and M. E. J. Newman, "Power-law distributions in empirical data", SIAM
//! Review 51, 661 (2009), and log-binned histograms.
//!
//! * [`fit_power_law`]: the exponent `α` of `p(x) ∝ x^(-α)` for `x ≥ x_min` by maximum
//!   likelihood, `x_min` by the smallest Kolmogorov–Smirnov distance, a bootstrap interval
//!   of both, and the goodness-of-fit p-value of Clauset et al. section 4.1. Samples are
//!   [`Support::Discrete`] (integer counts: the ruptures of an avalanche) or
//!   [`Support::Continuous`] (reals: a force drop in N, a stress drop in Pa).
//! * [`compare_alternatives`]: the same fit, and on its tail `x ≥ x_min` the
//!   alternatives of Clauset et al. section 5 fitted by maximum likelihood (the
//!   exponential, the log-normal and the power law with exponential cut-off, with a
//!   bootstrap interval of the cut-off law), the likelihood-ratio tests between them
//!   ([`LikelihoodRatio`]) and a verdict in words ([`Comparison::verdict`]).
//! * [`log_binned`]: a histogram with logarithmically spaced bins, as density estimates
//!   `P(x)` for log-log plots.
//!
//! Both drop the samples that are zero or negative before anything else (a power law
//! holds no such value: an avalanche of no rupture, a zero stress drop), and refuse NaN
//! and infinite ones. Results depend only on the multiset of samples, never on their
//! order, and are reproducible bit for bit from [`PowerLawOptions::seed`].
//!
//! ```
//! use precursors::statistics::{fit_power_law, PowerLawOptions, Support};
//! // Force drops (N) of a run, in any order; the zero drop is left out of the fit.
//! let drops = [0.0, 1.3e-3, 2.0e-3, 4.1e-3, 1.1e-3, 9.0e-3, 1.6e-3, 3.0e-2, 1.2e-3, 2.6e-3,
//!              1.0e-3, 5.5e-3, 1.4e-3];
//! let options = PowerLawOptions::default().bootstrap(20).goodness_samples(20).min_tail(5);
//! let fit = fit_power_law(&drops, Support::Continuous, &options)?;
//! assert_eq!(fit.samples, 12);
//! assert!(fit.alpha > 1.0 && fit.x_min >= 1.0e-3);
//! # Ok::<(), precursors::Error>(())
//! ```

use crate::error::{Error, Result};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

mod alternatives;
mod scaling;
mod special;

#[cfg(feature = "plot")]
pub(crate) use alternatives::cutoff_density;
pub use alternatives::LikelihoodRatio;
pub use scaling::{
    binned_means, classes_excluded, fit_collapse, fit_cutoff_scaling, fit_scaling, BinnedMean,
    Collapse, CutoffScaling, ScalingFit, UniversalityClass, UNIVERSALITY_CLASSES,
};

/// Whether samples are integers (counts: the ruptures of an avalanche) or reals (a force
/// drop in N, a stress drop in Pa).
///
/// The two are fitted by different laws: a discrete power law `P(X = k) = k^(-α) /
/// ζ(α, x_min)` over the integers `k ≥ x_min` (`ζ` the Hurwitz zeta function), or a
/// continuous density `p(x) = (α - 1) / x_min · (x / x_min)^(-α)` over `x ≥ x_min`.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Support {
    /// Integer samples (`x.fract() == 0`), e.g. the number of ruptures of an avalanche.
    Discrete,
    /// Real samples, e.g. force drops (N) or stress drops (Pa).
    Continuous,
}

/// Options of [`fit_power_law`].
///
/// The setters never fail: [`fit_power_law`] checks the values. The costs add up as
/// `(1 + bootstrap + goodness_samples)` complete fits (the `x_min` search included).
///
/// ```
/// use precursors::statistics::PowerLawOptions;
/// let options = PowerLawOptions::default().confidence(0.9).bootstrap(100).seed(7);
/// assert_eq!((options.confidence, options.bootstrap, options.seed), (0.9, 100, 7));
/// assert_eq!((options.goodness_samples, options.min_tail), (200, 10));
/// ```
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PowerLawOptions {
    /// Level of the bootstrap intervals of `α` and `x_min` (dimensionless, strictly
    /// between 0 and 1; default 0.95).
    pub confidence: f64,
    /// Bootstrap resamples (default 200). 0: no interval, the bounds equal the estimates.
    pub bootstrap: usize,
    /// Synthetic data sets of the goodness-of-fit test (default 200). 0: no test,
    /// [`PowerLawFit::p_value`] is `None`. The p-value is resolved to
    /// `1 / goodness_samples`; Clauset et al. suggest 2500 for a precision of 0.01.
    pub goodness_samples: usize,
    /// The fewest samples at or above `x_min` a candidate `x_min` may leave (at least 2;
    /// default 10).
    pub min_tail: usize,
    /// Seed of the bootstrap and of the synthetic data sets (default 0).
    pub seed: u64,
}

impl Default for PowerLawOptions {
    fn default() -> Self {
        Self {
            confidence: 0.95,
            bootstrap: 200,
            goodness_samples: 200,
            min_tail: 10,
            seed: 0,
        }
    }
}

impl PowerLawOptions {
    /// Sets [`PowerLawOptions::confidence`], the level of the bootstrap intervals (checked
    /// by [`fit_power_law`]: strictly between 0 and 1).
    #[must_use]
    pub fn confidence(mut self, v: f64) -> Self {
        self.confidence = v;
        self
    }

    /// Sets [`PowerLawOptions::bootstrap`], the number of bootstrap resamples.
    #[must_use]
    pub fn bootstrap(mut self, n: usize) -> Self {
        self.bootstrap = n;
        self
    }

    /// Sets [`PowerLawOptions::goodness_samples`], the number of synthetic data sets of the
    /// goodness-of-fit test.
    #[must_use]
    pub fn goodness_samples(mut self, n: usize) -> Self {
        self.goodness_samples = n;
        self
    }

    /// Sets [`PowerLawOptions::min_tail`] (checked by [`fit_power_law`]: at least 2).
    #[must_use]
    pub fn min_tail(mut self, n: usize) -> Self {
        self.min_tail = n;
        self
    }

    /// Sets [`PowerLawOptions::seed`].
    #[must_use]
    pub fn seed(mut self, s: u64) -> Self {
        self.seed = s;
        self
    }
}

/// The fit of `p(x) ∝ x^(-α)` for `x ≥ x_min` ([`fit_power_law`]). Values of `x` are in
/// the samples' unit (N for force drops, a count for avalanche sizes).
///
/// ```
/// use precursors::statistics::{fit_power_law, PowerLawOptions, Support};
/// // Reals spread as x^-2.5 above 1: the quantiles (1 - u)^(-1/1.5).
/// let x: Vec<f64> = (0..2000).map(|i| (1.0 - (i as f64 + 0.5) / 2000.0).powf(-1.0 / 1.5)).collect();
/// let fit = fit_power_law(&x, Support::Continuous, &PowerLawOptions::default().bootstrap(0).goodness_samples(0))?;
/// assert!(fit.tail <= fit.samples && fit.x_min >= 1.0);
/// assert!((fit.alpha - 2.5).abs() < 0.1, "{}", fit.alpha);
/// # Ok::<(), precursors::Error>(())
/// ```
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PowerLawFit {
    /// Whether the samples were fitted as integers or reals.
    pub support: Support,
    /// Samples fitted: the positive ones (zero and negative samples are dropped).
    pub samples: usize,
    /// Samples at or above `x_min`, the tail the exponent is fitted to.
    pub tail: usize,
    /// Lower bound of the power-law behaviour (samples' unit): the candidate of smallest
    /// Kolmogorov–Smirnov distance.
    pub x_min: f64,
    /// Maximum-likelihood exponent `α` (dimensionless, > 1). The discrete exponent is
    /// searched in `(1, 20]`, so 20 means "20 or steeper".
    pub alpha: f64,
    /// Asymptotic standard error of `α` at the chosen `x_min`: `(α - 1) / √tail` for
    /// continuous samples (Clauset et al. eq. 3.2), `1 / √(tail · Var(ln X))` for discrete
    /// ones (the discrete analogue, from the Fisher information: `Var(ln X) = ζ''/ζ -
    /// (ζ'/ζ)²` under the fitted law, derivatives in `α`).
    /// It does not include the uncertainty of `x_min`; the bootstrap interval does.
    pub alpha_std_error: f64,
    /// Lower end of the percentile bootstrap interval of `α` at the options' `confidence`;
    /// each resample refits `x_min` and `α` (the whole procedure, Clauset et al. sec. 3.4).
    /// Equal to `alpha` when `bootstrap` is 0. A percentile interval need not be centred
    /// on the estimate.
    pub alpha_low: f64,
    /// Upper end of the bootstrap interval of `α` (see [`PowerLawFit::alpha_low`]).
    pub alpha_high: f64,
    /// Lower end of the bootstrap interval of `x_min` (samples' unit), from the same
    /// resamples as that of `α`.
    pub x_min_low: f64,
    /// Upper end of the bootstrap interval of `x_min` (samples' unit).
    pub x_min_high: f64,
    /// Kolmogorov–Smirnov distance (dimensionless, in `[0, 1]`) between the tail's
    /// empirical distribution function and the fitted law at `x_min`.
    pub ks_distance: f64,
    /// Goodness of fit (Clauset et al. sec. 4.1): the fraction of synthetic data sets,
    /// drawn from the fitted law above `x_min` and from the data below it, whose own fit
    /// (`x_min` search included) has a Kolmogorov–Smirnov distance `≥ ks_distance`. Small
    /// values (Clauset et al.: `≤ 0.1`) rule the power law out. `None` when
    /// `goodness_samples` is 0.
    pub p_value: Option<f64>,
}

impl PowerLawFit {
    /// The fitted law as a density of all the samples (per unit of `x`, the unit of
    /// [`LogBin::density`], so the two plot on one chart): `(tail/samples) · p(x)` with
    /// `p(x) = (α-1)/x_min · (x/x_min)^(-α)` for reals and `p(x) = x^(-α) / ζ(α, x_min)`
    /// for counts (Hurwitz ζ); 0 below `x_min`.
    ///
    /// ```
    /// use precursors::statistics::{fit_power_law, PowerLawOptions, Support};
    /// let samples: Vec<f64> = (1..=200).map(|k| 200.0 / k as f64).collect();
    /// let fit = fit_power_law(&samples, Support::Continuous, &PowerLawOptions::default())?;
    /// assert_eq!(fit.density(0.5 * fit.x_min), 0.0);
    /// let at = fit.density(fit.x_min);
    /// let share = fit.tail as f64 / fit.samples as f64;
    /// assert!((at - share * (fit.alpha - 1.0) / fit.x_min).abs() <= 1e-12 * at);
    /// # Ok::<(), precursors::Error>(())
    /// ```
    pub fn density(&self, x: f64) -> f64 {
        if x.is_nan() || x < self.x_min || self.samples == 0 {
            return 0.0;
        }
        let share = self.tail as f64 / self.samples as f64;
        match self.support {
            Support::Discrete => share * x.powf(-self.alpha) / hurwitz_zeta(self.alpha, self.x_min),
            _ => share * (self.alpha - 1.0) / self.x_min * (x / self.x_min).powf(-self.alpha),
        }
    }
}

/// The power law with exponential cut-off `p(x) ∝ x^(-α) e^(-λx)`, `x ≥ x_min`, fitted by
/// maximum likelihood on the power law's tail ([`compare_alternatives`]).
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CutoffFit {
    /// Exponent `α` (dimensionless, searched in `[0, 20]`; `α = 0` is the exponential).
    pub alpha: f64,
    /// Rate `λ` of the cut-off (inverse unit of the samples, ≥ 0). 0 when the pure power
    /// law (`λ = 0`, the boundary) is at least as likely as any cut-off.
    pub lambda: f64,
    /// The cut-off scale `1/λ` (samples' unit); `+∞` when `λ = 0`.
    pub cutoff: f64,
    /// Lower end of the percentile bootstrap interval of `α` at the options'
    /// `confidence`, from the power law's resamples (each refits `x_min`, then the cut-off
    /// law on its own tail). Equal to `alpha` when `bootstrap` is 0.
    pub alpha_low: f64,
    /// Upper end of the bootstrap interval of `α`.
    pub alpha_high: f64,
    /// Lower end of the bootstrap interval of the cut-off scale `1/λ` (samples' unit).
    pub cutoff_low: f64,
    /// Upper end of the bootstrap interval of `1/λ` (samples' unit; `+∞` when a
    /// resample's `λ` is 0 that far up).
    pub cutoff_high: f64,
    /// Log-likelihood of the tail under the fitted law (natural log; for reals, of the
    /// density in the samples' inverse unit).
    pub log_likelihood: f64,
}

/// The exponential `p(x) = λ e^(-λ(x - x_min))` (integers: `P(k) = (1 - e^(-λ))
/// e^(-λ(k - x_min))`) fitted by maximum likelihood on the power law's tail
/// ([`compare_alternatives`]).
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ExponentialFit {
    /// Rate `λ` (inverse unit of the samples).
    pub lambda: f64,
    /// Log-likelihood of the tail (natural log).
    pub log_likelihood: f64,
}

/// The log-normal fitted by maximum likelihood on the power law's tail
/// ([`compare_alternatives`]): for reals the density `φ((ln x - μ)/σ) / (x σ)`
/// normalised over `x ≥ x_min`; for integers the continuous law's mass in `[k - 1/2, k +
/// 1/2)` normalised over `x ≥ x_min - 1/2` (the rounding discretisation).
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct LognormalFit {
    /// `μ`, the mean of `ln x` before truncation (`x` in the samples' unit; may lie far
    /// below `ln x_min`); `-∞` in the limit `σ = ∞`.
    pub mu: f64,
    /// `σ`, the standard deviation of `ln x` before truncation (dimensionless, > 0). As
    /// `σ → ∞` with `(ln x_min - μ)/σ²` fixed the law tends to a power law (for integers,
    /// its rounding); that limit is part of the fit: `σ = ∞` where it is the most likely.
    pub sigma: f64,
    /// Log-likelihood of the tail (natural log).
    pub log_likelihood: f64,
}

/// The power law and its alternatives on one tail ([`compare_alternatives`]).
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Comparison {
    /// The power-law fit, the same as [`fit_power_law`]'s for the same arguments.
    pub power_law: PowerLawFit,
    /// Log-likelihood of the tail under the power law (natural log).
    pub power_law_log_likelihood: f64,
    /// The power law with exponential cut-off.
    pub cutoff: CutoffFit,
    /// The exponential.
    pub exponential: ExponentialFit,
    /// The log-normal.
    pub lognormal: LognormalFit,
    /// Power law against exponential (non-nested, Vuong); `R > 0` favours the power law.
    pub vs_exponential: LikelihoodRatio,
    /// Power law against log-normal (non-nested, Vuong).
    pub vs_lognormal: LikelihoodRatio,
    /// Power law against the cut-off law (nested, Wilks); `R ≤ 0`.
    pub vs_cutoff: LikelihoodRatio,
    /// Cut-off law against log-normal (non-nested, Vuong); `R > 0` favours the cut-off law.
    pub cutoff_vs_lognormal: LikelihoodRatio,
}

/// A likelihood ratio's sign means something only below this p-value (Clauset et al.).
pub const LR_SIGNIFICANCE: f64 = 0.1;

impl Comparison {
    /// The tests in words, `; `-separated: the goodness-of-fit test of the pure power law
    /// (`rejected` at `p ≤ 0.1`, section 4.1), then each likelihood-ratio test in the
    /// order power law against exponential, log-normal and cut-off law, and cut-off law
    /// against log-normal: `A preferred over B (p = …)` when `p <` [`LR_SIGNIFICANCE`],
    /// else `A and B not distinguished (p = …)`. p-values to two decimals.
    ///
    /// ```
    /// use precursors::statistics::{compare_alternatives, PowerLawOptions, Support};
    /// // Exponential samples (mean 1): the power law loses to the exponential.
    /// let xs: Vec<f64> = (1..=400).map(|i| -(1.0 - (i as f64 - 0.5) / 400.0).ln()).collect();
    /// let options = PowerLawOptions::default().bootstrap(0).goodness_samples(0).min_tail(200);
    /// let c = compare_alternatives(&xs, Support::Continuous, &options)?;
    /// assert!(c.vs_exponential.log_ratio < 0.0 && c.vs_exponential.p_value < 0.1);
    /// assert!(c.verdict().contains("exponential preferred over power law"), "{}", c.verdict());
    /// # Ok::<(), precursors::Error>(())
    /// ```
    pub fn verdict(&self) -> String {
        let mut parts = Vec::new();
        if let Some(p) = self.power_law.p_value {
            let word = if p <= 0.1 { "rejected" } else { "not rejected" };
            parts.push(format!(
                "pure power law {word} by its goodness test (p = {p:.2})"
            ));
        }
        for (a, b, lr) in [
            ("power law", "exponential", &self.vs_exponential),
            ("power law", "log-normal", &self.vs_lognormal),
            ("power law", "cut-off law", &self.vs_cutoff),
            ("cut-off law", "log-normal", &self.cutoff_vs_lognormal),
        ] {
            let p = lr.p_value;
            parts.push(if p < LR_SIGNIFICANCE && lr.log_ratio > 0.0 {
                format!("{a} preferred over {b} (p = {p:.2})")
            } else if p < LR_SIGNIFICANCE && lr.log_ratio < 0.0 {
                format!("{b} preferred over {a} (p = {p:.2})")
            } else {
                format!("{a} and {b} not distinguished (p = {p:.2})")
            });
        }
        parts.join("; ")
    }
}

/// One bin of a log-binned histogram ([`log_binned`]). Values are in the samples' unit.
///
/// ```
/// use precursors::statistics::{log_binned, Support};
/// // Counts 1, 1, 2 and 10, one bin per decade: [1, 10) holds the integers 1 to 9.
/// let bins = log_binned(&[1.0, 1.0, 2.0, 10.0], Support::Discrete, 1)?;
/// assert_eq!((bins[0].low, bins[0].high, bins[0].count), (1.0, 10.0, 3));
/// assert!((bins[0].density - 3.0 / 4.0 / 9.0).abs() < 1e-15); // a share per integer
/// # Ok::<(), precursors::Error>(())
/// ```
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct LogBin {
    /// Lower edge (included).
    pub low: f64,
    /// Upper edge (excluded; the last bin holds the largest sample).
    pub high: f64,
    /// Geometric mean of `low` and `high`: where the density is plotted on log axes.
    pub center: f64,
    /// Samples in the bin.
    pub count: usize,
    /// Density estimate `P(x) = count / (n · width)` (inverse unit of the samples), `n`
    /// the number of positive samples. `width` is `high - low` for continuous samples and
    /// the number of integers in `[low, high)` for discrete ones, so that `P` is a
    /// probability per integer and compares with `P(X = k)` directly. Capped at
    /// `f64::MAX` (reached only in bins of subnormal width).
    pub density: f64,
}

/// Fits a power law `p(x) ∝ x^(-α)`, `x ≥ x_min`, to samples by maximum likelihood, with
/// `x_min` chosen by the Kolmogorov–Smirnov criterion of Clauset, Shalizi and Newman (SIAM
/// Review 51, 661, 2009), a bootstrap interval of `α` and `x_min` and the goodness-of-fit
/// p-value.
///
/// The procedure:
///
/// * Zero and negative samples are dropped (no power law holds them); the positive ones
///   are sorted, so the result does not depend on the samples' order.
/// * For each candidate `x_min`, `α` is the maximum-likelihood estimate of the tail
///   `x ≥ x_min`: `α = 1 + n / Σ ln(x_i / x_min)` for continuous samples; for discrete
///   ones the root of the score `d/dα [-n ln ζ(α, x_min) - α Σ ln x_i] = 0` in the
///   bracket `(1, 20]` (the log-likelihood is concave in `α`: safeguarded Newton steps,
///   bisection as fallback, to about 1e-13 relative; 20 when the likelihood still rises
///   there). `ζ` is the Hurwitz zeta function (direct summation plus an Euler–Maclaurin
///   tail, about 1e-15 relative).
/// * `x_min` is the candidate of smallest Kolmogorov–Smirnov distance `D = max |S - P|`
///   between the tail's empirical distribution function `S` and the fitted law's `P`
///   (the smallest `x_min` on ties). Continuous: `D` is taken at both sides of every jump
///   of `S`. Discrete: at every integer (where the two step functions can differ most:
///   at each sample value and just before the next one), with
///   `P(X ≤ x) = 1 - ζ(α, x + 1) / ζ(α, x_min)`.
/// * Candidates are the distinct sample values that leave at least
///   [`PowerLawOptions::min_tail`] samples at or above them, except the largest value
///   (a tail of one value has an infinite exponent). So that large data sets stay
///   affordable, a candidate is skipped when its tail is within 1 % of the tail of the
///   last candidate tried: tails of up to 100 samples are all tried, larger ones on a
///   grid of 1 % steps (a 1e4-sample set has about 560 candidates instead of 1e4).
/// * The bootstrap redraws the positive samples with replacement and refits both `x_min`
///   and `α` (Clauset et al. sec. 3.4); the intervals are the percentiles
///   `(1 ∓ confidence) / 2` of the resampled values (the order statistics at or outside
///   those ranks, so an end is a resampled value). A resample of
///   one value only (no fit possible) is left out.
/// * The goodness-of-fit test draws `goodness_samples` synthetic sets of as many samples,
///   each sample from the fitted law above `x_min` with probability `tail / samples`, else
///   uniformly from the samples below `x_min` (sec. 4.1). Discrete draws invert the exact
///   distribution function (Clauset's approximation `⌊(x_min - ½)(1 - r)^(-1/(α-1)) + ½⌋`
///   refined to the exact integer), capped at 2^53; continuous draws are
///   `x_min (1 - r)^(-1/(α-1))`, capped at `f64::MAX`. A synthetic set of a single value
///   counts as a perfect fit (`D = 0`).
/// * Randomness comes from two `Xoshiro256PlusPlus` streams seeded from
///   [`PowerLawOptions::seed`], one for the bootstrap and one for the synthetic sets, drawn
///   in a fixed order: the same samples (in any order), support and options give the same
///   fit bit for bit.
///
/// Cost: `1 + bootstrap + goodness_samples` fits of `n` samples; with the default options
/// 1e4 samples take 0.2 to 3 s in a release build (less for data that follow the law).
///
/// ```
/// use precursors::statistics::{fit_power_law, PowerLawOptions, Support};
/// // Avalanche sizes (ruptures per avalanche), counted as `(size, times)`: about k^-2.
/// let counts = [(1.0, 58), (2.0, 15), (3.0, 7), (4.0, 4), (5.0, 2), (6.0, 2), (8.0, 2),
///               (11.0, 1), (14.0, 1), (23.0, 1), (37.0, 1), (90.0, 1)];
/// let sizes: Vec<f64> = counts.iter().flat_map(|&(k, t)| std::iter::repeat_n(k, t)).collect();
/// let options = PowerLawOptions::default().bootstrap(50).goodness_samples(50);
/// let fit = fit_power_law(&sizes, Support::Discrete, &options)?;
/// assert_eq!((fit.samples, fit.x_min, fit.tail), (95, 1.0, 95));
/// assert!((fit.alpha - 2.0).abs() < 2.0 * fit.alpha_std_error, "alpha = {}", fit.alpha);
/// assert!(fit.alpha_low < 2.0 && 2.0 < fit.alpha_high);
/// assert!(fit.p_value.is_some_and(|p| p > 0.1));   // a power law is not ruled out
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
///
/// * [`Error::InvalidParameter`] (`name` `"confidence"`) when the confidence level is not
///   strictly between 0 and 1 (or NaN);
/// * [`Error::InvalidCount`] (`"min_tail"`) when `min_tail < 2`;
/// * [`Error::InvalidParameter`] (`"samples"`) for a NaN or infinite sample, a sample of
///   [`Support::Discrete`] that is not an integer or exceeds 2^53 in magnitude, or
///   positive samples that are all equal (no exponent can be fitted);
/// * [`Error::TooFewSamples`] (`what` `"power-law fit"`) when fewer than `min_tail`
///   samples are positive.
pub fn fit_power_law(
    samples: &[f64],
    support: Support,
    options: &PowerLawOptions,
) -> Result<PowerLawFit> {
    Ok(fit_with(samples, support, options, &|| {}, |_, _| ())?.0)
}

/// The positive samples of a fit: sorted, as runs of equal values, and for each sorted
/// sample the run it falls in (what a resample draws from).
struct Prepared {
    runs: Runs,
    run_of: Vec<usize>,
}

/// [`fit_power_law`], calling `progress` after each whole fit (the search on the data,
/// each bootstrap resample, each synthetic set) and `on_resample` with each bootstrap
/// resample and its fit (on the replicas' threads); also returns the samples, the fit at
/// `x_min` and `on_resample`'s values, in resample order.
fn fit_with<R: Send>(
    samples: &[f64],
    support: Support,
    options: &PowerLawOptions,
    progress: &(dyn Fn() + Sync),
    on_resample: impl Fn(&Runs, &TailFit) -> R + Sync,
) -> Result<(PowerLawFit, Prepared, TailFit, Vec<R>)> {
    check_fit_options(options)?;
    let min_tail = options.min_tail;
    let xs = positive_sorted(samples, support)?;
    let n = xs.len();
    if n < min_tail {
        return Err(Error::TooFewSamples {
            what: "power-law fit",
            count: n,
            needed: min_tail,
        });
    }
    let data = Prepared {
        runs: Runs::from_sorted(&xs),
        run_of: Runs::run_of(&xs),
    };
    drop(xs);
    let mut scratch = Scratch::default();
    let best =
        fit_runs(&data.runs, support, min_tail, &mut scratch).ok_or(Error::InvalidParameter {
            name: "samples",
            value: data.runs.values[0],
            reason: "all positive samples are equal (or their logarithms are): a power law \
                     needs two distinct values",
        })?;
    drop(scratch);
    progress();
    let alpha_std_error = alpha_std_error(&best, support);
    let (intervals, extras) = bootstrap_intervals(&data, support, options, progress, on_resample);
    // Without a bootstrap (or no resample fitted), the intervals are the estimate alone.
    let ((alpha_low, alpha_high), (x_min_low, x_min_high)) =
        intervals.unwrap_or(((best.alpha, best.alpha), (best.x_min, best.x_min)));
    let p_value = (options.goodness_samples > 0)
        .then(|| goodness_of_fit(&data, support, min_tail, &best, options, progress));
    let fit = PowerLawFit {
        support,
        samples: n,
        tail: best.tail,
        x_min: best.x_min,
        alpha: best.alpha,
        alpha_std_error,
        alpha_low,
        alpha_high,
        x_min_low,
        x_min_high,
        ks_distance: best.ks,
        p_value,
    };
    Ok((fit, data, best, extras))
}

/// [`fit_power_law`], and on its tail `x ≥ x_min` the alternatives of Clauset, Shalizi
/// and Newman (section 5) fitted by maximum likelihood and tested against it.
///
/// * **The alternatives**, on the same tail (`n` samples): the exponential (closed form),
///   the log-normal ([`LognormalFit`]) and the power law with exponential cut-off
///   `p(x) ∝ x^(-α) e^(-λx)` ([`CutoffFit`]; reals normalised by
///   `∫_{x_min}^∞ x^(-α) e^(-λx) dx = λ^(α-1) Γ(1-α, λ x_min) = x_min^(1-α) E_α(λ x_min)`,
///   the generalized exponential integral by series, upward recurrence and a continued
///   fraction to about 1e-14; integers by the sum over `k ≥ x_min`, 2000 terms or until
///   they fall below 1e-18 of it, then an Euler–Maclaurin tail). The log-normal and the
///   cut-off law are maximised by Nelder–Mead over two parameters (`(β, ln γ)` with the
///   log-normal written `∝ e^(-β y - γ y²)` in `y = ln(x/x_min)`; `(α, ln λ x_min)`), each
///   likelihood concave in its natural parameters, from two starts, restarted until a
///   restart gains at most 1e-13 in log-likelihood per sample (points to 1e-9).
/// * **The tests**: `R = Σ [ln p₁(x_i) - ln p₂(x_i)]` over the tail. Non-nested pairs
///   (power law against exponential, against log-normal; cut-off law against
///   log-normal): Vuong's statistic `R / √(n σ²)` (`σ²` the variance of the terms, over
///   `n`) and the two-sided p-value `erfc(|R| / √(2 n σ²))` (Clauset et al. eq. 5.7).
///   Nested (power law inside the cut-off law, `λ = 0`): Wilks' theorem,
///   `p = P(χ²₁ ≥ 2|R|) = erfc(√|R|)`, as Clauset et al. and the `powerlaw` package do
///   (the boundary `λ = 0` makes this conservative: the exact limit is half of it).
/// * **The cut-off law's interval**: each bootstrap resample of the power law (same
///   streams, so the power law's fields equal [`fit_power_law`]'s bit for bit) refits the
///   cut-off law on its own tail; the percentile interval at `confidence` of `α` and of
///   `1/λ`.
///
/// Seeded, one random stream per bootstrap resample and per synthetic set, made on the
/// threads of the current rayon pool (`ThreadPool::install` chooses them): the same
/// samples (in any order), support and options give the same comparison bit for bit,
/// on any number of threads ([`fit_power_law`] alike). Cost: [`fit_power_law`]'s plus `1 + bootstrap` fits
/// of the cut-off law (an optimisation over the tail's means, independent of its size for
/// reals; for integers each likelihood sums up to 2000 terms).
///
/// ```
/// use precursors::statistics::{compare_alternatives, PowerLawOptions, Support};
/// // Force drops (N) from a power law (α = 2.5 above 1 mN), by inversion of quantiles.
/// let drops: Vec<f64> = (0..500)
///     .map(|i| 1e-3 * (1.0 - (i as f64 + 0.5) / 500.0).powf(-1.0 / 1.5))
///     .collect();
/// let options = PowerLawOptions::default().bootstrap(20).goodness_samples(0);
/// let c = compare_alternatives(&drops, Support::Continuous, &options)?;
/// assert!((c.power_law.alpha - 2.5).abs() < 0.2);
/// assert!(c.vs_cutoff.p_value > 0.1);        // no cut-off needed
/// assert!(c.vs_exponential.log_ratio > 0.0 && c.vs_exponential.p_value < 0.1);
/// assert!(c.cutoff.alpha_low <= c.cutoff.alpha && c.cutoff.alpha <= c.cutoff.alpha_high);
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
///
/// Those of [`fit_power_law`], and [`Error::InvalidParameter`] (`"samples"`) when the
/// tail spans more than f64's range (`x/x_min` overflows for its largest sample, e.g.
/// samples from 1e-300 to 1e300).
pub fn compare_alternatives(
    samples: &[f64],
    support: Support,
    options: &PowerLawOptions,
) -> Result<Comparison> {
    compare_alternatives_with(samples, support, options, &|| {})
}

/// The whole fits [`compare_alternatives`] makes (and reports to its `progress`): the
/// search on the data, each bootstrap resample and each synthetic set.
#[cfg(feature = "serde")] // the sweep's statistics count them for their progress
pub(crate) fn whole_fits(options: &PowerLawOptions) -> usize {
    1 + options.bootstrap + options.goodness_samples
}

/// [`compare_alternatives`], calling `progress` after each of its [`whole_fits`] (from
/// the threads that make them).
pub(crate) fn compare_alternatives_with(
    samples: &[f64],
    support: Support,
    options: &PowerLawOptions,
    progress: &(dyn Fn() + Sync),
) -> Result<Comparison> {
    let (power_law, data, best, boot) =
        fit_with(samples, support, options, progress, |resample, fit| {
            let tail = alternatives::Tail::new(resample, fit, support);
            tail.is_finite().then(|| {
                let (alpha, lambda) = alternatives::cutoff_only(&tail);
                (alpha, 1.0 / lambda)
            })
        })?;
    let (mut boot_alpha, mut boot_cutoff): (Vec<f64>, Vec<f64>) =
        boot.into_iter().flatten().unzip();
    let tail = alternatives::Tail::new(&data.runs, &best, support);
    if !tail.is_finite() {
        return Err(Error::InvalidParameter {
            name: "samples",
            value: data.runs.values[data.runs.values.len() - 1],
            reason: "the tail spans more than f64's range (x / x_min overflows): the \
                     alternatives' likelihoods cannot be evaluated",
        });
    }
    let c = alternatives::compare(&tail);
    let (alpha, lambda, cutoff_ll) = c.cutoff;
    let cutoff = 1.0 / lambda;
    let (alpha_low, alpha_high) =
        percentile_interval(&mut boot_alpha, options.confidence).unwrap_or((alpha, alpha));
    let (cutoff_low, cutoff_high) =
        percentile_interval(&mut boot_cutoff, options.confidence).unwrap_or((cutoff, cutoff));
    Ok(Comparison {
        power_law,
        power_law_log_likelihood: c.power_law_ll,
        cutoff: CutoffFit {
            alpha,
            lambda,
            cutoff,
            alpha_low,
            alpha_high,
            cutoff_low,
            cutoff_high,
            log_likelihood: cutoff_ll,
        },
        exponential: ExponentialFit {
            lambda: c.exponential.0,
            log_likelihood: c.exponential.1,
        },
        lognormal: LognormalFit {
            mu: c.lognormal.0,
            sigma: c.lognormal.1,
            log_likelihood: c.lognormal.2,
        },
        vs_exponential: c.vs_exponential,
        vs_lognormal: c.vs_lognormal,
        vs_cutoff: c.vs_cutoff,
        cutoff_vs_lognormal: c.cutoff_vs_lognormal,
    })
}

/// The options [`fit_power_law`] refuses: a confidence level outside `(0, 1)` (or NaN)
/// and a minimum tail below 2.
fn check_fit_options(options: &PowerLawOptions) -> Result<()> {
    let confidence = options.confidence;
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(Error::InvalidParameter {
            name: "confidence",
            value: confidence,
            reason: "the confidence level must lie strictly between 0 and 1",
        });
    }
    if options.min_tail < 2 {
        return Err(Error::InvalidCount {
            name: "min_tail",
            value: options.min_tail as u64,
            reason: "a tail needs at least 2 samples to fit an exponent",
        });
    }
    Ok(())
}

/// The asymptotic standard error of the maximum-likelihood `α`: `(α - 1)/√n` for
/// continuous samples, `1/√(n Var(ln X))` (the Fisher information) for discrete ones.
fn alpha_std_error(best: &TailFit, support: Support) -> f64 {
    match support {
        Support::Continuous => (best.alpha - 1.0) / (best.tail as f64).sqrt(),
        Support::Discrete => {
            let (_, variance) = discrete_score(best.alpha, best.x_min, 0.0);
            let fisher = best.tail as f64 * variance;
            // Var(ln X) > 0 for any law over two integers or more; the guard only keeps a
            // rounding accident from giving an infinite or NaN error.
            if fisher > 0.0 && fisher.is_finite() {
                1.0 / fisher.sqrt()
            } else {
                (best.alpha - 1.0) / (best.tail as f64).sqrt()
            }
        }
    }
}

/// The bootstrap's percentile intervals `((α_low, α_high), (x_min_low, x_min_high))`:
/// whole refits of `options.bootstrap` resamples of the samples (Clauset et al. sec.
/// 3.4), `None` when no resample could be fitted; and `on_resample`'s value of each
/// fitted resample, in resample order. A resample is drawn as counts per run of equal
/// samples, so it is sorted without a sort and its logarithms are the data's.
#[allow(clippy::type_complexity)]
fn bootstrap_intervals<R: Send>(
    data: &Prepared,
    support: Support,
    options: &PowerLawOptions,
    progress: &(dyn Fn() + Sync),
    on_resample: impl Fn(&Runs, &TailFit) -> R + Sync,
) -> (Option<((f64, f64), (f64, f64))>, Vec<R>) {
    let runs = &data.runs;
    let n = runs.samples();
    let fits = replicas(options.bootstrap, progress, |i, s| {
        let mut rng = replica_rng(options.seed, BOOTSTRAP_STREAM, i);
        s.counts.clear();
        s.counts.resize(runs.len(), 0);
        for _ in 0..n {
            s.counts[data.run_of[rng.random_range(0..n)]] += 1;
        }
        let mut resample = std::mem::take(&mut s.resample);
        resample.clear();
        for (g, &c) in s.counts.iter().enumerate() {
            if c > 0 {
                resample.push(runs.values[g], runs.logs[g], c);
            }
        }
        let out = fit_runs(&resample, support, options.min_tail, s)
            .map(|fit| (fit.alpha, fit.x_min, on_resample(&resample, &fit)));
        s.resample = resample;
        out
    });
    let (mut alphas, mut x_mins) = (Vec::new(), Vec::new());
    let mut extras = Vec::new();
    for (alpha, x_min, extra) in fits.into_iter().flatten() {
        alphas.push(alpha);
        x_mins.push(x_min);
        extras.push(extra);
    }
    let intervals = percentile_interval(&mut alphas, options.confidence)
        .zip(percentile_interval(&mut x_mins, options.confidence));
    (intervals, extras)
}

/// The random streams of the bootstrap and of the synthetic sets.
const BOOTSTRAP_STREAM: u64 = 1;
const GOODNESS_STREAM: u64 = 2;

/// The generator of replica `replica` of `stream` (bootstrap or goodness of fit) under
/// `seed`: one stream per replica, so that a replica's draws, and the results, do not
/// depend on the threads that make them or on their order. SplitMix64's finaliser spreads
/// neighbouring `(seed, stream, replica)` over unrelated seeds.
fn replica_rng(seed: u64, stream: u64, replica: usize) -> Xoshiro256PlusPlus {
    let mix = |mut z: u64| {
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    let word = mix(mix(seed ^ mix(stream)) ^ replica as u64);
    Xoshiro256PlusPlus::seed_from_u64(word)
}

/// `replica(i, scratch)` for `i` in `0..count`, on the threads of the current rayon pool
/// (`ThreadPool::install` chooses them), each thread with its own buffers; `progress`
/// after each. The values come back in replica order.
fn replicas<R: Send>(
    count: usize,
    progress: &(dyn Fn() + Sync),
    replica: impl Fn(usize, &mut Scratch) -> R + Sync,
) -> Vec<R> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Mutex;
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<(usize, R)>> = Mutex::new(Vec::with_capacity(count));
    let threads = rayon::current_num_threads().clamp(1, count.max(1));
    let work = || {
        let mut scratch = Scratch::default();
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            if i >= count {
                break;
            }
            let r = replica(i, &mut scratch);
            // A poisoned lock means another replica panicked; its panic is re-raised by
            // the scope, so the values pushed here are never read.
            if let Ok(mut done) = done.lock() {
                done.push((i, r));
            }
            progress();
        }
    };
    rayon::scope(|s| {
        for _ in 1..threads {
            s.spawn(|_| work());
        }
        work();
    });
    let mut done = done.into_inner().unwrap_or_else(|e| e.into_inner());
    done.sort_unstable_by_key(|(i, _)| *i);
    done.into_iter().map(|(_, r)| r).collect()
}

/// The most bins (edges) [`log_binned`] makes.
const MAX_BINS: usize = 1_000_000;

/// A histogram of the positive samples in logarithmically spaced bins, as density
/// estimates `P(x)` for log-log plots.
///
/// Edges are `e_k = x0 · 10^(k / bins_per_decade)`, `x0` the smallest positive sample,
/// up to the first edge above the largest sample (so the last bin holds it). For
/// [`Support::Discrete`] the edges are rounded up to integers, bin `k` being
/// `[⌈e_k⌉, ⌈e_(k+1)⌉)` (an edge within 1e-9 relative of an integer counts as that
/// integer, so rounding noise in `10^(k/b)` does not shift a bin), so that every bin holds
/// whole integers; bins that would hold no integer are left out. Empty bins (no sample)
/// are listed with count and density 0, so that plots show the gaps.
///
/// `density = count / (n · width)`, `n` the number of positive samples, `width`
/// `high - low` (continuous) or the number of integers in the bin (discrete): the
/// densities times widths sum to 1. Zero and negative samples are dropped (as in
/// [`fit_power_law`]); with no positive sample the histogram is empty.
///
/// ```
/// use precursors::statistics::{log_binned, Support};
/// // Avalanche sizes (ruptures): a zero is left out, 7 positive sizes remain.
/// let sizes = [1.0, 1.0, 2.0, 3.0, 0.0, 5.0, 12.0, 40.0];
/// let bins = log_binned(&sizes, Support::Discrete, 2)?;
/// // Edges 1, 10^0.5 = 3.16, 10, 31.6, 100 rounded up: [1, 4), [4, 10), [10, 32), [32, 100).
/// let edges: Vec<_> = bins.iter().map(|b| (b.low, b.high, b.count)).collect();
/// assert_eq!(edges, [(1.0, 4.0, 4), (4.0, 10.0, 1), (10.0, 32.0, 1), (32.0, 100.0, 1)]);
/// assert_eq!(bins[0].density, 4.0 / (7.0 * 3.0));   // probability per integer
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
///
/// * [`Error::InvalidCount`] (`name` `"bins_per_decade"`) when `bins_per_decade` is 0,
///   above a million, or so large for the samples' range that the histogram would exceed
///   a million edges;
/// * [`Error::InvalidParameter`] (`"samples"`) for a NaN or infinite sample, or a sample
///   of [`Support::Discrete`] that is not an integer or exceeds 2^53 in magnitude.
pub fn log_binned(
    samples: &[f64],
    support: Support,
    bins_per_decade: usize,
) -> Result<Vec<LogBin>> {
    if bins_per_decade == 0 {
        return Err(Error::InvalidCount {
            name: "bins_per_decade",
            value: 0,
            reason: "a histogram needs at least one bin per decade",
        });
    }
    let xs = positive_sorted(samples, support)?;
    let (Some(&x0), Some(&x_max)) = (xs.first(), xs.last()) else {
        return Ok(Vec::new());
    };
    let per_decade = bins_per_decade as f64;
    // Edges needed: the decades spanned times the bins per decade, plus the last one.
    // At most MAX_BINS per decade also keeps 10^(1/b) distinguishable from 1.
    let edges = (x_max.log10() - x0.log10()) * per_decade + 2.0;
    if edges > MAX_BINS as f64 || bins_per_decade > MAX_BINS {
        return Err(Error::InvalidCount {
            name: "bins_per_decade",
            value: bins_per_decade as u64,
            reason: "the histogram would have more than a million edges (or bins per decade)",
        });
    }
    let edge = |k: usize| -> f64 {
        let e = x0 * 10f64.powf(k as f64 / per_decade);
        match support {
            Support::Continuous => e,
            Support::Discrete => {
                let r = e.round();
                if (e - r).abs() <= 1e-9 * e {
                    r
                } else {
                    e.ceil()
                }
            }
        }
    };
    let n = xs.len() as f64;
    let mut bins = Vec::new();
    let (mut next, mut low) = (0usize, edge(0));
    for k in 1.. {
        let mut high = edge(k);
        if high <= low {
            continue; // a discrete bin of no integer: its edges coincide
        }
        // Edges pass the largest sample by k ≈ `edges` (checked above); the bound only
        // makes the end certain, with every sample counted.
        let last = high > x_max || !high.is_finite() || k > MAX_BINS;
        if !high.is_finite() {
            high = f64::MAX; // beyond the largest float: the last bin ends there, closed
        }
        let start = next;
        while next < xs.len() && (last || xs[next] < high) {
            next += 1;
        }
        let count = next - start;
        let width = high - low;
        bins.push(LogBin {
            low,
            high,
            center: low.sqrt() * high.sqrt(),
            count,
            // Divided in turn: n · width could overflow for huge samples. Capped: bins of
            // subnormal width (samples near 1e-320) would give infinity. A zero width only
            // if the largest sample is f64::MAX and sits on an edge.
            density: if width > 0.0 {
                (count as f64 / n / width).min(f64::MAX)
            } else {
                0.0
            },
        });
        if last {
            break;
        }
        low = high;
    }
    Ok(bins)
}

/// The positive samples, sorted; refuses NaN, infinities, and discrete samples that are
/// not integers or exceed 2^53 in magnitude.
fn positive_sorted(samples: &[f64], support: Support) -> Result<Vec<f64>> {
    for &x in samples {
        if !x.is_finite() {
            return Err(Error::InvalidParameter {
                name: "samples",
                value: x,
                reason: "samples must be finite",
            });
        }
        if support == Support::Discrete && x.fract() != 0.0 {
            return Err(Error::InvalidParameter {
                name: "samples",
                value: x,
                reason: "discrete samples must be integers",
            });
        }
        if support == Support::Discrete && x.abs() > MAX_DRAW {
            return Err(Error::InvalidParameter {
                name: "samples",
                value: x,
                reason: "discrete samples must not exceed 2^53 in magnitude, where f64 \
                         stops holding every integer",
            });
        }
    }
    let mut xs: Vec<f64> = samples.iter().copied().filter(|&x| x > 0.0).collect();
    xs.sort_unstable_by(f64::total_cmp);
    Ok(xs)
}

/// Sorted positive samples as runs of equal values: all a fit reads. A resample or a
/// synthetic set is built as runs directly (counts per value), without a sort and, for a
/// resample, without a logarithm.
#[derive(Debug, Default)]
struct Runs {
    /// The distinct values, ascending.
    values: Vec<f64>,
    /// `ln` of each value.
    logs: Vec<f64>,
    /// Index of each run's first sample among the sorted samples, then the number of
    /// samples (one more entry than `values`).
    starts: Vec<usize>,
}

impl Runs {
    /// The runs of sorted samples.
    fn from_sorted(xs: &[f64]) -> Self {
        let mut runs = Self::default();
        let mut i = 0;
        while i < xs.len() {
            let x = xs[i];
            let end = i + xs[i..].iter().take_while(|&&y| y == x).count();
            runs.push(x, x.ln(), end - i);
            i = end;
        }
        runs
    }

    /// For each sorted sample, the index of its run.
    fn run_of(xs: &[f64]) -> Vec<usize> {
        let mut g = 0;
        xs.iter()
            .enumerate()
            .map(|(i, x)| {
                if i > 0 && xs[i - 1] != *x {
                    g += 1;
                }
                g
            })
            .collect()
    }

    fn clear(&mut self) {
        self.values.clear();
        self.logs.clear();
        self.starts.clear();
    }

    /// Appends `count ≥ 1` samples equal to `x` (`≥` the last value; merged into the last
    /// run when equal to it), `log` being `ln x`.
    fn push(&mut self, x: f64, log: f64, count: usize) {
        let end = self.samples();
        if self.values.last() == Some(&x) {
            if let Some(last) = self.starts.last_mut() {
                *last += count;
            }
            return;
        }
        if self.starts.is_empty() {
            self.starts.push(0);
        }
        self.values.push(x);
        self.logs.push(log);
        self.starts.push(end + count);
    }

    /// Number of runs (distinct values).
    fn len(&self) -> usize {
        self.values.len()
    }

    /// Number of samples.
    fn samples(&self) -> usize {
        self.starts.last().copied().unwrap_or(0)
    }
}

/// The fit at one `x_min`: what the search, the bootstrap and the synthetic sets need.
#[derive(Debug, Clone, Copy)]
struct TailFit {
    x_min: f64,
    alpha: f64,
    tail: usize,
    ks: f64,
    /// Index of the first sample `≥ x_min` in the sorted samples.
    start: usize,
    /// Index of the run of `x_min`.
    run: usize,
}

/// Buffers reused across the many fits of one thread.
#[derive(Debug, Default)]
struct Scratch {
    /// `Σ_{j ≥ i} ln x_j` over the samples from run `g` on (and 0 past the last run), as
    /// an unevaluated sum `hi + lo` (compensated: as exact as the logarithms), so that a
    /// candidate's `α` costs O(1).
    suffix: Vec<(f64, f64)>,
    /// `ζ(α, q)` for consecutive integers `q` (see [`zeta_ladder`]).
    ladder: Vec<f64>,
    /// The model's distribution function at the ends of the blocks of a candidate's
    /// Kolmogorov–Smirnov pass.
    ends: Vec<(usize, f64)>,
    /// Samples per run of a resample or a synthetic set.
    counts: Vec<usize>,
    /// A bootstrap resample.
    resample: Runs,
    /// A synthetic data set, and the exponential spacings of its sorted uniforms.
    synthetic: Runs,
    spacings: Vec<f64>,
}

/// Tail sizes are tried on a grid of this relative step (tails within 1 % of the last
/// candidate tried are skipped): the fit's cost falls from `O(n²)` to about
/// `O(100 n)` operations for large `n`, at an `x_min` resolution far below its bootstrap
/// spread.
const TAIL_STEP_PERCENT: u128 = 1;

/// The whole fit of positive samples (`r.samples() ≥ min_tail ≥ 2`): the `x_min` search
/// and the exponent there. `None` when every sample is equal.
fn fit_runs(r: &Runs, support: Support, min_tail: usize, s: &mut Scratch) -> Option<TailFit> {
    let n = r.samples();
    let groups = r.len();
    s.suffix.clear();
    s.suffix.resize(groups + 1, (0.0, 0.0));
    for g in (0..groups).rev() {
        let (hi, lo) = s.suffix[g + 1];
        // count · ln x exactly as `product + product_err` (fma); a single sample adds its
        // logarithm alone, as a sum sample by sample would.
        let count = (r.starts[g + 1] - r.starts[g]) as f64;
        let product = count * r.logs[g];
        let product_err = count.mul_add(r.logs[g], -product);
        let (sum, err) = two_sum(hi, product);
        s.suffix[g] = (sum, lo + err + product_err);
    }
    let Scratch {
        suffix,
        ladder,
        ends,
        ..
    } = s;
    let mut best: Option<TailFit> = None;
    // The run where the best candidate's distance peaks: tried first by the next
    // candidates, most of which it rules out at once.
    let mut peak = None;
    let mut last_tail: Option<usize> = None;
    // The last run is never a candidate: a tail of one value has an infinite exponent.
    for g in 0..groups.saturating_sub(1) {
        let start = r.starts[g];
        let tail = n - start;
        if tail < min_tail {
            break; // tails only shrink from here
        }
        if let Some(last) = last_tail {
            if (tail as u128) * 100 > (last as u128) * (100 - TAIL_STEP_PERCENT) {
                continue;
            }
        }
        last_tail = Some(tail);
        let bound = best.map_or(f64::INFINITY, |b| b.ks);
        let candidate = match support {
            Support::Continuous => continuous_candidate(r, suffix, g, bound, peak, ends),
            Support::Discrete => discrete_candidate(r, suffix, g, bound, peak, ladder),
        };
        // Strictly smaller only: on ties the smaller x_min, tried first, stays.
        if let Some((alpha, ks, at)) = candidate {
            peak = Some(at);
            best = Some(TailFit {
                x_min: r.values[g],
                alpha,
                tail,
                ks,
                start,
                run: g,
            });
        }
    }
    best
}

/// Below this many runs in a tail a candidate's distance is a plain pass over them.
const BLOCKED_KS_MIN: usize = 1024;

/// The continuous fit at the `g`-th run: `(α, D, the run where D peaks)`, or `None` once
/// `D` reaches `bound` (the candidate cannot win; the rest of its distance is not
/// computed).
///
/// `D` is the largest of the terms `|F_below - P|`, `|F_at - P|` at every run of the
/// tail (`P` the model's distribution function, `F` the empirical one just below and at
/// the run's value). All of them rise with the run, so the terms inside a block of runs
/// `(a, b)` are at most `max(F_below(b) - P(a), P(b) - F_at(a))`: a pass over the block
/// ends (blocks of about `√tail / 16` runs) leaves out every block whose bound stays
/// below the largest term found, and `D` is exactly the plain pass's maximum.
fn continuous_candidate(
    r: &Runs,
    suffix: &[(f64, f64)],
    g: usize,
    bound: f64,
    peak: Option<usize>,
    ends: &mut Vec<(usize, f64)>,
) -> Option<(f64, f64, usize)> {
    let logs = &r.logs;
    let starts = &r.starts;
    let start = starts[g];
    let groups = r.len();
    let tail = (r.samples() - start) as f64;
    let ln_min = logs[g];
    // Σ ln(x / x_min) = Σ ln x - tail · ln x_min from the compensated suffix sum and an
    // exact product (fma): the difference of a narrow tail far from 1 cancels, but both
    // terms carry their rounding errors along, so the result is as accurate as a sum
    // of the differences term by term.
    let (hi, lo) = suffix[g];
    let product = tail * ln_min;
    let product_err = tail.mul_add(ln_min, -product);
    let sum = (hi - product) + (lo - product_err);
    let alpha = 1.0 + tail / sum;
    if !alpha.is_finite() {
        return None; // distinct values of equal logarithms (adjacent floats near 1e300)
    }
    // P(x) = 1 - (x / x_min)^(1 - α), with expm1 for small distances.
    let model = |j: usize| -((1.0 - alpha) * (logs[j] - ln_min)).exp_m1();
    let below = |j: usize| (starts[j] - start) as f64 / tail;
    let term = |j: usize, p: f64| (below(j) - p).abs().max((below(j + 1) - p).abs());
    let (mut ks, mut at) = (0.0f64, g);
    let take = |j: usize, p: f64, ks: &mut f64, at: &mut usize| {
        let t = term(j, p);
        if t > *ks {
            (*ks, *at) = (t, j);
        }
        *ks >= bound
    };
    if let Some(j) = peak.filter(|&j| j > g && j < groups) {
        if take(j, model(j), &mut ks, &mut at) {
            return None;
        }
    }
    let runs = groups - g;
    if runs < BLOCKED_KS_MIN {
        for j in g..groups {
            if take(j, model(j), &mut ks, &mut at) {
                return None;
            }
        }
        return Some((alpha, ks, at));
    }
    let block = ((runs as f64).sqrt() / 16.0) as usize;
    ends.clear();
    for j in (g..groups)
        .step_by(block)
        .chain(std::iter::once(groups - 1))
    {
        let p = model(j);
        ends.push((j, p));
        if take(j, p, &mut ks, &mut at) {
            return None;
        }
    }
    for w in ends.windows(2) {
        let ((a, pa), (b, pb)) = (w[0], w[1]);
        // 1e-12: room for the rounding of P, which need not rise in the last bit.
        let most = (below(b) - pa).max(pb - below(a + 1));
        if most + 1e-12 < ks {
            continue;
        }
        for j in a + 1..b {
            if take(j, model(j), &mut ks, &mut at) {
                return None;
            }
        }
    }
    Some((alpha, ks, at))
}

/// The discrete fit at the `g`-th run: `(α, D, the run where D peaks)`, or `None` once
/// `D` reaches `bound`.
fn discrete_candidate(
    r: &Runs,
    suffix: &[(f64, f64)],
    g: usize,
    bound: f64,
    peak: Option<usize>,
    ladder: &mut Vec<f64>,
) -> Option<(f64, f64, usize)> {
    let (xs, starts) = (&r.values, &r.starts);
    let start = starts[g];
    let groups = r.len();
    let tail = (r.samples() - start) as f64;
    let x_min = xs[g];
    let sum = suffix[g].0 + suffix[g].1;
    let alpha = discrete_mle(x_min, sum / tail);
    zeta_ladder(alpha, x_min, ladder);
    let top = x_min + (ladder.len() - 1) as f64;
    let zeta = |q: f64| {
        if q <= top {
            ladder[(q - x_min) as usize]
        } else {
            hurwitz_tail(alpha, q)
        }
    };
    let norm = ladder[0];
    // The distance at run j: at the sample value, and just before the next one, where P
    // is largest while S stays at `at` (beyond the largest sample |1 - P| only falls).
    let term = |j: usize| {
        let x = xs[j];
        let at = (starts[j + 1] - start) as f64 / tail;
        let p = 1.0 - zeta(x + 1.0) / norm;
        let mut t = (at - p).abs();
        if j + 1 < groups {
            let x_next = xs[j + 1];
            if x_next > x + 1.0 {
                let p_before = 1.0 - zeta(x_next) / norm;
                t = t.max((at - p_before).abs());
            }
        }
        t
    };
    let (mut ks, mut at) = (0.0f64, g);
    let probe = peak.filter(|&j| j > g && j < groups);
    for j in probe.into_iter().chain(g..groups) {
        let t = term(j);
        if t > ks {
            (ks, at) = (t, j);
        }
        if ks >= bound {
            return None;
        }
    }
    Some((alpha, ks, at))
}

/// `(a + b, its rounding error)` exactly (Knuth's two-sum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// The largest discrete exponent searched.
const ALPHA_MAX: f64 = 20.0;

/// Minus the derivative in `α` of the discrete log-likelihood per tail sample,
/// `-ln ζ(α, q) - α m`: `ζ'/ζ + m` (zero at the estimate, rising with `α`), and its own
/// derivative `Var(ln X) = ζ''/ζ - (ζ'/ζ)²` under the law (`m = ⟨ln x⟩` of the tail).
fn discrete_score(alpha: f64, q: f64, m: f64) -> (f64, f64) {
    let (z, z1, z2) = hurwitz_zeta_derivatives(alpha, q);
    let r = z1 / z;
    (r + m, z2 / z - r * r)
}

/// The maximum-likelihood exponent of a discrete power law above `q` whose tail has mean
/// `m = ⟨ln x⟩`: the root of the score in `(1, ALPHA_MAX]`, by Newton steps kept inside
/// a shrinking bracket (the score rises with `α`: the log-likelihood is concave).
fn discrete_mle(q: f64, m: f64) -> f64 {
    let (at_max, _) = discrete_score(ALPHA_MAX, q, m);
    if at_max.is_nan() || at_max <= 0.0 {
        return ALPHA_MAX; // the likelihood still rises at the cap
    }
    let (mut lo, mut hi) = (1.0, ALPHA_MAX);
    // Clauset et al.'s approximation 1 + n / Σ ln(x / (q - 1/2)) as the start: within a
    // few per cent of the root.
    let guess = 1.0 + 1.0 / (m - (q - 0.5).ln());
    let mut alpha = if guess > lo && guess < hi {
        guess
    } else {
        0.5 * (lo + hi)
    };
    for _ in 0..200 {
        let (score, slope) = discrete_score(alpha, q, m);
        if score > 0.0 {
            hi = alpha;
        } else if score < 0.0 {
            lo = alpha;
        } else {
            return alpha;
        }
        let mut next = alpha - score / slope;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        let done = (next - alpha).abs() <= 1e-13 * alpha;
        alpha = next;
        if done || hi - lo <= 1e-14 * alpha {
            break;
        }
    }
    alpha
}

/// The Euler–Maclaurin tail starts at `q + N ≥ EM_START`; with `BERNOULLI.len()`
/// correction terms it is accurate to about 1e-16 relative for `s ∈ (1, 20]` (checked
/// against 90-digit values).
const EM_START: f64 = 20.0;

/// `B_2j / (2j)!`, `j = 1..=12`.
const BERNOULLI: [f64; 12] = [
    0.083_333_333_333_333_33,
    -0.001_388_888_888_888_889,
    3.306_878_306_878_307e-5,
    -8.267_195_767_195_768e-7,
    2.087_675_698_786_81e-8,
    -5.284_190_138_687_493e-10,
    1.338_253_653_068_467_9e-11,
    -3.389_680_296_322_582_7e-13,
    8.586_062_056_277_845e-15,
    -2.174_868_698_558_062e-16,
    5.509_002_828_360_229_5e-18,
    -1.395_446_468_581_252_2e-19,
];

/// `Σ_{k≥0} (k + a)^(-s)` by Euler–Maclaurin alone (accurate for `a ≥ EM_START`).
fn hurwitz_tail(s: f64, a: f64) -> f64 {
    // a^(1-s) rather than a · a^(-s): the latter is subnormal sooner (a = 2^53, s = 20).
    let a1s = a.powf(1.0 - s);
    let mut terms = [0.0; BERNOULLI.len()];
    // B_2j/(2j)! · s(s+1)…(s+2j-2) · a^(-s-2j+1)
    let mut t = s * a1s / (a * a);
    for (j, (term, b)) in terms.iter_mut().zip(BERNOULLI).enumerate() {
        *term = b * t;
        let j = j as f64 + 1.0;
        t *= (s + 2.0 * j - 1.0) * (s + 2.0 * j) / (a * a);
    }
    // Smallest first.
    let corrections: f64 = terms.iter().rev().sum();
    corrections + 0.5 * a1s / a + a1s / (s - 1.0)
}

/// The Hurwitz zeta function `ζ(s, q) = Σ_{k≥0} (k + q)^(-s)` for `s > 1`, `q > 0`: the
/// first terms summed up to `q + N ≥ EM_START`, then the Euler–Maclaurin tail. About
/// 1e-15 relative for `s ∈ (1, 20]`.
fn hurwitz_zeta(s: f64, q: f64) -> f64 {
    let terms = if q < EM_START {
        (EM_START - q).ceil() as usize
    } else {
        0
    };
    let mut sum = hurwitz_tail(s, q + terms as f64);
    // Smallest terms first.
    for k in (0..terms).rev() {
        sum += (q + k as f64).powf(-s);
    }
    sum
}

/// `ζ(s, q)` and its first two derivatives in `s`, `ζ' = -Σ ln(k+q) (k+q)^(-s)` and
/// `ζ'' = Σ ln²(k+q) (k+q)^(-s)`: the derivatives of the same summation and
/// Euler–Maclaurin formula, term by term.
fn hurwitz_zeta_derivatives(s: f64, q: f64) -> (f64, f64, f64) {
    let n = if q < EM_START {
        (EM_START - q).ceil() as usize
    } else {
        0
    };
    let a = q + n as f64;
    let la = a.ln();
    let a1s = ((1.0 - s) * la).exp();
    // a^(1-s)/(s-1): d/ds ln = -(ln a + 1/(s-1)), d²/ds² ln = 1/(s-1)².
    let g = a1s / (s - 1.0);
    let dg = la + 1.0 / (s - 1.0);
    let (mut z, mut z1, mut z2) = (0.0, 0.0, 0.0);
    // Corrections c_j = B_2j/(2j)! · P_j(s) · a^(-s-2j+1), P_j = s(s+1)…(s+2j-2):
    // d/ds ln c_j = Σ 1/(s+i) - ln a, d²/ds² ln c_j = -Σ 1/(s+i)².
    let mut terms = [(0.0, 0.0, 0.0); BERNOULLI.len()];
    let (mut c, mut s1, mut s2) = (s * a1s / (a * a), 1.0 / s, 1.0 / (s * s));
    for (j, (term, b)) in terms.iter_mut().zip(BERNOULLI).enumerate() {
        let l1 = s1 - la;
        let cj = b * c;
        *term = (cj, cj * l1, cj * (l1 * l1 - s2));
        let j = j as f64 + 1.0;
        let (u, v) = (s + 2.0 * j - 1.0, s + 2.0 * j);
        c *= u * v / (a * a);
        s1 += 1.0 / u + 1.0 / v;
        s2 += 1.0 / (u * u) + 1.0 / (v * v);
    }
    for (t0, t1, t2) in terms.iter().rev() {
        z += t0;
        z1 += t1;
        z2 += t2;
    }
    let h = 0.5 * a1s / a;
    z += h + g;
    z1 += -la * h - g * dg;
    z2 += la * la * h + g * (dg * dg + 1.0 / ((s - 1.0) * (s - 1.0)));
    for k in (0..n).rev() {
        let x = q + k as f64;
        let l = x.ln();
        let p = (-s * l).exp();
        z += p;
        z1 -= l * p;
        z2 += l * l * p;
    }
    (z, z1, z2)
}

/// Fills `out` with `ζ(s, q)` for the consecutive integers `q = q0, q0 + 1, …,
/// max(q0, EM_START)`, summed downwards from the Euler–Maclaurin tail at the top (adding
/// positive terms: no cancellation, unlike `ζ(s, q+1) = ζ(s, q) - q^(-s)` upwards).
fn zeta_ladder(s: f64, q0: f64, out: &mut Vec<f64>) {
    let top = q0.max(EM_START);
    let len = (top - q0) as usize + 1;
    out.clear();
    out.resize(len, 0.0);
    out[len - 1] = hurwitz_tail(s, top);
    for i in (0..len - 1).rev() {
        out[i] = out[i + 1] + (q0 + i as f64).powf(-s);
    }
}

/// The largest discrete sample accepted, and where draws of the discrete sampler stop:
/// f64 holds every integer up to 2^53.
const MAX_DRAW: f64 = 9_007_199_254_740_992.0; // 2^53

/// A discrete power law above `x_min` to draw from: its survival function
/// `S(x) = P(X ≥ x) = ζ(α, x) / ζ(α, x_min)`, tabulated near `x_min`.
struct DiscreteLaw {
    alpha: f64,
    x_min: f64,
    /// `ζ(α, x_min + k)`, `k = 0..TABLE`.
    table: Vec<f64>,
}

impl DiscreteLaw {
    const TABLE: usize = 1024;

    fn new(alpha: f64, x_min: f64) -> Self {
        let mut table = vec![0.0; Self::TABLE];
        let top = x_min + (Self::TABLE - 1) as f64;
        table[Self::TABLE - 1] = hurwitz_zeta(alpha, top);
        for i in (0..Self::TABLE - 1).rev() {
            table[i] = table[i + 1] + (x_min + i as f64).powf(-alpha);
        }
        Self {
            alpha,
            x_min,
            table,
        }
    }

    /// `P(X ≥ x)` for an integer `x ≥ x_min`.
    fn survival(&self, x: f64) -> f64 {
        let k = x - self.x_min;
        let z = if k < Self::TABLE as f64 {
            self.table[k as usize]
        } else {
            hurwitz_zeta(self.alpha, x)
        };
        z / self.table[0]
    }

    /// [`DiscreteLaw::draw`] for falling `u` in turn: `step` (0 at first) is the table
    /// index of the last draw, from which the next one walks up the table (and past it
    /// draws by bisection).
    fn draw_from(&self, u: f64, step: &mut usize) -> f64 {
        let fits = |k: usize| self.table[k] / self.table[0] <= u;
        while *step + 1 < Self::TABLE && !fits(*step + 1) {
            *step += 1;
        }
        if *step + 1 < Self::TABLE {
            self.x_min + *step as f64
        } else {
            self.draw(u)
        }
    }

    /// The smallest integer `x ≥ x_min` with `P(X > x) ≤ u`, `u ∈ (0, 1]`: the inverse
    /// distribution function at `1 - u`. Clauset et al.'s approximation (their appendix
    /// D) is the start; galloping steps bracket the exact integer, bisection finds it.
    fn draw(&self, u: f64) -> f64 {
        let x_min = self.x_min;
        let fits = |x: f64| self.survival(x + 1.0) <= u;
        let guess = ((x_min - 0.5) * u.powf(-1.0 / (self.alpha - 1.0)) + 0.5).floor();
        let guess = if guess.is_nan() {
            x_min
        } else {
            guess.clamp(x_min, MAX_DRAW.max(x_min))
        };
        // Invariant: `fits(hi)`, and `lo < x_min` or `!fits(lo)`.
        let (mut lo, mut hi);
        let mut step = 1.0;
        if fits(guess) {
            hi = guess;
            loop {
                let c = hi - step;
                if c < x_min {
                    lo = x_min - 1.0;
                    break;
                }
                if fits(c) {
                    hi = c;
                    step *= 2.0;
                } else {
                    lo = c;
                    break;
                }
            }
        } else {
            lo = guess;
            loop {
                let c = lo + step;
                if c >= MAX_DRAW {
                    if !fits(MAX_DRAW) {
                        return MAX_DRAW;
                    }
                    hi = MAX_DRAW;
                    break;
                }
                if fits(c) {
                    hi = c;
                    break;
                }
                lo = c;
                step *= 2.0;
            }
        }
        while hi - lo > 1.0 {
            let mid = lo + ((hi - lo) * 0.5).floor();
            if mid <= lo || mid >= hi {
                break; // no integer between them in f64 (not below 2^53)
            }
            if fits(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    }
}

/// Clauset et al. sec. 4.1: the fraction of `options.goodness_samples` synthetic data
/// sets, each refitted from scratch, whose Kolmogorov–Smirnov distance is at least the
/// data's. A set of `n` samples holds `m ~ Binomial(n, tail/n)` draws of the fitted law
/// and `n - m` draws of the data below `x_min`; both are drawn sorted (the law's as the
/// order statistics of `m` uniforms, from exponential spacings; the data's as counts per
/// run), so no set is sorted.
fn goodness_of_fit(
    data: &Prepared,
    support: Support,
    min_tail: usize,
    fit: &TailFit,
    options: &PowerLawOptions,
    progress: &(dyn Fn() + Sync),
) -> f64 {
    let runs = &data.runs;
    let n = runs.samples();
    let below = fit.start;
    let p_tail = fit.tail as f64 / n as f64;
    let law = match support {
        Support::Discrete => Some(DiscreteLaw::new(fit.alpha, fit.x_min)),
        Support::Continuous => None,
    };
    let sets = options.goodness_samples;
    let exceed = replicas(sets, progress, |i, s| {
        let mut rng = replica_rng(options.seed, GOODNESS_STREAM, i);
        let m = if below == 0 {
            n
        } else {
            // 0 < p_tail < 1 here: a valid binomial.
            rand_distr::Binomial::new(n as u64, p_tail).map_or(n, |b| rng.sample(b) as usize)
        };
        let mut set = std::mem::take(&mut s.synthetic);
        set.clear();
        s.counts.clear();
        s.counts.resize(fit.run, 0);
        for _ in m..n {
            s.counts[data.run_of[rng.random_range(0..below)]] += 1;
        }
        for (g, &c) in s.counts.iter().enumerate() {
            if c > 0 {
                set.push(runs.values[g], runs.logs[g], c);
            }
        }
        sorted_draws(m, fit, law.as_ref(), &mut rng, &mut s.spacings, &mut set);
        // One value only: a point mass, fitted perfectly in the limit α → ∞ (D = 0).
        let ks = fit_runs(&set, support, min_tail, s).map_or(0.0, |f| f.ks);
        s.synthetic = set;
        ks >= fit.ks
    });
    exceed.iter().filter(|&&e| e).count() as f64 / sets as f64
}

/// Appends to `set` (whose values are all below `fit.x_min`) `m` draws of the fitted
/// law above `fit.x_min` (`law` for counts, the continuous law without), in ascending
/// order: with `E_0..E_m` exponential and `T_k = Σ_{i ≥ k} E_i`, the `T_k / T_0`
/// (`k = 1..m`) fall as the order statistics of `m` uniforms on (0, 1), and the law's
/// inverse survival function turns them into rising draws. Summed from the top, the
/// small ones keep their relative precision.
fn sorted_draws(
    m: usize,
    fit: &TailFit,
    law: Option<&DiscreteLaw>,
    rng: &mut Xoshiro256PlusPlus,
    spacings: &mut Vec<f64>,
    set: &mut Runs,
) {
    spacings.clear();
    spacings.extend((0..=m).map(|_| rng.sample::<f64, _>(rand_distr::Exp1)));
    for k in (0..m).rev() {
        spacings[k] += spacings[k + 1];
    }
    let total = spacings[0];
    let exponent = -1.0 / (fit.alpha - 1.0);
    let mut last = fit.x_min;
    let mut step = 0;
    for &t in &spacings[1..] {
        // A survival probability u in (0, 1), falling: the draws rise.
        let u = t / total;
        let x = match law {
            Some(law) => law.draw_from(u, &mut step),
            None => {
                let x = fit.x_min * (exponent * u.ln()).exp();
                if x.is_finite() {
                    x
                } else {
                    f64::MAX
                }
            }
        };
        // Rounding must not unsort the draws.
        last = last.max(x);
        set.push(last, last.ln(), 1);
    }
}

/// The percentile interval `(1 ∓ confidence) / 2` of `values` (sorted in place): the
/// order statistics at or outside those ranks, so each end is a resampled value (an
/// integer `x_min` for counts) and the interval is never narrower than the percentiles;
/// `None` for no values.
fn percentile_interval(values: &mut [f64], confidence: f64) -> Option<(f64, f64)> {
    if values.is_empty() {
        return None;
    }
    values.sort_unstable_by(f64::total_cmp);
    let last = values.len() - 1;
    let rank = |p: f64| last as f64 * p;
    let low = rank(0.5 * (1.0 - confidence)).floor() as usize;
    let high = (rank(0.5 * (1.0 + confidence)).ceil() as usize).min(last);
    Some((values[low], values[high]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_distr::{Distribution, Exp, Pareto, Zeta};
    use std::f64::consts::PI;

    fn rng(seed: u64) -> Xoshiro256PlusPlus {
        Xoshiro256PlusPlus::seed_from_u64(seed)
    }

    fn pareto(alpha: f64, x_min: f64, n: usize, seed: u64) -> Vec<f64> {
        let law = Pareto::new(x_min, alpha - 1.0).unwrap();
        let mut r = rng(seed);
        (0..n).map(|_| law.sample(&mut r)).collect()
    }

    fn zeta_samples(alpha: f64, n: usize, seed: u64) -> Vec<f64> {
        let law = Zeta::new(alpha).unwrap();
        let mut r = rng(seed);
        (0..n).map(|_| law.sample(&mut r)).collect()
    }

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    #[test]
    fn hurwitz_zeta_matches_independent_values() {
        let pi2 = PI * PI / 6.0;
        for (s, q, expected) in [
            (2.0, 1.0, pi2),
            (3.0, 1.0, 1.202_056_903_159_594_2),
            (2.0, 2.0, pi2 - 1.0),
            (1.5, 1.0, 2.612_375_348_685_488),
            (4.0, 1.0, PI.powi(4) / 90.0),
            // mpmath.zeta(2.5, 7.3) at 50 digits.
            (2.5, 7.3, 0.037_470_518_158_700_956),
        ] {
            let z = hurwitz_zeta(s, q);
            assert!(
                close(z, expected, 2e-15),
                "zeta({s}, {q}) = {z}, expected {expected}"
            );
        }
        // A brute-force sum for a non-integer s and q = 7, with the rest as the midpoint
        // integral ∫_{K+q-1/2}^∞ x^(-s) dx (error ~ s(s+1)/24 · K^(-s-1)).
        let (s, q) = (1.7, 7.0);
        let k_max = 2_000_000;
        let direct: f64 = (0..k_max).rev().map(|k| (k as f64 + q).powf(-s)).sum();
        let rest = (k_max as f64 + q - 0.5).powf(1.0 - s) / (s - 1.0);
        let brute = direct + rest;
        let z = hurwitz_zeta(s, q);
        assert!(
            close(z, brute, 1e-11),
            "zeta({s}, {q}) = {z}, brute force {brute}"
        );
        assert!(close(z, 0.384_907_255_874_874_57, 2e-15)); // mpmath
                                                            // Large q, where only the Euler–Maclaurin tail is used; and q just above and
                                                            // below EM_START (same function, two paths).
        assert!(close(
            hurwitz_zeta(2.0, 1e6),
            1.000_000_500_000_166_6e-6,
            1e-14
        ));
        let (below, above) = (hurwitz_zeta(3.3, 19.5), hurwitz_zeta(3.3, 20.5));
        assert!(close(below - above, 19.5f64.powf(-3.3), 1e-12));
    }

    #[test]
    fn zeta_derivatives_match_independent_values() {
        // mpmath.zeta(s, q, 1) and mpmath.zeta(s, q, 2) at 50 digits.
        for (s, q, z1, z2) in [
            (2.0, 1.0, -0.937_548_254_315_843_8, 1.989_280_234_298_901),
            (
                2.5,
                7.3,
                -0.096_942_000_493_160_39,
                0.267_391_345_710_090_93,
            ),
            (1.5, 1.0, -3.932_239_737_431_101_6, 15.989_556_371_225_687),
            (3.0, 2.0, -0.198_126_242_885_636_85, 0.239_746_917_305_387_2),
            (
                19.5,
                1.0,
                -9.353_953_082_461_458e-7,
                6.485_896_800_551_832e-7,
            ),
            (1.05, 3.0, -399.592_903_170_232_94, 15_999.758_166_324_926),
        ] {
            let (z, d1, d2) = hurwitz_zeta_derivatives(s, q);
            assert!(close(z, hurwitz_zeta(s, q), 1e-14), "zeta({s}, {q})");
            assert!(
                close(d1, z1, 1e-13),
                "zeta'({s}, {q}) = {d1}, expected {z1}"
            );
            assert!(
                close(d2, z2, 1e-13),
                "zeta''({s}, {q}) = {d2}, expected {z2}"
            );
        }
    }

    #[test]
    fn discrete_mle_maximises_the_likelihood() {
        // The likelihood on a fine grid, written out directly, peaks where the fit says.
        let xs = {
            let mut v = zeta_samples(2.3, 3000, 5);
            v.sort_unstable_by(f64::total_cmp);
            v
        };
        for x_min in [1.0, 2.0, 4.0] {
            let tail: Vec<f64> = xs.iter().copied().filter(|&x| x >= x_min).collect();
            let n = tail.len() as f64;
            let sum_ln: f64 = tail.iter().map(|x| x.ln()).sum();
            let log_l = |a: f64| -n * hurwitz_zeta(a, x_min).ln() - a * sum_ln;
            let alpha = discrete_mle(x_min, sum_ln / n);
            let (mut best, mut best_l) = (1.0, f64::NEG_INFINITY);
            for i in 1..=19_000 {
                let a = 1.0 + i as f64 * 1e-3;
                let l = log_l(a);
                if l > best_l {
                    (best, best_l) = (a, l);
                }
            }
            assert!(
                (alpha - best).abs() <= 1e-3,
                "x_min {x_min}: {alpha} vs grid {best}"
            );
            assert!(log_l(alpha) >= best_l - 1e-9);
            assert!(log_l(alpha) >= log_l(alpha + 1e-5) && log_l(alpha) >= log_l(alpha - 1e-5));
        }
        // Every tail sample at x_min: the likelihood rises up to the cap.
        assert_eq!(discrete_mle(3.0, 3f64.ln()), ALPHA_MAX);
    }

    #[test]
    fn discrete_sampler_matches_rand_distr_zeta() {
        // The goodness-of-fit sampler at x_min = 1 against rand_distr's Zeta (an
        // independent rejection sampler): the frequencies of 1..=5, 6..=20 and > 20 agree
        // within 5 standard deviations.
        let n = 200_000;
        for alpha in [1.7, 2.5] {
            let law = DiscreteLaw::new(alpha, 1.0);
            let mut r = rng(11);
            let ours: Vec<f64> = (0..n).map(|_| law.draw(1.0 - r.random::<f64>())).collect();
            let theirs = zeta_samples(alpha, n, 12);
            let classes = |v: &[f64]| {
                let mut c = [0usize; 7];
                for &x in v {
                    assert!(x >= 1.0 && x.fract() == 0.0);
                    let i = if x <= 5.0 {
                        x as usize - 1
                    } else if x <= 20.0 {
                        5
                    } else {
                        6
                    };
                    c[i] += 1;
                }
                c
            };
            let (a, b) = (classes(&ours), classes(&theirs));
            for i in 0..7 {
                let (pa, pb) = (a[i] as f64 / n as f64, b[i] as f64 / n as f64);
                let sigma = ((pa * (1.0 - pa) + pb * (1.0 - pb)) / n as f64).sqrt();
                assert!(
                    (pa - pb).abs() < 5.0 * sigma,
                    "alpha {alpha}, class {i}: {pa} vs {pb}"
                );
            }
        }
        // Far in the tail (beyond the table) the draw inverts the survival function.
        let law = DiscreteLaw::new(2.0, 3.0);
        for u in [0.5, 1e-3, 1e-6, 1e-9] {
            let x = law.draw(u);
            assert!(
                law.survival(x + 1.0) <= u && (x == 3.0 || law.survival(x) > u),
                "{u}"
            );
        }
        assert_eq!(law.draw(1.0), 3.0);
    }

    #[test]
    fn continuous_fits_cover_the_true_exponent() {
        let options = PowerLawOptions::default()
            .confidence(0.9)
            .bootstrap(50)
            .goodness_samples(0);
        let (sets, mut covered) = (40usize, 0);
        for seed in 0..sets {
            let xs = pareto(2.5, 1.0, 2000, 100 + seed as u64);
            let fit = fit_power_law(&xs, Support::Continuous, &options).unwrap();
            assert!(
                (fit.alpha - 2.5).abs() < 4.0 * fit.alpha_std_error,
                "seed {seed}: {fit:?}"
            );
            assert!(fit.p_value.is_none() && fit.samples == 2000);
            assert!(fit.alpha_low <= fit.alpha_high && fit.x_min_low <= fit.x_min_high);
            covered += usize::from(fit.alpha_low <= 2.5 && 2.5 <= fit.alpha_high);
        }
        assert!(
            covered >= 30,
            "{covered} of {sets} intervals hold alpha = 2.5"
        );
    }

    #[test]
    fn discrete_fits_cover_the_true_exponent() {
        let options = PowerLawOptions::default()
            .confidence(0.9)
            .bootstrap(50)
            .goodness_samples(0);
        for alpha in [2.0, 2.7] {
            let (sets, mut covered, mut small_x_min) = (40usize, 0, 0);
            for seed in 0..sets {
                let xs = zeta_samples(alpha, 2000, 200 + seed as u64);
                let fit = fit_power_law(&xs, Support::Discrete, &options).unwrap();
                assert!(
                    (fit.alpha - alpha).abs() < 4.0 * fit.alpha_std_error,
                    "alpha {alpha}, seed {seed}: {fit:?}"
                );
                covered += usize::from(fit.alpha_low <= alpha && alpha <= fit.alpha_high);
                small_x_min += usize::from(fit.x_min <= 3.0);
            }
            assert!(
                covered * 4 >= sets * 3,
                "alpha {alpha}: {covered} of {sets} cover"
            );
            assert!(
                small_x_min * 10 >= sets * 8,
                "alpha {alpha}: x_min <= 3 in {small_x_min}"
            );
        }
    }

    /// Clauset's test has little power when the tail may shrink to a few dozen samples
    /// (the far tail of an exponential is locally a steep power law), so both kinds of
    /// data are tested for a power law over at least a quarter of the samples.
    #[test]
    fn goodness_of_fit_accepts_power_laws_and_rejects_exponentials() {
        let options = PowerLawOptions::default()
            .bootstrap(0)
            .goodness_samples(50)
            .min_tail(500);
        let exp = Exp::new(1.0f64).unwrap();
        let sets = 20;
        let (mut accepted, mut rejected) = ([0usize; 2], [0usize; 2]);
        for seed in 0..sets {
            let mut r = rng(300 + seed);
            let power = [
                (pareto(2.5, 1.0, 2000, 400 + seed), Support::Continuous),
                (zeta_samples(2.0, 2000, 500 + seed), Support::Discrete),
            ];
            let exponential = [
                // Force drops of 1 mN on average; sizes of 10 ruptures on average.
                (
                    (0..2000)
                        .map(|_| 1e-3 * exp.sample(&mut r))
                        .collect::<Vec<_>>(),
                    Support::Continuous,
                ),
                (
                    (0..2000)
                        .map(|_| (10.0 * exp.sample(&mut r)).ceil())
                        .collect(),
                    Support::Discrete,
                ),
            ];
            for (i, (xs, support)) in power.iter().enumerate() {
                let p = fit_power_law(xs, *support, &options)
                    .unwrap()
                    .p_value
                    .unwrap();
                assert!((0.0..=1.0).contains(&p));
                accepted[i] += usize::from(p > 0.05);
            }
            for (i, (xs, support)) in exponential.iter().enumerate() {
                let p = fit_power_law(xs, *support, &options)
                    .unwrap()
                    .p_value
                    .unwrap();
                rejected[i] += usize::from(p < 0.1);
            }
        }
        for i in 0..2 {
            assert!(
                accepted[i] >= 16,
                "power laws accepted: {accepted:?} of {sets}"
            );
            assert!(
                rejected[i] >= 16,
                "exponentials rejected: {rejected:?} of {sets}"
            );
        }
    }

    #[test]
    fn the_start_of_a_power_law_tail_is_found_in_a_mixture() {
        // A quarter of the samples uniform on [1, 10), the rest a power law (alpha 2.5)
        // above 10.
        let options = PowerLawOptions::default().bootstrap(0).goodness_samples(0);
        let (sets, mut found) = (30, 0);
        for seed in 0..sets {
            let mut r = rng(600 + seed);
            let mut xs = pareto(2.5, 10.0, 1500, 700 + seed);
            xs.extend((0..500).map(|_| 1.0 + 9.0 * r.random::<f64>()));
            let fit = fit_power_law(&xs, Support::Continuous, &options).unwrap();
            found += usize::from((7.0..=14.0).contains(&fit.x_min));
            assert!(fit.tail < 2000);
        }
        assert!(found >= 22, "x_min in [7, 14] in {found} of {sets} sets");
    }

    #[test]
    fn the_search_minimises_an_independently_computed_ks_distance() {
        // 100 samples: every candidate is tried (tails up to 100 are never thinned), so
        // the search is exhaustive and can be redone by brute force.
        let options = PowerLawOptions::default()
            .bootstrap(0)
            .goodness_samples(0)
            .min_tail(5);
        for seed in 0..4 {
            // Continuous: D over both sides of each sample of the tail.
            let mut xs = pareto(2.2, 1.0, 100, 800 + seed);
            let fit = fit_power_law(&xs, Support::Continuous, &options).unwrap();
            xs.sort_unstable_by(f64::total_cmp);
            let brute = |x_min: f64| {
                let tail: Vec<f64> = xs.iter().copied().filter(|&x| x >= x_min).collect();
                let t = tail.len() as f64;
                let alpha = 1.0 + t / tail.iter().map(|x| (x / x_min).ln()).sum::<f64>();
                let d = tail
                    .iter()
                    .enumerate()
                    .map(|(i, x)| {
                        let p = 1.0 - (x / x_min).powf(1.0 - alpha);
                        (i as f64 / t - p).abs().max(((i + 1) as f64 / t - p).abs())
                    })
                    .fold(0.0, f64::max);
                (alpha, d)
            };
            let (alpha, d) = brute(fit.x_min);
            assert!(close(fit.alpha, alpha, 1e-12) && (fit.ks_distance - d).abs() < 1e-12);
            for &x in &xs[..xs.len() - 5] {
                assert!(brute(x).1 >= d - 1e-12, "x_min {x} beats {}", fit.x_min);
            }

            // Discrete: D over every integer from x_min to the largest sample.
            let mut ks = zeta_samples(2.2, 100, 900 + seed);
            let fit = fit_power_law(&ks, Support::Discrete, &options).unwrap();
            ks.sort_unstable_by(f64::total_cmp);
            let brute = |x_min: f64, alpha: f64| {
                let tail: Vec<f64> = ks.iter().copied().filter(|&x| x >= x_min).collect();
                let t = tail.len() as f64;
                let norm = hurwitz_zeta(alpha, x_min);
                let (mut d, mut x, mut below) = (0.0f64, x_min, 0usize);
                while x <= tail[tail.len() - 1] {
                    below += tail.iter().filter(|&&y| y == x).count();
                    let p = 1.0 - hurwitz_zeta(alpha, x + 1.0) / norm;
                    d = d.max((below as f64 / t - p).abs());
                    x += 1.0;
                }
                d
            };
            let d = brute(fit.x_min, fit.alpha);
            assert!(
                (fit.ks_distance - d).abs() < 1e-12,
                "{} vs {d}",
                fit.ks_distance
            );
            let mut values = ks.clone();
            values.dedup();
            for &x in &values {
                let tail: Vec<f64> = ks.iter().copied().filter(|&y| y >= x).collect();
                if tail.len() < 5 || tail[0] == tail[tail.len() - 1] {
                    continue;
                }
                let m = tail.iter().map(|y| y.ln()).sum::<f64>() / tail.len() as f64;
                assert!(brute(x, discrete_mle(x, m)) >= d - 1e-12, "x_min {x}");
            }
        }
    }

    #[test]
    fn bad_samples_give_typed_errors() {
        let good = pareto(2.5, 1.0, 50, 1);
        let options = PowerLawOptions::default().bootstrap(0).goodness_samples(0);
        let fit = |xs: &[f64], support, o: &PowerLawOptions| fit_power_law(xs, support, o);
        let mut bad = good.clone();
        bad[7] = f64::NAN;
        let e = fit(&bad, Support::Continuous, &options).unwrap_err();
        assert!(
            matches!(e, Error::InvalidParameter { name: "samples", value, .. } if value.is_nan())
        );
        bad[7] = f64::NEG_INFINITY;
        let e = log_binned(&bad, Support::Continuous, 5).unwrap_err();
        assert!(
            matches!(e, Error::InvalidParameter { name: "samples", value, .. } if value == f64::NEG_INFINITY)
        );
        let e = fit(
            &[1.0, 2.0, 2.5, 3.0],
            Support::Discrete,
            &options.clone().min_tail(2),
        );
        assert!(matches!(
            e,
            Err(Error::InvalidParameter {
                name: "samples",
                value: 2.5,
                ..
            })
        ));
        let e = log_binned(&[1.0, 2.5], Support::Discrete, 5).unwrap_err();
        assert!(matches!(
            e,
            Error::InvalidParameter {
                name: "samples",
                value: 2.5,
                ..
            }
        ));
        let e = fit(&[3.0; 20], Support::Discrete, &options).unwrap_err();
        assert!(matches!(
            e,
            Error::InvalidParameter {
                name: "samples",
                value: 3.0,
                ..
            }
        ));
        let huge = [1.0, 2.0, 3.0, 1e16];
        let e = fit(&huge, Support::Discrete, &options.clone().min_tail(2)).unwrap_err();
        assert!(
            matches!(e, Error::InvalidParameter { name: "samples", value, .. } if value == 1e16)
        );
    }

    #[test]
    fn bad_fit_options_give_typed_errors() {
        let good = pareto(2.5, 1.0, 50, 1);
        let options = PowerLawOptions::default().bootstrap(0).goodness_samples(0);
        let fit = |xs: &[f64], support, o: &PowerLawOptions| fit_power_law(xs, support, o);
        // 9 positive samples (the zero and the negative one do not count) for min_tail 10.
        let few = [0.0, -1.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
        let e = fit(&few, Support::Discrete, &options).unwrap_err();
        assert!(matches!(
            e,
            Error::TooFewSamples {
                what: "power-law fit",
                count: 9,
                needed: 10
            }
        ));
        assert!(fit(&few, Support::Discrete, &options.clone().min_tail(9)).is_ok());
        for c in [0.0, 1.0, f64::NAN, -0.5, 1.5] {
            let e = fit(&good, Support::Continuous, &options.clone().confidence(c)).unwrap_err();
            assert!(
                matches!(
                    e,
                    Error::InvalidParameter {
                        name: "confidence",
                        ..
                    }
                ),
                "{c}"
            );
        }
        for m in [0, 1] {
            let e = fit(&good, Support::Continuous, &options.clone().min_tail(m)).unwrap_err();
            assert!(
                matches!(e, Error::InvalidCount { name: "min_tail", value, .. } if value == m as u64)
            );
        }
    }

    #[test]
    fn bad_bin_counts_give_typed_errors() {
        let good = pareto(2.5, 1.0, 50, 1);
        let e = log_binned(&good, Support::Continuous, 0).unwrap_err();
        assert!(matches!(
            e,
            Error::InvalidCount {
                name: "bins_per_decade",
                value: 0,
                ..
            }
        ));
        let e = log_binned(&[1e-300, 1e300], Support::Continuous, 10_000).unwrap_err();
        assert!(matches!(
            e,
            Error::InvalidCount {
                name: "bins_per_decade",
                value: 10_000,
                ..
            }
        ));
        assert_eq!(log_binned(&[0.0, -2.0], Support::Discrete, 3).unwrap(), []);
        let e = log_binned(&[1.0, 2.0], Support::Continuous, 2_000_000).unwrap_err();
        assert!(matches!(
            e,
            Error::InvalidCount {
                name: "bins_per_decade",
                ..
            }
        ));
    }

    #[test]
    fn extreme_samples_give_finite_results_or_errors() {
        let options = PowerLawOptions::default()
            .bootstrap(10)
            .goodness_samples(10)
            .min_tail(2);
        let finite = |f: &PowerLawFit| {
            [
                f.x_min,
                f.alpha,
                f.alpha_std_error,
                f.alpha_low,
                f.alpha_high,
            ]
            .iter()
            .chain(&[f.x_min_low, f.x_min_high, f.ks_distance, f.p_value.unwrap()])
            .all(|v| v.is_finite())
        };
        // Integers near 2^53, a steep law on them, and a heavy one (draws capped at 2^53).
        let big = 9_007_199_254_740_000.0;
        for xs in [
            vec![big, big, big + 1.0, big + 2.0, big + 900.0],
            vec![1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0],
            vec![1.0, 1e3, 1e6, 1e9, 1e12, 1e15],
        ] {
            let fit = fit_power_law(&xs, Support::Discrete, &options).unwrap();
            assert!(finite(&fit), "{fit:?}");
            let fit = fit_power_law(&xs, Support::Continuous, &options).unwrap();
            assert!(finite(&fit), "{fit:?}");
        }
        // Continuous samples over the whole float range, and adjacent floats whose
        // logarithms are equal (no exponent: an error, not a NaN).
        let wide = [5e-324, 1e-300, 1e-100, 1.0, 1e100, 1e300, f64::MAX];
        let fit = fit_power_law(&wide, Support::Continuous, &options).unwrap();
        assert!(finite(&fit), "{fit:?}");
        let x = 1e300f64;
        let close_pair = [x, x, x.next_up(), x.next_up()];
        let e = fit_power_law(&close_pair, Support::Continuous, &options).unwrap_err();
        assert!(matches!(
            e,
            Error::InvalidParameter {
                name: "samples",
                ..
            }
        ));
        for support in [Support::Continuous, Support::Discrete] {
            for per_decade in [1, 7, 1000] {
                let xs: &[f64] = match support {
                    Support::Continuous => &wide,
                    Support::Discrete => &[1.0, 2.0, 9e15],
                };
                let bins = log_binned(xs, support, per_decade).unwrap();
                assert_eq!(bins.iter().map(|b| b.count).sum::<usize>(), xs.len());
                assert!(bins.iter().all(|b| [b.low, b.high, b.center, b.density]
                    .iter()
                    .all(|v| v.is_finite())));
            }
        }
    }

    #[test]
    fn alternatives_of_extreme_samples_are_never_nan() {
        let options = PowerLawOptions::default()
            .bootstrap(5)
            .goodness_samples(0)
            .min_tail(2);
        let big = 9_007_199_254_740_000.0;
        let counts = [
            vec![big, big, big + 1.0, big + 2.0, big + 900.0],
            vec![1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0],
            vec![1.0, 1e3, 1e6, 1e9, 1e12, 1e15],
        ];
        let reals = [
            vec![1e-3, 1e-3, 2e-3, 1.0],
            vec![1e-100, 1e-50, 1.0, 1e50, 1e100],
        ];
        let cases = counts.iter().map(|x| (x, Support::Discrete)).chain(
            counts
                .iter()
                .chain(&reals)
                .map(|x| (x, Support::Continuous)),
        );
        for (xs, support) in cases {
            let c = compare_alternatives(xs, support, &options).unwrap();
            let k = &c.cutoff;
            let values = [
                c.power_law_log_likelihood,
                k.alpha,
                k.lambda,
                k.cutoff,
                k.alpha_low,
                k.alpha_high,
                k.cutoff_low,
                k.cutoff_high,
                k.log_likelihood,
                c.exponential.lambda,
                c.exponential.log_likelihood,
                c.lognormal.mu,
                c.lognormal.sigma,
                c.lognormal.log_likelihood,
            ];
            assert!(values.iter().all(|v| !v.is_nan()), "{xs:?}: {c:?}");
            for lr in [
                &c.vs_exponential,
                &c.vs_lognormal,
                &c.vs_cutoff,
                &c.cutoff_vs_lognormal,
            ] {
                assert!(
                    !lr.log_ratio.is_nan() && !lr.normalized.is_nan(),
                    "{xs:?}: {lr:?}"
                );
                assert!((0.0..=1.0).contains(&lr.p_value), "{xs:?}: {lr:?}");
            }
            assert!(!c.verdict().contains("NaN"));
        }
        // Beyond f64's range (x_min 1e-300 under 1e300): a typed error, not a NaN.
        let wide = [1e-300, 1e-300, 1e300, 1e300];
        let e = compare_alternatives(&wide, Support::Continuous, &options).unwrap_err();
        assert!(matches!(
            e,
            Error::InvalidParameter {
                name: "samples",
                ..
            }
        ));
    }

    /// The search as it was before runs, blocks and probes (issue 54 item 5): every
    /// candidate of the 1 % grid with `α` from a compensated sum of `ln x` sample by
    /// sample and `D` from a plain pass over all its runs, no early stop. The reference
    /// of [`the_fast_search_equals_the_plain_scan`].
    fn plain_search(xs: &[f64], support: Support, min_tail: usize) -> (f64, f64, f64) {
        let n = xs.len();
        let mut suffix = vec![(0.0, 0.0); n + 1];
        for i in (0..n).rev() {
            let (hi, lo) = suffix[i + 1];
            let (sum, err) = two_sum(hi, xs[i].ln());
            suffix[i] = (sum, lo + err);
        }
        let mut starts: Vec<usize> = (0..n).filter(|&i| i == 0 || xs[i - 1] != xs[i]).collect();
        starts.push(n);
        let (mut best, mut last) = ((f64::NAN, f64::NAN, f64::INFINITY), None::<usize>);
        for g in 0..starts.len() - 2 {
            let (start, tail) = (starts[g], n - starts[g]);
            if tail < min_tail {
                break;
            }
            if last.is_some_and(|l| tail * 100 > l * 99) {
                continue;
            }
            last = Some(tail);
            let (t, x_min) = (tail as f64, xs[start]);
            let (alpha, cdf): (f64, Box<dyn Fn(f64) -> f64>) = match support {
                Support::Continuous => {
                    let (hi, lo) = suffix[start];
                    let product = t * x_min.ln();
                    let sum = (hi - product) + (lo - t.mul_add(x_min.ln(), -product));
                    let alpha = 1.0 + t / sum;
                    (
                        alpha,
                        Box::new(move |x: f64| -((1.0 - alpha) * (x.ln() - x_min.ln())).exp_m1()),
                    )
                }
                _ => {
                    let alpha = discrete_mle(x_min, (suffix[start].0 + suffix[start].1) / t);
                    let norm = hurwitz_zeta(alpha, x_min);
                    (
                        alpha,
                        Box::new(move |x: f64| 1.0 - hurwitz_zeta(alpha, x + 1.0) / norm),
                    )
                }
            };
            let mut d = 0.0f64;
            for w in starts[g..].windows(2) {
                let (below, at) = ((w[0] - start) as f64 / t, (w[1] - start) as f64 / t);
                let x = xs[w[0]];
                match support {
                    Support::Continuous => {
                        let p = cdf(x);
                        d = d.max((below - p).abs()).max((at - p).abs());
                    }
                    _ => {
                        d = d.max((at - cdf(x)).abs());
                        if w[1] < n && xs[w[1]] > x + 1.0 {
                            d = d.max((at - cdf(xs[w[1]] - 1.0)).abs());
                        }
                    }
                }
            }
            if d < best.2 {
                best = (x_min, alpha, d);
            }
        }
        best
    }

    #[test]
    fn the_fast_search_equals_the_plain_scan() {
        // 30 000 samples: tails of many thousand runs, so the blocked passes and the
        // probes are used; reals rounded to 4 digits in part, so runs of equal samples
        // occur in both supports.
        for seed in 0..3 {
            let mut reals: Vec<f64> = pareto(2.4, 1.0, 24_000, 40 + seed);
            reals.extend((0..6_000).map(|i| 0.5 + (i as f64 * 0.618_034).fract() * 0.5));
            for x in reals.iter_mut().step_by(3) {
                *x = (*x * 1e4).round() / 1e4;
            }
            let mut counts = zeta_samples(2.1, 30_000, 50 + seed);
            for (support, xs) in [
                (Support::Continuous, &mut reals),
                (Support::Discrete, &mut counts),
            ] {
                xs.sort_unstable_by(f64::total_cmp);
                let (x_min, alpha, d) = plain_search(xs, support, 10);
                let fit =
                    fit_runs(&Runs::from_sorted(xs), support, 10, &mut Scratch::default()).unwrap();
                assert_eq!(fit.x_min, x_min, "{support:?} {seed}");
                // Counts of equal samples enter the sums as products (exact by fma)
                // rather than one by one: equal within rounding.
                assert!(close(fit.alpha, alpha, 1e-13), "{} vs {alpha}", fit.alpha);
                assert!((fit.ks - d).abs() < 1e-13, "{} vs {d}", fit.ks);
            }
        }
    }

    #[test]
    fn results_do_not_depend_on_the_threads() {
        let options = PowerLawOptions::default()
            .bootstrap(12)
            .goodness_samples(12)
            .seed(9);
        let xs = pareto(2.5, 1.0, 3000, 60);
        let ks = zeta_samples(2.3, 3000, 61);
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                (
                    compare_alternatives(&xs, Support::Continuous, &options).unwrap(),
                    compare_alternatives(&ks, Support::Discrete, &options).unwrap(),
                )
            })
        };
        let one = run(1);
        for threads in [2, 3] {
            // Debug prints the shortest round-tripping decimal: equal text, equal bits.
            assert_eq!(format!("{:?}", run(threads)), format!("{one:?}"));
        }
    }

    #[test]
    fn sorted_draws_follow_the_law() {
        // Discrete: the walk up the table draws what the bisection draws, for falling u.
        let law = DiscreteLaw::new(2.2, 3.0);
        let mut us: Vec<f64> = (1..5000).map(|i| (i as f64 / 5000.0).powi(3)).collect();
        us.reverse();
        let mut step = 0;
        for &u in &us {
            assert_eq!(law.draw_from(u, &mut step), law.draw(u), "u = {u}");
        }
        // Both: sorted, above x_min; the pooled continuous draws of five sets pass a
        // Kolmogorov–Smirnov test against the law (critical value at 1e-3: 1.95/√n).
        let fit = |x_min: f64| TailFit {
            x_min,
            alpha: 2.5,
            tail: 0,
            ks: 0.0,
            start: 0,
            run: 0,
        };
        let mut pooled = Vec::new();
        for seed in 0..5 {
            let mut r = rng(seed);
            let mut spacings = Vec::new();
            for (law, x_min) in [(None, 1.0), (Some(DiscreteLaw::new(2.5, 2.0)), 2.0)] {
                let mut set = Runs::default();
                sorted_draws(
                    4000,
                    &fit(x_min),
                    law.as_ref(),
                    &mut r,
                    &mut spacings,
                    &mut set,
                );
                assert_eq!(set.samples(), 4000);
                assert!(set.values.windows(2).all(|w| w[0] < w[1]) && set.values[0] >= x_min);
                if law.is_none() {
                    pooled.extend(set.values.iter().copied());
                }
            }
        }
        pooled.sort_unstable_by(f64::total_cmp);
        let n = pooled.len() as f64;
        let d = pooled
            .iter()
            .enumerate()
            .map(|(i, x)| {
                let p = 1.0 - x.powf(-1.5);
                (i as f64 / n - p).abs().max(((i + 1) as f64 / n - p).abs())
            })
            .fold(0.0, f64::max);
        assert!(d < 1.95 / n.sqrt(), "D = {d}");
    }

    #[test]
    fn results_depend_on_the_samples_not_their_order() {
        let options = PowerLawOptions::default()
            .bootstrap(30)
            .goodness_samples(30)
            .seed(3);
        let mut r = rng(17);
        for support in [Support::Continuous, Support::Discrete] {
            let mut xs = match support {
                Support::Continuous => pareto(2.2, 0.5, 800, 18),
                Support::Discrete => zeta_samples(2.2, 800, 19),
            };
            xs.extend([0.0, -1.0, 0.0]); // dropped
            let fit = fit_power_law(&xs, support, &options).unwrap();
            assert_eq!(fit.samples, 800);
            for _ in 0..3 {
                for i in (1..xs.len()).rev() {
                    xs.swap(i, r.random_range(0..=i));
                }
                let again = fit_power_law(&xs, support, &options).unwrap();
                // Debug prints the shortest round-tripping decimal: equal text, equal bits.
                assert_eq!(format!("{again:?}"), format!("{fit:?}"));
                assert_eq!(again.alpha_low.to_bits(), fit.alpha_low.to_bits());
            }
            // Another seed, another bootstrap: the seed is used.
            let other = fit_power_law(&xs, support, &options.clone().seed(4)).unwrap();
            assert_eq!(other.alpha.to_bits(), fit.alpha.to_bits());
            assert_ne!(
                (other.alpha_low, other.alpha_high),
                (fit.alpha_low, fit.alpha_high)
            );
        }
    }

    #[test]
    fn log_bins_count_every_sample_and_follow_the_slope() {
        // Zeta(2) sizes: P(k) ∝ k^-2, the binned densities fall with slope -2.
        let mut xs = zeta_samples(2.0, 100_000, 21);
        xs.extend([0.0, 0.0]); // dropped
        let n = 100_000.0;
        let bins = log_binned(&xs, Support::Discrete, 5).unwrap();
        assert_eq!(bins.iter().map(|b| b.count).sum::<usize>(), 100_000);
        let mass: f64 = bins.iter().map(|b| b.density * (b.high - b.low) * n).sum();
        assert!(close(mass, n, 1e-12), "{mass}");
        for pair in bins.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            assert!(a.low.fract() == 0.0 && a.high.fract() == 0.0 && a.low < a.high);
            assert!(a.high <= b.low, "overlap: {a:?} {b:?}");
        }
        assert_eq!(bins[0].low, 1.0);
        let largest = xs.iter().copied().fold(0.0, f64::max);
        let last = &bins[bins.len() - 1];
        assert!(last.low <= largest && largest < last.high && last.count >= 1);
        // Least-squares slope of ln P against ln center over well-filled bins (100 samples
        // or more) from 10 up: in narrower bins the centre misplaces the density (the mass
        // of [1, 2) sits at 1, not at √2), which steepens the expected slope to -2.11 with
        // them, -2.03 without.
        let points: Vec<(f64, f64)> = bins
            .iter()
            .filter(|b| b.count >= 100 && b.low >= 10.0)
            .map(|b| (b.center.ln(), b.density.ln()))
            .collect();
        assert!(points.len() >= 6, "{} well-filled bins", points.len());
        let m = points.len() as f64;
        let (mx, my) = points
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / m, b + y / m));
        let sxy: f64 = points.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
        let sxx: f64 = points.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
        let slope = sxy / sxx;
        assert!((slope + 2.0).abs() < 0.1, "slope {slope}");

        // Continuous: edges x0 · 10^(k/b) from the smallest sample, empty bins listed.
        let drops = [2e-3, 3e-3, 2.5, 0.0];
        let bins = log_binned(&drops, Support::Continuous, 1).unwrap();
        let counts: Vec<usize> = bins.iter().map(|b| b.count).collect();
        assert_eq!(counts, [2, 0, 0, 1]);
        assert!(close(bins[1].low, 2e-2, 1e-15) && close(bins[3].high, 20.0, 1e-15));
        assert_eq!((bins[1].density, bins[2].density), (0.0, 0.0));
        assert!(close(bins[0].center, 2e-3 * 10f64.sqrt(), 1e-15));
        let mass: f64 = bins
            .iter()
            .map(|b| b.density * (b.high - b.low) * 3.0)
            .sum();
        assert!(close(mass, 3.0, 1e-12));
        // Discrete bins of no integer are left out: 1, 1.26, 1.58, 2.00, 2.51, 3.16, 3.98,
        // 5.01, 6.31, 7.94, 10 round up to 1, 2, 2, 2, 3, 4, 4, 6, 7, 8, 10.
        let bins = log_binned(&[1.0, 2.0, 3.0, 9.0], Support::Discrete, 10).unwrap();
        let lows: Vec<f64> = bins.iter().map(|b| b.low).collect();
        assert_eq!(lows, [1.0, 2.0, 3.0, 4.0, 6.0, 7.0, 8.0]);
        assert_eq!(bins[bins.len() - 1].high, 10.0);
    }
}
