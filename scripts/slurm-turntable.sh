#!/usr/bin/env bash
# Renders a turntable on a Slurm cluster: a job array whose tasks are
# shards of the frame range (veil turntable --shard I/N --skip-existing),
# then a job that waits for all of them (afterok) and makes the contact
# sheet and the movie from the frames on disk.
#
#   scripts/slurm-turntable.sh SCENE OUT RANGE TASKS [-- more veil turntable options]
#
#   SCENE  the scene file (a path every node can read: a shared filesystem)
#   OUT    the frames' pattern, e.g. /shared/shots/smoke.####.exr
#   RANGE  frames, e.g. 1001-1100 or 1-36x2
#   TASKS  array tasks (shards); a task renders every TASKS-th frame
#
# Environment: VEIL (the veil program on the nodes; default the one on
# PATH, else this checkout's build/veil), MOVIE (default OUT's name before
# the frame number + .mp4; empty: no movie), SHEET (likewise + _sheet.png),
# LOGS (the folder for the jobs' logs, made if missing; default logs/ in
# OUT's folder, beside the frames: veil-frames_JOB_TASK.out for each array
# task, veil-review_JOB.out for the review job, never slurm-*.out in the
# folder sbatch ran from), SBATCH_ARGS (more sbatch options for every job:
# --partition, --time, --cpus-per-task, --gres=gpu:1 ...). Prints the two
# job ids and the logs' folder.
#
# Frames are renamed into place whole and each frame's bytes depend only on
# the scene and its number, so a re-queued task (Slurm's requeue, or
# running this script again) renders only what is missing, and the movie
# job can run again on its own. On a real cluster: put the scene, its VDBs
# and OUT on storage every node mounts, install veil (or point VEIL at a
# build there), and pass the partition and time limits in SBATCH_ARGS; on
# GPU nodes add --gres=gpu:1 (veil picks the NVIDIA EGL device when there
# is one, llvmpipe otherwise).
set -euo pipefail
if [ $# -lt 4 ]; then
  awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0" >&2 # the header above
  exit 2
fi
scene=$1 out=$2 range=$3 tasks=$4
shift 4
[ "${1:-}" = "--" ] && shift
extra=("$@")
case $tasks in '' | *[!0-9]* | 0) echo "slurm-turntable: TASKS must be a whole number >= 1, got '$tasks'" >&2; exit 2 ;; esac
here=$(cd "$(dirname "$0")/.." && pwd)
veil=${VEIL:-$(command -v veil || echo "$here/build/veil")}
[ -x "$veil" ] || { echo "slurm-turntable: no veil program at '$veil' (set VEIL)" >&2; exit 2; }
command -v sbatch > /dev/null || { echo "slurm-turntable: sbatch not found: is this a Slurm submit host?" >&2; exit 2; }
stem=${out%%#*}
stem=${stem%%\%*}
stem=${stem%.}
movie=${MOVIE-$stem.mp4}
sheet=${SHEET-${stem}_sheet.png}
# Slurm does not make an --output folder (a job whose log cannot be opened
# fails without a word), so it is made here, and named absolutely: the jobs
# may start in another folder than this one.
logs=${LOGS:-$(dirname -- "$out")/logs}
mkdir -p -- "$logs" || { echo "slurm-turntable: cannot make the logs' folder '$logs' (set LOGS)" >&2; exit 2; }
logs=$(cd -- "$logs" && pwd)
q() { printf '%q ' "$@"; } # quoted for the job's shell
# shellcheck disable=SC2086
array=$(sbatch --parsable ${SBATCH_ARGS:-} --job-name=veil-frames --array=1-"$tasks" \
  --output="$logs/veil-frames_%A_%a.out" \
  --wrap "$(q "$veil" turntable "$scene" -o "$out" --range "$range" --skip-existing "${extra[@]}") --shard \$SLURM_ARRAY_TASK_ID/$tasks")
review=()
[ -n "$sheet" ] && review+=(--contact-sheet "$sheet")
[ -n "$movie" ] && review+=(--movie "$movie")
# shellcheck disable=SC2086
assemble=$(sbatch --parsable ${SBATCH_ARGS:-} --job-name=veil-review --dependency=afterok:"${array%%;*}" \
  --output="$logs/veil-review_%j.out" \
  --wrap "$(q "$veil" turntable "$scene" -o "$out" --range "$range" --skip-existing "${extra[@]}" "${review[@]}")")
echo "frames: job array ${array%%;*} ($tasks tasks); review: job ${assemble%%;*} (after all of them); logs: $logs"
