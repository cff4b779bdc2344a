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

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from pneumorph.fem.fast.kernels import neo_hooke_plane_strain, ogden_plane_strain, principal_3d
from pneumorph.fem.fast.loads import DeadLoads

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: component pairs (i, k) of the 3D element blocks that are computed
_UPPER = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]
#: cells per chunk of the 3D tangent (keeps the temporaries in the tens of MB)
_CHUNK = 256
_EPS = np.array([[0.0, 1.0], [-1.0, 0.0]])  # 2D permutation symbol e_ik


@dataclass
class _Solid:
    """One material on some cells: gradients in the layouts the products need."""

    cells: IntArray  # (c, n)
    g: FloatArray  # (c, q, n, d) dN_a/dX_J
    dV: FloatArray  # (c, q)
    kernel: Any
    layouts: dict[str, FloatArray] = field(default_factory=dict)
    take: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))  # assembled entries
    scatter: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))  # their CSR positions
    edofs: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))


@dataclass
class _Walls:
    """The pressurised faces of one ``SolidBodyPressure``."""

    item: Any
    cells: IntArray  # (f, n) of the volume cells the faces belong to
    g: FloatArray  # (f, q, n, d)
    h: FloatArray  # (q, n)
    ndA: FloatArray  # (f, q, d)
    take: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    scatter: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    edofs: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))


def _deformation(g: FloatArray, cells: IntArray, U: FloatArray) -> FloatArray:
    """``F = I + grad u`` at every quadrature point, (c, q, d, d)."""
    F = np.matmul(U[cells].transpose(0, 2, 1)[:, None], g)  # (c, q, i, J)
    for i in range(U.shape[1]):
        F[..., i, i] += 1.0
    return F


class FastSystem:
    """Residual and active-block tangent of FElupe items, assembled fast.

    Use the dimension's subclass (:class:`PlaneStrainSystem`, :class:`SolidSystem3D`);
    this class holds what they share: the items' data, the CSR pattern, the scatter,
    dead loads, the tangent matrix and the enclosed cavity volume.

    Parameters
    ----------
    items : sequence
        ``felupe.SolidBody`` items with materials the dimension has a kernel for,
        ``felupe.SolidBodyPressure`` items on boundary regions of closed cavities and
        ``felupe.SolidBodyForce`` dead loads (all linked to one global field).
    field : felupe.FieldContainer
        The global field; only its size and mesh points are read here.
    dof1, dof0 : ndarray
        Active and prescribed degrees of freedom (FElupe numbering ``dim * point + component``).

    Attributes
    ----------
    indptr, indices : ndarray
        CSR pattern of ``K[dof1, dof1]`` (its upper triangle if :attr:`symmetric`).
    """

    dim: ClassVar[int]
    #: the tangent is symmetric and only its upper triangle is assembled
    symmetric: ClassVar[bool] = False
    #: PARDISO's fill-reducing ordering for this dimension's tangents
    ordering: ClassVar[int] = 0
    #: a Newton method that keeps its tangents may factorise in single precision
    single_precision: ClassVar[bool] = False
    #: the precision the element matrices are computed in (:class:`~pneumorph.fem.fast.newton.FastSubstep`
    #: sets float32 where it factorises in single precision; the residual is always double)
    tangent_dtype: type = np.float64

    def __init__(self, items: Sequence[Any], field: Any, dof1: IntArray, dof0: IntArray) -> None:
        import felupe as fem

        d = self.dim
        self.ndof = int(field[0].values.size)
        self.npoints = self.ndof // d
        self.dof1 = np.asarray(dof1, dtype=np.int64)
        self.dof0 = np.asarray(dof0, dtype=np.int64)
        self.points = np.asarray(field[0].region.mesh.points[:, :d], dtype=float)
        self.solids: list[_Solid] = []
        self.walls: list[_Walls] = []
        forces = []
        for item in items:
            self._check_field(item.field[0])
            if isinstance(item, fem.SolidBodyForce):
                forces.append(item)
                continue
            region = item.field[0].region
            cells = np.asarray(region.mesh.cells, dtype=np.int64)
            g = np.ascontiguousarray(np.transpose(region.dhdX[:, :d], (3, 2, 0, 1)))  # (c, q, n, d)
            if isinstance(item, fem.SolidBodyPressure):
                h = np.ascontiguousarray(region.h[:, :, 0].T)  # (n, q) -> (q, n)
                ndA = np.ascontiguousarray(np.transpose(region.dA[:d], (2, 1, 0)))  # (f, q, d)
                self.walls.append(_Walls(item, cells, g, h, ndA))
            elif isinstance(item, fem.SolidBody):
                solid = _Solid(cells, g, np.ascontiguousarray(region.dV.T), self._kernel_of(item.umat))
                solid.layouts = self._layouts(g)
                self.solids.append(solid)
            else:
                raise TypeError(f"no fast assembly for {type(item).__name__}; use the FElupe backend")
        self.dead = DeadLoads(forces, self.npoints, d)
        self._build_pattern()
        self._state: list[Any] = []
        self._U = np.zeros((self.npoints, d))

    # -- dimension hooks ---------------------------------------------------------------
    def _check_field(self, sub: Any) -> None:
        raise NotImplementedError  # pragma: no cover

    def _kernel_of(self, umat: Any) -> Any:
        raise NotImplementedError  # pragma: no cover

    def _layouts(self, g: FloatArray) -> dict[str, FloatArray]:
        """The gradients in the layouts this dimension's products need."""
        raise NotImplementedError  # pragma: no cover

    def _entries(self, owner: _Solid | _Walls, act: IntArray) -> tuple[IntArray, IntArray, NDArray[np.bool_]]:
        """Active (row, column) of every element-matrix entry as it is computed, and which
        of them are assembled (``act``: the active index of each cell's dofs, (c, n, d))."""
        raise NotImplementedError  # pragma: no cover

    def _entry_nodes(self, owner: _Solid | _Walls) -> tuple[IntArray, IntArray]:
        """The local nodes ``a``, ``b`` that each entry of :meth:`_entries` couples, as index
        arrays that broadcast to its shape without the cell axis."""
        raise NotImplementedError  # pragma: no cover

    def _solid_residual(self, s: _Solid, U: FloatArray) -> tuple[FloatArray, float, Any]:
        """The element vectors ``(c, n, d)`` of a solid, its smallest det F and the state
        :meth:`_solid_tangent` needs."""
        raise NotImplementedError  # pragma: no cover

    def _solid_tangent(self, s: _Solid, state: Any) -> FloatArray:
        """The element matrices of a solid, entries in :meth:`_entries` order."""
        raise NotImplementedError  # pragma: no cover

    def _wall_tangent(self, w: _Walls, p: float, U: FloatArray) -> FloatArray:
        """The follower-pressure stiffness of some walls, entries in :meth:`_entries` order."""
        raise NotImplementedError  # pragma: no cover

    @staticmethod
    def _cof_normal(F: FloatArray, ndA: FloatArray) -> FloatArray:
        """``cof(F) N dA`` at the boundary points, (f, q, d)."""
        raise NotImplementedError  # pragma: no cover

    # -- pattern ------------------------------------------------------------------------
    def _build_pattern(self) -> None:
        """CSR pattern and every element entry's position in it.

        No sort of the element entries: the nodes a cell couples are paired once
        (``np.unique`` of the cells' node pairs, unordered where the tangent is
        symmetric), the pattern follows from the pairs - in a row of node ``P``'s
        component ``i`` the columns are the active components of ``P``'s partners ``Q``
        in ascending order, since the active numbering keeps the order of the dofs - and
        an entry's position is its pair's row start, the columns of the partners before
        ``Q`` and the components before its own. Only the entries some element assembles
        are kept, so the pattern is exactly theirs.
        """
        d, npts = self.dim, self.npoints
        active = np.full(self.ndof, -1, dtype=np.int32)  # (int32: half the memory traffic of the gathers)
        active[self.dof1] = np.arange(self.dof1.size)
        n1 = self.dof1.size
        owners: list[_Solid | _Walls] = [*self.solids, *self.walls]
        # 1. the node pairs every owner's cells couple, numbered
        pair_keys = []
        for owner in owners:
            a, b = owner.cells[:, :, None], owner.cells[:, None, :]
            if self.symmetric:
                a, b = np.minimum(a, b), np.maximum(a, b)
            pair_keys.append((a * npts + b).ravel())
        every = np.concatenate(pair_keys)
        if npts * npts < 2**32:
            every = every.astype(np.uint32)  # sorts faster
        keys, inverse = np.unique(every, return_inverse=True)
        keys = keys.astype(np.int64)
        first, second = keys // npts, keys % npts
        # 2. the dof entries (pair, i, k) of every pair: position if all were assembled
        comp = np.arange(d)
        rows = active[d * first[:, None] + comp]  # (pairs, d)
        cols = active[d * second[:, None] + comp]
        exists = (rows[:, :, None] >= 0) & (cols[:, None, :] >= 0)
        if self.symmetric:  # a node with itself: the upper triangle of its block
            exists &= (first != second)[:, None, None] | (comp[:, None] <= comp[None, :])
        per_row = exists.sum(axis=2)  # (pairs, d): columns each pair adds to the rows of first
        before = np.cumsum(per_row, axis=0) - per_row  # columns of earlier pairs (all nodes)
        starts = np.flatnonzero(np.r_[True, first[1:] != first[:-1]])
        group = np.repeat(starts, np.diff(np.r_[starts, first.size]))
        before -= before[group]  # ... of earlier pairs of the same first node
        live = rows >= 0
        indptr = np.r_[0, np.cumsum(np.bincount(rows[live], weights=per_row[live], minlength=n1))].astype(np.int64)
        full = indptr[np.maximum(rows, 0)][:, :, None] + before[:, :, None] + (np.cumsum(exists, axis=2) - exists)
        # 3. every element entry's (pair, i, k), of the assembled ones
        offsets = np.cumsum([0, *(k.size for k in pair_keys)])
        component = (self.dof1 % d).astype(np.int32)  # of each active dof
        full_flat = full.reshape(-1)
        positions = []
        used = np.zeros(int(indptr[-1]), dtype=bool)
        for o, owner in enumerate(owners):
            dofs = d * owner.cells[:, :, None] + np.arange(d)  # (c, n, d)
            owner.edofs = dofs.ravel()
            erows, ecols, valid = self._entries(owner, active[dofs])
            owner.take = np.flatnonzero(valid)
            n = owner.cells.shape[1]
            pair = inverse[offsets[o] : offsets[o + 1]].reshape(-1, n, n).astype(np.int32)
            ia, ib = self._entry_nodes(owner)
            index = np.broadcast_to(pair[:, ia, ib] * (d * d), erows.shape).ravel()[owner.take]
            index += component[np.ravel(erows)[owner.take]] * d
            index += component[np.ravel(ecols)[owner.take]]
            pos = full_flat[index]
            used[pos] = True
            positions.append(pos)
        # 4. keep the entries some element assembles
        renumber = np.cumsum(used) - 1
        self.nnz = int(used.sum())
        kept_rows = np.repeat(np.arange(n1), np.diff(indptr))[used]
        self.indptr = np.r_[0, np.cumsum(np.bincount(kept_rows, minlength=n1))].astype(np.int32)
        columns = np.empty(int(indptr[-1]), dtype=np.int32)
        columns[full[exists]] = np.broadcast_to(cols[:, None, :], exists.shape)[exists]
        self.indices = columns[used]
        # every owner's CSR positions side by side (each owner's scatter is its slice)
        self._scatter = np.empty(sum(pos.size for pos in positions), dtype=np.int64)
        start = 0
        for owner, pos in zip(owners, positions, strict=True):
            owner.scatter = self._scatter[start : start + pos.size]
            np.take(renumber, pos, out=owner.scatter)
            start += pos.size
        self._values = np.empty(self._scatter.size)  # kept: a tangent fills it anew

    # -- evaluation -----------------------------------------------------------------------
    def residual(self, u: FloatArray) -> tuple[FloatArray, float]:
        """Residual over all dofs at the displacement vector ``u`` and the smallest det F.

        What the tangent needs is kept for :meth:`tangent_data` at the same state.
        """
        U = u.reshape(-1, self.dim)
        self._U = U.copy()
        r = np.zeros(self.ndof)
        self._state = []
        jmin = np.inf
        for s in self.solids:
            vectors, j, state = self._solid_residual(s, U)
            jmin = min(jmin, j)
            r += np.bincount(s.edofs, weights=vectors.ravel(), minlength=self.ndof)
            self._state.append(state)
        for w in self.walls:
            p = float(w.item.results.pressure)
            cofN = self._cof_normal(_deformation(w.g, w.cells, U), w.ndA)  # (f, q, d)
            # r[f, a, i] = p sum_q h[q, a] cof(F)_iJ N_J dA
            r += np.bincount(w.edofs, weights=(p * np.matmul(w.h.T[None], cofN)).ravel(), minlength=self.ndof)
        if self.dead:
            r -= self.dead.vector()
        return r, jmin

    def tangent_data(self) -> FloatArray:
        """CSR ``data`` of ``K[dof1, dof1]`` (its upper triangle if symmetric), state of the last residual."""
        # every owner's assembled entries side by side, then one scatter-add of them all
        values, start = self._values, 0
        for s, state in zip(self.solids, self._state, strict=True):
            values[start : start + s.take.size] = self._solid_tangent(s, state).ravel()[s.take]
            start += s.take.size
        for w in self.walls:
            K = self._wall_tangent(w, float(w.item.results.pressure), self._U)
            values[start : start + w.take.size] = K.ravel()[w.take]
            start += w.take.size
        return np.asarray(np.bincount(self._scatter, weights=values, minlength=self.nnz), dtype=np.float64)

    def tangent(self) -> Any:
        """``K[dof1, dof1]`` as ``scipy.sparse.csr_matrix`` (state of the last residual)."""
        import scipy.sparse as sp

        n1 = self.dof1.size
        matrix = sp.csr_matrix((self.tangent_data(), self.indices, self.indptr), shape=(n1, n1))
        if self.symmetric:
            matrix = (matrix + sp.triu(matrix, k=1).T).tocsr()
        return matrix

    def cavity_volume(self, u: FloatArray) -> float:
        """Volume (area in 2D) enclosed by the pressurised walls, as :func:`pneumorph.fem.cavity_volume`."""
        U = u.reshape(-1, self.dim)
        total = 0.0
        for w in self.walls:
            F = _deformation(w.g, w.cells, U)
            x = np.matmul(w.h[None], (self.points + U)[w.cells])  # (f, q, d)
            total += float(np.sum(x * self._cof_normal(F, w.ndA)))
        return -total / self.dim


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

        from pneumorph.fem.ogden import OgdenCompressible

        if isinstance(umat, OgdenCompressible):
            return lambda F: ogden_plane_strain(F, umat.mu, umat.alpha, umat.bulk)
        if isinstance(umat, fem.NeoHookeCompressible) and umat.lmbda is not None:
            return lambda F: neo_hooke_plane_strain(F, float(umat.mu), float(umat.lmbda))
        raise TypeError(f"no fast plane-strain kernel for {type(umat).__name__}; use the FElupe backend")

    def _layouts(self, g: FloatArray) -> dict[str, FloatArray]:
        c, q, n, _ = g.shape
        return {
            "g_res": np.ascontiguousarray(g.transpose(0, 2, 1, 3).reshape(c, n, 2 * q)),  # [c, a, (q, J)]
            "gT": np.ascontiguousarray(g.transpose(0, 1, 3, 2).reshape(c * q, 2, n)),  # [(c, q), L, b]
            # d_ii' g[c, q, a, J] as [c, (a, i), (q, i', J)]
            "B": np.ascontiguousarray(np.einsum("cqaJ,ij->caiqjJ", g, np.eye(2)).reshape(c, 2 * n, 4 * q)),
        }

    def _entries(self, owner: _Solid | _Walls, act: IntArray) -> tuple[IntArray, IntArray, NDArray[np.bool_]]:
        # the full element matrix, entries (c, a, i, k, b)
        c, n, _ = act.shape
        rows = np.broadcast_to(act[:, :, :, None, None], (c, n, 2, 2, n))
        cols = np.broadcast_to(act.transpose(0, 2, 1)[:, None, None, :, :], (c, n, 2, 2, n))
        return rows, cols, (rows >= 0) & (cols >= 0)

    def _entry_nodes(self, owner: _Solid | _Walls) -> tuple[IntArray, IntArray]:
        n = np.arange(owner.cells.shape[1])
        return n[:, None, None, None], n  # entries (a, i, k, b)

    def _solid_residual(self, s: _Solid, U: FloatArray) -> tuple[FloatArray, float, Any]:
        c, q = s.dV.shape
        F = _deformation(s.g, s.cells, U)
        P, A, J = s.kernel(np.ascontiguousarray(F.transpose(2, 3, 0, 1)).reshape(2, 2, c * q))
        dV = s.dV.reshape(-1)
        PdV = (P * dV).reshape(2, 2, c, q)
        # r[c, a, i] = sum_(q, J) g[c, q, a, J] P[i, J, c, q] dV
        return np.matmul(s.layouts["g_res"], PdV.transpose(2, 3, 1, 0).reshape(c, 2 * q, 2)), float(J.min()), A * dV

    def _solid_tangent(self, s: _Solid, AdV: FloatArray) -> FloatArray:
        c, q, n, _ = s.g.shape
        # D[cq, (i, J, k), b] = sum_L A[i, J, k, L, cq] dV g[cq, b, L]
        At = np.ascontiguousarray(AdV.reshape(16, c * q).T).reshape(c * q, 8, 2)
        D = np.matmul(At, s.layouts["gT"]).reshape(c, 4 * q, 2 * n)  # [c, (q, i, J), (k, b)]
        # K[c, (a, i), (k, b)] = sum_(q, J) g[c, q, a, J] D[c, (q, i, J), (k, b)]
        return np.matmul(s.layouts["B"], D)

    def _wall_tangent(self, w: _Walls, p: float, U: FloatArray) -> FloatArray:
        # t[f, q, b] = N_1 dN_b/dX_2 - N_2 dN_b/dX_1 (with dA); M[f, a, b] = p sum_q h_a t_b
        t = w.ndA[..., 0:1] * w.g[..., 1] - w.ndA[..., 1:2] * w.g[..., 0]
        M = p * np.matmul(w.h.T[None], t)  # (f, n, n)
        return _EPS[None, None, :, :, None] * M[:, :, None, None, :]  # (f, a, i, k, b)

    @staticmethod
    def _cof_normal(F: FloatArray, ndA: FloatArray) -> FloatArray:
        out = np.empty_like(ndA)
        out[..., 0] = F[..., 1, 1] * ndA[..., 0] - F[..., 1, 0] * ndA[..., 1]
        out[..., 1] = -F[..., 0, 1] * ndA[..., 0] + F[..., 0, 0] * ndA[..., 1]
        return out


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

        if isinstance(umat, OgdenCompressible):
            return lambda F, tangent, principal: umat.kernel(F, tangent, principal, _UPPER)
        raise TypeError(f"no fast 3D kernel for {type(umat).__name__}; use the FElupe backend")

    def _layouts(self, g: FloatArray) -> dict[str, FloatArray]:
        c, q, n, _ = g.shape
        return {
            "G": np.ascontiguousarray(g.transpose(0, 2, 1, 3).reshape(c, n, 3 * q)),  # [c, a, (q, J)]
            "gt": np.ascontiguousarray(g.transpose(0, 1, 3, 2)),  # [c, q, L, b]
        }

    def _entries(self, owner: _Solid | _Walls, act: IntArray) -> tuple[IntArray, IntArray, NDArray[np.bool_]]:
        ik = np.array(_UPPER)
        if isinstance(owner, _Solid):
            # entry (c, a, ik, b) at (row of (a, i), column of (b, k)); blocks i < k
            # stand for themselves and their transposes, blocks i == k hold both
            off = (ik[:, 0] != ik[:, 1])[None, None, :, None]
            rows = act[:, :, ik[:, 0]][:, :, :, None]
            cols = act[:, :, ik[:, 1]].transpose(0, 2, 1)[:, None]
            lo, hi = np.minimum(rows, cols), np.maximum(rows, cols)
            return lo, hi, (lo >= 0) & (off | (rows <= cols))
        # entry (f, a, i, b, k): the full face matrix, its upper-triangle entries
        rows = act[:, :, :, None, None]
        cols = act[:, None, None, :, :]
        rows, cols = np.broadcast_arrays(rows, cols)
        return rows, cols, (rows >= 0) & (rows <= cols)

    def _entry_nodes(self, owner: _Solid | _Walls) -> tuple[IntArray, IntArray]:
        n = np.arange(owner.cells.shape[1])
        if isinstance(owner, _Solid):
            return n[:, None, None], n  # entries (a, ik, b)
        return n[:, None, None, None], n[:, None]  # entries (a, i, b, k)

    def _solid_residual(self, s: _Solid, U: FloatArray) -> tuple[FloatArray, float, Any]:
        c, q = s.dV.shape
        # F[c, i, (q, J)] = sum_a u[c, a, i] g[c, q, a, J], then as [i, J, (c, q)]
        F = np.matmul(U[s.cells].transpose(0, 2, 1), s.layouts["G"]).reshape(c, 3, q, 3)
        Fp = np.ascontiguousarray(F.transpose(1, 3, 0, 2)).reshape(3, 3, c * q)
        Fp[0, 0] += 1.0
        Fp[1, 1] += 1.0
        Fp[2, 2] += 1.0
        principal = principal_3d(Fp)
        P, _, J = s.kernel(Fp, False, principal)
        # r[c, a, i] = sum_(q, J) g[c, q, a, J] P[i, J, c, q] dV
        PdV = (P * s.dV.reshape(-1)).reshape(3, 3, c, q).transpose(2, 3, 1, 0).reshape(c, 3 * q, 3)
        return np.matmul(s.layouts["G"], PdV), float(J.min()), (Fp, principal)

    def _solid_tangent(self, s: _Solid, state: Any) -> FloatArray:
        Fp, principal = state
        c, q, n, _ = s.g.shape
        _, A, _ = s.kernel(Fp, True, principal)
        assert A is not None
        dtype = self.tangent_dtype
        # A[i, J, k, L, p] for the computed (i, k) pairs, as [p, J, ik, L] with dV
        Ap = (A * s.dV.reshape(-1)).transpose(3, 1, 0, 2).astype(dtype).reshape(c, q, 3, 6, 3)
        key = f"blocks-{np.dtype(dtype).name}"
        if key not in s.layouts:  # kept: allocating tens of MB per tangent costs page faults
            s.layouts[key] = np.empty((c, n, 6, n), dtype=dtype)
            s.layouts[f"G-{np.dtype(dtype).name}"] = s.layouts["G"].astype(dtype)
            s.layouts[f"gt-{np.dtype(dtype).name}"] = s.layouts["gt"].astype(dtype)
        blocks = s.layouts[key]
        G, gt = s.layouts[f"G-{np.dtype(dtype).name}"], s.layouts[f"gt-{np.dtype(dtype).name}"]
        for start in range(0, c, _CHUNK):
            sl = slice(start, min(start + _CHUNK, c))
            m = sl.stop - sl.start
            # E[c, q, J, ik, b] = sum_L A dV g[c, q, b, L], a batched matrix product (einsum's
            # optimised path returns it transposed, which the reshape below would copy)
            E = np.matmul(Ap[sl].reshape(m * q, 18, 3), gt[sl].reshape(m * q, 3, n))
            # K[c, a, (ik, b)] = sum_(q, J) g[c, q, a, J] E[c, (q, J), (ik, b)]
            blocks[sl] = np.matmul(G[sl], E.reshape(m, 3 * q, 6 * n)).reshape(m, n, 6, n)
        return blocks

    def _wall_tangent(self, w: _Walls, p: float, U: FloatArray) -> FloatArray:
        F = _deformation(w.g, w.cells, U)
        # v[f, q, b, m] = [F (N dA x dN_b/dX)]_m; M[f, a, b, m] = p sum_q h_a v_bm
        t = _cross(w.ndA[:, :, None, :], w.g)  # (f, q, n, 3)
        v = np.matmul(t, F.transpose(0, 1, 3, 2))  # (f, q, n, m)
        f, q, n, _ = v.shape
        M = p * np.matmul(w.h.T[None], v.reshape(f, q, 3 * n)).reshape(f, n, n, 3)
        K = np.zeros((f, n, 3, n, 3))  # K[a, i, b, k] = e_ikm M[a, b, m]
        for i, k, m_, sign in ((0, 1, 2, 1), (1, 2, 0, 1), (2, 0, 1, 1), (1, 0, 2, -1), (2, 1, 0, -1), (0, 2, 1, -1)):
            K[:, :, i, :, k] = sign * M[..., m_]
        return K

    @staticmethod
    def _cof_normal(F: FloatArray, ndA: FloatArray) -> FloatArray:
        """``cof(F) N dA = N_1 F_2 x F_3 + N_2 F_3 x F_1 + N_3 F_1 x F_2`` (columns F_J), (f, q, 3)."""
        c1, c2, c3 = F[..., :, 0], F[..., :, 1], F[..., :, 2]
        return ndA[..., 0:1] * _cross(c2, c3) + ndA[..., 1:2] * _cross(c3, c1) + ndA[..., 2:3] * _cross(c1, c2)


__all__ = ["FastSystem", "PlaneStrainSystem", "SolidSystem3D"]
