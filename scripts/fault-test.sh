#!/usr/bin/env bash
# Full and read-only disks (issue 23): `precursors run`, `merge` and `plot` write into
# small tmpfs mounts that fill at different points. Each must end with exit code 4 and a
# short `error: ` message (no panic, no Rust Debug form), and leave every file under its
# final name either absent or complete:
#   * merged tables and figures: byte-identical to the same command's output on a roomy
#     disk (they are written whole);
#   * a run's tables: identical, or whole rows up to an event (what `resume` continues),
#     never a 0-byte or header-less file nor a cut row.
#
# Needs root (mount -t tmpfs), directly, through `sudo -n`, or in a user namespace
# (`unshare -rm`); where none works it prints SKIPPED and exits 0 (or 1 with
# FAULT_TEST_REQUIRED=1). About 10-20 s after the build.
#
#   bash scripts/fault-test.sh [path/to/precursors]   # default: builds target/release
set -euo pipefail

REPO=$(cd "$(dirname "$0")/.." && pwd)
if [[ ${1:-} ]]; then
    BIN=$(realpath "$1")
else
    (cd "$REPO" && cargo build --release --features cli --bin precursors -q)
    BIN=${CARGO_TARGET_DIR:-$REPO/target}/release/precursors
    BIN=$(realpath "$BIN")
fi

# Re-run inside a mount namespace where tmpfs can be mounted (the mounts vanish with it).
if [[ -z ${FAULT_TEST_INNER:-} ]]; then
    export FAULT_TEST_INNER=1
    if [[ $(id -u) == 0 ]] && unshare -m true 2>/dev/null; then
        exec unshare -m bash "$0" "$BIN"
    elif [[ $(id -u) == 0 ]]; then
        exec bash "$0" "$BIN"
    elif sudo -n true 2>/dev/null; then
        exec sudo -n --preserve-env=FAULT_TEST_INNER,FAULT_TEST_REQUIRED unshare -m bash "$0" "$BIN"
    elif unshare -rm true 2>/dev/null; then
        exec unshare -rm bash "$0" "$BIN"
    fi
    echo "SKIPPED: no root, sudo or user namespace to mount a tmpfs"
    [[ ${FAULT_TEST_REQUIRED:-} == 1 ]] && exit 1
    exit 0
fi

W=$(mktemp -d /tmp/precursors-fault.XXXXXX)
MNT=$W/mnt
mkdir -p "$MNT"
failures=0
cleanup() {
    umount "$MNT" 2>/dev/null || true
    rm -rf "$W"
}
trap cleanup EXIT

fail() {
    echo "FAIL: $*"
    failures=$((failures + 1))
}

# A tmpfs of `$1` bytes (rounded up to pages by the kernel) at $MNT.
mount_tmpfs() {
    umount "$MNT" 2>/dev/null || true
    mount -t tmpfs -o "size=$1" tmpfs "$MNT"
}

# The tmpfs shrunk to what it holds plus `$1` bytes.
leave_room() {
    local used
    used=$(df --block-size=1 --output=used "$MNT" | tail -1)
    mount -o "remount,size=$((used + $1))" "$MNT"
}

# Checks the exit code `$1` (expected 4, or 0 when everything fit) and stderr file `$2`.
check_exit() {
    local code=$1 err=$2 what=$3
    if grep -q 'panicked at' "$err"; then
        fail "$what: a panic: $(head -c 300 "$err")"
    fi
    if [[ $code == 0 ]]; then
        return 0
    fi
    if [[ $code != 4 ]]; then
        fail "$what: exit $code, expected 4 (a file could not be written): $(head -c 300 "$err")"
    fi
    if ! grep -q '^error: ' "$err"; then
        fail "$what: no 'error: ' message"
    fi
    if grep -Eq 'Os \{ code|IoError\(|ImageError\(|DrawingError|Kind\(|Custom \{' "$err"; then
        fail "$what: a Rust Debug form in the message: $(grep -m1 -E 'Os \{|Error\(' "$err" | head -c 300)"
    fi
    if (($(wc -c <"$err") > 4096)); then
        fail "$what: an error message of $(wc -c <"$err") bytes"
    fi
}

# A whole file `$1` named finally: absent, or identical to the reference `$2`.
check_whole() {
    local file=$1 ref=$2 what=$3
    if [[ -e $file ]] && ! cmp -s "$file" "$ref"; then
        fail "$what: $(basename "$file") is $(wc -c <"$file") bytes, not the reference's $(wc -c <"$ref") (incomplete under its final name)"
    fi
}

# A run's table `$1`: absent, identical to the reference `$2`, or whole rows of it
# (the header first, ending with a newline, a prefix of the reference).
check_rows() {
    local file=$1 ref=$2 what=$3
    [[ -e $file ]] || return 0
    cmp -s "$file" "$ref" && return 0
    local size
    size=$(wc -c <"$file")
    if ((size == 0)); then
        fail "$what: $(basename "$file") is empty"
    elif [[ $(tail -c 1 "$file" | od -An -c | tr -d ' ') != '\n' ]]; then
        fail "$what: $(basename "$file") ends in a cut row ($size bytes)"
    elif ! cmp -s "$file" <(head -c "$size" "$ref"); then
        fail "$what: $(basename "$file") is not rows of the reference"
    elif [[ $(head -1 "$file") != $(head -1 "$ref") ]]; then
        fail "$what: $(basename "$file") has no header"
    fi
}

echo "== reference outputs on a roomy disk ($W)"
cat >"$W/scene.json" <<'EOF'
{ "block": { "lx": 0.03, "ly": 0.005, "lz": 0.02 },
  "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
  "normal_load": 500.0,
  "drive": { "kind": "rod", "height": 0.004, "half_width": 0.001 } }
EOF
cat >"$W/sweep.json" <<'EOF'
{ "base": { "block": { "lx": 0.03, "ly": 0.005, "lz": 0.02 },
            "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
            "normal_load": 500.0,
            "drive": { "kind": "rod", "height": 0.004, "half_width": 0.001 } },
  "axes": [ { "key": "normal_load", "values": [400.0, 600.0] } ],
  "realizations": 2, "seed": 11 }
EOF
REF=$W/ref
"$BIN" run "$W/scene.json" --out "$REF/run" -q 2>/dev/null
"$BIN" sweep "$W/sweep.json" --out "$REF/sweep-in" --jobs 1 -q 2>/dev/null
cp -a "$REF/sweep-in" "$REF/sweep"
"$BIN" merge "$REF/sweep" -q 2>/dev/null
# Figures name their directory in the title: the reference is drawn where the test draws.
mount_tmpfs 64M
cp -a "$REF/run/." "$MNT/"
"$BIN" plot "$MNT" -q 2>/dev/null
mkdir "$REF/plot-run"
cp "$MNT"/*.png "$REF/plot-run/"
RUN_FILES=(events.csv curve.csv contact_map.csv)
MERGE_FILES=(curves.csv slip.csv avalanches.csv runs.csv)
PNGS=(precursor_length.png contact_area.png contact_map.png)
total=$(du -sb "$REF/run" | cut -f1)
echo "run tables: $total bytes; merged: $(cd "$REF/sweep" && cat "${MERGE_FILES[@]}" | wc -c) bytes"

echo "== run into a full disk"
for size in 4096 8192 16384 32768 65536 131072 262144; do
    mount_tmpfs "$size"
    set +e
    "$BIN" run "$W/scene.json" --out "$MNT/run" -q 2>"$W/err"
    code=$?
    set -e
    what="run, tmpfs of $size bytes"
    echo "$what: exit $code"
    check_exit "$code" "$W/err" "$what"
    for f in "${RUN_FILES[@]}"; do
        check_rows "$MNT/run/$f" "$REF/run/$f" "$what"
    done
    if [[ $code == 0 ]]; then
        for f in "${RUN_FILES[@]}"; do
            cmp -s "$MNT/run/$f" "$REF/run/$f" || fail "$what: exit 0 but $f differs from the reference"
        done
    fi
done

echo "== sweep into a full disk, then restarted with room"
for size in 16384 65536 262144; do
    mount_tmpfs "$size"
    set +e
    "$BIN" sweep "$W/sweep.json" --out "$MNT/s" --jobs 1 -q 2>"$W/err"
    code=$?
    set -e
    what="sweep, tmpfs of $size bytes"
    echo "$what: exit $code"
    check_exit "$code" "$W/err" "$what"
    # A run marked done is complete.
    for done in "$MNT"/s/p*/done; do
        [[ -e $done ]] || continue
        run=$(dirname "$done")
        for f in "${RUN_FILES[@]}"; do
            cmp -s "$run/$f" "$REF/sweep-in/$(basename "$run")/$f" ||
                fail "$what: $(basename "$run") is marked done but its $f differs from the reference"
        done
    done
    mount -o remount,size=64M "$MNT"
    set +e
    "$BIN" sweep "$W/sweep.json" --out "$MNT/s" --jobs 1 -q 2>"$W/err"
    code=$?
    set -e
    [[ $code == 0 ]] || fail "$what, restarted with room: exit $code: $(head -c 300 "$W/err")"
    diff -r -q -x meta.json "$MNT/s" "$REF/sweep-in" >"$W/diff" ||
        fail "$what, restarted with room: tables differ from the reference: $(head -3 "$W/diff")"
done

echo "== merge into a full disk"
for room in 0 4096 8192 12288 16384; do
    mount_tmpfs 64M
    cp -a "$REF/sweep-in/." "$MNT/"
    leave_room "$room"
    set +e
    "$BIN" merge "$MNT" -q 2>"$W/err"
    code=$?
    set -e
    what="merge, $room bytes free"
    echo "$what: exit $code"
    check_exit "$code" "$W/err" "$what"
    for f in "${MERGE_FILES[@]}"; do
        check_whole "$MNT/$f" "$REF/sweep/$f" "$what"
    done
done

echo "== plot into a full disk"
for room in 0 4096 16384 65536; do
    mount_tmpfs 64M
    cp -a "$REF/run/." "$MNT/"
    leave_room "$room"
    set +e
    "$BIN" plot "$MNT" -q 2>"$W/err"
    code=$?
    set -e
    what="plot, $room bytes free"
    echo "$what: exit $code"
    check_exit "$code" "$W/err" "$what"
    for f in "${PNGS[@]}"; do
        check_whole "$MNT/$f" "$REF/plot-run/$f" "$what"
    done
done

echo "== merge and plot on a read-only disk"
mount_tmpfs 64M
cp -a "$REF/sweep-in/." "$MNT/"
mkdir "$MNT/run"
cp -a "$REF/run/." "$MNT/run/"
mount -o remount,ro "$MNT"
for cmd in "merge $MNT" "plot $MNT/run"; do
    set +e
    # shellcheck disable=SC2086
    "$BIN" $cmd -q 2>"$W/err"
    code=$?
    set -e
    what="${cmd%% *} on a read-only disk"
    echo "$what: exit $code"
    if [[ $code == 0 ]]; then
        fail "$what: exit 0 though nothing could be written"
    fi
    check_exit "$code" "$W/err" "$what"
done

if ((failures > 0)); then
    echo "fault test: $failures failures"
    exit 1
fi
echo "fault test: all passed"
