#!/usr/bin/env python3
"""Independent prediction of the heights' statistics AFTER the Gaussian copula
(src/surface.rs, docs/model.md 3.1), pinned in tests/surfaces.rs
(`the_heights_after_the_copula_have_the_predicted_mean_and_covariance`).

Written from the specification, not from the Rust code. The Gaussian field g has unit
variance and correlation rho(r) = exp(-r^2/xi^2); the height at a point is
u0 = F^-1(Phi(g)), F the truncated Gaussian (mean m, sd s before truncation at 0); a
cell's height is the average of u0 over the cell. Then:

* mean of every height: the truncated Gaussian's, m + s phi(a)/Q(a), a = -m/s (closed
  form; averaging keeps it);
* covariance of u0 at two points whose g are correlated rho: by Mehler's expansion
  C(rho) = sum_{n>=1} c_n^2 rho^n / n!, c_n = E[u0(Z) He_n(Z)] (mpmath quadrature); the
  series is checked against the closed-form variance at rho = 1 and against a direct
  double integral E[u0(Z1) u0(Z2)] at rho = 0.5;
* covariance of two cells' heights at a lag of (kx, ky) cells of dx x dy: the average
  of C over both cells, int int (1-|t|)(1-|v|) C(rho(kx dx + t dx, ky dy + v dy)) dt dv
  over [-1, 1]^2 (the triangle weights of the difference of two uniform points).

    python3 docs/experiments/copula_correlation.py       # needs mpmath (1.3); ~1 min

prints, in units of s^2, the covariances pinned in the test (xi = 2 mm, 0.5 mm cells,
m = s = 1 um: the paper's marginal).
"""
import math

import mpmath as mp

mp.mp.dps = 25

M, S = mp.mpf("1e-6"), mp.mpf("1e-6")  # the paper's marginal (m)
XI = mp.mpf("2e-3")  # correlation length (m)
DX = DY = mp.mpf("0.5e-3")  # cell size (m)
LAGS = [(0, 0), (1, 0), (2, 0), (4, 0), (8, 0), (0, 2), (3, 3)]
N_TERMS = 40

A = -M / S
Q = mp.ncdf(-A)  # Q(a) = 1 - Phi(a)
PHI_A = mp.npdf(A)


def u0(z):
    """The height (in units of s) of the standard normal value z: y - a with y the
    truncated normal's quantile at Phi(z), F(y) = (Phi(y) - Phi(a))/Q(a)."""
    if z <= 0:
        p = mp.ncdf(A) + mp.ncdf(z) * Q
        return mp.sqrt(2) * mp.erfinv(2 * p - 1) - A
    # Upper half: Q(y) = Phi(-z) Q(a), solved by Newton on log Q from y = z (Q(y) <= Phi(-z)
    # so y >= z), since 2p - 1 rounds to 1 in the far tail.
    target = mp.log(mp.ncdf(-z) * Q)
    y = mp.mpf(z)
    for _ in range(100):
        tail = mp.ncdf(-y)
        step = (mp.log(tail) - target) * tail / mp.npdf(y)
        y += step
        if abs(step) < mp.mpf(10) ** (-mp.mp.dps + 3) * (1 + abs(y)):
            break
    return y - A


def hermite_values(z, n_terms):
    """He_0(z), ..., He_n(z) (probabilists'), by He_{n+1} = z He_n - n He_{n-1}."""
    h = [mp.mpf(1), z]
    for n in range(1, n_terms):
        h.append(z * h[n] - n * h[n - 1])
    return h


def hermite_coefficients(n_terms, nodes):
    """c_n = E[u0(Z) He_n(Z)], n = 0..n_terms, by Gauss-Hermite quadrature of `nodes`
    points (weight exp(-x^2), so Z = sqrt(2) x)."""
    xs, ws = mp.gauss_quadrature(nodes, "hermite")
    c = [mp.mpf(0)] * (n_terms + 1)
    for x, w in zip(xs, ws):
        z = mp.sqrt(2) * x
        uz = u0(z) * w / mp.sqrt(mp.pi)
        for n, h in enumerate(hermite_values(z, n_terms)):
            c[n] += uz * h
    return c


C = hermite_coefficients(N_TERMS, 160)
FACT = [mp.factorial(n) for n in range(N_TERMS + 1)]
# The Mehler series' coefficients as floats: the cell averages below need ~1e-8 only.
TERMS = [float(C[n] ** 2 / FACT[n]) for n in range(N_TERMS + 1)]


def cov_points(rho):
    """Covariance (units s^2) of u0 at two points whose g are correlated rho (Mehler)."""
    return mp.fsum(C[n] ** 2 * mp.mpf(rho) ** n / FACT[n] for n in range(1, N_TERMS + 1))


def cov_points_float(rho):
    total, power = 0.0, 1.0
    for n in range(1, N_TERMS + 1):
        power *= rho
        total += TERMS[n] * power
    return total


def main():
    mean = -A + PHI_A / Q  # units of s: (m + s phi/Q)/s
    var = 1 + A * PHI_A / Q - (PHI_A / Q) ** 2
    print(f"closed form: mean/s = {mp.nstr(mean, 17)}, var/s^2 = {mp.nstr(var, 17)}, "
          f"sd/s = {mp.nstr(mp.sqrt(var), 17)}")
    print(f"c_0 (the mean again) = {mp.nstr(C[0], 17)}")
    other = hermite_coefficients(N_TERMS, 200)
    print(f"the Mehler terms c_n^2/n! from 160 and 200 Gauss-Hermite points differ by at most "
          f"{mp.nstr(max(abs(x**2 - y**2) / f for x, y, f in zip(C, other, FACT)), 3)}")
    print(f"Mehler series at rho = 1: {mp.nstr(cov_points(1), 17)} "
          f"(closed form {mp.nstr(var, 17)}, last term {mp.nstr(C[N_TERMS]**2 / FACT[N_TERMS], 3)})")
    # Direct double integral at rho = 0.5: E[u0(Z1) u0(rho Z1 + sqrt(1-rho^2) W)] - mean^2.
    rho = mp.mpf("0.5")
    xs, ws = mp.gauss_quadrature(60, "hermite")
    direct = mp.fsum(
        w1 * w2 * u0(mp.sqrt(2) * x1) * u0(rho * mp.sqrt(2) * x1 + mp.sqrt(1 - rho**2) * mp.sqrt(2) * x2)
        for x1, w1 in zip(xs, ws) for x2, w2 in zip(xs, ws)) / mp.pi - C[0] ** 2
    print(f"rho = 0.5: Mehler {mp.nstr(cov_points(rho), 12)}, double integral {mp.nstr(direct, 12)}")
    # The cell average: Gauss-Legendre on [-1, 0] and [0, 1] per axis (the weight's kink).
    ts, wts = mp.gauss_quadrature(40, "legendre")
    half = [(float(t - 1) / 2, float(w) / 2) for t, w in zip(ts, wts)]
    half += [(float(t + 1) / 2, float(w) / 2) for t, w in zip(ts, wts)]
    xi, dx, dy = float(XI), float(DX), float(DY)
    print("cell-averaged covariances (units s^2), xi = 2 mm, 0.5 mm cells:")
    for kx, ky in LAGS:
        cov = 0.0
        for t, wt in half:
            for v, wv in half:
                x, y = (kx + t) * dx, (ky + v) * dy
                rho = math.exp(-(x * x + y * y) / xi**2)
                cov += wt * wv * (1 - abs(t)) * (1 - abs(v)) * cov_points_float(rho)
        print(f"    (({kx}, {ky}), {cov!r}),")


if __name__ == "__main__":
    main()
