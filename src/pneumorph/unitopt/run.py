"""The driver of the unit optimisation: NSGA-II over the design space, and what it writes.

:func:`optimise` runs pymoo's NSGA-II (Deb et al. 2002) on a
:class:`~pneumorph.unitopt.problem.UnitProblem`: a seeded Latin hypercube start that
holds the base unit (the built-in one) when it lies in the box, the space's rounding as
the repair, ``pop_size`` offspring per generation. Every candidate goes through the given
evaluator; with the package's cache (``CachedEvaluator``) a run that was stopped resumes:
the same seed asks for the same candidates, and those solved before are read back.

:func:`write_outputs` writes a folder:

- ``candidates.csv``: every candidate solved (dimensions, Omega, h_b and its parts, strain,
  feasibility, generation);
- ``pareto.csv`` and ``pareto.json``: the feasible non-dominated candidates (the front),
  the base unit and the settings, with provenance;
- ``front.png``: the front beside every candidate (:func:`pneumorph.unitopt.figures.plot_front`);
- ``units/*.toml``: unit files (``[unit]`` table, :meth:`UnitSpec.from_toml`) of the chosen
  points: the largest Omega, the smallest h_b, the knee of the front, and ``better.toml``,
  the largest Omega of the units that bend more than the base unit at the same or a lower
  h_b within the strain limit (if any).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from pneumorph.errors import GeometryError, RunFolderError, SettingsError
from pneumorph.unitopt.probe import DEFAULT_UNITS
from pneumorph.unitopt.problem import (
    CandidateEvaluator,
    SnapRepair,
    UnitCandidate,
    UnitProblem,
    check_strain_limit,
)
from pneumorph.unitopt.records import DEFAULT_STRAIN_LIMIT, STRAIN_LIMIT_SOURCE, OptimiseSettings, UnitOptimisation
from pneumorph.unitopt.space import DesignSpace, FloatArray


def latin_hypercube(space: DesignSpace, n: int, seed: int) -> FloatArray:
    """``n`` snapped points of a Latin hypercube over the space (seeded); row 0 is the base unit if inside.

    >>> x = latin_hypercube(DesignSpace.default(), 8, seed=1)
    >>> x.shape, x[0].tolist()
    ((8, 4), [6.0, 3.0, 1.5, 3.0])
    """
    rng = np.random.default_rng(seed)
    k = len(space.variables)
    strata = np.array([rng.permutation(n) for _ in range(k)]).T
    u = (strata + rng.random((n, k))) / n
    x = space.lower + u * (space.upper - space.lower)
    base = space.base_point()
    if np.all((base >= space.lower) & (base <= space.upper)):
        x[0] = base
    return np.array([space.snap(row) for row in x])


def front_of(candidates: list[UnitCandidate], strain_limit: float) -> list[UnitCandidate]:
    """The feasible candidates no other feasible one dominates (in ``-Omega``, h_b), by increasing h_b."""
    from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

    feasible = [c for c in candidates if c.feasible(strain_limit)]
    if not feasible:
        return []
    f = np.array([c.objectives() for c in feasible])
    first = NonDominatedSorting().do(f, only_non_dominated_front=True)
    return sorted((feasible[i] for i in first), key=lambda c: c.objectives()[1])


def optimise(settings: OptimiseSettings, evaluator: Any, on_candidate: Callable[[UnitCandidate], None] | None = None,
             on_generation: Callable[[int, list[UnitCandidate]], None] | None = None) -> UnitOptimisation:
    """Run NSGA-II on the unit (see the module docstring).

    Parameters
    ----------
    settings : OptimiseSettings
    evaluator : Evaluator
        Solves the probes (``iter_cases``); a ``CachedEvaluator`` makes the run resumable.
    on_candidate : callable, optional
        ``on_candidate(candidate)`` as each candidate is solved.
    on_generation : callable, optional
        ``on_generation(generation, front)`` after each generation.

    Raises
    ------
    GeometryError
        The space's bounds do not always make a unit (checked before any solve).
    """
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.core.callback import Callback
    from pymoo.optimize import minimize

    check_settings(settings.space, settings.strain_limit, settings.n_units)
    candidates = CandidateEvaluator(settings.space, evaluator, settings.n_units, settings.pressure, on_candidate)
    problem = UnitProblem(candidates, settings.strain_limit)
    base = candidates.evaluate(settings.space.base_point()[None])[0]  # in or outside the box: the reference

    class Generations(Callback):  # the front said after each generation
        def notify(self, algorithm: Any) -> None:
            candidates.generation = algorithm.n_gen  # the offspring asked for next belong to this generation
            if on_generation is not None:
                on_generation(algorithm.n_gen - 1, front_of(list(candidates.history.values()),
                                                            settings.strain_limit))

    algorithm = NSGA2(pop_size=settings.pop_size, sampling=latin_hypercube(settings.space, settings.pop_size,
                                                                           settings.seed),
                      repair=SnapRepair(settings.space), eliminate_duplicates=True)
    minimize(problem, algorithm, ("n_gen", settings.generations + 1), seed=settings.seed, callback=Generations(),
             verbose=False, save_history=False)
    everything = list(candidates.history.values())
    return UnitOptimisation(settings, everything, front_of(everything, settings.strain_limit), base,
                            solves=int(getattr(evaluator, "solves", 0)), hits=int(getattr(evaluator, "hits", 0)))


_COLUMNS = ("omega_deg", "balloon_mm", "balloon_bottom_mm", "balloon_end_mm", "balloon_side_mm", "strain",
            "layer_strain", "curl_per_unit_deg", "feasible", "failure", "reached_kpa", "generation", "cached",
            "wall_time_s")


def table_csv(result: UnitOptimisation, candidates: list[UnitCandidate]) -> str:
    """CSV text of ``candidates``: the varied dimensions, then the measures (see :class:`UnitCandidate.row`)."""
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=[*result.settings.space.names, *_COLUMNS], lineterminator="\n")
    writer.writeheader()
    for c in candidates:
        row = c.row(result.settings.strain_limit)
        writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) and not isinstance(v, bool) and math.isfinite(v)
                             else ("" if v is None else v)) for k, v in row.items()})
    return out.getvalue()


def unit_file(candidate: UnitCandidate, label: str, result: UnitOptimisation, prov: dict[str, Any]) -> str:
    """TOML text of a chosen unit: its ``[unit]`` table (what differs from the built-in unit, and its name),
    then ``[unitopt]`` with its measures and where it comes from (ignored by :meth:`UnitSpec.from_toml`)."""
    from dataclasses import replace

    from pneumorph.design.config import to_toml
    from pneumorph.geometry.unit import UnitSpec

    unit = replace(candidate.unit, name=f"unitopt_{label.replace('-', '_')}")
    default = UnitSpec().to_dict()
    table = {k: v for k, v in unit.to_dict().items() if k == "name" or v != default.get(k)}
    measures = candidate.measures.to_dict() if candidate.measures is not None else {}
    meta = {"label": label, **measures, "strain_limit": result.settings.strain_limit,
            "pressure_kpa": result.settings.pressure * 1e3, "probe_units": result.settings.n_units,
            "pneumorph": prov.get("pneumorph"), "created_utc": prov.get("created_utc"),
            "command": prov.get("command")}
    return to_toml({"unit": table, "unitopt": meta})


def write_outputs(result: UnitOptimisation, folder: str | Path, **provenance_extra: Any) -> list[Path]:
    """Write the tables, the figure and the chosen units' files into ``folder`` (see the module docstring)."""
    from pneumorph.io import provenance
    from pneumorph.io.files import atomic_write_text, write_json
    from pneumorph.unitopt.figures import plot_front

    out = Path(folder)
    (out / "units").mkdir(parents=True, exist_ok=True)
    prov = provenance(settings=result.settings.to_dict(), **provenance_extra)
    limit = result.settings.strain_limit
    written = [atomic_write_text(out / "candidates.csv", table_csv(result, result.candidates)),
               atomic_write_text(out / "pareto.csv", table_csv(result, result.front))]
    chosen = result.chosen()
    data = {
        "front": [c.row(limit) for c in result.front],
        "base": result.base.row(limit),
        "better_than_base": [c.row(limit) for c in result.better()],
        "chosen": {label: c.values for label, c in chosen.items()},
        "candidates": len(result.candidates),
        "feasible": sum(c.feasible(limit) for c in result.candidates),
        "failed": sum(c.measures is None for c in result.candidates),
        "solves": result.solves,
        "cache_hits": result.hits,
        "provenance": prov,
    }
    written.append(write_json(out / "pareto.json", data))
    written.append(plot_front(result, out / "front.png"))
    for label, c in chosen.items():
        written.append(atomic_write_text(out / "units" / f"{label}.toml", unit_file(c, label, result, prov)))
    for label in set(CHOSEN) - set(chosen):  # an earlier run's choice that this run did not make
        (out / "units" / f"{label}.toml").unlink(missing_ok=True)
    return written


#: what :func:`write_outputs` writes into a folder (``units`` holds the files of :data:`CHOSEN`)
OUTPUTS = ("candidates.csv", "pareto.csv", "pareto.json", "front.png", "units")
#: the chosen units' file names (``units/<label>.toml``)
CHOSEN = ("max-omega", "min-balloon", "knee", "better")


def check_folder(folder: str | Path, settings: OptimiseSettings, overwrite: bool = False) -> None:
    """Refuse an output folder that holds another run, before anything is solved or written.

    A folder that does not exist, is empty (a lock file aside), or holds a unit optimisation
    of the same settings (its ``pareto.json``; the rerun resumes through the cache and writes
    the same files again) is taken; so is any folder with ``overwrite``: the files of
    :data:`OUTPUTS` are then replaced, other files stay.

    Raises
    ------
    RunFolderError
        The folder holds a unit optimisation of other settings, or other files (another
        command's run); the message names them and the two ways out.
    """
    import json

    from pneumorph.io.files import strict_json
    from pneumorph.io.lock import LOCK_NAME
    from pneumorph.io.reading import read_json

    path = Path(folder)
    if overwrite or not path.is_dir():
        return
    entries = sorted(p.name for p in path.iterdir() if p.name != LOCK_NAME)
    if not entries:
        return
    others = [name for name in entries if name not in OUTPUTS]
    old = None
    if not others:
        try:  # the one bounded reader: a pipe, a device or a huge file in its place is not read
            old = read_json(path / "pareto.json", "the output folder's pareto.json", RunFolderError)
            old = old["provenance"]["settings"]
        except (RunFolderError, KeyError, TypeError):
            old = None
        if old == json.loads(strict_json(settings.to_dict())):
            return
    named = others or entries
    what = ("a unit optimisation with other settings" if old is not None else
            f"another run's files ({', '.join(named[:3])}{', ...' if len(named) > 3 else ''})")
    raise RunFolderError(f"{path} holds {what}; give another folder with --out, or write into it with --overwrite "
                         "(the files of a unit optimisation are replaced, others stay)")


def check_settings(space: DesignSpace, strain_limit: float, n_units: int = DEFAULT_UNITS, parallel: int = 1,
                   memory: int | None = None) -> None:
    """The checks of :func:`optimise` that need no solve (for the command line, before anything is written).

    In this order: the strain limit; a base unit that bends (not ``solid``); every variable's
    range holds at least two values at the space's resolution; the probe's mesh at every
    corner of the box, estimated before anything is meshed
    (:func:`pneumorph.geometry.meshsize.check_mesh`: ``parallel`` solves of ``n_units`` units
    within ``memory`` bytes, by default the memory available now); then every corner is
    built and meshed (:meth:`DesignSpace.check`).

    Raises
    ------
    SettingsError
        A bad strain limit, a solid base unit, a range without two values.
    GeometryError
        A corner that makes no unit or does not mesh; :class:`~pneumorph.geometry.limits.MeshLimitError`
        with the estimate for a probe too large for the memory.

    Examples
    --------
    >>> from pneumorph.unitopt.space import Variable
    >>> check_settings(DesignSpace((Variable("wall", 1.0, 1.04),)), 4.4)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: the range of wall 1-1.04 mm holds one value (1 mm) at the resolution
        0.1 mm: widen it or give a finer --resolution
    """
    from itertools import product

    from pneumorph.geometry import meshsize

    check_strain_limit(strain_limit)
    if not isinstance(space, DesignSpace):
        raise SettingsError(f"expected a DesignSpace, got {type(space).__name__}")
    if space.base.solid:
        raise SettingsError("the base unit is solid (solid = true: its cavity is filled), so it does not bend: "
                            "its Omega is 0 whatever its dimensions; optimise a unit with a cavity")
    r = space.resolution
    for v in space.variables:
        if r == 0:
            continue
        first, last = math.ceil(v.low / r - 1e-9), math.floor(v.high / r + 1e-9)  # the grid's values in the range
        if last - first < 1:
            held = f"one value ({round(first * r, 9):g} mm)" if last == first else "no value"
            raise SettingsError(f"the range of {v.name} {v.low:g}-{v.high:g} mm holds {held} at the resolution "
                                f"{r:g} mm: widen it or give a finer --resolution")
    free = meshsize.available_memory() if memory is None else memory
    for corner in product(*[(v.low, v.high) for v in space.variables]):
        values: dict[str, Any] = dict(zip(space.names, corner, strict=True))
        where = ", ".join(f"{n}={c:g}" for n, c in values.items())
        try:
            spec = replace(space.base, **values)
        except GeometryError:
            continue  # no unit at this corner: DesignSpace.check says so, naming the corner
        meshsize.check_mesh(spec, n_units, 3, memory=free, parallel=parallel,
                          advice=f"narrow the bounds (this is the unit at {where} mm), raise --element-size or use "
                                 "fewer --units")
    space.check()


__all__ = ["CHOSEN", "DEFAULT_STRAIN_LIMIT", "OUTPUTS", "STRAIN_LIMIT_SOURCE", "OptimiseSettings", "UnitOptimisation",
           "check_folder", "check_settings",
           "front_of", "latin_hypercube", "optimise", "table_csv", "unit_file", "write_outputs"]
