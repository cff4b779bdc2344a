"""The steps of an identification: the scans aligned to the nominal model, the shapes' derivatives, one
step of the fit in a trust region (the combinations the scans do not determine held where they were), a
step checked against the FE model's residual, the fit checked by FE and the verdict on each parameter.
:func:`pneumorph.identify.fit.identify` runs them in order.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from itertools import pairwise
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.correlation.compare import ModelShape, check_units, correlate
from pneumorph.errors import FitError
from pneumorph.identify.linear import (
    MAX_DIRECTION_ERROR,
    MAX_SHARE,
    NO_EFFECT,
    Directions,
    LinearisedScan,
    LinearisedState,
    directions,
    linearised_system,
    project_out,
    residual_sigma,
    shape_nodes,
    solve_linearised,
)
from pneumorph.identify.match import check_coverage, check_size
from pneumorph.identify.parameters import NAMES, SPANS, STEPS

FloatArray = NDArray[np.float64]

#: the trust region: a step moves each parameter by at most this many plausible changes (``SPANS``); a
#: step that raises the FE model's residual is taken back and the region shrunk to a quarter of it
TRUST = 3.0
#: the iterations stop when every step is below this fraction of its standard error ...
STEP_FRACTION = 0.1
#: ... or below this (scaled) floor
STEP_FLOOR = 1e-3
#: a fit that moves a parameter further than this many plausible changes from nominal (a modulus by 30 %)
#: is not trusted: a scan's pressure or unit given wrong moves the moduli far and the others with them
MAX_PLAUSIBLE_CHANGES = 6.0


@dataclass
class FitState:
    """What the iterations carry from one to the next.

    ``free`` are the parameters fitted (those the scans do not depend on leave at the first
    iteration, their reason in ``notes``); ``hold`` the combinations of them the scans do not
    determine (found at the first iteration, kept where they were by every step); ``transforms``
    each scan's alignment; ``directions`` the last step's analysis of ``J^T J``; ``radius`` the
    trust region in plausible changes; ``cost`` the residual's sum of squares at ``theta``.
    """

    theta: FloatArray
    free: list[str]
    notes: dict[str, str]
    transforms: list[Any] = field(default_factory=list)
    residual_before: FloatArray | None = None
    hold: FloatArray | None = None
    directions: Directions | None = None
    normal: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    sigma: float = float("nan")
    step: FloatArray = field(default_factory=lambda: np.zeros(0))
    radius: float = TRUST
    cost: float = float("inf")
    converged: bool = False
    solves: int = 0
    iterations: int = 0

    @property
    def idx(self) -> list[int]:
        """The free parameters' indices in :data:`~pneumorph.identify.parameters.NAMES`."""
        return [NAMES.index(n) for n in self.free]

    @property
    def scale(self) -> FloatArray:
        """The free parameters' plausible changes."""
        return np.array([SPANS[n] for n in self.free])


def trial_points(theta: FloatArray, idx: list[int], upper: FloatArray) -> list[FloatArray]:
    """The Jacobian's points: each parameter of ``idx`` moved by its step (backwards at the top of the box).

    >>> [p.tolist() for p in trial_points(np.zeros(len(NAMES)), [0], np.ones(len(NAMES)))][0][0] == STEPS[NAMES[0]]
    True
    """
    trial = []
    for i in idx:
        h = STEPS[NAMES[i]] if theta[i] + STEPS[NAMES[i]] <= upper[i] + 1e-12 else -STEPS[NAMES[i]]
        v = theta.copy()
        v[i] += h
        trial.append(v)
    return trial


def nominal_alignment(observations: Sequence[Any], shapes: Sequence[ModelShape], dim: int
                      ) -> tuple[list[Any], FloatArray]:
    """Each scan checked against and aligned to its nominal shape: the alignments and the surface (3D) or
    outline (2D) RMS before the fit."""
    transforms, before = [], []
    for o, shape in zip(observations, shapes, strict=True):
        check_units(o.scan, shape)
        check_size(o.scan, o.spec, [shape])
        c = correlate(o.scan, shape)
        check_coverage(o.scan, o.spec, [shape], aligned=[c.aligned])
        transforms.append(c.alignment.transform)
        before.append(c.surface.rms if dim == 3 else c.outline.rms)
    return transforms, np.array(before)


def shape_derivatives(specs: Sequence[Any], shapes: Sequence[ModelShape],
                      moved: Sequence[Sequence[ModelShape]], idx: list[int], theta: FloatArray,
                      trial: list[FloatArray], dim: int) -> list[FloatArray]:
    """Per scan, the derivatives of its model's nodes by each parameter of ``idx`` (forward differences to the
    ``trial`` points' shapes ``moved[j][s]``; ``specs``: the scans' designs and pressures)."""
    derivatives = []
    for s in range(len(specs)):
        nodes, _ = shape_nodes(shapes[s], dim)
        per = []
        for j, i in enumerate(idx):
            other, _ = shape_nodes(moved[j][s], dim)
            if other.shape != nodes.shape:
                raise FitError(f"the mesh of design {specs[s].design} changed with {NAMES[i]} "
                               f"({other.shape[0]} against {nodes.shape[0]} surface nodes); nothing is identified")
            per.append((other - nodes) / (trial[j][i] - theta[i]))
        derivatives.append(np.array(per).reshape(len(idx), *nodes.shape))
    return derivatives


def linearise(shapes: Sequence[ModelShape], derivatives: Sequence[FloatArray] | None, dim: int
              ) -> list[LinearisedScan]:
    """Each scan's shape with its nodes' derivatives (none: the shape alone)."""
    lins = []
    for s, shape in enumerate(shapes):
        nodes, normals = shape_nodes(shape, dim)
        d = np.zeros((0, *nodes.shape)) if derivatives is None else derivatives[s]
        lins.append(LinearisedScan(dim, nodes, d, normals))
    return lins


def aligned_cost(state: FitState, shapes: Sequence[ModelShape], points: Sequence[FloatArray], dim: int
                 ) -> tuple[float, list[Any], FloatArray]:
    """The residual's sum of squares of ``shapes`` with every scan aligned to its shape afresh, the
    alignments and the residuals."""
    solved, r, _ = solve_linearised(linearise(shapes, None, dim), points, state.transforms, np.zeros(0),
                                    np.zeros(0), np.zeros(0))
    return float(r @ r), solved.transforms, r


def accept(state: FitState, shapes: Sequence[ModelShape], points: Sequence[FloatArray], dim: int,
           say: Callable[[str], None]) -> bool:
    """Whether the shapes at ``state.theta`` (the last step's point, solved) fit the scans better than the
    point the step came from; if so they become the fit's point (its cost and alignments), else the trust
    region shrinks to a quarter of the step."""
    cost, transforms, r = aligned_cost(state, shapes, points, dim)
    if state.residual_before is None:
        state.residual_before = per_scan_rms(r, points)
    if cost <= state.cost:
        state.cost, state.transforms = cost, transforms
        state.radius = min(TRUST, 2.0 * state.radius)
        return True
    state.radius = 0.25 * float(np.max(np.abs(state.step) / state.scale, initial=0.0))
    say(f"  the step raised the residual to {np.sqrt(cost / len(r)):.4g} mm: taken back, trust region "
        f"{state.radius:.3g} plausible changes")
    return False


def drop_no_effect(state: FitState, derivatives: list[FloatArray], lins: list[LinearisedScan],
                   points: Sequence[FloatArray], say: Callable[[str], None]) -> list[LinearisedScan]:
    """The parameters the scans do not depend on leave the fit (their columns dropped from ``derivatives``,
    in place); the scans' linearisations without them."""
    _, a, _ = linearised_system(lins, points, LinearisedState(np.zeros(len(state.free)), state.transforms),
                                state.scale)
    norms = np.linalg.norm(project_out(a, len(state.free)), axis=0)
    keep = [c for c in range(len(state.free)) if norms[c] > NO_EFFECT * float(norms.max(initial=0.0))]
    for c in range(len(state.free)):
        if c not in keep:
            state.notes[state.free[c]] = "the scans do not depend on it"
            say(f"{state.free[c]}: the scans do not depend on it; fixed at nominal")
    derivatives[:] = [d[keep] for d in derivatives]
    state.free = [state.free[c] for c in keep]
    return [LinearisedScan(lin.dim, lin.nodes, lin.derivatives[keep], lin.normals) for lin in lins]


def gauss_newton_step(state: FitState, dim: int, shapes: Sequence[ModelShape], derivatives: list[FloatArray],
                      points: Sequence[FloatArray], lower: FloatArray, upper: FloatArray,
                      say: Callable[[str], None]) -> bool:
    """One step of the linearised fit from ``state`` (updated in place); True when it has converged.

    At the first step the parameters the scans do not depend on leave the fit, and the combinations
    they do not determine (:func:`~pneumorph.identify.linear.directions`) are held where they are
    from then on, each said with its size; the step stays in the trust region ``state.radius``.
    """
    lins = linearise(shapes, derivatives, dim)
    if state.hold is None:
        lins = drop_no_effect(state, derivatives, lins, points, say)
        _, r, a = solve_linearised(lins, points, state.transforms, lower[state.idx] - state.theta[state.idx],
                                   upper[state.idx] - state.theta[state.idx], state.scale)
        found = analyse(state, r, a)
        state.hold = found.vectors[:, found.held]
        for j in map(int, np.flatnonzero(found.held)):
            say(f"the scans do not determine {found.combination(j)} (it changes them by "
                f"{found.scan_change(j):.2g} mm RMS; standard error {found.errors()[j]:.2g} plausible changes): "
                "held at nominal")
    idx, scale = state.idx, state.scale
    solved, r, a = solve_linearised(lins, points, state.transforms,
                                    np.maximum(lower[idx] - state.theta[idx], -state.radius * scale),
                                    np.minimum(upper[idx] - state.theta[idx], state.radius * scale), scale,
                                    hold=state.hold)
    state.directions = analyse(state, r, a)
    se = state.directions.standard_errors()
    state.step = solved.step
    theta = state.theta.copy()
    theta[idx] = np.clip(theta[idx] + state.step, lower[idx], upper[idx])
    state.theta = theta
    say(f"  step {', '.join(f'{n} {d:+.4g}' for n, d in zip(state.free, state.step, strict=True))}; "
        f"residual {float(np.sqrt(np.mean(r**2))):.4g} mm")
    state.converged = bool(np.all(np.abs(state.step) <= np.maximum(STEP_FRACTION * se, STEP_FLOOR))
                           or state.radius < STEP_FLOOR)
    return state.converged


def analyse(state: FitState, r: FloatArray, a: FloatArray) -> Directions:
    """The combinations of the free parameters in the linearised problem ``(r, a)`` (those in
    ``state.hold`` held); the residual's sigma kept in ``state``."""
    k = len(state.free)
    held = 0 if state.hold is None else state.hold.shape[1]
    state.sigma = residual_sigma(r, a.shape[1] - held)
    ap = project_out(a, k)
    state.normal = ap.T @ ap
    return directions(state.normal, state.sigma, state.free, state.scale, len(r), state.hold)


def confirmed(observations: Sequence[Any], shapes: Sequence[ModelShape], points: Sequence[FloatArray],
              transforms: list[Any], dim: int) -> tuple[FloatArray, FloatArray]:
    """The fitted model's shapes against the scans: each scan's surface (3D) or outline (2D) RMS after
    alignment, and the residual per scan at the fit's own alignment."""
    after = []
    for o, shape in zip(observations, shapes, strict=True):
        c = correlate(o.scan, shape)
        after.append(c.surface.rms if dim == 3 else c.outline.rms)
    r, _, _ = linearised_system(linearise(shapes, None, dim), points,
                                LinearisedState(np.zeros(0), list(transforms)), np.zeros(0))
    return np.array(after), per_scan_rms(r, points)


def verdicts(state: FitState, lower: FloatArray, upper: FloatArray, nominal: FloatArray | None = None
             ) -> tuple[FloatArray, FloatArray, NDArray[np.bool_], NDArray[np.bool_]]:
    """Standard errors, confounded errors (the change per plausible change of the combinations held),
    which parameters were fitted and which are identified; the notes of those that are not (moving with
    a held combination, at a bound of the box, loosely determined, still moving, or in a fit that moved
    some parameter more than :data:`MAX_PLAUSIBLE_CHANGES` from ``nominal``) written into ``state``."""
    idx = state.idx
    errors, confounded = np.full(len(NAMES), np.nan), np.full(len(NAMES), np.nan)
    fitted = np.isin(np.arange(len(NAMES)), idx)
    identified = fitted.copy()
    found = state.directions
    if found is None:
        return errors, confounded, fitted, identified
    errors[idx] = found.standard_errors()
    shares = found.shares()
    confounded[idx] = shares * found.spans
    se = np.maximum(STEP_FRACTION * errors[idx], STEP_FLOOR)
    for c, i in enumerate(idx):
        name = NAMES[i]
        note = ""
        if shares[c] > MAX_SHARE:
            combos = "; ".join(found.combination(j) for j in map(int, np.flatnonzero(found.held))
                               if abs(found.vectors[c, j]) >= 0.1)
            note = (f"confounded: moves with {combos}, which the scans do not determine "
                    f"({shares[c]:.2g} of a plausible change per plausible change of it)")
        elif min(state.theta[i] - lower[i], upper[i] - state.theta[i]) <= 1e-9:
            note = (f"at the bound of the box ({lower[i]:g} to {upper[i]:g}); the scans ask for more "
                    "(widen --tolerance)")
        elif errors[i] > MAX_DIRECTION_ERROR * SPANS[name]:  # a plausible change moves the scans less than noise
            note = (f"loosely determined: standard error {errors[i]:.3g}, more than a plausible change "
                    f"({SPANS[name]:g})")
        elif not state.converged and abs(state.step[c]) > se[c]:
            note = f"still moving when the iterations stopped (last step {state.step[c]:+.3g})"
        if note:
            identified[i] = False
            state.notes[name] = note
    if nominal is not None:
        _distrust_far(state, nominal, identified)
    return errors, confounded, fitted, identified


def _distrust_far(state: FitState, nominal: FloatArray, identified: NDArray[np.bool_]) -> None:
    """Mark every identified parameter not identified when the fit moved one beyond plausibility."""
    moves = {NAMES[i]: abs(state.theta[i] - nominal[i]) / SPANS[NAMES[i]] for i in state.idx}
    name, far = max(moves.items(), key=lambda kv: kv[1], default=("", 0.0))
    if far <= MAX_PLAUSIBLE_CHANGES:
        return
    for i in map(int, np.flatnonzero(identified)):
        identified[i] = False
        state.notes[NAMES[i]] = (f"not trusted: the fit moved {name} {far:.3g} plausible changes from nominal "
                                 f"(more than {MAX_PLAUSIBLE_CHANGES:g}); check each scan's pressure and length "
                                 "unit, or measure the material by a coupon test")


def per_scan_rms(r: FloatArray, points: Sequence[FloatArray]) -> FloatArray:
    """The RMS of the residual ``r`` over each scan's points (stacked in the order of ``points``).

    >>> per_scan_rms(np.array([3.0, 4.0, 1.0]), [np.zeros((2, 2)), np.zeros((1, 2))]).round(4).tolist()
    [3.5355, 1.0]
    """
    bounds = np.cumsum([0, *(len(p) for p in points)])
    return np.array([float(np.sqrt(np.mean(r[a:b] ** 2))) for a, b in pairwise(bounds)])


__all__ = ["STEP_FLOOR", "STEP_FRACTION", "TRUST", "FitState", "accept", "aligned_cost", "analyse", "confirmed",
           "drop_no_effect", "gauss_newton_step", "linearise", "nominal_alignment", "per_scan_rms",
           "shape_derivatives", "trial_points", "verdicts"]
