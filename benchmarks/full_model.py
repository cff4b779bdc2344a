"""Wall time of one full 3D model solve (no mid-plane symmetry): a 15-unit design with sideways units.

A design over the built-in ``spatial`` library (``a`` bending in the plane, ``l`` sideways)
is solved by :class:`~pneumorph.models.fe.full3d.Full3D` on the full width (a sideways unit
breaks the mid-plane symmetry), the default 1.5 mm hex20 mesh, 10 reported levels to 45 kPa,
the model's own ramp and fast path. Run on one core as a search worker would:

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/full_model.py --repeat 3

The target: <= 30 s on one core (goal 20 s). ``--design`` takes any design over the
library (default: a random one of ``a A l L``, seed 0, with at least one sideways unit);
``--planar`` solves a planar design on the full width too (``half=False``) and on the half
width, to tell the cost of the full width from that of leaving the plane.

``--grid X Z`` is an experiment for the decision on the bar: the assembly's grid lines drawn
no further apart than X mm along the actuator and Z mm across the width (the breaks at every
wall and layer face stay), instead of the unit's element size; the centres are then compared
with the default mesh's. Not a model pneumorph offers (BENCHMARKS.md, "A coarser mesh for the
full model").
"""

from __future__ import annotations

import argparse
import contextlib
import os
import platform
import statistics
import time
from collections.abc import Iterator
from unittest import mock

import numpy as np

from pneumorph.geometry import assembly
from pneumorph.geometry.grid import grid_lines
from pneumorph.geometry.library import builtin_library
from pneumorph.models.fe import Full3D, RampSpec
from pneumorph.models.response import Response


def _solve(model: Full3D, design: str, repeat: int, label: str, grid: tuple[float, float] | None = None) -> Response:
    """Solve ``design`` ``repeat`` times, print each run and the median; the last response.

    ``grid``: the grid spacing along x and across the width (the experiment of ``--grid``).
    """
    times, response = [], None
    for i in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        with _coarser(grid):
            response = model.evaluate(design)
        times.append(time.perf_counter() - t0)
        m = response.metadata
        tip = response.tip[-1] - response.reference_tip
        print(f"  {label} run {i + 1}: {times[-1]:.2f} s wall, {time.process_time() - c0:.2f} s CPU, "
              f"{m['newton_iterations']} iterations ({m['factorisations']} factorisations), {m['cutbacks']} cut-backs, "
              f"{m['dofs']} dofs, curl {response.curl[-1]:.4f} deg, tip displacement "
              f"({', '.join(f'{v:.3f}' for v in tip)}) mm", flush=True)
    print(f"  {label}: median {statistics.median(times):.2f} s over {repeat} runs", flush=True)
    assert response is not None
    return response


@contextlib.contextmanager
def _coarser(grid: tuple[float, float] | None) -> Iterator[None]:
    """The assembly's grid lines no further apart than ``grid`` (x, z) mm while inside; unchanged for ``None``.

    The assembly draws the x, y and z lines in that order (``geometry.assembly``), so every
    third call is across the width.
    """
    if grid is None:
        yield
        return
    drawn = {"calls": 0}

    def lines(breaks: list[float], size: float) -> np.ndarray:
        axis = drawn["calls"] % 3
        drawn["calls"] += 1
        return grid_lines(breaks, (grid[0], size, grid[1])[axis])

    with mock.patch.object(assembly, "grid_lines", lines):
        yield


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--units", type=int, default=15)
    parser.add_argument("--pressure", type=float, default=45.0, help="kPa")
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--design", help="a design over the spatial library (default: random a/A/l/L, seed 0)")
    parser.add_argument("--planar", help="also solve this planar design (0/1 or a/A) on the full and the half width")
    parser.add_argument("--grid", type=float, nargs=2, metavar=("X", "Z"),
                        help="experiment: grid spacing along x and across the width, mm (module docstring)")
    args = parser.parse_args()
    library = builtin_library("spatial")
    model = Full3D(args.units, library=library,
                   ramp_spec=RampSpec(pressure=args.pressure / 1e3, steps=Full3D.default_steps))
    design = args.design or "".join(np.random.default_rng(0).choice(list("aAlL"), args.units))
    threads = os.environ.get("MKL_NUM_THREADS", "unset"), os.environ.get("OMP_NUM_THREADS", "unset")
    print(f"full 3D model ({model.backend}), spatial library, design {design}, {args.pressure:g} kPa; "
          f"{platform.machine()}, Python {platform.python_version()}, MKL_NUM_THREADS={threads[0]}, "
          f"OMP_NUM_THREADS={threads[1]}", flush=True)
    # warm-up: imports, MKL, caches, on a 1-unit sideways actuator (a second 15-unit solve would double the run)
    Full3D(1, library=library, ramp_spec=RampSpec(pressure=0.005, steps=Full3D.default_steps)).evaluate("l")
    print(f"  half model for this design: {model.half_for(design)} (a sideways unit: the full width)")
    response = _solve(model, design, args.repeat, "sideways design")
    if args.grid:
        coarse = _solve(model, design, args.repeat, f"the same on a grid of {args.grid[0]:g} x {args.grid[1]:g} mm",
                        grid=tuple(args.grid))
        print(f"  coarser grid against the default: centres within "
              f"{np.linalg.norm(coarse.centres - response.centres, axis=-1).max():.3f} mm, tip within "
              f"{np.linalg.norm(coarse.tip - response.tip, axis=-1).max():.3f} mm, curl "
              f"{coarse.curl[-1] - response.curl[-1]:+.3f} deg")
    if args.planar:
        full = Full3D(args.units, library=library, ramp_spec=model.ramp, half=False)
        a = _solve(full, args.planar, args.repeat, "planar design, full width")
        b = _solve(model, args.planar, args.repeat, "planar design, half width")
        gap = max(np.abs(a.centres[..., :2] - b.centres).max(), np.abs(a.tip[:, :2] - b.tip).max())
        print(f"  full against half width: centres and tip within {gap:.2e} mm, z within "
              f"{np.abs(a.centres[..., 2] - a.reference_centres[None, :, 2]).max():.2e} mm of the mid-plane")


if __name__ == "__main__":
    main()
