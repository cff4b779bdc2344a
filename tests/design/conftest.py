"""Fixtures shared by the design tests."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.chain.fit import build_table
from pneumorph.models.chain.model import ChainModel, design_strings
from pneumorph.models.fe import RampSpec, Reduced2D

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
