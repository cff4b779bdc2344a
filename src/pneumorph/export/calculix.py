"""The 3D model as a CalculiX/Abaqus input deck, and CalculiX's displacements read back.

:func:`calculix_deck` writes what :class:`~pneumorph.models.fe.Full3D` solves for one
design as a ``.inp`` deck: the same mesh (``C3D20`` from FElupe's ``hexahedron20``, or
``C3D8`` for linear units), one element set and one material per silicone, the clamped
base (``BASE``: u = 0), the half model's symmetry plane z = width / 2 (``SYMMETRY``:
u_z = 0), a follower pressure on the cavity walls (``*DLOAD`` ``Pn`` on the element faces
whose nodes all lie on the cavity walls - the faces FElupe's pressure acts on), and one
``*STEP, NLGEOM`` whose ``*STATIC`` increments and ``*TIME POINTS`` are the model's
reported levels. :func:`~pneumorph.export.ccx.run_calculix` runs ``ccx`` on it;
:func:`~pneumorph.export.ccx.read_dat_displacements` and
:func:`~pneumorph.export.ccx.read_frd_displacements` read its displacements and
:func:`~pneumorph.export.ccx.tip_positions` turns them into the tip pneumorph reports (the
mean deformed (x, y) of the end-face nodes on the mid-plane, ``ActuatorMesh.end_points``, node set ``TIP``).

Node order
    FElupe's ``hexahedron20`` is VTK's quadratic hexahedron; CalculiX's ``C3D20`` lists
    the same nodes in the same order (corners of the face zeta = -1, of zeta = +1, the
    midside nodes of those two faces, then of the four edges along zeta). The permutation
    is not assumed: :func:`c3d20_permutation` derives it from the natural coordinates of
    both elements and :func:`check_element_order` checks every element of the deck
    (midside nodes at the middle of their edges, a positive Jacobian at every corner).
    C3D20's faces: 1 (zeta = -1), 2 (zeta = +1), 3 (eta = -1), 4 (xi = +1), 5 (eta = +1),
    6 (xi = -1); a positive ``Pn`` load pushes into the element, so on a cavity wall it
    inflates the cavity, and it follows the deformed face (as pneumorph's pressure does).

Units
    mm, Pa and micronewtons (mass in grams): stresses are written in Pa, not MPa.
    CalculiX's residual test has an absolute floor of 1e-6; in N-mm-MPa this actuator's
    nodal forces are about 1e-3 N and every increment would "converge" at once, in
    micronewtons they are about 1e3. Displacements are in mm either way.

Materials
    pneumorph (Eq 2.12; :class:`pneumorph.fem.OgdenCompressible`) uses
    ``W = sum mu_n/alpha_n (sum_a lb_a^alpha_n - 3) + 9/2 K (J^(1/3) - 1)^2`` with the
    published (Marc) moduli ``mu_n`` and the isochoric stretches ``lb``. CalculiX writes
    ``U = sum 2 mu_i/alpha_i^2 (sum_a lb_a^alpha_i - 3) + sum_i (J - 1)^(2i)/D_i``, so
    ``mu_ccx = mu_marc alpha / 2`` (the exponents are the same), ``D1 = 2/K``, and ``D2``
    and ``D3`` are written as 1e30 (CalculiX replaces a zero by ``(0.1/mu0)^i``, which
    would add a volumetric term of its own). The deviatoric parts are then identical; the
    volumetric parts are not and the format has no way to write ours: CalculiX's pressure
    is ``K (J - 1)``, Eq 2.12's is ``3K (J^(-1/3) - J^(-2/3))``. Both have the slope K at
    J = 1, but Mold Star 15 is compressible (K = 0.119 MPa, nu0 about 0.1) and J reaches
    1.37 in its walls (``shared/notes/calculix-facts.md``), where CalculiX's term is
    stiffer. Measured at 20 kPa: CalculiX's tip displacement is 4.31 % smaller for one
    unit, 4.94 % for ``"01"`` (the notes: 4.9-5.2 % for 2-4 units); with the bulk moduli
    x100 in both codes, where the two volumetric terms nearly coincide, the tips agree to
    0.02 % (``tests/export/test_calculix.py``). ``benchmarks/calculix.py`` records a
    15-unit design (``BENCHMARKS.md``).

Solver controls
    CalculiX's Ogden routine (``rubber.f``) finds the principal stretches from the roots
    of a cubic, with special-case formulas where two or three of them coincide and
    derivatives divided by their differences elsewhere. Measured on the 15-unit
    benchmark design: from the unloaded state (C = I) its first iteration's largest
    displacement is 2.3 times the converged solution's (0.154 against 0.068 mm at
    0.28 kPa), and a first increment of 4.5 kPa diverges, and at small loads the residual
    stalls at 10-100 micronewtons, which
    CalculiX's default criterion (0.5 % of the running average nodal force, itself tiny
    in the first increments) never accepts. The deck therefore starts with a twentieth of
    the first level (``*STATIC``; the increments grow to one level, never beyond) and
    measures the residual against a fixed force, ``*CONTROLS, PARAMETERS=FIELD`` with
    ``q_u = residual_force / 0.005`` (``residual_force`` 1e-4 N by default: with walls of
    about 0.2 N/mm stiffness, a displacement error below 1e-3 mm), with up to 10
    cut-backs per increment. The displacement-correction criterion (1 %) is CalculiX's
    default. The 1-unit comparison is the same with and without these controls.

Not written: gravity (:class:`~pneumorph.models.fe.Full3D` with ``gravity`` is refused),
the end-face rotation (curl) and the cavity volume pneumorph also reports.

Examples
--------
>>> from pneumorph.models.fe import Full3D, RampSpec
>>> deck = calculix_deck(Full3D(1, ramp_spec=RampSpec(pressure=0.02)), "0")
>>> [line for line in deck.splitlines() if line.startswith("*ELEMENT")]
['*ELEMENT, TYPE=C3D20, ELSET=EALL']
>>> deck.count("*MATERIAL"), "*HYPERELASTIC, OGDEN, N=3" in deck
(2, True)
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph import __version__
from pneumorph.errors import (
    GeometryError,
    MaterialDataError,
    SettingsError,
)
from pneumorph.export.c3d20 import C3D20_EDGES as C3D20_EDGES  # public here before c3d20 was a module
from pneumorph.export.c3d20 import (
    C3D20_FACES,
    C3D20_NATURAL,
    c3d20_permutation,
    cavity_faces,
    check_element_order,
)
from pneumorph.geometry.alphabet import Design
from pneumorph.geometry.assembly import ActuatorMesh, assemble
from pneumorph.geometry.orientation import parse_orientation
from pneumorph.io.files import atomic_write_text, check_writable_file
from pneumorph.materials.laws.hyperelastic import Ogden

__all__ = [
    "C3D20_FACES",
    "C3D20_NATURAL",
    "c3d20_permutation",
    "calculix_deck",
    "cavity_faces",
    "check_element_order",
    "write_calculix_deck",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Stress in the deck per MPa (the deck is in mm, Pa and micronewtons).
PA_PER_MPA = 1.0e6
#: D2 and D3 of the Ogden entry: large enough that only D1 acts (0 would not do, see above).
HUGE_D = 1.0e30

_ELEMENT_TYPES = {"hexahedron20": "C3D20", "hexahedron": "C3D8"}


def _check_model(model: Any) -> None:
    from pneumorph.models.fe import Full3D

    if not isinstance(model, Full3D):
        raise SettingsError(f"a CalculiX deck is written for the 3D model (Full3D), got {type(model).__name__}")
    if model.gravity is not None:
        raise SettingsError("the CalculiX deck does not include gravity; export the model without gravity")
    if model.obstacles:
        raise SettingsError("the CalculiX deck does not include obstacles (no rigid contact pair yet); export the "
                            "model without them")


def _set_name(region: str) -> str:
    """A region's element-set name in the deck (a bottom wall's ``bottom:<material>`` without the colon).

    >>> _set_name("layer"), _set_name("bottom:bilinear_0_2")
    ('layer', 'bottom_bilinear_0_2')
    """
    return region.replace(":", "_")


def _ogden_line(material: Any, role: str) -> list[str]:
    """The *MATERIAL block of one silicone in the deck's units."""
    model = material.model
    if not isinstance(model, Ogden):
        raise MaterialDataError(f"{role} material {material.name!r}: the deck writes Ogden materials, "
                                f"got {type(model).__name__}")
    if model.terms > 3:
        raise MaterialDataError(f"{role} material {material.name!r}: CalculiX's Ogden takes at most 3 terms, "
                                f"got {model.terms}")
    if material.bulk_modulus is None:
        raise MaterialDataError(f"{role} material {material.name!r}: no bulk modulus; the deck needs one")
    k = material.bulk_modulus.value
    values = []
    for mu, alpha in zip(model.mu, model.alpha, strict=False):
        values += [mu * alpha / 2.0 * PA_PER_MPA, alpha]
    d = [2.0 / (k * PA_PER_MPA)] + [HUGE_D] * (model.terms - 1)
    values += d
    name = f"{role.upper()}_{material.name.upper()}"[:80]
    lines = [
        f"** {role}: {material.display_name} ({material.name}), K {k} MPa",
        f"** Marc convention (MPa): mu {list(model.mu)}, alpha {list(model.alpha)}",
        f"** mu_ccx = mu_marc * alpha / 2 in Pa, D1 = 2 / K (1/Pa), D2 = D3 = {HUGE_D:g} (inactive)",
        f"*MATERIAL, NAME={name}",
        f"*HYPERELASTIC, OGDEN, N={model.terms}",
    ]
    lines += _rows((_num(v) for v in values), 8)
    lines.append(f"*SOLID SECTION, ELSET={role.upper()}, MATERIAL={name}")
    return lines


def _num(v: float) -> str:
    return format(float(v), ".15g")


def _rows(items: Iterable[str], per_line: int) -> list[str]:
    items = list(items)
    return [", ".join(items[i:i + per_line]) for i in range(0, len(items), per_line)]


def _nset(name: str, indices: Iterable[int]) -> list[str]:
    ids = [str(int(i) + 1) for i in indices]
    if not ids:
        raise GeometryError(f"node set {name} is empty")
    return [f"*NSET, NSET={name}", *_rows(ids, 16)]


def calculix_mesh(model: Any, design: str | Design) -> ActuatorMesh:
    """The mesh :meth:`Full3D.build` would solve for ``design`` (without FElupe's objects).

    Over a unit library, the model's own mesh (a design with a sideways unit: the full
    width); a library's types share one body and one layer material (the library refuses
    others), so the deck's ``body`` and ``layer`` sets each have one.
    """
    _check_model(model)
    if getattr(model, "mixed", False):
        return model.mesh(design)
    design = parse_orientation(design.orientation if isinstance(design, Design) else design, model.n_units)
    return assemble(model.unit, design, 3, half=model.half)


def calculix_deck(model: Any, design: str | Design, *, full_output: bool = True, residual_force: float = 1.0e-4) -> str:
    """The CalculiX/Abaqus input deck of one design of a 3D model.

    Parameters
    ----------
    model : Full3D
        The 3D model: unit, materials, half or full, pressure ramp (its reported levels
        become the step's increments and output times).
    design : str or Design
        The orientation vector, one digit per unit (``"0101..."``; over a unit library its
        symbols), or the design as parsed (:func:`~pneumorph.geometry.alphabet.parse_design`).
    full_output : bool
        Also write every node's displacement at every level to the ``.frd`` file
        (``*NODE FILE``); the tip nodes always go to the ``.dat`` file (``*NODE PRINT``).
    residual_force : float
        Largest residual nodal force (N) of a converged iteration (see the module's
        notes on solver controls); written as CalculiX's user-defined average force.

    Returns
    -------
    str
        The deck, in mm, Pa and micronewtons (see the module's notes).

    Raises
    ------
    OrientationError
        If ``design`` is not 0/1 digits, one per unit of ``model``.
    SettingsError
        If ``model`` is not a :class:`~pneumorph.models.fe.Full3D` or has gravity, or
        ``residual_force`` is not a positive number.
    MaterialDataError
        If a silicone is not Ogden with at most three terms and a bulk modulus.
    GeometryError
        If an element is not in C3D20 order (never for pneumorph's meshes) or the mesh
        has no cavity faces.

    Examples
    --------
    >>> from pneumorph.models.fe import Full3D, RampSpec
    >>> deck = calculix_deck(Full3D(2, ramp_spec=RampSpec(pressure=0.01)), "01")
    >>> deck.count("\\n*NODE\\n"), "*BOUNDARY" in deck, "NLGEOM" in deck
    (1, True, True)
    """
    mesh = calculix_mesh(model, design)
    if mesh.cell_type not in _ELEMENT_TYPES:  # pragma: no cover - assemble makes hexahedra in 3D
        raise GeometryError(f"no CalculiX element for {mesh.cell_type!r} cells")
    etype = _ELEMENT_TYPES[mesh.cell_type]
    cells = mesh.cells[:, c3d20_permutation()] if etype == "C3D20" else mesh.cells
    check_element_order(mesh.points, cells)
    elements, faces = cavity_faces(cells, mesh.cavity_points)
    if elements.size == 0:
        raise GeometryError("the mesh has no cavity faces to load")
    if not (isinstance(residual_force, (int, float)) and np.isfinite(residual_force) and residual_force > 0):
        raise SettingsError(f"residual_force must be a positive number of newtons, got {residual_force!r}")
    out = _heading(model, mesh)
    out += _mesh_lines(mesh.points, cells, etype)
    out += _set_lines(mesh)
    out += _ogden_line(model.body, "body")
    out += _ogden_line(model.layer, "layer")
    for region, material in model.bottoms.items():  # bottom walls of other materials, where the design has them
        if len(mesh.regions[region]):
            out += _ogden_line(material, _set_name(region))
    out += _step_lines(model, mesh, (elements, faces), full_output, residual_force)
    return "\n".join(out)


def _heading(model: Any, mesh: ActuatorMesh) -> list[str]:
    """The deck's comments (design, fingerprint, units, the volumetric term) and ``*HEADING``."""
    halves = "half model, u_z = 0 on z = width/2" if mesh.symmetry_points is not None else "full model"
    return [
        f"** pneumorph {__version__}: CalculiX/Abaqus deck of the 3D model (Full3D)",
        f"** design {mesh.design or mesh.orientation} ({mesh.n_units} unit{'s' if mesh.n_units > 1 else ''}), {halves}",
        f"** model fingerprint {model.fingerprint()}",
        f"** units: mm, Pa, micronewtons; pressure {model.ramp.pressure * 1e3:g} kPa in "
        f"{len(model.ramp.steps.levels())} levels",
        "** tip = mean (x, y) of x + u over node set TIP (the end face on the mid-plane), as pneumorph's",
        "** volumetric term: CalculiX (J-1)^2/D1, pneumorph 9/2 K (J^(1/3)-1)^2 (Eq 2.12);",
        "** CalculiX's tip moves about 5 % less (see pneumorph.export.calculix)",
        "*HEADING",
        f"pneumorph design {mesh.design or mesh.orientation}",
    ]


def _mesh_lines(points: FloatArray, cells: IntArray, etype: str) -> list[str]:
    """``*NODE`` and ``*ELEMENT`` (set ``EALL``), 1-based, at most 16 entries on a line.

    Parameters
    ----------
    points : ndarray, shape (p, 3)
    cells : ndarray, shape (c, 20) or (c, 8)
        0-based, in C3D20 (C3D8) order.
    etype : {"C3D20", "C3D8"}
    """
    out = ["*NODE"]
    out += [f"{i + 1}, {_num(x)}, {_num(y)}, {_num(z)}" for i, (x, y, z) in enumerate(points)]
    out.append(f"*ELEMENT, TYPE={etype}, ELSET=EALL")
    first = 15 if cells.shape[1] == 20 else cells.shape[1]  # 16 entries on a line at most
    for e, conn in enumerate(cells + 1):
        ids = [str(e + 1), *(str(n) for n in conn)]
        out.append(", ".join(ids[: first + 1]) + ("," if len(ids) > first + 1 else ""))
        if len(ids) > first + 1:
            out.append(", ".join(ids[first + 1:]))
    return out


def _set_lines(mesh: ActuatorMesh) -> list[str]:
    """The element sets ``BODY``, ``LAYER`` and any bottom walls' (``BOTTOM_<MATERIAL>``); the node sets ``BASE``,
    ``SYMMETRY`` (a half model) and ``TIP``."""
    out = []
    bottoms = [r for r in mesh.regions if r.startswith("bottom:") and len(mesh.regions[r])]
    for region in ("body", "layer", *bottoms):
        ids = [str(int(i) + 1) for i in mesh.regions[region]]
        out += [f"*ELSET, ELSET={_set_name(region).upper()}", *_rows(ids, 16)]
    out += _nset("BASE", np.flatnonzero(mesh.base_points))
    if mesh.symmetry_points is not None:
        out += _nset("SYMMETRY", np.flatnonzero(mesh.symmetry_points))
    out += _nset("TIP", mesh.end_points)
    return out


def _step_lines(model: Any, mesh: ActuatorMesh, loaded: tuple[IntArray, IntArray], full_output: bool,
                residual_force: float) -> list[str]:
    """The supports, the ramp and the ``*STEP``: increments, solver controls, cavity pressure, output.

    Parameters
    ----------
    model : Full3D
        Its ramp: the reported levels are the step's time points, the pressure the load.
    mesh : ActuatorMesh
        A half model's symmetry plane is held too.
    loaded : (ndarray, ndarray)
        The loaded elements (0-based) and their C3D20 faces (:func:`cavity_faces`).
    full_output, residual_force
        See :func:`calculix_deck`.
    """
    levels = model.ramp.steps.levels()
    pressure_pa = model.ramp.pressure * PA_PER_MPA
    dt = float(np.min(np.diff(np.concatenate([[0.0], levels]))))
    q_u = residual_force * 1e6 / 0.005  # micronewtons; CalculiX's R_n = 0.005
    out = ["*BOUNDARY", "BASE, 1, 3, 0."]
    if mesh.symmetry_points is not None:
        out.append("SYMMETRY, 3, 3, 0.")
    out += ["*AMPLITUDE, NAME=RAMP", "0., 0., 1., 1."]
    out += ["*TIME POINTS, NAME=LEVELS", *_rows((_num(t) for t in levels), 8)]
    out += [
        "*STEP, NLGEOM, INC=10000",
        "*STATIC",
        f"{_num(dt / 20)}, 1., {_num(dt * 1e-6)}, {_num(dt)}",
        f"** residual criterion 0.005 x {_num(q_u)} = {_num(residual_force * 1e6)} micronewtons (fixed)",
        "*CONTROLS, PARAMETERS=FIELD",
        f"0.005, 0.01, , {_num(q_u)}",
        "** up to 10 cut-backs per increment, the other settings CalculiX's defaults",
        "*CONTROLS, PARAMETERS=TIME INCREMENTATION",
        "4, 8, 9, 16, 10, 4, 12, 10",
        "** follower pressure on the cavity walls: element, face (C3D20 numbering), Pa",
        "*DLOAD, AMPLITUDE=RAMP",
    ]
    out += [f"{e + 1}, P{f}, {_num(pressure_pa)}" for e, f in zip(*loaded, strict=False)]
    out += ["*NODE PRINT, NSET=TIP, TIME POINTS=LEVELS", "U"]
    if full_output:
        out += ["*NODE FILE, TIME POINTS=LEVELS", "U"]
    out += ["*END STEP", ""]
    return out


def write_calculix_deck(model: Any, design: str | Design, path: str | os.PathLike[str], *, full_output: bool = True,
                        residual_force: float = 1.0e-4) -> Path:
    """Write :func:`calculix_deck` to ``path`` atomically (the old file or the complete new one).

    Parameters
    ----------
    model : Full3D
    design : str
    path : str or path-like
        The ``.inp`` file; its folder must exist. CalculiX names its outputs after it
        (``job.inp`` -> ``job.dat``, ``job.frd``).
    full_output, residual_force
        See :func:`calculix_deck`.

    Returns
    -------
    Path

    Raises
    ------
    OutputPathError
        If ``path`` is a folder, read-only, or under a file.
    OrientationError, SettingsError, MaterialDataError, GeometryError
        As :func:`calculix_deck`.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from pneumorph.models.fe import Full3D, RampSpec
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "a.inp"
    >>> write_calculix_deck(Full3D(1, ramp_spec=RampSpec(pressure=0.01)), "1", p).name
    'a.inp'
    """
    target = check_writable_file(Path(path), "deck")
    text = calculix_deck(model, design, full_output=full_output, residual_force=residual_force)
    target.parent.mkdir(parents=True, exist_ok=True)
    return atomic_write_text(target, text)
