"""3D finite-element model of the bimodal actuator and its pressure ramp (section 3.3.3).

Quadratic hexahedra (``hexahedron20``) on the layered grid of
:func:`pneumorph.bimodal.geometry.mesh_actuator`, half the width with u_z = 0 on the
mid-plane, one displacement field shared by one :class:`felupe.SolidBody` per layer, each
with the compressible Ogden model of Eq 2.12 (:class:`pneumorph.fem.OgdenCompressible`):
Mold Star 15 body and seal, Smooth-Sil 950 strip (Table A.4). The bilinear composite is, by
default, the Ecoflex 0030 matrix with the crimped paper in it individually, as fibres along
the actuator that are slack until the crimp has straightened and then carry the paper's
stiffness (:func:`pneumorph.bimodal.paper.paper_composite`, section 8.2's remedy); or,
as the dissertation does (section 3.2.7), a homogeneous material with the Table B.1 Ogden
parameters of its crimp ratio (``composite="homogenised"``). A follower pressure acts on
every void wall; the base face is clamped. The ramp rises in equal steps (5 kPa: the
increments of the physical test, section 3.3.2) of the pressure, or of the voids' volume,
and is solved by :func:`pneumorph.fem.ramp` (cut-back, predictor, cavity-volume monitor);
a ramp that stops converging ends the response there, as the physical test ended at rupture.

The tip is the mid-point of the end face's chord on the mid-plane (between its bottom and
top corners); its displacement is ``(u_x, u_y)``, u_y > 0 towards the Smooth-Sil strip (the
first bending mode, composite on the outside).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pneumorph import __version__, checks
from pneumorph.bimodal.geometry import (
    BILINEAR,
    BODY,
    LABELS,
    SEAL,
    STRIP,
    BimodalMesh,
    BimodalSpec,
    mesh_actuator,
)
from pneumorph.bimodal.paper import PAPER_MODELS, measured_composite, paper_composite
from pneumorph.bimodal.switch import Switch, find_switch
from pneumorph.errors import MaterialDataError, SettingsError, SimulationFailed, UnknownMaterialError
from pneumorph.fem import OgdenCompressible, StepSettings, ramp
from pneumorph.fem.body import PressurisedBody, check_backend, pressurised_body
from pneumorph.fem.fast.mixed import nearly_incompressible
from pneumorph.fem.fast.volume import volume_control
from pneumorph.materials import get
from pneumorph.materials.laws.hyperelastic import Ogden
from pneumorph.models.fe import Full3D
from pneumorph.models.fe.gravity import gravity_vector
from pneumorph.models.fe.ramp import check_volume_steps
from pneumorph.models.fe.stages import gravity_steps

FloatArray = np.ndarray

#: Table B.1 crimp ratios and their library entries.
CRIMP_MATERIALS = {0.2: "bilinear_0_2", 0.25: "bilinear_0_25", 0.3: "bilinear_0_3"}
#: the composite's models: the Ecoflex matrix with the crimped paper as fibres along the actuator, or
#: the Table B.1 homogeneous Ogden material
COMPOSITES = ("fibre", "homogenised")
#: the fibre composite's matrix and paper (library names)
MATRIX, PAPER = "ecoflex_0030", "paper_purco_80gsm"


def bulk_from_poisson(shear_modulus: float, nu: float) -> float:
    """Small-strain bulk modulus ``K = 2 mu (1 + nu) / (3 (1 - 2 nu))`` (same unit as mu).

    Raises
    ------
    SettingsError
        A Poisson's ratio outside (-1, 0.5).

    Examples
    --------
    >>> round(bulk_from_poisson(1.0, 0.495), 4)
    99.6667
    """
    if not -1.0 < nu < 0.5:
        raise SettingsError(f"Poisson's ratio must lie in (-1, 0.5), got {nu}")
    return 2.0 * shear_modulus * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu))


def bilinear_material(crimp_ratio: float) -> str:
    """Library name of the Table B.1 composite of a crimp ratio.

    Raises
    ------
    UnknownMaterialError
        For a crimp ratio other than 0.2, 0.25 and 0.3 (Table B.1 has no others).

    Examples
    --------
    >>> bilinear_material(0.25)
    'bilinear_0_25'
    """
    for cr, name in CRIMP_MATERIALS.items():
        if abs(float(crimp_ratio) - cr) < 1e-9:
            return name
    raise UnknownMaterialError(f"bilinear composite of crimp ratio {crimp_ratio:g} (Table B.1)",
                               [f"crimp ratio {c:g}" for c in CRIMP_MATERIALS])


@dataclass(frozen=True)
class BimodalResult:
    """Tip response of one pressure ramp.

    Attributes
    ----------
    crimp_ratio : float or None
    pressures : ndarray
        Converged reported pressures (MPa), from the first step on.
    tip : ndarray, shape (k, 2)
        Tip displacement (u_x, u_y) in mm at those pressures.
    outline : ndarray, shape (k + 1, m, 2)
        Current (x, y) of the mid-plane outline (bottom edge, end face, top edge reversed)
        at zero pressure and at every converged pressure, for shape figures.
    pmax : float
        The ramp's top pressure (MPa).
    completed : bool
        True if the whole ramp converged.
    cause : str
        Why the ramp ended early ("" if it completed).
    switch : Switch
        Where the tip turns back and where it crosses to the other side.
    station : ndarray, shape (k, 2)
        Displacement of the mid-point of the section one void short of the tip
        (:attr:`BimodalMesh.station`), which the bulging free end wall does not move.
    station_switch : Switch
        The same for the station's transverse displacement.
    metadata : dict
        Model description, degrees of freedom, Newton iterations, cut-backs, wall time.
    """

    crimp_ratio: float | None
    pressures: FloatArray
    tip: FloatArray
    outline: FloatArray
    pmax: float
    completed: bool
    cause: str
    switch: Switch
    metadata: dict[str, Any] = field(default_factory=dict)
    station: FloatArray = field(default_factory=lambda: np.zeros((0, 2)))
    station_switch: Switch = field(default_factory=lambda: Switch(0, None, None, None))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (pressures in kPa, lengths in mm)."""
        return {
            "crimp_ratio": self.crimp_ratio,
            "pmax_kpa": 1e3 * self.pmax,
            "completed": self.completed,
            "cause": self.cause,
            "pressures_kpa": np.round(1e3 * self.pressures, 6).tolist(),
            "tip_ux_mm": np.round(self.tip[:, 0], 4).tolist(),
            "tip_uy_mm": np.round(self.tip[:, 1], 4).tolist(),
            "switch": self.switch.to_dict(),
            "station_ux_mm": np.round(self.station[:, 0], 4).tolist(),
            "station_uy_mm": np.round(self.station[:, 1], 4).tolist(),
            "station_switch": self.station_switch.to_dict(),
            "metadata": self.metadata,
        }


class BimodalModel:
    """The bimodal actuator's 3D FE model.

    Parameters
    ----------
    spec : BimodalSpec, optional
        Geometry and element size (default: the dissertation's actuator, 1.5 mm elements).
    crimp_ratio : float
        0.2, 0.25 or 0.3: selects the Table B.1 composite.
    pmax : float
        Top pressure of the ramp (MPa).
    step : float
        Pressure step (MPa); 0.005 = the 5 kPa of the physical test.
    materials : dict, optional
        Override library names per layer (``"bilinear"``, ``"seal"``, ``"body"``, ``"strip"``).
    bilinear_bulk : float, optional
        Bulk modulus of the composite (MPa; with ``composite="fibre"`` its matrix's) instead of
        the library's assumed value.
    substeps, max_cutbacks, max_iterations : int
        Newton solves per step, halvings allowed and Newton iterations per trial (see
        :class:`pneumorph.fem.StepSettings`; default 1, :attr:`default_max_cutbacks` and
        :attr:`default_max_iterations`). Near the pressure at which a wall balloons (a
        limit point) every trial that fails costs up to ``max_iterations`` iterations.
    half : bool
        Half model across the width (u_z = 0 on the mid-plane), the default.
    backend : {"fast", "felupe"}
        ``"fast"`` (default): the fast 3D system and its Newton method keeping factorised
        tangents, as :class:`pneumorph.models.fe.Full3D`; ``"felupe"``: FElupe's assembly
        and ``newtonraphson`` (the reference path). Both stop at the same criterion.
    volume : float, optional
        Volume control (fast backend): the voids' relative volume change ``V / V0 - 1`` at the
        ramp's end, reached in ``pmax / step`` equal volume steps; the pressure of every step
        is an output, so the ramp follows a wall that balloons past the pressure's maximum
        (:class:`~pneumorph.fem.fast.volume.VolumeControl`). None: the pressure is ramped.
    composite : {"fibre", "homogenised"}
        ``"fibre"`` (default): the Ecoflex 0030 matrix (or ``materials["bilinear"]``) with the
        crimped paper along the actuator (:func:`~pneumorph.bimodal.paper.paper_composite`);
        ``"homogenised"``: the Table B.1 Ogden material of the crimp ratio, isotropic (the
        dissertation's model). Without a crimp ratio the layer is ``materials["bilinear"]`` alone.
    paper : {"measured", "ideal"}
        With ``composite="fibre"``: the paper of the cast coupons (default; Table 3.2's primary
        modulus, transition strain and secondary modulus,
        :func:`~pneumorph.bimodal.paper.measured_composite`) or the ideal crimp (slack until the
        analytic straightening stretch, then the library paper's stiffness).
    transition : float, optional
        With ``paper="ideal"``: the paper's straightening strain instead of the crimp's analytic one.
    gravity : str or sequence of float, optional
        The layers' weight (:func:`~pneumorph.models.fe.gravity.gravity_vector`): ``"hanging"``
        hangs the actuator from its base as the bench did (section 3.3.2), loaded before the
        ramp; none by default.

    Examples
    --------
    >>> m = BimodalModel(BimodalSpec(voids=1, element_size=5.0), pmax=0.005)
    >>> r = m.solve()
    >>> r.completed, r.pressures.tolist(), bool(r.tip[0, 1] > 0)
    (True, [0.005], True)
    """

    #: the 3D actuator model's tuned Newton method (kept tangents with Anderson
    #: acceleration) on the same hexahedra, but the linear predictor: where the tip swings
    #: (CR 0.3: +37.8 to +63.2 mm from 20 to 25 kPa) the quadratic one overshoots, and the
    #: ramp ended at 25 kPa instead of 35
    predictor_order = 1
    tangent_reuse = Full3D.tangent_reuse
    #: with the ideal paper as fibres (about 3,000 times stiffer than the Ecoflex once straight) a kept tangent
    #: contracts the residual by about 0.6 per iteration, under the 0.7 that keeps it: the volume-controlled
    #: 3-void actuator (CR 0.2) crawled to a 1.7e-8 residual in 25 iterations and the ramp ended at 21 kPa;
    #: refreshed below 0.3 it reached 9 V0 (85 factorisations, 31 s). The cast paper (``paper="measured"``), 4-5 times
    #: softer once straight, keeps the silicones' :attr:`tangent_reuse`: the full-size CR 0.25 with a 1.5 mm end cap
    #: took 69 s of CPU with it, 79 s with 0.5 and 105 s with 0.3, the same tip to 1e-4 mm
    fibre_tangent_reuse = 0.3
    anderson_depth = Full3D.anderson_depth
    #: halvings of a step before the ramp ends there: the ramp ends where a wall balloons,
    #: and each further halving only creeps towards that limit point
    default_max_cutbacks = 2
    #: iterations per trial, as :class:`~pneumorph.models.fe.Full3D`'s: with 10, a 5 kPa step
    #: of the full-size actuator (CR 0.2) often needs a cut-back, and the ramp took 78 s
    #: where it takes 41 s with 25 (the same pressures and tip displacements)
    default_max_iterations = 25

    def __init__(
        self,
        spec: BimodalSpec | None = None,
        crimp_ratio: float | None = 0.3,
        pmax: float = 0.1,
        step: float = 0.005,
        materials: dict[str, str] | None = None,
        bilinear_bulk: float | None = None,
        substeps: int = 1,
        max_cutbacks: int | None = None,
        max_iterations: int | None = None,
        half: bool = True,
        backend: str = "fast",
        volume: float | None = None,
        composite: str = "fibre",
        transition: float | None = None,
        paper: str = "measured",
        gravity: str | Sequence[float] | None = None,
    ) -> None:
        pmax = checks.real(pmax, "pmax", 0.0, checks.MAX_PRESSURE_KPA / 1e3, low_open=True, unit="MPa",
                           limit="MAX_PRESSURE_KPA")
        step = checks.real(step, "step", 0.0, pmax, low_open=True, unit="MPa")
        increments = round(pmax / step)
        if abs(pmax / step - increments) > 1e-6 or increments > checks.MAX_INCREMENTS:
            raise SettingsError(
                f"the step {step * 1e3:g} kPa must divide pmax {pmax * 1e3:g} kPa into at most "
                f"{checks.MAX_INCREMENTS} equal steps "
                f"(e.g. step {pmax / max(1, min(round(pmax / step), 1000)) * 1e3:.4g} "
                "kPa); the ramp must end at pmax, not above it")
        if volume is not None:  # the one rule of a volume step, before any mesh is made
            check_volume_steps(volume, increments, ("volume", "pmax / step"), advice=lambda least: (
                f"use a smaller step (at least {least} steps, e.g. step {pmax / least * 1e3:.4g} kPa)"))
        max_cutbacks = self.default_max_cutbacks if max_cutbacks is None else max_cutbacks
        max_iterations = self.default_max_iterations if max_iterations is None else max_iterations
        for name, value, low in (("substeps", substeps, 1), ("max_cutbacks", max_cutbacks, 0),
                                 ("max_iterations", max_iterations, 1)):
            checks.integer(value, name, low, 1000)
        if composite not in COMPOSITES:
            raise SettingsError(f"composite must be one of {', '.join(COMPOSITES)}, got {composite!r}")
        if paper not in PAPER_MODELS or (transition is not None and paper != "ideal"):
            raise SettingsError(f"paper must be one of {', '.join(PAPER_MODELS)} (a transition strain only with "
                                f"the ideal paper), got {paper!r} and transition {transition!r}")
        self.paper = paper
        # without a crimp ratio there is no paper: the layer is the named material alone
        self.composite = composite if crimp_ratio is not None else "homogenised"
        self.transition = None if transition is None else checks.real(transition, "transition", 0.0, 10.0,
                                                                      low_open=True)
        self.spec = spec or BimodalSpec()
        self.crimp_ratio = crimp_ratio
        names = {"bilinear": None, "seal": "mold_star_15", "body": "mold_star_15", "strip": "smooth_sil_950"}
        if crimp_ratio is not None:  # Table B.1 knows the crimp ratio, also for the fibre law's matrix
            names["bilinear"] = bilinear_material(crimp_ratio)
            if self.composite == "fibre":
                names["bilinear"] = MATRIX
        unknown = set(materials or {}) - set(names)
        if unknown:
            raise ValueError(f"unknown layer(s) {sorted(unknown)}; layers: {sorted(names)}")
        names.update(materials or {})
        if names["bilinear"] is None:
            raise ValueError("give a crimp ratio or a bilinear material")
        self.names = names
        self.materials = {k: get(v) for k, v in names.items() if v is not None}
        self.bilinear_bulk = bilinear_bulk
        self.increments = increments
        self.step = float(step)
        self.pmax = float(pmax)
        self.substeps = int(substeps)
        self.max_cutbacks = int(max_cutbacks)
        self.max_iterations = int(max_iterations)
        self.half = bool(half)
        self.backend = check_backend(backend)
        self.volume = None if volume is None else checks.real(volume, "volume", 0.0, 100.0, low_open=True)
        self.gravity = gravity_vector(gravity, 3)
        if self.gravity is not None and (light := sorted(m.name for m in self.materials.values() if m.density is None)):
            raise MaterialDataError(f"gravity needs the density of {', '.join(light)}, which has none")

    def bulk(self, layer: str) -> float:
        """Bulk modulus (MPa) used for a layer."""
        if layer == "bilinear" and self.bilinear_bulk is not None:
            return float(self.bilinear_bulk)
        bulk = self.materials[layer].bulk_modulus
        assert bulk is not None, f"{layer}: a silicone without a bulk modulus"
        return float(bulk.value)

    def describe(self) -> dict[str, Any]:
        return {
            "spec": self.spec.to_dict(),
            "crimp_ratio": self.crimp_ratio,
            "materials": dict(self.names),
            "bulk_moduli_kpa": {k: 1e3 * self.bulk(k) for k in self.names},
            "pmax_kpa": 1e3 * self.pmax,
            "step_kpa": 1e3 * self.step,
            "substeps": self.substeps,
            "max_cutbacks": self.max_cutbacks,
            "max_iterations": self.max_iterations,
            "half_model": self.half,
            "element": "hexahedron20",
            "composite": self.composite if self.composite == "homogenised" else
            f"fibre: {self.names['bilinear']} with {PAPER} along x",
            "paper": self.paper if self.composite == "fibre" else None,
            "paper_transition": self.transition,
            "control": "pressure" if self.volume is None else f"volume (V/V0 - 1 = {self.volume:g} at the end)",
        } | ({} if self.gravity is None else {"gravity_mm_s2": list(self.gravity)})

    def build(self) -> tuple[BimodalMesh, PressurisedBody]:
        """The layered mesh and its pressurised body (one Ogden solid per layer, void walls)."""
        mesh = mesh_actuator(self.spec, half=self.half)
        regions = []
        for code in (BILINEAR, SEAL, BODY, STRIP):
            name = LABELS[code]
            m = self.materials[name].model
            assert isinstance(m, Ogden), f"{name}: the bimodal model takes Ogden silicones"
            # a nearly incompressible layer (the composite at nu = 0.495) on the u-p-J form, by the models' rule
            mixed = nearly_incompressible(self.bulk(name), self.materials[name].shear_modulus)
            umat = OgdenCompressible(m.mu, m.alpha, self.bulk(name), mixed=mixed)
            if code == BILINEAR and self.composite == "fibre" and self.paper == "measured":  # Table 3.2's paper
                umat = measured_composite(float(self.crimp_ratio or 0.0), matrix=str(self.names[name]),
                                          bulk=self.bulk(name), mixed=mixed)
            elif code == BILINEAR and self.composite == "fibre":  # the ideal crimp, the layer's thickness
                umat = paper_composite(float(self.crimp_ratio or 0.0), thickness=self.spec.bilinear,
                                       matrix=str(self.names[name]), paper=PAPER, bulk=self.bulk(name), mixed=mixed,
                                       transition=self.transition)
            regions.append((name, mesh.label == code, umat))
        densities = None if self.gravity is None else {  # every layer has one (checked at construction)
            name: float(m.density.value) for name, m in self.materials.items() if m.density is not None}
        body = pressurised_body(mesh.points, mesh.cells, mesh.cell_type, regions, mesh.void_points, mesh.base_points,
                                mesh.symmetry_points, densities=densities)
        return mesh, body

    def solve(self, on_level: Any = None) -> BimodalResult:
        """Ramp the pressure; stop at the top pressure or where the solve stops converging.

        Parameters
        ----------
        on_level : callable, optional
            ``on_level(k, pressure_mpa, tip_uy_mm)`` after each converged step (progress).
        """
        t0 = time.perf_counter()
        mesh, body = self.build()
        outline_ids = _outline(mesh)
        x0 = mesh.points[outline_ids][:, :2]
        pressures: list[float] = []
        tips: list[FloatArray] = []
        stations: list[FloatArray] = []
        outlines = [x0]
        settings = StepSettings(increments=self.increments, substeps=self.substeps, max_cutbacks=self.max_cutbacks,
                                max_iterations=self.max_iterations)

        def apply(t: float) -> None:
            body.pressure.update(t * self.pmax)

        ideal = self.composite == "fibre" and self.paper == "ideal"
        reuse = self.fibre_tangent_reuse if ideal else self.tangent_reuse
        substep, monitor = body.stepper(self.backend, reuse, self.anderson_depth)
        if self.gravity is not None:  # the weight first, held through the ramp (the tips include its sag)
            g = np.asarray(self.gravity)
            ramp(body.items, body.field, lambda t: body.set_gravity(t * g), body.dof1, body.dof0,
                 gravity_steps(settings), substep=substep, predictor_order=self.predictor_order)
        control = volume_control(self.volume, substep, apply, body.displacement)
        if control is not None:  # the voids' volume drives, the pressure is an output
            apply, substep = control.apply, control

        def record(k: int, t: float) -> None:
            u = body.displacement
            pressures.append((t if control is None else control.factor) * self.pmax)
            tips.append(u[mesh.tip, :2].mean(axis=0))
            stations.append(u[mesh.station, :2].mean(axis=0))
            outlines.append(x0 + u[outline_ids, :2])
            if on_level is not None:
                on_level(k, pressures[-1], float(tips[-1][1]))

        cause, stats = "", None
        try:
            stats = ramp(body.items, body.field, apply, body.dof1, body.dof0, settings, on_level=record,
                         monitor=monitor if control is None else None, substep=substep,
                         predictor_order=self.predictor_order)
        except SimulationFailed as exc:
            cause = f"stopped after {1e3 * (pressures[-1] if pressures else 0.0):g} kPa: {exc.cause}"
        p = np.asarray(pressures, dtype=float)
        tip = np.asarray(tips, dtype=float).reshape(-1, 2)
        station = np.asarray(stations, dtype=float).reshape(-1, 2)
        meta = {
            "model": self.describe(),
            "dofs": int(body.displacement.size),
            "cells": len(mesh.cells),
            "wall_time_s": round(time.perf_counter() - t0, 2),
            "backend": self.backend,
            "pneumorph": __version__,
        }
        if control is not None:
            meta.update(volume0_mm3=control.volume0, volumes_mm3=(control.volume0 * (
                1.0 + self.volume * settings.levels()[: len(pressures)])).tolist(),  # type: ignore[operator]
                pressure_max_kpa=1e3 * float(p.max(initial=0.0)))
        if stats is not None:
            meta.update(newton_iterations=stats.newton_iterations, substeps=stats.substeps, cutbacks=stats.cutbacks,
                        factorisations=getattr(substep, "factorisations", stats.newton_iterations))
        return BimodalResult(
            crimp_ratio=self.crimp_ratio, pressures=p, tip=tip, outline=np.asarray(outlines), pmax=self.pmax,
            completed=not cause, cause=cause, switch=find_switch(p, tip[:, 1]), metadata=meta,
            station=station, station_switch=find_switch(p, station[:, 1]),
        )


def _outline(mesh: BimodalMesh) -> np.ndarray:
    """Mid-plane outline points: bottom edge (base to tip), end face (up), top edge (back)."""
    pts, s = mesh.points, mesh.spec
    mid = np.isclose(pts[:, 2], s.width / 2)
    bottom = np.flatnonzero(mid & np.isclose(pts[:, 1], 0.0))
    top = np.flatnonzero(mid & np.isclose(pts[:, 1], s.height))
    bottom = bottom[np.argsort(pts[bottom, 0])]
    top = top[np.argsort(-pts[top, 0])]
    end = mesh.section_points[1:-1]
    return np.concatenate([bottom, end, top])


__all__ = ["COMPOSITES", "CRIMP_MATERIALS", "MATRIX", "PAPER", "BimodalModel", "BimodalResult", "bilinear_material",
           "bulk_from_poisson"]
