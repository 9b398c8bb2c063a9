"""Scenes: keyword arguments and attributes named as the command line's flags, every key of
the file by its path, TOML and link round trips, and clear errors on bad values."""

import copy

import numpy as np
import pytest

import fourfold
from fourfold import Scene

from conftest import SCENES


def test_keywords_set_and_read_back():
    s = Scene(
        "x^2 + y^2 + z^2 + w^2 = R",
        params={"R": 2.0},
        angles=[0.1, 0.2, 0.3, 0.4, 0.5, 0.6],
        domain=[-2, 2, -2, 2, -2, 2, -3, 3],
        rays=32,
        hits=2,
        background="#102030",
        colour_by="hidden",
        certified=True,
        cert_budget=512,
        max_level=7,
        slice=0.25,
        size=(320, 200),
    )
    assert s.params == {"R": 2.0}
    assert s.angles == [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
    assert s.domain == [-2, 2, -2, 2, -2, 2, -3, 3]
    assert (s.rays, s.hits, s.cert_budget, s.max_level) == (32, 2, 512, 7)
    assert s.background == "#102030"
    assert s.colour_by == "hidden" and s.color_by == "hidden"
    assert s.certified is True
    assert s.slice == 0.25 and s.slab is None
    assert s.size == (320, 200)
    s.slab = (0.1, 0.5)
    assert s.slab == (0.1, 0.5) and s.slice is None


def test_max_level_alone_takes_min_level_down():
    s = Scene("x = 0", max_level=3)
    assert (s.min_level, s.max_level) == (3, 3)
    s = Scene("x = 0", min_level=2, max_level=3)
    assert (s.min_level, s.max_level) == (2, 3)


def test_bad_values_name_the_keyword_and_range():
    with pytest.raises(ValueError, match=r"^rays=2000: between 1 and 1024"):
        Scene("x = 0", rays=2000)
    with pytest.raises(ValueError, match=r"min_level 9 is above max_level 6"):
        Scene("x = 0", min_level=9)
    with pytest.raises(ValueError, match=r"angles"):
        Scene("x = 0", angles=[float("nan")] * 6)
    with pytest.raises(ValueError, match=r"angles: expected 6 numbers, got 2"):
        Scene("x = 0", angles=[1, 2])
    with pytest.raises(ValueError, match=r"colour_by='depth': use 'surface' or 'hidden'"):
        Scene("x = 0", colour_by="depth")
    with pytest.raises(ValueError, match=r"background"):
        Scene("x = 0", background="#12")
    with pytest.raises(ValueError, match=r"the w range"):
        Scene("x = 0", domain=[-1, 1, -1, 1, -1, 1, 1, -1])
    with pytest.raises(ValueError, match=r"size=\(0, 10\): each side must be between 1 and"):
        Scene("x = 0", size=(0, 10))
    with pytest.raises(ValueError, match=r"rays=-3: a whole number from 0 up"):
        Scene("x = 0", rays=-3)
    with pytest.raises(ValueError, match=r"params\['R'\]"):
        Scene("x = R", params={"R": float("inf")})


def test_bad_types_are_type_errors():
    with pytest.raises(TypeError, match=r"rays: expected a whole number, got str 'many'"):
        Scene("x = 0", rays="many")
    with pytest.raises(TypeError, match=r"certified: expected True or False"):
        Scene("x = 0", certified=1)
    with pytest.raises(TypeError, match=r"zoom: expected a number, got str"):
        Scene("x = 0", zoom="2")
    with pytest.raises(TypeError, match=r"params: expected a dict"):
        Scene("x = 0", params=[1, 2])
    with pytest.raises(TypeError, match=r"unknown setting 'ray': did you mean rays\?"):
        Scene("x = 0", ray=4)
    with pytest.raises(TypeError, match=r"angles: expected a sequence of 6 numbers"):
        Scene("x = 0", angles="0,0,0,0,0,0")


def test_a_refused_attribute_leaves_the_scene_as_it_was():
    s = Scene("x = 0", rays=8)
    with pytest.raises(ValueError):
        s.rays = 0
    assert s.rays == 8
    with pytest.raises(TypeError):
        s.colour = "hidden"


def test_any_file_key_by_its_path():
    s = Scene("x = 0")
    s["render.border.tolerance"] = 0.05
    assert s["render.border.tolerance"] == 0.05
    assert s["render"]["border"]["tolerance"] == 0.05
    s["render.lighting.direction"] = [0.0, 0.0, 1.0, 0.0]
    assert s["render.lighting.direction"] == [0.0, 0.0, 1.0, 0.0]
    with pytest.raises(KeyError):
        s["render.nothing"]
    with pytest.raises(ValueError, match="render.rays"):
        s["render.rays"] = 0
    with pytest.raises(ValueError, match="unknown field"):
        s["render.colour"] = "red"


def test_toml_round_trip(tmp_path):
    s = Scene(
        "(sqrt(x^2 + y^2) - R)^2 + z^2 + w^2 = r^2",
        params={"R": 1.5, "r": 0.5},
        angles=[0.3, 0, 0.2, 0.1, 0, 0.7],
        rays=8,
        certified=True,
        slab=(0.1, 0.4),
        description="a spheritorus",
    )
    again = Scene.from_toml(s.to_toml())
    assert again == s
    path = tmp_path / "s.toml"
    s.save(path)
    assert Scene.load(path) == s
    assert fourfold.render(path, size=(8, 8), cpu=True).scene.params == {"R": 1.5, "r": 0.5}


def test_link_round_trip():
    s = Scene("x^2 + y^2 + z^2 + w^2 = R", params={"R": 0.7}, angles=[0.1, 0, 0, 0.2, 0, 0], rays=4)
    link = s.link("https://example.org/fourfold/")
    assert link.startswith("https://example.org/fourfold/#formula=")
    assert Scene.from_link(link) == s
    assert fourfold._native.is_link(link)


def test_bad_links_list_their_problems_or_warn():
    link = "#formula=x%5E2%3D1&render.rays=99999&angles=nan,0,0,0,0,0"
    with pytest.raises(ValueError, match="the link has 2 problems"):
        Scene.from_link(link)
    with pytest.warns(UserWarning):
        s = Scene.from_link(link, strict=False)
    assert s.rays == 16 and s.formula == "x^2=1"
    with pytest.raises(fourfold.FormulaError, match="did you mean sin"):
        Scene.from_link("#formula=sn(x)%3Dy")


def test_scene_files_and_examples():
    names = [name for name, _ in fourfold.examples()]
    assert "glome" in names and "fig-3-9-left" in names
    s = Scene.example("fig-3-9-left")
    assert s == Scene.load(SCENES / "fig-3-9-left.toml")
    assert s.params == {"R": 2.0, "r": 1.0}
    with pytest.raises(ValueError, match="no example scene 'glom'"):
        Scene.example("glom")
    with pytest.raises(FileNotFoundError):
        Scene.load("/nonexistent/scene.toml")


def test_a_bad_scene_file_has_a_caret_at_its_line(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('formula = "x = 0"\n[render]\nrays = 5000\n')
    with pytest.raises(ValueError) as caught:
        Scene.load(path)
    assert "rays = 5000: between 1 and 1024" in str(caught.value)
    assert "3 │ rays = 5000" in str(caught.value)


def test_replace_and_copy_leave_the_original():
    s = Scene("x = 0", rays=4)
    t = s.replace(rays=8, angles=[1, 0, 0, 0, 0, 0])
    assert (s.rays, t.rays) == (4, 8)
    u = copy.deepcopy(t)
    u.rays = 2
    assert t.rays == 8
    assert "rays" in dir(s)
    assert repr(Scene("x = 0", slice=0.5)) == "Scene(\"x = 0\", slice=0.5)"


def test_a_scene_refuses_a_formula_that_does_not_parse():
    with pytest.raises(fourfold.FormulaError, match="did you mean sin"):
        Scene("sn(x) = y")
    s = Scene("x = 0")
    with pytest.raises(fourfold.FormulaError):
        s.formula = "x +* y"
    assert s.formula == "x = 0"
    s.formula = "x^2 + y^2 + z^2 + w^2 = 1"
    assert s.formula == "x^2 + y^2 + z^2 + w^2 = 1"
