"""A script of the API that starts a process pool without the ``__main__`` guard is told about the guard."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

SCRIPT = """
from pneumorph.design import DesignConfig, run_design

config = DesignConfig(objective="sin", units=2, search="exhaustive", workers=1,
                      model={"fidelity": "2d", "pressure_kpa": 5, "unit": {"element_size": 3.0}})
run_design(config, config.make_model(), "runs/x", figures=False)
"""


def test_a_script_without_the_main_guard_is_told_to_add_it(tmp_path: Path) -> None:
    """The pool's workers import the script and run it again; the advice was a command-line flag (--executor)."""
    (tmp_path / "run.py").write_text(SCRIPT, encoding="utf-8")
    env = {**os.environ, "PNEUMORPH_CACHE": str(tmp_path / "c.sqlite"), "OMP_NUM_THREADS": "1"}
    done = subprocess.run([sys.executable, "run.py"], cwd=tmp_path, capture_output=True, text=True, env=env,
                          timeout=300)
    last = done.stderr.strip().splitlines()[-1]
    assert done.returncode == 1 and last.startswith("pneumorph.errors.EvaluationError: the worker processes died")
    assert 'if __name__ == "__main__":' in last and 'executor "serial"' in last and "--executor" not in last
