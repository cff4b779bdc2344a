"""A persistent evaluation cache (SQLite): no design is solved twice for the same model.

Entries are keyed by ``(model fingerprint, design)``. A converged solve stores its
:class:`~pneumorph.models.Response` as JSON; a failed solve stores its cause and the
pressure it reached (and the partial response, if the model returned one). The database
runs in WAL mode, so several processes can read it while one writes; every entry is
committed as soon as it is put, so a killed run loses nothing it had finished.
"""

from __future__ import annotations

import json
import os
import sqlite3
import threading
import time
from collections.abc import Iterable, Iterator
from datetime import UTC, datetime
from pathlib import Path
from typing import Self

from pneumorph.execution.outcome import Outcome
from pneumorph.models.response import ActuatorModel, Response

_SCHEMA = """
CREATE TABLE IF NOT EXISTS evaluations (
    fingerprint TEXT NOT NULL,
    design TEXT NOT NULL,
    status TEXT NOT NULL CHECK (status IN ('ok', 'failed')),
    response TEXT,
    cause TEXT,
    reached REAL,
    wall_time REAL,
    created TEXT NOT NULL,
    PRIMARY KEY (fingerprint, design)
)
"""


def default_cache_path() -> Path:
    """``$PNEUMORPH_CACHE``, else ``$XDG_CACHE_HOME/pneumorph/evaluations.sqlite`` (``~/.cache``)."""
    if os.environ.get("PNEUMORPH_CACHE"):
        return Path(os.environ["PNEUMORPH_CACHE"])
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "pneumorph" / "evaluations.sqlite"


class EvaluationCache:
    """Outcomes of solved designs, persisted in an SQLite file.

    Parameters
    ----------
    path : str or Path
        The database file (created with its folder if missing); ``":memory:"`` for a
        throw-away cache.

    Examples
    --------
    >>> cache = EvaluationCache(":memory:")
    >>> cache.put("abc", Outcome("0110", None, failure="diverged", reached=0.03))
    >>> hit = cache.get("abc", "0110")
    >>> hit.failure, hit.reached, hit.cached
    ('diverged', 0.03, True)
    >>> cache.get("other-model", "0110") is None
    True
    """

    def __init__(self, path: str | Path) -> None:
        self.path = str(path)
        if self.path != ":memory:":
            Path(self.path).parent.mkdir(parents=True, exist_ok=True)
        self._lock = threading.Lock()
        self._db = sqlite3.connect(self.path, timeout=60.0, check_same_thread=False, isolation_level=None)
        if self.path != ":memory:":
            self._db.execute("PRAGMA journal_mode=WAL")
        self._db.execute("PRAGMA busy_timeout=60000")
        self._db.execute(_SCHEMA)

    # -- reading ----------------------------------------------------------------------
    @staticmethod
    def _row_to_outcome(design: str, row: tuple) -> Outcome:
        status, response, cause, reached, wall = row
        resp = Response.from_dict(json.loads(response)) if response else None
        return Outcome(
            design,
            resp,
            failure=cause if status == "failed" else None,
            reached=reached,
            cached=True,
            wall_time=wall or 0.0,
        )

    def get(self, fingerprint: str, design: str) -> Outcome | None:
        """The stored outcome of ``design`` under a model fingerprint, or None."""
        with self._lock:
            row = self._db.execute(
                "SELECT status, response, cause, reached, wall_time FROM evaluations "
                "WHERE fingerprint = ? AND design = ?",
                (fingerprint, design),
            ).fetchone()
        return None if row is None else self._row_to_outcome(design, row)

    def get_many(self, fingerprint: str, designs: Iterable[str]) -> dict[str, Outcome]:
        """Stored outcomes of the designs that are in the cache."""
        return {d: hit for d in dict.fromkeys(designs) if (hit := self.get(fingerprint, d)) is not None}

    def designs(self, fingerprint: str) -> list[str]:
        """All designs stored under a fingerprint, sorted."""
        with self._lock:
            rows = self._db.execute(
                "SELECT design FROM evaluations WHERE fingerprint = ? ORDER BY design", (fingerprint,)
            ).fetchall()
        return [r[0] for r in rows]

    def count(self, fingerprint: str | None = None) -> int:
        """Number of entries (under one fingerprint, or all)."""
        with self._lock:
            if fingerprint is None:
                return int(self._db.execute("SELECT COUNT(*) FROM evaluations").fetchone()[0])
            return int(
                self._db.execute("SELECT COUNT(*) FROM evaluations WHERE fingerprint = ?", (fingerprint,)).fetchone()[0]
            )

    # -- writing ----------------------------------------------------------------------
    def put(self, fingerprint: str, outcome: Outcome) -> None:
        """Store an outcome (committed at once; an existing entry is kept)."""
        resp = None
        if outcome.response is not None:
            resp = json.dumps(outcome.response.to_dict(), default=str)
        status = "failed" if outcome.failure is not None else "ok"
        created = datetime.now(UTC).isoformat(timespec="seconds")
        with self._lock:
            self._db.execute(
                "INSERT OR IGNORE INTO evaluations VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
                (fingerprint, outcome.design, status, resp, outcome.failure, outcome.reached, outcome.wall_time, created),
            )

    def close(self) -> None:
        with self._lock:
            self._db.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class CachedEvaluator:
    """An evaluator that answers from the cache first and stores every new outcome.

    Parameters
    ----------
    inner : Evaluator
        Solves the designs the cache does not hold.
    cache : EvaluationCache
        Where outcomes are looked up and stored.

    The designs are deduplicated; each finished solve is stored the moment it arrives.
    ``solves`` counts the designs actually solved, ``hits`` those answered from the cache.
    """

    def __init__(self, inner, cache: EvaluationCache) -> None:
        self.inner = inner
        self.cache = cache
        self.solves = 0
        self.hits = 0
        self.solve_time = 0.0

    def iter_evaluate(self, model: ActuatorModel, designs: Iterable[str]) -> Iterator[tuple[int, Outcome]]:
        designs = list(designs)
        fp = model.fingerprint()
        found = self.cache.get_many(fp, designs)
        todo: dict[str, list[int]] = {}
        for i, d in enumerate(designs):
            if d in found:
                self.hits += 1
                yield i, found[d]
            else:
                todo.setdefault(d, []).append(i)
        unique = list(todo)
        start = time.perf_counter()
        for j, outcome in self.inner.iter_evaluate(model, unique):
            self.cache.put(fp, outcome)
            self.solves += 1
            first, *rest = todo[unique[j]]
            yield first, outcome
            for i in rest:
                yield i, outcome.as_cached()
        self.solve_time += time.perf_counter() - start

    def evaluate_many(self, model: ActuatorModel, designs: Iterable[str]) -> list[Outcome]:
        designs = list(designs)
        out: list[Outcome | None] = [None] * len(designs)
        for i, outcome in self.iter_evaluate(model, designs):
            out[i] = outcome
        return out  # type: ignore[return-value]

    def close(self) -> None:
        self.inner.close()
