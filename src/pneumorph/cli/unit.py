"""``pneumorph unit optimise``: the unit geometry optimisation of section 8.3.2 (docs/unit-library.md)."""

from __future__ import annotations

import sys
import time
from typing import Any

import click

from pneumorph.checks import MAX_GENERATIONS, MAX_POPULATION, MAX_UNITS
from pneumorph.cli.options import params as P
from pneumorph.cli.options.execution import (
    check_options,
    cluster_line,
    cluster_report,
    execution_options,
    open_evaluator,
)
from pneumorph.cli.progress import plan_solves, reporter


@click.group("unit")
def unit() -> None:
    """The articulating unit: geometry optimisation (documentation page unit-library, docs/unit-library.md in the
    source)."""


@unit.command("optimise")
@click.option("--var", "variables", multiple=True, metavar="NAME=LOW:HIGH", type=P.Text(max_length=200),
              help="A varied dimension and its bounds, mm (repeatable; default cavity_height=3:9, end_wall=1.5:4, "
                   "wall=1:2.5, layer=1.5:4.5). Names: cavity_height, end_wall, wall, layer, side_wall, pitch.")
@click.option("--strain-limit", type=P.Real(0.0, 1e3, low_open=True), default=4.4, show_default=True,
              help="Largest principal nominal strain allowed in the body (Mold Star 15: 440 % at break, Smooth-On).")
@click.option("--pressure", type=P.PRESSURE_KPA, default=45.0, show_default=True, help="Design pressure, kPa.")
@click.option("--units", "n_units", type=P.Count(3, MAX_UNITS, limit="MAX_UNITS"), default=3, show_default=True,
              help="Units of the 3D probe actuator (Omega is its middle unit's turn).")
@click.option("--pop", "pop_size", type=P.Count(4, MAX_POPULATION, limit="MAX_POPULATION"), default=16,
              show_default=True, help="NSGA-II population.")
@click.option("--gen", "generations", type=P.Count(1, MAX_GENERATIONS, limit="MAX_GENERATIONS"), default=8,
              show_default=True, help="NSGA-II generations after the initial population.")
@click.option("--seed", type=P.SEED, default=0, show_default=True, help="Seed of the start and of NSGA-II.")
@click.option("--resolution", type=P.Real(0.0, 10.0, unit="mm"), default=0.1, show_default=True,
              help="Dimensions are rounded to this, mm (0: not rounded).")
@click.option("--element-size", type=P.POSITIVE_MM, help="Element size of the candidates' mesh, mm (default: "
              "the base unit's, 1.5).")
@click.option("--unit", "unit_file", type=P.InputFile(), help="Base unit TOML file (default: the built-in unit).")
@execution_options(what="candidates")
@click.option("--cache", metavar="FILE", type=P.CacheFile(),
              help="Evaluation cache (default ~/.cache/pneumorph/evaluations.sqlite): a rerun resumes.")
@click.option("--out", required=True, type=P.OutputDir(),
              help="Folder for candidates.csv, pareto.csv/.json, front.png and units/*.toml.")
@click.option("--overwrite", is_flag=True,
              help="Write into a folder that holds another run (a unit optimisation's files are replaced).")
@click.option("--json", "as_json", is_flag=True, help="Print the front as JSON.")
def optimise(variables: tuple[str, ...], strain_limit: float, pressure: float, n_units: int, pop_size: int,
             generations: int, seed: int, resolution: float, element_size: float | None, unit_file: str | None,
             executor: str, workers: int | None, scheduler: str | None, cache: str | None, out: str,
             overwrite: bool, as_json: bool) -> None:
    """Maximise the bending angle per unit (Omega) and minimise the ballooning height (h_b) within a
    strain limit (Ellis 2020, 8.3.2), NSGA-II on a 3-unit 3D actuator; resumable through the cache."""
    from pneumorph.io.files import all_or_nothing
    from pneumorph.io.lock import RunLock
    from pneumorph.unitopt.run import OptimiseSettings, check_folder, optimise, write_outputs

    check_options(executor, workers, scheduler)
    space = _check_space(variables, resolution, element_size, unit_file, strain_limit, n_units, executor, workers)
    settings = OptimiseSettings(space=space, strain_limit=strain_limit, pressure=pressure / 1e3, n_units=n_units,
                                pop_size=pop_size, generations=generations, seed=seed)
    check_folder(out, settings, overwrite)
    evaluator = open_evaluator(executor, workers, scheduler, cache)
    t0 = time.perf_counter()
    # stopped before its files are whole: nothing left
    with reporter() as lines, all_or_nothing(out) as folder, RunLock(folder):
        lines.say(f"unit optimisation: {', '.join(f'{v.name} {v.low:g}-{v.high:g}' for v in space.variables)} mm; "
                  f"strain limit {strain_limit:g}; {pressure:g} kPa; {n_units}-unit 3D probe; NSGA-II {pop_size} x "
                  f"{generations} generations, seed {seed}")
        # the base unit and each generation's candidates, at most (duplicates and cached ones are not solved)
        plan_solves(lines, "unit optimisation", 1 + pop_size * (generations + 1), _probe(settings), executor, workers,
                    out, title="unit optimisation, at most")
        try:
            result = optimise(settings, evaluator, _on_candidate(lines),
                              lambda g, front: lines.say(f"  generation {g}: front of {len(front)}"))
        finally:
            evaluator.close()
        if (line := cluster_line(evaluator)) is not None:
            lines.say(line)
        lines.say(f"writing the candidates, the front, its figure and the chosen units to {folder}")
        write_outputs(result, out, command=" ".join(sys.argv), wall_time_s=time.perf_counter() - t0)
    _check_front(result, strain_limit, out)
    if as_json:
        _print_json(result, strain_limit, evaluator)
    else:
        _print_front(result, space.names, out, t0)


def _check_space(variables: tuple[str, ...], resolution: float, element_size: float | None, unit_file: str | None,
                 strain_limit: float, n_units: int, executor: str, workers: int | None) -> Any:
    """The design space of the options (the base unit, its element size, the ``--var`` ranges), checked with the
    optimisation's settings (:func:`pneumorph.unitopt.run.check_settings`) before anything is written.

    The messages name what to change (the unit, a range, the resolution, the units, the memory per worker); a
    corner of a box the user gave (``--var``) that makes no unit is a bad ``--var``.
    """
    from dataclasses import replace
    from types import SimpleNamespace

    from pneumorph.design.certified.planning import planned_workers
    from pneumorph.errors import GeometryError
    from pneumorph.geometry.limits import MeshLimitError
    from pneumorph.geometry.unit import UnitSpec
    from pneumorph.unitopt.run import check_settings
    from pneumorph.unitopt.space import DesignSpace, parse_variable

    with P.blame("--unit"):
        base = UnitSpec.from_toml(unit_file) if unit_file else UnitSpec()
    base = replace(base, name="unitopt")
    if element_size is not None:
        with P.blame("--element-size"):
            base = replace(base, element_size=element_size)
    with P.blame("--var"):
        space = (DesignSpace(tuple(parse_variable(v) for v in variables), base, resolution) if variables
                 else replace(DesignSpace.default(base), resolution=resolution))
    parallel = planned_workers(SimpleNamespace(executor=executor, workers=workers))
    try:
        check_settings(space, strain_limit, n_units, parallel=parallel)
    except GeometryError as exc:
        if isinstance(exc, MeshLimitError) or not variables:
            raise
        raise click.BadParameter(" ".join(str(exc).split()), param_hint="'--var'") from None
    return space


def _check_front(result: Any, strain_limit: float, out: str) -> None:
    """Refuse (exit 2) an optimisation without a feasible candidate: every one failed to converge or strained past
    the limit; its candidates stay in the folder, and the line says what to change."""
    from pneumorph.errors import SettingsError

    if result.front:
        return
    failed = sum(1 for c in result.candidates if c.measures is None)
    strained = len(result.candidates) - failed
    raise SettingsError(f"no feasible unit: of {len(result.candidates)} candidates {failed} failed to converge and "
                        f"{strained} strained past --strain-limit {strain_limit:g} ({out}/candidates.csv lists them); "
                        "change the bounds (--var), raise --strain-limit or lower --pressure")


def _probe(settings: Any) -> Any:
    """What the solve time of a candidate is estimated by: a 3D model of the probe's units."""
    from types import SimpleNamespace

    return SimpleNamespace(fidelity="3d", n_units=settings.n_units)


def _on_candidate(lines: Any) -> Any:
    """Each candidate counted (with the time left at the measured rate), its measures said, on standard error."""
    count = {"n": 0}

    def on_candidate(c: Any) -> None:
        count["n"] += 1
        dims = ", ".join(f"{v:g}" for v in c.values.values())
        if c.measures is None:
            state = f"failed at {c.reached * 1e3:.1f} kPa: {c.failure}"
        else:
            m = c.measures
            state = (f"Omega {m.omega_deg:.2f} deg, h_b {m.balloon_mm:.2f} mm, strain {m.strain:.2f}"
                     + (" (cached)" if c.cached else ""))
        lines.count(count["n"], f"({dims}): {state}", always=True)  # each a 3D solve: every one said

    return on_candidate


def _print_json(result: Any, strain_limit: float, evaluator: Any) -> None:
    """The front, the base unit and the units better than it (and the cluster's report) as JSON."""
    from pneumorph.io import strict_json

    cluster = cluster_report(evaluator)
    click.echo(strict_json({"front": [c.row(strain_limit) for c in result.front],
                            "base": result.base.row(strain_limit),
                            "better_than_base": [c.row(strain_limit) for c in result.better()],
                            **({"cluster": cluster} if cluster else {})}))


def _print_front(result: Any, names: Any, out: str, t0: float) -> None:
    """The front as a table (the base unit first), the best unit better than the base, the counts."""
    from pathlib import Path

    click.echo(" ".join(f"{n:>13}" for n in names) + f" {'Omega [deg]':>11} {'h_b [mm]':>8} {'strain':>7}")
    for c, mark in listed(result, names):
        m = c.measures
        tail = "failed" if m is None else f"{m.omega_deg:11.2f} {m.balloon_mm:8.2f} {m.strain:7.2f}"
        click.echo(" ".join(f"{c.values[n]:13.2f}" for n in names) + f" {tail}{mark}")
    better = result.better()
    if better:
        m = better[0].measures
        assert m is not None
        click.echo(f"{len(better)} unit(s) bend more than the base unit at the same or a lower h_b; best: Omega "
                   f"{m.omega_deg:.2f} deg, h_b {m.balloon_mm:.2f} mm")
    else:
        click.echo("no unit bends more than the base unit at the same or a lower h_b within the strain limit")
    click.echo(f"{len(result.candidates)} candidates ({result.solves} solved, {result.hits} from the cache) in "
               f"{time.perf_counter() - t0:.0f} s; written to {Path(out)}/")


def listed(result: Any, names: Any) -> list[tuple[Any, str]]:
    """The rows of the printed front: the base unit first (once, also when it is on the front), then the front.

    >>> from types import SimpleNamespace as S
    >>> base = S(values={"wall": 1.5})
    >>> r = S(base=base, front=[S(values={"wall": 1.5}), S(values={"wall": 2.0})])
    >>> [(c.values["wall"], mark) for c, mark in listed(r, ["wall"])]
    [(1.5, '  <- base unit (on the front)'), (2.0, '')]
    """
    def key(c: Any) -> dict[str, float]:
        return {n: round(float(c.values[n]), 9) for n in names}

    front = [c for c in result.front if key(c) != key(result.base)]
    on_front = len(front) < len(result.front)
    return [(result.base, "  <- base unit" + (" (on the front)" if on_front else "")), *[(c, "") for c in front]]
