"""Figures of the unit-geometry study (PNG into ../../docs/figures/).

    python make_figures.py section                      # unit sections coloured by material
    python make_figures.py deformed results/final_all0.json results/final_all1.json
    python make_figures.py curves results/*.json        # curl vs pressure
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

import unit_model as um  # noqa: E402

FIG = Path(__file__).resolve().parents[2] / "docs" / "figures"
COLOURS = np.array(["#4daf4a", "#377eb8", "#bbbbbb", "#dddddd"])  # MS15, SS950, medium, filler


def _faces(am: um.ActuatorMesh, plane: str, value: float):
    """Corner polygons of the cells' faces lying in a plane (z = value for 'xy')."""
    X = am.mesh.points
    c = am.mesh.cells
    if am.dim == 2:
        return c[:, :4], am.material
    faces = {"xy": ([0, 1, 2, 3], [4, 5, 6, 7], 2)}[plane]
    out, mat = [], []
    for f in faces[:2]:
        sel = np.all(np.isclose(X[c[:, f], faces[2]], value), axis=1)
        out.append(c[sel][:, f])
        mat.append(am.material[sel])
    return np.concatenate(out), np.concatenate(mat)


def _draw(ax, am, u, plane_value, reference=True, alpha=0.9):
    X = am.mesh.points
    x = X + (0 if u is None else u.reshape(X.shape))
    f, mat = _faces(am, "xy", plane_value)
    if reference and u is not None:
        ax.add_collection(PolyCollection(X[f][:, :, :2], facecolors="none", edgecolors="0.85", lw=0.3))
    ax.add_collection(PolyCollection(x[f][:, :, :2], facecolors=COLOURS[mat], edgecolors="k", lw=0.2,
                                     alpha=alpha))
    ax.set_aspect("equal")
    ax.autoscale()


def section(geometry: um.UnitGeometry, fname="unit-section.png"):
    fig, axs = plt.subplots(1, 2, figsize=(12, 3.6), gridspec_kw={"width_ratios": [3, 1]})
    am = um.build_mesh(geometry, "0010", dim=2)
    _draw(axs[0], am, None, None)
    axs[0].set_title("longitudinal section, orientation 0010 (quad8 mesh, element corners)")
    g = geometry
    for i, o in enumerate("0010"):
        axs[0].text((i + 0.5) * g.pitch, -1.5, o, ha="center")
    axs[0].set_xlabel("x (mm)")
    axs[0].set_ylabel("y (mm)")
    # cross-section (y-z) through the cavity, full width, orientation 0
    am3 = um.build_mesh(g, "0", dim=3, half=False)
    X = am3.mesh.points
    xm = g.end_wall + g.cavity_length / 2
    c = am3.mesh.cells
    xs = np.unique(X[c[:, :8], 0])
    xcut = xs[np.argmin(np.abs(xs - xm))]  # a corner-node grid line
    polys, mats = [], []
    for f in ([0, 3, 7, 4], [1, 2, 6, 5]):
        sel = np.all(np.isclose(X[c[:, f], 0], xcut), axis=1)
        polys.append(X[c[sel][:, f]][:, :, [2, 1]])
        mats.append(am3.material[sel])
    axs[1].add_collection(PolyCollection(np.concatenate(polys), facecolors=COLOURS[np.concatenate(mats)],
                                         edgecolors="k", lw=0.2))
    axs[1].set_aspect("equal")
    axs[1].autoscale()
    axs[1].set_title(f"cross-section at x = {xcut:g} mm")
    axs[1].set_xlabel("z (mm)")
    from matplotlib.patches import Patch

    axs[0].legend(handles=[Patch(color=COLOURS[0], label="Mold Star 15"),
                           Patch(color=COLOURS[1], label="Smooth-Sil 950")],
                  loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(FIG / fname, dpi=130)
    print(FIG / fname)


def _load(path):
    d = json.loads(Path(path).read_text())
    gd = {k: v for k, v in d["geometry"].items() if k not in ("height", "cavity_length")}
    g = um.UnitGeometry(**gd)
    am = um.build_mesh(g, d["orientation"], dim=d["dim"], half=d["half_width_model"],
                       filler=d["filler"])
    u = np.load(Path(path).with_suffix(".npz"))["u"]
    return d, am, u


def deformed(paths, fname="unit-deformed-3d.png"):
    if all(len(json.loads(Path(p).read_text())["orientation"]) < 15 for p in paths):
        fname = "unit-deformed-screen.png"
    fig, axs = plt.subplots(1, len(paths), figsize=(6 * len(paths), 6), squeeze=False)
    for ax, p in zip(axs[0], paths):
        d, am, u = _load(p)
        zmid = am.geometry.width / 2 if am.dim == 3 else None
        _draw(ax, am, u, zmid)
        inc = d["increments"][-1]
        cen = np.array(inc["centres"])
        ax.plot(cen[:, 0], cen[:, 1], "r.-", ms=4, lw=0.8)
        ax.set_title(f"{Path(p).stem}: {d['dim']}D, orientation {d['orientation']}\n"
                     f"{inc['pressure_kpa']:.0f} kPa: curl {inc['curl_deg']:.1f} deg "
                     f"(mid-width section; red: unit centres)", fontsize=9)
    fig.tight_layout()
    fig.savefig(FIG / fname, dpi=110)
    print(FIG / fname)


def curves(paths, fname="unit-curl-pressure.png"):
    if all(len(json.loads(Path(p).read_text())["orientation"]) == 15 for p in paths):
        fname = "unit-curl-pressure-15.png"
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for p in paths:
        d = json.loads(Path(p).read_text())
        g = d["geometry"]
        n = len(d["orientation"])
        pk = [0] + [i["pressure_kpa"] for i in d["increments"]]
        c = [0] + [i["curl_deg"] for i in d["increments"]]
        lab = (f"{d['dim']}D n={n} Hc={g['cavity_height']:g} Lc={g['cavity_length']:g}"
               f"{' slit+medium' if g['slit_width'] else ''}{' cap' if g['tip_cap'] else ''}"
               f"{' filler' if d['filler'] else ''}{' h=' + str(g['element_size']) if g['element_size'] != 1.5 else ''}"
               f"{' o=' + d['orientation'][0] if len(set(d['orientation'])) == 1 else ''}")
        ax.plot(pk, np.abs(c) * (15 / n if "--per15" in sys.argv else 1), ".-", label=lab)
    if fname.endswith("-15.png"):
        ax.axhline(270, color="k", lw=0.5, ls="--")
        ax.axhline(360, color="k", lw=0.5, ls=":")
    ax.set_xlabel("pressure (kPa)")
    ax.set_ylabel("|curl| at the tip (deg)")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(FIG / fname, dpi=120)
    print(FIG / fname)


def stretch(paths):
    """Largest principal stretch and smallest J at the quadrature points of the final state."""
    for p in paths:
        d, am, u = _load(p)
        model = um.ActuatorModel(am)
        model.u = u
        out = []
        for item, name in zip([i for i in model.items if hasattr(i, "umat")],
                              ["Mold Star 15", "Smooth-Sil 950", "medium/filler"]):
            F = item.field.extract(grad=True, sym=False, add_identity=True)[0]
            F = np.moveaxis(F, (0, 1), (-2, -1)).reshape(-1, 3, 3)
            lam = np.sqrt(np.linalg.eigvalsh(np.swapaxes(F, -1, -2) @ F))
            out.append(f"{name}: max stretch {lam.max():.2f}, min stretch {lam.min():.2f}, "
                       f"min J {np.linalg.det(F).min():.2f}")
        print(Path(p).name, "|", "; ".join(out))


def table(paths):
    """Markdown table of runs: geometry, pressure reached, curl, per-unit rotations, cost."""
    print("| run | cavity L x H (mm) | end wall | other | p reached (kPa) | curl (deg) | "
          "per-unit rotation (deg) | ballooning (mm) | Newton its | cut-backs | wall (s) | dofs |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for p in paths:
        d = json.loads(Path(p).read_text())
        g = d["geometry"]
        inc = d["increments"][-1]
        rot = np.diff(np.concatenate([[0.0], inc["unit_rotation_deg"]]))
        other = []
        if g["slit_width"]:
            other.append(f"slit {g['slit_width']:g} x {g['slit_depth']:g}, medium {g['medium']:g} MPa")
        if g["tip_cap"]:
            other.append(f"tip cap {g['tip_cap']:g}")
        if d["filler"]:
            other.append("Eq 5.2 filler")
        if g["element_size"] != 1.5:
            other.append(f"h = {g['element_size']:g}")
        other.append(f"{d['dim']}D, n={len(d['orientation'])}")
        rots = ", ".join(f"{r:.1f}" for r in rot) if len(rot) <= 4 else \
            f"{rot[0]:.1f}, {np.median(rot[1:-1]):.1f} (median 2..n-1), {rot[-1]:.1f}"
        print(f"| `{Path(p).stem}` | {g['cavity_length']:g} x {g['cavity_height']:g} | "
              f"{g['end_wall']:g} | {'; '.join(other)} | {d['pressure_reached_kpa']:.2f} | "
              f"{inc['curl_deg']:.1f} | {rots} | {inc['ballooning_mm']:.2f} | "
              f"{d['newton_iterations']} | {d['cutbacks']} | {d['wall_time_s']:.0f} | "
              f"{d['mesh']['dofs']} |")


if __name__ == "__main__":
    what = sys.argv[1]
    if what == "table":
        table([p for p in sys.argv[2:] if p.endswith(".json")])
    if what == "stretch":
        stretch([p for p in sys.argv[2:] if p.endswith(".json")])
    if what == "section":
        section(um.UnitGeometry(cavity_height=6.0, end_wall=3.0))
    elif what == "deformed":
        deformed([p for p in sys.argv[2:] if p.endswith(".json")])
    elif what == "curves":
        curves([p for p in sys.argv[2:] if p.endswith(".json")])
