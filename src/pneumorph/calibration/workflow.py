"""A whole calibration into a folder: what ``pneumorph calibrate`` runs.

:func:`run_calibration` solves (or finds in the cache) the 3D references, calibrates the
filler law (:func:`~pneumorph.calibration.calibrate`), checks the chosen law on held-out
designs (:func:`~pneumorph.calibration.validate`), solves the 2D responses the validation
figures compare (:func:`compare_laws`) and writes the files:

- ``calibration.json``: the points, both laws, the chosen degree, the validation, the
  figures' paths and provenance;
- ``calibration.png``: Fig 5.3;
- ``unit.toml``: the unit with the chosen law and its provenance (if a law was acceptable);
- ``profiles.png`` and ``filler_paths.png``: Figs 5.4 and 5.7 for the first held-out design
  (if a law was acceptable and held-out designs were asked for).

Examples
--------
>>> import inspect
>>> list(inspect.signature(run_calibration).parameters)[:4]
['unit', 'n_units', 'pressures_kpa', 'out']
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from pneumorph.calibration.designs import calibration_designs, holdout_designs
from pneumorph.calibration.figures import plot_calibration, plot_filler_paths, plot_law_profiles
from pneumorph.calibration.laws import constant_law, fit_law
from pneumorph.calibration.method import Calibration, calibrate
from pneumorph.calibration.points import FillerPoint, point_weights
from pneumorph.calibration.references import (
    ReferenceSolve,
    Solve3D,
    cached_3d_solver,
    open_cache,
    solve_references,
)
from pneumorph.calibration.validation import Validation, validate
from pneumorph.errors import MaterialDataError, SearchConfigError
from pneumorph.execution import EvaluationCache
from pneumorph.execution.evaluators import Evaluator
from pneumorph.geometry.unit import UnitSpec
from pneumorph.io import atomic_write_text, check_writable_dir, provenance, write_json
from pneumorph.io.files import all_or_nothing
from pneumorph.materials.laws.filler import FillerLaw
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D
from pneumorph.models.response import Response


def law_responses(unit: UnitSpec, n_units: int, design: str, ramp: RampSpec,
                  laws: Mapping[str, FillerLaw]) -> dict[str, Response]:
    """The 2D response of one design under each named filler law.

    Examples
    --------
    >>> law = FillerLaw("c", "c", (0.03,), (0.0, 0.005), 0.3)
    >>> r = law_responses(UnitSpec(), 2, "01", RampSpec(pressure=0.005), {"E = 0.03 MPa": law})
    >>> list(r), r["E = 0.03 MPa"].converged
    (['E = 0.03 MPa'], True)
    """
    return {name: Reduced2D(n_units, unit, ramp, law).evaluate(design) for name, law in laws.items()}


@dataclass(frozen=True)
class LawComparison:
    """The responses the validation figures compare, for one held-out design.

    Attributes
    ----------
    design : str
    reference : Response
        The 3D response.
    fitted : Response
        The 2D response under the chosen law E(P).
    runs : dict of str to Response
        The 2D response under each run's own law (``"run 1 law"``, ...; a run whose law
        has a problem is left out).
    constants : dict of str to Response
        The 2D response under constant fillers: the chosen law at 0 and at the highest
        pressure (``"constant E(0)"``, ``"constant E(45 kPa)"``).
    """

    design: str
    reference: Response
    fitted: Response
    runs: dict[str, Response] = field(default_factory=dict)
    constants: dict[str, Response] = field(default_factory=dict)


def compare_laws(calibration: Calibration, unit: UnitSpec, n_units: int, design: str, p_max: float,
                 solve_3d: Solve3D | None = None) -> LawComparison:
    """Solve one design in 3D and in 2D under the chosen law, each run's law and constant fillers.

    The data of Fig 5.4 (:func:`~pneumorph.calibration.plot_law_profiles`: each run's law
    and the chosen law against 3D) and Fig 5.7
    (:func:`~pneumorph.calibration.plot_filler_paths`: constant filler against E(P)).

    Parameters
    ----------
    calibration : Calibration
        With an acceptable law.
    unit : UnitSpec
        The unit (its filler law is replaced by each law compared).
    n_units : int
    design : str
        A held-out design.
    p_max : float
        The highest pressure, MPa (the ramp of every model).
    solve_3d : callable, optional
        ``solve_3d(model, design) -> Response`` (default: solve the model).

    Raises
    ------
    MaterialDataError
        If the calibration has no acceptable law.
    """
    law = calibration.law()
    chosen = calibration.chosen
    if chosen is None:  # pragma: no cover - law() raised
        raise MaterialDataError("no acceptable filler law")
    ramp = RampSpec(pressure=p_max)
    solve_3d = solve_3d or (lambda model, d: model.evaluate(d))
    reference = solve_3d(Full3D(n_units, unit, ramp), design)
    laws = {}
    for run in sorted({p.run for p in calibration.points}):
        pts = [p for p in calibration.points if p.run == run]
        fit = fit_law([p.pressure for p in pts], [p.modulus for p in pts], chosen.degree,
                      calibration.pressure_range, point_weights(pts, chosen.weighting))
        if fit.coefficients and not fit.problems:  # a run's law that is not positive cannot be solved
            laws[f"run {run + 1} law"] = replace(law, coefficients=fit.coefficients)
    constants = {"constant E(0)": constant_law(law, 0.0, "constant E(0)"),
                 f"constant E({p_max * 1e3:g} kPa)": constant_law(law, p_max, "constant E(p_max)")}
    solved = law_responses(unit, n_units, design, ramp, {"E(P)": law, **laws, **constants})
    fitted = solved.pop("E(P)")  # solved once, drawn in both figures
    return LawComparison(design, reference, fitted, {name: solved[name] for name in laws},
                         {name: solved[name] for name in constants})


@dataclass(frozen=True)
class CalibrationRun:
    """What :func:`run_calibration` computed and wrote.

    Attributes
    ----------
    calibration : Calibration
    folder : Path
        Where the files are.
    unit : UnitSpec or None
        The unit with the chosen law (written to ``unit.toml``); None if no law was acceptable.
    validation : Validation or None
        The held-out check (None without an acceptable law or held-out designs).
    comparison : LawComparison or None
        The responses of the validation figures, for the first held-out design.
    files : tuple of Path
        Every file written.
    summary : dict
        The contents of ``calibration.json``.
    """

    calibration: Calibration
    folder: Path
    unit: UnitSpec | None
    validation: Validation | None
    comparison: LawComparison | None
    files: tuple[Path, ...]
    summary: dict[str, Any]


def run_calibration(
    unit: UnitSpec,
    n_units: int,
    pressures_kpa: Sequence[float] = (5, 10, 15, 20, 25, 30, 35, 40, 45),
    out: str | Path = "runs/calibration",
    runs: int = 3,
    seed: int = 0,
    n_validate: int = 10,
    weighting: str = "relative",
    cache: EvaluationCache | str | Path | None = None,
    on_point: Callable[[FillerPoint], None] | None = None,
    evaluator: Evaluator | None = None,
    on_reference: Callable[[ReferenceSolve], None] | None = None,
    say: Callable[[str], None] | None = None,
) -> CalibrationRun:
    """Calibrate a unit's filler law against 3D, check it on held-out designs and write the folder.

    Parameters
    ----------
    unit : UnitSpec
        The articulating unit.
    n_units : int
        Actuator length of the calibration and the validation.
    pressures_kpa : sequence of float
        Calibration pressures, kPa (at least two different ones; sorted, duplicates dropped).
    out : str or Path
        The folder (created if missing; checked before anything is solved).
    runs, seed : int
        Independent runs and the seed of their designs and starting points
        (:func:`~pneumorph.calibration.calibrate`).
    n_validate : int
        Held-out designs for the 2D-against-3D check (0: none).
    weighting : {"relative", "sensitivity", "uniform"}
        Weights of the points in the fits (:mod:`pneumorph.calibration`).
    cache : EvaluationCache, str or Path, optional
        The 3D results cache (:func:`~pneumorph.calibration.open_cache`); by default
        :func:`~pneumorph.execution.default_cache_path`.
    on_point : callable, optional
        Progress: called with each :class:`~pneumorph.calibration.FillerPoint`.
    evaluator : Evaluator, optional
        Solves every 3D reference first, several at once (a process pool or a Dask
        cluster, :mod:`pneumorph.execution`; :func:`~pneumorph.calibration.solve_references`),
        into the cache the calibration then reads; by default each is solved in this process
        when the calibration asks for it.
    on_reference : callable, optional
        Progress of those solves: called with each :class:`~pneumorph.calibration.ReferenceSolve`.
    say : callable, optional
        Called with the line that says what is written where, before the held-out check and the files.

    Returns
    -------
    CalibrationRun

    Raises
    ------
    SearchConfigError
        Fewer than two different pressures, an unknown weighting, or fewer held-out designs than asked for.
    OutputPathError
        If ``out`` cannot be created or written.
    CacheError
        If ``cache`` cannot serve as a cache.

    Warns
    -----
    CalibrationWarning
        For each problem of a fitted law.
    """
    levels = tuple(sorted({float(p) for p in pressures_kpa}))
    if len(levels) < 2:
        raise SearchConfigError(f"a calibration needs at least two different pressures, got {list(pressures_kpa)}")
    folder = check_writable_dir(out, "calibration folder")
    plan = _Plan(unit, n_units, levels, runs, seed, n_validate)
    with open_cache(cache) as store:
        if evaluator is not None:
            solve_references(unit, n_units, levels, runs, seed, n_validate, store, on_reference, evaluator)
        solve_3d = cached_3d_solver(store)
        result = calibrate(unit, n_units, levels, runs, seed, solve_3d=solve_3d, on_point=on_point, weighting=weighting)
        with all_or_nothing(folder, say=say, what="the calibration and its check"):  # a Ctrl-C: no partial output
            written = _write(plan, result, solve_3d, folder)
    return written


@dataclass(frozen=True)
class _Plan:
    """A calibration's settings, as the steps after the fit use them (:func:`run_calibration`)."""

    unit: UnitSpec
    n_units: int
    levels: tuple[float, ...]
    runs: int
    seed: int
    n_validate: int


def _write(plan: _Plan, result: Calibration, solve_3d: Solve3D, folder: Path) -> CalibrationRun:
    """Fig 5.3, the calibrated unit, the held-out check with its figures, and ``calibration.json``."""
    from pneumorph.design.config import to_toml

    files = [plot_calibration(result, folder / "calibration.png")]
    summary: dict[str, Any] = {
        "points": [p.__dict__ for p in result.points],
        "linear": result.linear.__dict__, "quadratic": result.quadratic.__dict__,
        "chosen_degree": None if result.chosen is None else result.chosen.degree,
        "provenance": provenance(unit=plan.unit.to_dict(), calibration=result.metadata),
    }
    calibrated, check, comparison = None, None, None
    if result.chosen is not None:
        calibrated = result.unit_with_law(plan.unit)
        files.append(atomic_write_text(folder / "unit.toml", to_toml({"unit": calibrated.to_dict()})))
        if plan.n_validate > 0:
            check, comparison = _held_out(plan, result, calibrated, solve_3d)
            summary["validation"] = check.to_dict()
            figures = [plot_law_profiles({**comparison.runs, "fitted law": comparison.fitted},
                                         comparison.reference, folder / "profiles.png"),
                       plot_filler_paths({"E(P)": comparison.fitted, **comparison.constants},
                                         comparison.reference, folder / "filler_paths.png")]
            summary["figures"] = [str(f) for f in figures]
            files += figures
    files.append(write_json(folder / "calibration.json", summary))
    return CalibrationRun(result, folder, calibrated, check, comparison, tuple(files), summary)


def _held_out(plan: _Plan, result: Calibration, calibrated: UnitSpec, solve_3d: Solve3D
              ) -> tuple[Validation, LawComparison]:
    """The calibrated unit checked on held-out designs, and the laws compared on the first of them."""
    taken = calibration_designs(plan.n_units, plan.runs, plan.seed)
    designs = holdout_designs(plan.n_units, plan.n_validate, plan.seed, taken)
    p_max = max(plan.levels) / 1e3
    check = validate(calibrated, plan.n_units, designs, RampSpec(pressure=p_max), solve_3d)
    return check, compare_laws(result, calibrated, plan.n_units, designs[0], p_max, solve_3d)
