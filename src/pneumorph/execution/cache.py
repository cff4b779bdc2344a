"""A persistent evaluation cache (SQLite): no design is solved twice for the same model.

Entries are keyed by ``(model fingerprint, design)``. A converged solve stores its
:class:`~pneumorph.models.Response` as JSON; a failed solve stores its cause and the
pressure it reached (and the partial response, if the model returned one). The database
runs in WAL mode, so several processes can read it while one writes; every entry is
committed as soon as it is put, so a killed run loses nothing it had finished.

Every entry carries a SHA-256 ``checksum`` of its fingerprint, design, status, response
JSON, cause and reached pressure. An entry that no longer matches its checksum, or whose
response does not decode, is never used: it is deleted, counted in
:attr:`EvaluationCache.rejected` and answered as a miss, so it is solved again.

A database written before checksums existed is migrated when it is opened: the column is
added and the checksums of its rows are computed from their contents as they are then.
Those legacy rows are trusted once, at the migration (an edit made before it cannot be
told from a genuine entry); any change after it is detected.

Opening raises :class:`~pneumorph.errors.CacheError`, one line naming the file, what is
wrong and the way out, when the path is a folder, not an SQLite database, another
program's database, damaged (``PRAGMA quick_check``) or not writable, so a run fails
before its first solve rather than after it. Errors while reading or storing entries
are CacheError too; no raw :mod:`sqlite3` error escapes.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import shlex
import sqlite3
import threading
import time
import uuid
from collections.abc import Callable, Iterable, Iterator
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, Self

from pneumorph.errors import CacheError
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
    checksum TEXT,
    PRIMARY KEY (fingerprint, design)
)
"""
_COLUMNS = ("fingerprint", "design", "status", "response", "cause", "reached", "wall_time", "created")
_WAY_OUT = "choose another file with --cache"
_BUSY_MS = 60_000  # how long a statement waits for another process's write
_PROBE_MS = 250  # how long the write probe at opening waits before judging by permissions
# primary SQLite result codes (extended codes carry them in the low byte)
_PERM, _BUSY, _LOCKED, _READONLY, _IOERR, _CORRUPT = 3, 5, 6, 8, 10, 11
_FULL, _CANTOPEN, _AUTH, _NOTADB = 13, 14, 23, 26


def _checksum(fingerprint: Any, design: Any, status: Any, response: Any, cause: Any, reached: Any) -> str:
    """SHA-256 (hex) of an entry's canonical JSON ``[fingerprint, design, ..., reached]``."""
    canon = json.dumps([fingerprint, design, status, response, cause, reached], separators=(",", ":"), default=repr)
    return hashlib.sha256(canon.encode()).hexdigest()


def _real(value: float | None) -> float | None:
    """``value`` as SQLite returns it from a REAL column (NaN is stored as NULL, -0.0 as 0)."""
    if value is None:
        return None
    value = float(value)
    return None if math.isnan(value) else value + 0.0


def _text(value: str) -> str:
    """``value`` as a string SQLite can store (lone surrogates replaced)."""
    return str(value).encode("utf-8", "replace").decode("utf-8")


def default_cache_path() -> Path:
    """``$PNEUMORPH_CACHE``, else ``$XDG_CACHE_HOME/pneumorph/evaluations.sqlite`` (``~/.cache``)."""
    if os.environ.get("PNEUMORPH_CACHE"):
        return Path(os.environ["PNEUMORPH_CACHE"])
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "pneumorph" / "evaluations.sqlite"


def chain_table_dir(cache: str | Path | None = None) -> Path | None:
    """The folder of the chain tables kept beside an evaluation cache (None for a cache in memory).

    >>> chain_table_dir("/data/evaluations.sqlite").as_posix(), chain_table_dir(":memory:")
    ('/data/chain-tables', None)
    """
    path = str(cache if cache is not None else default_cache_path())
    return None if path == ":memory:" else Path(path).parent / "chain-tables"


class EvaluationCache:
    """Outcomes of solved designs, persisted in an SQLite file.

    Parameters
    ----------
    path : str or Path
        The database file (created with its folder if missing); ``":memory:"`` for a
        throw-away cache.

    Attributes
    ----------
    rejected : int
        Entries found damaged (checksum mismatch, undecodable response) and deleted;
        their designs read as misses and are solved again.

    Raises
    ------
    CacheError
        If the file cannot serve as a cache: a folder, not an SQLite database, another
        program's database, damaged, or not writable.

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
        self.rejected = 0
        self._lock = threading.Lock()
        memory = self.path == ":memory:"
        if not memory:
            self._check_path()
        db = None
        try:
            db = sqlite3.connect(self.path, timeout=_BUSY_MS / 1000, check_same_thread=False, isolation_level=None)
            self._db = db
            self._open(memory)
        except (sqlite3.Error, CacheError) as exc:
            if db is not None:
                with contextlib.suppress(sqlite3.Error):
                    db.close()
            if isinstance(exc, CacheError):
                raise
            raise self._error(exc) from exc

    # -- opening ----------------------------------------------------------------------
    def _check_path(self) -> None:
        """Refuse an empty path, a folder or a special file; create the missing folder."""
        if not self.path.strip():
            raise CacheError(f"cache path {self.path!r} is empty: {_WAY_OUT}")
        p = Path(self.path)
        try:
            if p.is_dir():
                raise CacheError(
                    f"cache {p} is a folder, not a database file: choose a file in it "
                    f"(--cache {shlex.quote(str(p / 'evaluations.sqlite'))}) or another file with --cache"
                )
            if p.exists() and not p.is_file():
                raise CacheError(f"cache {p} is not a regular file: {_WAY_OUT}")
        except OSError as exc:
            raise CacheError(f"cache {p} cannot be reached ({exc.strerror or exc}): {_WAY_OUT}") from exc
        try:
            p.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise CacheError(
                f"cache {p}: its folder {p.parent} cannot be created ({exc.strerror or exc}): {_WAY_OUT}"
            ) from exc

    def _open(self, memory: bool) -> None:
        """Check the database, create or migrate the table, and prove it can be written."""
        db = self._db
        tables = self._tables()  # the first read: a non-database fails here, before any write
        if "evaluations" not in tables and tables:
            raise CacheError(
                f"cache {self.path} is a database of something else (tables {', '.join(sorted(tables))}, "
                f"no 'evaluations'): {_WAY_OUT}"
            )
        columns = self._columns()
        if "evaluations" in tables and (missing := [c for c in _COLUMNS if c not in columns]):
            raise CacheError(
                f"cache {self.path} has an 'evaluations' table that is not pneumorph's "
                f"(missing columns: {', '.join(missing)}): {_WAY_OUT}"
            )
        if not memory:
            problems = db.execute("PRAGMA quick_check(1)").fetchall()
            if problems != [("ok",)]:
                what = " ".join(str(problems[0][0]).replace("*** in database main ***", "").split())
                raise CacheError(f"cache {self.path} is damaged ({what}): {self._aside()}")
            db.execute("PRAGMA journal_mode=WAL")
        if "checksum" not in columns:
            self._create_or_migrate()
        self._probe_write(memory)

    def _tables(self) -> set[str]:
        rows = self._db.execute(
            "SELECT name FROM sqlite_master WHERE type = 'table' AND name NOT LIKE 'sqlite\\_%' ESCAPE '\\'"
        ).fetchall()
        return {r[0] for r in rows}

    def _columns(self) -> set[str]:
        return {r[1] for r in self._db.execute("PRAGMA table_info(evaluations)").fetchall()}

    def _create_or_migrate(self) -> None:
        """Create the table, or add the checksum column and fill it (legacy rows, trusted once)."""
        db = self._db
        db.execute("BEGIN IMMEDIATE")
        try:
            db.execute(_SCHEMA)
            if "checksum" not in self._columns():  # another process may have migrated meanwhile
                db.execute("ALTER TABLE evaluations ADD COLUMN checksum TEXT")
                rows = db.execute(
                    "SELECT rowid, fingerprint, design, status, response, cause, reached FROM evaluations"
                )
                sums = [(_checksum(*r[1:]), r[0]) for r in rows]
                db.executemany("UPDATE evaluations SET checksum = ? WHERE rowid = ?", sums)
            db.execute("COMMIT")
        except BaseException:
            with contextlib.suppress(sqlite3.Error):
                db.execute("ROLLBACK")
            raise

    def _probe_write(self, memory: bool) -> None:
        """Write a row and roll it back, so a read-only cache fails now, not at the first put."""
        db = self._db
        db.execute(f"PRAGMA busy_timeout={_PROBE_MS}")
        try:
            db.execute("BEGIN IMMEDIATE")
        except sqlite3.OperationalError as exc:
            if _code(exc) not in (_BUSY, _LOCKED):
                raise
            # another process is writing right now: judge by the permissions instead
            if not memory and not all(os.access(p, os.W_OK) for p in (self.path, Path(self.path).parent)):
                raise CacheError(
                    f"cache {self.path} is read-only (no write permission on the file or its folder): "
                    f"{self._writable()}"
                ) from exc
        else:
            try:
                db.execute(
                    "INSERT INTO evaluations (fingerprint, design, status, created) VALUES (?, '', 'failed', '')",
                    (f"write-probe-{uuid.uuid4().hex}",),
                )
            finally:
                with contextlib.suppress(sqlite3.Error):
                    db.execute("ROLLBACK")
        finally:
            db.execute(f"PRAGMA busy_timeout={_BUSY_MS}")

    # -- errors -----------------------------------------------------------------------
    def _aside(self) -> str:
        q = shlex.quote(self.path)
        return f"move it aside (mv {q} {shlex.quote(self.path + '.bad')}) or {_WAY_OUT}"

    def _writable(self) -> str:
        return f"make the file and its folder writable (chmod u+w) or {_WAY_OUT}"

    def _error(self, exc: sqlite3.Error, doing: str = "") -> CacheError:
        """One line for a raw sqlite3 error: the file, what is wrong, the way out."""
        code = _code(exc)
        why = f"{exc}{', ' + doing if doing else ''}"
        p = self.path
        if code == _NOTADB:
            return CacheError(f"cache {p} is not an SQLite database: {self._aside()}")
        if code == _CORRUPT:
            return CacheError(f"cache {p} is damaged ({why}): {self._aside()}")
        folder_locked = code == _CANTOPEN and p != ":memory:" and not os.access(Path(p).parent, os.W_OK)
        if code in (_READONLY, _PERM, _AUTH) or folder_locked:
            return CacheError(f"cache {p} is read-only ({why}): {self._writable()}")
        if code == _FULL:
            return CacheError(f"cache {p} cannot grow ({why}): free disk space or {_WAY_OUT}")
        if code in (_BUSY, _LOCKED):
            return CacheError(f"cache {p} is locked by another process ({why}): wait for it or {_WAY_OUT}")
        if code == _CANTOPEN:
            return CacheError(f"cache {p} cannot be opened ({why}): {_WAY_OUT}")
        if code == _IOERR:
            return CacheError(f"cache {p} cannot be read or written ({why}): check the disk or {_WAY_OUT}")
        if isinstance(exc, sqlite3.ProgrammingError) and "closed" in str(exc):
            return CacheError(f"cache {p} is closed ({why}): open it again")
        return CacheError(f"cache {p} failed ({why}): {_WAY_OUT}")

    def _execute(self, sql: str, params: tuple[Any, ...] = (), doing: str = "") -> sqlite3.Cursor:
        """``self._db.execute`` with sqlite3 errors turned into CacheError (caller holds the lock)."""
        try:
            return self._db.execute(sql, params)
        except sqlite3.Error as exc:
            raise self._error(exc, doing) from exc

    # -- reading ----------------------------------------------------------------------
    @staticmethod
    def _row_to_outcome(fingerprint: str, design: str, row: tuple[Any, ...]) -> Outcome | None:
        """The outcome of a stored row, or None if the row is damaged."""
        status, response, cause, reached, wall, checksum = row
        if checksum != _checksum(fingerprint, design, status, response, cause, reached):
            return None
        try:
            resp = Response.from_dict(json.loads(response)) if response else None
            return Outcome(
                design,
                resp,
                failure=cause if status == "failed" else None,
                reached=reached,
                cached=True,
                wall_time=float(wall or 0.0),
            )
        except (ValueError, TypeError, KeyError, AttributeError, RecursionError):
            return None

    def get(self, fingerprint: str, design: str) -> Outcome | None:
        """The stored outcome of ``design`` under a model fingerprint, or None.

        A damaged entry is deleted, counted in ``rejected`` and answered with None.
        """
        with self._lock:
            try:
                row = self._db.execute(
                    "SELECT status, response, cause, reached, wall_time, checksum FROM evaluations "
                    "WHERE fingerprint = ? AND design = ?",
                    (fingerprint, design),
                ).fetchone()
            except sqlite3.Error as exc:
                raise self._error(exc, f"reading design {design}") from exc
            if row is None:
                return None
            outcome = self._row_to_outcome(fingerprint, design, row)
            if outcome is None:
                self.rejected += 1
                self._execute(
                    "DELETE FROM evaluations WHERE fingerprint = ? AND design = ? AND checksum IS ?",
                    (fingerprint, design, row[-1]),
                    f"deleting the damaged entry of design {design}",
                )
            return outcome

    def get_many(self, fingerprint: str, designs: Iterable[str]) -> dict[str, Outcome]:
        """Stored outcomes of the designs that are in the cache (and not damaged)."""
        return {d: hit for d in dict.fromkeys(designs) if (hit := self.get(fingerprint, d)) is not None}

    def designs(self, fingerprint: str) -> list[str]:
        """All designs stored under a fingerprint, sorted."""
        with self._lock:
            try:
                rows = self._db.execute(
                    "SELECT design FROM evaluations WHERE fingerprint = ? ORDER BY design", (fingerprint,)
                ).fetchall()
            except sqlite3.Error as exc:
                raise self._error(exc, "listing designs") from exc
        return [r[0] for r in rows]

    def count(self, fingerprint: str | None = None) -> int:
        """Number of entries (under one fingerprint, or all)."""
        with self._lock:
            try:
                if fingerprint is None:
                    return int(self._db.execute("SELECT COUNT(*) FROM evaluations").fetchone()[0])
                return int(
                    self._db.execute(
                        "SELECT COUNT(*) FROM evaluations WHERE fingerprint = ?", (fingerprint,)
                    ).fetchone()[0]
                )
            except sqlite3.Error as exc:
                raise self._error(exc, "counting entries") from exc

    # -- writing ----------------------------------------------------------------------
    def put(self, fingerprint: str, outcome: Outcome) -> None:
        """Store an outcome (committed at once; an existing entry is kept).

        Raises
        ------
        CacheError
            If it cannot be stored (read-only, disk full, damaged, locked too long).
        """
        resp = None
        if outcome.response is not None:
            resp = json.dumps(outcome.response.to_dict(), default=str)
        status = "failed" if outcome.failure is not None else "ok"
        cause = None if outcome.failure is None else _text(outcome.failure)
        entry = (fingerprint, outcome.design, status, resp, cause, _real(outcome.reached))
        wall = _real(outcome.wall_time)
        created = datetime.now(UTC).isoformat(timespec="seconds")
        with self._lock:
            self._execute(
                "INSERT OR IGNORE INTO evaluations (fingerprint, design, status, response, cause, reached, "
                "wall_time, created, checksum) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (*entry, wall, created, _checksum(*entry)),
                f"storing design {outcome.design}",
            )

    def close(self) -> None:
        with self._lock:
            self._db.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _code(exc: sqlite3.Error) -> int | None:
    """The primary SQLite result code of an error (None if it has none)."""
    code = getattr(exc, "sqlite_errorcode", None)
    return None if code is None else code & 0xFF


class CachedEvaluator:
    """An evaluator that answers from the cache first and stores every new outcome.

    Parameters
    ----------
    inner : Evaluator
        Solves the designs the cache does not hold.
    cache : EvaluationCache
        Where outcomes are looked up and stored.

    The designs are deduplicated; each finished solve is stored the moment it arrives.
    ``solves`` counts the designs actually solved, ``hits`` those answered from the cache;
    damaged entries are solved again and counted in ``cache.rejected``.
    """

    def __init__(self, inner: Any, cache: EvaluationCache) -> None:
        self.inner = inner
        self.cache = cache
        self.solves = 0
        self.hits = 0
        self.solve_time = 0.0

    def iter_evaluate(self, model: ActuatorModel, designs: Iterable[str]) -> Iterator[tuple[int, Outcome]]:
        designs = list(designs)
        fp = model.fingerprint()
        found = self.cache.get_many(fp, designs)
        yield from self._answer([(fp, d) for d in designs], lambda key: found.get(key[1]),
                                lambda keys: self.inner.iter_evaluate(model, [d for _, d in keys]))

    def evaluate_many(self, model: ActuatorModel, designs: Iterable[str]) -> list[Outcome]:
        designs = list(designs)
        out: list[Outcome | None] = [None] * len(designs)
        for i, outcome in self.iter_evaluate(model, designs):
            out[i] = outcome
        return out  # type: ignore[return-value]

    def iter_cases(self, cases: Iterable[tuple[ActuatorModel, str]]) -> Iterator[tuple[int, Outcome]]:
        """``(model, design)`` pairs of different models: cached ones first, the others as they are solved."""
        cases = list(cases)
        keys = [(m.fingerprint(), d) for m, d in cases]
        first: dict[tuple[str, str], tuple[ActuatorModel, str]] = {}
        for key, case in zip(keys, cases, strict=True):
            first.setdefault(key, case)
        yield from self._answer(keys, lambda key: self.cache.get(*key),
                                lambda todo: self.inner.iter_cases([first[key] for key in todo]))

    def _answer(
        self, keys: list[tuple[str, str]], lookup: Callable[[tuple[str, str]], Outcome | None],
        solve: Callable[[list[tuple[str, str]]], Iterator[tuple[int, Outcome]]],
    ) -> Iterator[tuple[int, Outcome]]:
        """Yield ``(index, Outcome)`` of every ``(fingerprint, design)`` key: the cache's first, then each key
        solved once (``solve(unique keys)``), stored the moment it arrives."""
        todo: dict[tuple[str, str], list[int]] = {}
        for i, key in enumerate(keys):
            found = None if key in todo else lookup(key)
            if found is not None:
                self.hits += 1
                yield i, found
            else:
                todo.setdefault(key, []).append(i)
        unique = list(todo)
        start = time.perf_counter()
        for j, outcome in solve(unique):
            if not outcome.transient:  # a dead worker says nothing about the design
                self.cache.put(unique[j][0], outcome)
            self.solves += 1
            first, *rest = todo[unique[j]]
            yield first, outcome
            for i in rest:
                yield i, outcome.as_cached()
        self.solve_time += time.perf_counter() - start

    def close(self) -> None:
        self.inner.close()
