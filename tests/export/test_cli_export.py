"""``pneumorph export``: parses, checks before building, writes the STL files and the mould."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import trimesh
from click.testing import CliRunner

from pneumorph.cli.casting.export import export

DEFAULT = "001111010001001"


def run(*args: str):
    return CliRunner().invoke(export, list(args))


def test_default_design_stl_and_json(tmp_path):
    out = tmp_path / "stl"
    result = run(DEFAULT, "--stl", str(out), "--json")
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["design"] == DEFAULT and summary["units"] == 15 and summary["length_mm"] == 157.5
    assert summary["volumes_mm3"]["body"] == pytest.approx(16402.5, rel=1e-12)
    assert sum(v for k, v in summary["volumes_mm3"].items() if k.startswith("layer_")) == pytest.approx(7087.5)
    assert summary["volumes_mm3"]["base_block"] == pytest.approx(1800.0)
    assert [(p["first_unit"], p["last_unit"], p["side"], p["length_mm"]) for p in summary["layer_pieces"]][:3] == [
        (1, 2, "top", 21.0), (3, 6, "bottom", 42.0), (7, 7, "top", 10.5)]
    assert sorted(p.name for p in out.iterdir()) == sorted(f"{k}.stl" for k in summary["volumes_mm3"])
    body = trimesh.load_mesh(out / "body.stl")
    assert body.is_watertight and body.volume == pytest.approx(16402.5, rel=1e-6)
    assert "mould" not in summary and not (out / "mould").exists()


def test_text_output_lists_files_volumes_and_cuts(tmp_path):
    result = run("01", "--stl", str(tmp_path))
    assert result.exit_code == 0, result.output
    assert "design 01: 2 units, 21 mm long" in result.output
    text = " ".join(result.output.split())
    assert "body.stl 2187.00 mm^3 mold_star_15 body, 2 cavities" in text
    assert "layer_2.stl 472.50 mm^3 smooth_sil_950 strip, unit 2, bottom, cut 10.5 mm" in text
    assert "base_block.stl 1800.00 mm^3 base block 10 x 12 x 15 mm" in text


def test_mould(tmp_path):
    result = run(DEFAULT, "--stl", str(tmp_path), "--mould", "--clearance", "0.3", "--json")
    assert result.exit_code == 0, result.output
    mould = json.loads(result.stdout)["mould"]
    assert mould["clearance_mm"] == 0.3 and mould["draft_deg"] == 0.0
    check = mould["check"]
    assert check["ok"] and all(check["watertight"].values()) and len(check["watertight"]) == 22
    assert check["max_overlap_mm3"] < 1e-9 and check["cavity_error_mm3"] < 1e-9
    assert check["cast_volume_mm3"] == pytest.approx(16402.5, rel=1e-12)
    assert mould["cast_mm3"] == pytest.approx({"open_body": 14276.25, "side_sheet": 2126.25}, rel=1e-12)
    folder = tmp_path / "mould"
    assert sorted(p.name for p in folder.iterdir()) == sorted([*(f"{k}.stl" for k in mould["volumes_mm3"]),
                                                               "mould.png"])
    assert (folder / "mould.png").read_bytes()[:4] == b"\x89PNG"
    lid = trimesh.load_mesh(folder / "lid.stl")
    assert lid.is_watertight and lid.volume == pytest.approx(mould["volumes_mm3"]["lid"], rel=1e-6)


def test_the_design_is_read_once(tmp_path, monkeypatch):
    """The command parses DESIGN once; the parts, the pieces and the mould's checks and solids take the parsed
    design (a ``Design``) and do not read its text again."""
    from pneumorph.geometry import alphabet

    texts: list[str] = []

    def counted(design, n_units=None):
        texts.append(design)
        return parse_orientation(design, n_units)

    parse_orientation = alphabet.parse_orientation
    monkeypatch.setattr(alphabet, "parse_orientation", counted)
    result = run("0110", "--stl", str(tmp_path), "--mould", "--json")
    assert result.exit_code == 0, result.output
    assert texts == ["0110"] and json.loads(result.stdout)["design"] == "0110"


def test_mould_text_and_draft(tmp_path):
    result = run("0", "--stl", str(tmp_path), "--mould", "--draft", "1")
    assert result.exit_code == 0, result.output
    assert "mould: 8 parts (clearance 0.2 mm, draft 1 deg)" in result.output
    assert "the draft adds 25.69 mm^3" in result.output


@pytest.mark.parametrize("args, message", [
    (["0120", "--stl", "{tmp}"], "Invalid value for 'DESIGN': orientation '0120' contains '2'"),
    (["", "--stl", "{tmp}"], "DESIGN must not be empty"),
    (["01"], "nothing to export: give --stl DIR"),
    (["01", "--stl", "{tmp}", "--draft", "1"], "--draft applies to the mould only: add --mould"),
    (["01", "--stl", "{tmp}", "--clearance", "0.1", "--draft", "1"], "--clearance and --draft apply to the mould"),
    (["01", "--stl", "{tmp}", "--mould", "--clearance", "1.2"], "'--clearance': mould clearance 1.2 mm is too large"),
    (["01", "--stl", "{tmp}", "--mould", "--clearance", "-0.1"], "--clearance must be a finite number"),
    (["01", "--stl", "{tmp}", "--mould", "--draft", "9"], "'--draft': mould draft 9 degrees narrows"),
    (["01", "--stl", "{tmp}", "--mould", "--draft", "nan"], "--draft must be a finite number"),
    (["01", "--stl", "{tmp}/file.txt"], "is a file, not a folder"),
    (["01", "--stl", "{tmp}", "--unit", "{tmp}/missing.toml"], "no such file"),
])
def test_bad_input_is_refused_before_anything_is_written(tmp_path, args, message):
    (tmp_path / "file.txt").write_text("x")
    result = run(*(a.format(tmp=tmp_path) for a in args))
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.output.split())
    assert [p.name for p in tmp_path.iterdir()] == ["file.txt"]


def test_unit_file(tmp_path):
    unit = tmp_path / "unit.toml"
    unit.write_text("[unit]\npitch = 12.0\nslit_width = 1.0\nslit_depth = 4.0\n")
    result = run("0", "--stl", str(tmp_path / "out"), "--unit", str(unit), "--json")
    assert result.exit_code == 0, result.output
    volumes = json.loads(result.stdout)["volumes_mm3"]
    # 12 x 9 x 15 - slit 1 x 4 x 15 - cavity (12 - 6 - 1) x 6 x 12
    assert volumes["body"] == pytest.approx(1620 - 60 - 360, rel=1e-12)
    bad = tmp_path / "bad.toml"
    bad.write_text("[unit]\npitch = 5.0\n")
    result = run("0", "--stl", str(tmp_path / "out2"), "--unit", str(bad))
    assert result.exit_code == 2 and "'--unit'" in result.output and "leave no cavity" in result.output
    assert not (tmp_path / "out2").exists()


def test_export_writes_the_calculix_deck_of_the_3d_model(tmp_path: Path) -> None:
    import json

    from pneumorph.cli import main
    from pneumorph.models.factory import make_model

    deck = tmp_path / "decks" / "d.inp"
    result = CliRunner().invoke(export, ["0110", "--inp", str(deck), "--pressure", "20", "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    model = make_model(4, {"fidelity": "3d", "pressure_kpa": 20})
    assert data["deck"]["fingerprint"] == model.fingerprint() and data["deck"]["levels"] == 10
    text = deck.read_text(encoding="utf-8")
    assert "*NODE" in text and "C3D20" in text and "design 0110" in text and "pressure 20 kPa" in text
    assert "files" not in data  # no --stl: the deck only
    assert main(["export", "0110", "--stl", str(tmp_path / "s"), "--pressure", "30"]) == 2  # a deck option alone


def test_a_solid_unit_is_exported_as_a_solid_body(tmp_path):
    """``solid = true``: the cavity is filled with the body material, so the body has none (it had four)."""
    unit = tmp_path / "solid.toml"
    unit.write_text("[unit]\nsolid = true\n")
    result = run("0101", "--stl", str(tmp_path / "out"), "--unit", str(unit), "--mould", "--json")
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    # 42 x 12 x 15 mm minus the four 10.5 x 3 x 15 mm layer pieces, no cavity
    assert summary["volumes_mm3"]["body"] == pytest.approx(42 * 12 * 15 - 4 * 472.5, rel=1e-12)
    body = trimesh.load_mesh(tmp_path / "out" / "body.stl")
    assert body.is_watertight and body.body_count == 1 and body.volume == pytest.approx(5670.0, rel=1e-6)
    mould = summary["mould"]
    assert mould["check"]["ok"] and not any(name.startswith("core_") for name in mould["volumes_mm3"])
    text = run("0101", "--stl", str(tmp_path / "out2"), "--unit", str(unit)).output
    assert "mold_star_15 body, no cavities (solid unit)" in " ".join(text.split())


def test_a_unit_without_a_layer_has_no_layer_pieces(tmp_path):
    """``layer = 0`` (an extending unit): a body and a base block, with its mould (not 'an empty box')."""
    unit = tmp_path / "extending.toml"
    unit.write_text("[unit]\nwall = 3.0\nlayer = 0.0\n")
    result = run("01", "--stl", str(tmp_path / "out"), "--unit", str(unit), "--mould", "--json")
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert sorted(summary["volumes_mm3"]) == ["base_block", "body"] and summary["layer_pieces"] == []
    # 21 x 12 x 15 mm minus two 4.5 x 6 x 12 mm cavities
    assert summary["volumes_mm3"]["body"] == pytest.approx(21 * 12 * 15 - 2 * 324.0, rel=1e-12)
    assert summary["mould"]["check"]["ok"]


def test_an_unknown_body_material_is_refused_before_anything_is_written(tmp_path):
    unit = tmp_path / "unit.toml"
    for table in ('body_material = "nonesuch"', 'layer_material = "nonesuch"'):
        unit.write_text(f"[unit]\n{table}\n")
        result = run("01", "--stl", str(tmp_path / "out"), "--unit", str(unit), "--mould")
        assert result.exit_code == 2, result.output
        assert "'--unit': unknown material 'nonesuch'; known materials: " in " ".join(result.output.split())
        assert sorted(p.name for p in tmp_path.iterdir()) == ["unit.toml"]


def test_a_model_file_gives_the_parts_its_unit_and_the_deck_its_materials(tmp_path: Path) -> None:
    from pneumorph.models.factory import make_model

    identified = tmp_path / "identified.toml"
    identified.write_text('[model]\nfidelity = "3d"\nbody_bulk_scale = 1.06\n[model.unit]\npitch = 12.0\n'
                          "slit_width = 1.0\nslit_depth = 4.0\n[provenance]\npneumorph = 'x'\n")
    result = run("0", "--stl", str(tmp_path / "out"), "--model-file", str(identified), "--json")
    assert result.exit_code == 0, result.output
    # the identified unit's body, as from the same unit given by --unit (12 x 9 x 15 - slit - cavity)
    assert json.loads(result.stdout)["volumes_mm3"]["body"] == pytest.approx(1620 - 60 - 360, rel=1e-12)
    result = run("0", "--inp", str(tmp_path / "d.inp"), "--pressure", "20", "--model-file", str(identified), "--json")
    assert result.exit_code == 0, result.output
    scaled = make_model(1, {"fidelity": "3d", "pressure_kpa": 20, "body_bulk_scale": 1.06,
                            "unit": {"pitch": 12.0, "slit_width": 1.0, "slit_depth": 4.0}})
    assert json.loads(result.stdout)["deck"]["fingerprint"] == scaled.fingerprint()
    assert scaled.fingerprint() != make_model(1, {"fidelity": "3d", "pressure_kpa": 20, "unit": {
        "pitch": 12.0, "slit_width": 1.0, "slit_depth": 4.0}}).fingerprint()


def test_a_sideways_unit_exports_its_parts_and_its_mould(tmp_path):
    """Its stiff strip lies on a side face: the right one as built, the left one turned over (9 mm high: two walls
    and the cavity). Its mould stands the turned-over unit's core on a plinth (docs/manufacturing.md)."""
    unit = tmp_path / "side.toml"
    unit.write_text("[unit]\nlayer_side = true\n")
    result = run("01", "--stl", str(tmp_path / "out"), "--unit", str(unit), "--json")
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    # per unit: 10.5 x 9 x 12 mm of body (the strip's 3 mm off the width) less the cavity 4.5 x 6 x 9
    assert summary["volumes_mm3"]["body"] == pytest.approx(2 * (10.5 * 9 * 12 - 4.5 * 6 * 9), rel=1e-12)
    assert [(p["side"], p["length_mm"]) for p in summary["layer_pieces"]] == [("right", 10.5), ("left", 10.5)]
    assert summary["volumes_mm3"]["layer_1"] == pytest.approx(10.5 * 9 * 3, rel=1e-12)
    result = run("01", "--stl", str(tmp_path / "mould"), "--unit", str(unit), "--mould", "--json")
    assert result.exit_code == 0, result.output
    mould = json.loads(result.stdout)["mould"]
    assert mould["check"]["ok"] and mould["check"]["reassembly_error_mm3"] < 1e-6
    # the sheet: 1.5 mm under both units' footprints, 21 x 9 mm (the turned-over unit's piece is its wall)
    assert mould["cast_mm3"]["side_sheet"] == pytest.approx(21 * 9 * 1.5, rel=1e-9)


def test_a_mixed_design_over_a_library_exports_its_parts_and_deck(tmp_path):
    """Over the spatial library: the strips on the top, left, right and bottom faces, each 10.5 mm long; the deck of
    the model that solves it (the full width: a sideways unit), under its design's letters."""
    result = run("aLlAl", "--library", "spatial", "--stl", str(tmp_path / "out"), "--inp", str(tmp_path / "d.inp"),
                 "--json")
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert [p["side"] for p in summary["layer_pieces"]] == ["top", "left", "right", "bottom", "right"]
    assert summary["length_mm"] == 52.5 and summary["unit"] == "spatial"
    # 5 x (10.5 x 12 x 15 less the cavity 4.5 x 6 x 12 (a) or 4.5 x 9 x 9 (l)), less the strips
    cavities = 2 * 4.5 * 6 * 12 + 3 * 4.5 * 9 * 9
    strips = 2 * 10.5 * 3 * 15 + 3 * 10.5 * 12 * 3
    assert summary["volumes_mm3"]["body"] == pytest.approx(5 * 10.5 * 12 * 15 - cavities - strips, rel=1e-12)
    from pneumorph.models.factory import make_model

    model = make_model(5, {"fidelity": "3d", "library": "spatial", "pressure_kpa": 45.0})
    assert summary["deck"]["fingerprint"] == model.fingerprint()
    deck = (tmp_path / "d.inp").read_text()
    assert "** design aLlAl (5 units), full model" in deck and "SYMMETRY" not in deck
    assert deck.count("\n*NODE\n") == 1 and len(model.mesh("aLlAl").points) == \
        int(deck.split("*ELEMENT")[0].strip().splitlines()[-1].split(",")[0])
    result = run("aLlAl", "--library", "spatial", "--stl", str(tmp_path / "m"), "--mould", "--json")
    assert result.exit_code == 0, result.output
    mould = json.loads(result.stdout)["mould"]  # the L unit's core on a plinth (tests/export/test_moulds.py)
    assert mould["check"]["ok"] and (tmp_path / "m" / "mould" / "base_plate.stl").is_file()
    assert mould["cast_mm3"]["side_sheet"] + mould["cast_mm3"]["open_body"] == pytest.approx(
        summary["volumes_mm3"]["body"], rel=1e-12)
    result = run("ll", "--library", "spatial", "--stl", str(tmp_path / "n"), "--mould")
    assert result.exit_code == 2 and "no unit's face on z = width is free" in result.output, result.output
    assert not (tmp_path / "n").exists()
