"""The notebook explorer: sliders for the angles and parameters redraw the picture."""

import fourfold
import fourfold.widget


def test_sliders_redraw_the_picture():
    e = fourfold.explore("x^2 + y^2 + z^2 + w^2 = R", size=(48, 48), params={"R": 0.8})
    first = bytes(e.image.value)
    assert first.startswith(b"\x89PNG") and "frame" in e.status.value
    assert [s.description for s in e.angles] == ["θ1", "θ2", "θ3", "θ4", "θ5", "θ6"]
    assert list(e.params) == ["R"] and e.params["R"].value == 0.8
    e.angles[3].value = 0.7
    assert e.scene.angles[3] == 0.7 and bytes(e.image.value) != first
    second = bytes(e.image.value)
    e.params["R"].value = 0.3
    assert e.scene.params == {"R": 0.3} and bytes(e.image.value) != second


def test_a_failed_picture_is_said_and_the_last_one_stays(monkeypatch):
    e = fourfold.explore("x^2 + y^2 + z^2 + w^2 = 1", size=(32, 32))
    kept = bytes(e.image.value)

    def lost(_scene):
        raise fourfold.RenderError("the GPU device was lost")

    monkeypatch.setattr(fourfold.widget, "render", lost)
    e.angles[0].value = 0.5
    assert e.status.value == "not drawn: the GPU device was lost"
    assert bytes(e.image.value) == kept
