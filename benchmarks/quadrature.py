"""Cheaper quadrature of the FE models' quadratic cells: cost and answers against the full rule.

The models integrate their quadratic cells with the rule of their ``quadrature`` setting
(``[model] quadrature``, :func:`pneumorph.fem.body.quadrature_scheme`): ``full`` (FElupe's
default Gauss rule, 3x3x3 = 27 points per hex20, 3x3 = 9 per quad8), ``reduced`` (2x2x2 = 8
points, the reduced integration of commercial codes' C3D20R; 2x2 per quad8) and ``irons``
(Irons' 14-point rule, exact to degree 5 like the full rule, which keeps the element's rank;
hex20 only). Each rule on the same default mesh and the same ramp.

For each design: the tip and curl at 36 and 45 kPa, the largest distance of the unit centres
from the first rule's at any level, Newton iterations, factorisations and CPU time. The
refined meshes' answers and their Richardson limits for the same designs are in
``src/pneumorph/models/data/mesh-study-3d.json`` (``pneumorph sensitivity mesh``). Run on one
core:

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/quadrature.py --design 001111010001001
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/quadrature.py --model 2d --rules full reduced

Also ``--rank``: the zero eigenvalues of one free hex20 element's tangent under each rule (6
rigid-body modes; reduced integration adds 6 spurious ones) and the smallest eigenvalues of a
clamped actuator's tangent (a spurious mode that spreads through the mesh would show as a
near-zero one). ``tests/fem/test_quadrature.py`` checks the same.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from pneumorph.fem.body import QUADRATURES


def rank(units: int) -> None:
    """Zero modes of a free element and the smallest eigenvalues of a clamped actuator, per rule."""
    import felupe as fem
    import scipy.sparse.linalg as sla

    from pneumorph.fem.body import regions_of
    from pneumorph.fem.fast.system import SolidSystem3D
    from pneumorph.fem.ogden import OgdenCompressible
    from pneumorph.models.fe import Full3D

    umat = OgdenCompressible([0.13], [2.0], 0.119)
    for name in QUADRATURES:
        mesh = fem.Cube(n=2).add_midpoints_edges()  # one hex20
        field = fem.FieldContainer([fem.Field(regions_of("hexahedron20", name)[0](mesh), dim=3)])
        system = SolidSystem3D([fem.SolidBody(umat, field)], field, np.arange(field[0].values.size),
                               np.zeros(0, dtype=np.int64))
        system.residual(np.zeros(system.ndof))
        w = np.linalg.eigvalsh(system.tangent().toarray())
        zero = int(np.sum(np.abs(w) < 1e-9 * np.abs(w).max()))
        _, body, _ = Full3D(units, quadrature=name).build("0" * units)
        clamped = SolidSystem3D(body.items, body.field, body.dof1, body.dof0)
        clamped.residual(np.zeros(clamped.ndof))
        smallest = np.sort(sla.eigsh(clamped.tangent(), k=4, sigma=-1e-9, return_eigenvectors=False))
        print(f"  {name:>8}: free hex20 element {zero} zero eigenvalues; clamped {units}-unit actuator, smallest "
              f"eigenvalues {', '.join(f'{v:.4e}' for v in smallest)}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--design", action="append", help="0/1 design (repeatable; default 001111010001001)")
    parser.add_argument("--model", choices=("2d", "3d"), default="3d")
    parser.add_argument("--rules", nargs="+", choices=QUADRATURES, default=list(QUADRATURES))
    parser.add_argument("--rank", type=int, metavar="UNITS", help="only the eigenvalue check on this many units")
    args = parser.parse_args()
    if args.rank:
        rank(args.rank)
        return
    from pneumorph.models.factory import make_model

    for design in args.design or ["001111010001001"]:
        reference = None
        for name in args.rules:
            model = make_model(len(design), {"fidelity": args.model, "quadrature": name})
            c0 = time.process_time()
            r = model.evaluate(design)
            cpu = time.process_time() - c0
            m = r.metadata
            levels = {round(float(p) * 1e3): k for k, p in enumerate(r.pressures)}
            at = "; ".join(f"{kpa} kPa tip ({r.tip[k][0]:.3f}, {r.tip[k][1]:.3f}) mm curl {r.curl[k]:.3f} deg"
                           for kpa, k in levels.items() if kpa in (36, 45))
            gap = "" if reference is None else (
                f"; centres within {np.linalg.norm(r.centres - reference.centres, axis=-1).max():.3f} mm of "
                f"{args.rules[0]}'s")
            reference = reference or r
            print(f"{design} {args.model} {m['quadrature']:>8}: {at}{gap}; {m['newton_iterations']} iterations, "
                  f"{m['factorisations']} factorisations, {m['cutbacks']} cut-backs, {cpu:.1f} s CPU", flush=True)


if __name__ == "__main__":
    main()
