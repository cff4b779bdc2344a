"""Reading what a user gave: one bounded reader for every text input, and the checks of a file before it is opened.

Only a regular file is read (a folder, a device such as ``/dev/zero``, a named pipe or a socket
is refused by name before it is opened, and the file is opened without blocking and checked
again once open), and at most a limit per kind of file: settings (:data:`MAX_SETTINGS_BYTES`),
tables and data (:data:`MAX_TEXT_BYTES`), scans (:data:`MAX_SCAN_BYTES`). Text is UTF-8; a
byte-order mark, as editors on Windows write, is read (UTF-8, UTF-16 or UTF-32), and bytes that
are not UTF-8 are refused with where they are. JSON and TOML are refused past a nesting depth
(their parsers recurse).
"""

from __future__ import annotations

import codecs
import csv
import json
import os
import stat
import tomllib
from collections.abc import Iterable
from pathlib import Path
from typing import Any, BinaryIO

from pneumorph.errors import PneumorphError, SettingsError

#: Largest settings file read (bytes): a design config, a unit, a unit library, a model file, a scan manifest, a
#: material file, a path file (the shipped ones are under 20 kB; a path of MAX_PATH_POINTS is about 60 kB)
MAX_SETTINGS_BYTES = 8 * 2**20

#: Largest text file read as a user's input (bytes): chain tables (the shipped ones are at most 7.3 MB) and test
#: data; settings take :data:`MAX_SETTINGS_BYTES`, scans :data:`MAX_SCAN_BYTES`
MAX_TEXT_BYTES = 64 * 2**20

#: Largest scan read (bytes): a point cloud of about four million points as text
MAX_SCAN_BYTES = 256 * 2**20

#: Most rows of a table of test data (a stress-strain curve, DIC or thermal strains): a test logged at 100 Hz for
#: 33 minutes; the rows are held as text while they are parsed (about 200 bytes each), so more would only cost memory
MAX_DATA_ROWS = 200_000

#: Deepest nesting of tables and arrays a settings file may have (the package's own go 4 deep)
MAX_TOML_DEPTH = 32

#: Deepest nesting of objects and arrays a JSON input may have (the package's chain tables go 5 deep)
MAX_JSON_DEPTH = 32

LIMIT_NAMES = {MAX_SETTINGS_BYTES: "MAX_SETTINGS_BYTES", MAX_TEXT_BYTES: "MAX_TEXT_BYTES",
               MAX_SCAN_BYTES: "MAX_SCAN_BYTES"}

#: Byte-order marks and the codec each one announces (the longest first: UTF-32 LE starts like UTF-16 LE)
BOMS = ((codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"), (codecs.BOM_UTF8, "utf-8-sig"),
        (codecs.BOM_UTF16_LE, "utf-16"), (codecs.BOM_UTF16_BE, "utf-16"))


def _megabytes(size: int) -> str:
    return f"{size / 2**20:.4g} MB"


def _too_big(what: str, p: Path, limit: int, size: int | None = None) -> str:
    name = LIMIT_NAMES.get(limit)
    where = f" ({name}, pneumorph.io.reading)" if name else ""
    have = f"{_megabytes(size)}, more" if size is not None else "more"
    return f"{what} {p}: {have} than the {limit / 2**20:g} MB a {what} may have{where}"


def check_input_file(path: str | Path, what: str, error: type[PneumorphError] = SettingsError,
                     limit: int = MAX_TEXT_BYTES) -> os.stat_result:
    """Refuse a path that is no regular, readable file of at most ``limit`` bytes, without opening it.

    Parameters
    ----------
    path : str or Path
    what : str
        What the file is, named in the message ("scan", "unit file").
    error : PneumorphError subclass
        Raised with the message.
    limit : int
        The most bytes the file may have.

    Returns
    -------
    os.stat_result
        The file's status.

    Raises
    ------
    PneumorphError
        (``error``) missing, a folder, a device, a named pipe or a socket, too large or unreadable.

    Examples
    --------
    >>> check_input_file("/dev/urandom", "scan")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: scan /dev/urandom: not a regular file (a device, a named pipe or a socket);
    give a file
    >>> check_input_file("/nonexistent.stl", "scan")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: scan /nonexistent.stl: no such file
    """
    p = Path(path)
    if str(path).strip() == "":
        raise error(f"{what} is empty; give a file")
    try:
        info = p.stat()
    except FileNotFoundError:
        raise error(f"{what} {p}: no such file") from None
    except OSError as exc:
        raise error(f"{what} {p}: cannot be read ({exc.strerror or exc})") from None
    if stat.S_ISDIR(info.st_mode):
        raise error(f"{what} {p}: is a folder, not a file")
    if not stat.S_ISREG(info.st_mode):
        raise error(f"{what} {p}: not a regular file (a device, a named pipe or a socket); give a file")
    if info.st_size > limit:
        raise error(_too_big(what, p, limit, info.st_size))
    if not os.access(p, os.R_OK):
        raise error(f"{what} {p}: the file is not readable")
    return info


def _open_regular(p: Path, what: str, error: type[PneumorphError]) -> BinaryIO:
    """``p`` opened for reading without blocking (a named pipe with no writer), refused once open unless it is
    still a regular file (it may have been swapped since it was checked); ``OSError`` is the caller's."""
    fh = os.fdopen(os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)), "rb")
    if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
        fh.close()
        raise error(f"{what} {p}: not a regular file (a device, a named pipe or a socket); give a file")
    return fh


def read_bytes_file(path: str | Path, what: str, error: type[PneumorphError] = SettingsError,
                    limit: int = MAX_TEXT_BYTES) -> bytes:
    """The bytes of a regular file of at most ``limit`` bytes (:func:`check_input_file`), read without blocking.

    The file is opened non-blocking and checked again once open, so that a path replaced by a named
    pipe between the check and the opening neither blocks nor is read; a file that reports no size
    (``/proc``) or grew is cut at the limit and refused.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "a.bin"
    >>> _ = p.write_bytes(b"abc")
    >>> read_bytes_file(p, "scan")
    b'abc'
    """
    p = Path(path)
    check_input_file(p, what, error, limit)
    try:
        with _open_regular(p, what, error) as fh:
            data = fh.read(limit + 1)
    except OSError as exc:
        raise error(f"{what} {p}: cannot be read ({exc.strerror or exc})") from None
    if len(data) > limit:
        raise error(_too_big(what, p, limit))
    return data


def _not_utf8(where: str, byte: int, line: int, column: int) -> str:
    return (f"{where}: not UTF-8 text: byte 0x{byte:02x} at line {line}, column {column} (text in another encoding, "
            "such as Latin-1 or Windows-1252: save it as UTF-8; or not a text file)")


def decode_text(data: bytes, where: str, error: type[PneumorphError] = SettingsError, encoding: str = "utf-8",
                errors: str = "strict") -> str:
    """``data`` as text: a byte-order mark's encoding if it has one, else ``encoding``; or one line saying where not.

    ``where`` starts the message ("unit file u.toml").

    Examples
    --------
    >>> decode_text(b"\\xef\\xbb\\xbf[unit]", "unit file u.toml")
    '[unit]'
    >>> decode_text("[unit]".encode("utf-16"), "unit file u.toml")
    '[unit]'
    >>> decode_text(b"[unit]\\nname = 'caf\\xe9'\\n", "unit file u.toml")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: unit file u.toml: not UTF-8 text: byte 0xe9 at line 2, column 12 (text in
    another encoding, such as Latin-1 or Windows-1252: save it as UTF-8; or not a text file)
    """
    for bom, codec in BOMS:
        if data.startswith(bom):
            encoding = codec
            break
    try:
        text = data.decode(encoding, errors)
    except UnicodeDecodeError as exc:
        if encoding.replace("-sig", "").lower() not in ("utf-8", "utf8"):
            raise error(f"{where}: not {encoding.upper()} text (the bytes at {exc.start} are not)") from None
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise error(_not_utf8(where, data[exc.start], line, column)) from None
    return text.removeprefix("\ufeff")


def read_text_file(path: str | Path, what: str, error: type[PneumorphError] = SettingsError,
                   encoding: str = "utf-8", limit: int = MAX_TEXT_BYTES, errors: str = "strict") -> str:
    """The text of a file a user gave, or one line saying why it cannot be read.

    :func:`read_bytes_file`, then :func:`decode_text`: a regular file of at most ``limit`` bytes,
    its byte-order mark read, bytes of another encoding refused with where they are.

    Parameters
    ----------
    path : str or Path
    what : str
        What the file is (named in the message: "unit file", "design config").
    error : PneumorphError subclass
        Raised with the message (the caller's own kind of error).
    encoding, errors : str
        How the bytes are decoded without a byte-order mark (``errors="replace"`` keeps a file with a stray byte).
    limit : int
        The most bytes read (:data:`MAX_TEXT_BYTES`; settings :data:`MAX_SETTINGS_BYTES`).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "b.toml"
    >>> _ = p.write_bytes(b"\\xff\\x00\\x01")
    >>> read_text_file(p, "unit file")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: unit file ...b.toml: not UTF-8 text: byte 0xff at line 1, column 1 ...
    >>> read_text_file("/dev/zero", "design config")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: design config /dev/zero: not a regular file (a device, a named pipe or a
    socket); give a file
    """
    data = read_bytes_file(path, what, error, limit)
    return decode_text(data, f"{what} {Path(path)}", error, encoding, errors)


def check_text_file(path: str | Path, what: str, error: type[PneumorphError] = SettingsError,
                    limit: int = MAX_TEXT_BYTES, chunk: int = 2**20) -> None:
    """Refuse a file that :func:`read_text_file` would refuse, reading it a chunk at a time (memory: one chunk).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "c.csv"
    >>> _ = p.write_bytes(b"x,y\\n" * 10 + b"1,\\x80")
    >>> check_text_file(p, "--data", chunk=7)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: --data ...c.csv: not UTF-8 text: byte 0x80 at line 11, column 3 ...
    """
    p = Path(path)
    check_input_file(p, what, error, limit)
    try:
        with _open_regular(p, what, error) as fh:
            block = fh.read(4)
            codec = next((c for bom, c in BOMS if block.startswith(bom)), "utf-8")
            decoder = codecs.getincrementaldecoder(codec)()
            seen, lines, column = 0, 0, 0  # bytes read, newlines before this block, bytes since the last one
            while block:
                seen += len(block)
                if seen > limit:
                    raise error(_too_big(what, p, limit))
                try:
                    decoder.decode(block)
                except UnicodeDecodeError as exc:
                    if not codec.startswith("utf-8"):
                        raise error(f"{what} {p}: not {codec.upper()} text (its byte-order mark says it is)") from None
                    before = exc.object[:exc.start]
                    last = before.rfind(b"\n")
                    column = (exc.start - last) if last >= 0 else column + exc.start + 1
                    raise error(_not_utf8(f"{what} {p}", exc.object[exc.start], lines + before.count(b"\n") + 1,
                                          column)) from None
                newline = block.rfind(b"\n")
                column = len(block) - newline - 1 if newline >= 0 else column + len(block)
                lines += block.count(b"\n")
                block = fh.read(chunk)
            decoder.decode(b"", final=True)
    except UnicodeDecodeError:
        raise error(f"{what} {p}: not {codec.upper()} text (it ends inside a character)") from None
    except OSError as exc:
        raise error(f"{what} {p}: cannot be read ({exc.strerror or exc})") from None


def read_toml(path: str | Path, what: str, error: type[PneumorphError] = SettingsError,
              limit: int = MAX_SETTINGS_BYTES) -> dict[str, Any]:
    """The tables of a TOML file a user gave, or one line saying why it cannot be read.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "c.toml"
    >>> _ = p.write_text("[design\\nunits = 3")
    >>> read_toml(p, "design config")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: design config ...c.toml: not valid TOML: ...
    """
    return parse_toml(read_text_file(path, what, error, limit=limit), f"{what} {path}", error)


def parse_toml(text: str, where: str, error: type[PneumorphError] = SettingsError) -> dict[str, Any]:
    """The tables of TOML ``text`` a user gave other than as a file (an upload), nested at most
    :data:`MAX_TOML_DEPTH` deep, or one line starting with ``where`` saying why not.

    Examples
    --------
    >>> parse_toml("[unit]\\nlength = 10.5", "the unit file")
    {'unit': {'length': 10.5}}
    >>> parse_toml("a = " + "[" * 40 + "]" * 40, "the unit file")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: the unit file: nested more than 32 levels deep (MAX_TOML_DEPTH)
    """
    # the values at the bottom count as a level of TOML's depth
    data: dict[str, Any] = _parsed(text, where, error, "TOML", MAX_TOML_DEPTH, MAX_TOML_DEPTH - 1)
    return data


def read_json(path: str | Path, what: str, error: type[PneumorphError] = SettingsError,
              limit: int = MAX_TEXT_BYTES) -> Any:
    """The value of a JSON file a user gave (nested at most :data:`MAX_JSON_DEPTH` deep), or one line saying why not.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "deep.json"
    >>> _ = p.write_text("[" * 100_000 + "]" * 100_000)
    >>> read_json(p, "chain table")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: chain table ...deep.json: nested more than 32 levels deep (MAX_JSON_DEPTH)
    """
    return _parsed(read_text_file(path, what, error, limit=limit), f"{what} {path}", error, "JSON",
                   MAX_JSON_DEPTH, MAX_JSON_DEPTH)


def _parsed(text: str, where: str, error: type[PneumorphError], kind: str, depth: int, levels: int) -> Any:
    """``text`` parsed as ``kind`` (TOML or JSON), refused when it nests more than ``levels`` deep."""
    loads, invalid = (tomllib.loads, tomllib.TOMLDecodeError) if kind == "TOML" else (json.loads,
                                                                                     json.JSONDecodeError)
    deep = f"{where}: nested more than {depth} levels deep (MAX_{kind}_DEPTH)"
    try:
        data = loads(text)
    except invalid as exc:
        raise error(f"{where}: not valid {kind}: {exc}") from None
    except RecursionError:
        raise error(deep) from None
    if nested_deeper(data, levels):
        raise error(deep)
    return data


def check_rows(text: str, where: str, error: type[PneumorphError] = SettingsError, limit: int = MAX_DATA_ROWS) -> None:
    """Refuse text of more than ``limit`` lines (counted, not split), before its rows are parsed.

    >>> check_rows("x,y\\n" + "1,2\\n" * 300_000, "data file big.csv")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: data file big.csv: 300,001 rows, more than MAX_DATA_ROWS = 200,000
        (pneumorph.io.reading); thin the data out (one row in 2 keeps 150,001)
    """
    rows = text.count("\n") + (not text.endswith("\n"))
    if rows > limit:
        every = -(-rows // limit)
        raise error(f"{where}: {rows:,} rows, more than MAX_DATA_ROWS = {limit:,} (pneumorph.io.reading); thin the "
                    f"data out (one row in {every} keeps {-(-rows // every):,})")


def csv_rows(lines: Iterable[str], where: str, error: type[PneumorphError] = SettingsError,
             delimiter: str = ",") -> list[list[str]]:
    """The rows of CSV ``lines``, or one line saying which row the csv module could not read.

    A field longer than the csv module's limit (128 kB: a file that is one long line) or a stray quote
    raises ``csv.Error``; here it is ``error``, naming ``where`` and the row.

    >>> csv_rows(["x,y", "1,2"], "scan a.csv")
    [['x', 'y'], ['1', '2']]
    >>> csv_rows(["x,y", "[" * 200_000], "scan a.csv")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: scan a.csv, row 2: not CSV (field larger than field limit (131072))
    """
    reader = csv.reader(lines, delimiter=delimiter)
    rows: list[list[str]] = []
    try:
        for row in reader:
            rows.append(row)
    except csv.Error as exc:
        raise error(f"{where}, row {reader.line_num}: not CSV ({exc})") from None
    return rows


def nested_deeper(data: Any, limit: int) -> bool:
    """Whether tables and lists (dicts and lists) nest deeper than ``limit`` levels, found without recursion.

    >>> nested_deeper({"a": [1, {"b": 2}]}, 3), nested_deeper({"a": [1, {"b": [2]}]}, 3)
    (False, True)
    """
    level, depth = [data], 0
    while level:  # breadth first: the readers of the data recurse
        depth += 1
        if depth > limit:
            return True
        level = [v for item in level if isinstance(item, (dict, list))
                 for v in (item.values() if isinstance(item, dict) else item) if isinstance(v, (dict, list))]
    return False
