"""Exception types raised by pneumorph.

Every error a user can cause derives from :class:`PneumorphError`, so a caller can catch
them all at once; each subclass also derives from the built-in exception that describes
it best (``ValueError``, ``KeyError``), so generic handlers keep working.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

# Ctrl-C presses the command line has seen (cli.main's SIGINT handler counts them). Some libraries
# import their optional parts under ``except BaseException`` (trimesh), which swallows a Ctrl-C that
# lands there; the count tells that one came.
_SIGINTS = [0]


def note_sigint() -> None:
    """Count a Ctrl-C (called by the command line's SIGINT handler before it raises KeyboardInterrupt)."""
    _SIGINTS[0] += 1


def sigints() -> int:
    """How many Ctrl-C presses the command line has seen."""
    return _SIGINTS[0]


@contextlib.contextmanager
def interrupts_kept() -> Iterator[None]:
    """Raise KeyboardInterrupt after the block if a Ctrl-C came during it and was swallowed.

    Wrap the lazy import of a library that catches ``BaseException`` around its own imports, so
    that a Ctrl-C during it stops the run there, as anywhere else.

    Examples
    --------
    >>> try:
    ...     with interrupts_kept():
    ...         note_sigint()  # a Ctrl-C that a library swallowed
    ... except KeyboardInterrupt:
    ...     print("stopped")
    stopped
    """
    before = _SIGINTS[0]
    yield
    if _SIGINTS[0] != before:
        raise KeyboardInterrupt


class PneumorphError(Exception):
    """Base class of all errors raised on purpose by pneumorph."""


class UnknownNameError(PneumorphError, KeyError):
    """A name that is not among the known ones; ``known`` lists them for the message.

    Parameters
    ----------
    name : str
        The name that was asked for.
    known : sequence of str
        The names that exist.
    """

    what = "name"

    def __init__(self, name: str, known: list[str] | tuple[str, ...]) -> None:
        self.name = name
        self.known = tuple(known)
        super().__init__(name)

    def __str__(self) -> str:
        return f"unknown {self.what} {self.name!r}; known {self.what}s: {', '.join(self.known)}"


class UnknownMaterialError(UnknownNameError):
    """A material name that is not in the library.

    Parameters
    ----------
    name : str
        The name that was asked for.
    known : sequence of str
        The names the library holds; listed in the message.
    """

    what = "material"


class UnknownModelError(UnknownNameError):
    """A constitutive model name that pneumorph does not implement."""

    what = "model"


class DataFormatError(PneumorphError, ValueError):
    """Test data that cannot be read: wrong columns, NaN, non-monotonic stretch, ...

    The message names the file, the row (1-based, as a text editor shows it) and what was
    expected.
    """

    def __init__(self, message: str, path: str | None = None, row: int | None = None) -> None:
        self.path = path
        self.row = row
        where = ""
        if path is not None:
            where = f"{path}"
            if row is not None:
                where += f", row {row}"
            where += ": "
        super().__init__(where + message)


class MaterialDataError(PneumorphError, ValueError):
    """A material definition (library or user TOML) that is incomplete or inconsistent."""


class FitError(PneumorphError, RuntimeError):
    """A model fit that could not be carried out (too few points, optimiser failure)."""


class PressureRangeError(PneumorphError, ValueError):
    """A pressure outside the range in which a pressure-dependent law was calibrated.

    Parameters
    ----------
    pressure : float
        The pressure asked for, in MPa.
    lower, upper : float
        The calibrated range, in MPa.
    what : str
        What the range belongs to (named in the message).
    """

    def __init__(self, pressure: float, lower: float, upper: float, what: str = "law") -> None:
        self.pressure = pressure
        self.lower = lower
        self.upper = upper
        super().__init__(
            f"pressure {pressure * 1e3:.6g} kPa is outside the calibrated range "
            f"{lower * 1e3:.6g}-{upper * 1e3:.6g} kPa of the {what}; "
            "recalibrate the law for this range instead of extrapolating"
        )


class SimulationFailed(PneumorphError, RuntimeError):
    """A finite-element solve that did not converge.

    Parameters
    ----------
    reached : float
        The last converged load factor (0 = unloaded, 1 = the full load).
    cause : str
        Why it stopped (e.g. Newton did not converge after the allowed cut-backs).
    design : str, optional
        The orientation vector of the design, as a string of digits.
    pressure : float, optional
        The full pressure of the ramp, in MPa; the message then names the pressure reached.
    partial : Response, optional
        What was solved before the failure: the converged levels, NaN after them.
    """

    def __init__(
        self, reached: float, cause: str, design: str | None = None, pressure: float | None = None,
        partial: object = None,
    ) -> None:
        self.partial = partial
        self.reached = reached
        self.cause = cause
        self.design = design
        self.pressure = pressure
        what = f"design {design}: " if design else ""
        if pressure is not None:
            where = f"converged up to {reached * pressure * 1e3:.4g} kPa of {pressure * 1e3:.4g} kPa"
        else:
            where = f"converged up to load factor {reached:.4g}"
        super().__init__(f"{what}simulation failed, {where}: {cause}")


class LimitPointError(SimulationFailed):
    """A load ramp stopped because its monitored quantity fell under a larger load: a limit point.

    Along a stable, rising pressure ramp the cavity volume (the work-conjugate of the pressure)
    cannot fall; a substep that converges to a smaller one has passed a maximum of the load the
    body holds, which no load-controlled ramp can follow. The ramp raises this kind of failure
    (the last cut-back still fell), so that a model can say what it means in its own terms.

    Parameters
    ----------
    reached : float
        The last converged load factor.
    cause : str
        Why it stopped, as :class:`SimulationFailed` says it.
    design, pressure, partial : optional
        As :class:`SimulationFailed`.
    before, after : float
        The monitored quantity at the last converged state and at the substep that fell.
    tried : float
        The load factor of the last substep tried.
    cutbacks : int
        The cut-backs allowed per substep (all used).

    Examples
    --------
    >>> exc = LimitPointError(0.5, "the monitored quantity fell", before=10.0, after=9.9, tried=0.52, cutbacks=6)
    >>> isinstance(exc, SimulationFailed), exc.before - exc.after
    (True, 0.09999999999999964)
    """

    def __init__(
        self, reached: float, cause: str, design: str | None = None, pressure: float | None = None,
        partial: object = None, *, before: float, after: float, tried: float, cutbacks: int,
    ) -> None:
        self.before = before
        self.after = after
        self.tried = tried
        self.cutbacks = cutbacks
        super().__init__(reached, cause, design=design, pressure=pressure, partial=partial)


class UnknownDatasetError(UnknownNameError):
    """A name that is neither a readable data file nor a bundled test-data set."""

    def __str__(self) -> str:
        return (
            f"no data file or bundled data set named {self.name!r}; "
            f"bundled data sets: {', '.join(self.known) or 'none'}"
        )


class OrientationError(PneumorphError, ValueError):
    """An orientation vector that is not a string of 0/1 digits of the expected length."""


class GeometryError(PneumorphError, ValueError):
    """A unit or actuator geometry that cannot be built (non-positive sizes, no cavity, ...)."""


class UnitLibraryError(GeometryError):
    """A unit library that cannot serve: a bad or repeated symbol, an unknown key, a unit that
    does not validate, or two units whose sections cannot be joined in one mesh."""


class CrimpError(PneumorphError, ValueError):
    """A crimp or composite coupon that cannot exist (non-positive amplitude, wavelength
    longer than the coupon, crimp deeper than the matrix, ...)."""


class TargetExpressionError(PneumorphError, ValueError):
    """A target expression that is not allowed: unknown names, attribute access, huge powers, ...

    The message quotes the offending part and its column (1-based).
    """


class UnknownObjectiveError(UnknownNameError):
    """An objective name that is neither a tip goal nor a target preset."""

    def __str__(self) -> str:
        return (
            f"unknown objective {self.name!r}; known objectives: {', '.join(self.known)}, "
            "or a profile 'y = f(x)' / 'r = f(theta)' / 'y = f(x), z = g(x)'"
        )


class SettingsError(PneumorphError, ValueError):
    """A setting that cannot work: wrong type, out of range, not finite, beyond a limit.

    Raised where the setting enters (CLI option, config key, API constructor); the message
    names the option or key, the value given and what is allowed.
    """


class SearchConfigError(SettingsError):
    """Design-search settings that cannot work (population below 2, no units, ...)."""


class SearchBudgetError(SearchConfigError):
    """The certified search's branch-and-bound past its budget of open prefixes (``[design] max_open``, or the
    memory they would take): the chain table's bound is too loose to prune. The message names the bound and what
    to do (a tighter table, a larger cap, or the genetic algorithm)."""


class EvaluationError(PneumorphError, RuntimeError):
    """A model that raised something other than SimulationFailed while evaluating a design."""


class SchedulerUnreachableError(PneumorphError, ConnectionError):
    """A Dask scheduler address that could not be reached within the timeout."""


class ClusterLostError(PneumorphError, ConnectionError):
    """The Dask cluster went away during a run: the scheduler, or every worker for too long.

    Nothing finished is lost (every solve was stored in the evaluation cache as it
    arrived); the same command resumes. The command line exits with ``exit_code`` (3)
    and appends the command that resumes.
    """

    exit_code = 3


class WorkerVersionError(PneumorphError, RuntimeError):
    """Dask workers that run another pneumorph (or none): refused at connect, naming both versions."""


class RunFolderError(PneumorphError, ValueError):
    """A run folder that holds a different run, is in use by another run, or cannot be written."""


class OutputPathError(PneumorphError, OSError):
    """An output file or folder that cannot be created or written."""


class CacheError(PneumorphError, RuntimeError):
    """An evaluation cache that cannot serve: damaged, not a cache, a folder, or read-only."""


class ChainTableError(PneumorphError, ValueError):
    """A chain table that cannot serve: damaged, of another model, or too wide a window."""


class MissingTableError(ChainTableError):
    """A table a run needs is neither shipped nor kept, and the run may not build it (``--no-build``).

    The message names the table and how to build it.
    """


class LocalityError(SearchConfigError):
    """The chain model cannot represent this model (gravity, or units that interact further)."""


class ScanError(PneumorphError, ValueError):
    """A scan that cannot be compared with a model: unreadable, empty, too few points, wrong units."""


class JobLimitError(PneumorphError, RuntimeError):
    """A background job the bench refuses: the session or the bench has as many jobs queued or
    running as it may, or the bench is stopping. The message names the limit and its option."""


class StateQuotaError(JobLimitError):
    """The bench's state folder is past its disk quota even without its finished jobs."""


class BodyTooLargeError(PneumorphError, ValueError):
    """A request body past the bench's limit, counted as it arrives (whatever its Content-Length says).

    Parameters
    ----------
    limit : int
        The limit in bytes (named in the message).
    """

    def __init__(self, limit: int) -> None:
        self.limit = limit
        super().__init__(f"requests are limited to {limit:,} bytes here")
