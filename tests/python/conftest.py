"""Shared fixtures of the Python module's tests: the CLI to compare against, the bundled lenses,
and the EXR reader (OpenImageIO's Python binding). CTest sets FF_CLI, FF_SOURCE_DIR, PYTHONPATH (the
module's build folder) and FF_CACHE_DIR (the tests' own cache)."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

SOURCE = Path(os.environ.get("FF_SOURCE_DIR", Path(__file__).resolve().parents[2]))
CLI = os.environ.get("FF_CLI", str(SOURCE / "build/release/src/cli/fourierflare"))
COOKE = str(SOURCE / "lenses/cooke-triplet-50mm-f5.lens")
DOUBLE_GAUSS = str(SOURCE / "lenses/double-gauss-50mm-f2.lens")
ZOOM = str(SOURCE / "lenses/zoom-70-200mm-f2.8.lens")
GRIN_ROD = str(SOURCE / "lenses/grin-rod-1.8mm-0.23-pitch.lens")


def run_cli(*args, check=True):
    """Runs the CLI with -q; returns the completed process (stdout, stderr as text)."""
    p = subprocess.run([CLI, "-q", *map(str, args)], capture_output=True, text=True, timeout=600)
    if check and p.returncode != 0:
        raise AssertionError(f"fourierflare {' '.join(map(str, args))} exited {p.returncode}: {p.stderr}")
    return p


def cli_json(*args):
    return json.loads(run_cli(*args).stdout)


def read_exr(path):
    """The EXR's R, G, B as a float32 (height, width, 3) array."""
    import OpenImageIO as oiio

    image = oiio.ImageInput.open(str(path))
    assert image, oiio.geterror()
    spec = image.spec()
    pixels = image.read_image(0, 0, 0, 3, oiio.FLOAT)
    image.close()
    return np.asarray(pixels, dtype=np.float32).reshape(spec.height, spec.width, 3)


@pytest.fixture(scope="session")
def ff():
    import fourierflare

    return fourierflare
