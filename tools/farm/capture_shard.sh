#!/usr/bin/env bash
# One shard of a farm capture: the INDEX-th chunk of CHUNK frames of the range FIRST..END-1,
# rendered with --resume into OUT (a re-run task renders only what its last attempt left
# missing or incomplete). Run by the Slurm array task (slurm_capture.sbatch, INDEX from
# SLURM_ARRAY_TASK_ID) and the Kubernetes Indexed Job (INDEX from JOB_COMPLETION_INDEX). OUT is
# created first where it is missing (a fresh volume has none; `capture` writes only into a folder).
#
# usage: capture_shard.sh INDEX FIRST END CHUNK OUT [capture options, e.g. SCENE.json --size WxH]
# The siviflow binary is $SIVIFLOW, or `siviflow` on the PATH.
set -euo pipefail
script=capture_shard
source "$(dirname "${BASH_SOURCE[0]}")/chunking.sh"

[ "$#" -ge 5 ] || farm_fail "usage: capture_shard.sh INDEX FIRST END CHUNK OUT [capture options]"
index="$1" out="$5"
[[ "$index" =~ ^[0-9]+$ ]] && [ "${#index}" -le 9 ] ||
  farm_fail "INDEX must be a whole number, not '$index'"
index=$((10#$index))
check_chunking "$2" "$3" "$4"
shift 5
[ "$index" -lt "$shards" ] || farm_fail "INDEX $index is past the last of the $shards chunks"

from=$((first + index * chunk))
mkdir -p -- "$out" || farm_fail "cannot create the output folder '$out'"
exec "${SIVIFLOW:-siviflow}" capture --range "$from:$((from + chunk))" --out "$out" --resume "$@"
