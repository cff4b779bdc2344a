"""Fixtures shared by the design tests."""

from __future__ import annotations

import pytest

from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.chain import ChainModel
from pneumorph.models.chainfit import build_table
from pneumorph.models.fe import RampSpec, Reduced2D

#: units of the coarse 2D actuator of :func:`coarse_2d`
COARSE_UNITS = 6


@pytest.fixture(scope="session")
def coarse_2d() -> tuple[Reduced2D, ChainModel, CachedEvaluator]:
    """The real 2D model (coarse mesh, 25 kPa, 6 units), its chain (window +-2) and the evaluator that solved it."""
    model = Reduced2D(COARSE_UNITS, UnitSpec(element_size=3.0), RampSpec(pressure=0.025))
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    return model, ChainModel(build_table(model, evaluator, window=2, heldout=8), COARSE_UNITS), evaluator
