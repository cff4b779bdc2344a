"""Gravity (dead loads): a bar hanging under its own weight against the closed form, and the
actuator models' gravity on the fast and FElupe paths.

A bar of length L on rollers at its top end (x = 0), hanging along +x under rho g, is in
uniaxial stress sigma_xx = rho g (L - x) in the small-strain limit, so

    u_x(x) = rho g / E' (L x - x^2 / 2),   u_x(L) = rho g L^2 / (2 E'),

with E' = E in 3D and E' = E / (1 - nu^2) in plane strain (the bar's sides are free, its
depth is held). With nu > 0 the exact field also has a term -nu' k y^2 / 2 in u_x, which
rollers at the top forbid (a Saint-Venant end effect of 5e-4 here); with nu = 0 there is
none, u_x is quadratic in x alone, which quadratic elements hold exactly, and the finite-
element field differs from it only by the strain's own size (the nonlinearity of the
hyperelastic solid): about 1e-4 here.
"""

from __future__ import annotations

import felupe as fem
import numpy as np
import pytest
from felupe.tools._newton import fun_items

from pneumorph.errors import MaterialDataError, SearchConfigError
from pneumorph.fem import StepSettings, ramp
from pneumorph.fem.fast.loads import DeadLoads
from pneumorph.fem.fast.newton import FastSubstep
from pneumorph.fem.fast.system import PlaneStrainSystem, SolidSystem3D
from pneumorph.fem.ogden import OgdenCompressible
from pneumorph.models.factory import make_model
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D
from pneumorph.models.fe.gravity import STANDARD_GRAVITY, gravity_vector

L, H = 10.0, 1.0
MU, LMBDA = 1000.0, 0.0  # nu = 0, E = 2 mu
RHO_G = 0.025  # strain at the top: rho g L / E = 1.25e-4
STRAIN = 1.25e-4  # the FE field must match the closed form to better than this, relative (measured 4e-5 / 9e-5)


def _hang(field, solid, dof1, dof0, System):
    force = fem.SolidBodyForce(solid.field, values=np.zeros(field[0].dim), scale=RHO_G)
    items = [solid, force]
    system = System(items, field, dof1, dof0)

    def apply(t: float) -> None:
        force.update(np.eye(field[0].dim)[0] * t)

    ramp(items, field, apply, dof1, dof0, StepSettings(increments=1, substeps=1),
         substep=FastSubstep(system))
    return field[0].values


def test_plane_strain_bar_hangs_like_the_closed_form() -> None:
    mesh = fem.Rectangle(b=(L, H), n=(11, 3)).add_midpoints_edges()
    field = fem.FieldContainer([fem.FieldPlaneStrain(fem.RegionQuadraticQuad(mesh), dim=2)])
    solid = fem.SolidBody(fem.NeoHookeCompressible(mu=MU, lmbda=LMBDA), field)
    x = mesh.points
    dof0, dof1 = fem.dof.partition(field, {
        "rollers": fem.Boundary(field[0], fx=0.0, skip=(0, 1)),
        "pin": fem.Boundary(field[0], mask=(x[:, 0] == 0) & (x[:, 1] == 0), skip=(1, 0)),
    })
    u = _hang(field, solid, dof1, dof0, PlaneStrainSystem)
    e, nu = MU * (3 * LMBDA + 2 * MU) / (LMBDA + MU), LMBDA / (2 * (LMBDA + MU))
    e_plane = e / (1 - nu**2)
    exact = RHO_G / e_plane * (L * x[:, 0] - x[:, 0] ** 2 / 2)
    assert nu == 0.0 and exact.max() == pytest.approx(6.25e-4)
    np.testing.assert_allclose(u[:, 0], exact, rtol=0, atol=STRAIN * exact.max())
    np.testing.assert_allclose(u[:, 1], 0.0, rtol=0, atol=STRAIN * exact.max())


def test_3d_bar_hangs_like_the_closed_form() -> None:
    mesh = fem.Cube(b=(L, H, H), n=(6, 2, 2)).add_midpoints_edges()
    field = fem.FieldContainer([fem.Field(fem.RegionQuadraticHexahedron(mesh), dim=3)])
    bulk = LMBDA + 2 * MU / 3  # nu = 0
    solid = fem.SolidBody(OgdenCompressible((MU,), (2.0,), bulk), field)  # initial shear modulus MU
    x = mesh.points
    dof0, dof1 = fem.dof.partition(field, {
        "x": fem.Boundary(field[0], fx=0.0, skip=(0, 1, 1)),
        "y": fem.Boundary(field[0], fy=0.0, skip=(1, 0, 1)),
        "z": fem.Boundary(field[0], fz=0.0, skip=(1, 1, 0)),
    })
    u = _hang(field, solid, dof1, dof0, SolidSystem3D)
    e = 9 * bulk * MU / (3 * bulk + MU)
    exact = RHO_G / e * (L * x[:, 0] - x[:, 0] ** 2 / 2)
    np.testing.assert_allclose(u[:, 0], exact, rtol=0, atol=STRAIN * exact.max())


def test_dead_loads_equal_felupes_body_force_and_the_weight() -> None:
    model = Reduced2D(2, gravity="horizontal")
    mesh, body, _ = model.build("01")
    field = body.field
    body.set_gravity(np.asarray(model.gravity))
    system = PlaneStrainSystem(body.items, field, body.dof1, body.dof0)
    r_fast, _ = system.residual(np.zeros(field[0].values.size))
    r_fe = fun_items(body.items, field)
    np.testing.assert_allclose(r_fast, r_fe, rtol=0, atol=1e-12 * np.abs(r_fe).max())
    # the weight: density times the area of each silicone's (straight-sided) cells by the shoelace rule
    weight = 0.0
    for name, material in (("body", model.body), ("layer", model.layer)):
        corners = mesh.points[mesh.cells[mesh.regions[name]][:, :4]]
        x, y = corners[..., 0], corners[..., 1]
        area = 0.5 * np.abs(np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)).sum()
        weight += material.density.value * STANDARD_GRAVITY * area
    loads = DeadLoads(list(body.forces.values()), system.npoints, 2).vector().reshape(-1, 2)
    assert loads[:, 1].sum() == pytest.approx(-weight, rel=1e-12)
    assert loads[:, 0].sum() == 0.0
    assert 1e-3 < weight < 1e-2  # N per mm of depth: about 1.1e-9 tonne/mm^3 * 9.8e3 mm/s^2 * ~500 mm^2


@pytest.mark.parametrize("setup", ["hanging", "horizontal"])
def test_fast_and_felupe_paths_agree_under_gravity(setup: str) -> None:
    ramp_spec = RampSpec(pressure=0.02, steps=StepSettings(increments=2, substeps=1))
    fast = Reduced2D(2, ramp_spec=ramp_spec, gravity=setup).evaluate("01")
    slow = Reduced2D(2, ramp_spec=ramp_spec, gravity=setup, backend="felupe").evaluate("01")
    np.testing.assert_allclose(fast.centres, slow.centres, rtol=0, atol=1e-6)
    plain = Reduced2D(2, ramp_spec=ramp_spec).evaluate("01")
    sag = np.subtract(fast.metadata["gravity_tip"], fast.reference_tip)  # under gravity, before pressure
    moved = np.abs(fast.centres - plain.centres).max()
    assert 1e-4 < moved < 1.0, moved  # gravity moves the 2-unit actuator, a little
    if setup == "horizontal":
        assert sag[1] < 0 and fast.tip[-1, 1] < plain.tip[-1, 1]  # it sags downwards (-y)
    else:
        assert sag[0] > 0 and fast.tip[-1, 0] > plain.tip[-1, 0]  # it stretches along its length


def test_3d_paths_agree_under_gravity() -> None:
    ramp_spec = RampSpec(pressure=0.02, steps=StepSettings(increments=2, substeps=1))
    unit_args = {"ramp_spec": ramp_spec, "gravity": "horizontal"}
    fast = Full3D(1, **unit_args).evaluate("1")
    slow = Full3D(1, backend="felupe", **unit_args).evaluate("1")
    np.testing.assert_allclose(fast.centres, slow.centres, rtol=0, atol=1e-6)
    assert fast.metadata["gravity_mm_s2"] == [0.0, -STANDARD_GRAVITY, 0.0]


def test_gravity_changes_the_fingerprint_only_when_set() -> None:
    plain, none = Reduced2D(2), Reduced2D(2, gravity="none")
    assert plain.fingerprint() == none.fingerprint() and "gravity_mm_s2" not in plain.describe()
    assert Reduced2D(2, gravity="hanging").fingerprint() != plain.fingerprint()


def test_bad_gravity_is_refused() -> None:
    with pytest.raises(ValueError, match="unknown gravity set-up 'sideways'"):
        gravity_vector("sideways", 3)
    with pytest.raises(ValueError, match="no z axis"):
        Reduced2D(2, gravity=(0.0, 0.0, -9806.65))
    with pytest.raises(ValueError, match="symmetry of the half model"):
        Full3D(2, gravity=(0.0, 0.0, -9806.65))
    with pytest.raises(ValueError, match="2 or 3 finite components"):
        gravity_vector([1.0, float("nan")], 2)
    with pytest.raises(SearchConfigError, match=r"\[model\] gravity"):
        make_model(2, {"gravity": "upside-down"})
    assert make_model(2, {"gravity": "hanging"}).gravity == (STANDARD_GRAVITY, 0.0)


def test_gravity_needs_densities(monkeypatch: pytest.MonkeyPatch) -> None:
    from dataclasses import replace

    from pneumorph.models.fe import base as febase

    real = febase.get  # FEModel's materials

    def without_density(name: str):  # type: ignore[no-untyped-def]
        return replace(real(name), density=None)

    monkeypatch.setattr(febase, "get", without_density)
    with pytest.raises(MaterialDataError, match="gravity needs the density of 'mold_star_15'"):
        Reduced2D(2, gravity="hanging")
    Reduced2D(2)  # without gravity no density is needed
