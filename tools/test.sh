#!/usr/bin/env bash
# README command 2: build and run the whole test suite, then once more under AddressSanitizer + UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/deps.sh
jobs=2
echo "== Release build (-Wall -Wextra -Werror) and tests"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCNCCOMP_UNITY=ON >/dev/null
ninja -C build -j$jobs
(cd build && ctest -j$jobs --output-on-failure --timeout 600)
echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and tests"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-O1 -DCNCCOMP_SANITIZE=ON -DCNCCOMP_BENCH=OFF -DCNCCOMP_UNITY=ON >/dev/null
ninja -C build-asan -j$jobs
(cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest -j$jobs --output-on-failure --timeout 900)
