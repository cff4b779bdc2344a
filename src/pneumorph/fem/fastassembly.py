"""Vectorised residual and tangent of a plane-strain model on a fixed mesh.

FElupe assembles every item into its own sparse matrix (COO to CSR), sums them and slices
the active block at every Newton iteration; on a 2D actuator that bookkeeping costs far
more than the few thousand quadrature points' arithmetic. :class:`PlaneStrainSystem` does
the bookkeeping once per design: the shape-function gradients ``dN/dX`` and volume
elements of every material group (taken from the FElupe regions), the CSR pattern of the
active block ``K[dof1, dof1]`` and, for every entry of every element matrix, its position
in the CSR ``data`` array. Each evaluation then computes ``F``, the stress ``P`` and
tangent ``A`` of every group with the kernels of :mod:`pneumorph.fem.kernels`, contracts
them to element vectors and matrices with batched products, and scatters them with one
``np.bincount`` each.

The cavity pressure is a follower load ``p cof(F) N dA`` on the cavity walls (FElupe's
``SolidBodyPressure`` with ``ensure_3d=True``): in plane strain ``cof(F)_iJ = e_ik e_JL F_kL``
with the 2D permutation symbol ``e``, so its (non-symmetric) stiffness is
``p h_a e_ik (N_1 dN_b/dX_2 - N_2 dN_b/dX_1) dA``. The model parameters (pressure, the
filler's Lame constants) are read from the FElupe items at every evaluation, so the same
``apply(t)`` drives both paths.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.fem.bodyforce import DeadLoads
from pneumorph.fem.kernels import neo_hooke_plane_strain, ogden_plane_strain

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
Kernel = Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]

_EPS = np.array([[0.0, 1.0], [-1.0, 0.0]])  # 2D permutation symbol e_ik


@dataclass
class _Group:
    """One material on some cells: gradients in the layouts the products need."""

    cells: IntArray  # (c, n) point indices
    g: FloatArray  # (c, q, n, 2) dN_a/dX_J
    g_res: FloatArray  # (c, n, 2q): g[c, q, a, J] as [c, a, (q, J)]
    gT: FloatArray  # (cq, 2, n): g[c, q, b, L] as [(c, q), L, b]
    B: FloatArray  # (c, 2n, 4q): d_ii' g[c, q, a, J] as [c, (a, i), (q, i', J)]
    dV: FloatArray  # (c, q)
    kernel: Kernel | None  # None for a pressurised boundary


def _kernel_of(umat: Any) -> Kernel:
    """The plane-strain kernel of a material, reading its parameters at every call."""
    import felupe as fem

    from pneumorph.fem.ogden import OgdenCompressible

    if isinstance(umat, OgdenCompressible):
        return lambda F: ogden_plane_strain(F, umat.mu, umat.alpha, umat.bulk)
    if isinstance(umat, fem.NeoHookeCompressible) and umat.lmbda is not None:
        return lambda F: neo_hooke_plane_strain(F, float(umat.mu), float(umat.lmbda))
    raise TypeError(f"no fast plane-strain kernel for {type(umat).__name__}; use the FElupe backend")


def _group(cells: IntArray, region: Any, kernel: Kernel | None) -> _Group:
    g = np.ascontiguousarray(np.transpose(region.dhdX[:, :2], (3, 2, 0, 1)))  # (c, q, n, 2)
    c, q, n, _ = g.shape
    return _Group(
        cells=np.asarray(cells, dtype=np.int64),
        g=g,
        g_res=np.ascontiguousarray(g.transpose(0, 2, 1, 3).reshape(c, n, 2 * q)),
        gT=np.ascontiguousarray(g.transpose(0, 1, 3, 2).reshape(c * q, 2, n)),
        B=np.ascontiguousarray(
            np.einsum("cqaJ,ij->caiqjJ", g, np.eye(2)).reshape(c, 2 * n, 4 * q)
        ),
        dV=np.ascontiguousarray(region.dV.T),
        kernel=kernel,
    )


def _gradients(group_g: FloatArray, cells: IntArray, u: FloatArray) -> FloatArray:
    """``F = I + grad u`` at every quadrature point, (c, q, 2, 2)."""
    ue = u[cells]  # (c, n, 2)
    F = np.matmul(ue.transpose(0, 2, 1)[:, None], group_g)  # (c, q, i, J)
    F[..., 0, 0] += 1.0
    F[..., 1, 1] += 1.0
    return F


class PlaneStrainSystem:
    """Residual and active-block tangent of FElupe plane-strain items, assembled fast.

    Parameters
    ----------
    items : sequence
        ``felupe.SolidBody`` items with :class:`~pneumorph.fem.ogden.OgdenCompressible`
        or ``felupe.NeoHookeCompressible`` materials on ``FieldPlaneStrain`` fields, and
        ``felupe.SolidBodyPressure`` items on boundary regions built with ``ensure_3d=True``
        and ``felupe.SolidBodyForce`` dead loads (all linked to one global field).
    field : felupe.FieldContainer
        The global field (one ``FieldPlaneStrain``); only its size is read here.
    dof1, dof0 : ndarray
        Active and prescribed degrees of freedom (FElupe numbering ``2 * point + component``).

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

    def __init__(self, items: Sequence[Any], field: Any, dof1: IntArray, dof0: IntArray) -> None:
        import felupe as fem

        self.ndof = int(field[0].values.size)
        self.npoints = self.ndof // 2
        self.dof1 = np.asarray(dof1, dtype=np.int64)
        self.dof0 = np.asarray(dof0, dtype=np.int64)
        self.groups: list[_Group] = []
        self.pressures: list[tuple[Any, _Group, FloatArray, FloatArray]] = []
        forces = []
        for item in items:
            sub = item.field[0]
            if not isinstance(sub, fem.FieldPlaneStrain):
                raise TypeError(f"the fast assembly needs FieldPlaneStrain fields, got {type(sub).__name__}")
            region = sub.region
            if isinstance(item, fem.SolidBodyPressure):
                # h (n, q) -> (q, n); N dA (3, q, f) -> (f, q, 2); X at the points for the volume
                grp = _group(region.mesh.cells, region, None)
                h = np.ascontiguousarray(region.h[:, :, 0].T)
                ndA = np.ascontiguousarray(np.transpose(region.dA[:2], (2, 1, 0)))
                self.pressures.append((item, grp, h, ndA))
            elif isinstance(item, fem.SolidBody):
                self.groups.append(_group(region.mesh.cells, region, _kernel_of(item.umat)))
            elif isinstance(item, fem.SolidBodyForce):
                forces.append(item)
            else:
                raise TypeError(f"no fast assembly for {type(item).__name__}; use the FElupe backend")
        self.dead = DeadLoads(forces, self.npoints, 2)
        self._build_pattern()
        self.points = np.asarray(field[0].region.mesh.points[:, :2], dtype=float)
        self._cache: list[FloatArray] = []

    # -- pattern ------------------------------------------------------------------------
    def _element_dofs(self, cells: IntArray) -> IntArray:
        return (2 * cells[:, :, None] + np.arange(2)).reshape(len(cells), -1)  # (c, 2n): (a, i)

    def _build_pattern(self) -> None:
        import scipy.sparse as sp

        active = np.full(self.ndof, -1, dtype=np.int64)
        active[self.dof1] = np.arange(self.dof1.size)
        n1 = self.dof1.size
        blocks = []  # per group: active rows/cols of entries in (c, a, i, k, b) order
        for grp in [*self.groups, *(p[1] for p in self.pressures)]:
            nodes = grp.cells.shape[1]
            a1 = active[2 * grp.cells]  # (c, n): x-dof of node a
            b1 = active[2 * grp.cells + 1]
            act = np.stack([a1, b1], axis=2)  # (c, n, 2): active index of dof (a, i)
            rows = np.broadcast_to(act[:, :, :, None, None], (len(act), nodes, 2, 2, nodes))
            cols = np.broadcast_to(act.transpose(0, 2, 1)[:, None, None, :, :], (len(act), nodes, 2, 2, nodes))
            blocks.append((rows.ravel(), cols.ravel()))
        rows = np.concatenate([b[0] for b in blocks])
        cols = np.concatenate([b[1] for b in blocks])
        valid = (rows >= 0) & (cols >= 0)
        keys = rows * n1 + cols
        unique = np.unique(keys[valid])
        pattern = sp.csr_matrix(
            (np.ones(unique.size), (unique // n1, unique % n1)), shape=(n1, n1)
        )
        pattern.sort_indices()
        self.indptr = pattern.indptr.astype(np.int32)
        self.indices = pattern.indices.astype(np.int32)
        self.nnz = int(unique.size)
        # CSR order is row-major with sorted columns, i.e. the order of the sorted keys
        pos = np.searchsorted(unique, keys)
        self._scatter = np.where(valid, pos, self.nnz)  # invalid entries go to a dump slot
        self._edofs = np.concatenate(
            [self._element_dofs(g.cells).ravel() for g in [*self.groups, *(p[1] for p in self.pressures)]]
        )

    # -- evaluation -----------------------------------------------------------------------
    def residual(self, u: FloatArray) -> tuple[FloatArray, float]:
        """Residual over all dofs at the displacement vector ``u`` and the smallest det F.

        The stress and tangent are kept for :meth:`tangent` at the same state.
        """
        U = u.reshape(-1, 2)
        vectors, self._cache = [], []
        jmin = np.inf
        for grp in self.groups:
            c, q = grp.dV.shape
            F = _gradients(grp.g, grp.cells, U)
            assert grp.kernel is not None
            P, A, J = grp.kernel(np.ascontiguousarray(F.transpose(2, 3, 0, 1)).reshape(2, 2, c * q))
            jmin = min(jmin, float(J.min()))
            dV = grp.dV.reshape(-1)
            PdV = (P * dV).reshape(2, 2, c, q)
            # r[c, a, i] = sum_(q, J) g[c, q, a, J] P[i, J, c, q] dV
            vectors.append(np.matmul(grp.g_res, PdV.transpose(2, 3, 1, 0).reshape(c, 2 * q, 2)).ravel())
            self._cache.append(A * dV)
        for item, grp, h, ndA in self.pressures:
            p = float(item.results.pressure)
            F = _gradients(grp.g, grp.cells, U)
            cofN = self._cof_normal(F, ndA)  # (f, q, 2)
            # r[f, a, i] = p sum_q h[q, a] cof(F)_iJ N_J dA
            vectors.append((p * np.matmul(h.T[None], cofN)).ravel())
        weights = np.concatenate(vectors)
        r = np.asarray(np.bincount(self._edofs, weights=weights, minlength=self.ndof), dtype=np.float64)
        if self.dead:
            r -= self.dead.vector()
        return r, jmin

    @staticmethod
    def _cof_normal(F: FloatArray, ndA: FloatArray) -> FloatArray:
        """``cof(F) N dA`` at the boundary points, (f, q, 2)."""
        out = np.empty_like(ndA)
        out[..., 0] = F[..., 1, 1] * ndA[..., 0] - F[..., 1, 0] * ndA[..., 1]
        out[..., 1] = -F[..., 0, 1] * ndA[..., 0] + F[..., 0, 0] * ndA[..., 1]
        return out

    def tangent_data(self) -> FloatArray:
        """CSR ``data`` of ``K[dof1, dof1]`` at the state of the last :meth:`residual`."""
        blocks = []
        for grp, AdV in zip(self.groups, self._cache, strict=False):
            c, q, n, _ = grp.g.shape
            # D[cq, (i, J, k), b] = sum_L A[i, J, k, L, cq] dV g[cq, b, L]
            At = np.ascontiguousarray(AdV.reshape(16, c * q).T).reshape(c * q, 8, 2)
            D = np.matmul(At, grp.gT).reshape(c, 4 * q, 2 * n)  # [c, (q, i, J), (k, b)]
            # K[c, (a, i), (k, b)] = sum_(q, J) g[c, q, a, J] D[c, (q, i, J), (k, b)]
            blocks.append(np.matmul(grp.B, D).ravel())
        for item, grp, h, ndA in self.pressures:
            p = float(item.results.pressure)
            # t[f, q, b] = N_1 dN_b/dX_2 - N_2 dN_b/dX_1 (with dA); M[f, a, b] = p sum_q h_a t_b
            t = ndA[..., 0:1] * grp.g[..., 1] - ndA[..., 1:2] * grp.g[..., 0]
            M = p * np.matmul(h.T[None], t)  # (f, n, n)
            blocks.append((_EPS[None, None, :, :, None] * M[:, :, None, None, :]).ravel())
        data = np.bincount(self._scatter, weights=np.concatenate(blocks), minlength=self.nnz + 1)
        return np.asarray(data[: self.nnz], dtype=np.float64)

    def tangent(self) -> Any:
        """``K[dof1, dof1]`` as a ``scipy.sparse.csr_matrix`` (state of the last residual)."""
        import scipy.sparse as sp

        n1 = self.dof1.size
        return sp.csr_matrix((self.tangent_data(), self.indices, self.indptr), shape=(n1, n1))

    def cavity_volume(self, u: FloatArray) -> float:
        """Area enclosed by the pressurised walls, as :func:`pneumorph.fem.cavity_volume`."""
        U = u.reshape(-1, 2)
        total = 0.0
        for _, grp, h, ndA in self.pressures:
            F = _gradients(grp.g, grp.cells, U)
            x = np.matmul(h[None], (self.points + U)[grp.cells])  # (f, q, 2)
            total += float(np.sum(x * self._cof_normal(F, ndA)))
        return -total / 2.0
