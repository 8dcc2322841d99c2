#!/usr/bin/env bash
# Renders a scene on a real one-node Slurm cluster started on this machine
# and checks the merged image against a single-machine render, byte for byte:
#   tests/slurm/run.sh [PBRS_BINARY]     (default: target/release/pbrs)
# 1. installs Debian's slurm-wlm and munge when missing (apt-get; needs root),
# 2. writes a slurm.conf and a munge key to a temporary folder and starts
#    munged, slurmctld and slurmd (localhost, ports 16817/16818),
# 3. renders the test scene on one machine, then as an array job of 2 and of
#    4 tasks followed by a merge job (--dependency=afterok), via
#    examples/farm/submit.sh, comparing each merge with `cmp`,
# 4. again with 4 tasks, killing one task's renderer midway (SIGKILL): the
#    task requeues itself, reruns, and the merge still gives the same bytes,
# 5. prints the timings and tears everything down (also on failure).
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
pbrs=$(realpath "${1:-$repo/target/release/pbrs}")
[ -x "$pbrs" ] || { echo "no pbrs binary at $pbrs (cargo build --release)"; exit 1; }
# The test scene and flags (the same for the single render and every task).
scene=$repo/scenes/cornell-box.pbrt
flags="--quiet --quick --spp 32"
timeout_s=${SLURM_TEST_TIMEOUT:-600}

log() { echo "[slurm-test $(date +%T)] $*"; }
now() { date +%s.%N; }
secs() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null || ! command -v sbatch >/dev/null; then
    log "installing slurm-wlm and munge"
    sudo=""; [ "$(id -u)" -eq 0 ] || sudo=sudo
    $sudo env DEBIAN_FRONTEND=noninteractive apt-get update -qq
    $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
fi

[ "$(id -u)" -eq 0 ] || { echo "slurmd runs as root here: run this as root"; exit 1; }
work=$(mktemp -d /tmp/pbrs-slurm.XXXXXX)
chmod 755 "$work"
pids=()
cleanup() {
    status=$?
    if [ -n "${SLURM_CONF:-}" ] && [ -f "$work/slurmctld.pid" ]; then
        scancel --quiet --full --signal=KILL -u "$(id -un)" 2>/dev/null || true
    fi
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    for f in slurmd slurmctld munged; do
        [ -f "$work/$f.pid" ] && kill "$(cat "$work/$f.pid")" 2>/dev/null || true
    done
    sleep 1
    if [ "$status" -ne 0 ]; then
        log "FAILED (status $status); logs:"
        for f in "$work"/slurmctld.log "$work"/slurmd.log "$work"/run-*/parts/*.log; do
            [ -f "$f" ] && { echo "== $f"; tail -n 30 "$f"; }
        done
    fi
    rm -rf "$work"
    exit "$status"
}
trap cleanup EXIT

# munge: its own key, socket and state in $work (the system's is untouched).
mkdir -p "$work/munge" && chmod 700 "$work/munge"
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$work/munge/munge.key"
munged --force --key-file="$work/munge/munge.key" --socket="$work/munge/munge.socket" \
    --pid-file="$work/munged.pid" --log-file="$work/munge/munged.log" \
    --seed-file="$work/munge/munged.seed"
cpus=$(nproc)
mem=$(awk '/MemTotal/ { print int($2 / 1024 / 2) }' /proc/meminfo)
mkdir -p "$work/state" "$work/spool"
cat > "$work/slurm.conf" <<CONF
ClusterName=pbrs-test
SlurmctldHost=localhost
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
# cred_expire: how long a requeued job waits before it may start again
# (default 120 s).
AuthInfo=socket=$work/munge/munge.socket,cred_expire=10
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
JobRequeue=1
MinJobAge=600
# Test all pending jobs every second (a requeued job becomes eligible by time,
# not by an event; the default pass is every 60 s).
SchedulerParameters=sched_interval=1
InactiveLimit=0
KillWait=5
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$work/slurm.conf
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF" -N localhost
for _ in $(seq 60); do
    sinfo -h -o %T 2>/dev/null | grep -qx idle && break
    sleep 1
done
sinfo -h -o %T | grep -qx idle || { log "the node did not come up"; sinfo || true; exit 1; }
log "slurm $(sinfo -V | awk '{ print $2 }') up: node localhost, $cpus CPUs"

# The single-machine render.
t=$(now)
# shellcheck disable=SC2086
# --reproducible: no render metadata (the merged frame has none), so cmp can compare.
"$pbrs" "$scene" $flags --reproducible --outfile "$work/full.exr"
single=$(secs "$t" "$(now)")
log "single-machine render: $single s"

# Waits until job $1 has left the queue; fails after $timeout_s.
wait_job() {
    local end=$((SECONDS + timeout_s))
    while squeue -h -j "$1" 2>/dev/null | grep -q .; do
        [ $SECONDS -lt $end ] || { log "job $1 timed out"; squeue; return 1; }
        sleep 0.2
    done
}

# Runs the scene as an array of $1 tasks and a merge; $2 = a task to kill.
farm() {
    local n=$1 kill_task=${2:-} dir="$work/run-$1${2:+-kill}"
    mkdir -p "$dir"
    local t0 ids array merge
    t0=$(now)
    # shellcheck disable=SC2086
    ids=$(PBRS=$pbrs PARTS=$dir/parts "$repo/examples/farm/submit.sh" "$scene" "$n" "$dir/frame.exr" $flags)
    read -r array merge <<<"$ids"
    if [ -n "$kill_task" ]; then
        local pidfile="$dir/parts/.task-$kill_task.attempt-0.pid" end=$((SECONDS + timeout_s))
        until [ -s "$pidfile" ]; do
            [ $SECONDS -lt $end ] || { log "task $kill_task never started"; return 1; }
            sleep 0.1
        done
        # Stop it early in its render (before it can finish on a fast
        # machine), then kill it: a crash or an OOM kill midway.
        sleep 0.3
        kill -STOP "$(cat "$pidfile")" ||
            { log "task $kill_task's renderer ended before it could be killed"; return 1; }
        kill -KILL "$(cat "$pidfile")"
        log "killed task $kill_task's renderer (pid $(cat "$pidfile")) midway"
    fi
    wait_job "$array"
    wait_job "$merge"
    local wall
    wall=$(secs "$t0" "$(now)")
    [ -f "$dir/frame.exr" ] || { log "no merged image"; cat "$dir/parts/merge.log" || true; return 1; }
    cmp "$work/full.exr" "$dir/frame.exr"
    if [ -n "$kill_task" ]; then
        [ -s "$dir/parts/.task-$kill_task.attempt-1.pid" ] ||
            { log "task $kill_task was not rerun"; return 1; }
        grep -q "requeued" "$dir/parts/task-$kill_task.log"
    fi
    # The merge alone (parts already on disk).
    local tm
    tm=$(now)
    "$pbrs" merge --quiet "$dir/again.exr" "$dir"/parts/part-*.exr
    local mt
    mt=$(secs "$tm" "$(now)")
    cmp "$work/full.exr" "$dir/again.exr"
    log "$n tasks${kill_task:+ (task $kill_task killed and requeued)}: array + merge job wall time $wall s, merge $mt s; merged image identical to the single render"
    echo "$n${kill_task:+ killed} $wall $mt" >> "$work/timings"
}

farm 2
farm 4
farm 4 1

# Per-part overhead: a one-row tile at 1 spp is all scene load + BVH build +
# write (its render is a few hundred samples).
t=$(now)
# shellcheck disable=SC2086
"$pbrs" "$scene" $flags --spp 1 --tile 0 --tiles 256 --outfile "$work/overhead.exr"
overhead=$(secs "$t" "$(now)")
log "summary: single render $single s; per-part overhead (1 row, 1 spp) $overhead s"
while read -r n k w m; do
    if [ "$k" = killed ]; then
        log "  $n tasks, one killed and requeued: wall $w s, merge $m s"
    else
        log "  $n tasks: wall $w s, merge $m s"
    fi
done < <(sed 's/ killed / killed /; t; s/^\([0-9]*\) /\1 - /' "$work/timings")
log "PASS"
