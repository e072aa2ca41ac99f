#!/usr/bin/env bash
# The far field's and the dirt's pictures in docs/diffraction.md and the README (needs only oiiotool
# and Python's standard library): a street lamp (3 x 3 pixels of 5e4 on a 960 x 540 plate of 0.01,
# a 36 mm sensor) through the bundled double Gauss given 6 blades at f/8 and at f/16; the same lamp
# through procedural dirt; the spike's profile against edge diffraction's 1/r^2 law (log-log); the
# night-street plate's sun with 6 blades at f/8. Usage: scripts/docs-far-field.sh [build dir]
set -euo pipefail
cd "$(dirname "$0")/.."
ff="${1:-build/release}/src/cli/fourierflare"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
variant() { # blades f-number -> a lens file
    sed "s/^sensor: 36x24/sensor: 36x24\naperture_blades: $1\nblade_rotation: 0\nf_number: $2/" \
        lenses/double-gauss-50mm-f2.lens > "$tmp/dg-$1-f$2.lens"
    echo "$tmp/dg-$1-f$2.lens"
}
oiiotool --pattern constant:color=0.01,0.01,0.01 960x540 3 -d float -o "$tmp/bg.exr"
oiiotool --pattern constant:color=50000,50000,50000 3x3 3 -d float -o "$tmp/spot.exr"
oiiotool "$tmp/spot.exr" "$tmp/bg.exr" --paste +479+269 -d float -o "$tmp/lamp.exr"
for n in 8 16; do
    "$ff" simulate --lens "$(variant 6 $n)" --plate "$tmp/lamp.exr" -o "$tmp/lamp-f$n.exr" \
        --preview "docs/images/far-field-lamp-f$n.png" > /dev/null
done
# Dirt: the diffraction layer around the lamp, clean and through --dirt 7,3, 160 x 160 pixels
# graded 2 stops up (x 4), enlarged twice.
"$ff" simulate --lens "$(variant 6 8)" --plate "$tmp/lamp.exr" -o "$tmp/dirty.exr" --dirt 7,3 > /dev/null
for f in lamp-f8 dirty; do
    oiiotool "$tmp/$f.exr" --ch diffraction.R,diffraction.G,diffraction.B --chnames R,G,B --cut 160x160+400+190 \
        --clamp:min=0 --mulc 4 --clamp:max=1 --powc 0.4545 --resize:filter=box 320x320 -d uint8 -o "$tmp/$f-crop.png"
done
oiiotool "$tmp/lamp-f8-crop.png" "$tmp/dirty-crop.png" --mosaic:pad=8 2x1 -o docs/images/far-field-dirt.png
# The profile along the spike that runs up from the lamp (render: the diffraction alone, the light's
# 4.5e5 of flux in one pixel), 7 columns across, 270 rows up.
for n in 8 16; do
    "$ff" render "$(variant 6 $n)" --mode diffraction --light 480.5,270.5,450000,450000,450000 --size 960x540 \
        --sensor-size 36x20.25 -o "$tmp/spike-f$n.exr" > /dev/null
    oiiotool "$tmp/spike-f$n.exr" --ch G --cut 7x271+477+0 -o "$tmp/band-f$n.exr"
    oiiotool --dumpdata "$tmp/band-f$n.exr" > "$tmp/band-f$n.txt"
done
python3 scripts/far-field-profile.py docs/images/far-field-profile.svg 0.0375 450000 \
    "f/8=8=$tmp/band-f8.txt" "f/16=16=$tmp/band-f16.txt"
# The night-street plate with 6 blades at f/8: the whole composite, its sun's spikes to the frame's edges.
"$ff" simulate --lens "$(variant 6 8)" --plate data/night-street.exr -o "$tmp/street.exr" --preview "$tmp/street.png" \
    > /dev/null
oiiotool "$tmp/street.png" --resize 640x360 -o docs/images/far-field-night-street-6-blades-f8.png
oiiotool "$tmp/street.png" --cut 320x200+890+270 -o docs/images/diffraction-night-street-6-blades-f8.png
