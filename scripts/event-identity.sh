#!/usr/bin/env bash
# Event identity (docs/accuracy.md): runs the scenes of scripts/identity/ to global slip
# with a given program and compares the tables of two such records byte for byte. Used
# before landing any change near the solvers or the driver: same-profile builds of the
# commit before and after must give identical events.csv, curve.csv and contact_map.csv.
#
#   scripts/event-identity.sh record PROGRAM DIR   # e.g. target/release/precursors out/before
#   scripts/event-identity.sh compare DIR_A DIR_B  # exit 1 and the differing tables if any
#
# The scenes cover both backends, every drive kind (top, rod, side, mixed, spring) and a
# two-thread spectral solve; together about two minutes of CPU in a release build.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
tables=(events.csv curve.csv contact_map.csv)
case "${1:-}" in
record)
    [ $# -eq 3 ] || { echo "usage: $0 record PROGRAM DIR" >&2; exit 2; }
    program=$2 dir=$3
    mkdir -p "$dir"
    for scene in "$here"/identity/*.json; do
        name=$(basename "$scene" .json)
        rm -rf "${dir:?}/$name"
        "$program" run "$scene" --out "$dir/$name" -q >/dev/null
        echo "$name: $(grep -c ',rupture,' "$dir/$name/events.csv") ruptures"
    done
    ;;
compare)
    [ $# -eq 3 ] || { echo "usage: $0 compare DIR_A DIR_B" >&2; exit 2; }
    status=0
    for scene in "$here"/identity/*.json; do
        name=$(basename "$scene" .json)
        for table in "${tables[@]}"; do
            if ! cmp -s "$2/$name/$table" "$3/$name/$table"; then
                echo "DIFFERENT: $name/$table"; status=1
            fi
        done
    done
    [ $status -eq 0 ] && echo "ALL IDENTICAL ($(ls "$here"/identity/*.json | wc -l) scenes, ${tables[*]})"
    exit $status
    ;;
*)
    echo "usage: $0 record PROGRAM DIR | compare DIR_A DIR_B" >&2; exit 2 ;;
esac
