"""Fixtures shared by the design tests."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.orientation import parse_orientation
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.chain.fit import build_table
from pneumorph.models.chain.model import ChainModel, design_strings
from pneumorph.models.fe import RampSpec, Reduced2D
from pneumorph.models.fe.base import FEModel
from tests.design.toy_model import ToyModel

#: units of the coarse 2D actuator of :func:`coarse_2d`
COARSE_UNITS = 6


@pytest.fixture(scope="session")
def coarse_2d() -> tuple[Reduced2D, ChainModel, CachedEvaluator]:
    """The real 2D model (coarse mesh, 25 kPa, 6 units), its chain (window +-2) and the evaluator that solved it."""
    model = Reduced2D(COARSE_UNITS, UnitSpec(element_size=3.0), RampSpec(pressure=0.025))
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    return model, ChainModel(build_table(model, evaluator, window=2, heldout=8), COARSE_UNITS), evaluator


def _keeps_every_design(every: Any, grown: Any) -> dict[str, float]:
    """Check a search forced past enumeration (``grown``) against the enumeration (``every``) of one chain.

    Every design whose enumerated cost lies below the grown search's threshold (its floor plus its
    greatest bound) is kept, with the same cost, and the best design is the same. Returns the
    enumerated costs by design.
    """
    assert every.complete and not grown.complete
    threshold = grown.floor + float(grown.bound.max())
    names = dict(zip(design_strings(every.bits), every.cost, strict=True))
    kept = dict(zip(design_strings(grown.bits), grown.cost, strict=True))
    must = {d for d, c in names.items() if c < threshold - 1e-9}
    assert must and must <= set(kept)
    assert all(abs(kept[d] - names[d]) < 1e-9 for d in kept)
    assert design_strings(grown.bits[grown.order()[:1]]) == design_strings(every.bits[every.order()[:1]])
    return names


@pytest.fixture
def keeps_every_design() -> Callable[[Any, Any], dict[str, float]]:
    """:func:`_keeps_every_design`, for tests of the branch-and-bound search."""
    return _keeps_every_design


@pytest.fixture
def solves(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> list[tuple[float, str]]:
    """The (element size, design) of every FE solve of the test, each answered by an analytical stand-in
    (:class:`tests.design.toy_model.ToyModel`, its turn grown with the element size so that two meshes differ); the
    evaluation cache in the test's folder."""
    seen: list[tuple[float, str]] = []

    def evaluate(self: FEModel, orientation: str, on_level: object = None) -> object:
        design = parse_orientation(orientation, self.n_units)
        size = float(self.unit.element_size)
        seen.append((size, design))
        p = self.pressures()
        toy = ToyModel(self.n_units, p_max=float(p[-1]), levels=len(p), turn=20.0 * (1.0 + 0.05 * size))
        return toy.evaluate(design)

    monkeypatch.setattr(FEModel, "evaluate", evaluate)
    monkeypatch.setenv("PNEUMORPH_CACHE", str(tmp_path / "cache.sqlite"))
    return seen
