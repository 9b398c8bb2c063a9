"""Type stubs of the Rust half of the package (python/src/); the Pythonic API is in
__init__.py."""

import os
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

class FormulaError(ValueError):
    """A formula that does not parse: str() is `fourfold check`'s caret message."""

    message: str
    hint: Optional[str]
    formula: str
    start: int
    end: int
    line: int
    column: int

class RenderError(RuntimeError):
    """Drawing failed for a reason that is not the caller's value (no GPU, a lost device)."""

class Formula:
    def __init__(self, text: str) -> None: ...
    @property
    def text(self) -> str: ...
    @property
    def f(self) -> str: ...
    @property
    def parameters(self) -> list[str]: ...
    def gradient(self) -> tuple[str, str, str, str]: ...
    def derivative(self, variable: str) -> str: ...
    def _values(
        self, points: npt.NDArray[np.float64], params: Optional[dict[str, float]] = None
    ) -> tuple[npt.NDArray[np.float64], list[str]]: ...
    def _gradients(
        self, points: npt.NDArray[np.float64], params: Optional[dict[str, float]] = None
    ) -> tuple[npt.NDArray[np.float64], list[str]]: ...
    def _interval(
        self, bounds: Sequence[float], params: Optional[dict[str, float]] = None
    ) -> tuple[tuple[float, float], bool, list[str]]: ...

class Scene:
    """Everything a scene file holds, and the picture's size. Attributes and keyword
    arguments are named as the command line's flags."""

    formula: str
    description: str
    params: dict[str, float]
    domain: list[float]
    angles: list[float]
    zoom: float
    pan: list[float]
    slice: Optional[float]
    slab: Optional[tuple[float, float]]
    size: tuple[int, int]
    rays: int
    hits: int
    steps: int
    bisection_iters: int
    approximation: float
    seed: int
    alpha: float
    sampling: str
    background: str
    colour_by: str
    color_by: str
    certified: bool
    cert_budget: int
    undecided: str
    brute_force: bool
    silhouette: bool
    border: bool
    lighting: bool
    max_level: int
    min_level: int
    node_budget: int
    def __init__(self, formula: Union[str, Formula], **settings: Any) -> None: ...
    @staticmethod
    def load(path: Union[str, os.PathLike[str]]) -> Scene: ...
    @staticmethod
    def from_toml(text: str, name: str = "<string>") -> Scene: ...
    @staticmethod
    def from_link(link: str, strict: bool = True) -> Scene: ...
    @staticmethod
    def example(name: str) -> Scene: ...
    def to_toml(self) -> str: ...
    def save(self, path: Union[str, os.PathLike[str]]) -> None: ...
    def link(self, base: str = "") -> str: ...
    def replace(self, **settings: Any) -> Scene: ...
    def copy(self) -> Scene: ...
    def __getitem__(self, path: str) -> Any: ...
    def __setitem__(self, path: str, value: Any) -> None: ...
    def _repr_png_(self) -> bytes: ...

class Mesh:
    @property
    def vertices(self) -> npt.NDArray[np.float64]: ...
    @property
    def faces(self) -> npt.NDArray[np.uint32]: ...
    @property
    def volume(self) -> float: ...
    @property
    def bounds(self) -> tuple[list[float], list[float]]: ...
    @property
    def stats(self) -> dict[str, float]: ...
    @property
    def build_ms(self) -> float: ...
    def save(self, path: Union[str, os.PathLike[str]], scale: float = 1.0) -> None: ...
    def __len__(self) -> int: ...

def render(
    scene: Scene, fit: bool = False, cpu: Optional[bool] = None
) -> tuple[npt.NDArray[np.uint8], Optional[npt.NDArray[np.uint8]], str, Scene]: ...
def wgsl(scene: Scene) -> str: ...
def png(rgba: npt.NDArray[np.uint8]) -> bytes: ...
def tree(
    scene: Scene,
) -> tuple[
    npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.uint32], npt.NDArray[np.bool_], str
]: ...
def animate(
    scene: Scene,
    path: Union[str, os.PathLike[str]],
    turn: Optional[str] = None,
    sweep: Optional[str] = None,
    slice_sweep: Optional[str] = None,
    frames: int = 60,
    fps: float = 24.0,
    fit: bool = False,
    cpu: bool = False,
    progress: Optional[Callable[[int, int], Any]] = None,
) -> str: ...
def mesh(
    scene: Scene,
    slice: Optional[float] = None,
    max_level: int = ...,
    tolerance: Optional[float] = None,
    open: bool = False,
) -> Mesh: ...
def critical(scene: Scene, max_level: int = ..., budget: int = ..., boundary: bool = True) -> str: ...
def examples() -> list[tuple[str, str]]: ...
def is_link(text: str) -> bool: ...
