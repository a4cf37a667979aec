#!/usr/bin/env bash
# Quick start, command 2: install what is missing, build, and run every test tier.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bash "$root/tools/scripts/install_deps.sh"
cmake -S "$root" -B "$root/build/test" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build "$root/build/test" -j2
ctest --test-dir "$root/build/test" -j2 --output-on-failure
