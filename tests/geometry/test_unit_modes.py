"""Units with a bottom wall of another material, and the built-in library ``modes`` (bimodal, low-bending)."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.bimodal.switch import find_switch
from pneumorph.errors import GeometryError, UnknownMaterialError
from pneumorph.fem import StepSettings
from pneumorph.geometry.assembly import assemble
from pneumorph.geometry.library import builtin_library, check_joinable
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D

MODES = builtin_library("modes")


def _volumes(mesh, region: str) -> float:
    """Total volume of a region's cells (axis-aligned boxes in the reference mesh), mm^3 (mm^2 in 2D)."""
    x = mesh.points[mesh.cells[mesh.regions[region]]]
    return float(np.prod(x.max(axis=1) - x.min(axis=1), axis=1).sum())


def test_library_modes_joins_and_keeps_the_builtin_unit():
    assert MODES.symbols == ("a", "b", "m")
    assert MODES["a"] == UnitSpec()
    check_joinable(dict(zip(MODES.symbols, MODES.units, strict=True)))
    # neither new type is its own mirror: the composite or the stiff bottom wall is on one side only
    assert not MODES["b"].symmetric and not MODES["m"].symmetric
    assert MODES["b"].height == MODES["m"].height == UnitSpec().height == 12.0


def test_default_descriptions_do_not_change():
    """The new field is left out at its default: the built-in unit's and library's fingerprints stay as they were."""
    assert "bottom_material" not in UnitSpec().to_dict()
    model = Full3D(15, library=builtin_library())
    assert model.bottoms == {}
    assert set(model.describe()["materials"]) == {"body", "layer"}
    assert MODES["b"].to_dict()["bottom_material"] == "bilinear_0_2"


@pytest.mark.parametrize("dim, half", [(2, False), (3, True), (3, False)])
def test_bottom_walls_are_their_own_regions(dim, half):
    """Each bottom wall is pitch x wall (x width) of its material, turned over with its unit."""
    mesh = assemble(MODES, "abBmM", dim=dim, half=half)
    u = MODES["b"]
    width = 1.0 if dim == 2 else (u.width / 2 if half else u.width)
    one = u.pitch * u.wall * width
    assert _volumes(mesh, "bottom:bilinear_0_2") == pytest.approx(2 * one, rel=1e-12)
    assert _volumes(mesh, "bottom:smooth_sil_950") == pytest.approx(2 * one, rel=1e-12)
    centres = mesh.points[mesh.cells].mean(axis=1)
    for region, up in (("bottom:bilinear_0_2", (False, True)), ("bottom:smooth_sil_950", (False, True))):
        cells = mesh.regions[region]
        turned = centres[cells, 1] > u.height / 2
        # one unit as built (wall at y < 1.5), one turned over (at y > 10.5)
        assert sorted(set(turned.tolist())) == list(up)
        assert np.all(np.where(turned, centres[cells, 1] > u.height - u.wall, centres[cells, 1] < u.wall))
    # no cell lost or counted twice
    counted = np.concatenate([v for k, v in mesh.regions.items()])
    assert len(counted) == len(np.unique(counted)) == len(mesh.cells)


def test_a_design_without_the_type_has_the_empty_region():
    mesh = assemble(MODES, "aaa", dim=3, half=True)
    assert len(mesh.regions["bottom:bilinear_0_2"]) == 0 and len(mesh.regions["body"]) > 0


def test_bad_bottom_material():
    with pytest.raises(GeometryError, match="bottom_material must be a material's name"):
        UnitSpec(bottom_material=3)  # type: ignore[arg-type]
    with pytest.raises(UnknownMaterialError, match="nonesuch"):
        Full3D(2, unit=UnitSpec(bottom_material="nonesuch"))


def test_low_bending_unit_bends_a_tenth_of_the_bending_unit():
    """2D, 45 kPa: the stiff bottom wall leaves the unit a small fraction of the bending unit's turn."""
    ramp = RampSpec(pressure=0.045, steps=StepSettings(increments=5, substeps=2))
    curls = {s: Reduced2D(3, library=MODES, ramp_spec=ramp).evaluate(s * 3).curl[-1] for s in "am"}
    assert curls["a"] > 30.0
    assert 0.0 < curls["m"] < 0.2 * curls["a"]


def test_bimodal_unit_switches_in_3d():
    """One bimodal unit in 3D bends towards its top, turns back and bends the other way within the ramp."""
    ramp = RampSpec(pressure=0.042, steps=StepSettings(increments=14, substeps=2))
    r = Full3D(1, library=MODES, ramp_spec=ramp).evaluate("b")
    s = find_switch(r.pressures, r.curl)
    assert s.first_direction == 1
    assert s.turning is not None and s.switch is not None
    assert 0.012 <= s.turning < s.switch < 0.042
    assert r.curl[-1] < -0.5 * s.peak  # well past the switch: bent the other way
    # turned over, the same body mirrored: the same turn with the opposite sign
    turned = Full3D(1, library=MODES, ramp_spec=ramp).evaluate("B")
    np.testing.assert_allclose(turned.curl, -r.curl, atol=1e-6)
