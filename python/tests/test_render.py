"""Pictures: the same pixels as `fourfold render`, certified counts as the command line
counts them, the CPU fallback, warnings, and Ctrl-C."""

import os
import re
import signal
import threading
import time

import numpy as np
import pytest

import fourfold
from fourfold import HIT, UNDECIDED, EMPTY, Scene

from conftest import SCENES, read_png

GLOME = "x^2 + y^2 + z^2 + w^2 = 1"


def test_render_shape_and_type():
    p = fourfold.render(GLOME, size=(64, 48))
    assert p.shape == (48, 64, 4) and p.dtype == np.uint8
    assert isinstance(p, np.ndarray) and isinstance(p, fourfold.Picture)
    # Certified by default: a verdict per pixel, counted; certified=False the plain pencil.
    assert p.verdicts.shape == (48, 64) and sum(p.counts.values()) == 64 * 48
    plain = fourfold.render(GLOME, size=(64, 48), certified=False)
    assert plain.verdicts is None and plain.counts is None
    assert p.adapter
    # Something is drawn, and the corners are the background.
    assert (p[0, 0, :3] == [20, 22, 30]).all()
    assert len(np.unique(p.reshape(-1, 4), axis=0)) > 10
    assert p._repr_png_().startswith(b"\x89PNG")


@pytest.mark.parametrize(
    "scene,flags,kwargs",
    [
        (str(SCENES / "fig-3-9-left.toml"), [], {}),
        (
            "(sqrt(x^2 + y^2) - 1.2)^2 + z^2 + w^2 = 0.2",
            ["--angles", "0.4,0.1,0,0.6,0,0.2", "--rays", "8", "--colour-by", "hidden"],
            {"angles": [0.4, 0.1, 0, 0.6, 0, 0.2], "rays": 8, "colour_by": "hidden"},
        ),
        (
            "abs(x) + abs(y) + max(z, w^2) = a",
            ["--param", "a=0.8", "--slab", "0.1,0.3", "--fit", "--background", "ffffff"],
            {"params": {"a": 0.8}, "slab": (0.1, 0.3), "fit": True, "background": "#ffffff"},
        ),
    ],
)
def test_same_picture_as_the_command_line(cli, tmp_path, scene, flags, kwargs):
    out = tmp_path / "cli.png"
    code, stdout, stderr = cli("render", scene, "-o", out, "--size", "96x72", *flags)
    assert code == 0, stderr
    picture = fourfold.render(scene, size=(96, 72), **kwargs)
    expected = read_png(out)
    assert picture.shape == expected.shape
    # The same scene on the same device: pixel-identical.
    assert np.array_equal(np.asarray(picture), expected)


def test_cpu_fallback_matches_the_command_lines_cpu(cli, tmp_path):
    out = tmp_path / "cpu.png"
    code, _, stderr = cli("render", GLOME, "-o", out, "--size", "40x40", "--cpu", "--angles", "0.2,0,0,0.3,0,0")
    assert code == 0, stderr
    picture = fourfold.render(GLOME, size=(40, 40), cpu=True, angles=[0.2, 0, 0, 0.3, 0, 0])
    assert picture.adapter == "CPU reference renderer"
    assert np.array_equal(np.asarray(picture), read_png(out))
    # The GPU picture agrees with the CPU twin on nearly every pixel.
    gpu = fourfold.render(GLOME, size=(40, 40), angles=[0.2, 0, 0, 0.3, 0, 0])
    differ = np.abs(gpu.astype(int) - picture.astype(int)).max(axis=2) > 8
    assert differ.mean() < 0.05


def test_a_small_slice_is_drawn_on_the_cpu_as_by_the_command_line(cli, tmp_path):
    out = tmp_path / "slice.png"
    code, stdout, stderr = cli("render", GLOME, "-o", out, "--size", "40x30", "--slice", "0.3")
    assert code == 0, stderr
    assert "drawn on the CPU" in stdout
    picture = fourfold.render(GLOME, size=(40, 30), slice=0.3)
    assert picture.adapter == "CPU reference renderer"
    assert np.array_equal(np.asarray(picture), read_png(out))
    # cpu=False asks for the GPU, and a projection is drawn there.
    assert fourfold.render(GLOME, size=(40, 30), slice=0.3, cpu=False).adapter != picture.adapter
    assert fourfold.render(GLOME, size=(40, 30)).adapter != picture.adapter


def test_certified_counts_equal_the_command_lines(cli, tmp_path):
    scene = "(x^2 + y^2 - 1)^2 + (z - w)^2 = 0.05 + 0.1*x"
    out = tmp_path / "c.png"
    code, stdout, stderr = cli("render", scene, "-o", out, "--size", "48x48", "--certified", "--angles", "0.3,0.2,0,0.5,0,0")
    assert code == 0, stderr
    hit, empty, undecided = map(int, re.search(r"(\d+) hit, (\d+) empty, (\d+) undecided", stdout).groups())
    picture = fourfold.render(scene, size=(48, 48), certified=True, angles=[0.3, 0.2, 0, 0.5, 0, 0])
    assert picture.counts == {"hit": hit, "empty": empty, "undecided": undecided}
    v = picture.verdicts
    assert v.shape == (48, 48) and v.dtype == np.uint8
    assert [(v == k).sum() for k in (HIT, EMPTY, UNDECIDED)] == [hit, empty, undecided]
    assert np.array_equal(np.asarray(picture), read_png(out))


def test_missing_parameter_warns_as_the_command_line_does():
    with pytest.warns(UserWarning, match=r"parameter R has no value; using 1.0"):
        fourfold.render("x^2 + y^2 + z^2 + w^2 = R", size=(8, 8), cpu=True)
    with pytest.warns(UserWarning, match="parameter Q is set but the formula does not use it"):
        fourfold.render(GLOME, size=(8, 8), cpu=True, params={"Q": 1.0})


def test_a_formula_that_only_touches_zero_warns_as_the_command_line_says():
    with pytest.warns(UserWarning, match=r"F does not change sign where it may be 0"):
        fourfold.render("(x^2 + y^2 + z^2 + w^2 - 1)^2", size=(8, 8), cpu=True)
    with pytest.warns(UserWarning, match=r"F does not change sign across part of M"):
        fourfold.render("x*y^2", size=(8, 8), cpu=True)


def test_bad_arguments():
    with pytest.raises(fourfold.FormulaError):
        fourfold.render("x^^2", size=(8, 8))
    with pytest.raises(TypeError, match="expected a formula string"):
        fourfold.render(42)
    with pytest.raises(ValueError, match=r"size"):
        fourfold.render(GLOME, size=(100000, 10))
    with pytest.raises(TypeError, match=r"size: expected \(width, height\)"):
        fourfold.render(GLOME, size="64x64")
    with pytest.raises(TypeError, match=r"unknown setting 'angle'"):
        fourfold.render(GLOME, angle=[0] * 6)


def test_a_scene_shows_itself_inline():
    s = Scene(GLOME, size=(24, 16))
    png = s._repr_png_()
    assert png.startswith(b"\x89PNG")


def test_ctrl_c_interrupts_a_long_render():
    # A tree this deep takes minutes; the interrupt must come back at once.
    slow = Scene("sin(9x) + sin(9y) + sin(9z) + sin(9w) = 0", max_level=12, min_level=9, node_budget=50_000_000)
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    started = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        fourfold.render(slow, size=(32, 32))
    took = time.monotonic() - started
    timer.join()
    assert took < 3.0, took
    # The interpreter and the package go on working.
    assert fourfold.render(GLOME, size=(8, 8), cpu=True).shape == (8, 8, 4)


def random_case(rng):
    """A formula from invented pieces (kinks, undefined regions, parameters) and random
    settings, as keywords and as the command line's flags."""
    pieces = ["x^2", "abs(y)", "sin(2z)", "w*x", "sqrt(abs(w) + 0.1)", "max(z, y^2)", "exp(-x^2)", "y*z*w", "ln(x^2 + 0.5)"]
    terms = rng.choice(pieces, size=3, replace=False)
    a = round(float(rng.uniform(0.2, 1.0)), 3)
    formula = f"{terms[0]} + {terms[1]} - {terms[2]} = a"
    angles = [round(float(v), 3) for v in rng.uniform(-1, 1, 6)]
    kwargs = {"params": {"a": a}, "angles": angles}
    flags = ["--param", f"a={a}", "--angles", ",".join(map(str, angles))]
    if rng.random() < 0.5:
        rays = int(rng.integers(1, 24))
        kwargs["rays"] = rays
        flags += ["--rays", str(rays)]
    if rng.random() < 0.4:
        hits = int(rng.integers(1, 8))
        kwargs["hits"] = hits
        flags += ["--hits", str(hits)]
    if rng.random() < 0.4:
        kwargs["sampling"] = "random"
        flags += ["--sampling", "random"]
    section = rng.random()
    if section < 0.3:
        c = round(float(rng.uniform(-0.8, 0.8)), 3)
        kwargs["slice"] = c
        flags += ["--slice", str(c)]
    elif section < 0.6:
        c, h = round(float(rng.uniform(-0.5, 0.5)), 3), round(float(rng.uniform(0.1, 1.0)), 3)
        kwargs["slab"] = (c, h)
        flags += ["--slab", f"{c},{h}"]
    if rng.random() < 0.4:
        kwargs["colour_by"] = "hidden"
        flags += ["--colour-by", "hidden"]
    if rng.random() < 0.3:
        kwargs["max_level"] = int(rng.integers(3, 7))
        flags += ["--max-level", str(kwargs["max_level"])]
    if rng.random() < 0.3:
        kwargs["lighting"] = False
        flags += ["--no-lighting"]
    if rng.random() < 0.3:
        kwargs["background"] = "#e0e0d0"
        flags += ["--background", "e0e0d0"]
    return formula, kwargs, flags


@pytest.mark.parametrize("seed", range(6))
def test_random_formulas_and_settings_draw_as_the_command_line(cli, tmp_path, seed):
    formula, kwargs, flags = random_case(np.random.default_rng(100 + seed))
    out = tmp_path / "cli.png"
    code, _, stderr = cli("render", formula, "-o", out, "--size", "64x48", *flags)
    assert code == 0, (formula, flags, stderr)
    picture = fourfold.render(formula, size=(64, 48), **kwargs)
    assert np.array_equal(np.asarray(picture), read_png(out)), (formula, kwargs)
    # Each case draws part of M (9-28% of the pixels at these seeds), not only background.
    background = np.asarray(picture)[0, 0]
    assert (np.asarray(picture) != background).any(axis=2).mean() > 0.02, (formula, kwargs)
