#!/usr/bin/env bash
# One shard of a farm capture: the INDEX-th chunk of CHUNK frames of the range FIRST..END-1,
# rendered with --resume into OUT (a re-run task renders only what its last attempt left
# missing or incomplete). Used by the Slurm array task (INDEX from SLURM_ARRAY_TASK_ID) and the
# Kubernetes Indexed Job (INDEX from JOB_COMPLETION_INDEX).
#
# usage: capture_shard.sh INDEX FIRST END CHUNK OUT [capture options, e.g. SCENE.json --size WxH]
# The siviflow binary is $SIVIFLOW, or `siviflow` on the PATH.
set -euo pipefail

fail() {
  echo "capture_shard: $*" >&2
  exit 1
}
is_count() { [[ "$1" =~ ^[0-9]+$ ]] && [ "${#1}" -le 9 ]; }

[ "$#" -ge 5 ] || fail "usage: capture_shard.sh INDEX FIRST END CHUNK OUT [capture options]"
index="$1" first="$2" end="$3" chunk="$4" out="$5"
shift 5
for name in index first end chunk; do
  is_count "${!name}" || fail "${name^^} must be a whole number, not '${!name}'"
done
index=$((10#$index)) first=$((10#$first)) end=$((10#$end)) chunk=$((10#$chunk))
[ "$chunk" -gt 0 ] || fail "CHUNK must be at least 1 frame"
[ "$end" -gt "$first" ] || fail "the range $first..$end is empty (END must be above FIRST)"
frames=$((end - first))
[ $((frames % chunk)) -eq 0 ] ||
  fail "the range's $frames frames do not divide into chunks of $chunk (choose a divisor of $frames)"
shards=$((frames / chunk))
[ "$index" -lt "$shards" ] || fail "INDEX $index is past the last of the $shards chunks"

from=$((first + index * chunk))
exec "${SIVIFLOW:-siviflow}" capture --range "$from:$((from + chunk))" --out "$out" --resume "$@"
