"""A tank at top speed pushing into walls never crosses them.

Every wall of every arena (the bundled ones and two made here) gets a tank started
beside it at top speed, aimed at it at an angle, driving at full throttle while its
steering sweeps, so that it hits, pushes, slides along and reaches the wall's ends and
corners.  Crossing is checked independently of the simulation's own detection: from
the recorded centres and hull points, with numpy, against every wall.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_fixtures import box_arena, bundled_arenas, bundled_vehicle_specs, maze_arena

from tanktool.formats.walls_txt import read_walls
from tanktool.sim.body import TankSpec
from tanktool.sim.collide import BruteWallIndex
from tanktool.sim.commands import Command
from tanktool.sim.world import World

TOL = 0.02   # m a hull point may sit past a wall line at the end of a step (SLOP is 0.1 mm)


def _arenas():
    """The flat arenas: walls of one plane (arenas with levels: tests/test_sim_ground.py)."""
    out = [("box-fixture", box_arena()[0]), ("maze-fixture", maze_arena()[0])]
    out += [(p.name, w) for p in bundled_arenas() for w in [read_walls(p / "walls.txt")] if not w.layered]
    return out


def _start_beside(seg: np.ndarray, k: int, brute: BruteWallIndex, bounds: np.ndarray, R: float):
    """A free place beside wall k and the unit normal pointing from it to the wall."""
    (ax, az), (bx, bz) = seg[k]
    ex, ez = bx - ax, bz - az
    ln = math.hypot(ex, ez)
    nx, nz = -ez / ln, ex / ln
    for d in (R + 2.0, R + 0.6):
        for u in (0.5, 0.3, 0.7, 0.15, 0.85, 0.05, 0.95):
            for side in (1.0, -1.0):
                px, pz = ax + u * ex + side * nx * d, az + u * ez + side * nz * d
                if not (bounds[0, 0] < px < bounds[1, 0] and bounds[0, 1] < pz < bounds[1, 1]):
                    continue
                if len(brute.query_point(np.array((px, pz)), R + 0.3)) == 0:
                    return px, pz, -side * nx, -side * nz
    return None


def _crossings(C: np.ndarray, H: np.ndarray, seg: np.ndarray) -> tuple[float, bool]:
    """Deepest hull-point crossing past any wall, and whether a centre switched sides.

    C (T, 2) centres, H (T, k, 2) hull points, seg (n, 2, 2)."""
    A, B = seg[:, 0], seg[:, 1]
    E = B - A
    L = np.hypot(E[:, 0], E[:, 1])
    P = H.reshape(-1, 2)
    Cr = np.repeat(C, H.shape[1], axis=0)
    D = P - Cr
    worst = 0.0
    for w in range(len(seg)):
        e = E[w]
        denom = D[:, 0] * e[1] - D[:, 1] * e[0]
        ac = Cr - A[w]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = -(ac[:, 0] * e[1] - ac[:, 1] * e[0]) / denom
            u = -(ac[:, 0] * D[:, 1] - ac[:, 1] * D[:, 0]) / denom
        cross = (denom != 0) & (s >= 0) & (s <= 1) & (u >= 0) & (u <= 1)
        if cross.any():
            depth = np.abs(e[0] * (P[cross, 1] - A[w, 1]) - e[1] * (P[cross, 0] - A[w, 0])) / L[w]
            worst = max(worst, float(depth.max()))
    # the centre's path: does any step's motion cross a wall?
    M0, M1 = C[:-1], C[1:]
    R = M1 - M0
    switched = False
    for w in range(len(seg)):
        e = E[w]
        denom = R[:, 0] * e[1] - R[:, 1] * e[0]
        ac = A[w] - M0
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (ac[:, 0] * e[1] - ac[:, 1] * e[0]) / denom
            u = (ac[:, 0] * R[:, 1] - ac[:, 1] * R[:, 0]) / denom
        if ((denom != 0) & (t >= 0) & (t <= 1) & (u >= 0) & (u <= 1)).any():
            switched = True
    return worst, switched


def _ends_inside(C: np.ndarray, HD: np.ndarray, spec: TankSpec, seg: np.ndarray) -> float:
    """Deepest a wall end point gets inside the tank's footprint polygon (0 if never).

    HD (T, 2): cos and sin of the heading."""
    ends = np.unique(seg.reshape(-1, 2), axis=0)
    d = ends[None, :, :] - C[:, None, :]                     # (T, m, 2)
    c, s = HD[:, 0:1], HD[:, 1:2]
    lx = d[..., 0] * c + d[..., 1] * s
    lz = -d[..., 0] * s + d[..., 1] * c
    inside = np.full(lx.shape, np.inf)
    for (vx, vz), (nx, nz) in zip(spec.footprint, spec.footprint_normals):
        inside = np.minimum(inside, -((lx - vx) * nx + (lz - vz) * nz))
    return float(max(inside.max(), 0.0))


def _push_runs(walls, steps: int, which=None, spec: TankSpec | None = None, end_on: bool = True):
    spec = spec or TankSpec.box("pusher", restitution=0.2)
    seg = walls.all_segments()
    bounds = walls.bounds
    brute = BruteWallIndex(seg)
    R = spec.radius
    world_box = [None]
    tested = skipped = 0
    for k in range(len(seg)) if which is None else which:
        if math.hypot(*(seg[k, 1] - seg[k, 0])) < 1e-6:
            continue
        runs = []
        start = _start_beside(seg, k, brute, bounds, R)
        if start is not None:
            px, pz, fx, fz = start
            # approach angle varies from wall to wall, within ±60° of head-on
            runs.append((px, pz, math.atan2(fz, fx) + math.radians(((k * 37) % 121) - 60), steps))
        else:
            skipped += 1
        # end-on: drive at each end along the wall's own line, slightly off-centre, so a
        # free end meets the nose between two hull points
        for end, other in ((seg[k, 0], seg[k, 1]), (seg[k, 1], seg[k, 0])) if end_on else ():
            u = (end - other) / np.hypot(*(end - other))
            off = np.array((-u[1], u[0])) * 0.3
            p = end + u * (R + 2.0) + off
            if (bounds[0] < p).all() and (p < bounds[1]).all() and \
                    len(brute.query_point(p, R + 0.3)) == 0:
                runs.append((float(p[0]), float(p[1]), math.atan2(-u[1], -u[0]), max(steps // 2, 1)))
        for px, pz, heading, n in runs:
            _run_one(walls, spec, seg, k, px, pz, heading, n, world_box)
        if start is not None:
            tested += 1
    return tested, skipped


def _run_one(walls, spec, seg, k, px, pz, heading, steps, world_box):
    if world_box[0] is None:
        world_box[0] = World(walls, [spec], [(px, pz, heading)], seed=k)
    world = world_box[0]
    t = world.tanks[0]
    t.place(px, pz, heading)
    t.vx, t.vz = spec.top_speed * math.cos(heading), spec.top_speed * math.sin(heading)
    C = np.empty((steps + 1, 2))
    H = np.empty((steps + 1, len(spec.hull_local), 2))
    HD = np.empty((steps + 1, 2))
    C[0] = (t.x, t.z)
    HD[0] = (t.c, t.s)
    H[0] = t.hull_world()
    for i in range(steps):
        sweep = math.sin(i * world.dt * 0.9 + k)
        world.step(None, [Command(advance=1.0, rotate=0.35 * sweep)])
        C[i + 1] = (t.x, t.z)
        HD[i + 1] = (t.c, t.s)
        H[i + 1] = t.hull_world()
    assert np.isfinite(C).all()
    worst, switched = _crossings(C, H, seg)
    assert not switched, f"wall {k}: the tank's centre crossed a wall"
    assert worst <= TOL, f"wall {k}: a hull point went {worst:.3f} m past a wall"
    poke = _ends_inside(C, HD, spec, seg)
    assert poke <= TOL, f"wall {k}: a wall end went {poke:.3f} m into the tank"


@pytest.mark.parametrize("name,walls", _arenas(), ids=[n for n, _ in _arenas()])
def test_push_into_every_wall(name, walls):
    tested, skipped = _push_runs(walls, steps=600)
    # a wall no tank can stand beside (a sliver between two others) cannot be pushed
    assert tested >= 0.9 * (tested + skipped) and tested > 0


@pytest.mark.parametrize("name,walls", _arenas(), ids=[n for n, _ in _arenas()])
def test_push_10000_steps(name, walls):
    """The issue's full 10,000 steps, on one wall per arena (every wall: -m slow)."""
    n = len(walls.all_segments())
    tested, _ = _push_runs(walls, steps=10_000, which=[n // 2], end_on=False)
    assert tested >= 1


@pytest.mark.slow
@pytest.mark.parametrize("name,walls", _arenas(), ids=[n for n, _ in _arenas()])
def test_push_10000_steps_every_wall(name, walls):
    tested, skipped = _push_runs(walls, steps=10_000)
    assert tested >= 0.9 * (tested + skipped) and tested > 0


@pytest.mark.parametrize("spec", bundled_vehicle_specs(), ids=lambda s: s.name)
def test_bundled_vehicles_push_into_every_wall(spec):
    """The bundled vehicles' own hull points (8..16, not a box) in the box fixture."""
    tested, skipped = _push_runs(box_arena()[0], steps=480, spec=spec)
    assert tested == len(box_arena()[0].all_segments())


@pytest.mark.parametrize("deg", [8, 20, 45, 90, 150])
def test_driving_into_a_wedge_corner(deg):
    """Full throttle into the apex of two walls meeting at ``deg`` degrees: the tank
    jams but neither crosses a wall nor sinks more than a few millimetres."""
    a = math.radians(deg)
    apex = np.array([80.0, 40.0])
    w1 = [apex, apex + 40 * np.array([-math.cos(a / 2), math.sin(a / 2)])]
    w2 = [apex, apex + 40 * np.array([-math.cos(a / 2), -math.sin(a / 2)])]
    from tanktool.formats.walls_txt import WallList, aux_rectangle

    walls = WallList(np.array([w1, w2]), np.ones(2, np.int8), aux_rectangle(0, 0, 100, 80))
    for spec in [TankSpec.box("b")] + bundled_vehicle_specs():
        world = World(walls, [spec], [(45.0, 40.0, 0.0)], seed=0)
        t = world.tanks[0]
        t.place(45.0, 40.0, 0.0)
        n = 1500
        C, H, HD = np.empty((n, 2)), np.empty((n, len(spec.hull_local), 2)), np.empty((n, 2))
        for i in range(n):
            world.step(None, [Command(advance=1.0, rotate=0.3 * math.sin(i * 0.01))])
            C[i], HD[i] = (t.x, t.z), (t.c, t.s)
            H[i] = t.hull_world()
        worst, switched = _crossings(C, H, walls.all_segments())
        assert not switched
        assert worst <= 0.005, f"{spec.name}: {worst:.4f} m past a wall"
        assert _ends_inside(C, HD, spec, walls.all_segments()) <= 0.005
        # it did drive into the wedge (narrow wedges stop it early, at its own width)
        assert C[:, 0].max() > C[0, 0] + 2.0
