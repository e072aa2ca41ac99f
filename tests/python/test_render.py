"""fourierflare.render against `fourierflare render` (same pixels), its arrays, its errors, the GIL
released while it runs, and no leak over many calls."""

import gc
import sys
import threading
import time

import numpy as np
import pytest

from conftest import COOKE, GRIN_ROD, read_exr, run_cli

LIGHTS = [(100.0, 40.0), (30.5, 60.25, 2.0, 1.0, 0.5)]
SIZE = (160, 90)


def cli_render(tmp_path, mode, *extra, lens=COOKE):
    out = tmp_path / f"{mode}.exr"
    args = ["render", lens, "--size", "160x90", "--mode", mode, "-o", out]
    for light in LIGHTS:
        args += ["--light", ",".join(str(v) for v in light)]
    run_cli(*args, *extra)
    return read_exr(out)


@pytest.mark.parametrize(
    "mode, kwargs, extra",
    [
        ("traced", dict(grid=8), ["--grid", "8"]),
        ("fitted", dict(table_grid=8, table_angles=9), ["--table-grid", "8", "--table-angles", "9"]),
        ("fourier", dict(table_grid=8, table_angles=9, fourier_n=48),
         ["--table-grid", "8", "--table-angles", "9", "--fourier-n", "48", "--backend", "cpu"]),
        ("shaped", dict(), []),
        ("diffraction", dict(), []),
    ],
)
def test_each_mode_gives_the_cli_pixels(ff, tmp_path, mode, kwargs, extra):
    lens = ff.Lens.load(COOKE)
    image = ff.render(lens, LIGHTS, SIZE, mode, **kwargs)
    assert image.shape == (90, 160, 3) and image.dtype == np.float32 and image.flags.c_contiguous
    cli = cli_render(tmp_path, mode, *extra)
    assert image.sum() > 0
    np.testing.assert_array_equal(image, cli)


@pytest.mark.parametrize("mode, kwargs, extra", [("traced", dict(grid=8), ["--grid", "8"]), ("shaped", dict(), [])])
def test_a_graded_lens_gives_the_cli_pixels(ff, tmp_path, mode, kwargs, extra):
    image = ff.render(ff.Lens.load(GRIN_ROD), LIGHTS, SIZE, mode, **kwargs)
    assert image.sum() > 0
    np.testing.assert_array_equal(image, cli_render(tmp_path, mode, *extra, lens=GRIN_ROD))


def test_a_table_renders_as_the_lens_does(ff):
    lens = ff.Lens.load(COOKE)
    table = ff.GhostTable.build(lens, table_grid=8, table_angles=9)
    lights = [{"x": 100.0, "y": 40.0}, {"x": 30.5, "y": 60.25, "flux": [2.0, 1.0, 0.5]}]
    a = ff.render(table, lights, SIZE, "fitted")
    b = ff.render(lens, LIGHTS, SIZE, "fitted", table_grid=8, table_angles=9)
    np.testing.assert_array_equal(a, b)


def test_one_field_angle(ff, tmp_path):
    lens = ff.Lens.load(COOKE)
    image = ff.render(lens, size=SIZE, angle=(12.0, 30.0), grid=8)
    out = tmp_path / "angle.exr"
    run_cli("render", COOKE, "--size", "160x90", "--angle", "12,30", "--grid", "8", "-o", out)
    np.testing.assert_array_equal(image, read_exr(out))


def test_bad_arguments_raise_usage_error(ff):
    lens = ff.Lens.load(COOKE)
    with pytest.raises(ff.UsageError, match="mode"):
        ff.render(lens, LIGHTS, SIZE, "painted")
    with pytest.raises(ff.UsageError, match="a light is"):
        ff.render(lens, [(1.0, 2.0, 3.0)], SIZE)
    with pytest.raises(ff.UsageError, match="16384"):
        ff.render(lens, LIGHTS, (0, 10))
    with pytest.raises(ff.UsageError, match="lights"):
        ff.render(lens, [], SIZE)
    with pytest.raises(ff.UsageError, match="mode='fitted' or 'fourier'"):
        ff.render(ff.GhostTable.build(lens, table_grid=8, table_angles=9), LIGHTS, SIZE, "traced")
    with pytest.raises(ff.InputError, match="field"):
        ff.render(lens, [(10000.0, 40.0)], SIZE, grid=8)
    with pytest.raises(TypeError, match="Lens or a fourierflare.GhostTable"):
        ff.render("not a lens", LIGHTS, SIZE)


def test_the_gil_is_released_while_rendering(ff):
    lens = ff.Lens.load(COOKE)
    ticks = [0]
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks[0] += 1

    counter = threading.Thread(target=count)
    counter.start()
    try:
        start = time.monotonic()
        # use_cache=False: the PSF made here (a second's work), not read from a warm cache.
        image = ff.render(lens, LIGHTS, (640, 360), "diffraction", use_cache=False)
        seconds = time.monotonic() - start
    finally:
        done.set()
        counter.join()
    # The lights through the PSF: their flux (6.5 over the channels), less what leaves the frame.
    assert 6.0 < image.sum() <= 6.5 * (1 + 1e-6)
    # With the GIL held through the render, the counting thread could not run at all; released, it
    # counts at Python's pace (millions a second) for the render's whole time.
    assert seconds > 0.05
    assert ticks[0] > 10000 * seconds


def test_no_leak_over_a_thousand_calls(ff):
    lens = ff.Lens.load(COOKE)
    table = ff.GhostTable.build(lens, table_grid=8, table_angles=9)

    def rss_mb():
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * 4096 / 2**20

    for _ in range(50):
        ff.render(table, LIGHTS, (64, 64), "fitted")
    gc.collect()
    refs = (sys.getrefcount(lens), sys.getrefcount(table))
    before = rss_mb()
    for _ in range(1000):
        image = ff.render(table, LIGHTS, (64, 64), "fitted")
        lens.first_order()
        table.ghost(0)
    del image
    gc.collect()
    # 1000 images of 64 x 64 x 3 floats are 47 MiB: a leaked array would show.
    assert rss_mb() - before < 8.0
    assert (sys.getrefcount(lens), sys.getrefcount(table)) == refs
