"""Locks on files, so that two processes never write the same thing at once.

A lock is a file (a run folder's ``.pneumorph.lock``, a chain table's ``<table>.lock``)
holding the process id, the host and the start time (UTC) of the process that holds it, one
``key=value`` a line. Where the operating system offers ``fcntl.flock`` (Linux, macOS, the
BSDs) the file is locked with ``LOCK_EX | LOCK_NB``: the lock belongs to the open file, so
the operating system releases it when the process ends in any way (even ``kill -9``) and a
lock file left behind by a dead process is no obstacle - the next one takes it over.
Elsewhere the lock is the exclusive creation of the file; a lock file of a process that no
longer runs on this host is then recognised by its process id and removed.

Releasing the lock removes the file (while still holding it: a process that opened the old
file in that instant sees that it was replaced and tries again).

:class:`FileLock` is the mechanism; it either refuses a lock that another process holds or,
with ``wait=True``, waits for it (saying once whom it waits for). :class:`RunLock` holds a
run folder for one run and refuses a second one.

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> with RunLock(folder) as lock:
...     (folder / ".pneumorph.lock").exists(), lock.held
(True, True)
>>> (folder / ".pneumorph.lock").exists()
False
>>> table = FileLock(folder / "table.json.lock", "chain table table.json")
>>> table.acquire(wait=True).held, FileLock.read(table.path)["pid"] == str(os.getpid())
(True, True)
>>> table.release()
"""

from __future__ import annotations

import contextlib
import errno
import os
import socket
import sys
import time
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path
from typing import Self

from pneumorph.errors import OutputPathError, PneumorphError, RunFolderError
from pneumorph.io.reading import read_text_file

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

LOCK_NAME = ".pneumorph.lock"
_BUSY = {errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK}
#: seconds between two looks at a lock that a waiting process wants
POLL_SECONDS = 0.25


def describe_holder(info: dict[str, str]) -> str:
    """The holder of a lock as text: ``pid 12 on host, started 2026-...`` (from :meth:`FileLock.read`).

    >>> describe_holder({"pid": "1", "host": "h", "started": "s"})
    'pid 1 on h, started s'
    """
    pid = info.get("pid", "?")
    host = info.get("host", "?")
    started = info.get("started", "?")
    me = " - this process" if pid == str(os.getpid()) and host == socket.gethostname() else ""
    return f"pid {pid} on {host}, started {started}{me}"


def _pid_alive(pid: int) -> bool | None:
    """Whether process ``pid`` of this host runs (None if it cannot be told)."""
    if pid <= 0:
        return None
    if sys.platform == "win32":  # pragma: no cover - Windows: os.kill would terminate it
        try:
            import ctypes

            kernel32 = ctypes.windll.kernel32  # type: ignore[attr-defined]
            handle = kernel32.OpenProcess(0x1000, False, pid)  # PROCESS_QUERY_LIMITED_INFORMATION
            if not handle:
                return False
            try:
                code = ctypes.c_ulong()
                if not kernel32.GetExitCodeProcess(handle, ctypes.byref(code)):
                    return None
                return code.value == 259  # STILL_ACTIVE
            finally:
                kernel32.CloseHandle(handle)
        except Exception:  # cannot tell: treated as running
            return None
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except OSError:
        return None
    return True


class FileLock:
    """An exclusive lock held as the file ``path``: a context manager (or :meth:`acquire` / :meth:`release`).

    Parameters
    ----------
    path : str or Path
        The lock file; its folder must exist.
    what : str, optional
        What the lock guards, for messages (default: the lock file).

    Raises
    ------
    OutputPathError
        On acquiring without waiting, if another process holds the lock (naming its pid,
        host and start); or if the lock file cannot be written.
    """

    #: the error of a lock that is busy or cannot be written
    error: type[PneumorphError] = OutputPathError

    def __init__(self, path: str | Path, what: str | None = None) -> None:
        self.path = Path(path)
        self.what = what or str(self.path)
        self._fd: int | None = None
        self._created = False

    @property
    def held(self) -> bool:
        """True while this object holds the lock."""
        return self._fd is not None or self._created

    @staticmethod
    def read(path: str | Path) -> dict[str, str]:
        """What the lock file ``path`` says (pid, host, started); empty if none or unreadable."""
        try:  # the one bounded reader: a named pipe or a device in the lock's place is not waited on
            text = read_text_file(path, "lock file", RunFolderError, limit=2**16, errors="replace")
        except RunFolderError:
            return {}
        info = {}
        for line in text.splitlines():
            key, sep, value = line.partition("=")
            if sep:
                info[key.strip()] = value.strip()
        return info

    def holder_text(self) -> str:
        """Who holds the lock now, as text (or that its pid is not written yet)."""
        info = self.read(self.path)
        return describe_holder(info) if info else "its pid is not written yet"

    def _busy(self, exclusive: bool = False) -> PneumorphError:
        return self.error(f"{self.what} is locked by another process ({self.holder_text()})")

    def _cannot(self, exc: OSError) -> PneumorphError:
        return self.error(f"{self.what}: cannot write its lock file {self.path} ({exc.strerror or exc})")

    def _content(self) -> bytes:
        started = datetime.now(UTC).isoformat(timespec="seconds")
        return f"pid={os.getpid()}\nhost={socket.gethostname()}\nstarted={started}\n".encode()

    def acquire(self, wait: bool = False, on_wait: Callable[[str], None] | None = None) -> Self:
        """Take the lock; returns self.

        Parameters
        ----------
        wait : bool
            If another process holds the lock, wait until it gives it back (looking every
            :data:`POLL_SECONDS`) instead of refusing it.
        on_wait : callable, optional
            Called once, with the holder as text (:func:`describe_holder`), when the lock has
            to be waited for.
        """
        if self.held:
            raise self.error(f"{self.what} is already held by this lock")
        looks = 0
        while True:
            taken = self._try_flock() if fcntl is not None else self._try_exclusive()
            if taken:
                return self
            if not wait:
                raise self._busy(exclusive=fcntl is None)
            # said once, as soon as the holder has written its name (or after a second without it)
            if on_wait is not None and looks >= 0 and (self.read(self.path) or looks >= 4):
                on_wait(self.holder_text())
                looks = -1
            elif looks >= 0:
                looks += 1
            time.sleep(POLL_SECONDS)

    def _try_flock(self) -> bool:
        """Take the lock if it is free (True); False if another process holds it."""
        for _ in range(100):
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as exc:
                raise self._cannot(exc) from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                os.close(fd)
                if exc.errno in _BUSY:
                    return False
                raise self._cannot(exc) from None
            try:
                same = os.stat(self.path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if not same:  # released and removed by its holder while we opened it: take the new one
                os.close(fd)
                continue
            try:
                os.ftruncate(fd, 0)
                os.write(fd, self._content())
                os.fsync(fd)
            except OSError as exc:
                os.close(fd)
                raise self._cannot(exc) from None
            self._fd = fd
            return True
        raise self.error(f"{self.what}: its lock file {self.path} keeps being replaced; try again")

    def _try_exclusive(self) -> bool:
        """As :meth:`_try_flock`, by the exclusive creation of the file (a stale file of a dead process is removed)."""
        for _ in range(2):
            try:
                fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
            except FileExistsError:
                info = self.read(self.path)
                stale = False
                if info.get("host") == socket.gethostname() and info.get("pid", "").isdigit():
                    stale = _pid_alive(int(info["pid"])) is False
                if not stale:
                    return False
                self.path.unlink(missing_ok=True)  # its process is gone
                continue
            except OSError as exc:
                raise self._cannot(exc) from None
            try:
                os.write(fd, self._content())
            finally:
                os.close(fd)
            self._created = True
            return True
        return False

    def release(self) -> None:
        """Give the lock back and remove the lock file (nothing if not held)."""
        if self._fd is not None:
            fd, self._fd = self._fd, None
            try:
                if os.stat(self.path).st_ino == os.fstat(fd).st_ino:
                    self.path.unlink()
            except OSError:
                pass
            finally:
                os.close(fd)  # closing releases the flock
        elif self._created:
            self._created = False
            self.path.unlink(missing_ok=True)

    def __enter__(self) -> Self:
        self.acquire()
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    def __del__(self) -> None:  # pragma: no cover - a lock object dropped without release
        with contextlib.suppress(Exception):  # nothing to release at interpreter shutdown
            self.release()


class RunLock(FileLock):
    """Hold a run folder for one run: a context manager (or :meth:`acquire` / :meth:`release`).

    Parameters
    ----------
    folder : str or Path
        The run folder; it must exist.

    Raises
    ------
    RunFolderError
        On entering, if another run (of this or another process) holds the folder, naming
        the folder and the holder's pid, host and start; or if the lock file cannot be
        written.
    """

    error = RunFolderError

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)
        super().__init__(self.folder / LOCK_NAME, f"run folder {self.folder}")

    @staticmethod
    def holder(folder: str | Path) -> dict[str, str]:
        """What the lock file of ``folder`` says (pid, host, started); empty if none or unreadable."""
        return FileLock.read(Path(folder) / LOCK_NAME)

    def _busy(self, exclusive: bool = False) -> PneumorphError:
        info = self.holder(self.folder)
        if exclusive:
            return RunFolderError(
                f"run folder {self.folder} is in use by another run ({describe_holder(info) if info else '?'}); "
                f"wait for it to end, or remove {self.path} if that run is over")
        who = describe_holder(info) if info else "its pid is not written yet"
        return RunFolderError(f"run folder {self.folder} is in use by another run ({who}); wait for it to end "
                              "or choose another output folder")

    def _cannot(self, exc: OSError) -> PneumorphError:
        return RunFolderError(f"run folder {self.folder}: cannot write its lock file ({exc.strerror or exc})")
