"""backend="cpu"|"gl"|"auto" through the module: the GL backend (llvmpipe where there is no GPU)
gives the CLI's --backend gl pixels and agrees with the CPU as the CLI's GL parity tests require;
the module's version is the CLI's."""

import numpy as np
import pytest

from conftest import COOKE, read_exr, run_cli
from test_simulate import plate_array

LIGHTS = [(100.0, 40.0), (30.5, 60.25, 2.0, 1.0, 0.5)]
SIZE = (160, 90)
TABLE = dict(table_grid=8, table_angles=9)


def relative_l2(a, b):
    a, b = a.astype(np.float64), b.astype(np.float64)
    assert (b * b).sum() > 0
    return np.sqrt(((a - b) ** 2).sum() / (b * b).sum())


@pytest.fixture(scope="module")
def gl(ff):
    """Skips the module's GL tests where no OpenGL 4.5 context can be made (no EGL, no Mesa)."""
    try:
        ff.render(ff.Lens.load(COOKE), LIGHTS, SIZE, "fourier", fourier_n=8, backend="gl", **TABLE)
    except ff.Error as e:
        if "no OpenGL 4.5 context" in str(e):
            pytest.skip(str(e))
        raise
    return ff


def test_the_version_is_the_cli_version(ff):
    assert run_cli("--version").stdout.strip() == f"fourierflare {ff.__version__}"


def test_a_backend_other_than_cpu_gl_auto_is_refused(ff):
    lens = ff.Lens.load(COOKE)
    with pytest.raises(ff.UsageError, match="cpu, gl or auto"):
        ff.render(lens, LIGHTS, SIZE, "fourier", backend="cuda", **TABLE)
    with pytest.raises(ff.UsageError, match="cpu, gl or auto"):
        ff.simulate(plate_array(), lens, backend="GL")
    with pytest.raises(ff.UsageError, match="cpu, gl or auto"):
        ff.compare(lens, LIGHTS, SIZE, backend="")


@pytest.mark.parametrize(
    "mode, kwargs, extra",
    [
        ("fourier", dict(fourier_n=24, **TABLE),
         ["--fourier-n", "24", "--table-grid", "8", "--table-angles", "9"]),
        ("shaped", dict(), []),
        ("diffraction", dict(), []),
    ],
)
def test_render_on_gl_gives_the_cli_gl_pixels_and_agrees_with_the_cpu(gl, tmp_path, mode, kwargs, extra):
    lens = gl.Lens.load(COOKE)
    on_gl = gl.render(lens, LIGHTS, SIZE, mode, backend="gl", **kwargs)
    on_cpu = gl.render(lens, LIGHTS, SIZE, mode, backend="cpu", **kwargs)
    out = tmp_path / "gl.exr"
    args = ["render", COOKE, "--size", "160x90", "--mode", mode, "--backend", "gl", "-o", out, *extra]
    for light in LIGHTS:
        args += ["--light", ",".join(str(v) for v in light)]
    run_cli(*args)
    np.testing.assert_array_equal(on_gl, read_exr(out))
    # The CLI's GL parity bound (test_cli_simulate, test_gl_*): float32 on the device against the
    # CPU's arithmetic, 1e-5 of the image's L2 norm.
    assert relative_l2(on_gl, on_cpu) <= 1e-5


@pytest.mark.parametrize("model", ["gaussian", "shaped"])
def test_simulate_on_gl_agrees_with_the_cpu_and_composites_exactly(gl, model):
    lens = gl.Lens.load(COOKE)
    plate = plate_array()
    kwargs = dict(ghost_model=model, fourier_n=32, **TABLE)
    a = gl.simulate(plate, lens, backend="gl", **kwargs)
    b = gl.simulate(plate, lens, backend="cpu", **kwargs)
    assert relative_l2(a["flare"], b["flare"]) <= 1e-5
    # plate + flare - the lights the diffraction spread, to float rounding (the plate gets the ghosts and
    # the light the iris moves in one addition).
    expected = plate.astype(np.float64) + a["flare"] - a["light_pixels"]
    assert np.all(np.abs(a["composite"] - expected) <= 1e-6 * (np.abs(plate) + a["flare"] + a["light_pixels"]))
    # Without diffraction the GL backend composites: plate + flare, one float addition per channel.
    c = gl.simulate(plate, lens, backend="gl", diffraction="off", **kwargs)
    np.testing.assert_array_equal(c["composite"], plate + c["flare"])


def test_compare_on_gl_measures_what_the_cpu_measures(gl):
    lens = gl.Lens.load(COOKE)
    kwargs = dict(grid=8, fourier_n_sweep=[16], **TABLE)
    a = gl.compare(lens, LIGHTS, SIZE, backend="gl", **kwargs)
    b = gl.compare(lens, LIGHTS, SIZE, backend="cpu", **kwargs)

    def errors(report, prefix=""):
        out = {}
        for k, v in report.items():
            if isinstance(v, dict):
                out.update(errors(v, f"{prefix}{k}."))
            elif k == "relativeL2" and isinstance(v, float):
                out[prefix + k] = v
        return out

    ea, eb = errors(a), errors(b)
    assert len(ea) >= 4 and ea.keys() == eb.keys()
    assert a["fourierBackend"].startswith("gl: ") and b["fourierBackend"] == "cpu"
    # By the triangle inequality, an image within 1e-5 (relative L2) of the CPU's moves each error
    # against a CPU-drawn reference by at most 1e-5 times the norms' ratio (~1: fluxes within 3 %).
    for k in ea:
        assert abs(ea[k] - eb[k]) <= 2e-5, k


def test_auto_without_a_gpu_draws_on_the_cpu(ff, caplog):
    lens = ff.Lens.load(COOKE)
    with caplog.at_level("INFO", logger="fourierflare"):
        a = ff.render(lens, LIGHTS, SIZE, "fourier", fourier_n=24, backend="auto", **TABLE)
    if "backend auto: no GPU" not in caplog.text:
        pytest.skip("this machine has a GPU: auto draws on it")
    b = ff.render(lens, LIGHTS, SIZE, "fourier", fourier_n=24, backend="cpu", **TABLE)
    np.testing.assert_array_equal(a, b)
