"""Cost of one constitutive evaluation (stress + tangent) per Newton iteration.

Evaluates the compressible Ogden model of Mold Star 15 (Table A.4, K = 119 kPa, Eq 2.12)
at the quadrature points of the 15-unit 2D mesh (1,260 quad8 cells x 9 points), as one
Newton iteration of the 2D model does:

- ``pneumorph.fem.OgdenCompressible`` (hand-coded spectral stress and tangent),
- the automatic-differentiation form ``pneumorph.materials.laws.felupe_models.build_umat``,
- FElupe's hand-coded neo-Hooke, as the floor of what a hyperelastic kernel costs.

Usage: ``OMP_NUM_THREADS=1 python benchmarks/constitutive_kernels.py [--repeat 5]``.
Prints CPU seconds (best of the repeats) per evaluation.
"""

from __future__ import annotations

import argparse
import platform
import time

import felupe as fem
import numpy as np

from pneumorph.fem import OgdenCompressible
from pneumorph.materials import get
from pneumorph.materials.laws.felupe_models import build_umat


def best_cpu_time(fn, F: np.ndarray, repeat: int) -> float:  # type: ignore[no-untyped-def]
    """Best CPU time of ``fn(F_k)`` over slightly different ``F_k`` (no cache hits)."""
    times = []
    for k in range(repeat):
        Fk = F * (1.0 + 1e-9 * (k + 1))
        t0 = time.process_time()
        fn(Fk)
        times.append(time.process_time() - t0)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--cells", type=int, default=1260)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    F = np.eye(3)[:, :, None, None] + 0.1 * rng.standard_normal((3, 3, 9, args.cells))
    F[2, :2] = F[:2, 2] = 0.0  # plane strain: F13 = F23 = F31 = F32 = 0
    F[2, 2] = 1.0
    ms15 = get("mold_star_15")
    K = ms15.bulk_modulus.value
    kernels = {
        "hand-coded Ogden (pneumorph.fem.OgdenCompressible)": OgdenCompressible(ms15.model.mu, ms15.model.alpha, K),
        "AD Ogden (felupe_models.build_umat, tensortrax)": build_umat(ms15.model, K, "compressible"),
        "FElupe hand-coded neo-Hooke (floor)": fem.NeoHooke(mu=ms15.shear_modulus, bulk=K),
    }
    print(f"{F.shape[-1] * F.shape[-2]} quadrature points; {platform.processor() or platform.machine()}, "
          f"Python {platform.python_version()}, numpy {np.__version__}, felupe {fem.__version__}")
    for name, umat in kernels.items():
        def both(Fk: np.ndarray, umat=umat) -> None:  # type: ignore[no-untyped-def]
            umat.gradient([Fk, None])  # a Newton iteration: residual, then tangent at the same F
            umat.hessian([Fk, None])

        g = best_cpu_time(lambda Fk, umat=umat: umat.gradient([Fk, None]), F, args.repeat)
        b = best_cpu_time(both, F, args.repeat)
        print(f"{name:55s} stress {g * 1e3:7.1f} ms   stress+tangent {b * 1e3:7.1f} ms")


if __name__ == "__main__":
    main()
