"""Where a command's designs are solved: the one option set (``--executor``, ``--workers``,
``--scheduler``) of every command that solves more than a handful of designs.

- :func:`execution_options` adds the three options to a command;
- :func:`check_options` refuses, before anything is computed, the combinations that would
  be ignored (``--scheduler`` without ``--executor dask``, ``--workers`` with ``serial`` or
  with a scheduler): one line, exit 2;
- :func:`open_evaluator` makes the evaluator (:func:`pneumorph.execution.make_evaluator`)
  behind the evaluation cache, its lines about the cluster (a lost worker, the designs
  retried) printed as progress;
- :func:`cluster_report` says what the cluster did, for a command's report and JSON.

docs/cluster.md describes running on a Dask cluster.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import click

from pneumorph.checks import EXECUTORS
from pneumorph.cli.options import params as P

NAMES = ("--executor", "--workers", "--scheduler")


def execution_options(default: str | None = "processes", what: str = "designs") -> Callable[[Any], Any]:
    """Add ``--executor``, ``--workers`` and ``--scheduler`` to a command (``default`` executor; None: unset).

    Examples
    --------
    >>> @click.command()
    ... @execution_options()
    ... def run(executor, workers, scheduler):
    ...     click.echo(f"{executor} {workers} {scheduler}")
    >>> from click.testing import CliRunner
    >>> CliRunner().invoke(run, ["--executor", "dask", "--scheduler", "tcp://10.0.0.5:8786"]).output
    'dask None tcp://10.0.0.5:8786\\n'
    """
    options = [
        click.option("--executor", type=click.Choice(EXECUTORS), default=default, show_default=default is not None,
                     help=f"Where the {what} are solved: one after another in this process (serial), a pool of "
                          "processes on this machine, or a Dask cluster (dask; documentation page cluster, "
                          "docs/cluster.md in the source)"
                          + ("" if default is not None else "; default processes") + "."),
        click.option("--workers", type=P.WORKERS,
                     help="Processes of the pool, or workers of a local Dask cluster (default: all cores); "
                          "not with serial or --scheduler."),
        click.option("--scheduler", metavar="ADDR", type=P.ADDRESS,
                     help="With --executor dask: the scheduler of a Dask cluster (tcp://host:8786; documentation page "
                          "cluster, docs/cluster.md in the source); default a local cluster on this machine."),
    ]

    def decorate(command: Any) -> Any:
        for option in reversed(options):
            command = option(command)
        return command

    return decorate


def check_options(executor: str | None, workers: int | None, scheduler: str | None) -> None:
    """Refuse settings that would be ignored as a usage error (one line, exit 2), before any work.

    Examples
    --------
    >>> check_options("processes", 2, None)
    >>> check_options("serial", None, "tcp://10.0.0.5:8786")
    Traceback (most recent call last):
    ...
    click.exceptions.UsageError: --scheduler only applies to --executor dask, not to serial
    """
    from pneumorph.errors import SearchConfigError
    from pneumorph.execution.evaluators import check_execution

    try:
        check_execution(executor or "processes", workers, scheduler, NAMES)
    except SearchConfigError as exc:
        raise click.UsageError(str(exc)) from None


def say(text: str) -> None:
    """A progress line about the cluster, on stderr."""
    click.echo(f"  {text}", err=True)


def open_evaluator(executor: str, workers: int | None, scheduler: str | None, cache: str | None) -> Any:
    """The command's evaluator: ``executor`` behind the evaluation cache (``cache`` or the default file).

    Connects to the cluster at once (an unreachable scheduler or workers of another
    pneumorph version end the command here, one line, exit 2).
    """
    from pneumorph.execution import CachedEvaluator, EvaluationCache, default_cache_path, make_evaluator

    check_options(executor, workers, scheduler)
    inner = make_evaluator(executor, workers, scheduler, on_message=say)
    try:
        return CachedEvaluator(inner, EvaluationCache(cache or default_cache_path()))
    except BaseException:
        inner.close()
        raise


def cluster_report(evaluator: Any) -> dict[str, int] | None:
    """What the Dask cluster did (``retried`` designs, ``lost_workers``), or None for another executor.

    Examples
    --------
    >>> from pneumorph.execution import SerialEvaluator
    >>> cluster_report(SerialEvaluator()) is None
    True
    """
    inner = getattr(evaluator, "inner", evaluator)
    if not hasattr(inner, "retried"):
        return None
    return {"retried": int(inner.retried), "lost_workers": int(inner.lost_workers)}


def cluster_line(evaluator: Any) -> str | None:
    """One line on the designs retried after lost workers (None if none were lost).

    Examples
    --------
    >>> from pneumorph.execution import SerialEvaluator
    >>> cluster_line(SerialEvaluator()) is None
    True
    """
    report = cluster_report(evaluator)
    if not report or not report["lost_workers"]:
        return None
    return (f"{report['lost_workers']} Dask worker(s) lost during the run; {report['retried']} design(s) they were "
            "solving or held queued were retried on the others")
