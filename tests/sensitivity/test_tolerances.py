"""Mould tolerances: seeded samples, the extremes of appendix E.2, and corners that bracket the samples' curl."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.errors import GeometryError, SettingsError
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D, RampSpec
from pneumorph.sensitivity import FIELDS, MACHINED, PRINTED, Tolerance, perturbed


def test_samples_are_seeded_reproducible_and_within_the_class() -> None:
    t = Tolerance(PRINTED)
    a, b, c = t.samples(30, seed=1), t.samples(30, seed=1), t.samples(30, seed=2)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    assert a.shape == (30, 3) and np.abs(a).max() <= PRINTED
    assert np.abs(Tolerance(MACHINED).samples(30, seed=1)).max() <= MACHINED
    # uniform in [-t, t]: mean near 0, standard deviation near t / sqrt(3)
    big = t.samples(20_000, seed=3)
    assert abs(big.mean()) < 0.002 and big.std() == pytest.approx(PRINTED / np.sqrt(3), rel=0.02)


def test_extremes_and_corners() -> None:
    t = Tolerance(0.02)
    ext = t.extremes()
    assert ext.shape == (6, 3) and (np.count_nonzero(ext, axis=1) == 1).all()
    assert sorted(np.abs(ext).sum(axis=0).tolist()) == [0.04, 0.04, 0.04]
    corners = t.corners()
    assert corners.shape == (8, 3) and len({tuple(c) for c in corners}) == 8 and (np.abs(corners) == 0.02).all()


def test_perturbed_units_and_bad_tolerances() -> None:
    unit = perturbed(UnitSpec(), FIELDS, np.array([0.078, 0.097, -0.09]))  # Table E.1, minimum curl
    assert (unit.side_wall, unit.wall, unit.layer) == (1.578, 1.597, 2.91)
    with pytest.raises(GeometryError):
        perturbed(UnitSpec(), ("wall",), np.array([-1.5]))
    for bad in (-0.1, float("nan"), "0.1", 2.0):
        with pytest.raises(SettingsError):
            Tolerance(bad)  # type: ignore[arg-type]
    with pytest.raises(SettingsError, match="unknown unit thickness"):
        Tolerance(0.1, ("side_wall", "colour"))


@pytest.mark.slow
def test_the_corners_bracket_the_curl_of_random_samples() -> None:
    t = Tolerance(PRINTED)
    base = UnitSpec(element_size=3.0)
    ramp = RampSpec(pressure=0.03)

    def curl(offsets: np.ndarray) -> float:
        model = Full3D(2, perturbed(base, t.fields, offsets), ramp)
        return float(model.evaluate("00").curl[-1])

    corners = [curl(c) for c in t.corners()]
    samples = [curl(s) for s in t.samples(4, seed=0)]
    assert min(corners) < min(samples) and max(samples) < max(corners)
    # thinner walls bend more, as Table E.1 found
    thin, thick = curl(np.array([-PRINTED, -PRINTED, 0.0])), curl(np.array([PRINTED, PRINTED, 0.0]))
    assert thin > thick


def test_every_unit_of_a_tolerance_box_is_meshed_alike() -> None:
    from dataclasses import replace

    from pneumorph.sensitivity.tolerances import _grid_shape, matched_element_size

    unit = UnitSpec()
    for tolerance in (Tolerance(PRINTED), Tolerance(MACHINED)):
        size = matched_element_size(unit, tolerance)
        assert unit.element_size <= size < 1.2 * unit.element_size
        shapes = {_grid_shape(perturbed(replace(unit, element_size=size), FIELDS, o))
                  for o in np.vstack([tolerance.corners(), tolerance.samples(5, seed=0)])}
        # one topology, and the nominal unit's own (the reference is the design model's mesh)
        assert shapes == {_grid_shape(unit)}
    # at the unit's own size a thicker layer gains a row of elements across the whole actuator
    assert _grid_shape(perturbed(unit, FIELDS, np.array([0.0, 0.0, 0.1]))) != _grid_shape(unit)
