//! Richardson extrapolation of an ensemble mean over three grids, with percentile
//! bootstrap intervals over the realizations (docs/convergence.md).
//!
//! A quantity measured on grids of representative cell size `h₁ > h₂ > h₃`, with
//! `h = √(ΔxΔy)` (a cell that is refined by different ratios along x and y, as
//! 2 x 1.75 mm → 1 mm, is refined by the ratio of the square roots of the cell areas), is
//! modelled as `Q(h) = Q∞ + C hᵖ`. With the differences `D₁₂ = Q₁ − Q₂` and
//! `D₂₃ = Q₂ − Q₃`, the order solves `D₁₂/D₂₃ = (h₁ᵖ − h₂ᵖ)/(h₂ᵖ − h₃ᵖ)` (for a constant
//! ratio `r`, `rᵖ = D₁₂/D₂₃`), found by bisection: the right-hand side increases with
//! `p`, from `ln(h₁/h₂)/ln(h₂/h₃)` at `p → 0`. Then
//! `Q∞ = Q₃ − D₂₃/((h₂/h₃)ᵖ − 1)`. The model holds only when a positive order fits: the
//! differences have one sign and `D₁₂/D₂₃ > ln(h₁/h₂)/ln(h₂/h₃)` (`> 1` for a constant
//! ratio); otherwise no order and no limit are read.
//!
//! Resampling: the realizations are drawn with replacement. When the grids are *paired*
//! (realization `k` is the same surface on every grid), one draw of indices serves all
//! grids, so every difference is taken between grids on the same realization; unpaired
//! grids are resampled each on its own. A resample in which no positive order fits is
//! *unresolved* and is not dropped: it has no order and no limit, so it counts as `−∞`
//! in the order's interval (no positive order) and as unbounded (`−∞` for the lower end,
//! `+∞` for the upper) in the limit's and the finest error's. Every interval then holds
//! 95 % of all resamples, and opens (an infinite end) once more than 2.5 % are
//! unresolved. Below [`RESOLVED_SHARE`] the order and the limit are not established.
#![allow(dead_code)] // each example uses its own part

/// The share of resolved resamples below which an order and a limit are reported as
/// not resolved (docs/convergence.md).
pub const RESOLVED_SHARE: f64 = 0.95;

/// SplitMix64 (Steele, Lea and Flood 2014): a fixed, portable stream, so that the
/// bootstrap's intervals repeat bit for bit on any machine.
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// An index in `0..n` (`n > 0`; the modulo bias is below `n/2⁶⁴`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// A value and its 95 % interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    pub value: f64,
    pub lo: f64,
    pub hi: f64,
}

impl Interval {
    /// Whether the interval holds zero (a difference not resolved from sampling noise).
    pub fn holds_zero(&self) -> bool {
        self.lo <= 0.0 && self.hi >= 0.0
    }
}

/// The 2.5 % and 97.5 % points of `samples` (linear interpolation between order
/// statistics) together with resamples that have no value: `below` of them count as
/// `−∞` at both points, `either` of them as `−∞` for the lower point and `+∞` for the
/// upper (unbounded: wherever their value would be, the interval holds 95 % of all).
/// `None` for fewer than two values in all.
pub fn percentile_interval(samples: &[f64], below: usize, either: usize) -> Option<(f64, f64)> {
    let mut s: Vec<f64> = samples.iter().copied().filter(|v| v.is_finite()).collect();
    let n = s.len() + below + either;
    if n < 2 {
        return None;
    }
    s.sort_by(f64::total_cmp);
    // Order statistic `k` of all values, the `either` ones at `−∞` or `+∞`.
    let value = |k: usize, either_low: bool| {
        let low = below + if either_low { either } else { 0 };
        if k < low {
            f64::NEG_INFINITY
        } else if k - low < s.len() {
            s[k - low]
        } else {
            f64::INFINITY
        }
    };
    let at = |q: f64, either_low: bool| {
        let x = q * (n - 1) as f64;
        let (k, t) = (x.floor() as usize, x - x.floor());
        let a = value(k, either_low);
        if t == 0.0 || k + 1 >= n {
            return a;
        }
        let b = value(k + 1, either_low);
        // Between an infinite and a finite statistic the point is the infinite one.
        if a.is_infinite() {
            a
        } else if b.is_infinite() {
            b
        } else {
            a * (1.0 - t) + b * t
        }
    };
    Some((at(0.025, true), at(0.975, false)))
}

/// The order `p` and the limit `Q∞` of three means on grids of representative cell size
/// `h` (coarse to fine); `None` where no positive order fits.
pub fn richardson(q: [f64; 3], h: [f64; 3]) -> Option<(f64, f64)> {
    let (d12, d23) = (q[0] - q[1], q[1] - q[2]);
    let (a, b) = ((h[0] / h[1]).ln(), (h[1] / h[2]).ln());
    let ratio = d12 / d23;
    if !(a > 0.0 && b > 0.0 && ratio.is_finite() && ratio > a / b) {
        return None;
    }
    // ln((h₁ᵖ − h₂ᵖ)/(h₂ᵖ − h₃ᵖ)) = a p + ln(1 − e^(−ap)) − ln(1 − e^(−bp)), increasing in
    // p (derivative ≥ a); written so that it neither overflows nor loses digits.
    let log_ratio = |p: f64| a * p + (-(-a * p).exp_m1()).ln() - (-(-b * p).exp_m1()).ln();
    let target = ratio.ln();
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    while log_ratio(hi) < target {
        hi *= 2.0;
        if hi > 1e6 {
            return None;
        }
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if log_ratio(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let p = 0.5 * (lo + hi);
    Some((p, q[2] - d23 / (b * p).exp_m1()))
}

/// The study of one quantity on three grids.
#[derive(Debug, Clone)]
pub struct Estimate {
    /// Per grid, coarse to fine: the ensemble mean and its bootstrap interval.
    pub means: [Interval; 3],
    /// `Q₁ − Q₂` and `Q₂ − Q₃`, with intervals (same-realization when paired).
    pub differences: [Interval; 2],
    /// The order, the limit and the finest grid's error; `None` when the grids were not
    /// to be extrapolated (a surface that changes with the cell has no limit).
    pub extrapolation: Option<Extrapolation>,
    /// Realizations used per grid.
    pub realizations: [usize; 3],
}

/// Richardson's order and limit of one quantity (module docs).
#[derive(Debug, Clone)]
pub struct Extrapolation {
    /// The order `p`, from the full sample, with the interval over all resamples (an
    /// unresolved one at `−∞`); `None` when the full sample gives none.
    pub order: Option<Interval>,
    /// `Q∞`, likewise (an unresolved resample unbounded on both sides).
    pub limit: Option<Interval>,
    /// `Q₃ − Q∞`: the error left on the finest grid, likewise.
    pub finest_error: Option<Interval>,
    /// The fraction of resamples in which a positive order fits.
    pub resolved: f64,
}

impl Extrapolation {
    /// Whether enough resamples resolve the order for it and the limit to be read
    /// ([`RESOLVED_SHARE`]).
    pub fn established(&self) -> bool {
        self.resolved >= RESOLVED_SHARE
    }
}

/// One resample's means: paired grids share one draw of realizations.
fn resample(values: &[Vec<f64>; 3], paired: bool, rng: &mut SplitMix64) -> [f64; 3] {
    let mut means = [0.0; 3];
    if paired {
        let n = values[0].len();
        let draw: Vec<usize> = (0..n).map(|_| rng.below(n)).collect();
        for (g, v) in values.iter().enumerate() {
            means[g] = draw.iter().map(|&k| v[k]).sum::<f64>() / n as f64;
        }
    } else {
        for (g, v) in values.iter().enumerate() {
            let n = v.len();
            means[g] = (0..n).map(|_| v[rng.below(n)]).sum::<f64>() / n as f64;
        }
    }
    means
}

/// `value` with the interval of `samples` and of the resamples without one (see
/// [`percentile_interval`]).
fn interval(value: f64, samples: &[f64], below: usize, either: usize) -> Interval {
    let (lo, hi) = percentile_interval(samples, below, either).unwrap_or((f64::NAN, f64::NAN));
    Interval { value, lo, hi }
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Estimates a quantity observed per realization on three grids (coarse to fine):
/// `observed[g][k]` is realization `k` on grid `g`, NaN where that run lacks it. Paired
/// grids keep only the realizations observed on all three. `h`: the grids'
/// representative cell sizes `√(ΔxΔy)`, to extrapolate; `None` for grids without a
/// common limit (means and differences only). `None` when a grid keeps fewer than two
/// realizations.
pub fn estimate(
    observed: &[Vec<f64>; 3],
    h: Option<[f64; 3]>,
    paired: bool,
    resamples: usize,
    seed: u64,
) -> Option<Estimate> {
    let values: [Vec<f64>; 3] = if paired {
        let n = observed.iter().map(Vec::len).min().unwrap_or(0);
        let keep: Vec<usize> = (0..n)
            .filter(|&k| observed.iter().all(|v| v[k].is_finite()))
            .collect();
        std::array::from_fn(|g| keep.iter().map(|&k| observed[g][k]).collect())
    } else {
        std::array::from_fn(|g| {
            observed[g]
                .iter()
                .copied()
                .filter(|v| v.is_finite())
                .collect()
        })
    };
    if values.iter().any(|v| v.len() < 2) {
        return None;
    }
    let q = [mean(&values[0]), mean(&values[1]), mean(&values[2])];
    let mut rng = SplitMix64::new(seed);
    let mut sample_means: [Vec<f64>; 3] = Default::default();
    let mut diffs: [Vec<f64>; 2] = Default::default();
    let (mut orders, mut limits, mut errors) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..resamples {
        let m = resample(&values, paired, &mut rng);
        for g in 0..3 {
            sample_means[g].push(m[g]);
        }
        diffs[0].push(m[0] - m[1]);
        diffs[1].push(m[1] - m[2]);
        if let Some((p, limit)) = h.and_then(|h| richardson(m, h)) {
            orders.push(p);
            limits.push(limit);
            errors.push(m[2] - limit);
        }
    }
    let unresolved = resamples - orders.len();
    let extrapolation = h.map(|h| {
        let full = richardson(q, h);
        Extrapolation {
            order: full.map(|(p, _)| interval(p, &orders, unresolved, 0)),
            limit: full.map(|(_, l)| interval(l, &limits, 0, unresolved)),
            finest_error: full.map(|(_, l)| interval(q[2] - l, &errors, 0, unresolved)),
            resolved: orders.len() as f64 / resamples as f64,
        }
    });
    Some(Estimate {
        means: std::array::from_fn(|g| interval(q[g], &sample_means[g], 0, 0)),
        differences: [
            interval(q[0] - q[1], &diffs[0], 0, 0),
            interval(q[1] - q[2], &diffs[1], 0, 0),
        ],
        extrapolation,
        realizations: std::array::from_fn(|g| values[g].len()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn richardson_recovers_order_and_limit_of_an_exact_power_law() {
        // Q(h) = 3 + 0.5 h^1.5 on h = 2, 1, 0.5 (by hand: 4.41421, 3.5, 3.17678).
        let h = [2.0, 1.0, 0.5];
        let q = h.map(|h: f64| 3.0 + 0.5 * h.powf(1.5));
        let (p, limit) = richardson(q, h).unwrap();
        assert!((p - 1.5).abs() < 1e-12, "{p}");
        assert!((limit - 3.0).abs() < 1e-12, "{limit}");
        // Differences that grow, or change sign, give no order.
        assert_eq!(richardson([1.0, 1.1, 1.3], h), None);
        assert_eq!(richardson([1.0, 1.2, 1.1], h), None);
        assert_eq!(richardson([1.0, 1.0, 1.0], h), None);
    }

    #[test]
    fn richardson_takes_the_refinement_of_the_cell_area() {
        // The study's coarsest grid has 2 x 1.75 mm cells: h = √3.5 ≈ 1.8708 mm, then 1
        // and 0.5 mm. An exact power law of order 1.5 on those h comes back exactly;
        // reading the ratio along x only (2, as the first version did) gives
        // log₂(D₁₂/D₂₃) ≈ 1.29 instead.
        let h = [3.5_f64.sqrt(), 1.0, 0.5];
        let q = h.map(|h: f64| 3.0 + 0.5 * h.powf(1.5));
        let (p, limit) = richardson(q, h).unwrap();
        assert!((p - 1.5).abs() < 1e-10, "{p}");
        assert!((limit - 3.0).abs() < 1e-10, "{limit}");
        // D₁₂/D₂₃ = 4/3 on these h: p = 0.5914928268254478 and, for Q = (−7/3, −1, 0),
        // Q∞ = 1.9731450785577156, both from an independent bisection of
        // (h₁ᵖ − h₂ᵖ)/(h₂ᵖ − h₃ᵖ) = 4/3 in Python floats (x-only ratio: p = 0.415).
        let (p, limit) = richardson([-7.0 / 3.0, -1.0, 0.0], h).unwrap();
        assert!((p - 0.5914928268254478).abs() < 1e-10, "{p}");
        assert!((limit - 1.9731450785577156).abs() < 1e-9, "{limit}");
        // A positive order fits down to D₁₂/D₂₃ = ln(h₁/h₂)/ln(h₂/h₃) ≈ 0.9037: the
        // first step is the shorter one in ln h.
        assert!(richardson([-1.95, -1.0, 0.0], h).is_some());
        assert_eq!(richardson([-1.9, -1.0, 0.0], h), None);
    }

    #[test]
    fn percentile_interval_interpolates_order_statistics() {
        // 0, 1, ..., 100: the 2.5 % point is 2.5 and the 97.5 % point 97.5 (by hand).
        let s: Vec<f64> = (0..=100).rev().map(f64::from).collect();
        assert_eq!(percentile_interval(&s, 0, 0), Some((2.5, 97.5)));
        assert_eq!(percentile_interval(&[1.0, f64::NAN], 0, 0), None);
    }

    #[test]
    fn unresolved_resamples_widen_the_interval() {
        // 0..=100 and one resample without a value, unbounded: 102 values, the 2.5 %
        // point at 0.025 * 101 = 2.525 of (−∞, 0, 1, ...) is 1.525 and the 97.5 % point
        // at 98.475 of (0, ..., 100, +∞) is 98.475 (by hand): wider than 2.5, 97.5.
        let s: Vec<f64> = (0..=100).map(f64::from).collect();
        let (lo, hi) = percentile_interval(&s, 0, 1).unwrap();
        assert!(
            (lo - 1.525).abs() < 1e-12 && (hi - 98.475).abs() < 1e-12,
            "{lo} {hi}"
        );
        // One at −∞ only (an order that is not positive): the lower point as above, the
        // upper at 98.475 of (−∞, 0, ..., 100) = 97.475.
        let (lo, hi) = percentile_interval(&s, 1, 0).unwrap();
        assert!(
            (lo - 1.525).abs() < 1e-12 && (hi - 97.475).abs() < 1e-12,
            "{lo} {hi}"
        );
        // Three of 104 (more than 2.5 %): the interval opens.
        assert_eq!(
            percentile_interval(&s, 0, 3),
            Some((f64::NEG_INFINITY, f64::INFINITY))
        );
        assert_eq!(percentile_interval(&s, 3, 0).unwrap().0, f64::NEG_INFINITY);
        assert_eq!(
            percentile_interval(&[], 0, 2),
            Some((f64::NEG_INFINITY, f64::INFINITY))
        );
    }

    #[test]
    fn splitmix_matches_the_reference_stream() {
        // The first two outputs for seed 1234567 of Vigna's splitmix64.c, recomputed
        // with Python's integers (64-bit masks) for this test.
        let mut rng = SplitMix64::new(1234567);
        assert_eq!(rng.next_u64(), 6457827717110365317);
        assert_eq!(rng.next_u64(), 3203168211198807973);
    }

    #[test]
    fn paired_differences_cancel_the_shared_scatter() {
        // Each realization k has its own offset s_k (large) shared by its three grids,
        // plus the grid's deterministic error 0.1 h: paired differences are exactly
        // 0.1 and 0.05 in every resample, so their intervals are points; unpaired ones
        // carry the offsets' scatter.
        let offsets: Vec<f64> = (0..12).map(|k| ((k * 7919) % 13) as f64).collect();
        let h = [2.0, 1.0, 0.5];
        let observed: [Vec<f64>; 3] = h.map(|h| offsets.iter().map(|s| s + 0.1 * h).collect());
        let e = estimate(&observed, Some(h), true, 500, 1).unwrap();
        for (d, want) in e.differences.iter().zip([0.1, 0.05]) {
            assert!(
                (d.lo - want).abs() < 1e-12 && (d.hi - want).abs() < 1e-12,
                "{d:?}"
            );
        }
        let x = e.extrapolation.unwrap();
        let p = x.order.unwrap();
        assert!(
            (p.value - 1.0).abs() < 1e-9 && (p.hi - p.lo).abs() < 1e-9,
            "{p:?}"
        );
        assert_eq!(x.resolved, 1.0);
        assert!(x.established());
        let mean_offset = offsets.iter().sum::<f64>() / 12.0;
        assert!((x.limit.unwrap().value - mean_offset).abs() < 1e-9);
        let u = estimate(&observed, Some(h), false, 500, 1).unwrap();
        assert!(
            u.differences[1].hi - u.differences[1].lo > 1.0,
            "{:?}",
            u.differences
        );
        let ux = u.extrapolation.unwrap();
        assert!(ux.resolved < 0.9 && !ux.established(), "{}", ux.resolved);
        // The unresolved resamples open the limit's interval instead of being dropped.
        let l = ux.limit.unwrap();
        assert_eq!((l.lo, l.hi), (f64::NEG_INFINITY, f64::INFINITY), "{l:?}");
        assert_eq!(ux.order.unwrap().lo, f64::NEG_INFINITY);
    }

    #[test]
    fn a_share_of_unresolved_resamples_opens_the_limit() {
        // Differences that shrink on average but not in every resample: the power law
        // 0.1 h plus, on the middle grid only, a scatter 0.4 e_k per realization (mean
        // 0.002, sd 0.11, so the resampled middle mean moves by about 0.034): the full
        // sample has D₁₂/D₂₃ ≈ 1.9, but where the middle mean rises by more than 0.025
        // the ratio falls below 1, in about a quarter of the resamples. Counted as
        // unbounded they open the limit's interval at both ends; the resolved
        // resamples alone (the first version) give a bounded one.
        let h = [2.0, 1.0, 0.5];
        let scatter = [0.3, -0.2, 0.25, -0.35, 0.1, -0.05, 0.4, -0.3, 0.15, -0.25];
        let observed: [Vec<f64>; 3] = std::array::from_fn(|g| {
            scatter
                .iter()
                .map(|e| 0.1 * h[g] + e * [0.0, 0.4, 0.0][g])
                .collect()
        });
        let e = estimate(&observed, Some(h), true, 2000, 3).unwrap();
        let x = e.extrapolation.unwrap();
        assert!(x.resolved > 0.05 && x.resolved < 0.95, "{}", x.resolved);
        assert!(!x.established());
        let l = x.limit.unwrap();
        assert_eq!((l.lo, l.hi), (f64::NEG_INFINITY, f64::INFINITY), "{l:?}");
        let err = x.finest_error.unwrap();
        assert_eq!((err.lo, err.hi), (f64::NEG_INFINITY, f64::INFINITY));
        assert_eq!(x.order.unwrap().lo, f64::NEG_INFINITY);
    }

    #[test]
    fn grids_without_a_limit_are_not_extrapolated() {
        // A surface that changes with the cell (the white noise): means and differences,
        // no order and no limit, even where the means happen to follow a power law.
        let h = [2.0, 1.0, 0.5];
        let observed: [Vec<f64>; 3] = h.map(|h| vec![1.0 + h, 1.1 + h, 0.9 + h]);
        let e = estimate(&observed, None, false, 100, 1).unwrap();
        assert!(e.extrapolation.is_none());
        assert!((e.differences[0].value - 1.0).abs() < 1e-12);
        assert!(estimate(&observed, Some(h), false, 100, 1)
            .unwrap()
            .extrapolation
            .is_some());
    }

    #[test]
    fn paired_grids_drop_a_realization_missing_on_any_grid() {
        let nan = f64::NAN;
        let observed = [
            vec![1.0, 2.0, 3.0],
            vec![1.0, nan, 3.0],
            vec![1.0, 2.0, 3.0],
        ];
        let h = Some([2.0, 1.0, 0.5]);
        assert_eq!(
            estimate(&observed, h, true, 10, 1).unwrap().realizations,
            [2; 3]
        );
        assert_eq!(
            estimate(&observed, h, false, 10, 1).unwrap().realizations,
            [3, 2, 3]
        );
        assert!(estimate(&[vec![1.0], vec![1.0], vec![1.0]], h, true, 10, 1).is_none());
    }
}
