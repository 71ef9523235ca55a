"""The contact-rules study's numbers (docs/contact-rules.md), from the sweeps' run tables.

Plain Python (no numpy), independent of the crate: it reads each run's `events.csv`,
`curve.csv` and `per_avalanche.csv` as written and recounts.

    python3 docs/experiments/contact_rules.py paper=study/rod anchored=cr/anchored \
        rejuvenation=cr/rejuvenation

prints one table row per sweep (medians over the runs, and pooled shares):
* `slip`: F/(μF_N) at global slip;
* `ruptures`, `attaches`: per run (events.csv);
* `flash`: flash ruptures over all ruptures (per_avalanche.csv, pooled);
* `reformed`: attach events of a site that had already broken, per run;
* `rebroken`: ruptures of a site that had already broken, over all ruptures (pooled);
* `path_rebroken`: over the avalanches of two or more ruptures before the spanning one,
  the median share of the sites broken by earlier avalanches (the path so far) that the
  avalanche breaks again;
* `span`: F/(μF_N) of the spanning avalanche (per_avalanche.csv's `spanning` flag);
* `heal`: the contacts regained before the spanning avalanche: the sum of the rises of the
  number of sites in contact (curve.csv's `attached`) from one stable state to the next,
  over the number at zero shear (median), and `rising`, the share of those steps where it
  rises;
* `drop`: the fall of the number of sites in contact from zero shear to the last stable
  state before the spanning avalanche, over the number at zero shear (median).
"""

import csv
import os
import statistics
import sys


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def run_dirs(sweep):
    for name in sorted(os.listdir(sweep)):
        d = os.path.join(sweep, name)
        if os.path.isfile(os.path.join(d, "done")):
            yield d


def one_run(d):
    events = rows(os.path.join(d, "events.csv"))
    curve = rows(os.path.join(d, "curve.csv"))
    aval = rows(os.path.join(d, "per_avalanche.csv"))
    mu_fn = None
    for r in curve:
        f, x = float(r["force_N"]), float(r["force_over_mu_FN"])
        if f > 0 and x > 0:
            mu_fn = f / x
            break
    broken = set()
    reformed = rebroken = ruptures = attaches = 0
    # Which avalanche each rupture event belongs to: per_avalanche's event ranges.
    ranges = [(int(a["start_event"]), int(a["end_event"]), a) for a in aval]
    broken_by = {}  # site -> index of the avalanche that first broke it
    per_aval_sites = {i: [] for i in range(len(ranges))}
    k = 0
    for e in events:
        kind = e["kind"]
        if kind == "attach":
            attaches += 1
            if (e["ix"], e["iy"]) in broken:
                reformed += 1
        elif kind == "rupture":
            ruptures += 1
            site = (e["ix"], e["iy"])
            if site in broken:
                rebroken += 1
            broken.add(site)
            index = int(e["index"])
            while k < len(ranges) and ranges[k][1] < index:
                k += 1
            if k < len(ranges) and ranges[k][0] <= index <= ranges[k][1]:
                per_aval_sites[k].append(site)
    # The share of the path so far that each precursor breaks again.
    path = set()
    shares = []
    for i, (_, _, a) in enumerate(ranges):
        if a["spanning"] == "1" or a["after_spanning"] == "1" or a["global_slip"] == "1":
            break
        sites = per_aval_sites[i]
        if len(sites) >= 2 and path:
            shares.append(len(path & set(sites)) / len(path))
        path |= set(sites)
    span = [float(a["force_before_N"]) / mu_fn for a in aval if a["spanning"] == "1"]
    span_start = [int(a["start_event"]) for a in aval if a["spanning"] == "1"]
    # The sites in contact from stable state to stable state before the spanning
    # avalanche. Every step holds ruptures (each load raise brings a site to its
    # threshold), so a rise is contact gained (attached or re-formed) beyond what broke.
    # Not the real contact area: under the paper's area law A_R grows as the normal load
    # concentrates on fewer sites (docs/model.md section 3), which hides the count.
    before = [r for r in curve if not span_start or int(r["event"]) < span_start[0]]
    heal = 0.0
    rising = 0
    for prev, cur in zip(before, before[1:]):
        delta = int(cur["attached"]) - int(prev["attached"])
        if delta > 0:
            heal += delta
            rising += 1
    area0 = int(curve[0]["attached"])
    return {
        "slip": float(curve[-1]["force_over_mu_FN"]),
        "ruptures": ruptures,
        "attaches": attaches,
        "flash": sum(int(a["flash_ruptures"]) for a in aval),
        "aval_ruptures": sum(int(a["ruptures"]) for a in aval),
        "reformed": reformed,
        "rebroken": rebroken,
        "path_shares": shares,
        "span": span[0] if span else float("nan"),
        "heal": heal / area0,
        "rising": rising / max(len(before) - 1, 1),
        "drop": 1.0 - int(before[-1]["attached"]) / area0,
    }


def main():
    print("| rule | runs | slip | ruptures | attaches | flash | reformed | rebroken | path_rebroken | span | heal | rising | drop |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for arg in sys.argv[1:]:
        name, sweep = arg.split("=", 1)
        runs = [one_run(d) for d in run_dirs(sweep)]
        med = lambda key: statistics.median(r[key] for r in runs)
        shares = [s for r in runs for s in r["path_shares"]]
        flash = sum(r["flash"] for r in runs) / sum(r["aval_ruptures"] for r in runs)
        rebroken = sum(r["rebroken"] for r in runs) / sum(r["ruptures"] for r in runs)
        print(
            f"| {name} | {len(runs)} | {med('slip'):.3f} | {med('ruptures'):.0f} | "
            f"{med('attaches'):.0f} | {flash:.3f} | {med('reformed'):.0f} | {rebroken:.3f} | "
            f"{statistics.median(shares) if shares else 0:.3f} ({len(shares)}) | "
            f"{med('span'):.3f} | {med('heal'):.3f} | {med('rising'):.3f} | {med('drop'):.3f} |"
        )


if __name__ == "__main__":
    main()
