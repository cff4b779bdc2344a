"""Regenerate the tables and figures of docs/material-fits.md.

Fits the five models to Treloar's (1944) three modes (bundled data set) and to the
Ecoflex 00-30 and Dragon Skin 30 tensile curves of the Soft Robotics Materials Database
(read from ../shared/reference-data beside the repository), evaluates Ogden's (1972)
published parameters on Treloar's data, prints Markdown tables and writes the figures.

Run from the repository root:

    python benchmarks/fit_reference_materials.py [--shared ../shared] [--figures docs/figures]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from pneumorph.materials.characterisation.datasets import load_dataset
from pneumorph.materials.characterisation.testdata import TestData, read_curve
from pneumorph.materials.fitting.comparison import compare
from pneumorph.materials.fitting.fit import r_squared
from pneumorph.materials.laws.hyperelastic import Ogden
from pneumorph.plot import plot_fits

MODELS = ("neo-hooke", "mooney-rivlin-2", "mooney-rivlin-3", "yeoh", "ogden-3")
SORO = "reference-data/marechal2021_SoRo-Materials-DB/Tensile-Tests-Data"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    repo = Path(__file__).resolve().parents[2]
    ap.add_argument("--shared", type=Path, default=repo.parent / "shared")
    ap.add_argument("--figures", type=Path, default=repo / "docs" / "figures")
    args = ap.parse_args()
    args.figures.mkdir(parents=True, exist_ok=True)

    t0 = time.perf_counter()
    treloar = load_dataset("treloar1944")
    table = compare(MODELS, treloar)
    print("## Treloar (1944), three modes fitted together\n")
    print(table.to_markdown())
    o = json.loads((args.shared / "reference-data/transcribed_by-helper/ogden1972_treloar_parameters.json").read_text())
    o72 = Ogden(mu=tuple(o["mu_MPa_exact_conversion"]), alpha=tuple(o["alpha"]))
    r2 = {m: r_squared(treloar.curve(m).stress, o72.nominal_stress(m, treloar.curve(m).stretch)) for m in treloar.modes}
    pooled = r_squared(np.concatenate([treloar.curve(m).stress for m in treloar.modes]),
                       np.concatenate([o72.nominal_stress(m, treloar.curve(m).stretch) for m in treloar.modes]))
    print(f"| Ogden (1972) published | {' | '.join(f'{r2[m]:.6f}' for m in treloar.modes)} | {pooled:.6f} "
          f"| {o72.shear_modulus:.4g} | - |")
    best = table.results[-1]
    print("\nogden-3 parameters:", ", ".join(f"{k} = {v:.6g}" for k, v in best.parameters.items()))
    plot_fits(treloar, table.results, args.figures / "fits-treloar1944.png")

    for name in ("Ecoflex 00-30", "Dragon Skin 30"):
        curve = read_curve(args.shared / SORO / f"{name}.csv")
        data = TestData((curve,), name)
        t = compare(MODELS, data)
        print(f"\n## {name}: {len(curve)} points, stretch {curve.stretch[0]:.4g}-{curve.stretch[-1]:.4g}\n")
        print(t.to_markdown())
        for r in t.results:
            print(f"- {r.model_name}: " + ", ".join(f"{k} = {v:.6g}" for k, v in r.parameters.items()))
        plot_fits(data, t.results, args.figures / f"fits-{name.lower().replace(' ', '-')}.png")
        ts = compare(MODELS, data, stable=True)
        print(f"\nwith stable=True (--stable):\n\n{ts.to_markdown()}")
        for r in ts.results[-2:]:
            print(f"- {r.model_name}: " + ", ".join(f"{k} = {v:.6g}" for k, v in r.parameters.items()))
    print(f"\n(total {time.perf_counter() - t0:.1f} s)")


if __name__ == "__main__":
    main()
