"""The full 3D model: the half model's answer on planar designs; sideways units leave the plane."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.fem import StepSettings
from pneumorph.geometry.library import UnitLibrary, builtin_library
from pneumorph.models.fe import Full3D, RampSpec

#: a short, low ramp: two levels to 10 kPa (seconds per solve)
RAMP = RampSpec(pressure=0.01, steps=StepSettings(increments=2, substeps=1))
#: solver tolerance on positions (mm): the ramp's relative residual 1e-8 moves the 2-3 unit actuators' points
#: by far less; the half model's u_z = 0 is exact for a planar design
ATOL = 1e-6


@pytest.fixture(scope="module")
def spatial() -> UnitLibrary:
    """The built-in spatial library (its 1.5 mm mesh: the units share their section's lines only at this size)."""
    return builtin_library("spatial")


@pytest.fixture(scope="module")
def sideways(spatial: UnitLibrary) -> dict[str, object]:
    """Two 2-unit designs with a sideways unit, one the other's mirror across the width, and their meshes."""
    model = Full3D(2, library=spatial, ramp_spec=RAMP)
    return {design: (model.evaluate(design), model.mesh(design)) for design in ("al", "aL")}


def test_the_full_model_equals_the_half_model_on_a_planar_design(spatial: UnitLibrary) -> None:
    half_model, full_model = Full3D(2, library=spatial, ramp_spec=RAMP), Full3D(2, library=spatial, ramp_spec=RAMP,
                                                                                  half=False)
    assert half_model.half_for("aA") and not full_model.half_for("aA")
    half, full = half_model.evaluate("aA"), full_model.evaluate("aA")
    assert (half.axes, full.axes) == (2, 3) and half.metadata["dofs"] < 0.6 * full.metadata["dofs"]
    assert np.abs(half.tip[-1] - half.reference_tip).max() > 0.1  # it moved: the comparison means something
    np.testing.assert_allclose(full.centres[..., :2], half.centres, atol=ATOL, rtol=0)
    np.testing.assert_allclose(full.tip[..., :2], half.tip, atol=ATOL, rtol=0)
    np.testing.assert_allclose(full.curl, half.curl, atol=1e-5, rtol=0)
    W = spatial["a"].width  # the full model's z stays on the mid-plane, where the half model holds it
    np.testing.assert_allclose(full.centres[..., 2], W / 2, atol=ATOL, rtol=0)
    np.testing.assert_allclose(full.tip[:, 2], W / 2, atol=ATOL, rtol=0)
    # the end face turns about z by the curl, without twist; the half model keeps no end frame
    assert half.end_frame is None and half.twist is None and full.end_frame is not None
    np.testing.assert_allclose(full.end_frame, np.column_stack([0 * full.curl, 0 * full.curl, np.radians(full.curl)]),
                               atol=1e-7, rtol=0)
    np.testing.assert_allclose(full.twist, 0.0, atol=1e-6)


def test_a_sideways_unit_bends_out_of_the_plane_towards_its_layer(spatial: UnitLibrary,
                                                                  sideways: dict[str, object]) -> None:
    W = spatial["a"].width
    for design, (response, mesh) in sideways.items():  # type: ignore[misc]
        assert response.axes == 3 and response.converged and mesh.symmetry_points is None
        layer = mesh.points[mesh.cells[mesh.regions["layer"], :8]].mean(axis=1)
        in_unit_2 = layer[:, 0] > mesh.unit_bounds[1]
        side = np.sign(layer[in_unit_2, 2].mean() - W / 2)  # the side the sideways unit's layer lies on
        assert side == (1 if design == "al" else -1)
        dz = response.tip[:, 2] - response.reference_tip[2]
        assert (np.sign(dz) == side).all() and abs(dz[-1]) > 0.05  # towards its layer, and not by rounding


def test_the_turned_over_sideways_unit_mirrors_the_response_across_the_width(sideways: dict[str, object]) -> None:
    (left, _), (right, _) = sideways["al"], sideways["aL"]  # type: ignore[misc]
    W = 2 * float(left.reference_tip[2])
    np.testing.assert_allclose(right.tip[:, 2], W - left.tip[:, 2], atol=ATOL, rtol=0)
    np.testing.assert_allclose(right.centres[..., 2], W - left.centres[..., 2], atol=ATOL, rtol=0)
    np.testing.assert_allclose(right.tip[:, :2], left.tip[:, :2], atol=ATOL, rtol=0)  # in-plane the same
    np.testing.assert_allclose(right.centres[..., :2], left.centres[..., :2], atol=ATOL, rtol=0)
    np.testing.assert_allclose(right.curl, left.curl, atol=1e-5, rtol=0)
    # mirrored across the width, the end face tilts and twists the other way: rotation vector (-x, -y, z)
    np.testing.assert_allclose(right.end_frame, left.end_frame * [-1, -1, 1], atol=1e-7, rtol=0)
    np.testing.assert_allclose(right.twist, -left.twist, atol=1e-5, rtol=0)
    assert abs(left.end_frame[-1, 1]) > 1e-3  # the sideways unit tilts the face about y: it bends across the width


def test_a_sideways_response_keeps_z_through_its_file(sideways: dict[str, object], tmp_path: object) -> None:
    from pathlib import Path

    from pneumorph.models.response import Response

    response, _ = sideways["al"]  # type: ignore[misc]
    response.save(Path(str(tmp_path)) / "r")
    again = Response.load(Path(str(tmp_path)) / "r")
    assert again.axes == 3
    np.testing.assert_array_equal(again.centres, response.centres)
    np.testing.assert_array_equal(again.end_frame, response.end_frame)
    np.testing.assert_array_equal(again.centreline(-1)[1:-1], response.centres[-1])
    assert again.centreline(0)[0].tolist() == [0.0, *response.reference_centres[0, 1:].tolist()]


def test_the_full_width_gets_the_half_models_single_precision_limit_per_half_width(
        spatial: UnitLibrary, monkeypatch: pytest.MonkeyPatch) -> None:
    """The limit stands for an element size (the tangent's conditioning): twice the unknowns on the full width."""
    from pneumorph.fem.fast import newton

    model = Full3D(2, library=spatial, ramp_spec=RAMP)
    half_body, full_body = model.build("aA")[1], model.build("aL")[1]
    n_half, n_full = len(half_body.dof1), len(full_body.dof1)
    assert half_body.half and not full_body.half and n_half < n_full < 2 * n_half
    monkeypatch.setattr(newton, "SINGLE_PRECISION_MAX_DOFS", n_full // 2 + 1)  # below the full body's unknowns
    assert full_body.stepper("fast", model.tangent_reuse, model.anderson_depth)[0].precision == "single"
    monkeypatch.setattr(newton, "SINGLE_PRECISION_MAX_DOFS", n_full // 2 - 1)
    assert full_body.stepper("fast", model.tangent_reuse, model.anderson_depth)[0].precision == "double"
    for limit, precision in ((n_half, "single"), (n_half - 1, "double")):  # the half model's limit as it was
        monkeypatch.setattr(newton, "SINGLE_PRECISION_MAX_DOFS", limit)
        assert half_body.stepper("fast", model.tangent_reuse, model.anderson_depth)[0].precision == precision


def test_a_chain_table_over_sideways_units_is_planned_on_the_full_width(spatial: UnitLibrary) -> None:
    """A chain in space: every training design on the full width, estimated at the full model's solve time."""
    from pneumorph.models.chain.model import source_key, training_model
    from pneumorph.models.chain.plan import FULL_WIDTH, build_plan

    model = Full3D(15, library=spatial)
    plan = build_plan(model, window=1, short=True)
    assert plan.fidelity == FULL_WIDTH and "3d full-width model" in plan.text()
    assert training_model(model).half is False and model.half is True  # the user's model is left as it was
    assert source_key(training_model(model)) == source_key(model)  # a table of either serves both
    planar = Full3D(15, library=UnitLibrary.single(spatial["a"]))
    assert training_model(planar) is planar and build_plan(planar).fidelity == "3d"  # a planar one as before
