"""Passages between cavities and the base block (appendix D.1, D.2): valid meshes, exact volumes, clear errors."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.errors import GeometryError, SettingsError
from pneumorph.fem import cavity_volume
from pneumorph.geometry.assembly import assemble
from pneumorph.geometry.features import PHYSICAL_PASSAGE, BaseBlock, passage_side
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import FEModel, Full3D, RampSpec, Reduced2D


def _volumes(mesh) -> np.ndarray:
    """Volume of every hexahedron20 cell by Gauss quadrature (all positive for a valid mesh)."""
    import felupe as fem

    region = fem.RegionQuadraticHexahedron(fem.Mesh(mesh.points, mesh.cells, mesh.cell_type))
    assert (region.dV > 0).all(), "an inverted or degenerate element"
    return region.dV.sum(axis=0)


def test_passages_remove_exactly_their_channels_and_keep_the_mesh_valid() -> None:
    u = UnitSpec()
    plain, holed = assemble(u, "0110", dim=3), assemble(u, "0110", dim=3, passage=PHYSICAL_PASSAGE)
    s = passage_side(PHYSICAL_PASSAGE)
    assert s**2 == pytest.approx(np.pi * PHYSICAL_PASSAGE**2 / 4)  # the hole's area
    # solid volume: the box less 4 cavities, less 3 channels through the 2 end walls between them
    box = 4 * u.pitch * u.height * u.width
    cavities = 4 * u.cavity_length * u.cavity_height * (u.width - 2 * u.side_wall)
    assert _volumes(plain).sum() == pytest.approx(box - cavities, rel=1e-9)
    assert _volumes(holed).sum() == pytest.approx(box - cavities - 3 * s * s * 2 * u.end_wall, rel=1e-6)
    # one connected solid: every point is used by a cell and the pressure acts on the channels' walls
    assert np.array_equal(np.unique(holed.cells), np.arange(len(holed.points)))
    assert holed.cavity_points.sum() > plain.cavity_points.sum()


@pytest.mark.parametrize("design", ["000", "011"])
def test_the_pressurised_surface_encloses_cavities_and_passages(design: str) -> None:
    u = UnitSpec()
    s = passage_side(PHYSICAL_PASSAGE)
    model = Full3D(3, half=False, passage=PHYSICAL_PASSAGE)
    enclosed = cavity_volume(model.build(design)[1].walls)
    cavities = 3 * u.cavity_length * u.cavity_height * (u.width - 2 * u.side_wall)
    assert enclosed == pytest.approx(cavities + 2 * s * s * 2 * u.end_wall, rel=1e-6)


def test_base_block_mesh_regions_and_jaws() -> None:
    u, block = UnitSpec(), BaseBlock(length=6.0, margin=1.5)
    m = assemble(u, "01", dim=3, half=True, base=block)
    vol = _volumes(m)
    x0, x1, y0, y1, z0, _ = block.box(u)
    assert vol[m.regions["base"]].sum() == pytest.approx((x1 - x0) * (y1 - y0) * (u.width / 2 - z0), rel=1e-9)
    jaws = m.points[m.base_points]
    assert (jaws[:, 0] <= 1e-9).all() and np.isin(np.round(jaws[:, 1], 9), [y0, y1]).all()
    assert not np.isclose(m.points[m.base_points][:, 0], 0.0).all()  # no longer the face x = 0 alone
    m2 = assemble(u, "01", dim=2, base=BaseBlock(length=6.0))
    assert _area_2d(m2, m2.regions["base"]) == pytest.approx(6.0 * u.height)


def _area_2d(mesh, cells) -> float:
    import felupe as fem

    region = fem.RegionQuadraticQuad(fem.Mesh(mesh.points, mesh.cells[cells], mesh.cell_type))
    return float(region.dV.sum())


@pytest.mark.slow
def test_features_solve_and_change_the_shape_as_expected() -> None:
    ramp = RampSpec(pressure=0.02)
    plain = Full3D(2, ramp_spec=ramp).evaluate("00")
    holed = Full3D(2, ramp_spec=ramp, passage=PHYSICAL_PASSAGE).evaluate("00")
    based = Full3D(2, ramp_spec=ramp, base_block=BaseBlock()).evaluate("00")
    # a passage weakens the walls between cavities and adds to the pressurised area: more curl; the
    # block and its jaws give a stiffer response than the clamped face, as appendix D.2 found
    assert holed.curl[-1] > plain.curl[-1] > based.curl[-1] > 0
    assert Reduced2D(2, ramp_spec=ramp, base_block=BaseBlock()).evaluate("00").converged
    fps = {Full3D(2).fingerprint(), Full3D(2, passage=1.5).fingerprint(),
           Full3D(2, base_block=BaseBlock()).fingerprint()}
    assert len(fps) == 3


def test_bad_features_are_refused() -> None:
    with pytest.raises(GeometryError, match="wider than the walls"):
        Full3D(2, passage=4.0)
    with pytest.raises(GeometryError, match="finite number >= 0"):
        Full3D(2, passage=-1.0)
    with pytest.raises(SettingsError, match="3D model option"):
        FEModel(2, passage=1.5)  # the common base of the models is two-dimensional
    with pytest.raises(GeometryError, match="slit"):
        Full3D(2, UnitSpec(slit_width=1.0, slit_depth=3.0), passage=1.5)
    with pytest.raises(GeometryError, match="3D feature"):
        assemble(UnitSpec(), "01", dim=2, passage=1.5)
    with pytest.raises(GeometryError, match="margin"):
        BaseBlock(margin=-1.0)


def test_the_model_factory_takes_the_features_and_refuses_bad_ones() -> None:
    from pneumorph.errors import SearchConfigError
    from pneumorph.models.factory import make_model

    m = make_model(3, {"fidelity": "3d", "passage": 1.5, "base_block": {"length": 8.0, "margin": 1.0}})
    assert m.passage == 1.5 and m.base_block == BaseBlock(length=8.0, margin=1.0)
    assert m.fingerprint() == Full3D(3, passage=1.5, base_block=BaseBlock(length=8.0, margin=1.0)).fingerprint()
    assert make_model(3, {"base_block": {}}).base_block == BaseBlock()  # 2D takes the block
    for bad, message in (({"passage": 1.5}, "3D model option"), ({"fidelity": "3d", "passage": 9.0}, "wider"),
                         ({"base_block": {"length": -1}}, "length"), ({"base_block": {"foo": 1}}, "foo"),
                         ({"base_block": 3}, "must be a table")):
        with pytest.raises(SearchConfigError, match=message):
            make_model(3, bad)
