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
- ``report.md`` - the winning design, its pressure (kPa) and error, the settings.
- ``profile.png`` - the winner at its pressure against the target (Figs 6.6-6.11);
  ``convergence.png`` - best and mean fitness per generation.
- whatever the model's optional hook ``write_deformed(response, level, folder) -> list[Path]``
  writes (the deformed shape, VTK of the winner).

Running the same settings into the same folder again resumes: the GA replays with the same
seed and the evaluation cache answers every design solved before. Ctrl-C stops the run
after the files written so far are flushed; :attr:`RunResult.status` is then
``"interrupted"``.
"""

from __future__ import annotations

import csv
import json
import platform
import time
import tomllib
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path
from typing import Any

from pneumorph.design.certified import CertifiedResult, certified_search, chain_candidate
from pneumorph.design.config import DesignConfig, to_toml
from pneumorph.design.exhaustive import run_exhaustive
from pneumorph.design.figures import plot_convergence, plot_profile
from pneumorph.design.fitness import Score
from pneumorph.design.ga import GenerationStats, run_ga
from pneumorph.design.scoring import Candidate
from pneumorph.design.targets import Objective, ProfileTarget
from pneumorph.errors import PneumorphError, RunFolderError, SearchConfigError
from pneumorph.execution.cache import (
    CachedEvaluator,
    EvaluationCache,
    default_cache_path,
)
from pneumorph.execution.evaluators import Evaluator, make_evaluator
from pneumorph.models.chain import ChainModel, design_strings
from pneumorph.models.chaintables import find_table, table_for
from pneumorph.models.factory import make_model
from pneumorph.models.response import ActuatorModel

DEPENDENCIES = ("numpy", "scipy", "felupe", "tensortrax", "deap", "matplotlib", "distributed")
_COMPARED = ("design", "ga", "model")


def _version(name: str) -> str | None:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return None


def provenance(config: DesignConfig, model: ActuatorModel) -> dict[str, Any]:
    """Where a run comes from: versions, date, seed, model identity."""
    return {
        "pneumorph": _version("pneumorph") or "unknown",
        "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "seed": config.seed,
        "model_fidelity": str(getattr(model, "fidelity", "unknown")),
        "model_fingerprint": model.fingerprint(),
        "model_units": int(model.n_units),
        "pressures_kPa": [round(float(p) * 1e3, 9) for p in model.pressures()],
        "python": platform.python_version(),
        "platform": platform.platform(),
        "dependencies": {name: v for name in DEPENDENCIES if (v := _version(name)) is not None},
    }


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
    files : tuple of Path
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

    @property
    def best(self) -> Candidate | None:
        """The winner: the FE-verified one of a certified search, else the first of the hall of fame."""
        if self.certified is not None:
            return self.certified.winner
        return self.hall_of_fame[0] if self.hall_of_fame else None


def _check_folder(folder: Path, config: DesignConfig, fingerprint: str, overwrite: bool) -> bool:
    """True if ``folder`` holds the same run (resume); an error if it holds another one."""
    path = folder / "config.toml"
    if not path.exists() or overwrite:
        return False
    old = tomllib.loads(path.read_text(encoding="utf-8"))
    new = config.to_dict()
    for table in _COMPARED:
        if old.get(table, {}) != new.get(table, {}):
            raise RunFolderError(
                f"{folder} holds a run with other [{table}] settings ({old.get(table)} instead of "
                f"{new.get(table)}); choose another output folder or overwrite it"
            )
    old_fp = old.get("provenance", {}).get("model_fingerprint")
    if old_fp not in (None, fingerprint):
        raise RunFolderError(
            f"{folder} holds a run of another model (fingerprint {old_fp}, now {fingerprint}); "
            "choose another output folder or overwrite it"
        )
    return True


class _GenerationLog:
    """``generations.csv``, one flushed row per generation."""

    FIELDS = tuple(GenerationStats.__dataclass_fields__)

    def __init__(self, path: Path) -> None:
        self.file = path.open("w", newline="", encoding="utf-8")
        self.writer = csv.DictWriter(self.file, fieldnames=self.FIELDS)
        self.writer.writeheader()
        self.file.flush()
        self.rows: list[GenerationStats] = []

    def __call__(self, stats: GenerationStats) -> None:
        self.rows.append(stats)
        self.writer.writerow(stats.as_row())
        self.file.flush()

    def close(self) -> None:
        self.file.close()


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
) -> RunResult:
    """Run a design search and write its folder.

    Parameters
    ----------
    config : DesignConfig
    model : ActuatorModel
        Built for ``config`` (its ``n_units`` must equal ``config.units``).
    folder : str or Path
        The run folder; created if missing; resumed if it holds the same run.
    evaluator : Evaluator, optional
        By default made from ``config.executor`` (and closed at the end).
    cache : EvaluationCache, optional
        By default opened at ``config.cache`` or :func:`default_cache_path`.
    on_generation, on_progress, on_message : callable, optional
        Progress callbacks: a GA generation's stats; exhaustive (done, total); a line of
        text from the certified search (table build, scoring, verification).
    overwrite : bool
        Start afresh in a folder that holds another run.
    figures : bool
        Draw the figures (and call the model's ``write_deformed`` hook).

    Returns
    -------
    RunResult

    Raises
    ------
    SearchConfigError
        The model's number of units differs from the config's.
    RunFolderError
        The folder holds another run and ``overwrite`` is not set.
    """
    folder = Path(folder)
    if int(model.n_units) != config.units:
        raise SearchConfigError(f"the model has {model.n_units} units but the config asks for {config.units}")
    objective = config.make_objective()
    fingerprint = model.fingerprint()
    resumed = _check_folder(folder, config, fingerprint, overwrite)
    say = on_message or (lambda text: None)
    table_dir = None
    if config.search == "certified":
        if getattr(model, "gravity", None) is not None:
            from pneumorph.errors import LocalityError

            raise LocalityError("the certified search needs a free actuator (its chain model does not hold under "
                                "gravity); search with --search ga or exhaustive")
        if config.units < 3:
            raise SearchConfigError(f"the certified search needs at least 3 units (a window of +-1), got "
                                    f"{config.units}; use --search exhaustive")
        if config.chain_table is not None:  # check a given table before anything is written
            table = table_for(model, _training(model), path=config.chain_table)
            ChainModel(table, config.units)

    own_evaluator = evaluator is None
    inner = evaluator or make_evaluator(config.executor, config.workers, config.scheduler)
    own_cache = cache is None
    cache = cache or EvaluationCache(config.cache or default_cache_path())
    if cache.path != ":memory:":
        table_dir = Path(cache.path).parent / "chain-tables"
    cached = CachedEvaluator(inner, cache)
    chain = None
    if config.search == "certified":
        # the table (built on first use, through the cache) before the folder is claimed: a model the
        # chain cannot represent leaves nothing behind
        try:
            table = table_for(model, _training(model), folder=table_dir, path=config.chain_table, evaluator=cached,
                              on_progress=say)
            chain = ChainModel(table, config.units)
        except BaseException:
            if own_evaluator:
                inner.close()
            if own_cache:
                cache.close()
            raise
    folder.mkdir(parents=True, exist_ok=True)
    prov = provenance(config, model)
    prov["resumed"] = resumed
    if chain is not None:
        prov["chain_table"] = chain.table.fingerprint()
    (folder / "config.toml").write_text(to_toml({**config.to_dict(), "provenance": prov}), encoding="utf-8")
    start = time.perf_counter()
    log = _GenerationLog(folder / "generations.csv") if config.search == "ga" else None

    def on_gen(stats: GenerationStats) -> None:
        log(stats)  # type: ignore[misc]
        if on_generation:
            on_generation(stats)

    status, hof, history, ranking, cert = "finished", (), (), None, None
    try:
        if config.search == "ga":
            ga = run_ga(model, objective, config.ga, cached, on_gen)
            hof, history = ga.hall_of_fame, ga.history
        elif config.search == "certified":
            assert chain is not None
            verify = config.verify or int(getattr(inner, "workers", 1) or 1)
            cert = certified_search(model, chain, objective, cached, verify=verify, certify=config.certify,
                                    hall_of_fame=config.ga.hall_of_fame, margin=config.margin, on_progress=say)
            hof = cert.hall_of_fame
            order = cert.scores.order()[:1000]
            names = design_strings(cert.scores.bits[order])
            ranking = [(d, _chain_score(cert, i)) for d, i in zip(names, order)]
        else:
            ex = run_exhaustive(model, objective, cached, hall_of_fame=config.ga.hall_of_fame, on_progress=on_progress)
            hof, ranking = ex.hall_of_fame, [(d, ex.scores[d]) for d in ex.ranking]
    except KeyboardInterrupt:
        status = "interrupted"
        history = tuple(log.rows) if log else ()
    finally:
        if log:
            log.close()
        if own_evaluator:
            inner.close()
        if own_cache:
            cache.close()
    opinion = _opinion_2d(config, model, objective, cert) if cert is not None else {}
    result = RunResult(status, folder, objective, tuple(hof), tuple(history), cached.solves, cached.hits,
                       time.perf_counter() - start, certified=cert, opinion_2d=opinion)
    files = _write_outputs(result, config, model, ranking, figures)
    return replace(result, files=tuple(files))


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
    """The 2D reduced-order model's values of the listed designs (its shipped chain table), if it has one."""
    if getattr(model, "fidelity", None) != "3d":
        return {}
    try:
        model2d = make_model(config.units, {**config.model, "fidelity": "2d"})
        table = find_table(model2d)
    except PneumorphError:
        return {}
    if table is None:
        return {}
    chain = ChainModel(table, config.units)
    designs = dict.fromkeys([cert.winner.design, *(c.design for c in cert.hall_of_fame)])
    return {d: chain_candidate(chain, objective, d).value for d in designs}


def _write_outputs(
    result: RunResult, config: DesignConfig, model: ActuatorModel, ranking: Any, figures: bool
) -> list[Path]:
    folder, files = result.folder, []
    if result.history:
        files.append(folder / "generations.csv")
    if ranking is not None:
        path = folder / "ranking.csv"
        with path.open("w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["rank", "design", "value", "level", "pressure_kPa", "failed"])
            for i, (d, s) in enumerate(ranking, 1):
                p = "" if s.pressure is None else round(s.pressure * 1e3, 9)
                w.writerow([i, d, s.value, "" if s.level is None else s.level, p, s.failed])
        files.append(path)
    if result.hall_of_fame:
        path = folder / "hall_of_fame.json"
        entries = [{"rank": i, **c.to_dict()} for i, c in enumerate(result.hall_of_fame, 1)]
        doc = {"objective": result.objective.label, "sense": result.objective.sense,
               "unit": result.objective.unit, "designs": entries}
        path.write_text(json.dumps(doc, indent=1), encoding="utf-8")
        files.append(path)
    cert = result.certified
    if cert is not None:
        files += _write_certificate(result, folder)
    best = result.best
    if figures and best is not None and best.response is not None and best.level is not None:
        files.append(plot_profile(best, result.objective, folder / "profile.png"))
        if cert is not None:
            files.append(plot_profile(best, result.objective, folder / "chain-vs-fe.png",
                                      compare=[("chain model", cert.winner_chain)]))
        hook = getattr(model, "write_deformed", None)
        if callable(hook) and cert is None:  # a certified run does not solve its winner a second time
            files.extend(Path(p) for p in hook(best.response, best.level, folder / "winner"))
    if figures and result.history:
        files.append(plot_convergence(result.history, folder / "convergence.png", result.objective.unit))
    path = folder / "report.md"
    names = [f.relative_to(folder).as_posix() if f.is_relative_to(folder) else f.name for f in files]
    path.write_text(report_text(result, config, model, names), encoding="utf-8")
    files.append(path)
    return files


def _top_rows(result: RunResult) -> list[dict[str, Any]]:
    """The listed designs by chain value with their FE and 2D values."""
    cert = result.certified
    assert cert is not None
    rows = []
    for i, c in enumerate(cert.hall_of_fame, 1):
        fe = cert.verified.get(c.design)
        rows.append({
            "rank_chain": i, "design": c.design, "chain": c.value,
            "chain_pressure_kPa": None if c.pressure is None else round(c.pressure * 1e3, 9),
            "fe": None if fe is None or fe.failure else fe.value,
            "fe_pressure_kPa": None if fe is None or fe.pressure is None else round(fe.pressure * 1e3, 9),
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
    path = folder / "certificate.json"
    path.write_text(json.dumps(doc, indent=1, default=float), encoding="utf-8")
    top = folder / "top.csv"
    with top.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return [path, top]


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
    }[config.search]
    lines += [
        f"- objective: {o.label} ({'minimised' if o.sense == 'min' else 'maximised'})",
        f"- actuator: {config.units} units, model {getattr(model, 'fidelity', '?')} ({model.fingerprint()})",
        f"- search: {search}",
        (f"- new solves: {result.solves}, answered by the cache: {result.cache_hits}, "
        f"wall time {result.wall_time:.1f} s"),
        "",
    ]
    best = result.best
    if best is not None:
        what = "error (Eq 4.1)" if isinstance(o, ProfileTarget) else "value"
        pressure = "-" if best.pressure is None else f"{best.pressure * 1e3:.4g} kPa"
        if best.failure is not None:
            lines += [f"**No design converged.** The best entry failed: {best.failure}", ""]
        lines += [
            "## Winner",
            "",
            f"- design (base first): `{best.design}`",
            f"- pressure: {pressure}",
            f"- {what}: {best.value:.6g} {o.unit}",
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
        c = cert.certificate
        u = o.unit
        verdict = ("**certified**: no unverified design can beat the winner" if c["certified"] else
                   f"not certified: {c['could_beat']} unverified design(s) could beat the winner by up to "
                   f"{c['gap']:.3g} {u}; run with --certify to verify them")
        lines += [
            "## Certificate",
            "",
            f"- designs scored by the chain model: {c['designs_scored']:,}"
            + ("" if c["complete"] else " (branch-and-bound; every other design is worse by the chain)"),
            f"- verified by FE ({getattr(model, 'fidelity', '?')}): {', '.join(f'`{d}`' for d in c['verified'])}",
            f"- bound on the chain's objective error: {c['bound']:.3g} {u} (validated centre errors x {c['margin']:g})",
            f"- {verdict}",
            "",
            f"| chain rank | design | chain ({u}) | FE ({u}) | 2D chain ({u}) | pressure (kPa) |",
            "|---:|---|---:|---:|---:|---:|",
        ]

        def fmt(v: Any) -> str:
            return "-" if v is None else f"{v:.4g}"

        for row in _top_rows(result):
            lines.append(f"| {row['rank_chain']} | `{row['design']}` | {fmt(row['chain'])} | {fmt(row['fe'])} | "
                         f"{fmt(row['chain_2d'])} | {fmt(row['fe_pressure_kPa'] or row['chain_pressure_kPa'])} |")
        lines.append("")
    if files:
        lines += ["## Files", "", *[f"- [{f}]({f})" for f in files], ""]
    return "\n".join(lines)
