"""The material library against the dissertation's printed tables, and user TOML files.

The printed numbers are read from the dissertation text itself (shared/seed), so a typo in
the data file cannot be mirrored by the same typo in the test.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import MaterialDataError, UnknownMaterialError
from pneumorph.materials.laws.hyperelastic import Ogden, Yeoh
from pneumorph.materials.library import builtin as library

THESIS = "seed/000_2f6eb7f132ab41d4.txt"
SILICONES = {"Ecoflex 0030": "ecoflex_0030", "Mold Star 15": "mold_star_15", "Smooth-Sil 950": "smooth_sil_950"}
COMPOSITES = {"0.2": "bilinear_0_2", "0.25": "bilinear_0_25", "0.3": "bilinear_0_3"}


@pytest.fixture(autouse=True)
def _clean_registry():
    library.clear_registered()
    yield
    library.clear_registered()


@pytest.fixture(scope="module")
def thesis(shared_dir: Path) -> list[str]:
    return (shared_dir / THESIS).read_text(encoding="utf-8").splitlines()


def rows_after(lines: list[str], marker: str, n: int) -> list[list[str]]:
    """The first n non-empty tab-separated lines after the line starting with marker."""
    start = next(i for i, line in enumerate(lines) if line.startswith(marker))
    out = [line.split("\t") for line in lines[start + 1 :] if line.strip()]
    return out[:n]


def test_table_a2_densities(thesis: list[str]) -> None:
    names, values = rows_after(thesis, "Table A.2:", 2)
    assert [n.strip() for n in names] == list(SILICONES)
    for display, printed in zip(names, values, strict=False):
        q = library.get(display).density
        assert q.printed == float(printed) and q.printed_unit == "kg/m^3" and not q.assumed
        assert "Table A.2" in q.source
        assert q.value == pytest.approx(float(printed) * 1e-12, rel=1e-15)  # tonne/mm^3
        assert q.unit == "tonne/mm^3"


def test_table_a3_r_squared(thesis: list[str]) -> None:
    header, *rows = rows_after(thesis, "Table A.3:", 4)
    keys = {"Ogden": "ogden", "MR2": "mooney-rivlin-2", "MR3": "mooney-rivlin-3", "Yeoh": "yeoh"}
    for row in rows:
        m = library.get(row[0])
        printed = {keys[h]: float(v) for h, v in zip(header[1:], row[1:], strict=False) if v.strip()}
        assert dict(m.r_squared) == printed
        assert "Table A.3" in (m.r_squared_source or "")
    assert dict(library.get("ecoflex_0030").r_squared) == {"mooney-rivlin-2": 0.7991}


def test_table_a4_ogden_parameters(thesis: list[str]) -> None:
    _, *rows = rows_after(thesis, "Table A.4:", 4)
    assert [r[0] for r in rows] == list(SILICONES)
    for row in rows:
        m = library.get(row[0])
        numbers = [float(x) for x in row[1:]]
        params = dict(m.model_record.parameters)
        assert params["mu"] == tuple(numbers[0::2])
        assert params["alpha"] == tuple(numbers[1::2])
        assert m.model_record.convention == "marc" and m.model_record.unit == "N/mm^2"
        assert "Table A.4" in m.model_record.source
        assert m.model == Ogden(mu=tuple(numbers[0::2]), alpha=tuple(numbers[1::2]))  # N/mm^2 = MPa


def test_table_a5_bulk_moduli(thesis: list[str]) -> None:
    _, *rows = rows_after(thesis, "Table A.5:", 3)
    assert [r[0] for r in rows] == ["Mold Star 15", "Smooth-Sil 950"]
    for name, printed in rows:
        q = library.get(name).bulk_modulus
        assert (q.printed, q.printed_unit, q.assumed) == (float(printed), "kPa", False)
        assert q.value == float(printed) / 1000.0 and q.unit == "MPa"
    assert library.get("mold_star_15").bulk_modulus.value == 0.119
    assert library.get("smooth_sil_950").bulk_modulus.value == 0.679


def test_table_a6_thermal_expansion(thesis: list[str]) -> None:
    names, values = rows_after(thesis, "Table A.6:", 2)
    assert "mu mm/mm" in next(line for line in thesis if line.startswith("Table A.6:"))
    for display, printed in zip(names, values, strict=False):
        q = library.get(display).thermal_expansion
        assert (q.printed, q.printed_unit) == (float(printed), "micro-mm/mm/degC")
        assert q.value == pytest.approx(float(printed) * 1e-6, rel=1e-15) and q.unit == "1/K"


def test_table_b1_composites(thesis: list[str]) -> None:
    header, *rows = rows_after(thesis, "The parameters for the three-term Ogden model of each crimp", 4)
    assert header[0] == "Crimp ratio"
    assert [r[0] for r in rows] == list(COMPOSITES)
    for row in rows:
        m = library.get(COMPOSITES[row[0]])
        numbers = [float(x) for x in row[1:]]
        params = dict(m.model_record.parameters)
        assert (params["mu"], params["alpha"]) == (tuple(numbers[0::2]), tuple(numbers[1::2]))
        assert "Table B.1" in m.model_record.source
        assert m.model_record.convention == "marc" and m.kind == "hyperelastic"


def test_initial_shear_modulus_in_both_conventions() -> None:
    """mu0 = sum mu_n alpha_n / 2 (Marc) = sum of FElupe moduli; Mold Star 15 = 0.1314 MPa."""
    assert round(library.get("mold_star_15").shear_modulus, 4) == 0.1314
    expected = {  # sum mu_n alpha_n / 2 from the printed Tables A.4 and B.1, in MPa
        "ecoflex_0030": (-0.0143 * -5.224 + -3.646e-10 * -0.1628 + 9.594e-8 * 11.38) / 2,
        "mold_star_15": (-6.503e-6 * -21.32 + 0.2169 * 1.180 + 1.372e-3 * 4.884) / 2,
        "smooth_sil_950": (-0.3062 * -3.059 + 0.0283 * 4.597 + 6.596e-9 * 17.69) / 2,
        "bilinear_0_2": (20.32 * 2.24 + 5.48e-4 * 40.59 + -19.08 * 2.38) / 2,
        "bilinear_0_25": (5.20 * 15.68 + 1.18 * 0.20 + -5.21 * 15.67) / 2,
        "bilinear_0_3": (2.67 * 0.0224 + 1.013 * 0.052 + 6.233e-7 * 39.09) / 2,
    }
    for name, mu0 in expected.items():
        m = library.get(name)
        assert m.shear_modulus == pytest.approx(mu0, rel=1e-12)
        felupe = m.ogden_felupe_mu
        assert felupe == pytest.approx([a * b / 2 for a, b in zip(m.model.mu, m.model.alpha, strict=False)], rel=1e-12)
        assert math.fsum(felupe) == pytest.approx(mu0, rel=1e-12)
    assert round(expected["ecoflex_0030"] * 1e3, 2) == 37.35  # kPa
    assert round(expected["smooth_sil_950"], 4) == 0.5334


def test_paper_is_linear_elastic() -> None:
    paper = library.get("Paper, Purco 80 gsm")
    assert paper.kind == "linear-elastic" and paper.model is None
    assert paper.youngs_modulus.value == 6500.0 and paper.poisson_ratio.value == 0.2
    assert paper.shear_modulus == pytest.approx(6500.0 / 2.4)
    assert paper.ogden_felupe_mu == () and paper.initial_poisson_ratio == 0.2


def test_assumed_values_are_flagged_with_reasons() -> None:
    expected = {
        "ecoflex_0030": ("bulk_modulus",),
        "mold_star_15": (),
        "smooth_sil_950": (),
        "bilinear_0_2": ("density", "bulk_modulus"),
        "bilinear_0_25": ("density", "bulk_modulus"),
        "bilinear_0_3": ("density", "bulk_modulus"),
        "paper_purco_80gsm": ("density", "youngs_modulus", "poisson_ratio", "thickness"),
        "paper_0_2": ("density", "bulk_modulus"),
        "paper_0_25": ("density", "bulk_modulus"),
        "paper_0_3": ("density", "bulk_modulus"),
    }
    # then the silicones fitted to the Soft Robotics Materials Database (tests/materials/test_database_silicones.py)
    database = library.names()[len(expected):]
    assert library.names()[: len(expected)] == tuple(expected) and len(database) == 19
    expected |= dict.fromkeys(database, ("bulk_modulus",))
    for name, assumed in expected.items():
        m = library.get(name)
        assert m.assumed == assumed
        for q in m.quantities:
            assert q.source
            assert (q.reason is not None) == q.assumed


def test_assumed_bulk_moduli_follow_their_stated_rule() -> None:
    """K / mu0 equal to Mold Star 15's measured ratio, rounded to 3 significant figures."""
    ms15 = library.get("mold_star_15")
    ratio = ms15.bulk_modulus.value / ms15.shear_modulus
    for name in ("ecoflex_0030", "bilinear_0_2", "bilinear_0_25", "bilinear_0_3"):
        m = library.get(name)
        k_kpa = ratio * m.shear_modulus * 1e3
        assert m.bulk_modulus.printed == float(f"{k_kpa:.3g}"), name
        assert m.initial_poisson_ratio == pytest.approx(ms15.initial_poisson_ratio, abs=2e-3)
    assert ms15.initial_poisson_ratio == pytest.approx(0.0965, abs=1e-4)


def test_assumed_densities_follow_their_stated_rule() -> None:
    eco = library.get("ecoflex_0030").density
    for name in COMPOSITES.values():
        assert library.get(name).density.printed == eco.printed
    paper = library.get("paper")
    # thickness = grammage / density: 80 g/m^2 / 750 kg/m^3, printed to 3 digits
    assert paper.density.printed == 750
    assert paper.thickness.printed == pytest.approx(80e-3 / paper.density.printed * 1e3, abs=5e-4)


@pytest.mark.parametrize("spelling", ["mold_star_15", "Mold Star 15", "mold-star-15", "MOLD STAR 15", " mold.star.15 "])
def test_names_are_case_and_format_tolerant(spelling: str) -> None:
    assert library.get(spelling).name == "mold_star_15"


def test_aliases() -> None:
    assert library.get("Ecoflex 0030").name == "ecoflex_0030"
    assert library.get("Ecoflex 00-30").name == "ecoflex_00_30"  # the database's, not the dissertation's
    assert library.get("bilinear cr 0.25").name == "bilinear_0_25"
    assert library.get("paper").name == "paper_purco_80gsm"


def test_unknown_name_lists_the_known_ones() -> None:
    with pytest.raises(UnknownMaterialError) as info:
        library.get("unobtainium")
    message = str(info.value)
    assert "unobtainium" in message
    for name in library.names():
        assert name in message
    assert isinstance(info.value, KeyError)


def test_material_is_frozen() -> None:
    m = library.get("mold_star_15")
    with pytest.raises(AttributeError):
        m.name = "x"  # type: ignore[misc]


def test_to_dict_is_json_and_complete() -> None:
    for name in library.names():
        d = json.loads(json.dumps(library.get(name).to_dict()))
        assert d["name"] == name
        assert d["assumed"] == list(library.get(name).assumed)
    d = library.get("mold_star_15").to_dict()
    assert d["model"]["parameters"]["mu"] == [-6.503e-6, 0.2169, 1.372e-3]
    assert d["shear_modulus"]["marc"] == pytest.approx(d["shear_modulus"]["felupe"], rel=1e-12)
    assert d["properties"]["bulk_modulus"]["printed"] == 119
    assert d["properties"]["bulk_modulus"]["value"] == 0.119


@pytest.mark.parametrize("name", ["mold_star_15", "smooth_sil_950", "ecoflex_0030", "paper"])
def test_umat_small_strain_moduli(name: str) -> None:
    """FElupe material: shear stress / shear strain -> mu0; volumetric -> K (Eq 2.12)."""
    pytest.importorskip("felupe")
    m = library.get(name)
    umat = m.umat()
    g = 1e-6
    shear = np.eye(3)
    shear[0, 1] = g
    p_shear = umat.gradient([shear.reshape(3, 3, 1, 1), None])[0]
    assert p_shear[0, 1].item() / g == pytest.approx(m.shear_modulus, rel=1e-4)
    e = 1e-7
    p_vol = umat.gradient([(np.eye(3) * (1 + e)).reshape(3, 3, 1, 1), None])[0]
    k = m.bulk_modulus.value if m.model is not None else (
        m.youngs_modulus.value / (3 * (1 - 2 * m.poisson_ratio.value))
    )
    assert p_vol[0, 0].item() / (3 * e) == pytest.approx(k, rel=1e-4)


def test_umat_nearly_incompressible_and_errors() -> None:
    pytest.importorskip("felupe")
    umat = library.get("mold_star_15").umat("nearly-incompressible")
    assert type(umat).__name__ == "NearlyIncompressible" and umat.bulk == 0.119
    with pytest.raises(MaterialDataError, match="linear-elastic"):
        library.get("paper").umat("nearly-incompressible")
    with pytest.raises(MaterialDataError, match="formulation"):
        library.get("mold_star_15").umat("incompressible")


# ---------------------------------------------------------------------------------------
# user TOML files
# ---------------------------------------------------------------------------------------

USER = """
[materials.my_silicone]
display_name = "My Silicone 20"
kind = "hyperelastic"
source = "own tests, 2026"
aliases = ["ms20"]

[materials.my_silicone.model]
type = "yeoh"
unit = "kPa"
c = [100.0, -1.0, 0.1]
source = "own fit"

[materials.my_silicone.bulk_modulus]
value = 2.5
unit = "MPa"
source = "own test"

[materials.my_silicone.density]
value = 1.07
unit = "g/cm^3"
source = "datasheet"
"""


def write(tmp_path: Path, text: str, name: str = "user.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_user_toml_round_trip(tmp_path: Path) -> None:
    path = write(tmp_path, USER)
    lib = library.load_library(path)
    m = lib.get("My Silicone 20")
    assert m.model == Yeoh(c=(0.1, -0.001, 0.0001))  # kPa -> MPa
    assert m.shear_modulus == pytest.approx(0.2)
    assert m.bulk_modulus.value == 2.5 and m.density.value == pytest.approx(1.07e-9, rel=1e-15)
    assert m.origin == str(path)
    assert "my_silicone" not in library.names()  # loading does not register
    library.register_toml(path)
    assert library.get("ms20") == m and library.names()[-1] == "my_silicone"
    back = json.loads(json.dumps(m.to_dict()))
    assert back["model"]["parameters"] == {"c": [100.0, -1.0, 0.1]}
    assert back["properties"]["density"]["printed"] == 1.07


def test_builtin_file_round_trips_through_load_library(tmp_path: Path) -> None:
    from importlib import resources

    text = resources.files("pneumorph.materials").joinpath("data/materials.toml").read_text("utf-8")
    lib = library.load_library(write(tmp_path, text))
    for name in library.names():
        a, b = lib.get(name), library.get(name)
        assert a.to_dict() | {"origin": None} == b.to_dict() | {"origin": None}
    assert lib.filler("ellis2020_eq5_2").coefficients == library.get_filler().coefficients


def test_register_refuses_clashes_unless_replace(tmp_path: Path) -> None:
    clash = USER.replace('aliases = ["ms20"]', 'aliases = ["Mold Star 15"]')
    path = write(tmp_path, clash)
    with pytest.raises(MaterialDataError, match="already used"):
        library.register_toml(path)
    library.register_toml(path, replace=True)
    assert library.get("Mold Star 15").name == "my_silicone"
    library.clear_registered()
    assert library.get("Mold Star 15").name == "mold_star_15"


GOOD_ENTRY = """
[materials.x]
display_name = "X"
kind = "hyperelastic"
source = "s"
[materials.x.model]
type = "ogden"
convention = "marc"
unit = "MPa"
mu = [0.1, 0.01]
alpha = [2.0, 4.0]
source = "s"
[materials.x.bulk_modulus]
value = 100
unit = "kPa"
source = "s"
"""


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ('display_name = "X"\n', "", "missing key 'display_name'"),
        ("alpha = [2.0, 4.0]", "alpha = [2.0]", "'mu' has 2 terms but 'alpha' has 1"),
        ("alpha = [2.0, 4.0]", "", "missing key 'alpha'"),
        ("value = 100", "value = -100", "bulk modulus must be positive"),
        ("value = 100", "value = 0", "bulk modulus must be positive"),
        ("mu = [0.1, 0.01]", "mu = [-0.1, 0.01]", "initial shear modulus of the ogden model must be positive"),
        ('unit = "kPa"', 'unit = "psi"', "unit 'psi'"),
        ('unit = "MPa"', 'unit = "kg/m^3"', "not a stress unit"),
        ('type = "ogden"', 'type = "arruda-boyce"', "unknown model type"),
        ('kind = "hyperelastic"', 'kind = "plastic"', "kind must be one of"),
        ('convention = "marc"', 'convention = "felupe"', "not supported"),
        ('source = "s"\n[materials.x.model]', 'source = "s"\ncolour = "red"\n[materials.x.model]',
         "unknown key(s) colour"),
        ("value = 100", "value = true", "finite number"),
        ("mu = [0.1, 0.01]", "mu = []", "non-empty list"),
        ('value = 100\nunit = "kPa"\nsource = "s"', 'value = 100\nunit = "kPa"\nsource = "s"\nassumed = true',
         "missing key 'reason'"),
    ],
)
def test_validation_errors_name_file_and_entry(tmp_path: Path, old: str, new: str, message: str) -> None:
    assert old in GOOD_ENTRY
    path = write(tmp_path, GOOD_ENTRY.replace(old, new, 1))
    with pytest.raises(MaterialDataError) as info:
        library.load_library(path)
    text = str(info.value)
    assert str(path) in text and "materials.x" in text
    assert message in text


def test_good_entry_loads(tmp_path: Path) -> None:
    m = library.load_library(write(tmp_path, GOOD_ENTRY)).get("x")
    assert m.shear_modulus == pytest.approx(0.1 * 2 / 2 + 0.01 * 4 / 2)


def test_linear_elastic_validation(tmp_path: Path) -> None:
    text = """
[materials.sheet]
display_name = "Sheet"
kind = "linear-elastic"
source = "s"
[materials.sheet.youngs_modulus]
value = 2
unit = "GPa"
source = "s"
[materials.sheet.poisson_ratio]
value = 0.5
unit = "-"
source = "s"
"""
    with pytest.raises(MaterialDataError, match=r"materials\.sheet\.poisson_ratio.*\(-1, 0\.5\)"):
        library.load_library(write(tmp_path, text))
    missing = text.split("[materials.sheet.poisson_ratio]")[0]
    with pytest.raises(MaterialDataError, match="missing table 'poisson_ratio'"):
        library.load_library(write(tmp_path, missing))
    ok = library.load_library(write(tmp_path, text.replace("value = 0.5", "value = 0.3"))).get("sheet")
    assert ok.youngs_modulus.value == 2000.0


def test_file_level_errors(tmp_path: Path) -> None:
    with pytest.raises(MaterialDataError, match="not valid TOML"):
        library.load_library(write(tmp_path, "[materials.x\n"))
    with pytest.raises(MaterialDataError, match="no \\[materials"):
        library.load_library(write(tmp_path, "schema_version = 1\n"))
    with pytest.raises(MaterialDataError, match=r"missing\.toml: no such file"):
        library.load_library(tmp_path / "missing.toml")
    with pytest.raises(MaterialDataError, match="schema_version 2"):
        library.load_library(write(tmp_path, "schema_version = 2\n" + GOOD_ENTRY))


def test_materials_built_in_code_obey_the_library_rules() -> None:
    from dataclasses import replace

    from pneumorph.materials.library.material import Material, Quantity

    good = library.get("smooth_sil_950")
    with pytest.raises(MaterialDataError, match="needs a model"):
        replace(good, model=None)
    with pytest.raises(MaterialDataError, match="kind must be one of"):
        replace(good, kind="plastic")
    with pytest.raises(MaterialDataError, match="lower case"):
        replace(good, name="Smooth Sil")
    with pytest.raises(MaterialDataError, match="density must be positive"):
        Quantity("density", -1e-9, "tonne/mm^3", -1.0, "g/cm^3", "test")
    with pytest.raises(MaterialDataError, match="Poisson's ratio must lie in"):
        Quantity("poisson_ratio", 0.5, "-", 0.5, "-", "test")
    with pytest.raises(MaterialDataError, match="finite"):
        Quantity("bulk_modulus", float("nan"), "MPa", float("nan"), "MPa", "test")
    with pytest.raises(MaterialDataError, match="linear-elastic"):
        Material("paper", "Paper", "linear-elastic", "test")
