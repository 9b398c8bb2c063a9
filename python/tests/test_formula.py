"""Formulas: parse errors as the command line words them, F and ∇F on numpy arrays against
numpy and finite differences, and rigorous enclosures against sampled values."""

import re
import warnings

import numpy as np
import pytest

import fourfold
from fourfold import Formula, FormulaError

# Formulas with thin parts, kinks, undefined regions and parameters; each with the same F
# written in numpy (x, y, z, w, params).
CASES = [
    ("x^2 + y^2 + z^2 + w^2 = 1", {}, lambda x, y, z, w, p: x**2 + y**2 + z**2 + w**2 - 1),
    (
        "(sqrt(x^2 + y^2) - R)^2 + z^2 + w^2 = r^2",
        {"R": 1.3, "r": 0.4},
        lambda x, y, z, w, p: (np.sqrt(x**2 + y**2) - p["R"]) ** 2 + z**2 + w**2 - p["r"] ** 2,
    ),
    ("abs(x) + abs(y) + abs(z) + abs(w) = 1", {}, lambda x, y, z, w, p: abs(x) + abs(y) + abs(z) + abs(w) - 1),
    ("sqrt(1 - x^2 - y^2) = z + w", {}, lambda x, y, z, w, p: np.sqrt(1 - x**2 - y**2) - (z + w)),
    ("ln(x + 2) * sin(3y) - w*z = a", {"a": 0.2}, lambda x, y, z, w, p: np.log(x + 2) * np.sin(3 * y) - w * z - p["a"]),
    ("max(x^2 + y^2, z^2 + w^2) = 0.5", {}, lambda x, y, z, w, p: np.maximum(x**2 + y**2, z**2 + w**2) - 0.5),
    ("exp(-x^2) + cos(y*z) / (1 + w^2) = 1", {}, lambda x, y, z, w, p: np.exp(-(x**2)) + np.cos(y * z) / (1 + w**2) - 1),
]


def random_points(n, seed, scale=1.5):
    return np.random.default_rng(seed).uniform(-scale, scale, size=(n, 4))


def test_parse_error_is_the_command_lines_caret_message(cli):
    text = "x^2 + sn(y) = 1"
    with pytest.raises(FormulaError) as caught:
        Formula(text)
    e = caught.value
    assert isinstance(e, ValueError)
    code, _, stderr = cli("check", text)
    assert code == 2
    assert str(e).strip() in stderr
    assert "did you mean sin?" in str(e)
    assert text[e.start : e.end] == "sn"
    assert (e.line, e.column) == (1, 7)
    assert e.message == "unknown function 'sn'"
    assert e.hint == "did you mean sin?"
    assert e.formula == text


def test_parse_error_spans_count_characters_not_bytes():
    text = "θ + x^2 = )"
    with pytest.raises(FormulaError) as caught:
        Formula(text)
    e = caught.value
    assert 0 <= e.start <= e.end <= len(text)
    assert e.column == e.start + 1


def test_multiline_error_position():
    with pytest.raises(FormulaError) as caught:
        Formula("x^2 +\n  y^2 + (z")
    assert caught.value.line == 2


def test_text_parameters_and_gradient_strings():
    f = Formula("x^2 + y^2 + z^2 + w^2 = R")
    assert f.parameters == ["R"]
    assert f.gradient() == ("2x", "2y", "2z", "2w")
    assert f.derivative("w") == "2w"
    assert str(f) == "x^2 + y^2 + z^2 + w^2 = R"
    with pytest.raises(ValueError, match="the variables are x, y, z and w"):
        f.derivative("q")


@pytest.mark.parametrize("text,params,numpy_f", CASES)
def test_values_match_numpy(text, params, numpy_f):
    f = Formula(text)
    p = random_points(2000, 1)
    with np.errstate(all="ignore"):
        expected = numpy_f(p[:, 0], p[:, 1], p[:, 2], p[:, 3], params)
    got = f(p, params=params)
    assert got.shape == (2000,)
    assert np.array_equal(np.isnan(got), np.isnan(expected))
    ok = ~np.isnan(expected)
    np.testing.assert_allclose(got[ok], expected[ok], rtol=1e-12, atol=1e-12)


def test_four_arrays_broadcast():
    f = Formula("x + 2y + 3z + 4w = 0")
    x = np.linspace(-1, 1, 5)[:, None]
    y = np.linspace(-1, 1, 3)[None, :]
    got = f(x, y, 0.5, 1)
    assert got.shape == (5, 3)
    np.testing.assert_allclose(got, x + 2 * y + 1.5 + 4)
    assert f([[0, 0, 0, 1], [1, 0, 0, 0]]).tolist() == [4.0, 1.0]


@pytest.mark.parametrize("text,params,numpy_f", CASES)
def test_gradient_matches_finite_differences(text, params, numpy_f):
    f = Formula(text)
    p = random_points(500, 2)
    g = f.grad(p, params=params)
    assert g.shape == (500, 4)
    h = 1e-6
    for axis in range(4):
        step = np.zeros(4)
        step[axis] = h
        with np.errstate(all="ignore"):
            fd = (f(p + step, params=params) - f(p - step, params=params)) / (2 * h)
        # Away from kinks and undefined points, central differences agree.
        ok = np.isfinite(fd) & np.isfinite(g[:, axis]) & (abs(fd) < 1e4)
        close = np.isclose(g[ok, axis], fd[ok], rtol=1e-4, atol=1e-5)
        assert close.mean() > 0.98, (text, axis, close.mean())


@pytest.mark.parametrize("text,params,numpy_f", CASES)
def test_derivative_text_parses_and_agrees(text, params, numpy_f):
    f = Formula(text)
    p = random_points(300, 3)
    g = f.grad(p, params=params)
    for axis, name in enumerate("xyzw"):
        d = Formula(f.derivative(name) + " = 0")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            v = d(p, params={k: v for k, v in params.items() if k in d.parameters})
        both = np.isfinite(v) & np.isfinite(g[:, axis])
        np.testing.assert_allclose(v[both], g[both, axis], rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("text,params,numpy_f", CASES)
def test_interval_encloses_sampled_values(text, params, numpy_f):
    f = Formula(text)
    rng = np.random.default_rng(4)
    for _ in range(40):
        lo = rng.uniform(-1.5, 1.2, 4)
        hi = lo + rng.uniform(0.01, 0.8, 4)
        box = np.stack([lo, hi], axis=1).reshape(-1)
        enclosure = f.interval(box, params=params)
        samples = rng.uniform(lo, hi, size=(400, 4))
        values = f(samples, params=params)
        values = values[np.isfinite(values)]
        if values.size == 0:
            continue
        assert enclosure.lo <= values.min() and values.max() <= enclosure.hi, (text, box)


def test_interval_of_undefined_box_and_continuity():
    f = Formula("sqrt(x) = y")
    nowhere = f.interval([-2, -1, 0, 1, 0, 1, 0, 1])
    assert np.isnan(nowhere.lo) and np.isnan(nowhere.hi)
    inside = f.interval([1, 2, 0, 1, 0, 1, 0, 1])
    assert inside.continuous and 0.0 - 1 <= inside.lo
    assert not f.interval([-1, 1, 0, 1, 0, 1, 0, 1]).continuous
    with pytest.raises(ValueError, match="the z range"):
        f.interval([0, 1, 0, 1, 1, 0, 0, 1])
    with pytest.raises(ValueError, match="8 numbers"):
        f.interval([0, 1])


def test_parameters_missing_warn_and_unknown_are_refused():
    f = Formula("x^2 + y^2 + z^2 + w^2 = R")
    with pytest.warns(UserWarning, match=re.escape("parameter R has no value; using 1.0")):
        assert f([0, 0, 0, 1]).item() == 0.0
    with pytest.raises(ValueError, match="the formula has no parameter Q"):
        f([0, 0, 0, 1], params={"R": 1, "Q": 2})
    with pytest.raises(TypeError, match=r"params\['R'\]: expected a number"):
        f([0, 0, 0, 1], params={"R": "two"})


def test_bad_points_say_what_shape_they_need():
    f = Formula("x = 0")
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 4\)"):
        f(np.zeros((3, 3)))
    with pytest.raises(TypeError, match="all four"):
        f(1, 2)
    with pytest.raises(ValueError, match="broadcast"):
        f(np.zeros(3), np.zeros(4), 0, 0)
    with pytest.raises(TypeError):
        Formula(42)
