#!/usr/bin/env bash
# The pictures of docs/diffraction.md: the bundled double Gauss with its iris given 6 or 9 blades and
# stopped down, one light of flux 10^4 at the centre of a 256 x 256 crop of a 1080p sensor (pitch
# 18.75 um), through `render --mode diffraction`. Usage: scripts/docs-diffraction.sh [build dir]
set -euo pipefail
cd "$(dirname "$0")/.."
ff="${1:-build/release}/src/cli/fourierflare"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
variant() { # blades f-number rotation -> a lens file
    sed "s/^sensor: 36x24/sensor: 36x24\naperture_blades: $1\nblade_rotation: $3\nf_number: $2/" \
        lenses/double-gauss-50mm-f2.lens > "$tmp/dg-$1-f$2.lens"
    echo "$tmp/dg-$1-f$2.lens"
}
shot() { # lens out.png
    "$ff" render "$1" --mode diffraction --light 128,128,10000,10000,10000 --size 256x256 --sensor-size 4.8x4.8 \
        --exposure -1 -o "$tmp/out.exr" --preview "$2"
}
shot "$(variant 6 11 0)" docs/images/diffraction-6-blades-f11.png
shot "$(variant 9 11 0)" docs/images/diffraction-9-blades-f11.png
shot "$(variant 6 2.8 0)" docs/images/diffraction-6-blades-f2.8.png
shot "$(variant 7 16 15)" docs/images/diffraction-7-blades-f16.png
