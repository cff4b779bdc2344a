"""Which search a certified run makes, with which chain table, and what it will build - before anything runs.

A certified run (:func:`pneumorph.design.driver.run_design`) first looks for a chain table
that serves its model (:func:`pneumorph.models.chain.sources.serve_table`: the shipped or a
kept table of its source, or of a longer ramp of the same step, restricted to the levels
at or below its pressure). Then :func:`plan_search` decides:

- **certified search** with that table, when it serves the actuator's length (a table of
  window ``+-w`` needs ``n >= 2w + 1`` units); the FE verifications use the model remade
  with the table's levels;
- **FE exhaustive search** over all ``2^n`` designs, when the actuator is shorter than the
  table needs, or when no table serves and the actuator is shorter than a new table could
  need (``2 MAX_WINDOW + 1`` = 7 units): ``2^(n-1) + 1`` FE solves of ``n`` units by mirror
  symmetry, fewer and smaller than a table build's (22-59 solves of 15 units);
- **a table build**, announced with its estimate when the run starts; with ``build=False``
  (``--no-build``) the run stops instead, with one line naming the missing table and the
  command that builds it (:class:`~pneumorph.errors.MissingTableError`).

Examples
--------
>>> from pneumorph.design.config import DesignConfig
>>> from pneumorph.models.factory import make_model
>>> config = DesignConfig(units=6)
>>> plan = plan_search(config, make_model(6, {"fidelity": "3d"}), None, workers=2)
>>> plan.search, plan.note  # doctest: +ELLIPSIS
('exhaustive', 'FE exhaustive search over all 64 designs instead of the certified search: the chain table ...')
"""

from __future__ import annotations

import os
import shlex
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pneumorph.design.certified.spacegrowth import check_space_objective
from pneumorph.errors import ChainTableError, MissingTableError, SearchConfigError
from pneumorph.models.chain.fit import MAX_WINDOW
from pneumorph.models.chain.model import ChainTable, in_space, source_key
from pneumorph.models.chain.plan import build_plan, estimate_text
from pneumorph.models.chain.sources import (
    TRAINING_UNITS,
    ServedTable,
    build_options,
    limits_text,
    same_source,
    serve_table,
    shipped_for,
    table_file,
)

#: the model settings `pneumorph chain build` takes as options (the command of a missing table names them)
_BUILD_OPTIONS = {"fidelity": "--model", "pressure_kpa": "--pressure", "unit_file": "--unit", "library": "--library",
                  "quadrature": "--quadrature"}


@dataclass(frozen=True)
class SearchPlan:
    """What a certified run does.

    Attributes
    ----------
    search : {"certified", "exhaustive"}
        The search that runs.
    served : ServedTable or None
        The chain table and the FE model it verifies with (certified search with a table at hand).
    build : bool
        A certified search whose table is built first (announced, under the table's lock).
    note : str
        The search as a sentence: which table and levels the chain scores, or why the FE
        exhaustive search and what it costs; said at the start and in the report.
    """

    search: str
    served: ServedTable | None = None
    build: bool = False
    note: str = ""


def planned_workers(config: Any) -> int:
    """The workers a run's evaluator will have: 1 for serial, the config's or all cores otherwise.

    >>> from pneumorph.design.config import DesignConfig
    >>> planned_workers(DesignConfig(executor="serial")), planned_workers(DesignConfig(executor="processes", workers=3))
    (1, 3)
    """
    if config.executor == "serial":
        return 1
    return int(config.workers or os.cpu_count() or 1)


def exhaustive_note(n_units: int, fidelity: str, workers: int, why: str) -> str:
    """The note of an FE exhaustive search chosen for a short actuator: designs, solves, estimated time, why.

    >>> print(exhaustive_note(6, "3d", 2, "the reason"))  # doctest: +NORMALIZE_WHITESPACE
    FE exhaustive search over all 64 designs instead of the certified search: the reason; 33 FE solves (the mirror
    designs by symmetry), estimated 1.7 min with 2 workers (about 6 s a 3d solve of 6 units on one core, from
    BENCHMARKS.md; an estimate)
    """
    solves = exhaustive_solves(n_units)
    plural = "s" if solves > 1 else ""
    return (f"FE exhaustive search over all {2**n_units:,} designs instead of the certified search: {why}; "
            f"{solves} FE solve{plural} (the mirror designs by symmetry), "
            f"{estimate_text(solves, fidelity, n_units, workers)}")


def exhaustive_solves(n_units: int) -> int:
    """FE solves of an exhaustive search over ``n_units`` units with mirror symmetry (``run_exhaustive``): the
    designs whose first unit is 0, and the mirror of one of them that checks the symmetry.

    >>> [exhaustive_solves(n) for n in (1, 2, 6)]
    [1, 3, 33]
    """
    n = int(n_units)
    return 2 ** (n - 1) + (1 if n > 1 else 0)


def serves(table: ChainTable, n_units: int) -> bool:
    """Whether ``table`` can score actuators of ``n_units`` units (every window seen: ``n >= 2w + 1``).

    >>> from pneumorph.models.chain.sources import shipped_path
    >>> table = ChainTable.load(shipped_path("3d"))
    >>> serves(table, 6), serves(table, 7), serves(table, 15)
    (False, True, True)
    """
    try:
        table.check_units(n_units)
    except ChainTableError:
        return False
    return True


def given_table_error(path: str | Path, exc: ChainTableError) -> ChainTableError:
    """A given table's refusal naming the option that gave it: ``--chain-table PATH: ...``."""
    return ChainTableError(f"--chain-table {path}: {str(exc).removeprefix(f'{path}: ')}")


def _given_table(model: Any, table_dir: str | Path | None, path: str | Path | None) -> Any:
    """:func:`serve_table`, a given table's refusal named by :func:`given_table_error`."""
    try:
        return serve_table(model, table_dir, path)
    except ChainTableError as exc:
        if path is None:
            raise
        raise given_table_error(path, exc) from None


def plan_search(config: Any, model: Any, table_dir: str | Path | None, build: bool = True,
                workers: int = 1) -> SearchPlan:
    """Choose the search of a certified run (see the module): no solve, no file written.

    Parameters
    ----------
    config : DesignConfig
        A certified run's settings (``units``, ``chain_table``, ``model``).
    model : ActuatorModel
        The FE model asked for.
    table_dir : path or None
        The table folder beside the evaluation cache (None: an in-memory cache keeps no table).
    build : bool
        Whether the run may build a table it needs.
    workers : int
        The evaluator's workers, for the estimates.

    Raises
    ------
    ChainTableError
        A given table (``chain_table``) is damaged, of another model, or too narrow for the
        actuator's length.
    MissingTableError
        No table serves the model and ``build`` is False: one line naming the table and
        the command that builds it.
    SearchConfigError
        A short actuator over a unit library of several types (no exhaustive search lists
        their designs); an objective the chain in space cannot score, over sideways units.
    """
    n = int(config.units)
    fidelity = str(getattr(model, "fidelity", "?"))
    mixed = bool(getattr(model, "mixed", False))
    if in_space(model):  # before a table is served or built: what a chain in space cannot score
        check_space_objective(config.make_objective())
    served = _given_table(model, table_dir, config.chain_table)
    if served is not None and config.chain_table is not None and not serves(served.table, n):
        w = served.table.window
        raise ChainTableError(
            f"--chain-table {config.chain_table}: a chain table of window +-{w} needs at least {2 * w + 1} units "
            f"(every window then holds at most one end); got {n}. Leave --chain-table out to search all "
            f"{2**n:,} designs by FE, or use --search exhaustive")
    if served is not None and serves(served.table, n):
        t = served.table
        note = f"certified search with the chain table of window +-{t.window}"
        if served.restricted:
            note += f" {served.origin_text()}, {served.levels_text()}"
        if limits_text(t):
            note += f"; {limits_text(t)}"
        return SearchPlan("certified", served, note=note)
    if served is not None:
        w = served.table.window
        why = f"the chain table of window +-{w} needs at least {2 * w + 1} units"
    else:
        why = (f"no chain table serves this model, and {n} units are fewer than a new table could need "
               f"({2 * MAX_WINDOW + 1} for window +-{MAX_WINDOW}); these designs cost fewer solves than a table build")
    if mixed and (served is not None or n < 3):
        raise SearchConfigError(f"{why if served is not None else f'{n} units are too few for a chain table'}: "
                                "over a unit library of several types the FE exhaustive search is not available "
                                "(it lists one type's designs); use --search ga")
    if not mixed and (served is not None or n < 2 * MAX_WINDOW + 1):
        return SearchPlan("exhaustive", note=exhaustive_note(n, fidelity, workers, why))
    if not build:
        raise MissingTableError(missing_table_message(config, model, table_dir, workers))
    return SearchPlan("certified", build=True,
                      note="certified search with a chain table built first (its plan follows)")


#: what the FE exhaustive search a short actuator is handed to does not do, per setting of the certified search it
#: has no use for: it solves every design, so no chain bound is left to widen or certify within, no prefix to keep
#: open, no batch to verify (``verify`` sets, with ``refine``, how many of its best designs the refinement solves
#: again) and no chain to rank the designs under the tolerance
EXHAUSTIVE_CANNOT = {"verify": "verifies no batches: it solves every design (beside a refinement, verify sets how "
                               "many of the best are solved again)",
                     "margin": "has no chain bound to widen", "epsilon": "has no chain bound to certify within",
                     "max_open": "keeps no open prefixes", "robust": "ranks no design by the chain under the tolerance"}


def check_handover(config: Any, plan: SearchPlan, keys: Sequence[str] | None = None,
                   named: Callable[[str], str] | None = None) -> None:
    """Refuse the settings of a certified run handed to the FE exhaustive search (a short actuator) that mean nothing
    there (:data:`EXHAUSTIVE_CANNOT`), before any solve.

    ``keys`` are the run's certified settings (default
    :meth:`~pneumorph.design.config.DesignConfig.certified_settings`); ``named`` says a key as the run was given it
    (default ``[design] key value``). ``certify`` (every design is solved: none can beat the winner), ``refine`` and
    ``chain_table`` (refused earlier where its window is too wide) pass, as ``verify`` does with ``refine``.

    Raises
    ------
    SearchConfigError
        One line naming the settings and what the exhaustive search does not do.

    Examples
    --------
    >>> from pneumorph.design.config import DesignConfig
    >>> plan = SearchPlan("exhaustive", note="FE exhaustive search over all 8 designs instead of the certified "
    ...                   "search: the reason; 5 FE solves")
    >>> check_handover(DesignConfig(units=3, margin=2.0), plan)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchConfigError: [design] margin 2: FE exhaustive search over all 8 designs instead of the
    certified search, which has no chain bound to widen; leave it out
    >>> check_handover(DesignConfig(units=3, verify=4, refine=1.0), plan)  # refines the best 4
    """
    given = config.certified_settings() if keys is None else keys
    unused = [k for k in given if k in EXHAUSTIVE_CANNOT and not (k == "verify" and config.refine)]
    if plan.search != "exhaustive" or not unused:
        return
    say = named or (lambda key: f"[design] {key}{config.value_text(key)}")
    raise SearchConfigError(f"{', '.join(say(k) for k in unused)}: {plan.note.split(':')[0]}, which "
                            f"{' and '.join(EXHAUSTIVE_CANNOT[k] for k in unused)}; leave "
                            f"{'it' if len(unused) == 1 else 'them'} out")


def missing_table_message(config: Any, model: Any, table_dir: str | Path | None, workers: int = 1) -> str:
    """The one line of a run that needs a chain table and may not build it: which table, how to build it.

    >>> from pneumorph.design.config import DesignConfig
    >>> from pneumorph.models.factory import make_model
    >>> config = DesignConfig(units=10, model={"fidelity": "3d", "pressure_kpa": 3})
    >>> print(missing_table_message(config, make_model(10, config.model), "tables"))
    ... # doctest: +ELLIPSIS +NORMALIZE_WHITESPACE
    --no-build: no chain table serves the 3d model (the built-in unit, 0.3-3 kPa in 10 levels; source ...): none
    is shipped or kept in tables (the shipped table's levels start at 4.5 kPa); build it with `pneumorph chain
    build --model 3d --pressure 3 --out tables/chain-3d-....json` (22-68 FE solves, estimated ...), or run without
    --no-build
    """
    training = model.with_units(TRAINING_UNITS) if callable(getattr(model, "with_units", None)) else model
    plan = build_plan(training, workers=workers, **build_options(training))
    p = model.pressures() * 1e3
    fidelity = str(getattr(model, "fidelity", "?"))
    where = f"kept in {table_dir}" if table_dir is not None else "kept (the evaluation cache is in memory)"
    shipped = shipped_for(model)
    reach = ""
    if shipped.is_file():
        table = ChainTable.load(shipped)
        if same_source(table, model):
            first, top = (float(table.pressures[i]) * 1e3 for i in (0, -1))
            reach = (f" (the shipped table's levels start at {first:.4g} kPa)" if p[-1] < first else
                     f" (the shipped table reaches {top:.4g} kPa)")
    target = table_file(table_dir, model) if table_dir is not None else Path(f"chain-{fidelity}.json")
    command = build_command(config.model, target)
    how = (f"build it with `{command}` ({plan.cost_text().split(' (about')[0]}), or run without --no-build"
           if command is not None else
           f"run without --no-build to build it ({plan.cost_text().split(' (about')[0]}; `pneumorph chain build` "
           "takes this model's other [model] settings only through the API, build_table)")
    return (f"--no-build: no chain table serves the {fidelity} model ({plan.unit}, {p[0]:.4g}-{p[-1]:.4g} kPa in "
            f"{len(p)} levels; source {source_key(model)}): none is shipped or {where}{reach}; {how}")


def build_command(settings: dict[str, Any], out: Path) -> str | None:
    """The ``pneumorph chain build`` command of a model's table, from the run's ``[model]`` settings; None if
    a setting has no option there (an inline unit, increments, a temperature change, ...).

    >>> build_command({"fidelity": "3d", "pressure_kpa": 25.0}, Path("t/chain.json"))
    'pneumorph chain build --model 3d --pressure 25 --out t/chain.json'
    >>> build_command({"fidelity": "3d", "quadrature": "reduced"}, Path("t.json"))
    'pneumorph chain build --model 3d --quadrature reduced --out t.json'
    >>> build_command({"fidelity": "2d", "increments": 20}, Path("t.json")) is None
    True
    """
    if set(settings) - set(_BUILD_OPTIONS):
        return None
    words = ["pneumorph", "chain", "build"]
    for key, option in _BUILD_OPTIONS.items():
        if key in settings:
            value = settings[key]
            words += [option, f"{value:g}" if isinstance(value, float) else str(value)]
    words += ["--out", str(out)]
    return " ".join(shlex.quote(w) for w in words)
