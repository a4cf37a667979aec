#!/usr/bin/env bash
# A farm capture on Slurm: a job array with one task per CHUNK frames of FIRST..END-1 (each task
# renders its chunk with --resume), and a last job, run once every task has succeeded, that
# verifies the folder with `siviflow verify`. Prints the two job ids. OUT is created where it is
# missing: the tasks' logs go into it.
#
# usage: submit_slurm.sh FIRST END CHUNK OUT [capture options, e.g. SCENE.json --size WxH]
# Extra sbatch options (partition, account, time limit) in SBATCH_OPTIONS; the siviflow binary
# is $SIVIFLOW, or `siviflow` on the PATH of the nodes.
set -euo pipefail
script=submit_slurm
farm="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
source "$farm/chunking.sh"

[ "$#" -ge 4 ] || farm_fail "usage: submit_slurm.sh FIRST END CHUNK OUT [capture options]"
check_chunking "$1" "$2" "$3"
out="$4"
shift 4
mkdir -p -- "$out" || farm_fail "cannot create the output folder '$out'"
out="$(cd "$out" && pwd)"
logs="$out/slurm-logs"  # the tasks' output; verify reads only frame files
mkdir -p "$logs"

export SIVIFLOW_FARM="$farm"
# shellcheck disable=SC2086  # SBATCH_OPTIONS is a list of options
array=$(sbatch --parsable ${SBATCH_OPTIONS:-} --array="0-$((shards - 1))" \
  --output="$logs/capture-%A_%a.log" "$farm/slurm_capture.sbatch" "$first" "$end" "$chunk" "$out" "$@")
array="${array%%;*}"
verify_command=$(printf '%q ' "${SIVIFLOW:-siviflow}" verify "$out" --range "$first:$end")
# shellcheck disable=SC2086
verify=$(sbatch --parsable ${SBATCH_OPTIONS:-} --job-name=siviflow-verify \
  --dependency="afterok:$array" --output="$logs/verify-%j.log" --wrap "$verify_command")
echo "capture array job $array ($shards tasks), verify job ${verify%%;*}"
