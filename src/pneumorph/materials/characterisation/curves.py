"""Test curves as records: one mode's stretch and nominal stress (:class:`TestCurve`, checked on
creation) and a material's set of them (:class:`TestData`); reading them from files:
:mod:`pneumorph.materials.characterisation.testdata`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import ClassVar

import numpy as np

from pneumorph.checks import MODES
from pneumorph.errors import DataFormatError
from pneumorph.materials.laws.hyperelastic import FloatArray

#: Bounds of plausible test data: beyond them a number is a unit mistake (or overflows the fit).
MAX_STRETCH = 100.0
MAX_STRESS_MPA = 1e5


@dataclass(frozen=True, eq=False)
class TestCurve:
    """One homogeneous test: stretch against nominal stress.

    Attributes
    ----------
    mode : {"uniaxial", "equibiaxial", "planar"}
        Loading mode; uniaxial curves may include compression (``stretch < 1``).
    stretch : ndarray
        Stretch in the loaded direction, strictly increasing (read-only).
    stress : ndarray
        Nominal (engineering, first Piola-Kirchhoff) stress in MPa (read-only).
    source : str or None
        File the curve was read from.
    description : str
        Free text (material, test).
    metadata : mapping of str to str
        Metadata found in the file (the database's ``PARAMETER;INFO`` block).
    notes : tuple of str
        What was done to the numbers: unit scaling, conversions, truncation.
    """

    __test__: ClassVar[bool] = False  # not a pytest test class

    mode: str
    stretch: FloatArray
    stress: FloatArray
    source: str | None = None
    description: str = ""
    metadata: Mapping[str, str] = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ValueError(f"unknown loading mode {self.mode!r}; expected one of {MODES}")
        lam = np.array(self.stretch, dtype=float)
        p = np.array(self.stress, dtype=float)
        if lam.ndim != 1 or lam.shape != p.shape:
            raise DataFormatError("stretch and stress must be 1-D arrays of the same length", path=self.source)
        if not (np.all(np.isfinite(lam)) and np.all(np.isfinite(p))):
            raise DataFormatError("stretch and stress must be finite numbers", path=self.source)
        if lam.size and (lam.min() <= 0 or lam.max() > MAX_STRETCH):
            raise DataFormatError(f"stretch must lie in (0, {MAX_STRETCH:g}], found {lam.min():.6g} to {lam.max():.6g}",
                                  path=self.source)
        if p.size and np.abs(p).max() > MAX_STRESS_MPA:
            raise DataFormatError(
                f"a stress of {np.abs(p).max():.6g} MPa is beyond {MAX_STRESS_MPA:g} MPa, no rubber's; "
                "check the stress unit (--stress-unit)", path=self.source)
        lam.setflags(write=False)
        p.setflags(write=False)
        object.__setattr__(self, "stretch", lam)
        object.__setattr__(self, "stress", p)
        object.__setattr__(self, "metadata", MappingProxyType(dict(self.metadata)))
        object.__setattr__(self, "notes", tuple(self.notes))

    def __len__(self) -> int:
        return int(self.stretch.size)


@dataclass(frozen=True, eq=False)
class TestData:
    """The test curves of one material, any number per mode.

    Attributes
    ----------
    curves : tuple of TestCurve
    name : str
        A short name (file stem or dataset name) for tables and figures.
    """

    __test__: ClassVar[bool] = False

    curves: tuple[TestCurve, ...]
    name: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "curves", tuple(self.curves))
        if not self.curves:
            raise ValueError("TestData needs at least one curve")

    @property
    def modes(self) -> tuple[str, ...]:
        """Modes present, in the order uniaxial, equibiaxial, planar."""
        return tuple(m for m in MODES if any(c.mode == m for c in self.curves))

    @property
    def sources(self) -> tuple[str, ...]:
        """Files the curves came from."""
        return tuple(c.source for c in self.curves if c.source)

    def curve(self, mode: str) -> TestCurve:
        """All points of ``mode`` as one curve, sorted by stretch."""
        parts = [c for c in self.curves if c.mode == mode]
        if not parts:
            raise KeyError(f"no {mode} data in {self.name or 'this data'}; modes: {self.modes}")
        if len(parts) == 1:
            return parts[0]
        lam = np.concatenate([c.stretch for c in parts])
        p = np.concatenate([c.stress for c in parts])
        order = np.argsort(lam, kind="stable")
        return TestCurve(
            mode, lam[order], p[order], source=", ".join(c.source or "?" for c in parts),
            description="; ".join(c.description for c in parts if c.description),
            notes=tuple(n for c in parts for n in c.notes),
        )

    def restrict(self, min_stretch: float | None = None, max_stretch: float | None = None) -> TestData:
        """Only the points with ``min_stretch <= stretch <= max_stretch``.

        Examples
        --------
        >>> from pneumorph.materials.characterisation.datasets import load_dataset
        >>> len(load_dataset("treloar1944").restrict(max_stretch=3.0).curve("uniaxial"))
        9
        """
        lo = -math.inf if min_stretch is None else min_stretch
        hi = math.inf if max_stretch is None else max_stretch
        out = []
        for c in self.curves:
            keep = (c.stretch >= lo) & (c.stretch <= hi)
            if keep.any():
                note = f"restricted to stretch {lo:g}-{hi:g} ({int(keep.sum())} of {len(c)} points)"
                out.append(TestCurve(c.mode, c.stretch[keep], c.stress[keep], c.source,
                                     c.description, c.metadata, (*c.notes, note)))
        if not out:
            raise DataFormatError(f"no data point has a stretch between {lo:g} and {hi:g}",
                                  path=self.name or None)
        return TestData(tuple(out), self.name)
