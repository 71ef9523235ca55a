#!/usr/bin/env python3
"""Reference values for the alternatives of `statistics::compare_alternatives`
(tests/statistics.rs, `alternatives_agree_with_an_independent_scipy_fit`).

Draws fixed samples from known laws with numpy, fits on each the power law, the
exponential, the log-normal and the power law with exponential cut-off by maximum
likelihood with scipy (written here from the likelihood formulas: normalisations by
scipy.special.zeta, scipy.stats.norm and scipy.integrate.quad or a direct sum; optimisation
by scipy.optimize), and computes the likelihood-ratio tests (Vuong for non-nested pairs,
Wilks for the nested cut-off). Nothing here is ported from the Rust code.

Writes lr_samples.csv (case,value: the samples, so Rust need not reproduce numpy's
generator) and lr_expected.csv (case,quantity,value). Run once, committed with its output:

    python3 -m venv /tmp/pyref && /tmp/pyref/bin/pip install numpy scipy
    /tmp/pyref/bin/python tests/data/statistics/make_lr_fixtures.py

Conventions shared with the Rust code (docs/statistics.md): every law is fitted on the
whole sample with x_min = its smallest value; the cut-off exponent is searched in [0, 20];
the log-normal includes its limit sigma -> infinity (a power law for reals, the rounded
power law for integers) and is that limit where the limit is at least as likely; the
discrete log-normal is the continuous one's mass in [k - 1/2, k + 1/2) normalised over
x >= x_min - 1/2. R = sum ln p1 - ln p2; Vuong's statistic R / sqrt(n var) (var over n);
p = erfc(|R| / sqrt(2 n var)) (1 when R = 0); Wilks p = chi2.sf(2|R|, 1).
"""
import os

import numpy as np
from scipy import integrate, optimize, special, stats

HERE = os.path.dirname(os.path.abspath(__file__))
N = 1000


def draw(name, rng):
    if name == "continuous_power_law":  # alpha 2.5 above 1
        return (1.0 - rng.random(N)) ** (-1.0 / 1.5)
    if name == "continuous_cutoff":  # alpha 1.5, lambda 0.01 above 1: rejection
        out = []
        while len(out) < N:
            x = (1.0 - rng.random()) ** (-1.0 / 0.5)
            if rng.random() < np.exp(-0.01 * (x - 1.0)):
                out.append(x)
        return np.array(out)
    if name == "continuous_lognormal":  # mu 0.5, sigma 1, kept above 1
        out = []
        while len(out) < N:
            x = rng.lognormal(0.5, 1.0)
            if x >= 1.0:
                out.append(x)
        return np.array(out)
    if name == "continuous_exponential":  # rate 1 above 1
        return 1.0 + rng.exponential(1.0, N)
    if name == "discrete_power_law":  # zeta, alpha 2.2
        return rng.zipf(2.2, N).astype(float)
    if name == "discrete_cutoff":  # alpha 1.5, lambda 0.02 above 1: rejection from zipf
        out = []
        while len(out) < N:
            k = float(rng.zipf(1.5))
            if rng.random() < np.exp(-0.02 * (k - 1.0)):
                out.append(k)
        return np.array(out)
    if name == "discrete_lognormal":  # rounded log-normal mu 2, sigma 0.8, kept >= 2
        out = []
        while len(out) < N:
            k = np.floor(rng.lognormal(2.0, 0.8) + 0.5)
            if k >= 2:
                out.append(k)
        return np.array(out)
    if name == "discrete_exponential":  # geometric above 1, lambda 0.3
        return rng.geometric(1.0 - np.exp(-0.3), N).astype(float)
    raise ValueError(name)


def maximise(f, starts, bounds):
    """Maximises f over a box: L-BFGS-B from each start, Nelder-Mead polish of the best."""
    best = None
    for s in starts:
        r = optimize.minimize(lambda v: -f(v), s, method="L-BFGS-B", bounds=bounds,
                              options={"ftol": 1e-15, "gtol": 1e-11, "maxiter": 10000})
        if best is None or r.fun < best.fun:
            best = r
    r = optimize.minimize(lambda v: -f(np.clip(v, [b[0] for b in bounds], [b[1] for b in bounds])),
                          best.x, method="Nelder-Mead",
                          options={"xatol": 1e-11, "fatol": 1e-13, "maxiter": 20000})
    x = np.clip(r.x, [b[0] for b in bounds], [b[1] for b in bounds])
    if -f(x) < best.fun:
        return x, f(x)
    return best.x, -best.fun


def scalar_max(f, lo, hi):
    r = optimize.minimize_scalar(lambda v: -f(v), bounds=(lo, hi), method="bounded",
                                 options={"xatol": 1e-12})
    return r.x, -r.fun


# ---------- continuous laws (x >= xm) ----------

def c_power_law(x, xm):
    a = 1.0 + len(x) / np.sum(np.log(x / xm))
    return {"alpha": a}, np.log(a - 1.0) - np.log(xm) - a * np.log(x / xm)


def c_exponential(x, xm):
    ll = lambda lnl: np.sum(lnl - np.exp(lnl) * (x - xm))
    lnl, _ = scalar_max(ll, -30.0, 30.0)
    lam = np.exp(lnl)
    return {"lambda": lam}, np.log(lam) - lam * (x - xm)


def c_lognormal(x, xm, pl):
    lx = np.log(x)
    lnpdf = lambda v: stats.norm.logpdf(lx, v[0], np.exp(v[1])) - lx - stats.norm.logsf(np.log(xm), v[0], np.exp(v[1]))
    f = lambda v: np.sum(lnpdf(v))
    m, s = lx.mean(), lx.std()
    v, best = maximise(f, [[m, np.log(s)], [m - 3 * s, np.log(3 * s)]], [(-1e4, 1e4), (-20, 20)])
    if np.sum(pl) >= best:  # the limit sigma -> inf: the power law itself
        return {"mu": -np.inf, "sigma": np.inf, "boundary": 1.0}, pl
    return {"mu": v[0], "sigma": np.exp(v[1]), "boundary": 0.0}, lnpdf(v)


def c_cutoff_lnz(a, lam, xm):
    """ln of int_xm^inf x^-a e^(-lam x) dx by quadrature in u = ln(x / xm)."""
    mu = lam * xm
    upper = np.log1p(800.0 / mu)
    g = lambda u: np.exp((1.0 - a) * u - mu * np.expm1(u))
    i, _ = integrate.quad(g, 0.0, upper, epsabs=0.0, epsrel=1e-13, limit=1000)
    return (1.0 - a) * np.log(xm) - mu + np.log(i)


def c_cutoff(x, xm, pl, alpha_pl):
    lx = np.log(x)
    lnpdf = lambda v: -v[0] * lx - np.exp(v[1]) * x - c_cutoff_lnz(v[0], np.exp(v[1]), xm)
    f = lambda v: np.sum(lnpdf(v))
    t1 = np.mean(x - xm)
    starts = [[min(alpha_pl, 20.0), np.log(1e-3 / t1)], [0.5 * alpha_pl, np.log(1.0 / t1)]]
    v, best = maximise(f, starts, [(0.0, 20.0), (np.log(1e-12 / t1), np.log(1e6 / t1))])
    if np.sum(pl) >= best:
        return {"alpha": alpha_pl, "lambda": 0.0}, pl
    return {"alpha": v[0], "lambda": np.exp(v[1])}, lnpdf(v)


# ---------- discrete laws (integers k >= xm) ----------

def d_power_law(k, xm):
    slk = np.sum(np.log(k))
    f = lambda a: -len(k) * np.log(special.zeta(a, xm)) - a * slk
    a, _ = scalar_max(f, 1.0 + 1e-9, 20.0)
    return {"alpha": a}, -a * np.log(k) - np.log(special.zeta(a, xm))


def d_exponential(k, xm):
    ll = lambda lnl: np.sum(np.log(-np.expm1(-np.exp(lnl))) - np.exp(lnl) * (k - xm))
    lnl, _ = scalar_max(ll, -30.0, 10.0)
    lam = np.exp(lnl)
    return {"lambda": lam}, np.log(-np.expm1(-lam)) - lam * (k - xm)


def log_mass(lo, hi, mu, s):
    """ln P(lo <= N(mu, s) < hi), from the side away from the mode."""
    a, b = (lo - mu) / s, (hi - mu) / s
    right = a > 0
    out = np.empty_like(a)
    sa, sb = stats.norm.logsf(a[right]), stats.norm.logsf(b[right])
    out[right] = sa + np.log(-np.expm1(sb - sa))
    ca, cb = stats.norm.logcdf(a[~right]), stats.norm.logcdf(b[~right])
    out[~right] = cb + np.log(-np.expm1(ca - cb))
    return out


def d_lognormal(k, xm):
    lo, hi, l0 = np.log(k - 0.5), np.log(k + 0.5), np.log(xm - 0.5)
    lnpdf = lambda v: log_mass(lo, hi, v[0], np.exp(v[1])) - stats.norm.logsf((l0 - v[0]) / np.exp(v[1]))
    f = lambda v: np.sum(lnpdf(v))
    lk = np.log(k)
    m, s = lk.mean(), lk.std()
    v, best = maximise(f, [[m, np.log(s)], [m - 3 * s, np.log(3 * s)]], [(-1e4, 1e4), (-20, 20)])
    # The limit sigma -> inf: the rounded power law ((k-1/2)/(xm-1/2))^-b - ((k+1/2)/(xm-1/2))^-b.
    limit = lambda b: -b * (lo - l0) + np.log(-np.expm1(-b * (hi - lo)))
    b, best_limit = scalar_max(lambda b: np.sum(limit(b)), 1e-9, 60.0)
    if best_limit >= best:
        return {"mu": -np.inf, "sigma": np.inf, "boundary": 1.0}, limit(b)
    return {"mu": v[0], "sigma": np.exp(v[1]), "boundary": 0.0}, lnpdf(v)


def d_cutoff_lnz(a, lam, xm):
    """ln sum_{j >= xm} j^-a e^(-lam j): directly while terms matter, the rest by quad."""
    top = int(min(xm + 60.0 / lam, xm + 5e6))
    j = np.arange(xm, top + 1, dtype=float)
    ln_terms = -a * np.log(j / xm) - lam * (j - xm)
    s = np.sum(np.exp(ln_terms))
    # Midpoint rule's remainder: int_{top+1/2}^inf, negligible (< e^-60) unless lam is tiny.
    g = lambda u: np.exp(-a * np.log(u / xm) - lam * (u - xm))
    rest, _ = integrate.quad(g, top + 0.5, np.inf, epsabs=0.0, epsrel=1e-12, limit=500)
    return -a * np.log(xm) - lam * xm + np.log(s + rest)


def d_cutoff(k, xm, pl, alpha_pl):
    lk = np.log(k)
    lnpdf = lambda v: -v[0] * lk - np.exp(v[1]) * k - d_cutoff_lnz(v[0], np.exp(v[1]), xm)
    f = lambda v: np.sum(lnpdf(v))
    t1 = np.mean(k - xm) / xm
    starts = [[min(alpha_pl, 20.0), np.log(1e-3 / t1 / xm)], [0.5 * alpha_pl, np.log(1.0 / t1 / xm)]]
    v, best = maximise(f, starts, [(0.0, 20.0), (np.log(1e-12 / t1 / xm), np.log(1e6 / t1 / xm))])
    if np.sum(pl) >= best:
        return {"alpha": alpha_pl, "lambda": 0.0}, pl
    return {"alpha": v[0], "lambda": np.exp(v[1])}, lnpdf(v)


def test(l1, l2, nested):
    d = l1 - l2
    n = len(d)
    r = np.sum(d)
    var = np.mean((d - d.mean()) ** 2)
    if var > 0:
        v = r / np.sqrt(n * var)
    else:
        v = 0.0 if r == 0 else np.copysign(np.inf, r)
    if nested:
        p = stats.chi2.sf(2 * abs(r), 1)
    else:
        p = 1.0 if r == 0 else special.erfc(abs(r) / np.sqrt(2 * n * var))
    return {"R": r, "normalized": v, "p": p}


CASES = [
    "continuous_power_law", "continuous_cutoff", "continuous_lognormal", "continuous_exponential",
    "discrete_power_law", "discrete_cutoff", "discrete_lognormal", "discrete_exponential",
]


def main():
    samples_rows, expected_rows = [], []
    for seed, name in enumerate(CASES):
        x = np.sort(draw(name, np.random.default_rng(1000 + seed)))
        xm = x[0]
        if name.startswith("continuous"):
            plp, pl = c_power_law(x, xm)
            exp, ex = c_exponential(x, xm)
            lnp, ln = c_lognormal(x, xm, pl)
            cut, cu = c_cutoff(x, xm, pl, plp["alpha"])
        else:
            plp, pl = d_power_law(x, xm)
            exp, ex = d_exponential(x, xm)
            lnp, ln = d_lognormal(x, xm)
            cut, cu = d_cutoff(x, xm, pl, plp["alpha"])
        values = {
            "x_min": xm,
            "power_law_alpha": plp["alpha"], "power_law_ll": np.sum(pl),
            "exponential_lambda": exp["lambda"], "exponential_ll": np.sum(ex),
            "lognormal_mu": lnp["mu"], "lognormal_sigma": lnp["sigma"],
            "lognormal_boundary": lnp["boundary"], "lognormal_ll": np.sum(ln),
            "cutoff_alpha": cut["alpha"], "cutoff_lambda": cut["lambda"], "cutoff_ll": np.sum(cu),
        }
        for key, (a, b, nested) in {
            "vs_exponential": (pl, ex, False), "vs_lognormal": (pl, ln, False),
            "vs_cutoff": (pl, cu, True), "cutoff_vs_lognormal": (cu, ln, False),
        }.items():
            for q, v in test(a, b, nested).items():
                values[f"{key}_{q}"] = v
        for v in x:
            samples_rows.append(f"{name},{float(v)!r}")
        for q, v in values.items():
            expected_rows.append(f"{name},{q},{float(v)!r}")
        print(name, {k: float(f"{v:.6g}") for k, v in values.items()})
    with open(os.path.join(HERE, "lr_samples.csv"), "w") as f:
        f.write("case,value\n" + "\n".join(samples_rows) + "\n")
    with open(os.path.join(HERE, "lr_expected.csv"), "w") as f:
        f.write("case,quantity,value\n" + "\n".join(expected_rows) + "\n")


if __name__ == "__main__":
    main()
