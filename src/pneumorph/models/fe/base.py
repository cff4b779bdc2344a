"""The finite-element actuator models' common machinery on FElupe: :class:`FEModel`.

A model takes a unit (or a unit library), an orientation vector and a pressure ramp (:class:`RampSpec`) and returns
a :class:`~pneumorph.models.response.Response`; a :class:`Solution` keeps the displacement fields besides (the solve
itself: :mod:`pneumorph.models.fe.solving`). Silicones
use the dissertation's compressible Ogden model (Eq 2.12, Tables A.4, A.5) through the hand-coded kernel
:class:`pneumorph.fem.OgdenCompressible`; the base face is clamped and a follower pressure acts on the cavity walls.
Optionally gravity acts on the silicones (their densities): it is applied in full first, then the pressure is ramped
(the hanging test of appendix A.2.2). The fidelities are :class:`~pneumorph.models.fe.reduced2d.Reduced2D` (chapter
5) and :class:`~pneumorph.models.fe.full3d.Full3D` (chapter 4); :mod:`pneumorph.models.fe` is their public import
place.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from dataclasses import asdict
from typing import Any

from pneumorph import checks
from pneumorph.errors import MaterialDataError, SettingsError
from pneumorph.fem import OgdenCompressible, StepSettings
from pneumorph.fem.body import QUADRATURES, PressurisedBody, check_backend, pressurised_body, quadrature_scheme
from pneumorph.fem.fibre import CAST_PAPER
from pneumorph.geometry.alphabet import Design, parse_design
from pneumorph.geometry.assembly import ActuatorMesh, assemble, bottom_materials
from pneumorph.geometry.features import BaseBlock, check_passage
from pneumorph.geometry.library import UnitLibrary
from pneumorph.geometry.unit import UnitSpec
from pneumorph.io.provenance import digest
from pneumorph.materials import get
from pneumorph.materials.laws.filler import FillerLaw
from pneumorph.materials.library.material import Material
from pneumorph.models.fe.gravity import gravity_vector
from pneumorph.models.fe.obstacles import check_obstacles, contact_items
from pneumorph.models.fe.ramp import RampSpec
from pneumorph.models.fe.solving import Solution as Solution
from pneumorph.models.fe.solving import end_face_angle as end_face_angle
from pneumorph.models.fe.solving import solve_design
from pneumorph.models.fe.volumetric import FORMULATIONS, element_volume
from pneumorph.models.response import FloatArray, Response

#: The cells of a model's meshes by dimension and element order (:attr:`UnitSpec.element_order`).
CELL_TYPES = {(2, 1): "quad", (2, 2): "quad8", (3, 1): "hexahedron", (3, 2): "hexahedron20"}

#: Bumped whenever a change to the model changes its results (it is part of the fingerprint).
MODEL_REVISION = 1


def model_library(unit: UnitSpec | None, library: UnitLibrary | None) -> UnitLibrary:
    """The unit library of a model: ``library``, else the one-type library of ``unit`` (default unit).

    Raises
    ------
    SettingsError
        ``library`` is no :class:`UnitLibrary`, or a unit is given too that is not the
        library's first type.

    Examples
    --------
    >>> model_library(None, None).is_single
    True
    >>> model_library(UnitSpec(pitch=9.0), None)["a"].pitch
    9.0
    """
    if library is None:
        if unit is not None and not isinstance(unit, UnitSpec):
            raise SettingsError(f"unit must be a UnitSpec, got {type(unit).__name__}; a unit library goes to library=")
        return UnitLibrary.single(unit or UnitSpec())
    if not isinstance(library, UnitLibrary):
        raise SettingsError(f"library must be a UnitLibrary, got {type(library).__name__}")
    if unit is not None and unit != library[library.default]:
        raise SettingsError("give the model a unit or a unit library, not both (the library's first type is its "
                            "unit)")
    return library


class FEModel:
    """Common machinery of the 2D and 3D models (build once per design, solve the ramp)."""

    fidelity = "fe"
    dim = 2
    half = False
    backends: tuple[str, ...] = ("felupe",)
    #: degree of the predictor's extrapolation through the last converged states
    predictor_order = 1
    #: start a level after a cut-back at the substep that converged last (ramp's ``carry``)
    carry_step = False
    #: fast backend: keep a factorised tangent while the residual falls by this factor
    #: per iteration (None: Newton's method), with Anderson acceleration of this depth
    tangent_reuse: float | None = None
    anderson_depth = 0
    #: the ramp when none is given
    default_steps = StepSettings(increments=10, substeps=2)

    def __init__(
        self, n_units: int, unit: UnitSpec | None = None, ramp_spec: RampSpec | None = None,
        filler: FillerLaw | None = None, backend: str | None = None, gravity: str | Sequence[float] | None = None,
        temperature_change: float = 0.0, passage: float = 0.0, base_block: BaseBlock | None = None,
        materials: Mapping[str, Material] | None = None, library: UnitLibrary | None = None,
        formulation: str = "auto", obstacles: Sequence[Any] | None = None, quadrature: str = "full",
    ) -> None:
        self.backend = check_backend(backend or self.backends[0], self.backends)
        self.obstacles = check_obstacles(obstacles, self.dim)  # rigid, against the outer surface (fast backend)
        if self.obstacles and self.backend != "fast":
            raise SettingsError("contact with obstacles is solved by the fast backend only (the default)")
        self.formulation = checks.text(formulation, "formulation", FORMULATIONS)
        self.quadrature = checks.text(quadrature, "quadrature", QUADRATURES)
        self.n_units = checks.integer(n_units, "n_units", 1, checks.MAX_UNITS, limit="MAX_UNITS")
        self.library = model_library(unit, library)
        self.unit = self.library[self.library.default]
        for order in {spec.element_order for spec in self.library.units}:  # a rule of the model's cells
            quadrature_scheme(CELL_TYPES[self.dim, order], self.quadrature)
        if all(spec.solid for spec in self.library.units):
            raise SettingsError("every unit type is solid (solid = true: no cavity), so there is nothing to "
                                "inflate; a solid unit joins units with a cavity in a library (docs/unit-library.md)")
        self.ramp = ramp_spec or RampSpec(steps=self.default_steps)
        self.filler = filler
        self.materials = dict(materials or {})
        for name, material in self.materials.items():
            if not isinstance(material, Material) or material.kind != "hyperelastic":
                raise SettingsError(f"materials[{name!r}] must be a hyperelastic Material, got {material!r}")
        self.body = self._material(self.unit.body_material)
        # the units of a library share the body material and the layer's (check_joinable)
        layered = [u for u in self.library.units if u.layer > 0] or [self.unit]
        self.layer = self._material(layered[0].layer_material)
        # the bottom walls of other materials (UnitSpec.bottom_material), one region each
        self.bottoms = {f"bottom:{name}": self._material(name) for name in bottom_materials(self.library.units)}
        self.gravity = gravity_vector(gravity, self.dim)
        self.temperature_change = checks.real(temperature_change, "temperature_change", -100.0, 100.0, unit="degC")
        if passage and self.dim != 3:
            raise SettingsError("a passage between cavities is a 3D model option: the 2D section would be cut in two")
        self.passage = float(passage)
        for spec in dict.fromkeys(self.library.units):
            if not spec.solid:  # assemble refuses a passage through a solid unit
                check_passage(spec, self.passage)
        if base_block is not None and not isinstance(base_block, BaseBlock):
            raise SettingsError(f"base_block must be a BaseBlock or None, got {base_block!r}")
        self.base_block = base_block
        self.base = self._material(base_block.material) if base_block is not None else None
        if self.temperature_change != 0.0 and self.backend != "fast":
            # the thermal strain loads the body before any pressure; FElupe's Newton check on that first
            # state does not converge (seen on a 1-unit actuator), the fast path's does
            raise SettingsError("a temperature change needs the fast backend (the 3D model's default)")
        if self.temperature_change != 0.0:
            for material in self.silicones.values():
                if material.thermal_expansion is None:
                    raise MaterialDataError(f"a temperature change needs the thermal expansion of {material.name!r}, "
                                            "which has none (Table A.6 gives it for the built-in silicones); add "
                                            "one to its material entry or leave the temperature unchanged")
        if self.backend != "fast" and any(self.element_volume(m) for m in self.silicones.values()):
            raise SettingsError("the u-p-J form of a nearly incompressible silicone is integrated by the fast "
                                "backend only (the default)")
        if self.gravity is not None:
            for material in self.silicones.values():
                if material.density is None:
                    raise MaterialDataError(f"gravity needs the density of {material.name!r}, which has none; "
                                            "add one to its material entry or run without gravity")

    def _material(self, name: str) -> Material:
        """``name`` from the model's own materials, else from the library."""
        return self.materials.get(name) or get(name)

    def options(self) -> dict[str, Any]:
        """The constructor's arguments that give this model (see :meth:`variant`)."""
        out: dict[str, Any] = {"n_units": self.n_units, "unit": self.unit, "ramp_spec": self.ramp,
                               "backend": self.backend, "gravity": None if self.gravity is None else list(self.gravity),
                               "base_block": self.base_block, "materials": dict(self.materials),
                               "formulation": self.formulation, "obstacles": self.obstacles,
                               "quadrature": self.quadrature}
        if not self.library.is_single:
            out["library"] = self.library
        return out

    @property
    def mixed(self) -> bool:
        """True for a model over a library of several unit types (designs may mix them)."""
        return not self.library.is_single

    def variant(self, **changes: Any) -> FEModel:
        """The same model with some constructor arguments changed (a sensitivity study's variant).

        >>> from pneumorph.models.fe.full3d import Full3D
        >>> Full3D(15).variant(passage=1.5).passage
        1.5
        """
        return type(self)(**{**self.options(), **changes})

    @property
    def silicones(self) -> dict[str, Any]:
        """The material of every silicone region of the mesh: body, layer, bottom walls and base block if any."""
        out = {"body": self.body, "layer": self.layer, **self.bottoms}
        if self.base is not None:
            out["base"] = self.base
        return out

    # -- identity -----------------------------------------------------------------------
    def describe(self) -> dict[str, Any]:
        """Everything that determines the results (hashed into the fingerprint)."""
        out = {
            "fidelity": self.fidelity,
            "revision": MODEL_REVISION,
            "n_units": self.n_units,
            "unit": self.unit.to_dict(),
            "materials": {name: material.to_dict() | ({"paper": CAST_PAPER[material.name].to_dict()}  # its paper too
                                                      if material.name in CAST_PAPER else {})
                          for name, material in {"body": self.body, "layer": self.layer, **self.bottoms}.items()},
            "pressure_mpa": self.ramp.pressure,
            "steps": asdict(self.ramp.steps),
        }
        if self.ramp.volume is not None:  # absent under pressure control: earlier fingerprints stay valid
            out["volume_change"] = self.ramp.volume
        if self.filler is not None:
            out["filler"] = self.filler.to_dict()
        if self.gravity is not None:  # absent without gravity: earlier fingerprints stay valid
            out["gravity_mm_s2"] = list(self.gravity)
        if self.temperature_change != 0.0:  # likewise
            out["temperature_change_c"] = self.temperature_change
        if self.passage:  # likewise
            out["passage_mm"] = self.passage
        if self.base_block is not None:  # likewise
            assert self.base is not None
            out["base_block"] = {**self.base_block.to_dict(), "material_data": self.base.to_dict()}
        if self.mixed:  # likewise: a one-type library is described by its unit alone
            out["library"] = self.library.to_dict()
        if self.formulation != "auto":  # likewise ("auto" follows from the materials, which are described)
            out["formulation"] = self.formulation
        if self.obstacles:  # likewise
            out["obstacles"] = [o.to_dict() for o in self.obstacles]
        if self.quadrature != "full":  # likewise: a chain table's source names the rule it was fitted at
            out["quadrature"] = self.quadrature
        return out

    def with_units(self, n_units: int) -> FEModel:
        """The same model (unit, materials, ramp, solver) for an actuator of ``n_units`` units.

        >>> from pneumorph.models.fe.reduced2d import Reduced2D
        >>> Reduced2D(15).with_units(4).n_units
        4
        """
        other = copy.copy(self)
        other.n_units = checks.integer(n_units, "n_units", 1, checks.MAX_UNITS, limit="MAX_UNITS")
        return other

    def fingerprint(self) -> str:
        return digest(self.describe())

    def pressures(self) -> FloatArray:
        return self.ramp.pressures()

    # -- building -------------------------------------------------------------------------
    def thermal_stretch(self, material: Any) -> float:
        """``1 + a dT``: the free stretch of ``material`` under the model's temperature change."""
        if self.temperature_change == 0.0:
            return 1.0
        return 1.0 + material.thermal_expansion.value * self.temperature_change

    def element_volume(self, material: Any) -> bool:
        """Whether ``material``'s volumetric term is on each element's own dilatation in this model
        (:func:`~pneumorph.models.fe.volumetric.element_volume` with its ``formulation``)."""
        return element_volume(material, self.formulation)

    def _silicone_umat(self, material: Any) -> OgdenCompressible:
        paper = CAST_PAPER.get(material.name)  # a cast composite: its matrix with the paper along x (no thermal
        if paper is not None:  # expansion in its entry: a temperature change is refused with its material's name)
            return paper.law(material.model.mu, material.model.alpha, material.bulk_modulus.value,
                             mixed=self.element_volume(material))
        return OgdenCompressible(material.model.mu, material.model.alpha, material.bulk_modulus.value,
                                 self.thermal_stretch(material), mixed=self.element_volume(material))

    def _extra_regions(self, mesh: ActuatorMesh) -> tuple[list[tuple[str, Any, Any]], Any]:
        """Further material regions (the 2D filler) and a callback ``set_pressure(p)`` for them."""
        return [], lambda p: None

    def parse(self, design: str | Design) -> Design:
        """A design of this model's length over its library (0/1 text or the library's symbols).

        Raises
        ------
        OrientationError
            The wrong length, or a character that is no symbol of the library.

        >>> from pneumorph.geometry.library import builtin_library
        >>> from pneumorph.models.fe.reduced2d import Reduced2D
        >>> Reduced2D(3, library=builtin_library()).parse("aEr").text
        'aEr'
        """
        return parse_design(design, self.library, self.n_units)

    def mesh(self, orientation: str | Design) -> ActuatorMesh:
        """The meshed design (no solver data): what :meth:`build` solves on.

        A design with a sideways unit is meshed whole (:meth:`half_for`).

        >>> from pneumorph.models.fe.full3d import Full3D
        >>> Full3D(2).mesh("01").cells.shape[1]
        20
        """
        if self.mixed:
            design = self.parse(orientation)
            return assemble(self.library, design, self.dim, half=self.half_for(design), passage=self.passage,
                            base=self.base_block)
        # one unit type: its meshes to the last bit
        return assemble(self.unit, orientation if isinstance(orientation, str) else orientation.orientation,
                        self.dim, half=self.half and not self.unit.layer_side, passage=self.passage,
                        base=self.base_block)

    def half_for(self, design: str | Design) -> bool:
        """Whether ``design`` is solved on the half width: a half model's design without a sideways unit.

        A sideways unit (``layer_side``) bends across the width: no mid-plane symmetry.

        >>> from pneumorph.geometry.library import builtin_library
        >>> from pneumorph.models.fe.full3d import Full3D
        >>> model = Full3D(2, library=builtin_library("spatial"))
        >>> model.half_for("aA"), model.half_for("aL")
        (True, False)
        """
        return self.half and not any(u.layer_side for u in self.parse(design).units(self.library))

    def predictor_order_for(self, design: str | Design) -> int:
        """The degree of the ramp's predictor for ``design`` (:attr:`predictor_order`)."""
        return self.predictor_order

    def build(self, orientation: str | Design) -> tuple[ActuatorMesh, PressurisedBody, Any]:
        """The meshed design, its pressurised body and ``set_pressure(p)`` for a load level.

        ``set_pressure`` sets the cavity pressure and everything that follows it (the 2D
        filler's modulus). ``orientation`` is a design over the model's library.
        """
        mesh = self.mesh(orientation)
        # a design of extending units has no layer cells: the empty region is left out
        silicones = {name: material for name, material in self.silicones.items() if len(mesh.regions[name])}
        if self.dim == 2 and (paper := sorted(set(CAST_PAPER) & {m.name for m in silicones.values()})):
            raise SettingsError(f"{', '.join(paper)}: the paper along the unit's axis is a 3D law; use the 3D model")
        regions = [(name, mesh.regions[name], self._silicone_umat(material)) for name, material in silicones.items()]
        extra, set_extra = self._extra_regions(mesh)
        densities = None
        if self.gravity is not None:  # dead loads rho g on the silicones, switched on by the gravity stage
            densities = {name: material.density.value for name, material in silicones.items()}
        body = pressurised_body(mesh.points, mesh.cells, mesh.cell_type, [*regions, *extra], mesh.cavity_points,
                                mesh.base_points, mesh.symmetry_points, walls_of=list(silicones),
                                densities=densities, quadrature=self.quadrature)
        body.contacts = contact_items(self.obstacles, mesh, self.body.shear_modulus)

        def set_pressure(p: float) -> None:
            body.pressure.update(p)
            set_extra(p)

        return mesh, body, set_pressure

    def empty_response(self, mesh: ActuatorMesh, design: str) -> Response:
        """The response of ``design`` on its ``mesh``: its undeformed centres and tip, every level still unknown."""
        x_end0 = mesh.points[mesh.end_points][:, : mesh.axes]
        return Response.empty(design, self.pressures(), mesh.unit_centres(axes=mesh.axes), x_end0.mean(axis=0),
                              metadata={"fidelity": self.fidelity, "fingerprint": self.fingerprint()})

    # -- solving --------------------------------------------------------------------------
    def evaluate(self, orientation: str | Design, on_level: Any = None) -> Response:
        """Solve the pressure ramp of one design and return its :class:`Response`.

        See :meth:`solve` for the parameters and errors.
        """
        return self.solve(orientation, on_level).response

    def solve(self, orientation: str | Design, on_level: Any = None) -> Solution:
        """Solve the pressure ramp of one design, keeping the displacement fields.

        :func:`~pneumorph.models.fe.solving.solve_design` on this model: see there for the
        parameters and errors (:class:`~pneumorph.errors.SimulationFailed` when the ramp cannot
        be completed).
        """
        return solve_design(self, orientation, on_level)
