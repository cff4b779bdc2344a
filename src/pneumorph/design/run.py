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
  :class:`_GenerationLog`).
- ``overwrite=True`` removes the files of the old run (:data:`RUN_FILES` and the files its
  report lists), only once every check has passed; files of others in the folder stay.
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
import time
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from pneumorph.design.certificate import certificate_text
from pneumorph.design.certified import (
    CertifiedResult,
    certified_search,
    chain_candidate,
)
from pneumorph.design.config import DesignConfig, to_toml
from pneumorph.design.exhaustive import run_exhaustive
from pneumorph.design.figures import plot_convergence, plot_profile
from pneumorph.design.fitness import Score, stage_values
from pneumorph.design.ga import GenerationStats, run_ga
from pneumorph.design.planning import plan_search, planned_workers
from pneumorph.design.robustness import chain_robustness, fe_robustness, robust_ranking, robust_winner
from pneumorph.design.scoring import Candidate
from pneumorph.design.targets import Objective, ProfileTarget, StagedTarget
from pneumorph.errors import (
    MissingTableError,
    OutputPathError,
    PneumorphError,
    RunFolderError,
    SearchConfigError,
)
from pneumorph.execution.cache import (
    CachedEvaluator,
    EvaluationCache,
    default_cache_path,
)
from pneumorph.execution.evaluators import Evaluator, make_evaluator
from pneumorph.io.files import (
    atomic_path,
    atomic_write_text,
    check_writable_dir,
    write_json,
)
from pneumorph.io.lock import LOCK_NAME as LOCK_FILE
from pneumorph.io.lock import RunLock
from pneumorph.io.provenance import provenance as make_provenance
from pneumorph.models.buildplan import evaluator_workers
from pneumorph.models.chain import ChainModel
from pneumorph.models.chaintables import serve_table, table_for
from pneumorph.models.factory import make_model
from pneumorph.models.response import ActuatorModel
from pneumorph.sensitivity.robust import find_tolerance_tables, tolerance_plan_text, tolerance_tables_for
from pneumorph.sensitivity.tolerances import Tolerance

_COMPARED = ("design", "ga", "model")
#: designs a certified run with ``refine`` verifies (and solves on the finer mesh) at least
REFINE_TOP = 3

#: The files a run writes into its folder (glob patterns, relative to it): what ``overwrite`` removes,
#: besides the files the old run's report lists and the temporary files of an interrupted write.
#: The lock file (``.pneumorph.lock``) is not a run file.
RUN_FILES = (
    "config.toml",
    "generations.csv",
    "ranking.csv",
    "hall_of_fame.json",
    "certificate.json",
    "top.csv",
    "robustness.json",
    "profile.png",
    "chain-vs-fe.png",
    "convergence.png",
    "winner/deformed.png",  # an FE model's winner, solved again with its fields
    "winner/vtk/winner.pvd",
    "winner/vtk/winner_*.vtu",
    "report.md",
)


def provenance(config: DesignConfig, model: ActuatorModel) -> dict[str, Any]:
    """Where a run comes from: the common record (:func:`pneumorph.io.provenance`), seed, model identity."""
    return make_provenance(
        seed=config.seed,
        model_fidelity=str(getattr(model, "fidelity", "unknown")),
        model_fingerprint=model.fingerprint(),
        model_units=int(model.n_units),
        pressures_kpa=[round(float(p) * 1e3, 9) for p in model.pressures()],
    )


@dataclass(frozen=True)
class RunResult:
    """What a run produced.

    Attributes
    ----------
    status : {"finished", "interrupted"}
    folder : Path
    objective : ProfileTarget or TipGoal
    hall_of_fame : tuple of Candidate
        Best first; empty if the run was interrupted before its end.
    history : tuple of GenerationStats
        GA generations (empty for an exhaustive search).
    solves, cache_hits : int
        New model solves and designs answered by the evaluation cache in this run.
    wall_time : float
    rejected : int
        Cache entries that failed their checksum and were solved again instead of used.
    retried : int
        Designs retried on other workers after a Dask worker was lost (0 for other executors).
    files : tuple of Path
    search : str
        The search that ran: the config's, or for a certified run of an actuator shorter
        than its chain table needs, ``"exhaustive"``.
    search_note : str
        A certified run's choice: its table and the levels it scores, or why it searched
        exhaustively (and the estimated cost).
    refinement : dict or None
        With ``[design] refine``: the verified designs on the finer mesh
        (:func:`pneumorph.design.refine.refine_verified`).
    """

    status: str
    folder: Path
    objective: Objective
    hall_of_fame: tuple[Candidate, ...]
    history: tuple[GenerationStats, ...]
    solves: int
    cache_hits: int
    wall_time: float
    files: tuple[Path, ...] = field(default=())
    certified: CertifiedResult | None = None
    opinion_2d: dict[str, float] = field(default_factory=dict)
    rejected: int = 0
    robustness: dict[str, Any] | None = None
    robust_winner: Candidate | None = None
    search: str = ""
    search_note: str = ""
    retried: int = 0
    refinement: dict[str, Any] | None = None

    @property
    def best(self) -> Candidate | None:
        """The winner: the most robust design of a ``robust`` run (FE-verified), the FE-verified one of a
        certified search, else the first of the hall of fame."""
        if self.robust_winner is not None:
            return self.robust_winner
        if self.certified is not None:
            return self.certified.winner
        return self.hall_of_fame[0] if self.hall_of_fame else None


def _check_folder(folder: Path, config: DesignConfig, fingerprint: str, overwrite: bool) -> bool:
    """True if ``folder`` holds the same run (resume); an error if it holds another one."""
    path = folder / "config.toml"
    if not path.exists() or overwrite:
        return False
    try:
        old = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise RunFolderError(f"{folder} holds a config.toml that cannot be read ({exc}); choose another output "
                             "folder or overwrite it") from None
    new = config.to_dict()
    for table in _COMPARED:
        if old.get(table, {}) != new.get(table, {}):
            there, here = old.get(table, {}), new.get(table, {})
            keys = sorted(k for k in {*there, *here} if there.get(k) != here.get(k))
            diff = "; ".join(f"{k} = {_setting(there.get(k))} there, {_setting(here.get(k))} now" for k in keys[:4])
            more = f" (and {len(keys) - 4} more)" if len(keys) > 4 else ""
            raise RunFolderError(
                f"{folder} holds a run with other [{table}] settings: {diff}{more}; give another folder with --out "
                "or replace that run with --overwrite"
            )
    old_fp = old.get("provenance", {}).get("model_fingerprint")
    if old_fp not in (None, fingerprint):
        raise RunFolderError(
            f"{folder} holds a run of another model (fingerprint {old_fp}, now {fingerprint}); "
            "give another folder with --out or replace that run with --overwrite"
        )
    return True


def _setting(value: Any) -> str:
    """A setting as a config shows it (``unset`` when absent), cut to 40 characters."""
    text = "unset" if value is None else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


class _GenerationLog:
    """``generations.csv``: one row per generation, written (flushed and synced) as it is known.

    A new run starts the file with its header. A resumed run keeps every row the file holds
    and appends to it; it never truncates it. The rule for rows: **a generation is logged
    once, by the run that first computed it.** A resumed GA replays generations 0, 1, ...
    with the same seed, the evaluation cache answering the designs solved before; a replayed
    generation that the file already holds is not written again (the kept row has the same
    fitness statistics, and the solves and wall time it really took), and the first
    generation beyond them is appended. A last line cut short by a kill (no line end) or a
    row that cannot be read is dropped; only then is the file rewritten, atomically, with the
    rows it keeps.
    """

    FIELDS = tuple(GenerationStats.__dataclass_fields__)

    def __init__(self, path: Path, resume: bool) -> None:
        self.path = path
        self.rows: list[GenerationStats] = []
        self.logged: set[int] = set()
        kept, clean = self._existing() if resume else ([], False)
        if not clean:
            atomic_write_text(path, self._lines([self.FIELDS, *kept]))
        self.file = path.open("a", newline="", encoding="utf-8")

    def _existing(self) -> tuple[list[list[str]], bool]:
        """The readable rows of the file, and whether it is exactly its header and those rows."""
        try:
            text = self.path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return [], False
        lines = text.splitlines(keepends=True)
        clean = True
        if lines and not lines[-1].endswith(("\n", "\r")):
            lines, clean = lines[:-1], False  # cut short by a kill
        records = list(csv.reader(lines))
        if not records or "generation" not in records[0]:
            return [], False
        header, kept = records[0], []
        clean = clean and tuple(header) == self.FIELDS
        for record in records[1:]:
            row = dict(zip(header, record, strict=False))
            try:
                generation = int(row["generation"])
            except ValueError:
                generation = None
            if len(record) != len(header) or generation is None or generation in self.logged:
                clean = False
                continue
            self.logged.add(generation)
            kept.append([row.get(f, "") for f in self.FIELDS])
        return kept, clean

    @staticmethod
    def _lines(records: list[Any]) -> str:
        buffer = io.StringIO()
        csv.writer(buffer).writerows(records)
        return buffer.getvalue()

    def __call__(self, stats: GenerationStats) -> None:
        self.rows.append(stats)
        if stats.generation in self.logged:
            return
        row = stats.as_row()
        self.file.write(self._lines([[row[f] for f in self.FIELDS]]))  # one write: a whole line or nothing
        self.file.flush()
        os.fsync(self.file.fileno())
        self.logged.add(stats.generation)

    def close(self) -> None:
        self.file.close()


def _created_top(folder: Path) -> Path | None:
    """The outermost folder of ``folder`` and its parents that does not exist yet (None if it exists)."""
    top = None
    probe = folder
    while not probe.exists() and probe.parent != probe:
        top, probe = probe, probe.parent
    return top


def _remove_empty(folder: Path, top: Path) -> None:
    """Remove ``folder`` and its parents up to ``top`` while they are empty."""
    probe = folder
    while True:
        try:
            probe.rmdir()
        except OSError:
            return
        if probe == top or probe.parent == probe:
            return
        probe = probe.parent


def _reported_files(folder: Path) -> list[Path]:
    """The files of ``folder`` that its ``report.md`` lists (what the last run wrote)."""
    try:
        text = (folder / "report.md").read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return []
    _, found, files = text.partition("\n## Files\n")
    out = []
    for name in re.findall(r"^- \[[^\]]*\]\(([^)\n]+)\)$", files if found else "", flags=re.MULTILINE):
        rel = Path(name)
        if rel.is_absolute() or ".." in rel.parts or rel.name == LOCK_FILE:
            continue
        out.append(folder / rel)
    return out


def run_files(folder: str | Path) -> list[Path]:
    """The files of an earlier run in ``folder``: :data:`RUN_FILES`, the files its report lists and
    the temporary files of an interrupted write, ``config.toml`` last."""
    folder = Path(folder)
    found: set[Path] = set(_reported_files(folder))
    for pattern in RUN_FILES:
        parent, _, name = pattern.rpartition("/")
        found.update(folder.glob(pattern))
        found.update(folder.glob(f"{parent}/.{name}.*.tmp*" if parent else f".{name}.*.tmp*"))
    files = [p for p in found if p.name != LOCK_FILE and (p.is_file() or p.is_symlink())]
    return sorted(files, key=lambda p: (p.name == "config.toml", str(p)))


def _remove_run_files(folder: Path) -> None:
    """Remove the old run's files (``config.toml`` last: a removal cut short still reads as that run)."""
    parents: set[Path] = set()
    for path in run_files(folder):
        try:
            path.unlink()
        except FileNotFoundError:
            continue
        except OSError as exc:
            raise RunFolderError(f"{folder}: cannot remove {path.name} of the old run "
                                 f"({exc.strerror or exc})") from None
        parents.update(p for p in path.parents if p != folder and p.is_relative_to(folder))
    for parent in sorted(parents, key=lambda p: len(p.parts), reverse=True):
        try:
            parent.rmdir()  # only if empty
        except OSError:
            pass


def _atomic_figure(path: Path, draw: Callable[[Path], Any]) -> Path:
    """Draw a figure into a temporary file beside ``path`` (same suffix, for its format), then rename it."""
    with atomic_path(path) as tmp:
        draw(tmp)
    return path


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


def _stage_lines(objective: Objective, best: Candidate) -> list[str]:
    """A staged winner's value at each stage, one report line each (none for other objectives)."""
    if not isinstance(objective, StagedTarget) or best.response is None or not best.response.converged:
        return []
    values = stage_values(best.response, objective)
    return [f"  - stage at {stage.pressure * 1e3:g} kPa (weight {stage.weight:g}): {v:.4g} mm "
            f"({'Eq 4.1' if isinstance(stage.target, ProfileTarget) else 'tip to the point'}, {stage.target.label})"
            for stage, v in zip(objective.stages, values, strict=True)]


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


def _csv_text(header: list[str], rows: Any) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    writer.writerow(header)
    writer.writerows(rows)
    return buffer.getvalue()


def _write_outputs(
    result: RunResult, config: DesignConfig, model: ActuatorModel, ranking: Any, figures: bool, files: list[Path]
) -> None:
    """Write the results into the run folder, each file atomically; ``files`` collects them as they are
    written, the report last."""
    folder = result.folder
    if result.history:
        files.append(folder / "generations.csv")
    if ranking is not None:
        rows = []
        for i, (d, s) in enumerate(ranking, 1):
            p = "" if s.pressure is None else round(s.pressure * 1e3, 9)
            rows.append([i, d, s.value, "" if s.level is None else s.level, p, s.failed])
        text = _csv_text(["rank", "design", "value", "level", "pressure_kpa", "failed"], rows)
        files.append(atomic_write_text(folder / "ranking.csv", text))
    if result.hall_of_fame:
        entries = [{"rank": i, **c.to_dict()} for i, c in enumerate(result.hall_of_fame, 1)]
        doc = {"objective": result.objective.label, "sense": result.objective.sense,
               "unit": result.objective.unit, "designs": entries}
        files.append(write_json(folder / "hall_of_fame.json", doc))
    cert = result.certified
    if cert is not None:
        files += _write_certificate(result, folder)
    if result.robustness is not None:
        doc = {"objective": result.objective.label, "sense": result.objective.sense, "unit": result.objective.unit,
               **result.robustness}
        files.append(write_json(folder / "robustness.json", doc))
    best = result.best
    if figures and best is not None and best.response is not None and best.level is not None:
        files.append(_atomic_figure(folder / "profile.png", lambda p: plot_profile(best, result.objective, p)))
        if cert is not None:
            files.append(_atomic_figure(folder / "chain-vs-fe.png", lambda p: plot_profile(
                best, result.objective, p, compare=[("chain model", cert.winner_chain)])))
        if callable(getattr(model, "solve", None)) and cert is None:  # a certified run solves no winner again
            files.extend(_write_winner(model, best.response.orientation, best.level, folder / "winner"))
    if figures and result.history:
        files.append(_atomic_figure(folder / "convergence.png",
                                    lambda p: plot_convergence(result.history, p, result.objective.unit)))
    files.append(_write_report(result, config, model, files))


def _write_winner(model: Any, design: str, level: int, folder: Path) -> list[Path]:
    """Solve the winner again with its fields (``model.solve``, an FE model) and write its deformed
    shape at the winning level and its VTK series (for ParaView) into ``folder``."""
    from pneumorph.io import provenance as record
    from pneumorph.io import write_vtk_series
    from pneumorph.plot.shape import plot_shape

    folder.mkdir(parents=True, exist_ok=True)
    solution = model.solve(design)
    shape = folder / "deformed.png"
    plot_shape(solution, shape, levels=[level])
    meta = record(model=model.describe(), fingerprint=model.fingerprint(), design=design)
    return [shape, write_vtk_series(solution, folder / "vtk", stem="winner", meta=meta)]


def _write_report(result: RunResult, config: DesignConfig, model: ActuatorModel, files: list[Path]) -> Path:
    folder = result.folder
    names = [f.relative_to(folder).as_posix() if f.is_relative_to(folder) else f.name for f in files]
    return atomic_write_text(folder / "report.md", report_text(result, config, model, names))


def _top_rows(result: RunResult) -> list[dict[str, Any]]:
    """The listed designs by chain value with their FE and 2D values."""
    cert = result.certified
    assert cert is not None
    rows = []
    for i, c in enumerate(cert.hall_of_fame, 1):
        fe = cert.verified.get(c.design)
        rows.append({
            "rank_chain": i, "design": c.design, "chain": c.value,
            "chain_pressure_kpa": None if c.pressure is None else round(c.pressure * 1e3, 9),
            "fe": None if fe is None or fe.failure else fe.value,
            "fe_pressure_kpa": None if fe is None or fe.pressure is None else round(fe.pressure * 1e3, 9),
            "chain_2d": result.opinion_2d.get(c.design),
        })
    return rows


def _write_certificate(result: RunResult, folder: Path) -> list[Path]:
    cert = result.certified
    assert cert is not None
    w = cert.winner
    rows = _top_rows(result)
    doc = {
        "objective": result.objective.label, "sense": result.objective.sense, "unit": result.objective.unit,
        "winner": {**w.to_dict(), "chain_value": cert.winner_chain.value, "chain_2d": result.opinion_2d.get(w.design)},
        "certificate": cert.certificate,
        "verified": {d: c.to_dict() for d, c in cert.verified.items()},
        "top": rows,
    }
    if result.refinement is not None:
        doc["mesh"] = result.refinement
    path = write_json(folder / "certificate.json", doc)
    text = _csv_text(list(rows[0]), [list(row.values()) for row in rows])
    return [path, atomic_write_text(folder / "top.csv", text)]


def report_text(result: RunResult, config: DesignConfig, model: ActuatorModel, files: list[str]) -> str:
    """The markdown report of a run."""
    o = result.objective
    lines = [f"# Design run: {o.label}", ""]
    if result.status == "interrupted":
        lines += ["**Interrupted.** Run the same command again to resume; solved designs are cached.", ""]
    search = {
        "ga": f"genetic algorithm (population {config.ga.population}, {config.ga.generations} generations, "
              f"seed {config.seed})",
        "exhaustive": "exhaustive search",
        "certified": "certified search (every design scored by the chain model, the best verified by FE)",
    }[result.search or config.search]
    if result.search_note:  # a certified run's choice: its table and levels, or why it searched exhaustively
        search = result.search_note
    lines += [
        f"- objective: {o.label} ({'minimised' if o.sense == 'min' else 'maximised'})",
        f"- actuator: {config.units} units, model {getattr(model, 'fidelity', '?')} ({model.fingerprint()})",
        f"- search: {search}",
        (f"- new solves: {result.solves}, answered by the cache: {result.cache_hits}, "
        f"wall time {result.wall_time:.1f} s"
         + (f"; {result.rejected} damaged cache entries were solved again, not used" if result.rejected else "")),
        "",
    ]
    best = result.best
    if best is not None:
        what = ("error (Eq 4.1)" if isinstance(o, ProfileTarget) else
                "weighted root-sum-square of the stages" if isinstance(o, StagedTarget) else "value")
        pressure = "-" if best.pressure is None else f"{best.pressure * 1e3:.4g} kPa"
        if best.failure is not None:
            lines += [f"**No design converged.** The best entry failed: {best.failure}", ""]
        lines += [
            "## Winner",
            "",
            f"- design (base first): `{best.design}`",
            f"- pressure: {pressure}",
            f"- {what}: {best.value:.6g} {o.unit}" + (
                f" (the root of the summed squared offsets of the {config.units} unit centres from the target: "
                f"{best.value / config.units**0.5:.3g} {o.unit} RMS per centre)"
                if isinstance(o, ProfileTarget) and math.isfinite(best.value) else ""),
            *_stage_lines(o, best),
            "",
            "## Hall of fame",
            "",
            f"| rank | design | {o.unit} | pressure (kPa) |",
            "|---:|---|---:|---:|",
        ]
        for i, c in enumerate(result.hall_of_fame, 1):
            p = "failed" if c.pressure is None else f"{c.pressure * 1e3:.4g}"
            lines.append(f"| {i} | `{c.design}` | {c.value:.6g} | {p} |")
        lines.append("")
    cert = result.certified
    if cert is not None:
        sure = cert.certificate
        u = o.unit
        words = certificate_text(sure, u, cert.winner.design, getattr(model, "fidelity", None),
                                 show=len(sure["verified"]))
        lines += [
            "## Certificate",
            "",
            *[f"- {line}" for line in words],
            "",
            f"| chain rank | design | chain ({u}) | FE ({u}) | 2D chain ({u}) | pressure (kPa) |",
            "|---:|---|---:|---:|---:|---:|",
        ]

        def fmt(v: Any) -> str:
            return "-" if v is None else f"{v:.4g}"

        for row in _top_rows(result):
            lines.append(f"| {row['rank_chain']} | `{row['design']}` | {fmt(row['chain'])} | {fmt(row['fe'])} | "
                         f"{fmt(row['chain_2d'])} | {fmt(row['fe_pressure_kpa'] or row['chain_pressure_kpa'])} |")
        lines.append("")
    if result.refinement is not None:
        lines += _refinement_lines(result.refinement, o)
    if result.robustness is not None:
        lines += _robustness_lines(result.robustness, o)
    if files:
        lines += ["## Files", "", *[f"- [{f}]({f})" for f in files], ""]
    return "\n".join(lines)


def _refinement_lines(ref: dict[str, Any], o: Objective) -> list[str]:
    """The report's section on the finer mesh (or, without one, what the mesh study says)."""
    u = o.unit
    if "study" in ref:
        s = ref["study"]
        coarse, fine = s["sizes_mm"]
        lo, hi = s["value_change"]
        within = s["within"]
        return ["## Mesh", "",
                f"The values above are on the model's {coarse:g} mm mesh. In the mesh study of this model "
                f"(docs/mesh-convergence.md, {s['designs']} designs), refining to {fine:g} mm moved the values "
                f"by {lo:+.3g} to {hi:+.3g} {u}, but the gap between any two designs by at most "
                f"{s['gap_change']:.3g} {u}.", "",
                "- " + (f"verified designs within {s['gap_change']:.3g} {u} of the winner, whose order a finer mesh "
                        f"could swap: {', '.join(f'`{d}`' for d in within)} (`--refine {fine:g}` solves them on it)"
                        if within else f"no verified design lies within {s['gap_change']:.3g} {u} of the winner: "
                        "the mesh study gives no reason for a finer mesh to swap them"), ""]
    coarse, fine = ref["element_size_mm"]
    lines = ["## Mesh", "",
             f"The verified designs solved again with {fine:g} mm elements (the model's: {coarse:g} mm; "
             f"representative cell sizes {ref['cell_size_mm'][0]:.3g} and {ref['cell_size_mm'][1]:.3g} mm). "
             f"Limits by Richardson extrapolation with the order {ref['order']:g} observed in the mesh study "
             f"(docs/mesh-convergence.md), +- its grid convergence index (safety factor {ref['safety_factor']:g}). "
             "The gap to the winner is extrapolated the same way: the mesh moves all designs alike, so the gap "
             "is known far better than either value.", "",
             f"| design | {coarse:g} mm ({u}) | {fine:g} mm ({u}) | change ({u}) | limit ({u}) | "
             f"gap to the winner, limit ({u}) |",
             "|---|---:|---:|---:|---:|---:|"]
    for r in ref["rows"]:
        if r.get("refined") is None:
            lines.append(f"| `{r['design']}` | {r['value']:.4g} | failed: {r.get('failure')} | - | - | - |")
            continue
        gap = ref["gaps"].get(r["design"])
        gap_text = "-" if gap is None else f"{gap['limit']:+.3g} +- {gap['error']:.2g}"
        lines.append(f"| `{r['design']}` | {r['value']:.4g} | {r['refined']:.4g} | {r['change']:+.3g} | "
                     f"{r['extrapolated']:.4g} +- {r['error']:.2g} | {gap_text} |")
    held = ("**the winner holds** on the finer mesh" if ref["holds"] else
            f"**the winner does not hold**: `{ref['refined_best']}` is better on the finer mesh")
    could = ref["could_overtake"]
    lines += ["", f"- {held}",
              "- " + (f"designs whose gap to the winner could close on a converged mesh: "
                      f"{', '.join(f'`{d}`' for d in could)}" if could else
                      "no verified design's gap to the winner can close within the estimated mesh error"), ""]
    return lines


def _robustness_lines(rob: dict[str, Any], o: Objective) -> list[str]:
    """The report's section on mould tolerances."""
    u = o.unit
    lines = ["## Robustness to mould tolerances", "",
             f"Every thickness of Fig E.4 (side walls, Mold Star wall, Smooth-Sil layer) within "
             f"+-{rob['tolerance_mm']:g} mm, {rob['samples']} seeded samples (seed {rob['seed']}); "
             f"{rob['method']}.", ""]

    def row(label: str, w: dict[str, Any]) -> str:
        p = "-" if w.get("pressure_kpa") is None else f"{w['pressure_kpa']:.4g}"
        if "mean" not in w:
            return f"| {label} | `{w['design']}` | {p} | {w['nominal_fe']:.4g} | - | - | - |"
        return (f"| {label} | `{w['design']}` | {p} | {w['nominal_fe']:.4g} | {w['mean']:.4g} | {w['p95']:.4g} | "
                f"{w['worst']:.4g} |")

    lines += [f"| | design | pressure (kPa) | nominal FE ({u}) | mean ({u}) | 95th percentile ({u}) | worst ({u}) |",
              "|---|---|---:|---:|---:|---:|---:|", row("winner", rob["winner"])]
    if "robust_winner" in rob:
        lines.append(row(f"most robust ({rob['statistic']})", rob["robust_winner"]))
    if rob.get("failed"):
        lines.append(f"\n{rob['failed']} of the samples did not converge in the FE model.")
    if "ranking" in rob:
        lines += ["", f"Designs by their {rob['statistic']} error under the tolerance (chain model):", "",
                  f"| rank | design | pressure (kPa) | mean ({u}) | 95th percentile ({u}) | worst ({u}) |",
                  "|---:|---|---:|---:|---:|---:|"]
        lines += [f"| {r['rank']} | `{r['design']}` | {r['pressure_kpa']:.4g} | {r['mean']:.4g} | {r['p95']:.4g} | "
                  f"{r['worst']:.4g} |" for r in rob["ranking"]]
    return [*lines, ""]
