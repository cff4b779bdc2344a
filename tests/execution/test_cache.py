"""The SQLite evaluation cache: round trip, failures, persistence, concurrent readers."""

from __future__ import annotations

import sqlite3
import sys
from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import EvaluationError
from pneumorph.execution import (
    CachedEvaluator,
    EvaluationCache,
    Outcome,
    SerialEvaluator,
)

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))  # the toy model lives in tests/design
from tests.design.toy_model import ToyModel


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
    lock.execute("INSERT INTO evaluations VALUES ('x', '1', 'failed', NULL, 'c', 0, 0, 'now')")
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
