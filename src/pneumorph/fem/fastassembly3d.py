"""Vectorised residual and symmetric tangent of a 3D solid model on a fixed mesh.

The 3D counterpart of :class:`pneumorph.fem.fastassembly.PlaneStrainSystem` for FElupe
``Field`` items on hexahedra (hex20 with 27 quadrature points, or hex8): the
shape-function gradients, volume elements and the CSR pattern of the active block are
taken once per design, every evaluation runs the points-last kernel
:func:`pneumorph.fem.kernels.ogden_3d` and contracts with batched matrix products.

The tangent is symmetric: the material part is the Hessian of a strain energy, and the
follower pressure on the walls of closed cavities is conservative (its load is the
derivative of ``-p V``): each face's load stiffness ``p h_a e_ikm [F (N dA x dN_b/dX)]_m``
is not symmetric, but their sum over a closed surface is, up to terms on the surface's
rim, which lies on the plane of symmetry where the normal displacement is held (a rim
term pairs two in-plane displacements into a normal vector). The 27-point rule integrates
the face terms of quadratic elements exactly, so the sum is symmetric to rounding, and
only the upper triangle of ``K[dof1, dof1]`` is assembled, for PARDISO's symmetric
indefinite solver (``mtype=-2``). Of the element matrices only the blocks ``i <= k`` of
the component pairs are computed (their transposes are the other blocks).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.fem.bodyforce import DeadLoads
from pneumorph.fem.kernels import principal_3d

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
Kernel = Callable[[FloatArray, bool, Any], tuple[FloatArray, FloatArray | None, FloatArray]]

#: component pairs (i, k) of the element blocks that are computed
_UPPER = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]
#: cells per chunk of the tangent (keeps the temporaries in the tens of MB)
_CHUNK = 256


@dataclass
class _Solid:
    cells: IntArray  # (c, n)
    g: FloatArray  # (c, q, n, 3) dN_a/dX_J
    G: FloatArray  # (c, n, 3q): g as [c, a, (q, J)]
    gt: FloatArray  # (c, q, 3, n): g as [c, q, L, b]
    dV: FloatArray  # (c, q)
    kernel: Kernel
    take: IntArray  # positions in the (c, a, (i, k), b) element blocks that are assembled
    scatter: IntArray  # their CSR positions
    blocks: FloatArray | None = None  # buffer of the element blocks


@dataclass
class _Walls:
    item: Any
    cells: IntArray  # (f, n) of the volume cells the faces belong to
    g: FloatArray  # (f, q, n, 3)
    h: FloatArray  # (q, n)
    ndA: FloatArray  # (f, q, 3)
    take: IntArray  # positions in the (f, a, i, b, k) element matrices that are assembled
    scatter: IntArray


def _kernel_of(umat: Any) -> Kernel:
    from pneumorph.fem.ogden import OgdenCompressible

    if isinstance(umat, OgdenCompressible):
        return lambda F, tangent, principal: umat.kernel(F, tangent, principal, _UPPER)
    raise TypeError(f"no fast 3D kernel for {type(umat).__name__}; use the FElupe backend")


def _gradients_of(region: Any) -> FloatArray:
    return np.ascontiguousarray(np.transpose(region.dhdX, (3, 2, 0, 1)))  # (c, q, n, 3)


def _deformation(g: FloatArray, cells: IntArray, U: FloatArray) -> FloatArray:
    """``F = I + grad u`` at every quadrature point, (c, q, 3, 3)."""
    ue = U[cells]  # (c, n, 3)
    F = np.matmul(ue.transpose(0, 2, 1)[:, None], g)  # (c, q, i, J)
    for i in range(3):
        F[..., i, i] += 1.0
    return F


def _cross(a: FloatArray, b: FloatArray) -> FloatArray:
    """Cross products along the last axis (faster than ``numpy.cross`` on small shapes)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def _cof_normal(F: FloatArray, ndA: FloatArray) -> FloatArray:
    """``cof(F) N dA = N_1 F_2 x F_3 + N_2 F_3 x F_1 + N_3 F_1 x F_2`` (columns F_J), (f, q, 3)."""
    c1, c2, c3 = F[..., :, 0], F[..., :, 1], F[..., :, 2]
    return (
        ndA[..., 0:1] * _cross(c2, c3) + ndA[..., 1:2] * _cross(c3, c1) + ndA[..., 2:3] * _cross(c1, c2)
    )


class SolidSystem3D:
    """Residual and upper triangle of the active-block tangent of FElupe 3D items.

    Parameters
    ----------
    items : sequence
        ``felupe.SolidBody`` items with :class:`~pneumorph.fem.ogden.OgdenCompressible`
        materials, ``felupe.SolidBodyPressure`` items on boundary regions of closed
        cavities and ``felupe.SolidBodyForce`` dead loads (all on ``felupe.Field`` fields
        linked to one global field).
    field : felupe.FieldContainer
        The global 3D field; only its size is read here.
    dof1, dof0 : ndarray
        Active and prescribed degrees of freedom (FElupe numbering ``3 * point + component``).

    Attributes
    ----------
    indptr, indices : ndarray
        CSR pattern of the upper triangle of ``K[dof1, dof1]`` (sorted columns).
    symmetric : bool
        Always True: :meth:`tangent_data` holds the upper triangle only.

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

    symmetric = True
    #: PARDISO ordering: METIS nested dissection suits the 3D pattern
    ordering = 2
    #: a Newton method that keeps its tangents may factorise in single precision
    single_precision = True

    def __init__(self, items: Sequence[Any], field: Any, dof1: IntArray, dof0: IntArray) -> None:
        import felupe as fem

        self.ndof = int(field[0].values.size)
        self.dof1 = np.asarray(dof1, dtype=np.int64)
        self.dof0 = np.asarray(dof0, dtype=np.int64)
        self.points = np.asarray(field[0].region.mesh.points, dtype=float)
        self.solids: list[_Solid] = []
        self.walls: list[_Walls] = []
        empty = np.zeros(0, dtype=np.int64)
        forces = []
        for item in items:
            sub = item.field[0]
            if type(sub) is not fem.Field or sub.dim != 3:
                raise TypeError(f"the fast 3D assembly needs 3D felupe.Field fields, got {type(sub).__name__}")
            if isinstance(item, fem.SolidBodyForce):
                forces.append(item)
                continue
            region = sub.region
            cells = np.asarray(region.mesh.cells, dtype=np.int64)
            g = _gradients_of(region)
            if isinstance(item, fem.SolidBodyPressure):
                h = np.ascontiguousarray(region.h[:, :, 0].T)
                ndA = np.ascontiguousarray(np.transpose(region.dA, (2, 1, 0)))
                self.walls.append(_Walls(item, cells, g, h, ndA, empty, empty))
            elif isinstance(item, fem.SolidBody):
                c, q, n, _ = g.shape
                self.solids.append(
                    _Solid(
                        cells=cells,
                        g=g,
                        G=np.ascontiguousarray(g.transpose(0, 2, 1, 3).reshape(c, n, 3 * q)),
                        gt=np.ascontiguousarray(g.transpose(0, 1, 3, 2)),
                        dV=np.ascontiguousarray(region.dV.T),
                        kernel=_kernel_of(item.umat),
                        take=empty,
                        scatter=empty,
                    )
                )
            else:
                raise TypeError(f"no fast assembly for {type(item).__name__}; use the FElupe backend")
        self.dead = DeadLoads(forces, self.ndof // 3, 3)
        self._build_pattern()
        self._state: list[tuple[FloatArray, Any]] = []
        self._U = np.zeros((self.ndof // 3, 3))

    # -- pattern ------------------------------------------------------------------------
    def _build_pattern(self) -> None:
        """CSR pattern of the upper triangle and every element entry's position in it.

        Entries are keyed ``row * n1 + column`` (active numbering, upper triangle); one
        argsort of all keys gives both the pattern and the scatter positions.
        """
        active = np.full(self.ndof, -1, dtype=np.int64)
        active[self.dof1] = np.arange(self.dof1.size)
        n1 = self.dof1.size
        ik = np.array(_UPPER)
        off = (ik[:, 0] != ik[:, 1])[None, None, :, None]
        keys_all = []
        owners: list[_Solid | _Walls] = [*self.solids, *self.walls]
        for owner in owners:
            act = active[3 * owner.cells[:, :, None] + np.arange(3)]  # (c, n, 3)
            if isinstance(owner, _Solid):
                # entry (c, a, ik, b) at (row of (a, i), column of (b, k)); blocks i < k
                # stand for themselves and their transposes, blocks i == k hold both
                rows = act[:, :, ik[:, 0]][:, :, :, None]
                cols = act[:, :, ik[:, 1]].transpose(0, 2, 1)[:, None]
                lo, hi = np.minimum(rows, cols), np.maximum(rows, cols)
                valid = (lo >= 0) & (off | (rows <= cols))
            else:
                # entry (f, a, i, b, k): the full face matrix, its upper-triangle entries
                rows = act[:, :, :, None, None]
                cols = act[:, None, None, :, :]
                lo, hi = rows, cols
                valid = (rows >= 0) & (rows <= cols)
            owner.take = np.flatnonzero(valid)
            keys_all.append((lo * n1 + hi).ravel()[owner.take])
        keys = np.concatenate(keys_all)
        if n1 * n1 < 2**32:
            keys = keys.astype(np.uint32)  # sorts faster
        order = np.argsort(keys)
        sorted_keys = keys[order]
        first = np.empty(keys.size, dtype=bool)
        first[0] = True
        np.not_equal(sorted_keys[1:], sorted_keys[:-1], out=first[1:])
        starts = np.flatnonzero(first)
        position = np.empty(keys.size, dtype=np.int64)
        position[order] = np.repeat(np.arange(starts.size), np.diff(np.append(starts, keys.size)))
        unique = sorted_keys[first].astype(np.int64)
        self.nnz = int(unique.size)
        rows_u = unique // n1
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(rows_u, minlength=n1))]).astype(np.int32)
        self.indices = (unique - rows_u * n1).astype(np.int32)
        start = 0
        for owner, k in zip(owners, keys_all, strict=False):
            owner.scatter = position[start : start + k.size]
            start += k.size
        self._edofs = [(3 * o.cells[:, :, None] + np.arange(3)).ravel() for o in owners]

    # -- evaluation -----------------------------------------------------------------------
    def residual(self, u: FloatArray) -> tuple[FloatArray, float]:
        """Residual over all dofs at the displacement vector ``u`` and the smallest det F.

        The deformation gradients are kept for :meth:`tangent_data` at the same state
        (the material tangent is only computed there: a Newton method that reuses its
        factorisation needs many residuals and few tangents).
        """
        U = u.reshape(-1, 3)
        self._U = U.copy()
        r = np.zeros(self.ndof)
        self._state = []
        jmin = np.inf
        for s, edofs in zip(self.solids, self._edofs, strict=False):
            c, q = s.dV.shape
            # F[c, i, (q, J)] = sum_a u[c, a, i] g[c, q, a, J], then as [i, J, (c, q)]
            F = np.matmul(U[s.cells].transpose(0, 2, 1), s.G).reshape(c, 3, q, 3)
            Fp = np.ascontiguousarray(F.transpose(1, 3, 0, 2)).reshape(3, 3, c * q)
            Fp[0, 0] += 1.0
            Fp[1, 1] += 1.0
            Fp[2, 2] += 1.0
            principal = principal_3d(Fp)
            P, _, J = s.kernel(Fp, False, principal)
            jmin = min(jmin, float(J.min()))
            # r[c, a, i] = sum_(q, J) g[c, q, a, J] P[i, J, c, q] dV
            PdV = (P * s.dV.reshape(-1)).reshape(3, 3, c, q).transpose(2, 3, 1, 0).reshape(c, 3 * q, 3)
            r += np.bincount(edofs, weights=np.matmul(s.G, PdV).ravel(), minlength=self.ndof)
            self._state.append((Fp, principal))
        for w, edofs in zip(self.walls, self._edofs[len(self.solids):], strict=False):
            p = float(w.item.results.pressure)
            F = _deformation(w.g, w.cells, U)
            cofN = _cof_normal(F, w.ndA)  # (f, q, 3)
            r += np.bincount(edofs, weights=(p * np.matmul(w.h.T[None], cofN)).ravel(), minlength=self.ndof)
        if self.dead:
            r -= self.dead.vector()
        return r, jmin

    def tangent_data(self) -> FloatArray:
        """CSR ``data`` of the upper triangle of ``K[dof1, dof1]`` (state of the last residual)."""
        data = np.zeros(self.nnz)
        for s, (Fp, principal) in zip(self.solids, self._state, strict=False):
            c, q, n, _ = s.g.shape
            _, A, _ = s.kernel(Fp, True, principal)
            assert A is not None
            dV = s.dV.reshape(-1)
            # A[i, J, k, L, p] for the computed (i, k) pairs, as [p, J, ik, L] with dV
            Ap = (A * dV).transpose(3, 1, 0, 2).reshape(c, q, 3, 6, 3)
            if s.blocks is None:  # kept: allocating tens of MB per tangent costs page faults
                s.blocks = np.empty((c, n, 6, n))
            blocks = s.blocks
            for start in range(0, c, _CHUNK):
                sl = slice(start, min(start + _CHUNK, c))
                m = sl.stop - sl.start
                # E[c, q, J, ik, b] = sum_L A dV g[c, q, b, L]
                # (optimize=True: a batched matrix product, 3x faster than the plain loop)
                E = np.einsum(
                    "pmL,pLb->pmb", Ap[sl].reshape(m * q, 18, 3), s.gt[sl].reshape(m * q, 3, n), optimize=True
                )
                # K[c, a, (ik, b)] = sum_(q, J) g[c, q, a, J] E[c, (q, J), (ik, b)]
                blocks[sl] = np.matmul(s.G[sl], E.reshape(m, 3 * q, 6 * n)).reshape(m, n, 6, n)
            data += np.bincount(s.scatter, weights=blocks.ravel()[s.take], minlength=self.nnz)
        for w in self.walls:
            p = float(w.item.results.pressure)
            F = _deformation(w.g, w.cells, self._U)
            # v[f, q, b, m] = [F (N dA x dN_b/dX)]_m; M[f, a, b, m] = p sum_q h_a v_bm
            t = _cross(w.ndA[:, :, None, :], w.g)  # (f, q, n, 3)
            v = np.matmul(t, F.transpose(0, 1, 3, 2))  # (f, q, n, m)
            f, q, n, _ = v.shape
            M = p * np.matmul(w.h.T[None], v.reshape(f, q, 3 * n)).reshape(f, n, n, 3)
            K = np.zeros((f, n, 3, n, 3))  # K[a, i, b, k] = e_ikm M[a, b, m]
            for i, k, m_, sign in ((0, 1, 2, 1), (1, 2, 0, 1), (2, 0, 1, 1), (1, 0, 2, -1), (2, 1, 0, -1),
                                   (0, 2, 1, -1)):
                K[:, :, i, :, k] = sign * M[..., m_]
            data += np.bincount(w.scatter, weights=K.ravel()[w.take], minlength=self.nnz)
        return data

    def tangent(self) -> Any:
        """The full symmetric ``K[dof1, dof1]`` as ``scipy.sparse.csr_matrix``."""
        import scipy.sparse as sp

        n1 = self.dof1.size
        upper = sp.csr_matrix((self.tangent_data(), self.indices, self.indptr), shape=(n1, n1))
        return (upper + sp.triu(upper, k=1).T).tocsr()

    def cavity_volume(self, u: FloatArray) -> float:
        """Volume enclosed by the pressurised walls, as :func:`pneumorph.fem.cavity_volume`."""
        U = u.reshape(-1, 3)
        total = 0.0
        for w in self.walls:
            F = _deformation(w.g, w.cells, U)
            x = np.matmul(w.h[None], (self.points + U)[w.cells])  # (f, q, 3)
            total += float(np.sum(x * _cof_normal(F, w.ndA)))
        return -total / 3.0
