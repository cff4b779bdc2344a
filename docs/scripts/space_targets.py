"""Measure the certified search over sideways units on targets in space, FE-verified in 3D.

Three targets for a 15-unit actuator of the built-in spatial library (`a` and the sideways
`l`) at 45 kPa, each run by `pneumorph design` as a user would (a design file, `--json`):

- ``helix``: radius 25 mm, one right-handed turn over the actuator;
- ``s-curve``: an S in the bending plane that bows out of it, ``y = 10 sin(2 pi x / L)``,
  ``z = 6 sin(pi x / L)``;
- ``own``: a drawn space curve through the FE unit centres of a sideways design at 36 kPa
  (its undeformed axis taken off): the search should give that design back, or one whose
  FE error is at most 0.15 mm.

Each result has the certificate's best design that stays in the plane beside the winner.
Writes ``docs/figures/space-targets.json`` and the runs' shape figures
``docs/figures/space-{helix,s-curve,own}.png``.

    OMP_NUM_THREADS=1 .venv/bin/python docs/scripts/space_targets.py --certify [--table FILE] [--workers 2]
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FIGURES = ROOT / "docs" / "figures"
OWN = "aalLaaLlaAAlAla"  # a design that leaves the plane both ways
OWN_KPA = 36.0


def own_curve(cache: Path) -> list[list[float]]:
    """The FE unit centres of :data:`OWN` at :data:`OWN_KPA`, from the undeformed axis, as a drawn curve."""
    from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
    from pneumorph.models.factory import make_model

    model = make_model(len(OWN), {"fidelity": "3d", "library": "spatial"})
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(cache))
    try:
        (outcome,) = evaluator.evaluate_many(model, [OWN])
    finally:
        evaluator.close()
    r = outcome.response
    k = r.level_of(OWN_KPA / 1e3)
    off = r.centres[k].copy()
    off[:, 1:] -= r.reference_centres[:, 1:]  # from the undeformed axis, as Eq 4.1 measures the centres
    return [[0.0, 0.0, 0.0], *off.round(6).tolist()]


def run(name: str, design: dict, args: argparse.Namespace, out: Path) -> dict:
    """One `pneumorph design` run of a design file; its JSON result and wall time."""
    config = out / f"{name}.toml"
    lines = ["[design]", "units = 15", 'search = "certified"', "[model]", 'fidelity = "3d"', 'library = "spatial"']
    body = "\n".join(f"{k} = {json.dumps(v)}" for k, v in design.items())
    config.write_text(lines[0] + "\n" + body + "\n" + "\n".join(lines[1:3]) + "\n" + "\n".join(lines[3:]) + "\n")
    command = [sys.executable, "-m", "pneumorph", "design", str(config), "--json", "--out", str(out / name),
               "--overwrite", "--cache", str(args.cache), "--workers", str(args.workers)]
    if args.table:
        command += ["--chain-table", str(args.table)]
    if args.certify:
        command.append("--certify")
    t0 = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    if done.returncode != 0:
        raise SystemExit(f"{name}: {done.stderr.strip().splitlines()[-1]}")
    result = json.loads(done.stdout)
    shutil.copy(out / name / "profile.png", FIGURES / f"space-{name}.png")
    cert = result["certificate"]
    best = result["best"]
    print(f"{name}: {best['design']} at {best['pressure_kpa']} kPa, FE {best['fitness']:.3f} mm; "
          f"in the plane {cert['planar']['design']} FE {cert['planar']['fe']:.3f} mm; certified {cert['certified']} "
          f"(gap {cert['gap']:.3g} mm, {len(cert['verified'])} verified); {wall:.0f} s", flush=True)
    return {"design_file": design, "wall_s": wall, "best": result["best"], "certificate": cert,
            "top": result["top"][:5], "solves": result["solves"]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", type=Path, help="the spatial library's chain table (default: the shipped one)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--certify", action="store_true", help="verify by FE until no design can beat the winner")
    parser.add_argument("--cache", type=Path, default=ROOT / ".cache" / "space-targets.sqlite")
    parser.add_argument("--out", type=Path, default=ROOT / ".cache" / "space-targets")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    args.cache.parent.mkdir(parents=True, exist_ok=True)
    cases = {
        "helix": {"objective": "helix", "amplitude": 25.0, "periods": 1.0},
        "s-curve": {"objective": "y = 10*sin(2*pi*x/L), z = 6*sin(pi*x/L)"},
        "own": {"objective": "curve", "curve": own_curve(args.cache)},
    }
    results = {name: run(name, design, args, args.out) for name, design in cases.items()}
    results["own"]["drawn_through"] = {"design": OWN, "pressure_kpa": OWN_KPA}
    command = "OMP_NUM_THREADS=1 python docs/scripts/space_targets.py" + (" --certify" if args.certify else "")
    out = {"command": command + (f" --table {args.table}" if args.table else ""),
           "results": results}
    (FIGURES / "space-targets.json").write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
