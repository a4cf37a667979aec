#!/usr/bin/env bash
# Re-renders the golden frames of tests/golden from a build (default build/test). Run it only
# when a change to the picture is intended, look at the PNGs it writes, and commit the EXRs.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build/test}"
work="$(mktemp -d)"
for frame in 0 75 240; do
  "$build/tools/siviflow" capture --range "$frame:$((frame + 1))" --size 320x180 \
    --aov depth,flow --validation --preview --out "$work"
done
cp "$work"/frame_*.exr "$root/tests/golden/"
echo "goldens updated; previews to look at: $work"
