"""Regenerate the bimodal-actuator table and figures of docs/bimodal.md.

Runs the 3D model for the three crimp ratios, each with the composite's variants: the Ecoflex
matrix with the crimped paper as fibres, the paper of the cast coupons (the default
model, Table 3.2: ``cast``) or the ideal crimp (``ideal``), and the Table B.1
homogeneous material with a nearly incompressible composite (``homogenised``, nu = 0.495) or
the library's assumed bulk modulus (``library``); one process, one run after the other;
every run's result is kept as JSON in ``--out`` and reused when the script is started again
(delete the file to re-run it). Figures go to docs/figures/. The ramp drives the voids'
volume (``--control volume``, the default) or the pressure.

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python docs/scripts/bimodal_table.py [--voids 15]
        [--element-size 2.5] [--pmax 60] [--end-cap 0] [--max-cutbacks N] [--max-iterations N]
        [--control volume] [--volume-change 8] [--variants cast ideal homogenised library]
        [--out /tmp/bimodal-runs] [--only 0.2] [--tag=-v5]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from pneumorph.bimodal.figures import plot_outlines, plot_tip_paths
from pneumorph.bimodal.geometry import BimodalSpec
from pneumorph.bimodal.model import BimodalModel, BimodalResult, bilinear_material, bulk_from_poisson
from pneumorph.bimodal.switch import find_switch
from pneumorph.materials import get

DOCS = Path(__file__).resolve().parents[1]
#: variant: (composite model, the composite's Poisson's ratio or None for the library's bulk modulus, label)
VARIANTS = {"cast": ("fibre", None, "cast paper as fibres"),
            "ideal": ("fibre", None, "ideal crimp as fibres"),
            "homogenised": ("homogenised", 0.495, "homogenised, nu = 0.495"),
            "library": ("homogenised", None, "homogenised, library K")}


def station_from_outline(outline: np.ndarray, spec: dict) -> np.ndarray:
    """Mean displacement of the bottom and top outline points at x = (voids - 1) pitch."""
    ref = outline[0]
    x = (spec["voids"] - 1) * spec["pitch"]
    height = spec["bilinear"] + spec["seal"] + spec["body_height"] + spec["strip"]
    ids = [int(np.flatnonzero(np.isclose(ref[:, 0], x) & np.isclose(ref[:, 1], y))[0]) for y in (0.0, height)]
    return (outline[1:, ids] - ref[ids]).mean(axis=1)


def load(path: Path) -> BimodalResult:
    d = json.loads(path.read_text())
    p = np.asarray(d["pressures_kpa"], float) / 1e3
    tip = np.column_stack([d["tip_ux_mm"], d["tip_uy_mm"]]).reshape(-1, 2)
    outline = np.asarray(d["outline"])
    station = station_from_outline(outline, d["metadata"]["model"]["spec"])
    return BimodalResult(d["crimp_ratio"], p, tip, outline, d["pmax_kpa"] / 1e3, d["completed"],
                         d["cause"], find_switch(p, tip[:, 1]), d["metadata"], station=station,
                         station_switch=find_switch(p, station[:, 1]))


def run(cr: float, variant: str, args: argparse.Namespace, path: Path) -> BimodalResult:
    if path.exists():
        return load(path)
    composite, nu, _ = VARIANTS[variant]
    bulk = None if nu is None else bulk_from_poisson(get(bilinear_material(cr)).shear_modulus, nu)
    spec = BimodalSpec(voids=args.voids, element_size=args.element_size, end_cap=args.end_cap)
    model = BimodalModel(spec, crimp_ratio=cr, pmax=args.pmax / 1e3, bilinear_bulk=bulk,
                         max_cutbacks=args.max_cutbacks, max_iterations=args.max_iterations, composite=composite,
                         volume=args.volume_change if args.control == "volume" else None,
                         paper="ideal" if variant == "ideal" else "measured")
    t0 = time.perf_counter()
    print(f"CR {cr} {variant}: ", end="", flush=True)
    r = model.solve(on_level=lambda k, p, v: print(f"{1e3 * p:g}:{v:+.2f} ", end="", flush=True))
    print(f"({time.perf_counter() - t0:.0f} s)", flush=True)
    d = r.to_dict()
    d["outline"] = np.round(r.outline, 4).tolist()
    path.write_text(json.dumps(d))
    return load(path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--voids", type=int, default=15)
    ap.add_argument("--element-size", type=float, default=2.5)
    ap.add_argument("--pmax", type=float, default=60.0)
    ap.add_argument("--end-cap", type=float, default=0.0)  # the tables of docs/bimodal.md: none unless named
    ap.add_argument("--max-cutbacks", type=int, default=BimodalModel.default_max_cutbacks)
    ap.add_argument("--max-iterations", type=int, default=BimodalModel.default_max_iterations)
    ap.add_argument("--control", choices=["volume", "pressure"], default="volume")
    ap.add_argument("--volume-change", type=float, default=8.0)
    ap.add_argument("--out", type=Path, default=Path("/tmp/bimodal-runs"))
    ap.add_argument("--only", type=float, nargs="*", default=None, help="crimp ratios to run")
    ap.add_argument("--variants", nargs="*", default=list(VARIANTS), choices=list(VARIANTS),
                    help="composite models to run")
    ap.add_argument("--tag", default="", help="suffix of the figure names (e.g. for reduced models)")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    ratios = args.only or [0.2, 0.25, 0.3]
    stem = (f"v{args.voids}-h{args.element_size:g}-p{args.pmax:g}-cap{args.end_cap:g}"
            f"-c{args.max_cutbacks}-i{args.max_iterations}-{args.control}"
            + (f"{args.volume_change:g}" if args.control == "volume" else ""))
    rows = []
    for cr in ratios:
        runs = []
        for key, (_, _, label) in VARIANTS.items():
            if key not in args.variants:
                continue
            r = run(cr, key, args, args.out / f"{stem}-cr{cr:g}-{key}.json")
            runs.append((label, r))
            s, ss = r.switch, r.station_switch
            m = r.metadata
            rows.append(
                f"| {cr:g} | {label} ({m['model']['bulk_moduli_kpa']['bilinear']:.4g} kPa) "
                f"| {1e3 * r.pressures[-1] if len(r.pressures) else 0:g} | "
                f"{'-' if s.turning is None else f'{1e3 * s.turning:g} ({s.peak:+.2f} mm)'} | "
                f"{'none' if s.switch is None else f'{1e3 * s.switch:.1f}'} | "
                f"{'-' if ss.turning is None else f'{1e3 * ss.turning:g} ({ss.peak:+.2f} mm)'} | "
                f"{'none' if ss.switch is None else f'{1e3 * ss.switch:.1f}'} | "
                f"{r.tip[:, 1].max():+.2f} / {r.tip[:, 1].min():+.2f} | {1e3 * r.pressures.max():.1f} | "
                f"{m['dofs']:,} | {m['wall_time_s']:.0f} |"
            )
        tag = f"cr{cr:g}".replace(".", "_") + args.tag
        plot_tip_paths(runs, title=f"Bimodal actuator, CR {cr:g} ({args.voids} voids)",
                       path=DOCS / "figures" / f"bimodal-{tag}.png")
        best = max(runs, key=lambda lr: len(lr[1].pressures))[1]
        plot_outlines(best, title=f"Mid-plane outline, CR {cr:g} ({args.voids} voids)",
                      path=DOCS / "figures" / f"bimodal-{tag}-shape.png")
    print("| CR | composite (its bulk modulus) | last converged (kPa) | tip turns back at (kPa) | tip switch (kPa) "
          "| station turns back at (kPa) | station switch (kPa) | tip max / min u_y (mm) | pressure max (kPa) "
          "| dofs | time (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
