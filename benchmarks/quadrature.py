"""Cheaper quadrature of the 3D model's hex20 bodies: cost and answers against the default rule.

The 3D model integrates its quadratic hexahedra with FElupe's default 3x3x3 Gauss rule (27
points). Two cheaper rules are tried on the same 1.5 mm mesh and the same ramp:

* ``reduced``: 2x2x2 Gauss (8 points), the reduced integration of commercial codes' C3D20R;
* ``fourteen``: the 14-point rule of Irons (exact for polynomials of degree 5, the same
  degree per direction as the default rule), which keeps the element's rank.

For each design: the tip and curl at 36 and 45 kPa, the largest distance of the unit centres
from the default rule's at any level, Newton iterations, factorisations and CPU time. The
refined meshes' answers and their Richardson limits for the same designs are in
``src/pneumorph/models/data/mesh-study-3d.json`` (``pneumorph sensitivity mesh``). Run on one
core:

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/quadrature.py --design 001111010001001

Also ``--rank``: the zero eigenvalues of one free hex20 element's tangent under each rule (6
rigid-body modes; reduced integration adds 6 spurious ones) and the smallest eigenvalues of a
clamped 1-unit actuator's tangent (a spurious mode that spreads through the mesh would show
as a near-zero one).
"""

from __future__ import annotations

import argparse
import contextlib
import time
from collections.abc import Iterator
from unittest import mock

import numpy as np

RULES = ("default", "reduced", "fourteen")


def irons14() -> object:
    """The 14-point rule of Irons on the cube [-1, 1]^3 (weights sum to 8)."""
    import felupe as fem

    a, b = 0.795822425754222, 0.758786910639328
    points = [[s * a if j == axis else 0.0 for j in range(3)] for axis in range(3) for s in (-1, 1)]
    points += [[sx * b, sy * b, sz * b] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    weights = [0.886426592797784] * 6 + [0.335180055401662] * 8
    return fem.quadrature.Scheme(np.array(points), np.array(weights))


def rule(name: str) -> object | None:
    """FElupe's quadrature of a rule name (None: the region's default)."""
    import felupe as fem

    return {"default": None, "reduced": fem.GaussLegendre(order=1, dim=3), "fourteen": irons14()}[name]


@contextlib.contextmanager
def quadrature(name: str) -> Iterator[None]:
    """Every hex20 solid region built inside uses the rule ``name``."""
    from pneumorph.fem import parts

    original, scheme = parts.linked_solid, rule(name)

    def linked(umat, points, cells, cell_type, region, field_type, dim, field):  # type: ignore[no-untyped-def]
        if scheme is not None and cell_type == "hexahedron20":
            return original(umat, points, cells, cell_type, lambda m: region(m, quadrature=scheme), field_type, dim,
                            field)
        return original(umat, points, cells, cell_type, region, field_type, dim, field)

    with mock.patch.object(parts, "linked_solid", linked):
        yield


def rank(units: int) -> None:
    """Zero modes of a free element and the smallest eigenvalues of a clamped actuator, per rule."""
    import felupe as fem
    import scipy.sparse.linalg as sla

    from pneumorph.fem.fast.system import SolidSystem3D
    from pneumorph.fem.ogden import OgdenCompressible
    from pneumorph.models.fe import Full3D

    umat = OgdenCompressible([0.13], [2.0], 0.119)
    for name in RULES:
        mesh = fem.Cube(n=2).add_midpoints_edges()  # one hex20
        scheme = rule(name)
        region = fem.RegionQuadraticHexahedron(mesh, **({} if scheme is None else {"quadrature": scheme}))
        field = fem.FieldContainer([fem.Field(region, dim=3)])
        system = SolidSystem3D([fem.SolidBody(umat, field)], field, np.arange(field[0].values.size),
                               np.zeros(0, dtype=np.int64))
        system.residual(np.zeros(field[0].values.size))
        w = np.linalg.eigvalsh(system.tangent().toarray())
        zero = int(np.sum(np.abs(w) < 1e-9 * np.abs(w).max()))
        with quadrature(name):
            _, body, _ = Full3D(units).build("0" * units)
        clamped = SolidSystem3D(body.items, body.field, body.dof1, body.dof0)
        clamped.residual(np.zeros(body.field[0].values.size))
        smallest = np.sort(sla.eigsh(clamped.tangent(), k=4, sigma=-1e-9, return_eigenvectors=False))
        print(f"  {name:>8}: free hex20 element {zero} zero eigenvalues; clamped {units}-unit actuator, smallest "
              f"eigenvalues {', '.join(f'{v:.4e}' for v in smallest)}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--design", action="append", help="0/1 design (repeatable; default 001111010001001)")
    parser.add_argument("--rules", nargs="+", choices=RULES, default=list(RULES))
    parser.add_argument("--rank", type=int, metavar="UNITS", help="only the eigenvalue check on this many units")
    args = parser.parse_args()
    if args.rank:
        rank(args.rank)
        return
    from pneumorph.models.fe import Full3D

    for design in args.design or ["001111010001001"]:
        reference = None
        for name in args.rules:
            with quadrature(name):
                model = Full3D(len(design))
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
            print(f"{design} {name:>8}: {at}{gap}; {m['newton_iterations']} iterations, {m['factorisations']} "
                  f"factorisations, {m['cutbacks']} cut-backs, {cpu:.1f} s CPU", flush=True)


if __name__ == "__main__":
    main()
