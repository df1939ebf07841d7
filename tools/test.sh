#!/usr/bin/env bash
# README command 2: build and run the whole test suite once, under AddressSanitizer + UndefinedBehaviorSanitizer
# (-O1, -Wall -Wextra -Werror), the oracle tests (rs274, the real LinuxCNC, headless Chromium) included.
# The optimised Release build is command 1's (tools/quickstart.sh); one sanitized pass of every test keeps the suite
# within a 2-core CI's budget (two passes took 25 min there).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/deps.sh
jobs=2
echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and tests"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-O1 -DCNCCOMP_SANITIZE=ON \
  -DCNCCOMP_BENCH=OFF -DCNCCOMP_UNITY=ON >/dev/null
ninja -C build-asan -j$jobs
(cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest -j$jobs --output-on-failure --timeout 900)
