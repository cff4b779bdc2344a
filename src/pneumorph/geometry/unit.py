"""The articulating unit (section 4.2): dimensions, materials and mesh size.

The unit's longitudinal section in its own frame (orientation 0), x along the actuator,
y across its height, the soft face at y = 0 and the stiff layer on top::

    y = height  +--------------------------------------------+
                |  stiff layer (layer_material), `layer` thick |
                +--------------------------------------------+
                | wall  (body material)                       |
                |   +---------------------------+  +---+      |
                |   |          cavity           |  |   |      |
                |   +---------------------------+  |   |      |
                | bottom wall (`wall`)             |slit|     |
    y = 0       +--------------------------------  +---+  ---+
                x = 0   end_wall             cavity   end_wall  slit   x = pitch

Along x a unit is ``end_wall | cavity | end_wall | slit``: adjacent units share nothing but
material, so two cavities are ``2 end_wall`` (+ the slit) apart. The optional slit is a gap
of ``slit_width`` cut from the soft face to ``slit_depth`` at the end of the unit, so the
inflating end walls can push each other apart (as in Pneu-nets) instead of only bulging the
soft wall. In 3D the cavity stops ``side_wall`` short of both sides; the slit goes through
the whole width. Orientation 1 is the unit turned 180 degrees about the long axis: its
section is mirrored, y -> height - y (and z -> width - z).

A *sideways* unit (``layer_side = True``) has its stiff layer on the side face z = width
instead of the top (orientation 1: on the face z = 0), ``layer`` thick, with a ``side_wall``
between it and the cavity; its height is then ``2 wall + cavity_height``. Seen from above
(x along the actuator, z across its width)::

    z = width   +--------------------------------------------+
                |  stiff layer, `layer` thick                 |
                +--------------------------------------------+
                | side wall                                   |
                |   +---------------------------+             |
                |   |          cavity           |             |
                |   +---------------------------+             |
    z = 0       +--------------------------------------------+

It bends about the actuator's vertical (y) axis, out of the plane the other units bend in.

Unit types
----------
The same parameters describe the deformation modes of a library of units (section 8.4,
``docs/unit-library.md``):

- *bending* (the default): the stiff layer on one side bends the unit towards it;
- *extending*: no stiff layer (``layer = 0``) and equal walls on both sides of the cavity,
  so the section is symmetric and the unit lengthens instead of bending;
- *near-rigid*: ``solid = True``, the cavity filled with the body material: no pressure
  acts in it, its box is still meshed and tracked (for the unit's centre);
- *short-pitch* (section 8.3.1): a shorter ``pitch`` with thinner end walls, so more units
  fit in the same length;
- *sideways*: ``layer_side = True``, the stiff layer on a side face, so the unit
  bends out of the plane of the others (3D models only);
- *low-bending*: a stiff ``bottom_material`` under the cavity as well as the layer above
  it: the unit lengthens a little and bends about a tenth as much;
- *bimodal* (section 8.4 mode 5): no layer, the bottom wall of the bilinear composite
  (``bottom_material``): the unit bends one way, then back as the composite stiffens.

Examples
--------
>>> u = UnitSpec()
>>> u.height, u.cavity_length
(12.0, 4.5)
>>> extending = UnitSpec(wall=3.0, layer=0.0)
>>> extending.height, extending.cavity
(12.0, (3.0, 7.5, 3.0, 9.0))
>>> sideways = UnitSpec(cavity_height=9.0, layer_side=True)
>>> sideways.height, sideways.cavity_z
(12.0, (1.5, 10.5))
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path
from typing import Any

from pneumorph.checks import MIN_ELEMENT_FRACTION
from pneumorph.errors import GeometryError
from pneumorph.geometry.limits import (
    MAX_NAME_CHARS,
    UNIT_LENGTHS,
    MeshLimitError,
    check_lengths,
    check_manufacturable,
)
from pneumorph.materials.laws.filler import FillerLaw


def _numbers(values: object, key: str, count: int | None = None) -> tuple[float, ...]:
    """A list field of numbers, refused as one line naming the field (text, booleans, a wrong count).

    >>> _numbers([1, 2.5], "filler_coefficients")
    (1.0, 2.5)
    >>> _numbers("x", "filler_range_kpa", 2)
    Traceback (most recent call last):
    ...
    pneumorph.errors.GeometryError: unit filler_range_kpa must be a list of 2 numbers, got 'x'
    """
    what = f"a list of {count} numbers" if count is not None else "a list of numbers"
    if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
        raise GeometryError(f"unit {key} must be {what}, got {values!r}")
    items = list(values)
    if (count is not None and len(items) != count) or any(
            isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) for v in items):
        raise GeometryError(f"unit {key} must be {what}, got {values!r}")
    return tuple(float(v) for v in items)


@dataclass(frozen=True)
class UnitSpec:
    """Dimensions (mm), materials and element size of one articulating unit.

    Parameters
    ----------
    pitch : float
        Length of one unit along the actuator (10.5 mm: 15 units = 157.5 mm).
    width : float
        Width across the actuator (3D only).
    wall : float
        Thickness of the soft (bottom) wall and of the wall between cavity and layer.
    side_wall : float
        Thickness of the side walls (3D only).
    end_wall : float
        Thickness of each end wall of the cavity.

    layer : float
        Thickness of the stiff layer that gives the preferential bending direction; 0: no
        stiff layer (an extending unit when the walls are equal).
    cavity_height : float
        Height of the cavity.
    slit_width, slit_depth : float
        The gap cut from the soft face at the end of the unit (0 = no slit).
    end_cap : float
        Extra material closing the free end of the last unit (mm). The interior walls
        between cavities are ``2 end_wall`` thick; the free end wall is only ``end_wall``
        plus this cap, and balloons first if it is thin.
    body_material, layer_material : str
        Library names of the body and the stiff layer.
    element_size : float
        Target edge length of the elements.
    element_order : {1, 2}
        2: quadratic elements (quad8 / hex20, the default); 1: linear (quad4 / hex8), for
        mesh studies such as Table 4.1.
    name : str
        A label for reports.
    filler_coefficients : tuple of float
        The unit's calibrated filler law of the 2D model, ``E(P) = sum_k c_k P^k`` (MPa, P
        in MPa; ``pneumorph calibrate`` writes it). Empty: the dissertation's Eq 5.2.
    filler_range_kpa : (float, float)
        The pressure range the law was calibrated over.
    filler_poisson_ratio : float
        Poisson's ratio of the filler.
    filler_source : str
        Where the law comes from (provenance of the calibration).
    solid : bool
        True: the cavity is filled with the body material (a near-rigid unit). Its box is
        still meshed with the same lines, and its vertices are still tracked.
    layer_side : bool
        True: the stiff layer lies on the side face z = width (a sideways unit, bending about
        the vertical axis), with a side wall between it and the cavity; False (default): on
        top. Needs a layer (``layer > 0``) and no slit; 3D models only.
    bottom_material : str
        Library name of the material of the soft (bottom) wall, the ``wall`` below the
        cavity along the whole unit (turned over with it); empty (default): the body
        material. A stiff material there lowers the unit's preferential bending; the
        bilinear paper-silicone composite (``bilinear_0_2``) makes it bimodal: softer than
        the body at first, the unit bends towards its top, then the composite stiffens
        (its paper straightens) and the unit bends back (``docs/unit-library.md``).

    Raises
    ------
    GeometryError
        Non-positive dimensions, walls that leave no cavity, a slit that cuts the unit in two.

    Notes
    -----
    Fields added after the unit's first release (:data:`OPTIONAL_FIELDS`: ``solid``,
    ``layer_side``, ``bottom_material``) are
    left out of :meth:`to_dict` while they hold their default, so the description of every
    earlier unit, and the fingerprints of models and chain tables built on it, stay the same.

    The defaults are the unit of the geometry study (``docs/unit-geometry.md``): 3 mm end
    walls and a 6 mm high cavity make 15 aligned units curl about 300 degrees at 45 kPa in
    3D, where the closed 1.5 mm-walled 7.5 x 12 mm cavity balloons instead of bending.
    """

    pitch: float = 10.5
    width: float = 15.0
    wall: float = 1.5
    side_wall: float = 1.5
    end_wall: float = 3.0
    layer: float = 3.0
    cavity_height: float = 6.0
    slit_width: float = 0.0
    slit_depth: float = 0.0
    end_cap: float = 0.0
    body_material: str = "mold_star_15"
    layer_material: str = "smooth_sil_950"
    element_size: float = 1.5
    element_order: int = 2
    name: str = "unit"
    filler_coefficients: tuple[float, ...] = ()
    filler_range_kpa: tuple[float, float] = (0.0, 45.0)
    filler_poisson_ratio: float = 0.3
    filler_source: str = ""
    solid: bool = False
    layer_side: bool = False
    bottom_material: str = ""

    def __post_init__(self) -> None:
        for key in ("solid", "layer_side"):
            if not isinstance(getattr(self, key), bool):
                raise GeometryError(f"unit {key} must be true or false, got {getattr(self, key)!r}")
        object.__setattr__(self, "filler_coefficients", _numbers(self.filler_coefficients, "filler_coefficients"))
        object.__setattr__(self, "filler_range_kpa", _numbers(self.filler_range_kpa, "filler_range_kpa", 2))
        low, high = self.filler_range_kpa
        if not low < high:
            raise GeometryError(f"unit filler_range_kpa must rise from its low to its high pressure, got "
                                f"[{low:g}, {high:g}] kPa")
        if self.filler_coefficients:
            self.filler_law()  # validates: positive modulus over the range, Poisson's ratio
        if isinstance(self.element_order, bool) or self.element_order not in (1, 2):
            raise GeometryError(f"element_order must be 1 (linear) or 2 (quadratic), got {self.element_order!r}")
        for key in ("body_material", "layer_material", "name"):
            if not isinstance(getattr(self, key), str) or not getattr(self, key).strip():
                raise GeometryError(f"unit {key} must be a non-empty text, got {getattr(self, key)!r}")
        if not isinstance(self.bottom_material, str) or self.bottom_material != self.bottom_material.strip():
            raise GeometryError(f"unit bottom_material must be a material's name (or empty: the body material), got "
                                f"{self.bottom_material!r}")
        for key in UNIT_LENGTHS:
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise GeometryError(f"unit {key} must be a finite number of mm, got {value!r}")
        check_lengths(self)
        if len(self.name) > MAX_NAME_CHARS:
            raise MeshLimitError(f"unit name is {len(self.name):,} characters long; the limit is {MAX_NAME_CHARS} "
                                 "(MAX_NAME_CHARS, pneumorph.geometry.limits)")
        for key in ("pitch", "width", "wall", "side_wall", "end_wall", "cavity_height", "element_size"):
            if getattr(self, key) <= 0:
                raise GeometryError(f"unit {key} must be positive, got {getattr(self, key)} mm")
        for key in ("layer", "slit_width", "slit_depth", "end_cap"):
            if getattr(self, key) < 0:
                raise GeometryError(f"unit {key} must be >= 0, got {getattr(self, key)} mm")
        thinnest = min(self.wall, self.side_wall, self.end_wall, *([self.layer] if self.layer > 0 else []))
        if self.element_size < MIN_ELEMENT_FRACTION * thinnest:
            raise GeometryError(
                f"unit element_size {self.element_size:g} mm is below {MIN_ELEMENT_FRACTION:g} x the thinnest wall "
                f"({thinnest:g} mm), the limit MIN_ELEMENT_FRACTION: the mesh would not fit in memory"
            )
        if self.cavity_length <= 0:
            raise GeometryError(
                f"the walls leave no cavity: pitch {self.pitch} mm - 2 x end wall {self.end_wall} mm "
                f"- slit {self.slit_width} mm = {self.cavity_length:g} mm"
            )
        if 2 * self.side_wall + self.side_layer >= self.width:
            layer = f" + side layer {self.side_layer:g} mm" if self.layer_side else ""
            raise GeometryError(
                f"the side walls leave no cavity: 2 x {self.side_wall} mm{layer} >= width {self.width} mm"
            )
        self._check_side_layer()
        if (self.slit_width > 0) != (self.slit_depth > 0):
            raise GeometryError(
                f"a slit needs both a width and a depth, got width {self.slit_width} mm and "
                f"depth {self.slit_depth} mm"
            )
        if self.slit_depth >= self.height - self.top_layer:
            raise GeometryError(
                f"slit depth {self.slit_depth} mm reaches the stiff layer (at {self.height - self.top_layer} mm): "
                "the units would only be joined by the layer; make it shallower"
            )

    def _check_side_layer(self) -> None:
        """Refuse a sideways unit (``layer_side``) without a layer, or with a slit."""
        if not self.layer_side:
            return
        if self.layer == 0:
            raise GeometryError("unit layer_side = true needs a stiff layer to put on the side (layer > 0), got "
                                "layer 0 mm")
        if self.slit_width > 0:
            raise GeometryError("a sideways unit (layer_side = true) takes no slit: the slit is cut from the bottom "
                                "face, and a sideways unit's soft face is its side (slit_width = 0)")

    @property
    def height(self) -> float:
        """Total height: bottom wall + cavity + top wall + stiff layer (on top; a sideways unit's is on its side)."""
        return self.wall + self.cavity_height + self.wall + self.top_layer

    @property
    def top_layer(self) -> float:
        """Thickness of the stiff layer on top (0 for a sideways unit).

        >>> UnitSpec().top_layer, UnitSpec(cavity_height=9.0, layer_side=True).top_layer
        (3.0, 0.0)
        """
        return 0.0 if self.layer_side else self.layer

    @property
    def side_layer(self) -> float:
        """Thickness of the stiff layer on the side face z = width (0 unless a sideways unit)."""
        return self.layer if self.layer_side else 0.0

    @property
    def cavity_z(self) -> tuple[float, float]:
        """The cavity across the width ``(z0, z1)`` in the unit's own frame (orientation 0; 3D).

        >>> UnitSpec().cavity_z, UnitSpec(cavity_height=9.0, layer_side=True).cavity_z
        ((1.5, 13.5), (1.5, 10.5))
        """
        return (self.side_wall, self.width - self.side_wall - self.side_layer)

    @property
    def cavity_length(self) -> float:
        """Length of the cavity along the actuator."""
        return self.pitch - 2 * self.end_wall - self.slit_width

    @property
    def cavity(self) -> tuple[float, float, float, float]:
        """The cavity ``(x0, x1, y0, y1)`` in the unit's own frame (orientation 0)."""
        x0 = self.end_wall
        return (x0, x0 + self.cavity_length, self.wall, self.wall + self.cavity_height)

    @property
    def slit(self) -> tuple[float, float, float, float] | None:
        """The slit ``(x0, x1, y0, y1)`` in the unit's own frame, or None."""
        if self.slit_width == 0:
            return None
        return (self.pitch - self.slit_width, self.pitch, 0.0, self.slit_depth)

    @property
    def symmetric(self) -> bool:
        """True if the unit turned over is the same body: no stiff layer and no slit.

        The walls above and below the cavity are both ``wall`` thick, so with ``layer = 0``
        and no slit (cut from the soft face) the section is its own mirror about the unit's
        mid-height, the tracked cavity corners map onto each other, and the two orientations
        of the unit are one: a design over a library writes it in one letter.

        Examples
        --------
        >>> UnitSpec().symmetric, UnitSpec(wall=3.0, layer=0.0).symmetric
        (False, True)
        >>> UnitSpec(wall=3.0, layer=0.0, slit_width=0.5, slit_depth=2.0).symmetric
        False

        A bottom wall of another material (:attr:`bottom_material`) has no mirror either:

        >>> UnitSpec(layer=0.0, cavity_height=9.0, bottom_material="bilinear_0_2").symmetric
        False
        """
        return self.layer == 0.0 and self.slit is None and not self.bottom_material

    def is_builtin_shape(self) -> bool:
        """True if the unit's dimensions and materials are the built-in unit's.

        Names, mesh settings and filler fields do not count: the built-in filler law
        (:data:`BUILTIN_FILLER`) belongs to the physical unit, whatever its mesh.

        Examples
        --------
        >>> UnitSpec(element_size=0.75).is_builtin_shape(), UnitSpec(cavity_height=5.0).is_builtin_shape()
        (True, False)
        """
        ignored = {"name", "element_size", "element_order"}
        mine, builtin = asdict(self), asdict(UnitSpec())
        return all(mine[k] == builtin[k] for k in mine if k not in ignored and not k.startswith("filler_"))

    def with_own_filler(self) -> UnitSpec:
        """This unit with the filler law it gets written into its own fields, so that a cast of it with other
        thicknesses keeps the law (the built-in unit's :data:`BUILTIN_FILLER` belongs to the physical unit: a
        wall 0.08 mm thinner would otherwise switch the 2D model to Eq 5.2).

        >>> from dataclasses import replace
        >>> replace(UnitSpec(), wall=1.42).filler_law() is None
        True
        >>> replace(UnitSpec().with_own_filler(), wall=1.42).filler_law() == UnitSpec().filler_law()
        True
        """
        if self.filler_coefficients or not self.is_builtin_shape():
            return self
        return replace(self, filler_coefficients=tuple(BUILTIN_FILLER["coefficients"]),
                       filler_range_kpa=tuple(BUILTIN_FILLER["range_kpa"]), filler_source=BUILTIN_FILLER["source"])

    def filler_law(self) -> FillerLaw | None:
        """The unit's calibrated filler law, or None (then the 2D model uses Eq 5.2).

        A unit without its own coefficients gets :data:`BUILTIN_FILLER` if it has the
        built-in unit's shape; any other unit has no law until it is calibrated.

        Raises
        ------
        MaterialDataError
            A law that is not positive over its range, or a bad Poisson's ratio.

        Examples
        --------
        >>> round(float(UnitSpec().filler_law().modulus(0.045)) * 1e3, 2)   # kPa at 45 kPa
        19.36
        >>> UnitSpec(cavity_height=5.0).filler_law() is None
        True
        """
        if self.filler_coefficients:
            coefficients, (lo, hi), source = self.filler_coefficients, self.filler_range_kpa, self.filler_source
        elif self.is_builtin_shape():
            coefficients, (lo, hi), source = (BUILTIN_FILLER["coefficients"], BUILTIN_FILLER["range_kpa"],
                                              BUILTIN_FILLER["source"])
        else:
            return None
        return FillerLaw(
            name=f"{self.name}_filler",
            display_name=f"filler of {self.name}",
            coefficients=tuple(coefficients),
            pressure_range=(lo / 1e3, hi / 1e3),
            poisson_ratio=self.filler_poisson_ratio,
            source=source or f"calibrated for unit {self.name!r}",
        )

    def to_dict(self) -> dict[str, Any]:
        """All parameters, for TOML files, provenance and model fingerprints.

        The fields of :data:`OPTIONAL_FIELDS` appear only when they differ from their
        default, so that a unit described before they existed is described the same now.

        Examples
        --------
        >>> "solid" in UnitSpec().to_dict(), UnitSpec(solid=True).to_dict()["solid"]
        (False, True)
        """
        out = asdict(self)
        out["filler_coefficients"] = list(self.filler_coefficients)
        out["filler_range_kpa"] = list(self.filler_range_kpa)
        for key, default in OPTIONAL_FIELDS.items():
            if out[key] == default:
                del out[key]
        return out

    @classmethod
    def from_dict(cls, data: dict[str, Any], source: str = "unit definition") -> UnitSpec:
        """Build from a mapping (e.g. the ``[unit]`` table of a TOML file).

        Raises
        ------
        GeometryError
            Unknown keys (the message lists the known ones) or invalid values.
        """
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise GeometryError(
                f"{source}: unknown unit parameter(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}"
            )
        try:
            return cls(**data)
        except TypeError as exc:  # pragma: no cover - guarded by the key check
            raise GeometryError(f"{source}: {exc}") from None

    @classmethod
    def from_toml(cls, path: str | Path) -> UnitSpec:
        """Read a unit from a TOML file with a ``[unit]`` table (lengths in mm): a unit a mould can cast
        (:func:`~pneumorph.geometry.limits.check_manufacturable`).

        Examples
        --------
        >>> import tempfile, pathlib
        >>> p = pathlib.Path(tempfile.mkdtemp()) / "u.toml"
        >>> _ = p.write_text("[unit]\\npitch = 12.0\\nslit_width = 1.0\\nslit_depth = 6.0\\n")
        >>> UnitSpec.from_toml(p).cavity_length
        5.0
        """
        from pneumorph.io.files import read_toml

        p = Path(path)
        data = read_toml(p, "unit file", GeometryError)
        if "unit" not in data or not isinstance(data["unit"], dict):
            raise GeometryError(f"{p}: expected a [unit] table with the unit's dimensions in mm")
        spec = cls.from_dict(data["unit"], source=str(p))
        check_manufacturable(spec, f"{p}: unit")
        return spec


#: Fields added after the first release, with their defaults: :meth:`UnitSpec.to_dict` leaves
#: them out while they hold these values (earlier descriptions and fingerprints stay valid).
OPTIONAL_FIELDS: dict[str, Any] = {"solid": False, "layer_side": False, "bottom_material": ""}

#: The filler law of the built-in unit: ``pneumorph calibrate`` (defaults: 15 units, 5-45 kPa
#: in 5 kPa steps, three runs, seed 0, relative weighting) against the 3D model; the
#: quadratic law, chosen by the calibration, R^2 = 0.9438 in its weighting, 0.9530
#: unweighted (docs/calibration.md). E in MPa, P in MPa.
BUILTIN_FILLER: dict[str, Any] = {
    "coefficients": (0.046869544771897344, -0.7517352995800477, 3.1221708231645415),
    "range_kpa": (0.0, 45.0),
    "source": "pneumorph calibrate of the built-in unit: 27 points (15 units, 3 runs, 5-45 kPa), "
              "degree 2, relative weighting, R^2 0.9438 (unweighted 0.9530) (docs/calibration.md)",
}
