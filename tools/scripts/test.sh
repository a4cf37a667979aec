#!/usr/bin/env bash
# Quick start, command 2: install what is missing, build, and run every test tier; then build
# again with AddressSanitizer and UndefinedBehaviorSanitizer (halting on any report) and run the
# cpu and gpu tiers under them.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bash "$root/tools/scripts/install_deps.sh"
cmake -S "$root" -B "$root/build/test" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build "$root/build/test" -j2
ctest --test-dir "$root/build/test" -j2 --output-on-failure
cmake -S "$root" -B "$root/build/sanitize" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSIVIFLOW_SANITIZE=address,undefined
cmake --build "$root/build/sanitize" -j2
ctest --test-dir "$root/build/sanitize" -j2 --output-on-failure -L "cpu|gpu"
