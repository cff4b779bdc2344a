"""The steps of an identification: the scans aligned to the nominal model, the shapes' derivatives, one
Gauss-Newton step (confounded parameters fixed at the first), the fit checked by FE and the verdict on
each parameter. :func:`pneumorph.identify.fit.identify` runs them in order.
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
    LinearisedScan,
    LinearisedState,
    confounded,
    linearised_system,
    scaled_covariance,
    shape_nodes,
    solve_linearised,
)
from pneumorph.identify.match import check_coverage, check_size
from pneumorph.identify.parameters import NAMES, SPANS, STEPS

FloatArray = NDArray[np.float64]

#: a Gauss-Newton step is at most this many plausible changes (``SPANS``) of each parameter
TRUST = 3.0
#: the iterations stop when every step is below this fraction of its standard error ...
STEP_FRACTION = 0.1
#: ... or below this (scaled) floor
STEP_FLOOR = 1e-3


@dataclass
class FitState:
    """What the Gauss-Newton iterations carry from one to the next.

    ``free`` are the parameters still fitted (confounded ones leave at the first iteration,
    their reason in ``notes``); ``transforms`` each scan's alignment; ``cov`` and ``sigma`` the
    scaled covariance of the last step and the residual's scale.
    """

    theta: FloatArray
    free: list[str]
    notes: dict[str, str]
    transforms: list[Any] = field(default_factory=list)
    residual_before: FloatArray | None = None
    cov: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    sigma: float = float("nan")
    step: FloatArray = field(default_factory=lambda: np.zeros(0))
    solves: int = 0
    iterations: int = 0

    @property
    def idx(self) -> list[int]:
        """The free parameters' indices in :data:`~pneumorph.identify.parameters.NAMES`."""
        return [NAMES.index(n) for n in self.free]


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


def shape_derivatives(observations: Sequence[Any], shapes: Sequence[ModelShape],
                      moved: Sequence[Sequence[ModelShape]], idx: list[int], theta: FloatArray,
                      trial: list[FloatArray], dim: int) -> list[FloatArray]:
    """Per scan, the derivatives of its model's nodes by each parameter of ``idx`` (forward differences to the
    ``trial`` points' shapes ``moved[j][s]``)."""
    derivatives = []
    for s in range(len(observations)):
        nodes, _ = shape_nodes(shapes[s], dim)
        per = []
        for j, i in enumerate(idx):
            other, _ = shape_nodes(moved[j][s], dim)
            if other.shape != nodes.shape:
                raise FitError(f"the mesh of design {observations[s].spec.design} changed with {NAMES[i]} "
                               f"({other.shape[0]} against {nodes.shape[0]} surface nodes); nothing is identified")
            per.append((other - nodes) / (trial[j][i] - theta[i]))
        derivatives.append(np.array(per).reshape(len(idx), *nodes.shape))
    return derivatives


def linearised(problem: tuple[Any, ...], chosen: list[int], columns: list[int]
               ) -> tuple[LinearisedState, FloatArray, FloatArray, list[LinearisedScan], FloatArray]:
    """The linearised problem of the ``columns`` of the Jacobian (parameters ``chosen``), solved."""
    dim, shapes, derivatives, points, transforms, lower, upper = problem
    lins = []
    for shape, d in zip(shapes, derivatives, strict=True):
        nodes, normals = shape_nodes(shape, dim)
        lins.append(LinearisedScan(dim, nodes, d[columns], normals))
    scale = np.array([SPANS[NAMES[i]] for i in chosen])
    state, r, a = solve_linearised(lins, points, transforms, np.maximum(lower[chosen], -TRUST * scale),
                                    np.minimum(upper[chosen], TRUST * scale), scale)
    return state, r, a, lins, scale


def gauss_newton_step(state: FitState, dim: int, shapes: Sequence[ModelShape], derivatives: list[FloatArray],
                      points: Sequence[FloatArray], lower: FloatArray, upper: FloatArray,
                      say: Callable[[str], None]) -> bool:
    """One step of the linearised fit from ``state`` (updated in place); True when it has converged.

    At the first step the residual before the fit is kept, and parameters the scans cannot tell apart
    (:func:`~pneumorph.identify.linear.confounded`) are fixed at nominal, with their reason in the notes.
    """
    idx = state.idx
    columns = list(range(len(idx)))
    problem = (dim, shapes, derivatives, points, state.transforms, lower - state.theta, upper - state.theta)
    solved, r, a, lins, scale = linearised(problem, idx, columns)
    if state.residual_before is None:
        r0, _, _ = linearised_system(lins, points, LinearisedState(np.zeros(len(idx)), list(state.transforms)), scale)
        state.residual_before = per_scan_rms(r0, points)
        cov, _ = scaled_covariance(r, a, len(idx))
        fixed = confounded(state.free, cov, np.linalg.norm(project_out(a, len(idx)), axis=0))
        if fixed:
            for name, why in fixed.items():
                state.notes[name] = why
                say(f"{name}: {why}; fixed at nominal")
            columns = [c for c in columns if NAMES[idx[c]] not in fixed]
            solved, r, a, lins, scale = linearised(problem, [idx[c] for c in columns], columns)
            state.free = [NAMES[idx[c]] for c in columns]
            idx = [idx[c] for c in columns]
    state.cov, state.sigma = scaled_covariance(r, a, len(idx))
    se = np.sqrt(np.maximum(np.diag(state.cov), 0.0)) * scale
    state.step = solved.step
    state.transforms = solved.transforms
    theta = state.theta.copy()
    theta[idx] = np.clip(theta[idx] + state.step, lower[idx], upper[idx])
    state.theta = theta
    say(f"  step {', '.join(f'{n} {d:+.4g}' for n, d in zip(state.free, state.step, strict=True))}; "
        f"residual {float(np.sqrt(np.mean(r**2))):.4g} mm")
    return bool(np.all(np.abs(state.step) <= np.maximum(STEP_FRACTION * se, STEP_FLOOR)))


def confirmed(observations: Sequence[Any], shapes: Sequence[ModelShape], points: Sequence[FloatArray],
              transforms: list[Any], dim: int) -> tuple[FloatArray, FloatArray]:
    """The fitted model's shapes against the scans: each scan's surface (3D) or outline (2D) RMS after
    alignment, and the residual per scan at the fit's own alignment."""
    after = []
    for o, shape in zip(observations, shapes, strict=True):
        c = correlate(o.scan, shape)
        after.append(c.surface.rms if dim == 3 else c.outline.rms)
    lins = []
    for shape in shapes:
        nodes, normals = shape_nodes(shape, dim)
        lins.append(LinearisedScan(dim, nodes, np.zeros((0, *nodes.shape)), normals))
    r, _, _ = linearised_system(lins, points, LinearisedState(np.zeros(0), list(transforms)), np.zeros(0))
    return np.array(after), per_scan_rms(r, points)


def verdicts(state: FitState, lower: FloatArray, upper: FloatArray) -> tuple[FloatArray, NDArray[np.bool_],
                                                                               NDArray[np.bool_]]:
    """Standard errors, which parameters were fitted and which are identified; the notes of those that are
    not (at a bound of the box, fitted beside confounded ones, loosely determined) written into ``state``."""
    idx = state.idx
    errors = np.full(len(NAMES), np.nan)
    errors[idx] = np.sqrt(np.maximum(np.diag(state.cov), 0.0)) * np.array([SPANS[n] for n in state.free])
    fitted = np.isin(np.arange(len(NAMES)), idx)
    identified = fitted.copy()
    theta, notes = state.theta, state.notes
    # fixing a confounded parameter at nominal moves every fitted one by its correlation with it (times the
    # fixed one's error over its standard error: large when the scans are precise): none stands alone
    partners = [n for n, why in notes.items() if why.startswith("cannot")]
    for i in idx:
        name = NAMES[i]
        if min(theta[i] - lower[i], upper[i] - theta[i]) <= 1e-9:
            identified[i] = False
            notes[name] = (f"at the bound of the box ({lower[i]:g} to {upper[i]:g}); the scans ask for more "
                           "(widen --tolerance)")
        elif partners:
            identified[i] = False
            notes[name] = (f"fitted with {', '.join(partners)} fixed at nominal: its value absorbs their change "
                           "from nominal")
        elif errors[i] > SPANS[name]:  # a plausible change moves the scans less than their scatter
            identified[i] = False
            notes[name] = (f"loosely determined: standard error {errors[i]:.3g}, more than a plausible change "
                           f"({SPANS[name]:g})")
    return errors, fitted, identified


def project_out(a: FloatArray, k: int) -> FloatArray:
    """The first ``k`` columns of ``a`` with their parts along the other (alignment) columns removed.

    >>> project_out(np.array([[1.0, 1.0], [1.0, 0.0]]), 1).ravel().tolist()
    [0.0, 1.0]
    """
    q, _ = np.linalg.qr(a[:, k:])
    return a[:, :k] - q @ (q.T @ a[:, :k])


def per_scan_rms(r: FloatArray, points: Sequence[FloatArray]) -> FloatArray:
    """The RMS of the residual ``r`` over each scan's points (stacked in the order of ``points``).

    >>> per_scan_rms(np.array([3.0, 4.0, 1.0]), [np.zeros((2, 2)), np.zeros((1, 2))]).round(4).tolist()
    [3.5355, 1.0]
    """
    bounds = np.cumsum([0, *(len(p) for p in points)])
    return np.array([float(np.sqrt(np.mean(r[a:b] ** 2))) for a, b in pairwise(bounds)])


__all__ = ["STEP_FLOOR", "STEP_FRACTION", "TRUST", "FitState", "confirmed", "gauss_newton_step", "linearised",
           "nominal_alignment", "per_scan_rms", "project_out", "shape_derivatives", "trial_points", "verdicts"]
