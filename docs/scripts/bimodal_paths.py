"""Tip paths of several ``pneumorph bimodal --json`` runs in one figure (docs/bimodal.md, like Figs 3.12-3.14).

    python docs/scripts/bimodal_paths.py --title TITLE --out docs/figures/NAME.png LABEL=run.json [LABEL=run.json ...]

Each run is the JSON that ``pneumorph bimodal --json`` prints (or writes to ``--out``).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from pneumorph.bimodal.figures import plot_tip_paths
from pneumorph.bimodal.model import BimodalResult
from pneumorph.bimodal.switch import find_switch


def load(path: Path) -> BimodalResult:
    """A :class:`BimodalResult` of a run's JSON (the tip; no outline)."""
    d = json.loads(path.read_text())
    p = np.asarray(d["pressures_kpa"], float) / 1e3
    tip = np.column_stack([d["tip_ux_mm"], d["tip_uy_mm"]]).reshape(-1, 2)
    return BimodalResult(d["crimp_ratio"], p, tip, np.zeros((len(p) + 1, 0, 2)), d["pmax_kpa"] / 1e3,
                         d["completed"], d["cause"], find_switch(p, tip[:, 1]), d["metadata"])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", help="LABEL=path.json")
    ap.add_argument("--title", default="")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    runs = [(label, load(Path(path))) for label, path in (item.split("=", 1) for item in args.runs)]
    plot_tip_paths(runs, title=args.title, path=args.out)


if __name__ == "__main__":
    main()
