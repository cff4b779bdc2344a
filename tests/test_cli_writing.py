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
