#!/usr/bin/env bash
# Quick start, command 2: install what is missing, build, and run every test tier; then build
# again with AddressSanitizer and UndefinedBehaviorSanitizer (halting on any report) and run the
# cpu and gpu tiers under them; then the thread tier under ThreadSanitizer; last, build the
# libFuzzer targets with clang and run each for 30 s.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bash "$root/tools/scripts/install_deps.sh"
cmake -S "$root" -B "$root/build/test" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build "$root/build/test" -j2
ctest --test-dir "$root/build/test" -j2 --output-on-failure
# The sanitizer builds compile at -O1 with line tables only: half the time of -O2 -g, and their
# reports still name the file and line.
checked=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG")
# The mutation test's 400 mutants run in the plain build; under the sanitizers a sample of them.
cmake -S "$root" -B "$root/build/sanitize" -G Ninja "${checked[@]}" \
  -DSIVIFLOW_SANITIZE=address,undefined -DSIVIFLOW_MUTANTS=120
cmake --build "$root/build/sanitize" -j2
ctest --test-dir "$root/build/sanitize" -j2 --output-on-failure -L "cpu|gpu"
cmake -S "$root" -B "$root/build/thread" -G Ninja "${checked[@]}" -DSIVIFLOW_SANITIZE=thread
cmake --build "$root/build/thread" -j2 --target thread_handoff_test
ctest --test-dir "$root/build/thread" -j2 --output-on-failure -L thread
cmake -S "$root" -B "$root/build/fuzz" -G Ninja "${checked[@]}" \
  -DCMAKE_CXX_COMPILER=clang++-15 -DSIVIFLOW_FUZZ=ON -DSIVIFLOW_BUILD_TOOLS=OFF \
  -DSIVIFLOW_BUILD_TESTS=OFF
cmake --build "$root/build/fuzz" -j2
ctest --test-dir "$root/build/fuzz" -j2 --output-on-failure -L fuzz
