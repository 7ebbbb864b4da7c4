#!/usr/bin/env bash
# The installed package works in a project outside focal's tree (docs/embedding.md). Two parts:
#
# (a) Library only: configure the `library` preset (FOCAL_BUILD_APPS=OFF) with OpenImageIO,
#     CLI11, nlohmann_json and pkg-config made unfindable, build it, install it into a fresh
#     prefix. Build examples/embed against that prefix in its own build tree (find_package) and
#     once more with `pkg-config focal`; its checksum must be the multilayer_demo line of
#     tests/golden/dof/hashes.txt (the same render as that golden), at 0, 2 and 3 threads.
# (b) With the program: install the release build into another prefix; the installed `focal`
#     renders the same checksum; examples/golden-installed's golden test passes against the
#     installed program, and the installed check fails against a wrong golden and stores the
#     right one with the update switch (examples/golden/check_can_fail.cmake).
#
# Needs the release preset configured (tools/test.sh builds it first); it builds the `focal`
# target there, a no-op when it is up to date. Work and install folders: build/package-check.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
jobs=$(nproc)
release=build/release
library=build/library
work=$root/build/package-check
start=$SECONDS

fail() {
  echo "package-check: FAILED: $*" >&2
  exit 1
}
note() { echo "package-check: $* ($((SECONDS - start)) s)"; }
run() { # LOG COMMAND...: run it with its output in $work/LOG, shown only when it fails
  local log=$work/$1
  shift
  "$@" >"$log" 2>&1 || {
    tail -60 "$log"
    fail "$* (log: $log)"
  }
}

expected=$(awk '$1 == "multilayer_demo" { print $2 }' tests/golden/dof/hashes.txt)
[ -n "$expected" ] || fail "no multilayer_demo line in tests/golden/dof/hashes.txt"
rm -rf "$work"
mkdir -p "$work"

# --- (a) the library alone -------------------------------------------------------------------
# From a fresh cache (objects are reused) so that nothing found by an earlier configure counts.
rm -f "$library/CMakeCache.txt"
run library-configure.log cmake --preset library --no-warn-unused-cli \
  -DCMAKE_DISABLE_FIND_PACKAGE_OpenImageIO=ON -DCMAKE_DISABLE_FIND_PACKAGE_PkgConfig=ON \
  -DCMAKE_DISABLE_FIND_PACKAGE_CLI11=ON -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON
# Nothing of the apps' dependencies in the cache (the option's help text and the switches above
# aside) or the build.
if grep -vE '^//|^CMAKE_DISABLE_FIND_PACKAGE_' "$library/CMakeCache.txt" |
  grep -iE 'openimageio|cli11|nlohmann'; then
  fail "the library-only configure looked for the apps' dependencies (above)"
fi
if grep -qi openimageio "$library/build.ninja"; then
  fail "the library-only build mentions OpenImageIO ($library/build.ninja)"
fi
run library-build.log cmake --build --preset library -- -j"$jobs"
run library-install.log cmake --install "$library" --prefix "$work/prefix-lib"
note "library-only configure, build, install"
if [ -e "$work/prefix-lib/bin" ] || [ -e "$work/prefix-lib/lib/cmake/focal/FocalGolden.cmake" ]; then
  fail "a library-only install holds the program or its CMake function"
fi
for f in lib/libfocal_raster.a lib/libfocal_dof.a lib/libfocal_scenes.a include/dof/multilayer.h \
  include/scenes/builtin.h lib/cmake/focal/focalConfig.cmake \
  lib/cmake/focal/focalConfigVersion.cmake lib/pkgconfig/focal.pc; do
  [ -f "$work/prefix-lib/$f" ] || fail "the install has no $f"
done
# The package must not point back into this tree (a consumer may never see it) or at OpenImageIO.
if grep -rE "$root|OpenImageIO" "$work/prefix-lib/lib/cmake" "$work/prefix-lib/lib/pkgconfig"; then
  fail "the installed package names the source tree or OpenImageIO (above)"
fi

check_sum() { # PROGRAM...: runs it, its checksum must be the golden's
  local out
  out=$("$@") || fail "$* failed"
  [ "${out%% *}" = "$expected" ] || fail "$*: printed '$out', expected $expected (multilayer_demo)"
}
run embed-configure.log cmake -S examples/embed -B "$work/embed" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$work/prefix-lib" \
  -DCMAKE_CXX_FLAGS="-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Werror"
run embed-build.log cmake --build "$work/embed"
# Its include paths: the prefix and the system's, none into focal's source tree.
include_paths=$(grep -E '^ +INCLUDES = ' "$work/embed/build.ninja" | tr ' ' '\n' | grep '^/' || true)
if grep -F "$root" <<<"$include_paths" | grep -vF "$work/"; then
  fail "examples/embed compiles with focal's source tree on its include path (above)"
fi
grep -qF "$work/prefix-lib/include" <<<"$include_paths" ||
  fail "examples/embed does not take focal's headers from the install"
for threads in 0 2 3; do
  check_sum "$work/embed/focal_embed" $threads
done
# The same program through pkg-config, without CMake.
# shellcheck disable=SC2046 # the flags are meant to be split
run embed-pkgconfig.log c++ -std=c++20 -O2 examples/embed/main.cpp -o "$work/focal_embed_pkgconfig" \
  $(PKG_CONFIG_PATH="$work/prefix-lib/lib/pkgconfig" pkg-config --cflags --libs focal)
check_sum "$work/focal_embed_pkgconfig"
note "examples/embed against the installed library (CMake and pkg-config): $expected"

# --- (b) the package with the focal program --------------------------------------------------
[ -f "$release/CMakeCache.txt" ] || fail "configure and build the release preset first"
run release-build.log cmake --build "$release" --target focal -- -j"$jobs"
run release-install.log cmake --install "$release" --prefix "$work/prefix"
focal=$work/prefix/bin/focal
run demo-render.log "$focal" render builtin:demo --width 160 --height 120 --method multilayer \
  -o "$work/demo.exr"
"$focal" hash "$work/demo.exr" --expect "$expected" >/dev/null ||
  fail "the installed focal's multilayer render of builtin:demo does not hash to $expected"

run golden-installed-configure.log cmake -S examples/golden-installed \
  -B "$work/golden-installed" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix"
config=$work/golden-installed/focal-golden/installed_two_planes_multilayer.cmake
grep -qF "$focal" "$config" || fail "the golden test does not run the installed focal ($config)"
run golden-installed-test.log env -u FOCAL_UPDATE_GOLDENS ctest \
  --test-dir "$work/golden-installed" --output-on-failure --no-tests=error
# The installed check fails against a wrong golden and stores the right one when told to.
run golden-selftest.log cmake -DCONFIG="$config" \
  -DCHECK="$work/prefix/lib/cmake/focal/FocalGoldenCheck.cmake" \
  -DWRONG_PNG="$root/examples/golden/goldens/example_two_planes.png" \
  -DSCRATCH="$work/golden-selftest" -P examples/golden/check_can_fail.cmake
note "installed focal and focal_add_golden_test (examples/golden-installed)"
echo "package-check: passed in $((SECONDS - start)) s"
