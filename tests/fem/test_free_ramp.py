"""The free 3D ramp's solver choices against the ones they replace: the same answers within the tolerance.

The cubic predictor of :class:`~pneumorph.models.fe.Full3D` and the kept rising steps of a kept tangent
(:data:`pneumorph.fem.fast.newton.RISE`) change only the path of Newton's method, so a ramp must end every level
at the equilibrium the quadratic predictor, taking every rising step back, reaches: both stop at a relative
residual below 1e-8, which leaves the states free to differ by about 1e-8 of the displacements (tens of mm).
"""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.fem.fast import newton
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D


def test_kept_rises_and_cubic_predictor_reach_the_same_levels(monkeypatch: pytest.MonkeyPatch) -> None:
    kept = []
    rule = newton.kept_rise

    def counted(norm_new: float, norm: float, jmin: float) -> bool:
        kept.append(rule(norm_new, norm, jmin))
        return kept[-1]

    monkeypatch.setattr(newton, "kept_rise", counted)
    unit = UnitSpec(element_size=3.0)
    new = Full3D(3, unit=unit).evaluate("000")
    assert sum(kept) >= 1  # the rule was used: a rising step kept, the tangent refreshed at its end

    monkeypatch.setattr(newton, "RISE", 1.0)  # every rising step taken back, as before
    old_model = Full3D(3, unit=unit)
    old_model.free_predictor_order = 2
    old = old_model.evaluate("000")
    assert abs(new.curl[-1]) > 45.0  # a real bending (58 degrees)
    np.testing.assert_allclose(new.tip, old.tip, rtol=0, atol=1e-6)
    np.testing.assert_allclose(new.centres, old.centres, rtol=0, atol=1e-6)
    np.testing.assert_allclose(new.curl, old.curl, rtol=0, atol=1e-5)
