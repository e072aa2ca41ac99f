#!/usr/bin/env bash
# A shot's flare on a Slurm cluster, as a job array (docs/farm.md). Run it on the login node:
#
#   scripts/slurm-simulate.sh --frames 1001-1100 --per-task 10 --cache /shared/ff-cache \
#       [--sbatch "--partition=render --time=1:00:00"] [--wait] -- \
#       --lens double-gauss-50mm-f2 --plate shot/plate.%04d.exr -o out/flare.%04d.exr [simulate options]
#
# It submits itself as `sbatch --array=0-(N-1)`, N = ceil(frames / per-task); task i renders frames
# FIRST + i*per-task .. (the next per-task - 1, at most LAST) with
#   fourierflare simulate <options> --frames A-B --skip-existing
# with FF_CACHE_DIR set to the shared cache folder on every task: the first tasks to need a ghost
# table or PSF build it, the others read it. Each frame's files are written under a temporary name
# and renamed, so a failed or killed task leaves no partial frame; submitting the same command again
# renders only the frames that are missing. The frames' bytes do not depend on how the shot was split.
#
# FOURIERFLARE names the binary (default: fourierflare on the PATH). Each task takes the CPUs
# --sbatch gives it (--cpus-per-task, default 2) and passes them as --threads.
set -euo pipefail

usage() { sed -n '2,7p' "$0" >&2; exit 2; }

if [ -n "${SLURM_ARRAY_TASK_ID:-}" ]; then
  # Inside a task: its frame range, from the submission's settings.
  first="$FF_FARM_FIRST" last="$FF_FARM_LAST" per="$FF_FARM_PER_TASK"
  a=$((first + SLURM_ARRAY_TASK_ID * per))
  b=$((a + per - 1))
  [ "$b" -le "$last" ] || b="$last"
  export FF_CACHE_DIR="$FF_FARM_CACHE"
  threads="${SLURM_CPUS_PER_TASK:-${SLURM_CPUS_ON_NODE:-1}}"
  echo "slurm-simulate: task $SLURM_ARRAY_TASK_ID of job $SLURM_ARRAY_JOB_ID on $(hostname): frames $a-$b, $threads threads"
  exec "${FOURIERFLARE:-fourierflare}" --threads "$threads" simulate "$@" --frames "$a-$b" --skip-existing
fi

frames="" per="" cache="" extra="--cpus-per-task=2" wait=""
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames="$2"; shift 2 ;;
    --per-task) per="$2"; shift 2 ;;
    --cache) cache="$2"; shift 2 ;;
    --sbatch) extra="$extra $2"; shift 2 ;;
    --wait) wait="--wait"; shift ;;
    --) shift; break ;;
    *) echo "slurm-simulate: unknown option '$1'" >&2; usage ;;
  esac
done
[ $# -gt 0 ] && [ -n "$frames" ] && [ -n "$per" ] && [ -n "$cache" ] || usage
[[ "$frames" =~ ^([0-9]+)-([0-9]+)$ ]] || { echo "slurm-simulate: --frames FIRST-LAST, got '$frames'" >&2; exit 2; }
first="${BASH_REMATCH[1]}" last="${BASH_REMATCH[2]}"
[[ "$per" =~ ^[1-9][0-9]*$ ]] || { echo "slurm-simulate: --per-task is a whole number > 0" >&2; exit 2; }
[ "$first" -le "$last" ] || { echo "slurm-simulate: FIRST > LAST in --frames" >&2; exit 2; }
for arg in "$@"; do
  case "$arg" in --frames|--frames=*|--skip-existing|--threads|--threads=*)
    echo "slurm-simulate: give $arg to the script, not to simulate" >&2; exit 2 ;; esac
done
mkdir -p "$cache"
cache="$(cd "$cache" && pwd)"
tasks=$(( (last - first + per) / per ))
logs="${FF_FARM_LOGS:-slurm-logs}"
mkdir -p "$logs"
echo "slurm-simulate: frames $first-$last in $tasks tasks of up to $per, cache $cache, logs in $logs/"
# shellcheck disable=SC2086 # $extra holds several sbatch options
FF_FARM_FIRST="$first" FF_FARM_LAST="$last" FF_FARM_PER_TASK="$per" FF_FARM_CACHE="$cache" \
  sbatch --export=ALL --job-name=fourierflare --array="0-$((tasks - 1))" \
    --output="$logs/%A_%a.log" $extra $wait "$0" "$@"
