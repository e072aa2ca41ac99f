#!/usr/bin/env python3
"""`fourierflare simulate` against FlareSim CLI on the same plates, in one run (docs/performance.md).

The recipe of the many-lights comparison: 1920 x 1080 plates (half RGB, background 0.05) holding N
square lights of 3 x 3 pixels at radiance 200, placed at random (seed 7); the bundled double Gauss
for FourierFlare, FlareSim's own double Gauss for FlareSim, each tool at its defaults. FourierFlare
runs warm (its ghost table and PSF cached by a first run into a cache folder of this run); FlareSim
has no cache. Each command runs `--repeat` times; the table gives the fastest wall time, the peak
resident memory and, for FourierFlare, the stages it reports.

    bench/side_by_side.py --fourierflare build/release/src/cli/fourierflare \\
        --flaresim ../flaresim/build/flaresim --flaresim-commit 74c6bfc --lights 3,30,300

FlareSim builds from its source with CMake (space55/blackhole-rt, folder flaresim/; its
flaresim.conf is copied beside the binary, and it runs in that folder so that the configuration's
relative lens path holds). Needs oiiotool to write the plates.
"""

import argparse
import array
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def write_plate(path, lights, width=1920, height=1080, radiance=200.0, background=0.05, seed=7):
    pixels = array.array("f", [background]) * (width * height * 3)
    rng = random.Random(seed)
    for _ in range(lights):
        x, y = rng.randrange(8, width - 8), rng.randrange(8, height - 8)
        for dy in range(3):
            for dx in range(3):
                i = ((y + dy) * width + x + dx) * 3
                pixels[i] = pixels[i + 1] = pixels[i + 2] = radiance
    pfm = path + ".pfm"
    with open(pfm, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (width, height))  # little-endian floats
        if sys.byteorder != "little":
            pixels.byteswap()
        pixels.tofile(f)
    subprocess.run(["oiiotool", pfm, "-d", "half", "-o", path], check=True)
    os.remove(pfm)


def timed(command, cwd=None, env=None):
    """Runs command; returns (wall seconds, peak resident MiB, stderr text)."""
    with tempfile.TemporaryFile() as err:
        start = time.perf_counter()
        p = subprocess.Popen(command, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=err)
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - start
        p.returncode = os.waitstatus_to_exitcode(status)
        err.seek(0)
        text = err.read().decode(errors="replace")
    if p.returncode != 0:
        sys.exit(f"{command[0]} failed ({p.returncode}):\n{text}")
    return wall, usage.ru_maxrss / 1024.0, text


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fourierflare", default=os.path.join(ROOT, "build/release/src/cli/fourierflare"))
    ap.add_argument("--lens", default=os.path.join(ROOT, "lenses/double-gauss-50mm-f2.lens"))
    ap.add_argument("--flaresim", help="FlareSim's binary (its flaresim.conf beside it); none: FourierFlare only")
    ap.add_argument("--flaresim-commit", default="unknown", help="recorded in the table")
    ap.add_argument("--lights", default="3,30,300")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--extra", default="", help="more options for simulate, e.g. '--half'")
    ap.add_argument("--keep", help="folder to keep the plates and outputs in")
    args = ap.parse_args()

    work = args.keep or tempfile.mkdtemp(prefix="fourierflare-side-by-side-")
    os.makedirs(work, exist_ok=True)
    env = dict(os.environ, FF_CACHE_DIR=os.path.join(work, "cache"))
    rows = []
    for n in (int(v) for v in args.lights.split(",")):
        plate = os.path.join(work, f"plate-{n}.exr")
        write_plate(plate, n)
        ours = [args.fourierflare, "simulate", args.lens, "--plate", plate, "-o", os.path.join(work, f"ff-{n}.exr")]
        ours += args.extra.split()
        timed(ours, env=env)  # warm: the table and the PSF into the cache
        best = min((timed(ours, env=env) for _ in range(args.repeat)), key=lambda r: r[0])
        stages = dict(re.findall(r"(read|detect|table|flare|diffraction|write) ([0-9.]+) s", best[2]))
        row = {"lights": n, "ff": best[0], "ffMiB": best[1], "stages": stages}
        if args.flaresim:
            folder = os.path.dirname(os.path.abspath(args.flaresim))
            theirs = [os.path.abspath(args.flaresim), "flaresim.conf", "--input", plate,
                      "--output", os.path.join(work, f"fs-{n}.exr"), "--tga", os.path.join(work, f"fs-{n}.tga")]
            fs = min((timed(theirs, cwd=folder) for _ in range(args.repeat)), key=lambda r: r[0])
            row["fs"], row["fsMiB"] = fs[0], fs[1]
        rows.append(row)
        print(row, flush=True)

    print(f"\nFlareSim commit {args.flaresim_commit}; simulate {' '.join(args.extra.split()) or 'at its defaults'}; "
          f"fastest of {args.repeat}\n")
    print("| lights | FlareSim CLI | simulate | ratio | of which flare | read / table / diffraction / write "
          "| peak memory (FlareSim / simulate) |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        s = r["stages"]
        fs = f"{r['fs']:.2f} s" if "fs" in r else "–"
        ratio = f"{r['fs'] / r['ff']:.1f}×" if "fs" in r else "–"
        mem = f"{r['fsMiB']:.0f} / {r['ffMiB']:.0f} MiB" if "fs" in r else f"{r['ffMiB']:.0f} MiB"
        print(f"| {r['lights']} | {fs} | {r['ff']:.2f} s | {ratio} | {s.get('flare', '?')} s | "
              f"{s.get('read', '?')} / {s.get('table', '?')} / {s.get('diffraction', '?')} / {s.get('write', '?')} s "
              f"| {mem} |")
    if not args.keep:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
