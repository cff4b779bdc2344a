"""A chain table build that survives designs which do not converge: fitted to the levels every design reached."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from pneumorph.errors import ChainTableError, SimulationFailed
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.chain.fit import build_table
from pneumorph.models.chain.levels import first_levels, levels_reached
from pneumorph.models.chain.model import check_source, source_key
from pneumorph.models.chain.sources import cut_from, serve_table, served_as_built, table_file
from pneumorph.models.chain.training import training_designs
from pneumorph.models.chain.validation import heldout_designs
from pneumorph.models.fe import RampSpec, Reduced2D
from pneumorph.models.response import Response

COARSE = UnitSpec(element_size=3.0)
RAMP = RampSpec(pressure=0.02)
#: a covering design of window +-1 that stops after level 6, a held-out design that stops after level 4
COVERING = training_designs(7, 1, False, False)[0]
HELDOUT = heldout_designs(7, 6, exclude=training_designs(7, 1, False, False), seed=1)[2]
STOPS = {COVERING: 6, HELDOUT: 4}


class StopsEarly(Reduced2D):
    """The real coarse 2D model, except that the designs of :data:`STOPS` fail after their level (the levels
    before it are the real model's, NaN after, as a failed ramp reports them)."""

    stops: dict[str, int] = STOPS

    def evaluate(self, orientation: Any, on_level: Any = None) -> Response:
        response = super().evaluate(orientation, on_level)
        m = self.stops.get(response.orientation)
        if m is None:
            return response
        cut = {name: getattr(response, name).copy() for name in ("centres", "tip", "curl")}
        for values in cut.values():
            values[m:] = np.nan
        partial = replace(response, **cut, converged=False, reached=float(response.pressures[m - 1]))
        raise SimulationFailed(reached=(m + 0.5) / response.n_levels, cause="no convergence (forced)",
                               design=response.orientation, pressure=self.ramp.pressure, partial=partial)


@pytest.fixture(scope="module")
def builds() -> tuple[Any, Any, Any, Any]:
    """Tables of the same model and designs: every design converged, and two designs stopping early."""
    full_model, stopping = Reduced2D(7, COARSE, RAMP), StopsEarly(7, COARSE, RAMP)
    assert source_key(full_model) == source_key(stopping)
    full = build_table(full_model, CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:")), window=1,
                       heldout=6)
    lines: list[str] = []
    cut = build_table(stopping, CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:")), window=1,
                      heldout=6, on_progress=lines.append)
    return full_model, full, cut, lines


def test_the_table_keeps_the_levels_every_design_reached(builds) -> None:  # type: ignore[no-untyped-def]
    model, full, cut, lines = builds
    assert HELDOUT in full.validation["designs"]  # the held-out design that stops early is validated
    # the held-out design stopped at level 4, below the covering design's 6: the table was fitted again to 4
    assert cut.n_levels == 4 and np.allclose(cut.pressures, model.pressures()[:4], rtol=0, atol=1e-15)
    # the same designs' first 4 levels: the entries of the full table at those levels, exactly
    assert np.array_equal(cut.turn, full.turn[:, :4]) and np.array_equal(cut.length, full.length[:, :4])
    assert cut.validation["centre_worst_mm"] == pytest.approx(full.validation["centre_worst_mm"][:4], abs=1e-12)
    assert cut.source["cut_from"] == {"key": source_key(model), "levels": 10, "pressure_mpa": 0.02,
                                      "why": "every design reached (2 did not converge beyond)",
                                      "failed": dict(sorted(STOPS.items()))}
    assert any(f"{COVERING} to level 6 of 10 only" in line for line in lines)
    assert any("fitted to the first 4 level(s), 2-8 kPa of the ramp's 10 (up to 20 kPa), those every design "
               "reached (2 did not converge beyond)" in line for line in lines)


def test_a_cut_table_serves_its_model_at_its_levels(builds, tmp_path) -> None:  # type: ignore[no-untyped-def]
    model, _full, cut, _lines = builds
    assert cut_from(cut, model)
    with pytest.raises(ChainTableError, match="another model"):
        check_source(cut, model)  # not the full ramp's table
    served = served_as_built(cut, model)
    assert served.restricted and served.model.ramp.steps.increments == 4
    assert served.model.ramp.pressure == pytest.approx(0.008, abs=1e-15)
    check_source(cut, served.model)
    assert served.origin_text() == "fitted to the first 4 of 10 levels, those every design reached (2 did not " \
                                   "converge beyond)"
    # kept in a table folder under the full model's name: found again for the same model, at its levels
    cut.save(table_file(tmp_path, model))
    again = serve_table(model, tmp_path)
    assert again is not None and again.restricted and again.table.n_levels == 4
    assert np.allclose(again.model.pressures(), model.pressures()[:4], rtol=0, atol=1e-12)


def test_first_levels_refuses_levels_not_reached() -> None:
    r = Response.empty("0", np.array([0.01, 0.02]), np.zeros((1, 2)), np.zeros(2), converged=False)
    r.centres[0], r.tip[0], r.curl[0] = 1.0, 1.0, 5.0
    assert levels_reached(r) == 1
    with pytest.raises(ChainTableError, match="reached 1 level"):
        first_levels(r, 2)


@pytest.mark.slow
def test_the_widest_affordable_table_is_served_with_its_errors_stated() -> None:
    """The built-in library on 7 units: window +-2 needs at least 2801 covering solves, so +-1 is validated on
    every held-out design (no stop above the tolerance) and returned with its errors, not refused."""
    from pneumorph.models.chain.sources import limits_text
    from pneumorph.models.chain.validation import prediction_errors
    from pneumorph.models.factory import make_model

    model = make_model(7, {"fidelity": "2d", "library": "builtin", "pressure_kpa": 10})
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    lines: list[str] = []
    table = build_table(model, evaluator, tolerance=1e-6, heldout=6, on_progress=lines.append)
    val = table.validation
    assert table.window == 1 and val["beyond_tolerance"] is True and val["heldout_solved"] == 6
    assert val["stopped_early"] == "" and "2801 FE solves of 7-unit designs" in val["wider"]
    # the stated errors are the table's own against the six held-out FE responses
    responses = [o.response for o in evaluator.evaluate_many(model, val["designs"])]  # from the cache
    assert prediction_errors(table, responses)["centre_worst_mm"] == pytest.approx(val["centre_worst_mm"], abs=1e-12)
    assert limits_text(table).startswith(f"its worst held-out centre error {max(val['centre_worst_mm']):.3g} mm is "
                                         "above the tolerance 1e-06 mm")
    assert any("window +-2: not tried" in line for line in lines)
