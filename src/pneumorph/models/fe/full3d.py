"""The 3D model (chapter 4): quadratic hexahedra, empty cavities, half the width or the full width.

The machinery is :class:`~pneumorph.models.fe.base.FEModel`'s; this model adds the half
model's symmetry (the full model for designs with a sideways unit, whose responses keep
z), the temperature change, the air passages and the base block.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from pneumorph.errors import SettingsError
from pneumorph.fem import StepSettings
from pneumorph.geometry.alphabet import Design
from pneumorph.geometry.features import BaseBlock
from pneumorph.geometry.library import UnitLibrary
from pneumorph.geometry.unit import UnitSpec
from pneumorph.materials.library.material import Material
from pneumorph.models.fe.base import FEModel
from pneumorph.models.fe.ramp import RampSpec


class Full3D(FEModel):
    """The 3D model: quadratic hexahedra, empty cavities, the same ramp (chapter 4).

    Parameters are those of :class:`Reduced2D` without the filler (the ramp: one
    substep per reported level before any cut-back), and

    half : bool
        Model half the width with u_z = 0 on the mid-plane (default): the same solution
        as the full model for an actuator of planar units, with half the unknowns. A design
        with a sideways unit (``layer_side``, the ``spatial`` library) has no such symmetry
        and is always solved on the full width, its response keeping (x, y, z)
        (:meth:`half_for`); ``half=False``: every design on the full width.
    backend : {"fast", "felupe"}
        ``"fast"`` (default): :class:`pneumorph.fem.fast.system.SolidSystem3D` (the
        upper triangle of the symmetric tangent, PARDISO's symmetric indefinite solver in
        single precision) and :class:`pneumorph.fem.fast.newton.FastSubstep` keeping its
        factorised tangent while it converges well; ``"felupe"``: FElupe's assembly and ``newtonraphson``.
        Both stop at the same criterion.
    gravity : str or sequence of float, optional
        As for :class:`Reduced2D`; a half model needs gravity in its plane of symmetry
        (no z component).
    temperature_change : float
        A uniform temperature change (degC, default 0) from the casting temperature: each
        silicone expands freely by ``1 + a dT`` with its linear coefficient ``a`` (Table A.6;
        appendix D.3), in the energy of :class:`~pneumorph.fem.ogden.OgdenCompressible`.
        The clamped base holds the expansion back; the pressure ramp starts from there.
    passage : float
        The diameter (mm) of an air passage through every wall between adjacent cavities
        (appendix D.1; 1.5 mm in the physical actuators, section 6.4.1), meshed as a square
        channel of the same area; 0 (default): closed cavities.
    base_block : BaseBlock, optional
        Mesh the silicone block at the base, held by the clamp's jaws (appendix D.2),
        instead of clamping the base face (default).

    The fingerprint holds the result-determining ramp settings only - the reported
    increments, the pressure and the tolerance - not how the ramp is solved (substeps,
    predictor, cut-backs, iteration limits, backend), which changes the converged states
    only within the tolerance.
    """

    fidelity = "3d"
    dim = 3
    backends = ("fast", "felupe")
    # one substep per level from the quadratic extrapolation of the last three states: 36
    # Newton iterations for a 3-unit design at 45 kPa where two substeps from the linear one
    # took 62 (same results within the tolerance); in free air the cubic one (free_predictor_order)
    predictor_order = 2
    # on the half width without obstacles the cubic extrapolation of the last four states
    # (predictor_order_for): the 15-unit designs 011100110010010, 001111010001001 and 000000000000000
    # took 71, 70, 131 Newton iterations and 15, 13, 51 factorisations where the quadratic one took 72,
    # 77, 163 and 17, 13, 60 (3 cut-backs: 2), and 110101101010001, 111101110010000, 101010101010101,
    # 000111000111000 and 111000000111111 21, 32, 14, 19, 14 factorisations against 23, 34, 16, 22, 14
    # (with RISE); the quartic one cut back on 001111010001001. On the full width it does not pay: the
    # sideways LllAAaaaaLlLllL took 99 iterations, 23 factorisations and 1 cut-back against 97, 19 and
    # none (66.3 s against 49.6 s CPU), aALlaaLLAaalLAa 92 and 24 against 90 and 27, the planar
    # 111000000111111 82 and 14 against 86 and 15. Against a cylinder (001111010001001,
    # "path:22.5:5;4") it took 122 iterations and 64 factorisations against 102 and 52: a tip that
    # slides on an obstacle does not follow a smooth path. The linear one is no better there: 102 and 47
    # on that cylinder, but 139, 71 and a cut-back against 91 and 34 on 111000000111111 grazing its
    # cylinder ("tip;4") with friction 0.5
    free_predictor_order = 3
    default_steps = StepSettings(increments=10, substeps=1, max_iterations=25)
    # a tangent assembled and factorised costs several residuals: keep it while the
    # residual norm at least halves per iteration (chord steps with Anderson acceleration;
    # the kept tangents are factorised in single precision, SolidSystem3D.single_precision).
    # 15-unit benchmark design, double-precision factorisations: 17 factorisations and 69
    # iterations where Newton's method took 37 of each; a threshold of 0.3 took 21 and 60,
    # 0.7 took 15 and 74. Single precision with element matrices in single precision too
    # (one thread): at 0.5 17 factorisations and 76 iterations, 16.5 s, at 0.7 14 and
    # 84, 15.8 s (0.8: 14 and 86, 17.8 s); the all-aligned design 69 and 178, 52.9 s at 0.5,
    # 60 and 174, 47.9 s at 0.7 (0.8: 61, 49.8 s); curls equal to 1e-4 degrees.
    tangent_reuse = 0.7
    anderson_depth = 6
    # the all-aligned 15-unit design curls harder level by level: 3 cut-backs where starting
    # every level at the nominal substep took 4 (and 5 where a failed step clipped at a level
    # was tried again unchanged), 43.9 s against 45.3 s
    carry_step = True

    def __init__(
        self, n_units: int, unit: UnitSpec | None = None, ramp_spec: RampSpec | None = None, half: bool = True,
        backend: str | None = None, gravity: str | Sequence[float] | None = None, temperature_change: float = 0.0,
        passage: float = 0.0, base_block: BaseBlock | None = None, materials: Mapping[str, Material] | None = None,
        library: UnitLibrary | None = None, formulation: str = "auto", obstacles: Sequence[Any] | None = None,
        quadrature: str = "full",
    ) -> None:
        super().__init__(n_units, unit, ramp_spec, None, backend, gravity, temperature_change, passage, base_block,
                         materials, library, formulation, obstacles, quadrature)
        self.half = bool(half)
        if self.half and self.gravity is not None and self.gravity[2] != 0.0:
            raise SettingsError(f"gravity {list(self.gravity)} mm/s^2 has a z component, which breaks the symmetry "
                             "of the half model; use half=False")

    def predictor_order_for(self, design: str | Design) -> int:
        """The cubic predictor (:attr:`free_predictor_order`) for a design on the half width without obstacles,
        else the quadratic one (:attr:`predictor_order`; measured in the class's notes).

        >>> from pneumorph.geometry.library import builtin_library
        >>> model = Full3D(2, library=builtin_library("spatial"))
        >>> model.predictor_order_for("aA"), model.predictor_order_for("aL")
        (3, 2)
        >>> Full3D(2, half=False).predictor_order_for("01")
        2
        """
        return self.free_predictor_order if not self.obstacles and self.half_for(design) else self.predictor_order

    def describe(self) -> dict[str, Any]:
        out = {**super().describe(), "half_model": self.half}
        # the 3D model has no filler: a unit's filler law must not change its fingerprint
        out["unit"] = {k: v for k, v in out["unit"].items() if not k.startswith("filler_")}
        if "library" in out:  # nor the filler laws of a library's units
            out["library"]["units"] = [{**entry, "unit": {k: v for k, v in entry["unit"].items()
                                                          if not k.startswith("filler_")}}
                                       for entry in out["library"]["units"]]
        steps = self.ramp.steps
        out["steps"] = {"increments": steps.increments, "tolerance": steps.tolerance}
        return out

    def options(self) -> dict[str, Any]:
        return {**super().options(), "half": self.half, "temperature_change": self.temperature_change,
                "passage": self.passage}
