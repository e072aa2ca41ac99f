#!/usr/bin/env bash
# Quick start, first command: install what is missing, build in Release, run the main job.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh release
echo
echo "== fourierflare lens info lenses/double-gauss-50mm-f2.lens"
build/release/src/cli/fourierflare lens info lenses/double-gauss-50mm-f2.lens
