#!/usr/bin/env bash
# A turntable on a real Slurm: a one-node cluster on this machine (munged,
# slurmctld and slurmd on localhost, state and spool in a temporary folder,
# stopped by their PIDs at the end), scripts/slurm-turntable.sh submitting
# a job array of shards and the review job after them. The frames must be
# byte for byte those of one local run, and the contact sheet must exist;
# the jobs' logs must land in logs/ beside the frames (or in LOGS when it
# names a folder), never in the folder the script was run from.
# Skipped (exit 77) without the Debian packages slurm-wlm and munge, or when
# not root (slurmd runs jobs as their users: the test's user must be root to
# run the daemons without systemd). Usage: farm_test.sh VEIL SCENE ROOT
set -u
veil=$1
scene=$2
root=$3
for p in munged mungekey slurmctld slurmd sbatch squeue sinfo; do
  command -v "$p" > /dev/null || { echo "SKIPPED: no $p (make test-farm installs slurm-wlm and munge)"; exit 77; }
done
[ "$(id -u)" -eq 0 ] || { echo "SKIPPED: the daemons need root here"; exit 77; }
tmp=$(mktemp -d /tmp/veil-farm.XXXXXX)
chmod 755 "$tmp"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2> /dev/null; done
  sleep 1
  for p in "${pids[@]}"; do kill -9 "$p" 2> /dev/null; done
  rm -rf "$tmp"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  for f in "$tmp"/*.log; do echo "== $f"; tail -20 "$f"; done
  exit 1
}

# munge: a key, the daemon on a socket of our own
mungekey -c -k "$tmp/munge.key" > /dev/null 2>&1 || fail "mungekey"
chmod 600 "$tmp/munge.key"
munged --force --key-file="$tmp/munge.key" --socket="$tmp/munge.socket" --pid-file="$tmp/munged.pid" \
  --log-file="$tmp/munged.log" --seed-file="$tmp/munge.seed" || fail "munged did not start"
for _ in $(seq 50); do [ -s "$tmp/munged.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$tmp/munged.pid")")

# slurm: one node, this machine's cores, ports of our own
port=$((20000 + RANDOM % 20000))
node=$(hostname -s)
mkdir -p "$tmp/state" "$tmp/spool"
cat > "$tmp/slurm.conf" <<EOF
ClusterName=veilfarm
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge.socket
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=$node NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=farm Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$tmp/slurm.conf
slurmctld -D -i -f "$tmp/slurm.conf" > "$tmp/slurmctld.out.log" 2>&1 &
pids+=($!)
slurmd -D -N "$node" -f "$tmp/slurm.conf" > "$tmp/slurmd.out.log" 2>&1 &
pids+=($!)
up=0
for _ in $(seq 100); do
  sinfo -h -o '%T' 2> /dev/null | grep -q -E '^idle' && { up=1; break; }
  sleep 0.3
done
[ $up -eq 1 ] || fail "the node did not come up: $(sinfo 2>&1)"

# the turntable: 6 frames over 2 array tasks, then the review job
out=$tmp/frames
mkdir -p "$out" "$tmp/local" "$tmp/submit"
opts=(--width 40 --height 30 --degrees 90 --seed 3)
wait_queue() {
  for _ in $(seq 300); do
    [ -z "$(squeue -h 2> /dev/null)" ] && return 0
    sleep 0.5
  done
  fail "jobs still queued after 150 s: $(squeue 2>&1)"
}
# submitted from a folder of its own, where Slurm would write slurm-*.out without --output
(cd "$tmp/submit" && SHEET="$tmp/sheet.png" MOVIE="" VEIL="$veil" bash "$root/scripts/slurm-turntable.sh" "$scene" \
  "$out/f.####.exr" 1-6 2 -- "${opts[@]}") > "$tmp/submit.log" 2>&1 || fail "submit: $(cat "$tmp/submit.log")"
wait_queue
"$veil" turntable "$scene" -o "$tmp/local/f.####.exr" --range 1-6 "${opts[@]}" > /dev/null || fail "local run"
for f in 1 2 3 4 5 6; do
  cmp -s "$out/f.000$f.exr" "$tmp/local/f.000$f.exr" || fail "frame $f differs from one local run (or is missing)"
done
[ -s "$tmp/sheet.png" ] || fail "the review job made no contact sheet"
# the logs: by default in logs/ beside the frames, one a task and one for the review job
n=$(find "$out/logs" -name 'veil-frames_*.out' 2> /dev/null | wc -l)
[ "$n" -eq 2 ] || fail "$n frame tasks' logs in $out/logs, expected 2: $(ls -A "$out" "$out/logs" 2>&1)"
n=$(find "$out/logs" -name 'veil-review_*.out' 2> /dev/null | wc -l)
[ "$n" -eq 1 ] || fail "$n review jobs' logs in $out/logs, expected 1"
grep -q "shard 1/2" "$out"/logs/veil-frames_*_1.out || fail "the first task's log does not hold its turntable line"
# again with LOGS: every frame is there (--skip-existing), so the jobs only log, into the named folder
(cd "$tmp/submit" && LOGS="$tmp/named-logs" SHEET="" MOVIE="" VEIL="$veil" bash "$root/scripts/slurm-turntable.sh" \
  "$scene" "$out/f.####.exr" 1-6 1 -- "${opts[@]}") > "$tmp/submit2.log" 2>&1 || fail "submit with LOGS: $(cat "$tmp/submit2.log")"
wait_queue
n=$(find "$tmp/named-logs" -name 'veil-*.out' 2> /dev/null | wc -l)
[ "$n" -eq 2 ] || fail "$n logs in LOGS=$tmp/named-logs, expected 2 (one task, the review job)"
n=$(find "$out/logs" -name 'veil-*.out' | wc -l)
[ "$n" -eq 3 ] || fail "the run with LOGS also wrote into logs/ beside the frames ($n logs there, expected 3)"
stray=$(find "$tmp/submit" -name 'slurm-*.out')
[ -z "$stray" ] || fail "logs in the folder the script ran from: $stray"
echo "PASS: 6 frames from 2 array tasks, the same bytes as one local run; the review job's contact sheet;"
echo "      the logs beside the frames (or in LOGS), none where the script ran"

# bench/farm: with FARM_BENCH_SCENE and FARM_BENCH_FRAMES, the time from submission to an empty queue
# for 1 and 2 array tasks on this cluster (docs/performance.md)
if [ -n "${FARM_BENCH_SCENE:-}" ]; then
  for tasks in 1 2; do
    rm -rf "$tmp/bench" && mkdir -p "$tmp/bench"
    t0=$(date +%s.%N)
    SHEET="" MOVIE="" VEIL="$veil" bash "$root/scripts/slurm-turntable.sh" "$FARM_BENCH_SCENE" "$tmp/bench/f.####.exr" \
      "1-${FARM_BENCH_FRAMES:-36}" $tasks > /dev/null 2>&1 || fail "bench submit"
    while [ -n "$(squeue -h 2> /dev/null)" ]; do sleep 0.2; done
    t1=$(date +%s.%N)
    n=$(ls "$tmp/bench" | grep -c '\.exr$')
    awk -v a="$t0" -v b="$t1" -v t=$tasks -v n="$n" 'BEGIN { printf "farm bench: %d task(s): %d frames in %.2f s\n", t, n, b - a }'
  done
fi
