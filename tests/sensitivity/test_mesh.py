"""Mesh convergence: Richardson extrapolation and the observed order (closed forms), and a real refinement."""

import math
from typing import Any

import numpy as np
import pytest

from pneumorph.errors import SettingsError
from pneumorph.geometry.library import UnitLibrary, builtin_library
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D, Reduced2D
from pneumorph.sensitivity.mesh import (
    SAFETY_THREE,
    SAFETY_TWO,
    MeshPoint,
    MeshStudy,
    converge,
    refined,
    representative_size,
)


@pytest.mark.parametrize("p", [0.7, 1.0, 2.0, 3.5])
@pytest.mark.parametrize("sizes", [(1.5, 1.0, 0.75), (2.0, 1.0, 0.5), (1.5, 0.89, 0.75)])
def test_three_meshes_recover_order_and_limit(p: float, sizes: tuple[float, ...]) -> None:
    """f(h) = f* + C h^p through three meshes of any ratios: the order and limit are recovered exactly and the
    error estimate is Fs times the distance of the finest value from the limit."""
    f_star, c = 7.25, -0.4
    values = [f_star + c * h**p for h in sizes]
    conv = converge(sizes, values)
    assert conv.method == "three meshes"
    assert conv.order == pytest.approx(p, rel=1e-8)
    assert conv.extrapolated == pytest.approx(f_star, abs=1e-9)
    assert conv.error == pytest.approx(SAFETY_THREE * abs(values[-1] - f_star), rel=1e-6)


def test_only_the_three_finest_meshes_count() -> None:
    sizes = (4.0, 2.0, 1.0, 0.5)
    values = [1.0 + 5.0, *[1.0 + 0.5 * h**2 for h in sizes[1:]]]  # the coarsest is off the asymptotic curve
    assert converge(sizes, values).extrapolated == pytest.approx(1.0)


def test_two_meshes_with_an_assumed_order() -> None:
    conv = converge((1.5, 0.75), (3.0 + 1.5**1.5, 3.0 + 0.75**1.5), order=1.5)
    assert conv.extrapolated == pytest.approx(3.0)
    assert conv.error == pytest.approx(SAFETY_TWO * 0.75**1.5)
    assert converge((1.5, 0.75), (1.0, 2.0)).method == "two meshes, no order"


def test_oscillating_values_have_no_order() -> None:
    conv = converge((1.5, 1.0, 0.75), (1.0, 1.4, 1.2))
    assert conv.order is None and conv.extrapolated is None
    assert conv.error == pytest.approx(0.4)


@pytest.mark.parametrize("sizes", [(1.0, 1.5), (1.5, 1.5), (1.5, -1.0)])
def test_sizes_must_decrease(sizes: tuple[float, ...]) -> None:
    with pytest.raises(SettingsError, match="decrease"):
        converge(sizes, (1.0, 2.0))


def test_nan_values_refused() -> None:
    with pytest.raises(SettingsError, match="finite"):
        converge((1.5, 0.75), (1.0, math.nan))


def test_representative_size_of_nested_meshes_halves() -> None:
    """Halving the element size of the built-in unit divides every cell (grid lines stay): 8 times the cells,
    half the representative size, the same volume."""
    model = Full3D(2)
    coarse, fine = refined(model, 1.5).mesh("01"), refined(model, 0.75).mesh("01")
    assert len(fine.cells) == 8 * len(coarse.cells)
    assert representative_size(coarse) == pytest.approx(2 * representative_size(fine))
    assert representative_size(coarse) == pytest.approx(1.5)
    assert refined(model, 0.75).fingerprint() != model.fingerprint()
    assert refined(model, 1.5).fingerprint() == model.fingerprint()


def test_refined_library_model_refines_every_unit() -> None:
    from pneumorph.geometry.library import builtin_library

    model = Full3D(2, library=builtin_library())
    fine = refined(model, 0.75)
    assert {u.element_size for u in fine.library.units} == {0.75}
    assert len(fine.mesh("aR").cells) == 8 * len(model.mesh("aR").cells)


@pytest.mark.slow
def test_a_short_actuator_converges_at_its_observed_order() -> None:
    """The 2D section of one unit on four nested meshes (1.5 to 0.1875 mm): the order observed on the three
    coarsest holds on the three finest (the solution is in the asymptotic range), and the Richardson limit
    of the coarse three predicts the fine three's within its error estimate."""
    base = Reduced2D(1)
    sizes, curls, tips = [], [], []
    for h in (1.5, 0.75, 0.375, 0.1875):
        model = refined(base, h)
        r = model.evaluate("0")
        sizes.append(representative_size(model.mesh("0")))
        curls.append(float(r.curl[-1]))
        tips.append(float(r.tip[-1, 1]))
    np.testing.assert_allclose(sizes, [1.5, 0.75, 0.375, 0.1875])
    for values in (curls, tips):
        coarse, fine = converge(sizes[:3], values[:3]), converge(sizes[1:], values[1:])
        assert coarse.order is not None and fine.order is not None
        # re-entrant cavity corners limit quadratic elements to well below their smooth-solution order
        assert 1.0 < coarse.order < 2.5 and 1.0 < fine.order < 2.5
        assert abs(coarse.order - fine.order) < 0.3
        assert coarse.extrapolated is not None and fine.extrapolated is not None
        assert abs(coarse.extrapolated - fine.extrapolated) < coarse.error
        assert fine.error < coarse.error


def test_study_convergence_from_points() -> None:
    pts = tuple(MeshPoint("01", h, h, 10, 30, (100.0 - h**2, 5.0), 20.0 + h, 7.0 + 0.1 * h**2, 36.0, 1.0)
                for h in (1.5, 1.0, 0.75))
    study = MeshStudy((*pts, MeshPoint("10", 1.5, 1.5, 10, 30, None, None, None, None, 1.0, "diverged")),
                      "sin")
    assert study.designs == ["01", "10"]
    assert study.convergence("01", "value").extrapolated == pytest.approx(7.0)
    assert study.convergence("01", "tip_x").order == pytest.approx(2.0)
    assert study.convergence("10", "curl") is None
    doc = study.to_dict()
    assert doc["convergence"]["01"]["curl"]["order"] == pytest.approx(1.0)
    with pytest.raises(SettingsError, match="unknown quantity"):
        study.convergence("01", "volume")


def test_memory_check_before_meshing() -> None:
    from pneumorph.geometry.limits import MeshLimitError
    from pneumorph.sensitivity.mesh import check_refinement

    model = Full3D(15)
    nodes, peak = check_refinement(model, [1.0], memory=10**12)[1.0]
    assert nodes > 4 * check_refinement(model, [1.5], memory=10**12)[1.5][0]
    assert check_refinement(model, [1.5, 1.0], memory=int(1.01 * peak))[1.0] == (nodes, peak)
    with pytest.raises(MeshLimitError, match=r"x 2 at once.*fewer workers"):
        check_refinement(model, [1.0], parallel=2, memory=int(1.5 * peak))
    with pytest.raises(MeshLimitError, match=r"element size 0\.75 mm"):
        check_refinement(model, [1.5, 0.75], memory=int(1.01 * peak))


@pytest.mark.parametrize(("model", "large"), [
    (Full3D(15, library=builtin_library("spatial")), "l"),  # the sideways unit: meshed across the whole width
    (Reduced2D(15, library=UnitLibrary(("a", "b"), (UnitSpec(), UnitSpec(pitch=31.5, name="long")))), "b")])
def test_a_librarys_refinement_is_estimated_from_its_largest_unit_type(model: Any, large: str) -> None:
    """An actuator of the library's largest type is a design too: its mesh, not the nominal unit's, is the cost."""
    from dataclasses import replace

    from pneumorph.geometry.limits import MeshLimitError
    from pneumorph.geometry.meshsize import estimate_mesh
    from pneumorph.sensitivity.mesh import check_refinement

    def mesh(spec: UnitSpec) -> tuple[int, int]:
        e = estimate_mesh(replace(spec, element_size=0.75), 15, model.dim, model.half)
        return e.nodes, e.bytes

    nominal, largest = mesh(model.unit), mesh(model.library[large])
    assert largest[0] > 1.5 * nominal[0]
    assert check_refinement(model, [0.75], memory=10**12) == {0.75: largest}
    with pytest.raises(MeshLimitError, match=rf"^element size 0\.75 mm, unit type '{large}' "):
        check_refinement(model, [0.75], memory=(nominal[1] + largest[1]) // 2)  # the nominal unit's would fit
