#!/usr/bin/env python3
"""The plots of docs/diffraction.md, from `render --mode diffraction` EXRs (needs OpenImageIO's Python
module, Debian's python3-openimageio, and numpy).

  diffraction-plots.py profile OUT.svg PITCH_UM LABEL=FILE.exr [LABEL=FILE.exr ...]
      the azimuthal mean of each render's G channel around its brightest pixel, over that pixel's value,
      on a log scale against the distance in micrometres (pixels of PITCH_UM)
  diffraction-plots.py iris OUT.svg BLADES:ROTATION_DEG [BLADES:ROTATION_DEG ...]
      the iris shapes: BLADES straight blades (0: round), their edge normals at
      rotation + (k + 1/2) 360 / BLADES degrees (as the lens file's blade_rotation)
"""
import math
import sys

import numpy as np

COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"]


def read_g(path):
    import OpenImageIO as oiio

    buf = oiio.ImageBuf(path)
    if buf.has_error:
        sys.exit(f"{path}: {buf.geterror()}")
    names = list(buf.spec().channelnames)
    pixels = buf.get_pixels(oiio.FLOAT)
    return pixels[:, :, names.index("G")]


def radial_mean(image):
    y0, x0 = np.unravel_index(np.argmax(image), image.shape)
    yy, xx = np.indices(image.shape)
    r = np.hypot(xx - x0, yy - y0)
    reach = int(min(x0, y0, image.shape[1] - 1 - x0, image.shape[0] - 1 - y0))
    bins = np.round(r).astype(int)
    sums = np.bincount(bins.ravel(), image.ravel())
    counts = np.bincount(bins.ravel())
    mean = sums[: reach + 1] / counts[: reach + 1]
    return mean / image[y0, x0]


def svg(width, height, body):
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
        f'viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="12">\n'
        f'<rect width="{width}" height="{height}" fill="white"/>\n' + "\n".join(body) + "\n</svg>\n"
    )


def profile(out, pitch, curves):
    W, H, left, right, top, bottom = 640, 400, 60, 20, 20, 50
    data = [(label, radial_mean(read_g(path))) for label, path in curves]
    rmax = max(len(m) - 1 for _, m in data) * pitch
    lo = -8.0

    def x(r):
        return left + (W - left - right) * r / rmax

    def y(v):
        return top + (H - top - bottom) * (0.0 - max(math.log10(max(v, 1e-30)), lo)) / (0.0 - lo)

    body = [f'<rect x="{left}" y="{top}" width="{W - left - right}" height="{H - top - bottom}" fill="none" stroke="black"/>']
    for e in range(0, int(lo) - 1, -1):
        body.append(f'<line x1="{left}" x2="{W - right}" y1="{y(10.0**e):.1f}" y2="{y(10.0**e):.1f}" stroke="#ddd"/>')
        body.append(f'<text x="{left - 6}" y="{y(10.0**e) + 4:.1f}" text-anchor="end">1e{e}</text>')
    step = 10 ** math.floor(math.log10(rmax / 4))
    step *= 2 if rmax / step > 10 else 1
    r = 0.0
    while r <= rmax + 1e-9:
        body.append(f'<text x="{x(r):.1f}" y="{H - bottom + 16}" text-anchor="middle">{r:g}</text>')
        r += step
    body.append(f'<text x="{(left + W - right) / 2}" y="{H - 10}" text-anchor="middle">distance from the light (um)</text>')
    body.append(f'<text x="14" y="{(top + H - bottom) / 2}" transform="rotate(-90 14 {(top + H - bottom) / 2})" '
                'text-anchor="middle">G, azimuthal mean / the light\'s pixel</text>')
    for k, (label, mean) in enumerate(data):
        pts = " ".join(f"{x(i * pitch):.1f},{y(v):.1f}" for i, v in enumerate(mean))
        c = COLOURS[k % len(COLOURS)]
        body.append(f'<polyline points="{pts}" fill="none" stroke="{c}" stroke-width="1.5"/>')
        body.append(f'<text x="{W - right - 8}" y="{top + 18 + 16 * k}" text-anchor="end" fill="{c}">{label}</text>')
    open(out, "w").write(svg(W, H, body))


def iris(out, shapes):
    size, pad = 120, 10
    body = []
    for k, spec in enumerate(shapes):
        blades, rotation = spec.split(":")
        n, rot = int(blades), math.radians(float(rotation))
        cx, cy, R = pad + k * (size + pad) + size / 2, pad + size / 2, size / 2 - 4
        if n < 3:
            body.append(f'<circle cx="{cx}" cy="{cy}" r="{R}" fill="#333"/>')
        else:
            # Edge normals at rot + (k + 1/2) 2 pi / n: the vertices lie between them, at rot + k 2 pi / n.
            pts = " ".join(
                f"{cx + R * math.cos(rot + 2 * math.pi * i / n):.1f},{cy - R * math.sin(rot + 2 * math.pi * i / n):.1f}"
                for i in range(n)
            )
            body.append(f'<polygon points="{pts}" fill="#333"/>')
        label = "round" if n < 3 else f"{n} blades, {float(rotation):g} deg"
        body.append(f'<text x="{cx}" y="{pad + size + 14}" text-anchor="middle">{label}</text>')
    open(out, "w").write(svg(pad + len(shapes) * (size + pad), size + pad + 24, body))


if __name__ == "__main__":
    if len(sys.argv) >= 5 and sys.argv[1] == "profile":
        profile(sys.argv[2], float(sys.argv[3]), [a.split("=", 1) for a in sys.argv[4:]])
    elif len(sys.argv) >= 4 and sys.argv[1] == "iris":
        iris(sys.argv[2], sys.argv[3:])
    else:
        sys.exit(__doc__)
