"""A command that writes its results after a long computation says so first: the line
``writing <what> to <DIR>`` on standard error, through the command's reporter, before any file of DIR exists.

The solves are replaced by stubs and the first writer by a probe that records what standard error held and what
the folder held when it was called, then stops the command (Ctrl-C): nothing is left written.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from pneumorph.cli import main


def _probe(capsys: pytest.CaptureFixture[str], folder: Path, seen: list[tuple[str, list[str]]]) -> Any:
    """A writer that records standard error so far and the folder's files, then is interrupted."""

    def write(*args: Any, **kwargs: Any) -> None:
        err = capsys.readouterr().err
        seen.append((err, sorted(p.name for p in folder.iterdir()) if folder.exists() else []))
        raise KeyboardInterrupt

    return write


def test_simulate_says_what_it_writes_where_before_writing(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    from pneumorph.models.fe.base import FEModel

    out, seen = tmp_path / "sim", []
    response = SimpleNamespace(save=_probe(capsys, out, seen), n_levels=2)

    def solved(self: FEModel, orientation: str, on_level: Any = None) -> Any:
        for k in range(len(self.pressures())):
            on_level(k, self.pressures()[k])
        return SimpleNamespace(response=response)

    monkeypatch.setattr(FEModel, "solve", solved)
    code = main(["simulate", "-o", "0110", "--increments", "2", "--out", str(out)])
    assert code == 130 and not out.exists()  # stopped while writing: nothing left
    ((err, files),) = seen
    assert err.splitlines()[-1] == (f"writing the response, the VTK series, the shape figure and the provenance to "
                                    f"{out}")
    assert "2/2" in err.splitlines()[-2]  # after the solve's last level
    assert files == []


@pytest.mark.parametrize("quiet", [False, True])
def test_bimodal_says_what_it_writes_where_before_writing(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                          monkeypatch: pytest.MonkeyPatch, quiet: bool) -> None:
    """The line before any file exists; with ``-q`` standard error stays free of it, as of every progress line."""
    from pneumorph.bimodal.model import BimodalModel

    out, seen = tmp_path / "bimodal", []
    monkeypatch.setattr(BimodalModel, "solve", lambda self, on_level=None: SimpleNamespace(
        crimp_ratio=0.2, to_dict=lambda: {}))
    monkeypatch.setattr("pneumorph.io.files.write_json", _probe(capsys, out, seen))
    code = main(["bimodal", "-c", "0.2", "--voids", "1", "--element-size", "5", "--pmax", "5", "--control",
                 "pressure", *(["-q"] if quiet else []), "--out", str(out)])
    assert code == 130 and not out.exists()
    ((err, files),) = seen
    assert files == []
    if quiet:
        assert "writing" not in err
    else:
        assert err.splitlines()[-1] == f"writing the response (JSON) and the figures to {out}"


def test_chain_build_says_what_it_writes_where_before_writing(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                              monkeypatch: pytest.MonkeyPatch) -> None:
    """The build is a stub; the table's save is the probe: the line is said, and the table's folder not yet made."""
    out, seen = tmp_path / "tables", []
    target = out / "chain-2d.json"
    monkeypatch.setattr("pneumorph.models.chain.fit.build_table",
                        lambda *args, **kwargs: SimpleNamespace(save=_probe(capsys, out, seen)))
    code = main(["chain", "build", "--model", "2d", "--units", "5", "--window", "1", "--out", str(target)])
    assert code == 130 and not out.exists()  # stopped while writing: no table, no folder
    ((err, files),) = seen
    assert err.splitlines()[-1] == f"writing the chain table to {target}"
    assert target.name not in files  # the table is written to a temporary file, renamed into place once whole


@pytest.mark.parametrize("mould", [False, True])
def test_export_says_what_it_writes_where_before_building_the_parts(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, mould: bool) -> None:
    """The parts' builder is the probe (after the deck's writer, a stub): both lines are said before the parts'
    booleans start, and nothing is left once stopped."""
    out, deck, seen = tmp_path / "parts", tmp_path / "deck" / "a.inp", []
    monkeypatch.setattr("pneumorph.export.write_calculix_deck", lambda model, design, path: path.write_text("*"))
    monkeypatch.setattr("pneumorph.export.actuator_parts", _probe(capsys, out, seen))
    code = main(["export", "0110", "--stl", str(out), "--inp", str(deck), *(["--mould"] if mould else [])])
    assert code == 130 and not out.exists() and not deck.parent.exists()
    ((err, files),) = seen
    parts = "the parts' STL files" + (", the casting mould and its drawing" if mould else "")
    assert err.splitlines()[-2:] == [f"writing {parts} to {out}", f"writing the CalculiX deck to {deck}"]
    assert files == []
