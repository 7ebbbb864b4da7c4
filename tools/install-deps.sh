#!/usr/bin/env bash
# Installs, with apt-get, whatever focal needs to build and test that is missing on a Debian 12
# machine. Idempotent: when everything is present it changes nothing and says so.
set -euo pipefail

packages=(
  cmake ninja-build g++ clang pkg-config
  libglm-dev libtinygltf-dev libopenimageio-dev libimath-dev
  libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev
  gnuplot-nox
  clang libclang-rt-14-dev  # the libFuzzer targets (tools/fuzz.sh)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} dependencies are already installed; nothing to do."
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo="sudo"
  else
    echo "install-deps: error: not root and no sudo; install as root: apt-get install ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install-deps: done."
