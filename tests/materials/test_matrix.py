"""An entry with ``matrix = "<key>"``: it takes that entry's kind, law, density and bulk modulus.

The cast-paper entries (``paper_0_2`` etc.) are written this way; their records, and with them the
descriptions and fingerprints of the models cast in them (the keys of chain tables and caches), are
pinned to the digests they had when each entry repeated Ecoflex 0030's numbers.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from pneumorph.errors import MaterialDataError
from pneumorph.io.provenance import digest
from pneumorph.materials.library import builtin as library

MATRIX = """
[materials.base]
display_name = "Base"
kind = "hyperelastic"
source = "base paper"
model = { type = "neo-hooke", unit = "kPa", c10 = 50.0, source = "base fit" }
density = { value = 1100, unit = "kg/m^3", source = "base datasheet" }
bulk_modulus = { value = 2.0, unit = "MPa", source = "base test" }
thermal_expansion = { value = 200, unit = "micro-mm/mm/degC", source = "base test" }
"""


def load(tmp_path: Path, text: str):
    path = tmp_path / "lib.toml"
    path.write_text(MATRIX + text, encoding="utf-8")
    return library.load_library(path)


def test_the_cast_paper_entries_keep_their_records_and_the_models_their_fingerprints() -> None:
    """Digests of ``Material.to_dict()`` (what a model's description holds of it) and of models with a
    ``paper_0_2`` region, as they were with the numbers repeated in each entry."""
    from pneumorph.geometry.library import builtin_library
    from pneumorph.models.fe import Full3D

    pinned = {"paper_0_2": "8aa5d6c990ebcf49", "paper_0_25": "c9fe05642f91caf2", "paper_0_3": "9b72a8f8789d5796"}
    assert {name: digest(library.get(name).to_dict()) for name in pinned} == pinned
    modes = builtin_library("modes")
    assert Full3D(3, library=modes).fingerprint() == "97fbc7739be8bd94"
    assert Full3D(1, unit=modes["p"]).fingerprint() == "6d00f38333b98292"
    ecoflex = library.get("ecoflex_0030")
    for name in pinned:
        entry = library.get(name)
        assert entry.model == ecoflex.model and entry.kind == "hyperelastic"
        assert entry.density.value == ecoflex.density.value and entry.density.assumed
        assert entry.bulk_modulus.value == ecoflex.bulk_modulus.value
        assert entry.thermal_expansion is None  # not inherited: the paper has no thermal law


def test_an_entry_inherits_its_matrix_under_its_own_keys(tmp_path: Path) -> None:
    lib = load(tmp_path, """
[materials.child]
display_name = "Child"
source = "child paper"
matrix = "base"
density = { value = 1.2, unit = "g/cm^3", source = "child datasheet" }
bulk_modulus.source = "base test, as the child's"
bulk_modulus.assumed = true
bulk_modulus.reason = "not measured for the child"
""")
    base, child = lib.get("base"), lib.get("child")
    assert child.kind == "hyperelastic" and child.model == base.model and child.model_record == base.model_record
    assert child.shear_modulus == pytest.approx(0.1)  # 2 c10 = 100 kPa
    assert child.density.value == pytest.approx(1.2e-9, rel=1e-15) and child.density.source == "child datasheet"
    k = child.bulk_modulus
    assert (k.value, k.printed, k.printed_unit) == (2.0, 2.0, "MPa")
    assert (k.source, k.assumed, k.reason) == ("base test, as the child's", True, "not measured for the child")
    assert child.thermal_expansion is None and child.source == "child paper"
    # a model of its own (a type) replaces the matrix's whole
    own = load(tmp_path, """
[materials.child]
display_name = "Child"
source = "child paper"
matrix = "base"
model = { type = "neo-hooke", unit = "kPa", c10 = 80.0, source = "child fit" }
""").get("child")
    assert own.shear_modulus == pytest.approx(0.16) and own.bulk_modulus.value == 2.0


@pytest.mark.parametrize(("text", "message"), [
    ('matrix = "nothing"', r"\[materials\.child\]: matrix 'nothing' is not an entry of"),
    ('matrix = "child"', r"\[materials\.child\]: matrix 'child' is the entry itself"),
    ('matrix = "middle"', r"\[materials\.child\]: matrix 'middle' has a matrix of its own \('base'\)"),
    ('matrix = "sheet"', r"\[materials\.child\]: matrix 'sheet' is not a hyperelastic entry"),
    ("matrix = 3", r"\[materials\.child\]: 'matrix' must be a non-empty string"),
])
def test_bad_matrices_are_refused_naming_the_entry(tmp_path: Path, text: str, message: str) -> None:
    others = """
[materials.middle]
display_name = "Middle"
source = "s"
matrix = "base"

[materials.sheet]
display_name = "Sheet"
kind = "linear-elastic"
source = "s"
youngs_modulus = { value = 1.0, unit = "MPa", source = "s" }
poisson_ratio = { value = 0.3, unit = "-", source = "s" }
"""
    with pytest.raises(MaterialDataError, match=message) as info:
        load(tmp_path, others + f'\n[materials.child]\ndisplay_name = "Child"\nsource = "s"\n{text}\n')
    assert "\n" not in str(info.value)


def test_a_cycle_of_matrices_is_refused(tmp_path: Path) -> None:
    with pytest.raises(MaterialDataError, match=r"\[materials\.a\]: matrix 'b' has a matrix of its own \('a'\)"):
        load(tmp_path, """
[materials.a]
display_name = "A"
source = "s"
matrix = "b"

[materials.b]
display_name = "B"
source = "s"
matrix = "a"
""")
