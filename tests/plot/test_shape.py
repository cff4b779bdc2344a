"""The shape figure of a 2D solve (:func:`pneumorph.plot.shape.plot_shape`): its legend is one, the first section's,
at a fixed place outside every section, so it covers no part of the actuator and clears the provenance line."""

from __future__ import annotations

import pytest
from matplotlib.legend import Legend

from pneumorph.models.fe import Reduced2D
from pneumorph.plot.shape import plot_shape

DESIGN = "0110"


@pytest.fixture(scope="module")
def solution() -> object:
    return Reduced2D(len(DESIGN)).solve(DESIGN)


def _overlap(a: object, b: object) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1  # type: ignore[attr-defined]


@pytest.mark.parametrize("levels", [[9], [4, 9]])
def test_the_legend_is_outside_the_sections_at_a_fixed_place(solution: object, levels: list[int]) -> None:
    fig = plot_shape(solution, levels=levels)
    assert [ax.get_legend() for ax in fig.axes] == [None] * len(levels)
    (legend,) = fig.legends
    assert isinstance(legend, Legend) and legend._loc != 0  # not "best": no search over the cells' polygons
    assert [t.get_text() for t in legend.get_texts()] == ["body", "stiff layer", "filler (2D model)", "unit centres"]
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    box = legend.get_window_extent(renderer)
    assert not any(_overlap(box, ax.get_window_extent(renderer)) for ax in fig.axes)
    (provenance,) = [t for t in fig.texts if t.get_text().startswith("pneumorph ")]
    assert not _overlap(box, provenance.get_window_extent(renderer))
    assert 0 <= box.x0 and box.x1 <= fig.bbox.x1 and 0 <= box.y0  # whole, inside the figure
