#!/usr/bin/env python3
"""simulate on every file of folders of damaged images, as docs/reliability.md reports it.

    scripts/damaged-plates.py [--load N] [--fourierflare PATH] FOLDER...

Runs `fourierflare -q simulate` with each file as the plate (the bundled Cooke triplet, a cache and
an output folder of its own), optionally with N busy processes beside it (a loaded machine), and
prints per folder: how many runs exited 2, 0 or otherwise, the slowest and mean wall-clock time,
the files left in the output folder, and the slowest runs' messages. Exit status 1 when a run
exits 0 with a file that is not a valid plate is not judged here: the table says what happened.
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("folders", nargs="+")
    ap.add_argument("--load", type=int, default=0, help="busy processes to run beside (default 0)")
    ap.add_argument("--fourierflare", default=os.path.join(ROOT, "build/release/src/cli/fourierflare"))
    ap.add_argument("--show", type=int, default=3, help="slowest runs to print with their message")
    a = ap.parse_args()
    busy = [subprocess.Popen(["sh", "-c", "while :; do :; done"]) for _ in range(a.load)]
    work = tempfile.mkdtemp(prefix="ff-damaged-")
    worst = 0.0
    try:
        lens = os.path.join(ROOT, "lenses/cooke-triplet-50mm-f5.lens")
        print("| corpus | files | exit 2 | exit 0 | other | slowest | mean | files left |")
        print("|---|---|---|---|---|---|---|---|")
        details = []
        for folder in a.folders:
            files = sorted(f for f in os.listdir(folder) if os.path.isfile(os.path.join(folder, f))
                           and not f.endswith((".rst", ".md")) and f != "LICENSE")
            codes, times, left = {}, [], 0
            for f in files:
                out = os.path.join(work, "out")
                os.makedirs(out, exist_ok=True)
                env = dict(os.environ, FF_CACHE_DIR=os.path.join(work, "cache"))
                t0 = time.monotonic()
                r = subprocess.run([a.fourierflare, "-q", "simulate", "--lens", lens, "--backend", "cpu",
                                    "--plate", os.path.join(folder, f), "-o", os.path.join(out, "out.exr")],
                                   env=env, capture_output=True, text=True, errors="replace")
                dt = time.monotonic() - t0
                codes[r.returncode] = codes.get(r.returncode, 0) + 1
                times.append((dt, f, r.returncode, r.stderr.strip().splitlines()[-1:] or [""]))
                if r.returncode != 0:
                    left += len(os.listdir(out))
                shutil.rmtree(out)
            times.sort(reverse=True)
            other = sum(n for c, n in codes.items() if c not in (0, 2))
            mean = sum(t for t, *_ in times) / max(1, len(times))
            print(f"| {folder} | {len(files)} | {codes.get(2, 0)} | {codes.get(0, 0)} | {other} | "
                  f"{times[0][0]:.2f} s | {mean:.2f} s | {left} |")
            worst = max(worst, times[0][0])
            details += [(folder, t) for t in times[: a.show]]
        for folder, (dt, f, code, msg) in details:
            print(f"  {dt:6.2f} s exit {code} {os.path.join(folder, f)}: {msg[0][:300]}")
    finally:
        for p in busy:
            p.kill()
            p.wait()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
