#!/usr/bin/env bash
# Capture throughput against rendering, side by side in one sitting (issue 14's figure): the wall
# time per frame of an N-frame capture over `siviflow bench`'s median whole-frame time for the same
# scene and size, beauty only and with every AOV.
#
# usage: tools/scripts/capture_throughput.sh BUILD_DIR [WxH] [FRAMES]   (a Release build)
set -euo pipefail
build="$1" size="${2:-1280x720}" frames="${3:-30}"
siviflow="$build/tools/siviflow"
export VK_DRIVER_FILES="${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}"
export LP_NUM_THREADS="${LP_NUM_THREADS:-2}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

frame_ms=$("$siviflow" bench --size "$size" --frames "$frames" --json |
  python3 -c 'import json, sys; print(json.load(sys.stdin)["frame_ms"])')
echo "bench: median frame $frame_ms ms at $size"
for aovs in "" "depth,flow,particles,normal,reflection,foam"; do
  rm -f "$out"/*
  start=$(date +%s.%N)
  "$siviflow" capture --frames "$frames" --size "$size" ${aovs:+--aov "$aovs"} --out "$out" > /dev/null
  end=$(date +%s.%N)
  python3 - "$start" "$end" "$frames" "$frame_ms" "${aovs:-beauty only}" <<'PY'
import sys
start, end, frames, frame_ms, what = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), sys.argv[5]
per_frame = (end - start) * 1000 / frames
print(f"capture ({what}): {per_frame:.1f} ms per frame, {per_frame / frame_ms:.2f}x the bench frame")
PY
done
