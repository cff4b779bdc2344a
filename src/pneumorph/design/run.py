"""A design run in a folder: settings with provenance, logs, hall of fame, report, figures.

Folder contents:

- ``config.toml`` - the settings (:class:`~pneumorph.design.config.DesignConfig`) and a
  ``[provenance]`` table: pneumorph version, date, seed, model fidelity and fingerprint,
  pressures, Python and dependency versions.
- ``generations.csv`` - one row per generation, written as the run goes (GA).
- ``ranking.csv`` - every design and its fitness (exhaustive search).
- ``hall_of_fame.json`` - the best distinct designs.
- ``certificate.json`` - certified search: the FE-verified winner, the bound, the designs
  verified, how much better at most an unverified design could be; ``top.csv`` - the best
  designs by chain value with their FE and 2D values; ``chain-vs-fe.png`` - the winner's
  shape from the chain against its FE verification.
- ``robustness.json`` - the winner's objective under seeded samples of the mould tolerance
  (``tolerance``, by the chain with tolerance tables or by FE solves) and, with ``robust``,
  the designs ranked by their worst or mean error under it.
- ``report.md`` - the winning design, its pressure (kPa) and error, the settings, its
  robustness.
- ``profile.png`` - the winner at its pressure against the target (Figs 6.6-6.11);
  ``convergence.png`` - best and mean fitness per generation.
- ``winner/deformed.png`` and ``winner/vtk/`` - an FE model's winner solved again with its
  fields (``model.solve``): the deformed shape at the winning pressure and its VTK series.

Running the same settings into the same folder again resumes: the GA replays with the same
seed and the evaluation cache answers every design solved before. Ctrl-C (or any
``KeyboardInterrupt``, such as the CLI's SIGTERM) stops the run after the files written so
far are flushed; the report is written and says so, and :attr:`RunResult.status` is
``"interrupted"``.

Nothing a run writes is lost or mixed up:

- one run at a time: the folder is held by a :class:`~pneumorph.io.RunLock`
  (``.pneumorph.lock``, naming the pid, host and start of its run) from before anything
  is written or built (a chain table built on first use) to the end; a second run into it
  is refused with :class:`RunFolderError` before it solves anything. A lock left by a
  killed run is released by the operating system.
- a start that fails (settings, model, chain table, a table it may not build, cache,
  executor, another run in the folder) leaves the folder as it was: the checks that need no
  solve come before the folder is touched; the folder is then created (if missing) and
  claimed, and a start that still fails (a table build the chain cannot represent, say)
  releases it and removes the lock file and the folders it created; a result is written
  only once every check has passed.
- every result file is written to a temporary file and renamed over the old one
  (``config.toml``, ``report.md``, the JSON and CSV files, the figures); JSON is strict.
- ``generations.csv`` is appended to, never truncated by a resumed run (see
  :class:`~pneumorph.design.folder._GenerationLog`).
- ``overwrite=True`` removes the files of the old run (:data:`~pneumorph.design.folder.RUN_FILES` and the files its
  report lists), only once every check has passed; files of others in the folder stay.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from pneumorph.design.certified import (
    CertifiedResult,
    certified_search,
    chain_candidate,
)
from pneumorph.design.config import DesignConfig, to_toml
from pneumorph.design.exhaustive import run_exhaustive
from pneumorph.design.fitness import Score
from pneumorph.design.folder import (
    _check_folder,
    _created_top,
    _GenerationLog,
    _remove_empty,
    _remove_run_files,
)
from pneumorph.design.ga import GenerationStats, run_ga
from pneumorph.design.planning import plan_search, planned_workers
from pneumorph.design.report import RunResult, _write_outputs, _write_report
from pneumorph.design.robustness import chain_robustness, fe_robustness, robust_ranking, robust_winner
from pneumorph.design.scoring import Candidate
from pneumorph.design.targets import Objective, StagedTarget
from pneumorph.errors import (
    MissingTableError,
    OutputPathError,
    PneumorphError,
    SearchConfigError,
)
from pneumorph.execution.cache import (
    CachedEvaluator,
    EvaluationCache,
    default_cache_path,
)
from pneumorph.execution.evaluators import Evaluator, make_evaluator
from pneumorph.io.files import (
    atomic_write_text,
    check_writable_dir,
)
from pneumorph.io.lock import RunLock
from pneumorph.io.provenance import provenance as make_provenance
from pneumorph.models.buildplan import evaluator_workers
from pneumorph.models.chain import ChainModel
from pneumorph.models.chaintables import serve_table, table_for
from pneumorph.models.factory import make_model
from pneumorph.models.response import ActuatorModel
from pneumorph.sensitivity.robust import find_tolerance_tables, tolerance_plan_text, tolerance_tables_for
from pneumorph.sensitivity.tolerances import Tolerance

#: designs a certified run with ``refine`` verifies (and solves on the finer mesh) at least
REFINE_TOP = 3


def provenance(config: DesignConfig, model: ActuatorModel) -> dict[str, Any]:
    """Where a run comes from: the common record (:func:`pneumorph.io.provenance`), seed, model identity."""
    return make_provenance(
        seed=config.seed,
        model_fidelity=str(getattr(model, "fidelity", "unknown")),
        model_fingerprint=model.fingerprint(),
        model_units=int(model.n_units),
        pressures_kpa=[round(float(p) * 1e3, 9) for p in model.pressures()],
    )


def run_design(
    config: DesignConfig,
    model: ActuatorModel,
    folder: str | Path,
    evaluator: Evaluator | None = None,
    cache: EvaluationCache | None = None,
    on_generation: Any = None,
    on_progress: Any = None,
    overwrite: bool = False,
    figures: bool = True,
    on_message: Any = None,
    build: bool = True,
) -> RunResult:
    """Run a design search and write its folder.

    Parameters
    ----------
    config : DesignConfig
    model : ActuatorModel
        Built for ``config`` (its ``n_units`` must equal ``config.units``).
    folder : str or Path
        The run folder; created if missing (once every check has passed); resumed if it
        holds the same run. Held by a :class:`~pneumorph.io.RunLock` for the whole run.
    evaluator : Evaluator, optional
        By default made from ``config.executor`` (and closed at the end).
    cache : EvaluationCache, optional
        By default opened at ``config.cache`` or :func:`default_cache_path`.
    on_generation, on_progress, on_message : callable, optional
        Progress callbacks: a GA generation's stats; exhaustive (done, total); a line of
        text from the certified search (table build, scoring, verification).
    overwrite : bool
        Start afresh in a folder that holds another run: once every check has passed, the
        old run's files are removed (:func:`run_files`); other files in the folder stay.
    figures : bool
        Draw the figures (and, for an FE model, solve the winner again for its shape and VTK).
    build : bool
        Whether a certified search may build a chain table (or tolerance tables) that no
        shipped or kept table serves; a build first says what it builds and its estimated
        time. False: such a run stops with :class:`MissingTableError` before anything is
        written.

    A certified search picks its table and its search before the folder is touched
    (:func:`pneumorph.design.planning.plan_search`): a table of the model's source, or of a
    longer ramp of the same step restricted to the levels at or below the model's pressure
    (the FE verifications then use the model remade with those levels); for an actuator
    shorter than the table needs, the FE exhaustive search of all its designs instead
    (:attr:`RunResult.search` and :attr:`RunResult.search_note` say which and why).

    Returns
    -------
    RunResult

    Raises
    ------
    SearchConfigError
        The model's number of units differs from the config's.
    RunFolderError
        The folder holds another run and ``overwrite`` is not set, its ``config.toml``
        cannot be read, or another run is writing into it now (its pid, host and start).
    OutputPathError
        The folder cannot be created or written.
    MissingTableError
        ``build`` is False and the run needs a table that no shipped or kept table serves.

    Any error raised before the run starts leaves the folder as it was. A
    ``KeyboardInterrupt`` (or a subclass) during the search or while the results are
    written ends the run with ``status == "interrupted"`` and a report saying so.
    """
    folder = check_writable_dir(folder, "run folder")
    if int(model.n_units) != config.units:
        raise SearchConfigError(f"the model has {model.n_units} units but the config asks for {config.units}")
    objective = config.make_objective()
    say = on_message or (lambda text: None)
    table_dir = _table_dir(config, cache)
    search, plan = config.search, None
    if config.search == "certified":
        if getattr(model, "gravity", None) is not None:
            from pneumorph.errors import LocalityError

            raise LocalityError("the certified search needs a free actuator (its chain model does not hold under "
                                "gravity); search with --search ga or exhaustive")
        # which table serves the model (and the model remade with its levels), or the FE exhaustive search of a
        # short actuator, or a build (refused here with build=False): decided before anything is written
        workers = evaluator_workers(evaluator) if evaluator is not None else planned_workers(config)
        plan = plan_search(config, model, table_dir, build=build, workers=workers)
        search = plan.search
        if plan.served is not None:
            model = plan.served.model  # the FE verifications report the chain's levels
            tolerance = Tolerance(config.tolerance) if _tolerance_tables_wanted(config, model) else None
            if not build and tolerance is not None and find_tolerance_tables(model, tolerance, table_dir) is None:
                raise MissingTableError(
                    f"--no-build: the mould tolerance tables of this unit (+-{config.tolerance:g} mm) are neither "
                    f"shipped nor kept in {table_dir}; run without --no-build to build them "
                    f"({tolerance_plan_text(model, tolerance, workers, what=False)}), or leave the robustness "
                    "report out with --tolerance 0")
    if isinstance(objective, StagedTarget):
        objective.levels(model.pressures())  # a stage off the levels of the ramp: refused before anything is written
    if config.refine and search == "certified":
        _check_refine(config, model, evaluator)
    fingerprint = model.fingerprint()
    _check_folder(folder, config, fingerprint, overwrite)  # checked again under the lock

    own_evaluator, own_cache = evaluator is None, cache is None
    inner: Evaluator | None = evaluator
    lock: RunLock | None = None
    log: _GenerationLog | None = None
    made: Path | None = None  # the outermost folder this run created
    started = False  # True once a result (config.toml) is written

    closed = False

    def release() -> None:
        """Stop the workers and close the cache (once; the results need neither)."""
        nonlocal closed
        if closed:
            return
        closed = True
        try:
            if own_evaluator and inner is not None:
                inner.close()
        finally:
            if own_cache and cache is not None:
                cache.close()

    try:
        inner = evaluator or make_evaluator(config.executor, config.workers, config.scheduler, on_message=say)
        cache = cache or EvaluationCache(config.cache or default_cache_path())
        cached = CachedEvaluator(inner, cache)
        # the folder is claimed before any table is built: a second run into it is refused at once; a start that
        # fails from here on releases it and removes what this run created (the lock file, a new folder)
        made = _created_top(folder)
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputPathError(f"run folder {folder}: cannot be created ({exc.strerror or exc})") from None
        lock = RunLock(folder).acquire()
        # under the lock, no other run can have written the folder since the first look
        resumed = _check_folder(folder, config, fingerprint, overwrite)
        chain = None
        tol_tables = None
        if plan is not None:
            say(plan.note)
        if search == "certified":
            assert plan is not None
            if plan.served is not None:
                table = plan.served.table
            else:  # built now (its plan and estimate said first), under the table's lock; a model the chain
                # cannot represent raises LocalityError and leaves nothing behind
                table = table_for(model, _training(model), folder=table_dir, evaluator=cached, on_progress=say)
            chain = ChainModel(table, config.units)
            # the unit's tolerance tables, likewise (of one unit type: none over a library of several yet)
            if _tolerance_tables_wanted(config, model):
                tol_tables = tolerance_tables_for(model, Tolerance(config.tolerance), folder=table_dir,
                                                  evaluator=cached, on_progress=say)
        if overwrite:
            _remove_run_files(folder)
        prov = provenance(config, model)
        prov["resumed"] = resumed
        if search != config.search:
            prov["search"] = search
        if chain is not None:
            prov["chain_table"] = chain.table.fingerprint()
            if "restricted_from" in chain.table.source:
                prov["chain_table_restricted_from"] = chain.table.source["restricted_from"]
        atomic_write_text(folder / "config.toml", to_toml({**config.to_dict(), "provenance": prov}))
        started = True
        start = time.perf_counter()
        log = _GenerationLog(folder / "generations.csv", resume=resumed) if search == "ga" else None

        def on_gen(stats: GenerationStats) -> None:
            log(stats)  # type: ignore[misc]
            if on_generation:
                on_generation(stats)

        status = "finished"
        hof: tuple[Candidate, ...] = ()
        history: tuple[GenerationStats, ...] = ()
        ranking: list[tuple[str, Score]] | None = None
        cert: CertifiedResult | None = None
        robustness: dict[str, Any] | None = None
        robust_best: Candidate | None = None
        refinement: dict[str, Any] | None = None
        try:
            if search == "ga":
                ga = run_ga(model, objective, config.ga, cached, on_gen, on_message=say)
                hof, history = ga.hall_of_fame, ga.history
            elif search == "certified":
                assert chain is not None
                verify = config.verify or int(getattr(inner, "workers", 1) or 1)
                if config.refine:  # the designs to refine: the winner and its closest runners-up at least
                    verify = max(verify, REFINE_TOP)
                cert = certified_search(model, chain, objective, cached, verify=verify, certify=config.certify,
                                        hall_of_fame=config.ga.hall_of_fame, margin=config.margin,
                                        on_progress=say, epsilon=config.epsilon)
                hof = cert.hall_of_fame
                if config.refine:
                    refinement = _refine(config, model, objective, cert, cached, say)
                else:
                    refinement = _mesh_note(model, objective, cert)
                order = cert.scores.order()[:1000]
                names = chain.table.texts(cert.scores.bits[order])
                ranking = [(d, _chain_score(cert, i)) for d, i in zip(names, order, strict=False)]
            else:
                ex = run_exhaustive(model, objective, cached, hall_of_fame=config.ga.hall_of_fame,
                                    on_progress=on_progress)
                hof, ranking = ex.hall_of_fame, [(d, ex.scores[d]) for d in ex.ranking]
            robustness, robust_best = _robustness(config, model, objective, cached, cert, chain, tol_tables, hof, say)
        except KeyboardInterrupt:  # Ctrl-C, and its subclasses (the CLI's SIGTERM)
            status = "interrupted"
            history = tuple(log.rows) if log else ()
            hof, ranking, cert, robustness, robust_best, refinement = (), None, None, None, None, None
        finally:
            if log:
                log.close()
            release()
        result = RunResult(status, folder, objective, tuple(hof), tuple(history), cached.solves, cached.hits,
                           time.perf_counter() - start, certified=cert, rejected=int(getattr(cache, "rejected", 0)),
                           robustness=robustness, robust_winner=robust_best, search=search,
                           search_note=plan.note if plan is not None else "",
                           retried=int(getattr(inner, "retried", 0)), refinement=refinement)
        files: list[Path] = []
        try:
            if cert is not None:
                result = replace(result, opinion_2d=_opinion_2d(config, model, objective, cert))
            _write_outputs(result, config, model, ranking, figures, files)
        except KeyboardInterrupt:  # while writing the results: the report still says what there is
            result = replace(result, status="interrupted")
            files = [f for f in files if f.exists() and f.name != "report.md"]
            files.append(_write_report(result, config, model, files))
        return replace(result, files=tuple(files))
    finally:
        if log:
            log.close()
        release()
        if lock is not None:
            lock.release()
        if not started and made is not None:
            _remove_empty(folder, made)


def _check_refine(config: DesignConfig, model: Any, evaluator: Any) -> None:
    """Refuse, before the folder is touched, a refinement that is not finer or would not fit in memory."""
    from pneumorph.design.refine import check_refine

    workers = evaluator_workers(evaluator) if evaluator is not None else planned_workers(config)
    check_refine(model, config.refine, parallel=max(1, min(int(workers or 1), config.verify or 1024)))


def _refine(config: DesignConfig, model: Any, objective: Objective, cert: CertifiedResult, evaluator: Any,
            say: Callable[[str], None]) -> dict[str, Any]:
    """The verified designs on the finer mesh of ``[design] refine`` (:func:`.refine.refine_verified`)."""
    from pneumorph.design.refine import refine_verified

    values = {d: c.value for d, c in cert.verified.items() if c.failure is None}
    return refine_verified(model, objective, list(values), values, cert.winner.design, config.refine, evaluator,
                           say=say)


def _mesh_note(model: Any, objective: Objective, cert: CertifiedResult) -> dict[str, Any] | None:
    """What the shipped mesh study says about the verified values (:func:`.refine.mesh_note`)."""
    from pneumorph.design.refine import mesh_note

    values = {d: c.value for d, c in cert.verified.items() if c.failure is None}
    note = mesh_note(model, objective, values, cert.winner.design)
    return None if note is None else {"study": note}


def _robustness(config: DesignConfig, model: ActuatorModel, objective: Objective, evaluator: Any,
                cert: CertifiedResult | None, chain: ChainModel | None, tables: Any, hof: Any,
                say: Callable[[str], None]) -> tuple[dict[str, Any] | None, Candidate | None]:
    """The winner's spread under the mould tolerance and, with ``robust``, the most robust design.

    None for a model over a unit library of several types (the tolerances are those of one unit).
    """
    if config.tolerance == 0 or getattr(model, "mixed", False):
        return None, None
    if cert is not None and tables is not None:
        assert chain is not None
        out = chain_robustness(config, chain, tables, objective, cert.winner)
        best = None
        if config.robust is not None:
            rows, _ = robust_ranking(config, chain, tables, objective, cert.scores.bits)
            best = robust_winner(config, model, objective, evaluator, rows)
            say(f"most robust by the {config.robust} error under +-{config.tolerance:g} mm: {best.design} "
                f"(chain {rows[0][config.robust]:.4g}; FE nominal {best.value:.4g})")
            winner = chain_robustness(config, chain, tables, objective, best)["winner"]
            out.update(statistic=config.robust, ranking=rows, robust_winner=winner)
        w = out["winner"]
        say(f"robustness of {w['design']} under +-{config.tolerance:g} mm ({config.samples(True)} samples, chain): "
            f"mean {w['mean']:.4g}, 95th percentile {w['p95']:.4g}, worst {w['worst']:.4g}")
        return out, best
    best_candidate = cert.winner if cert is not None else (hof[0] if hof else None)
    if best_candidate is None or best_candidate.failure is not None:
        return None, None
    say(f"robustness of {best_candidate.design}: {config.samples(False) + 1} FE solves under +-{config.tolerance:g} mm")
    return fe_robustness(config, model, objective, best_candidate, evaluator), None


def _tolerance_tables_wanted(config: DesignConfig, model: ActuatorModel) -> bool:
    """Whether a certified run scores its winner's robustness with the unit's tolerance tables (one unit type)."""
    return config.tolerance > 0 and hasattr(model, "variant") and not getattr(model, "mixed", False)


def _table_dir(config: DesignConfig, cache: EvaluationCache | None) -> Path | None:
    """The chain tables' folder beside the evaluation cache (None for a cache in memory)."""
    path = cache.path if cache is not None else str(config.cache or default_cache_path())
    return None if path == ":memory:" else Path(path).parent / "chain-tables"


def _training(model: ActuatorModel) -> Any:
    """``n -> the same model with n units`` (the training actuator of a new chain table)."""
    with_units = getattr(model, "with_units", None)
    if not callable(with_units):
        def refuse(n: int) -> Any:
            raise SearchConfigError(f"the {getattr(model, 'fidelity', '?')} model cannot be re-built with other "
                                    "lengths to fit a chain table; give a table (chain_table) or another search")
        return refuse
    return with_units


def _chain_score(cert: CertifiedResult, i: int) -> Score:
    """The chain's :class:`Score` of the ``i``-th scored design."""
    sc = cert.scores
    sign = 1.0 if cert.certificate["sense"] == "min" else -1.0
    level = int(sc.level[i])
    pressures = cert.winner.response.pressures if cert.winner.response is not None else None
    p = None if pressures is None else float(pressures[level])
    return Score(sc.per_level[i], level, sign * float(sc.cost[i]), p)


def _opinion_2d(config: DesignConfig, model: ActuatorModel, objective: Objective,
                cert: CertifiedResult) -> dict[str, float]:
    """The 2D reduced-order model's values of the listed designs (its shipped chain table, at the levels the
    chain scored), if it has one."""
    if getattr(model, "fidelity", None) != "3d":
        return {}
    try:
        model2d = make_model(config.units, {**config.model, "fidelity": "2d"})
        served = serve_table(model2d)
        if served is None or not np.allclose(served.table.pressures, model.pressures(), rtol=0, atol=1e-12):
            return {}
        chain = ChainModel(served.table, config.units)
    except PneumorphError:
        return {}
    designs = dict.fromkeys([cert.winner.design, *(c.design for c in cert.hall_of_fame)])
    return {d: chain_candidate(chain, objective, d).value for d in designs}


