"""A design run's result and the files it writes: hall of fame, ranking, certificate, robustness,
figures, the winner solved again with its fields, and the markdown report.

Every result file is written to a temporary file and renamed over the old one; JSON is
strict; the report is written last and lists the files.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from pneumorph.design.certified.certificate import certificate_text
from pneumorph.design.certified.search import CertifiedResult
from pneumorph.design.runs.comparison import comparison_lines
from pneumorph.design.config import DesignConfig
from pneumorph.design.runs.figures import plot_convergence, plot_profile
from pneumorph.design.objectives.fitness import stage_values
from pneumorph.design.search.genetic import GenerationStats
from pneumorph.design.runs.pathfigure import placed_path
from pneumorph.design.objectives.paths import PathTarget
from pneumorph.design.search.scoring import Candidate
from pneumorph.design.objectives.targets import Objective, ProfileTarget, StagedTarget
from pneumorph.io.files import atomic_path, atomic_write_text, write_json
from pneumorph.models.response import ActuatorModel


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
        (:func:`pneumorph.design.certified.refine.refine_verified`).
    comparison : dict or None
        With a reference model (``design --model-file``): the nominal model's optimum judged
        by this model (:func:`pneumorph.design.runs.comparison.compare_with_reference`).
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
    comparison: dict[str, Any] | None = None

    @property
    def best(self) -> Candidate | None:
        """The winner: the most robust design of a ``robust`` run (FE-verified), the FE-verified one of a
        certified search, else the first of the hall of fame."""
        if self.robust_winner is not None:
            return self.robust_winner
        if self.certified is not None:
            return self.certified.winner
        return self.hall_of_fame[0] if self.hall_of_fame else None

    def summary(self) -> dict[str, Any]:
        """The result as plain data, as ``pneumorph design --json`` prints it (pressures in kPa, values in the
        objective's unit; the certificate, the top designs and the 2D model's opinion of a certified run)."""
        def kpa(pressure: float | None) -> float:
            return float("nan") if pressure is None else pressure * 1e3

        best = self.best
        out: dict[str, Any] = {
            "status": self.status, "folder": str(self.folder), "objective": self.objective.label,
            "best": None if best is None else {"design": best.design, "pressure_kpa": kpa(best.pressure),
                                               "fitness": best.value},
            "hall_of_fame": [{"design": c.design, "pressure_kpa": kpa(c.pressure), "fitness": c.value,
                              "failure": c.failure} for c in self.hall_of_fame],
            "search": self.search, "search_note": self.search_note, "retried": self.retried,
            "solves": self.solves, "cache_hits": self.cache_hits, "wall_time_s": self.wall_time,
            "cache_entries_rejected": self.rejected,
            "robustness": None if self.robustness is None else
            {k: v for k, v in self.robustness.items() if k not in ("offsets_mm", "winner_values")},
            "mesh": self.refinement,
            "comparison": self.comparison,
        }
        if isinstance(self.objective, ProfileTarget | PathTarget) and best is not None and best.response is not None:
            out["rms_per_centre_mm"] = best.value / best.response.n_units ** 0.5  # Eq 4.1 per centre (SPADA's figure)
        if isinstance(self.objective, PathTarget) and best is not None and best.response is not None:
            out["path"] = [list(p) for p in placed_path(self.objective, best.response).points]  # as drawn for it
        if self.certified is not None:
            out.update(certificate=self.certified.certificate, top=_top_rows(self), opinion_2d=self.opinion_2d)
        return out


def _atomic_figure(path: Path, draw: Callable[[Path], Any]) -> Path:
    """Draw a figure into a temporary file beside ``path`` (same suffix, for its format), then rename it."""
    with atomic_path(path) as tmp:
        draw(tmp)
    return path


def value_words(objective: Objective, value: float, units: int) -> str:
    """A winner's value in words with its unit: Eq 4.1 and its RMS per centre for a profile or a path.

    >>> from pneumorph.design.objectives.targets import make_objective
    >>> value_words(make_objective("hook"), 6.0, 9).split("; ")[1]
    '2 mm RMS per centre)'
    """
    if isinstance(objective, ProfileTarget):
        return (f"error {value:.4g} {objective.unit} (Eq 4.1: root of the summed squared offsets of the {units} "
                f"unit centres from the target; {value / units**0.5:.3g} {objective.unit} RMS per centre)")
    if isinstance(objective, PathTarget):
        return (f"path error {value:.4g} mm (root of the summed squared distances of the {units} unit centres from "
                f"their stretches of the path; {value / units**0.5:.3g} mm RMS per centre)")
    return f"{objective.name} {value:.4g} {objective.unit}"


def _path_lines(objective: Objective, best: Candidate, units: int) -> list[str]:
    """A path's value per centre, and its length beside the line through the winner's centres (one line each)."""
    if not isinstance(objective, PathTarget) or best.response is None or best.level is None \
            or not math.isfinite(best.value):
        return []
    r = best.response
    route = placed_path(objective, r)
    centres = r.centres[best.level]
    line = float(np.linalg.norm(np.diff(centres, axis=0), axis=1).sum())
    return [f"- RMS distance per centre: {best.value / units**0.5:.3g} mm (the root of the summed squared distances of "
            f"the {units} unit centres, as the model reports them, from their stretches of the path)",
            f"- the path: {len(route.points)} points, {route.arc_length():.4g} mm long; the line through the winner's "
            f"centres {line:.4g} mm (the actuator {float(r.reference_tip[0]):.4g} mm undeformed)"]


def _stage_lines(objective: Objective, best: Candidate) -> list[str]:
    """A staged winner's value at each stage, one report line each (none for other objectives)."""
    if not isinstance(objective, StagedTarget) or best.response is None or not best.response.converged:
        return []
    values = stage_values(best.response, objective)
    return [f"  - stage at {stage.pressure * 1e3:g} kPa (weight {stage.weight:g}): {v:.4g} mm "
            f"({'Eq 4.1' if isinstance(stage.target, ProfileTarget) else 'tip to the point'}, {stage.target.label})"
            for stage, v in zip(objective.stages, values, strict=True)]


def _csv_text(header: list[str], rows: Any) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    writer.writerow(header)
    writer.writerows(rows)
    return buffer.getvalue()


def write_outputs(
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
    files.append(write_report(result, config, model, files))


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


def write_report(result: RunResult, config: DesignConfig, model: ActuatorModel, files: list[Path]) -> Path:
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


def _contact_lines(model: ActuatorModel, objective: Any = None) -> list[str]:
    """How a run over obstacles measured and searched: by FE with contact on every design solved, nothing of the
    grip certified; with a clearance, the designs the chain's bound rejected (certified not to clear)."""
    obstacles = getattr(model, "obstacles", ())
    if not obstacles:
        return []
    tables = "; ".join(", ".join(f"{k} {v}" for k, v in o.to_dict().items()) for o in obstacles)
    clear = getattr(objective, "clear", None)
    lines = [f"- contact: obstacles {tables}. Every design searched{' but those rejected below' if clear else ''} "
             "was solved by FE with contact and scored by what that solve reports; the chain model knows no contact, "
             f"so nothing {'of the grip ' if clear else ''}is certified: the winner is the best of the designs "
             "searched"]
    if clear is not None:
        lines.append(f"- clearing: {clear.label}. Certified by the chain's bound: a design whose free shape by the "
                     "chain comes closer than the clearance less the chain's validated error cannot clear; it was "
                     "rejected without a solve (its failure says so). Searched by FE with contact: the clearance "
                     "and the grip of every other design (a design that does not clear scores as failed)")
    return lines


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
    }.get(result.search or config.search, result.search)  # another algorithm (run_design's algorithm): its name
    if result.search_note:  # a certified run's choice: its table and levels, or why it searched exhaustively
        search = result.search_note
    lines += [
        f"- objective: {o.label} ({'minimised' if o.sense == 'min' else 'maximised'})",
        f"- actuator: {config.units} units, model {getattr(model, 'fidelity', '?')} ({model.fingerprint()})",
        f"- search: {search}",
        *_contact_lines(model, o),
        (f"- new solves: {result.solves}, answered by the cache: {result.cache_hits}, "
        f"wall time {result.wall_time:.1f} s"
         + (f"; {result.rejected} damaged cache entries were solved again, not used" if result.rejected else "")),
        "",
    ]
    best = result.best
    if best is not None:
        what = ("error (Eq 4.1)" if isinstance(o, ProfileTarget) else
                "path error (Eq 4.1 over the path)" if isinstance(o, PathTarget) else
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
            *_path_lines(o, best, config.units),
            *_stage_lines(o, best),
            "",
            "## Hall of fame",
            "",
            *(["The chain model's values (the winner's above and the verified designs' below are by FE).", ""]
              if result.certified is not None else []),
            f"| rank | design | {'chain' if result.certified is not None else 'FE'} ({o.unit}) | pressure (kPa) |",
            "|---:|---|---:|---:|",
        ]
        for i, c in enumerate(result.hall_of_fame, 1):
            p = "failed" if c.pressure is None else f"{c.pressure * 1e3:.4g}"
            lines.append(f"| {i} | `{c.design}` | {c.value:.6g} | {p} |")
        lines.append("")
    if result.certified is not None:
        lines += _certificate_lines(result, model)
    if result.comparison is not None:
        lines += ["## The nominal model's design", "", *[f"- {line}" for line in comparison_lines(result.comparison)],
                  ""]
    if result.refinement is not None:
        lines += _refinement_lines(result.refinement, o)
    if result.robustness is not None:
        lines += _robustness_lines(result.robustness, o)
    if files:
        lines += ["## Files", "", *[f"- [{f}]({f})" for f in files], ""]
    return "\n".join(lines)


def _certificate_lines(result: RunResult, model: ActuatorModel) -> list[str]:
    """The report's certificate: in words, and the chain's best designs with their FE and 2D values."""
    cert = result.certified
    assert cert is not None
    sure, u = cert.certificate, result.objective.unit
    words = certificate_text(sure, u, cert.winner.design, getattr(model, "fidelity", None), show=len(sure["verified"]))
    lines = ["## Certificate", "", *[f"- {line}" for line in words], "",
             f"| chain rank | design | chain ({u}) | FE ({u}) | 2D chain ({u}) | pressure (kPa) |",
             "|---:|---|---:|---:|---:|---:|"]

    def fmt(v: Any) -> str:
        return "-" if v is None else f"{v:.4g}"

    for row in _top_rows(result):
        lines.append(f"| {row['rank_chain']} | `{row['design']}` | {fmt(row['chain'])} | {fmt(row['fe'])} | "
                     f"{fmt(row['chain_2d'])} | {fmt(row['fe_pressure_kpa'] or row['chain_pressure_kpa'])} |")
    return [*lines, ""]


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
