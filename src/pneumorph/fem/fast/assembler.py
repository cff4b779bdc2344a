"""The fast assembler's base (:class:`FastSystem`): residual and tangent of FElupe items straight
into a fixed CSR pattern of the free unknowns, any dimension; its plane-strain and 3D hooks:
:mod:`pneumorph.fem.fast.system`.
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from pneumorph.fem.fast.contact import RigidContact
from pneumorph.fem.fast.loads import DeadLoads
from pneumorph.fem.fast.mixed import cofactor, pressure_space, volumetric

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: cells per chunk of the 3D tangent (keeps the temporaries in the tens of MB)
TANGENT_CHUNK = 256

#: CSR patterns (with every owner's entries and positions) kept for systems of the same mesh: a design solved
#: again (a verification, an identification's solves, a benchmark's repeats) skips the 1 s of a 15-unit 3D
#: pattern. About 140 MB each on the 15-unit 3D half model, so only the last few.
PATTERN_CACHE_SIZE = 2


@dataclass(frozen=True)
class Pattern:
    """A system's CSR pattern of the active block and every owner's assembled entries and their positions."""

    indptr: NDArray[np.int32]
    indices: NDArray[np.int32]
    nnz: int
    scatter: IntArray  # every owner's CSR positions side by side
    owners: tuple[tuple[IntArray, IntArray, int, int], ...]  # (edofs, take, start, size) per owner
    #: the linear solver's fill-reducing permutations of the pattern, by the solver's kind (set by its first user)
    orderings: dict[Any, NDArray[np.int32]] = field(default_factory=dict)


_patterns: OrderedDict[str, Pattern] = OrderedDict()
_patterns_lock = threading.Lock()


@dataclass
class SolidData:
    """One material on some cells: gradients in the layouts the products need."""

    cells: IntArray  # (c, n)
    g: FloatArray  # (c, q, n, d) dN_a/dX_J
    dV: FloatArray  # (c, q)
    kernel: Any
    layouts: dict[str, FloatArray] = field(default_factory=dict)
    take: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))  # assembled entries
    scatter: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))  # their CSR positions
    edofs: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    #: the material and its elements' pressure space when its volumetric term is integrated on a dilatation of its
    #: own (:mod:`.mixed`)
    mixed: Any = None
    #: every cell is a box along the axes (``dN/dX = dN/dr dr/dX`` with a constant, diagonal ``dr/dX`` per cell):
    #: the dimension may contract its tangent with the reference gradients, a constant of the element, in one
    #: matrix product (and order the entries otherwise: part of the pattern's key)
    boxes: bool = False


@dataclass
class WallData:
    """The pressurised faces of one ``SolidBodyPressure``."""

    item: Any
    cells: IntArray  # (f, n) of the volume cells the faces belong to
    g: FloatArray  # (f, q, n, d)
    h: FloatArray  # (q, n)
    ndA: FloatArray  # (f, q, d)
    take: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    scatter: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    edofs: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    #: what the dimension's tangent keeps of the reference faces between evaluations
    layouts: dict[str, Any] = field(default_factory=dict)


def deformation_gradient(g: FloatArray, cells: IntArray, U: FloatArray) -> FloatArray:
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
        ``felupe.SolidBodyForce`` dead loads (all linked to one global field) and
        :class:`~pneumorph.fem.fast.contact.RigidContact` obstacles (owners of their nodes' own blocks).
    field : felupe.FieldContainer
        The global field; only its size and mesh points are read here.
    dof1, dof0 : ndarray
        Active and prescribed degrees of freedom (FElupe numbering ``dim * point + component``).

    Attributes
    ----------
    indptr, indices : ndarray
        CSR pattern of ``K[dof1, dof1]`` (its upper triangle if :attr:`symmetric`).
    pattern : Pattern
        The pattern and every owner's entries and positions, shared (read-only) by the systems of one mesh: the
        last :data:`PATTERN_CACHE_SIZE` meshes' are kept, by a key of the active dofs and every owner's cells.
    remainder : scipy.sparse.csr_matrix or None
        Of a symmetric system, what the last :meth:`tangent_data` left out of ``K[dof1, dof1]``: the
        non-symmetric rest of the friction blocks of its obstacles (None: nothing), for a solver that corrects
        the symmetric factorisation (:func:`~pneumorph.fem.linear.corrected`).
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
        self.solids: list[SolidData] = []
        self.walls: list[WallData] = []
        self.contacts: list[RigidContact] = []
        forces = []
        for item in items:
            if isinstance(item, RigidContact):  # rigid obstacles: a block per surface node
                self.contacts.append(item)
                continue
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
                self.walls.append(WallData(item, cells, g, h, ndA))
            elif isinstance(item, fem.SolidBody):
                solid = SolidData(cells, g, np.ascontiguousarray(region.dV.T), self._kernel_of(item.umat))
                self._prepare(solid, region)
                if getattr(item.umat, "mixed", False):  # P1 on quadratic cells, P0 on linear ones
                    X = np.einsum("aq,cad->cqd", region.h[:, :, 0], self.points[cells])
                    solid.mixed = (item.umat, pressure_space(X, solid.dV, linear=cells.shape[1] > 2**d))
                self.solids.append(solid)
            else:
                raise TypeError(f"no fast assembly for {type(item).__name__}; use the FElupe backend")
        self.dead = DeadLoads(forces, self.npoints, d)
        self._build_pattern()
        self._state: list[Any] = []
        self._U = np.zeros((self.npoints, d))
        self.remainder: Any = None

    # -- dimension hooks ---------------------------------------------------------------
    def _check_field(self, sub: Any) -> None:
        raise NotImplementedError  # pragma: no cover

    def _kernel_of(self, umat: Any) -> Any:
        raise NotImplementedError  # pragma: no cover

    def _prepare(self, s: SolidData, region: Any) -> None:
        """Set a solid's gradients in the layouts this dimension's products need (``s.layouts``, ``s.boxes``;
        ``region``: the FElupe region they come from)."""
        raise NotImplementedError  # pragma: no cover

    def _entries(self, owner: SolidData | WallData, act: IntArray) -> tuple[IntArray, IntArray, NDArray[np.bool_]]:
        """Active (row, column) of every element-matrix entry as it is computed, and which
        of them are assembled (``act``: the active index of each cell's dofs, (c, n, d))."""
        raise NotImplementedError  # pragma: no cover

    def _entry_nodes(self, owner: SolidData | WallData) -> tuple[IntArray, IntArray]:
        """The local nodes ``a``, ``b`` that each entry of :meth:`_entries` couples, as index
        arrays that broadcast to its shape without the cell axis."""
        raise NotImplementedError  # pragma: no cover

    def _solid_residual(self, s: SolidData, U: FloatArray) -> tuple[FloatArray, float, Any]:
        """The element vectors ``(c, n, d)`` of a solid, its smallest det F and the state
        :meth:`_solid_tangent` needs."""
        raise NotImplementedError  # pragma: no cover

    def _solid_tangent(self, s: SolidData, state: Any) -> FloatArray:
        """The element matrices of a solid, entries in :meth:`_entries` order."""
        raise NotImplementedError  # pragma: no cover

    def _wall_tangent(self, w: WallData, p: float, U: FloatArray) -> FloatArray:
        """The follower-pressure stiffness of some walls: its assembled entries (``w.take`` of the
        :meth:`_entries` order)."""
        raise NotImplementedError  # pragma: no cover

    @staticmethod
    def _cof_normal(F: FloatArray, ndA: FloatArray) -> FloatArray:
        """``cof(F) N dA`` at the boundary points, (f, q, d)."""
        raise NotImplementedError  # pragma: no cover

    @staticmethod
    def _mixed_volumetric(s: SolidData, F: FloatArray, P: FloatArray, J: FloatArray) -> tuple[FloatArray, Any]:
        """The stress with the volumetric term on the elements' own dilatation (:mod:`.mixed`), and what the
        tangent needs: the pressure at every point, ``cof(F)``, ``det F`` and the element term (c, m, m).

        ``F``, ``P`` (points last, (d, d, c q)) and ``J`` (of the elastic part, (c q,)) as the kernel gives them.
        """
        c, q = s.dV.shape
        umat, space = s.mixed
        t3 = float(getattr(umat, "thermal_stretch", 1.0)) ** 3
        first, second = volumetric(space.project(J.reshape(c, q), s.dV), float(umat.bulk))
        p = space.project(first, s.dV).reshape(-1)
        cof = cofactor(F)
        return P + p * cof, (p, cof, J * t3, space.element_term(second, s.dV) / t3)

    def _pressure_vectors(self, s: SolidData, cof: FloatArray) -> FloatArray:
        """``b_m[c, a, i] = int N_m cof(F)_iJ dN_a/dX_J dV`` of every pressure basis function, (c, m, n, d)."""
        N = s.mixed[1].N
        return np.stack([self._element_vectors(s, cof * N[:, :, m].reshape(-1)) for m in range(N.shape[2])], axis=1)

    def _element_vectors(self, s: SolidData, P: FloatArray) -> FloatArray:
        """``r[c, a, i] = sum_(q, J) g[c, q, a, J] P[i, J, c, q] dV`` of a stress-like field ``P`` (d, d, c q)."""
        raise NotImplementedError  # pragma: no cover

    # -- pattern ------------------------------------------------------------------------
    def _pattern_key(self) -> str:
        """What the pattern follows from: the system's kind, its active dofs, every owner's kind and cells."""
        digest = hashlib.blake2b(digest_size=20)
        digest.update(f"{type(self).__name__} {self.symmetric} {self.ndof}".encode())
        digest.update(np.ascontiguousarray(self.dof1).tobytes())
        owners: list[Any] = [*self.solids, *self.walls, *self.contacts]
        for owner in owners:
            cells = np.ascontiguousarray(owner.cells, dtype=np.int64)
            digest.update(f"{type(owner).__name__} {cells.shape} {getattr(owner, 'boxes', False)}".encode())
            digest.update(cells.tobytes())
        return digest.hexdigest()

    def _build_pattern(self) -> None:
        """The CSR pattern and every owner's entries: the cached ones of the same mesh (:data:`PATTERN_CACHE_SIZE`,
        the arrays shared read-only), else computed (:meth:`_compute_pattern`) and kept."""
        owners: list[Any] = [*self.solids, *self.walls, *self.contacts]
        key = self._pattern_key() if PATTERN_CACHE_SIZE > 0 else ""
        with _patterns_lock:
            pattern = _patterns.get(key)
            if pattern is not None:
                _patterns.move_to_end(key)
        if pattern is None:
            pattern = self._compute_pattern()
            arrays: list[NDArray[Any]] = [pattern.indptr, pattern.indices, pattern.scatter]
            for array in arrays + [a for owner in pattern.owners for a in (owner[0], owner[1])]:
                array.flags.writeable = False
            if key:
                with _patterns_lock:
                    _patterns[key] = pattern
                    while len(_patterns) > PATTERN_CACHE_SIZE:
                        _patterns.popitem(last=False)
        self.indptr, self.indices, self.nnz, self._scatter = pattern.indptr, pattern.indices, pattern.nnz, \
            pattern.scatter
        for owner, (edofs, take, start, size) in zip(owners, pattern.owners, strict=True):
            owner.edofs, owner.take, owner.scatter = edofs, take, pattern.scatter[start : start + size]
        self.pattern = pattern
        self._values = np.empty(self._scatter.size)  # kept: a tangent fills it anew

    def _compute_pattern(self) -> Pattern:
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
        d, npts, n1 = self.dim, self.npoints, self.dof1.size
        active = np.full(self.ndof, -1, dtype=np.int32)  # (int32: half the memory traffic of the gathers)
        active[self.dof1] = np.arange(n1)
        owners: list[Any] = [*self.solids, *self.walls, *self.contacts]
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
        total = int(indptr[-1])
        # int32 positions and indices where they fit: half the memory traffic of the gathers below
        small: type[np.signedinteger[Any]] = np.int32 if max(total, keys.size * d * d) < 2**31 else np.int64
        full = (indptr[np.maximum(rows, 0)][:, :, None] + before[:, :, None]
                + (np.cumsum(exists, axis=2) - exists)).astype(small)
        # 3. every element entry's (pair, i, k), of the assembled ones
        offsets = np.cumsum([0, *(k.size for k in pair_keys)])
        component = (self.dof1 % d).astype(small)  # of each active dof
        full_flat = full.reshape(-1)
        positions = []
        used = np.zeros(total, dtype=bool)
        for o, owner in enumerate(owners):
            dofs = d * owner.cells[:, :, None] + np.arange(d)  # (c, n, d)
            owner.edofs = dofs.ravel()
            erows, ecols, valid = self._entries(owner, active[dofs])
            owner.take = np.flatnonzero(valid)
            n = owner.cells.shape[1]
            pair = inverse[offsets[o] : offsets[o + 1]].reshape(-1, n, n).astype(small)
            ia, ib = self._entry_nodes(owner)
            # every entry's index (invalid ones' too: one gather of the assembled ones after)
            index = pair[:, ia, ib] * (d * d) + component[erows] * d + component[ecols]  # int32 stays int32
            pos = full_flat[index.reshape(-1)[owner.take]]
            used[pos] = True
            positions.append(pos)
        # 4. the columns (a position past the end takes what does not exist); every owner's CSR positions side by
        # side; of the entries no element assembles none kept (there are none on the actuators' meshes)
        columns = np.empty(total + 1, dtype=np.int32)
        columns[np.where(exists, full, total).reshape(-1)] = np.broadcast_to(cols[:, None, :], exists.shape).ravel()
        spans = np.cumsum([0, *(pos.size for pos in positions)])
        parts = tuple((o.edofs, o.take, int(spans[i]), int(spans[i + 1] - spans[i])) for i, o in enumerate(owners))
        if used.all():
            return Pattern(indptr.astype(np.int32), columns[:total], total,
                           np.concatenate(positions).astype(np.int64), parts)
        renumber = np.cumsum(used) - 1
        kept_rows = np.repeat(np.arange(n1), np.diff(indptr))[used]
        return Pattern(np.r_[0, np.cumsum(np.bincount(kept_rows, minlength=n1))].astype(np.int32),
                       columns[:total][used], int(used.sum()), np.take(renumber, np.concatenate(positions)), parts)

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
            cofN = self._cof_normal(deformation_gradient(w.g, w.cells, U), w.ndA)  # (f, q, d)
            # r[f, a, i] = p sum_q h[q, a] cof(F)_iJ N_J dA
            r += np.bincount(w.edofs, weights=(p * np.matmul(w.h.T[None], cofN)).ravel(), minlength=self.ndof)
        for c in self.contacts:  # k g n at the nodes inside an obstacle
            r += np.bincount(c.edofs, weights=c.residual(self.points + U).ravel(), minlength=self.ndof)
        if self.dead:
            r -= self.dead.vector()
        return r, jmin

    def tangent_data(self) -> FloatArray:
        """CSR ``data`` of ``K[dof1, dof1]`` (its upper triangle if symmetric), state of the last residual.

        A symmetric system keeps the symmetric part of its obstacles' blocks without the coupling of a sliding
        node's friction to its normal force (:func:`~pneumorph.fem.fast.friction.coulomb`), and sets
        ``remainder`` to the rest of them.
        """
        # every owner's assembled entries side by side, then one scatter-add of them all
        values, start = self._values, 0
        for s, state in zip(self.solids, self._state, strict=True):
            values[start : start + s.take.size] = self._solid_tangent(s, state).ravel()[s.take]
            start += s.take.size
        for w in self.walls:
            values[start : start + w.take.size] = self._wall_tangent(w, float(w.item.results.pressure), self._U)
            start += w.take.size
        remainders = []
        for c in self.contacts:  # (m, d, d): the entries (a, i, k, b) and (a, i, b, k) of one node alike
            K = c.tangent(self.points + self._U, self.symmetric)
            if self.symmetric:  # friction's blocks are not: the rest of them apart (``remainder``)
                K = 0.5 * (K + K.transpose(0, 2, 1))
                if c.friction > 0.0:
                    remainders.append((c.edofs, c.tangent(self.points + self._U) - K))
            values[start : start + c.take.size] = K.ravel()[c.take]
            start += c.take.size
        self.remainder = self._remainder(remainders)
        return np.asarray(np.bincount(self._scatter, weights=values, minlength=self.nnz), dtype=np.float64)

    def _remainder(self, blocks: list[tuple[IntArray, FloatArray]]) -> Any:
        """The nodes' blocks ``(edofs, K (m, d, d))`` as a sparse matrix over the active dofs, or None if all zero."""
        import scipy.sparse as sp

        blocks = [(edofs, K) for edofs, K in blocks if np.any(K)]
        if not blocks:
            return None
        d, n1 = self.dim, self.dof1.size
        active = np.full(self.ndof, -1, dtype=np.int64)
        active[self.dof1] = np.arange(n1)
        rows, cols, vals = [], [], []
        for edofs, K in blocks:
            dofs = active[edofs.reshape(-1, d)]  # (m, d)
            r, c = np.broadcast_arrays(dofs[:, :, None], dofs[:, None, :])
            keep = (r >= 0) & (c >= 0) & (K != 0.0)
            rows.append(r[keep])
            cols.append(c[keep])
            vals.append(K[keep])
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n1, n1))

    def tangent(self) -> Any:
        """``K[dof1, dof1]`` as ``scipy.sparse.csr_matrix``, ``remainder`` included (state of the last residual)."""
        import scipy.sparse as sp

        n1 = self.dof1.size
        matrix = sp.csr_matrix((self.tangent_data(), self.indices, self.indptr), shape=(n1, n1))
        if self.symmetric:
            matrix = (matrix + sp.triu(matrix, k=1).T).tocsr()
            if self.remainder is not None:
                matrix = (matrix + self.remainder).tocsr()
        return matrix

    def wall_loads(self, u: FloatArray) -> list[FloatArray]:
        """Every wall's residual at unit pressure, ``int h cof(F) N dA`` over all dofs, at ``u``.

        The residual's derivative with respect to a wall's pressure; over closed cavities
        their sum is minus the derivative of the enclosed volume (:meth:`cavity_volume`)
        with respect to ``u``, the border of a volume-controlled solve
        (:class:`~pneumorph.fem.fast.volume.VolumeControl`).
        """
        U = u.reshape(-1, self.dim)
        loads: list[FloatArray] = []
        for w in self.walls:
            cofN = self._cof_normal(deformation_gradient(w.g, w.cells, U), w.ndA)
            load = np.bincount(w.edofs, weights=np.matmul(w.h.T[None], cofN).ravel(), minlength=self.ndof)
            loads.append(load.astype(np.float64, copy=False))
        return loads

    def cavity_volume(self, u: FloatArray) -> float:
        """Volume (area in 2D) enclosed by the pressurised walls, as :func:`pneumorph.fem.cavity_volume`."""
        U = u.reshape(-1, self.dim)
        total = 0.0
        for w in self.walls:
            F = deformation_gradient(w.g, w.cells, U)
            x = np.matmul(w.h[None], (self.points + U)[w.cells])  # (f, q, d)
            total += float(np.sum(x * self._cof_normal(F, w.ndA)))
        return -total / self.dim
