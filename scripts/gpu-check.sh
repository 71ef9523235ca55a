#!/usr/bin/env bash
# The GPU check of the CUDA backend (issue 42 items 4 and 5; docs/gpu.md), for a machine
# with the NVIDIA driver and the CUDA libraries but no Rust: the binaries are built on
# another x86-64 Linux machine and carried here.
#
#   cargo build --release --features cli,cuda            # on the build machine
#   scripts/gpu-check.sh BIN_DIR OUT_DIR [--dry-run]     # here; BIN_DIR/precursors
#
# It prints what `precursors info` says of the GPU (the libraries found), then compares
# the CUDA backend with the CPU's spectral backend (scripts/compare-events.py: the same
# events by kind and site, loads and A_R within 1e-9 relative):
#   1. the five scenes of scripts/identity/, each run as backend "cuda" and "spectral";
#   2. the per-phase times at N = 1e4, 1e5, 1e6 (examples/gpu_timings, carried beside
#      the program: cargo build --release --features cuda --example gpu_timings);
#   3. N = 1e4 (200 x 50), the first 2000 ruptures; N = 1e5 (1000 x 100, 1 MPa), the
#      first 1000 (runs stopped by a time limit: the ruptures both reached are compared);
#   4. a checkpoint of a GPU run resumed on the CPU, and the reverse;
# with each run's wall time and peak memory (/usr/bin/time), then one summary table and
# the per-phase table (scripts/phase-table.py). The CPU runs go in the background while
# the GPU runs. Every run has a time limit, cut to what is left of a budget of 450 s
# (GPU_CHECK_BUDGET) and skipped when under 10 s of it is left, so the whole ends within
# 8 minutes whatever the GPU does; the steps go in the order above. With --dry-run, or
# when `precursors info` finds no usable GPU, it checks its inputs, skips every GPU step,
# says so and exits 0.
# Exit status: 0 all compared runs the same (or the GPU steps skipped), 1 a difference or
# a failed run, 2 bad arguments or inputs.
set -uo pipefail
here="$(cd "$(dirname "$0")" && pwd)"

usage() { echo "usage: $0 BIN_DIR OUT_DIR [--dry-run]" >&2; exit 2; }
[ $# -ge 2 ] && [ $# -le 3 ] || usage
bin_dir=$1 out=$2 dry=0
if [ $# -eq 3 ]; then [ "$3" = "--dry-run" ] && dry=1 || usage; fi
program="$bin_dir/precursors"

# Time limits (s) of the runs stopped early, and the ruptures compared.
N4_LIMIT=${GPU_CHECK_N4_LIMIT:-60}
N5_LIMIT=${GPU_CHECK_N5_LIMIT:-120}
N4_RUPTURES=2000
N5_RUPTURES=1000
# The whole check's budget (s): each run's limit is cut to what is left of it.
BUDGET=${GPU_CHECK_BUDGET:-450}
[[ "$BUDGET" =~ ^[0-9]+$ && "$N4_LIMIT" =~ ^[0-9]+$ && "$N5_LIMIT" =~ ^[0-9]+$ ]] ||
    { echo "gpu-check: GPU_CHECK_BUDGET, GPU_CHECK_N4_LIMIT and GPU_CHECK_N5_LIMIT are whole seconds" >&2; exit 2; }

# --- inputs -------------------------------------------------------------------------
fail_input() { echo "gpu-check: $*" >&2; exit 2; }
[ -x "$program" ] || fail_input "$program is not an executable (build it with cargo build --release --features cli,cuda)"
command -v python3 >/dev/null || fail_input "python3 is needed (the scene edits and scripts/compare-events.py)"
[ -f "$here/compare-events.py" ] || fail_input "$here/compare-events.py is missing"
[ -f "$here/phase-table.py" ] || fail_input "$here/phase-table.py is missing"
timings="$bin_dir/gpu_timings"
[ -x "$timings" ] || timings="$bin_dir/examples/gpu_timings"
[ -x "$timings" ] || timings=""
scenes=("$here"/identity/*.json)
[ -f "${scenes[0]}" ] || fail_input "no scenes in $here/identity/"
case "$(uname -m)" in x86_64) ;; *) fail_input "this machine is $(uname -m); the binaries are x86-64" ;; esac
mkdir -p "$out" || fail_input "cannot create $out"
out="$(cd "$out" && pwd)"
timer=()
if [ -x /usr/bin/time ]; then timer=(/usr/bin/time -f "%e %M"); fi

echo "== precursors info (the GPU and its libraries)"
info_scene="$out/info-scene.json"
cp "${scenes[0]}" "$info_scene"
timeout -k 5 60 "$program" info "$info_scene" >"$out/info.txt" 2>&1
gpu_line=$(grep '^gpu ' "$out/info.txt" || echo "gpu        (no gpu line: $(head -c 300 "$out/info.txt"))")
echo "$gpu_line"
echo "LD_LIBRARY_PATH=${LD_LIBRARY_PATH:-}"

skip=""
if [ $dry -eq 1 ]; then
    skip="--dry-run"
elif [[ "$gpu_line" == *"none usable"* || "$gpu_line" == *"no CUDA backend"* || "$gpu_line" == *"no gpu line"* ]]; then
    skip="no usable GPU (the gpu line above says why)"
fi
if [ -n "$skip" ]; then
    echo "== inputs checked: $program, python3, compare-events.py, phase-table.py, ${#scenes[@]} identity scenes"
    echo "== gpu_timings: ${timings:-none beside the program (the per-phase table will be skipped)}"
    echo "== every GPU step skipped: $skip"
    exit 0
fi

# --- helpers ------------------------------------------------------------------------
# scene_with SRC DEST BACKEND [THREADS]: SRC with "solver": {"backend": BACKEND}.
scene_with() {
    python3 - "$1" "$2" "$3" "${4:-}" <<'EOF'
import json, sys
src, dest, backend, threads = sys.argv[1:5]
scene = json.load(open(src))
solver = scene.setdefault("solver", {})
solver["backend"] = backend
if backend == "cuda":
    solver.pop("threads", None)  # the device solves: one host thread
elif threads:
    solver["threads"] = int(threads)
json.dump(scene, open(dest, "w"), indent=1)
EOF
}

# swap_backend SRC DEST FROM TO: a checkpoint with its scene's backend changed and its
# digest (FNV-1a of the body, src/driver/checkpoint.rs) written again. The identity, and
# so the scene digest inside, is the same: cuda solves the spectral rule.
swap_backend() {
    python3 - "$@" <<'EOF'
import sys
src, dest, old, new = sys.argv[1:5]
text = open(src, encoding="utf-8").read()
key = ',"digest":"'
at = text.rfind(key)
body = text[:at] + "}"
count = body.count(f'"backend":"{old}"')
if at < 0 or count != 1:
    sys.exit(f"{src}: expected one backend {old!r} and a digest, found {count}")
body = body.replace(f'"backend":"{old}"', f'"backend":"{new}"')
h = 0xcbf29ce484222325
for b in body.encode("utf-8"):
    h = ((h ^ b) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
open(dest, "w", encoding="utf-8").write(body[:-1] + key + f"{h:016x}" + '"}')
EOF
}

# within LIMIT: LIMIT cut to what is left of the budget (less 5 s for the summary), or
# 0 when under 10 s is left (the run is then skipped).
within() {
    local left=$((BUDGET - SECONDS - 5))
    if [ $left -lt 10 ]; then echo 0; elif [ "$1" -lt $left ]; then echo "$1"; else echo $left; fi
}

# timed NAME LIMIT CMD...: runs CMD (its stderr and time in $out/NAME.log), stopped after
# LIMIT seconds, cut to the budget (within), by SIGINT to its process group:
# /usr/bin/time ignores it and still reports the program's peak memory. Sets $secs and
# $rc (124: stopped at the limit; 125: not run, the budget spent).
timed() {
    local name=$1 limit
    limit=$(within "$2")
    shift 2
    local start=$SECONDS
    if [ "$limit" -eq 0 ]; then
        rc=125 secs="not run (budget spent)"
        return
    fi
    timeout -k 10 -s INT "$limit" "${timer[@]}" "$@" >"$out/$name.stdout" 2>"$out/$name.log"
    rc=$?
    secs=$((SECONDS - start))
    if [ ${#timer[@]} -gt 0 ]; then
        local last
        last=$(tail -1 "$out/$name.log")
        [[ "$last" =~ ^[0-9.]+\ [0-9]+$ ]] && secs="${last% *} s, $((${last#* } / 1024)) MB" || secs="$secs s"
    else
        secs="$secs s"
    fi
}

rows=()   # the summary table
status=0
# row STEP RESULT GPU CPU
row() { rows+=("$(printf '%-34s | %-9s | %-20s | %-20s' "$1" "$2" "$3" "$4")"); }

# compare_dirs STEP GPU_DIR CPU_DIR GPU_TIME CPU_TIME [--ruptures K]
compare_dirs() {
    local step=$1 g=$2 c=$3 gt=$4 ct=$5
    shift 5
    local line
    line=$(python3 "$here/compare-events.py" "$g" "$c" "$@")
    local code=$?
    echo "   $step: $line"
    case $code in
        0) row "$step" SAME "$gt" "$ct" ;;
        *) row "$step" DIFFERENT "$gt" "$ct"; status=1 ;;
    esac
}

mkdir -p "$out/scenes" "$out/runs"
for scene in "${scenes[@]}"; do
    name=$(basename "$scene" .json)
    scene_with "$scene" "$out/scenes/$name.cuda.json" cuda
    scene_with "$scene" "$out/scenes/$name.spectral.json" spectral
done
big() {  # big NAME LX LY LOAD BACKEND THREADS
    python3 - "$out/scenes/$1.$5.json" "$2" "$3" "$4" "$5" "$6" <<'EOF'
import json, sys
dest, lx, ly, load, backend, threads = sys.argv[1:7]
solver = {"backend": backend}
if backend != "cuda":
    solver["threads"] = int(threads)
json.dump({"block": {"lx": float(lx), "ly": float(ly), "lz": 0.075},
           "cells": {"kind": "size", "dx": 0.001, "dy": 0.001},
           "heights": {"kind": "gaussian", "seed": 1},
           "normal_load": float(load), "solver": solver}, open(dest, "w"), indent=1)
EOF
}
# The scenes of docs/performance.md: N = 1e4 at 3.5 MPa, N = 1e5 at 1 MPa; rod drive.
for backend in cuda spectral; do
    big n1e4 0.200 0.050 35000.0 $backend 2
    big n1e5 1.000 0.100 100000.0 $backend 2
done

# --- the CPU runs, in the background --------------------------------------------------
# Limits (s) of the runs that go to the end: an identity scene, a checkpoint's run, and
# the timings at each size (the first equilibrium, EVENTS events, then PHASE_EVENTS with
# the per-phase timing on).
SCENE_LIMIT=60
echo "== CPU runs (spectral) started in the background"
cpu_run() {  # cpu_run NAME LIMIT
    local name=$1 limit=$2
    rm -rf "$out/runs/$name.cpu"
    timed "$name.cpu" "$limit" "$program" run "$out/scenes/$name.spectral.json" --out "$out/runs/$name.cpu" -q
    echo "$rc|$secs" >"$out/runs/$name.cpu.done"
}
for scene in "${scenes[@]}"; do
    cpu_run "$(basename "$scene" .json)" "$BUDGET" &
done
cpu_run n1e4 "$N4_LIMIT" &
cpu_run n1e5 "$N5_LIMIT" &

# --- the GPU runs, one at a time -------------------------------------------------------
gpu_run() {  # gpu_run NAME LIMIT STOPPED_OK: sets gpu_time, gpu_rc
    local name=$1 limit=$2 stopped_ok=$3
    rm -rf "$out/runs/$name.gpu"
    timed "$name.gpu" "$limit" "$program" run "$out/scenes/$name.cuda.json" --out "$out/runs/$name.gpu" -q
    gpu_time=$secs
    gpu_rc=$rc
    # A run stopped by its time limit (124) is expected for N = 1e4 and 1e5.
    if [ "$gpu_rc" -ne 0 ] && [ "$gpu_rc" -ne 125 ] && { [ "$stopped_ok" -eq 0 ] || [ "$gpu_rc" -ne 124 ]; }; then
        echo "   $name on the GPU failed (exit $gpu_rc): $(grep -v '^[0-9.]* [0-9]*$' "$out/$name.gpu.log" | tail -3)"
    fi
}
cpu_result() {  # cpu_result NAME: waits for the CPU run, sets cpu_time and cpu_rc
    while [ ! -f "$out/runs/$1.cpu.done" ]; do sleep 1; done
    IFS='|' read -r cpu_rc cpu_time <"$out/runs/$1.cpu.done"
}
# not_run STEP GPU_RC CPU_RC GPU_TIME CPU_TIME: a row for a step not compared.
not_run() {
    local result=FAILED
    [ "$2" -eq 125 ] || [ "$3" -eq 125 ] && result=SKIPPED
    row "$1" $result "exit $2, $4" "exit $3, $5"
    status=1
}

echo "== 1. the identity scenes, cuda against spectral"
for scene in "${scenes[@]}"; do
    name=$(basename "$scene" .json)
    gpu_run "$name" $SCENE_LIMIT 0
    cpu_result "$name"
    if [ "$gpu_rc" -ne 0 ] || [ "$cpu_rc" -ne 0 ]; then
        not_run "$name" "$gpu_rc" "$cpu_rc" "$gpu_time" "$cpu_time"
    else
        compare_dirs "$name" "$out/runs/$name.gpu" "$out/runs/$name.cpu" "$gpu_time" "$cpu_time"
    fi
done

# The per-phase times (examples/gpu_timings with PHASE_EVENTS): N = 1e4, 1e5, 1e6.
echo "== 2. per-phase times (examples/gpu_timings)"
phase_outputs=()
if [ -n "$timings" ]; then
    # NAME NX NY EVENTS PHASE_EVENTS LIMIT
    for spec in "t1e4 200 50 500 200 30" "t1e5 1000 100 100 50 45" "t1e6 2000 500 20 10 90"; do
        read -r name nx ny events phase_events limit <<<"$spec"
        timed "$name.cuda" "$limit" "$timings" cuda "$nx" "$ny" "$events" "$phase_events"
        line=$(grep '^backend' "$out/$name.cuda.stdout" 2>/dev/null || echo "exit $rc: see $out/$name.cuda.log")
        echo "   $line ($secs)"
        phase_outputs+=("$out/$name.cuda.stdout")
        result=measured
        case $rc in 0) ;; 125) result=SKIPPED ;; *) result="exit $rc" ;; esac
        row "timing $name (N = $((nx * ny)))" "$result" "$secs" "-"
    done
else
    echo "   no gpu_timings beside $program: skipped"
    row "per-phase times" SKIPPED "-" "no gpu_timings binary"
fi

echo "== 3. N = 1e4 (first $N4_RUPTURES ruptures) and N = 1e5 (first $N5_RUPTURES)"
for size in n1e4 n1e5; do
    if [ $size = n1e4 ]; then limit=$N4_LIMIT k=$N4_RUPTURES; else limit=$N5_LIMIT k=$N5_RUPTURES; fi
    gpu_run $size "$limit" 1
    cpu_result $size
    ok=1
    for r in "$gpu_rc" "$cpu_rc"; do [ "$r" -eq 0 ] || [ "$r" -eq 124 ] || ok=0; done
    if [ $ok -eq 1 ]; then
        compare_dirs "$size, first $k ruptures" "$out/runs/$size.gpu" "$out/runs/$size.cpu" \
            "$gpu_time" "$cpu_time" --ruptures "$k"
    else
        not_run "$size" "$gpu_rc" "$cpu_rc" "$gpu_time" "$cpu_time"
    fi
done

echo "== 4. checkpoints across devices (top_64x32_spectral)"
cross="top_64x32_spectral"
reference="$out/runs/$cross.cpu"
if [ -f "$reference/curve.csv" ]; then
    stable=$(($(wc -l <"$reference/curve.csv") - 1))
    every=$((stable / 2 + 1))  # one checkpoint, past the middle of the run
    for way in gpu-to-cpu cpu-to-gpu; do
        if [ $way = gpu-to-cpu ]; then first=cuda then=spectral; else first=spectral then=cuda; fi
        dir="$out/runs/$cross.$way"
        rm -rf "$dir" "$dir.resumed"
        timed "$cross.$way.first" $SCENE_LIMIT "$program" run "$out/scenes/$cross.$first.json" --out "$dir" \
            -q --checkpoint "$dir.ck.json" --every "$every"
        first_time=$secs first_rc=$rc
        resumed_rc=1 resumed_time="-"
        if [ "$first_rc" -eq 0 ] && swap_backend "$dir.ck.json" "$dir.ck2.json" "$first" "$then"; then
            cp -r "$dir" "$dir.resumed"
            timed "$cross.$way.resume" $SCENE_LIMIT "$program" resume "$dir.ck2.json" --out "$dir.resumed" -q
            resumed_time=$secs resumed_rc=$rc
        fi
        if [ "$first_rc" -ne 0 ] || [ "$resumed_rc" -ne 0 ]; then
            not_run "checkpoint $way" "$first_rc" "$resumed_rc" "$first_time" "$resumed_time"
        else
            # GPU and CPU columns: the run that wrote the checkpoint and the resumed one.
            if [ $way = gpu-to-cpu ]; then g=$first_time c=$resumed_time; else g=$resumed_time c=$first_time; fi
            compare_dirs "checkpoint $way (at stable $every)" "$dir.resumed" "$reference" "$g" "$c"
        fi
    done
else
    row "checkpoints" SKIPPED "-" "no CPU reference"; status=1
fi
wait

echo
echo "== summary (times: wall seconds, peak resident memory of the process)"
printf '%-34s | %-9s | %-20s | %-20s\n' "check" "result" "GPU (cuda)" "CPU (spectral)"
printf '%s\n' "-----------------------------------+-----------+----------------------+---------------------"
printf '%s\n' "${rows[@]}"
if [ ${#phase_outputs[@]} -gt 0 ]; then
    echo
    echo "== per-phase times of the CUDA backend (the timed events of gpu_timings; a"
    echo "   synchronisation of the stream around each part; ms per CG iteration, share of the solves)"
    python3 "$here/phase-table.py" "${phase_outputs[@]}" | tee "$out/phases.txt"
fi
echo "$gpu_line"
echo "the check took $SECONDS s (budget $BUDGET s); outputs and logs: $out"
exit $status
