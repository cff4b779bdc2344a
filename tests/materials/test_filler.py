"""The pressure-dependent filler law (Eq 5.2) and its calibrated range."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import MaterialDataError, PressureRangeError
from pneumorph.materials.laws.filler import FillerLaw
from pneumorph.materials.library import builtin as library
from pneumorph.materials.library.builtin import eq_5_2


@pytest.fixture(scope="module")
def printed(shared_dir: Path) -> tuple[float, float, float]:
    """(c0, c1, c2) of Eq 5.2 as printed: E = c0 - c1 P + c2 P^2."""
    text = (shared_dir / "seed/000_2f6eb7f132ab41d4.txt").read_text(encoding="utf-8")
    match = re.search(r"\$\$E = ([\d.]+) - ([\d.]+)P \+ ([\d.]+)P\^2 \(5\.2\)\$\$", text)
    assert match, "Eq 5.2 not found in the dissertation text"
    c0, c1, c2 = (float(x) for x in match.groups())
    return c0, -c1, c2


def printed_polynomial(c: tuple[float, float, float], p_mpa: float) -> float:
    return c[0] + c[1] * p_mpa + c[2] * p_mpa**2


def test_coefficients_and_range_as_printed(printed: tuple[float, float, float]) -> None:
    law = eq_5_2()
    assert law.coefficients == printed == (0.0643, -1.82, 12.4)
    assert law.pressure_range == (0.0, 0.045)
    assert law.printed == ((0.0643, -1.82, 12.4), "MPa", "MPa")
    assert "Eq 5.2" in law.source


@pytest.mark.parametrize("kpa", [0.0, 22.5, 45.0])
def test_values_equal_the_printed_polynomial(printed: tuple[float, float, float], kpa: float) -> None:
    p = kpa / 1000.0
    assert eq_5_2().modulus(p) == pytest.approx(printed_polynomial(printed, p), rel=1e-14)


def test_known_values() -> None:
    law = eq_5_2()
    assert law.modulus(0.0) == 0.0643
    assert law.modulus(0.045) == pytest.approx(0.0643 - 1.82 * 0.045 + 12.4 * 0.045**2, rel=1e-14)
    assert law.modulus(0.045) == pytest.approx(0.00751, rel=1e-10)
    assert law.minimum() == pytest.approx((0.045, 0.00751), rel=1e-10)


def test_vectorised_with_shape() -> None:
    p = np.linspace(0.0, 0.045, 10).reshape(2, 5)
    e = eq_5_2().modulus(p)
    assert isinstance(e, np.ndarray) and e.shape == (2, 5)
    np.testing.assert_allclose(e, 0.0643 - 1.82 * p + 12.4 * p**2, rtol=1e-14)
    assert isinstance(eq_5_2().modulus(0.01), float)


def test_60_kpa_is_refused() -> None:
    """Eq 5.2 turns negative between ~59 and ~88 kPa; 60 kPa is outside 0-45 kPa anyway."""
    roots = sorted(np.roots([12.4, -1.82, 0.0643]).real * 1e3)
    assert 59.0 < roots[0] < 60.0 and 87.0 < roots[1] < 88.0
    with pytest.raises(PressureRangeError) as info:
        eq_5_2().modulus(0.060)
    assert "60 kPa" in str(info.value) and "0-45 kPa" in str(info.value)
    assert info.value.pressure == 0.060


@pytest.mark.parametrize("p", [-0.001, 0.0451, [0.01, 0.02, 0.05]])
def test_outside_range_refused(p: object) -> None:
    with pytest.raises(PressureRangeError):
        eq_5_2().modulus(p)


def test_ramp_rounding_at_the_ends_is_accepted() -> None:
    law = eq_5_2()
    assert law.modulus(0.045 * (1 + 1e-13)) == pytest.approx(0.00751, rel=1e-9)
    assert law.modulus(-1e-15) == 0.0643


def test_non_finite_pressure_refused() -> None:
    with pytest.raises(ValueError, match="finite"):
        eq_5_2().modulus(float("nan"))


def test_non_positive_modulus_inside_range_refused_at_construction() -> None:
    with pytest.raises(MaterialDataError, match="not positive"):
        FillerLaw("eq5_2_wide", "wide", (0.0643, -1.82, 12.4), (0.0, 0.070), 0.3)
    # positive at both ends (0.01 MPa), negative at the interior vertex P = 0.05 MPa
    with pytest.raises(MaterialDataError, match=r"-0\.015 MPa at 50 kPa"):
        FillerLaw("dip", "dip", (0.01, -1.0, 10.0), (0.0, 0.1), 0.3)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"pressure_range": (0.02, 0.01)}, "lower < upper"),
        ({"pressure_range": (-0.01, 0.01)}, "0 <= lower"),
        ({"poisson_ratio": 0.5}, "Poisson"),
        ({"coefficients": ()}, "coefficients"),
    ],
)
def test_construction_errors(kwargs: dict, message: str) -> None:
    args = {"name": "f", "display_name": "f", "coefficients": (0.06,), "pressure_range": (0.0, 0.045),
            "poisson_ratio": 0.3}
    with pytest.raises(MaterialDataError, match=message):
        FillerLaw(**(args | kwargs))


def test_poisson_ratio_is_flagged_assumed() -> None:
    law = eq_5_2()
    assert law.poisson_ratio == 0.3 and law.poisson_ratio_assumed
    assert law.poisson_ratio_reason and law.poisson_ratio_source


def test_unit_conversion_of_a_user_law(tmp_path: Path) -> None:
    """The same law written in kPa (E[kPa] = 64.3 - 1.82 P[kPa] + 0.0124 P[kPa]^2)."""
    text = """
[fillers.eq5_2_kpa]
display_name = "Eq 5.2 in kPa"
source = "rewritten"
coefficients = [64.3, -1.82, 0.0124]
modulus_unit = "kPa"
pressure_unit = "kPa"
calibrated_range = [0.0, 0.045]
range_unit = "MPa"
[fillers.eq5_2_kpa.poisson_ratio]
value = 0.3
unit = "-"
source = "s"
"""
    path = tmp_path / "f.toml"
    path.write_text(text, encoding="utf-8")
    law = library.load_library(path).filler("eq5_2_kpa")
    p = np.linspace(0.0, 0.045, 7)
    np.testing.assert_allclose(law.modulus(p), eq_5_2().modulus(p), rtol=1e-12)
    bad = text.replace("[0.0, 0.045]", "[0.0, 0.07]")
    path.write_text(bad, encoding="utf-8")
    with pytest.raises(MaterialDataError, match=r"fillers\.eq5_2_kpa.*not positive"):
        library.load_library(path)


def test_umat_at_a_pressure() -> None:
    pytest.importorskip("felupe")
    law = eq_5_2()
    umat = law.umat(0.0225)
    e = law.modulus(0.0225)
    assert umat.material.mu == pytest.approx(e / (2 * 1.3), rel=1e-12)
    with pytest.raises(PressureRangeError):
        law.umat(0.05)


def test_to_dict() -> None:
    d = eq_5_2().to_dict()
    assert d["calibrated_range_kPa"] == pytest.approx([0.0, 45.0])
    assert d["printed"]["coefficients"] == [0.0643, -1.82, 12.4]
    assert d["poisson_ratio"]["assumed"] is True
