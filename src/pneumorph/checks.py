"""Checks of settings where they enter, and the limits of what pneumorph agrees to compute.

Every setting a user gives (a CLI option, a config key, a constructor argument) passes one
of these functions, which refuse it with a :class:`~pneumorph.errors.SettingsError` that
names the setting, the value and what is allowed (or the subclass given as ``error``). Types are strict: a bool is not a
number, a float is not a count, a string is not a number (the CLI parses its text first,
:mod:`pneumorph.cli.options.params`).

Limits
------
Sizes beyond these are refused up front instead of hanging or exhausting memory; each is
far beyond what the dissertation's actuators need (15 units, 45-85 kPa, 10 levels).

========================  ======  =======================================================
``MAX_UNITS``                100  units of an actuator (1.05 m of the built-in unit)
``MAX_PRESSURE_KPA``        1000  kPa; the silicones tear long before (Table A.2 strains)
``MAX_INCREMENTS``          1000  reported pressure levels of a ramp
``MAX_SUBSTEPS``             100  substeps per level
``MAX_POPULATION``        10 000  GA population
``MAX_GENERATIONS``       10 000  GA generations
``MAX_STARTS``              1000  multistarts of a fit, runs, seeds, held-out designs
``MIN_ELEMENT_FRACTION``     1/8  element size against the unit's thinnest wall
``MIN_VOLUME_CHANGE``       1e-6  V0, a volume-controlled ramp's relative volume change
``MAX_VOLUME_CHANGE``        100  V0, the same; no silicone survives a hundredfold inflation
``MAX_VOLUME_STEP``            2  V0, the volume change of one step of such a ramp
``MAX_FRICTION``              10  Coulomb coefficient of an obstacle; elastomers reach 2-3
========================  ======  =======================================================

The limits and :func:`check_volume_steps` live here, below every model, so that a command's
options can name them without importing the models (``simulate --help`` imports no FE code).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from typing import Any, Literal

from pneumorph.errors import SettingsError

MAX_UNITS = 100
MAX_PRESSURE_KPA = 1000.0
MAX_INCREMENTS = 1000
MAX_SUBSTEPS = 100
MAX_POPULATION = 10_000
MAX_GENERATIONS = 10_000
MAX_STARTS = 1000
MIN_ELEMENT_FRACTION = 1.0 / 8.0

#: the range of a volume-controlled ramp's relative volume change ``V / V0 - 1``: a smaller change is lost in the
#: cavity volume's rounding and the solver's tolerance (the ramp would report an unloaded actuator ten times); a
#: larger one is a hundredfold inflation no silicone survives
MIN_VOLUME_CHANGE, MAX_VOLUME_CHANGE = 1e-6, 100.0

#: the largest relative volume change of one step of a volume-controlled ramp (``simulate --volume-change`` over
#: its ``--increments``, ``[model] volume_change`` over ``increments``, ``bimodal --volume-change`` over
#: ``--pmax``/``--step``): the bimodal actuator converges at 0.67 V0 a step (the default 8 V0 in 12 steps) and 1.6 V0
#: (two voids, 5 steps) but not at 4 V0 in one step from rest; a 4-unit 2D actuator of Ecoflex 00-30 takes 0.5 V0 in
#: one step and stops at 1 V0 (its first iterate's pressure past the filler law's range), in a few seconds, not a
#: long ramp
MAX_VOLUME_STEP = 2.0

#: the largest Coulomb friction coefficient of an obstacle (``friction`` of ``--obstacle`` and
#: ``[[model.obstacle]]``): soft elastomers on clean, smooth glass or metal reach about 2-3, rarely more, at the
#: peak of their adhesive friction (Grosch 1963, "The relation between the friction and visco-elastic properties
#: of rubber", Proc. R. Soc. Lond. A 274, 21-39; Roberts 1992, "A guide to estimating the friction of rubber",
#: Rubber Chem. Technol. 65, 673-686); 10 leaves a wide margin, and a larger number is a typing error, not a
#: surface
MAX_FRICTION = 10.0

# The choices of the material commands' options (``pneumorph materials fit``), defined here for the same reason as
# the limits: a command's --help names them without importing NumPy and the material code.
Mode = Literal["uniaxial", "equibiaxial", "planar"]
#: The homogeneous deformation modes of the test data: uniaxial, equibiaxial, planar (pure shear).
MODES: tuple[Mode, ...] = ("uniaxial", "equibiaxial", "planar")
#: Names of the models a fit accepts (``N`` is a number of terms, 1-6).
MODEL_NAMES = ("neo-hooke", "mooney-rivlin-2", "mooney-rivlin-3", "yeoh", "yeoh-N", "ogden-3", "ogden-N")
#: The residuals of a fit: plain stress, relative to the stress, or per-mode normalised.
WEIGHTINGS = ("absolute", "relative", "balanced")
#: Column roles of a test file (``columns=``); ``"skip"`` ignores a column.
COLUMN_ROLES = ("stretch", "strain", "true-strain", "stress", "skip")
#: How much of a test curve is kept: all of it, its rows up to the largest stretch, or up to the peak stress.
TRUNCATE = ("none", "loading", "peak-stress")

#: where a batch of designs is solved (``--executor``, ``[execution] executor``;
#: :func:`pneumorph.execution.make_evaluator`)
EXECUTORS = ("serial", "processes", "dask")


def _bound_text(low: float | None, high: float | None, low_open: bool, high_open: bool) -> str:
    parts = []
    if low is not None:
        parts.append(f"{'>' if low_open else '>='} {low:g}")
    if high is not None:
        parts.append(f"{'<' if high_open else '<='} {high:g}")
    return " and ".join(parts)


def integer(value: Any, name: str, low: int | None = None, high: int | None = None, limit: str = "",
            error: type[SettingsError] = SettingsError) -> int:
    """``value`` as an int, refusing bools, floats, strings and values outside ``[low, high]``.

    ``limit`` names the constant behind ``high`` for the message.

    Examples
    --------
    >>> integer(15, "--units", 1, MAX_UNITS)
    15
    >>> integer(True, "units", 1)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: units must be a whole number >= 1, got True
    >>> integer(500, "--units", 1, MAX_UNITS, limit="MAX_UNITS")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: --units must be a whole number >= 1 and <= 100 (limit MAX_UNITS), got 500
    """
    ok = isinstance(value, int) and not isinstance(value, bool)
    if not ok and hasattr(value, "dtype") and getattr(value, "ndim", 1) == 0 and value.dtype.kind in "iu":
        value, ok = int(value), True
    if ok and (low is None or value >= low) and (high is None or value <= high):
        return int(value)
    bounds = _bound_text(low, high, False, False)
    suffix = f" (limit {limit})" if limit and ok and high is not None and value > high else ""
    raise error(f"{name} must be a whole number{' ' + bounds if bounds else ''}{suffix}, got {value!r}")


def real(value: Any, name: str, low: float | None = None, high: float | None = None, *, low_open: bool = False,
         high_open: bool = False, unit: str = "", limit: str = "", error: type[SettingsError] = SettingsError) -> float:
    """``value`` as a finite float within the bounds; ints are accepted, bools and strings are not.

    Examples
    --------
    >>> real(45, "--pressure", 0, MAX_PRESSURE_KPA, low_open=True, unit="kPa")
    45.0
    >>> real(float("nan"), "--pressure", 0, low_open=True, unit="kPa")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: --pressure must be a finite number > 0 (kPa), got nan
    """
    ok = isinstance(value, (int, float)) and not isinstance(value, bool)
    if not ok and hasattr(value, "dtype") and getattr(value, "ndim", 1) == 0 and value.dtype.kind in "iuf":
        value, ok = float(value), True
    if ok:
        v = float(value)
        if math.isfinite(v) and (low is None or (v > low if low_open else v >= low)) and (
                high is None or (v < high if high_open else v <= high)):
            return v
    bounds = _bound_text(low, high, low_open, high_open)
    what = f"a finite number{' ' + bounds if bounds else ''}{f' ({unit})' if unit else ''}"
    suffix = f" (limit {limit})" if limit and ok and high is not None and math.isfinite(float(value)) \
        and float(value) > high else ""
    raise error(f"{name} must be {what}{suffix}, got {value!r}")


def flag(value: Any, name: str, error: type[SettingsError] = SettingsError) -> bool:
    """``value`` if it is a bool (``true``/``false`` in TOML), else an error.

    >>> flag(1, "certify")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: certify must be true or false, got 1
    """
    if isinstance(value, bool):
        return value
    raise error(f"{name} must be true or false, got {value!r}")


def text(value: Any, name: str, choices: Iterable[str] | None = None,
         error: type[SettingsError] = SettingsError) -> str:
    """``value`` if it is a non-empty string (one of ``choices`` if given).

    >>> text("", "objective")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: objective must be a non-empty text, got ''
    >>> text("fast", "search", ("ga", "certified"))
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: search must be one of ga, certified, got 'fast'
    """
    if not isinstance(value, str) or not value.strip():
        raise error(f"{name} must be a non-empty text, got {value!r}")
    if choices is not None:
        allowed = tuple(choices)
        if value not in allowed:
            raise error(f"{name} must be one of {', '.join(allowed)}, got {value!r}")
    return value


def pair(value: Any, name: str, unit: str = "", error: type[SettingsError] = SettingsError) -> tuple[float, float]:
    """Two finite numbers (a point, a range).

    >>> pair([1, 2.5], "point")
    (1.0, 2.5)
    """
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise error(f"{name} must be two numbers{f' ({unit})' if unit else ''}, got {value!r}")
    return real(value[0], name, unit=unit, error=error), real(value[1], name, unit=unit, error=error)


def check_volume_steps(volume: float, increments: int, names: tuple[str, str] = ("volume change", "increments"),
                       error: type[Exception] = SettingsError, advice: Callable[[int], str] | None = None) -> None:
    """Refuse a volume-controlled ramp whose steps change the volume by more than :data:`MAX_VOLUME_STEP`.

    Parameters
    ----------
    volume : float
        The ramp's relative volume change ``V / V0 - 1``.
    increments : int
        Its equal steps.
    names : (str, str)
        How the caller names the two settings (``("--volume-change", "--increments")``).
    error : exception class
        Raised with the one-line message (the caller's kind: a settings error, a usage error).
    advice : callable, optional
        ``advice(least_steps)``: what to do instead, in the caller's terms (default: at least that
        many of ``names[1]``).

    Examples
    --------
    >>> check_volume_steps(4.0, 2)
    >>> check_volume_steps(100.0, 1, ("--volume-change", "--increments"))  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: --volume-change 100 over --increments 1 is 100 V0 per step, more than the 2 V0 a
    step can take from rest (MAX_VOLUME_STEP, pneumorph.checks): give at least 50 --increments
    """
    per = float(volume) / max(1, int(increments))
    if per <= MAX_VOLUME_STEP * (1 + 1e-12):
        return
    least = math.ceil(float(volume) / MAX_VOLUME_STEP * (1 - 1e-12))
    todo = advice(least) if advice is not None else f"give at least {least} {names[1]}"
    raise error(f"{names[0]} {float(volume):g} over {names[1]} {int(increments)} is {per:g} V0 per step, more than "
                f"the {MAX_VOLUME_STEP:g} V0 a step can take from rest (MAX_VOLUME_STEP, pneumorph.checks): {todo}")


_SCHEMES = ("tcp", "tls", "ucx", "ws", "wss", "inproc")


def address(value: Any, name: str, error: type[SettingsError] = SettingsError) -> str:
    """A Dask scheduler address ``scheme://host:port`` or ``host:port``, checked for its form only.

    >>> address("tcp://10.0.0.5:8786", "--scheduler")
    'tcp://10.0.0.5:8786'
    >>> address("not a url", "--scheduler")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: --scheduler must be an address like tcp://host:8786, got 'not a url'
    """
    import re

    ok = isinstance(value, str) and re.fullmatch(
        rf"(?:(?:{'|'.join(_SCHEMES)})://)?[A-Za-z0-9_.\-\[\]:]+:\d{{1,5}}", value.strip()) is not None
    if ok and value.startswith("inproc://"):
        return value
    if not ok or not 0 < int(value.rsplit(":", 1)[1]) < 65536:
        raise error(f"{name} must be an address like tcp://host:8786, got {value!r}")
    return value.strip()
