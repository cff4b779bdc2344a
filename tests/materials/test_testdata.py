"""Reading stress-stretch test data: layouts, conversions, bad input, bundled data."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import DataFormatError, UnknownDatasetError
from pneumorph.materials.characterisation.datasets import list_datasets, load_dataset, read_test_data
from pneumorph.materials.characterisation.testdata import TestCurve, TestData, guess_mode, read_curve

SORO = "marechal2021_SoRo-Materials-DB/Tensile-Tests-Data"


@pytest.fixture(scope="module")
def cml(reference_dir: Path) -> Path:
    return reference_dir / "treloar1944_CML-HyperData"


def _raw(path: Path) -> np.ndarray:
    return np.loadtxt(path)


# --------------------------------------------------------------------------- layouts


def test_cml_tab_no_header(cml: Path) -> None:
    c = read_curve(cml / "Treloar_ut.dat")
    raw = _raw(cml / "Treloar_ut.dat")
    assert c.mode == "uniaxial"  # from the file name
    assert len(c) == 25
    np.testing.assert_array_equal(c.stretch, raw[:, 0])
    np.testing.assert_array_equal(c.stress, raw[:, 1])
    assert (c.stretch[0], c.stress[0]) == (1.0, 0.0)
    assert c.stretch[-1] == 7.6 and c.stress[-1] == pytest.approx(64.4 * 0.0981)
    assert read_curve(cml / "Treloar_et.dat").mode == "equibiaxial"
    assert read_curve(cml / "Treloar_ps.dat").mode == "planar"


def test_chongran_zhao_reversed_columns(reference_dir: Path, cml: Path) -> None:
    for mode, short in (("UT", "ut"), ("ET", "et"), ("PS", "ps")):
        path = reference_dir / "treloar1944_Chongran-Zhao/Treloar_1944" / mode / "stress_stretch.txt"
        c = read_curve(path, columns="stress,stretch")
        ref = _raw(cml / f"Treloar_{short}.dat")[1:]  # CML adds the (1, 0) row
        assert c.mode == guess_mode(cml / f"Treloar_{short}.dat")
        np.testing.assert_allclose(c.stretch, ref[:, 0], atol=5e-5)
        np.testing.assert_allclose(c.stress, ref[:, 1], atol=5e-5)


def test_meunier_compression_and_wrong_column_order(reference_dir: Path) -> None:
    path = reference_dir / "meunier2008-silicone_Chongran-Zhao/Meunier_2008/UT/stress_stretch.txt"
    c = read_curve(path, columns=("stress", "stretch"))
    assert c.mode == "uniaxial" and len(c) == 33
    assert c.stretch[0] == pytest.approx(0.49) and c.stretch[-1] == pytest.approx(2.17, abs=0.01)
    assert c.stress[0] == pytest.approx(-1.3878)
    assert np.all(c.stress[c.stretch < 1] < 0) and np.all(c.stress[c.stretch > 1] > 0)
    with pytest.raises(DataFormatError, match=r"stress_stretch\.txt, row 1: stretch must be positive"):
        read_curve(path)  # stress first: the first column cannot be a stretch


def test_soro_database_format(reference_dir: Path) -> None:
    path = reference_dir / SORO / "Ecoflex 00-30.csv"
    c = read_curve(path)
    raw = np.genfromtxt(path, delimiter=";", skip_header=18)
    assert c.mode == "uniaxial"
    assert c.metadata["Material"] == "EcoFlex30"
    assert c.metadata["Strain Measurement"] == "Global"
    assert c.metadata["Material supplier URL"].startswith("https://www.smooth-on.com")
    assert c.description == "EcoFlex30"
    # engineering columns, stretch = 1 + e; the peak stress is the last row here
    assert len(c) == raw.shape[0] == 705
    np.testing.assert_allclose(c.stretch, 1.0 + raw[:, 3], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(c.stress, raw[:, 4])


def test_soro_failure_truncated_at_peak(reference_dir: Path) -> None:
    path = reference_dir / SORO / "Dragon Skin 30.csv"
    raw = np.genfromtxt(path, delimiter=";", skip_header=18)
    assert raw.shape[0] == 311 and raw[-1, 4] < raw[-2, 4]  # stress drops in the last row
    c = read_curve(path)
    assert len(c) == 310 and c.stress[-1] == raw[:, 4].max()
    assert any("row 328" in n and "1 later rows dropped" in n for n in c.notes)
    assert len(read_curve(path, truncate="none")) == 311


def test_true_stress_and_true_strain_conversion(reference_dir: Path) -> None:
    """The database's true columns, converted with P = sigma / lambda, give its engineering ones."""
    path = reference_dir / SORO / "Dragon Skin 30.csv"
    eng = read_curve(path)
    true = read_curve(path, columns="skip,true-strain,stress,skip,skip", stress_kind="true")
    assert any("P = sigma / lambda" in n for n in true.notes)
    np.testing.assert_allclose(true.stretch, eng.stretch, rtol=2e-5)
    np.testing.assert_allclose(true.stress, eng.stress, rtol=5e-5, atol=1e-6)


@pytest.mark.parametrize("mode", ["uniaxial", "equibiaxial", "planar"])
def test_true_stress_every_mode(tmp_path: Path, mode: str) -> None:
    f = tmp_path / "t.csv"
    f.write_text("stretch,true stress (kPa)\n1.0,0\n1.5,300\n2.0,800\n")
    c = read_curve(f, mode)
    np.testing.assert_allclose(c.stress, [0.0, 0.3 / 1.5, 0.8 / 2.0])


def test_header_percent_kpa_comma(tmp_path: Path) -> None:
    f = tmp_path / "ecoflex.csv"
    f.write_text("# my test\nEngineering strain (%),Engineering stress (kPa)\n0,0\n50,20\n100,35.5\n")
    c = read_curve(f)
    np.testing.assert_allclose(c.stretch, [1.0, 1.5, 2.0])
    np.testing.assert_allclose(c.stress, [0.0, 0.020, 0.0355])
    assert any("kPa" in n for n in c.notes)


def test_header_units_with_explicit_columns(tmp_path: Path) -> None:
    f = tmp_path / "reversed.csv"
    f.write_text("Stress [kPa],Strain [%]\n0,0\n12,20\n")
    c = read_curve(f, columns="stress,strain")
    np.testing.assert_allclose(c.stretch, [1.0, 1.2])
    np.testing.assert_allclose(c.stress, [0.0, 0.012])
    assert read_curve(f, columns="stress,strain", stress_unit="MPa").stress[1] == 12.0


def test_semicolon_decimal_comma_and_whitespace(tmp_path: Path) -> None:
    f = tmp_path / "a.txt"
    f.write_text("Strain;Stress (MPa);Stretch\n0,0;0,0;1,0\n0,5;0,12;1,5\n")
    c = read_curve(f)  # stretch column preferred over strain
    np.testing.assert_allclose(c.stretch, [1.0, 1.5])
    np.testing.assert_allclose(c.stress, [0.0, 0.12])
    g = tmp_path / "b.dat"
    g.write_text("  1.0   0.0\n  1.2   0.1\n\n  1.4   0.2   \n")
    np.testing.assert_allclose(read_curve(g).stress, [0.0, 0.1, 0.2])
    h = tmp_path / "c.txt"
    h.write_text("1.0;0.0\n1.2;0.1\n")
    np.testing.assert_allclose(read_curve(h, columns="strain,stress").stretch, [2.0, 2.2])


def test_kgf_per_cm2(reference_dir: Path, tmp_path: Path) -> None:
    """Treloar's original kgf/cm^2 numbers scale to the transcription's exact MPa column."""
    src = reference_dir / "transcribed_by-helper/treloar1944_kgf-cm2_felupe-ex14.csv"
    rows = [ln.split(",") for ln in src.read_text().splitlines() if ln.startswith("UT,")]
    f = tmp_path / "ut_kgf.csv"
    f.write_text("".join(f"{r[1]},{r[2]}\n" for r in rows))
    c = read_curve(f, stress_unit="kgf/cm^2")
    np.testing.assert_allclose(c.stress, [float(r[3]) for r in rows], atol=1e-6)


def test_decreasing_stretch_is_sorted(tmp_path: Path) -> None:
    f = tmp_path / "compression.csv"
    f.write_text("stretch,stress\n1.0,0\n0.9,-0.05\n0.8,-0.12\n")
    c = read_curve(f)
    np.testing.assert_allclose(c.stretch, [0.8, 0.9, 1.0])
    np.testing.assert_allclose(c.stress, [-0.12, -0.05, 0.0])


def test_unloading_branch(tmp_path: Path) -> None:
    f = tmp_path / "cycle.csv"
    f.write_text("1.0,0\n1.5,0.2\n2.0,0.5\n1.6,0.25\n1.2,0.05\n")
    with pytest.raises(DataFormatError, match=r"cycle\.csv, row 4: stretch 1\.6 does not increase"):
        read_curve(f)
    c = read_curve(f, truncate="loading")
    np.testing.assert_allclose(c.stretch, [1.0, 1.5, 2.0])


# --------------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("text", "row", "what"),
    [
        ("stretch,stress\n1.0,0\n1.1,0.1,7\n", 3, "expected 2 columns, found 3"),
        ("1.0,0\n1.1,abc\n", 2, "column 2: expected a number, found 'abc'"),
        ("1.0,0\n1.1,0.1\n1.2,nan\n", 3, "expected a finite number, found 'nan'"),
        ("0.0,0\n1.1,0.1\n", 1, "stretch must be positive"),
        ("1.0,0\n-1.1,0.1\n", 2, "stretch must be positive"),
        ("# c\n1.0,0\n1.2,0.1\n1.2,0.2\n", 4, "does not increase"),
        ("stretch\tstress\n1.0\t0\nx\ty\n", 3, "expected a number"),
    ],
)
def test_bad_rows_name_file_and_row(tmp_path: Path, text: str, row: int, what: str) -> None:
    f = tmp_path / "broken_file.csv"
    f.write_text(text)
    with pytest.raises(DataFormatError) as err:
        read_curve(f)
    msg = str(err.value)
    assert "broken_file.csv" in msg and f"row {row}:" in msg and what in msg, msg
    assert err.value.row == row


def test_bad_files(tmp_path: Path) -> None:
    empty = tmp_path / "empty.csv"
    empty.write_text("# nothing\n\n")
    with pytest.raises(DataFormatError, match=r"empty\.csv: no data rows"):
        read_curve(empty)
    one = tmp_path / "one.csv"
    one.write_text("1.0,0\n")
    with pytest.raises(DataFormatError, match="at least 2 data rows"):
        read_curve(one)
    unnamed = tmp_path / "unnamed.csv"
    unnamed.write_text("a,b,c\n1,2,3\n")
    with pytest.raises(DataFormatError, match=r"unnamed.csv, row 1: cannot tell"):
        read_curve(unnamed)
    ok = tmp_path / "ok.csv"
    ok.write_text("1,0\n2,1\n")
    with pytest.raises(DataFormatError, match="unknown stress unit"):
        read_curve(ok, stress_unit="bar")
    with pytest.raises(DataFormatError, match=r"missing\.csv: no such file"):
        read_curve(tmp_path / "missing.csv")


# --------------------------------------------------------------------------- containers and data sets


def test_bundled_treloar_equals_reference(cml: Path) -> None:
    data = load_dataset("treloar1944")
    assert data.modes == ("uniaxial", "equibiaxial", "planar")
    for mode, short in (("uniaxial", "ut"), ("equibiaxial", "et"), ("planar", "ps")):
        raw = _raw(cml / f"Treloar_{short}.dat")
        c = data.curve(mode)
        np.testing.assert_array_equal(c.stretch, raw[:, 0])
        np.testing.assert_array_equal(c.stress, raw[:, 1])
    info = {d.name: d for d in list_datasets()}["treloar1944"]
    assert "GPL-3.0" in info.licence and "10.1039/tf9444000059" in info.citation
    folder = Path(data.curves[0].source).parent
    assert "Computational-Micromechanics-Laboratory/HyperData" in (folder / "SOURCE.md").read_text()


def test_read_test_data_mixes_files_and_datasets(reference_dir: Path) -> None:
    meunier = reference_dir / "meunier2008-silicone_Chongran-Zhao/Meunier_2008"
    files = [meunier / m / "stress_stretch.txt" for m in ("UT", "ET", "PS")]
    d = read_test_data(files, columns="stress,stretch")
    assert d.modes == ("uniaxial", "equibiaxial", "planar")
    assert [len(d.curve(m)) for m in d.modes] == [33, 14, 19]
    both = read_test_data(["treloar1944", files[0]], columns="stress,stretch")
    merged = both.curve("uniaxial")  # two uniaxial curves become one, sorted
    assert len(merged) == 25 + 33 and np.all(np.diff(merged.stretch) >= 0)
    with pytest.raises(UnknownDatasetError, match=r"'nonesuch'.*treloar1944"):
        read_test_data(["nonesuch"])
    with pytest.raises(UnknownDatasetError):
        load_dataset("nonesuch")


def test_restrict_and_types(cml: Path) -> None:
    d = load_dataset("treloar1944")
    r = d.restrict(max_stretch=2.0)
    assert all(c.stretch.max() <= 2.0 for c in r.curves)
    assert len(r.curve("planar")) == int(np.sum(_raw(cml / "Treloar_ps.dat")[:, 0] <= 2.0)) == 7
    with pytest.raises(DataFormatError, match="no data point"):
        d.restrict(min_stretch=100)
    c = d.curves[0]
    with pytest.raises((AttributeError, TypeError)):
        c.mode = "planar"  # type: ignore[misc]
    with pytest.raises(ValueError):
        c.stretch[0] = 2.0
    with pytest.raises(ValueError, match="unknown loading mode"):
        TestCurve("shear", [1.0, 2.0], [0.0, 1.0])
    with pytest.raises(ValueError):
        TestData(())
    assert math.isclose(float(c.stretch[-1]), 7.6)


def test_guess_mode() -> None:
    assert guess_mode("Treloar_ut.dat") == "uniaxial"
    assert guess_mode("data/ET/stress_stretch.txt") == "equibiaxial"
    assert guess_mode("silicone pure shear.csv") == "planar"
    assert guess_mode("Ecoflex 00-30.csv") is None
