"""The built-in unit types' responses in 3D (docs/unit-library.md).

For every type of a built-in library: a single unit's bending angle (the turn of its
free end face) and extension (the free end's displacement along the actuator) against
pressure, where the angle turns back and changes sign (the switch of a bimodal unit,
:func:`pneumorph.bimodal.switch.find_switch`), and the curl of a 15-unit actuator of that
type, all units aligned, at the design pressure. Solved through the evaluation cache, so
a second run reads its results back; writes a figure and a JSON table with provenance.

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python docs/scripts/unit_types.py --out docs/figures/unit-types.png
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python docs/scripts/unit_types.py --library modes --pressure 42 \
        --increments 14 --out docs/figures/unit-modes.png
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python docs/scripts/unit_types.py --library modes --symbols bp \
        --pressure 42 --increments 14 --out docs/figures/unit-modes-paper.png
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

from pneumorph.bimodal.switch import find_switch
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator, default_cache_path
from pneumorph.geometry.library import builtin_library
from pneumorph.io.provenance import provenance
from pneumorph.models.fe import Full3D, RampSpec
from pneumorph.plot.figure import new_figure, save_figure


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pressure", type=float, default=45.0, help="kPa")
    parser.add_argument("--units", type=int, default=15, help="units of the aligned actuator")
    parser.add_argument("--library", default="builtin", help="a built-in library: builtin, spatial, modes")
    parser.add_argument("--increments", type=int, default=Full3D.default_steps.increments, help="reported levels")
    parser.add_argument("--symbols", default="", help="only these types of the library (default: all)")
    parser.add_argument("--cache", default=str(default_cache_path()))
    parser.add_argument("--out", default="docs/figures/unit-types.png")
    args = parser.parse_args()
    library = builtin_library(args.library)
    ramp = RampSpec(pressure=args.pressure / 1e3, steps=replace(Full3D.default_steps, increments=args.increments))
    cases = []
    for symbol, spec in zip(library.symbols, library.units, strict=True):
        if spec.solid or (args.symbols and symbol not in args.symbols):
            continue  # a solid unit alone is refused (nothing to inflate); it only follows its neighbours
        cases.append((symbol, "single", Full3D(1, unit=spec, ramp_spec=ramp), "0"))
        cases.append((symbol, "aligned", Full3D(args.units, unit=spec, ramp_spec=ramp), "0" * args.units))
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(args.cache))
    results: dict[str, dict[str, object]] = {}
    for index, outcome in evaluator.iter_cases([(model, design) for _, _, model, design in cases]):
        symbol, kind, model, _ = cases[index]
        r = outcome.response
        entry = results.setdefault(symbol, {"mode": library.modes[library.symbols.index(symbol)],
                                            "pitch_mm": model.unit.pitch})
        if r is None:
            entry[kind] = {"failed": outcome.failure}
            print(symbol, kind, "failed:", outcome.failure, flush=True)
            continue
        entry[kind] = {"pressures_kpa": (r.pressures * 1e3).round(3).tolist(), "curl_deg": r.curl.round(3).tolist(),
                       "tip_dx_mm": (r.tip[:, 0] - r.reference_tip[0]).round(4).tolist(),
                       "tip_dy_mm": (r.tip[:, 1] - r.reference_tip[1]).round(4).tolist(),
                       "reached_kpa": round(float(r.reached) * 1e3, 3), "fingerprint": model.fingerprint(),
                       "seconds": outcome.wall_time}
        if kind == "single":
            # of the bending angle (its peak in degrees), to 1e-6 deg: a symmetric unit's rounding noise is no switch
            switch = find_switch(r.pressures, r.curl.round(6)).to_dict()
            switch["peak_deg"] = switch.pop("peak_mm")
            entry[kind]["switch"] = switch
        print(symbol, kind, f"curl {r.curl[-1]:.2f} deg, tip dx {r.tip[-1, 0] - r.reference_tip[0]:.3f} mm, "
              f"{outcome.wall_time:.1f} s", flush=True)
    evaluator.close()
    fig = new_figure(9.0, 3.2)
    ax_angle, ax_ext, ax_curl = fig.subplots(1, 3)
    for row, (symbol, entry) in enumerate(results.items()):
        single = entry.get("single")
        if isinstance(single, dict) and "curl_deg" in single:
            label = f"{symbol}: {entry['mode']}"
            ax_angle.plot(single["pressures_kpa"], single["curl_deg"], "o-", ms=3, label=label)
            ax_ext.plot(single["pressures_kpa"], single["tip_dx_mm"], "o-", ms=3, label=label)
            switch = single.get("switch", {}).get("switch_kpa")
            if switch is not None:  # where the unit's bending changes direction
                ax_angle.plot([switch], [0.0], "kx", ms=8)
                ax_angle.annotate(f"{symbol} switches at {switch:.1f} kPa", (switch, 0.0), textcoords="offset points",
                                  xytext=(6, -14 - 10 * row), fontsize=7)  # one line per type
        aligned = entry.get("aligned")
        if isinstance(aligned, dict) and "curl_deg" in aligned:
            ax_curl.plot(aligned["pressures_kpa"], aligned["curl_deg"], "o-", ms=3, label=f"{symbol}")
    ax_angle.set(xlabel="pressure (kPa)", ylabel="bending angle of one unit (deg)", title="single unit")
    ax_ext.set(xlabel="pressure (kPa)", ylabel="extension of one unit (mm)", title="single unit")
    ax_curl.set(xlabel="pressure (kPa)", ylabel="curl (deg)", title=f"{args.units} aligned units")
    for ax in (ax_angle, ax_ext, ax_curl):
        ax.grid(alpha=0.3)
    ax_angle.legend(fontsize=7)
    out = Path(args.out)
    save_figure(fig, out, description=f"built-in unit types ({args.library}): single-unit response and "
                "aligned-actuator curl (3D)")
    table = {"provenance": provenance(), "library": args.library, "pressure_kpa": args.pressure,
             "increments": args.increments, "types": results}
    out.with_suffix(".json").write_text(json.dumps(table, indent=1, default=str), encoding="utf-8")
    print(f"wrote {out} and {out.with_suffix('.json')}")


if __name__ == "__main__":
    main()
