#!/usr/bin/env bash
# README command (a): install what is missing, build Release, render the demo scene with depth
# of field to out/demo.png (8-bit sRGB) and out/demo.exr (linear float), and print where.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target focal -- -j"$(nproc)"
mkdir -p out
focal=build/release/apps/focal
# The accumulation reference (the thin-lens integral, docs/dof/accum.md) with 256 lens samples and
# anti-aliasing: the most accurate depth of field focal renders. Faster methods: --method
# multilayer, multiview or gather (docs/benchmarks.md compares them).
"$focal" render builtin:demo --method accum --samples 256 --pixel-jitter \
    -o out/demo.exr -o out/demo.png --stats out/demo.json
echo "demo: images in $(pwd)/out/demo.png and $(pwd)/out/demo.exr (stats in out/demo.json)"
