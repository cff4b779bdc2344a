"""The 2D reduced-order model (chapter 5): a plane-strain longitudinal section.

Its cavities hold a linear filler whose modulus follows the calibrated law E(P) at every
substep of the ramp (section 5.3, natively - no temperature trick); the filler stands in
for air and has no mass under gravity. The machinery is :class:`~pneumorph.models.fe.base.FEModel`'s.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from pneumorph.errors import SettingsError
from pneumorph.fem import StepSettings
from pneumorph.geometry.assembly import ActuatorMesh
from pneumorph.geometry.features import BaseBlock
from pneumorph.geometry.library import UnitLibrary
from pneumorph.geometry.unit import UnitSpec
from pneumorph.materials import get_filler
from pneumorph.materials.laws.filler import FillerLaw
from pneumorph.materials.library.material import Material
from pneumorph.models.fe.base import FEModel, model_library
from pneumorph.models.fe.ramp import RampSpec


class Reduced2D(FEModel):
    """The 2D plane-strain reduced-order model with a pressure-dependent filler (chapter 5).

    Parameters
    ----------
    n_units : int
        Number of units.
    unit : UnitSpec, optional
        The articulating unit (default: :class:`UnitSpec` defaults).
    ramp_spec : RampSpec, optional
        Pressure ramp (default 45 kPa in 10 reported increments, one substep each before
        any cut-back).
    filler : FillerLaw, optional
        The filler law E(P) (default: the unit's calibrated law, else Eq 5.2). The ramp
        must lie inside its calibrated range, else
        :class:`pneumorph.errors.PressureRangeError` is raised at once.
    backend : {"fast", "felupe"}
        ``"fast"`` (default): the vectorised assembly of
        :class:`pneumorph.fem.fast.system.PlaneStrainSystem` and its Newton method;
        ``"felupe"``: FElupe's assembly and ``newtonraphson``. Both solve the same
        equations to the same tolerance (the fingerprint does not depend on it).
    gravity : str or sequence of float, optional
        Gravity on the silicones, applied in full before the pressure ramp: ``"hanging"``
        (along the actuator, appendix A.2.2), ``"horizontal"`` (-y), or an acceleration
        vector in mm/s^2 (:func:`pneumorph.models.fe.gravity.gravity_vector`). Default none.
        Responses then include the sag under gravity (displacements from the unloaded
        mesh); the filler has no mass.
    obstacles : sequence of mapping, optional
        Rigid obstacles (frictionless, or with Coulomb ``friction``) against the outer surface, as
        ``[[model.obstacle]]`` tables (:mod:`pneumorph.models.fe.obstacles`): each level's forces on
        them and the base reaction go to the response's ``metadata["contact"]``. Default none.
    quadrature : {"full", "reduced", "irons"}
        The quadrature rule of the quadratic cells (:func:`pneumorph.fem.body.quadrature_scheme`):
        ``"full"`` (default; 9 points per quad8, 27 per hex20), ``"reduced"`` (4 and 8 points) or,
        in 3D, ``"irons"`` (14 points). A rule other than the full one is part of the
        fingerprint, so that a chain table fitted at one rule is served with the model at
        that rule.

    A library or unit with a sideways unit (``layer_side``) is refused: it bends out of the
    section's plane (:class:`~pneumorph.models.fe.full3d.Full3D` solves it).

    Examples
    --------
    >>> m = Reduced2D(2, ramp_spec=RampSpec(pressure=0.01))   # 10 kPa in 10 increments
    >>> r = m.evaluate("00")
    >>> r.converged, r.n_levels, bool(r.curl[-1] > 0)
    (True, 10, True)
    """

    fidelity = "2d"
    dim = 2
    backends = ("fast", "felupe")
    # one substep per reported level, started from the quadratic extrapolation of the
    # last three states: 114 Newton iterations for the 15-unit benchmark design at 45 kPa
    # where two substeps from the linear one took 168 (same results within the tolerance)
    predictor_order = 2
    default_steps = StepSettings(increments=10, substeps=1)

    def __init__(
        self,
        n_units: int,
        unit: UnitSpec | None = None,
        ramp_spec: RampSpec | None = None,
        filler: FillerLaw | None = None,
        backend: str | None = None,
        gravity: str | Sequence[float] | None = None,
        base_block: BaseBlock | None = None,
        materials: Mapping[str, Material] | None = None,
        library: UnitLibrary | None = None,
        formulation: str = "auto",
        obstacles: Sequence[Any] | None = None,
        quadrature: str = "full",
    ) -> None:
        lib = model_library(unit, library)
        sideways = [s for s, spec in zip(lib.symbols, lib.units, strict=True) if spec.layer_side]
        if sideways:  # its layer lies outside the plane-strain section
            what = "the unit is" if lib.is_single else f"unit type {', '.join(map(repr, sideways))} is"
            raise SettingsError(f"{what} sideways (layer_side): it bends out of the 2D model's plane; solve it with "
                                "the 3D model (fidelity \"3d\", --model 3d)")
        first = lib[lib.default]
        super().__init__(n_units, unit, ramp_spec, filler or first.filler_law() or get_filler(), backend, gravity,
                         base_block=base_block, materials=materials, library=library, formulation=formulation,
                         obstacles=obstacles, quadrature=quadrature)
        # (a temperature change is a 3D model option: the 2D model's filler has no expansion of its own)
        assert self.filler is not None
        #: the filler law of every unit type: the given one for all, else each unit's calibrated law, else
        #: Eq 5.2 (the extending and short units of the built-in library have no calibrated law)
        self.fillers = {s: filler or spec.filler_law() or get_filler() for s, spec in zip(
            self.library.symbols, self.library.units, strict=True)}
        # PressureRangeError outside the calibrated range, naming the ramp's top pressure
        for law in dict.fromkeys([self.filler, *self.fillers.values()]):
            law.modulus(self.ramp.pressure)

    def options(self) -> dict[str, Any]:
        # the law in use, given or the unit's: a variant of another unit (a mould tolerance) keeps it
        # (a library model's given law; else each type's own)
        given = self.filler if not self.mixed or len(set(self.fillers.values())) == 1 else None
        return {**super().options(), "filler": given}

    def describe(self) -> dict[str, Any]:
        out = super().describe()
        if self.mixed:  # absent for one unit type: earlier fingerprints stay valid
            out["fillers"] = {s: law.to_dict() for s, law in self.fillers.items()}
        return out

    def _extra_regions(self, mesh: ActuatorMesh) -> tuple[list[tuple[str, Any, Any]], Any]:
        import felupe as fem

        cells = mesh.regions["filler"]
        groups: dict[FillerLaw, Any] = {}
        if not self.mixed:  # one region
            assert self.filler is not None
            groups[self.filler] = cells
        else:  # the filler of each unit's cavity follows its type's law
            centres = mesh.points[mesh.cells[cells]].mean(axis=1)[:, 0]
            unit = np.clip(np.searchsorted(mesh.unit_bounds, centres, side="right") - 1, 0, mesh.n_units - 1)
            symbols = np.array(list(self.parse(mesh.design).symbols))[unit]
            for symbol in dict.fromkeys(symbols.tolist()):
                law = self.fillers[symbol]
                groups[law] = np.concatenate([groups.get(law, np.zeros(0, dtype=np.int64)),
                                              cells[symbols == symbol]])
        items: list[tuple[str, Any, Any]] = []
        setters: list[tuple[FillerLaw, Any]] = []
        for i, (law, members) in enumerate(groups.items()):
            umat = fem.NeoHookeCompressible(mu=1.0, lmbda=1.0)
            items.append(("filler" if i == 0 else f"filler_{i + 1}", members, umat))
            setters.append((law, umat))

        def set_pressure(p: float) -> None:
            # linear-elastic filler at large strain: compressible neo-Hooke with the Lame
            # constants of E(P) and nu (small-strain limit = Hooke's law)
            for law, umat in setters:
                nu = law.poisson_ratio
                e = float(law.modulus(p))
                umat.mu = e / (2 * (1 + nu))
                umat.lmbda = e * nu / ((1 + nu) * (1 - 2 * nu))

        set_pressure(0.0)
        return items, set_pressure

