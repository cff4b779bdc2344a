"""The identification: the model's parameters fitted to scans by least squares on the correlation distances.

The method (docs/identify.md):

1. **Align.** Each scan is aligned to the nominal model's deformed shape as
   ``pneumorph correlate`` aligns it (:func:`pneumorph.correlation.correlate`): the
   residual RMS *before*.
2. **Jacobian by FE.** At the current parameters, every scanned design is solved, and
   again with each free parameter moved by its step (forward differences; a thickness
   moved with the mesh grid kept, as the tolerance study keeps it, so that surface nodes
   correspond): the nodes' sensitivities ``dQ/dtheta``. A moved model starts from the
   solved state at the top pressure (:func:`~pneumorph.models.fe.warmstart.solve_near`: a few
   Newton iterations to the ramp's own convergence test, not a ramp).
3. **Gauss-Newton on the linearised shape.** The residual of a scan point is its signed
   distance to the model's surface (3D: the tangent plane at its nearest surface node;
   2D: its nearest outline segment). With the shape linear in the parameters, the
   parameters and every scan's rigid alignment are solved together by bounded linear
   least squares (:func:`scipy.optimize.lsq_linear`), the nearest points matched again
   at every step, until the step vanishes.
4. **Iterate** 2-3 at the new parameters in a trust region (a step that raises the FE model's
   residual is taken back and shortened) until the parameter step is below a tenth of its
   standard error (or 0.001), then **confirm**: solve at the fitted parameters and measure
   each scan as ``correlate`` does (the residual RMS *after*).

The standard errors are those of linear least squares, ``s^2 (J^T J)^-1`` with the
alignment parameters in ``J`` (so a parameter that a rigid motion could mimic is not
credited), ``s^2`` the residual variance. The combinations of parameters the scans do not
determine (eigenvectors of ``J^T J`` whose standard error exceeds
:data:`~pneumorph.identify.linear.MAX_DIRECTION_ERROR` plausible changes, and as many of the
weakest as the correlation form of ``J^T J`` has eigenvalues below
:data:`~pneumorph.identify.linear.MIN_EIGENVALUE`: columns too alike to tell apart) are held at
nominal; every parameter outside them is fitted and identified with its standard error, those
in them are reported as confounded, with the combination (:func:`~pneumorph.identify.advice.next_scans`
ranks the further scans that would determine it).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.correlation.compare import ModelShape, check_units
from pneumorph.correlation.scans import Scan
from pneumorph.errors import FitError, PressureRangeError, ScanError, SearchConfigError
from pneumorph.identify.advice import candidate_normal, candidates, rank
from pneumorph.identify.extent import chain_shapes
from pneumorph.identify.gaussnewton import (
    FitState,
    accept,
    confirmed,
    gauss_newton_step,
    nominal_alignment,
    shape_derivatives,
    trial_points,
    verdicts,
)
from pneumorph.identify.linear import MAX_DIRECTION_ERROR, MAX_SHARE, MIN_EIGENVALUE, correlation_of, directions
from pneumorph.identify.match import check_coverage, check_size
from pneumorph.identify.parameters import NAMES, ParameterSet, parameter_indices
from pneumorph.identify.probe import JacobianProbe, ShapeProbe, shape_of, variant_shapes
from pneumorph.identify.scans import ScanSpec
from pneumorph.models.factory import make_model

FloatArray = NDArray[np.float64]

#: scan points used per scan (a seeded sample of larger scans)
MAX_POINTS = 4000
#: the iterations (FE Jacobians) before the fit stops at its best point, declared not converged
MAX_ITERATIONS = 8


@dataclass(frozen=True)
class Observation:
    """A scan with its design and pressure, read and checked (:func:`~pneumorph.identify.scans.load_scans`)."""

    spec: ScanSpec
    scan: Scan


@dataclass(frozen=True)
class Identification:
    """The fitted parameters, their uncertainty and what the scans could not tell apart.

    Attributes
    ----------
    values, nominal, standard_errors : ndarray, shape (5,)
        In the order of :data:`~pneumorph.identify.parameters.NAMES` (scales, then mm);
        the standard error is NaN for a parameter that was not fitted. It holds the
        combinations the scans do not determine where they are (``confounded_errors``: how
        far they could move it).
    fitted, identified : ndarray of bool, shape (5,)
        Fitted by the least squares; fitted, determined by the scans (not moving with a
        combination they do not determine), within the box and converged.
    notes : tuple of str
        Per parameter, why it is not identified (empty when it is).
    correlation : ndarray, shape (k, k)
        Correlations of the fitted parameters (``free`` order).
    free : tuple of str
        The fitted parameters.
    rms_before, rms_after : ndarray, shape (scans,)
        Per scan, ``correlate``'s RMS (3D: surface; 2D: outline), mm, at nominal and at the fit.
    residual_before, residual_after : ndarray, shape (scans,)
        Per scan, RMS of the fit's point-to-surface residuals, mm.
    sigma : float
        The residual standard deviation of the last linearisation, mm.
    iterations : int
        FE Jacobians computed.
    solves : int
        FE solves asked of the evaluator (cache hits included).
    settings : dict
        The ``[model]`` settings of the fitted model (unit and scales).
    fingerprints : tuple of str
        The fitted model's fingerprint per scan (its pressure).
    confounded_errors : ndarray, shape (5,)
        How far each fitted parameter moves per plausible change of the combinations held (its
        unit; 0 for a parameter outside them, NaN for one not fitted).
    combinations : tuple of dict
        The combinations the scans do not determine: ``combination`` (one plausible change of
        it, in the parameters' units), ``scan_change_mm`` (the RMS change of the scans along
        it), ``standard_error`` (in plausible changes).
    converged : bool
        The steps became small before :data:`MAX_ITERATIONS` (else the best point is kept,
        the parameters still moving not identified).
    advice : tuple of dict
        The further scans weighed, best first (:func:`~pneumorph.identify.advice.rank`).
    weakest_error : float
        The standard error of the combination of the fitted parameters the scans determine
        least (none held), in plausible changes: what a further scan would lower.
    """

    values: FloatArray
    nominal: FloatArray
    standard_errors: FloatArray
    fitted: NDArray[np.bool_]
    identified: NDArray[np.bool_]
    notes: tuple[str, ...]
    correlation: FloatArray
    free: tuple[str, ...]
    rms_before: FloatArray
    rms_after: FloatArray
    residual_before: FloatArray
    residual_after: FloatArray
    sigma: float
    iterations: int
    solves: int
    settings: dict[str, Any]
    fingerprints: tuple[str, ...]
    observations: tuple[Observation, ...] = field(repr=False, default=())
    confounded_errors: FloatArray = field(default_factory=lambda: np.full(len(NAMES), np.nan))
    combinations: tuple[dict[str, Any], ...] = ()
    converged: bool = True
    advice: tuple[dict[str, Any], ...] = ()
    weakest_error: float = float("nan")

    def parameters(self) -> dict[str, dict[str, Any]]:
        """Per parameter: value, standard error, confounded error, identified, fitted, nominal, unit and a note."""
        out = {}
        for i, name in enumerate(NAMES):
            se, ce = float(self.standard_errors[i]), float(self.confounded_errors[i])
            out[name] = {"value": float(self.values[i]), "standard_error": se if np.isfinite(se) else None,
                         "confounded_error": ce if np.isfinite(ce) else None,
                         "identified": bool(self.identified[i]), "fitted": bool(self.fitted[i]),
                         "nominal": float(self.nominal[i]), "unit": "mm" if i >= 2 else "-",
                         "note": self.notes[i]}
        return out

    def to_dict(self) -> dict[str, Any]:
        def rms(a: FloatArray) -> dict[str, Any]:
            return {"per_scan_mm": a.tolist(), "all_mm": float(np.sqrt(np.mean(a**2)))}

        return {"parameters": self.parameters(),
                "correlation": {"parameters": list(self.free), "matrix": self.correlation.tolist()},
                "residual_rms": {"before": rms(self.rms_before), "after": rms(self.rms_after),
                                 "fit_before": rms(self.residual_before), "fit_after": rms(self.residual_after),
                                 "measure": "surface" if self.observations and self.observations[0].scan.dim == 3
                                 else "outline"},
                "sigma_mm": self.sigma, "iterations": self.iterations, "solves": self.solves,
                "converged": self.converged, "undetermined": list(self.combinations), "next_scans": list(self.advice),
                "weakest_error": self.weakest_error,
                "scans": [o.spec.to_dict() for o in self.observations], "model": self.settings,
                "fingerprints": list(self.fingerprints)}


# -- the driver ------------------------------------------------------------------------------
def _sample(scan: Scan, seed: int) -> FloatArray:
    p = scan.points
    if len(p) <= MAX_POINTS:
        return p
    return p[np.sort(np.random.default_rng(seed).choice(len(p), MAX_POINTS, replace=False))]


def precheck_designs(observations: Sequence[Observation], params: ParameterSet, base: dict[str, Any],
                     table_dir: str | Path | None = None) -> int:
    """Check each scan against its design's shape predicted by a chain table, before any solve.

    Its size and its units (:func:`~pneumorph.identify.match.check_size`,
    :func:`~pneumorph.identify.match.check_coverage`). A pressure between two of a table's
    levels is checked against the shapes at both
    (:func:`~pneumorph.identify.extent.chain_shapes`). Scans whose model has no chain table
    around their pressure (or is too short for its window) are checked after their nominal
    solve only. Returns how many were checked.

    Raises
    ------
    ScanError
        A scan's unit or its design's unit count is wrong.
    """
    checked = 0
    build_probes([o.spec for o in observations], params, base, params.nominal)  # every model refused now
    for o in observations:
        # the unit as given (the fit meshes it a little coarser or finer to keep its grid): its table's model
        shapes = chain_shapes({**base, "pressure_kpa": o.spec.pressure_kpa, "unit": params.unit.to_dict()},
                              o.spec.design, table_dir)
        if shapes:
            check_units(o.scan, shapes[0])
            check_size(o.scan, o.spec, shapes, predicted=True)
            check_coverage(o.scan, o.spec, shapes, predicted=True)
            checked += 1
    return checked


def build_probes(specs: Sequence[ScanSpec], params: ParameterSet, base: dict[str, Any],
                 values: FloatArray) -> list[ShapeProbe]:
    """The probe of every scan's design at ``values`` (its model's ramp ends at the scan's pressure).

    Raises
    ------
    SearchConfigError, PressureRangeError
        A setting the model factory refuses, a pressure outside the model's range.
    """
    return [ShapeProbe(make_model(len(s.design), params.settings(values, {**base, "pressure_kpa": s.pressure_kpa})))
            for s in specs]


def identify(observations: Sequence[Observation], params: ParameterSet, evaluator: Any,
             base: dict[str, Any] | None = None, parameters: Sequence[str] = NAMES, seed: int = 0,
             max_iterations: int = MAX_ITERATIONS, on_progress: Callable[[str], None] | None = None,
             table_dir: str | Path | None = None, advise: bool = True) -> Identification:
    """Fit ``parameters`` to the scans (see the module docstring; a fit solves the FE model many times, so
    its examples are ``tests/identify/test_fit.py``).

    Parameters
    ----------
    observations : sequence of Observation
        The scans, each with its design and pressure (checked: :func:`~pneumorph.identify.scans.load_scans`).
    params : ParameterSet
        The nominal unit, scales and the thicknesses' box.
    evaluator : Evaluator
        Solves the probes (``iter_cases``); behind the evaluation cache a rerun is fast.
    base : dict, optional
        Further model settings (``fidelity``, ...; not the unit: ``params`` holds it).
    parameters : sequence of str
        The parameters to fit; the others stay at nominal.
    seed, table_dir : int, path
        Seed of the sample of a scan's points (over :data:`MAX_POINTS`); kept chain tables, for
        the size check before any solve (:func:`precheck_designs`).
    advise : bool
        When a fitted parameter is not identified, solve the candidate further scans
        (:mod:`pneumorph.identify.advice`) and rank them (``advice``).

    Raises
    ------
    FitError
        A solve failed: nothing is identified.
    ScanError
        A scan far from its model's size (unit mistake), or a 3D scan against the 2D model.
    """
    base = dict(base or {})
    say = on_progress or (lambda text: None)
    if not observations:
        raise FitError("no scans to identify from")
    dim = observations[0].scan.dim
    if dim == 3 and base.get("fidelity", "2d") != "3d":
        raise ScanError("a 3D scan needs the 3D model (--model 3d); a 2D model has no surface")
    points = [_sample(o.scan, seed + k) for k, o in enumerate(observations)]
    precheck_designs(observations, params, base, table_dir)  # every model refused now, before any solve
    specs = [o.spec for o in observations]
    state = FitState(params.nominal.copy(), [NAMES[i] for i in parameter_indices(parameters)],
                     {name: "" for name in NAMES})
    trial = trial_points(state.theta, state.idx, params.upper)
    say(f"solving the nominal model of {len(observations)} scan(s) and its Jacobian ({len(trial)} warm-started "
        "solves each)")
    shapes, moved = jacobian_at(specs, params, base, evaluator, state.theta, trial)
    state.solves += len(observations) * (1 + len(trial))
    state.transforms, rms_before = nominal_alignment(observations, shapes, dim)
    _iterate(state, (specs, params, base, evaluator, points, dim), shapes, moved, trial, max_iterations, say)
    say("confirming the fit by FE")
    final_shapes, _ = jacobian_at(specs, params, base, evaluator, state.theta, [])
    state.solves += len(observations)
    rms_after, residual_after = confirmed(observations, final_shapes, points, state.transforms, dim)
    errors, confounded_errors, fitted, identified = verdicts(state, params.lower, params.upper, params.nominal)
    found = state.directions
    held = [] if found is None else [
        {"combination": found.combination(j), "scan_change_mm": found.scan_change(j),
         "standard_error": float(found.errors()[j])} for j in map(int, np.flatnonzero(found.held))]
    spread = np.empty(0) if found is None else directions(state.normal, found.sigma, found.names, found.spans,
                                                          found.points).errors()
    weakest = float(spread.max()) if spread.size else float("nan")  # no direction: nothing the scans determine
    advice: list[dict[str, Any]] = []
    if advise and not identified[fitted].all() and found is not None:
        say("weighing further scans that would determine what these do not")
        advice = _advice(state, (specs, params, base, evaluator, points, dim))
    fingerprints = tuple(p.model.fingerprint() for p in build_probes(specs, params, base, state.theta))
    return Identification(
        values=state.theta, nominal=params.nominal, standard_errors=errors, fitted=fitted, identified=identified,
        notes=tuple(state.notes[n] for n in NAMES),
        correlation=correlation_of(found.covariance()) if found is not None else np.zeros((0, 0)),
        free=tuple(state.free), rms_before=rms_before, rms_after=rms_after,
        residual_before=(state.residual_before if state.residual_before is not None
                         else np.full(len(points), np.nan)),
        residual_after=residual_after, sigma=state.sigma, iterations=state.iterations, solves=state.solves,
        settings=params.settings(state.theta, base), fingerprints=fingerprints, observations=tuple(observations),
        confounded_errors=confounded_errors, combinations=tuple(held), converged=state.converged,
        advice=tuple(advice), weakest_error=weakest)


def _iterate(state: FitState, problem: tuple[Any, ...], shapes: list[ModelShape], moved: list[list[ModelShape]],
             trial: list[FloatArray], max_iterations: int, say: Callable[[str], None]) -> None:
    """The iterations from the nominal solve: each solved point accepted (or taken back), a step from the
    best point, until the steps vanish or ``max_iterations`` FE Jacobians; ``state`` ends at the best point."""
    specs, params, base, evaluator, points, dim = problem
    best: tuple[FloatArray, list[ModelShape], list[FloatArray]] | None = None
    while True:
        state.iterations += 1
        if state.iterations > 1:
            trial = trial_points(state.theta, state.idx, params.upper)
            say(f"iteration {state.iterations}: {len(specs)} ramp(s) and {len(trial) * len(specs)} "
                f"warm-started solves for the Jacobian of {', '.join(state.free)}")
            shapes, moved = jacobian_at(specs, params, base, evaluator, state.theta, trial)
            state.solves += len(specs) * (1 + len(trial))
        derivatives = shape_derivatives(specs, shapes, moved, state.idx, state.theta, trial, dim)
        if accept(state, shapes, points, dim, say) or best is None:
            best = (state.theta.copy(), shapes, derivatives)
        else:
            state.theta, shapes, derivatives = best[0].copy(), best[1], best[2]
        if gauss_newton_step(state, dim, shapes, derivatives, points, params.lower, params.upper, say):
            return
        if state.iterations >= max_iterations:
            state.theta = best[0].copy()
            say(f"not converged in {max_iterations} iterations: the best point kept, the parameters still moving "
                "not identified")
            return


def _advice(state: FitState, problem: tuple[Any, ...]) -> list[dict[str, Any]]:
    """The candidates of :func:`~pneumorph.identify.advice.candidates` the model accepts, solved at the fit with
    their Jacobians, ranked (:func:`~pneumorph.identify.advice.rank`)."""
    specs, params, base, evaluator, points, dim = problem
    assert state.directions is not None
    further = []
    for spec in candidates(specs):
        try:
            build_probes([spec], params, base, state.theta)
        except (PressureRangeError, SearchConfigError):
            continue  # a pressure the model refuses: not a scan to advise
        further.append(spec)
    if not further:
        return []
    trial = trial_points(state.theta, state.idx, params.upper)
    shapes, moved = jacobian_at(further, params, base, evaluator, state.theta, trial)
    state.solves += len(further) * (1 + len(trial))
    derivatives = shape_derivatives(further, shapes, moved, state.idx, state.theta, trial, dim)
    size = int(np.mean([len(p) for p in points]))
    normals = [candidate_normal(s, d, dim, state.scale, size) for s, d in zip(shapes, derivatives, strict=True)]
    return rank(state.directions, state.normal, list(zip(further, normals, strict=True)), specs)


def jacobian_at(specs: Sequence[ScanSpec], params: ParameterSet, base: dict[str, Any], evaluator: Any,
                values: FloatArray, trial: list[FloatArray]) -> tuple[list[ModelShape], list[list[ModelShape]]]:
    """Every scan's shape at ``values`` and at each of the ``trial`` points: one case per scan, its ramp at
    ``values`` and the trial points warm-started from it (:class:`~pneumorph.identify.probe.JacobianProbe`).

    Raises
    ------
    FitError
        A solve failed.
    """
    points_of = [build_probes(specs, params, base, v) for v in trial]
    cases = [(JacobianProbe(probe.model, [p[s].model for p in points_of]), specs[s].design)
             for s, probe in enumerate(build_probes(specs, params, base, values))]
    at: list[Any] = [None] * len(specs)
    moved: list[list[Any]] = [[None] * len(specs) for _ in trial]
    for s, outcome in evaluator.iter_cases(cases):
        if not outcome.ok or outcome.response is None:
            raise FitError(f"the fit's solve of design {specs[s].design} at "
                           f"{specs[s].pressure_kpa:g} kPa (the Jacobian at "
                           f"{', '.join(f'{n} {x:.6g}' for n, x in zip(NAMES, values, strict=True))}) failed: "
                           f"{outcome.failure}; nothing is identified")
        at[s] = shape_of(outcome.response)
        for j, shape in enumerate(variant_shapes(outcome.response)):
            moved[j][s] = shape
    return at, moved


__all__ = [
    "MAX_DIRECTION_ERROR",
    "MAX_ITERATIONS",
    "MAX_POINTS",
    "MAX_SHARE",
    "MIN_EIGENVALUE",
    "Identification",
    "Observation",
    "build_probes",
    "identify",
    "jacobian_at",
    "precheck_designs",
]
