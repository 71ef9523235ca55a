#!/usr/bin/env bash
# A sweep as a SLURM job array on a real (one-node) SLURM, compared with the same sweep run
# locally: the tables must be identical (docs/cluster.md, where its output is shown).
#
# Needs root on a Debian 12 machine (apt-get installs slurm-wlm and munge); starts its own
# munged, slurmctld and slurmd directly (no systemd), with their configuration, sockets,
# state and logs under $SMOKE_DIR (default /tmp/precursors-slurm-smoke, emptied first), and
# stops them on exit. It touches neither /etc/slurm nor the system's munge. Takes about a
# minute after the build. Not part of .ci/run (root, minutes).
#
#   sudo bash scripts/slurm-smoke.sh        # exit 0: identical tables; non-zero otherwise
set -euo pipefail

REPO=$(cd "$(dirname "$0")/.." && pwd)
W=${SMOKE_DIR:-/tmp/precursors-slurm-smoke}
NODE=$(hostname -s)
CPUS=$(nproc)
# 90 % of the memory (MB): a node configured with more than it has is drained.
MEMORY=$(awk '/^MemTotal/ { print int($2 / 1024 * 0.9) }' /proc/meminfo)
# Ports of our own, so that a SLURM the machine may run is not disturbed.
CTLD_PORT=16817
SLURMD_PORT=16818
WAIT_SECONDS=${SMOKE_WAIT_SECONDS:-900}

say() { printf '\n== %s\n' "$*"; }
fail() {
    echo "FAIL: $*" >&2
    exit 1
}

[ "$(id -u)" = 0 ] || fail "run as root (installs packages, starts slurmd)"
command -v cargo >/dev/null || fail "cargo is not on PATH (sudo may reset it: sudo env PATH=\"\$PATH\" ...)"
# $W is emptied: refuse a directory this script did not make.
if [ -e "$W" ] && [ ! -e "$W/.precursors-slurm-smoke" ] && [ -n "$(ls -A "$W")" ]; then
    fail "$W exists and is not this script's (set SMOKE_DIR)"
fi

say "packages: slurm-wlm, munge"
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi
dpkg-query -W -f='${Package} ${Version}\n' slurm-wlm slurmctld slurmd munge

# Stops the jobs and daemons this script started (pid files in $W/pids): on exit, and
# first, those an interrupted earlier run left.
stop_daemons() {
    local name pid
    # Jobs first, while slurmd can still end their slurmstepd (it would outlive slurmd).
    if [ -f "$W/pids/slurmctld" ] && kill -0 "$(cat "$W/pids/slurmctld")" 2>/dev/null; then
        export SLURM_CONF=$W/etc/slurm.conf
        timeout 10 scancel --user=root 2>/dev/null || true
        for _ in $(seq 30); do
            [ -z "$(timeout 5 squeue -h 2>/dev/null)" ] && break
            sleep 1
        done
    fi
    for name in slurmd slurmctld munged; do
        [ -f "$W/pids/$name" ] || continue
        pid=$(cat "$W/pids/$name")
        if kill -0 "$pid" 2>/dev/null; then
            kill "$pid" 2>/dev/null || true
            for _ in $(seq 50); do
                kill -0 "$pid" 2>/dev/null || break
                sleep 0.2
            done
            kill -0 "$pid" 2>/dev/null && kill -9 "$pid" 2>/dev/null || true
        fi
        rm -f "$W/pids/$name"
    done
}
stop_daemons
trap 'status=$?; say "stopping the daemons"; stop_daemons; exit $status' EXIT
trap 'exit 130' INT TERM
rm -rf "$W"
mkdir -p "$W"/{etc,pids,run,log,state/ctld,state/d,munge,bin,logs}
touch "$W/.precursors-slurm-smoke" "$W/log/jobcomp.txt"
chmod 700 "$W/munge" # the key; the sockets are in run/

say "build: cargo build --release --features cli"
(cd "$REPO" && cargo build --release --features cli --bin precursors -q)
TARGET=$(cd "$REPO" && cargo metadata --format-version 1 --no-deps |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
# The jobs run a copy, so a rebuild while they run cannot change what they run.
cp "$TARGET/release/precursors" "$W/bin/precursors"
P=$W/bin/precursors
"$P" --version

say "munge: a key and a munged of our own"
mungekey --create --keyfile="$W/munge/munge.key" --bits=1024
munged --foreground --force --socket="$W/run/munge.socket" \
    --key-file="$W/munge/munge.key" --pid-file="$W/run/munged.pid" \
    --seed-file="$W/munge/munged.seed" >"$W/log/munged.log" 2>&1 &
echo $! >"$W/pids/munged"
for _ in $(seq 50); do
    [ -S "$W/run/munge.socket" ] && break
    sleep 0.2
done
munge --socket="$W/run/munge.socket" -n | unmunge --socket="$W/run/munge.socket" |
    grep -E '^STATUS' || fail "munge does not answer (log: $W/log/munged.log)"

say "slurm.conf: one node ($NODE, $CPUS CPUs, $MEMORY MB) on localhost"
export SLURM_CONF=$W/etc/slurm.conf
cat >"$SLURM_CONF" <<EOF
ClusterName=smoke
SlurmctldHost=$NODE(127.0.0.1)
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$W/run/munge.socket
StateSaveLocation=$W/state/ctld
SlurmdSpoolDir=$W/state/d
SlurmctldPidFile=$W/run/slurmctld.pid
SlurmdPidFile=$W/run/slurmd.pid
# No cgroups: processes tracked through /proc, no task binding.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$W/log/jobcomp.txt
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
NodeName=$NODE NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$MEMORY State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
grep -v '^#' "$SLURM_CONF" | sed 's/^/  /'

say "start slurmctld and slurmd"
# In the foreground (-D) as our children, logging to log/.
slurmctld -D -f "$SLURM_CONF" >"$W/log/slurmctld.log" 2>&1 &
echo $! >"$W/pids/slurmctld"
slurmd -D -N "$NODE" -f "$SLURM_CONF" >"$W/log/slurmd.log" 2>&1 &
echo $! >"$W/pids/slurmd"
for _ in $(seq 120); do
    state=$(sinfo -h -N -o %t 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.5
done
[ "$state" = idle ] || fail "node not idle (state '$state'; logs in $W/log)"
sinfo --version
sinfo -N -o '%N %P %t %c'

say "the sweep: calibration scene, 2 loads x 4 realizations = 8 runs"
cat >"$W/study.json" <<'EOF'
{ "base": { "block": { "lx": 0.140, "ly": 0.007, "lz": 0.075 },
            "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
            "normal_load": 3500.0,
            "drive": { "kind": "rod", "height": 0.006, "half_width": 0.002 } },
  "axes": [ { "key": "normal_load", "values": [2500.0, 3500.0] } ],
  "realizations": 4, "seed": 1 }
EOF
cat "$W/study.json"

# The array task: its shard comes from SLURM's variables, unless SHARD is exported (to
# rerun one task alone: sbatch --array=2 --export=ALL,SHARD=2/4).
cat >"$W/job.sh" <<EOF
#!/usr/bin/env bash
#SBATCH --job-name=precursors-smoke
#SBATCH --cpus-per-task=1
#SBATCH --time=00:10:00
#SBATCH --output=$W/logs/%x-%A_%a.out
set -euo pipefail
echo "task \$SLURM_ARRAY_TASK_ID on \$(hostname -s): SLURM_ARRAY_TASK_COUNT=\${SLURM_ARRAY_TASK_COUNT-unset} MIN=\${SLURM_ARRAY_TASK_MIN-unset} MAX=\${SLURM_ARRAY_TASK_MAX-unset} STEP=\${SLURM_ARRAY_TASK_STEP-unset} SHARD=\${SHARD-unset}"
exec "$P" sweep "$W/study.json" --out "\$1" --jobs "\${SLURM_CPUS_PER_TASK:-1}" \${SHARD:+--shard "\$SHARD"}
EOF

# Waits until squeue shows none of the jobs $1 (comma-separated).
wait_jobs() {
    local t0=$SECONDS
    while [ -n "$(squeue -h -j "$1" 2>/dev/null)" ]; do
        [ $((SECONDS - t0)) -lt "$WAIT_SECONDS" ] || fail "jobs $1 still running after ${WAIT_SECONDS}s"
        sleep 1
    done
    echo "all tasks ended after $((SECONDS - t0)) s"
}

# Checks in the job completion record that the $2 tasks of array job $1 ended COMPLETED
# with exit code 0, and prints the record and the tasks' logs ($3: their file names, with
# the task id as '*').
check_tasks() {
    local job=$1 tasks=$2 logs=$3 records f
    # One line per task, given a few seconds to be written.
    for _ in $(seq 10); do
        records=$(awk -v job="$job" '$0 ~ (" ArrayJobId=" job " ") {
            for (i = 1; i <= NF; i++) { split($i, kv, "="); f[kv[1]] = $i }
            print f["ArrayTaskId"], f["JobState"], f["ExitCode"], f["StartTime"], f["EndTime"]
            }' "$W/log/jobcomp.txt" | sort -t= -k2 -n)
        [ "$(grep -c . <<<"$records")" -ge "$tasks" ] && break
        sleep 1
    done
    echo "$records"
    [ "$(grep -c 'JobState=COMPLETED ExitCode=0:0' <<<"$records")" = "$tasks" ] ||
        fail "not every task of job $job completed with exit code 0 (logs: $logs)"
    for f in $logs; do
        echo "--- $(basename "$f")"
        cat "$f"
    done
}

# Checks that the (non-array) job $1 ended COMPLETED with exit code 0 and prints its log $2.
check_job() {
    echo "--- $(basename "$2")"
    cat "$2"
    grep -q "^JobId=$1 .*JobState=COMPLETED .*ExitCode=0:0" "$W/log/jobcomp.txt" ||
        fail "job $1 did not complete with exit code 0"
}

# Submits job.sh as an array of $1 tasks writing into $2 (sbatch's options: the rest),
# waits for it and checks its tasks. With MERGE=1, also submits `precursors merge` at once
# as a job that waits for the array (--dependency=afterok): it must find every run
# complete.
run_array() {
    local tasks=$1 out=$2 job jobs merge_job=
    shift 2
    job=$(sbatch --parsable "$@" "$W/job.sh" "$out")
    job=${job%%;*}
    JOB=$job
    jobs=$job
    echo "sbatch $* job.sh $out: job $job"
    if [ "${MERGE:-0}" = 1 ]; then
        merge_job=$(sbatch --parsable --dependency=afterok:"$job" --job-name=precursors-merge \
            --output="$W/logs/merge-%j.out" --wrap "$P merge $out")
        echo "sbatch --dependency=afterok:$job --wrap \"precursors merge $out\": job $merge_job"
        jobs=$job,$merge_job
    fi
    squeue -r -j "$jobs" -o '%.10i %.9T %.6M %R' || true
    wait_jobs "$jobs"
    check_tasks "$job" "$tasks" "$W/logs/precursors-smoke-${job}_*.out"
    [ -z "$merge_job" ] || check_job "$merge_job" "$W/logs/merge-$merge_job.out"
}

# Compares two sweep directories: every file byte for byte, except meta.json, compared
# without its timings (`seconds`).
compare() {
    local a=$1 b=$2 n
    diff -r -x meta.json "$a" "$b" || fail "$a and $b differ"
    python3 - "$a" "$b" <<'EOF' || fail "meta.json differ (beyond the timings)"
import json, pathlib, sys
a, b = (pathlib.Path(p) for p in sys.argv[1:])
metas = sorted(p.relative_to(a) for p in a.glob("*/meta.json"))
assert metas == sorted(p.relative_to(b) for p in b.glob("*/meta.json")), "runs differ"
for m in metas:
    x, y = (json.loads((root / m).read_text()) for root in (a, b))
    x.pop("seconds"); y.pop("seconds")
    assert x == y, f"{m} differs"
print(f"meta.json: {len(metas)} files identical but for `seconds`")
EOF
    n=$(cd "$a" && find . -type f ! -name meta.json | wc -l)
    echo "IDENTICAL: $a and $b ($n files byte for byte: merged tables, each run's events.csv, curve.csv, contact_map.csv, done; sweep.json)"
}

say "local: the same sweep, unsharded, --jobs $CPUS"
"$P" sweep "$W/study.json" --out "$W/local" --jobs "$CPUS"
"$P" merge "$W/local"

say "SLURM: sbatch --array=0-3 (ids from 0), and the merge as a job after it (afterok)"
MERGE=1 run_array 4 "$W/slurm" --array=0-3
compare "$W/local" "$W/slurm"

say "SLURM: sbatch --array=10-16:2 (ids 10, 12, 14, 16: neither from 0 nor contiguous)"
run_array 4 "$W/slurm-step" --array=10-16:2
"$P" merge "$W/slurm-step"
compare "$W/local" "$W/slurm-step"

# Cuts run 6 (p0001-r0002, shard 2 of 4) as a killed task leaves it: no meta.json nor
# 'done', events.csv cut mid-line; and removes the merged tables.
cut_run() {
    local run=$W/slurm/p0001-r0002
    rm "$run/done" "$run/meta.json"
    head -c 2000 "$run/events.csv" >"$run/events.tmp"
    mv "$run/events.tmp" "$run/events.csv"
    rm "$W"/slurm/{curves,slip,avalanches,runs}.csv
}
# The runs the tasks of job $JOB ran (not skipped).
runs_done() {
    cat "$W"/logs/precursors-smoke-"$JOB"_*.out | awk '/runs done/ { s += $1 } END { print s }'
}

say "restart: run 6 cut, the whole array submitted again"
cut_run
run_array 4 "$W/slurm" --array=0-3
[ "$(runs_done)" = 1 ] || fail "the restarted array ran $(runs_done) runs, not the 1 cut"
"$P" merge "$W/slurm"
compare "$W/local" "$W/slurm"

say "restart: run 6 cut, task 2 alone (sbatch --array=2 --export=ALL,SHARD=2/4)"
cut_run
run_array 1 "$W/slurm" --array=2 --export=ALL,SHARD=2/4
[ "$(runs_done)" = 1 ] || fail "the restarted task ran $(runs_done) runs, not the 1 cut"
"$P" merge "$W/slurm"
compare "$W/local" "$W/slurm"

say "the batch script of docs/cluster.md, as written there but for --array=0-3 and --cpus-per-task=1"
mkdir -p "$W/doc/logs"
cp "$W/study.json" "$W/doc/study.json"
awk '/^## The batch script/ { f = 1 } f && /^```bash/ { b = 1; next } b && /^```/ { exit } b' \
    "$REPO/docs/cluster.md" >"$W/doc/sweep.sbatch"
[ -s "$W/doc/sweep.sbatch" ] || fail "no batch script found in docs/cluster.md"
(
    cd "$W/doc"
    job=$(PRECURSORS=$P sbatch --parsable --array=0-3 --cpus-per-task=1 sweep.sbatch)
    merge_job=$(sbatch --parsable --dependency=afterok:"$job" --output=logs/merge-%j.out \
        --wrap "$P merge study")
    echo "cd $W/doc; sbatch --array=0-3 --cpus-per-task=1 sweep.sbatch: job $job;" \
        "sbatch --dependency=afterok:$job --wrap \"precursors merge study\": job $merge_job"
    wait_jobs "$job,$merge_job"
    check_tasks "$job" 4 "$W/doc/logs/precursors-sweep-${job}_*.out"
    check_job "$merge_job" "$W/doc/logs/merge-$merge_job.out"
)
compare "$W/local" "$W/doc/study"

say "PASS: the SLURM arrays' tables equal the local sweep's"
