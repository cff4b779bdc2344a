"""Writing outputs safely: paths checked before any computation, files replaced atomically,
JSON that is strict JSON.

A result file is either the old one or the complete new one, never half of each: it is
written to a temporary file beside it and renamed over it (``os.replace`` is atomic on one
file system). Output paths are checked up front, without creating anything, so a command
that cannot write its results refuses before it solves.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import shutil
import tempfile
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

from pneumorph.errors import OutputPathError

# the readers of a user's files (their module: pneumorph.io.reading), named here too
from pneumorph.io.reading import MAX_SCAN_BYTES as MAX_SCAN_BYTES
from pneumorph.io.reading import MAX_SETTINGS_BYTES as MAX_SETTINGS_BYTES
from pneumorph.io.reading import MAX_TEXT_BYTES as MAX_TEXT_BYTES
from pneumorph.io.reading import MAX_TOML_DEPTH as MAX_TOML_DEPTH
from pneumorph.io.reading import nested_deeper as nested_deeper
from pneumorph.io.reading import read_text_file as read_text_file
from pneumorph.io.reading import read_toml as read_toml


def _existing_ancestor(path: Path) -> Path:
    probe = path
    while not probe.exists():
        if probe.parent == probe:
            break
        probe = probe.parent
    return probe


def check_writable_dir(path: str | Path, option: str = "--out") -> Path:
    """Refuse a folder that could not be created or written, without creating it.

    Parameters
    ----------
    path : str or Path
        The folder (need not exist).
    option : str
        The CLI option or key that gave it, named in the message.

    Returns
    -------
    Path

    Raises
    ------
    OutputPathError
        ``path`` is empty, is a file, sits under a file, or its nearest existing folder is
        not writable.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> check_writable_dir(d / "new" / "run") == d / "new" / "run"
    True
    >>> (d / "f").write_text("x")
    1
    >>> check_writable_dir(d / "f" / "run")
    Traceback (most recent call last):
    ...
    pneumorph.errors.OutputPathError: --out ...f/run: ...f is a file, not a folder
    """
    if str(path).strip() == "":
        raise OutputPathError(f"{option} is empty; give a folder")
    path = Path(path)
    base = _existing_ancestor(path)
    if not base.is_dir():
        raise OutputPathError(f"{option} {path}: {base} is a file, not a folder")
    if not os.access(base, os.W_OK | os.X_OK):
        raise OutputPathError(f"{option} {path}: {base} is not writable")
    try:  # permissions alone do not tell (root, read-only mounts, /proc and /sys): make and remove a folder there
        os.rmdir(tempfile.mkdtemp(prefix=".pneumorph-probe-", dir=base))
    except OSError as exc:
        raise OutputPathError(f"{option} {path}: nothing can be created in {base} "
                              f"({exc.strerror or type(exc).__name__})") from None
    return path


def check_writable_file(path: str | Path, option: str = "--out") -> Path:
    """Refuse a file that could not be written (a folder, under a file, read-only), creating nothing.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> check_writable_file(d / "sub" / "fig.png", "--plot").name
    'fig.png'
    >>> check_writable_file(d, "--plot")
    Traceback (most recent call last):
    ...
    pneumorph.errors.OutputPathError: --plot ...: is a folder, not a file
    """
    if str(path).strip() == "":
        raise OutputPathError(f"{option} is empty; give a file name")
    path = Path(path)
    if path.is_dir():
        raise OutputPathError(f"{option} {path}: is a folder, not a file")
    if path.exists() and not os.access(path, os.W_OK):
        raise OutputPathError(f"{option} {path}: the file is not writable")
    check_writable_dir(path.parent, option)
    return path


def current_umask() -> int:
    """The process's file-creation mask (read without changing it where the system allows)."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)  # elsewhere: set and restore at once
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path beside ``path`` to write to; renamed over ``path`` if the block succeeds.

    The temporary name ends in ``path``'s suffix, so writers that pick their format from
    the name (matplotlib's ``savefig``) write the right one. If the block fails, the
    temporary file is removed and ``path`` is left as it was. The file gets the mode an
    ordinary ``open`` would give it (0666 less the umask), not the temporary file's 0600,
    so that a shared folder's group can read what a run wrote.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "a.txt"
    >>> with atomic_path(p) as tmp:
    ...     _ = tmp.write_text("done")
    >>> p.read_text(), sorted(f.name for f in p.parent.iterdir())
    ('done', ['a.txt'])
    >>> oct(p.stat().st_mode & 0o777) == oct(0o666 & ~current_umask())
    True
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)  # a new folder given with the file (checked up front)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=f".tmp{path.suffix}", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        if Path(tmp).exists():
            os.chmod(tmp, 0o666 & ~current_umask())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def all_or_nothing(folder: str | Path, say: Callable[[str], None] | None = None,
                   what: str = "the results") -> Iterator[Path]:
    """Create ``folder`` for a command's outputs; if the block fails (an error, Ctrl-C), remove what it added.

    The files and folders that were not there before the block are removed, and the folder itself
    (with any parents this call created) if it was new: a command stopped while writing leaves no
    partial output. A file the block replaced (:func:`atomic_path`) is its new version. With ``say``
    (a command's progress reporter, :class:`~pneumorph.io.progress.Progress`), the line
    ``writing <what> to <folder>`` is said before anything is written: writing figures and VTK files after a
    long solve takes seconds, which a command does not spend silent.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> try:
    ...     with all_or_nothing(d / "new" / "run") as out:
    ...         _ = (out / "a.json").write_text("{}")
    ...         raise KeyboardInterrupt
    ... except KeyboardInterrupt:
    ...     pass
    >>> sorted(p.name for p in d.iterdir())
    []
    >>> with all_or_nothing(d / "run", say=print, what="the response") as out:  # doctest: +ELLIPSIS
    ...     _ = (out / "a.json").write_text("{}")
    writing the response to .../run
    """
    folder = Path(folder)
    if say is not None:
        say(f"writing {what} to {folder}")
    top = folder
    while not top.parent.exists() and top.parent != top:
        top = top.parent
    existed = folder.exists()
    before = set(folder.iterdir()) if existed else set()
    folder.mkdir(parents=True, exist_ok=True)
    try:
        yield folder
    except BaseException:
        if not existed:
            shutil.rmtree(top if top.exists() else folder, ignore_errors=True)
        else:
            for entry in set(folder.iterdir()) - before:
                if entry.is_dir() and not entry.is_symlink():
                    shutil.rmtree(entry, ignore_errors=True)
                else:
                    entry.unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def all_or_nothing_file(path: str | Path, say: Callable[[str], None] | None = None,
                        what: str = "the results") -> Iterator[Path]:
    """A temporary path for ``path``'s new version (:func:`atomic_path`), in place when the block succeeds.

    The one-file counterpart of :func:`all_or_nothing`: if the block fails (an error, Ctrl-C),
    ``path`` is left as it was and the folders made for it are removed. Nested with
    :func:`all_or_nothing`, the file appears only once the whole block has succeeded. With ``say``,
    the line ``writing <what> to <path>`` is said first, as :func:`all_or_nothing` says it.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> try:
    ...     with all_or_nothing_file(d / "new" / "deck.inp") as tmp:
    ...         _ = tmp.write_text("*HEADING")
    ...         raise KeyboardInterrupt
    ... except KeyboardInterrupt:
    ...     pass
    >>> sorted(p.name for p in d.iterdir())
    []
    >>> with all_or_nothing_file(d / "deck.inp", say=print, what="the deck") as tmp:  # doctest: +ELLIPSIS
    ...     _ = tmp.write_text("*HEADING")
    writing the deck to .../deck.inp
    """
    path = Path(path)
    if say is not None:
        say(f"writing {what} to {path}")
    with contextlib.ExitStack() as stack:
        if not path.parent.exists():
            stack.enter_context(all_or_nothing(path.parent))
        yield stack.enter_context(atomic_path(path))


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file and a rename (:func:`atomic_path`).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "a.bin"
    >>> atomic_write_bytes(p, b"abc").read_bytes()
    b'abc'
    """
    with atomic_path(path) as tmp, tmp.open("wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())
    return Path(path)


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically (see :func:`atomic_write_bytes`)."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def _reason(value: float) -> str:
    return "not a number" if math.isnan(value) else ("+infinite" if value > 0 else "-infinite")


def json_safe(obj: Any) -> Any:
    """``obj`` with every NaN or infinite float replaced by None (numpy scalars and arrays too).

    In a mapping, a replaced value ``key`` gets a sibling ``key_reason`` saying what it was,
    so the reader knows why it is null.

    Examples
    --------
    >>> json_safe({"fitness": float("nan"), "tip": [1.0, float("inf")]})
    {'fitness': None, 'fitness_reason': 'not a number', 'tip': [1.0, None]}
    """
    if isinstance(obj, bool) or obj is None or isinstance(obj, (str, int)):
        return obj
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, Mapping):
        out: dict[str, Any] = {}
        for key, value in obj.items():
            clean = json_safe(value)
            out[str(key)] = clean
            if clean is None and _is_float(value):
                out[f"{key}_reason"] = _reason(float(value))
        return out
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if hasattr(obj, "tolist"):  # numpy arrays and scalars
        return json_safe(obj.tolist())
    if isinstance(obj, Path):
        return str(obj)
    return str(obj)


def _is_float(value: Any) -> bool:
    try:
        return isinstance(value, float) or (hasattr(value, "dtype") and value.dtype.kind == "f" and value.ndim == 0)
    except AttributeError:
        return False


def strict_json(obj: Any, indent: int | None = 1) -> str:
    """Strict JSON (no NaN, no Infinity): :func:`json_safe`, then ``json.dumps(allow_nan=False)``.

    Examples
    --------
    >>> strict_json({"value": float("inf")}, indent=None)
    '{"value": null, "value_reason": "+infinite"}'
    """
    return json.dumps(json_safe(obj), indent=indent, allow_nan=False)


def write_json(path: str | Path, obj: Any, indent: int | None = 1) -> Path:
    """Write :func:`strict_json` of ``obj`` to ``path`` atomically."""
    return atomic_write_text(path, strict_json(obj, indent=indent) + "\n")
