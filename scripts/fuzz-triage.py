#!/usr/bin/env python3
"""Triage of libFuzzer findings (docs/reliability.md).

    scripts/fuzz-triage.py [--cli build/release/src/cli/fourierflare] FINDING...

Each finding (`build-fuzz/<target>-crash-…`, `-oom-`, `-timeout-`, `-leak-`) is run again through
its target and the report's first frame outside the sanitizers' runtime and the standard library
says whose fault it is. In a parser target every finding is ours. In the image targets (plate,
aperture_mask) a fault inside the image library is what the guarded read exists for: there the
finding is accepted only if the CLI, reading the file as a plate (or as an aperture mask), exits 2
within 10 s with nothing written. Prints one line per finding; exits 1 if any is ours or escapes the
guard.
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
IMAGE_TARGETS = {"plate", "aperture_mask"}
FRAME = re.compile(r"^\s*#\d+ 0x[0-9a-f]+ in (.+?) (\S+)$")
BUILD_ID = re.compile(r" \(BuildId: [0-9a-f]+\)$")
RUNTIME = ("__asan", "__sanitizer", "__interceptor", "__lsan", "__ubsan", "operator new", "operator delete",
           "malloc", "calloc", "realloc", "free", "std::", "__gnu_cxx", "fuzzer::", "__libc", "__GI_", "raise",
           "__pthread_kill", "MallocHook",
           "abort")


def blame(report):
    """'ours', 'library' or None (no stack): the first frame not in a runtime or the standard library.
    Frames of our libraries name files under src/ or fuzz/; the image library's name its .so."""
    for line in report.splitlines():
        # Frames without debug information end with their module's build id: "(lib.so+0x…) (BuildId: …)".
        m = FRAME.match(BUILD_ID.sub("", line))
        if not m:
            continue
        function, where = m.groups()
        if function.startswith(RUNTIME) or "libc.so" in where or "libstdc++" in where or "/c++/" in where:
            continue
        here = where.lstrip("(")
        if not here.startswith("/"):
            continue  # the C library's own sources (nptl/pthread_kill.c, stdlib/abort.c): its debug info
        return "ours" if here.startswith((os.path.join(ROOT, "src"), os.path.join(ROOT, "fuzz"))) else "library"
    return None


def rerun(target, finding):
    binary = os.path.join(ROOT, "build-fuzz", "fuzz", f"{target}_fuzzer")
    env = dict(os.environ, LSAN_OPTIONS=f"suppressions={ROOT}/fuzz/lsan.supp")
    try:
        r = subprocess.run([binary, "-rss_limit_mb=2048", "-timeout=10", finding], env=env, capture_output=True,
                           text=True, errors="replace", timeout=120)
        return r.returncode, r.stderr
    except subprocess.TimeoutExpired as e:
        return None, (e.stderr or b"").decode(errors="replace") if isinstance(e.stderr, bytes) else (e.stderr or "")


def guard_holds(cli, target, finding):
    """The CLI's contract for a hostile image: exit 2 within 10 s, nothing written. (ok, description)"""
    with tempfile.TemporaryDirectory(prefix="ff-triage-") as work:
        out = os.path.join(work, "out.exr")
        plate = finding
        extra = []
        if target == "aperture_mask":
            plate = os.path.join(ROOT, "fuzz", "seeds", "plate", "rgb-half-zip.exr")
            extra = ["--aperture-mask", finding]
        command = [cli, "-q", "simulate", "--lens", os.path.join(ROOT, "lenses", "cooke-triplet-50mm-f5.lens"),
                   "--plate", plate, "-o", out, "--preview", os.path.join(work, "out.png")] + extra
        start = time.monotonic()
        try:
            r = subprocess.run(command, capture_output=True, text=True, errors="replace", timeout=60,
                               env=dict(os.environ, FF_CACHE_DIR=os.path.join(work, "cache")))
        except subprocess.TimeoutExpired:
            return False, "the CLI did not finish within 60 s"
        seconds = time.monotonic() - start
        written = sorted(os.listdir(work))
        written = [n for n in written if n != "cache"]
        message = r.stderr.strip().splitlines()[-1] if r.stderr.strip() else ""
        if r.returncode == 0:
            return True, f"the CLI reads it as a usable image (exit 0, {seconds:.1f} s)"
        ok = r.returncode == 2 and seconds < 10.0 and not written
        return ok, f"CLI exit {r.returncode} in {seconds:.1f} s, {len(written)} files written: {message[:160]}"


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cli", default=os.path.join(ROOT, "build", "release", "src", "cli", "fourierflare"))
    p.add_argument("findings", nargs="*")
    a = p.parse_args()
    bad = 0
    for finding in a.findings:
        name = os.path.basename(finding)
        target, _, kind = name.partition("-")
        kind = kind.split("-")[0]
        code, report = rerun(target, finding)
        whose = blame(report) if code != 0 else None
        if target not in IMAGE_TARGETS:
            verdict = "OURS" if code != 0 else "OURS (did not reproduce on its own)"
            bad += 1
        elif whose == "ours":
            verdict = "OURS"
            bad += 1
        else:
            ok, how = guard_holds(a.cli, target, finding)
            origin = "library" if whose == "library" else "not reproduced alone" if code == 0 else "no stack"
            verdict = f"{origin}; guard {'holds' if ok else 'BROKEN'}: {how}"
            bad += 0 if ok else 1
        print(f"{name}: {kind}: {verdict}")
        if verdict.startswith("OURS") or "BROKEN" in verdict:
            print("\n".join(report.splitlines()[-40:]))
    print(f"fuzz-triage: {len(a.findings)} findings, {bad} ours or not contained")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
