//! Projected preconditioned conjugate gradients for the equality-constrained solve on an
//! attached set: `A f + U 1 = b`, `1ᵀ f = total`, `A` symmetric positive definite.
//!
//! The iterates stay on the constraint (every search direction has zero sum), and the
//! multiplier `U` is estimated in the preconditioner's metric, `U = -1ᵀM⁻¹r / 1ᵀM⁻¹1`
//! (the constraint preconditioner of Gould, Hribar and Nocedal, 2001). With an exact
//! preconditioner (the dense backend's LDLᵀ factor) one iteration solves the system.

/// The operator and preconditioner restricted to one attached set.
pub(crate) trait SetSystem {
    /// `y = A x`.
    fn apply(&mut self, x: &[f64], y: &mut [f64]);
    /// `z = M⁻¹ r`.
    fn precondition(&mut self, r: &[f64], z: &mut [f64]);
    /// An upper bound of `‖A‖₂` (m/Pa), the scale of the backward error.
    fn norm_bound(&self) -> f64;
}

/// What [`projected_pcg`] returns.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PcgOutcome {
    /// The multiplier `U` (units of `b`).
    pub offset: f64,
    /// Iterations spent.
    pub iterations: usize,
    /// Normwise backward error `‖A f + U 1 - b‖∞ / (‖A‖ ‖f‖∞ + ‖b‖∞ + |U|)`.
    pub residual: f64,
    /// Whether `residual ≤ tol`.
    pub converged: bool,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Solves in place: `f` holds the warm start on entry and the solution on exit.
pub(crate) fn projected_pcg<S: SetSystem>(
    sys: &mut S,
    b: &[f64],
    total: f64,
    f: &mut [f64],
    tol: f64,
    max_iterations: usize,
) -> PcgOutcome {
    let n = f.len();
    debug_assert_eq!(b.len(), n);
    let fix_sum = |f: &mut [f64]| {
        let shift = (total - f.iter().sum::<f64>()) / n as f64;
        f.iter_mut().for_each(|x| *x += shift);
    };
    fix_sum(f);
    let ones = vec![1.0; n];
    let mut w = vec![0.0; n];
    sys.precondition(&ones, &mut w);
    let s1: f64 = w.iter().sum();
    let norm_a = sys.norm_bound();
    let norm_b = max_abs(b);

    let mut r = vec![0.0; n];
    let mut q = vec![0.0; n];
    let mut z = vec![0.0; n];
    let mut p = vec![0.0; n];
    // r = A f + U 1 - b, the residual of the whole KKT system.
    let residual_of = |sys: &mut S, f: &[f64], offset: f64, r: &mut [f64]| {
        sys.apply(f, r);
        r.iter_mut().zip(b).for_each(|(ri, bi)| *ri += offset - bi);
    };
    // z = P M⁻¹ r (zero sum). The multiplier estimate is folded into U and r at once,
    // so r stays small (the constant part of r would otherwise swamp rᵀz in rounding:
    // the residual-update strategy of Gould, Hribar and Nocedal).
    let project = |sys: &mut S, r: &mut [f64], z: &mut [f64], offset: &mut f64| {
        sys.precondition(r, z);
        let u = -z.iter().sum::<f64>() / s1;
        z.iter_mut().zip(&w).for_each(|(zi, wi)| *zi += u * wi);
        r.iter_mut().for_each(|ri| *ri += u);
        *offset += u;
    };
    let backward = |r: &[f64], f: &[f64], u: f64| -> f64 {
        let num = max_abs(r);
        let den = norm_a * max_abs(f) + norm_b + u.abs();
        if den > 0.0 {
            num / den
        } else {
            0.0
        }
    };

    let mut offset = 0.0;
    residual_of(sys, f, offset, &mut r);
    project(sys, &mut r, &mut z, &mut offset);
    let mut residual = backward(&r, f, offset);
    let mut iterations = 0;
    if residual <= tol {
        return PcgOutcome {
            offset,
            iterations,
            residual,
            converged: true,
        };
    }
    p.iter_mut().zip(&z).for_each(|(pi, zi)| *pi = -zi);
    let mut rz = dot(&r, &z);
    // The best iterate so far, kept in one buffer (no allocation per iteration).
    let mut best = (residual, f.to_vec(), offset);
    let mut confirmed = false;
    while iterations < max_iterations {
        iterations += 1;
        sys.apply(&p, &mut q);
        let pq = dot(&p, &q);
        if !(pq > 0.0 && rz.is_finite()) {
            break; // no curvature left: rounding has taken over
        }
        let alpha = rz / pq;
        f.iter_mut().zip(&p).for_each(|(fi, pi)| *fi += alpha * pi);
        if iterations % 64 == 0 {
            fix_sum(f);
            residual_of(sys, f, offset, &mut r); // refresh the recurrence against drift
        } else {
            r.iter_mut().zip(&q).for_each(|(ri, qi)| *ri += alpha * qi);
        }
        project(sys, &mut r, &mut z, &mut offset);
        residual = backward(&r, f, offset);
        keep_best(&mut best, residual, f, offset);
        if residual <= tol {
            // Confirm with the true residual; rounding in the recurrence can flatter it.
            fix_sum(f);
            residual_of(sys, f, offset, &mut r);
            project(sys, &mut r, &mut z, &mut offset);
            residual = backward(&r, f, offset);
            keep_best(&mut best, residual, f, offset);
            if residual <= tol {
                confirmed = true;
                break;
            }
            // Restart from the true residual.
            p.iter_mut().zip(&z).for_each(|(pi, zi)| *pi = -zi);
            rz = dot(&r, &z);
            continue;
        }
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        p.iter_mut()
            .zip(&z)
            .for_each(|(pi, zi)| *pi = beta * *pi - zi);
    }
    if confirmed {
        // The true residual of f was just computed: another product would only repeat it.
        return PcgOutcome {
            offset,
            iterations,
            residual,
            converged: true,
        };
    }
    // Report the true residual of the returned iterate, not the recurrence's.
    if best.0 < residual {
        f.copy_from_slice(&best.1);
        offset = best.2;
    }
    fix_sum(f);
    residual_of(sys, f, offset, &mut r);
    project(sys, &mut r, &mut z, &mut offset);
    residual = backward(&r, f, offset);
    PcgOutcome {
        offset,
        iterations,
        residual,
        converged: residual <= tol,
    }
}

/// Keeps the iterate with the smallest backward error (CG residuals are not monotone).
fn keep_best(best: &mut (f64, Vec<f64>, f64), residual: f64, f: &[f64], offset: f64) {
    if residual < best.0 {
        best.0 = residual;
        best.1.copy_from_slice(f);
        best.2 = offset;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    struct Diag(Vec<f64>);
    impl SetSystem for Diag {
        fn apply(&mut self, x: &[f64], y: &mut [f64]) {
            let n = x.len();
            for i in 0..n {
                y[i] = self.0[i] * x[i];
                if i > 0 {
                    y[i] += 0.3 * x[i - 1];
                }
                if i + 1 < n {
                    y[i] += 0.3 * x[i + 1];
                }
            }
        }
        fn precondition(&mut self, r: &[f64], z: &mut [f64]) {
            z.copy_from_slice(r);
        }
        fn norm_bound(&self) -> f64 {
            100.0
        }
    }
    #[test]
    fn solves_small_system() {
        let n = 50;
        let mut sys = Diag((0..n).map(|i| 1.0 + i as f64).collect());
        let b: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut f = vec![0.0; n];
        let out = projected_pcg(&mut sys, &b, 2.0, &mut f, 1e-14, 500);
        eprintln!("{out:?}");
        assert!(out.converged);
    }
}
