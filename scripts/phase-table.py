#!/usr/bin/env python3
"""The per-phase time table of scripts/gpu-check.sh (issue 57 item 6; docs/gpu.md): reads
the `phases` lines that examples/gpu_timings prints with its fifth argument (one file of
its output per grid size) and prints, per part of a device solve, the time per CG
iteration (ms) and its share of the solve time, one column per grid size.

    scripts/phase-table.py OUTPUT...

A file without a `phases` line (a run that failed or was stopped first) gives a column
of `-` and a note. Exit status: 0 (a table, even of dashes), 2 bad arguments.
scripts/test-gpu-check.sh tests it.
"""

import re
import sys

# (field of the phases line, row label), in the table's order.
PARTS = [
    ("operator", "operator (A x, C_s f)"),
    ("preconditioner", "preconditioner"),
    ("coarse_upkeep", "coarse upkeep (E)"),
    ("preconditioner_upkeep", "FSAI rows, spectral table"),
    ("reductions", "reductions"),
    ("updates", "vector updates"),
    ("copies", "copies"),
]
FIELDS = ["n", "events", "iterations", "solves", "solve"] + [p for p, _ in PARTS]


def parse(path):
    """The phases line's fields of one output file, or the reason there is none."""
    try:
        text = open(path, encoding="utf-8", errors="replace").read()
    except OSError as e:
        return None, f"{path}: {e.strerror}"
    lines = [l for l in text.splitlines() if l.startswith("phases ")]
    if not lines:
        return None, f"{path}: no phases line (the run failed or was stopped first)"
    fields = dict(kv.split("=", 1) for kv in lines[-1].split()[1:] if "=" in kv)
    missing = [f for f in FIELDS if f not in fields]
    if missing:
        return None, f"{path}: the phases line lacks {', '.join(missing)}"
    try:
        return {k: float(fields[k]) for k in FIELDS}, None
    except ValueError as e:
        return None, f"{path}: {e}"


def size(n):
    """`1e4` for 10 000, else the number."""
    n = int(n)
    exponent = len(str(n)) - 1
    return f"N = 1e{exponent}" if n == 10 ** exponent else f"N = {n}"


def main(paths):
    if not paths:
        print(__doc__.split("\n\n")[1].strip(), file=sys.stderr)
        return 2
    columns, notes = [], []
    for path in paths:
        fields, why = parse(path)
        columns.append(fields)
        if why:
            notes.append(why)
    width = 20
    heads = [size(c["n"]) if c else re.sub(r"\..*", "", path.split("/")[-1]) for c, path in zip(columns, paths)]
    print(f"{'part':<26} | " + " | ".join(f"{h:^{width}}" for h in heads))
    print(f"{'':<26} | " + " | ".join(f"{'ms/iteration  share':^{width}}" for _ in heads))
    print("-" * 27 + ("+" + "-" * (width + 2)) * len(heads))

    def row(label, cell):
        print(f"{label:<26} | " + " | ".join(f"{cell(c) if c else '-':>{width}}" for c in columns))

    per_iteration = lambda c, s: 1e3 * s / max(c["iterations"], 1)
    for field, label in PARTS:
        row(label, lambda c, f=field: f"{per_iteration(c, c[f]):9.4f}  {100 * c[f] / c['solve'] if c['solve'] > 0 else 0:5.1f} %")
    rest = lambda c: c["solve"] - sum(c[f] for f, _ in PARTS)
    row("host (the rest)", lambda c: f"{per_iteration(c, rest(c)):9.4f}  {100 * rest(c) / c['solve'] if c['solve'] > 0 else 0:5.1f} %")
    row("solve, all parts", lambda c: f"{per_iteration(c, c['solve']):9.4f}  100.0 %")
    row("events, CG iterations", lambda c: f"{int(c['events'])}, {int(c['iterations'])}")
    for note in notes:
        print(f"note: {note}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
