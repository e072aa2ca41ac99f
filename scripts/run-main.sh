#!/usr/bin/env bash
# Quick start, first command: install what is missing, build in Release, run the main job: the
# bundled double Gauss against the bundled night-street plate, writing out/night-street.exr (the
# plate's channels + flare.* + composite.*) and out/night-street.png (the composite).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh --main   # only what the command needs; scripts/run-tests.sh installs the rest
scripts/build.sh main            # only the command (and its man page): no tests, benchmarks or module
mkdir -p out
echo
echo "== fourierflare simulate --lens lenses/double-gauss-50mm-f2.lens --plate data/night-street.exr -o out/night-street.exr --preview out/night-street.png"
build/release/src/cli/fourierflare simulate --lens lenses/double-gauss-50mm-f2.lens --plate data/night-street.exr \
    -o out/night-street.exr --preview out/night-street.png --preview-flare out/night-street-flare.png
