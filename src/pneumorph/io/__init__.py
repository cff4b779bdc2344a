"""Outputs: safe file writing (atomic, strict JSON, paths checked first), ParaView (VTK)
files, provenance records, and the lines a long command says about its work (plan, progress,
heartbeat); inputs: the one bounded reader of a user's files (:mod:`pneumorph.io.reading`)."""

from pneumorph.io.files import (
    atomic_write_bytes,
    atomic_write_text,
    check_writable_dir,
    check_writable_file,
    json_safe,
    strict_json,
    write_json,
)
from pneumorph.io.lock import FileLock, RunLock
from pneumorph.io.progress import HEARTBEAT, THROTTLE, Progress, duration_text, estimate_seconds, load_factor
from pneumorph.io.provenance import digest, provenance
from pneumorph.io.vtk import write_vtk_series

__all__ = [
    "HEARTBEAT",
    "THROTTLE",
    "FileLock",
    "Progress",
    "RunLock",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_writable_dir",
    "check_writable_file",
    "digest",
    "duration_text",
    "estimate_seconds",
    "json_safe",
    "load_factor",
    "provenance",
    "strict_json",
    "write_json",
    "write_vtk_series",
]
