"""The calibration method (chapter 5; the dissertation's "method 2", section 4.3).

Each of several independent runs solves one random design in 3D; one 3D ramp reports every
calibration pressure. At each pressure level the best constant filler modulus is found
(:func:`~pneumorph.calibration.best_filler_modulus`, Eq 5.1) from a random starting point.
The 2D solve for a trial E uses a constant filler of modulus E up to the level's pressure:
a hyperelastic equilibrium does not depend on the loading path, so this is the 2D state at
that pressure with E(P) = E. Linear and quadratic laws E(P) are then fitted to all (P, E)
points (:func:`~pneumorph.calibration.fit_law`, Fig 5.3); the quadratic is chosen if it
has no problem, else the linear; a law with a problem is reported with a
:class:`~pneumorph.calibration.CalibrationWarning` and not used.

Examples
--------
>>> from pneumorph.calibration import FillerPoint, fit_law
>>> pts = tuple(FillerPoint(0, p, "01", 0.05 - p, 0.0, 0.03, 1) for p in (0.01, 0.02, 0.03))
>>> fit = fit_law([p.pressure for p in pts], [p.modulus for p in pts], 1, (0.0, 0.03))
>>> cal = Calibration(pts, fit, fit, fit, (0.0, 0.03), 0.3)
>>> round(cal.law().modulus(0.015), 6)
0.035
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from pneumorph.calibration.designs import calibration_designs
from pneumorph.calibration.laws import CalibrationWarning, LawFit, fit_law
from pneumorph.calibration.points import WEIGHTINGS, FillerPoint, best_filler_modulus, point_weights
from pneumorph.calibration.references import Solve3D, reference_model
from pneumorph.errors import MaterialDataError, SearchConfigError
from pneumorph.fem import StepSettings
from pneumorph.geometry.unit import UnitSpec
from pneumorph.materials.laws.filler import FillerLaw
from pneumorph.models.fe import RampSpec, Reduced2D


@dataclass(frozen=True)
class Calibration:
    """The points of every run, both fitted laws and the chosen one.

    Attributes
    ----------
    points : tuple of FillerPoint
        Every run's best modulus at every level.
    linear, quadratic : LawFit
        The laws fitted to all points.
    chosen : LawFit or None
        The quadratic if it has no problem, else the linear if it has none, else None.
    pressure_range : (float, float)
        Range of the laws, MPa (0 to the highest calibration pressure).
    poisson_ratio : float
        The filler's Poisson's ratio (the unit's).
    metadata : dict
        Settings and the 3D model's fingerprint, for provenance.
    """

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


def calibrate(
    unit: UnitSpec,
    n_units: int,
    pressures_kpa: Sequence[float] = (5, 10, 15, 20, 25, 30, 35, 40, 45),
    runs: int = 3,
    seed: int = 0,
    bounds: tuple[float, float] = (1e-4, 1.0),
    steps: StepSettings | None = None,
    solve_3d: Solve3D | None = None,
    on_point: Callable[[FillerPoint], None] | None = None,
    weighting: str = "relative",
) -> Calibration:
    """Calibrate the unit's filler law (chapter 5, Fig 5.3).

    See the module notes; :func:`~pneumorph.calibration.run_calibration` adds the
    validation, the figures and the files.

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
        Weights of the points in the fits (:mod:`pneumorph.calibration`); ``"sensitivity"`` measures the
        curvature of Eq 5.1 at every point (two more 2D solves each).

    Returns
    -------
    Calibration
    """
    if weighting not in WEIGHTINGS:
        raise SearchConfigError(f"weighting must be one of {', '.join(WEIGHTINGS)}, got {weighting!r}")
    model3d = reference_model(unit, n_units, pressures_kpa, steps)
    points = _points(model3d, unit, n_units, np.asarray(pressures_kpa, dtype=float) / 1e3, runs, seed, bounds,
                     solve_3d or (lambda model, design: model.evaluate(design)), on_point, weighting)
    prange = (0.0, model3d.ramp.pressure)
    linear, quadratic, chosen = _fit_laws(points, prange, weighting)
    return Calibration(tuple(points), linear, quadratic, chosen, prange, unit.filler_poisson_ratio,
                       metadata={"n_units": n_units, "runs": runs, "seed": seed, "weighting": weighting,
                                 "fingerprint_3d": model3d.fingerprint()})


def _points(model3d: Any, unit: UnitSpec, n_units: int, levels: np.ndarray, runs: int, seed: int,
            bounds: tuple[float, float], solve_3d: Solve3D, on_point: Callable[[FillerPoint], None] | None,
            weighting: str) -> list[FillerPoint]:
    """Every run's best filler modulus at every level (Eq 5.1), each from a random start."""
    rng = np.random.default_rng(seed)
    steps, p_max = model3d.ramp.steps, model3d.ramp.pressure
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
    return points


def _fit_laws(points: Sequence[FillerPoint], prange: tuple[float, float], weighting: str
              ) -> tuple[LawFit, LawFit, LawFit | None]:
    """The linear and the quadratic law fitted to all points, and the chosen one; each problem warned of
    (:class:`CalibrationWarning`, at the caller of :func:`calibrate`)."""
    ps = [pt.pressure for pt in points]
    es = [pt.modulus for pt in points]
    w = point_weights(points, weighting)
    linear = fit_law(ps, es, 1, prange, w, weighting)
    quadratic = fit_law(ps, es, 2, prange, w, weighting)
    chosen = next((f for f in (quadratic, linear) if not f.problems), None)
    for f in (linear, quadratic):
        for problem in f.problems:
            warnings.warn(f"filler law {problem}", CalibrationWarning, stacklevel=3)
    return linear, quadratic, chosen
