"""Regenerate the library's silicones fitted to the Soft Robotics Materials Database.

Reads each material's tensile test (``Tensile-Tests-Data/<name>.csv`` of Marechal et al.
2021, from ../shared/reference-data beside the repository), fits it with
``pneumorph.materials.fitting.database.fit_tensile_curve`` (stable Ogden-2, relative
residuals, 8 starts, seed 0), rounds the parameters to 4 significant figures, and prints
the Markdown table of docs/material-fits.md. With ``--write`` it also replaces the block
of entries between the markers in src/pneumorph/materials/data/materials.toml.

Run from the repository root (about 5 s):

    python docs/scripts/fit_database_silicones.py [--shared ../shared] [--write]
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np

from pneumorph.materials.characterisation.testdata import read_curve
from pneumorph.materials.fitting.database import TENSILE_FIT, fit_tensile_curve
from pneumorph.materials.fitting.fit import r_squared
from pneumorph.materials.laws.hyperelastic import Ogden
from pneumorph.materials.library.material import FitRecord

SORO = "reference-data/marechal2021_SoRo-Materials-DB/Tensile-Tests-Data"
COMMIT = "8ff66c3b"
ATTRIBUTION = ("Data: Soft Robotics Materials Database, Marechal et al. 2021, doi:10.1089/soro.2019.0115, "
               "ODbL 1.0")
CITATION = ("L. Marechal et al., Toward a common framework and database of materials for soft robotics, "
            "Soft Robotics 8(3) (2021), doi:10.1089/soro.2019.0115")
NU = 0.49  # assumed small-strain Poisson's ratio of the bulk modulus
BEGIN = "# >>> silicones fitted to the Soft Robotics Materials Database (docs/scripts/fit_database_silicones.py)"
END = "# <<< silicones fitted to the Soft Robotics Materials Database"

#: (file stem, library key, display name, aliases)
MATERIALS: tuple[tuple[str, str, str, list[str]], ...] = (
    ("Ecoflex 00-10", "ecoflex_00_10", "Ecoflex 00-10", []),
    ("Ecoflex 00-30", "ecoflex_00_30", "Ecoflex 00-30", []),
    ("Ecoflex 00-35 FAST", "ecoflex_00_35_fast", "Ecoflex 00-35 FAST", ["ecoflex 00-35"]),
    ("Ecoflex 00-50", "ecoflex_00_50", "Ecoflex 00-50", []),
    ("Dragon Skin 10 MEDIUM", "dragon_skin_10_medium", "Dragon Skin 10 MEDIUM", ["dragon skin 10"]),
    ("Dragon Skin 20", "dragon_skin_20", "Dragon Skin 20", []),
    ("Dragon Skin 30", "dragon_skin_30", "Dragon Skin 30", []),
    ("Dragon Skin FX Pro", "dragon_skin_fx_pro", "Dragon Skin FX Pro", []),
    ("Dragon Skin FX Pro Slacker", "dragon_skin_fx_pro_slacker", "Dragon Skin FX Pro with Slacker", []),
    ("Mold Star 16 FAST", "mold_star_16_fast", "Mold Star 16 FAST", ["mold star 16"]),
    ("Mold Star 20T", "mold_star_20t", "Mold Star 20T", []),
    ("SortaClear 40", "sortaclear_40", "SortaClear 40", ["sorta clear 40"]),
    ("Rebound 25", "rebound_25", "Rebound 25", []),
    ("BodyDouble SILK", "body_double_silk", "Body Double SILK", ["bodydouble silk"]),
    ("PlatSil Gel 10", "platsil_gel_10", "PlatSil Gel 10", []),
    ("Psycho Paint", "psycho_paint", "Psycho Paint", []),
    ("RTV615", "rtv615", "RTV615", []),
    ("SOLOPLAST 150318", "soloplast_150318", "SOLOPLAST 150318", []),
    ("WAGNERSIL 20 NF", "wagnersil_20_nf", "WAGNERSIL 20 NF", []),
)

CAVEATS = (
    "strain from the crosshead displacement (the database's 'Global' strain measurement), not an "
    "extensometer on the gauge length: it includes the deformation outside the gauge length, so it "
    "overstates the specimen's strain, the moduli come out low and the stretches high (Ecoflex 00-30 "
    "reaches engineering strain 16 here against about 9 on its datasheet)",
    "uniaxial tension only: the fit is of one mode; equibiaxial and planar tension (a cavity wall's "
    "loading) and compression are the model's extrapolation, not measured",
    "one representative curve per material: the scatter between specimens and batches is not known",
)


def sig(x: float, digits: int = 4) -> float:
    """``x`` rounded to ``digits`` significant figures."""
    return float(f"{x:.{digits}g}")


def text(value: str) -> str:
    """A TOML basic string."""
    return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'


def numbers(values: list[float] | tuple[float, ...]) -> str:
    return "[" + ", ".join(repr(v) for v in values) + "]"


def fitted(shared: Path, stem: str) -> dict:  # type: ignore[type-arg]
    """The stored model (rounded), its R^2, mu0, bulk modulus and fit record for one file."""
    path = shared / SORO / f"{stem}.csv"
    curve = read_curve(path)
    result = fit_tensile_curve(curve)
    assert isinstance(result.model, Ogden)
    model = Ogden(tuple(sig(m) for m in result.model.mu), tuple(sig(a) for a in result.model.alpha))
    r2 = r_squared(curve.stress, model.uniaxial(curve.stretch))
    meta = curve.metadata
    speed = meta.get("Speed (mm/min)", "?")
    data = (f"Soft Robotics Materials Database (LucMarechal/Soft-Robotics-Materials-Database @ {COMMIT}), "
            f"Tensile-Tests-Data/{stem}.csv: {meta.get('Standard', 'ASTM D412')} dumbbell "
            f"({meta.get('Specimen Thickness (mm)', '?')} x {meta.get('Specimen Width (mm)', '?')} mm, "
            f"gauge length {meta.get('Specimen Length (mm)', '?')} mm), pulled to failure at {speed} mm/min "
            f"on an {' '.join(meta.get('Machine', 'Instron').split())}; engineering strain and stress, "
            "the loading curve up to the peak stress")
    lo, hi = float(curve.stretch[0]), float(curve.stretch[-1])
    record = FitRecord(data=data, attribution=ATTRIBUTION, mode="uniaxial", stretch_range=(sig(lo), sig(hi)),
                       points=len(curve), caveats=CAVEATS,
                       method=(f"Ogden, {model.terms} term{'s' if model.terms > 1 else ''} kept of "
                               f"{TENSILE_FIT['model_name']}, signs constrained for Drucker stability "
                               f"(mu_n alpha_n >= 0), {TENSILE_FIT['weighting']} residuals, "
                               f"{TENSILE_FIT['starts']} starts, seed {TENSILE_FIT['seed']} "
                               "(pneumorph.materials.fitting.database.fit_tensile_curve); parameters "
                               "rounded to 4 significant figures"))
    mu0 = model.shear_modulus
    k = sig(2.0 * mu0 * (1.0 + NU) / (3.0 * (1.0 - 2.0 * NU)) * 1e3, 3)
    error = {x: float(np.interp(x, curve.stretch, model.uniaxial(curve.stretch) / curve.stress - 1.0))
             for x in (1.5, 2.0)}
    return {"model": model, "r2": r2, "mu0": mu0, "k_kpa": k, "record": record, "error": error,
            "stable": record.stability(model), "supplier": meta.get("Material supplier", "")}


def entry(stem: str, key: str, name: str, aliases: list[str], f: dict) -> str:  # type: ignore[type-arg]
    """The TOML entry of one material."""
    model, record = f["model"], f["record"]
    ratio = 2.0 * (1.0 + NU) / (3.0 * (1.0 - 2.0 * NU))
    lines = [
        f"[materials.{key}]",
        f"display_name = {text(name)}",
        'kind = "hyperelastic"',
    ]
    if aliases:
        lines.append("aliases = [" + ", ".join(text(a) for a in aliases) + "]")
    description = f"{f['supplier']} {name} silicone; Ogden fit to its uniaxial tensile test"
    lines += [
        f"description = {text(description)}",
        f"source = {text(CITATION + '; Soft Robotics Materials Database, Tensile-Tests-Data/' + stem + '.csv')}",
        "",
        f"[materials.{key}.model]",
        'type = "ogden"',
        'convention = "marc"',
        'unit = "MPa"',
        f"mu = {numbers(model.mu)}",
        f"alpha = {numbers(model.alpha)}",
        f"source = {text(f'pneumorph fit to Tensile-Tests-Data/{stem}.csv (see [materials.{key}.fit])')}",
        "",
        f"[materials.{key}.bulk_modulus]",
        f"value = {f['k_kpa']:g}",
        'unit = "kPa"',
        f"source = {text(f'assumed Poisson ratio {NU} with the fitted mu0: K = 2 mu0 (1 + nu) / (3 (1 - 2 nu))')}",
        "assumed = true",
        'reason = """The database holds uniaxial tension tests only, no volumetric test. \\',
        f"Chosen from an assumed small-strain Poisson's ratio nu = {NU}: K = 2 mu0 (1 + nu) / \\",
        f"(3 (1 - 2 nu)) = {ratio:.2f} mu0 = {f['k_kpa']:g} kPa with mu0 = {f['mu0'] * 1e3:.4g} kPa (3 significant \\",
        "figures). Silicone rubbers are nearly incompressible (bulk moduli of the order of 1 GPa, four \\",
        "to five orders above these mu0); nu = 0.49 (K about 50 mu0) is the usual stand-in in \\",
        'displacement-based FE models of silicone actuators, which lock as K/mu0 grows."""',
        "",
        f"[materials.{key}.r_squared]",
        f"source = {text(f'pneumorph fit to the uniaxial curve ({record.points} points; stored, rounded parameters)')}",
        f"ogden-{model.terms} = {round(f['r2'], 5)!r}",
        "",
        f"[materials.{key}.fit]",
        f"data = {text(record.data)}",
        f"attribution = {text(record.attribution)}",
        f"mode = {text(record.mode)}",
        f"stretch_range = {numbers(record.stretch_range)}",
        f"points = {record.points}",
        f"method = {text(record.method)}",
        "caveats = [",
        *(f"    {text(c)}," for c in record.caveats),
        "]",
    ]
    return "\n".join(lines)


def write(toml: Path, block: str) -> None:
    """Replace the block between the markers of ``toml`` (or append it with them)."""
    old = toml.read_text(encoding="utf-8")
    new = f"{BEGIN}\n\n{block}\n\n{END}\n"
    pattern = re.compile(re.escape(BEGIN) + r".*?" + re.escape(END) + r"\n", re.S)
    toml.write_text(pattern.sub(lambda _: new, old) if pattern.search(old) else f"{old.rstrip()}\n\n{new}",
                    encoding="utf-8")


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    repo = Path(__file__).resolve().parents[2]
    ap.add_argument("--shared", type=Path, default=repo.parent / "shared")
    ap.add_argument("--write", action="store_true", help="replace the entries in materials.toml")
    args = ap.parse_args()

    entries = []
    print("| material | key | mu [MPa] | alpha | mu0 [kPa] | R^2 | stress error at stretch 1.5, 2 | "
          "stretch fitted | points | K assumed [kPa] | Drucker-stable |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for stem, key, name, aliases in MATERIALS:
        f = fitted(args.shared, stem)
        m, rec = f["model"], f["record"]
        lo, hi = rec.stability_range
        stable = "yes" if f["stable"].is_stable else "no"
        print(f"| {name} | `{key}` | {', '.join(f'{x:g}' for x in m.mu)} | {', '.join(f'{x:g}' for x in m.alpha)} "
              f"| {f['mu0'] * 1e3:.4g} | {f['r2']:.5f} | {f['error'][1.5]:+.1%}, {f['error'][2.0]:+.1%} "
              f"| {rec.stretch_range[0]:g}-{rec.stretch_range[1]:g} "
              f"| {rec.points} | {f['k_kpa']:g} | {stable} ({lo:g}-{hi:g}) |")
        entries.append(entry(stem, key, name, aliases, f))
    if args.write:
        toml = repo / "src" / "pneumorph" / "materials" / "data" / "materials.toml"
        write(toml, "\n\n\n".join(entries))
        print(f"\nwrote {len(entries)} entries to {toml}")


if __name__ == "__main__":
    main()
