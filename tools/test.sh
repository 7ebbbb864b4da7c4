#!/usr/bin/env bash
# README command (b): install what is missing, build, and run the whole test suite:
# the Release build (every test: quick, full, golden and stress tiers; warnings as errors), the
# installed package in projects outside the tree (tools/package-check.sh), the ASan+UBSan build
# (quick tier, with the allocation and fault-injection tests), a clang++ Release build of focal and the golden tests (which must match the same
# goldens as g++), ThreadSanitizer on the pinhole determinism sweeps, each libFuzzer target
# for 60 s, and the stage-stepper page in Debian's Chromium (label browser; docs/testing.md,
# "What runs where"). Each step prints its wall time, so a slow CI run shows where the time went.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
step() { # NAME COMMAND...: run it, then print how long it took
  local name=$1 t0=$SECONDS
  shift
  "$@"
  echo "test: $name: $((SECONDS - t0)) s (total $((SECONDS - start)) s)"
}
jobs=$(nproc)
step "install" tools/install-deps.sh
cmake --preset release >/dev/null
step "release build" cmake --build --preset release -- -j"$jobs"
# Every tier but browser, which has its own step below (so its time shows on its own line).
step "release tests" ctest --preset release -j"$jobs" -LE browser
# The steps page (tests/browser) with the release build's focal, in /usr/bin/chromium driven by
# playwright-core; one test at a time (each starts its own browser).
step "browser tests" ctest --preset release --no-tests=error -L browser
# The installed package in projects outside the tree: a library-only build (no OpenImageIO)
# with examples/embed, and the release build's install with examples/golden-installed.
step "package" tools/package-check.sh
cmake --preset asan-ubsan >/dev/null
step "asan-ubsan build" cmake --build --preset asan-ubsan \
  --target focal focal_unit_tests focal_alloc_tests -- -j"$jobs"
# The allocation tests' fault injection tries 40 values of K per method here (150 in Release).
step "asan-ubsan quick tier" env FOCAL_FAULT_TRIALS=40 ctest --preset asan-ubsan -j"$jobs" -L quick
cmake --preset clang-release >/dev/null
# The preset's targets: focal, focal_golden_tests; its test filter: label golden.
step "clang build" cmake --build --preset clang-release -- -j"$jobs"
step "clang golden tier" ctest --preset clang-release -j"$jobs"
cmake --preset tsan >/dev/null
step "tsan build" cmake --build --preset tsan --target focal focal_golden_tests -- -j"$jobs"
step "tsan determinism" env TSAN_OPTIONS="halt_on_error=1" \
  ctest --preset tsan -j"$jobs" --no-tests=error -R '^Scenes/Determinism\.'
step "fuzz build and run" tools/fuzz.sh 60
echo "test: all suites passed in $((SECONDS - start)) s"
