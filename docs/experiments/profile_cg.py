"""Where a run's time goes, by job (issue 26 item 2; docs/performance.md, "A CG iteration,
profiled"). Reads `perf report --no-children --sort symbol --stdio` on stdin and sums the
sample shares of the symbols into the stages of the solver's work. Usage:

    cargo build --release --example large_run
    LARGE_RUN_MAX_RUPTURES=300 perf record -F 999 -o /tmp/cg.data \
        ./target/release/examples/large_run 1 1e-13 1          # N = 1e4, one thread
    perf report -i /tmp/cg.data --no-children --sort symbol --stdio \
        | python3 docs/experiments/profile_cg.py

Symbols are matched by name only (no call graphs: the release build has no frame
pointers), so faer's matrix-product kernels count as the y-DCT also where the coarse
space's Cholesky factor runs them (grids of 32 768 cells and more: a few ms per set
change, docs/performance.md).
"""
import re
import sys

# First match wins.
GROUPS = [
    ("parallel layer: phase dispatch, helpers waiting", r"parallel::|spin_loop|sched_yield|futex|\[k\]"),
    ("y-DCT (matrix products)", r"gemm|Dct2d::columns|faer::linalg::matmul|pulp::"),
    ("x-DCT (FFTs)", r"rustfft|PairDct"),
    ("filter (the table's product)", r"filter_columns"),
    ("set <-> grid (scatter, gather)", r"forward_rows|inverse_rows|staged_head"),
    ("FSAI (G, G^T, halos)", r"Fsai::g\b|Fsai::gt\b|SetSystem>::precondition|FsaiBuffers"),
    ("coarse space (restrict, prolong, solve, update)", r"Coarse::"),
    ("CG vector updates and reductions", r"Pre::apply|pcg::dot|pcg::sum|pcg::max_abs|Tasks>::run"),
    ("copies and fills (memmove, memset)", r"memmove|memset|memcpy"),
    ("preconditioner upkeep (FSAI rows, kernel table)", r"Fsai::update|Entries::"),
    ("driver, active set, interface", r"driver::|active_set|tangential::|interface::|exp_fma"),
]


def main() -> None:
    totals = {name: 0.0 for name, _ in GROUPS}
    other = 0.0
    for line in sys.stdin:
        m = re.match(r"\s+([0-9.]+)%\s+\[[.k]\]\s+(.*)", line)
        if not m:
            continue
        share, symbol = float(m.group(1)), m.group(2)
        if line.lstrip().split()[1] == "[k]":
            symbol = "[k] " + symbol
        for name, pattern in GROUPS:
            if re.search(pattern, symbol):
                totals[name] += share
                break
        else:
            other += share
    for name, _ in GROUPS:
        print(f"{totals[name]:6.1f} %  {name}")
    print(f"{other:6.1f} %  other")


if __name__ == "__main__":
    main()
