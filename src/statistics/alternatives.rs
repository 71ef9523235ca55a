//! The alternatives to a power law (Clauset, Shalizi and Newman 2009, section 5): the
//! exponential, the log-normal and the power law with exponential cut-off, each fitted by
//! maximum likelihood on the power law's tail `x ≥ x_min`, and the likelihood-ratio tests
//! between them.

use super::special::{chi2_one_survival_of_twice, ln_erfcx, ln_expint, normal_two_sided};
use super::{hurwitz_zeta, Runs, Support, TailFit, ALPHA_MAX};

/// The tail `x ≥ x_min` of samples as its distinct values and their counts, with
/// the means the continuous likelihoods need (`t = x / x_min`, `y = ln t`).
pub(super) struct Tail {
    pub support: Support,
    pub x_min: f64,
    pub n: usize,
    /// Distinct values, ascending, and how often each occurs.
    pub values: Vec<(f64, usize)>,
    /// `⟨ln(x / x_min)⟩`.
    pub mean_y: f64,
    /// `⟨ln²(x / x_min)⟩`.
    pub mean_y2: f64,
    /// `⟨x / x_min - 1⟩`.
    pub mean_t1: f64,
    /// The power law's exponent on this tail.
    pub alpha: f64,
}

impl Tail {
    pub(super) fn new(runs: &Runs, fit: &TailFit, support: Support) -> Self {
        let x_min = fit.x_min;
        let n = runs.samples() - fit.start;
        let values: Vec<(f64, usize)> = (fit.run..runs.len())
            .map(|g| (runs.values[g], runs.starts[g + 1] - runs.starts[g]))
            .collect();
        let (mut sy, mut sy2, mut st) = (0.0, 0.0, 0.0);
        for &(x, c) in &values {
            let y = ln_ratio(x, x_min);
            let c = c as f64;
            sy += c * y;
            sy2 += c * y * y;
            st += c * ((x - x_min) / x_min);
        }
        let nf = n as f64;
        Self {
            support,
            x_min,
            n,
            values,
            mean_y: sy / nf,
            mean_y2: sy2 / nf,
            mean_t1: st / nf,
            alpha: fit.alpha,
        }
    }

    /// Whether the means the likelihoods need are finite (`x / x_min` can overflow for
    /// samples spanning more than f64's range).
    pub(super) fn is_finite(&self) -> bool {
        self.mean_y.is_finite() && self.mean_y2.is_finite() && self.mean_t1.is_finite()
    }
}

/// `ln(x / x_min)`, also where the quotient overflows.
fn ln_ratio(x: f64, x_min: f64) -> f64 {
    let r = x / x_min;
    if r.is_finite() {
        r.ln()
    } else {
        x.ln() - x_min.ln()
    }
}

/// Minimises `f` over the box `[lo, hi]` by Nelder–Mead (reflection 1, expansion 2,
/// contraction and shrink 1/2; trial points clamped into the box), restarted from the best
/// point with the initial steps until a restart improves by no more than `F_TOL`. A run
/// stops when the simplex's values agree within `F_TOL` and its points within `X_TOL` in
/// each coordinate, or after 2000 steps. NaN counts as `+∞`.
pub(super) fn nelder_mead(
    mut f: impl FnMut([f64; 2]) -> f64,
    start: [f64; 2],
    step: [f64; 2],
    lo: [f64; 2],
    hi: [f64; 2],
) -> ([f64; 2], f64) {
    /// Absolute, on a log-likelihood per sample: a ratio of `n` samples to `n · 1e-13`.
    const F_TOL: f64 = 1e-13;
    const X_TOL: f64 = 1e-9;
    let clamp = |x: [f64; 2]| [x[0].clamp(lo[0], hi[0]), x[1].clamp(lo[1], hi[1])];
    let mut eval = |x: [f64; 2]| {
        let v = f(x);
        if v.is_nan() {
            f64::INFINITY
        } else {
            v
        }
    };
    let x0 = clamp(start);
    let mut best = (x0, eval(x0));
    for restart in 0..10 {
        let x0 = best.0;
        let mut s = [best; 3];
        for (k, point) in s.iter_mut().enumerate().skip(1) {
            let mut x = x0;
            x[k - 1] += step[k - 1];
            if clamp(x) == x0 {
                x[k - 1] = x0[k - 1] - step[k - 1]; // at the upper bound: step down
            }
            let x = clamp(x);
            *point = (x, eval(x));
        }
        for _ in 0..2000 {
            s.sort_by(|a, b| a.1.total_cmp(&b.1));
            let spread = |i: usize| {
                let v = [s[0].0[i], s[1].0[i], s[2].0[i]];
                v.iter().fold(f64::NEG_INFINITY, |m, &x| m.max(x))
                    - v.iter().fold(f64::INFINITY, |m, &x| m.min(x))
            };
            if (s[2].1 - s[0].1).abs() <= F_TOL && spread(0) <= X_TOL && spread(1) <= X_TOL {
                break;
            }
            let c = [0.5 * (s[0].0[0] + s[1].0[0]), 0.5 * (s[0].0[1] + s[1].0[1])];
            let along =
                |t: f64| clamp([c[0] + t * (s[2].0[0] - c[0]), c[1] + t * (s[2].0[1] - c[1])]);
            let xr = along(-1.0);
            let fr = eval(xr);
            if fr < s[0].1 {
                let xe = along(-2.0);
                let fe = eval(xe);
                s[2] = if fe < fr { (xe, fe) } else { (xr, fr) };
            } else if fr < s[1].1 {
                s[2] = (xr, fr);
            } else {
                let xc = if fr < s[2].1 { along(-0.5) } else { along(0.5) };
                let fc = eval(xc);
                if fc < fr.min(s[2].1) {
                    s[2] = (xc, fc);
                } else {
                    let b = s[0].0;
                    for point in s.iter_mut().skip(1) {
                        let x = [0.5 * (b[0] + point.0[0]), 0.5 * (b[1] + point.0[1])];
                        *point = (x, eval(x));
                    }
                }
            }
        }
        s.sort_by(|a, b| a.1.total_cmp(&b.1));
        let improved = best.1 - s[0].1;
        if s[0].1 <= best.1 {
            best = s[0];
        }
        if restart > 0 && (improved.is_nan() || improved <= F_TOL) {
            break;
        }
    }
    best
}

/// The minimum of a unimodal `f` on `[lo, hi]` by golden-section search, to 1e-12
/// relative in `x`: `(x, f(x))`.
fn golden_section(f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> (f64, f64) {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (lo, hi);
    let mut c = b - r * (b - a);
    let mut d = a + r * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    while b - a > 1e-12 * (a.abs() + b.abs()) {
        if fc.total_cmp(&fd).is_le() {
            (b, d, fd) = (d, c, fc);
            c = b - r * (b - a);
            fc = f(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + r * (b - a);
            fd = f(d);
        }
    }
    let x = 0.5 * (a + b);
    (x, f(x))
}

/// The power law's log-density at each value of the tail (samples' unit).
fn power_law_ln_pdf(tail: &Tail, alpha: f64) -> impl Fn(f64) -> f64 + '_ {
    let norm = match tail.support {
        Support::Discrete => hurwitz_zeta(alpha, tail.x_min).ln(),
        _ => tail.x_min.ln() - (alpha - 1.0).ln(),
    };
    move |x| match tail.support {
        Support::Discrete => -alpha * x.ln() - norm,
        _ => -alpha * (x / tail.x_min).ln() - norm,
    }
}

/// The exponential on the tail: `p(x) = λ e^(-λ(x - x_min))` for reals, `P(k) = (1 -
/// e^(-λ)) e^(-λ(k - x_min))` for integers (Clauset et al. table 2.1); both maximum
/// likelihood in closed form (`λ = 1/⟨x - x_min⟩`, `λ = ln(1 + 1/⟨k - x_min⟩)`).
fn exponential(tail: &Tail) -> (f64, impl Fn(f64) -> f64 + '_) {
    let mean = tail.mean_t1 * tail.x_min; // ⟨x - x_min⟩ > 0: the tail holds two values
    let lambda = match tail.support {
        Support::Discrete => (1.0 / mean).ln_1p(),
        _ => 1.0 / mean,
    };
    let head = match tail.support {
        Support::Discrete => (-(-lambda).exp_m1()).ln(),
        _ => lambda.ln(),
    };
    (lambda, move |x| head - lambda * (x - tail.x_min))
}

/// The log-normal's parameters as fitted: `y = ln(x / x_ref)` is a normal variate
/// truncated to `y ≥ 0`, written `∝ e^(-β y - γ y²)` (natural parameters: the
/// likelihood is concave in them, and `γ → 0` is the power law `α = 1 + β`). `x_ref` is
/// `x_min` for reals, `x_min - 1/2` for integers.
#[derive(Clone, Copy)]
struct LogNormal {
    beta: f64,
    gamma: f64,
    ln_ref: f64,
}

impl LogNormal {
    /// `ln ∫_y^∞ e^(-β u - γ u²) du`.
    fn ln_w(&self, y: f64) -> f64 {
        let (b, g) = (self.beta, self.gamma);
        let sg = g.sqrt();
        let a = sg * y + b / (2.0 * sg);
        let ln_h = if a > 1e8 {
            // ½√(π/γ) erfcx(a) → 1/(2γy + β) (1 - 1/(2a²)): exact where a overflows a².
            -(2.0 * g * y + b).ln() + (-0.5 / (a * a)).ln_1p()
        } else {
            (0.5 * (std::f64::consts::PI / g).sqrt()).ln() + ln_erfcx(a)
        };
        -b * y - g * y * y + ln_h
    }

    /// `μ` and `σ` of `ln x` (natural logarithm of the samples' unit).
    fn mu_sigma(&self) -> (f64, f64) {
        let sigma = (0.5 / self.gamma).sqrt();
        (self.ln_ref - self.beta * sigma * sigma, sigma)
    }
}

/// The log-normal on the tail by maximum likelihood, and its log-density. Reals: the
/// density `φ((ln x - μ)/σ) / (x σ)` normalised over `x ≥ x_min`; integers: the
/// continuous law's mass in `[k - 1/2, k + 1/2)` normalised over `x ≥ x_min - 1/2` (the
/// rounding discretisation). Fitted by [`nelder_mead`] in `(β, ln γ)`, `γ ⟨y²⟩ ∈
/// [1e-12, 1e12]`, and compared with the limit `γ = 0` (`σ = ∞`).
fn lognormal(tail: &Tail) -> (LogNormal, f64, Vec<f64>) {
    let ln_ref = match tail.support {
        Support::Discrete => (tail.x_min - 0.5).ln(),
        _ => tail.x_min.ln(),
    };
    let ys: Vec<(f64, f64, f64, f64)> = match tail.support {
        Support::Discrete => tail
            .values
            .iter()
            .map(|&(k, c)| {
                let lo = (k - 0.5).ln() - ln_ref;
                let hi = (k + 0.5).ln() - ln_ref;
                (lo, hi, c as f64, k.ln())
            })
            .collect(),
        _ => Vec::new(),
    };
    let nf = tail.n as f64;
    let (mean_y, mean_y2) = match tail.support {
        Support::Discrete => {
            let (mut s, mut s2) = (0.0, 0.0);
            for &(k, c) in &tail.values {
                let y = k.ln() - ln_ref;
                s += c as f64 * y;
                s2 += c as f64 * y * y;
            }
            (s / nf, s2 / nf)
        }
        _ => (tail.mean_y, tail.mean_y2),
    };
    // Minus the log-likelihood per sample.
    let objective = |law: LogNormal| -> f64 {
        let ln_w0 = law.ln_w(0.0);
        match tail.support {
            Support::Discrete => {
                let mut sum = 0.0;
                for &(lo, hi, c, _) in &ys {
                    let (a, b) = (law.ln_w(lo), law.ln_w(hi));
                    sum += c * (a + (-(b - a).exp_m1()).ln());
                }
                -(sum / nf - ln_w0)
            }
            _ => ln_ref + mean_y + law.beta * mean_y + law.gamma * mean_y2 + ln_w0,
        }
    };
    let at = |v: [f64; 2]| LogNormal {
        beta: v[0],
        gamma: v[1].exp(),
        ln_ref,
    };
    let var = (mean_y2 - mean_y * mean_y).max(1e-300);
    let g_lo = (1e-12 / mean_y2).ln();
    let g_hi = (1e12 / mean_y2).ln();
    let bound = 1e6 / mean_y2.sqrt();
    let starts = [
        [-mean_y / var, (0.5 / var).ln()],
        [1.0 / mean_y, (1e-6 / mean_y2).ln()],
    ];
    let mut best: Option<([f64; 2], f64)> = None;
    for start in starts {
        let step = [0.5 * start[0].abs().max(0.2 / mean_y2.sqrt()), 1.0];
        let found = nelder_mead(
            |v| objective(at(v)),
            start,
            step,
            [-bound, g_lo],
            [bound, g_hi],
        );
        if best.is_none_or(|b| found.1 < b.1) {
            best = Some(found);
        }
    }
    let (v, value) = best.expect("two starts");
    // The boundary γ = 0, the limit σ → ∞ (a power law in x for reals, its rounding for
    // integers), is part of the family: where it is at least as likely, it is the fit.
    let limit = |beta: f64| LogNormal {
        beta,
        gamma: 0.0,
        ln_ref,
    };
    let (beta_limit, value_limit) = match tail.support {
        Support::Discrete => golden_section(|b| objective(limit(b)), 1e-9, 60.0),
        _ => {
            let b = 1.0 / mean_y;
            (b, objective(limit(b)))
        }
    };
    let on_boundary = value_limit <= value;
    let law = if on_boundary {
        limit(beta_limit)
    } else {
        at(v)
    };
    let ln_w0 = law.ln_w(0.0);
    let ln_pdf: Vec<f64> = match tail.support {
        Support::Discrete => ys
            .iter()
            .map(|&(lo, hi, _, _)| {
                let (a, b) = (law.ln_w(lo), law.ln_w(hi));
                a + (-(b - a).exp_m1()).ln() - ln_w0
            })
            .collect(),
        // The limit is the power law itself (α = 1 + β): its own densities, so that R is 0.
        _ if on_boundary => {
            let f = power_law_ln_pdf(tail, tail.alpha);
            tail.values.iter().map(|&(x, _)| f(x)).collect()
        }
        _ => tail
            .values
            .iter()
            .map(|&(x, _)| {
                let y = (x / tail.x_min).ln();
                -x.ln() - law.beta * y - law.gamma * y * y - ln_w0
            })
            .collect(),
    };
    let ll = ln_pdf
        .iter()
        .zip(&tail.values)
        .map(|(l, &(_, c))| c as f64 * l)
        .sum();
    (law, ll, ln_pdf)
}

/// The most terms of a discrete cut-off law's normalisation summed one by one; the rest
/// is the Euler–Maclaurin tail.
const CUTOFF_TERMS: usize = 2000;

/// `S(α, λ) = Σ_{k ≥ x_min} (k/x_min)^(-α) e^(-λ(k - x_min))` (`≥ 1`): terms summed until
/// one falls below 1e-18 of the sum (they decrease) or [`CUTOFF_TERMS`] of them, then
/// `Σ_{k≥K} f(k) ≈ ∫_K^∞ f + f(K)/2 - f'(K)/12 + f'''(K)/720` with `∫_K^∞ f = K f(K)
/// e^(λK) E_α(λK)`; the next Euler–Maclaurin term is below `f(K) ((α/K + λ)⁵)/30240`, under
/// 1e-11 `f(K)` for `K ≥ 2000` and terms that have not yet decayed (`λ < 0.03`).
fn cutoff_discrete_sum(alpha: f64, lambda: f64, x_min: f64) -> f64 {
    let f = |k: f64| (-alpha * (k / x_min).ln() - lambda * (k - x_min)).exp();
    let mut sum = 0.0;
    let mut k = x_min;
    for _ in 0..CUTOFF_TERMS {
        let term = f(k);
        sum += term;
        k += 1.0;
        if term < 1e-18 * sum {
            return sum;
        }
    }
    let fk = f(k);
    if fk == 0.0 {
        return sum;
    }
    let g1 = -alpha / k - lambda;
    let g2 = alpha / (k * k);
    let g3 = -2.0 * alpha / (k * k * k);
    let d1 = fk * g1;
    let d3 = fk * (g1 * g1 * g1 + 3.0 * g1 * g2 + g3);
    let integral = k * fk * (ln_expint(alpha, lambda * k) + lambda * k).exp();
    sum + integral + 0.5 * fk - d1 / 12.0 + d3 / 720.0
}

/// The cut-off law's parameters: `α`, and `μ = λ x_min` (dimensionless).
#[derive(Clone, Copy)]
struct Cutoff {
    alpha: f64,
    mu: f64,
}

/// Minus the cut-off law's log-likelihood per sample: continuous `p(x) = x^(-α) e^(-λx) /
/// (x_min^(1-α) E_α(λ x_min))` (`∫_{x_min}^∞ x^(-α) e^(-λx) dx = x_min^(1-α) E_α(λ x_min)
/// = λ^(α-1) Γ(1-α, λ x_min)`); discrete `P(k) = k^(-α) e^(-λk) / Σ_{j≥x_min} j^(-α)
/// e^(-λj)`.
fn cutoff_objective(tail: &Tail, law: Cutoff) -> f64 {
    let x_min = tail.x_min;
    match tail.support {
        Support::Discrete => {
            let s = cutoff_discrete_sum(law.alpha, law.mu / x_min, x_min);
            law.alpha * tail.mean_y + law.mu * tail.mean_t1 + s.ln()
        }
        _ => {
            // ln E_α(μ) + μ: finite where e^(-μ) underflows.
            let shifted = ln_expint(law.alpha, law.mu) + law.mu;
            law.alpha * tail.mean_y + law.mu * tail.mean_t1 + shifted + x_min.ln()
        }
    }
}

/// The cut-off law's log-density at `x` (samples' unit).
fn cutoff_ln_pdf(tail: &Tail, law: Cutoff) -> impl Fn(f64) -> f64 + '_ {
    let x_min = tail.x_min;
    let norm = match tail.support {
        Support::Discrete => cutoff_discrete_sum(law.alpha, law.mu / x_min, x_min).ln(),
        _ => ln_expint(law.alpha, law.mu) + law.mu + x_min.ln(),
    };
    move |x| -law.alpha * (x / x_min).ln() - law.mu * ((x - x_min) / x_min) - norm
}

/// The cut-off law `x^(-α) e^(-λx)` on `x ≥ x_min` as a density of all the samples, of
/// which the tail is the share `share` (the unit of [`super::LogBin::density`], as
/// [`super::PowerLawFit::density`]): `share · p(x)`, 0 below `x_min` and for parameters
/// that are not a law (`α ≤ 1` at `λ = 0`). The figures draw the fitted law with it.
#[cfg_attr(not(feature = "plot"), allow(dead_code))] // drawn by `plot` alone
pub(crate) fn cutoff_density(
    support: Support,
    (alpha, lambda, x_min): (f64, f64, f64),
    share: f64,
    x: f64,
) -> f64 {
    let law = Cutoff {
        alpha,
        mu: lambda * x_min,
    };
    // NaN anywhere fails a comparison: no law there.
    let within = x >= x_min && x_min > 0.0 && lambda >= 0.0;
    if !within {
        return 0.0;
    }
    let norm = match support {
        Support::Discrete => cutoff_discrete_sum(law.alpha, lambda, x_min).ln(),
        _ => ln_expint(law.alpha, law.mu) + law.mu + x_min.ln(),
    };
    if !norm.is_finite() {
        return 0.0;
    }
    share * (-law.alpha * (x / x_min).ln() - law.mu * ((x - x_min) / x_min) - norm).exp()
}

/// The cut-off law on the tail by maximum likelihood: [`nelder_mead`] in `(α, ln μ)`,
/// `α ∈ [0, 20]`, `μ ⟨x/x_min - 1⟩ ∈ [1e-12, 1e6]`, from two starts; then the boundary
/// `λ = 0` (the pure power law, nested) wins when its likelihood is at least as high. The
/// likelihood is concave in `(α, λ)` (an exponential family), so the maximum found is the
/// maximum.
fn cutoff(tail: &Tail) -> (Cutoff, f64) {
    let scale = tail.mean_t1;
    let lo = [0.0, (1e-12 / scale).ln()];
    let hi = [ALPHA_MAX, (1e6 / scale).ln()];
    let objective = |v: [f64; 2]| {
        cutoff_objective(
            tail,
            Cutoff {
                alpha: v[0],
                mu: v[1].exp(),
            },
        )
    };
    let alpha = tail.alpha.min(ALPHA_MAX);
    let starts = [
        [alpha, (1e-3 / scale).ln()],
        [0.5 * alpha, (1.0 / scale).ln()],
    ];
    let mut best: Option<([f64; 2], f64)> = None;
    for start in starts {
        let found = nelder_mead(objective, start, [0.3, 1.0], lo, hi);
        if best.is_none_or(|b| found.1 < b.1) {
            best = Some(found);
        }
    }
    let (v, value) = best.expect("two starts");
    let pure = Cutoff {
        alpha: tail.alpha,
        mu: 0.0,
    };
    let pure_value = -power_law_mean_ll(tail, tail.alpha);
    if pure_value <= value {
        (pure, pure_value)
    } else {
        (
            Cutoff {
                alpha: v[0],
                mu: v[1].exp(),
            },
            value,
        )
    }
}

/// The power law's log-likelihood per sample.
fn power_law_mean_ll(tail: &Tail, alpha: f64) -> f64 {
    let pdf = power_law_ln_pdf(tail, alpha);
    tail.values
        .iter()
        .map(|&(x, c)| c as f64 * pdf(x))
        .sum::<f64>()
        / tail.n as f64
}

/// A likelihood-ratio test between two laws fitted to the same tail
/// ([`super::compare_alternatives`]).
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct LikelihoodRatio {
    /// `R = Σ_i [ln p₁(x_i) - ln p₂(x_i)]` over the tail (dimensionless, natural log):
    /// positive when the first law named is the more likely.
    pub log_ratio: f64,
    /// Vuong's normalised statistic `R / √(n σ²)` (dimensionless), `σ²` the variance (over
    /// `n`, not `n - 1`) of the `n` terms of `R`; 0 when `R` and `σ²` are both 0, `±∞`
    /// when only `σ²` is.
    pub normalized: f64,
    /// Two-sided p-value (dimensionless, in `[0, 1]`): for non-nested laws Vuong's
    /// `erfc(|R| / √(2 n σ²))` (1 when `R = 0`); for nested ones Wilks' `P(χ²₁ ≥ 2|R|) =
    /// erfc(√|R|)`. The sign of `R` means something only when this is small (Clauset et
    /// al.: below 0.1).
    pub p_value: f64,
    /// Whether the second law contains the first (the cut-off law contains the power law):
    /// the p-value is Wilks'.
    pub nested: bool,
}

/// The test of per-sample log-densities `a` against `b` (weights: each distinct value's
/// count).
fn ratio(a: &[f64], b: &[f64], counts: &[usize], nested: bool) -> LikelihoodRatio {
    let n: f64 = counts.iter().map(|&c| c as f64).sum();
    let r: f64 = a
        .iter()
        .zip(b)
        .zip(counts)
        .map(|((x, y), &c)| c as f64 * (x - y))
        .sum();
    let mean = r / n;
    let var: f64 = a
        .iter()
        .zip(b)
        .zip(counts)
        .map(|((x, y), &c)| c as f64 * (x - y - mean).powi(2))
        .sum::<f64>()
        / n;
    let normalized = if var > 0.0 {
        r / (n * var).sqrt()
    } else if r == 0.0 {
        0.0
    } else {
        r.signum() * f64::INFINITY
    };
    if !r.is_finite() {
        // A law that gives some sample no likelihood at all: the other wins outright.
        return LikelihoodRatio {
            log_ratio: r,
            normalized: r,
            p_value: if r.is_nan() { 1.0 } else { 0.0 },
            nested,
        };
    }
    let p_value = if nested {
        chi2_one_survival_of_twice(r)
    } else if r == 0.0 {
        1.0
    } else {
        normal_two_sided(normalized)
    };
    LikelihoodRatio {
        log_ratio: r,
        normalized,
        p_value,
        nested,
    }
}

/// What [`super::compare_alternatives`] computes on one tail besides the bootstrap.
pub(super) struct Compared {
    pub power_law_ll: f64,
    pub exponential: (f64, f64),
    pub lognormal: (f64, f64, f64),
    pub cutoff: (f64, f64, f64),
    pub vs_exponential: LikelihoodRatio,
    pub vs_lognormal: LikelihoodRatio,
    pub vs_cutoff: LikelihoodRatio,
    pub cutoff_vs_lognormal: LikelihoodRatio,
}

/// The cut-off law's `(α, λ)` (λ in the samples' inverse unit) on a tail: what the
/// bootstrap refits.
pub(super) fn cutoff_only(tail: &Tail) -> (f64, f64) {
    let (law, _) = cutoff(tail);
    (law.alpha, law.mu / tail.x_min)
}

/// Fits every alternative to the tail and tests them.
pub(super) fn compare(tail: &Tail) -> Compared {
    let counts: Vec<usize> = tail.values.iter().map(|&(_, c)| c).collect();
    let ll = |v: &[f64]| -> f64 { v.iter().zip(&counts).map(|(l, &c)| c as f64 * l).sum() };
    let pl = {
        let f = power_law_ln_pdf(tail, tail.alpha);
        tail.values.iter().map(|&(x, _)| f(x)).collect::<Vec<_>>()
    };
    let (lambda, ex) = {
        let (lambda, f) = exponential(tail);
        (
            lambda,
            tail.values.iter().map(|&(x, _)| f(x)).collect::<Vec<_>>(),
        )
    };
    let (ln_law, ln_ll, ln) = lognormal(tail);
    let (cut_law, _) = cutoff(tail);
    let cut = if cut_law.mu == 0.0 {
        pl.clone() // the boundary: the pure power law itself, R = 0 exactly
    } else {
        let f = cutoff_ln_pdf(tail, cut_law);
        tail.values.iter().map(|&(x, _)| f(x)).collect()
    };
    let (mu, sigma) = ln_law.mu_sigma();
    Compared {
        power_law_ll: ll(&pl),
        exponential: (lambda, ll(&ex)),
        lognormal: (mu, sigma, ln_ll),
        cutoff: (cut_law.alpha, cut_law.mu / tail.x_min, ll(&cut)),
        vs_exponential: ratio(&pl, &ex, &counts, false),
        vs_lognormal: ratio(&pl, &ln, &counts, false),
        vs_cutoff: ratio(&pl, &cut, &counts, true),
        cutoff_vs_lognormal: ratio(&cut, &ln, &counts, false),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_discrete_cutoff_normalisation_matches_a_brute_force_sum() {
        // Summed term by term far past where the terms matter (λ k ≥ 3000 at the end, or
        // the ζ tail below 1e-16 of the sum for the slowest case), smallest first.
        for (alpha, lambda, x_min) in [(2.245, 2e-4, 1.0), (0.5, 1e-3, 3.0), (1.5, 0.02, 7.0)] {
            let top = 20_000_000u64;
            let brute: f64 = (0..top)
                .rev()
                .map(|j| {
                    let k = x_min + j as f64;
                    (-alpha * (k / x_min).ln() - lambda * (k - x_min)).exp()
                })
                .sum();
            let s = cutoff_discrete_sum(alpha, lambda, x_min);
            assert!(
                (s - brute).abs() <= 1e-12 * brute,
                "α {alpha}, λ {lambda}: {s} vs {brute}"
            );
        }
    }

    /// The drawn cut-off law carries the tail's share of the samples: its masses over the
    /// integers from `x_min` (brute-force sum) and its density over the reals (trapezoids
    /// on a log grid) add up to `share`.
    #[test]
    fn the_cutoff_density_holds_the_tails_share() {
        let share = 0.3;
        for (alpha, lambda, x_min) in [(1.5, 0.02, 7.0), (2.4, 0.003, 9.0)] {
            let law = (alpha, lambda, x_min);
            let masses: f64 = (0..200_000u32)
                .rev()
                .map(|j| cutoff_density(Support::Discrete, law, share, x_min + f64::from(j)))
                .sum();
            assert!((masses - share).abs() < 1e-9, "{law:?}: {masses}");
            assert_eq!(
                cutoff_density(Support::Discrete, law, share, x_min - 1.0),
                0.0
            );
            let xs: Vec<f64> = (0..=400_000)
                .map(|i| x_min * 10f64.powf(f64::from(i) * 6.0 / 400_000.0))
                .collect();
            let integral: f64 = xs
                .windows(2)
                .map(|w| {
                    let f = |x| cutoff_density(Support::Continuous, law, share, x);
                    0.5 * (f(w[0]) + f(w[1])) * (w[1] - w[0])
                })
                .sum();
            assert!((integral - share).abs() < 1e-6, "{law:?}: {integral}");
        }
    }

    #[test]
    fn nelder_mead_finds_the_minimum_of_a_tilted_quadratic_and_respects_bounds() {
        let f = |v: [f64; 2]| (v[0] - 1.3).powi(2) + 10.0 * (v[1] + 0.7 - 0.5 * v[0]).powi(2);
        let (x, fx) = nelder_mead(f, [5.0, 5.0], [1.0, 1.0], [-10.0, -10.0], [10.0, 10.0]);
        assert!(
            (x[0] - 1.3).abs() < 1e-6 && (x[1] + 0.05).abs() < 1e-6,
            "{x:?}"
        );
        assert!(fx < 1e-12);
        // The minimum outside the box: found on its edge.
        let (x, _) = nelder_mead(f, [0.0, 0.0], [1.0, 1.0], [-10.0, -10.0], [0.5, 10.0]);
        assert!((x[0] - 0.5).abs() < 1e-9, "{x:?}");
    }
}
