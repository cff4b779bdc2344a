"""A uniform temperature change: free thermal expansion in the Ogden energy and the 3D model (appendix D.3)."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.errors import MaterialDataError, SearchConfigError, SettingsError
from pneumorph.fem.fast.kernels import principal_3d
from pneumorph.fem.ogden import OgdenCompressible
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.factory import make_model
from pneumorph.models.fe import Full3D, RampSpec

MU, ALPHA, BULK = [0.05, 0.01], [2.5, -1.5], 0.5  # MPa
THETA = 1.0 + 2.453e-4 * 10.0  # Mold Star 15 (Table A.6), 10 degC warmer


def _gradients(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return (np.eye(3)[..., None] + 0.15 * rng.standard_normal((3, 3, n))).reshape(3, 3, 1, n)


def test_a_free_thermal_stretch_is_stress_free_and_the_energy_scales() -> None:
    umat = OgdenCompressible(MU, ALPHA, BULK, THETA)
    F = np.broadcast_to((THETA * np.eye(3))[..., None, None], (3, 3, 1, 4)).copy()
    P, _ = umat.gradient([F, None])
    assert np.abs(P).max() < 1e-12
    # P(F) = theta^2 P_e(F / theta), the derivative of theta^3 W_e(F / theta)
    F = _gradients(6, 0)
    plain = OgdenCompressible(MU, ALPHA, BULK)
    np.testing.assert_allclose(umat.gradient([F, None])[0], THETA**2 * plain.gradient([F / THETA, None])[0],
                               rtol=1e-12, atol=1e-14)


def test_the_thermal_tangent_is_the_derivative_of_the_thermal_stress() -> None:
    umat = OgdenCompressible(MU, ALPHA, BULK, 1.05)
    F = _gradients(3, 1)
    A = umat.hessian([F, None])[0]
    h = 1e-6
    for i, J in ((0, 0), (1, 2), (2, 1)):
        dF = np.zeros_like(F)
        dF[i, J] = h
        fd = (umat.gradient([F + dF, None])[0] - umat.gradient([F - dF, None])[0]) / (2 * h)
        np.testing.assert_allclose(A[:, :, i, J], fd, rtol=1e-6, atol=1e-8)


def test_the_fast_kernel_follows_the_thermal_stretch() -> None:
    umat = OgdenCompressible(MU, ALPHA, BULK, 1.05)
    F4 = _gradients(8, 2)
    F = F4[:, :, 0]
    P, A, J = umat.kernel(F, True, principal_3d(F), [(a, b) for a in range(3) for b in range(a, 3)])
    np.testing.assert_allclose(P, umat.gradient([F4, None])[0][:, :, 0], rtol=1e-9, atol=1e-12)
    full = umat.hessian([F4, None])[0][:, :, :, :, 0]
    for n, (i, k) in enumerate([(a, b) for a in range(3) for b in range(a, 3)]):
        np.testing.assert_allclose(A[n], full[i, :, k, :], rtol=1e-8, atol=1e-11)
    np.testing.assert_allclose(J, np.linalg.det(np.moveaxis(F, -1, 0)) / 1.05**3, rtol=1e-12)


def test_a_free_block_expands_by_the_closed_form() -> None:
    felupe = pytest.importorskip("felupe")
    mesh = felupe.Cube(b=(4.0, 2.0, 1.0), n=(5, 3, 2)).add_midpoints_edges()
    mesh.update(cell_type="hexahedron20")
    region = felupe.RegionQuadraticHexahedron(mesh)
    field = felupe.FieldContainer([felupe.Field(region, dim=3)])
    x = mesh.points
    bounds = {  # rollers on three faces: free to expand, no rigid motion
        "x": felupe.Boundary(field[0], mask=np.isclose(x[:, 0], 0.0), skip=(0, 1, 1)),
        "y": felupe.Boundary(field[0], mask=np.isclose(x[:, 1], 0.0), skip=(1, 0, 1)),
        "z": felupe.Boundary(field[0], mask=np.isclose(x[:, 2], 0.0), skip=(1, 1, 0)),
    }
    solid = felupe.SolidBody(OgdenCompressible(MU, ALPHA, BULK, THETA), field)
    dof0, dof1 = felupe.dof.partition(field, bounds)
    res = felupe.newtonraphson(items=[solid], x0=field, dof1=dof1, dof0=dof0, tol=1e-12, verbose=0)
    np.testing.assert_allclose(res.x[0].values, (THETA - 1.0) * x, atol=1e-10)  # u = a dT X


@pytest.fixture(scope="module")
def warm() -> tuple[Full3D, Full3D]:
    ramp = RampSpec(pressure=0.01)
    unit = UnitSpec(element_size=3.0)
    return Full3D(2, unit, ramp), Full3D(2, unit, ramp, temperature_change=10.0)


def test_a_warmer_actuator_is_longer_and_its_fingerprint_says_so(warm: tuple[Full3D, Full3D]) -> None:
    cold, hot = warm
    assert cold.fingerprint() != hot.fingerprint()
    assert "temperature_change_c" not in cold.describe()  # earlier fingerprints stay valid
    a, b = cold.evaluate("01"), hot.evaluate("01")
    growth = b.tip[0, 0] - a.tip[0, 0]
    free = (hot.thermal_stretch(hot.body) - 1.0) * a.reference_tip[0]
    # the clamped base holds the silicone back only near it: about the free expansion
    assert 0.5 * free < growth < 1.2 * free


def test_bad_temperature_settings_are_refused() -> None:
    with pytest.raises(MaterialDataError, match="thermal expansion of 'bilinear_0_2'"):
        Full3D(2, UnitSpec(layer_material="bilinear_0_2"), temperature_change=10.0)
    Full3D(2, UnitSpec(layer_material="bilinear_0_2"))  # no temperature change: no coefficient needed
    with pytest.raises(SearchConfigError, match="3D model option"):
        make_model(2, {"fidelity": "2d", "temperature_change": 10})
    with pytest.raises(SearchConfigError, match="temperature_change"):
        make_model(2, {"fidelity": "3d", "temperature_change": float("nan")})
    assert make_model(2, {"fidelity": "3d", "temperature_change": 10}).temperature_change == 10.0
    with pytest.raises(SettingsError, match="fast backend"):
        Full3D(2, backend="felupe", temperature_change=10.0)
