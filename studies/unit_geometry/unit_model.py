"""Parametric articulating-unit actuator for the unit-geometry study (2D quad8 / 3D hex20).

Self-contained study code (not part of the package): builds an actuator of ``n`` units from
an orientation string, solves a follower-pressure ramp with FElupe and measures the curl.

Geometry of one unit in orientation 0 (x along the actuator, y up, z across the width)::

    y = H  +---------------------------------------------+
           |  Smooth-Sil 950 layer (``layer``)           |
           +---------------------------------------------+
           |  Mold Star 15 top wall (``wall``)           |
           |      +-----------------------------+        |
           | end  |   cavity  Lc x Hc x (W-2t)  |  end   |
           | wall |                             |  wall  |
           |      +-----------------------------+        |
           |  Mold Star 15 bottom wall (``wall``)        |
    y = 0  +---------------------------------------------+
           x = 0                                 x = pitch

``Lc = pitch - 2 end_wall - slit_width``. Orientation 1 is the unit turned 180 degrees about
the long axis (y -> H - y, z -> W - z). Optional features evaluated in the study: a slit
cut from the soft face at the distal end of every unit (width ``slit_width``, depth
``slit_depth``), optionally filled by a very soft third medium (``medium``, shear modulus
in MPa) that stands in for contact between neighbouring end walls, and a solid Mold Star
cap appended at the tip (``tip_cap``).

Units: mm, N, MPa. Pressures given in kPa at the command line.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field, asdict

for _k in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    os.environ.setdefault(_k, "1")

import numpy as np  # noqa: E402
import felupe as fem  # noqa: E402
import tensortrax.math as tm  # noqa: E402

try:  # optional, much faster on 3D models
    import pypardiso  # noqa: E402
except ImportError:  # pragma: no cover
    pypardiso = None

#: Ellis (2020) Table A.4 (Ogden, MSC Marc convention W = sum mu/alpha (...), MPa) and
#: Table A.5 (bulk modulus, MPa).
MOLD_STAR_15 = {"mu": (-6.503e-6, 0.2169, 1.372e-3), "alpha": (-21.32, 1.180, 4.884), "K": 0.119}
SMOOTH_SIL_950 = {"mu": (-0.3062, 0.0283, 6.596e-9), "alpha": (-3.059, 4.597, 17.69), "K": 0.679}


def filler_modulus(p_mpa: float) -> float:
    """Young's modulus of the 2D filler, Ellis (2020) Eq 5.2 (P and E in MPa)."""
    return 0.0643 - 1.82 * p_mpa + 12.4 * p_mpa**2


# --- constitutive models (tensortrax strain energies of C) ------------------------------


def ogden_compressible(C, mu, alpha, K):
    """Isochoric Ogden (FElupe convention mu_i = mu_marc alpha / 2) + 9/2 K (J^(1/3) - 1)^2."""
    J = tm.sqrt(tm.linalg.det(C))
    return fem.ogden(C, mu, alpha) + 4.5 * K * (J ** (1 / 3) - 1) ** 2


def neo_hooke_compressible(C, mu, K):
    """Isochoric neo-Hooke + 9/2 K (J^(1/3) - 1)^2 (screening only)."""
    J = tm.sqrt(tm.linalg.det(C))
    return mu / 2 * (tm.trace(C) * J ** (-2 / 3) - 3) + 4.5 * K * (J ** (1 / 3) - 1) ** 2


def neo_hooke_log(C, mu, lmbda):
    """Compressible neo-Hooke with a log barrier (filler, third medium)."""
    lnJ = tm.log(tm.linalg.det(C)) / 2
    return mu / 2 * (tm.trace(C) - 3) - mu * lnJ + lmbda / 2 * lnJ**2


def silicone_umat(material: dict, model: str = "ogden"):
    mu = [m * a / 2 for m, a in zip(material["mu"], material["alpha"])]
    if model == "ogden":
        return fem.Hyperelastic(ogden_compressible, mu=mu, alpha=list(material["alpha"]),
                                K=material["K"])
    if model == "neohooke":
        return fem.Hyperelastic(neo_hooke_compressible, mu=sum(mu), K=material["K"])
    raise ValueError(f"model must be 'ogden' or 'neohooke', got {model!r}")


# --- geometry and mesh ------------------------------------------------------------------


@dataclass(frozen=True)
class UnitGeometry:
    """Dimensions of one articulating unit (mm)."""

    pitch: float = 10.5
    width: float = 15.0
    wall: float = 1.5
    layer: float = 3.0
    cavity_height: float = 12.0
    end_wall: float = 1.5
    slit_width: float = 0.0
    slit_depth: float = 0.0
    medium: float = 0.0
    tip_cap: float = 0.0
    element_size: float = 1.5

    @property
    def height(self) -> float:
        return 2 * self.wall + self.cavity_height + self.layer

    @property
    def cavity_length(self) -> float:
        return self.pitch - 2 * self.end_wall - self.slit_width

    def __post_init__(self):
        if self.cavity_length <= 0:
            raise ValueError(f"cavity length must be positive, got {self.cavity_length} mm")
        if self.slit_width > 0 and not 0 < self.slit_depth < self.height:
            raise ValueError(f"slit depth must lie in (0, {self.height}), got {self.slit_depth}")


def _lines(breaks, h):
    breaks = np.unique(np.round(np.asarray(breaks, float), 9))
    out = [breaks[0]]
    for a, b in zip(breaks[:-1], breaks[1:]):
        n = max(1, int(np.ceil((b - a) / h - 1e-9)))
        out.extend(np.linspace(a, b, n + 1)[1:])
    return np.array(out)


@dataclass
class ActuatorMesh:
    mesh: fem.Mesh
    material: np.ndarray  # per cell: 0 Mold Star 15, 1 Smooth-Sil 950, 2 medium, 3 filler
    cavity_points: np.ndarray  # point mask of the cavity walls
    tracked: np.ndarray  # (n, 4) cavity vertices per unit (mid-width plane in 3D)
    geometry: UnitGeometry
    orientation: str
    dim: int
    half: bool

    def submesh(self, materials) -> fem.Mesh:
        sel = np.isin(self.material, materials)
        return fem.Mesh(self.mesh.points, self.mesh.cells[sel], self.mesh.cell_type)


def build_mesh(g: UnitGeometry, orientation: str, dim: int = 3, half: bool = True,
               filler: bool = False) -> ActuatorMesh:
    """Structured quad8 (2D) / hex20 (3D) mesh of the actuator; grid lines on every interface.

    In 3D with ``half=True`` only z in [0, W/2] is meshed (symmetry plane at z = W/2; exact
    for every orientation string because the section is symmetric across the width).
    ``filler=True`` (2D only) keeps the cavity cells as the reduced-order model's filler.
    """
    if set(orientation) - {"0", "1"} or not orientation:
        raise ValueError(f"orientation must be a non-empty string of 0/1, got {orientation!r}")
    n = len(orientation)
    H, W, P = g.height, g.width, g.pitch
    xc0, xc1 = g.end_wall, g.end_wall + g.cavity_length
    xs0 = P - g.slit_width
    yc0, yc1 = g.wall, g.wall + g.cavity_height
    yb = [0, yc0, yc1, H - g.layer, H] + ([g.slit_depth] if g.slit_width > 0 else [])
    ys = _lines(yb + [H - y for y in yb], g.element_size)
    xb = [i * P + v for i in range(n) for v in (0, xc0, xc1, xc1 + g.end_wall, xs0, P)]
    if g.tip_cap > 0:
        xb.append(n * P + g.tip_cap)
    xs = _lines(xb, g.element_size)
    if dim == 3:
        zb = [0, g.wall, W / 2] if half else [0, g.wall, W / 2, W - g.wall, W]
        grid = fem.Grid(xs, ys, _lines(zb, g.element_size))
    else:
        grid = fem.Grid(xs, ys)
    cen = grid.points[grid.cells].mean(axis=1)
    cx, cy = cen[:, 0], cen[:, 1]
    unit = np.clip((cx // P).astype(int), 0, n - 1)
    cap = cx > n * P
    lx = cx - unit * P
    o = np.array([int(c) for c in orientation])[unit]
    ly = np.where(o == 0, cy, H - cy)  # height in the unit's own (orientation-0) frame
    cavity = (lx > xc0) & (lx < xc1) & (ly > yc0) & (ly < yc1) & ~cap
    if dim == 3:
        cavity &= (cen[:, 2] > g.wall) & (cen[:, 2] < W - g.wall)
    slit = (lx > xs0) & (ly < g.slit_depth) & ~cap if g.slit_width > 0 else np.zeros_like(cavity)
    mat = np.where((ly > H - g.layer) & ~cap, 1, 0)
    if g.medium > 0:
        mat[slit] = 2
        slit = np.zeros_like(slit)
    if filler and dim == 2:
        mat[cavity] = 3
        cavity = np.zeros_like(cavity)
    keep = ~(cavity | slit)
    cells, mat = grid.cells[keep], mat[keep]
    used = np.unique(cells)
    remap = np.full(len(grid.points), -1)
    remap[used] = np.arange(len(used))
    mesh = fem.Mesh(grid.points[used], remap[cells], grid.cell_type).add_midpoints_edges()
    p = mesh.points
    mask = np.zeros(len(p), bool)
    tracked = np.zeros((n, 4), int)
    tol = 1e-6
    for i, oi in enumerate(orientation):
        lxp = p[:, 0] - i * P
        lyp = p[:, 1] if oi == "0" else H - p[:, 1]
        m = (lxp > xc0 - tol) & (lxp < xc1 + tol) & (lyp > yc0 - tol) & (lyp < yc1 + tol)
        if dim == 3:
            m &= (p[:, 2] > g.wall - tol) & (p[:, 2] < W - g.wall + tol)
        mask |= m
        yv = (yc0, yc1) if oi == "0" else (H - yc1, H - yc0)
        k = 0
        for xv in (i * P + xc0, i * P + xc1):
            for y in yv:
                d = (p[:, 0] - xv) ** 2 + (p[:, 1] - y) ** 2
                if dim == 3:
                    d = d + (p[:, 2] - W / 2) ** 2
                tracked[i, k] = np.argmin(d)
                k += 1
    return ActuatorMesh(mesh, mat, mask, tracked, g, orientation, dim, half and dim == 3)


# --- model and solver -------------------------------------------------------------------


class ActuatorModel:
    """FElupe items of one actuator: silicone bodies, optional medium/filler, cavity pressure."""

    def __init__(self, am: ActuatorMesh, model: str = "ogden"):
        self.am = am
        dim = am.dim
        if dim == 3:
            Region, Boundary, Field = (fem.RegionQuadraticHexahedron,
                                       fem.RegionQuadraticHexahedronBoundary, fem.Field)
        else:
            Region, Boundary, Field = (fem.RegionQuadraticQuad, fem.RegionQuadraticQuadBoundary,
                                       fem.FieldPlaneStrain)
        self.field = fem.FieldContainer([Field(Region(am.mesh), dim=dim)])
        self.items = []
        self.filler = None
        g = am.geometry
        for mat_id, spec in ((0, MOLD_STAR_15), (1, SMOOTH_SIL_950), (2, "medium"), (3, "filler")):
            sub = am.submesh([mat_id])
            if sub.ncells == 0:
                continue
            f = fem.FieldContainer([Field(Region(sub), dim=dim)])
            f.link(self.field)
            if spec == "medium":
                umat = fem.Hyperelastic(neo_hooke_log, mu=g.medium, lmbda=g.medium)
            elif spec == "filler":  # nu = 0.3, E(P) of Eq 5.2 set per increment
                umat = fem.Hyperelastic(neo_hooke_log, mu=1.0, lmbda=1.0)
                self.filler = umat
            else:
                umat = silicone_umat(spec, model)
            self.items.append(fem.SolidBody(umat, f))
        # cavity walls: outline faces of the solid (non-filler) cells whose points all lie on
        # the cavity boundary
        solid = am.submesh([0, 1, 2])
        kw = {"ensure_3d": True} if dim == 2 else {}
        self.walls = Boundary(solid, mask=am.cavity_points, **kw)
        wf = fem.FieldContainer([Field(self.walls, dim=dim)])
        wf.link(self.field)
        self.pressure = fem.SolidBodyPressure(wf, pressure=0.0)
        self.items.append(self.pressure)
        bounds = {"base": fem.Boundary(self.field[0], fx=lambda x: np.isclose(x, 0.0))}
        if am.half:
            w2 = g.width / 2
            bounds["symmetry"] = fem.Boundary(self.field[0], fz=lambda z: np.isclose(z, w2),
                                              skip=(1, 1, 0))
        self.dof0, self.dof1 = fem.dof.partition(self.field, bounds)
        self.ndof = self.field[0].values.size

    def set_pressure(self, p: float) -> None:
        self.pressure.update(p)
        if self.filler is not None:
            E, nu = filler_modulus(p), 0.3
            self.filler.kwargs["mu"] = E / (2 * (1 + nu))
            self.filler.kwargs["lmbda"] = E * nu / ((1 + nu) * (1 - 2 * nu))

    def residual_and_tangent(self, matrix: bool = True):
        """Sum over items; FElupe's item multipliers applied (the pressure's is -1)."""
        r, K = 0.0, 0.0
        for item in self.items:
            mult = item.assemble.multiplier or 1.0
            r = r + mult * item.assemble.vector(item.field)
            if matrix:
                K = K + mult * item.assemble.matrix(item.field)
        return np.asarray(r.todense()).ravel(), (K.tocsr() if matrix else None)

    @property
    def u(self) -> np.ndarray:
        return self.field[0].values.ravel().copy()

    @u.setter
    def u(self, value: np.ndarray) -> None:
        self.field[0].values[:] = value.reshape(self.field[0].values.shape)

    def min_det_F(self) -> float:
        m = np.inf
        for item in self.items:
            if isinstance(item, fem.SolidBody):
                F = item.field.extract(grad=True, sym=False, add_identity=True)[0]
                m = min(m, float(np.linalg.det(np.moveaxis(F, (0, 1), (-2, -1))).min()))
        return m


def _solve_linear(K, b):
    if pypardiso is not None:
        return pypardiso.spsolve(K, b)
    import scipy.sparse.linalg as sla

    return sla.spsolve(K.tocsc(), b)


@dataclass
class SolverSettings:
    p_max: float = 0.045  # MPa
    first_step: float = 0.05  # load-factor increments
    max_step: float = 0.1
    min_step: float = 1e-3
    max_iterations: int = 10
    grow_below: int = 4  # grow the step by 1.5 if converged in <= this many iterations
    tol_du: float = 1e-8  # |du| / max(1, |u|)
    tol_r: float = 1e-6  # |r| / max(1, |r_0|) + 1e-6 N


@dataclass
class Increment:
    pressure_kpa: float
    iterations: int
    wall_time: float
    curl_deg: float
    unit_rotation_deg: list
    centres: list
    ballooning_mm: float


@dataclass
class SolveResult:
    converged: bool
    pressure_reached_kpa: float
    newton_iterations: int
    cutbacks: int
    wall_time: float
    dofs: int
    increments: list = field(default_factory=list)
    u: np.ndarray | None = None


def newton(model: ActuatorModel, lam: float, u0: np.ndarray, s: SolverSettings):
    u = u0.copy()
    free = model.dof1
    model.set_pressure(lam * s.p_max)
    model.u = u
    r0 = None
    for it in range(1, s.max_iterations + 1):
        r, K = model.residual_and_tangent()
        rf = r[free]
        if not np.all(np.isfinite(rf)):
            return False, u, it
        r0 = max(np.linalg.norm(rf), 1e-12) if r0 is None else r0
        du = _solve_linear(K[free][:, free], -rf)
        if not np.all(np.isfinite(du)) or np.linalg.norm(du) > 1e3:
            return False, u, it
        u[free] += du
        model.u = u
        if np.linalg.norm(du) < s.tol_du * max(1.0, np.linalg.norm(u)):
            r, _ = model.residual_and_tangent(matrix=False)
            if np.linalg.norm(r[free]) < s.tol_r * max(1.0, r0) + 1e-6:
                return True, u, it
    return False, u, s.max_iterations


def solve(model: ActuatorModel, s: SolverSettings = SolverSettings(), verbose: bool = True,
          keep_states: bool = False) -> SolveResult:
    """Pressure ramp 0 -> p_max with an extrapolating predictor and cut-back.

    Each increment starts from the linear extrapolation (in the load factor) of the last two
    converged states; a failed increment (no convergence in ``max_iterations``, NaN, or an
    inverted element) is halved, a fast one (<= ``grow_below`` iterations) grows by 1.5.
    """
    t0 = time.perf_counter()
    u, u_prev = np.zeros(model.ndof), None
    lam, lam_prev, dlam = 0.0, 0.0, s.first_step
    res = SolveResult(False, 0.0, 0, 0, 0.0, model.ndof)
    states = []
    while lam < 1.0 - 1e-12:
        dl = min(dlam, 1.0 - lam)
        guess = u if u_prev is None else u + (u - u_prev) * dl / (lam - lam_prev)
        ok, u_new, its = newton(model, lam + dl, guess, s)
        res.newton_iterations += its
        if ok and model.min_det_F() <= 0:
            ok = False
        if not ok:
            res.cutbacks += 1
            dlam = dl / 2
            model.u = u
            if verbose:
                print(f"  cut-back at {(lam + dl) * s.p_max * 1e3:.2f} kPa ({its} its)", flush=True)
            if dlam < s.min_step:
                break
            continue
        u_prev, lam_prev, u, lam = u, lam, u_new, lam + dl
        rot, cen = unit_rotations(model.am, u)
        inc = Increment(lam * s.p_max * 1e3, its, time.perf_counter() - t0, float(rot[-1]),
                        rot.tolist(), cen.tolist(), ballooning(model.am, u))
        res.increments.append(inc)
        if keep_states:
            states.append(u.copy())
        if verbose:
            print(f"  p={inc.pressure_kpa:6.2f} kPa its={its:2d} curl={inc.curl_deg:8.2f} deg "
                  f"ballooning={inc.ballooning_mm:5.2f} mm t={inc.wall_time:6.1f} s", flush=True)
        if its <= s.grow_below:
            dlam = min(1.5 * dl, s.max_step)
    model.u = u
    res.converged = lam >= 1.0 - 1e-12
    res.pressure_reached_kpa = lam * s.p_max * 1e3
    res.wall_time = time.perf_counter() - t0
    res.u = u
    res.states = states
    return res


# --- measures ---------------------------------------------------------------------------


def unit_rotations(am: ActuatorMesh, u: np.ndarray):
    """Cumulative rotation (deg, counter-clockwise positive) of every unit and unit centres.

    A unit's rotation is that of its distal cavity edge (the line through its two distal
    cavity vertices); relative rotations of neighbours are wrapped to (-180, 180] and summed,
    so the tip value (the curl) may exceed 360 degrees. Centres: mean of the four vertices.
    """
    X = am.mesh.points
    x = (X + u.reshape(X.shape))[:, :2]
    tr = am.tracked
    v = x[tr[:, 3]] - x[tr[:, 2]]  # lower -> upper distal vertex
    ang = np.arctan2(-v[:, 0], v[:, 1])
    rel = np.diff(np.concatenate([[0.0], ang]))
    rel = (rel + np.pi) % (2 * np.pi) - np.pi
    return np.degrees(np.cumsum(rel)), x[tr].mean(axis=1)


def ballooning(am: ActuatorMesh, u: np.ndarray) -> float:
    """Largest non-rigid displacement of any unit (mm): per unit, the points of its pitch
    are fitted by a rigid motion (Kabsch) and the largest residual is taken."""
    X = am.mesh.points
    U = u.reshape(X.shape)
    P = am.geometry.pitch
    worst = 0.0
    for i in range(len(am.orientation)):
        sel = (X[:, 0] >= i * P - 1e-9) & (X[:, 0] <= (i + 1) * P + 1e-9)
        A, B = X[sel], X[sel] + U[sel]
        a0, b0 = A.mean(0), B.mean(0)
        Hm = (A - a0).T @ (B - b0)
        Us, _, Vt = np.linalg.svd(Hm)
        d = np.sign(np.linalg.det(Vt.T @ Us.T))
        D = np.eye(A.shape[1])
        D[-1, -1] = d
        R = Vt.T @ D @ Us.T
        fit = (A - a0) @ R.T + b0
        worst = max(worst, float(np.linalg.norm(B - fit, axis=1).max()))
    return worst


def geometry_dict(g: UnitGeometry) -> dict:
    d = asdict(g)
    d.update(height=g.height, cavity_length=g.cavity_length)
    return d
