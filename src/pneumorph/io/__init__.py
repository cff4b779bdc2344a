"""Outputs: safe file writing (atomic, strict JSON, paths checked first), ParaView (VTK)
files and provenance records."""

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
from pneumorph.io.provenance import digest, provenance
from pneumorph.io.vtk import write_vtk_series

__all__ = [
    "FileLock",
    "RunLock",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_writable_dir",
    "check_writable_file",
    "digest",
    "json_safe",
    "provenance",
    "strict_json",
    "write_json",
    "write_vtk_series",
]
