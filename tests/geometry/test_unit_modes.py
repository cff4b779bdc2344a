"""Units with a bottom wall of another material, and the built-in library ``modes`` (bimodal, low-bending)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from pneumorph.bimodal.switch import find_switch
from pneumorph.errors import ChainTableError, GeometryError, MaterialDataError, SettingsError, UnknownMaterialError
from pneumorph.fem import StepSettings
from pneumorph.fem.fibre import CAST_PAPER, CrimpedFibreOgden
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
    assert MODES.symbols == ("a", "b", "m", "p")
    assert MODES["a"] == UnitSpec()
    check_joinable(dict(zip(MODES.symbols, MODES.units, strict=True)))
    # neither new type is its own mirror: the composite or the stiff bottom wall is on one side only
    assert not MODES["b"].symmetric and not MODES["m"].symmetric and not MODES["p"].symmetric
    assert MODES["b"].height == MODES["m"].height == MODES["p"].height == UnitSpec().height == 12.0
    # the paper unit is the bimodal unit but for its bottom wall's material
    assert MODES["p"] == replace(MODES["b"], name="bimodal_paper", bottom_material="paper_0_2")


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


def test_the_paper_units_wall_is_the_cast_composite_along_the_axis_turned_or_not():
    """``p``'s bottom wall is its own region, the Ecoflex matrix with the cast paper of CR 0.2 along x in both
    orientations (a unit turned about its long axis keeps its paper along it); ``b``'s stays the Ogden law."""
    mesh = assemble(MODES, "pPb", dim=3, half=True)
    u = MODES["p"]
    one = u.pitch * u.wall * u.width / 2
    assert _volumes(mesh, "bottom:paper_0_2") == pytest.approx(2 * one, rel=1e-12)
    assert _volumes(mesh, "bottom:bilinear_0_2") == pytest.approx(one, rel=1e-12)
    centres = mesh.points[mesh.cells[mesh.regions["bottom:paper_0_2"]]].mean(axis=1)
    assert sorted(set((centres[:, 1] > u.height / 2).tolist())) == [False, True]  # one as built, one turned
    model = Full3D(3, library=MODES)
    _, body, _ = model.build("pPb")
    law = body.solids["bottom:paper_0_2"].umat
    assert isinstance(law, CrimpedFibreOgden) and law.direction.tolist() == [[1.0, 0.0, 0.0]]
    paper = CAST_PAPER["paper_0_2"]
    assert (law.primary, law.straight, law.slope, law.blend) == (paper.primary, paper.straight, paper.slope, 0.02)
    assert not isinstance(body.solids["bottom:bilinear_0_2"].umat, CrimpedFibreOgden)
    # the paper's law is in the model's description; the bimodal unit's is as before (docs/figures/unit-modes.json)
    assert model.describe()["materials"]["bottom:paper_0_2"]["paper"] == paper.to_dict()
    assert "paper" not in model.describe()["materials"]["bottom:bilinear_0_2"]
    ramp = RampSpec(pressure=0.042, steps=StepSettings(increments=14, substeps=2))
    assert Full3D(1, unit=MODES["b"], ramp_spec=ramp).fingerprint() == "0d14baf34204f6b7"
    assert Full3D(15, unit=MODES["b"], ramp_spec=ramp).fingerprint() == "6a9ce45bb72fefe0"
    with pytest.raises(MaterialDataError, match="thermal expansion of 'paper_0_2'"):  # the paper has no thermal law
        Full3D(1, unit=MODES["p"], temperature_change=10.0)


def test_the_shipped_bimodal_table_refuses_the_paper_unit(tmp_path):
    """The 3D table of ``a``, ``b`` (40 kPa) serves its library; the same library with ``b``'s wall of the cast
    paper is another model, which the table refuses instead of serving it."""
    from pathlib import Path

    from pneumorph.models.chain.model import ChainTable, check_source
    from pneumorph.models.factory import make_model

    libraries = Path(__file__).resolve().parents[2] / "examples" / "libraries"
    table = ChainTable.load(libraries / "chain-3d-bending-bimodal-40kpa-far.json")
    shipped = libraries / "units-bending-bimodal.toml"
    check_source(table, make_model(15, {"fidelity": "3d", "pressure_kpa": 40, "library": str(shipped)}))
    paper = tmp_path / "units-bending-bimodal-paper.toml"
    paper.write_text(shipped.read_text(encoding="utf-8").replace('"bilinear_0_2"', '"paper_0_2"'), encoding="utf-8")
    model = make_model(15, {"fidelity": "3d", "pressure_kpa": 40, "library": str(paper)})
    with pytest.raises(ChainTableError):
        check_source(table, model)


@pytest.mark.slow
def test_the_paper_unit_switches_early_in_3d():
    """The cast paper in the bimodal unit's wall (docs/unit-library.md): the unit turns back at 9 kPa from 0.36
    degrees and crosses near 12.9 kPa, where the homogenised wall of ``b`` crosses at 29 kPa; turned over, the
    same turn with the opposite sign (the paper stays along the unit's axis)."""
    ramp = RampSpec(pressure=0.042, steps=StepSettings(increments=14, substeps=2))
    model = Full3D(1, library=MODES, ramp_spec=ramp)
    r = model.evaluate("p")
    s = find_switch(r.pressures, r.curl)
    assert s.first_direction == 1 and s.turning == pytest.approx(0.009)
    assert s.peak == pytest.approx(0.356, abs=0.01) and s.switch == pytest.approx(0.0129, abs=3e-4)
    assert r.curl[-1] == pytest.approx(-22.2, abs=0.2)
    np.testing.assert_allclose(model.evaluate("P").curl, -r.curl, atol=1e-6)


def test_the_paper_unit_is_refused_in_2d_before_any_solve():
    """The paper's law is 3D (the plane-strain assembly has no kernel for it): a 2D design with a ``p`` unit is
    refused as it is built; the library's other designs solve in 2D as before."""
    model = Reduced2D(2, library=MODES)
    with pytest.raises(SettingsError, match="paper_0_2: the paper along the unit's axis is a 3D law"):
        model.build("aP")
    model.build("ab")
