"""The fast system's CSR pattern, kept per mesh: a second system of the same mesh shares the first one's pattern,
which equals one computed afresh, and assembles the same tangent; another mesh gets its own."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.fem.fast import assembler
from pneumorph.fem.fast.system import PlaneStrainSystem, SolidSystem3D
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D, Reduced2D


def _system(model, design: str):
    _, body, set_pressure = model.build(design)
    set_pressure(0.02)
    kind = SolidSystem3D if body.dim == 3 else PlaneStrainSystem
    return kind(body.items, body.field, body.dof1, body.dof0)


def _entries(system):
    owners = [*system.solids, *system.walls, *system.contacts]
    return [system.indptr, system.indices, *(o.edofs for o in owners), *(o.take for o in owners),
            *(o.scatter for o in owners)]


@pytest.mark.parametrize("model", [Full3D(2, UnitSpec(element_size=3.0)), Reduced2D(2, UnitSpec(element_size=2.0))],
                         ids=["3d", "2d"])
def test_a_second_system_of_a_mesh_shares_the_pattern_a_fresh_one_equals(model, monkeypatch) -> None:
    first = _system(model, "10")
    second = _system(model, "10")
    assert second.pattern is first.pattern
    assert all(np.shares_memory(a, b) for a, b in zip(_entries(first), _entries(second), strict=True))
    monkeypatch.setattr(assembler, "PATTERN_CACHE_SIZE", 0)
    fresh = _system(model, "10")
    assert fresh.pattern is not first.pattern
    assert fresh.nnz == first.nnz
    for a, b in zip(_entries(first), _entries(fresh), strict=True):
        assert not np.shares_memory(a, b) and np.array_equal(a, b)
    # the same tangent at a deformed state, from the shared pattern and from the fresh one
    u = np.zeros(first.ndof)
    u[first.dof1] = 1e-3 * np.random.default_rng(3).standard_normal(first.dof1.size)
    first.residual(u)
    fresh.residual(u)
    np.testing.assert_array_equal(first.tangent_data(), fresh.tangent_data())


def test_another_mesh_gets_its_own_pattern_and_the_cache_stays_small() -> None:
    model = Full3D(2, UnitSpec(element_size=3.0))
    a, b = _system(model, "00"), _system(model, "01")  # a turned unit: other cells
    assert a.pattern is not b.pattern
    assert a.indptr.size == b.indptr.size  # as many active dofs, numbered otherwise
    for design in ("10", "11", "00"):
        _system(model, design)
    assert len(assembler._patterns) == assembler.PATTERN_CACHE_SIZE


def test_a_shared_pattern_is_read_only() -> None:
    system = _system(Full3D(1, UnitSpec(element_size=3.0)), "0")
    with pytest.raises(ValueError):
        system.indices[0] = 1
    with pytest.raises(ValueError):
        system.solids[0].scatter[0] = 0


def test_a_second_solver_of_a_pattern_takes_the_first_ones_ordering_and_factors_alike() -> None:
    pytest.importorskip("pypardiso")
    from pneumorph.fem.fast.newton import FastSubstep

    model = Full3D(2, UnitSpec(element_size=3.0))
    steps = []
    for _ in range(2):
        system = _system(model, "01")
        substep = FastSubstep(system, reuse=0.7)
        u = np.zeros(system.ndof)
        u[system.dof1] = 1e-3 * np.random.default_rng(5).standard_normal(system.dof1.size)
        r, _ = system.residual(u)
        substep.factorize()
        steps.append((substep.solver, substep.solve(r[system.dof1])))
    (first, x1), (second, x2) = steps
    assert first.iparm[4] == 2 and second.iparm[4] == 1  # computed, then given
    assert np.array_equal(np.sort(first.perm), np.arange(1, first.n + 1))  # a permutation (1-based)
    assert np.array_equal(first.perm, second.perm)
    np.testing.assert_array_equal(x1, x2)


def test_a_design_solved_again_on_the_kept_pattern_and_ordering_gives_the_same_answer() -> None:
    from pneumorph.fem.stepping import StepSettings
    from pneumorph.models.fe import RampSpec

    model = Full3D(2, UnitSpec(element_size=3.0), RampSpec(pressure=0.02, steps=StepSettings(
        increments=3, substeps=1, max_iterations=25)))
    first, second = model.solve("01"), model.solve("01")
    assert second.response.metadata["newton_iterations"] == first.response.metadata["newton_iterations"]
    np.testing.assert_array_equal(second.displacements, first.displacements)
    assert np.abs(first.displacements[-1]).max() > 1.0  # it bent (mm)


@pytest.mark.parametrize("distorted", [False, True], ids=["boxes", "distorted"])
def test_the_tangent_of_box_cells_and_of_distorted_cells_is_felupes(distorted: bool) -> None:
    """Box cells contract the tangent with the element's reference gradients in one matrix product (their
    own order of entries, their own pattern key); distorted cells take every point's gradients. Both: FElupe's
    tangent to rounding, in double and (to single precision) in single precision."""
    import felupe as fem
    from felupe.tools._newton import fun_items, jac_items

    from pneumorph.fem import OgdenCompressible

    mesh = fem.Cube(b=(2.0, 1.0, 1.5), n=(4, 3, 3)).add_midpoints_edges()
    X = mesh.points.copy()
    if distorted:  # a smooth map that shears and bends the cells
        mesh.points[:, 1] += 0.15 * X[:, 0] ** 2 + 0.1 * X[:, 2]
        mesh.points[:, 2] += 0.1 * np.sin(2.0 * X[:, 1])
    field = fem.FieldContainer([fem.Field(fem.RegionQuadraticHexahedron(mesh), dim=3)])
    solid = fem.SolidBody(OgdenCompressible((-6.503e-6, 0.2169, 1.372e-3), (-21.32, 1.180, 4.884), 0.119), field)
    dof0, dof1 = fem.dof.partition(field, {"x0": fem.Boundary(field[0], fx=0.0)})
    system = SolidSystem3D([solid], field, dof1, dof0)
    assert system.solids[0].boxes is not distorted
    u = np.zeros(system.ndof)
    u[dof1] = 0.02 * np.random.default_rng(7).standard_normal(dof1.size)
    field[0].values[:] = u.reshape(-1, 3)
    system.residual(u)
    K = system.tangent()
    fun_items([solid], field)
    K_fe = jac_items([solid], field).tocsr()[dof1][:, dof1]
    assert abs(K - K_fe).max() <= 1e-12 * abs(K_fe).max()
    system.tangent_dtype = np.float32
    assert abs(system.tangent() - K_fe).max() <= 1e-6 * abs(K_fe).max()


def test_the_3d_kernels_in_passes_give_one_passs_numbers(monkeypatch) -> None:
    """The Ogden kernel and the eigen-decomposition of C run over slices of points (POINT_CHUNK): to the bit the
    numbers of one pass over all points, with and without the tangent, given the decomposition or not."""
    from pneumorph.fem.fast import kernels

    rng = np.random.default_rng(11)
    F = np.eye(3)[..., None] + 0.2 * rng.standard_normal((3, 3, 1000))
    F = F[..., np.linalg.det(np.moveaxis(F, -1, 0)) > 0.2]
    F[..., 0] = np.eye(3)  # equal stretches: LAPACK's points among the closed form's
    mu, alpha, bulk = (-6.503e-6, 0.2169, 1.372e-3), (-21.32, 1.180, 4.884), 0.119
    whole = kernels.principal_3d(F), kernels.ogden_3d(F, mu, alpha, bulk, pairs=[(0, 0), (1, 2)]), \
        kernels.ogden_3d(F, mu, alpha, bulk, tangent=False)
    monkeypatch.setattr(kernels, "POINT_CHUNK", 97)
    principal = kernels.principal_3d(F)
    passes = principal, kernels.ogden_3d(F, mu, alpha, bulk, principal=principal, pairs=[(0, 0), (1, 2)]), \
        kernels.ogden_3d(F, mu, alpha, bulk, tangent=False)
    for one, many in zip(whole, passes, strict=True):
        for a, b in zip(one, many, strict=True):
            assert (a is None and b is None) or np.array_equal(a, b)
    assert passes[2][1] is None and passes[1][1].shape == (2, 3, 3, F.shape[-1])


def _reference_pattern(system) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """The CSR pattern of every assembled element entry by a sort of all of them: indptr, indices and every
    owner's positions."""
    n1 = system.dof1.size
    active = np.full(system.ndof, -1, dtype=np.int64)
    active[system.dof1] = np.arange(n1)
    keys = []
    for owner in [*system.solids, *system.walls, *system.contacts]:
        rows, cols, valid = system._entries(owner, active[owner.edofs.reshape(*owner.cells.shape, -1)])
        take = np.flatnonzero(valid)
        keys.append(np.ravel(rows)[take].astype(np.int64) * n1 + np.ravel(cols)[take])
    unique = np.unique(np.concatenate(keys))
    indptr = np.r_[0, np.cumsum(np.bincount(unique // n1, minlength=n1))]
    return indptr, unique % n1, [np.searchsorted(unique, k) for k in keys]


class _SomeEntriesUnassembled(SolidSystem3D):
    """A 3D system whose solids assemble no entry of a node's own diagonal block: those of the pairs' pattern
    that no element assembles are left out."""

    def _entries(self, owner, act):
        rows, cols, valid = super()._entries(owner, act)
        if isinstance(owner, assembler.SolidData):
            valid = valid & (rows != cols)
        return rows, cols, valid


@pytest.mark.parametrize(("model", "kind"), [(Full3D(2, UnitSpec(element_size=3.0)), SolidSystem3D),
                                             (Reduced2D(2, UnitSpec(element_size=2.0)), PlaneStrainSystem),
                                             (Full3D(1, UnitSpec(element_size=3.0)), _SomeEntriesUnassembled)],
                         ids=["3d", "2d", "3d-unassembled"])
def test_the_pattern_is_that_of_a_sort_of_every_assembled_entry(model, kind, monkeypatch) -> None:
    monkeypatch.setattr(assembler, "PATTERN_CACHE_SIZE", 0)
    _, body, _ = model.build("10"[: model.n_units])
    system = kind(body.items, body.field, body.dof1, body.dof0)
    indptr, indices, positions = _reference_pattern(system)
    assert system.indptr.dtype == system.indices.dtype == np.int32
    np.testing.assert_array_equal(system.indptr, indptr)
    np.testing.assert_array_equal(system.indices, indices)
    assert system.nnz == indices.size
    for owner, expected in zip([*system.solids, *system.walls, *system.contacts], positions, strict=True):
        np.testing.assert_array_equal(owner.scatter, expected)
