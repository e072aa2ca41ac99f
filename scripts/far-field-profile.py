#!/usr/bin/env python3
"""A log-log plot (SVG) of the starburst along a spike against edge diffraction's 1/r^2 law.

  far-field-profile.py OUT.svg PITCH_MM FLUX LABEL=N=DUMP ...

Each DUMP is `oiiotool --dumpdata` of a W x H crop whose bottom row's middle pixel is the light, the
spike running up the crop: the pixels summed across each row are the spike's share at r = rows above
the light. The law for a hexagonal iris of equal area pi/4 (diameter 1): two parallel edges of length
L = sqrt(pi / (6 sqrt 3)) per spike, 2 L beta / (4 pi^2 A r^2) of the flux per pixel of length,
beta = lambda N / pitch, at 550 nm (docs/diffraction.md, "The far field"). Standard library only.
"""
import math
import re
import sys

PIXEL = re.compile(r"Pixel \((\d+), (\d+)\):\s+([-+0-9.eE]+)")


def profile(path):
    rows = {}
    width = height = 0
    for line in open(path):
        m = PIXEL.search(line)
        if m:
            x, y, v = int(m.group(1)), int(m.group(2)), float(m.group(3))
            rows[y] = rows.get(y, 0.0) + v
            width, height = max(width, x + 1), max(height, y + 1)
    return [(height - 1 - y, s) for y, s in sorted(rows.items()) if height - 1 - y > 0]


def main():
    out, pitch, flux = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
    series = []
    for arg in sys.argv[4:]:
        label, n, dump = arg.split("=", 2)
        series.append((label, float(n), profile(dump)))
    W, H, left, right, top, bottom = 640, 420, 70, 20, 20, 50
    r0, r1, v0, v1 = 2.0, 600.0, 1e-4, 1e4
    X = lambda r: left + (W - left - right) * math.log10(r / r0) / math.log10(r1 / r0)
    Y = lambda v: top + (H - top - bottom) * (1 - math.log10(v / v0) / math.log10(v1 / v0))
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
           f'<rect width="{W}" height="{H}" fill="white"/>']
    for e in range(int(math.log10(v0)), int(math.log10(v1)) + 1):
        y = Y(10.0 ** e)
        svg.append(f'<line x1="{left}" y1="{y:.1f}" x2="{W - right}" y2="{y:.1f}" stroke="#ddd"/>')
        svg.append(f'<text x="{left - 6}" y="{y + 4:.1f}" text-anchor="end">1e{e}</text>')
    for r in (2, 5, 10, 20, 50, 100, 200, 500):
        x = X(r)
        svg.append(f'<line x1="{x:.1f}" y1="{top}" x2="{x:.1f}" y2="{H - bottom}" stroke="#ddd"/>')
        svg.append(f'<text x="{x:.1f}" y="{H - bottom + 16}" text-anchor="middle">{r}</text>')
    svg.append(f'<text x="{(left + W - right) / 2}" y="{H - 12}" text-anchor="middle">pixels from the light along the spike</text>')
    svg.append(f'<text x="14" y="{(top + H - bottom) / 2}" transform="rotate(-90 14 {(top + H - bottom) / 2})" '
               'text-anchor="middle">diffraction layer, summed across the spike</text>')
    L, A = math.sqrt(math.pi / (6 * math.sqrt(3))), math.pi / 4
    colours = ["#c0392b", "#2471a3", "#229954", "#7d3c98"]
    for k, (label, n, pts) in enumerate(series):
        colour = colours[k % len(colours)]
        beta = 550e-6 * n / pitch
        law = lambda r: flux * 2 * L * beta / (4 * math.pi ** 2 * A * r * r)
        svg.append(f'<polyline fill="none" stroke="{colour}" stroke-dasharray="5,4" points="' +
                   " ".join(f"{X(r):.1f},{Y(law(r)):.1f}" for r in (r0, r1)) + '"/>')
        print(label + ": measured / law at r = " +
              ", ".join(f"{r}: {v / law(r):.3f}" for r, v in pts if r in (5, 10, 20, 30, 50, 100, 200, 270)))
        for r, v in pts:
            if r0 <= r <= r1 and v0 <= v <= v1:
                svg.append(f'<circle cx="{X(r):.1f}" cy="{Y(v):.1f}" r="1.6" fill="{colour}"/>')
        y = top + 16 + 18 * k
        svg.append(f'<circle cx="{W - 250}" cy="{y - 4}" r="3" fill="{colour}"/>')
        svg.append(f'<text x="{W - 240}" y="{y}">{label} (dashed: the law, 550 nm)</text>')
    svg.append("</svg>")
    open(out, "w").write("\n".join(svg) + "\n")


if __name__ == "__main__":
    main()
