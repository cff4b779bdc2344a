"""The library's silicones fitted to the Soft Robotics Materials Database (Marechal et al. 2021).

The stored numbers come back from the database's files with the package's recipe; the
entries carry their data, attribution, caveats, fitted range and an assumed bulk modulus;
a unit cast in two of them simulates.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.errors import MaterialDataError
from pneumorph.materials.characterisation.testdata import read_curve
from pneumorph.materials.fitting.database import fit_tensile_curve
from pneumorph.materials.fitting.fit import r_squared
from pneumorph.materials.laws.hyperelastic import Ogden
from pneumorph.materials.library import builtin as library
from tests.cli import run

SORO = "marechal2021_SoRo-Materials-DB/Tensile-Tests-Data"
ATTRIBUTION = "Data: Soft Robotics Materials Database, Marechal et al. 2021, doi:10.1089/soro.2019.0115, ODbL 1.0"
#: library key -> database file (the silicones soft actuators are most often cast in, and more)
COMMON = {
    "ecoflex_00_10": "Ecoflex 00-10", "ecoflex_00_30": "Ecoflex 00-30", "ecoflex_00_50": "Ecoflex 00-50",
    "dragon_skin_10_medium": "Dragon Skin 10 MEDIUM", "dragon_skin_20": "Dragon Skin 20",
    "dragon_skin_30": "Dragon Skin 30", "mold_star_16_fast": "Mold Star 16 FAST",
    "mold_star_20t": "Mold Star 20T", "sortaclear_40": "SortaClear 40",
}
DATABASE = [n for n in library.names() if (m := library.get(n)).fitting is not None
            and m.fitting.attribution == ATTRIBUTION]


@pytest.fixture(autouse=True)
def _clean_registry():  # type: ignore[no-untyped-def]
    library.clear_registered()
    yield
    library.clear_registered()


def test_every_file_of_the_database_is_in_the_library(reference_dir: Path) -> None:
    files = sorted(p.name for p in (reference_dir / SORO).glob("*.csv"))
    fitted = sorted(library.get(n).fitting.data.split("Tensile-Tests-Data/")[1].split(":")[0]  # type: ignore[union-attr]
                    for n in DATABASE)
    assert len(files) == 19 and fitted == files
    assert set(COMMON) <= set(DATABASE)
    for name, stem in COMMON.items():
        assert library.get(stem).name == name  # the product's name finds the database's entry
    # the dissertation's Ecoflex 0030 stays what it was, under its own name
    assert library.get("ecoflex_0030").shear_modulus == pytest.approx(0.03735, abs=1e-5)
    assert library.get("ecoflex_0030").fitting is None


@pytest.mark.parametrize("name", DATABASE)
def test_entry_is_stable_and_its_bulk_modulus_is_assumed_from_nu_049(name: str) -> None:
    m = library.get(name)
    assert isinstance(m.model, Ogden) and m.fitting is not None and m.bulk_modulus is not None
    assert all(mu * a > 0 for mu, a in zip(m.model.mu, m.model.alpha, strict=True))
    assert m.fitting.stability(m.model).is_stable
    assert m.fitting.mode == "uniaxial" and m.fitting.stability_range[0] == 0.5
    caveats = " ".join(m.fitting.caveats)
    assert "crosshead" in caveats and "uniaxial tension only" in caveats
    # K = 2 mu0 (1 + nu) / (3 (1 - 2 nu)) at nu = 0.49, printed to 3 significant figures
    mu0 = m.shear_modulus
    assert m.bulk_modulus.value == pytest.approx(2 * mu0 * 1.49 / (3 * 0.02), rel=5e-3)
    assert m.initial_poisson_ratio == pytest.approx(0.49, abs=1e-4)
    assert m.assumed == ("bulk_modulus",) and "0.49" in (m.bulk_modulus.reason or "")


@pytest.mark.parametrize(("name", "r2_min", "errors"), [
    ("ecoflex_00_30", 0.9997, (-0.014, -0.037)),
    ("dragon_skin_30", 0.99, (0.080, -0.009)),
])
def test_refit_gives_the_stored_numbers(name: str, r2_min: float, errors: tuple[float, float],
                                         reference_dir: Path) -> None:
    stored = library.get(name)
    record = stored.fitting
    assert isinstance(stored.model, Ogden) and record is not None
    curve = read_curve(reference_dir / SORO / f"{COMMON[name]}.csv")
    refit = fit_tensile_curve(curve)
    assert isinstance(refit.model, Ogden)
    # stored: the refit rounded to 4 significant figures
    np.testing.assert_allclose(stored.model.mu, refit.model.mu, rtol=6e-4)
    np.testing.assert_allclose(stored.model.alpha, refit.model.alpha, rtol=6e-4)
    assert record.points == len(curve)
    assert record.stretch_range == pytest.approx((curve.stretch[0], curve.stretch[-1]), rel=5e-4)
    r2 = r_squared(curve.stress, stored.model.uniaxial(curve.stretch))
    assert r2 > r2_min and dict(stored.r_squared)[f"ogden-{stored.model.terms}"] == pytest.approx(r2, abs=6e-6)
    # the small strains of a wall: the stress error at stretch 1.5 and 2 (docs/material-fits.md's table)
    error = stored.model.uniaxial(curve.stretch) / curve.stress - 1.0
    assert [np.interp(x, curve.stretch, error) for x in (1.5, 2.0)] == pytest.approx(errors, abs=5e-4)


def test_show_ecoflex_00_30(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "materials", "show", "ecoflex_00_30")
    assert code == 0
    for text in ("doi:10.1089/soro.2019.0115", ATTRIBUTION, "Tensile-Tests-Data/Ecoflex 00-30.csv",
                 "stretch 1.068-17.07 (705 points)", "crosshead", "uniaxial tension only",
                 "767 kPa = 0.767 MPa  [ASSUMED]", "Poisson's ratio nu = 0.49",
                 "Drucker stability (uniaxial, equibiaxial, planar; stretch 0.5-17.07): stable in every mode",
                 "assumed values: bulk_modulus"):
        assert text in out, text
    code, out, _ = run(capsys, "materials", "show", "Ecoflex 00-30", "--json")
    d = json.loads(out)
    assert code == 0 and d["name"] == "ecoflex_00_30" and d["assumed"] == ["bulk_modulus"]
    assert d["fit"]["attribution"] == ATTRIBUTION and d["fit"]["stretch_range"] == [1.068, 17.07]
    assert d["fit"]["drucker_stability"] | {"stable_limits": None} == {
        "checked": [0.5, 17.07], "modes": ["uniaxial", "equibiaxial", "planar"], "stable": True, "stable_limits": None}
    assert d["properties"]["bulk_modulus"]["assumed"] is True
    assert d["shear_modulus"]["value"] == pytest.approx(0.01545, abs=1e-5)


def test_list_shows_the_database_silicones(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "materials", "list")
    assert code == 0
    rows = {line.split()[0]: line.split() for line in out.splitlines()[1:] if line.strip()}
    assert rows["ecoflex_00_30"][2:4] == ["15.45", "767*"]
    assert rows["dragon_skin_30"][2:4] == ["196.4", "9760*"]
    assert all(name in rows for name in DATABASE)


@pytest.mark.parametrize(("fit", "message"), [
    ('mode = "shear"', "fit mode must be one of"),
    ("stretch_range = [2.0]", "'stretch_range' must be [lower, upper]"),
    ("points = 0", "fit points must be a positive whole number"),
    ('caveats = "none"', "'caveats' must be a list of texts"),
    ('colour = "red"', "unknown key(s) colour"),
])
def test_bad_fit_table_names_the_entry(tmp_path: Path, fit: str, message: str) -> None:
    good = {"data": '"a curve"', "attribution": '"Data: me"', "mode": '"uniaxial"', "stretch_range": "[1.0, 3.0]",
            "points": "10", "method": '"by hand"'}
    key = fit.split(" =")[0]
    lines = [f"{k} = {v}" for k, v in good.items() if k != key] + [fit]
    path = tmp_path / "mine.toml"
    path.write_text('[materials.mine]\ndisplay_name = "Mine"\nkind = "hyperelastic"\nsource = "me"\n'
                    '[materials.mine.model]\ntype = "neo-hooke"\nunit = "MPa"\nc10 = 0.01\nsource = "me"\n'
                    "[materials.mine.fit]\n" + "\n".join(lines) + "\n")
    with pytest.raises(MaterialDataError) as err:
        library.load_library(path)
    assert "[materials.mine.fit]" in str(err.value) and message in str(err.value)


def _simulate(tmp_path: Path, name: str, unit: str | None) -> dict:  # type: ignore[type-arg]
    args = ["simulate", "-o", "0110", "--model", "2d", "--pressure", "15", "--increments", "3",
            "--out", str(tmp_path / name)]
    if unit is not None:
        (tmp_path / f"{name}.toml").write_text(f"[unit]\n{unit}\n")
        args += ["--unit", str(tmp_path / f"{name}.toml")]
    assert main(args) == 0
    provenance: dict = json.loads((tmp_path / name / "provenance.json").read_text())  # type: ignore[type-arg]
    return provenance | {"response": json.loads((tmp_path / name / "response.json").read_text())}


def test_unit_cast_in_ecoflex_00_30_with_a_dragon_skin_30_layer_simulates_in_2d(tmp_path: Path) -> None:
    cast = _simulate(tmp_path, "cast", 'body_material = "ecoflex_00_30"\nlayer_material = "dragon_skin_30"')
    materials = cast["model"]["materials"]
    assert materials["body"]["name"] == "ecoflex_00_30" and materials["layer"]["name"] == "dragon_skin_30"
    assert materials["body"]["fit"]["attribution"] == ATTRIBUTION  # the provenance carries the data's credit
    reference = _simulate(tmp_path, "reference", None)  # Mold Star 15 body, Smooth-Sil 950 layer
    assert reference["model"]["materials"]["body"]["name"] == "mold_star_15"
    tip = np.array(cast["response"]["tip"])
    ref_tip = np.array(reference["response"]["tip"])
    assert tip.shape == ref_tip.shape == (3, 2) and np.all(np.isfinite(tip))
    # four units of 10.5 mm: at rest the tip is at x = 42 mm; both extend, the softer body
    # (mu0 15 kPa against 131 kPa) more
    assert np.all(np.diff(tip[:, 0]) > 0) and tip[-1, 0] > ref_tip[-1, 0] > 42.0


def test_a_database_silicone_makes_the_bottom_wall(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    def tip_x(unit: str) -> float:
        (tmp_path / "unit.toml").write_text(f"[unit]\n{unit}\n")
        code, out, _ = run(capsys, "simulate", "-o", "0110", "--model", "2d", "--pressure", "15", "--increments",
                           "3", "--unit", str(tmp_path / "unit.toml"), "--json")
        data = json.loads(out)
        assert code == 0 and data["converged"]
        return float(data["levels"][-1]["tip_mm"][0])

    cast = 'body_material = "ecoflex_00_30"\nlayer_material = "dragon_skin_30"'
    # a stiffer bottom wall (Ecoflex 00-50, mu0 21 kPa, against the body's 15 kPa) extends less
    assert 42.0 < tip_x(cast + '\nbottom_material = "ecoflex_00_50"') < tip_x(cast)
