#!/usr/bin/env bash
# Builds the Debian package of FourierFlare from the Release build (building it first when absent):
#   scripts/package.sh [OUT_DIR]   -> OUT_DIR/fourierflare_<version>_<arch>.deb (default: build/package)
# Its dependencies are computed by dpkg-shlibdeps (dpkg-dev) from what the binary and the Python module
# link. Install with: sudo apt install ./build/package/fourierflare_*.deb
set -euo pipefail
cd "$(dirname "$0")/.."
out="$(mkdir -p "${1:-build/package}" && cd "${1:-build/package}" && pwd)"
[ -f build/release/CMakeCache.txt ] || scripts/build.sh release
cmake --build build/release -j "$(nproc 2>/dev/null || echo 2)"
(cd build/release && cpack -G DEB -B "$out")
ls "$out"/fourierflare_*.deb
