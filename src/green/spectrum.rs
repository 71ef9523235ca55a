//! The eigenvalues of the Galerkin operator: alias sums over the wavenumbers of each
//! DCT mode, cell-averaged and depth-summed (module docs of [`super::plan`]).

use crate::error::{Error, Result};
use crate::geometry::Grid;
use std::f64::consts::PI;

/// Largest alias box half-width `Q` before the alias sum reports [`Error::NotConverged`].
pub(super) const MAX_ALIAS: usize = 512;

/// Cell-averaging weights and wavenumbers of the aliases of one 1-D DCT mode.
pub(super) struct Aliases {
    pub(super) theta: f64,
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
        return Aliases {
            theta,
            terms,
            weight: 0.5,
        };
    }
    let s2 = theta.sin().powi(2);
    let mut weight = 0.0;
    for q in -(q_max as i64)..=(q_max as i64) {
        let t = theta + q as f64 * PI;
        let w = s2 / (t * t);
        weight += w;
        terms.push((w, 2.0 * t.abs() / cell));
    }
    Aliases {
        theta,
        terms,
        weight,
    }
}

/// `Σ_{|q|>Q} 1/|θ + qπ|³` by the Euler–Maclaurin midpoint rule (error O(Q⁻⁷)).
fn tail_cubed(theta: f64, q: usize) -> f64 {
    let mut total = 0.0;
    for a in [theta / PI, -theta / PI] {
        let b = q as f64 + 0.5 + a;
        total += 1.0 / (2.0 * b * b) + 1.0 / (8.0 * b.powi(4)) - 7.0 / (96.0 * b.powi(6));
    }
    total / PI.powi(3)
}

/// `coth(κ Lz)/κ`, the depth-summed kernel of the bottom face; `Lz/3` at `κ = 0`.
fn depth_kernel(kappa: f64, lz: f64) -> f64 {
    if kappa == 0.0 {
        lz / 3.0
    } else {
        1.0 / (kappa * (kappa * lz).tanh())
    }
}

/// The alias sum of one eigenvalue with box `Q`, tail-corrected.
fn lambda_box(grid: &Grid, p: usize, m: usize, q: usize) -> f64 {
    let b = grid.block();
    let ax = aliases(p, grid.nx(), grid.dx(), q);
    let ay = aliases(m, grid.ny(), grid.dy(), q);
    let lz = b.lz();
    let mut sum = 0.0;
    for &(wx, kx) in &ax.terms {
        for &(wy, ky) in &ay.terms {
            sum += wx * wy * depth_kernel((kx * kx + ky * ky).sqrt(), lz);
        }
    }
    // Strips outside the box: κ ≈ k along the long side, coth = 1 there.
    if p != 0 {
        sum += ay.weight * ax.theta.sin().powi(2) * grid.dx() / 2.0 * tail_cubed(ax.theta, q);
    }
    if m != 0 {
        sum += ax.weight * ay.theta.sin().powi(2) * grid.dy() / 2.0 * tail_cubed(ay.theta, q);
    }
    4.0 / (b.lx() * b.ly()) * sum
}

/// One eigenvalue with its error estimate, `Q` doubled until converged.
pub(super) fn lambda_adaptive(grid: &Grid, p: usize, m: usize, tol: f64) -> Result<(f64, f64)> {
    if p == 0 && m == 0 {
        let b = grid.block();
        return Ok((b.lz() / (3.0 * b.lx() * b.ly()), 0.0));
    }
    let mut q = 2;
    let mut previous = lambda_box(grid, p, m, 1);
    loop {
        let value = lambda_box(grid, p, m, q);
        // Successive errors shrink ~14x per doubling: |Δ|/4 over-estimates the error.
        let error = (value - previous).abs() / 4.0;
        if error <= tol * value {
            return Ok((value, error));
        }
        if q >= MAX_ALIAS {
            return Err(Error::NotConverged {
                what: "alias sum of the influence operator",
                value,
                error,
                tolerance: tol,
                terms: ((2 * q + 1) * (2 * q + 1)) as u64,
            });
        }
        previous = value;
        q *= 2;
    }
}
