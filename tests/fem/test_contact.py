"""Rigid obstacles in the fast assembler (:mod:`pneumorph.fem.fast.contact`): the penalty's residual and tangent,
a ramp that closes contact mid-way, the balance of forces, and FElupe's own rigid contact as the reference."""

from __future__ import annotations

import felupe as fem
import numpy as np
import pytest
import scipy.sparse.linalg as spla

from pneumorph.errors import SettingsError
from pneumorph.fem import OgdenCompressible, StepSettings, ramp
from pneumorph.fem.body import pressurised_body
from pneumorph.fem.fast.contact import RigidContact, penalty_gap, surface_points
from pneumorph.fem.fast.shapes import Cylinder, Plane, Sphere, obstacle_from_dict, start_inside
from pneumorph.fem.fast.system import PlaneStrainSystem, SolidSystem3D

UMAT = OgdenCompressible([0.03], [2.0], 0.3)


def _beam(length: float = 20.0, cell_type: str = "quad8") -> tuple[np.ndarray, np.ndarray]:
    mesh = fem.Rectangle(b=(length, 2.0), n=(int(length) + 1, 3))
    if cell_type == "quad8":
        mesh = mesh.add_midpoints_edges()
    return np.asarray(mesh.points), np.asarray(mesh.cells)


def _body(points: np.ndarray, cells: np.ndarray, cell_type: str, density: float | None = None) -> object:
    """A solid without a cavity, clamped at x = 0 (a weight if a density is given)."""
    return pressurised_body(points, cells, cell_type, [("s", np.ones(len(cells), bool), UMAT)],
                            np.zeros(len(points), bool), points[:, 0] == 0.0,
                            densities=None if density is None else {"s": density})


def _fd_check(system: object, u: np.ndarray, h: float = 1e-7) -> float:
    """Largest difference between the tangent and the finite differences of the residual, over its largest entry."""
    r0, _ = system.residual(u)
    K = system.tangent().toarray()
    fd = np.zeros_like(K)
    for j, dof in enumerate(system.dof1):
        du = np.zeros_like(u)
        du[dof] = h
        fd[:, j] = ((system.residual(u + du)[0] - r0) / h)[system.dof1]
    return float(np.abs(K - fd).max() / np.abs(K).max())


def _stick_and_slide(contact: RigidContact, obstacle: object, x: np.ndarray, nodes: np.ndarray) -> None:
    """Anchors a little off the nodes at ``x``: some nodes in contact stick, the others slide (friction 0.5)."""
    contact.anchors = x[nodes] + np.random.default_rng(1).normal(0.0, 0.3, (len(nodes), x.shape[1]))
    force, active = contact.forces(x)
    n = obstacle.kinematics(x[nodes])[1]  # type: ignore[attr-defined]
    normal = np.einsum("ai,ai->a", force, n)
    along = np.linalg.norm(force - normal[:, None] * n, axis=1)
    sliding = active & np.isclose(along, 0.5 * np.abs(normal), rtol=1e-9)
    assert np.any(sliding) and np.any(active & ~sliding)


@pytest.mark.parametrize("obstacle", [Plane((3.75, 0.0), (-0.8, -0.6)), Cylinder((4.6, 1.0), 0.9),
                                      Sphere((4.6, 1.0), 0.9)], ids=["plane", "circle", "sphere"])
@pytest.mark.parametrize("smoothing", [0.0, 0.2])
def test_tangent_is_the_residuals_derivative_2d(obstacle: object, smoothing: float) -> None:
    points, cells = _beam(4.0)
    body = _body(points, cells, "quad8")
    faces, nodes = surface_points(cells, "quad8")
    body.contacts.append(RigidContact(obstacle, nodes, 3.0, faces, smoothing))
    system = PlaneStrainSystem(body.items, body.field, body.dof1, body.dof0)
    u = np.zeros(system.ndof)
    u[0::2] = 0.05 * points[:, 0]  # the free end pushed into the obstacle
    assert body.contacts[0].forces(points + u.reshape(-1, 2))[1].sum() >= 2
    assert _fd_check(system, u) < 1e-5


def test_tangent_is_the_residuals_derivative_3d() -> None:
    mesh = fem.Cube(b=(3.0, 1.0, 1.0), n=(4, 2, 2))
    points, cells = np.asarray(mesh.points), np.asarray(mesh.cells)
    body = _body(points, cells, "hexahedron")
    faces, nodes = surface_points(cells, "hexahedron")
    body.contacts.append(RigidContact(Cylinder((3.5, 0.5, 0.5), 0.8, (0.0, 0.6, 0.8)), nodes, 2.0, faces, 0.05))
    system = SolidSystem3D(body.items, body.field, body.dof1, body.dof0)
    u = np.zeros(system.ndof)
    u[0::3] = 0.05 * points[:, 0]
    assert body.contacts[0].forces(points + u.reshape(-1, 3))[1].sum() >= 2
    assert _fd_check(system, u) < 1e-5


@pytest.mark.parametrize("obstacle", [Plane((3.75, 0.0), (-0.8, -0.6)), Cylinder((4.6, 1.0), 0.9)],
                         ids=["plane", "circle"])
def test_friction_tangent_is_the_residuals_derivative(obstacle: object) -> None:
    """Anchors a little off: some nodes in contact stick, the others slide."""
    points, cells = _beam(4.0)
    body = _body(points, cells, "quad8")
    faces, nodes = surface_points(cells, "quad8")
    contact = RigidContact(obstacle, nodes, 3.0, faces, 0.2, friction=0.5)
    body.contacts.append(contact)
    system = PlaneStrainSystem(body.items, body.field, body.dof1, body.dof0)
    u = np.zeros(system.ndof)
    u[0::2] = 0.05 * points[:, 0]
    x = points + u.reshape(-1, 2)
    _stick_and_slide(contact, obstacle, x, nodes)
    assert _fd_check(system, u) < 1e-5


@pytest.mark.parametrize("obstacle", [Plane((2.9, 0.0, 0.0), (-0.8, -0.6, 0.0)),
                                      Cylinder((3.5, 0.5, 0.5), 0.8, (0.0, 0.6, 0.8))], ids=["plane", "cylinder"])
def test_friction_tangent_is_the_residuals_derivative_3d(obstacle: object) -> None:
    """The symmetric 3D tangent and its remainder (the non-symmetric rest of the friction blocks) together are the
    residual's derivative, with some nodes sticking and others sliding; the remainder is no rounding."""
    mesh = fem.Cube(b=(3.0, 1.0, 1.0), n=(4, 2, 2))
    points, cells = np.asarray(mesh.points), np.asarray(mesh.cells)
    body = _body(points, cells, "hexahedron")
    faces, nodes = surface_points(cells, "hexahedron")
    contact = RigidContact(obstacle, nodes, 2.0, faces, 0.05, friction=0.5)
    body.contacts.append(contact)
    system = SolidSystem3D(body.items, body.field, body.dof1, body.dof0)
    u = np.zeros(system.ndof)
    u[0::3] = 0.05 * points[:, 0]
    x = points + u.reshape(-1, 3)
    _stick_and_slide(contact, obstacle, x, nodes)
    assert _fd_check(system, u) < 1e-5
    system.residual(u)
    upper = system.tangent_data()
    assert system.remainder is not None and abs(system.remainder).max() > 1e-2 * np.abs(upper).max()


def test_penalty_blend_is_continuous_and_its_slope_too() -> None:
    s = 0.1
    gap = np.array([-s - 1e-9, -s + 1e-9, s - 1e-9, s + 1e-9])
    phi, slope = penalty_gap(gap, s)
    assert phi[0] == pytest.approx(phi[1], abs=1e-8) and phi[2] == pytest.approx(phi[3], abs=1e-8)
    assert slope[0] == pytest.approx(slope[1], abs=1e-7) and slope[2] == pytest.approx(slope[3], abs=1e-7)
    eps = 1e-7  # the slope is phi's derivative
    g = np.linspace(-2 * s, 2 * s, 41)
    assert np.allclose((penalty_gap(g + eps, s)[0] - penalty_gap(g - eps, s)[0]) / (2 * eps), penalty_gap(g, s)[1],
                       atol=1e-6)


def test_a_sagging_cantilever_lands_on_a_floor_mid_ramp() -> None:
    """Its weight goes to the clamp and the floor; the floor takes nothing before the tip reaches it."""
    points, cells = _beam()
    body = _body(points, cells, "quad8", density=1.1e-9)
    faces, nodes = surface_points(cells, "quad8")
    body.contacts.append(RigidContact(Plane((0.0, -1.5), (0.0, 1.0)), nodes, 3.0, faces, 0.02))
    substep, _ = body.stepper("fast")
    g = np.array([0.0, -9810.0])
    forces, reactions, weights = [], [], []

    def record(k: int, t: float) -> None:
        u = body.displacement
        r = substep.system.residual(u.ravel())[0].reshape(-1, 2)
        forces.append(body.contacts[0].report(points + u)["force"])
        reactions.append(r[points[:, 0] == 0.0].sum(axis=0))
        weights.append(substep.system.dead.vector().reshape(-1, 2).sum(axis=0))

    ramp(body.items, body.field, lambda t: body.set_gravity(t * g), body.dof1, body.dof0,
         StepSettings(increments=5, substeps=2), on_level=record, substep=substep)
    forces_y = np.array(forces)[:, 1]
    assert forces_y[0] == 0.0 and forces_y[-1] < 0.0  # contact closes within the ramp, pressed down
    # clamp + floor = weight: the clamp's reaction on the beam is the floor's force minus the weight
    for force, reaction, weight in zip(forces, reactions, weights, strict=True):
        assert np.allclose(reaction, force - weight, rtol=0.0, atol=1e-6 * np.abs(weight).max())
    assert body.displacement[:, 1].min() > -1.5 - 0.05  # penetration within a small part of an element


def test_friction_holds_the_landing_tip_within_its_cone() -> None:
    """With friction the floor also pushes along itself, never beyond the cone; clamp + floor = weight still."""
    points, cells = _beam()
    body = _body(points, cells, "quad8", density=1.1e-9)
    faces, nodes = surface_points(cells, "quad8")
    contact = RigidContact(Plane((0.0, -1.5), (0.0, 1.0)), nodes, 3.0, faces, 0.02, friction=0.5)
    contact.commit(points)
    body.contacts.append(contact)
    substep, _ = body.stepper("fast")
    g = np.array([0.0, -9810.0])

    def committed(t: float) -> None:
        contact.commit(points + body.displacement)

    ramp(body.items, body.field, lambda t: body.set_gravity(t * g), body.dof1, body.dof0,
         StepSettings(increments=5, substeps=2), substep=substep, on_substep=committed)
    force, active = contact.forces(points + body.displacement)
    assert np.abs(force[active, 0]).max() > 1e-3 * np.abs(force[active, 1]).max()  # friction acts
    assert np.all(np.abs(force[:, 0]) <= 0.5 * np.abs(force[:, 1]) * (1 + 1e-9) + 1e-15)  # within the cone
    r = substep.system.residual(body.displacement.ravel())[0].reshape(-1, 2)
    weight = substep.system.dead.vector().reshape(-1, 2).sum(axis=0)
    assert np.allclose(r[points[:, 0] == 0.0].sum(axis=0), force.sum(axis=0) - weight, atol=1e-6 * abs(weight[1]))


@pytest.mark.parametrize("friction", [0.0, 0.5])
def test_a_3d_cantilever_lands_on_a_rough_floor(friction: float) -> None:
    """In 3D (a symmetric factorisation, the friction's non-symmetric rest solved by GMRES) the landing tip slides
    at the edge of its cone; clamp + floor = weight; friction 0 is the frictionless path (no remainder, no
    tangential force)."""
    mesh = fem.Cube(b=(20.0, 2.0, 2.0), n=(11, 3, 3))
    points, cells = np.asarray(mesh.points), np.asarray(mesh.cells)
    body = _body(points, cells, "hexahedron", density=1.1e-9)
    faces, nodes = surface_points(cells, "hexahedron")
    contact = RigidContact(Plane((0.0, -1.5, 0.0), (0.0, 1.0, 0.0)), nodes, 3.0, faces, 0.02, friction=friction)
    contact.commit(points)
    body.contacts.append(contact)
    substep, _ = body.stepper("fast", reuse=0.5, depth=2)
    remainders = []

    def committed(t: float) -> None:
        contact.commit(points + body.displacement)
        remainders.append(substep.system.remainder is not None)

    g = np.array([0.0, -9810.0, 0.0])
    ramp(body.items, body.field, lambda t: body.set_gravity(t * g), body.dof1, body.dof0,
         StepSettings(increments=5, substeps=2), substep=substep, on_substep=committed)
    force, active = contact.forces(points + body.displacement)
    assert active.sum() >= 2 and force[:, 1].sum() < 0.0  # pressed down
    if friction == 0.0:
        assert not any(remainders) and np.all(force[:, [0, 2]] == 0.0)
    else:  # the tip slides back along the floor as it lands: friction at the cone's edge, against it
        assert any(remainders) and force[:, 0].sum() > 0.0
        assert np.allclose(np.linalg.norm(force[active][:, [0, 2]], axis=1), 0.5 * np.abs(force[active, 1]), rtol=1e-6)
    r = substep.system.residual(body.displacement.ravel())[0].reshape(-1, 3)
    weight = substep.system.dead.vector().reshape(-1, 3).sum(axis=0)
    assert np.allclose(r[points[:, 0] == 0.0].sum(axis=0), force.sum(axis=0) - weight, atol=1e-6 * abs(weight[1]))


def test_the_same_penalty_as_felupes_rigid_plane() -> None:
    """FElupe's ``ContactRigidPlane`` (its multiplier the penalty, no friction) on the same block: the same state."""
    mesh = fem.Rectangle(b=(4.0, 1.0), n=(9, 3))
    mesh.update(points=np.vstack([mesh.points, [[5.0, 0.5]]]))  # FElupe's centre point of the plane
    points = np.asarray(mesh.points)
    solid_points = np.arange(len(points) - 1)
    umat = fem.NeoHookeCompressible(mu=1.0, lmbda=2.0)
    field = fem.FieldContainer([fem.FieldPlaneStrain(fem.RegionQuad(mesh), dim=2)])
    solid = fem.SolidBody(umat, field)
    load = fem.SolidBodyForce(field, values=[0.4, 0.0])
    clamp = {"x0": fem.Boundary(field[0], fx=0.0), "centre": fem.Boundary(field[0], fx=5.0)}
    dof0, dof1 = fem.dof.partition(field, clamp)
    wall = points[solid_points, 0] == 4.0
    reference = fem.ContactRigidPlane(field, solid_points[wall], len(points) - 1, normal=[-1.0, 0.0],
                                      multiplier=5.0)
    fem.newtonraphson(field, items=[solid, load, reference], dof1=dof1, dof0=dof0, tol=1e-10, verbose=0)
    u_felupe = field[0].values.copy()
    # the fast system: the plane through FElupe's centre point, which is held
    field[0].values[:] = 0.0
    contact = RigidContact(Plane((5.0, 0.0), (-1.0, 0.0)), solid_points[wall], 5.0)
    system = PlaneStrainSystem([solid, load, contact], field, dof1, dof0)
    u = np.zeros(system.ndof)
    for _ in range(20):
        r, _ = system.residual(u)
        if np.linalg.norm(r[dof1]) < 1e-11:
            break
        u[dof1] -= spla.spsolve(system.tangent().tocsc(), r[dof1])
    assert np.abs(u_felupe[:-1, 0]).max() > 0.05  # the load moved the block against the plane
    assert np.allclose(u.reshape(-1, 2)[:-1], u_felupe[:-1], atol=1e-8)


def test_bad_obstacles_are_refused() -> None:
    with pytest.raises(SettingsError, match="radius"):
        obstacle_from_dict({"kind": "sphere", "centre": [0, 0], "radius": -1.0}, 2)
    with pytest.raises(SettingsError, match="zero"):
        obstacle_from_dict({"kind": "plane", "point": [0, 0], "normal": [0, 0]}, 2)
    with pytest.raises(SettingsError, match="finite"):
        obstacle_from_dict({"kind": "plane", "point": [float("nan"), 0], "normal": [1, 0]}, 2)
    for friction in (-0.1, float("nan"), "0.5"):
        with pytest.raises(SettingsError, match="friction"):
            obstacle_from_dict({"kind": "plane", "point": [0, 0], "normal": [1, 0], "friction": friction}, 2)
    with pytest.raises(SettingsError, match="axis"):
        obstacle_from_dict({"kind": "cylinder", "centre": [0, 0, 0], "radius": 1.0}, 3)
    points, _ = _beam(4.0, "quad")
    assert "starts inside" in (start_inside([Sphere((4.0, 1.0), 0.5)], points) or "")
    assert start_inside([Sphere((5.0, 1.0), 0.5), Plane((4.0, 0.0), (-1.0, 0.0))], points) is None  # touching


def test_a_block_pressed_on_a_floor_has_the_contact_pressure_of_its_stress() -> None:
    """A block compressed from its top onto a frictionless floor is in a uniform state: every node on the floor
    carries the pressure of the top's reaction over the (deformed) width, quadratic elements and all."""
    mesh = fem.Rectangle(b=(2.0, 4.0), n=(5, 9)).add_midpoints_edges()
    points = np.asarray(mesh.points)
    field = fem.FieldContainer([fem.FieldPlaneStrain(fem.RegionQuadraticQuad(mesh), dim=2)])
    solid = fem.SolidBody(fem.NeoHookeCompressible(mu=1.0, lmbda=2.0), field)
    top = points[:, 1] == 4.0
    held = {"roller": fem.Boundary(field[0], fx=0.0, skip=(0, 1)), "top": fem.Boundary(field[0], fy=4.0, skip=(1, 0))}
    dof0, dof1 = fem.dof.partition(field, held)
    faces, nodes = surface_points(np.asarray(mesh.cells), "quad8")
    contact = RigidContact(Plane((0.0, 0.0), (0.0, 1.0)), nodes, 1e4, faces)  # stiff: the floor barely let in
    system = PlaneStrainSystem([solid, contact], field, dof1, dof0)
    u = np.zeros_like(points)
    u[:, 1] = -0.05 * points[:, 1] / 4.0  # the top 0.05 mm down
    u = u.ravel()
    for _ in range(20):
        r, _ = system.residual(u)
        if np.linalg.norm(r[dof1]) < 1e-13:
            break
        u[dof1] -= spla.spsolve(system.tangent().tocsc(), r[dof1])
    x = points + u.reshape(-1, 2)
    report = contact.report(x)
    pressure = -r.reshape(-1, 2)[top, 1].sum() / x[top, 0].max()  # MPa: the top's reaction over the width
    assert pressure > 0.03 and sorted(report["nodes"].tolist()) == np.flatnonzero(points[:, 1] == 0.0).tolist()
    assert np.allclose(report["node_pressures"], pressure, rtol=1e-3)


def test_penalty_of_a_gap_past_the_range_of_a_square_warns_nothing() -> None:
    """An obstacle 1e300 mm across (a fuzzed radius) puts the nodes 1e300 mm inside or outside it: the blend's
    square is taken only within the blend, so the refusal that follows comes without an overflow warning."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        phi, slope = penalty_gap(np.array([-1e300, -0.05, 1e300]), 0.1)
    assert phi[[0, 2]].tolist() == [-1e300, 0.0] and slope[[0, 2]].tolist() == [1.0, 0.0]
    assert phi[1] == pytest.approx(-(0.15**2) / 0.4, rel=1e-12) and slope[1] == pytest.approx(0.75, rel=1e-12)
