#!/usr/bin/env bash
# Capture throughput against rendering, side by side in one sitting (issue 14's figure): the wall
# time per frame of an N-frame capture over `siviflow bench`'s median whole-frame time for the same
# scene and size, beauty only and with every AOV (and every AOV with motion, where the build has
# it). Each round runs bench and the captures back to back; the medians over the rounds are what
# to quote (the machine is shared and noisy).
#
# usage: tools/scripts/capture_throughput.sh BUILD_DIR [WxH] [FRAMES] [ROUNDS]   (a Release build)
set -euo pipefail
build="$1" size="${2:-1280x720}" frames="${3:-30}" rounds="${4:-3}"
siviflow="$build/tools/siviflow"
export VK_DRIVER_FILES="${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}"
export LP_NUM_THREADS="${LP_NUM_THREADS:-2}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

# Wall milliseconds per frame of one capture into the emptied output folder.
capture_ms() {
  rm -f "$out"/*
  local start end
  start=$(date +%s%N)
  "$siviflow" capture --frames "$frames" --size "$size" "$@" --out "$out" > /dev/null
  end=$(date +%s%N)
  awk -v ns=$((end - start)) -v frames="$frames" 'BEGIN { printf "%.1f", ns / frames / 1e6 }'
}

# Builds with the motion AOV also capture every AOV with it (a third capture per round).
motion=0
"$siviflow" capture --help | grep -q "motion" && motion=1

rows=""
for round in $(seq "$rounds"); do
  bench=$("$siviflow" bench --size "$size" --frames "$frames" --json |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["frame_ms"])')
  beauty=$(capture_ms)
  aovs=$(capture_ms --aov depth,flow,particles,normal,reflection,foam)
  with_motion=0
  [ "$motion" = 1 ] && with_motion=$(capture_ms --aov depth,flow,particles,normal,reflection,foam,motion)
  echo "round $round: bench $bench ms, capture beauty $beauty ms, every AOV $aovs ms," \
    "with motion $with_motion ms per frame"
  rows+="$bench $beauty $aovs $with_motion"$'\n'
done
python3 - "$size" "$frames" "$motion" <<PY
import statistics, sys
rows = [list(map(float, line.split())) for line in """$rows""".strip().splitlines()]
median = lambda values: statistics.median(values)
bench = median([r[0] for r in rows])
line = (f"{sys.argv[1]}, {sys.argv[2]} frames, medians of {len(rows)} rounds: bench frame {bench:.1f} ms;"
        f" capture beauty {median([r[1] for r in rows]):.1f} ms ({median([r[1] / r[0] for r in rows]):.2f}x),"
        f" every AOV {median([r[2] for r in rows]):.1f} ms ({median([r[2] / r[0] for r in rows]):.2f}x)")
if sys.argv[3] == "1":
    line += (f", with motion {median([r[3] for r in rows]):.1f} ms"
             f" ({median([r[3] / r[0] for r in rows]):.2f}x)")
print(line)
PY
