"""Reading stress-stretch test data of rubber-like materials.

A :class:`TestCurve` is one homogeneous test (uniaxial tension and/or compression,
equibiaxial tension or planar tension, i.e. pure shear) as stretch against *nominal*
stress in MPa; a :class:`TestData` holds the curves of one material, any number per mode.

:func:`read_curve` reads the usual text layouts:

- delimiter comma, semicolon, tab or whitespace, detected from the first line (with a
  semicolon, tab or whitespace delimiter a decimal comma is accepted);
- an optional header row; column roles are read from it where it names them
  (``stretch``/``lambda``, ``strain``, ``stress``, ``true``, ``%``, a unit in brackets),
  else given with ``columns``, e.g. ``("stress", "stretch")`` for files with stress first;
- the x column as stretch, engineering strain or true (logarithmic) strain, as a fraction
  or in percent;
- the stress as nominal (engineering) or true (Cauchy) stress in MPa, kPa, Pa, N/mm^2,
  kgf/cm^2 or psi. True stress is turned into nominal stress with incompressibility: in
  all three modes the loaded direction has ``sigma = P * lambda`` (uniaxial ``F = diag(l,
  l^-1/2, l^-1/2)``, equibiaxial ``diag(l, l, l^-2)``, planar ``diag(l, 1, l^-1)``, all
  with ``J = 1``), so ``P = sigma / lambda``;
- the format of the Soft Robotics Materials Database (Marechal et al. 2021): a
  ``PARAMETER;INFO;URL`` block of metadata, a blank line, the header
  ``Time (s);True Strain;True Stress (MPa);Engineering Strain;Engineering Stress (MPa)``.
  It is recognised automatically; the metadata are kept and the engineering columns used.

Curves must be monotonic in stretch. ``truncate`` keeps part of a curve that is not:
``"loading"`` keeps the rows up to the largest stretch (drops an unloading branch),
``"peak-stress"`` keeps the rows up to the largest stress (drops what follows failure).
Pull-to-failure tests of the database are truncated at the peak stress by default: the
rows after it record the specimen tearing, not the material law.

Examples
--------
>>> from pneumorph.materials.characterisation.datasets import load_dataset
>>> data = load_dataset("treloar1944")
>>> data.modes
('uniaxial', 'equibiaxial', 'planar')
>>> c = data.curve("uniaxial")
>>> len(c.stretch), float(c.stretch[-1]), round(float(c.stress[-1]), 4)
(25, 7.6, 6.3176)
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import MappingProxyType

import numpy as np

from pneumorph import checks
from pneumorph.errors import DataFormatError
from pneumorph.io.reading import check_rows, read_text_file
from pneumorph.materials.characterisation.curves import MAX_STRESS_MPA, MAX_STRETCH, TestCurve, TestData

#: Stress units understood by the readers and their factor to MPa.
STRESS_UNITS: Mapping[str, float] = MappingProxyType(
    {
        "mpa": 1.0,
        "n/mm^2": 1.0,
        "n/mm2": 1.0,
        "kpa": 1e-3,
        "pa": 1e-6,
        "kgf/cm^2": 0.0980665,
        "kgf/cm2": 0.0980665,
        "kg/cm^2": 0.0980665,
        "psi": 0.00689475729,
    }
)
_SORO_MARK = "parameter;info"
_MODE_WORDS = {
    "uniaxial": ("ut", "uc", "uni", "uniaxial", "tension", "tensile", "compression"),
    "equibiaxial": ("et", "eb", "bt", "equibiaxial", "biaxial", "equibi"),
    "planar": ("ps", "pt", "planar", "pureshear", "shear"),
}


def guess_mode(path: str | Path) -> str | None:
    """Loading mode named in a file's name or folder (``Treloar_ut.dat``, ``PS/...``).

    Examples
    --------
    >>> guess_mode("Treloar_et.dat"), guess_mode("data/PS/stress_stretch.txt"), guess_mode("x.csv")
    ('equibiaxial', 'planar', None)
    """
    p = Path(path)
    words = re.split(r"[^a-z0-9]+", f"{p.parent.name} {p.stem}".lower().replace("pure shear", "pureshear"))
    found = {mode for mode, names in _MODE_WORDS.items() for w in words if w in names}
    return found.pop() if len(found) == 1 else None


def column_roles(columns: str | Sequence[str], path: str | None = None) -> list[str]:
    """The roles of the columns (``"stretch,stress"``), checked: one stretch or strain, one stress, else skip.

    Examples
    --------
    >>> column_roles("Skip, Stretch, stress")
    ['skip', 'stretch', 'stress']
    >>> column_roles("stress")
    Traceback (most recent call last):
    ...
    pneumorph.errors.DataFormatError: columns ['stress'] must name one of stretch/strain/true-strain, one
    stress and otherwise 'skip' (roles: stretch, strain, true-strain, stress, skip)
    """
    roles = [c.strip().lower() for c in (columns.split(",") if isinstance(columns, str) else columns)]
    bad = [r for r in roles if r not in checks.COLUMN_ROLES]
    strains = sum(r in ("stretch", "strain", "true-strain") for r in roles)
    if bad or sum(r == "stress" for r in roles) != 1 or strains != 1:
        raise DataFormatError(
            f"columns {roles} must name one of stretch/strain/true-strain, one stress and "
            f"otherwise 'skip' (roles: {', '.join(checks.COLUMN_ROLES)})", path=path)
    return roles


def stress_unit_factor(unit: str, path: str | None = None) -> float:
    """The factor from ``unit`` to MPa (one of :data:`STRESS_UNITS`, case and spaces ignored).

    >>> stress_unit_factor("kPa")
    0.001
    """
    key = unit.strip().lower().replace(" ", "")
    if key not in STRESS_UNITS:
        raise DataFormatError(f"unknown stress unit {unit!r}; expected one of "
                              "MPa, N/mm^2, kPa, Pa, kgf/cm^2, psi", path=path)
    return STRESS_UNITS[key]


def _split(line: str, delimiter: str | None) -> list[str]:
    cells = line.split() if delimiter is None else [c.strip() for c in line.split(delimiter)]
    while cells and cells[-1] == "":
        cells.pop()
    return cells


def _number(cell: str, delimiter: str | None) -> float:
    if delimiter != "," and "," in cell and "." not in cell:
        cell = cell.replace(",", ".")  # decimal comma
    return float(cell)


def _is_numeric_row(cells: list[str], delimiter: str | None) -> bool:
    try:
        for c in cells:
            _number(c, delimiter)
    except ValueError:
        return False
    return True


def _header_info(header: list[str], roles: list[str]) -> dict[str, str]:
    """What the header cells of the stress and x columns say of kind and unit."""
    s = roles.index("stress")
    x = next(i for i, r in enumerate(roles) if r in ("stretch", "strain", "true-strain"))
    info = {"stress_kind": "true" if re.search(r"true|cauchy", header[s].lower()) else "nominal"}
    unit = re.search(r"[\(\[]\s*([^\)\]]+?)\s*[\)\]]", header[s])
    if unit and unit.group(1).lower().replace(" ", "") in STRESS_UNITS:
        info["stress_unit"] = unit.group(1)
    if "%" in header[x] or "percent" in header[x].lower():
        info["strain_unit"] = "percent"
    return info


def _roles_from_header(header: list[str]) -> list[str] | None:
    """Column roles named by a header row; None if it cannot tell."""
    kinds = []
    for h in header:
        t = h.lower()
        if "stress" in t:
            kinds.append(("stress", "true" if re.search(r"true|cauchy", t) else "nominal"))
        elif "stretch" in t or "lambda" in t:
            kinds.append(("stretch", ""))
        elif "strain" in t:
            kinds.append(("true-strain" if re.search(r"true|log|hencky", t) else "strain", ""))
        else:
            kinds.append(("skip", ""))
    stress = [i for i, k in enumerate(kinds) if k[0] == "stress"]
    xs = [i for i, k in enumerate(kinds) if k[0] in ("stretch", "strain", "true-strain")]
    if not stress or not xs:
        return None
    # prefer nominal stress and stretch > engineering strain > true strain
    s = min(stress, key=lambda i: kinds[i][1] != "nominal")
    x = min(xs, key=lambda i: ("stretch", "strain", "true-strain").index(kinds[i][0]))
    roles = ["skip"] * len(header)
    roles[s], roles[x] = "stress", kinds[x][0]
    return roles


def read_curve(
    path: str | Path,
    mode: str | None = None,
    *,
    columns: Sequence[str] | str | None = None,
    strain_unit: str | None = None,
    stress_kind: str | None = None,
    stress_unit: str | None = None,
    delimiter: str | None = None,
    truncate: str | None = None,
    description: str | None = None,
) -> TestCurve:
    """Read one stress-stretch curve from a text file.

    Parameters
    ----------
    path : str or Path
        The file.
    mode : {"uniaxial", "equibiaxial", "planar"}, optional
        Loading mode; by default taken from the file name (:func:`guess_mode`), else uniaxial.
    columns : sequence of str or str, optional
        Role of each column, from ``stretch``, ``strain`` (engineering), ``true-strain``,
        ``stress`` and ``skip`` (e.g. ``"stress,stretch"``). By default read from the header
        or, for two columns without a header, ``stretch, stress``.
    strain_unit : {"fraction", "percent"}, optional
        Unit of a strain column (default: percent if the header says ``%``, else fraction).
    stress_kind : {"nominal", "true"}, optional
        Default: what the header says, else nominal. True stress becomes ``sigma / lambda``.
    stress_unit : str, optional
        One of :data:`STRESS_UNITS` (default: the header's unit, else MPa).
    delimiter : str, optional
        ``","``, ``";"``, ``"\\t"`` or ``" "`` (any whitespace); detected by default.
    truncate : {"none", "loading", "peak-stress"}, optional
        Keep only the rows up to the largest stretch (``loading``) or the largest stress
        (``peak-stress``). Default: ``peak-stress`` for pull-to-failure files of the
        materials database, ``none`` otherwise (a non-monotonic curve is then an error).
    description : str, optional
        Defaults to the material named in the metadata, else the file name.

    Returns
    -------
    TestCurve
        Sorted by increasing stretch.

    Raises
    ------
    DataFormatError
        With the file, the 1-based row and what was expected.
    """
    path = Path(path)
    src = str(path)
    body, metadata = _data_lines(path)
    delimiter = _delimiter(body[0][1], delimiter)
    header, body, roles = _columns(body, delimiter, columns, src)
    info = _header_info(header, roles) if header is not None else {}
    table = _table(body, delimiter, roles, src)
    rownum = np.array([n for n, _ in body])
    xrole = next(r for r in roles if r in ("stretch", "strain", "true-strain"))
    notes: list[str] = []
    lam = _stretch(table[:, roles.index(xrole)], xrole, roles.index(xrole) + 1, strain_unit or
                   info.get("strain_unit", "fraction"), rownum, src, notes)
    p = _nominal_stress(table[:, roles.index("stress")], lam, stress_unit or info.get("stress_unit", "MPa"),
                        stress_kind or info.get("stress_kind") or "nominal", src, notes)
    if truncate is None:
        failure = "pull-to-failure" in metadata.get("Type of test", "").lower()
        truncate = "peak-stress" if failure else "none"
    lam, p, rownum = _truncated(lam, p, rownum, truncate, src, notes)
    lam, p = _increasing(lam, p, rownum, src)
    if mode is None:
        mode = guess_mode(path) or "uniaxial"
    if mode not in checks.MODES:
        raise DataFormatError(f"unknown loading mode {mode!r}; expected one of {', '.join(checks.MODES)}", path=src)
    desc = description or metadata.get("Material") or path.stem
    return TestCurve(mode, lam, p, source=src, description=desc, metadata=metadata, notes=tuple(notes))


def _data_lines(path: Path) -> tuple[list[tuple[int, str]], dict[str, str]]:
    """The file's numbered lines that are neither blank nor comments, and the database's metadata.

    Raises
    ------
    DataFormatError
        An unreadable file, a metadata block without its header, or no data rows.
    """
    src = str(path)
    text = read_text_file(path, "data file", DataFormatError, encoding="utf-8-sig", errors="replace")
    check_rows(text, f"data file {src}", DataFormatError)  # counted before they are split
    lines = list(enumerate(text.splitlines(), start=1))
    metadata: dict[str, str] = {}
    body = [(n, s) for n, s in lines if s.strip() and not s.lstrip().startswith("#")]
    if body and body[0][1].strip().lower().startswith(_SORO_MARK):
        body, metadata = _soro_metadata(body, src)
    if not body:
        raise DataFormatError("no data rows found", path=src)
    return body, metadata


def _delimiter(first: str, delimiter: str | None) -> str | None:
    """The delimiter given (``None`` for any whitespace), else the first of ``;``, ``,``, tab in ``first``."""
    if delimiter in (" ", "whitespace"):
        return None
    if delimiter is None:
        return next((d for d in (";", ",", "\t") if d in first), None)
    return delimiter


def _columns(body: list[tuple[int, str]], delimiter: str | None, columns: Sequence[str] | str | None,
             src: str) -> tuple[list[str] | None, list[tuple[int, str]], list[str]]:
    """The header (if the first row is not numbers), the rows after it, and the role of each column.

    Raises
    ------
    DataFormatError
        A header that names no stretch and stress (without ``columns``), or of another width
        than ``columns``.
    """
    header: list[str] | None = None
    header_row = body[0][0]
    if not _is_numeric_row(_split(body[0][1], delimiter), delimiter):
        header = _split(body[0][1], delimiter)
        body = body[1:]
    if columns is None:
        if header is not None and (found := _roles_from_header(header)) is not None:
            roles = found
        elif header is not None:
            raise DataFormatError(
                f"cannot tell the stretch and stress columns from the header {header}; "
                "name them with columns=, e.g. 'stretch,stress'", path=src, row=header_row)
        else:
            roles = ["stretch", "stress"]
    else:
        roles = column_roles(columns, src)
    if header is not None and len(header) != len(roles):
        raise DataFormatError(f"the header has {len(header)} columns but columns= names {len(roles)}",
                              path=src, row=header_row)
    return header, body, roles


def _table(body: list[tuple[int, str]], delimiter: str | None, roles: list[str], src: str) -> np.ndarray:
    """The rows as numbers, shape (rows, columns) (a skipped column as 0).

    Raises
    ------
    DataFormatError
        A row of another width, a cell that is no finite number, fewer than 2 rows.
    """
    ncol = len(roles)
    rows = []
    for n, line in body:
        cells = _split(line, delimiter)
        if len(cells) != ncol:
            raise DataFormatError(f"expected {ncol} columns, found {len(cells)}: {line.strip()!r}",
                                  path=src, row=n)
        values = []
        for k, cell in enumerate(cells, start=1):
            if roles[k - 1] == "skip":
                values.append(0.0)
                continue
            try:
                v = _number(cell, delimiter)
            except ValueError:
                raise DataFormatError(f"column {k}: expected a number, found {cell!r}",
                                      path=src, row=n) from None
            if not math.isfinite(v):
                raise DataFormatError(f"column {k}: expected a finite number, found {cell!r}",
                                      path=src, row=n)
            values.append(v)
        rows.append(values)
    if len(rows) < 2:
        raise DataFormatError(f"expected at least 2 data rows, found {len(rows)}", path=src)
    return np.array(rows)


def _stretch(x: np.ndarray, xrole: str, column: int, strain_unit: str, rownum: np.ndarray, src: str,
             notes: list[str]) -> np.ndarray:
    """The stretch from column ``column`` read as ``xrole`` in ``strain_unit``; a note of the conversion.

    Raises
    ------
    DataFormatError
        An unknown strain unit, or a stretch that is not positive.
    """
    if strain_unit not in ("fraction", "percent"):
        raise DataFormatError(f"strain_unit must be 'fraction' or 'percent', got {strain_unit!r}", path=src)
    scale = 0.01 if strain_unit == "percent" and xrole != "stretch" else 1.0
    lam = {"stretch": x, "strain": 1.0 + scale * x, "true-strain": np.exp(scale * x)}[xrole]
    if xrole != "stretch":
        notes.append(f"stretch = {'1 + e' if xrole == 'strain' else 'exp(eps)'}"
                     f" from {xrole} in {strain_unit}")
    bad_rows = np.flatnonzero(lam <= 0)
    if bad_rows.size:
        i = int(bad_rows[0])
        raise DataFormatError(
            f"stretch must be positive, found {lam[i]:.6g} (column {column}"
            f" read as {xrole}; is the column order right? see columns=)", path=src, row=int(rownum[i]))
    return lam


def _nominal_stress(y: np.ndarray, lam: np.ndarray, unit: str, kind: str, src: str,
                    notes: list[str]) -> np.ndarray:
    """Nominal stress in MPa from ``y`` in ``unit`` (``kind`` nominal or true); notes of the conversions.

    Raises
    ------
    DataFormatError
        An unknown stress unit or kind.
    """
    factor = stress_unit_factor(unit, src)
    p = y * factor
    if factor != 1.0:
        notes.append(f"stress converted from {unit} to MPa (x {factor:g})")
    if kind not in ("nominal", "true"):
        raise DataFormatError(f"stress_kind must be 'nominal' or 'true', got {kind!r}", path=src)
    if kind == "true":
        p = p / lam
        notes.append("true stress converted to nominal with incompressibility: P = sigma / lambda")
    return p


def _truncated(lam: np.ndarray, p: np.ndarray, rownum: np.ndarray, truncate: str, src: str,
               notes: list[str]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rows up to the largest stretch (``loading``) or stress (``peak-stress``), or all (``none``).

    Raises
    ------
    DataFormatError
        ``truncate`` not one of :data:`~pneumorph.checks.TRUNCATE`.
    """
    if truncate not in checks.TRUNCATE:
        raise DataFormatError(f"truncate must be one of {checks.TRUNCATE}, got {truncate!r}", path=src)
    if truncate != "none":
        end = int(np.argmax(lam if truncate == "loading" else p)) + 1
        if end < lam.size:
            notes.append(f"truncated at the {'largest stretch' if truncate == 'loading' else 'peak stress'}"
                         f" (row {rownum[end - 1]}); {lam.size - end} later rows dropped")
        lam, p, rownum = lam[:end], p[:end], rownum[:end]
    return lam, p, rownum


def _increasing(lam: np.ndarray, p: np.ndarray, rownum: np.ndarray, src: str) -> tuple[np.ndarray, np.ndarray]:
    """The curve by increasing stretch (a decreasing one reversed).

    Raises
    ------
    DataFormatError
        A stretch that is not monotonic, naming its row.
    """
    d = np.diff(lam)
    direction = 1.0 if d.size and d[0] > 0 else -1.0
    wrong = np.flatnonzero(d * direction <= 0)
    if wrong.size:
        i = int(wrong[0]) + 1
        raise DataFormatError(
            f"stretch {lam[i]:.6g} does not {'increase' if direction > 0 else 'decrease'} from the "
            f"previous row ({lam[i - 1]:.6g}); expected a monotonic loading curve (for a test that "
            "unloads or fails use truncate='loading' or 'peak-stress')", path=src, row=int(rownum[i]))
    if direction < 0:
        lam, p = lam[::-1], p[::-1]
    return lam, p


def _soro_metadata(body: list[tuple[int, str]], src: str) -> tuple[list[tuple[int, str]], dict[str, str]]:
    """Split the database's ``PARAMETER;INFO;URL`` block from the table."""
    meta: dict[str, str] = {}
    for k, (_n, line) in enumerate(body[1:], start=1):
        cells = _split(line, ";")
        if not cells:  # a line of empty cells ends the block
            continue
        if "stress" in line.lower() and "strain" in line.lower():
            return body[k:], meta
        meta[cells[0]] = cells[1] if len(cells) > 1 else ""
        if len(cells) > 2 and cells[2]:
            meta[f"{cells[0]} URL"] = cells[2]
    raise DataFormatError("metadata block found but no header row with strain and stress",
                          path=src, row=body[-1][0])


__all__ = [
    "MAX_STRESS_MPA",
    "MAX_STRETCH",
    "STRESS_UNITS",
    "TestCurve",
    "TestData",
    "column_roles",
    "guess_mode",
    "read_curve",
    "stress_unit_factor",
]
