"""Measure how tight a bound on a tip goal in space would be: support functions over a sphere of directions.

A prototype of the next step for certifying tip goals over sideways units (docs/space-curves.md,
"What is not done yet"), not used by the search. For the spatial library's shipped chain in
space at its last level, it computes by a dynamic programme over the window state (the last
``m`` units) the support function of the displacement of the chords still to place, on the
vertices of an icosphere, each value read between grid directions by the conic weights of
the spherical triangle around it (an upper bound of any support function). Windows that
differ only in the units the state forgets are merged, widened by their chords' spread and
the set's radius times their rotations' spread. Then it prints, for each prefix of a design,
the lower bound on its distance to a point: along the direction to the point, and the
largest over every grid direction (the distance to the hull, up to the grid), beside the
design's own distance.

    python docs/scripts/space_support.py --memory 5 --subdivisions 4

Measured (2 cores, 24 GB, shared with a table build): memory 5 (1,024 states, 4,096 rows
merged from 16,384 windows, widened by 0.016 mm and 0.00107 in rotation), 2,562 directions,
40 s for one level; ``reach`` (100, 40, 40) mm with ``LAAllalalalaall``, 1.982 mm off at 45
kPa: the hull bound is -3.47 mm with 6 units placed, 0.32 with 9, 1.34 with 11, 1.96 with 14.
"""

import argparse
import time

import numpy as np
import trimesh
from scipy.spatial import cKDTree

from pneumorph.models.chain.sources import find_table
from pneumorph.models.chain.space import rotation_matrices
from pneumorph.models.chain.windows import ends, window_codes
from pneumorph.models.factory import make_model

EMPTY = -1e30


class Sphere:
    """An icosphere's unit vertices and triangles, and where a direction lies among them."""

    def __init__(self, sub):
        m = trimesh.creation.icosphere(subdivisions=sub)
        self.points = np.asarray(m.vertices, dtype=float)
        self.points /= np.linalg.norm(self.points, axis=1)[:, None]
        self.faces = np.asarray(m.faces)
        M = np.stack([self.points[self.faces[:, i]] for i in range(3)], axis=-1)
        self.inverse = np.linalg.inv(M)
        self.tree = cKDTree(self.points)
        vf = [[] for _ in range(len(self.points))]
        for fi, f in enumerate(self.faces):
            for v in f:
                vf[v].append(fi)
        width = max(len(x) for x in vf)
        self.vertex_faces = np.array([x + [x[0]] * (width - len(x)) for x in vf])
        self.wmax = np.linalg.norm(np.einsum("fij,i->fj", self.inverse, np.ones(3)), axis=-1).max()

    def locate(self, v):
        """The triangle's vertices (..., 3) around directions ``v`` (..., 3) and their conic weights (..., 3)."""
        shape = v.shape[:-1]
        v = v.reshape(-1, 3)
        v = v / np.linalg.norm(v, axis=1)[:, None]
        nn = self.tree.query(v)[1]
        cand = self.vertex_faces[nn]  # (M, c)
        w = np.einsum("mcij,mj->mci", self.inverse[cand], v)
        ok = (w >= -1e-12).all(axis=-1)
        pick = np.argmax(ok, axis=1)
        found = ok[np.arange(len(v)), pick]
        face = cand[np.arange(len(v)), pick]
        weights = w[np.arange(len(v)), pick]
        for i in np.flatnonzero(~found):  # brute force, rare
            ww = self.inverse @ v[i]
            good = np.flatnonzero((ww >= -1e-12).all(axis=1))
            face[i], weights[i] = good[0], ww[good[0]]
        idx = self.faces[face]
        return idx.reshape(*shape, 3), np.maximum(weights, 0.0).reshape(*shape, 3)


def digits(codes, base, count):
    """Digits of window codes, the first unit first."""
    return (np.asarray(codes, dtype=np.int64)[:, None] // base ** np.arange(count)[None, :]) % base


def state_code(d, c):
    """A state's units as one integer in base ``c``."""
    return (d * c ** np.arange(d.shape[1])[None, :]).sum(axis=1)


def build(table, level, m, sphere, steps):
    """The support functions (steps + 1, states, directions) of the tip's displacement at one level."""
    w, k = table.window, table.n_types
    c, b = 2 * k, 2 * k + 2
    S = c ** m
    N = len(sphere.points)
    ud = digits(table.codes, b, 2 * w + 1)
    unit = (ud < c).all(axis=1)
    ud = ud[unit]
    el = table.space[unit, level]  # (W, 6)
    R = rotation_matrices(el[:, 3:])
    ch = el[:, :3]
    before = state_code(ud[:, 2 * w - m: 2 * w], c)
    after = state_code(ud[:, 2 * w - m + 1:], c)
    pair = state_code(ud[:, 2 * w - m:], c)
    # clusters: one row per pair, representative the first window; spreads
    uniq, first, inv = np.unique(pair, return_index=True, return_inverse=True)
    R0 = R[first]
    disp = np.einsum("wij,wj->wi", R, ch)
    d0 = disp[first]
    dspread = np.zeros(len(uniq))
    np.maximum.at(dspread, inv, np.linalg.norm(disp - d0[inv], axis=1))
    rspread = np.zeros(len(uniq))
    np.maximum.at(rspread, inv, np.linalg.norm(R - R0[inv], ord=2, axis=(1, 2)))
    print(f"  rows {len(uniq)} of {len(ud)} windows; widened by {dspread.max():.4f} mm in the chord and "
          f"{rspread.max():.5f} in the rotation")
    rb, ra = before[first], after[first]
    order = np.argsort(rb, kind="stable")
    rb, ra, R0, d0, dspread, rspread = rb[order], ra[order], R0[order], d0[order], dspread[order], rspread[order]
    starts = np.flatnonzero(np.r_[True, rb[1:] != rb[:-1]])
    states = rb[starts]
    E = sphere.points  # (N, 3)
    base = E @ d0.T  # (N, rows) -> transpose
    base = base.T + dspread[:, None]
    q = np.einsum("rji,nj->rni", R0, E)  # R0^T e
    idx, wts = sphere.locate(q)  # (rows, N, 3)
    flat = ra[:, None, None] * N + idx
    # tip start: the last w chords of each full state
    tip_sym = ends(k)[1]
    full = np.unique(table.codes[(digits(table.codes, b, 2 * w + 1) < c).all(axis=1)] % b ** (2 * w))
    D = np.zeros((len(full), 3))
    F = np.broadcast_to(np.eye(3), (len(full), 3, 3)).copy()
    window = full.copy()
    okk = np.ones(len(full), bool)
    for _ in range(w):
        window = window + tip_sym * b ** (2 * w)
        rows, found = table.find(window)
        okk &= found
        F = F @ rotation_matrices(table.space[rows, level, 3:])
        D += np.einsum("mij,mj->mi", F, table.space[rows, level, :3])
        window = window // b
    fstate = state_code(digits(full, b, 2 * w)[:, 2 * w - m:], c)
    h0 = np.full((S, N), EMPTY)
    vals = D @ E.T
    np.maximum.at(h0, fstate[okk], vals[okk])
    hs = [h0]
    for _ in range(steps):
        prev = hs[-1]
        pf = prev.ravel()
        v = base + (wts * pf[flat]).sum(axis=-1)
        radius = np.maximum(prev.max(axis=1), 0.0) * sphere.wmax
        v += (radius[ra] * rspread)[:, None]
        v[prev[ra, 0] <= EMPTY / 2] = EMPTY
        out = np.full((S, N), EMPTY)
        out[states] = np.maximum.reduceat(v, starts, axis=0)
        hs.append(out)
    return hs


def check(table, hs, sphere, m, design, point):
    """Print the bounds at every prefix of ``design`` (module docstring)."""
    lev = table.n_levels - 1
    bits = table.designs(design)
    n = bits.shape[1]
    el = table.space[table.lookup(window_codes(bits, table.window, n_types=table.n_types)[0]), lev]
    P, F = np.array([0.0, table.heights[bits[0, 0]], table.centre_z]), np.eye(3)
    pts, frames = [P.copy()], [F.copy()]
    for j in range(n + 1):
        F = F @ rotation_matrices(el[j, 3:])
        P = P + F @ el[j, :3]
        pts.append(P.copy())
        frames.append(F.copy())
    target = np.asarray(point) + np.array([0.0, table.tip_ref[1], table.centre_z])
    print(f"{design}: {np.linalg.norm(pts[-1] - target):.3f} mm from the point at the last level")
    for p in range(2 * table.window, n):
        P, F, a = pts[p - 2], frames[p - 2], n - p
        s = state_code(bits[:, p - m:p].astype(np.int64), 2 * table.n_types)[0]
        d = target - P
        idx, w = sphere.locate(F.T @ (d / np.linalg.norm(d)))
        along = np.linalg.norm(d) - (w * hs[a][s][idx]).sum()
        hull = (sphere.points @ (F.T @ d) - hs[a][s]).max()
        print(f"  {p} units placed: along the point's direction {along:.3f} mm, over every direction {hull:.3f} mm")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--memory", type=int, default=5)
    parser.add_argument("--subdivisions", type=int, default=4)
    parser.add_argument("--design", default="LAAllalalalaall")
    parser.add_argument("--point", type=float, nargs=3, default=(100.0, 40.0, 40.0))
    args = parser.parse_args()
    table = find_table(make_model(15, {"fidelity": "3d", "library": "spatial"}))
    sphere = Sphere(args.subdivisions)
    t0 = time.perf_counter()
    hs = build(table, table.n_levels - 1, args.memory, sphere, 10)
    print(f"memory {args.memory}, {len(sphere.points)} directions: built in {time.perf_counter() - t0:.1f} s")
    check(table, hs, sphere, args.memory, args.design, args.point)


if __name__ == "__main__":
    main()
