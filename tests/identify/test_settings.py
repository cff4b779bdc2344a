"""The [model] settings of an identified model: the body's scaled moduli, checked like the other settings."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.errors import SearchConfigError, SettingsError
from pneumorph.geometry.unit import UnitSpec
from pneumorph.identify import ParameterSet
from pneumorph.models.factory import make_model


def test_scales_reach_the_body_and_only_the_body() -> None:
    nominal = make_model(3)
    scaled = make_model(3, {"body_bulk_scale": 1.06, "body_shear_scale": 0.9})
    assert scaled.body.bulk_modulus.value == pytest.approx(1.06 * nominal.body.bulk_modulus.value, rel=1e-12)
    assert scaled.body.shear_modulus == pytest.approx(0.9 * nominal.body.shear_modulus, rel=1e-12)
    assert scaled.layer.to_dict() == nominal.layer.to_dict()
    assert scaled.fingerprint() != nominal.fingerprint()
    # scales of 1 are the library's silicone: the same fingerprint, the same cache entries
    assert make_model(3, {"body_bulk_scale": 1.0, "body_shear_scale": 1}).fingerprint() == nominal.fingerprint()


@pytest.mark.parametrize("value", [0, -1.0, float("nan"), "1.1", True, 1001.0])
def test_bad_scales_are_refused(value: object) -> None:
    with pytest.raises(SearchConfigError, match="body_bulk_scale"):
        make_model(3, {"body_bulk_scale": value})


def test_every_unit_of_the_box_is_meshed_alike_and_keeps_the_filler_law() -> None:
    params = ParameterSet(UnitSpec(element_size=3.0))
    units = [params.unit_at(params.nominal + np.array(d)) for d in ([0, 0, 0.1, 0.1, -0.1], [0, 0, -0.1, -0.1, 0.1])]
    models = [make_model(4, {"unit": u.to_dict()}) for u in units]
    meshes = [m.build("0110")[0] for m in models]
    assert meshes[0].points.shape == meshes[1].points.shape and np.array_equal(meshes[0].cells, meshes[1].cells)
    assert models[0].filler == models[1].filler == make_model(4).filler  # the built-in unit's calibrated law
    with pytest.raises(SettingsError, match="outside the identification box"):
        params.unit_at(params.nominal + np.array([0, 0, 0, 0.11, 0]))
