#!/usr/bin/env python3
"""Compares the events of two run directories (issue 42 item 4: the CUDA backend against
the CPU's): the same events by kind and site, the loads and the real contact area A_R
within a relative tolerance.

    scripts/compare-events.py DIR_A DIR_B [--ruptures K] [--rtol 1e-9]

Each directory's `events.csv` is read, else its `events.csv.partial` (a run stopped by a
time limit: only its complete lines). `--ruptures K` compares the events up to the K-th
rupture; when a run stopped before it, the ruptures both reached (the summary says how
many). Compared:

* `events.csv`, row by row: `index`, `kind`, `ix`, `iy` and `ruptures` exactly;
  `force_N` and `drive_displacement_m` (the loads) within `rtol` (relative to the larger
  magnitude; empty cells must be empty in both);
* `curve.csv` (or `.partial`), the stable states up to the last event compared: `event`
  exactly, `force_N` and `real_contact_area_m2` (A_R) within `rtol`.

Prints one line, `SAME ...` (exit 0) or `DIFFERENT ...` naming the first difference
(exit 1); a missing or malformed table exits 2. Needs only Python 3's standard library.
"""

import argparse
import csv
import math
import os
import sys

EXACT_EVENT = ("index", "kind", "ix", "iy", "ruptures")
CLOSE_EVENT = ("force_N", "drive_displacement_m")
CLOSE_CURVE = ("force_N", "real_contact_area_m2")


class Bad(Exception):
    """A table missing or not as the program writes it."""


def rows(directory, table):
    """The header and complete rows of DIR/table, else DIR/table.partial (its last line
    dropped when the run was stopped in the middle of writing it)."""
    for name in (table, table + ".partial"):
        path = os.path.join(directory, name)
        if os.path.isfile(path):
            break
    else:
        raise Bad(f"{directory} has neither {table} nor {table}.partial")
    with open(path, newline="") as f:
        text = f.read()
    if not text.endswith("\n"):
        text = text[: text.rfind("\n") + 1]
    lines = list(csv.reader(text.splitlines()))
    if not lines:
        raise Bad(f"{path} is empty")
    header, body = lines[0], lines[1:]
    for row in body:
        if len(row) != len(header):
            raise Bad(f"{path}: a row of {len(row)} cells under {len(header)} columns")
    return path, header, [dict(zip(header, row)) for row in body]


def columns(path, header, wanted):
    missing = [c for c in wanted if c not in header]
    if missing:
        raise Bad(f"{path} has no column {', '.join(missing)}")


def relative(a, b):
    """The relative difference of two cells (0 for two empty ones, inf for one)."""
    if a == "" and b == "":
        return 0.0
    if a == "" or b == "":
        return math.inf
    x, y = float(a), float(b)
    scale = max(abs(x), abs(y))
    return 0.0 if scale == 0.0 else abs(x - y) / scale


def up_to_rupture(events, k):
    """The events up to and including the k-th rupture (all of them for k = None)."""
    if k is None:
        return events
    seen = 0
    for i, event in enumerate(events):
        if event["kind"] == "rupture":
            seen += 1
            if seen == k:
                return events[: i + 1]
    return events


def ruptures(events):
    return sum(1 for e in events if e["kind"] == "rupture")


def compare(dir_a, dir_b, k, rtol):
    """(same, summary line)."""
    path_a, head_a, ev_a = rows(dir_a, "events.csv")
    path_b, head_b, ev_b = rows(dir_b, "events.csv")
    for path, head in ((path_a, head_a), (path_b, head_b)):
        columns(path, head, EXACT_EVENT + CLOSE_EVENT)
    # The ruptures both runs reached, at most k.
    both = min(ruptures(ev_a), ruptures(ev_b))
    limit = both if k is None else min(k, both)
    complete = k is None and len(ev_a) == len(ev_b)
    if k is not None:
        if limit == 0:
            return False, (
                f"DIFFERENT: nothing compared, {ruptures(ev_a)} ruptures in {dir_a} and "
                f"{ruptures(ev_b)} in {dir_b} (a run stopped before its first?)"
            )
        ev_a, ev_b = up_to_rupture(ev_a, limit), up_to_rupture(ev_b, limit)
    elif not complete:
        return False, (
            f"DIFFERENT: {len(ev_a)} events in {dir_a}, {len(ev_b)} in {dir_b} "
            "(give --ruptures K to compare the first K of runs stopped early)"
        )
    worst = {"load": 0.0, "A_R": 0.0}
    for a, b in zip(ev_a, ev_b):
        for c in EXACT_EVENT:
            if a[c] != b[c]:
                return False, (
                    f"DIFFERENT: event {a['index']}: {c} {a[c]!r} against {b[c]!r} "
                    f"({a['kind']} at ({a['ix']}, {a['iy']}) against {b['kind']} at "
                    f"({b['ix']}, {b['iy']}))"
                )
        for c in CLOSE_EVENT:
            d = relative(a[c], b[c])
            worst["load"] = max(worst["load"], d)
            if d > rtol:
                return False, (
                    f"DIFFERENT: event {a['index']} ({a['kind']}): {c} {a[c]} against "
                    f"{b[c]} (relative {d:.2e} > {rtol:g})"
                )
    if len(ev_a) != len(ev_b):
        return False, f"DIFFERENT: {len(ev_a)} events against {len(ev_b)}"
    last = int(ev_a[-1]["index"]) if ev_a else 0
    cpath_a, chead_a, cu_a = rows(dir_a, "curve.csv")
    cpath_b, chead_b, cu_b = rows(dir_b, "curve.csv")
    for path, head in ((cpath_a, chead_a), (cpath_b, chead_b)):
        columns(path, head, ("event",) + CLOSE_CURVE)
    cu_a = [s for s in cu_a if int(s["event"]) <= last]
    cu_b = [s for s in cu_b if int(s["event"]) <= last]
    # A run stopped early may not have written its last stable states yet.
    if not complete:
        n = min(len(cu_a), len(cu_b))
        cu_a, cu_b = cu_a[:n], cu_b[:n]
    if len(cu_a) != len(cu_b):
        return False, f"DIFFERENT: {len(cu_a)} stable states against {len(cu_b)}"
    for a, b in zip(cu_a, cu_b):
        if a["event"] != b["event"]:
            return False, f"DIFFERENT: stable state at event {a['event']} against {b['event']}"
        for c in CLOSE_CURVE:
            d = relative(a[c], b[c])
            key = "A_R" if c == "real_contact_area_m2" else "load"
            worst[key] = max(worst[key], d)
            if d > rtol:
                return False, (
                    f"DIFFERENT: stable state at event {a['event']}: {c} {a[c]} against "
                    f"{b[c]} (relative {d:.2e} > {rtol:g})"
                )
    reached = "" if k is None or limit == k else f" (of the {k} asked: a run stopped early)"
    return True, (
        f"SAME: {len(ev_a)} events, {limit} ruptures{reached}, {len(cu_a)} stable states; "
        f"largest relative difference: loads {worst['load']:.1e}, A_R {worst['A_R']:.1e}"
    )


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dir_a")
    parser.add_argument("dir_b")
    parser.add_argument("--ruptures", type=int, default=None, metavar="K",
                        help="compare the events up to the K-th rupture")
    parser.add_argument("--rtol", type=float, default=1e-9,
                        help="relative tolerance of loads and A_R (default 1e-9)")
    args = parser.parse_args(argv)
    if args.ruptures is not None and args.ruptures < 1:
        parser.error("--ruptures must be at least 1")
    try:
        same, line = compare(args.dir_a, args.dir_b, args.ruptures, args.rtol)
    except (Bad, ValueError, KeyError, OSError) as e:
        print(f"ERROR: {e}")
        return 2
    print(line)
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
