#!/usr/bin/env bash
# Rasterizer throughput (issue 3, "Measure"): ms per frame, Mtriangles/s and Mpixels/s of
# `focal render` (pinhole) for builtin:demo, builtin:dense and the ToyCar glTF (camera 0, only
# when /work/shared exists) at 800x600 and 1280x720 with 1 and 2 threads, and the same frames
# through Mesa's llvmpipe (bench/llvmpipe, when it was built) for a focal/llvmpipe ratio measured
# in the same run. Prints a Markdown table on stdout; raw JSON goes to --out.
#
# Noise control (the machine is shared): each configuration runs --rounds rounds, and every round
# runs focal and llvmpipe back to back (--repeat frames each, alternating which goes first), so
# both see the same background load; the table shows medians over all rounds x repeats frames.
# Times are render only: scene load, JIT warm-up (llvmpipe, 1 untimed frame) and image writes
# are excluded.
#
# usage: bench/raster_bench.sh [--build DIR] [--repeat K] [--rounds R] [--out DIR]
#                              [--scenes "builtin:demo ..."] [--sizes "800x600 ..."]
#                              [--threads "1 2"] [--no-llvmpipe]
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
build="$repo/build-bench"
repeat=7
rounds=3
out="${TMPDIR:-/tmp}/focal_raster_bench"
toycar=/work/shared/scenes/ToyCar/glTF/ToyCar.gltf
scenes="builtin:demo builtin:dense"
[ -d /work/shared ] && [ -f "$toycar" ] && scenes="$scenes $toycar"
sizes="800x600 1280x720"
threads="1 2"
use_llvmpipe=1

while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=$2; shift 2 ;;
    --repeat) repeat=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
    --sizes) sizes=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --no-llvmpipe) use_llvmpipe=0; shift ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) echo "raster_bench: error: unknown argument $1" >&2; exit 2 ;;
  esac
done

focal="$build/apps/focal"
lpbench="$build/bench/llvmpipe/llvmpipe_bench"
if [ ! -x "$focal" ]; then
  echo "raster_bench: error: $focal not found; build it first:" >&2
  echo "  cmake -S $repo -B $build -G Ninja -DCMAKE_BUILD_TYPE=Release && ninja -C $build focal" >&2
  exit 1
fi
if [ "$use_llvmpipe" = 1 ] && [ ! -x "$lpbench" ]; then
  echo "raster_bench: note: $lpbench not built (needs libosmesa6-dev); focal only" >&2
  use_llvmpipe=0
fi
command -v python3 >/dev/null || { echo "raster_bench: error: python3 is needed for the table" >&2; exit 1; }
mkdir -p "$out"
rm -f "$out"/*.json "$out/stderr.log"
load_before=$(cut -d' ' -f1-3 /proc/loadavg)

# One configuration id per (scene, size, threads); file names carry it.
slug() { basename "$1" | sed 's/^builtin://; s/\.gltf$//; s/\.glb$//' | tr -c 'A-Za-z0-9_\n' '_'; }

run_focal() {  # scene w h t round
  local extra=()
  case "$1" in builtin:*) ;; *) extra=(--camera 0) ;; esac
  "$focal" render "$1" -o "$out/image_focal.png" --width "$2" --height "$3" --threads "$4" \
    --repeat "$repeat" "${extra[@]}" --stats "$out/focal_$(slug "$1")_${2}x${3}_t${4}_r${5}.json" \
    >/dev/null 2>>"$out/stderr.log"
}
run_llvmpipe() {  # scene w h t round
  "$lpbench" "$1" --width "$2" --height "$3" --threads "$4" --camera 0 --repeat "$repeat" \
    >"$out/llvmpipe_$(slug "$1")_${2}x${3}_t${4}_r${5}.json" 2>>"$out/stderr.log"
}

for scene in $scenes; do
  for size in $sizes; do
    w=${size%x*}; h=${size#*x}
    for t in $threads; do
      echo "raster_bench: $scene ${w}x${h} threads=$t" >&2
      for ((r = 1; r <= rounds; ++r)); do
        if [ "$use_llvmpipe" = 1 ] && [ $((r % 2)) = 0 ]; then
          run_llvmpipe "$scene" "$w" "$h" "$t" "$r"
          run_focal "$scene" "$w" "$h" "$t" "$r"
        else
          run_focal "$scene" "$w" "$h" "$t" "$r"
          if [ "$use_llvmpipe" = 1 ]; then run_llvmpipe "$scene" "$w" "$h" "$t" "$r"; fi
        fi
      done
    done
  done
done

load_after=$(cut -d' ' -f1-3 /proc/loadavg)

python3 - "$out" "$scenes" "$sizes" "$threads" "$use_llvmpipe" "$load_before" "$load_after" <<'EOF'
import glob, json, os, re, statistics, sys
out, scenes, sizes, threads, use_lp = sys.argv[1], sys.argv[2].split(), sys.argv[3].split(), \
    sys.argv[4].split(), sys.argv[5] == "1"
load_before, load_after = sys.argv[6], sys.argv[7]

def slug(s):
    b = os.path.basename(s)
    b = re.sub(r"^builtin:", "", b)
    b = re.sub(r"\.(gltf|glb)$", "", b)
    return re.sub(r"[^A-Za-z0-9_]", "_", b)

def runs(kind, cfg):
    times, tris, extra = [], None, []
    for path in sorted(glob.glob(os.path.join(out, f"{kind}_{cfg}_r*.json"))):
        j = json.load(open(path))
        if kind == "focal":
            times += [r["total"] for r in j["runs"]]
            tris = j["triangles"]["in"]
        else:
            times += j["runs"]
            tris = j["triangles"]
            extra.append(j.get("cores_busy", 0.0))
    return times, tris, extra

name = {"demo": "builtin:demo", "dense": "builtin:dense", "ToyCar": "ToyCar (camera 0)"}
head = "| scene | size | threads | focal ms | focal Mtri/s | focal Mpix/s |"
rule = "| --- | --- | ---: | ---: | ---: | ---: |"
if use_lp:
    head += " llvmpipe ms | llvmpipe Mtri/s | llvmpipe Mpix/s | focal / llvmpipe time |"
    rule += " ---: | ---: | ---: | ---: |"
print(head)
print(rule)
for scene in scenes:
    for size in sizes:
        w, h = map(int, size.split("x"))
        for t in threads:
            cfg = f"{slug(scene)}_{size}_t{t}"
            ft, tris, _ = runs("focal", cfg)
            if not ft:
                continue
            fm = statistics.median(ft)
            row = (f"| {name.get(slug(scene), scene)} | {size} | {t} | {fm:.1f} | "
                   f"{tris / fm / 1e3:.2f} | {w * h / fm / 1e3:.1f} |")
            if use_lp:
                lt, ltris, _ = runs("llvmpipe", cfg)
                if lt:
                    lm = statistics.median(lt)
                    row += (f" {lm:.1f} | {ltris / lm / 1e3:.2f} | {w * h / lm / 1e3:.1f} |"
                             f" {fm / lm:.2f} |")
                else:
                    row += " – | – | – | – |"
            print(row)
print(f"\nmedians over {len(ft)} frames per cell; triangles = triangles submitted "
      f"(focal stats triangles.in); load average before {load_before}, after {load_after}; "
      f"raw JSON in {out}")
EOF
