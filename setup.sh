#!/usr/bin/env bash
# Installs brickworld's build dependencies from Debian 12 packages, only what is missing.
# Does nothing (and needs no network) when everything is already installed.
set -euo pipefail
packages=(
  g++ cmake ninja-build make git
  clang                # the determinism check: a clang build gives GCC's state hashes
  libclang-rt-14-dev   # libFuzzer and the sanitizer runtimes for clang (the fuzz preset)
  libeigen3-dev        # Eigen 3.4: math types
  libbullet-dev        # Bullet 3.24: narrowphase primitives and the baseline
  libtbb-dev           # oneTBB 2021: jobs
  libgtest-dev         # GoogleTest
  libbenchmark-dev     # Google Benchmark
  libcli11-dev         # CLI11: the brickworld CLI
  nlohmann-json3-dev   # scene files, JSON output
  zlib1g-dev           # .brs save sections
  python3              # plot scripts read CSV (matplotlib is optional); the browser test
  libjs-three          # three.js r111: inlined into `brickworld view` pages
  chromium-headless-shell  # the replay page's test (tests/recording/browser_check.py)
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup.sh: all dependencies present"
  exit 0
fi
echo "setup.sh: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
