"""fourierflare.compare against `fourierflare compare`: the same report numbers and images."""

import glob
import json
import os
import tempfile

import numpy as np
import pytest

from conftest import COOKE, read_exr, run_cli
from test_lens import same


def without_timing(report):
    """The report without what differs between two runs: seconds and the command line."""
    if isinstance(report, dict):
        return {k: without_timing(v) for k, v in report.items() if k not in ("seconds", "commandLine")}
    if isinstance(report, list):
        return [without_timing(v) for v in report]
    return report


def test_the_report_and_images_are_the_cli_ones(ff, tmp_path):
    lens = ff.Lens.load(COOKE)
    lights = [(250.0, 40.0), (100.0, 120.0, 2.0, 1.0, 0.5)]
    mine = ff.compare(lens, lights, (320, 180), str(tmp_path / "mine"), fourier_n_sweep=[16, 8],
                      table_grid=8, table_angles=9, diffraction="physical")
    run_cli("compare", COOKE, "--light", "250,40", "--light", "100,120,2,1,0.5", "--size", "320x180",
            "--fourier-n-sweep", "8,16", "--table-grid", 8, "--table-angles", 9, "--diffraction", "physical",
            "--backend", "cpu", "-o", tmp_path / "cli")
    cli = json.loads((tmp_path / "cli" / "report.json").read_text())
    assert mine["tool"] == cli["tool"]
    assert same(without_timing(mine), without_timing(cli))
    assert [e["n"] for e in mine["profiles"]["gaussian"]["errorVsN"]] == [8, 16]
    for name in ("traced", "shaped", "fitted-gaussian", "fourier-cos2", "diffraction-physical"):
        np.testing.assert_array_equal(read_exr(tmp_path / "mine" / f"{name}.exr"),
                                      read_exr(tmp_path / "cli" / f"{name}.exr"), err_msg=name)
    assert (tmp_path / "mine" / "report.md").exists() and (tmp_path / "mine" / "error-vs-n.svg").exists()


def test_without_a_folder_only_the_numbers_remain(ff):
    pattern = os.path.join(tempfile.gettempdir(), "fourierflare-compare-*")
    before = set(glob.glob(pattern))
    report = ff.compare(ff.Lens.load(COOKE), [(125.0, 20.0)], (160, 90), fourier_n_sweep=[8],
                        table_grid=8, table_angles=9)
    assert 0.0 < report["profiles"]["gaussian"]["fittedVsTraced"]["relativeL2"] < 1.0
    assert set(glob.glob(pattern)) == before


def test_bad_arguments(ff, tmp_path):
    lens = ff.Lens.load(COOKE)
    with pytest.raises(ff.UsageError, match="8..8192"):
        ff.compare(lens, [(1.0, 1.0)], (4, 4))
    with pytest.raises(ff.UsageError, match="1..2048"):
        ff.compare(lens, [(1.0, 1.0)], (64, 64), fourier_n_sweep=[0])
    with pytest.raises(ff.UsageError, match="at least one light"):
        ff.compare(lens, [], (64, 64))
    (tmp_path / "file").write_text("x")
    with pytest.raises(ff.UsageError, match="not a folder"):
        ff.compare(lens, [(1.0, 1.0)], (64, 64), str(tmp_path / "file"))
