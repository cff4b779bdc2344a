"""``pneumorph design``: the main job - the actuator whose inflated shape best meets a goal."""

from __future__ import annotations

import sys
from types import SimpleNamespace
from typing import Any

import click

from pneumorph.checks import MAX_GENERATIONS, MAX_POPULATION
from pneumorph.cli.options import params as P
from pneumorph.cli.options import targets as T
from pneumorph.cli.options.execution import check_options, execution_options
from pneumorph.cli.progress import RunLines, reporter

# the options that are [design] and [execution] settings of the same name
_DESIGN_OPTIONS = ("amplitude", "periods", "point", "units", "search", "seed", "certify", "verify", "margin",
                   "epsilon", "max_open", "refine", "chain_table", "tolerance", "robust", "robust_samples", "executor",
                   "workers", "scheduler", "cache")
_TIP_GOALS = ("max-x", "min-x", "max-y", "min-y", "min-distance", "max-curl", "reach", "grip", "wrap")


def _kpa(pressure: float | None) -> float:
    return float("nan") if pressure is None else pressure * 1e3


@click.command("design")
@click.argument("config_file", required=False, type=P.InputFile())
@click.option("--target", metavar="TARGET", type=P.Text(),
              help="Profile to match: 'sin', 'cos', 'y = <expr in x, L, A>' or 'r = <expr in theta>'; a path of any "
                   "shape: 'path:FILE' (CSV/TXT of x, y[, z] mm, from the base to the free end) or a preset "
                   "(letter-l, letter-s, letter-r, hook, spiral, coil). "
                   "Default (no config file): sin, amplitude 10 mm, one period.")
@click.option("--objective", type=click.Choice(_TIP_GOALS),
              help="A tip goal instead of a profile (Table 6.1), or over the model's obstacles (--model-file with "
                   "[[model.obstacle]]): grip (the force on them, N) or wrap (the contact length or area).")
@click.option("--amplitude", type=P.POSITIVE_MM, help="Amplitude A of the sin/cos target, mm (default 10).")
@click.option("--periods", type=P.Real(0.0, 1000.0, low_open=True),
              help="Periods of the sin/cos target over the actuator (default 1).")
@click.option("--point", type=P.Real(-1e5, 1e5, unit="mm"), nargs=2, metavar="X Y",
              help="Tip point (mm) for --objective reach.")
@click.option("--stage", "stages", metavar="KPA:TARGET", type=P.Text(), multiple=True,
              help="A target at one pressure of the ramp (repeat for several): 'KPA:sin', 'KPA:y = <expr>', or "
                   "'KPA:reach X Y' (a tip point, mm; X Y Z off the plane); --amplitude and --periods shape the "
                   "presets. The cost is the root-sum-square of the stages (weights: [[design.stage]] in a config "
                   "file).")
@click.option("--clear", metavar="KPA[:MM]", type=P.Text(),
              help="With --objective grip or wrap: keep MM mm (default 0) from every obstacle at the pressure KPA, a "
                   "level of the ramp below its top, and grip above it; the chain rejects the designs that cannot "
                   "([design.clear] in a config file; documentation page grasping, docs/grasping.md in the source).")
@click.option("--units", type=P.UNITS, help="Number of articulating units (default 15).")
@click.option("--pop", "population", type=P.Count(2, MAX_POPULATION, limit="MAX_POPULATION"),
              help="GA population (default 100; also the GA a certified search falls back to).")
@click.option("--gen", "generations", type=P.Count(0, MAX_GENERATIONS, limit="MAX_GENERATIONS"),
              help="GA generations (default 15).")
@click.option("--seed", type=P.SEED, help="Random seed (default 0): the same seed gives the same run.")
@click.option("--search", type=click.Choice(["certified", "ga", "exhaustive"]),
              help="certified (default): every design scored by the chain model, the best verified by FE; "
                   "ga: genetic algorithm; exhaustive: all 2^n designs by FE.")
@click.option("--certify", is_flag=True, default=None,
              help="Certified search: verify by FE until no design can beat the winner.")
@click.option("--verify", type=P.Count(1, 1024),
              help="Certified search: designs verified by FE per batch (default: one per worker); on an actuator "
                   "handed to the FE exhaustive search, the best designs --refine solves again.")
@click.option("--margin", type=P.Real(0.0, 1e3, low_open=True),
              help="Certified search: factor on the chain's validated errors in the bound (default 1).")
@click.option("--epsilon", type=P.Real(0.0, 1e3),
              help="Certified search: certify within this much (the objective's units): designs that could beat the "
                   "winner by less are counted as ties, not verified (default 0).")
@click.option("--max-open", type=P.Count(1, 10**9),
              help="Certified search: open prefixes its branch-and-bound keeps at most, the best where more stay open"
                   " (default 500,000, fewer past 4 GB; 20,000 for a table beyond its tolerance).")
@click.option("--refine", metavar="MM", type=P.Real(0.0, 100.0, low_open=True, unit="mm"),
              help="Certified search: solve the FE-verified designs again with this element size (e.g. 1.0 or 0.75; "
                   "the default mesh is 1.5 mm), report both meshes' values, the estimated mesh error and whether "
                   "the winner holds (documentation page mesh-convergence, docs/mesh-convergence.md in the source).")
@click.option("--chain-table", metavar="FILE", type=P.InputFile(),
              help="Certified search: a chain table file (default: the shipped one, or built on first use).")
@click.option("--tolerance", type=P.Real(0.0, 1.0, unit="mm"),
              help="Mould tolerance of the winner's robustness report, +- mm on the side walls, the Mold Star wall and "
                   "the Smooth-Sil layer (default 0.1: FDM-printed moulds; 0: no report).")
@click.option("--robust", type=click.Choice(["worst", "mean"]),
              help="Certified search: rank every design by its worst or mean error under the tolerance (chain model "
                   "with tolerance tables) and verify the most robust by FE.")
@click.option("--robust-samples", type=P.Count(1, 10_000),
              help="Seeded samples of the tolerance class (default 30 by the chain model, 8 FE solves otherwise).")
@execution_options(default=None, what="designs (and the tables a run builds)")
@click.option("--model", "fidelity", type=click.Choice(["2d", "3d"]),
              help="Model fidelity (default: 3d for the certified search, 2d for ga and exhaustive).")
@click.option("--pressure", type=P.PRESSURE_KPA, help="Maximum pressure, kPa (default 45).")
@click.option("--unit", "unit_file", type=P.InputFile(), help="Unit TOML file.")
@click.option("--model-file", type=P.InputFile(),
              help="A model's [model] table (an identified model, identified.toml from pneumorph identify): its "
                   "unit and material scales; --model, --pressure, --unit and --library still apply.")
@click.option("--library", metavar="builtin|spatial|modes|FILE", type=P.Text(),
              help="Designs over a unit library ('builtin', 'spatial' (sideways units that bend out of the plane: "
                   "a chain in space, 3D only), 'modes' (bimodal and low-bending units) or a library TOML file; "
                   "documentation "
                   "page unit-library, docs/unit-library.md in the source): certified search over every type and "
                   "orientation per unit; instead of --unit.")
@click.option("--cache", metavar="FILE", type=P.CacheFile(),
              help="Evaluation cache (SQLite); default ~/.cache/pneumorph/evaluations.sqlite.")
@click.option("--out", metavar="DIR", type=P.OutputDir(),
              help="Run folder (default runs/<target>-<units>u-<search>-<model>-<key>, the key a digest of every "
                   "setting that changes the answer: the same command again resumes its own run).")
@click.option("--overwrite", is_flag=True, help="Start afresh in a folder that holds another run.")
@click.option("--no-build", "no_build", is_flag=True,
              help="Certified search: stop with a message instead of building a chain table (or tolerance tables) "
                   "that no shipped or kept table serves, or instead of falling back to the genetic algorithm on "
                   "the FE model when the chain cannot represent it.")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
def design(config_file: str | None, **options: Any) -> None:
    """Design the actuator whose inflated shape best matches a target or tip goal.

    Without options: a 15-unit actuator for the target "sin, amplitude 10 mm, one period":
    all 32,768 designs scored by the chain model of the 3D model (shipped table), the best
    verified by a 3D FE solve, with a certificate of how much better at most any other
    design could be. Running the same command again answers from the evaluation cache.
    """
    o = SimpleNamespace(**options)
    _check_inputs(o)
    config, fallback, fidelity_given, nominal = _config(config_file, o)
    model = config.make_model()
    _check_run(config, model, o)
    o.reference = nominal.make_model() if nominal is not None and config.search == "certified" else None
    if fallback:  # said once every setting has been checked
        click.echo(f"{fallback}: falling back to the genetic algorithm", err=True)
    if o.model_file is not None:
        _warn_unidentified(o.model_file)
    result, model = _run(config, model, o, fidelity_given)
    if result.rejected:
        click.echo(f"  {result.rejected} cache entries failed their checksum: solved again, not used", err=True)
    if o.as_json:
        from pneumorph.io.files import strict_json

        click.echo(strict_json(result.summary()))
    elif result.best is not None:
        _print_result(result, config, model)
    if result.status == "interrupted":
        click.echo(f"interrupted; run the same command again to resume from {result.folder}", err=True)
        sys.exit(130)


def _check_inputs(o: Any) -> None:
    """The target, unit file and library checked as the options that gave them (before any setting is merged); the
    config's changes for the target kept as ``o.target_changes``."""
    from pneumorph.design import DesignConfig
    from pneumorph.errors import SearchConfigError

    if o.target and o.objective:
        raise SearchConfigError("give either --target (a profile) or --objective (a tip goal), not both")
    o.target_changes = None
    if o.target is not None:
        from pneumorph.design.objectives.targets import make_objective
        from pneumorph.geometry.unit import UnitSpec

        with P.blame("--target"):  # along the built-in unit; checked again along the model's
            o.target_changes = target = T.target_changes(o.target)  # a path file read once, here
            make_objective(target["objective"], o.amplitude if o.amplitude is not None else DesignConfig.amplitude,
                           o.periods if o.periods is not None else DesignConfig.periods,
                           length=(o.units or DesignConfig.units) * UnitSpec.pitch, path=target.get("path"))
    if o.unit_file is not None:
        P.unit_option(o.unit_file)
    if o.library is not None:
        P.library_option(o.library, o.unit_file)


def _config(config_file: str | None, o: Any) -> tuple[Any, str | None, bool, Any]:
    """The run's settings: the config file's (or the defaults) with the options over them
    (:meth:`DesignConfig.with_options`), the fidelity of its search written in; why the certified search fell
    back to the GA (:meth:`DesignConfig.searchable`), or None; whether the fidelity was given; with
    ``--model-file``, the same settings without it (the nominal model, whose design the report compares)."""
    from pneumorph.design import DesignConfig

    config = DesignConfig.read(config_file) if config_file else DesignConfig()
    check_options(o.executor or config.executor, config.workers if o.workers is None else o.workers,
                  o.scheduler or config.scheduler)
    units = o.units or config.units
    if o.periods is not None and o.periods > max(1.0, units / 2):  # named as typed; the config refuses it too
        raise click.UsageError(f"--periods {o.periods:g}: a sin or cos target over {units} unit centres shows at most "
                               f"{max(1.0, units / 2):g} periods (Eq 4.1 samples it at the centres); give fewer "
                               "periods or more units")
    design = {key: getattr(o, key) for key in _DESIGN_OPTIONS}
    design["objective"] = o.target or o.objective
    if o.target_changes is not None:
        target = o.target_changes
        design.update(target)
        if config.curve is not None or config.path is not None:  # the config's points belong to its own target
            data = config.to_dict()
            for key in ("curve", "path"):
                data["design"].pop(key, None)
            data["design"].update(target)
            config = DesignConfig.from_dict(data)
    design.update(T.stage_changes(o.stages, bool(o.target or o.objective or o.point), o.amplitude, o.periods,
                                  o.units))
    if o.clear is not None:
        design["clear"] = T.clear_option(o.clear, design["objective"] or config.objective)
    identified = None
    if o.model_file is not None:  # the identified model's settings over the config's
        from pneumorph.models.factory import read_model_file

        with P.blame("--model-file"):
            identified = read_model_file(o.model_file)
    # --pop/--gen also set the genetic algorithm a certified search falls back to; certified options alone
    _check_options_apply(o.search or config.search, "certified",
                         {"--certify": o.certify, "--verify": o.verify, "--margin": o.margin, "--epsilon": o.epsilon,
                          "--max-open": o.max_open, "--refine": o.refine, "--chain-table": o.chain_table,
                          "--no-build": o.no_build or None})
    options = {"fidelity": o.fidelity, "pressure_kpa": o.pressure, "unit_file": o.unit_file, "library": o.library}
    ga = {"population": o.population, "generations": o.generations}
    nominal = None if identified is None else config.with_options(design, ga=ga, model=options)
    config = config.with_options(design, ga=ga, model=options, model_file=identified)
    fidelity_given = "fidelity" in config.model
    config, fallback = _searchable(config, o)
    if nominal is not None:  # the nominal model at the fidelity and pressure of the run's
        nominal = nominal.with_options({}, model={"fidelity": config.fidelity,
                                                  "pressure_kpa": config.model.get("pressure_kpa")})
    return config.with_options({}, model=config.model_settings()), fallback, fidelity_given, nominal


def _searchable(config: Any, o: Any) -> tuple[Any, str | None]:
    """:meth:`DesignConfig.searchable`, refusing a fall-back to the genetic algorithm that would drop what the run
    was given (:func:`_check_fallback`), before any solve."""
    searched, why = config.searchable()
    if why is not None:
        _check_fallback(config, o, why)
    return searched, why


def _check_fallback(config: Any, o: Any, why: str) -> None:
    """Refuse the fall-back to the genetic algorithm of a certified run that cannot search (``why``) where the run
    was given what the GA cannot honour: ``--no-build`` (stop instead of falling back), ``--search certified``
    typed, or a setting only the certified search reads (:meth:`DesignConfig.certified_settings`, or its option
    typed at its default), in one line naming them as given. Options and settings at their defaults, not given, are
    not refused."""
    from pneumorph.design.config import GA_CANNOT
    from pneumorph.errors import MissingTableError, SearchConfigError

    if o.no_build:  # the fall-back is the GA on the FE model: hundreds of solves, more than any table build
        raise MissingTableError(f"--no-build: {why}; the fall-back to the genetic algorithm on the FE model is not "
                                "started (run without --no-build to start it)")
    given = _given_keys(config, o)
    named = [_as_given(key, o, config) for key in given]
    cannot = [GA_CANNOT[key] for key in given]
    if o.search == "certified":
        named, cannot = ["--search certified", *named], ["is not the certified search", *cannot]
    if named:
        raise SearchConfigError(f"{', '.join(named)}: {why}; the fall-back to the genetic algorithm "
                                f"{' and '.join(cannot)}, and is not started (run without "
                                f"{'it' if len(named) == 1 else 'them'} to start it)")


def _as_given(key: str, o: Any, config: Any) -> str:
    """A setting as the run was given it, with its value: the option typed (``--refine 0.75``, ``--certify``), else
    the config file's key (``[design] refine 0.75``)."""
    return (f"--{key.replace('_', '-')}" if getattr(o, key) is not None else f"[design] {key}") + config.value_text(key)


def _given_keys(config: Any, o: Any) -> list[str]:
    """The settings only the certified search reads that the run gave: away from their defaults
    (:meth:`DesignConfig.certified_settings`) or typed as options, even at their defaults."""
    from pneumorph.design.config import CERTIFIED_ONLY

    away = config.certified_settings()
    return [key for key in CERTIFIED_ONLY if getattr(o, key) is not None or key in away]


def _warn_unidentified(path: str) -> None:
    """Say which parameters an identified model's scans left undetermined: its design is only as good as the fit
    (docs/notes/identification.md: a redesign on a model whose bulk modulus the scans left confounded is worse on
    the truth)."""
    from pneumorph.identify import NAMES
    from pneumorph.io.files import read_toml

    provenance = read_toml(path, "model file").get("provenance", {})
    identified = provenance.get("identified") if isinstance(provenance, dict) else None
    if not isinstance(identified, list):
        return  # not a file of pneumorph identify
    left = [n for n in NAMES if n not in identified]
    if left:
        click.echo(f"warning: the scans behind {path} did not identify {', '.join(left)} (fixed at nominal or "
                   "confounded): a design for this model, and its comparison with the nominal design, are only as "
                   "good as that fit; scans of designs that bend differently, or at a second pressure, tell them "
                   "apart", err=True)


def _check_run(config: Any, model: Any, o: Any) -> None:
    """What the settings cannot do with this model, refused naming the options, before any solve."""
    mixed = bool(getattr(model, "mixed", False))
    if mixed:
        _check_library_run(config, model, o.tolerance)
    made = config.make_objective(length=model.n_units * model.unit.pitch)  # finite along this model's actuator
    _check_shape_options(made, o.amplitude, o.periods)
    if config.tolerance > 0 and not mixed:  # the robustness report's mould tolerance
        from pneumorph.sensitivity.tolerances import Tolerance

        with P.blame("--tolerance" if o.tolerance is not None else "[design] tolerance"):
            Tolerance(config.tolerance).check(model.unit)
    if o.robust_samples is not None and config.tolerance == 0:
        raise click.UsageError("--robust-samples sets the samples of the mould tolerance report, which --tolerance 0 "
                               "turns off; leave one of them out")
    if config.search == "certified":  # refused here, naming the option; the run checks again
        from pneumorph.design.algorithms.certified import max_open
        from pneumorph.design.certified.refine import check_refine

        if config.refine:
            with P.blame("--refine" if o.refine is not None else "[design] refine"):
                check_refine(model, config.refine)
        with P.blame("--max-open" if o.max_open is not None else "[design] max_open"):
            max_open(config, model)  # the memory of the open prefixes it may keep
        _check_handover(config, model, o)


def _check_handover(config: Any, model: Any, o: Any) -> None:
    """Refuse, naming them as given, the certified settings that mean nothing to the FE exhaustive search a short
    actuator is handed to (:func:`~pneumorph.design.certified.planning.check_handover`; the run checks again): its
    plan is asked only where the run gives such a setting."""
    from pneumorph.design.certified.planning import EXHAUSTIVE_CANNOT, check_handover, plan_search, planned_workers
    from pneumorph.execution.cache import chain_table_dir

    keys = _given_keys(config, o)
    if any(key in EXHAUSTIVE_CANNOT for key in keys):
        plan = plan_search(config, model, chain_table_dir(config.cache), build=not o.no_build,
                           workers=planned_workers(config))
        check_handover(config, plan, keys, named=lambda key: _as_given(key, o, config))


def _run(config: Any, model: Any, o: Any, fidelity_given: bool) -> tuple[Any, Any]:
    """The run and its model; a certified run the chain cannot represent (nothing written) falls back to the GA
    (on the 2D model unless the fidelity was given). Its lines go through one reporter, whose heartbeat speaks in
    any silence (a long FE verification, a table build, the figures)."""
    with reporter() as lines:
        return _run_with(config, model, o, fidelity_given, lines)


def _run_with(config: Any, model: Any, o: Any, fidelity_given: bool, lines: Any) -> tuple[Any, Any]:
    from pneumorph.design import run_design
    from pneumorph.design.runs.folder import default_folder
    from pneumorph.errors import LocalityError

    progress = RunLines(config, model, o.out or default_folder(config), lines)
    try:
        result = run_design(config, model, progress.folder, overwrite=o.overwrite, build=not o.no_build,
                            reference=o.reference, **progress.callbacks())
        progress.announce()
        return result, model
    except LocalityError as exc:
        if config.search != "certified":
            raise
        _check_fallback(config, o, str(exc))  # after the chain table's solves, which stay in the evaluation cache
        click.echo(f"{exc}; falling back to the genetic algorithm", err=True)
    config = config.fallback(fidelity_given)
    model = config.make_model()
    progress = RunLines(config, model, o.out or default_folder(config), lines)  # the new run's own first line
    result = run_design(config, model, progress.folder, overwrite=o.overwrite, **progress.callbacks())
    progress.announce()
    return result, model


def _print_result(result: Any, config: Any, model: Any) -> None:
    """The winner, its certificate, mesh note, robustness and retries, in words."""
    from pneumorph.design.runs.report import value_words

    best = result.best
    words = value_words(result.objective, best.value, config.units)
    click.echo(f"best design {best.design} at {_kpa(best.pressure):.4g} kPa: {words} "
               f"({result.solves} solves, {result.cache_hits} cache hits, {result.wall_time:.1f} s)")
    if result.certified is not None:
        from pneumorph.design.certified.certificate import certificate_text

        for line in certificate_text(result.certified.certificate, result.objective.unit, best.design, model.fidelity):
            click.echo(f"  {line}")
        two_d = result.opinion_2d.get(best.design)
        if two_d is not None:
            click.echo(f"  The 2D model's chain value of {best.design}: {two_d:.4g} {result.objective.unit}.")
    _print_mesh(result)
    from pneumorph.design.runs.comparison import comparison_lines

    for line in comparison_lines(result.comparison):
        click.echo(f"  {line}")
    rob = result.robustness
    if rob is not None and "mean" in rob["winner"]:
        w, u = rob["winner"], result.objective.unit
        click.echo(f"  under +-{rob['tolerance_mm']:g} mm mould tolerances ({rob['samples']} samples, "
                   f"{rob['method'].split(',')[0]}): {w['design']} mean {w['mean']:.4g} {u}, 95th percentile "
                   f"{w['p95']:.4g} {u}, worst {w['worst']:.4g} {u}")
    if result.retried:
        click.echo(f"  {result.retried} design(s) retried on other Dask workers after lost workers")
    click.echo(f"report: {result.folder / 'report.md'}")


def _print_mesh(result: Any) -> None:
    """What the mesh study or the refinement says of the winner."""
    best, ref = result.best, result.refinement
    if ref is not None and "study" in ref:
        note = ref["study"]
        click.echo(f"  mesh: the mesh study moved gaps between designs by at most {note['gap_change']:.3g} "
                   f"{result.objective.unit} from "
                   f"{note['sizes_mm'][0]:g} to {note['sizes_mm'][1]:g} mm elements; "
                   + (f"within it of the winner: {', '.join(note['within'])} (--refine checks them)"
                      if note["within"] else "no verified design lies within it of the winner"))
    elif ref is not None:
        mine = next(r for r in ref["rows"] if r["design"] == best.design)
        fine = "failed" if mine.get("refined") is None else f"{mine['refined']:.4g}"
        click.echo(f"  at {ref['element_size_mm'][1]:g} mm elements: {best.design} {best.value:.4g} -> {fine}; "
                   + ("the winner holds" if ref["holds"] else f"{ref['refined_best']} is better there")
                   + (f"; could still overtake it: {', '.join(ref['could_overtake'])}"
                      if ref["could_overtake"] else ""))


def _check_shape_options(objective: Any, amplitude: float | None, periods: float | None) -> None:
    """Refuse --amplitude and --periods where the objective would ignore them (one line, exit 2)."""
    from pneumorph.design.objectives.targets import PRESETS, PathTarget, ProfileTarget, StagedTarget

    if isinstance(objective, StagedTarget):
        profiles = [s.target for s in objective.stages if isinstance(s.target, ProfileTarget)]
        if amplitude is not None and not any("A" in getattr(t.expression, "used", ()) for t in profiles):
            raise click.UsageError("--amplitude sets A, which none of the stages' targets uses; leave it out")
        if periods is not None and not any(t.name in PRESETS for t in profiles):
            raise click.UsageError("--periods applies to the sin and cos presets, which none of the stages uses")
        return
    if isinstance(objective, ProfileTarget):
        uses_a = "A" in getattr(objective.expression, "used", ())
        if amplitude is not None and not uses_a:
            raise click.UsageError(f"--amplitude sets A, which the target {objective.label} does not use; leave "
                                   "it out or write A into the target")
        if periods is not None and objective.name not in PRESETS:
            raise click.UsageError(f"--periods applies to the sin and cos presets, not to the target "
                                   f"{objective.label}; write the periods into the expression")
        return
    given = [name for name, value in (("--amplitude", amplitude), ("--periods", periods)) if value is not None]
    if given:
        what = f"the path {objective.name}" if isinstance(objective, PathTarget) else f"the tip goal {objective.name}"
        raise click.UsageError(f"{'/'.join(given)} shape{'s' if len(given) == 1 else ''} a profile target, not "
                               f"{what}; leave {'/'.join(given)} out")


def _check_options_apply(search: str, owner: str, options: dict) -> None:
    """Refuse options of another search than the one that runs, instead of ignoring them."""
    given = [name for name, value in options.items() if value is not None]
    if given and search != owner:
        raise click.UsageError(f"{'/'.join(given)} only appl{'y' if len(given) > 1 else 'ies'} to --search {owner}, "
                               f"but this run's search is {search}; add --search {owner} or leave "
                               f"{'/'.join(given)} out")


def _check_library_run(config: Any, model: Any, tolerance: float | None) -> None:
    """Refuse, before any computation, what a run over a unit library of several types cannot do yet.

    The certified search and the GA choose among every type and orientation per unit; the FE
    exhaustive search lists orientations of one type only; a given chain table must cover every
    unit type of the library ("unit type 'x' has no table"); the mould tolerance report is of one unit.
    """
    from pneumorph.errors import ChainTableError, SearchConfigError

    if config.search == "exhaustive":
        raise SearchConfigError("--search exhaustive over a unit library is not available: it lists the 2^n "
                                "orientations of one type (use --search certified or ga)")
    if tolerance or config.robust is not None:
        raise SearchConfigError(f"{'--robust' if config.robust else '--tolerance'}: the mould tolerance report is of "
                                "one unit type; over a unit library leave it out")
    if config.chain_table is not None:
        from pneumorph.design.certified.planning import given_table_error
        from pneumorph.models.chain.model import ChainTable

        try:
            table = ChainTable.load(config.chain_table)
        except ChainTableError as exc:
            raise given_table_error(config.chain_table, exc) from None
        missing = [s for s in model.library.symbols if s not in table.alphabet]
        if missing:
            covers = ", ".join(table.alphabet) if table.alphabet else "one unit type, written 0/1"
            raise ChainTableError(f"--chain-table {config.chain_table}: unit type "
                                  f"{', '.join(repr(m) for m in missing)} has no table (it covers {covers}); "
                                  "build one with `pneumorph chain build --library`")
