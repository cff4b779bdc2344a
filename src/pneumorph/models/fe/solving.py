"""One design's pressure ramp solved on an FE model: every level recorded as it converges, the fields kept.

:func:`solve_design` is what :meth:`FEModel.solve <pneumorph.models.fe.base.FEModel.solve>` runs on the body the
model built: the stages before the ramp (the weight, the ramp's driver), the ramp itself, and at each reported
level the unit centres, the units' frames on the full width, the tip, the end face's curl (followed substep by
substep) and the forces on any obstacles. A completed ramp's :class:`~pneumorph.models.response.Response` carries
the solver's statistics; a failed one is raised with the levels it converged (``SimulationFailed.partial``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from pneumorph import __version__
from pneumorph.errors import SimulationFailed
from pneumorph.fem import RampStatistics, ramp
from pneumorph.geometry.alphabet import Design
from pneumorph.geometry.assembly import ActuatorMesh
from pneumorph.models.fe.obstacles import ContactRecord
from pneumorph.models.fe.ramp import past_the_maximum
from pneumorph.models.fe.stages import before_the_ramp
from pneumorph.models.frames import record_frames
from pneumorph.models.response import FloatArray, Response


@dataclass(frozen=True)
class Solution:
    """A solved design with its full fields, for figures and VTK files.

    Attributes
    ----------
    response : Response
        What the search sees.
    mesh : ActuatorMesh
        The meshed actuator.
    displacements : ndarray, shape (k, p, dim)
        Nodal displacements at every reported level (NaN after a failure).
    """

    response: Response
    mesh: ActuatorMesh
    displacements: FloatArray


def end_face_angle(x: FloatArray) -> float:
    """Angle (rad) of the end face, from its lowest to its highest point, against +y.

    >>> round(end_face_angle(np.array([[0.0, 0.0], [-1.0, 1.0]])) * 180 / np.pi, 6)  # leaning back: turned +45
    45.0
    """
    d = x[-1] - x[0]
    return float(np.arctan2(-d[0], d[1]))


def solve_design(model: Any, orientation: str | Design, on_level: Any = None) -> Solution:
    """Solve the pressure ramp of one design on ``model`` (an :class:`~pneumorph.models.fe.base.FEModel`).

    Parameters
    ----------
    model : FEModel
        The model: it parses the design, builds its mesh and body (:meth:`~pneumorph.models.fe.base.FEModel.build`)
        and gives the ramp's settings.
    orientation : str or Design
        The design, one digit per unit (``"0101..."``), or over the model's library
        (``"aAer..."``, :mod:`pneumorph.geometry.alphabet`); the response keeps its
        canonical text (0/1 digits for a one-type library).
    on_level : callable, optional
        ``on_level(k, pressure_mpa)`` after each reported level (progress).

    Raises
    ------
    SimulationFailed
        If the ramp cannot be completed; ``reached`` and ``pressure`` name how far it got, ``partial`` holds the
        levels it converged.
    OrientationError
        A design of the wrong length or with symbols the library does not have.

    Examples
    --------
    >>> from pneumorph.models.fe import Reduced2D, RampSpec
    >>> solution = solve_design(Reduced2D(2, ramp_spec=RampSpec(pressure=0.002)), "01")
    >>> solution.response.converged, solution.displacements.shape[0]
    (True, 10)
    """
    parsed = model.parse(orientation)
    design = parsed.text
    t0 = time.perf_counter()
    mesh, body, set_pressure = model.build(parsed if model.mixed else design)
    pressures = model.pressures()
    axes = mesh.axes  # (x, y), or (x, y, z) on the full width
    x_end0 = mesh.points[mesh.end_points][:, :axes]
    response = model.empty_response(mesh, design)
    turned = _EndTurn(x_end0[:, :2])
    displacements = np.full((len(pressures), *mesh.points.shape), np.nan)

    def apply(t: float) -> None:
        set_pressure(t * model.ramp.pressure)

    def follow(t: float) -> None:
        turned.follow(x_end0[:, :2] + body.displacement[:, :2][mesh.end_points])
        for item in body.contacts:  # friction's anchors: the converged state's
            item.commit(mesh.points + body.displacement)

    def tip_of(v: FloatArray) -> FloatArray:
        return (x_end0 + v[mesh.end_points][:, :axes]).mean(axis=0)

    def record(k: int, t: float) -> None:
        displacements[k] = body.displacement[:, : model.dim]
        response.centres[k] = mesh.unit_centres(displacements[k], axes)
        record_frames(response, k, mesh, displacements[k])  # the full width: each unit's and the end face's
        response.tip[k] = tip_of(displacements[k])
        response.curl[k] = np.degrees(turned.total)
        if control is not None:
            pressures[k] = response.pressures[k] = control.factor * model.ramp.pressure
        if contact is not None:  # the obstacles' forces, the base reaction
            contact.record(k, pressures[k], substep.system, displacements[k])
            response.metadata["contact"] = contact.metadata()
        if on_level is not None:
            on_level(k, pressures[k])

    substep, monitor = body.stepper(model.backend, model.tangent_reuse, model.anderson_depth)
    contact = ContactRecord(model.obstacles, mesh, body.contacts, mesh.symmetry_points is not None) \
        if model.obstacles else None
    apply, substep, control, gravity_iterations = before_the_ramp(model, body, substep, follow, design,
                                                                  response.metadata, tip_of, apply)
    try:
        stats = ramp(body.items, body.field, apply, body.dof1, body.dof0, model.ramp.steps, on_level=record,
                     monitor=monitor if control is None else None, on_substep=follow, substep=substep,
                     predictor_order=model.predictor_order_for(design), carry=model.carry_step)
    except SimulationFailed as exc:
        raise _failed(exc, response, control, model.ramp.pressure) from None
    final = converged_response(response, stats, substep, gravity_iterations, int(body.displacement.size), t0,
                               {"backend": model.backend, "quadrature": model.quadrature})
    return Solution(final, mesh, displacements)


class _EndTurn:
    """The end face's rotation (rad) from its start, followed substep by substep: through whole turns too."""

    def __init__(self, x: FloatArray) -> None:
        self.total = 0.0
        self.last = end_face_angle(x)

    def follow(self, x: FloatArray) -> None:
        """Add the turn from the last angle to that of the end face at ``x`` (the shorter way round)."""
        angle = end_face_angle(x)
        self.total += (angle - self.last + np.pi) % (2 * np.pi) - np.pi
        self.last = angle


def _failed(exc: SimulationFailed, response: Response, control: Any, pressure: float) -> SimulationFailed:
    """The ramp's failure ``exc`` for the caller: its cause (a limit point named as such) and the levels converged
    (``partial``); under volume control the pressure reached is the control's."""
    reached = exc.reached if control is None else control.factor
    cause = exc.cause if control is not None else past_the_maximum(exc)
    partial = replace(response, converged=False, reached=reached * pressure, failure=cause)
    return SimulationFailed(reached=exc.reached, cause=cause, design=response.orientation, pressure=pressure,
                            partial=partial)


def converged_response(response: Response, stats: RampStatistics, substep: Any, gravity_iterations: int, dofs: int,
                       t0: float, settings: dict[str, Any]) -> Response:
    """``response`` of a completed ramp, with the solver's statistics in its metadata.

    Parameters
    ----------
    response : Response
        The levels as recorded.
    stats : RampStatistics
        The pressure ramp's statistics; ``gravity_iterations`` those of the gravity stage.
    substep : callable
        The ramp's Newton solver (its factorisations and precision, if it keeps them).
    dofs : int
        The number of unknowns; ``t0`` the solve's start (:func:`time.perf_counter`).
    settings : dict
        The model's solver settings to record (its ``backend`` and ``quadrature``).
    """
    meta = dict(response.metadata)
    meta.update(
        newton_iterations=stats.newton_iterations + gravity_iterations,
        factorisations=getattr(substep, "factorisations", stats.newton_iterations),
        precision=getattr(substep, "precision", "double"),
        substeps=stats.substeps,
        cutbacks=stats.cutbacks,
        wall_time_s=time.perf_counter() - t0,
        dofs=dofs,
        **settings,
        pneumorph=__version__,
    )
    return replace(response, converged=True, reached=float(response.pressures[-1]), metadata=meta)
