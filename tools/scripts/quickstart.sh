#!/usr/bin/env bash
# Quick start, command 1: install what is missing, build Release, render the default scene.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bash "$root/tools/scripts/install_deps.sh"
cmake -S "$root" -B "$root/build/release" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$root/build/release" -j2
out="$root/out/default_scene"
mkdir -p "$out"
# --force: over the frames an earlier build or run left there, whatever made them.
"$root/build/release/tools/siviflow" capture --frames 3 --size 1280x720 --aov depth --preview --force \
  --out "$out"
echo "EXR frames and PNG previews: $out"
ls -1 "$out"
