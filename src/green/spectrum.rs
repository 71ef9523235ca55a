//! The eigenvalues of the Galerkin operator: alias sums over the wavenumbers of each
//! DCT mode, cell-averaged and depth-summed (module docs of [`super::plan`]), and the
//! aliases of a mode that the plane transfer sums.

use crate::geometry::Grid;
use std::f64::consts::PI;

/// Largest alias box half-width `Q` before an alias sum of the plane transfer reports
/// [`crate::Error::SeriesNotConverged`].
pub(super) const MAX_ALIAS: usize = 512;

/// Cell-averaging weights and wavenumbers of the aliases of one 1-D DCT mode.
pub(super) struct Aliases {
    /// `(weight w S², k)` for q = -Q..=Q, skipping zero weights.
    pub(super) terms: Vec<(f64, f64)>,
    /// Sum of the weights in the box (½ for mode 0, whose only alias has `w_0 = ½`).
    pub(super) weight: f64,
}

pub(super) fn aliases(mode: usize, n: usize, cell: f64, q_max: usize) -> Aliases {
    let theta = mode as f64 * PI / (2.0 * n as f64);
    let mut terms = Vec::with_capacity(2 * q_max + 1);
    if mode == 0 {
        // Only the q = 0 alias (p = 0) survives: sinc(qπ) = 0 otherwise; w_0 = ½.
        terms.push((0.5, 0.0));
        return Aliases { terms, weight: 0.5 };
    }
    let s2 = theta.sin().powi(2);
    let mut weight = 0.0;
    for q in -(q_max as i64)..=(q_max as i64) {
        let t = theta + q as f64 * PI;
        let w = s2 / (t * t);
        weight += w;
        terms.push((w, 2.0 * t.abs() / cell));
    }
    Aliases { terms, weight }
}

/// `coth(κ Lz)/κ`, the depth-summed kernel of the bottom face.
fn depth_kernel(kappa: f64, lz: f64) -> f64 {
    1.0 / (kappa * (kappa * lz).tanh())
}

/// `ϑ(s) = Σ_k e^{-k² Lz²/s²}` (k ∈ ℤ), the depth's images in the Gaussian
/// representation of the kernel: directly for `s ≤ Lz` (`|k| ≤ 7`: `e^{-49}`), through
/// Poisson's dual `(√π s/Lz) Σ_n e^{-n²π² s²/Lz²}` above (`|n| ≤ 3`: `e^{-9π²}`).
fn depth_images(s: f64, lz: f64) -> f64 {
    if s <= lz {
        1.0 + 2.0
            * (1..=7)
                .map(|k| (-(k as f64 * lz / s).powi(2)).exp())
                .sum::<f64>()
    } else {
        let t = PI * s / lz;
        PI.sqrt() * s / lz
            * (1.0
                + 2.0
                    * (1..=3)
                        .map(|n| (-(n as f64 * t).powi(2)).exp())
                        .sum::<f64>())
    }
}

/// Panels of the integral over `s` (m, the width of the Gaussians) and the two
/// Gauss–Legendre orders whose difference is the error estimate.
const FINE_PANELS: usize = 9;
const HIGH_ORDER: usize = 20;
const LOW_ORDER: usize = 17;
/// The integrand is below `e^{-π² s²/Δ²} < 1e-21` beyond `s = S_END Δ`.
const S_END: f64 = 2.25;
/// Growth of the panels between the finer and the coarser cell size.
const PANEL_GROWTH: f64 = 1.5;

/// The nodes and weights of Gauss–Legendre of order `n` on [-1, 1] (Newton on `P_n`).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut derivative = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let k = k as f64;
                    (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
                }
                derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / derivative;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * derivative * derivative))
        })
        .collect()
}

/// Panel edges over `[0, S_END d_max]`: `FINE_PANELS` panels of equal width up to
/// `S_END h` (`h` the smallest length: the finer cell size, or the depth of a block
/// thinner than a cell), then panels growing by `PANEL_GROWTH`.
fn panel_edges(h: f64, d_max: f64) -> Vec<f64> {
    let fine_end = S_END * h;
    let mut edges: Vec<f64> = (0..=FINE_PANELS)
        .map(|k| fine_end * k as f64 / FINE_PANELS as f64)
        .collect();
    let end = S_END * d_max;
    let mut width = fine_end / FINE_PANELS as f64;
    while let Some(&last) = edges.last() {
        if last >= end * (1.0 - 1e-12) {
            break;
        }
        width *= PANEL_GROWTH;
        edges.push((last + width).min(end));
    }
    edges
}

/// Composite Gauss–Legendre rules of two orders on the panels: `(nodes, weights)` of each.
fn composite_rules(edges: &[f64]) -> [(Vec<f64>, Vec<f64>); 2] {
    [HIGH_ORDER, LOW_ORDER].map(|order| {
        let rule = gauss_legendre(order);
        let mut nodes = Vec::with_capacity(order * edges.len());
        let mut weights = Vec::with_capacity(order * edges.len());
        for pair in edges.windows(2) {
            let (half, mid) = ((pair[1] - pair[0]) / 2.0, (pair[1] + pair[0]) / 2.0);
            for &(x, w) in &rule {
                nodes.push(mid + half * x);
                weights.push(half * w);
            }
        }
        (nodes, weights)
    })
}

/// One 1-D DCT mode's part of the Gaussian representation at the quadrature nodes.
struct AxisMode {
    /// Weight `S_0² = sin²θ/θ²` and wavenumber `2θ/Δ` of the nearest alias (`q = 0`);
    /// `½` and 0 for mode 0.
    w0: f64,
    k0: f64,
    /// At each node `s`: `X(s) - x0(s)` and `x0(s) = S_0² e^{-k_0² s²}`, where
    /// `X(s) = Σ_q S_q² e^{-k_q² s²}`.
    rest: Vec<f64>,
    nearest: Vec<f64>,
}

impl AxisMode {
    fn new(mode: usize, n: usize, cell: f64, nodes: &[f64]) -> Self {
        if mode == 0 {
            // Only the q = 0 alias (k = 0) has weight: sinc(qπ) = 0 otherwise; w_0 = ½.
            return Self {
                w0: 0.5,
                k0: 0.0,
                rest: vec![0.0; nodes.len()],
                nearest: vec![0.5; nodes.len()],
            };
        }
        let theta = mode as f64 * PI / (2.0 * n as f64);
        let s2 = theta.sin().powi(2);
        let w0 = s2 / (theta * theta);
        let k0 = 2.0 * theta / cell;
        let mut rest = Vec::with_capacity(nodes.len());
        let mut nearest = Vec::with_capacity(nodes.len());
        for &s in nodes {
            let sigma = 2.0 * s / cell;
            let x0 = w0 * (-(k0 * s).powi(2)).exp();
            // Σ_{q≠0}: directly where the Gaussians are narrow (σ ≥ 1: the first alias
            // left out, |q| = 5, has |θ + qπ| ≥ 4.5π, e^{-(4.5π)²} < 1e-80); for σ < 1 from
            // X = sin²θ Σ_q e^{-σ²u_q²}/u_q² = 1 - sin²θ ∫_0^{σ²} Θ(t) dt (Σ_q 1/u_q² =
            // 1/sin²θ), with Poisson's dual Θ(t) = (1 + 2Σ_n e^{-n²/t} cos 2nθ)/√(πt),
            // integrated in closed form (n ≤ 8: e^{-81/σ²} < 1e-35).
            let r = if sigma >= 1.0 {
                (-4i32..=4)
                    .filter(|&q| q != 0)
                    .map(|q| {
                        let u = theta + q as f64 * PI;
                        (-(sigma * u).powi(2)).exp() / (u * u)
                    })
                    .sum::<f64>()
                    * s2
            } else {
                let mut integral = 2.0 * sigma / PI.sqrt();
                for k in 1..=8 {
                    let n = k as f64;
                    // ∫_0^T t^{-1/2} e^{-n²/t} dt = 2√T e^{-n²/T} - 2√π n erfc(n/√T).
                    let j = 2.0 * sigma * (-(n / sigma).powi(2)).exp()
                        - 2.0 * PI.sqrt() * n * libm::erfc(n / sigma);
                    integral += 2.0 / PI.sqrt() * (2.0 * n * theta).cos() * j;
                }
                1.0 - s2 * integral - x0
            };
            rest.push(r);
            nearest.push(x0);
        }
        Self {
            w0,
            k0,
            rest,
            nearest,
        }
    }
}

/// Every eigenvalue `λ(p', m')` (index `m' Nx + p'`, m⁻¹) with its error estimate.
///
/// The alias sum `Σ_{q,r} S_q² S_r² coth(κ Lz)/κ` converges like `1/Q` in the alias box,
/// so it is not summed term by term. With `coth(κLz)/κ = (2/√π) ∫_0^∞ e^{-κ² s²} ϑ(s) ds`
/// (Mittag-Leffler's expansion of coth, each term a Gaussian integral; [`depth_images`])
/// and `κ² = k_q² + k_r²`, the sum is `(2/√π) ∫_0^∞ X(s) Y(s) ϑ(s) ds`, a product of two
/// 1-D Gaussian alias sums (each summed directly or through its Poisson dual, see
/// [`AxisMode`]). The nearest alias pair `q = r = 0`, whose Gaussian is the widest, is
/// taken out and summed with its closed-form kernel; the rest decays like
/// `e^{-π² s²/Δ²}` and is integrated by composite Gauss–Legendre. The 1-D sums are
/// tabulated per mode and shared by every eigenvalue: `O(N)` work. Error estimate: the
/// difference of two quadrature orders plus rounding; the values agree with alias boxes
/// of half-width 4096 to about 1e-13 (docs/accuracy.md). Also returns the number of
/// quadrature nodes per eigenvalue.
pub(super) fn eigenvalues(grid: &Grid) -> (Vec<f64>, Vec<f64>, usize) {
    let b = grid.block();
    let lz = b.lz();
    let (dx, dy) = (grid.dx(), grid.dy());
    let edges = panel_edges(dx.min(dy).min(lz), dx.max(dy));
    let [(high_nodes, high_weights), (low_nodes, low_weights)] = composite_rules(&edges);
    let nodes: Vec<f64> = high_nodes.iter().chain(&low_nodes).copied().collect();
    let images: Vec<f64> = nodes.iter().map(|&s| depth_images(s, lz)).collect();
    let xs: Vec<AxisMode> = (0..grid.nx())
        .map(|p| AxisMode::new(p, grid.nx(), dx, &nodes))
        .collect();
    let ys: Vec<AxisMode> = (0..grid.ny())
        .map(|m| AxisMode::new(m, grid.ny(), dy, &nodes))
        .collect();
    let split = high_nodes.len();
    let scale = 4.0 / (b.lx() * b.ly());
    let gauss = 2.0 / PI.sqrt();
    let mut lambda = Vec::with_capacity(grid.len());
    let mut errors = Vec::with_capacity(grid.len());
    for y in &ys {
        for x in &xs {
            if x.k0 == 0.0 && y.k0 == 0.0 {
                // κ = 0: the mean, `Lz/3` in place of the kernel.
                lambda.push(lz / (3.0 * b.lx() * b.ly()));
                errors.push(0.0);
                continue;
            }
            let integrand = |j: usize| {
                (x.rest[j] * y.rest[j] + x.rest[j] * y.nearest[j] + x.nearest[j] * y.rest[j])
                    * images[j]
            };
            let high: f64 = (0..split).map(|j| high_weights[j] * integrand(j)).sum();
            let low: f64 = (0..low_nodes.len())
                .map(|j| low_weights[j] * integrand(split + j))
                .sum();
            let nearest = x.w0 * y.w0 * depth_kernel(x.k0.hypot(y.k0), lz);
            let value = nearest + gauss * high;
            let error =
                gauss * (high - low).abs() + 16.0 * f64::EPSILON * (nearest + gauss * high.abs());
            lambda.push(scale * value);
            errors.push(scale * error);
        }
    }
    (lambda, errors, nodes.len())
}
