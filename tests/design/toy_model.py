"""An analytical stand-in for an actuator model, for testing the design search only.

It is not a model of any real actuator. It is a chain of rigid segments (one per unit,
10.5 mm long) in which unit ``i`` turns by ``+theta_i(p)`` (orientation 0) or
``-theta_i(p)`` (orientation 1). ``theta_i`` grows nonlinearly with pressure, differs from
unit to unit (a fixed, uneven stiffness profile along the chain) and grows when a
neighbour faces the same way (so designs interact and the search is not separable).
Inverting every unit mirrors the shape exactly (y -> -y), like the finite-element models.
It is cheap, deterministic and satisfies :class:`pneumorph.models.ActuatorModel`.
"""

from __future__ import annotations

import hashlib
import json
import math

import numpy as np

from pneumorph.errors import SimulationFailed
from pneumorph.geometry.orientation import parse_orientation
from pneumorph.models.response import Response


class ToyModel:
    """A chain of rigid segments with pressure-dependent turns (test double).

    Parameters
    ----------
    n_units : int
        Number of units.
    p_max : float
        The last reported pressure (MPa); ``levels`` equal increments up to it.
    levels : int
        Number of reported pressures.
    turn : float
        Turn of an average unit at ``p_max`` in degrees.
    fail : set of str
        Designs whose ramp "fails" (raises SimulationFailed half way).
    """

    fidelity = "toy"
    unit_length = 10.5

    def __init__(
        self,
        n_units: int = 8,
        p_max: float = 0.045,
        levels: int = 10,
        turn: float = 30.0,
        fail: frozenset[str] | set[str] = frozenset(),
    ) -> None:
        self.n_units = n_units
        self.p_max = p_max
        self.levels = levels
        self.turn = turn
        self.fail = frozenset(fail)
        self.calls: list[str] = []
        i = np.arange(n_units)
        self.stiffness = 1.0 + 0.35 * np.sin(1.7 * i + 0.4)  # uneven along the chain

    def fingerprint(self) -> str:
        spec = {"n": self.n_units, "p": self.p_max, "k": self.levels, "turn": self.turn, "fail": sorted(self.fail)}
        return hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:16]

    def pressures(self) -> np.ndarray:
        return self.p_max * np.arange(1, self.levels + 1) / self.levels

    def _turns(self, bits: np.ndarray, p: float) -> np.ndarray:
        sign = np.where(bits == 0, 1.0, -1.0)
        same = np.zeros(len(bits))
        same[1:] += bits[1:] == bits[:-1]
        same[:-1] += bits[:-1] == bits[1:]
        amount = math.radians(self.turn) * (p / self.p_max) ** 1.5
        return sign * amount * self.stiffness * (1.0 + 0.3 * same)

    def evaluate(self, orientation: str) -> Response:
        design = parse_orientation(orientation, self.n_units)
        self.calls.append(design)
        bits = np.array([int(c) for c in design])
        n, ell = self.n_units, self.unit_length
        ref = np.column_stack([ell * (np.arange(n) + 0.5), np.zeros(n)])
        p = self.pressures()
        r = Response.empty(design, p, ref, np.array([n * ell, 0.0]), metadata={"fidelity": self.fidelity})
        if design in self.fail:
            raise SimulationFailed(0.5, "toy failure", design=design, pressure=self.p_max)
        for k, pk in enumerate(p):
            pos, phi = np.zeros(2), 0.0
            stretch = 1.0 + 0.04 * pk / self.p_max
            for i, t in enumerate(self._turns(bits, pk)):
                phi += t / 2
                r.centres[k, i] = pos + 0.5 * ell * stretch * np.array([math.cos(phi), math.sin(phi)])
                phi += t / 2
                pos = r.centres[k, i] + 0.5 * ell * stretch * np.array([math.cos(phi), math.sin(phi)])
            r.tip[k] = pos
            r.curl[k] = math.degrees(phi)
        return Response(
            orientation=r.orientation,
            pressures=r.pressures,
            centres=r.centres,
            reference_centres=r.reference_centres,
            tip=r.tip,
            reference_tip=r.reference_tip,
            curl=r.curl,
            converged=True,
            reached=float(p[-1]),
            metadata=r.metadata,
        )


class DyingToy(ToyModel):
    """Solves ``budget`` designs, then raises ``signal`` (same fingerprint as the plain toy)."""

    def __init__(self, budget: int, signal: type[BaseException] = KeyboardInterrupt, **kw: object) -> None:
        super().__init__(**kw)
        self.budget = budget
        self.signal = signal

    def evaluate(self, orientation: str):  # type: ignore[no-untyped-def]
        if len(self.calls) >= self.budget:
            raise self.signal()
        return super().evaluate(orientation)
