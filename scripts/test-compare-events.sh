#!/usr/bin/env bash
# Tests scripts/compare-events.py (the comparison of scripts/gpu-check.sh) on small
# hand-written tables: two identical runs are the same, and each kind of difference (a
# site, a kind, a load beyond 1e-9 relative, A_R beyond it, a run stopped early) is found.
# Needs bash and python3 only; .ci/run runs it.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
compare=("python3" "$here/compare-events.py")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0

# A run: events.csv and curve.csv in DIR, from the rows given on stdin (events, a line
# "--", then curve rows).
write_run() {
    local dir=$1 part=events
    mkdir -p "$dir"
    echo "index,kind,ix,iy,force_N,drive_displacement_m,energy_J,ruptures,area_exceeds_nominal" >"$dir/events.csv"
    echo "event,force_N,force_over_mu_FN,drive_displacement_m,real_contact_area_m2,precursor_length_m,precursor_over_Lx,broken,attached,area_exceeds_nominal" >"$dir/curve.csv"
    while IFS= read -r line; do
        if [ "$line" = "--" ]; then part=curve; continue; fi
        echo "$line" >>"$dir/$part.csv"
    done
}

base_run() {
    cat <<'EOF'
1,load_raised,,,100.0,,,,0
2,rupture,3,1,100.0,,1.5e-6,,0
3,rupture,4,1,100.0,,1.2e-6,,0
4,stable,,,100.0,,,2,0
5,load_raised,,,150.0,,,,0
6,rupture,7,0,150.0,,2.0e-6,,0
7,stable,,,150.0,,,1,0
--
4,100.0,0.04,,1.25e-3,0.002,0.014,2,0,0
7,150.0,0.06,,1.20e-3,0.003,0.021,3,0,0
EOF
}

# expect CODE WORD A B [ARGS...]: the comparison of A and B exits with CODE and prints WORD.
expect() {
    local code=$1 word=$2 a=$3 b=$4
    shift 4
    local out rc=0
    out=$("${compare[@]}" "$tmp/$a" "$tmp/$b" "$@") || rc=$?
    if [ "$rc" -ne "$code" ] || [[ "$out" != *"$word"* ]]; then
        echo "FAIL: $a vs $b $*: exit $rc, expected $code with '$word': $out"
        failures=$((failures + 1))
    else
        echo "ok: $a vs $b $*: $out"
    fi
}

base_run | write_run "$tmp/a"
base_run | write_run "$tmp/same"
# Loads 1e-12 apart, relatively: the same within 1e-9.
base_run | sed 's/^6,rupture,7,0,150.0,/6,rupture,7,0,150.00000000015,/' | write_run "$tmp/close"
base_run | sed 's/^3,rupture,4,1,/3,rupture,5,1,/' | write_run "$tmp/site"
base_run | sed 's/^3,rupture,4,1,100.0,,1.2e-6,,0/3,detach,4,1,100.0,,,,0/' | write_run "$tmp/kind"
base_run | sed 's/^6,rupture,7,0,150.0,/6,rupture,7,0,150.000001,/' | write_run "$tmp/load"
base_run | sed 's/^7,150.0,0.06,,1.20e-3,/7,150.0,0.06,,1.2000001e-3,/' | write_run "$tmp/area"
# A run stopped after its second rupture, in the middle of a line, tables not renamed.
mkdir -p "$tmp/stopped"
base_run | write_run "$tmp/stopped-full"
head -4 "$tmp/stopped-full/events.csv" >"$tmp/stopped/events.csv.partial"
printf '4,stab' >>"$tmp/stopped/events.csv.partial"
head -1 "$tmp/stopped-full/curve.csv" >"$tmp/stopped/curve.csv.partial"

expect 0 SAME a same
expect 0 SAME a close
expect 1 "DIFFERENT: event 3: ix '4' against '5'" a site
expect 1 "DIFFERENT: event 3: kind 'rupture' against 'detach'" a kind
expect 1 "DIFFERENT: event 6 (rupture): force_N" a load
expect 1 "real_contact_area_m2" a area
# Without --ruptures a run stopped early differs; with it, the ruptures both reached.
expect 1 "DIFFERENT: " a stopped
expect 0 "SAME: 3 events, 2 ruptures (of the 3 asked: a run stopped early)" a stopped --ruptures 3
expect 0 "SAME: 2 events, 1 ruptures" a site --ruptures 1
expect 1 "DIFFERENT" a site --ruptures 2
expect 2 "ERROR" a missing
# A run stopped before its first rupture: nothing to compare is not the same.
mkdir -p "$tmp/none"
head -2 "$tmp/stopped-full/events.csv" >"$tmp/none/events.csv.partial"
head -1 "$tmp/stopped-full/curve.csv" >"$tmp/none/curve.csv.partial"
expect 1 "DIFFERENT: nothing compared, 3 ruptures" a none --ruptures 5

if [ "$failures" -ne 0 ]; then
    echo "$failures comparison(s) wrong"
    exit 1
fi
echo "compare-events.py: all comparisons as expected"
