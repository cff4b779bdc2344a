"""A lock on a run folder, so that two runs never write into the same folder at once.

The lock is a file ``.pneumorph.lock`` in the folder holding the process id, the host and
the start time (UTC) of the run that holds it, one ``key=value`` a line. Where the
operating system offers ``fcntl.flock`` (Linux, macOS, the BSDs) the file is locked with
``LOCK_EX | LOCK_NB``: the lock belongs to the open file, so the operating system releases
it when the process ends in any way (even ``kill -9``) and a lock file left behind by a
dead run is no obstacle - the next run takes it over. Elsewhere the lock is the exclusive
creation of the file; a lock file of a process that no longer runs on this host is then
recognised by its process id and removed.

Releasing the lock removes the file (while still holding it: a run that opened the old
file in that instant sees that it was replaced and tries again).

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> with RunLock(folder) as lock:
...     (folder / ".pneumorph.lock").exists(), lock.held
(True, True)
>>> (folder / ".pneumorph.lock").exists()
False
"""

from __future__ import annotations

import contextlib
import errno
import os
import socket
import sys
from datetime import UTC, datetime
from pathlib import Path
from typing import Self

from pneumorph.errors import RunFolderError

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

LOCK_NAME = ".pneumorph.lock"
_BUSY = {errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK}


def _describe(info: dict[str, str]) -> str:
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


class RunLock:
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

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)
        self.path = self.folder / LOCK_NAME
        self._fd: int | None = None
        self._created = False

    @property
    def held(self) -> bool:
        """True while this object holds the lock."""
        return self._fd is not None or self._created

    @staticmethod
    def holder(folder: str | Path) -> dict[str, str]:
        """What the lock file of ``folder`` says (pid, host, started); empty if none or unreadable."""
        try:
            text = (Path(folder) / LOCK_NAME).read_text(encoding="utf-8", errors="replace")
        except OSError:
            return {}
        info = {}
        for line in text.splitlines():
            key, sep, value = line.partition("=")
            if sep:
                info[key.strip()] = value.strip()
        return info

    def _busy(self) -> RunFolderError:
        info = self.holder(self.folder)
        who = _describe(info) if info else "its pid is not written yet"
        return RunFolderError(f"run folder {self.folder} is in use by another run ({who}); wait for it to end "
                              "or choose another output folder")

    def _content(self) -> bytes:
        started = datetime.now(UTC).isoformat(timespec="seconds")
        return f"pid={os.getpid()}\nhost={socket.gethostname()}\nstarted={started}\n".encode()

    def _cannot(self, exc: OSError) -> RunFolderError:
        return RunFolderError(f"run folder {self.folder}: cannot write its lock file ({exc.strerror or exc})")

    def acquire(self) -> RunLock:
        """Take the lock (see the class); returns self."""
        if self.held:
            raise RunFolderError(f"run folder {self.folder} is already held by this lock")
        if fcntl is not None:
            self._acquire_flock()
        else:  # pragma: no cover - exercised on Linux by a test that hides fcntl
            self._acquire_exclusive()
        return self

    def _acquire_flock(self) -> None:
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
                    raise self._busy() from None
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
            return
        raise RunFolderError(f"run folder {self.folder}: its lock file keeps being replaced; try again")

    def _acquire_exclusive(self) -> None:
        for _ in range(2):
            try:
                fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
            except FileExistsError:
                info = self.holder(self.folder)
                stale = False
                if info.get("host") == socket.gethostname() and info.get("pid", "").isdigit():
                    stale = _pid_alive(int(info["pid"])) is False
                if not stale:
                    raise RunFolderError(
                        f"run folder {self.folder} is in use by another run ({_describe(info) if info else '?'}); "
                        f"wait for it to end, or remove {self.path} if that run is over"
                    ) from None
                self.path.unlink(missing_ok=True)  # its process is gone
                continue
            except OSError as exc:
                raise self._cannot(exc) from None
            try:
                os.write(fd, self._content())
            finally:
                os.close(fd)
            self._created = True
            return
        raise self._busy()

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
