"""fourfold: see the 3-manifold F(x, y, z, w) = 0 in four dimensions, from Python.

Type a formula, get pictures, the 16-tree, the shader, animations, slice meshes and the
sweep's proved critical values as numpy arrays and plain values, made by the same code as
the `fourfold` command line (docs/python.md)::

    import fourfold
    picture = fourfold.render("x^2 + y^2 + z^2 + w^2 = 1", size=(256, 256), angles=[0.3, 0, 0, 0.5, 0, 0])
    picture.shape            # (256, 256, 4), uint8 RGBA; shown inline in Jupyter

Every function takes a formula, a `Scene`, a scene file's path or a share link, and the
scene's settings as keyword arguments named as the command line's flags (`rays`,
`max_level`, `colour_by`, ...). Long work releases the GIL and stops on Ctrl-C.
"""

from __future__ import annotations

import json
import os
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np

try:
    from . import _native
except ImportError as e:  # pragma: no cover - a source tree, not an installed package
    raise ImportError(
        "fourfold's compiled half (fourfold._native) is missing: install the package with "
        "`pip install ./python` from the repository, and run Python outside python/ so that "
        "the sources there do not hide the installed package"
    ) from e
from ._native import FormulaError, Mesh, RenderError, Scene, examples

__version__ = _native.__version__

__all__ = [
    "Formula",
    "Scene",
    "Picture",
    "Tree",
    "Mesh",
    "CriticalValues",
    "FormulaError",
    "RenderError",
    "render",
    "tree",
    "wgsl",
    "animate",
    "mesh",
    "critical",
    "explore",
    "examples",
    "EMPTY",
    "HIT",
    "UNDECIDED",
]

#: Certified pixels' verdicts, as in `Picture.verdicts`: F has no zero on the pixel's
#: observer plane (the background is right), F changes sign there (M is hit), or the
#: budget ran out first.
EMPTY, HIT, UNDECIDED = 0, 1, 2

SceneLike = Union[str, "os.PathLike[str]", "Formula", Scene]


def _warn_missing(missing: Sequence[str]) -> None:
    for name in missing:
        warnings.warn(
            f"parameter {name} has no value; using 1.0 (give params={{'{name}': VALUE}})",
            stacklevel=3,
        )


def _points(x: Any, y: Any, z: Any, w: Any) -> tuple[np.ndarray, tuple[int, ...]]:
    """Rows (x, y, z, w) and the shape of the result: from one array whose last axis has
    the four coordinates, or from four arrays broadcast together."""
    if y is None and z is None and w is None:
        p = np.asarray(x, dtype=np.float64)
        if p.ndim == 0 or p.shape[-1] != 4:
            raise ValueError(
                f"points: expected an array whose last axis holds x, y, z, w (shape (..., 4)), "
                f"got shape {p.shape}; or give four arrays f(x, y, z, w)"
            )
        return np.ascontiguousarray(p.reshape(-1, 4)), p.shape[:-1]
    if y is None or z is None or w is None:
        raise TypeError("give one (..., 4) array of points, or all four of x, y, z, w")
    try:
        arrays = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in (x, y, z, w)))
    except ValueError as e:
        raise ValueError(f"x, y, z, w do not broadcast together: {e}") from None
    shape = arrays[0].shape
    return np.ascontiguousarray(np.stack([a.reshape(-1) for a in arrays], axis=1)), shape


@dataclass(frozen=True)
class Enclosure:
    """A rigorous enclosure [lo, hi] of F over a box; `continuous`: F is defined and
    continuous on the whole box as far as the enclosures tell. An enclosure (nan, nan)
    means F is defined nowhere on the box."""

    lo: float
    hi: float
    continuous: bool

    def __contains__(self, value: float) -> bool:
        return self.lo <= value <= self.hi

    def __iter__(self):
        return iter((self.lo, self.hi))


class Formula(_native.Formula):
    """A formula F(x, y, z, w) = 0, parsed and differentiated.

    A formula that does not parse raises `FormulaError` (a `ValueError`) whose message is
    the caret message of `fourfold check`. `f(x, y, z, w)` evaluates F on numpy arrays
    (NaN where F is undefined); `f.grad(...)` evaluates ∇F; `f.interval(box)` encloses F
    over a box rigorously; `f.gradient()` and `f.derivative("x")` give the derivatives as
    text.
    """

    def __call__(self, x, y=None, z=None, w=None, *, params: Optional[dict] = None) -> np.ndarray:
        points, shape = _points(x, y, z, w)
        values, missing = self._values(points, params)
        _warn_missing(missing)
        return values.reshape(shape)

    def grad(self, x, y=None, z=None, w=None, *, params: Optional[dict] = None) -> np.ndarray:
        """∇F at the points, as an array of shape (..., 4): ∂F/∂x, ∂F/∂y, ∂F/∂z, ∂F/∂w."""
        points, shape = _points(x, y, z, w)
        values, missing = self._gradients(points, params)
        _warn_missing(missing)
        return values.reshape(shape + (4,))

    def interval(self, box: Sequence[float], *, params: Optional[dict] = None) -> Enclosure:
        """A rigorous enclosure of F over `box`: [x0, x1, y0, y1, z0, z1, w0, w1], or a (4, 2)
        array of (low, high) rows."""
        bounds = np.asarray(box, dtype=np.float64).reshape(-1)
        if bounds.shape != (8,):
            raise ValueError(
                f"box: expected 8 numbers x0, x1, y0, y1, z0, z1, w0, w1, got {bounds.size}"
            )
        (lo, hi), continuous, missing = self._interval([float(b) for b in bounds], params)
        _warn_missing(missing)
        return Enclosure(lo, hi, continuous)


def _count(name: str, value: Any) -> int:
    """A whole number from 0 up, or a clear error naming the argument."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name}: expected a whole number, got {type(value).__name__} {value!r}")
    if value < 0:
        raise ValueError(f"{name}={value}: a whole number from 0 up")
    return int(value)


def _scene(scene: SceneLike, settings: dict) -> Scene:
    """The scene a function is given (a formula, a Scene, a scene file, a share link) with
    `settings` applied."""
    if isinstance(scene, Scene):
        return scene.replace(**settings) if settings else scene
    if isinstance(scene, _native.Formula):
        return Scene(scene.text, **settings)
    if isinstance(scene, os.PathLike):
        return Scene.load(os.fspath(scene)).replace(**settings)
    if isinstance(scene, str):
        if _native.is_link(scene):
            return Scene.from_link(scene).replace(**settings)
        if scene.endswith(".toml") or os.path.isfile(scene):
            return Scene.load(scene).replace(**settings)
        return Scene(scene, **settings)
    raise TypeError(
        "expected a formula string, a Formula, a Scene, a scene file's path or a share link, "
        f"got {type(scene).__name__}"
    )


class Picture(np.ndarray):
    """A rendered picture: an (h, w, 4) uint8 RGBA array, with what its making says.

    `verdicts`: each pixel's verdict (EMPTY, HIT or UNDECIDED) as an (h, w) uint8 array, or
    None with `certified=False`; `counts` their numbers; `info` the adapter, the stage
    times, the tree's statistics; `scene` the scene as drawn (zoomed and centred with
    `fit=True`). Shown inline in Jupyter.
    """

    verdicts: Optional[np.ndarray]
    info: dict
    scene: Optional[Scene]

    def __new__(cls, rgba, verdicts=None, info=None, scene=None):
        obj = np.asarray(rgba, dtype=np.uint8).view(cls)
        obj.verdicts = verdicts
        obj.info = info or {}
        obj.scene = scene
        return obj

    def __array_finalize__(self, obj):
        self.verdicts = getattr(obj, "verdicts", None)
        self.info = getattr(obj, "info", {})
        self.scene = getattr(obj, "scene", None)

    @property
    def counts(self) -> Optional[dict]:
        """How many pixels are hit, empty and undecided (None with `certified=False`)."""
        return self.info.get("counts")

    @property
    def adapter(self) -> str:
        return self.info.get("adapter", "")

    def png(self) -> bytes:
        """The picture as a PNG file's bytes."""
        return bytes(_native.png(np.ascontiguousarray(self, dtype=np.uint8).view(np.ndarray)))

    def save(self, path: Union[str, "os.PathLike[str]"]) -> None:
        """Writes the picture as a PNG file."""
        with open(path, "wb") as f:
            f.write(self.png())

    def _repr_png_(self) -> Optional[bytes]:
        if self.ndim == 3 and self.shape[2] == 4 and self.dtype == np.uint8:
            return self.png()
        return None


def render(
    scene: SceneLike,
    /,
    *,
    size: Optional[tuple[int, int]] = None,
    fit: bool = False,
    cpu: Optional[bool] = None,
    **settings: Any,
) -> Picture:
    """Renders a picture, as `fourfold render` does: an RGBA `Picture` of shape (h, w, 4).

    `size` is (width, height) in pixels (the scene's, else 512 × 512); `fit` zooms and
    centres on the manifold; `cpu=True` draws on the CPU reference renderer instead of the
    GPU, `cpu=False` on the GPU; by default a slice the CPU draws sooner than a GPU could be
    opened for it (up to 2^17 pixels per thread of this machine) is drawn there, as by
    `fourfold render`.
    `settings` are the scene's keywords: `angles=[θ1, ..., θ6]`, `domain=[x0, x1, ..., w0,
    w1]`, `params={"R": 2.0}`, `rays`, `hits`, `background="#rrggbb"`, `slice=C`,
    `slab=(C, H)`, `colour_by="hidden"`, `certified=False` (the plain ray pencil: pictures are
    certified by default), `max_level`, ... (see `Scene`).
    """
    if size is not None:
        settings["size"] = size
    s = _scene(scene, settings)
    rgba, verdicts, info, drawn = _native.render(s, fit=fit, cpu=cpu)
    return Picture(rgba, verdicts, json.loads(info), drawn)


@dataclass
class Tree:
    """The 16-tree's leaves: `lows` and `highs` (n, 4) corners, `levels` (n,), `critical`
    (n,): whether 0 is in every partial derivative's enclosure there (F may have a
    critical point); `stats`: what `fourfold tree --json` prints."""

    lows: np.ndarray
    highs: np.ndarray
    levels: np.ndarray
    critical: np.ndarray
    stats: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.levels)

    def __repr__(self) -> str:
        return (
            f"<Tree: {len(self)} leaves, {self.stats.get('nodes')} nodes, levels "
            f"{self.stats.get('min_level')}..{self.stats.get('max_level')}>"
        )


def tree(scene: SceneLike, /, **settings: Any) -> Tree:
    """Builds the 16-tree, as `fourfold tree` does (`max_level`, `min_level`,
    `node_budget` and the other scene keywords apply)."""
    s = _scene(scene, settings)
    lows, highs, levels, critical, stats = _native.tree(s)
    return Tree(lows, highs, levels, critical, json.loads(stats))


def wgsl(scene: SceneLike, /, **settings: Any) -> str:
    """The complete WGSL shader, validated by naga, as `fourfold wgsl` prints it."""
    return _native.wgsl(_scene(scene, settings))


def _progress_bar(progress: Union[bool, Callable[[int, int], Any], None], total: int):
    """The callback that shows progress, and what closes it."""
    if callable(progress):
        return progress, lambda: None
    if not progress:
        return None, lambda: None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None, lambda: None
    # Opened at the first frame, so that a refused call shows no bar.
    bars = []

    def step(done: int, _total: int) -> None:
        if not bars:
            bars.append(tqdm(total=total, unit="frame"))
        bars[0].update(done - bars[0].n)

    def close() -> None:
        for bar in bars:
            bar.close()

    return step, close


def _range_text(value: Any, keyword: str) -> Optional[str]:
    """A range as the command line writes it, A..B (repr keeps every digit)."""
    if value is None or isinstance(value, str):
        return value
    try:
        a, b = value
        return f"{float(a)!r}..{float(b)!r}"
    except (TypeError, ValueError):
        raise TypeError(f"{keyword}: expected (A, B) or 'A..B', got {value!r}") from None


def animate(
    scene: SceneLike,
    path: Union[str, "os.PathLike[str]"],
    /,
    *,
    turn: Optional[str] = None,
    sweep: Union[str, tuple, None] = None,
    slice_sweep: Union[str, tuple, None] = None,
    frames: int = 60,
    fps: float = 24.0,
    size: Optional[tuple[int, int]] = None,
    fit: bool = False,
    cpu: bool = False,
    progress: Union[bool, Callable[[int, int], Any]] = True,
    **settings: Any,
) -> dict:
    """Draws an animation into `path` (.gif, an animated .png, or a folder of PNGs), as
    `fourfold animate` does, and says what it drew.

    `turn="xw"` (or "xw:2", "θ3"): the manifold turns in that plane; `sweep="R=1..2"` (or
    ("R", 1, 2)): a parameter moves; `slice_sweep=(-0.5, 0.5)`: a slice moves (frames are
    placed around its critical values). `progress`: a bar (tqdm, in a terminal or a
    notebook, if installed), False for none, or a callable(done, total). Ctrl-C stops after
    the frame being drawn and keeps the file with the frames so far.
    """
    if size is not None:
        settings["size"] = size
    s = _scene(scene, settings)
    if isinstance(sweep, tuple):
        if len(sweep) != 3:
            raise TypeError(f"sweep: expected (name, A, B) or 'NAME=A..B', got {sweep!r}")
        sweep = f"{sweep[0]}={_range_text(sweep[1:], 'sweep')}"
    frames = _count("frames", frames)
    if isinstance(fps, bool) or not isinstance(fps, (int, float, np.number)):
        raise TypeError(f"fps: expected a number, got {type(fps).__name__} {fps!r}")
    step, close = _progress_bar(progress, frames)
    try:
        summary = _native.animate(
            s,
            os.fspath(path),
            turn=turn,
            sweep=sweep,
            slice_sweep=_range_text(slice_sweep, "slice_sweep"),
            frames=frames,
            fps=float(fps),
            fit=fit,
            cpu=cpu,
            progress=step,
        )
    finally:
        close()
    return json.loads(summary)


def mesh(
    scene: SceneLike,
    /,
    *,
    slice: Optional[float] = None,
    max_level: Optional[int] = None,
    tolerance: Optional[float] = None,
    open: bool = False,
    **settings: Any,
) -> Mesh:
    """The slice at `slice` along n2 (the scene's own slice if left out) as a closed,
    outward-wound triangle `Mesh`, as `fourfold mesh` makes it: `.vertices` (n, 3),
    `.faces` (m, 3), `.volume`, `.save("out.stl")` (or .obj, .ply, .glb)."""
    s = _scene(scene, settings)
    kwargs: dict = {"slice": slice, "tolerance": tolerance, "open": open}
    if max_level is not None:
        kwargs["max_level"] = _count("max_level", max_level)
    return _native.mesh(s, **kwargs)


@dataclass
class CriticalValues:
    """The sweep's proved critical values: the places c along n2 where the slice can change
    its topology. `points`: each as `fourfold critical --json` gives it (`value` [lo, hi],
    `point`, `index` or None, `status`, `place`, `boxes`, `meaning`); `reach`: slices within
    ±reach meet the domain; `budget_spent`: the search ran out of boxes (the rest is
    undecided)."""

    points: list
    reach: float
    visited: int
    degenerate_boxes: int
    undecided_boxes: int
    budget_spent: bool

    @property
    def values(self) -> np.ndarray:
        """The middles of the values' enclosures, in order."""
        return np.array(sorted(0.5 * (p["value"][0] + p["value"][1]) for p in self.points))

    def __len__(self) -> int:
        return len(self.points)

    def __iter__(self):
        return iter(self.points)


def critical(
    scene: SceneLike,
    /,
    *,
    max_level: Optional[int] = None,
    budget: Optional[int] = None,
    boundary: bool = True,
    **settings: Any,
) -> CriticalValues:
    """The sweep's proved critical values along the view's n2, as `fourfold critical`
    finds them (`max_level` of the search's boxes, `budget` boxes at most, `boundary`: also
    on the domain's faces, where they meet, and its edges)."""
    s = _scene(scene, settings)
    kwargs: dict = {"boundary": boundary}
    if max_level is not None:
        kwargs["max_level"] = _count("max_level", max_level)
    if budget is not None:
        kwargs["budget"] = _count("budget", budget)
    return CriticalValues(**json.loads(_native.critical(s, **kwargs)))


def explore(scene: SceneLike, /, *, size: tuple[int, int] = (384, 384), **settings: Any):
    """In a notebook: the picture with sliders for the view's six angles and the formula's
    parameters, drawn again when a slider is let go (needs ipywidgets)."""
    from .widget import explore as make

    return make(scene, size=size, **settings)
