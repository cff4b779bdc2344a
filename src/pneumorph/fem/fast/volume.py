"""A volume-controlled ramp on the fast path: the cavities' volume drives, the pressure is an unknown.

A pressure-controlled ramp cannot pass a maximum of the pressure (a wall that balloons: no
equilibrium at a higher pressure nearby). The enclosed volume ``V`` - the work-conjugate of
the pressure, what a syringe pump drives - rises through it. :class:`VolumeControl` is a
substep strategy of :func:`pneumorph.fem.ramp` whose load factor ``t`` sets the volume,

    V(u) = V0 (1 + t change),

and whose unknowns are the displacements ``u`` and the model's load factor ``lambda``
(the pressure ``lambda`` times the model's top pressure). Newton's method on

    r(u, lambda) = 0,    V(u) - V* = 0

is the bordered system ``[K, r_lambda; g^T, 0]`` with ``r_lambda`` the walls' load at unit
pressure times ``dp/dlambda`` and ``g = dV/du`` (minus the sum of the walls' unit loads,
the derivative of the enclosed volume over closed cavities). It is solved by block
elimination with the one factorisation of ``K``: ``a = K^-1 r``, ``b = K^-1 r_lambda``,

    d lambda = (c - g.a) / (g.b),    du = -a - b d lambda,

so the CSR pattern, PARDISO's kept analysis and the tangent's symmetry are those of the
pressure ramp; past the limit point ``K`` is indefinite and the bordered system is not
singular. The iteration is :class:`~pneumorph.fem.fast.newton.FastSubstep`'s, with the load
factor as a border (:meth:`VolumeControl.step`): kept tangents with Anderson acceleration,
the step limit and line search at obstacles and the switch of a stalled single-precision
factorisation to double precision are those of the pressure ramp.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import SettingsError
from pneumorph.fem.fast.newton import FastSubstep

FloatArray = NDArray[np.float64]


class VolumeControl:
    """Volume-controlled substeps of :func:`pneumorph.fem.ramp` on a fast system.

    Pass :meth:`apply` as the ramp's ``apply`` and the object itself as its ``substep``
    (and no monitor: the volume only rises). The ramp's factor ``t`` sets the target volume
    ``V0 (1 + t change)``; the load factor that holds it is found with the displacements
    and read from ``factor`` after each converged substep.

    Parameters
    ----------
    substep : FastSubstep
        Its system, solver and tangent reuse are used (``reuse`` None: a fresh tangent at
        every iteration).
    apply : callable
        The model's ``apply(lambda)``: sets the walls' pressure ``lambda`` times the top
        pressure (linear in ``lambda``) and whatever follows the pressure.
    change : float
        The relative volume change ``V / V0 - 1`` at the ramp's end (> -1).
    u0 : ndarray
        The displacements the ramp starts from (its volume is ``V0``).

    Attributes
    ----------
    factor : float
        The load factor of the current state (the last converged one after a substep).
    volume0 : float
        The enclosed volume at the start.

    Examples
    --------
    A pressurised square hole in a plate: the volume ramp ends on the pressure ramp's state.

    >>> import numpy as np
    >>> from pneumorph.fem import StepSettings, ramp
    >>> from pneumorph.fem.fast.volume import example_plate
    >>> body, apply, step = example_plate()
    >>> settings = StepSettings(increments=2, substeps=1)
    >>> _ = ramp(body.items, body.field, apply, body.dof1, body.dof0, settings, substep=step)
    >>> area = step.system.cavity_volume(body.displacement.ravel())
    >>> body2, apply2, step2 = example_plate()
    >>> control = VolumeControl(step2, apply2, area / step2.system.cavity_volume(0 * body2.displacement.ravel()) - 1,
    ...                         body2.displacement.ravel())
    >>> _ = ramp(body2.items, body2.field, control.apply, body2.dof1, body2.dof0, settings, substep=control)
    >>> round(control.factor, 6), bool(np.allclose(body2.displacement, body.displacement, atol=1e-6))
    (1.0, True)
    """

    def __init__(self, substep: FastSubstep, apply: Callable[[float], None], change: float, u0: FloatArray) -> None:
        if not (np.isfinite(change) and change > -1.0):
            raise ValueError(f"the volume change must be a finite number above -1, got {change}")
        self.substep = substep
        self.system = substep.system
        self.load = apply
        self.change = float(change)
        self.volume0 = float(self.system.cavity_volume(np.asarray(u0, dtype=float).ravel()))
        if not self.volume0 > 0.0:
            raise ValueError(f"the enclosed volume must be positive, got {self.volume0:.6g}")
        pressures = []
        for t in (0.0, 1.0):
            apply(t)
            pressures.append(np.array([float(w.item.results.pressure) for w in self.system.walls]))
        self.slopes = pressures[1] - pressures[0]  # dp/dlambda of every wall
        self.factor = 0.0
        self.target = self.volume0
        self._t = 0.0
        self.history: list[tuple[float, float]] = [(0.0, 0.0)]  # converged (t, lambda)
        apply(0.0)

    @property
    def factorisations(self) -> int:
        return int(self.substep.factorisations)

    @property
    def precision(self) -> str:
        return self.substep.precision

    def apply(self, t: float) -> None:
        """The ramp's ``apply``: the target volume of factor ``t`` and the predicted load factor."""
        self._t = float(t)
        self.target = self.volume0 * (1.0 + t * self.change)
        known = [h for h in self.history if h[0] <= t + 1e-14]
        (t1, f1) = known[-1]
        if t > t1 + 1e-14 and len(known) > 1:
            t0, f0 = known[-2]
            f1 = f1 + (f1 - f0) * (t - t1) / (t1 - t0)  # linear extrapolation of the load factor
        self._set(f1)

    def _set(self, factor: float) -> None:
        self.factor = float(factor)
        self.load(self.factor)

    def start(self) -> FloatArray:
        """The extra unknown of the substep's Newton loop: the load factor now."""
        return np.array([self.factor])

    def set(self, x: FloatArray) -> None:
        """Set the load factor ``x[0]``."""
        self._set(float(x[0]))

    def error(self, u: FloatArray) -> float:
        """The relative volume error at ``u``."""
        return float(abs(self.system.cavity_volume(u) - self.target) / self.volume0)

    def step(self, substep: FastSubstep, u: FloatArray, r: FloatArray) -> FloatArray:
        """The bordered Newton step (du over the active dofs, then d lambda) with the factorised tangent."""
        dof1 = self.system.dof1
        loads = self.system.wall_loads(u)
        r_factor = sum((s * load for s, load in zip(self.slopes, loads, strict=True)), start=np.zeros_like(u))
        g = -sum(loads, start=np.zeros_like(u))[dof1]  # dV/du
        a = substep.solve(r[dof1])
        b = substep.solve(r_factor[dof1])
        dfactor = (self.system.cavity_volume(u) - self.target - g @ a) / (g @ b)
        return np.append(-a - b * dfactor, dfactor)

    def __call__(self, fields: Any, settings: Any) -> tuple[int, str | None]:
        """Solve one substep from the values in ``fields`` (written back on convergence) with the substep's
        Newton loop, bordered by the load factor."""
        iterations, cause = self.substep(fields, settings, border=self)
        if cause is None:
            self.history = [*self.history[-2:], (self._t, self.factor)]
        return iterations, cause


def volume_control(change: float | None, substep: Any, apply: Callable[[float], None],
                   displacement: FloatArray) -> VolumeControl | None:
    """The ramp's :class:`VolumeControl` for a relative volume ``change``, or None without one (pressure control).

    Raises
    ------
    SettingsError
        Volume control on the FElupe backend (it needs the fast path's system).

    >>> volume_control(None, None, print, np.zeros(3)) is None
    True
    """
    if change is None:
        return None
    if not isinstance(substep, FastSubstep):
        raise SettingsError("volume control needs the fast backend (backend = \"fast\")")
    return VolumeControl(substep, apply, change, np.asarray(displacement).ravel())


def example_plate(wall: float = 1.0, cells_per_mm: int = 2, pressure: float = 0.02,
                  reuse: float | None = None) -> tuple[Any, Callable[[float], None], FastSubstep]:
    """A small plane-strain plate, 3 x 3 mm, with a pressurised square hole, for examples and tests.

    Returns the :class:`~pneumorph.fem.body.PressurisedBody`, its ``apply(t)`` (pressure
    ``t`` times ``pressure`` MPa) and a :class:`FastSubstep` on it (tangent ``reuse``).
    The walls around the hole are ``wall`` mm thick (a multiple of ``1 / cells_per_mm``);
    Ogden silicone (mu 0.03 MPa, alpha 2: neo-Hooke, bulk modulus 0.3 MPa); quad8 cells;
    the bottom edge clamped.
    """
    import felupe as fem

    from pneumorph.fem.body import pressurised_body
    from pneumorph.fem.ogden import OgdenCompressible

    mesh = fem.Rectangle(b=(3.0, 3.0), n=3 * cells_per_mm + 1).add_midpoints_edges()
    points = mesh.points
    centre = points[mesh.cells].mean(axis=1)
    half = 1.5 - wall
    hole = (np.abs(centre[:, 0] - 1.5) < half) & (np.abs(centre[:, 1] - 1.5) < half)
    cells = mesh.cells[~hole]
    used = np.unique(cells)
    renumber = np.full(len(points), -1)
    renumber[used] = np.arange(used.size)
    points, cells = points[used], renumber[cells]
    cavity = (np.abs(points[:, 0] - 1.5) <= half + 1e-9) & (np.abs(points[:, 1] - 1.5) <= half + 1e-9)
    base = points[:, 1] < 1e-9
    umat = OgdenCompressible(mu=[0.03], alpha=[2.0], bulk=0.3)
    body = pressurised_body(points, cells, "quad8", [("silicone", np.ones(len(cells), dtype=bool), umat)],
                            cavity, base)
    step, _ = body.stepper("fast", reuse=reuse)

    def apply(t: float) -> None:
        body.pressure.update(pressure * t)

    return body, apply, step
