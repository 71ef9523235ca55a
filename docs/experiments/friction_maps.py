#!/usr/bin/env python3
"""Heterogeneous friction under a top load (docs/contact-rules.md, issue 55 item 5).

Reads the sweeps of examples/sweeps/contact-rules/friction_map_*.json from their run
directories' events.csv, curve.csv, per_avalanche.csv and scene.json alone (plain Python,
independent of the crate), and prints, per sweep point, medians and quartiles over the
runs of:

  slip     F/(mu_bar F_N) of the last stable state before global slip, mu_bar the
           map's mean (the material's mu without a map): not the tables' F/(mu F_N),
           which take mu as the map's largest value;
  onset    the load of the first stable state with a detached patch of 5 mm or more
           (5 consecutive columns whose every site has broken), over the slip load;
  patch50, patch90
           the longest such patch anywhere on the interface, over Lx, at the stable
           state in effect at 0.5 and 0.9 of the slip load;
  ell90    the paper's precursor length l/Lx (curve.csv), from the trailing edge, there;
  jumps    the arrested events: stable states (before global slip) at which the longest
           detached patch grew by 5 mm or more in one avalanche, and the largest such
           growth over Lx (jump);
  biggest  the largest avalanche before the spanning one, in ruptures, and its extent
           over Lx (per_avalanche.csv's extent_m).

Usage: python3 friction_maps.py NAME=SWEEP_DIR [NAME=SWEEP_DIR ...]
"""
import csv
import json
import os
import statistics
import sys


def quartiles(xs):
    xs = sorted(xs)
    if not xs:
        return (float("nan"),) * 3
    q = statistics.quantiles(xs, n=4, method="inclusive") if len(xs) > 1 else [xs[0]] * 3
    return q[0], statistics.median(xs), q[2]


def longest_patch(broken_cols, ny, min_len=1):
    """Longest run of consecutive columns with all ny sites broken."""
    best = run = 0
    for b in broken_cols:
        run = run + 1 if b == ny else 0
        best = max(best, run)
    return best


def analyse_run(d):
    scene = json.load(open(os.path.join(d, "scene.json")))
    lx, ly = scene["block"]["lx"], scene["block"]["ly"]
    cells = scene["cells"]
    nx = round(lx / cells["dx"]) if cells["kind"] == "size" else cells["nx"]
    ny = round(ly / cells["dy"]) if cells["kind"] == "size" else cells["ny"]
    fmap = scene.get("maps", {}).get("friction_coefficient")
    mu = fmap["mean"] if fmap else scene["material"]["friction_coefficient"]
    fn = scene["normal_load"]
    broken = [0] * nx
    states = []  # (force, longest patch in columns) at each stable state
    for row in csv.DictReader(open(os.path.join(d, "events.csv"))):
        kind = row["kind"]
        if kind == "rupture":
            broken[int(row["ix"])] += 1
        elif kind == "stable":
            states.append((float(row["force_N"]), longest_patch(broken, ny), int(row["index"])))
    slip = states[-1][0]
    curve = [(float(r["force_N"]), float(r["precursor_over_Lx"]))
             for r in csv.DictReader(open(os.path.join(d, "curve.csv")))]

    def at(frac, series):
        level = frac * slip
        last = series[0]
        for s in series:
            if s[0] <= level:
                last = s
        return last

    min_cols = round(0.005 / (lx / nx))
    growth = [b[1] - a[1] for a, b in zip(states, states[1:])]
    jumps = [g for g in growth if g >= min_cols]
    onset = next((s[0] for s in states if s[1] >= round(0.005 / (lx / nx))), slip) / slip
    av = list(csv.DictReader(open(os.path.join(d, "per_avalanche.csv"))))
    before = [a for a in av if a["spanning"] == "0" and a["after_spanning"] == "0"
              and a["global_slip"] == "0"]
    big = max(before, key=lambda a: int(a["ruptures"])) if before else None
    return {
        "slip": slip / (mu * fn),
        "onset": onset,
        "patch50": at(0.5, states)[1] / nx,
        "patch90": at(0.9, states)[1] / nx,
        "ell90": at(0.9, curve)[1],
        "jumps": len(jumps),
        "jump": max(jumps, default=0) / nx,
        "biggest": int(big["ruptures"]) if big else 0,
        "biggest_extent": float(big["extent_m"]) / lx if big else 0.0,
    }


def main():
    keys = ["slip", "onset", "patch50", "patch90", "ell90", "jumps", "jump", "biggest",
            "biggest_extent"]
    print("| sweep | correlation length (mm) | runs | " + " | ".join(keys) + " |")
    print("|---" * (len(keys) + 3) + "|")
    for arg in sys.argv[1:]:
        name, root = arg.split("=", 1)
        runs = {}
        for row in csv.DictReader(open(os.path.join(root, "runs.csv"))):
            if not row["stable_states"]:
                continue
            xi = row.get("maps.friction_coefficient.correlation_length", "")
            d = os.path.join(root, "p%04d-r%04d" % (int(row["point"]), int(row["realization"])))
            runs.setdefault(xi, []).append(analyse_run(d))
        for xi, rs in sorted(runs.items(), key=lambda kv: float(kv[0] or 0)):
            cells = []
            for k in keys:
                lo, med, hi = quartiles([r[k] for r in rs])
                fmt = "%.0f" if k in ("biggest", "jumps") else "%.3f"
                cells.append((fmt + " [" + fmt + ", " + fmt + "]") % (med, lo, hi))
            xi_mm = "%g" % (float(xi) * 1e3) if xi else "(no map)"
            print("| %s | %s | %d | %s |" % (name, xi_mm, len(rs), " | ".join(cells)))


if __name__ == "__main__":
    main()
