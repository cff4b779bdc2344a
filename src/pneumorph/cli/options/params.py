"""Click parameter types that parse the command line's text and check it with :mod:`pneumorph.checks`.

A value is refused while the command line is read, before anything is computed, with the
option's name in the message: ``--pressure must be a finite number > 0 (kPa), got nan``.

A command's options are built when its module is imported, also for ``--help``: this module
imports :mod:`pneumorph.io`'s file checks (and NumPy with them) only when a file option is
parsed.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from pneumorph import checks
from pneumorph.errors import OutputPathError, PneumorphError, SettingsError

if TYPE_CHECKING:
    from pneumorph.geometry.library import UnitLibrary


def _name(param: click.Parameter | None) -> str:
    if param is None:
        return "value"
    opts = [o for o in getattr(param, "opts", []) if o.startswith("--")]
    return opts[0] if opts else (param.human_readable_name if param.param_type_name == "option" else
                                 (param.name or "value").upper())


class Real(click.ParamType):
    """A finite number within bounds (``nan``, ``inf`` and text refused)."""

    name = "number"

    def __init__(self, low: float | None = None, high: float | None = None, *, low_open: bool = False,
                 high_open: bool = False, unit: str = "", limit: str = "") -> None:
        self.kw = dict(low=low, high=high, low_open=low_open, high_open=high_open, unit=unit, limit=limit)

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> float:
        number = value
        if isinstance(value, str):
            try:
                number = float(value)
            except ValueError:
                number = value
        try:
            return checks.real(number, _name(param), **self.kw)  # type: ignore[arg-type]
        except SettingsError as exc:
            self.fail(str(exc), param, ctx)


class Count(click.ParamType):
    """A whole number within bounds (``1.5``, ``true`` and text refused)."""

    name = "integer"

    def __init__(self, low: int | None = None, high: int | None = None, limit: str = "") -> None:
        self.low, self.high, self.limit = low, high, limit

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> int:
        number = value
        if isinstance(value, str):
            try:
                number = int(value.strip())
            except ValueError:
                number = value
        try:
            return checks.integer(number, _name(param), self.low, self.high, self.limit)
        except SettingsError as exc:
            self.fail(str(exc), param, ctx)


class RealList(click.ParamType):
    """Comma-separated finite numbers within bounds (at least one, or ``min_items``)."""

    name = "list"

    def __init__(self, item: click.ParamType, min_items: int = 1, max_items: int = checks.MAX_STARTS) -> None:
        self.item, self.min_items, self.max_items = item, min_items, max_items

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> list[Any]:
        if isinstance(value, (list, tuple)):
            return list(value)
        parts = [p.strip() for p in str(value).split(",")]
        if any(p == "" for p in parts) or not (self.min_items <= len(parts) <= self.max_items):
            self.fail(f"{_name(param)} must be {self.min_items} to {self.max_items} comma-separated values, "
                      f"got {value!r}", param, ctx)
        return [self.item.convert(p, param, ctx) for p in parts]


class Text(click.ParamType):
    """A non-empty text (blank refused)."""

    name = "text"

    def __init__(self, max_length: int = 10_000) -> None:
        self.max_length = max_length

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> str:
        if not isinstance(value, str) or not value.strip():
            self.fail(f"{_name(param)} must not be empty", param, ctx)
        if len(value) > self.max_length:
            self.fail(f"{_name(param)} is {len(value)} characters long; at most {self.max_length} allowed",
                      param, ctx)
        return value


class InputFile(click.ParamType):
    """An existing, readable regular file of at most ``limit`` bytes; ``text=True`` also requires text (UTF-8, or
    with a byte-order mark), checked a chunk at a time: the command's own reader then applies its kind's limit.

    A folder, a device (``/dev/zero``), a named pipe or a socket is refused by name without being opened."""

    name = "file"

    def __init__(self, text: bool = True, limit: int | None = None) -> None:
        self.text = text
        self.limit = limit

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> str:
        from pneumorph.io.reading import MAX_SCAN_BYTES, MAX_TEXT_BYTES, check_input_file, check_text_file

        name = _name(param)
        if str(value).strip() == "":
            self.fail(f"{name} must not be empty", param, ctx)
        limit = self.limit if self.limit is not None else (MAX_TEXT_BYTES if self.text else MAX_SCAN_BYTES)
        try:
            if self.text:
                check_text_file(value, name, limit=limit)
            else:
                check_input_file(value, name, limit=limit)
        except PneumorphError as exc:
            self.fail(str(exc), param, ctx)
        return str(value)


class OutputDir(click.ParamType):
    """A folder that can be created or written (checked, not created)."""

    name = "dir"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> str:
        from pneumorph.io.files import check_writable_dir

        try:
            check_writable_dir(value, _name(param))
        except OutputPathError as exc:
            self.fail(str(exc), param, ctx)
        return str(value)


class OutputFile(click.ParamType):
    """A file that can be written (checked, not created)."""

    name = "file"

    def __init__(self, suffixes: tuple[str, ...] = ()) -> None:
        self.suffixes = suffixes

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> str:
        from pneumorph.io.files import check_writable_file

        try:
            check_writable_file(value, _name(param))
        except OutputPathError as exc:
            self.fail(str(exc), param, ctx)
        if self.suffixes and Path(value).suffix.lower() not in self.suffixes:
            self.fail(f"{_name(param)} {value}: the file name must end in {' or '.join(self.suffixes)}", param, ctx)
        return str(value)


class CacheFile(click.ParamType):
    """The evaluation cache: a file (existing or to be created) in a writable folder, not a folder."""

    name = "file"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> str:
        from pneumorph.io.files import check_writable_dir

        name = _name(param)
        if str(value).strip() == "":
            self.fail(f"{name} must not be empty", param, ctx)
        if Path(value).is_dir():
            self.fail(f"{name} {value}: is a folder; give the cache's file (e.g. {Path(value) / 'evaluations.sqlite'})",
                      param, ctx)
        try:
            check_writable_dir(Path(value).parent, name)
        except OutputPathError as exc:
            self.fail(str(exc), param, ctx)
        return str(value)


PRESSURE_KPA = Real(0.0, checks.MAX_PRESSURE_KPA, low_open=True, unit="kPa", limit="MAX_PRESSURE_KPA")
UNITS = Count(1, checks.MAX_UNITS, limit="MAX_UNITS")
INCREMENTS = Count(1, checks.MAX_INCREMENTS, limit="MAX_INCREMENTS")
WORKERS = Count(1, 1024)
SEED = Count(0, 2**32 - 1)
POSITIVE_MM = Real(0.0, 1e4, low_open=True, unit="mm")


class Address(click.ParamType):
    """A Dask scheduler address: ``tcp://host:port`` (or ``host:port``, tls://, inproc://)."""

    name = "address"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> str:
        try:
            return checks.address(value, _name(param))
        except SettingsError as exc:
            self.fail(str(exc), param, ctx)


ADDRESS = Address()


class Delimiter(click.ParamType):
    """One column separator character (``\\t`` for a tab)."""

    name = "char"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> str:
        text = "\t" if value in ("\\t", "\t", "tab") else value
        if not isinstance(text, str) or len(text) != 1 or text in "\r\n\"'.0123456789-+eE":
            self.fail(f"{_name(param)} must be one separator character (',', ';', '\\t', ' ', ...), got {value!r}",
                      param, ctx)
        return text


DELIMITER = Delimiter()


@contextlib.contextmanager
def blame(option: str) -> Iterator[None]:
    """Report a pneumorph error raised inside as a bad value of ``option`` (usage error, exit 2).

    For values checked by the package rather than by their type (a target expression, a
    unit file), so that the message names the option the user typed.
    """
    try:
        yield
    except PneumorphError as exc:
        raise click.BadParameter(" ".join(str(exc).split()), param_hint=f"'{option}'") from None


def library_option(library: str, unit_file: str | None) -> UnitLibrary:
    """The :class:`~pneumorph.geometry.library.UnitLibrary` that ``--library`` names (``builtin`` or a
    library file), refused as a usage error beside ``--unit`` or when it is no valid library."""
    from pneumorph.models.factory import load_unit_library

    if unit_file is not None:
        raise click.UsageError("give either --unit or --library, not both")
    with blame("--library"):
        return load_unit_library(library, "unit library")


def unit_option(unit_file: str) -> None:
    """Refuse a ``--unit`` file that is no valid unit as a usage error naming ``--unit``, before any model is built
    (the model factory would name its own key, ``[model] unit_file``)."""
    from pneumorph.geometry.unit import UnitSpec

    with blame("--unit"):
        UnitSpec.from_toml(unit_file)


#: ``--model-file``'s help, the same for every command that takes it
MODEL_FILE_HELP = ("A model's [model] table (an identified model, identified.toml from pneumorph identify): its unit, "
                   "material scales and fidelity; options given on the command line win.")


def model_file_option(settings: dict[str, Any], model_file: str | None, options: dict[str, str]) -> dict[str, Any]:
    """The model settings of a command with ``--model-file``: the file's ``[model]`` table over ``settings``,
    except the keys whose option (``options``: setting key -> parameter name) was typed on the command line, and
    its unit when ``settings`` name one (``unit_file`` or ``library``)."""
    if model_file is None:
        return settings
    from pneumorph.models.factory import read_model_file

    with blame("--model-file"):
        table = read_model_file(model_file)
    source = click.get_current_context().get_parameter_source
    typed = {key for key, param in options.items() if source(param) == click.core.ParameterSource.COMMANDLINE}
    if {"unit_file", "library"} & set(settings):
        table = {k: v for k, v in table.items() if k not in ("unit", "unit_file", "library")}
    return {**settings, **{k: v for k, v in table.items() if k not in typed}}


def scan_unit(unit: str | None, scale: float | None) -> str:
    """The unit of a scan's coordinates from ``--scan-unit`` (mm if not given), refused beside ``--scale``, which says
    the same another way."""
    if unit is not None and scale is not None:
        raise click.UsageError("give --scan-unit or --scale, not both (--scale is the mm per unit of the scan)")
    return unit or "mm"
