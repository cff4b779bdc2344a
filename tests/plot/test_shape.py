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


def test_a_3d_figure_names_its_obstacles_in_a_legend() -> None:
    """The 3D figure (here of an unloaded 2-unit mesh at two levels, no solve) has the 2D figure's legend for its
    obstacles: each named with its force at the last level drawn and that level's pressure; without obstacles, none."""
    from types import SimpleNamespace

    import numpy as np

    from pneumorph.geometry.assembly import assemble
    from pneumorph.geometry.unit import UnitSpec

    mesh = assemble(UnitSpec(), "00", dim=3, half=True)
    contact = {"obstacles": [{"kind": "plane", "point": [40.0, 0.0, 0.0], "normal": [-1.0, 0.0, 0.0]},
                             {"kind": "sphere", "centre": [20.0, 30.0, 0.0], "radius": 3.0}],
               "levels": [{"obstacles": [{"force_magnitude_n": 0.0}, {"force_magnitude_n": 0.0}]},
                          {"obstacles": [{"force_magnitude_n": 0.25}, {"force_magnitude_n": 0.0}]}]}
    response = SimpleNamespace(n_levels=2, pressures=np.array([0.015, 0.03]), curl=np.zeros(2), orientation="00",
                               metadata={"fidelity": "3d", "contact": contact})
    solution = SimpleNamespace(response=response, mesh=mesh, displacements=np.zeros((2, *mesh.points.shape)))
    fig = plot_shape(solution, levels=[0, 1])
    (legend,) = fig.legends
    assert [t.get_text() for t in legend.get_texts()] == ["obstacle 1: 0.25 N at 30 kPa", "obstacle 2: 0 N at 30 kPa"]
    assert [ax.get_legend() for ax in fig.axes] == [None, None]
    response.metadata = {"fidelity": "3d"}
    assert plot_shape(solution).legends == []
