"""Synthetic scans: the model's shape moved rigidly and given noise, put back by the alignment to within the
noise; the cast's changes reach the model; ``pneumorph scan synth`` writes the scan and its truth, or nothing."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.correlation import correlate, model_shape, read_scan
from pneumorph.correlation.synthetic import ScanNoise, cast_settings, synthetic_scan, write_scan
from pneumorph.errors import ScanError, SettingsError
from pneumorph.models.factory import make_model

SETTINGS = {"fidelity": "2d", "pressure_kpa": 30.0}


@pytest.fixture(scope="module")
def nominal():  # type: ignore[no-untyped-def]
    return model_shape(make_model(4, SETTINGS).solve("0110"))


def test_the_motion_is_rigid_and_the_alignment_undoes_it_within_the_noise(nominal) -> None:
    scan, motion = synthetic_scan(nominal, ScanNoise(points=800, noise=0.05, rotation=15.0, shift=10.0, seed=3))
    assert scan.dim == 2 and len(scan.points) == 800
    assert np.linalg.det(motion.rotation) == pytest.approx(1.0, abs=1e-12)
    assert np.degrees(np.arctan2(motion.rotation[1, 0], motion.rotation[0, 0])) == pytest.approx(15.0, abs=1e-9)
    assert np.linalg.norm(motion.translation) == pytest.approx(10.0, abs=1e-9)
    result = correlate(scan, nominal)
    # the alignment maps the scan back: its rotation is the motion's inverse, to a small fraction of a degree
    back = result.alignment.transform.rotation @ motion.rotation
    assert np.degrees(np.arccos(np.clip(back[0, 0], -1, 1))) < 0.05
    # distances to the outline: the noise's normal component, 0.05 mm (800 points: within 10 %)
    assert result.outline.rms == pytest.approx(0.05, rel=0.1)


def test_the_same_seed_gives_the_same_scan_and_another_seed_another(nominal) -> None:
    a, _ = synthetic_scan(nominal, ScanNoise(points=100, seed=1))
    b, _ = synthetic_scan(nominal, ScanNoise(points=100, seed=1))
    c, _ = synthetic_scan(nominal, ScanNoise(points=100, seed=2))
    assert np.array_equal(a.points, b.points) and not np.allclose(a.points, c.points)


def test_cast_settings_change_the_unit_and_the_scales_and_refuse_the_rest() -> None:
    s = cast_settings(SETTINGS, {"wall": 1.3, "body_bulk_scale": 2.0})
    assert s["unit"]["wall"] == 1.3 and s["body_bulk_scale"] == 2.0 and s["pressure_kpa"] == 30.0
    assert cast_settings(SETTINGS, {}) == SETTINGS
    with pytest.raises(SettingsError, match="unknown cast change 'walls'; known: body_bulk_scale"):
        cast_settings(SETTINGS, {"walls": 1.3})
    with pytest.raises(SettingsError, match=r"body_shear_scale must be a finite number >= 0\.1 and <= 10, got 20\.0"):
        cast_settings(SETTINGS, {"body_shear_scale": 20.0})
    with pytest.raises(SettingsError, match="a unit library's types"):
        cast_settings({**SETTINGS, "library": "builtin"}, {"wall": 1.3})
    with pytest.raises(SettingsError, match="the cast's unit"):
        cast_settings(SETTINGS, {"wall": -1.0})


def test_write_scan_round_trips_and_refuses_a_suffix_that_does_not_hold_it(tmp_path: Path, nominal) -> None:
    scan, _ = synthetic_scan(nominal, ScanNoise(points=50, seed=0))
    assert np.allclose(read_scan(write_scan(scan, tmp_path / "t.csv")).points, scan.points, atol=5e-6)
    with pytest.raises(ScanError, match=r"a 2D trace goes to a \.csv file"):
        write_scan(scan, tmp_path / "t.xyz")
    with pytest.raises(ScanError, match="between 10 and 500000 points"):
        synthetic_scan(nominal, ScanNoise(points=3))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]


def test_scan_synth_writes_a_scan_of_the_changed_cast_and_its_truth(tmp_path: Path, nominal,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "scans" / "cast.csv"
    args = ["scan", "synth", "0110", "--model", "2d", "--pressure", "30", "--set", "wall=1.3", "--set",
            "body_shear_scale=0.8", "--points", "800", "--seed", "5", "-o", str(out)]
    assert main(args) == 0
    captured = capsys.readouterr()
    assert captured.out.strip() == f"wrote 800 points (0.05 mm noise, seed 5) to {out}; the truth to {out}.json"
    assert ("synthetic scan of design 0110's cast at 30 kPa (2d model, wall = 1.3, body_shear_scale = 0.8)"
            in captured.err)
    assert "10/10" in captured.err
    truth = json.loads(Path(f"{out}.json").read_text())
    assert truth["changes"] == {"wall": 1.3, "body_shear_scale": 0.8} and truth["settings"]["unit"]["wall"] == 1.3
    assert truth["provenance"]["pneumorph"]
    scan = read_scan(out)
    cast = model_shape(make_model(4, truth["settings"]).solve("0110"))
    # the scan is the cast, within its noise; the nominal model is measurably elsewhere
    assert correlate(scan, cast).outline.rms == pytest.approx(0.05, rel=0.1)
    assert correlate(scan, nominal).outline.rms > 0.1


@pytest.mark.parametrize(("args", "message"), [
    (["--model", "2d", "--set", "walls=1.3"], "unknown cast change 'walls'"),
    (["--model", "2d", "--set", "wall"], "give KEY=VALUE"),
    (["--model", "2d", "--set", "wall=thin"], "give KEY=VALUE"),
    (["--model", "2d", "--set", "wall=-1"], "the cast's unit: unit wall must be positive"),
    (["--model", "3d"], "the 3D model's scan is an .xyz file"),
    (["--model", "2d", "--noise", "-1"], "--noise"),
])
def test_scan_synth_refuses_bad_input_and_writes_nothing(tmp_path: Path, args: list[str], message: str,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["scan", "synth", "0110", "-o", str(tmp_path / "s" / "c.csv"), *args])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and message in err[0], err
    assert not list(tmp_path.iterdir())
