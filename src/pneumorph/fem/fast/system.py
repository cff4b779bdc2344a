"""The fast assembler: residual and tangent of FElupe items on a fixed mesh, any dimension.

FElupe assembles every item into its own sparse matrix (COO to CSR), sums them and slices
the active block at every Newton iteration; on an actuator that bookkeeping costs far more
than the quadrature points' arithmetic. :class:`FastSystem` does the bookkeeping once per
design: the shape-function gradients ``dN/dX`` and volume elements of every material
region (taken from the FElupe regions), the CSR pattern of the active block
``K[dof1, dof1]`` and, for every element-matrix entry, its position in the CSR ``data``
array. Each evaluation computes ``F``, the stress ``P`` and tangent ``A`` with the
points-last kernels of :mod:`pneumorph.fem.fast.kernels`, contracts them with batched
products and scatters them with ``np.bincount``. The model's parameters (pressure, the 2D
filler's Lame constants, dead loads) are read from the FElupe items at every evaluation,
so the same ``apply(t)`` drives both paths.

What depends on the dimension are the hooks of two small subclasses:

* :class:`PlaneStrainSystem` (quad4/quad8, ``FieldPlaneStrain``): the full active block,
  non-symmetric, for PARDISO's LU; the follower pressure ``p cof(F) N dA`` with
  ``cof(F)_iJ = e_ik e_JL F_kL`` (2D permutation symbol ``e``), whose stiffness is
  ``p h_a e_ik (N_1 dN_b/dX_2 - N_2 dN_b/dX_1) dA``.
* :class:`SolidSystem3D` (hex8/hex20, ``Field``): only the upper triangle. The material
  part is the Hessian of a strain energy, and the follower pressure on the walls of closed
  cavities is conservative (its load is the derivative of ``-p V``): each face's load
  stiffness ``p h_a e_ikm [F (N dA x dN_b/dX)]_m`` is not symmetric, but their sum over a
  closed surface is, up to terms on the surface's rim, which lies on the plane of symmetry
  where the normal displacement is held. The 27-point rule integrates the face terms of
  quadratic elements exactly, so the sum is symmetric to rounding, for PARDISO's symmetric
  indefinite solver (``mtype=-2``). Of the element matrices only the blocks ``i <= k`` of
  the component pairs are computed.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.fem.fast.assembler import TANGENT_CHUNK, FastSystem, SolidData, WallData, deformation_gradient
from pneumorph.fem.fast.kernels import neo_hooke_plane_strain, ogden_plane_strain, principal_3d
from pneumorph.fem.fast.mixed import geometric_blocks

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: component pairs (i, k) of the 3D element blocks that are computed
_UPPER = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]
_EPS = np.array([[0.0, 1.0], [-1.0, 0.0]])  # 2D permutation symbol e_ik


class PlaneStrainSystem(FastSystem):
    """The fast assembler's plane-strain hooks (quad4/quad8 on ``FieldPlaneStrain``).

    Materials: :class:`~pneumorph.fem.ogden.OgdenCompressible` and
    ``felupe.NeoHookeCompressible``; pressure walls built with ``ensure_3d=True``.

    Examples
    --------
    >>> import felupe as fem, numpy as np
    >>> mesh = fem.Rectangle(n=3).add_midpoints_edges()
    >>> field = fem.FieldContainer([fem.FieldPlaneStrain(fem.RegionQuadraticQuad(mesh), dim=2)])
    >>> solid = fem.SolidBody(fem.NeoHookeCompressible(mu=1.0, lmbda=2.0), field)
    >>> dof0, dof1 = fem.dof.partition(field, {"x0": fem.Boundary(field[0], fx=0.0)})
    >>> system = PlaneStrainSystem([solid], field, dof1, dof0)
    >>> r, jmin = system.residual(np.zeros(field[0].values.size))
    >>> float(abs(r).max()), float(jmin), system.tangent().shape == (dof1.size, dof1.size)
    (0.0, 1.0, True)
    """

    dim = 2

    def _check_field(self, sub: Any) -> None:
        import felupe as fem

        if not isinstance(sub, fem.FieldPlaneStrain):
            raise TypeError(f"the fast assembly needs FieldPlaneStrain fields, got {type(sub).__name__}")

    def _kernel_of(self, umat: Any) -> Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]:
        """The plane-strain kernel of a material, reading its parameters at every call."""
        import felupe as fem

        from pneumorph.fem.fibre import CrimpedFibreOgden
        from pneumorph.fem.ogden import OgdenCompressible

        if isinstance(umat, CrimpedFibreOgden):  # its kernel is 3D; the 2D coupon carries its paper as trusses
            raise TypeError("no fast plane-strain kernel for the crimped-fibre law; model the paper in 3D")
        if isinstance(umat, OgdenCompressible):  # without its volumetric term when that is on the mean dilatation
            return lambda F: ogden_plane_strain(F, umat.mu, umat.alpha, 0.0 if umat.mixed else umat.bulk)
        if isinstance(umat, fem.NeoHookeCompressible) and umat.lmbda is not None:
            return lambda F: neo_hooke_plane_strain(F, float(umat.mu), float(umat.lmbda))
        raise TypeError(f"no fast plane-strain kernel for {type(umat).__name__}; use the FElupe backend")

    def _prepare(self, s: SolidData, region: Any) -> None:
        g = s.g
        c, q, n, _ = g.shape
        s.layouts = {
            "g_res": np.ascontiguousarray(g.transpose(0, 2, 1, 3).reshape(c, n, 2 * q)),  # [c, a, (q, J)]
            "gT": np.ascontiguousarray(g.transpose(0, 1, 3, 2).reshape(c * q, 2, n)),  # [(c, q), L, b]
            # d_ii' g[c, q, a, J] as [c, (a, i), (q, i', J)]
            "B": np.ascontiguousarray(np.einsum("cqaJ,ij->caiqjJ", g, np.eye(2)).reshape(c, 2 * n, 4 * q)),
        }

    def _entries(self, owner: SolidData | WallData, act: IntArray) -> tuple[IntArray, IntArray, NDArray[np.bool_]]:
        # the full element matrix, entries (c, a, i, k, b)
        c, n, _ = act.shape
        rows = np.broadcast_to(act[:, :, :, None, None], (c, n, 2, 2, n))
        cols = np.broadcast_to(act.transpose(0, 2, 1)[:, None, None, :, :], (c, n, 2, 2, n))
        return rows, cols, (rows >= 0) & (cols >= 0)

    def _entry_nodes(self, owner: SolidData | WallData) -> tuple[IntArray, IntArray]:
        n = np.arange(owner.cells.shape[1])
        return n[:, None, None, None], n  # entries (a, i, k, b)

    def _solid_residual(self, s: SolidData, U: FloatArray) -> tuple[FloatArray, float, Any]:
        c, q = s.dV.shape
        F = np.ascontiguousarray(deformation_gradient(s.g, s.cells, U).transpose(2, 3, 0, 1)).reshape(2, 2, c * q)
        P, A, J = s.kernel(F)
        mixed = None
        if s.mixed is not None:  # the volumetric term on the elements' own dilatation (its tangent's terms later)
            P, mixed = self._mixed_volumetric(s, F, P, J)
        return self._element_vectors(s, P), float(J.min()), (A, mixed)

    def _element_vectors(self, s: SolidData, P: FloatArray) -> FloatArray:
        """``r[c, a, i] = sum_(q, J) g[c, q, a, J] P[i, J, c, q] dV`` of a stress-like field ``P`` (2, 2, c q)."""
        c, q = s.dV.shape
        PdV = (P * s.dV.reshape(-1)).reshape(2, 2, c, q)
        return np.matmul(s.layouts["g_res"], PdV.transpose(2, 3, 1, 0).reshape(c, 2 * q, 2))

    def _solid_tangent(self, s: SolidData, state: Any) -> FloatArray:
        A, mixed = state
        c, q, n, _ = s.g.shape
        if mixed is not None:  # the pressure's geometric term at every point
            p, cof, detF, term = mixed
            A = A + geometric_blocks(cof, detF, p)
        AdV = A * s.dV.reshape(-1)
        # D[cq, (i, J, k), b] = sum_L A[i, J, k, L, cq] dV g[cq, b, L]
        At = np.ascontiguousarray(AdV.reshape(16, c * q).T).reshape(c * q, 8, 2)
        D = np.matmul(At, s.layouts["gT"]).reshape(c, 4 * q, 2 * n)  # [c, (q, i, J), (k, b)]
        # K[c, (a, i), (k, b)] = sum_(q, J) g[c, q, a, J] D[c, (q, i, J), (k, b)]
        K = np.matmul(s.layouts["B"], D)
        if mixed is not None:  # sum_mn [M^-1 H M^-1]_mn b_m (x) b_n
            b = self._pressure_vectors(s, cof)
            m = b.shape[1]
            K += np.matmul(np.matmul(b.reshape(c, m, 2 * n).transpose(0, 2, 1), term),
                           b.transpose(0, 1, 3, 2).reshape(c, m, 2 * n))
        return K

    def _wall_tangent(self, w: WallData, p: float, U: FloatArray) -> FloatArray:
        # t[f, q, b] = N_1 dN_b/dX_2 - N_2 dN_b/dX_1 (with dA); M[f, a, b] = p sum_q h_a t_b
        t = w.ndA[..., 0:1] * w.g[..., 1] - w.ndA[..., 1:2] * w.g[..., 0]
        M = p * np.matmul(w.h.T[None], t)  # (f, n, n)
        return (_EPS[None, None, :, :, None] * M[:, :, None, None, :]).ravel()[w.take]  # of (f, a, i, k, b)

    @staticmethod
    def _cof_normal(F: FloatArray, ndA: FloatArray) -> FloatArray:
        out = np.empty_like(ndA)
        out[..., 0] = F[..., 1, 1] * ndA[..., 0] - F[..., 1, 0] * ndA[..., 1]
        out[..., 1] = -F[..., 0, 1] * ndA[..., 0] + F[..., 0, 0] * ndA[..., 1]
        return out


def _box_scales(region: Any) -> FloatArray | None:
    """``dr_J/dX_J`` of every cell ``(c, 3)`` if every cell of a 3D region is a box along the axes (``dr/dX``
    diagonal and the same at every point, to 1e-12 of its largest entry), else None."""
    drdX, dhdr = np.asarray(region.drdX), np.asarray(region.dhdr)
    if drdX.shape[:2] != (3, 3) or dhdr.ndim != 4 or dhdr.shape[-1] != 1:
        return None
    scales = np.ascontiguousarray(np.diagonal(drdX[:, :, 0], axis1=0, axis2=1))  # (c, 3)
    box = np.eye(3)[:, :, None, None] * scales.T[:, None, None, :]
    return scales if np.abs(drdX - box).max() <= 1e-12 * np.abs(drdX).max() else None


def _cross(a: FloatArray, b: FloatArray) -> FloatArray:
    """Cross products along the last axis (faster than ``numpy.cross`` on small shapes)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


class SolidSystem3D(FastSystem):
    """The fast assembler's 3D hooks (hex8/hex20 on ``Field``): the upper triangle.

    Materials: :class:`~pneumorph.fem.ogden.OgdenCompressible` (its thermal stretch too).
    The material tangent is only computed in :meth:`tangent_data`: a Newton method that
    reuses its factorisation needs many residuals and few tangents.

    Examples
    --------
    >>> import felupe as fem, numpy as np
    >>> from pneumorph.fem import OgdenCompressible
    >>> mesh = fem.Cube(n=2)
    >>> field = fem.FieldContainer([fem.Field(fem.RegionHexahedron(mesh), dim=3)])
    >>> solid = fem.SolidBody(OgdenCompressible([0.1], [2.0], 10.0), field)
    >>> dof0, dof1 = fem.dof.partition(field, {"x0": fem.Boundary(field[0], fx=0.0)})
    >>> system = SolidSystem3D([solid], field, dof1, dof0)
    >>> r, jmin = system.residual(np.zeros(field[0].values.size))
    >>> float(abs(r).max()), float(jmin), system.tangent().shape == (dof1.size, dof1.size)
    (0.0, 1.0, True)
    """

    dim = 3
    symmetric = True
    #: METIS nested dissection suits the 3D pattern
    ordering = 2
    single_precision = True

    def _check_field(self, sub: Any) -> None:
        import felupe as fem

        if type(sub) is not fem.Field or sub.dim != 3:
            raise TypeError(f"the fast 3D assembly needs 3D felupe.Field fields, got {type(sub).__name__}")

    def _kernel_of(self, umat: Any) -> Any:
        from pneumorph.fem.ogden import OgdenCompressible

        if isinstance(umat, OgdenCompressible):  # without its volumetric term when that is on the mean dilatation
            return lambda F, tangent, principal: umat.kernel(F, tangent, principal, _UPPER,
                                                             volumetric=not umat.mixed)
        raise TypeError(f"no fast 3D kernel for {type(umat).__name__}; use the FElupe backend")

    def _prepare(self, s: SolidData, region: Any) -> None:
        g = s.g
        c, q, n, _ = g.shape
        scales = _box_scales(region)
        if scales is None:  # every point's gradients
            s.layouts = {
                "G": np.ascontiguousarray(g.transpose(0, 2, 1, 3).reshape(c, n, 3 * q)),  # [c, a, (q, J)]
                "gt": np.ascontiguousarray(g.transpose(0, 1, 3, 2)),  # [c, q, L, b]
            }
            return
        # g[c, q, b, L] = D[q, b, L] t[c, L]: the products by D, a constant
        D = np.ascontiguousarray(np.transpose(region.dhdr[..., 0], (2, 0, 1)))  # (q, n, 3)
        s.layouts = {  # W[c, J, L, q] = t_J t_L dV, DD[(J, L, q), (a, b)] = D[q, a, J] D[q, b, L]
            "W": (scales[:, :, None, None] * scales[:, None, :, None] * s.dV[:, None, None, :])[:, None],
            "DD": np.einsum("qaJ,qbL->JLqab", D, D).reshape(9 * q, n * n),
            "Dr": np.ascontiguousarray(D.transpose(1, 0, 2).reshape(n, 3 * q)),  # [a, (q, J)]
            "t": np.ascontiguousarray(scales.T[None, :, :, None]),  # [., J, c, .]
            "tdV": scales[:, None, None, :] * s.dV[:, None, :, None],  # [c, ., q, J]
        }
        s.boxes = True

    def _entries(self, owner: SolidData | WallData, act: IntArray) -> tuple[IntArray, IntArray, NDArray[np.bool_]]:
        ik = np.array(_UPPER)
        if isinstance(owner, SolidData):
            # entry (c, a, ik, b) at (row of (a, i), column of (b, k)), (c, ik, a, b) of boxes; blocks i < k
            # stand for themselves and their transposes, blocks i == k hold both
            off = (ik[:, 0] != ik[:, 1])[None, None, :, None]
            rows = act[:, :, ik[:, 0]][:, :, :, None]
            cols = act[:, :, ik[:, 1]].transpose(0, 2, 1)[:, None]
            lo, hi = np.minimum(rows, cols), np.maximum(rows, cols)
            valid = (lo >= 0) & (off | (rows <= cols))
            if owner.boxes:
                return lo.transpose(0, 2, 1, 3), hi.transpose(0, 2, 1, 3), valid.transpose(0, 2, 1, 3)
            return lo, hi, valid
        # entry (f, a, i, b, k): the full face (or obstacle's node) matrix, its upper-triangle entries; of a wall not
        # those of the blocks i == k, which are zero (e_ikm): the face's cell is a solid's cell, whose entries hold
        # their places in the pattern
        rows = act[:, :, :, None, None]
        cols = act[:, None, None, :, :]
        rows, cols = np.broadcast_arrays(rows, cols)
        valid = (rows >= 0) & (rows <= cols)
        if isinstance(owner, WallData):
            valid &= np.arange(3)[:, None, None] != np.arange(3)  # (i, b, k)
        return rows, cols, valid

    def _entry_nodes(self, owner: SolidData | WallData) -> tuple[IntArray, IntArray]:
        n = np.arange(owner.cells.shape[1])
        if isinstance(owner, SolidData):
            return (n[None, :, None], n) if owner.boxes else (n[:, None, None], n)  # entries (ik, a, b) or (a, ik, b)
        return n[:, None, None, None], n[:, None]  # entries (a, i, b, k)

    def _solid_residual(self, s: SolidData, U: FloatArray) -> tuple[FloatArray, float, Any]:
        c, q = s.dV.shape
        if s.boxes:  # F[c, i, (q, J)] = t_J sum_a u[c, a, i] D[q, a, J], one matrix product, then as [i, J, (c, q)]
            F = np.matmul(U[s.cells].transpose(0, 2, 1).reshape(3 * c, -1), s.layouts["Dr"]).reshape(c, 3, q, 3)
            scaled = np.empty((3, 3, c, q))
            np.multiply(F.transpose(1, 3, 0, 2), s.layouts["t"], out=scaled)
            Fp = scaled.reshape(3, 3, c * q)
        else:  # F[c, i, (q, J)] = sum_a u[c, a, i] g[c, q, a, J], then as [i, J, (c, q)]
            F = np.matmul(U[s.cells].transpose(0, 2, 1), s.layouts["G"]).reshape(c, 3, q, 3)
            Fp = np.ascontiguousarray(F.transpose(1, 3, 0, 2)).reshape(3, 3, c * q)
        Fp[0, 0] += 1.0
        Fp[1, 1] += 1.0
        Fp[2, 2] += 1.0
        principal = principal_3d(Fp)
        P, _, J = s.kernel(Fp, False, principal)
        mixed = None
        if s.mixed is not None:  # the volumetric term on the elements' own dilatation
            P, mixed = self._mixed_volumetric(s, Fp, P, J)
        return self._element_vectors(s, P), float(J.min()), (Fp, principal, mixed)

    def _element_vectors(self, s: SolidData, P: FloatArray) -> FloatArray:
        """``r[c, a, i] = sum_(q, J) g[c, q, a, J] P[i, J, c, q] dV`` of a stress-like field ``P`` (3, 3, c q)."""
        c, q = s.dV.shape
        if s.boxes:  # r[c, i, a] = sum_(q, J) P[i, J, c, q] t_J dV D[q, a, J], one matrix product
            weighted = np.empty((c, 3, q, 3))
            np.multiply(P.reshape(3, 3, c, q).transpose(2, 0, 3, 1), s.layouts["tdV"], out=weighted)
            r = np.matmul(weighted.reshape(3 * c, 3 * q), s.layouts["Dr"].T).reshape(c, 3, -1)
            return np.ascontiguousarray(r.transpose(0, 2, 1))
        PdV = (P * s.dV.reshape(-1)).reshape(3, 3, c, q).transpose(2, 3, 1, 0).reshape(c, 3 * q, 3)
        return np.matmul(s.layouts["G"], PdV)

    def _solid_tangent(self, s: SolidData, state: Any) -> FloatArray:
        Fp, principal, mixed = state
        c, q, n, _ = s.g.shape
        _, A, _ = s.kernel(Fp, True, principal)
        assert A is not None
        if mixed is not None:
            p, cof, detF, _ = mixed
            A += geometric_blocks(cof, detF, p, _UPPER)
        dtype = self.tangent_dtype
        name = np.dtype(dtype).name
        if s.boxes:
            blocks = self._box_tangent(s, A, dtype)
            if mixed is not None:
                self._add_pressure_blocks(s, mixed, blocks.transpose(0, 2, 1, 3))
            return blocks
        # A[i, J, k, L, p] for the computed (i, k) pairs, as [p, J, ik, L] with dV
        A *= s.dV.reshape(-1)  # in place: the kernel's own array, tens of MB
        Ap = A.transpose(3, 1, 0, 2).astype(dtype).reshape(c, q, 3, 6, 3)
        key = f"blocks-{name}"
        if key not in s.layouts:  # kept: allocating tens of MB per tangent costs page faults
            s.layouts[key] = np.empty((c, n, 6, n), dtype=dtype)
            s.layouts[f"G-{name}"] = s.layouts["G"].astype(dtype)
            s.layouts[f"gt-{name}"] = s.layouts["gt"].astype(dtype)
        blocks = s.layouts[key]
        G, gt = s.layouts[f"G-{name}"], s.layouts[f"gt-{name}"]
        for start in range(0, c, TANGENT_CHUNK):
            sl = slice(start, min(start + TANGENT_CHUNK, c))
            m = sl.stop - sl.start
            # E[c, q, J, ik, b] = sum_L A dV g[c, q, b, L], a batched matrix product (einsum's
            # optimised path returns it transposed, which the reshape below would copy)
            E = np.matmul(Ap[sl].reshape(m * q, 18, 3), gt[sl].reshape(m * q, 3, n))
            # K[c, a, (ik, b)] = sum_(q, J) g[c, q, a, J] E[c, (q, J), (ik, b)]
            blocks[sl] = np.matmul(G[sl], E.reshape(m, 3 * q, 6 * n)).reshape(m, n, 6, n)
        if mixed is not None:
            self._add_pressure_blocks(s, mixed, blocks)
        return blocks

    def _box_tangent(self, s: SolidData, A: FloatArray, dtype: type) -> FloatArray:
        """The element blocks ``(c, ik, a, b)`` of boxes (:attr:`SolidData.boxes`) from the kernel's ``A``
        ``[ik, J, L, (c, q)]``: ``sum_(J, L, q) A t_J t_L dV D[q, a, J] D[q, b, L]``, one matrix product."""
        c, q, n, _ = s.g.shape
        name = np.dtype(dtype).name
        if f"box-{name}" not in s.layouts:  # kept: allocating tens of MB per tangent costs page faults
            s.layouts[f"box-{name}"] = np.empty((c, 6, 3, 3, q), dtype=dtype)
            s.layouts[f"blocks-{name}"] = np.empty((c, 6, n, n), dtype=dtype)
            s.layouts[f"DD-{name}"] = s.layouts["DD"].astype(dtype)
        weighted, blocks = s.layouts[f"box-{name}"], s.layouts[f"blocks-{name}"]
        np.multiply(A.reshape(6, 3, 3, c, q).transpose(3, 0, 1, 2, 4), s.layouts["W"], out=weighted,
                    casting="same_kind")
        np.matmul(weighted.reshape(c * 6, 9 * q), s.layouts[f"DD-{name}"], out=blocks.reshape(c * 6, n * n))
        return blocks

    def _add_pressure_blocks(self, s: SolidData, mixed: Any, blocks: FloatArray) -> None:
        """Add ``sum_mn [M^-1 H M^-1]_mn b_m (x) b_n`` of the elements' own pressure to the blocks (i, k) of the
        computed pairs (``blocks`` as ``(c, a, ik, b)``)."""
        b, term = self._pressure_vectors(s, mixed[1]), mixed[3]
        for m_, (i, k) in enumerate(_UPPER):
            blocks[:, :, m_, :] += np.matmul(np.matmul(b[..., i].transpose(0, 2, 1), term), b[..., k])

    def _wall_tangent(self, w: WallData, p: float, U: FloatArray) -> FloatArray:
        if "t" not in w.layouts:  # of the reference faces: kept
            f, q, n, _ = w.g.shape
            w.layouts["t"] = _cross(w.ndA[:, :, None, :], w.g)  # (f, q, n, 3)
            # the entry (f, a, i, b, k) is e_ikm M[f, a, b, m]: its m and sign
            face, a, i, b, k = np.unravel_index(w.take, (f, n, 3, n, 3))
            w.layouts["source"] = ((face * n + a) * n + b) * 3 + (3 - i - k)
            w.layouts["sign"] = np.where((k - i) % 3 == 1, 1.0, -1.0)
        F = deformation_gradient(w.g, w.cells, U)
        # v[f, q, b, m] = [F (N dA x dN_b/dX)]_m; M[f, a, b, m] = p sum_q h_a v_bm
        v = np.matmul(w.layouts["t"], F.transpose(0, 1, 3, 2))  # (f, q, n, m)
        f, q, n, _ = v.shape
        M = np.matmul(w.h.T[None], v.reshape(f, q, 3 * n))  # (f, a, (b, m))
        return M.ravel()[w.layouts["source"]] * (p * w.layouts["sign"])

    @staticmethod
    def _cof_normal(F: FloatArray, ndA: FloatArray) -> FloatArray:
        """``cof(F) N dA = N_1 F_2 x F_3 + N_2 F_3 x F_1 + N_3 F_1 x F_2`` (columns F_J), (f, q, 3)."""
        c1, c2, c3 = F[..., :, 0], F[..., :, 1], F[..., :, 2]
        return ndA[..., 0:1] * _cross(c2, c3) + ndA[..., 1:2] * _cross(c3, c1) + ndA[..., 2:3] * _cross(c1, c2)


__all__ = ["FastSystem", "PlaneStrainSystem", "SolidSystem3D"]
