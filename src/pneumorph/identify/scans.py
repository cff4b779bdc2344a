"""What an identification is given: scans of cast actuators, each with its design and pressure.

One scan comes from the command line (``pneumorph identify SCAN --design D --pressure P``);
several from a TOML manifest of ``[[scan]]`` tables::

    [[scan]]
    file = "cast-1.stl"          # relative to the manifest
    design = "001111010001001"
    pressure_kpa = 36
    scan_unit = "mm"             # optional: mm (default), cm, m, in
    # scale = 0.2                # optional instead: mm per unit of the file (a photo's mm per pixel)

:func:`load_scans` reads every scan and checks it against its design before any solve,
with the checks of ``pneumorph correlate`` (:func:`pneumorph.correlation.read_scan`,
:func:`pneumorph.correlation.compare.check_length`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pneumorph import checks
from pneumorph.correlation.compare import check_length
from pneumorph.correlation.scans import SCAN_UNITS, Scan, read_scan
from pneumorph.errors import ScanError, SettingsError
from pneumorph.geometry.orientation import parse_orientation
from pneumorph.io.files import read_toml

#: the keys of a manifest's ``[[scan]]`` table
SCAN_KEYS = ("file", "design", "pressure_kpa", "scan_unit", "scale")
#: most scans one identification takes (each costs a solve per parameter and iteration)
MAX_SCANS = 64
#: least pressure a scan to identify from may be taken at (kPa): at 1 kPa four built-in units lift their tip by
#: 0.22 mm in the 2D model (``pneumorph simulate -o 0000 --model 2d --pressure 1``), about what a scan or a photo
#: trace resolves; below it the scan says nothing of the moduli
MIN_SCAN_PRESSURE_KPA = 1.0


def check_scan_pressure(pressure_kpa: float, name: str) -> None:
    """Refuse a scan's pressure below :data:`MIN_SCAN_PRESSURE_KPA` (``name`` says whose).

    >>> check_scan_pressure(1e-300, "--pressure")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: --pressure 1e-300 kPa is below MIN_SCAN_PRESSURE_KPA = 1 kPa
        (pneumorph.identify.scans): the actuator barely deforms, so the scan cannot tell the moduli; scan it inflated
    """
    if pressure_kpa < MIN_SCAN_PRESSURE_KPA:
        raise SettingsError(f"{name} {pressure_kpa:g} kPa is below MIN_SCAN_PRESSURE_KPA = {MIN_SCAN_PRESSURE_KPA:g} "
                            "kPa (pneumorph.identify.scans): the actuator barely deforms, so the scan cannot tell the "
                            "moduli; scan it inflated")


@dataclass(frozen=True)
class ScanSpec:
    """One scan of a cast actuator: its file, the design cast and the pressure it was scanned at.

    Attributes
    ----------
    file : str
    design : str
        0/1 per unit, base first.
    pressure_kpa : float
    scan_unit : str
        The unit of the file's coordinates (mm, cm, m, in).
    scale : float or None
        mm per unit of the file, instead of ``scan_unit``.

    Examples
    --------
    >>> ScanSpec("a.stl", "0110", 36.0).to_dict()
    {'file': 'a.stl', 'design': '0110', 'pressure_kpa': 36.0, 'scan_unit': 'mm'}
    >>> ScanSpec("a.stl", "01x", 36.0)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: scan a.stl: design: orientation '01x' contains 'x'; only the digits 0 and 1 are
    allowed (0 = unit as built, 1 = unit turned 180 degrees about the long axis)
    """

    file: str
    design: str
    pressure_kpa: float
    scan_unit: str = "mm"
    scale: float | None = None

    def __post_init__(self) -> None:
        where = f"scan {self.file}"
        try:
            object.__setattr__(self, "design", parse_orientation(self.design))
        except (ValueError, TypeError) as exc:
            raise SettingsError(f"{where}: design: {exc}") from None
        object.__setattr__(self, "pressure_kpa", checks.real(self.pressure_kpa, f"{where}: pressure_kpa", 0.0,
                                                             checks.MAX_PRESSURE_KPA, low_open=True, unit="kPa",
                                                             limit="MAX_PRESSURE_KPA"))
        check_scan_pressure(self.pressure_kpa, f"{where}: pressure_kpa")
        checks.text(self.scan_unit, f"{where}: scan_unit", tuple(SCAN_UNITS))
        if self.scale is not None:
            object.__setattr__(self, "scale", checks.real(self.scale, f"{where}: scale", 0.0, 1e6, low_open=True))

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"file": self.file, "design": self.design, "pressure_kpa": self.pressure_kpa}
        if self.scale is not None:
            out["scale"] = self.scale
        else:
            out["scan_unit"] = self.scan_unit
        return out


def read_manifest(path: str | Path) -> list[ScanSpec]:
    """The scans of a manifest (``[[scan]]`` tables; files relative to the manifest).

    Raises
    ------
    SettingsError
        Not readable TOML, no ``[[scan]]`` table, a table without ``file``, ``design`` or
        ``pressure_kpa``, an unknown key, both ``scan_unit`` and ``scale``, or a bad value:
        one line naming the manifest and the table.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "scans.toml"
    >>> _ = p.write_text('[[scan]]\\nfile = "a.csv"\\ndesign = "0110"\\npressure_kpa = 36\\nscale = 0.2\\n')
    >>> [(s.design, s.pressure_kpa, s.scale, Path(s.file).name) for s in read_manifest(p)]
    [('0110', 36.0, 0.2, 'a.csv')]
    >>> _ = p.write_text('[[scan]]\\nfile = "a.csv"\\npressure_kpa = 36\\n')
    >>> read_manifest(p)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: manifest ...scans.toml, [[scan]] 1: missing design (give file, design, pressure_kpa)
    """
    p = Path(path)
    data = read_toml(p, "manifest", SettingsError)
    unknown = sorted(set(data) - {"scan"})
    if unknown:
        raise SettingsError(f"manifest {p}: unknown table or key {', '.join(unknown)}; a manifest holds [[scan]] "
                            "tables")
    tables = data.get("scan")
    if not isinstance(tables, list) or not tables or not all(isinstance(t, dict) for t in tables):
        raise SettingsError(f"manifest {p}: no [[scan]] tables (each with file, design, pressure_kpa)")
    if len(tables) > MAX_SCANS:
        raise SettingsError(f"manifest {p}: {len(tables)} scans, more than {MAX_SCANS} (MAX_SCANS)")
    out = []
    for k, table in enumerate(tables, start=1):
        where = f"manifest {p}, [[scan]] {k}"
        extra = sorted(set(table) - set(SCAN_KEYS))
        if extra:
            raise SettingsError(f"{where}: unknown key(s) {', '.join(extra)}; known: {', '.join(SCAN_KEYS)}")
        missing = [key for key in ("file", "design", "pressure_kpa") if key not in table]
        if missing:
            raise SettingsError(f"{where}: missing {', '.join(missing)} (give file, design, pressure_kpa)")
        if "scan_unit" in table and "scale" in table:
            raise SettingsError(f"{where}: give scan_unit or scale, not both")
        file = checks.text(table["file"], f"{where}: file")
        design = table["design"]
        if not isinstance(design, str):
            raise SettingsError(f"{where}: design must be a text of 0 and 1 (quoted), got {design!r}")
        try:
            out.append(ScanSpec(str(p.parent / file), design, table["pressure_kpa"], table.get("scan_unit", "mm"),
                                table.get("scale")))
        except SettingsError as exc:
            raise SettingsError(f"{where}: {exc}") from None
        same = next((j for j, spec in enumerate(out[:-1], start=1)
                     if Path(spec.file).resolve() == Path(out[-1].file).resolve()
                     and spec.pressure_kpa == out[-1].pressure_kpa), None)
        if same is not None:  # one scan counted twice would claim more certainty than the data hold
            raise SettingsError(f"{where}: the same scan at the same pressure as [[scan]] {same}; list each scan "
                                "once")
    return out


def load_scans(specs: Sequence[ScanSpec], pitch: float) -> list[Scan]:
    """Read every scan and refuse, before any solve, one that cannot be of its design.

    ``pitch`` is the unit's pitch (mm): a scan must span between 0.12 and 3 times its
    design's length (:func:`~pneumorph.correlation.compare.check_length`, as
    ``pneumorph correlate`` checks).

    Raises
    ------
    ScanError
        An unreadable or bad scan, or one far larger or smaller than its design.
    """
    scans = []
    dims = set()
    for spec in specs:
        scan = read_scan(spec.file, spec.scan_unit, spec.scale)
        check_length(scan, len(spec.design) * pitch)
        dims.add(scan.dim)
        scans.append(scan)
    if len(dims) > 1:
        raise ScanError("the scans mix 3D scans and 2D traces; identify from one kind at a time (a 3D scan needs "
                        "--model 3d, a photo trace --model 2d)")
    return scans


__all__ = ["MAX_SCANS", "SCAN_KEYS", "ScanSpec", "load_scans", "read_manifest"]
