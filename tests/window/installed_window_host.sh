#!/usr/bin/env bash
# The installed window_host example (built by installed_package_embeds against the installed
# package) in a real window: an Xvfb server of its own on a display it picks (-displayfd, no TCP),
# 30 frames presented through a swapchain, the engine's reflection callback drawing every frame's
# reflection, under the validation layer; the server is stopped whatever happens.
# usage: installed_window_host.sh WINDOW_HOST_BINARY WORK_DIR
set -euo pipefail
binary="$1" work="$2"
[ -x "$binary" ] || { echo "no installed window_host at $binary (installed_package_embeds builds it)"; exit 1; }
command -v Xvfb > /dev/null ||
  { echo "Xvfb is missing (package xvfb, installed by tools/scripts/install_deps.sh)"; exit 1; }
mkdir -p "$work"
display_file="$work/display"
: > "$display_file"
Xvfb -displayfd 3 -nolisten tcp -screen 0 1024x768x24 3> "$display_file" 2> "$work/xvfb.log" &
xvfb=$!
trap 'kill "$xvfb" 2> /dev/null; wait "$xvfb" 2> /dev/null || true' EXIT
for _ in $(seq 100); do
  [ -s "$display_file" ] && break
  kill -0 "$xvfb" 2> /dev/null || { echo "Xvfb exited: $(cat "$work/xvfb.log")"; exit 1; }
  sleep 0.1
done
[ -s "$display_file" ] || { echo "Xvfb did not say its display within 10 s"; exit 1; }
output=$(DISPLAY=":$(head -n1 "$display_file")" WAYLAND_DISPLAY= "$binary" --frames 30 2>&1) || {
  echo "window_host failed: $output"
  exit 1
}
echo "$output"
grep -q "^30 frames presented, 30 reflections drawn by the engine" <<< "$output" ||
  { echo "window_host did not present 30 frames with 30 reflections"; exit 1; }
grep -q "validation on, errors 0" <<< "$output" ||
  { echo "window_host ran without the validation layer, or with errors"; exit 1; }
