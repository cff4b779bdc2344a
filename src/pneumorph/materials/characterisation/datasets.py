"""Data sets bundled with pneumorph (``data/datasets/``) and reading files or data sets.

Examples
--------
>>> from pneumorph.materials.characterisation.datasets import list_datasets, load_dataset
>>> [d.name for d in list_datasets()]
['treloar1944']
>>> sorted(load_dataset("treloar1944").modes)
['equibiaxial', 'planar', 'uniaxial']
"""

from __future__ import annotations

import tomllib
from collections.abc import Iterable
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from pneumorph.errors import DataFormatError, UnknownDatasetError
from pneumorph.materials.characterisation.testdata import TestCurve, TestData, read_curve


@dataclass(frozen=True)
class DatasetInfo:
    """A bundled data set: its name, what it is, its licence and where it comes from."""

    name: str
    description: str
    licence: str
    citation: str
    origin: str


def _dataset_root() -> Path:
    return Path(str(resources.files("pneumorph.materials") / "data" / "datasets"))


def _manifest(name: str) -> tuple[Path, dict[str, Any]]:
    folder = _dataset_root() / name
    with open(folder / "dataset.toml", "rb") as fh:
        return folder, tomllib.load(fh)


def list_datasets() -> tuple[DatasetInfo, ...]:
    """The bundled data sets.

    Examples
    --------
    >>> [d.name for d in list_datasets()]
    ['treloar1944']
    """
    out = []
    for folder in sorted(_dataset_root().iterdir()):
        if (folder / "dataset.toml").is_file():
            _, m = _manifest(folder.name)
            out.append(DatasetInfo(folder.name, m["description"], m["licence"], m["citation"], m["origin"]))
    return tuple(out)


def load_dataset(name: str) -> TestData:
    """Load a bundled data set by name (see :func:`list_datasets`).

    Raises
    ------
    UnknownDatasetError
        If there is no such data set.
    """
    known = [d.name for d in list_datasets()]
    if name not in known:
        raise UnknownDatasetError(name, known)
    folder, m = _manifest(name)
    curves = []
    for c in m["curve"]:
        opts = {k: v for k, v in c.items() if k not in ("file", "mode")}
        curves.append(read_curve(folder / c["file"], c["mode"], description=m["description"], **opts))
    return TestData(tuple(curves), name)


def read_test_data(sources: Iterable[str | Path], mode: str | None = None, **options: object) -> TestData:
    """Read files and/or bundled data sets into one :class:`TestData`.

    Parameters
    ----------
    sources : iterable of str or Path
        Data files (read with :func:`read_curve`) or names of bundled data sets.
    mode : str, optional
        Loading mode of every file; by default guessed from each file name, else uniaxial.
    **options
        Passed to :func:`read_curve` for the files.

    Examples
    --------
    >>> read_test_data(["treloar1944"]).name
    'treloar1944'
    """
    curves: list[TestCurve] = []
    names = []
    for s in sources:
        p = Path(s)
        if p.exists() and not p.is_dir():  # a file, or a device or pipe its reader refuses by name
            curves.append(read_curve(p, mode, **options))  # type: ignore[arg-type]
            names.append(p.stem)
        elif str(s) in {d.name for d in list_datasets()}:
            curves.extend(load_dataset(str(s)).curves)
            names.append(str(s))
        else:
            raise UnknownDatasetError(str(s), [d.name for d in list_datasets()])
    if not curves:
        raise DataFormatError("no data file or data set given")
    return TestData(tuple(curves), " + ".join(dict.fromkeys(names)))
