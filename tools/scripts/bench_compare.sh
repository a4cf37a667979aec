#!/usr/bin/env bash
# Wall time per frame of `siviflow bench`, two or more builds side by side in one sitting:
#   tools/scripts/bench_compare.sh ROUNDS SIZE FRAMES NAME=BINARY NAME=BINARY ...
# Each round runs every binary for 10 and for FRAMES frames (after 5 warm-up frames, one at a
# time), alternating the binaries; a sample is (T(FRAMES) - T(10)) / (FRAMES - 10), so start-up
# and the flow solve cancel out. Prints every sample and each binary's median. Lavapipe with 2
# threads, as CI renders.
set -euo pipefail
if [ $# -lt 4 ]; then
  echo "usage: $0 ROUNDS SIZE FRAMES NAME=BINARY [NAME=BINARY ...]" >&2
  exit 1
fi
rounds=$1 size=$2 frames=$3
shift 3
if [ "$frames" -le 10 ]; then
  echo "$0: FRAMES must be more than 10 (the short run's)" >&2
  exit 1
fi
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}
export LP_NUM_THREADS=${LP_NUM_THREADS:-2}
nanoseconds() {
  local start
  start=$(date +%s%N)
  "$@" > /dev/null
  echo $(($(date +%s%N) - start))
}
samples=$(mktemp)
trap 'rm -f "$samples"' EXIT
for _ in $(seq "$rounds"); do
  for pair in "$@"; do
    name=${pair%%=*} binary=${pair#*=}
    short=$(nanoseconds "$binary" bench --size "$size" --frames 10 --warmup 5)
    long=$(nanoseconds "$binary" bench --size "$size" --frames "$frames" --warmup 5)
    awk -v n="$name" -v d=$((long - short)) -v f="$frames" \
        'BEGIN {printf "%s %.2f\n", n, d / 1e6 / (f - 10)}' | tee -a "$samples"
  done
done
for pair in "$@"; do
  name=${pair%%=*}
  grep "^$name " "$samples" | awk '{print $2}' | sort -g |
    awk -v n="$name" '{v[NR]=$1} END {m = NR % 2 ? v[(NR+1)/2] : (v[NR/2] + v[NR/2+1]) / 2;
                                      printf "%s median %.1f ms per frame (%d samples)\n", n, m, NR}'
done
