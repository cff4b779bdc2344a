"""Regenerate the tables and figures of docs/sensitivity.md.

    OMP_NUM_THREADS=1 python docs/scripts/sensitivity_tables.py [--solve]

Every study's solves are in the evaluation cache once the commands of docs/sensitivity.md
have run (about 1.5 h of 3D solves on a 2-core machine); this script then re-runs them from
the cache (seconds), copies each study's figure to docs/figures/sensitivity-<study>.png,
draws Fig E.1 (the two calibrations of Mold Star 15) and prints the markdown rows. Without
``--solve`` it refuses to start a solve.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
FIGURES = ROOT / "docs" / "figures"
STUDIES = [  # (figure tag, study, options)
    ("simplifications", "simplifications", []),
    ("simplifications-mixed", "simplifications", ["--design", "001111010001001"]),
    ("temperature", "temperature", []),
    ("bulk-modulus", "bulk-modulus", []),
    ("calibration", "calibration", []),
    ("tolerances", "tolerances", ["--corners"]),
    ("tolerances-machined", "tolerances", ["--tolerance", "0.02"]),
]


def run(name: str, extra: list[str], out: Path, solve: bool) -> dict:
    args = [sys.executable, "-m", "pneumorph", "sensitivity", name, *extra, "--executor", "serial", "--out", str(out),
            "--json"]
    done = subprocess.run(args, check=True, capture_output=True, text=True)
    data = json.loads(done.stdout)
    fresh = [c["label"] for c in data["cases"] if not c["cached"]] + ([] if data["reference"]["cached"] else ["ref"])
    if fresh and not solve:
        raise SystemExit(f"{name}: {fresh} were solved, not cached; run with --solve to allow it")
    return data


def rows(data: dict) -> list[str]:
    out = []
    for c in data["cases"]:
        d = c.get("difference")
        if d is None:
            out.append(f"| {c['label']} | failed | | | | |")
            continue
        match = f" (closest at {c['matching_kpa']:.1f} kPa, {c['matching_mm']:.2f} mm)" if "matching_kpa" in c else ""
        out.append(f"| {c['label']}{match} | {d['distance_mm']:.2f} | {d['x_error_pct']:.2f} | "
                   f"{d['y_error_pct']:.2f} | {d['tip_mm']:.2f} | {d['curl_deg']:.1f} |")
    return out


def figure_e1(path: Path) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from pneumorph.materials import get
    from pneumorph.sensitivity.variants import COMPRESSION_RANGE, TENSION_RANGE, tension_only

    ms = get("mold_star_15")
    soft, fitted = tension_only(ms)
    lam = np.linspace(0.55, 3.0, 400)
    fig = Figure(figsize=(6.0, 4.2), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.plot(lam - 1, ms.model.uniaxial(lam), "k-", label="Table A.4 (tension and compression)")
    ax.plot(lam - 1, soft.model.uniaxial(lam), "r--", label=f"refit to tension only (R^2 {fitted.r2['uniaxial']:.6f})")
    ax.axvspan(TENSION_RANGE[0] - 1, TENSION_RANGE[1] - 1, color="0.9", label="tension data")
    ax.axvspan(COMPRESSION_RANGE[0] - 1, COMPRESSION_RANGE[1] - 1, color="#dde8f5", label="compression left out")
    ax.set(xlabel="engineering strain", ylabel="nominal stress [MPa]", ylim=(-1.0, 0.5),
           title="Mold Star 15, uniaxial (cf. Fig E.1)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")
    fig.savefig(path, dpi=150)


def main() -> None:
    solve = "--solve" in sys.argv
    FIGURES.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for tag, name, extra in STUDIES:
            data = run(name, extra, Path(tmp) / tag, solve)
            shutil.copy(Path(tmp) / tag / "study.png", FIGURES / f"sensitivity-{tag}.png")
            r = data["reference"]
            print(f"\n### {tag}: design {data['design']}, reference curl {r['curl_deg']:.2f} deg\n")
            print("| case | distance (mm) | X (%) | Y (%) | tip (mm) | curl (deg) |")
            print("|---|---:|---:|---:|---:|---:|")
            print("\n".join(rows(data)))
            if name == "tolerances":
                print("\n" + json.dumps(data["summary"], indent=1))
    figure_e1(FIGURES / "sensitivity-calibration-curves.png")


if __name__ == "__main__":
    main()
