#!/usr/bin/env python3
"""Soak: a long `simulate --frames` sequence of a moving light and many Python `render` calls in one
process, watching peak memory, open file descriptors and files left behind (docs/reliability.md).

    scripts/soak.py [--frames 1000] [--calls 1000] [--build build/release] [--max-growth 0.01] [--leak-kb 0]

The light's path repeats every 100 steps. For `simulate`, peak RSS (VmHWM) is taken once the first
tenth of the work is done (caches built, pools started, every position of the light seen) and at the
end. The Python calls run in this script's child, which reads its own peak after each call and resets
it (/proc/self/clear_refs), so each call's peak is compared with the peak of the call at the same step
of the path and in the same mode in the first period (the median of those growths: a leak
raises every call's peak, two threads' buffers meeting by chance in one call raise one), and its RSS
once malloc has given its free pages back (malloc_trim) and the bytes malloc has handed out in all
its arenas (malloc_info: a leak taken from freed memory still resident does not raise RSS) at the
end with those after the first tenth, at the same step. Each growth must stay under
--max-growth, the descriptors open at the end no more than after the first tenth (for simulate the
fewest open over ten frames at each end: a frame holds some open for a while), and no temporary
file may be left in the output folder, the cache or $TMPDIR. Prints the figures as JSON; exits 1 when
a bound is broken.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LENS = os.path.join(ROOT, "lenses", "double-gauss-50mm-f2.lens")
WIDTH, HEIGHT = 320, 180


def status(pid):
    """VmRSS and VmHWM in kB and the number of open descriptors of a live process (None once gone)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            fields = dict(line.split(":", 1) for line in f if ":" in line)
        fds = len(os.listdir(f"/proc/{pid}/fd"))
        return int(fields["VmRSS"].split()[0]), int(fields["VmHWM"].split()[0]), fds
    except (FileNotFoundError, ProcessLookupError, KeyError):
        return None


PERIOD = 100


def light_at(i):
    """The moving light's pixel position at step i: across the frame and down it (the field angle and
    the azimuth both change), there and back every PERIOD steps. The work of a frame depends on where
    its light is; repeating the path makes the first tenth (one period) hold every position, so that
    a peak above its peak later is memory kept, not a harder frame."""
    t = i % PERIOD
    k = 2 * t if t < PERIOD // 2 else 2 * (PERIOD - t)  # 0 .. PERIOD .. 0
    return 20 + (WIDTH - 40) * k // PERIOD, 30 + (HEIGHT - 60) * k // PERIOD


def leftovers(folder, expected=lambda name: False):
    """Files under folder that are not expected: hidden temporaries above all."""
    left = []
    for base, _, files in os.walk(folder):
        left += [os.path.join(base, f) for f in files if not expected(f)]
    return left


def soak_simulate(cli, frames, work):
    plates, out, cache, tmp = (os.path.join(work, d) for d in ("plates", "out", "cache", "tmp"))
    for d in (plates, out, cache, tmp):
        os.makedirs(d)
    for f in range(1, frames + 1):  # one plate per position of the light; the other frames link to it
        plate = os.path.join(plates, f"plate.{f:04d}.exr")
        if f > PERIOD:
            os.symlink(f"plate.{(f - 1) % PERIOD + 1:04d}.exr", plate)
            continue
        x, y = light_at(f)
        subprocess.run(["oiiotool", "--pattern", "constant:color=0.02,0.02,0.03", f"{WIDTH}x{HEIGHT}", "3",
                        "--box:color=800,600,400:fill=1", f"{x},{y},{x + 2},{y + 2}", "-d", "half",
                        "-o", plate], check=True)
    env = dict(os.environ, FF_CACHE_DIR=cache, TMPDIR=tmp)
    command = [cli, "-q", "simulate", "--lens", LENS, "--plate", os.path.join(plates, "plate.%04d.exr"),
               "--frames", f"1-{frames}", "-o", os.path.join(out, "out.%04d.exr"),
               "--preview", os.path.join(out, "out.%04d.png")]
    start = time.monotonic()
    proc = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    warm = last = None
    fds = []  # (frames done, descriptors open) at every sample
    while proc.poll() is None:
        s = status(proc.pid)
        if s:
            done = len([n for n in os.listdir(out) if n.endswith(".exr") and not n.startswith(".")])
            if warm is None and done >= max(PERIOD, frames // 10):
                warm = (done,) + s
            last = (done,) + s
            fds.append((done, s[2]))
        time.sleep(0.1)
    # Descriptors: the fewest open over the ten frames after the first tenth and over the last ten. A
    # frame opens some for a while (its plate, the plate checker's pipe, the output being written), so
    # one sample at an arbitrary moment can catch one open; a descriptor kept is open at every moment
    # after it leaked and raises the fewest.
    def fewest(first, stop, otherwise):
        inside = [n for d, n in fds if first <= d < stop]
        return min(inside) if inside else otherwise
    if warm and last:
        warm = warm[:3] + (fewest(warm[0], warm[0] + 10, warm[3]),)
        last = last[:3] + (fewest(frames - 10, frames + 1, last[3]),)
    err = proc.stderr.read().decode()
    seconds = time.monotonic() - start
    written = len([n for n in os.listdir(out) if n.endswith(".exr") and not n.startswith(".")])
    left = (leftovers(out, lambda n: not n.startswith(".") and n.startswith("out.")) +
            leftovers(cache, lambda n: not n.startswith(".")) + leftovers(tmp))
    return {
        "frames": frames, "exit": proc.returncode, "stderr": err[-2000:], "written": written, "seconds": round(seconds, 1),
        "warm": {"frames_done": warm[0], "rss_kb": warm[1], "hwm_kb": warm[2], "fds": warm[3]} if warm else None,
        "end": {"frames_done": last[0], "rss_kb": last[1], "hwm_kb": last[2], "fds": last[3]} if last else None,
        "left_behind": left,
    }


PY_CHILD = r"""
import json, os, resource, sys
import fourierflare as ff
calls, lens_path, leak_kb = int(sys.argv[1]), sys.argv[2], int(sys.argv[3])
kept = []  # --leak-kb: memory kept on purpose, to see the check fail
width, height = %d, %d
lens = ff.Lens.load(lens_path)
table = ff.GhostTable.build(lens)
modes = ["fourier", "shaped", "fitted", "diffraction"]
import ctypes, re, tempfile
libc = ctypes.CDLL(None)
libc.fopen.restype = ctypes.c_void_p
libc.fopen.argtypes = [ctypes.c_char_p, ctypes.c_char_p]
libc.malloc_info.argtypes = [ctypes.c_int, ctypes.c_void_p]
libc.fclose.argtypes = [ctypes.c_void_p]
def malloc_in_use():
    # The bytes glibc's malloc has handed out and not had back, over every arena (each thread of a
    # pool allocates from its own; mallinfo2 sees the main arena only): malloc_info's totals, the
    # memory the arenas hold from the system less their free chunks, plus the mmapped blocks.
    fd, path = tempfile.mkstemp()
    os.close(fd)
    f = libc.fopen(path.encode(), b"w")
    libc.malloc_info(0, f)
    libc.fclose(f)
    with open(path) as x:
        xml = x.read()
    os.unlink(path)
    totals = xml[xml.rfind("</heap>"):]
    size = lambda what: int(re.search(what + r' size="(\d+)"', totals).group(1))
    return (size(r'<system type="current"') - size(r'<total type="fast" count="\d+"') -
            size(r'<total type="rest" count="\d+"') + size(r'<total type="mmap" count="\d+"'))
def sample(done):
    # rss_kb is read after malloc_trim(0) has given the arenas' free pages back: what glibc keeps of
    # freed memory depends on which pool thread freed it, and is no leak; malloc_kb (see above) is what
    # RSS hides while a leak is carved from memory freed earlier and still resident.
    libc.malloc_trim(0)
    fields = dict(l.split(":", 1) for l in open("/proc/self/status") if ":" in l)
    return {"calls_done": done, "rss_kb": int(fields["VmRSS"].split()[0]), "hwm_kb": int(fields["VmHWM"].split()[0]),
            "malloc_kb": malloc_in_use() // 1024, "fds": len(os.listdir("/proc/self/fd"))}
samples = {}
def call_peak():
    # This call's peak resident size, then the peak reset to the current size (Linux >= 4.0); None
    # where the kernel does not allow the reset.
    fields = dict(l.split(":", 1) for l in open("/proc/self/status") if ":" in l)
    peak = int(fields["VmHWM"].split()[0])
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
    except OSError:
        return None
    return peak
call_peak()
peaks = []
for i in range(1, calls + 1):
    t = i %% %d
    k = 2 * t if t < %d // 2 else 2 * (%d - t)
    x, y = 20 + (width - 40) * k // %d, 30 + (height - 60) * k // %d
    mode = modes[i %% len(modes)]
    image = ff.render(lens if mode in ("shaped", "diffraction") else table, [(float(x), float(y))], (width, height), mode)
    assert image.shape == (height, width, 3) and image.sum() > 0, (mode, image.shape)
    if i == max(%d, calls // 10): samples["warm"] = sample(i)
    kept.append(b"\1" * (1024 * leak_kb))
    peaks.append(call_peak())
samples["end"] = sample(calls)
samples["call_peaks_kb"] = peaks if None not in peaks else None
print(json.dumps(samples))
""" % (WIDTH, HEIGHT, PERIOD, PERIOD, PERIOD, PERIOD, PERIOD, PERIOD)


def module_python(build):
    """The interpreter the module was built for (CMake's Python3_EXECUTABLE), else this one."""
    try:
        with open(os.path.join(build, "CMakeCache.txt")) as f:
            for line in f:
                if line.startswith(("Python3_EXECUTABLE:", "_Python3_EXECUTABLE:")):
                    return line.split("=", 1)[1].strip()
    except FileNotFoundError:
        pass
    return sys.executable


def soak_python(build, calls, work, leak_kb=0):
    cache, tmp = os.path.join(work, "pycache"), os.path.join(work, "pytmp")
    os.makedirs(cache)
    os.makedirs(tmp)
    env = dict(os.environ, FF_CACHE_DIR=cache, TMPDIR=tmp, PYTHONPATH=os.path.join(build, "python"))
    start = time.monotonic()
    r = subprocess.run([module_python(build), "-c", PY_CHILD, str(calls), LENS, str(leak_kb)], env=env, capture_output=True, text=True)
    seconds = time.monotonic() - start
    result = {"calls": calls, "exit": r.returncode, "seconds": round(seconds, 1), "stderr": r.stderr[-2000:]}
    if r.returncode == 0:
        result.update(json.loads(r.stdout.strip().splitlines()[-1]))
    result["left_behind"] = leftovers(cache, lambda n: not n.startswith(".")) + leftovers(tmp)
    return result


def growth(part, key="hwm_kb"):
    return (part["end"][key] - part["warm"][key]) / part["warm"][key]


def call_peak_growth(peaks):
    """The median over the last period's calls of each one's peak against the peak of the call at the
    same step of the path in the first period (PERIOD is a multiple of the four modes, so the mode is
    the same too). The first period holds the cold calls: their peaks include building the caches."""
    first, last = peaks[:PERIOD], peaks[-PERIOD:]
    rel = sorted((b - a) / a for a, b in zip(first, last))
    return (rel[(PERIOD - 1) // 2] + rel[PERIOD // 2]) / 2


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--frames", type=int, default=1000)
    p.add_argument("--calls", type=int, default=1000)
    p.add_argument("--build", default=os.path.join(ROOT, "build", "release"))
    p.add_argument("--max-growth", type=float, default=0.01)
    p.add_argument("--leak-kb", type=int, default=0, help="keep this much memory per Python call (a check of the check)")
    a = p.parse_args()
    if a.frames < 2 * PERIOD or a.calls < 2 * PERIOD:
        p.error(f"--frames and --calls must be at least {2 * PERIOD} (the light's path repeats every {PERIOD})")
    cli = os.path.join(a.build, "src", "cli", "fourierflare")
    report, problems = {}, []
    with tempfile.TemporaryDirectory(prefix="ff-soak-") as work:
        report["simulate"] = sim = soak_simulate(cli, a.frames, work)
        report["python"] = py = soak_python(a.build, a.calls, work, a.leak_kb)
    for name, part, count in (("simulate", sim, "written"), ("python", py, None)):
        if part["exit"] != 0:
            problems.append(f"{name} exited {part['exit']}")
            continue
        if count and part[count] != a.frames:
            problems.append(f"{name} wrote {part[count]} of {a.frames} frames")
        if not part.get("warm") or not part.get("end"):
            problems.append(f"{name}: no samples")
            continue
        peaks = part.pop("call_peaks_kb", None)
        if name == "python" and peaks:
            # Each call's own peak (see the module's docstring): VmHWM is reset after every call.
            part["call_peak_growth"] = round(call_peak_growth(peaks), 5)
            part["call_peak_kb"] = {"first_period_max": max(peaks[:PERIOD]), "last_period_max": max(peaks[-PERIOD:])}
            part["rss_growth"] = round(growth(part, "rss_kb"), 5)
            part["malloc_growth"] = round(growth(part, "malloc_kb"), 5)
            for what, key in (("each call's peak RSS (median)", "call_peak_growth"), ("RSS", "rss_growth"),
                              ("memory in use by malloc", "malloc_growth")):
                if part[key] >= a.max_growth:
                    problems.append(f"{name}: {what} grew by {100 * part[key]:.2f} % after the first tenth")
        else:
            part["peak_rss_growth"] = round(growth(part), 5)
            if part["peak_rss_growth"] >= a.max_growth:
                problems.append(f"{name}: peak RSS grew by {100 * part['peak_rss_growth']:.2f} % after the first tenth")
        if part["end"]["fds"] > part["warm"]["fds"]:
            problems.append(f"{name}: {part['end']['fds'] - part['warm']['fds']} more descriptors open at the end")
        if part["left_behind"]:
            problems.append(f"{name} left {len(part['left_behind'])} files behind: {part['left_behind'][:3]}")
    report["problems"] = problems
    print(json.dumps(report, indent=1))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
