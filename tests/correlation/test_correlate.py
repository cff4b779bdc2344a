"""Scan correlation: a synthetic scan (the model's own deformed surface, moved, with noise) is
put back where it came from, within the noise; a photo trace of unknown scale too."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pneumorph.cli import main
from pneumorph.correlation import Scan, Transform, correlate, fit_transform, icp, model_shape, read_scan
from pneumorph.errors import ScanError
from pneumorph.fem import StepSettings
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D

RAMP = RampSpec(0.02, StepSettings(increments=2, substeps=1))
SIGMA = 0.05  # mm of scanner noise


@pytest.fixture(scope="module")
def shape3d():  # type: ignore[no-untyped-def]
    return model_shape(Full3D(4, ramp_spec=RAMP).solve("0110"))


@pytest.fixture(scope="module")
def shape2d():  # type: ignore[no-untyped-def]
    return model_shape(Reduced2D(4, ramp_spec=RAMP).solve("0110"))


def test_matched_points_give_the_transform_exactly() -> None:
    rng = np.random.default_rng(4)
    p = rng.normal(size=(30, 3))
    true = Transform(Rotation.from_rotvec([0.4, 0.1, -0.7]).as_matrix(), np.array([3.0, -2.0, 1.0]), 1.7)
    found = fit_transform(p, true(p), scale=True)
    assert np.allclose(found.rotation, true.rotation, atol=1e-12)
    assert np.allclose(found.translation, true.translation, atol=1e-12) and found.scale == pytest.approx(1.7)
    assert np.linalg.det(found.rotation) == pytest.approx(1.0)


def test_a_moved_noisy_3d_scan_is_put_back_within_the_noise(shape3d) -> None:  # type: ignore[no-untyped-def]
    rng = np.random.default_rng(0)
    true = Transform(Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix(), np.array([5.0, -3.0, 7.0]))
    points = shape3d.surface[rng.choice(len(shape3d.surface), 1000, replace=False)]
    scan = Scan(true(points) + rng.normal(scale=SIGMA, size=points.shape), None, "synthetic")
    result = correlate(scan, shape3d)
    back = true.then(result.alignment.transform)  # the identity if the transform was recovered
    assert back.angle_deg < 0.1 and np.linalg.norm(back.translation) < SIGMA
    # the surface distances are the noise: RMS sigma*sqrt(3) for 3D Gaussian noise
    assert result.surface.rms == pytest.approx(SIGMA * np.sqrt(3), rel=0.1)
    assert result.centreline.count == 4 and result.centreline.max < 3 * SIGMA


def test_a_photo_trace_of_unknown_scale_is_aligned_in_the_plane(shape2d) -> None:  # type: ignore[no-untyped-def]
    rng = np.random.default_rng(1)
    outline = shape2d.samples[rng.choice(len(shape2d.samples), 800, replace=False)]
    turn = Rotation.from_rotvec([0.0, 0.0, 0.4]).as_matrix()[:2, :2]
    pixels = (outline @ turn.T + [10.0, 4.0]) / 0.2 + rng.normal(scale=0.25, size=outline.shape)  # 0.2 mm/px
    scan = Scan(pixels * 0.2 * 1.03, None, "photo")  # the scale given is 3 % off
    result = correlate(scan, shape2d, scale=True)
    t = result.alignment.transform
    assert t.scale == pytest.approx(1 / 1.03, rel=2e-3)
    assert t.angle_deg == pytest.approx(np.degrees(0.4), abs=0.1)
    assert result.outline.rms < 2 * 0.25 * 0.2  # the tracing noise, in mm


def test_icp_finds_a_curve_from_any_start() -> None:
    t = np.linspace(0, 3, 5000)
    model = np.c_[100 * t / 3, 10 * np.sin(t)]  # sampled every 0.02 mm
    u = np.random.default_rng(2).uniform(0, 3, 150)  # the scan's points lie between the model's samples
    curve = np.c_[100 * u / 3, 10 * np.sin(u)]
    for angle in (0.2, 2.5, -2.0):
        c, s = np.cos(angle), np.sin(angle)
        scan = (curve - [5, 1]) @ np.array([[c, s], [-s, c]])
        tangent = np.gradient(model, axis=0)
        normals = np.c_[-tangent[:, 1], tangent[:, 0]] / np.linalg.norm(tangent, axis=1, keepdims=True)
        found = icp(scan, model, normals=normals)
        # exact up to the 0.02 mm sampling of the model: the points slide along it to the true fit
        assert found.rms < 0.01 and abs(found.transform.angle_deg - np.degrees(abs(angle))) < 1e-4


def test_scans_of_the_wrong_size_or_no_scan_at_all_are_refused(tmp_path: Path, shape3d) -> None:  # type: ignore[no-untyped-def]
    metres = Scan(shape3d.surface / 1000.0, None, "in-metres")
    with pytest.raises(ScanError, match="--scan-unit"):
        correlate(metres, shape3d)
    empty = tmp_path / "empty.stl"
    empty.write_bytes(b"")
    with pytest.raises(ScanError, match="empty"):
        read_scan(empty)
    garbage = tmp_path / "garbage.stl"
    garbage.write_bytes(b"solid nonsense\nthis is not a facet\n" * 3)
    with pytest.raises(ScanError, match=r"garbage\.stl"):
        read_scan(garbage)
    few = tmp_path / "few.csv"
    few.write_text("x,y\n1,2\n3,4\n", encoding="utf-8")
    with pytest.raises(ScanError, match="at least 10"):
        read_scan(few)
    few.write_text("a,b\n" + "1,2\n" * 12, encoding="utf-8")
    with pytest.raises(ScanError, match="header"):
        read_scan(few)


def test_scans_past_a_kilometre_are_refused_in_one_line_without_a_warning(tmp_path: Path) -> None:
    """Coordinates of 1e300 mm overflowed when squared for the spread (a RuntimeWarning beside the refusal);
    spread ones of 1e305 mm reached the length check as a scan spanning "inf mm", with another warning."""
    import warnings

    from pneumorph.correlation.scans import MAX_SCAN_MM

    same = tmp_path / "same.csv"
    same.write_text("x,y\n" + "1e300,1e300\n" * 50, encoding="utf-8")
    spread = tmp_path / "spread.csv"
    spread.write_text("x,y\n" + "".join(f"{i * 1e305:g},{(i % 7) * 1e305:g}\n" for i in range(60)),
                      encoding="utf-8")
    metres = tmp_path / "metres.csv"  # 1.18 m across in metres: 1,180 mm; times 1e3 more: 1.18e6 mm, past the limit
    metres.write_text("x,y\n" + "".join(f"{i * 0.02:g},{(i % 7) * 0.01:g}\n" for i in range(60)), encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ScanError, match=r"a coordinate of 1e\+300 mm, and a scan lies within 1e\+06 mm"):
            read_scan(same)
        with pytest.raises(ScanError, match=r"a coordinate of 5\.9e\+306 mm"):
            read_scan(spread)
        with pytest.raises(ScanError, match=r"a coordinate of inf mm"):
            read_scan(spread, scale=1e6)
        assert read_scan(metres, unit="m").points.max() == pytest.approx(1180.0)
        with pytest.raises(ScanError, match=r"1\.18e\+06 mm"):
            read_scan(metres, scale=1e6)
    assert MAX_SCAN_MM == 1e6


def test_a_mesh_scan_round_trips_through_stl(tmp_path: Path, shape3d) -> None:  # type: ignore[no-untyped-def]
    import trimesh

    cloud = trimesh.PointCloud(shape3d.surface)
    path = tmp_path / "scan.ply"
    cloud.export(path)
    scan = read_scan(path)
    assert scan.dim == 3 and len(scan.points) == len(shape3d.surface)
    assert np.allclose(np.sort(scan.points, axis=0), np.sort(shape3d.surface, axis=0), atol=1e-5)


def test_correlate_command_end_to_end(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                      shape2d) -> None:  # type: ignore[no-untyped-def]
    trace = tmp_path / "trace.csv"
    rows = "".join(f"{x / 0.2:.4f},{y / 0.2:.4f}\n" for x, y in shape2d.samples[::7])
    trace.write_text("x,y\n" + rows, encoding="utf-8")
    # the command solves the default ramp (10 levels to the pressure): the same shape at 20 kPa
    code = main(["correlate", str(trace), "--design", "0110", "--model", "2d", "--pressure", "20",
                 "--scale", "0.2", "--out", str(tmp_path / "c"), "--json"])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert data["outline"]["rms_mm"] < 0.05 and abs(data["transform"]["angle_deg"]) < 0.2
    assert (tmp_path / "c" / "correlation.png").stat().st_size > 0
    assert json.loads((tmp_path / "c" / "correlation.json").read_text())["provenance"]["fingerprint"]


def test_the_readme_sample_scan_correlates_to_its_noise(tmp_path, capsys) -> None:
    """examples/data/scan-0110-30kpa.xyz (docs/scripts/sample_scan.py) is the 3D model's surface moved and given
    0.05 mm noise: `pneumorph correlate` as the README runs it aligns it to a surface RMS of sigma * sqrt(3)."""
    import json
    from pathlib import Path

    from pneumorph.cli import main

    scan = Path(__file__).resolve().parents[2] / "examples" / "data" / "scan-0110-30kpa.xyz"
    assert main(["correlate", str(scan), "--design", "0110", "--pressure", "30", "--out", str(tmp_path / "corr"),
                 "--json"]) == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert abs(data["surface"]["rms_mm"] - 0.05 * 3**0.5) < 0.01
    assert "aligning 1,170 scan points to the model (about 0.1 s) ..." in captured.err
    assert (tmp_path / "corr" / "correlation.png").is_file()


def test_unreadable_scans_say_what_is_wrong_with_the_file(tmp_path, capsys) -> None:
    import numpy as np

    from pneumorph.cli import main

    junk = tmp_path / "junk.stl"
    junk.write_bytes(np.random.default_rng(0).integers(0, 256, 2000, dtype=np.uint8).tobytes())
    ply = tmp_path / "flat.ply"
    ply.write_text("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nend_header\n"
                   "1 2\n3 4\n")
    for path, words in ((junk, "neither a binary nor a text .stl file"), (ply, "its vertices have no z coordinate")):
        assert main(["correlate", str(path), "--design", "0110"]) == 2
        err = capsys.readouterr().err
        assert words in err and "ModuleNotFoundError" not in err and "KeyError" not in err


def _png_header(width: int, height: int) -> bytes:
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    # a few hundred bytes whose header claims the size: IHDR, a tiny IDAT, IEND
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"\0" * 64)) + chunk(b"IEND", b"")


def test_a_bad_photo_is_refused_before_the_solve(tmp_path, capsys) -> None:
    """Not an image, or a header claiming 60000 x 60000 pixels: one line, exit 2, nothing solved or written."""
    from pneumorph.cli import main

    trace = tmp_path / "trace.csv"
    trace.write_text("x,y\n" + "".join(f"{x},{0.01 * x * x}\n" for x in range(0, 200, 5)))
    text = tmp_path / "notes.png"
    text.write_text("not an image")
    huge = tmp_path / "huge.png"
    huge.write_bytes(_png_header(60_000, 60_000))
    large = tmp_path / "large.png"
    large.write_bytes(_png_header(8_000, 8_000))
    for photo, words in ((text, "not a readable image"), (huge, "MAX_PHOTO_PIXELS"),
                         (large, "8,000 x 8,000 pixels")):
        out = tmp_path / "corr"
        assert main(["correlate", str(trace), "--design", "0110", "--model", "2d", "--scale", "0.2",
                     "--photo", str(photo), "--out", str(out)]) == 2
        captured = capsys.readouterr()
        assert words in captured.err and "solving" not in captured.err
        assert not out.exists()


def test_a_scan_past_the_point_limit_is_refused_with_its_estimate_before_the_solve(tmp_path, capsys,
                                                                                   monkeypatch) -> None:
    """A 600,000-point scan (STL and CSV) would align for about 36 s: refused in one line, nothing solved or written
    (a 2-million-point scan ran for minutes without a word)."""
    import numpy as np

    import pneumorph.models.fe as fe
    from pneumorph.cli import main

    def tripwire(*a: object, **k: object) -> None:
        raise AssertionError("a solve was reached")

    monkeypatch.setattr(fe.FEModel, "solve", tripwire)
    triangles = 200_000  # 600,000 vertices, read without merging
    record = np.dtype([("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attr", "<u2")])
    data = np.zeros(triangles, dtype=record)
    data["vertices"] = np.random.default_rng(0).random((triangles, 3, 3)) * 40
    stl = tmp_path / "big.stl"
    stl.write_bytes(b"\0" * 80 + np.uint32(triangles).tobytes() + data.tobytes())
    csv = tmp_path / "big.csv"
    csv.write_text("x,y,z\n" + "1,2,3\n" * 600_000)
    for path in (stl, csv):
        assert main(["correlate", str(path), "--design", "0110", "--out", str(tmp_path / "corr")]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "600,000 points, more than MAX_SCAN_POINTS = 500,000" in err, err
        assert "aligning them would take about 36 s; thin the scan out (one point in 2 leaves 300,000)" in err
        assert not (tmp_path / "corr").exists()


def test_correlate_with_a_model_file_compares_with_that_model(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    # a trace of a softer cast (the identified model's) fits that model to the tracing, not the nominal one
    from pneumorph.models.factory import make_model

    identified = {"fidelity": "2d", "body_shear_scale": 0.8}
    soft = make_model(4, {**identified, "pressure_kpa": 20})
    trace = tmp_path / "trace.csv"
    rows = "".join(f"{x:.4f},{y:.4f}\n" for x, y in model_shape(soft.solve("0110")).samples[::7])
    trace.write_text("x,y\n" + rows, encoding="utf-8")
    (tmp_path / "identified.toml").write_text('[model]\nfidelity = "2d"\nbody_shear_scale = 0.8\n', encoding="utf-8")
    rms = {}
    model_file = ["--model-file", str(tmp_path / "identified.toml")]
    for name, extra in (("nominal", ["--model", "2d"]), ("identified", model_file)):
        assert main(["correlate", str(trace), "--design", "0110", "--pressure", "20", *extra, "--json"]) == 0
        data = json.loads(capsys.readouterr().out)
        assert data["model"] == "2d"  # the file's fidelity: the 3D default is not used
        rms[name] = data["outline"]["rms_mm"]
    assert rms["identified"] < 0.01 < rms["nominal"], rms


@pytest.mark.slow
def test_a_scan_of_a_sideways_design_is_measured_on_its_surface(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    """A design that leaves the bending plane (`aL` over the spatial library, full model): a moved scan of its own
    surface with 0.05 mm noise comes back to the noise (RMS 0.05 sqrt 3 = 0.087 mm) and the move; the bending
    plane's outline and centreline are not measured; the figure shows two views. A 2D trace of it is refused
    before any solve."""
    from pneumorph.models.factory import make_model

    shape = model_shape(make_model(2, {"fidelity": "3d", "library": "spatial", "pressure_kpa": 36}).solve("aL"))
    assert np.ptp(shape.surface[:, 2]) > 15.5  # it leaves the width of the straight actuator (15 mm)
    rng = np.random.default_rng(3)
    true = Transform(Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix(), np.array([5.0, -3.0, 7.0]))
    points = true(shape.surface) + rng.normal(scale=0.05, size=shape.surface.shape)
    scan = tmp_path / "side.xyz"
    np.savetxt(scan, points)
    out = tmp_path / "out"
    assert main(["correlate", str(scan), "--design", "aL", "--library", "spatial", "--pressure", "36",
                 "--out", str(out), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert 0.07 < result["surface"]["rms_mm"] < 0.1
    assert result["outline"]["points"] == 0 and result["centreline"]["points"] == 0
    t = result["transform"]
    back = true.then(Transform(np.array(t["rotation"]), np.array(t["translation_mm"]), t["scale"]))
    assert back.angle_deg < 0.05 and np.linalg.norm(back.translation) < 0.05
    assert (out / "correlation.png").stat().st_size > 0
    trace = tmp_path / "trace.csv"
    np.savetxt(trace, points[:, :2], delimiter=",", header="x,y", comments="")
    assert main(["correlate", str(trace), "--design", "aL", "--library", "spatial", "--pressure", "36"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "needs a 3D scan" in err[0] and "solving" not in err[0]


def test_correlate_design_from_the_api_puts_the_models_own_outline_back(tmp_path: Path, shape2d) -> None:  # type: ignore[no-untyped-def]
    from pneumorph.correlation import correlate_design

    points = shape2d.samples[::7] + np.array([3.0, -2.0])  # moved by (3, -2) mm
    said: list[str] = []
    result, summary = correlate_design(Scan(points, None, "trace"), "0110", Reduced2D(4, ramp_spec=RAMP), 20.0,
                                       out=tmp_path / "c", source="trace.csv", say=said.append)
    assert result.outline.rms < 0.01 and np.allclose(result.alignment.transform.translation, [-3.0, 2.0], atol=0.01)
    assert summary["design"] == "0110" and summary["scan"] == "trace.csv" and summary["model"] == "2d"
    written = json.loads((tmp_path / "c" / "correlation.json").read_text())
    assert written["outline"] == summary["outline"] and written["provenance"]["fingerprint"]
    assert said[0].startswith("solving design 0110 at 20 kPa") and said[1].startswith("aligning")
