"""Arenas and tanks made by hand for the simulation tests (no bundle needed)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from tanktool.formats.bundle import write_toml
from tanktool.formats.walls_txt import WallList, aux_rectangle, write_walls
from tanktool.sim.body import TankSpec
from tanktool.sim.world import World

ROOT = Path(__file__).resolve().parent.parent


def box_arena() -> tuple[WallList, np.ndarray]:
    """A 120 m x 90 m box with a free-standing thin wall, an L and a closed block."""
    walls = [
        [[60, 20], [60, 50]],                 # thin free-standing wall
        [[20, 60], [40, 60]], [[40, 60], [40, 75]],   # an L
        [[85, 55], [100, 55]], [[100, 55], [100, 70]], [[100, 70], [85, 70]], [[85, 70], [85, 55]],  # a block
    ]
    wl = WallList(np.array(walls, float), np.ones(len(walls), np.int8), aux_rectangle(0, 0, 120, 90))
    spawns = np.array([[10, 10, 0], [110, 10, math.pi], [10, 80, 0], [110, 80, math.pi],
                       [30, 30, 0.5], [90, 30, 2.5], [30, 45, -0.5], [75, 85, math.pi],
                       [50, 10, 1.0], [70, 10, 2.0]], float)
    return wl, spawns


def box_world(positions, headings=None, seed=1):
    """The :func:`box_arena` (120 x 90, a thin wall x=60 from z=20 to 50) with box tanks
    placed at ``positions`` [(x, z)] facing ``headings``."""
    walls, spawns = box_arena()
    n = len(positions)
    w = World(walls, [TankSpec.box("t")] * n, spawns, seed=seed)
    for t, (x, z), h in zip(w.tanks, positions, headings or [0.0] * n):
        t.place(x, z, h)
    return w


def maze_arena() -> tuple[WallList, np.ndarray]:
    """A small maze of thin walls with corridors 14 m wide."""
    walls = []
    for i in range(1, 4):
        x = 14.0 * i * 1.0 + 7 * (i - 1)
        walls.append([[x, 0 if i % 2 else 20], [x, 50 if i % 2 else 70]])
    walls.append([[0, 35], [8, 35]])
    walls.append([[50, 35], [70, 35]])
    wl = WallList(np.array(walls, float), np.ones(len(walls), np.int8), aux_rectangle(0, 0, 70, 70))
    spawns = np.array([[6, 6, 1.57], [6, 62, -1.57], [27, 10, 1.57], [27, 60, -1.57],
                       [44, 10, 1.57], [44, 60, -1.57], [62, 10, 1.57], [62, 60, -1.57]], float)
    return wl, spawns


def write_arena_bundle(folder: Path, walls: WallList, spawns: np.ndarray, name: str = "testbox") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    write_walls(folder / "walls.txt", walls)
    b = walls.bounds
    write_toml(folder / "arena.toml", {"name": name, "bounds": b.tolist(), "spawns": spawns.tolist()})
    return folder


def free_spec(**kw) -> TankSpec:
    """A box tank with no friction, grip or turn drag: no outside force on it."""
    params = dict(friction=0.0, grip=0.0, turn_torque=0.0)
    params.update(kw)
    return TankSpec.box("free", **params)


def bundled_vehicle_specs() -> list[TankSpec]:
    """TankSpecs of the bundled vehicles (vehicles/*/vehicle.toml)."""
    from tanktool.sim.match import load_tank_spec

    return [load_tank_spec(p.parent) for p in sorted((ROOT / "vehicles").glob("*/vehicle.toml"))]


def bundled_arenas() -> list[Path]:
    return sorted(p.parent for p in (ROOT / "arenas").glob("*/walls.txt"))


def start_beside(seg: np.ndarray, k: int, brute, bounds: np.ndarray, R: float, gaps=(2.0, 0.6)):
    """A free place beside wall k (no wall within R + 0.3) and the unit vector from it
    towards the wall, or None."""
    (ax, az), (bx, bz) = seg[k]
    ex, ez = bx - ax, bz - az
    ln = math.hypot(ex, ez)
    nx, nz = -ez / ln, ex / ln
    for gap in gaps:
        d = R + gap
        for u in (0.5, 0.3, 0.7, 0.15, 0.85, 0.05, 0.95):
            for side in (1.0, -1.0):
                px, pz = ax + u * ex + side * nx * d, az + u * ez + side * nz * d
                if not (bounds[0, 0] < px < bounds[1, 0] and bounds[0, 1] < pz < bounds[1, 1]):
                    continue
                if len(brute.query_point(np.array((px, pz)), min(R + 0.3, d - 0.01))) == 0:
                    return px, pz, -side * nx, -side * nz
    return None
