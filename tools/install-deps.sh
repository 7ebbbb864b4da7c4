#!/usr/bin/env bash
# Installs, with apt-get, whatever focal needs to build and test that is missing on a Debian 12
# machine, then the browser test's npm packages (tests/browser, pinned by its package-lock.json).
# Idempotent: when everything is present it changes nothing and says so, and needs no network.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  cmake ninja-build g++ clang pkg-config
  libglm-dev libtinygltf-dev libopenimageio-dev libimath-dev
  libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev
  gnuplot-nox
  clang libclang-rt-14-dev  # the libFuzzer targets (tools/fuzz.sh)
  chromium python3          # the browser tests (tests/browser: Chromium, the page's fixture)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# Node.js and npm run the browser tests. Any node on the PATH will do (it may not come from
# Debian's package, e.g. NodeSource's nodejs, which includes npm); Debian's only when there is none.
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  missing+=(nodejs npm)
fi

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages (and node, npm) are already installed."
else
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
fi

# tests/browser's packages: `npm ci` only when node_modules does not hold exactly the versions of
# package-lock.json, so a second run (or one without network) changes nothing.
lock_matches='
  const fs = require("fs");
  const lock = JSON.parse(fs.readFileSync("package-lock.json", "utf8"));
  for (const [where, entry] of Object.entries(lock.packages)) {
    if (!where) continue;
    let installed = null;
    try { installed = JSON.parse(fs.readFileSync(where + "/package.json", "utf8")).version; } catch {}
    if (installed !== entry.version) process.exit(1);
  }'
if (cd tests/browser && node -e "$lock_matches"); then
  echo "install-deps: tests/browser/node_modules matches package-lock.json; nothing to do."
else
  echo "install-deps: npm ci in tests/browser"
  (cd tests/browser && npm ci --no-audit --no-fund)
fi
echo "install-deps: done."
