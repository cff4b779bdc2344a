"""The unit-chain model: an actuator's response from a table of per-window chord turns and lengths.

Why it works. A free actuator (no gravity, no contact) carries only cavity pressure, which
is self-equilibrated on every closed cavity, so a cut between two units carries no
resultant force or moment; by Saint-Venant each unit deforms according to its own
neighbourhood. Describe a response at every level by the polyline base -> unit centres ->
tip (``n + 2`` points, ``n + 1`` chords):

- the *turn* of chord ``j`` (its angle minus the angle of chord ``j - 1``; for ``j = 0`` the
  angle of the first chord itself) and its *length*, for ``j = 0 .. n``;
- the *end turn*: the curl of the end face minus the angle of the last chord.

Element ``j`` (turn and length of chord ``j``, which starts at point ``j``: the base for
``j = 0``, the centre of unit ``j`` otherwise) is keyed by its *window*, the orientations of
the units ``j - w .. j + w`` (1-based), where positions before the first unit read as the
base symbol ``B`` and positions after the last as the tip symbol ``T``. The end turn is keyed
by the window of the last chord. A :class:`ChainTable` maps every window to its turn, length
(and end turn) at every reported level; chaining the tabulated chords from the clamped base
reproduces the unit centres, the tip and the curl of any design in microseconds.

Mirror symmetry (every unit inverted mirrors the actuator) gives the window with 0 and 1
exchanged the negated turns and the same lengths, so a training design teaches two
windows at once and the covering set needs half as many FE solves.

Over a unit library of several types (:mod:`pneumorph.geometry.library`) the windows are
those of the types and orientations (``a``, ``A``, ``e``, ``E``, ... : codes ``2t + o``,
:mod:`pneumorph.models.chain.windows`), and the table keeps the types' symbols (its *alphabet*)
and each type's pitch, centre offset and centre heights; a design with a type the table
has not seen is refused ("unit type 'x' has no table"). A table of one unit type is
the 0/1 table of the built-in unit, its file and fingerprint unchanged.

The table is fitted from FE solves and validated on held-out designs by
:mod:`pneumorph.models.chain.fit`.
"""

from __future__ import annotations

import copy
import hashlib
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import ChainTableError
from pneumorph.io.provenance import digest
from pneumorph.models.chain.table import ChainTable
from pneumorph.models.chain.tablefile import ALPHABET_FORMAT, TABLE_FORMAT
from pneumorph.models.chain.windows import (
    BASE,
    TIP,
    covering_designs,
    design_array,
    design_strings,
    mirror_codes,
    possible_codes,
    window_codes,
    window_symbols,
    window_text,
)
from pneumorph.models.response import FloatArray, Response

__all__ = [
    "ALPHABET_FORMAT",
    "BASE",
    "TABLE_FORMAT",
    "TIP",
    "ChainModel",
    "ChainTable",
    "check_source",
    "covering_designs",
    "design_array",
    "design_strings",
    "in_space",
    "mirror_codes",
    "possible_codes",
    "source_description",
    "source_key",
    "training_model",
    "window_codes",
    "window_symbols",
    "window_text",
]


# -- identity of the source model -------------------------------------------------------------
def in_space(model: Any) -> bool:
    """Whether ``model``'s designs can leave the plane: it has a sideways unit type (``layer_side``).

    Its chain table is then a chain in space (:attr:`ChainTable.space`), fitted to every
    training design solved on the full width (:func:`training_model`).

    >>> from pneumorph.geometry.library import builtin_library
    >>> from pneumorph.models.fe import Full3D
    >>> in_space(Full3D(15, library=builtin_library())), in_space(Full3D(15, library=builtin_library("spatial")))
    (False, True)
    """
    library = getattr(model, "library", None)
    units = library.units if library is not None else [getattr(model, "unit", None)]
    return any(getattr(u, "layer_side", False) for u in units)


def training_model(model: Any) -> Any:
    """The model a chain table is fitted to: a model over sideways units solves every design on the full width.

    A chain in space needs each unit's frame, which the full-width response keeps; a design
    of planar units has the same response on either width, to the solver's tolerance
    (tests/models/test_full_model.py). Any other model is returned as it is.
    """
    if in_space(model) and getattr(model, "half", False):
        whole = copy.copy(model)
        whole.half = False
        return whole
    return model


def source_description(model: Any) -> dict[str, Any]:
    """What a model's results depend on, except its number of units.

    A model over sideways units is described as solved on the full width, as its table's
    training model is (:func:`training_model`).
    """
    describe = getattr(model, "describe", None)
    desc = dict(describe()) if callable(describe) else {"fingerprint": model.fingerprint()}
    desc.pop("n_units", None)
    if in_space(model) and "half_model" in desc:
        desc["half_model"] = False
    return desc


def source_key(model: Any) -> str:
    """Hash of :func:`source_description`: equal for the same unit, materials, ramp, fidelity."""
    return digest(source_description(model))


def fitted_quadrature(table: ChainTable) -> str:
    """The quadrature rule of the FE model ``table`` was fitted to (:data:`pneumorph.fem.body.QUADRATURES`).

    A model's description names a rule other than the full one (``"full"`` is left out, so
    that the tables fitted before the rule was a setting keep their keys); the rule is part
    of the source key, so a table is served only with the model at its rule.

    >>> from pneumorph.models.chain.sources import shipped_path
    >>> fitted_quadrature(ChainTable.load(shipped_path("3d")))
    'full'
    """
    return str(table.source.get("description", {}).get("quadrature", "full"))


def check_source(table: ChainTable, model: Any) -> None:
    """Refuse a table fitted to another model (unit, materials, ramp, fidelity or quadrature rule)."""
    key = source_key(model)
    if table.source.get("key") != key:
        theirs = table.source.get("fidelity", "?")
        rule, mine = fitted_quadrature(table), getattr(model, "quadrature", "full")
        raise ChainTableError(
            f"the chain table was fitted to another model ({theirs}, {rule} quadrature, source "
            f"{table.source.get('key')}) than the one asked for ({getattr(model, 'fidelity', '?')}, {mine} "
            f"quadrature, source {key}); rebuild it for this unit and model with `pneumorph chain build`"
        )


# -- the model -------------------------------------------------------------------------------
class ChainModel:
    """An :class:`~pneumorph.models.ActuatorModel` that chains a :class:`ChainTable`.

    Parameters
    ----------
    table : ChainTable
    n_units : int
        Units of the actuator (any number from ``2 w + 1``; the table's windows do not
        depend on the length).

    Examples
    --------
    >>> import numpy as np
    >>> from pneumorph.models import Response
    >>> ref = np.array([[5.0, 0.0], [15.0, 0.0], [25.0, 0.0]])
    >>> r = Response.empty("010", np.array([0.045]), ref, np.array([30.0, 0.0]))
    >>> r.centres[0] = ref; r.tip[0] = [30.0, 0.0]; r.curl[0] = 0.0
    >>> from pneumorph.models.chain.fit import fit_table
    >>> table = fit_table([r], 1, {"fidelity": "toy", "key": "x", "n_units": 3})
    >>> ChainModel(table, 3).evaluate("101").tip.round(9).tolist()
    [[30.0, 0.0]]
    """

    def __init__(self, table: ChainTable, n_units: int) -> None:
        table.check_units(n_units)
        self.table = table
        self.n_units = int(n_units)
        self.fidelity = f"chain-{table.source.get('fidelity', '?')}"

    def fingerprint(self) -> str:
        return hashlib.sha256(f"{self.table.fingerprint()}-{self.n_units}".encode()).hexdigest()[:16]

    def describe(self) -> dict[str, Any]:
        return {"fidelity": self.fidelity, "n_units": self.n_units, "window": self.table.window,
                "table": self.table.fingerprint(), "source": self.table.source.get("key"),
                "quadrature": fitted_quadrature(self.table)}

    def pressures(self) -> FloatArray:
        return self.table.pressures.copy()

    @property
    def length(self) -> float:
        """The undeformed length of the actuator, base to tip (mm): the ``L`` of a profile target.

        Over several unit types: that of the actuator of the first type only (the designs'
        lengths differ with their units' pitches).
        """
        tip = self.table.reference(np.zeros((1, self.n_units), dtype=np.uint8))[1]
        return float(np.atleast_2d(tip)[0, 0])

    @property
    def alphabet(self) -> tuple[str, ...]:
        """The unit types of the table (empty: one type, 0/1 designs)."""
        return self.table.alphabet

    def predict(self, bits: NDArray[np.integer]) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Centres (m, k, n, 2), tip (m, k, 2), curl (m, k) of many designs at once."""
        bits = np.atleast_2d(np.asarray(bits))
        if bits.shape[1] != self.n_units:
            raise ChainTableError(f"designs of {bits.shape[1]} units given to a chain model of {self.n_units}")
        return self.table.predict(bits)

    def evaluate(self, orientation: str) -> Response:
        """The chained response of one design (0/1, or over the table's unit types).

        Raises
        ------
        ChainTableError
            A unit type the table has no entries for ("unit type 'x' has no table").
        OrientationError
            A design of the wrong length or with characters that are no symbols.
        """
        bits = self.table.designs(orientation, self.n_units)
        design = self.table.texts(bits)[0]
        c, t, cu = self.predict(bits)
        ref_c, ref_t = self.table.reference(bits)
        ref_t = np.atleast_2d(ref_t)[0]
        end = self.table.end_frames(bits)  # a chain in space: the end face's frame, and so its twist
        return Response(design, self.pressures(), c[0], ref_c[0], t[0], ref_t, cu[0], converged=True,
                        reached=float(self.table.pressures[-1]), end_frame=None if end is None else end[0],
                        metadata={"fidelity": self.fidelity, "fingerprint": self.fingerprint()})
