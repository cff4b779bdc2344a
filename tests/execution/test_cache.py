"""The SQLite evaluation cache: round trip, failures, persistence, concurrent readers;
damaged entries, files that are no cache, read-only and full caches, legacy databases."""

from __future__ import annotations

import json
import os
import sqlite3
import stat
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import CacheError, EvaluationError
from pneumorph.execution import (
    CachedEvaluator,
    EvaluationCache,
    Outcome,
    SerialEvaluator,
)

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))  # the toy model lives in tests/design
from tests.design.toy_model import ToyModel  # noqa: E402 - after the path it is found on


def test_response_round_trip_is_bit_exact(tmp_path: Path) -> None:
    model = ToyModel(n_units=5)
    original = model.evaluate("01101")
    with EvaluationCache(tmp_path / "c.sqlite") as cache:
        cache.put(model.fingerprint(), Outcome("01101", original, wall_time=0.25))
    with EvaluationCache(tmp_path / "c.sqlite") as cache:  # reopened: persisted
        hit = cache.get(model.fingerprint(), "01101")
    assert hit.cached and hit.ok and hit.wall_time == 0.25
    for name in ("pressures", "centres", "reference_centres", "tip", "reference_tip", "curl"):
        np.testing.assert_array_equal(getattr(hit.response, name), getattr(original, name))


def test_failures_are_recorded_with_cause_and_reached_pressure(tmp_path: Path) -> None:
    model = ToyModel(n_units=3, fail={"010"})
    ev = CachedEvaluator(SerialEvaluator(), EvaluationCache(tmp_path / "c.sqlite"))
    out = ev.evaluate_many(model, ["000", "010"])
    assert out[0].ok and not out[1].ok
    assert out[1].failure == "toy failure" and out[1].reached == pytest.approx(0.0225)
    again = CachedEvaluator(SerialEvaluator(), EvaluationCache(tmp_path / "c.sqlite")).evaluate_many(model, ["010"])
    assert again[0].cached and again[0].failure == "toy failure" and again[0].reached == pytest.approx(0.0225)


def test_each_design_is_solved_once_across_evaluators_and_duplicates(tmp_path: Path) -> None:
    model = ToyModel(n_units=4)
    path = tmp_path / "c.sqlite"
    first = CachedEvaluator(SerialEvaluator(), EvaluationCache(path))
    out = first.evaluate_many(model, ["0000", "0101", "0000", "1111"])
    assert [o.design for o in out] == ["0000", "0101", "0000", "1111"]
    assert model.calls == ["0000", "0101", "1111"] and (first.solves, first.hits) == (3, 0)
    assert out[2].cached and not out[0].cached
    second = CachedEvaluator(SerialEvaluator(), EvaluationCache(path))
    second.evaluate_many(model, ["1111", "0011", "0101"])
    assert model.calls[3:] == ["0011"] and (second.solves, second.hits) == (1, 2)
    other = ToyModel(n_units=4, turn=20.0)  # another fingerprint: solved anew
    second.evaluate_many(other, ["1111"])
    assert other.calls == ["1111"] and second.cache.count() == 5


def test_readers_see_entries_while_a_writer_holds_the_database(tmp_path: Path) -> None:
    path = tmp_path / "c.sqlite"
    model = ToyModel(n_units=3)
    writer = EvaluationCache(path)
    writer.put(model.fingerprint(), Outcome("000", model.evaluate("000")))
    assert sqlite3.connect(path).execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    lock = sqlite3.connect(path, isolation_level=None)
    lock.execute("BEGIN IMMEDIATE")  # another process in the middle of a write
    lock.execute("INSERT INTO evaluations (fingerprint, design, status, created) VALUES ('x', '1', 'failed', 'now')")
    readers = [EvaluationCache(path) for _ in range(2)]
    assert all(r.get(model.fingerprint(), "000").ok for r in readers)
    assert all(r.count() == 1 for r in readers)  # the uncommitted row is not seen
    lock.execute("COMMIT")
    assert readers[0].count() == 2


def test_a_model_fault_is_not_recorded_as_a_failed_design(tmp_path: Path) -> None:
    class Broken(ToyModel):
        def evaluate(self, orientation: str):
            raise ZeroDivisionError("bug")

    ev = CachedEvaluator(SerialEvaluator(), EvaluationCache(tmp_path / "c.sqlite"))
    with pytest.raises(EvaluationError, match="design 01: the model raised ZeroDivisionError: bug"):
        ev.evaluate_many(Broken(n_units=2), ["01"])
    assert ev.cache.count() == 0


# -- damaged entries ------------------------------------------------------------------
def edit_response(db: sqlite3.Connection, design: str) -> None:
    """Change one number of a stored response, leaving valid JSON."""
    (text,) = db.execute("SELECT response FROM evaluations WHERE design = ?", (design,)).fetchone()
    data = json.loads(text)
    data["curl"][-1] += 1.0
    db.execute("UPDATE evaluations SET response = ? WHERE design = ?", (json.dumps(data), design))


TAMPER: dict[str, Callable[[sqlite3.Connection], None]] = {
    "response value": lambda db: edit_response(db, "101"),
    "reached pressure": lambda db: db.execute("UPDATE evaluations SET reached = 0.04 WHERE design = '010'"),
    "cause": lambda db: db.execute("UPDATE evaluations SET cause = 'other' WHERE design = '010'"),
    "status": lambda db: db.execute("UPDATE evaluations SET status = 'ok', cause = NULL WHERE design = '010'"),
    "checksum": lambda db: db.execute("UPDATE evaluations SET checksum = 'f00' WHERE design = '101'"),
    "no checksum": lambda db: db.execute("UPDATE evaluations SET checksum = NULL WHERE design = '101'"),
}


@pytest.mark.parametrize("how", TAMPER)
def test_an_edited_entry_is_never_used_but_solved_again(tmp_path: Path, how: str) -> None:
    path = tmp_path / "c.sqlite"
    model = ToyModel(n_units=3, fail={"010"})
    designs = ["000", "010", "101"]
    truth = CachedEvaluator(SerialEvaluator(), EvaluationCache(path)).evaluate_many(model, designs)
    with sqlite3.connect(path) as db:
        TAMPER[how](db)
    victim = "101" if how in ("response value", "checksum", "no checksum") else "010"
    model.calls.clear()
    ev = CachedEvaluator(SerialEvaluator(), EvaluationCache(path))
    out = ev.evaluate_many(model, designs)
    assert model.calls == [victim] and (ev.solves, ev.hits, ev.cache.rejected) == (1, 2, 1)
    for got, want in zip(out, truth, strict=True):
        assert (got.failure, got.reached) == (want.failure, want.reached)
        if want.response is not None:
            np.testing.assert_array_equal(got.response.curl, want.response.curl)
    again = EvaluationCache(path)  # the recomputed entry was stored in place of the damaged one
    assert again.get(model.fingerprint(), victim) is not None and again.rejected == 0 and again.count() == 3


# -- legacy databases -----------------------------------------------------------------
LEGACY_SCHEMA = """
CREATE TABLE evaluations (
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


def legacy_cache(path: Path, model: ToyModel) -> None:
    """A cache as written before entries had checksums (rollback journal, 8 columns)."""
    fp = model.fingerprint()
    with sqlite3.connect(path) as db:
        db.execute(LEGACY_SCHEMA)
        rows = [
            (fp, "00", "ok", json.dumps(model.evaluate("00").to_dict()), None, None, 0.5, "then"),
            (fp, "11", "failed", None, "diverged", 0.0225, 0.25, "then"),
            (fp, "01", "ok", '{"orientation": "01", "pressures": [0.1', None, None, 0.5, "then"),  # cut short
        ]
        db.executemany("INSERT INTO evaluations VALUES (?, ?, ?, ?, ?, ?, ?, ?)", rows)
    model.calls.clear()


def test_a_legacy_database_is_migrated_and_still_answers(tmp_path: Path) -> None:
    path = tmp_path / "old.sqlite"
    model = ToyModel(n_units=2)
    legacy_cache(path, model)
    ev = CachedEvaluator(SerialEvaluator(), EvaluationCache(path))
    columns = [r[1] for r in sqlite3.connect(path).execute("PRAGMA table_info(evaluations)")]
    assert columns[-1] == "checksum"
    sums = sqlite3.connect(path).execute("SELECT checksum FROM evaluations").fetchall()
    assert len(sums) == 3 and all(len(s) == 64 for (s,) in sums)  # filled once, at the migration
    out = ev.evaluate_many(model, ["00", "11", "01"])
    np.testing.assert_array_equal(out[0].response.tip, model.evaluate("00").tip)
    assert out[0].cached and out[1].cached and (out[1].failure, out[1].reached) == ("diverged", 0.0225)
    # the response that does not parse is a miss, not a crash: solved again and replaced
    assert not out[2].cached and out[2].ok and ev.cache.rejected == 1 and (ev.solves, ev.hits) == (1, 2)
    assert sqlite3.connect(path).execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    with sqlite3.connect(path) as db:  # after the migration, edits are caught
        db.execute("UPDATE evaluations SET reached = 0.03 WHERE design = '11'")
    reopened = EvaluationCache(path)
    assert reopened.get(model.fingerprint(), "11") is None and reopened.rejected == 1
    assert reopened.get(model.fingerprint(), "01").ok  # the recomputed one was stored with a checksum


def test_an_empty_file_becomes_a_cache(tmp_path: Path) -> None:
    path = tmp_path / "empty.sqlite"
    path.touch()
    with EvaluationCache(path) as cache:
        cache.put("fp", Outcome("01", None, failure="diverged", reached=0.0))
        assert cache.get("fp", "01").reached == 0.0


def test_stored_numbers_come_back_under_their_checksum() -> None:
    cache = EvaluationCache(":memory:")
    odd = {"a": -0.0, "b": float("nan"), "c": 3, "d": float("inf"), "e": 1e300, "f": None}
    for design, reached in odd.items():
        cache.put("fp", Outcome(design, None, failure="cause \ud800 with a lone surrogate", reached=reached))
    got = {d: cache.get("fp", d) for d in odd}
    assert cache.rejected == 0 and all(o is not None for o in got.values())
    assert got["a"].reached == 0.0 and got["b"].reached is None and got["c"].reached == 3.0
    assert got["d"].reached == float("inf") and got["f"].reached is None


# -- files that cannot be a cache -----------------------------------------------------
def damaged(path: Path) -> None:
    model = ToyModel(n_units=8)
    with EvaluationCache(path) as cache:
        for i in range(40):
            design = format(i, "08b")
            cache.put(model.fingerprint(), Outcome(design, model.evaluate(design)))
    data = bytearray(path.read_bytes())
    assert len(data) > 30 * 4096
    data[19 * 4096 : 20 * 4096] = bytes(range(256)) * 16  # a page in the middle, not read on opening
    path.write_bytes(bytes(data))


def foreign(path: Path) -> None:
    with sqlite3.connect(path) as db:
        db.execute("CREATE TABLE invoices (id INTEGER, amount REAL)")
        db.execute("INSERT INTO invoices VALUES (1, 9.5)")


def other_evaluations(path: Path) -> None:
    with sqlite3.connect(path) as db:
        db.execute("CREATE TABLE evaluations (id INTEGER, score REAL)")


def truncated(path: Path) -> None:
    damaged(path)
    path.write_bytes(path.read_bytes()[: 5 * 4096 + 100])


NOT_A_CACHE: dict[str, tuple[Callable[[Path], None], str]] = {
    "folder": (lambda p: p.mkdir(), "is a folder, not a database file: choose a file in it"),
    "text file": (lambda p: p.write_text("fingerprint,design\nabc,0110\n"), "is not an SQLite database: move it aside"),
    "random bytes": (lambda p: p.write_bytes(bytes(range(256)) * 40), "is not an SQLite database: move it aside"),
    "foreign database": (foreign, "is a database of something else (tables invoices, no 'evaluations')"),
    "foreign evaluations": (other_evaluations, "has an 'evaluations' table that is not pneumorph's"),
    "damaged database": (damaged, "is damaged ("),
    "truncated database": (truncated, "is damaged ("),
}


@pytest.mark.parametrize("what", NOT_A_CACHE)
def test_a_file_that_cannot_be_a_cache_is_refused_in_one_line(tmp_path: Path, what: str) -> None:
    path = tmp_path / "c.sqlite"
    make, expected = NOT_A_CACHE[what]
    make(path)
    before = path.read_bytes() if path.is_file() else None
    with pytest.raises(CacheError) as info:
        EvaluationCache(path)
    message = str(info.value)
    assert message.startswith(f"cache {path} ") and expected in message and "\n" not in message
    assert message.endswith("file with --cache")
    if "move it aside" in expected or "damaged" in expected:
        assert f"mv {path} {path}.bad" in message
    if before is not None:
        assert path.read_bytes() == before  # nothing written into it
    assert sorted(os.listdir(tmp_path)) == ["c.sqlite"]  # no -wal / -shm left behind


def test_a_folder_that_cannot_be_created_is_refused(tmp_path: Path) -> None:
    (tmp_path / "plain").write_text("a file")
    with pytest.raises(CacheError, match=r"cache .*/plain/sub/c\.sqlite: its folder .*/plain/sub cannot be created"):
        EvaluationCache(tmp_path / "plain" / "sub" / "c.sqlite")
    with pytest.raises(CacheError, match="empty"):
        EvaluationCache("")


# -- writing fails ----------------------------------------------------------------------
@pytest.mark.skipif(os.geteuid() == 0, reason="root writes read-only files anyway")
@pytest.mark.parametrize("what", ["file", "folder", "new file in folder"])
def test_a_read_only_cache_is_refused_when_opened(tmp_path: Path, what: str) -> None:
    folder = tmp_path / "ro"
    folder.mkdir()
    path = folder / "c.sqlite"
    if what != "new file in folder":
        EvaluationCache(path).close()  # a valid cache; closing removes its -wal and -shm
    if what == "file":
        path.chmod(stat.S_IRUSR)
    else:
        folder.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        with pytest.raises(CacheError) as info:
            EvaluationCache(path)
    finally:
        folder.chmod(stat.S_IRWXU)
        if path.exists():
            path.chmod(stat.S_IRUSR | stat.S_IWUSR)
    message = str(info.value)
    assert message.startswith(f"cache {path} is read-only (") and "\n" not in message
    assert message.endswith("make the file and its folder writable (chmod u+w) or choose another file with --cache")


def test_a_full_disk_while_storing_raises_cache_error(tmp_path: Path) -> None:
    model = ToyModel(n_units=8)
    cache = EvaluationCache(tmp_path / "c.sqlite")
    pages = cache._db.execute("PRAGMA page_count").fetchone()[0]
    cache._db.execute(f"PRAGMA max_page_count = {pages + 2}")  # the disk fills up soon
    with pytest.raises(CacheError, match=r"cannot grow \(database or disk is full, storing design \d{8}\): free"):
        for i in range(100):
            design = format(i, "08b")
            cache.put(model.fingerprint(), Outcome(design, model.evaluate(design)))
    assert 0 < cache.count() < 100


def test_another_writer_holding_the_lock_too_long_raises_cache_error(tmp_path: Path) -> None:
    path = tmp_path / "c.sqlite"
    cache = EvaluationCache(path)
    cache._db.execute("PRAGMA busy_timeout = 50")
    lock = sqlite3.connect(path, isolation_level=None)
    lock.execute("BEGIN IMMEDIATE")
    with pytest.raises(CacheError, match=r"is locked by another process \(database is locked, storing design 01\)"):
        cache.put("fp", Outcome("01", None, failure="x", reached=0.0))
    lock.execute("ROLLBACK")
    cache.put("fp", Outcome("01", None, failure="x", reached=0.0))
    cache.close()
    with pytest.raises(CacheError, match="is closed"):
        cache.get("fp", "01")
