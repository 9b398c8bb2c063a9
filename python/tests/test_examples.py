"""The example notebook runs headlessly with its pictures produced, and the chapter's
figures script writes its grid."""

import base64
import pathlib
import subprocess
import sys

import nbformat
from nbclient import NotebookClient

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def test_the_notebook_runs_and_shows_its_pictures(tmp_path):
    nb = nbformat.read(EXAMPLES / "fourfold.ipynb", as_version=4)
    NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}).execute()
    pngs = [
        base64.b64decode(out["data"]["image/png"])
        for cell in nb.cells
        if cell.cell_type == "code"
        for out in cell.get("outputs", [])
        if "image/png" in out.get("data", {})
    ]
    assert len(pngs) >= 4
    assert all(png.startswith(b"\x89PNG") for png in pngs)
    gifs = [out for cell in nb.cells for out in cell.get("outputs", []) if "image/gif" in out.get("data", {})]
    assert gifs and (tmp_path / "glome-turning.gif").exists()
    errors = [out for cell in nb.cells for out in cell.get("outputs", []) if out.get("output_type") == "error"]
    assert not errors


def test_the_chapter_figures_script(tmp_path):
    from PIL import Image

    out = tmp_path / "grid.png"
    done = subprocess.run([sys.executable, str(EXAMPLES / "chapter_figures.py"), str(out)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "figures" in done.stdout
    with Image.open(out) as image:
        assert image.size[0] >= 600
