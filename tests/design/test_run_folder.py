"""Nothing a run writes is lost or mixed up: the folder lock, resume appends, overwrite removes only the
run's files, a failed start leaves the folder as it was, atomic writes, interruption, a dying worker."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import pneumorph.design.runs.report as report_module
from pneumorph.design import DesignConfig, GAConfig, run_design
from pneumorph.design.runs.folder import RUN_FILES, GenerationLog, run_files
from pneumorph.errors import (
    CacheError,
    OutputPathError,
    RunFolderError,
    SearchConfigError,
)
from pneumorph.execution import EvaluationCache
from pneumorph.io import RunLock

from .toy_model import DyingToy, ToyModel

REPO = Path(__file__).resolve().parents[2]
LOCK = ".pneumorph.lock"


class Terminated(KeyboardInterrupt):
    """Stands for the CLI's SIGTERM (a KeyboardInterrupt subclass)."""


class BrokenPressures(ToyModel):
    """A model that fails only when its pressures are asked for (the provenance, after the checks)."""

    def pressures(self):
        raise ValueError("no pressures")


def config(tmp_path: Path, **kw) -> DesignConfig:
    ga = GAConfig(population=16, generations=8, indpb=1 / 8, hall_of_fame=5)
    return DesignConfig(**{"objective": "sin", "units": 8, "ga": ga, "cache": str(tmp_path / "cache.sqlite"),
                           "search": "ga", "executor": "serial", **kw})  # toy models, solved in this process


def snapshot(folder: Path) -> dict[str, bytes | None]:
    """Every file (its bytes) and folder (None) under ``folder``."""
    if not folder.exists():
        return {}
    return {p.relative_to(folder).as_posix(): (p.read_bytes() if p.is_file() else None)
            for p in sorted(folder.rglob("*"))}


def temporaries(folder: Path) -> list[str]:
    return [p.name for p in folder.rglob("*") if ".tmp" in p.name]


# -- the lock ---------------------------------------------------------------------------------------------
def test_a_second_run_into_a_held_folder_is_refused_and_a_dead_holders_lock_is_not_an_obstacle(
        tmp_path: Path) -> None:
    folder = tmp_path / "run"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine")
    holder = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent("""
            import sys, time
            from pneumorph.io import RunLock
            lock = RunLock(sys.argv[1]).acquire()
            print("held", flush=True)
            time.sleep(60)
        """), str(folder)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        before = snapshot(folder)
        with pytest.raises(RunFolderError) as err:
            run_design(config(tmp_path), ToyModel(), folder, figures=False)
        message = str(err.value)
        assert "\n" not in message and str(folder) in message and "in use by another run" in message
        assert f"pid {holder.pid} on " in message and "started 20" in message
        assert snapshot(folder) == before  # nothing written, the holder's lock untouched
    finally:
        holder.kill()  # killed: its lock file stays behind, its flock goes with it
        holder.wait()
    assert (folder / LOCK).exists()
    result = run_design(config(tmp_path), ToyModel(), folder, figures=False)
    assert result.status == "finished"
    assert not (folder / LOCK).exists()  # released at the end
    assert (folder / "notes.txt").read_text() == "mine"


def test_the_lock_is_held_for_the_whole_run(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    seen = []

    def on_generation(stats) -> None:
        seen.append(RunLock.holder(folder).get("pid"))
        if stats.generation == 1:  # a run nested in this one, into the same folder
            with pytest.raises(RunFolderError, match=f"pid {os.getpid()} on .* - this process"):
                run_design(config(tmp_path), ToyModel(), folder, figures=False)

    run_design(config(tmp_path), ToyModel(), folder, figures=False, on_generation=on_generation)
    assert seen == [str(os.getpid())] * 9
    assert not (folder / LOCK).exists()


def test_the_lock_without_fcntl(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import socket

    import pneumorph.io.lock as lock_module

    monkeypatch.setattr(lock_module, "fcntl", None)
    with RunLock(tmp_path), pytest.raises(RunFolderError, match="in use by another run"):
        RunLock(tmp_path).acquire()
    assert not (tmp_path / LOCK).exists()
    # the lock file of a process that no longer runs on this host is stale
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True,
                          check=True)
    (tmp_path / LOCK).write_text(f"pid={gone.stdout.strip()}\nhost={socket.gethostname()}\nstarted=x\n")
    with RunLock(tmp_path) as lock:
        assert lock.held and RunLock.holder(tmp_path)["pid"] == str(os.getpid())


# -- resume -----------------------------------------------------------------------------------------------
def test_a_resumed_run_appends_to_generations_csv(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    first = run_design(config(tmp_path), DyingToy(budget=40), folder, figures=False)
    assert first.status == "interrupted"
    old = (folder / "generations.csv").read_bytes()
    logged = len(list(csv.DictReader(old.decode().splitlines())))
    assert 1 <= logged < 9
    with (folder / "generations.csv").open("a") as fh:  # a row cut short by a kill
        fh.write(f"{logged},0.5,0.7")
    checked = []

    def on_generation(stats) -> None:  # the old rows are there while the run computes
        checked.append((folder / "generations.csv").read_bytes().startswith(old))

    again = run_design(config(tmp_path), ToyModel(), folder, figures=False, on_generation=on_generation)
    assert again.status == "finished" and all(checked) and len(checked) == 9
    text = (folder / "generations.csv").read_bytes()
    assert text.startswith(old)  # kept as they were: not rewritten, not truncated
    rows = list(csv.DictReader(text.decode().splitlines()))
    assert [int(r["generation"]) for r in rows] == list(range(9))  # each generation once
    assert [float(r["best"]) for r in rows] == [h.best for h in again.history]
    # a third run of the same settings adds nothing
    run_design(config(tmp_path), ToyModel(), folder, figures=False)
    assert (folder / "generations.csv").read_bytes() == text


def test_generation_log_rules(tmp_path: Path) -> None:
    path = tmp_path / "generations.csv"
    fields = ",".join(GenerationLog.FIELDS)
    path.write_text(f"{fields}\n0,1,2,3,4,5,6,7,8,9,01,0\nx,1\n0,9,9,9,9,9,9,9,9,9,11,0\n1,1,2,3,4,5,6,7,8,9,10,0\n")
    log = GenerationLog(path, resume=True)
    log.close()
    rows = list(csv.reader(path.read_text().splitlines()))
    assert [r[0] for r in rows[1:]] == ["0", "1"] and rows[1][-2] == "01"  # unreadable and repeated rows dropped
    assert not temporaries(tmp_path)
    # a log written before the repeats column: its rows kept under the new header, the column empty
    old = ",".join(f for f in GenerationLog.FIELDS if f != "repeats")
    path.write_text(f"{old}\n0,1,2,3,4,5,6,7,8,9,01\n")
    GenerationLog(path, resume=True).close()
    assert path.read_text().splitlines() == [fields, "0,1,2,3,4,5,6,7,8,9,01,"]
    GenerationLog(path, resume=False).close()  # a new run starts the file afresh
    assert path.read_text().splitlines() == [fields]
    # a named pipe in its place is not read (that would wait for a writer for ever): the log starts afresh
    path.unlink()
    os.mkfifo(path)
    GenerationLog(path, resume=True).close()
    assert path.is_file() and path.read_text().splitlines() == [fields]


# -- overwrite --------------------------------------------------------------------------------------------
def test_overwrite_removes_the_old_runs_files_only(tmp_path: Path) -> None:
    from pneumorph.models.fe import RampSpec, Reduced2D

    folder = tmp_path / "run"
    small = config(tmp_path, units=2, ga=GAConfig(population=4, generations=1, hall_of_fame=2))
    run_design(small, Reduced2D(2, ramp_spec=RampSpec(pressure=0.01)), folder)  # an FE model: its winner's fields
    names = {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}
    assert {"report.md", "profile.png", "convergence.png", "winner/deformed.png", "winner/vtk/winner.pvd",
            "winner/vtk/winner_01.vtu"} <= names
    assert {p.relative_to(folder).as_posix() for p in run_files(folder)} == names
    (folder / "notes.txt").write_text("mine")
    (folder / "photo.png").write_bytes(b"not a run figure")
    (folder / "winner" / "mine.txt").write_text("mine too")
    old_report = (folder / "report.md").read_bytes()

    other = config(tmp_path / "elsewhere", amplitude=15.0)  # its own cache: it solves
    with pytest.raises(RunFolderError, match=r"other \[design\] settings"):
        run_design(other, ToyModel(), folder)
    with pytest.raises(SearchConfigError):  # a check fails: nothing is removed, even with overwrite
        run_design(other, ToyModel(n_units=6), folder, overwrite=True)
    assert (folder / "report.md").read_bytes() == old_report and (folder / "profile.png").exists()

    result = run_design(other, DyingToy(budget=20), folder, overwrite=True, figures=False)
    assert result.status == "interrupted"
    left = {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}
    assert left == {"config.toml", "generations.csv", "report.md", "notes.txt", "photo.png", "winner/mine.txt"}
    assert (folder / "report.md").read_bytes() != old_report
    assert not (folder / "winner" / "vtk").exists()  # emptied by the removal
    assert "amplitude = 15.0" in (folder / "config.toml").read_text()


def _needs_a_table(tmp_path: Path) -> tuple[DesignConfig, object]:
    """A certified run of a unit no shipped table serves (2D, coarse mesh, 7 units): it would build a table."""
    from pneumorph.models.factory import make_model

    settings = {"fidelity": "2d", "unit": {"element_size": 3.0}, "pressure_kpa": 10}
    cfg = DesignConfig(objective="cos", units=7, search="certified", tolerance=0.0, executor="serial",
                       cache=str(tmp_path / "cache" / "c.sqlite"), model=settings)
    return cfg, make_model(7, settings)


def test_a_second_run_is_refused_before_it_builds_a_table(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine")
    cfg, model = _needs_a_table(tmp_path)
    with RunLock(folder):  # the same run, started before, holds the folder
        before = snapshot(folder)
        said: list[str] = []
        with pytest.raises(RunFolderError, match="in use by another run"):
            run_design(cfg, model, folder, on_message=said.append)
        assert snapshot(folder) == before
    assert not any("building" in line for line in said)  # refused before the table build began
    tables = tmp_path / "cache" / "chain-tables"
    assert not tables.exists() or not list(tables.iterdir())
    with EvaluationCache(cfg.cache) as cache:
        assert cache.count() == 0  # not one design solved


@pytest.mark.slow
def test_a_failed_table_build_releases_the_folder_it_claimed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from pneumorph.errors import LocalityError
    from pneumorph.models.chain import sources as chaintables

    def no_locality(*args, **kwargs):  # type: ignore[no-untyped-def]
        assert (folder / LOCK).exists() or (tmp_path / "new" / LOCK).exists()  # built with the folder claimed
        raise LocalityError("the chain model does not reproduce this model within 0.2 mm")

    monkeypatch.setattr(chaintables, "build_table", no_locality)
    cfg, model = _needs_a_table(tmp_path)
    folder = tmp_path / "run"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine")
    before = snapshot(folder)
    with pytest.raises(LocalityError):
        run_design(cfg, model, folder)
    assert snapshot(folder) == before  # its lock file removed again
    with pytest.raises(LocalityError):
        run_design(cfg, model, tmp_path / "new")
    assert not (tmp_path / "new").exists()  # the folder it created, removed again


def test_run_files_are_listed_in_one_place() -> None:
    assert "config.toml" in RUN_FILES and "report.md" in RUN_FILES and LOCK not in RUN_FILES


# -- a failed start ---------------------------------------------------------------------------------------
def test_a_failed_start_leaves_the_folder_as_it_was(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    run_design(config(tmp_path), ToyModel(), folder, figures=False)
    (folder / "notes.txt").write_text("mine")
    before = snapshot(folder)
    with pytest.raises(RunFolderError, match=r"other \[design\] settings"):
        run_design(config(tmp_path, amplitude=15.0), ToyModel(), folder)
    with pytest.raises(RunFolderError, match="another model"):
        run_design(config(tmp_path), ToyModel(turn=25.0), folder)
    with pytest.raises(SearchConfigError, match="the model has 6 units"):
        run_design(config(tmp_path), ToyModel(n_units=6), folder)
    with pytest.raises(ValueError, match="no pressures"):  # fails after the lock was taken
        run_design(config(tmp_path), BrokenPressures(), folder)
    (tmp_path / "cache-folder").mkdir()
    with pytest.raises(CacheError):
        run_design(config(tmp_path, cache=str(tmp_path / "cache-folder")), ToyModel(), folder)
    assert snapshot(folder) == before


def test_a_failed_start_does_not_leave_a_new_folder_behind(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="no pressures"):  # the folder was made and locked, then the run failed
        run_design(config(tmp_path), BrokenPressures(), tmp_path / "new" / "deep" / "run")
    with pytest.raises(SearchConfigError):
        run_design(config(tmp_path), ToyModel(n_units=6), tmp_path / "new" / "run")
    assert not (tmp_path / "new").exists()
    (tmp_path / "file").write_text("x")
    with pytest.raises(OutputPathError, match="is a file, not a folder"):
        run_design(config(tmp_path), ToyModel(), tmp_path / "file" / "run")
    # a config.toml that is not TOML: refused, not overwritten
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "config.toml").write_text("[design\n")
    with pytest.raises(RunFolderError, match=r"config\.toml .*: not valid TOML: .*; choose another output folder"):
        run_design(config(tmp_path), ToyModel(), tmp_path / "bad")
    assert (tmp_path / "bad" / "config.toml").read_text() == "[design\n"


# -- atomic writes ----------------------------------------------------------------------------------------
def test_results_are_written_atomically_and_json_is_strict(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = tmp_path / "run"
    run_design(config(tmp_path), ToyModel(fail={"00000000", "11111111"}), folder)
    assert not temporaries(folder)
    def refuse(constant: str) -> None:
        pytest.fail(f"not strict JSON: {constant}")

    hof = json.loads((folder / "hall_of_fame.json").read_text(), parse_constant=refuse)
    assert hof["designs"]
    figure = (folder / "convergence.png").read_bytes()
    report = (folder / "report.md").read_bytes()

    def broken(history, path, unit):  # dies half way through writing its file
        Path(path).write_bytes(b"half a figure")
        raise RuntimeError("disk full")

    monkeypatch.setattr(report_module, "plot_convergence", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        run_design(config(tmp_path), ToyModel(fail={"00000000", "11111111"}), folder)
    assert (folder / "convergence.png").read_bytes() == figure  # the old file, whole
    assert (folder / "report.md").read_bytes() == report
    assert not temporaries(folder) and not (folder / LOCK).exists()


def test_exhaustive_outputs_are_atomic(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    run_design(config(tmp_path, objective="max-y", search="exhaustive", units=5), ToyModel(n_units=5), folder)
    assert {"ranking.csv", "hall_of_fame.json", "report.md", "profile.png"} <= {p.name for p in folder.iterdir()}
    assert not temporaries(folder)


def test_json_is_strict_when_every_design_fails(tmp_path: Path) -> None:
    model = ToyModel(fail={format(i, "08b") for i in range(256)})
    result = run_design(config(tmp_path), model, tmp_path / "run", figures=False)
    assert result.status == "finished" and result.best.failure == "toy failure"
    text = (tmp_path / "run" / "hall_of_fame.json").read_text()
    assert "Infinity" not in text and "NaN" not in text
    first = json.loads(text)["designs"][0]
    assert first["value"] is None and first["value_reason"] == "+infinite"


# -- interruption -----------------------------------------------------------------------------------------
def test_a_keyboard_interrupt_subclass_is_an_interruption(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    result = run_design(config(tmp_path), DyingToy(budget=40, signal=Terminated), folder, figures=False)
    assert result.status == "interrupted"
    assert "**Interrupted.**" in (folder / "report.md").read_text()
    assert not (folder / LOCK).exists()


def test_an_interrupt_while_drawing_still_writes_the_report(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def interrupted(*args, **kw):
        raise Terminated()

    monkeypatch.setattr(report_module, "plot_convergence", interrupted)
    folder = tmp_path / "run"
    result = run_design(config(tmp_path), ToyModel(), folder)
    assert result.status == "interrupted"
    report = (folder / "report.md").read_text()
    assert "**Interrupted.**" in report and "profile.png" in report and "convergence.png" not in report
    assert {p.name for p in result.files} == {"generations.csv", "hall_of_fame.json", "profile.png", "report.md"}
    assert not temporaries(folder) and not (folder / LOCK).exists()


# -- a worker that dies -----------------------------------------------------------------------------------
def test_a_worker_that_dies_fails_its_design_and_the_run_goes_on(tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(REPO))
    from tests.execution.test_evaluators import TroubleToy

    model = TroubleToy(n_units=5, exit={"01101"})
    cfg = config(tmp_path, objective="max-y", search="exhaustive", units=5, executor="processes", workers=2)
    result = run_design(cfg, model, tmp_path / "run", figures=False)
    assert result.status == "finished" and result.solves == 17
    rows = {r["design"]: r for r in csv.DictReader((tmp_path / "run" / "ranking.csv").open())}
    assert len(rows) == 32 and rows["01101"]["failed"] == "True"
    assert sum(r["failed"] == "True" for r in rows.values()) == 2  # the design and its mirror, derived from it


def test_a_worker_death_is_not_cached(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(REPO))
    from tests.execution.test_evaluators import TroubleToy

    model = TroubleToy(n_units=5, exit={"01101"})
    cfg = config(tmp_path, objective="max-y", search="exhaustive", units=5, executor="processes", workers=1)
    run_design(cfg, model, tmp_path / "run", figures=False)
    with EvaluationCache(tmp_path / "cache.sqlite") as cache:
        assert cache.get(model.fingerprint(), "01101") is None
        assert cache.get(model.fingerprint(), "01100") is not None
