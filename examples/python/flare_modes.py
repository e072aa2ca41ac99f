"""One light through the Cooke triplet, three ways: ray-traced, the ghost table's fitted Gaussians
drawn directly, and the same Gaussians aggregated through the Fourier series; then the Fourier
image's error against the number of terms, plotted with matplotlib where it is installed.

    PYTHONPATH=build/release/python python3 examples/python/flare_modes.py [out-folder]
"""

import sys
import time
from pathlib import Path

import numpy as np

import fourierflare as ff

ROOT = Path(__file__).resolve().parents[2]
out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/python-example")
out.mkdir(parents=True, exist_ok=True)

# The lens and its first-order optics (mm).
lens = ff.Lens.load(str(ROOT / "lenses/cooke-triplet-50mm-f5.lens"))
fo = lens.first_order()
print(f"{lens.name}: EFL {fo['efl_mm']:.2f} mm, f/{fo['f_number']:.2f}, {fo['two_bounce_ghosts']} ghosts")

# One light about 17 degrees off the axis (15 mm on a 36 mm wide sensor), in a 640 x 360 frame.
size = (640, 360)
light = [(580.0, 120.0)]


def timed(what, f):
    t = time.perf_counter()
    image = f()
    print(f"{what}: {time.perf_counter() - t:.2f} s, flux {image.sum():.4g}")
    return image


table = ff.GhostTable.build(lens)
traced = timed("traced", lambda: ff.render(lens, light, size, "traced"))
fitted = timed("fitted", lambda: ff.render(table, light, size, "fitted"))
fourier = timed("fourier", lambda: ff.render(table, light, size, "fourier"))


def relative_l2(a, b):
    return float(np.sqrt(((a - b) ** 2).sum() / (b**2).sum()))


print(f"fitted vs traced (the Gaussian model's error): {relative_l2(fitted, traced):.3f}")
print(f"fourier vs fitted (the series' error):         {relative_l2(fourier, fitted):.2e}")

# The truncation error against the number of terms N along x (M follows the periods' ratio), every
# ghost through the series (hybrid=False; by default those that need more terms than the budget
# allows are drawn directly).
ns = [8, 16, 32, 64, 128, 256]
errors = [relative_l2(ff.render(table, light, size, "fourier", fourier_n=n, hybrid=False), fitted) for n in ns]
for n, e in zip(ns, errors):
    print(f"N = {n:4d}: relative L2 against fitted {e:.2e}")

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed (Debian: python3-matplotlib): no plot")
else:
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.5))
    a.imshow(np.clip(traced / np.percentile(traced, 99.9), 0, 1) ** (1 / 2.2))
    a.set_title("traced")
    a.axis("off")
    b.loglog(ns, errors, "o-")
    b.set_xlabel("N (terms along x)")
    b.set_ylabel("relative L2 against fitted")
    b.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "flare-modes.png", dpi=100)
    print(f"wrote {out / 'flare-modes.png'}")
