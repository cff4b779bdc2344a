"""Calibrate the 2D model's filler law E(P) against the 3D model (chapter 5).

Each of several independent runs solves one random design in 3D (:mod:`.designs`,
:mod:`.references`); one 3D ramp reports every calibration pressure (the dissertation's
"method 2", section 4.3). At each pressure level the filler modulus E that makes the 2D
model reproduce that 3D state best is found with a SciPy optimiser from a random starting
point, minimising Eq 5.1 (:mod:`.points`):

    Gamma(E) = sum over units [(X2 - X3)^2 + (Y2 - Y3)^2]

over the unit-centre displacements at that pressure. Linear and quadratic laws E(P) are
then fitted to all (P, E) points by weighted least squares with their R^2 (:mod:`.laws`,
Fig 5.3); a law that fits badly or is not positive over the range is reported with a
:class:`CalibrationWarning` and not silently used (:mod:`.method`). The chosen law is
checked against 3D on held-out designs (:mod:`.validation`). :func:`run_calibration`
(:mod:`.workflow`) does all of it into a folder, with the figures (:mod:`.figures`): it is
``pneumorph calibrate``.

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

Examples
--------
>>> from pneumorph.calibration import fit_law
>>> fit = fit_law([0.005, 0.01, 0.02], [0.05, 0.04, 0.02], 1, (0.0, 0.02))
>>> [round(c, 6) for c in fit.coefficients]
[0.06, -2.0]
"""

from pneumorph.calibration.designs import calibration_designs, holdout_designs
from pneumorph.calibration.figures import plot_calibration, plot_filler_paths, plot_law_profiles
from pneumorph.calibration.laws import R2_WARNING, CalibrationWarning, LawFit, constant_law, fit_law
from pneumorph.calibration.method import Calibration, calibrate
from pneumorph.calibration.points import (
    CURVATURE_STEP,
    WEIGHTINGS,
    FillerPoint,
    best_filler_modulus,
    gamma,
    point_weights,
    unit_centre_displacements,
)
from pneumorph.calibration.references import (
    ReferenceSolve,
    Solve3D,
    cached_3d_solver,
    open_cache,
    reference_model,
    solve_references,
)
from pneumorph.calibration.validation import Validation, centre_distances, validate
from pneumorph.calibration.workflow import (
    CalibrationRun,
    LawComparison,
    compare_laws,
    law_responses,
    run_calibration,
)

__all__ = [
    "CURVATURE_STEP",
    "R2_WARNING",
    "WEIGHTINGS",
    "Calibration",
    "CalibrationRun",
    "CalibrationWarning",
    "FillerPoint",
    "LawComparison",
    "LawFit",
    "ReferenceSolve",
    "Solve3D",
    "Validation",
    "best_filler_modulus",
    "cached_3d_solver",
    "calibrate",
    "calibration_designs",
    "centre_distances",
    "compare_laws",
    "constant_law",
    "fit_law",
    "gamma",
    "holdout_designs",
    "law_responses",
    "open_cache",
    "plot_calibration",
    "plot_filler_paths",
    "plot_law_profiles",
    "point_weights",
    "reference_model",
    "run_calibration",
    "solve_references",
    "unit_centre_displacements",
    "validate",
]
