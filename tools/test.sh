#!/usr/bin/env bash
# README command (b): install what is missing, build, and run the whole test suite:
# the Release build (every test: quick, full, golden and stress tiers; warnings as errors), the
# ASan+UBSan build (quick tier), a clang++ Release build of focal and the golden tests (which must
# match the same goldens as g++), ThreadSanitizer on the pinhole determinism sweeps, and each
# libFuzzer target for 60 s (docs/testing.md, "What runs where").
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install-deps.sh
jobs=$(nproc)
cmake --preset release >/dev/null
cmake --build --preset release -- -j"$jobs"
ctest --preset release -j"$jobs"
cmake --preset asan-ubsan >/dev/null
cmake --build --preset asan-ubsan --target focal focal_unit_tests -- -j"$jobs"
ctest --preset asan-ubsan -j"$jobs" -L quick
cmake --preset clang-release >/dev/null
cmake --build --preset clang-release -- -j"$jobs"   # the preset's targets: focal, focal_golden_tests
ctest --preset clang-release -j"$jobs"              # the preset's filter: label golden
cmake --preset tsan >/dev/null
cmake --build --preset tsan --target focal focal_golden_tests -- -j"$jobs"
TSAN_OPTIONS="halt_on_error=1" ctest --preset tsan -j"$jobs" --no-tests=error -R '^Scenes/Determinism\.'
tools/fuzz.sh 60
echo "test: all suites passed"
