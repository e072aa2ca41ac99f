"""fourierflare.ghost_report and GhostTable against the CLI's `ghosts --json` and `table`; progress,
interruption, and errors."""

import json
import os
import signal
import threading
import time

import numpy as np
import pytest

from conftest import COOKE, DOUBLE_GAUSS, cli_json, run_cli
from test_lens import same


def test_ghost_report_matches_the_cli(ff):
    lens = ff.Lens.load(DOUBLE_GAUSS)
    kw = dict(azimuth_deg=30.0, grid=16, sampling="paraxial-grid", sensor="paraxial", coating="none")
    full = ff.ghost_report(lens, 10.0, [450.0, 650.0], full=True, **kw)
    cli = cli_json("ghosts", DOUBLE_GAUSS, "--angle", "10,30", "--wavelength", "450", "--wavelength", "650",
                   "--grid", "16", "--sampling", "paraxial-grid", "--sensor", "paraxial", "--coating", "none",
                   "--json")
    assert same(full, cli)
    rows = ff.ghost_report(lens, 10.0, [450.0, 650.0], **kw)
    assert len(rows) == 2 * cli["ghost_count"]
    expected = [dict(g, wavelength_nm=w["wavelength_nm"]) for w in cli["wavelengths"] for g in w["ghosts"]]
    assert same(rows, expected)
    assert rows[0]["relative_energy"] >= rows[1]["relative_energy"]


def test_ghost_report_refuses_bad_arguments(ff):
    lens = ff.Lens.load(COOKE)
    with pytest.raises(ff.UsageError, match="sampling"):
        ff.ghost_report(lens, 5.0, sampling="random")
    with pytest.raises(ff.UsageError, match="300..2000 nm"):
        ff.ghost_report(lens, 5.0, [100.0])
    with pytest.raises(ff.UsageError, match="grid"):
        ff.ghost_report(lens, 5.0, grid=1)


def without_timing(text):
    j = json.loads(text)
    j.pop("build_seconds", None)
    return j


def test_table_matches_the_cli_and_round_trips(ff, tmp_path):
    lens = ff.Lens.load(COOKE)
    calls = []
    table = ff.GhostTable.build(lens, table_grid=8, table_angles=9, use_cache=False,
                                progress=lambda done, total: calls.append((done, total)))
    run_cli("table", COOKE, "-o", tmp_path / "cli.json", "--table-grid", 8, "--table-angles", 9, "--no-cache")
    assert same(without_timing(table.to_json()), without_timing((tmp_path / "cli.json").read_text()))
    assert calls and all(0 < d <= t for d, t in calls) and calls[-1][0] == calls[-1][1]

    table.save(str(tmp_path / "mine.json"))
    back = ff.GhostTable.load(str(tmp_path / "mine.json"))
    assert back.to_json() == table.to_json()
    assert len(back) == len(table) > 0
    assert back.wavelengths_nm.tolist() == [650.0, 550.0, 450.0]

    g = table.ghost(0)
    angles = g["angles_deg"]
    assert g["flux"].shape == (3, len(angles)) and g["flux"].dtype == np.float64
    doc = json.loads(table.to_json())["ghosts"][0]
    assert list(g["surfaces"]) == doc["surfaces"]
    # An entry at one of the ghost's own angles is that entry, not an interpolation.
    e = table.at(0, 1, float(angles[2]))
    assert e["flux"] == g["flux"][1, 2] and e["sigma_r_mm"] == g["sigma_r_mm"][1, 2]
    with pytest.raises(IndexError):
        table.ghost(len(table))


def test_a_progress_callback_that_raises_stops_the_build(ff):
    lens = ff.Lens.load(COOKE)

    class Stop(Exception):
        pass

    seen = []

    def progress(done, total):
        seen.append(done)
        if len(seen) == 3:
            raise Stop("enough")

    with pytest.raises(Stop, match="enough"):
        ff.GhostTable.build(lens, table_grid=8, table_angles=9, use_cache=False, progress=progress)
    assert len(seen) == 3  # no call after the one that raised


def test_ctrl_c_interrupts_a_build(ff):
    lens = ff.Lens.load(DOUBLE_GAUSS)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            # About 16 s when left to finish (no progress callback: the signal is checked anyway).
            ff.GhostTable.build(lens, table_grid=16, table_angles=16, use_cache=False)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 10.0


def test_a_corrupt_table_raises_input_error_naming_the_file(ff, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"schema": "fourierflare-ghost-table", "ghosts": [')
    with pytest.raises(ff.InputError) as e:
        ff.GhostTable.load(str(bad))
    assert str(bad) in str(e.value)
    with pytest.raises(ff.UsageError, match="table_grid"):
        ff.GhostTable.build(ff.Lens.load(COOKE), table_grid=2)
