"""Run every design example in ``examples/`` and tabulate the results in ``docs/examples.md``.

All runs share one evaluation cache, so a design solved for one target is not solved again
for another. GA settings come from each example file unless ``--pop``/``--gen`` override
them (the table says which were used).

    python docs/scripts/run_examples.py [--pop 100 --gen 15] [--cache FILE] [--runs DIR]
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
ORDER = ["tip-max-x", "tip-min-x", "tip-max-y", "tip-min-distance", "sin-10", "sin-15", "sin-20",
         "cos-20", "cos-40", "cos-60"]


def run(name: str, args: argparse.Namespace) -> dict:
    out = Path(args.runs) / name
    cmd = [sys.executable, "-m", "pneumorph", "design", str(ROOT / "examples" / f"{name}.toml"),
           "--cache", args.cache, "--out", str(out), "--json", "--overwrite"]
    if args.pop:
        cmd += ["--pop", str(args.pop)]
    if args.gen:
        cmd += ["--gen", str(args.gen)]
    t0 = time.perf_counter()
    done = subprocess.run(cmd, check=True, capture_output=True, text=True)
    result = json.loads(done.stdout)
    result["wall_s"] = time.perf_counter() - t0
    import tomllib

    ga = tomllib.loads((out / "config.toml").read_text(encoding="utf-8")).get("ga", {})
    result["budget"] = f"{ga.get('population', '?')} x {ga.get('generations', '?')}"
    figures = ROOT / "docs" / "figures" / "examples"
    figures.mkdir(parents=True, exist_ok=True)
    shutil.copy(out / "profile.png", figures / f"{name}.png")
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pop", type=int)
    parser.add_argument("--gen", type=int)
    parser.add_argument("--cache", default=str(ROOT / "runs" / "examples.sqlite"))
    parser.add_argument("--runs", default=str(ROOT / "runs" / "examples"))
    parser.add_argument("--only", nargs="*", default=ORDER)
    args = parser.parse_args()
    store = ROOT / "docs" / "figures" / "examples" / "results.json"
    saved = json.loads(store.read_text(encoding="utf-8")) if store.is_file() else {}
    for name in args.only:
        r = run(name, args)
        saved[name] = {k: v for k, v in r.items() if k != "folder"}
        store.write_text(json.dumps(saved, indent=1), encoding="utf-8")
        print(f"{name}: {r['best']} ({r['solves']} solves, {r['cache_hits']} cache hits, {r['wall_s']:.0f} s)",
              flush=True)
    rows = [(name, saved[name]) for name in ORDER if name in saved]
    lines = [
        "# Results of the design examples",
        "",
        "Every example of `examples/` (the targets of Ellis (2020), chapter 6), run with the 2D",
        "reduced-order model and the built-in unit's calibrated filler law, 15 units, 10 levels",
        "to 45 kPa, seed 0, all runs sharing one evaluation cache. GA: population x generations",
        "(the files ask for 100 x 15, the dissertation's budget; a smaller budget is given on the",
        "command line, e.g. `python docs/scripts/run_examples.py --pop 24 --gen 8`).",
        "Fitness: Eq 4.1 (mm) for profiles, the tip coordinate or distance (mm) for tip goals.",
        "",
        "| example | objective | best design (base first) | pressure | fitness | GA | solves | wall |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, r in rows:
        b = r["best"]
        lines.append(f"| [`{name}`](figures/examples/{name}.png) | {r['objective']} | `{b['design']}` | "
                     f"{b['pressure_kpa']:.1f} kPa | {b['fitness']:.2f} | {r['budget']} | {r['solves']} | {r['wall_s']:.0f} s |")
    lines += ["", "Solves: new finite-element solves of that run (the others came from the shared cache).", ""]
    for name, _ in rows:
        lines += [f"![{name}](figures/examples/{name}.png)", ""]
    (ROOT / "docs" / "examples.md").write_text("\n".join(lines), encoding="utf-8")


if __name__ == "__main__":
    main()
