//! Richardson extrapolation of an ensemble mean over three grids, with percentile
//! bootstrap intervals over the realizations (docs/convergence.md).
//!
//! A quantity measured on grids of cell size `h₁ > h₂ > h₃` in a constant ratio
//! `r = h₁/h₂ = h₂/h₃` is modelled as `Q(h) = Q∞ + C hᵖ`. With the differences
//! `D₁₂ = Q₁ − Q₂` and `D₂₃ = Q₂ − Q₃`, `rᵖ = D₁₂/D₂₃` and
//! `Q∞ = Q₃ − D₂₃/(rᵖ − 1) = Q₃ − D₂₃²/(D₁₂ − D₂₃)`. The model holds only when the
//! differences have one sign and shrink (`D₁₂/D₂₃ > 1`, i.e. `p > 0`); otherwise no order
//! and no limit are read.
//!
//! Resampling: the realizations are drawn with replacement. When the grids are *paired*
//! (realization `k` is the same surface on every grid), one draw of indices serves all
//! grids, so every difference is taken between grids on the same realization; unpaired
//! grids are resampled each on its own.
#![allow(dead_code)] // each example uses its own part

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
/// statistics); `None` for fewer than two finite samples.
pub fn percentile_interval(samples: &[f64]) -> Option<(f64, f64)> {
    let mut s: Vec<f64> = samples.iter().copied().filter(|v| v.is_finite()).collect();
    if s.len() < 2 {
        return None;
    }
    s.sort_by(f64::total_cmp);
    let at = |q: f64| {
        let x = q * (s.len() - 1) as f64;
        let (k, t) = (x.floor() as usize, x - x.floor());
        if k + 1 < s.len() {
            s[k] * (1.0 - t) + s[k + 1] * t
        } else {
            s[k]
        }
    };
    Some((at(0.025), at(0.975)))
}

/// The order `p` and the limit `Q∞` of three means on grids in the ratio `r`; `None`
/// where the differences do not shrink with one sign.
pub fn richardson(q: [f64; 3], r: f64) -> Option<(f64, f64)> {
    let (d12, d23) = (q[0] - q[1], q[1] - q[2]);
    let ratio = d12 / d23;
    if !(ratio.is_finite() && ratio > 1.0) {
        return None;
    }
    Some((ratio.ln() / r.ln(), q[2] - d23 * d23 / (d12 - d23)))
}

/// The study of one quantity on three grids.
#[derive(Debug, Clone)]
pub struct Estimate {
    /// Per grid, coarse to fine: the ensemble mean and its bootstrap interval.
    pub means: [Interval; 3],
    /// `Q₁ − Q₂` and `Q₂ − Q₃`, with intervals (same-realization when paired).
    pub differences: [Interval; 2],
    /// The order `p`, from the full sample, with the interval over the resamples where
    /// it is defined; `None` when the full sample gives none.
    pub order: Option<Interval>,
    /// `Q∞`, likewise.
    pub limit: Option<Interval>,
    /// `Q₃ − Q∞`: the error left on the finest grid.
    pub finest_error: Option<Interval>,
    /// The fraction of resamples in which the differences shrink with one sign.
    pub resolved: f64,
    /// Realizations used per grid.
    pub realizations: [usize; 3],
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

fn interval(value: f64, samples: &[f64]) -> Interval {
    let (lo, hi) = percentile_interval(samples).unwrap_or((f64::NAN, f64::NAN));
    Interval { value, lo, hi }
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Estimates a quantity observed per realization on three grids (coarse to fine, cell
/// ratio `r`): `observed[g][k]` is realization `k` on grid `g`, NaN where that run lacks
/// it. Paired grids keep only the realizations observed on all three. `None` when a grid
/// keeps fewer than two realizations.
pub fn estimate(
    observed: &[Vec<f64>; 3],
    r: f64,
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
        if let Some((p, limit)) = richardson(m, r) {
            orders.push(p);
            limits.push(limit);
            errors.push(m[2] - limit);
        }
    }
    let full = richardson(q, r);
    Some(Estimate {
        means: std::array::from_fn(|g| interval(q[g], &sample_means[g])),
        differences: [
            interval(q[0] - q[1], &diffs[0]),
            interval(q[1] - q[2], &diffs[1]),
        ],
        order: full.map(|(p, _)| interval(p, &orders)),
        limit: full.map(|(_, l)| interval(l, &limits)),
        finest_error: full.map(|(_, l)| interval(q[2] - l, &errors)),
        resolved: orders.len() as f64 / resamples as f64,
        realizations: std::array::from_fn(|g| values[g].len()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn richardson_recovers_order_and_limit_of_an_exact_power_law() {
        // Q(h) = 3 + 0.5 h^1.5 on h = 2, 1, 0.5 (by hand: 4.41421, 3.5, 3.17678).
        let q = [2.0, 1.0, 0.5].map(|h: f64| 3.0 + 0.5 * h.powf(1.5));
        let (p, limit) = richardson(q, 2.0).unwrap();
        assert!((p - 1.5).abs() < 1e-12, "{p}");
        assert!((limit - 3.0).abs() < 1e-12, "{limit}");
        // Differences that grow, or change sign, give no order.
        assert_eq!(richardson([1.0, 1.1, 1.3], 2.0), None);
        assert_eq!(richardson([1.0, 1.2, 1.1], 2.0), None);
        assert_eq!(richardson([1.0, 1.0, 1.0], 2.0), None);
    }

    #[test]
    fn percentile_interval_interpolates_order_statistics() {
        // 0, 1, ..., 100: the 2.5 % point is 2.5 and the 97.5 % point 97.5 (by hand).
        let s: Vec<f64> = (0..=100).rev().map(f64::from).collect();
        assert_eq!(percentile_interval(&s), Some((2.5, 97.5)));
        assert_eq!(percentile_interval(&[1.0, f64::NAN]), None);
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
        let observed: [Vec<f64>; 3] =
            [2.0, 1.0, 0.5].map(|h| offsets.iter().map(|s| s + 0.1 * h).collect());
        let e = estimate(&observed, 2.0, true, 500, 1).unwrap();
        for (d, want) in e.differences.iter().zip([0.1, 0.05]) {
            assert!(
                (d.lo - want).abs() < 1e-12 && (d.hi - want).abs() < 1e-12,
                "{d:?}"
            );
        }
        let p = e.order.unwrap();
        assert!(
            (p.value - 1.0).abs() < 1e-9 && (p.hi - p.lo).abs() < 1e-9,
            "{p:?}"
        );
        assert_eq!(e.resolved, 1.0);
        let mean_offset = offsets.iter().sum::<f64>() / 12.0;
        assert!((e.limit.unwrap().value - mean_offset).abs() < 1e-9);
        let u = estimate(&observed, 2.0, false, 500, 1).unwrap();
        assert!(
            u.differences[1].hi - u.differences[1].lo > 1.0,
            "{:?}",
            u.differences
        );
        assert!(u.resolved < 0.9, "{}", u.resolved);
    }

    #[test]
    fn paired_grids_drop_a_realization_missing_on_any_grid() {
        let nan = f64::NAN;
        let observed = [
            vec![1.0, 2.0, 3.0],
            vec![1.0, nan, 3.0],
            vec![1.0, 2.0, 3.0],
        ];
        assert_eq!(
            estimate(&observed, 2.0, true, 10, 1).unwrap().realizations,
            [2; 3]
        );
        assert_eq!(
            estimate(&observed, 2.0, false, 10, 1).unwrap().realizations,
            [3, 2, 3]
        );
        assert!(estimate(&[vec![1.0], vec![1.0], vec![1.0]], 2.0, true, 10, 1).is_none());
    }
}
