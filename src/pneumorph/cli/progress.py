"""The command line's side of the progress contract (:mod:`pneumorph.io.progress`): every long command's lines
go to standard error through one reporter, whose heartbeat speaks in any silence; results stay on standard
output (its JSON modes clean)."""

from __future__ import annotations

import math
import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

if TYPE_CHECKING:
    from pneumorph.io.progress import Progress


def reporter(quiet: bool = False) -> Progress:
    """A reporter writing each line to standard error (``with reporter() as say:`` runs its heartbeat); with
    ``quiet`` (a command's ``-q``) one that says nothing.

    The heartbeat speaks after :data:`~pneumorph.io.progress.HEARTBEAT` seconds of silence, or after the seconds
    in the environment variable ``PNEUMORPH_HEARTBEAT`` (a log file may want fewer lines; the contract's test
    a shorter beat). Standard output is the results' alone, so a command's ``--json`` keeps these lines."""
    from pneumorph.io.progress import HEARTBEAT, Progress

    if quiet:
        return Progress(lambda line: None, heartbeat=0)

    text = os.environ.get("PNEUMORPH_HEARTBEAT", "").strip()
    heartbeat = HEARTBEAT
    if text:
        try:
            heartbeat = float(text)
        except ValueError:
            heartbeat = float("nan")
        if not (math.isfinite(heartbeat) and heartbeat > 0):
            raise click.UsageError(f"PNEUMORPH_HEARTBEAT={text!r}: give the seconds of silence after which a long "
                                   "command says it is still running, a number > 0 (default 7)")
    return Progress(lambda line: click.echo(line, err=True), heartbeat=heartbeat)


def plan_solves(lines: Progress, what: str, total: int, model: Any, executor: str, workers: int | None,
                where: str | None = None, title: str | None = None) -> None:
    """Say the plan of ``total`` FE solves of ``model`` (estimated by its fidelity's measured solve time, among
    the workers the execution options make) and start counting them (:meth:`Progress.plan`)."""
    from types import SimpleNamespace

    from pneumorph.design.certified.planning import planned_workers
    from pneumorph.models.chain.plan import model_seconds

    each = model_seconds(model)
    lines.plan(what, total, each=each, workers=planned_workers(SimpleNamespace(executor=executor, workers=workers)),
               where=where, title=title)


def solve_levels(model: Any, design: str, what: str, title: str, where: str | None = None) -> Any:
    """Solve ``design`` on ``model``, saying the plan (its levels, estimated by its fidelity's measured solve time
    and, for a volume-controlled ramp, its measured cost) and counting each level as it converges; the
    :class:`~pneumorph.models.fe.solving.Solution`."""
    from pneumorph.models.chain.plan import model_seconds, ramp_note

    each, levels = model_seconds(model, len(design)), len(model.pressures())
    with reporter() as lines:
        lines.plan(what, levels, each=None if each is None else each / levels, noun="levels", where=where,
                   title=title)
        if note := ramp_note(model):
            lines.say(f"  {note}")
        return model.solve(design, on_level=lambda k, p: lines.count(k + 1, f"{p * 1e3:7.3f} kPa converged",
                                                                      always=True))


class RunLines:
    """A design run's lines on stderr, through the command's reporter (:func:`reporter`): its
    first line once it has started (an error before it stays one line), then the GA's generations with the time
    left at the measured rate, the exhaustive search's plan (designs, estimate) and count, and the certified
    search's messages."""

    def __init__(self, config: Any, model: Any, folder: str | Path, lines: Any) -> None:
        self.config, self.model, self.folder, self.lines = config, model, folder, lines
        objective = config.make_objective()
        self.label, self.unit = objective.label, objective.unit
        self.said = self.counting = False
        self.started = 0.0

    def announce(self) -> None:
        if not self.said:
            self.said, self.started = True, time.perf_counter()
            c = self.config
            units = f"{c.units} unit{'s' if c.units != 1 else ''}"
            self.lines.say(f"designing {units} for {self.label} ({self.model.fidelity} model, {c.search}, "
                           f"executor {c.executor}) -> {self.folder}")

    def on_generation(self, stats: Any) -> None:
        from pneumorph.io.progress import duration_text

        self.announce()
        total, done = self.config.ga.generations, stats.generation
        bar = "#" * int(20 * done / max(total, 1))
        each = (time.perf_counter() - self.started) / (done + 1)  # generation 0 is the first population's
        left = f"; about {duration_text(each * (total - done))} left" if done < total else ""
        self.lines.say(f"  [{bar:<20}] generation {done:2d}/{total}: {stats.describe(self.unit)}{left}")

    def on_progress(self, done: int, total: int) -> None:
        self.announce()
        if not self.counting:  # before the first solve: the plan, estimated by the model's measured solve time
            from pneumorph.design.certified.planning import planned_workers
            from pneumorph.design.search.exhaustive import mirror_holds
            from pneumorph.models.chain.plan import model_seconds

            self.counting = True
            each = model_seconds(self.model)
            mirrored = mirror_holds(self.model)
            if each is not None and mirrored:
                each /= 2  # a solve scores a design and its mirror
            noun = "designs (a solve scores a design and its mirror)" if mirrored else "designs"
            self.lines.plan("exhaustive search", total, each=each, workers=planned_workers(self.config), noun=noun,
                            done=done)
            return
        self.lines.count(done)

    def on_message(self, text: str) -> None:
        self.announce()
        self.lines.say(f"  {text}")

    def callbacks(self) -> dict[str, Any]:
        return {"on_generation": self.on_generation, "on_progress": self.on_progress, "on_message": self.on_message}


__all__ = ["RunLines", "plan_solves", "reporter", "solve_levels"]
