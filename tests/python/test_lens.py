"""fourierflare.Lens against `fourierflare lens info --json`, and its errors."""

import math

import pytest

from conftest import COOKE, DOUBLE_GAUSS, GRIN_ROD, ZOOM, cli_json, run_cli


def same(a, b):
    """Equal JSON-like values; floats equal to the last bit (both come from the same doubles)."""
    if isinstance(a, float) or isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return a == b


@pytest.mark.parametrize("path", [DOUBLE_GAUSS, COOKE, GRIN_ROD])
def test_first_order_and_surfaces_match_the_cli(ff, path):
    lens = ff.Lens.load(path)
    cli = cli_json("lens", "info", path, "--json")
    mine = lens.first_order()
    assert mine.pop("wavelength_nm") == pytest.approx(587.56, abs=0.01)
    assert same(mine, cli["first_order"][0])
    assert same(lens.surfaces, cli["surfaces"])
    assert same(lens.info(), cli)
    assert lens.name == cli["name"] and lens.content_hash == cli["content_hash"]


def test_a_graded_medium_and_its_focal_length(ff):
    # The rod's n = n0 (1 - A r^2 / 2), n0 = 1.608, sqrt(A) = 0.339 / mm, 4.26 mm long:
    # f = 1 / (n0 sqrt(A) sin(sqrt(A) L)).
    lens = ff.Lens.load(GRIN_ROD)
    medium = lens.surfaces[0]["medium"]
    assert medium["gradient"]["radial"] == [pytest.approx(-1.608 * 0.339**2 / 2, rel=1e-9)]
    assert medium["gradient"]["axial"] == []
    assert "gradient" not in lens.surfaces[1]["medium"]
    f = 1 / (1.608 * 0.339 * math.sin(0.339 * 4.26))
    assert lens.first_order()["efl_mm"] == pytest.approx(f, rel=1e-9)


def test_first_order_at_another_wavelength_matches_the_cli(ff):
    mine = ff.Lens.load(DOUBLE_GAUSS).first_order(wavelength_nm=486.13)
    cli = cli_json("lens", "info", DOUBLE_GAUSS, "--json", "--wavelength", "486.13")["first_order"][0]
    mine.pop("wavelength_nm")
    assert same(mine, cli)


def test_a_zoom_position_by_label_and_by_index(ff):
    lens = ff.Lens.load(ZOOM)
    labels = lens.zoom_positions
    assert len(labels) >= 2
    last = labels[-1]
    by_label = ff.Lens.load(ZOOM, zoom=last).first_order()
    by_index = ff.Lens.load(ZOOM, zoom=len(labels)).first_order()
    cli = cli_json("lens", "info", ZOOM, "--json", "--zoom", last)["first_order"][0]
    for d in (by_label, by_index):
        d.pop("wavelength_nm")
        assert same(d, cli)


def test_a_malformed_lens_raises_input_error_with_its_place(ff, tmp_path):
    bad = tmp_path / "bad.lens"
    # The second surface's thickness is not a number: line 18, column 17 of the file.
    text = open(COOKE).read().replace("-435.76044    6.00755", "-435.76044    6.0x755")
    bad.write_text(text)
    with pytest.raises(ff.InputError) as e:
        ff.Lens.load(str(bad))
    err = e.value
    assert isinstance(err, ff.Error) and isinstance(err, ValueError)
    assert (err.file, err.line, err.column) == (str(bad), 18, 17)
    assert str(err).startswith(f"{bad}:{err.line}:{err.column}: ")
    assert err.message in str(err)
    # The CLI says the same.
    p = run_cli("lens", "info", bad, check=False)
    assert p.returncode == 2
    assert f"fourierflare: error: {err}" in p.stderr


def test_missing_file_and_unknown_zoom(ff):
    with pytest.raises(ff.InputError, match="no such file"):
        ff.Lens.load("/nonexistent/x.lens")
    with pytest.raises(ff.Error):
        ff.Lens.load(ZOOM, zoom="no-such-position")
    lens = ff.Lens.load(COOKE)
    assert "Lens" in repr(lens)
