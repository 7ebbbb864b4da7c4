#!/usr/bin/env bash
# Builds the libFuzzer targets (the `fuzz` preset: clang, ASan + UBSan) and runs each one for
# SECONDS (default 60) from its seed corpus; exits non-zero on the first crash, leak, sanitizer
# report, timeout or out-of-memory, leaving the input in build/fuzz/artifacts/.
#   tools/fuzz.sh            # what CI runs: 60 s per target
#   tools/fuzz.sh 14400      # four hours per target
#   tools/fuzz.sh 600 cli    # one target
# New inputs go to build/fuzz/corpus-TARGET (the seeds in tests/fuzz/corpus stay untouched);
# a crash that gets fixed has its input copied into tests/fuzz/corpus/TARGET as a regression.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(gltf_import cli)

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz --target "${targets[@]/#/focal_fuzz_}" -- -j"$(nproc)"

out=build/fuzz
mkdir -p "$out/artifacts"
for t in "${targets[@]}"; do
  seeds=(tests/fuzz/corpus/"$t")
  extra=()
  case "$t" in
    gltf_import) seeds+=(tests/data/gltf/valid tests/data/gltf/bad) ;;
    # runCli prints help and errors: keep the fuzzer's own output readable.
    cli) extra+=(-close_fd_mask=3) ;;
  esac
  mkdir -p "$out/corpus-$t"
  echo "fuzz: $t for ${seconds}s"
  # -rss_limit_mb: an input that makes focal take more than 2 GiB is a bug (the importer's budget
  # in the target is 512 MiB). -timeout: one input may not take more than 30 s.
  if ! (cd "$out" && "tests/fuzz/focal_fuzz_$t" -max_total_time="$seconds" -timeout=30 \
      -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="artifacts/$t-" "${extra[@]}" \
      "corpus-$t" "${seeds[@]/#/../../}") 2>&1 | tail -n 12; then
    echo "fuzz: $t failed; see $out/artifacts" >&2
    exit 1
  fi
done
echo "fuzz: no crash"
