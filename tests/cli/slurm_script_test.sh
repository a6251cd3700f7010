#!/usr/bin/env bash
# scripts/slurm-turntable.sh's logs, without a cluster: a stand-in sbatch on
# PATH records each submission and writes each job's log where Slurm would
# (the --output pattern with %A, %a and %j filled in, or slurm-JOB.out and
# slurm-JOB_TASK.out in the folder it was called from when no --output is
# given). The logs must land in LOGS when it is set, else in logs/ beside
# the frames, never in the folder the script ran from; an unmakeable LOGS
# stops the script before anything is submitted. tests/cli/farm_test.sh checks
# the same on a real one-node Slurm (label farm). Usage: slurm_script_test.sh ROOT
set -u
root=$1
script=$root/scripts/slurm-turntable.sh
tmp=$(mktemp -d /tmp/veil-slurm-script.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

mkdir -p "$tmp/bin"
cat > "$tmp/bin/sbatch" <<'SBATCH'
#!/usr/bin/env bash
# A stand-in for sbatch --parsable: one job id a call, a log a job (task).
state=${FAKE_SBATCH_STATE:?}
echo "$*" >> "$state/calls"
n=$(( $(cat "$state/next" 2> /dev/null || echo 0) + 1 ))
echo "$n" > "$state/next"
output= tasks=
for a in "$@"; do
  case $a in
    --output=*) output=${a#--output=} ;;
    --array=1-*) tasks=${a#--array=1-} ;;
  esac
done
if [ -n "$tasks" ]; then
  for t in $(seq "$tasks"); do
    f=${output:-slurm-%A_%a.out}
    f=${f//%A/$n}; f=${f//%a/$t}; f=${f//%j/$n}
    echo "task $t of job $n" > "$f" || exit 1
  done
else
  f=${output:-slurm-%j.out}
  f=${f//%j/$n}
  echo "job $n" > "$f" || exit 1
fi
echo "$n"
SBATCH
chmod +x "$tmp/bin/sbatch"

# submit NAME [ENV...]: runs the script from a fresh folder $tmp/NAME/cwd, the frames in $tmp/NAME/shot/
submit() {
  local name=$1
  shift
  mkdir -p "$tmp/$name/cwd" "$tmp/$name/state"
  (cd "$tmp/$name/cwd" && env PATH="$tmp/bin:$PATH" FAKE_SBATCH_STATE="$tmp/$name/state" VEIL=/bin/true \
    MOVIE= SHEET= "$@" bash "$script" scene.json "$tmp/$name/shot/f.####.exr" 1-6 2 -- --width 40) \
    > "$tmp/$name/out.log" 2>&1
}
# expect_logs NAME DIR: the two array tasks' and the review job's logs in DIR, none where the script ran
expect_logs() {
  local name=$1 dir=$2
  for f in veil-frames_1_1.out veil-frames_1_2.out veil-review_2.out; do
    [ -s "$dir/$f" ] || fail "$name: no $f in $dir (there: $(ls "$dir" 2> /dev/null | tr '\n' ' '))"
  done
  local stray
  stray=$(cd "$tmp/$name/cwd" && ls slurm-*.out 2> /dev/null)
  [ -z "$stray" ] || fail "$name: logs in the folder the script ran from: $stray"
  grep -q -- "--output=$dir/" "$tmp/$name/state/calls" || fail "$name: no --output=$dir/ in $(cat "$tmp/$name/state/calls")"
  grep -q "logs: $dir\$" "$tmp/$name/out.log" || fail "$name: the script did not print its logs' folder: $(cat "$tmp/$name/out.log")"
}

# the stand-in without --output writes where the check above looks: the check can fail
mkdir -p "$tmp/self/cwd" "$tmp/self/state"
(cd "$tmp/self/cwd" && FAKE_SBATCH_STATE="$tmp/self/state" "$tmp/bin/sbatch" --parsable --array=1-2 --wrap true > /dev/null)
{ [ -s "$tmp/self/cwd/slurm-1_1.out" ] && [ -s "$tmp/self/cwd/slurm-1_2.out" ]; } ||
  fail "the stand-in sbatch wrote no slurm-*.out without --output: the stray-log check would be vacuous"

# default: logs/ beside the frames
submit default || fail "default: the script failed: $(cat "$tmp/default/out.log")"
expect_logs default "$tmp/default/shot/logs"

# LOGS, relative to the folder the script runs from: made, and named absolutely for the jobs
submit named LOGS=farm-logs || fail "named: the script failed: $(cat "$tmp/named/out.log")"
expect_logs named "$tmp/named/cwd/farm-logs"
[ ! -e "$tmp/named/shot/logs" ] || fail "named: logs/ beside the frames was made although LOGS names another folder"

# a LOGS that cannot be made: usage error, nothing submitted
mkdir -p "$tmp/bad"
touch "$tmp/bad/file"
submit bad LOGS="$tmp/bad/file/logs"
rc=$?
[ $rc -eq 2 ] || fail "bad: exit $rc for an unmakeable LOGS, expected 2"
grep -q "logs' folder" "$tmp/bad/out.log" || fail "bad: the message does not name the logs' folder: $(cat "$tmp/bad/out.log")"
[ ! -e "$tmp/bad/state/calls" ] || fail "bad: sbatch was called although the logs' folder could not be made"

[ $fails -eq 0 ] || exit 1
echo "PASS: the jobs' logs in LOGS or beside the frames, none where the script ran; an unmakeable LOGS refused"
