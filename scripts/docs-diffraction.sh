#!/usr/bin/env bash
# The pictures of docs/diffraction.md: the bundled double Gauss with its iris given 6 or 9 blades and
# stopped down, one light of flux 10^4 at the centre of a 256 x 256 crop of a 1080p sensor (pitch
# 18.75 um), through `render --mode diffraction`. Usage: scripts/docs-diffraction.sh [build dir]
set -euo pipefail
cd "$(dirname "$0")/.."
ff="${1:-build/release}/src/cli/fourierflare"
python="${PYTHON:-/usr/bin/python3}" # with numpy and OpenImageIO's module (python3-numpy, python3-openimageio)
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

# The iris shapes of the pictures above.
"$python" scripts/diffraction-plots.py iris docs/images/diffraction-irises.svg 6:0 9:0 7:15 0:0

# Radial profiles: a round iris at f/2.8 and f/11, and the bundled double Gauss at f/2 on the axis,
# aberration-free and with its traced wavefront.
profile() { # lens label extra-options -> $tmp/label.exr
    "$ff" render "$1" --mode diffraction --light 128.5,128.5,10000,10000,10000 --size 257x257 --sensor-size 4.81875x4.81875 \
        -o "$tmp/$2.exr" $3 > /dev/null
}
profile "$(variant 0 2.8 0)" round-f2.8 ""
profile "$(variant 0 11 0)" round-f11 ""
profile lenses/double-gauss-50mm-f2.lens dg-physical ""
profile lenses/double-gauss-50mm-f2.lens dg-traced "--diffraction traced"
"$python" scripts/diffraction-plots.py profile docs/images/diffraction-profiles.svg 18.75 \
    "round iris, f/11=$tmp/round-f11.exr" "round iris, f/2.8=$tmp/round-f2.8.exr" \
    "double Gauss f/2, aberration-free=$tmp/dg-physical.exr" "double Gauss f/2, traced wavefront=$tmp/dg-traced.exr"

# The bundled double Gauss at f/2 with a light near the corner of a 1080p frame (15.5 mm from the
# axis): the aberration-free PSF and the one with the lens's traced wavefront and vignetting, the
# 48 x 48 pixels around the light enlarged 4 times.
for d in physical traced; do
    "$ff" render lenses/double-gauss-50mm-f2.lens --mode diffraction --diffraction "$d" \
        --light 1700.5,150.5,10000,10000,10000 --size 1920x1080 --sensor-size 36x20.25 -o "$tmp/corner-$d.exr" \
        --exposure 2 --preview "$tmp/corner-$d.png" > /dev/null
    oiiotool "$tmp/corner-$d.png" --cut 48x48+1677+127 --resample 192x192 -o "docs/images/diffraction-corner-$d.png"
done

# simulate on the bundled night-street plate with the double Gauss given 6 blades at f/8: the sun's
# starburst (the composite's preview, 320 x 200 around the sun).
"$ff" simulate --lens "$(variant 6 8 0)" --plate data/night-street.exr -o "$tmp/street.exr" --preview "$tmp/street.png" \
    > /dev/null
oiiotool "$tmp/street.png" --cut 320x200+890+270 -o docs/images/diffraction-night-street-6-blades-f8.png
