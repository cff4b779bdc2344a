"""Physics of the bimodal actuator's 3D model on tiny meshes (three voids, coarse cells)."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.bimodal.geometry import BimodalSpec
from pneumorph.bimodal.model import BimodalModel, bilinear_material
from pneumorph.errors import MaterialDataError, SettingsError, UnknownMaterialError
from pneumorph.materials import drucker_stability, get

TINY = BimodalSpec(voids=3, element_size=5.0)


def test_first_mode_bends_towards_the_stiff_strip() -> None:
    """Section 3.3.1: at low pressure the composite is soft and on the outside (u_y > 0)."""
    r = BimodalModel(TINY, crimp_ratio=0.3, pmax=0.005).solve()
    assert r.completed and r.pressures.tolist() == [0.005]
    assert r.tip[0, 1] > 0.0
    # a stiff layer in place of the composite bends it the other way
    stiff = BimodalModel(TINY, crimp_ratio=0.3, pmax=0.005, materials={"bilinear": "smooth_sil_950"}).solve()
    assert stiff.tip[0, 1] < 0.0


def test_mirror_image_of_a_symmetric_stack() -> None:
    """Same thicknesses above and below the voids and the materials swapped: the tip moves
    to the mirror-image position (u_x equal, u_y opposite)."""
    spec = BimodalSpec(voids=3, element_size=5.0, bilinear=2.0, strip=2.0, seal=1.5, top_wall=1.5)
    up = BimodalModel(spec, crimp_ratio=None, pmax=0.005,
                      materials={"bilinear": "mold_star_15", "strip": "smooth_sil_950"}).solve()
    down = BimodalModel(spec, crimp_ratio=None, pmax=0.005,
                        materials={"bilinear": "smooth_sil_950", "strip": "mold_star_15"}).solve()
    assert abs(up.tip[0, 1]) > 0.01
    assert down.tip[0, 0] == pytest.approx(up.tip[0, 0], rel=1e-6)
    assert down.tip[0, 1] == pytest.approx(-up.tip[0, 1], rel=1e-6)


def test_half_model_equals_full_model() -> None:
    spec = BimodalSpec(voids=1, element_size=5.0)
    half = BimodalModel(spec, pmax=0.005, half=True).solve()
    full = BimodalModel(spec, pmax=0.005, half=False).solve()
    assert half.metadata["dofs"] < full.metadata["dofs"]
    np.testing.assert_allclose(half.tip, full.tip, rtol=1e-6, atol=1e-9)


def test_bulk_modulus_override() -> None:
    m = BimodalModel(TINY, crimp_ratio=0.2, bilinear_bulk=5.0)
    assert m.bulk("bilinear") == 5.0
    assert m.bulk("body") == get("mold_star_15").bulk_modulus.value
    # the fibre composite's matrix is Ecoflex 0030; the homogenised composite is Table B.1's material
    assert BimodalModel(TINY, crimp_ratio=0.2).bulk("bilinear") == get("ecoflex_0030").bulk_modulus.value
    assert BimodalModel(TINY, crimp_ratio=0.2, composite="homogenised").bulk("bilinear") == get(
        "bilinear_0_2").bulk_modulus.value


def test_slack_paper_leaves_the_ecoflex_alone() -> None:
    """Below the crimp's straightening (28 % for CR 0.2) the paper carries nothing: the fibre composite's actuator
    is the one with a plain Ecoflex 0030 layer, and both differ from the homogenised Table B.1 layer."""
    spec = BimodalSpec(voids=1, element_size=5.0)
    fibre = BimodalModel(spec, crimp_ratio=0.2, pmax=0.005, paper="ideal").solve()
    plain = BimodalModel(spec, crimp_ratio=None, pmax=0.005, materials={"bilinear": "ecoflex_0030"}).solve()
    homogenised = BimodalModel(spec, crimp_ratio=0.2, pmax=0.005, composite="homogenised").solve()
    np.testing.assert_allclose(fibre.tip, plain.tip, rtol=1e-9, atol=1e-12)
    assert abs(fibre.tip[0, 1] - homogenised.tip[0, 1]) > 0.05 * abs(homogenised.tip[0, 1])
    assert fibre.metadata["model"]["composite"].startswith("fibre")
    # the cast paper (the default) carries load from the start (216 kPa primary modulus against the Ecoflex's 68)
    cast = BimodalModel(spec, crimp_ratio=0.2, pmax=0.005).solve()
    assert cast.metadata["model"]["paper"] == "measured"
    assert cast.tip[0, 1] > 0.0 and abs(cast.tip[0, 1] - fibre.tip[0, 1]) > 0.01 * fibre.tip[0, 1]


def test_a_transition_strain_only_with_the_ideal_paper() -> None:
    assert BimodalModel(TINY, crimp_ratio=0.2, paper="ideal", transition=0.152).transition == 0.152
    with pytest.raises(SettingsError, match="ideal"):
        BimodalModel(TINY, crimp_ratio=0.2, transition=0.152)
    with pytest.raises(SettingsError, match="crimped"):
        BimodalModel(TINY, crimp_ratio=0.2, paper="crimped")


def test_unknown_composite() -> None:
    with pytest.raises(SettingsError, match="rebar"):
        BimodalModel(TINY, composite="rebar")


def test_only_table_b1_crimp_ratios() -> None:
    assert bilinear_material(0.3) == "bilinear_0_3"
    with pytest.raises(UnknownMaterialError, match=r"0\.35"):
        bilinear_material(0.35)


def test_table_b1_stability() -> None:
    """Drucker stability of the Table B.1 fits over stretches 0.3-3: CR 0.2 is not stable
    (in uniaxial compression and equibiaxial tension just beyond l = 1), CR 0.25 and 0.3 are."""
    r = {cr: drucker_stability(get(bilinear_material(cr)).model, (0.3, 3.0), 541) for cr in (0.2, 0.25, 0.3)}
    assert not r[0.2].is_stable
    lam = r[0.2].stretch
    bad = lam[~r[0.2].stable["uniaxial"]]
    assert 0.85 < bad.min() and bad.max() < 0.96
    assert r[0.25].is_stable and r[0.3].is_stable


def test_a_volume_step_too_large_to_take_from_rest_is_refused_before_any_solve() -> None:
    # 8 V0 in two steps (4 V0 each) fails on its first step; the default 12 steps (0.67 V0 each) converge
    with pytest.raises(SettingsError, match=r"4 V0 per step, more than the 2 V0 .*at least 4 steps, e\.g\. step 2\.5"):
        BimodalModel(BimodalSpec(voids=2), crimp_ratio=0.2, pmax=0.010, step=0.005, volume=8.0)
    BimodalModel(BimodalSpec(voids=2), crimp_ratio=0.2, pmax=0.010, step=0.0025, volume=8.0)  # 2 V0 per step


def test_the_weight_is_a_small_load_that_acts_both_ways() -> None:
    """``gravity``: the layers' weight is loaded before the ramp and held. Across the actuator it is a small
    dead load: its weight turned over moves the tip the other way by the same amount (to 5 %); hung from its base
    (the bench, section 3.3.2) it pulls the tip along the axis. The description names it; without it, none."""
    spec = BimodalSpec(voids=2, element_size=5.0)
    tips = {}
    for name, g in (("none", None), ("down", [0.0, -9806.65, 0.0]), ("up", [0.0, 9806.65, 0.0]),
                    ("hanging", "hanging")):
        model = BimodalModel(spec, crimp_ratio=0.2, pmax=0.005, gravity=g)
        r = model.solve()
        assert r.completed
        tips[name] = r.tip[-1]
        assert ("gravity_mm_s2" in model.describe()) == (g is not None)
    down, up = tips["down"] - tips["none"], tips["up"] - tips["none"]
    assert down[1] < -0.05 and up[1] == pytest.approx(-down[1], rel=0.05)
    assert tips["hanging"][0] > tips["none"][0]
    with pytest.raises(MaterialDataError, match="density of ecoflex_00_10"):  # before any solve
        BimodalModel(spec, crimp_ratio=0.2, materials={"strip": "ecoflex_00_10"}, gravity="hanging")
