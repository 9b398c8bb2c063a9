"""Shared fixtures: the command line's binary (the Python package is checked against it),
the repository's example scenes, and a PNG reader independent of the package."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENES = ROOT / "examples" / "scenes"


@pytest.fixture(scope="session")
def cli():
    """Runs `fourfold ARGS...` (the workspace's release build, or $FOURFOLD_CLI) and returns
    (exit code, stdout, stderr)."""
    binary = pathlib.Path(os.environ.get("FOURFOLD_CLI", ROOT / "target" / "release" / "fourfold"))
    if not binary.exists():
        pytest.fail(
            f"the command line's binary {binary} is missing: build it with "
            "`cargo build --release` (or set FOURFOLD_CLI)"
        )

    def run(*args):
        env = dict(os.environ, XDG_RUNTIME_DIR=os.environ.get("XDG_RUNTIME_DIR", "/tmp"))
        done = subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True, env=env, timeout=600)
        return done.returncode, done.stdout, done.stderr

    return run


def read_png(path):
    """An RGBA array of a PNG file, read by Pillow (not by fourfold)."""
    import numpy as np
    from PIL import Image

    with Image.open(path) as image:
        return np.asarray(image.convert("RGBA"))
