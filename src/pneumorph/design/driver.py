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
  :class:`~pneumorph.design.runs.folder._GenerationLog`).
- ``overwrite=True`` removes the files of the old run (:data:`~pneumorph.design.runs.folder.RUN_FILES` and the files its
  report lists), only once every check has passed; files of others in the folder stay.

The driver, :func:`run_design`, runs one of the search strategies of
:mod:`pneumorph.design.algorithms` (the config's ``search``) on a
:class:`~pneumorph.design.algorithms.problem.Problem`: the algorithm plans before the folder is touched
(a certified search picks its chain table, or hands a short actuator to the FE exhaustive
search; :attr:`RunResult.search` and :attr:`RunResult.search_note` say which and why), sets
up under the folder's lock (builds a table no shipped or kept table serves, or with
``build=False`` stops with :class:`~pneumorph.errors.MissingTableError` before anything is
written), and runs; the driver writes what it found.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path
from types import TracebackType
from typing import Any

from pneumorph.design.algorithms import algorithm_for
from pneumorph.design.algorithms.problem import Algorithm, Problem, SearchOutcome
from pneumorph.design.certified.clearing import clearing_screen
from pneumorph.design.certified.planning import planned_workers
from pneumorph.design.config import DesignConfig, to_toml
from pneumorph.design.objectives.contact import ContactGoal, check_contact_goal
from pneumorph.design.objectives.targets import StagedTarget, on_actuator
from pneumorph.design.runs.folder import check_folder, created_top, remove_empty, remove_run_files
from pneumorph.design.runs.report import RunResult, write_outputs, write_report
from pneumorph.errors import OutputPathError, SearchConfigError
from pneumorph.execution.cache import CachedEvaluator, EvaluationCache, chain_table_dir, default_cache_path
from pneumorph.execution.evaluators import Evaluator, make_evaluator
from pneumorph.io.files import atomic_write_text, check_writable_dir
from pneumorph.io.lock import RunLock
from pneumorph.io.provenance import provenance as make_provenance
from pneumorph.models.chain.plan import evaluator_workers
from pneumorph.models.response import ActuatorModel


def provenance(config: DesignConfig, model: ActuatorModel) -> dict[str, Any]:
    """Where a run comes from: the common record (:func:`pneumorph.io.provenance`), seed, model identity."""
    return make_provenance(
        seed=config.seed,
        model_fidelity=str(getattr(model, "fidelity", "unknown")),
        model_fingerprint=model.fingerprint(),
        model_units=int(model.n_units),
        pressures_kpa=[round(float(p) * 1e3, 9) for p in model.pressures()],
    )


def run_design(config: DesignConfig, model: ActuatorModel, folder: str | Path, evaluator: Evaluator | None = None,
               cache: EvaluationCache | None = None, on_generation: Any = None, on_progress: Any = None,
               overwrite: bool = False, figures: bool = True, on_message: Any = None, build: bool = True,
               algorithm: Algorithm | None = None, reference: ActuatorModel | None = None) -> RunResult:
    """Run the config's search on ``model`` (built for it) into ``folder`` (see the module for what it holds).

    ``evaluator`` and ``cache`` default to the config's (and are closed at the end);
    ``on_generation``, ``on_progress`` and ``on_message`` receive a GA generation's stats, the
    exhaustive search's (done, total) and a line of text; ``overwrite`` starts afresh in a
    folder of another run; ``figures`` draws them; ``build`` lets a certified run build the
    tables it needs; ``algorithm`` searches instead of the config's ``search`` (any object with the
    :class:`~pneumorph.design.algorithms.problem.Algorithm` interface; the run's provenance names it);
    ``reference`` is a model whose optimum a certified run judges by ``model`` (the nominal
    model of an identified one, :mod:`pneumorph.design.runs.comparison`).

    Raises :class:`~pneumorph.errors.SearchConfigError` (the model's units differ from the
    config's), :class:`~pneumorph.errors.RunFolderError` (the folder holds
    another run, or another run is writing into it),
    :class:`~pneumorph.errors.OutputPathError` or :class:`~pneumorph.errors.MissingTableError`,
    each leaving the folder as it was. A Ctrl-C ends the run with ``status == "interrupted"``.
    """
    folder = check_writable_dir(folder, "run folder")
    if int(model.n_units) != config.units:
        raise SearchConfigError(f"the model has {model.n_units} units but the config asks for {config.units}")
    workers = evaluator_workers(evaluator) if evaluator is not None else planned_workers(config)
    objective = config.make_objective()
    check_contact_goal(objective, model)
    unit = getattr(model, "unit", None)  # a preset path drawn once for the FE model's actuator (its first unit type)
    if unit is not None:
        objective = on_actuator(objective, model.n_units * unit.pitch, unit.height / 2)
    problem = Problem(config, model, objective, workers=workers, table_dir=_table_dir(config, cache),
                      build=build, say=on_message or (lambda text: None), on_generation=on_generation,
                      on_progress=on_progress, reference=reference)
    algorithm, problem = (algorithm or algorithm_for(config)).plan(problem)
    if isinstance(problem.objective, StagedTarget):  # a stage off the levels of the ramp: refused here
        problem.objective.levels(problem.model.pressures())
    if isinstance(problem.objective, ContactGoal):  # a clearance off the levels below the top: likewise
        problem.objective.clear_level(problem.model.pressures())
    fingerprint = problem.model.fingerprint()
    check_folder(folder, config, fingerprint, overwrite)  # checked again under the lock
    with _Claim(folder, config, evaluator, cache) as claim:
        resumed = claim.take(fingerprint, overwrite, problem.say)
        screened, clearing = clearing_screen(claim.cached, problem.model, problem.objective, problem.table_dir,
                                             config.margin)
        problem = replace(problem, evaluator=screened, workers=evaluator_workers(claim.inner), folder=folder,
                          resumed=resumed)
        if clearing:
            problem.say(clearing)
        if algorithm.note:
            problem.say(algorithm.note)
        problem, entries = algorithm.setup(problem)
        if isinstance(problem.objective, StagedTarget):  # the levels of a table built to fewer: checked again
            problem.objective.levels(problem.model.pressures())
        searched = {"search": algorithm.name} if algorithm.name != config.search else {}
        claim.start(overwrite, {**provenance(config, problem.model), "resumed": resumed, **searched, **entries})
        status, outcome = _search(algorithm, problem, claim)
        return _finish(claim, algorithm, problem, status, outcome, figures)


class _Claim:
    """A run's hold on its folder, evaluator and cache, from the first write to the last.

    The folder is claimed (created if missing, locked) before any table is built: a second run
    into it is refused at once. A start that fails before :meth:`start` releases it and removes
    what this run created (the lock file, a new folder). The evaluator and cache the run made
    are closed once the search is over (:meth:`release`; the results need neither).
    """

    def __init__(self, folder: Path, config: DesignConfig, evaluator: Evaluator | None,
                 cache: EvaluationCache | None) -> None:
        self.folder, self.config = folder, config
        self.inner, self.cache = evaluator, cache
        self.own_evaluator, self.own_cache = evaluator is None, cache is None
        self.lock: RunLock | None = None
        self.made: Path | None = None  # the outermost folder this run created
        self.started: float | None = None  # when config.toml was written
        self.closed = False
        self.cached: Any = None  # the cache over the evaluator, once taken

    def __enter__(self) -> _Claim:
        return self

    def take(self, fingerprint: str, overwrite: bool, say: Any) -> bool:
        """Make the evaluator and cache, create and lock the folder; whether it resumes this run."""
        config = self.config
        self.inner = self.inner or make_evaluator(config.executor, config.workers, config.scheduler, on_message=say)
        self.cache = self.cache or EvaluationCache(config.cache or default_cache_path())
        self.cached = CachedEvaluator(self.inner, self.cache)
        self.made = created_top(self.folder)
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputPathError(f"run folder {self.folder}: cannot be created ({exc.strerror or exc})") from None
        self.lock = RunLock(self.folder).acquire()
        # under the lock, no other run can have written the folder since the first look
        return check_folder(self.folder, config, fingerprint, overwrite)

    def start(self, overwrite: bool, prov: dict[str, Any]) -> None:
        """Remove an overwritten run's files and write ``config.toml``: from here on the folder holds this run."""
        if overwrite:
            remove_run_files(self.folder)
        atomic_write_text(self.folder / "config.toml", to_toml({**self.config.to_dict(), "provenance": prov}))
        self.started = time.perf_counter()

    def release(self) -> None:
        """Stop the workers and close the cache that this run made (once)."""
        if self.closed:
            return
        self.closed = True
        try:
            if self.own_evaluator and self.inner is not None:
                self.inner.close()
        finally:
            if self.own_cache and self.cache is not None:
                self.cache.close()

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None, tb: TracebackType | None) -> None:
        self.release()
        if self.lock is not None:
            self.lock.release()
        if self.started is None and self.made is not None:
            remove_empty(self.folder, self.made)


def _search(algorithm: Algorithm, problem: Problem, claim: _Claim) -> tuple[str, SearchOutcome]:
    """Run the algorithm; a Ctrl-C (or a subclass: the CLI's SIGTERM) keeps what the algorithm says survives it."""
    try:
        return "finished", algorithm.run(problem)
    except KeyboardInterrupt:
        return "interrupted", algorithm.interrupted()
    finally:
        claim.release()


def _finish(claim: _Claim, algorithm: Algorithm, problem: Problem, status: str, outcome: SearchOutcome,
            figures: bool) -> RunResult:
    """The run's result, its files written; a Ctrl-C while writing still leaves a report that says so."""
    assert claim.started is not None
    result = RunResult(status, claim.folder, problem.objective, tuple(outcome.hall_of_fame), tuple(outcome.history),
                       claim.cached.solves, claim.cached.hits, time.perf_counter() - claim.started,
                       certified=outcome.certified, opinion_2d=outcome.opinion_2d,
                       rejected=int(getattr(claim.cache, "rejected", 0)), robustness=outcome.robustness,
                       robust_winner=outcome.robust_winner, search=algorithm.name, search_note=algorithm.note,
                       retried=int(getattr(claim.inner, "retried", 0)), refinement=outcome.refinement,
                       comparison=outcome.comparison)
    files: list[Path] = []
    problem.say(f"writing the report{' and figures' if figures else ''} to {claim.folder}")
    try:
        write_outputs(result, problem.config, problem.model, outcome.ranking, figures, files)
    except KeyboardInterrupt:
        result = replace(result, status="interrupted")
        files = [f for f in files if f.exists() and f.name != "report.md"]
        files.append(write_report(result, problem.config, problem.model, files))
    return replace(result, files=tuple(files))


def _table_dir(config: DesignConfig, cache: EvaluationCache | None) -> Path | None:
    """The chain tables' folder beside the evaluation cache (None for a cache in memory)."""
    return chain_table_dir(cache.path if cache is not None else config.cache)
