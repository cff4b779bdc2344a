"""One build of a table at a time: a lock on its file, the second process waits and reuses what the first built.

A chain table (:func:`~pneumorph.models.chain.sources.table_for`) and a unit's tolerance tables
(:func:`~pneumorph.sensitivity.robust.tolerance_tables_for`) are built through :func:`build_once`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from pneumorph.errors import ChainTableError
from pneumorph.io.lock import FileLock

__all__ = ["build_once"]

T = TypeVar("T")


def build_once(target: Path, find: Callable[[], T | None], build: Callable[[], T],
               on_progress: Callable[[str], None] | None = None, what: str | None = None) -> T:
    """``find()``, else ``build()``, under a lock on ``target`` (``<target>.lock``): built once for all processes.

    A process that finds the lock held waits for it (saying once that it waits, and for
    whom), then looks again: the table the holder built is reused (saying so) and nothing is
    built twice. ``build`` is expected to write ``target``; the lock is given back however
    it ends (a killed holder's lock is released by the operating system).

    Parameters
    ----------
    target : Path
        The file built; its folder is created.
    find : callable
        Returns what is there already (or None); called again under the lock.
    build : callable
        Builds (and writes) it.
    what : str, optional
        What is built, for the messages (default: the file's name).

    Examples
    --------
    >>> import tempfile
    >>> target = Path(tempfile.mkdtemp()) / "t.json"
    >>> def make():
    ...     target.write_text("1")
    ...     return 1
    >>> build_once(target, lambda: None, make), build_once(target, lambda: 2 if target.exists() else None, make)
    (1, 2)
    """
    say = on_progress or (lambda text: None)
    name = what or target.name
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ChainTableError(f"{name}: cannot create its folder {target.parent} ({exc.strerror or exc})") from None
    lock = FileLock(target.with_name(target.name + ".lock"), name)
    waited: list[str] = []

    def on_wait(holder: str) -> None:
        waited.append(holder)
        say(f"waiting for {name}: another process builds it ({holder})")

    lock.acquire(wait=True, on_wait=on_wait)
    try:
        found = find()
        if found is not None:
            if waited:
                say(f"{name} was built meanwhile by {waited[0].split(',')[0]}: reusing it")
            return found
        return build()
    finally:
        lock.release()
