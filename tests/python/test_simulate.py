"""fourierflare.simulate against `fourierflare simulate` on the same plate (same layers, same
lights), and its errors."""

import json

import numpy as np
import pytest

from conftest import COOKE, run_cli


def plate_array():
    """A dark 240 x 136 plate with two lights: a small hot one and a larger dimmer one."""
    rng = np.random.default_rng(7)
    p = (0.02 + 0.01 * rng.random((136, 240, 3))).astype(np.float32)
    p[40:43, 170:173] = [600.0, 500.0, 400.0]
    p[90:95, 60:65] = [40.0, 60.0, 80.0]
    return p


def write_plate(path, pixels):
    import OpenImageIO as oiio

    spec = oiio.ImageSpec(pixels.shape[1], pixels.shape[0], 3, "float")
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec) and out.write_image(pixels) and out.close()


def read_layers(path):
    import OpenImageIO as oiio

    buf = oiio.ImageBuf(str(path))
    names = list(buf.spec().channelnames)
    pixels = buf.get_pixels(oiio.FLOAT)
    # The EXR's lights layer is the dict's light_pixels ("lights" there lists the lights found).
    return {key: pixels[:, :, [names.index(f"{layer}.{c}") for c in "RGB"]].copy()
            for key, layer in (("ghosts", "ghosts"), ("diffraction", "diffraction"), ("light_pixels", "lights"),
                               ("flare", "flare"), ("composite", "composite"))}


@pytest.mark.parametrize(
    "kwargs, extra",
    [
        (dict(), []),
        (dict(ghost_model="gaussian", diffraction="off", lights=[(100.5, 30.25, 50.0, 40.0, 30.0)],
              table_grid=8, table_angles=9, flare_gain=2.0),
         ["--ghost-model", "gaussian", "--diffraction", "off", "--light", "100.5,30.25,50,40,30",
          "--table-grid", "8", "--table-angles", "9", "--flare-gain", "2"]),
        (dict(fov=50.0, threshold="max:0.5", diffraction_gain=0.5),
         ["--fov", "50", "--threshold", "max:0.5", "--diffraction-gain", "0.5"]),
    ],
)
def test_the_layers_are_the_cli_layers(ff, tmp_path, kwargs, extra):
    pixels = plate_array()
    write_plate(tmp_path / "plate.exr", pixels)
    run_cli("simulate", "--lens", COOKE, "--plate", tmp_path / "plate.exr", "-o", tmp_path / "out.exr",
            "--lights-out", tmp_path / "lights.json", "--backend", "cpu", "--layers", "all", *extra)
    cli = read_layers(tmp_path / "out.exr")
    mine = ff.simulate(pixels, ff.Lens.load(COOKE), **kwargs)
    for layer, image in cli.items():
        assert mine[layer].shape == (136, 240, 3) and mine[layer].dtype == np.float32
        np.testing.assert_array_equal(mine[layer], image, err_msg=layer)
    assert mine["flare"].sum() != 0.0
    lights = json.loads((tmp_path / "lights.json").read_text())["lights"]
    assert mine["lights"] == lights


def test_a_one_channel_plate_and_named_channels(ff):
    lens = ff.Lens.load(COOKE)
    grey = plate_array()[:, :, 1]
    a = ff.simulate(grey, lens, diffraction="off")
    b = ff.simulate(np.repeat(grey[:, :, None], 3, axis=2), lens, diffraction="off")
    np.testing.assert_array_equal(a["flare"], b["flare"])
    four = np.concatenate([plate_array(), np.ones((136, 240, 1), np.float32)], axis=2)
    c = ff.simulate(four[:, :, ::-1].copy(), lens, channels=["A", "B", "G", "R"], diffraction="off")
    d = ff.simulate(plate_array(), lens, diffraction="off")
    np.testing.assert_array_equal(c["flare"], d["flare"])


def test_bad_plates_and_arguments(ff):
    lens = ff.Lens.load(COOKE)
    with pytest.raises(ff.InputError, match="not usable image data"):
        ff.simulate(np.full((20, 30, 3), np.nan, np.float32), lens)
    with pytest.raises(ff.UsageError, match="channels"):
        ff.simulate(np.zeros((20, 30, 5), np.float32), lens)
    with pytest.raises(ff.InputError, match="no R, G, B"):
        ff.simulate(np.zeros((20, 30, 2), np.float32), lens, channels=["U", "V"])
    with pytest.raises(ff.UsageError, match="ghost model"):
        ff.simulate(plate_array(), lens, ghost_model="painted")
    with pytest.raises(ff.UsageError, match="threshold|expected"):
        ff.simulate(plate_array(), lens, threshold="bright")
    with pytest.raises(ff.UsageError, match="not both"):
        ff.simulate(plate_array(), lens, fov=40.0, sensor_size=(36.0, 24.0))
