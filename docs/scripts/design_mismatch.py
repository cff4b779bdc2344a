"""Measure how a scan shows a design one or two units off it (docs/identify.md, "Bad input").

Five synthetic casts of a 15-unit design at 36 kPa (nominal; bulk x1.06 with wall +0.08 mm;
bulk x0.94 with wall -0.08 mm; shear x1.1 with side wall +0.1, wall -0.1, layer +0.1 mm; bulk
x1.1 with shear x0.9), each the FE model's own outline (2D) or surface (3D) with 0.05 mm
noise on 3000 points, moved. Each is aligned to the chain-predicted shape of its own design and
of seven designs one or two units off, and the coverage of :mod:`pneumorph.identify.match` is
printed: the share of points beyond half a pitch, the end units' shares, the verdict. Then the
nominal cast against its own design's shape at every level of the table (how far off a cast
may behave and pass). Writes
docs/figures/design-mismatch-<model>.json.

    OMP_NUM_THREADS=1 .venv/bin/python docs/scripts/design_mismatch.py --model 2d
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from pneumorph.correlation import correlate
from pneumorph.geometry.unit import UnitSpec
from pneumorph.identify import ParameterSet
from pneumorph.identify.extent import chain_shape
from pneumorph.identify.match import coverage
from pneumorph.models.factory import make_model

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
from tests.identify.conftest import synthetic  # noqa: E402  (the tests' synthetic casts)

DESIGN = "001111010001001"
CASTS = ([0, 0, 0, 0, 0], [0.06, 0, 0, 0.08, 0], [-0.06, 0, 0, -0.08, 0], [0, 0.1, 0.1, -0.1, 0.1],
         [0.1, -0.1, 0, 0, 0])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", choices=("2d", "3d"), default="2d")
    args = ap.parse_args()
    params = ParameterSet(UnitSpec())
    candidates = (DESIGN, DESIGN[:-1], DESIGN[1:], DESIGN[:-2], DESIGN + "0", DESIGN + "1", "0" + DESIGN,
                  DESIGN + "00")
    rows = []
    for k, change in enumerate(CASTS):
        cast = synthetic(params, params.nominal + np.array(change, dtype=float), DESIGN, args.model, seed=k,
                         points=3000)
        print(f"cast {change}", flush=True)
        for design in candidates:
            shape = chain_shape(make_model(len(design), {"fidelity": args.model, "pressure_kpa": 36.0}), design)
            assert shape is not None
            c = coverage(correlate(cast.scan, shape).aligned, shape)
            problem = c.problem()
            rows.append({"cast": change, "design": design, "units_off": len(design) - len(DESIGN),
                         "beyond": c.beyond, "first": float(c.shares[0]), "last": float(c.shares[-1]),
                         "shares": c.shares.tolist(), "refused": bool(problem)})
            print(f"  {design:18s} beyond {100 * c.beyond:5.2f} %  first {c.shares[0]:.2f}  last {c.shares[-1]:.2f}"
                  f"  {'refused' if problem else 'passes'}", flush=True)
    levels = []  # the nominal cast against its own design at every level of the table: how far off it may be
    nominal = synthetic(params, params.nominal, DESIGN, args.model, seed=0, points=3000)
    for i, kpa in enumerate(np.arange(4.5, 45.1, 4.5)):
        model = make_model(len(DESIGN), {"fidelity": args.model, "pressure_kpa": float(kpa), "increments": i + 1})
        shape = chain_shape(model, DESIGN)
        assert shape is not None
        c = coverage(correlate(nominal.scan, shape).aligned, shape)
        levels.append({"pressure_kpa": float(kpa), "beyond": c.beyond, "first": float(c.shares[0]),
                       "last": float(c.shares[-1]), "refused": bool(c.problem())})
        print(f"  cast at 36 kPa, shape at {kpa:4.1f} kPa: {'refused' if c.problem() else 'passes'}", flush=True)
    right = [r for r in rows if r["design"] == DESIGN]
    wrong = [r for r in rows if r["design"] != DESIGN]
    summary = {"right_refused": sum(r["refused"] for r in right), "right": len(right),
               "wrong_passed": sum(not r["refused"] for r in wrong), "wrong": len(wrong),
               "right_end_shares": [min(min(r["first"], r["last"]) for r in right),
                                    max(max(r["first"], r["last"]) for r in right)],
               "right_beyond_max": max(r["beyond"] for r in right),
               "passing_levels_kpa": [r["pressure_kpa"] for r in levels if not r["refused"]]}
    print(summary)
    out = ROOT / "docs" / "figures" / f"design-mismatch-{args.model}.json"
    out.write_text(json.dumps({"command": f"python docs/scripts/design_mismatch.py --model {args.model}",
                               "design": DESIGN, "pressure_kpa": 36.0, "summary": summary, "rows": rows,
                               "levels": levels}, indent=1))


if __name__ == "__main__":
    main()
