"""``pneumorph materials list|show|characterise``: output and exit codes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pneumorph.materials.library import builtin as library
from tests.cli import run


@pytest.fixture(autouse=True)
def _clean_registry():
    library.clear_registered()
    yield
    library.clear_registered()


def test_list(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "materials", "list")
    assert code == 0
    for name in (*library.names(), *library.filler_names()):
        assert name in out
    assert "131.4" in out  # Mold Star 15 mu0 in kPa


def test_list_json(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "materials", "list", "--json")
    data = json.loads(out)
    assert code == 0
    assert [m["name"] for m in data["materials"]] == list(library.names())
    ms15 = next(m for m in data["materials"] if m["name"] == "mold_star_15")
    assert ms15["bulk_modulus_MPa"] == 0.119 and ms15["assumed"] == []
    assert [f["name"] for f in data["fillers"]] == ["ellis2020_eq5_2"]


def test_show_mold_star_15(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "materials", "show", "Mold Star 15")
    assert code == 0
    for text in ("Table A.4", "-6.503e-06", "0.2169", "-21.32", "Marc", "FElupe", "0.127971",
                 "119 kPa = 0.119 MPa", "1139 kg/m^3", "245.3 micro-mm/mm/degC", "0.9926",
                 "mu0 = 0.131391 MPa", "assumed values: none"):
        assert text in out, text


def test_show_json_has_both_conventions(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "materials", "show", "smooth-sil-950", "--json")
    d = json.loads(out)
    assert code == 0
    assert d["shear_modulus"]["marc"] == pytest.approx(d["shear_modulus"]["felupe"], rel=1e-12)
    assert d["shear_modulus"]["marc"] == pytest.approx(0.53338, abs=1e-5)
    assert d["properties"]["bulk_modulus"] | {"source": None} == {
        "value": 0.679, "unit": "MPa", "printed": 679, "printed_unit": "kPa", "source": None, "assumed": False
    }
    assert d["model"]["convention"] == "marc"


def test_show_flags_assumed_values(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "materials", "show", "ecoflex_0030")
    assert code == 0
    assert "33.8 kPa = 0.0338 MPa  [ASSUMED]" in out and "reason:" in out
    assert "assumed values: bulk_modulus" in out


def test_show_filler(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "materials", "show", "ellis2020_eq5_2")
    assert code == 0
    assert "E(P) = 0.0643 - 1.82 P + 12.4 P^2" in out and "0-45 kPa" in out
    code, out, _ = run(capsys, "materials", "show", "ellis2020_eq5_2", "--json")
    assert json.loads(out)["printed"]["coefficients"] == [0.0643, -1.82, 12.4]


def test_show_unknown_exits_2(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "materials", "show", "unobtainium")
    assert code == 2 and out == ""
    assert err.startswith("error: unknown material 'unobtainium'; known materials: ecoflex_0030")
    assert "ellis2020_eq5_2" in err and len(err.strip().splitlines()) == 1


def test_show_user_library(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "mine.toml"
    path.write_text(
        '[materials.gel]\ndisplay_name = "Gel"\nkind = "hyperelastic"\nsource = "mine"\n'
        '[materials.gel.model]\ntype = "neo-hooke"\nunit = "kPa"\nc10 = 5\nsource = "mine"\n',
        encoding="utf-8",
    )
    code, out, _ = run(capsys, "materials", "show", "gel", "--library", str(path))
    assert code == 0 and "mu0 = 0.01 MPa" in out
    path.write_text(path.read_text().replace("c10 = 5", "c10 = -5"), encoding="utf-8")
    library.clear_registered()
    code, _, err = run(capsys, "materials", "show", "gel", "--library", str(path))
    assert code == 2 and str(path) in err and "materials.gel.model" in err


# ---------------------------------------------------------------------------------------
# characterise
# ---------------------------------------------------------------------------------------


def write_csv(tmp_path: Path, header: str, rows: np.ndarray, name: str = "data.csv") -> Path:
    path = tmp_path / name
    body = "\n".join(",".join(f"{v:.12g}" for v in row) for row in rows)
    path.write_text(header + "\n" + body + "\n", encoding="utf-8")
    return path


def test_characterise_poisson(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    eps = np.linspace(0.0, 2.0, 41)
    nu, e = 0.3, 0.5
    path = write_csv(tmp_path, "axial_strain,transverse_strain,axial_stress", np.c_[eps, -nu * eps, e * eps])
    code, out, _ = run(capsys, "materials", "characterise", "poisson", str(path), "--json")
    d = json.loads(out)
    assert code == 0
    assert d["points"] == 30 and d["strain_range_percent"] == [0.0, 150.0]
    assert d["mean_poisson_ratio"] == pytest.approx(nu)
    assert d["mean_bulk_modulus_MPa"] == pytest.approx(e / (3 * (1 - 2 * nu)))
    code, out, _ = run(capsys, "materials", "characterise", "poisson", str(path), "--strain-range", "0", "50")
    assert code == 0 and "416.7 kPa" in out and "10 points" in out


def test_characterise_poisson_percent_and_semicolons(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "pct.csv"
    path.write_text("Axial_Strain; Transverse_Strain\n10; -4\n20; -8\n", encoding="utf-8")
    code, out, _ = run(capsys, "materials", "characterise", "poisson", str(path), "--strain-unit", "percent", "--json")
    d = json.loads(out)
    assert code == 0 and d["mean_poisson_ratio"] == pytest.approx(0.4) and d["mean_bulk_modulus_MPa"] is None


@pytest.mark.parametrize(
    ("content", "where", "what"),
    [
        ("axial_strain,stress\n0.1,1\n", "row 1", "missing column 'transverse_strain'"),
        ("axial_strain,transverse_strain\n0.1,-0.03\n0.2,-0.06\n0.3,abc\n", "row 4", "expected a number, got 'abc'"),
        ("axial_strain,transverse_strain\n0.1,-0.03\n0.2\n", "row 3", "1 field(s)"),
        ("axial_strain,transverse_strain\n0.1,nan\n", "row 2", "finite"),
        ("", "row 1", "empty file"),
        ("axial_strain,transverse_strain\n", "row 2", "no data rows"),
    ],
)
def test_bad_csv_names_file_and_row(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], content: str, where: str, what: str
) -> None:
    path = tmp_path / "bad.csv"
    path.write_text(content, encoding="utf-8")
    code, _, err = run(capsys, "materials", "characterise", "poisson", str(path))
    assert code == 2
    assert f"{path}, {where}: " in err and what in err


def test_characterise_poisson_nu_half_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    eps = np.array([0.1, 0.2])
    path = write_csv(tmp_path, "axial_strain,transverse_strain,axial_stress", np.c_[eps, -0.5 * eps, eps])
    code, _, err = run(capsys, "materials", "characterise", "poisson", str(path))
    assert code == 2 and ">= 0.5" in err


def test_characterise_thermal(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    t = np.linspace(85.0, 20.0, 10)
    path = write_csv(tmp_path, "temperature,strain", np.c_[t, 214.2e-6 * (t - 20.0)])
    code, out, _ = run(capsys, "materials", "characterise", "thermal", str(path), "--json")
    d = json.loads(out)
    assert code == 0 and d["alpha_micro_per_degC"] == pytest.approx(214.2, rel=1e-9) and d["points"] == 10
    code, out, _ = run(capsys, "materials", "characterise", "thermal", str(path))
    assert "alpha = 214.2" in out


def test_characterise_bilinear(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    eps = np.linspace(0.0, 0.6, 61)
    sig = np.where(eps <= 0.356, 0.080 * eps, 0.080 * 0.356 + 16.5 * (eps - 0.356))
    path = write_csv(tmp_path, "strain,stress", np.c_[eps, sig])
    code, out, _ = run(capsys, "materials", "characterise", "bilinear", str(path), "--json")
    d = json.loads(out)
    assert code == 0
    assert d["primary_modulus_MPa"] == pytest.approx(0.080, rel=1e-6)
    assert d["secondary_modulus_MPa"] == pytest.approx(16.5, rel=1e-6)
    assert d["transition_strain"] == pytest.approx(0.356, rel=1e-6)
    code, out, _ = run(capsys, "materials", "characterise", "bilinear", str(path))
    assert "primary modulus   80 kPa" in out and "35.6 % strain" in out


def test_characterise_help_documents_columns(capsys: pytest.CaptureFixture[str]) -> None:
    for command, columns in {
        "poisson": ("axial_strain", "transverse_strain", "axial_stress"),
        "thermal": ("temperature", "strain"),
        "bilinear": ("strain", "stress"),
    }.items():
        code, out, _ = run(capsys, "materials", "characterise", command, "--help")
        assert code == 0
        for col in columns:
            assert col in out


def test_missing_file_is_a_usage_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "materials", "characterise", "thermal", str(tmp_path / "none.csv"))
    assert code == 2 and "no such file" in err
