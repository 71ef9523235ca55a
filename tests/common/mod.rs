//! Shared test helpers: Gauss–Legendre quadrature (the independent reference for cell
//! averages and face integrals) and relative comparison.

/// Gauss–Legendre nodes and weights on [-1, 1] by Newton iteration on P_n.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        out.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    out
}

/// Composite Gauss–Legendre rule on [a, b] with `panels` panels of `n` points.
pub fn rule(a: f64, b: f64, panels: usize, n: usize) -> Vec<(f64, f64)> {
    let base = gauss_legendre(n);
    let h = (b - a) / panels as f64;
    let mut out = Vec::with_capacity(panels * n);
    for k in 0..panels {
        let (lo, hi) = (a + k as f64 * h, a + (k + 1) as f64 * h);
        for &(x, w) in &base {
            out.push((0.5 * (lo + hi) + 0.5 * (hi - lo) * x, 0.5 * (hi - lo) * w));
        }
    }
    out
}

/// Integral of `f` over [a, b].
pub fn integrate(a: f64, b: f64, panels: usize, n: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
    rule(a, b, panels, n)
        .into_iter()
        .map(|(x, w)| w * f(x))
        .sum()
}

/// |a - b| / max(|b|, floor)
pub fn rel(a: f64, b: f64, floor: f64) -> f64 {
    (a - b).abs() / b.abs().max(floor)
}

#[test]
fn gauss_legendre_integrates_polynomials_exactly() {
    // Degree 2n-1 exactness: ∫_0^2 x^9 dx = 2^10/10 with n = 5.
    let v = integrate(0.0, 2.0, 1, 5, |x| x.powi(9));
    assert!((v - 102.4).abs() < 1e-12);
}
