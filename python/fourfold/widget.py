"""An interactive picture for Jupyter: the six angles and the formula's parameters as
sliders, the picture drawn again when one is let go (needs ipywidgets)."""

from __future__ import annotations

import math
from typing import Any

from . import RenderError, Scene, _scene, render


class Explorer:
    """The widget's parts: `scene` (what is shown now), `angles` and `params` (the
    sliders, by name), `image`, `status`, and `box`, the widget to display."""

    def __init__(self, scene: Scene, formula_parameters: list[str]) -> None:
        import ipywidgets as w

        self.scene = scene
        self.image = w.Image(format="png")
        self.status = w.Label()
        self.angles = [
            w.FloatSlider(
                value=a,
                min=-math.pi,
                max=math.pi,
                step=0.01,
                description=f"θ{i + 1}",
                continuous_update=False,
            )
            for i, a in enumerate(scene.angles)
        ]
        self.params = {}
        for name in formula_parameters:
            value = scene.params.get(name, 1.0)
            reach = max(1.0, 2 * abs(value))
            self.params[name] = w.FloatSlider(
                value=value,
                min=value - reach,
                max=value + reach,
                step=reach / 200,
                description=name,
                continuous_update=False,
            )
        for slider in self.angles + list(self.params.values()):
            slider.observe(self.redraw, names="value")
        columns = [w.VBox(self.angles)]
        if self.params:
            columns.append(w.VBox(list(self.params.values())))
        self.box = w.VBox([self.image, w.HBox(columns), self.status])
        self.redraw()

    def redraw(self, _change: Any = None) -> None:
        """Draws the scene at the sliders' values; a value the scene refuses, or a picture
        that fails, is said under the picture and the last picture stays."""
        try:
            self.scene = self.scene.replace(
                angles=[s.value for s in self.angles],
                params={**self.scene.params, **{n: s.value for n, s in self.params.items()}},
            )
            picture = render(self.scene)
        except (ValueError, RenderError) as e:
            self.status.value = f"not drawn: {e}"
            return
        self.image.value = picture.png()
        t = picture.info["times_ms"]
        self.status.value = f"{picture.adapter}: frame {t['frame']:.0f} ms"

    def _ipython_display_(self) -> None:
        from IPython.display import display

        display(self.box)


def explore(scene: Any, /, *, size: tuple[int, int] = (384, 384), **settings: Any) -> Explorer:
    """A picture of `scene` with sliders for the view's six angles and the formula's
    parameters (in a notebook: `fourfold.explore("x^2 + y^2 + z^2 + w^2 = R")`)."""
    try:
        import ipywidgets  # noqa: F401
    except ImportError:
        raise ImportError("explore() needs ipywidgets: pip install ipywidgets") from None
    from . import Formula

    s = _scene(scene, {**settings, "size": size})
    return Explorer(s, Formula(s.formula).parameters)
