#!/usr/bin/env python3
"""What `precursors stats` does for one observable, done with the `powerlaw` package
(J. Alstott et al., pip `powerlaw`), timed: the reference of docs/performance.md,
"`stats` against the powerlaw package" (issue 54 item 5).

The samples: the avalanche sizes (`ruptures`) of every run under DIR (a run directory or
a sweep's), read from each run's `per_avalanche.csv` with the rows `stats` pools (not
global slip, not the spanning avalanche, not after it); or the samples of --samples
FILE, one number a line. For them, as `stats` does:

1. `powerlaw.Fit` (x_min by the smallest KS distance over every distinct value, alpha by
   maximum likelihood) and the likelihood-ratio tests against the exponential, the
   log-normal and the truncated power law, and of the truncated law against the
   log-normal;
2. BOOTSTRAP resamples, each refitted (x_min, alpha, and the truncated law's alpha and
   1/lambda on its tail);
3. GOODNESS synthetic sets (Clauset et al. sec. 4.1: the fitted law above x_min, the
   data below it, binomially mixed), each refitted for its KS distance.

Prints the time of each part and per refit. The full default (200 and 200) on 1e6
samples takes hours; `--bootstrap 4 --goodness 4` times a few refits, and the total is
then the one fit plus 400 refits at the measured mean (docs/performance.md says which
figures are measured and which are extrapolated).

Not a dependency of the crate or of CI: `python3 -m venv /tmp/pl && /tmp/pl/bin/pip
install powerlaw`, then `/tmp/pl/bin/python scripts/powerlaw-stats.py DIR`.
"""
import argparse
import csv
import json
import pathlib
import time
import warnings

import numpy as np
import powerlaw


def pooled_sizes(root):
    files = sorted(pathlib.Path(root).rglob("per_avalanche.csv"))
    sizes = []
    for f in files:
        with open(f, newline="") as h:
            for row in csv.DictReader(h):
                if row["global_slip"] == "1" or row["spanning"] == "1" or row["after_spanning"] == "1":
                    continue
                sizes.append(float(row["ruptures"]))
    return np.array(sizes), len(files)


def fit(xs, discrete):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return powerlaw.Fit(xs, discrete=discrete, verbose=False)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dir", nargs="?")
    ap.add_argument("--samples")
    ap.add_argument("--continuous", action="store_true")
    ap.add_argument("--bootstrap", type=int, default=200)
    ap.add_argument("--goodness", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    discrete = not a.continuous
    if a.samples:
        xs, files = np.loadtxt(a.samples), 0
    else:
        xs, files = pooled_sizes(a.dir)
    xs = xs[xs > 0]
    rng = np.random.default_rng(a.seed)
    out = {"samples": int(len(xs)), "runs": files, "discrete": discrete}

    t0 = time.perf_counter()
    f = fit(xs, discrete)
    out.update(x_min=float(f.xmin), alpha=float(f.alpha), ks=float(f.D))
    t1 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name, (d1, d2) in {
            "exponential": ("power_law", "exponential"),
            "lognormal": ("power_law", "lognormal"),
            "cutoff": ("power_law", "truncated_power_law"),
            "cutoff_vs_lognormal": ("truncated_power_law", "lognormal"),
        }.items():
            r, p = f.distribution_compare(d1, d2, normalized_ratio=True)
            out[f"lr_{name}"] = [float(r), float(p)]
        out["cutoff"] = [float(f.truncated_power_law.alpha), float(1 / f.truncated_power_law.Lambda)]
    t2 = time.perf_counter()
    out["seconds_fit"] = t1 - t0
    out["seconds_alternatives"] = t2 - t1

    boot = []
    t3 = time.perf_counter()
    for _ in range(a.bootstrap):
        r = fit(rng.choice(xs, size=len(xs), replace=True), discrete)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            boot.append((r.alpha, r.xmin, r.truncated_power_law.alpha, r.truncated_power_law.Lambda))
    t4 = time.perf_counter()
    below = xs[xs < f.xmin]
    p_tail = 1.0 - len(below) / len(xs)
    exceed = 0
    for _ in range(a.goodness):
        m = rng.binomial(len(xs), p_tail) if len(below) else len(xs)
        syn = np.concatenate(
            [f.power_law.generate_random(m), rng.choice(below, size=len(xs) - m) if len(below) else []]
        )
        exceed += fit(syn, discrete).D >= f.D
    t5 = time.perf_counter()
    out["bootstrap"] = a.bootstrap
    out["goodness"] = a.goodness
    out["seconds_bootstrap"] = t4 - t3
    out["seconds_goodness"] = t5 - t4
    if a.goodness:
        out["p_value"] = exceed / a.goodness
    refits = a.bootstrap + a.goodness
    if refits:
        per = (t5 - t3) / refits
        out["seconds_per_refit"] = per
        out["seconds_default_estimate"] = (t2 - t0) + 400 * per
    out["seconds_total"] = t5 - t0
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
