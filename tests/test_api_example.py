"""The worked example of docs/api.md runs as written (on the 2D model, to be quick)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[1] / "docs" / "api.md"


@pytest.mark.docs
def test_the_api_page_example_runs(tmp_path: Path) -> None:
    code = re.search(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)
    assert code is not None
    script = code.group(1).replace("units=15)", 'units=15, model={"fidelity": "2d"})')
    assert script != code.group(1)  # the page's example is the 3D run (the defaults); here its 2D twin
    (tmp_path / "example.py").write_text(script, encoding="utf-8")
    env = {**os.environ, "MPLBACKEND": "Agg", "PNEUMORPH_CACHE": str(tmp_path / "cache.sqlite")}
    done = subprocess.run([sys.executable, "example.py"], cwd=tmp_path, capture_output=True, text=True, env=env,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    lines = done.stdout.splitlines()
    assert re.fullmatch(r"[01]{15}: Eq 4\.1 error \d+\.\d+ mm at \d+(\.\d+)? kPa", lines[0]), lines
    assert lines[1] == "certified: True"
    assert lines[2].startswith("Certified: of the 32,768 designs scored by the chain model, none can beat ")
    assert lines[4].startswith("Verified by FE (2d): ")
    assert (tmp_path / "runs" / "api-sin" / "report.md").is_file()
