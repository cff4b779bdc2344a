"""The response of one actuator design to a pressure ramp, and the model interface.

Coordinates: ``x`` along the actuator's long axis (the base at ``x = 0``), ``y`` in the
bending plane (positive towards the side a unit of orientation 0 bends to), ``z`` across
the width (3D only). Lengths in mm, pressures in MPa (kPa only at the edges). A response
keeps (x, y) of its points, or (x, y, z) when its model can leave the plane (the full 3D
model, which any design with a sideways unit needs: :attr:`Response.axes`).

A model of any fidelity (2D reduced-order, 3D, a surrogate) turns an orientation vector
into a :class:`Response`; the design search sees nothing else.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import DataFormatError
from pneumorph.io.reading import read_json

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Response:
    """Unit centres, tip and curl of one design at every reported pressure.

    Attributes
    ----------
    orientation : str
        The design, base first (``"0101..."``).
    pressures : ndarray, shape (k,)
        The reported pressures (MPa), increasing; e.g. 4.5, 9, ..., 45 kPa.
    centres : ndarray, shape (k, n, 2) or (k, n, 3)
        Current (x, y) of every unit centre - the mean of the unit's four tracked nodes at
        the cavity's vertices (Fig 4.4) - at every reported pressure; NaN after a failure.
        (x, y, z) from a model of the full width (3D, no mid-plane symmetry): z across the
        width, the mesh's coordinate (the actuator's axis at ``z = width / 2``).
    reference_centres : ndarray, shape (n, 2) or (n, 3)
        The unit centres of the undeformed actuator.
    tip : ndarray, shape (k, 2) or (k, 3)
        Current (x, y) or (x, y, z) of the tip (centre of the free end face).
    reference_tip : ndarray, shape (2,) or (3,)
        The undeformed tip.
    curl : ndarray, shape (k,)
        Rotation of the free end face in degrees, counter-clockwise positive, unwrapped
        (it can exceed 360).
    converged : bool
        True if the whole ramp converged.
    reached : float
        The highest pressure that converged (MPa); equals ``pressures[-1]`` if converged.
    failure : str or None
        Why the ramp stopped, if it did.
    metadata : dict
        Provenance: model fidelity and fingerprint, solver statistics, wall time, versions.
    frames : ndarray, shape (k, n, 3), or None
        Each unit's rotation (a rotation vector, rad) per level: the full 3D model's
        responses (points in space) keep it (:mod:`pneumorph.models.frames`); None otherwise.
    end_frame : ndarray, shape (k, 3), or None
        The free end face's rotation (a rotation vector, rad) per level, of the full 3D
        model's responses (:func:`pneumorph.models.frames.end_frame`) and of a chain in space
        that predicts it (:meth:`~pneumorph.models.chain.table.ChainTable.end_frames`); its
        :attr:`twist` about the face's normal. None for planar responses.

    Examples
    --------
    >>> import numpy as np
    >>> r = Response.empty("01", np.array([0.0225, 0.045]), np.array([[5.0, 0.0], [15.0, 0.0]]),
    ...                    np.array([20.0, 0.0]))
    >>> r.n_units, r.n_levels, bool(np.isnan(r.centres).all()), r.axes
    (2, 2, True, 2)

    Points in space (the full 3D model): three coordinates each.

    >>> Response.empty("0", np.array([0.045]), np.array([[5.0, 6.0, 7.5]]), np.array([10.0, 6.0, 7.5])).tip.shape
    (1, 3)
    """

    orientation: str
    pressures: FloatArray
    centres: FloatArray
    reference_centres: FloatArray
    tip: FloatArray
    reference_tip: FloatArray
    curl: FloatArray
    converged: bool = True
    reached: float = float("nan")
    failure: str | None = None
    metadata: dict[str, Any] = field(default_factory=dict)
    frames: FloatArray | None = None
    end_frame: FloatArray | None = None

    def __post_init__(self) -> None:
        k, n = len(self.pressures), len(self.orientation)
        d = 3 if self.reference_tip.shape == (3,) else 2  # (x, y, z) from a model of the full width
        shapes = {
            "centres": (self.centres.shape, (k, n, d)),
            "reference_centres": (self.reference_centres.shape, (n, d)),
            "tip": (self.tip.shape, (k, d)),
            "reference_tip": (self.reference_tip.shape, (d,)),
            "curl": (self.curl.shape, (k,)),
        }
        if self.frames is not None:  # each unit's rotation vector, per level (a full-width response)
            shapes["frames"] = (self.frames.shape, (k, n, 3))
        if self.end_frame is not None:
            shapes["end_frame"] = (self.end_frame.shape, (k, 3))
        for name, (got, want) in shapes.items():
            if tuple(got) != want:
                raise ValueError(f"Response.{name} has shape {tuple(got)}, expected {want}")

    @classmethod
    def empty(
        cls,
        orientation: str,
        pressures: FloatArray,
        reference_centres: FloatArray,
        reference_tip: FloatArray,
        **kwargs: Any,
    ) -> Response:
        """A response with every level still unknown (NaN), to be filled level by level.

        Its points have the coordinates of ``reference_tip``: (x, y), or (x, y, z).
        """
        k, n = len(pressures), len(orientation)
        d = len(reference_tip)
        if d == 3:  # a full-width response keeps each unit's frame too (pneumorph.models.frames)
            kwargs.setdefault("frames", np.full((k, n, 3), np.nan))
            kwargs.setdefault("end_frame", np.full((k, 3), np.nan))
        return cls(
            orientation=orientation,
            pressures=np.asarray(pressures, dtype=float),
            centres=np.full((k, n, d), np.nan),
            reference_centres=np.asarray(reference_centres, dtype=float),
            tip=np.full((k, d), np.nan),
            reference_tip=np.asarray(reference_tip, dtype=float),
            curl=np.full(k, np.nan),
            **kwargs,
        )

    @property
    def n_units(self) -> int:
        return len(self.orientation)

    @property
    def n_levels(self) -> int:
        return len(self.pressures)

    @property
    def axes(self) -> int:
        """The coordinates of every point: 2 (x, y) or 3 (x, y, z; a model of the full width)."""
        return int(self.reference_tip.shape[0])

    @property
    def twist(self) -> FloatArray | None:
        """The end face's twist about its own normal (deg) per level (:func:`pneumorph.models.frames.twist`), or
        None without the end face's frame."""
        from pneumorph.models.frames import twist

        return None if self.end_frame is None else twist(self.end_frame)

    @property
    def displacements(self) -> FloatArray:
        """Unit-centre displacements ``centres - reference_centres``, shape (k, n, axes)."""
        return self.centres - self.reference_centres[None]

    def centreline(self, level: int) -> FloatArray:
        """The polyline base -> unit centres -> tip at a reported level, shape (n + 2, axes)."""
        base = np.concatenate([[0.0], self.reference_centres[0, 1:]])[None]
        return np.concatenate([base, self.centres[level], self.tip[level][None]])

    def level_of(self, pressure: float) -> int:
        """Index of the reported level at ``pressure`` (MPa), within 1e-9 MPa.

        Raises
        ------
        KeyError
            If ``pressure`` is not a reported level.
        """
        hits = np.flatnonzero(np.isclose(self.pressures, pressure, rtol=0.0, atol=1e-9))
        if not hits.size:
            levels = ", ".join(f"{p * 1e3:g}" for p in self.pressures)
            raise KeyError(f"{pressure * 1e3:g} kPa is not a reported level ({levels} kPa)")
        return int(hits[0])

    # -- persistence ------------------------------------------------------------------
    _ARRAYS = ("pressures", "centres", "reference_centres", "tip", "reference_tip", "curl")
    #: arrays only full-width responses keep (None otherwise)
    _OPTIONAL = ("frames", "end_frame")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (pressures in MPa, lengths in mm, NaN as null)."""

        def clean(a: FloatArray) -> Any:
            out = np.asarray(a).astype(object)
            out[np.isnan(a)] = None
            return out.tolist()

        out: dict[str, Any] = {"orientation": self.orientation}
        out.update({name: clean(getattr(self, name)) for name in self._ARRAYS})
        out.update(converged=self.converged, reached=self.reached, failure=self.failure)
        out["metadata"] = self.metadata
        out.update({name: clean(getattr(self, name)) for name in self._OPTIONAL if getattr(self, name) is not None})
        return out

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Response:
        arrays: dict[str, Any] = {
            name: np.array(data[name], dtype=float) for name in cls._ARRAYS
        }  # None -> nan via dtype float
        arrays.update({name: None if data.get(name) is None else np.array(data[name], dtype=float)
                       for name in cls._OPTIONAL})
        return cls(
            orientation=data["orientation"],
            converged=bool(data["converged"]),
            reached=float(data["reached"]),
            failure=data.get("failure"),
            metadata=dict(data.get("metadata", {})),
            **arrays,
        )

    def save(self, path: str | Path) -> tuple[Path, Path]:
        """Write ``<path>.npz`` (arrays) and ``<path>.json`` (everything, readable)."""
        base = Path(path)
        base.parent.mkdir(parents=True, exist_ok=True)
        npz, js = base.with_suffix(".npz"), base.with_suffix(".json")
        arrays = {name: getattr(self, name) for name in (*self._ARRAYS, *self._OPTIONAL)
                  if getattr(self, name) is not None}
        np.savez(npz, **arrays)
        js.write_text(json.dumps(self.to_dict(), indent=1), encoding="utf-8")
        return npz, js

    @classmethod
    def load(cls, path: str | Path) -> Response:
        """Read a response written by :meth:`save` (from its JSON file, through the one bounded reader).

        Raises
        ------
        DataFormatError
            One line naming the file: not a regular file, too large, not UTF-8, not JSON, nested
            too deep (:func:`pneumorph.io.reading.read_json`), or not a response.
        """
        js = Path(path).with_suffix(".json")
        data = read_json(js, "response", DataFormatError)
        try:
            return cls.from_dict(data)
        except (AttributeError, KeyError, TypeError, ValueError) as exc:
            raise DataFormatError(f"response {js}: not a response file ({type(exc).__name__}: {exc})") from None


@runtime_checkable
class ActuatorModel(Protocol):
    """What the design search needs from a model of any fidelity.

    ``evaluate`` raises :class:`pneumorph.errors.SimulationFailed` when the ramp cannot be
    completed; evaluators record that as a failed design. ``fingerprint`` changes whenever
    anything that changes results changes (unit, materials, filler law, mesh, solver
    settings, pressure ramp), and keys the evaluation cache.
    """

    fidelity: str
    n_units: int

    def fingerprint(self) -> str: ...

    def pressures(self) -> FloatArray: ...

    def evaluate(self, orientation: str) -> Response: ...


def _wrap(a: FloatArray) -> FloatArray:
    return (a + np.pi) % (2 * np.pi) - np.pi


def response_elements(response: Response) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Turns (rad) and lengths (mm) of the ``n + 1`` chords, and the end turn, per level.

    Returns
    -------
    turn, length : ndarray, shape (k, n + 1)
    end : ndarray, shape (k,)
    """
    k = response.n_levels
    pts = np.stack([response.centreline(i) for i in range(k)])  # (k, n + 2, 2)
    chords = np.diff(pts, axis=1)
    angle = np.unwrap(np.arctan2(chords[..., 1], chords[..., 0]), axis=-1)
    turn = np.diff(angle, axis=-1, prepend=0.0)
    length = np.hypot(chords[..., 0], chords[..., 1])
    end = _wrap(np.radians(response.curl) - angle[:, -1])
    return turn, length, end
