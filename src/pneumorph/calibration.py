"""Calibrate the 2D model's filler law E(P) against the 3D model (chapter 5).

Each of several independent runs solves one random design in 3D; one 3D ramp reports every
calibration pressure (the dissertation's "method 2", section 4.3). At each pressure level the
filler modulus E that makes the 2D model reproduce that 3D state best is found with a SciPy
optimiser from a random starting point, minimising Eq 5.1:

    Gamma(E) = sum over units [(X2 - X3)^2 + (Y2 - Y3)^2]

over the unit-centre displacements at that pressure. The 2D solve for a trial E uses a
constant filler of modulus E up to the level's pressure: a hyperelastic equilibrium does not
depend on the loading path, so this is the 2D state at that pressure with E(P) = E. Linear
and quadratic laws E(P) are then fitted to all (P, E) points by weighted least squares with
their R^2 (Fig 5.3); a law that fits badly or is not positive over the range is reported
with a warning and not silently used.

Weighting (:data:`WEIGHTINGS`). Near its optimum E*, Eq 5.1 grows like
``Gamma* + kappa/2 (ln E - ln E*)^2``: what a law's miss costs in displacement is set by its
*relative* error, scaled by the curvature ``kappa``, which rises steeply with pressure (the
actuator softens). ``"relative"`` (the default) minimises the squared relative errors;
``"sensitivity"`` also weights each point by its measured ``kappa`` (two more 2D solves per
point), which minimises the summed Eq 5.1 over all points to second order; ``"uniform"`` is
ordinary least squares on E, as in the dissertation. R^2 is reported in the fit's own
weighting (the weighted-least-squares R^2) and, for comparison with Fig 5.3, unweighted.

3D responses are cached (:class:`pneumorph.execution.EvaluationCache`), so recalibrating
repeats no 3D solve.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from pneumorph.errors import MaterialDataError, SearchConfigError, SimulationFailed
from pneumorph.fem import StepSettings
from pneumorph.geometry.unit import UnitSpec
from pneumorph.materials.filler import FillerLaw
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D
from pneumorph.models.response import Response

#: R^2 below which a fitted law is reported as a poor fit.
R2_WARNING = 0.9
#: How the calibration points are weighted in the fits of E(P) (see the module notes).
WEIGHTINGS = ("relative", "sensitivity", "uniform")
#: Step in ln E of the finite difference that measures the curvature of Eq 5.1.
CURVATURE_STEP = 0.05


class CalibrationWarning(UserWarning):
    """A fitted filler law that fits badly or is not positive over its range."""


@dataclass(frozen=True)
class FillerPoint:
    """The best constant filler modulus for one design at one pressure."""

    run: int
    pressure: float  # MPa
    design: str
    modulus: float  # MPa
    gamma: float  # Eq 5.1 at the optimum, mm^2
    start: float  # the optimiser's random starting modulus, MPa
    evaluations: int
    curvature: float | None = None  # d^2 Gamma / d(ln E)^2 at the optimum, mm^2 (if measured)


@dataclass(frozen=True)
class LawFit:
    """A polynomial law E(P) fitted to the calibration points."""

    degree: int
    coefficients: tuple[float, ...]  # c_0, c_1, ... (MPa, P in MPa)
    r_squared: float  # in the fit's own weighting
    minimum: tuple[float, float]  # (pressure, modulus) over the range
    problems: tuple[str, ...] = ()
    weighting: str = "uniform"
    r_squared_unweighted: float = float("nan")


@dataclass(frozen=True)
class Calibration:
    """The points of every run, both fitted laws and the chosen one."""

    points: tuple[FillerPoint, ...]
    linear: LawFit
    quadratic: LawFit
    chosen: LawFit | None
    pressure_range: tuple[float, float]
    poisson_ratio: float
    metadata: dict[str, Any] = field(default_factory=dict)

    def law(self) -> FillerLaw:
        """The chosen law as a :class:`FillerLaw` (raises if no law was acceptable)."""
        if self.chosen is None:
            raise MaterialDataError(
                "no acceptable filler law: " + "; ".join(self.linear.problems + self.quadratic.problems)
            )
        return FillerLaw(
            name="calibrated_filler",
            display_name="calibrated filler",
            coefficients=self.chosen.coefficients,
            pressure_range=self.pressure_range,
            poisson_ratio=self.poisson_ratio,
            source="pneumorph calibrate (Eq 5.1 against the 3D model)",
        )

    def unit_with_law(self, unit: UnitSpec) -> UnitSpec:
        """``unit`` carrying the chosen law, with provenance."""
        law = self.law()
        fit = self.chosen
        assert fit is not None
        src = (f"pneumorph calibrate: {len(self.points)} points, degree {fit.degree}, {fit.weighting} weighting, "
               f"R^2 {fit.r_squared:.4f} (unweighted {fit.r_squared_unweighted:.4f})")
        return replace(
            unit,
            filler_coefficients=law.coefficients,
            filler_range_kpa=(self.pressure_range[0] * 1e3, self.pressure_range[1] * 1e3),
            filler_poisson_ratio=self.poisson_ratio,
            filler_source=src,
        )


def unit_centre_displacements(response: Response, level: int) -> np.ndarray:
    """(n, 2) displacements of the unit centres at a reported level."""
    return response.centres[level] - response.reference_centres


def gamma(d2: np.ndarray, d3: np.ndarray) -> float:
    """Eq 5.1: summed squared differences of the unit-centre displacements (mm^2).

    Examples
    --------
    >>> gamma(np.array([[1.0, 0.0], [0.0, 2.0]]), np.array([[0.0, 0.0], [0.0, 0.0]]))
    5.0
    """
    return float(np.sum((np.asarray(d2) - np.asarray(d3)) ** 2))


def fit_law(pressures: Sequence[float], moduli: Sequence[float], degree: int,
            pressure_range: tuple[float, float], weights: Sequence[float] | np.ndarray | None = None,
            weighting: str = "uniform") -> LawFit:
    """Weighted least-squares polynomial E(P) of a degree, with R^2 (Eqs A.1-A.3) and checks.

    Parameters
    ----------
    pressures, moduli : sequence of float
        The calibration points (MPa).
    degree : int
        Degree of the polynomial.
    pressure_range : (float, float)
        Range over which the law must stay positive (MPa).
    weights : sequence of float, optional
        Multiply the residuals ``E_i - E(P_i)`` (default: all 1). R^2 is computed with the
        same weights, about the weighted mean; ``r_squared_unweighted`` without them.
    weighting : str
        Name of the weighting, recorded in the result.

    Examples
    --------
    >>> f = fit_law([0.005, 0.01, 0.02], [0.05, 0.04, 0.02], 1, (0.0, 0.02))
    >>> [round(c, 6) for c in f.coefficients], round(f.r_squared, 6)
    ([0.06, -2.0], 1.0)
    """
    p = np.asarray(pressures, dtype=float)
    e = np.asarray(moduli, dtype=float)
    w = np.ones_like(e) if weights is None else np.asarray(weights, dtype=float)
    if w.shape != e.shape or not np.all(np.isfinite(w)) or np.any(w < 0) or not np.any(w > 0):
        raise ValueError(f"weights must be finite, non-negative, not all zero and one per point, got {w}")
    levels = len(np.unique(p[w > 0]))
    if levels <= degree + 1:
        nan = float("nan")
        return LawFit(degree, (), nan, (nan, nan),
                      ((f"degree {degree}: {levels} pressure levels cannot test a law with "
                       f"{degree + 1} coefficients"),), weighting)
    coeffs = np.polynomial.polynomial.polyfit(p, e, degree, w=w)
    pred = np.polynomial.polynomial.polyval(p, coeffs)

    def r2_of(w2: np.ndarray) -> float:
        mean = np.sum(w2 * e) / np.sum(w2)
        ssto = float(np.sum(w2 * (e - mean) ** 2))
        return 1.0 - float(np.sum(w2 * (e - pred) ** 2)) / ssto if ssto > 0 else 1.0

    r2 = r2_of(w**2)
    grid = np.linspace(*pressure_range, 201)
    values = np.polynomial.polynomial.polyval(grid, coeffs)
    i = int(np.argmin(values))
    problems = []
    if r2 < R2_WARNING:
        problems.append(f"degree {degree}: R^2 = {r2:.4f} ({weighting} weighting) is below {R2_WARNING}")
    if values[i] <= 0:
        problems.append(f"degree {degree}: modulus {values[i]:.4g} MPa at {grid[i] * 1e3:.4g} kPa is not positive")
    return LawFit(degree, tuple(float(c) for c in coeffs), r2, (float(grid[i]), float(values[i])), tuple(problems),
                  weighting, r2_of(np.ones_like(e)))


def point_weights(points: Sequence[FillerPoint], weighting: str) -> np.ndarray:
    """Weights of the calibration points' residuals in E for a weighting of :data:`WEIGHTINGS`.

    ``"uniform"``: 1; ``"relative"``: 1/E; ``"sensitivity"``: sqrt(kappa)/E with kappa the
    measured curvature of Eq 5.1 in ln E, so that the weighted squared residual is twice
    the second-order rise of Eq 5.1 from missing the point.

    Examples
    --------
    >>> pts = [FillerPoint(0, 0.01, "00", 0.04, 0.0, 0.04, 1, curvature=16.0)]
    >>> point_weights(pts, "relative"), point_weights(pts, "sensitivity")
    (array([25.]), array([100.]))
    """
    e = np.array([pt.modulus for pt in points], dtype=float)
    if weighting == "uniform":
        return np.ones_like(e)
    if weighting == "relative":
        return 1.0 / e
    if weighting == "sensitivity":
        kappa = np.array([np.nan if pt.curvature is None else pt.curvature for pt in points], dtype=float)
        if np.any(np.isnan(kappa)):
            raise ValueError("sensitivity weighting needs the curvature of every point (best_filler_modulus "
                             "with curvature=True)")
        return np.sqrt(np.maximum(kappa, 0.0)) / e
    raise ValueError(f"weighting must be one of {', '.join(WEIGHTINGS)}, got {weighting!r}")


def best_filler_modulus(
    design: str,
    level: int,
    reference: Response,
    make_2d: Callable[[float, float], Reduced2D],
    start: float,
    bounds: tuple[float, float] = (1e-4, 1.0),
    curvature: bool = False,
) -> FillerPoint:
    """The constant filler modulus minimising Eq 5.1 for one design at one reported level.

    Brent's method on log10(E), its first bracket at ``start`` (relative tolerance about
    0.5 % in E); trial moduli outside ``bounds`` are clipped and penalised. A 2D solve that
    fails for a trial modulus scores as a very large Gamma, so the search moves away from it.
    With ``curvature``, two more 2D solves at ``E* exp(+-h)`` (h = :data:`CURVATURE_STEP`)
    measure ``d^2 Gamma / d(ln E)^2`` at the optimum by a central difference.
    """
    from scipy.optimize import minimize_scalar

    pressure = float(reference.pressures[level])
    target = unit_centre_displacements(reference, level)
    counter = {"n": 0}

    lo, hi = np.log10(bounds[0]), np.log10(bounds[1])

    def objective(x: float) -> float:
        clipped = min(max(float(x), lo), hi)
        penalty = 1e6 * (float(x) - clipped) ** 2
        counter["n"] += 1
        model = make_2d(10.0**clipped, pressure)
        try:
            r = model.evaluate(design)
        except SimulationFailed:
            return 1e12 + penalty
        return gamma(unit_centre_displacements(r, -1), target) + penalty

    x0 = float(np.log10(start))
    res = minimize_scalar(objective, bracket=(x0, x0 + 0.2), method="brent", options={"xtol": 2e-3, "maxiter": 50})
    x = min(max(float(res.x), lo), hi)
    best = float(objective(x))
    kappa = None
    if curvature:
        dx = CURVATURE_STEP / np.log(10.0)
        kappa = (objective(x + dx) - 2.0 * best + objective(x - dx)) / CURVATURE_STEP**2
    return FillerPoint(run=-1, pressure=pressure, design=design, modulus=float(10.0**x),
                       gamma=best, start=float(start), evaluations=counter["n"], curvature=kappa)


def _random_design(rng: np.random.Generator, n_units: int) -> str:
    return "".join(map(str, rng.integers(0, 2, n_units)))


def calibration_designs(n_units: int, runs: int, seed: int = 0) -> list[str]:
    """The random design of each calibration run (one 3D solve each).

    Examples
    --------
    >>> calibration_designs(6, 2, seed=0)
    ['011100', '110010']
    """
    rng = np.random.default_rng(seed + 1)
    return [_random_design(rng, n_units) for _ in range(runs)]


def holdout_designs(n_units: int, count: int, seed: int = 0, exclude: Sequence[str] = ()) -> list[str]:
    """Distinct random designs for validation, none of them in ``exclude``.

    Pass the calibration designs as ``exclude`` so that the validation is held out.

    Raises
    ------
    SearchConfigError
        If the design space has fewer than ``count`` designs outside ``exclude``.

    Examples
    --------
    >>> held = holdout_designs(15, 10, exclude=calibration_designs(15, 3))
    >>> len(held), len(set(held)), len(held[0])
    (10, 10, 15)
    """
    excluded = set(exclude)
    free = 2**n_units - len(excluded)
    if count > free:
        raise SearchConfigError(f"{n_units} units have only {free} designs outside the {len(excluded)} excluded ones; "
                         f"{count} held-out designs were asked for")
    rng = np.random.default_rng(seed + 10_000)
    out: list[str] = []
    while len(out) < count:
        d = _random_design(rng, n_units)
        if d not in excluded and d not in out:
            out.append(d)
    return out


def reference_model(unit: UnitSpec, n_units: int, pressures_kpa: Sequence[float],
                    steps: StepSettings | None = None) -> Full3D:
    """The 3D model of a calibration: its ramp reports every calibration pressure.

    Examples
    --------
    >>> m = reference_model(UnitSpec(), 15, (5, 10, 15, 20, 25, 30, 35, 40, 45))
    >>> m.ramp.steps.increments, round(m.ramp.pressure * 1e3, 6)
    (9, 45.0)
    """
    levels = np.asarray(pressures_kpa, dtype=float) / 1e3
    p_max = float(levels.max())
    increments = round(p_max / np.gcd.reduce(np.round(levels * 1e4).astype(int)) * 1e4)
    steps = steps or StepSettings(increments=increments, substeps=2)
    if steps.increments != increments:
        steps = replace(steps, increments=increments)
    return Full3D(n_units, unit, RampSpec(pressure=p_max, steps=steps))


def calibrate(
    unit: UnitSpec,
    n_units: int,
    pressures_kpa: Sequence[float] = (5, 10, 15, 20, 25, 30, 35, 40, 45),
    runs: int = 3,
    seed: int = 0,
    bounds: tuple[float, float] = (1e-4, 1.0),
    steps: StepSettings | None = None,
    solve_3d: Callable[[Full3D, str], Response] | None = None,
    on_point: Callable[[FillerPoint], None] | None = None,
    weighting: str = "relative",
) -> Calibration:
    """Calibrate the unit's filler law (chapter 5, Fig 5.3).

    Parameters
    ----------
    unit : UnitSpec
        The articulating unit.
    n_units : int
        Actuator length used for calibration (15 in the dissertation).
    pressures_kpa : sequence of float
        Pressure levels (5-45 kPa in 5 kPa steps by default).
    runs : int
        Independent runs; each solves one random design in 3D (all levels from one ramp)
        and starts the optimiser from a new random modulus at every level.
    seed : int
        Seed of the designs and starting points.
    bounds : (float, float)
        Search range of the filler modulus (MPa).
    steps : StepSettings, optional
        Ramp of the 3D and 2D solves; levels are placed so that each calibration pressure
        is a reported level of the 3D ramp.
    solve_3d : callable, optional
        ``solve_3d(model, design) -> Response``; pass a cached solver to reuse 3D results.
    on_point : callable, optional
        Progress: called with each :class:`FillerPoint`.
    weighting : {"relative", "sensitivity", "uniform"}
        Weights of the points in the fits (module notes); ``"sensitivity"`` measures the
        curvature of Eq 5.1 at every point (two more 2D solves each).

    Returns
    -------
    Calibration
    """
    if weighting not in WEIGHTINGS:
        raise SearchConfigError(f"weighting must be one of {', '.join(WEIGHTINGS)}, got {weighting!r}")
    rng = np.random.default_rng(seed)
    levels = np.asarray(pressures_kpa, dtype=float) / 1e3
    model3d = reference_model(unit, n_units, pressures_kpa, steps)
    steps, p_max = model3d.ramp.steps, model3d.ramp.pressure
    solve_3d = solve_3d or (lambda model, design: model.evaluate(design))
    nu = unit.filler_poisson_ratio

    def make_2d(e: float, pressure: float) -> Reduced2D:
        law = FillerLaw("trial", "trial", (e,), (0.0, pressure), nu)
        n = max(1, round(pressure / p_max * steps.increments))
        return Reduced2D(n_units, unit, RampSpec(pressure=pressure, steps=replace(steps, increments=n)), law)

    points = []
    for run, design in enumerate(calibration_designs(n_units, runs, seed)):
        reference = solve_3d(model3d, design)
        for p in levels:
            start = float(10.0 ** rng.uniform(np.log10(bounds[0]) + 0.5, np.log10(bounds[1]) - 0.5))
            level = reference.level_of(p)
            point = replace(best_filler_modulus(design, level, reference, make_2d, start, bounds,
                                                curvature=weighting == "sensitivity"), run=run)
            points.append(point)
            if on_point is not None:
                on_point(point)
    prange = (0.0, p_max)
    ps = [pt.pressure for pt in points]
    es = [pt.modulus for pt in points]
    w = point_weights(points, weighting)
    linear = fit_law(ps, es, 1, prange, w, weighting)
    quadratic = fit_law(ps, es, 2, prange, w, weighting)
    chosen = next((f for f in (quadratic, linear) if not f.problems), None)
    for f in (linear, quadratic):
        for problem in f.problems:
            warnings.warn(f"filler law {problem}", CalibrationWarning, stacklevel=2)
    return Calibration(tuple(points), linear, quadratic, chosen, prange, nu,
                       metadata={"n_units": n_units, "runs": runs, "seed": seed, "weighting": weighting,
                                 "fingerprint_3d": model3d.fingerprint()})


@dataclass(frozen=True)
class Validation:
    """2D against 3D on held-out designs: distances between matching unit centres (mm)."""

    designs: tuple[str, ...]
    pressures: np.ndarray  # (k,) MPa
    mean: np.ndarray  # (k,) mean over designs and units
    max: np.ndarray  # (k,)
    per_design_mean: np.ndarray  # (d, k)

    def to_dict(self) -> dict[str, Any]:
        return {"designs": list(self.designs), "pressures_kpa": (self.pressures * 1e3).tolist(),
                "mean_mm": self.mean.tolist(), "max_mm": self.max.tolist(),
                "per_design_mean_mm": self.per_design_mean.tolist()}


def validate(
    unit: UnitSpec,
    n_units: int,
    designs: Sequence[str],
    ramp: RampSpec,
    solve_3d: Callable[[Full3D, str], Response] | None = None,
) -> Validation:
    """Distances between matching unit centres, 2D (the unit's law) against 3D, per level."""
    model2d = Reduced2D(n_units, unit, ramp)
    model3d = Full3D(n_units, unit, ramp)
    solve_3d = solve_3d or (lambda model, design: model.evaluate(design))
    per = []
    for design in designs:
        r2 = model2d.evaluate(design)
        r3 = solve_3d(model3d, design)
        per.append(np.linalg.norm(r2.centres - r3.centres, axis=-1))  # (k, n)
    d = np.stack(per)  # (designs, k, n)
    return Validation(tuple(designs), model2d.pressures(), d.mean(axis=(0, 2)), d.max(axis=(0, 2)),
                      d.mean(axis=2))


def cached_3d_solver(cache: Any) -> Callable[[Full3D, str], Response]:
    """A ``solve_3d`` that answers from an :class:`~pneumorph.execution.EvaluationCache` and stores
    what it solves (a :class:`~pneumorph.execution.CachedEvaluator` over the serial evaluator)."""
    from pneumorph.execution import CachedEvaluator, SerialEvaluator

    cached = CachedEvaluator(SerialEvaluator(), cache)

    def solve_3d(model: Full3D, design: str) -> Response:
        (outcome,) = cached.evaluate_many(model, [design])
        if not outcome.ok or outcome.response is None:
            raise SimulationFailed(reached=0.0, cause=f"3D reference failed: {outcome.failure}", design=design)
        return outcome.response

    return solve_3d


def plot_calibration(cal: Calibration, path: Any) -> Any:
    """Fig 5.3: the best modulus per pressure for each run, and both fitted laws."""
    from pneumorph.plot.figure import new_figure, save_figure

    fig = new_figure(6.0, 4.2)
    ax = fig.add_subplot()
    for run in sorted({p.run for p in cal.points}):
        pts = [p for p in cal.points if p.run == run]
        ax.plot([p.pressure * 1e3 for p in pts], [p.modulus for p in pts], "o", label=f"run {run + 1}")
    grid = np.linspace(*cal.pressure_range, 100)
    for fit, style in ((cal.linear, "--"), (cal.quadratic, "-")):
        if fit.coefficients:
            ax.plot(grid * 1e3, np.polynomial.polynomial.polyval(grid, fit.coefficients), style,
                    label=f"degree {fit.degree}, {fit.weighting} weighting, R$^2$ = {fit.r_squared:.4f}")
    ax.set(xlabel="pressure [kPa]", ylabel="filler modulus E [MPa]", title="Filler law calibration (Eq 5.1)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, path, "filler law calibration (Fig 5.3)")
