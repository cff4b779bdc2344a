"""A design run's folder: which files are a run's, whether a folder holds the same run, the
generation log a resumed run appends to.

Nothing a run writes is lost or mixed up (:mod:`pneumorph.design.driver` says how the run
claims its folder): ``overwrite`` removes the files of the old run (:data:`RUN_FILES` and the
files its report lists), ``config.toml`` last; ``generations.csv`` is appended to, never
truncated by a resumed run (see :class:`GenerationLog`).
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import re
from pathlib import Path
from typing import Any

from pneumorph.design.config import DesignConfig
from pneumorph.design.search.genetic import GenerationStats
from pneumorph.errors import RunFolderError
from pneumorph.io.files import atomic_write_text, read_text_file
from pneumorph.io.lock import LOCK_NAME as LOCK_FILE
from pneumorph.io.reading import read_toml

_COMPARED = ("design", "ga", "model")

#: The files a run writes into its folder (glob patterns, relative to it): what ``overwrite`` removes,
#: besides the files the old run's report lists and the temporary files of an interrupted write.
#: The lock file (``.pneumorph.lock``) is not a run file.
RUN_FILES = (
    "config.toml",
    "generations.csv",
    "ranking.csv",
    "hall_of_fame.json",
    "certificate.json",
    "top.csv",
    "robustness.json",
    "profile.png",
    "chain-vs-fe.png",
    "convergence.png",
    "winner/deformed.png",  # an FE model's winner, solved again with its fields
    "winner/vtk/winner.pvd",
    "winner/vtk/winner_*.vtu",
    "report.md",
)


def default_folder(config: DesignConfig, root: str | Path = "runs") -> Path:
    """The folder a run of ``config`` writes to when none is given: ``<root>/<target>-<units>u-<search>-<model>-<key>``.

    ``key`` is a digest of every setting that changes the answer (the ``[design]``, ``[ga]`` and
    ``[model]`` tables :func:`check_folder` compares: the target and its parameters, stages,
    search, seed, robustness, library, unit, pressure, model), so two runs that could answer
    differently never share a folder, and the same command again resumes its own run.

    Examples
    --------
    >>> a = default_folder(DesignConfig(objective="cos", amplitude=20.0))
    >>> a.parent.name, a.name.startswith("cos-15u-certified-")
    ('runs', True)
    >>> a == default_folder(DesignConfig(objective="cos", amplitude=20.0))
    True
    >>> a == default_folder(DesignConfig(objective="cos", amplitude=10.0))
    False
    """
    data = config.to_dict()
    key = hashlib.sha256(json.dumps({t: data.get(t, {}) for t in _COMPARED}, sort_keys=True,
                                    default=str).encode()).hexdigest()[:8]
    target = "path" if config.path is not None else config.objective
    slug = re.sub(r"[^a-z0-9]+", "-", target.lower()).strip("-")[:40] or "target"
    model = str(config.model.get("fidelity", "model"))
    return Path(root) / f"{slug}-{config.units}u-{config.search}-{model}-{key}"


def check_folder(folder: Path, config: DesignConfig, fingerprint: str, overwrite: bool) -> bool:
    """True if ``folder`` holds the same run (resume); an error if it holds another one."""
    path = folder / "config.toml"
    if not path.exists() or overwrite:
        return False
    try:  # the one bounded reader: a pipe, a file past its size or nested too deep is refused naming it
        old = read_toml(path, "the output folder's config.toml", RunFolderError)
    except RunFolderError as exc:
        raise RunFolderError(f"{exc}; choose another output folder or overwrite it") from None
    new = config.to_dict()
    for table in _COMPARED:
        if old.get(table, {}) != new.get(table, {}):
            there, here = old.get(table, {}), new.get(table, {})
            keys = sorted(k for k in {*there, *here} if there.get(k) != here.get(k))
            diff = "; ".join(f"{k} = {_setting(there.get(k))} there, {_setting(here.get(k))} now" for k in keys[:4])
            more = f" (and {len(keys) - 4} more)" if len(keys) > 4 else ""
            raise RunFolderError(
                f"{folder} holds a run with other [{table}] settings: {diff}{more}; give another folder with --out "
                "or replace that run with --overwrite"
            )
    old_fp = old.get("provenance", {}).get("model_fingerprint")
    if old_fp not in (None, fingerprint):
        raise RunFolderError(
            f"{folder} holds a run of another model (fingerprint {old_fp}, now {fingerprint}); "
            "give another folder with --out or replace that run with --overwrite"
        )
    return True


def _setting(value: Any) -> str:
    """A setting as a config shows it (``unset`` when absent), cut to 40 characters."""
    text = "unset" if value is None else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


class GenerationLog:
    """``generations.csv``: one row per generation, written (flushed and synced) as it is known.

    A new run starts the file with its header. A resumed run keeps every row the file holds
    and appends to it; it never truncates it. The rule for rows: **a generation is logged
    once, by the run that first computed it.** A resumed GA replays generations 0, 1, ...
    with the same seed, the evaluation cache answering the designs solved before; a replayed
    generation that the file already holds is not written again (the kept row has the same
    fitness statistics, and the solves and wall time it really took), and the first
    generation beyond them is appended. A last line cut short by a kill (no line end) or a
    row that cannot be read is dropped; only then is the file rewritten, atomically, with the
    rows it keeps.
    """

    FIELDS = tuple(GenerationStats.__dataclass_fields__)

    def __init__(self, path: Path, resume: bool) -> None:
        self.path = path
        self.rows: list[GenerationStats] = []
        self.logged: set[int] = set()
        kept, clean = self._existing() if resume else ([], False)
        if not clean:
            atomic_write_text(path, self._lines([self.FIELDS, *kept]))
        self.file = path.open("a", newline="", encoding="utf-8")

    def _existing(self) -> tuple[list[list[str]], bool]:
        """The readable rows of the file, and whether it is exactly its header and those rows."""
        try:  # the one bounded reader: a pipe, a device or a huge file in its place is not read
            text = read_text_file(self.path, "the run's generations.csv", RunFolderError)
        except RunFolderError:
            return [], False
        lines = text.splitlines(keepends=True)
        clean = True
        if lines and not lines[-1].endswith(("\n", "\r")):
            lines, clean = lines[:-1], False  # cut short by a kill
        records = list(csv.reader(lines))
        if not records or "generation" not in records[0]:
            return [], False
        header, kept = records[0], []
        clean = clean and tuple(header) == self.FIELDS
        for record in records[1:]:
            row = dict(zip(header, record, strict=False))
            try:
                generation = int(row["generation"])
            except ValueError:
                generation = None
            if len(record) != len(header) or generation is None or generation in self.logged:
                clean = False
                continue
            self.logged.add(generation)
            kept.append([row.get(f, "") for f in self.FIELDS])
        return kept, clean

    @staticmethod
    def _lines(records: list[Any]) -> str:
        buffer = io.StringIO()
        csv.writer(buffer).writerows(records)
        return buffer.getvalue()

    def __call__(self, stats: GenerationStats) -> None:
        self.rows.append(stats)
        if stats.generation in self.logged:
            return
        row = stats.as_row()
        self.file.write(self._lines([[row[f] for f in self.FIELDS]]))  # one write: a whole line or nothing
        self.file.flush()
        os.fsync(self.file.fileno())
        self.logged.add(stats.generation)

    def close(self) -> None:
        self.file.close()


def created_top(folder: Path) -> Path | None:
    """The outermost folder of ``folder`` and its parents that does not exist yet (None if it exists)."""
    top = None
    probe = folder
    while not probe.exists() and probe.parent != probe:
        top, probe = probe, probe.parent
    return top


def remove_empty(folder: Path, top: Path) -> None:
    """Remove ``folder`` and its parents up to ``top`` while they are empty."""
    probe = folder
    while True:
        try:
            probe.rmdir()
        except OSError:
            return
        if probe == top or probe.parent == probe:
            return
        probe = probe.parent


def _reported_files(folder: Path) -> list[Path]:
    """The files of ``folder`` that its ``report.md`` lists (what the last run wrote)."""
    try:  # the one bounded reader: a pipe, a device or a huge file in its place is not read
        text = read_text_file(folder / "report.md", "the output folder's report.md", RunFolderError)
    except RunFolderError:
        return []
    _, found, files = text.partition("\n## Files\n")
    out = []
    for name in re.findall(r"^- \[[^\]]*\]\(([^)\n]+)\)$", files if found else "", flags=re.MULTILINE):
        rel = Path(name)
        if rel.is_absolute() or ".." in rel.parts or rel.name == LOCK_FILE:
            continue
        out.append(folder / rel)
    return out


def run_files(folder: str | Path) -> list[Path]:
    """The files of an earlier run in ``folder``: :data:`RUN_FILES`, the files its report lists and
    the temporary files of an interrupted write, ``config.toml`` last."""
    folder = Path(folder)
    found: set[Path] = set(_reported_files(folder))
    for pattern in RUN_FILES:
        parent, _, name = pattern.rpartition("/")
        found.update(folder.glob(pattern))
        found.update(folder.glob(f"{parent}/.{name}.*.tmp*" if parent else f".{name}.*.tmp*"))
    files = [p for p in found if p.name != LOCK_FILE and (p.is_file() or p.is_symlink())]
    return sorted(files, key=lambda p: (p.name == "config.toml", str(p)))


def remove_run_files(folder: Path) -> None:
    """Remove the old run's files (``config.toml`` last: a removal cut short still reads as that run)."""
    parents: set[Path] = set()
    for path in run_files(folder):
        try:
            path.unlink()
        except FileNotFoundError:
            continue
        except OSError as exc:
            raise RunFolderError(f"{folder}: cannot remove {path.name} of the old run "
                                 f"({exc.strerror or exc})") from None
        parents.update(p for p in path.parents if p != folder and p.is_relative_to(folder))
    for parent in sorted(parents, key=lambda p: len(p.parts), reverse=True):
        try:
            parent.rmdir()  # only if empty
        except OSError:
            pass
