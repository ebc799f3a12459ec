"""Spawning beyond the spawn points (issue 25): when more tanks play than an arena has
spawn points, the others start at free places of the ground where they fit.

The places are nodes of the ground's grid (the agents' grid at ``CELL`` m with the
tank's footprint radius as clearance: on a relief, measured along the surface, so a
node by a drop-off or a wall's foot does not count), reachable from the arena's own
spawn points, so every one is on a level -- never in a hole or on a roof nobody can
reach.  They are picked by farthest-point sampling from the spawn points already there
(each the candidate farthest from every spawn so far, at least a tank's length from
them), which also keeps them out of the others' way; each faces the arena's centre.
Deterministic: the same arena gives the same places.  How many tanks of a size an
arena holds at once is :func:`capacity`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ArenaError

if TYPE_CHECKING:  # pragma: no cover
    from .world import World

#: the node spacing of the places [m]
CELL = 1.0


def _candidates(world: "World", radius: float) -> tuple[np.ndarray, np.ndarray]:
    """(k, 2) centres of the reachable nodes a tank of ``radius`` fits on and (k,) their
    heights (NaN on a flat ground)."""
    from .agents.navigation import strict_grid

    grid = strict_grid(world, CELL, radius)
    g = grid.layers if grid.layers is not None else grid
    ll, ii, jj = np.nonzero(np.asarray(g.valid) & np.asarray(g.reachable))
    # a grid of the walls alone (a flat ground) has no heights
    ys = np.asarray(g.height, dtype=np.float64)[ll, ii, jj] if g.height is not None else np.full(len(ii), np.nan)
    pts = np.stack([g.origin[0] + (jj + 0.5) * g.cell, g.origin[1] + (ii + 0.5) * g.cell], axis=1)
    return pts.astype(np.float64), ys


def _pick(pts: np.ndarray, taken: np.ndarray, count: int, spacing: float) -> list[int]:
    """Farthest-point picks among ``pts`` from the ``taken`` points, each at least
    ``spacing`` from all before it (first index on ties)."""
    if len(pts) == 0:
        return []
    d = np.full(len(pts), np.inf)
    for p in taken:
        d = np.minimum(d, np.hypot(pts[:, 0] - p[0], pts[:, 1] - p[1]))
    out: list[int] = []
    while len(out) < count:
        k = int(np.argmax(d))
        if not d[k] >= spacing:
            break
        out.append(k)
        d = np.minimum(d, np.hypot(pts[:, 0] - pts[k, 0], pts[:, 1] - pts[k, 1]))
    return out


def places(world: "World", count: int, radius: float, length: float) -> list[tuple[float, float, float, Any]]:
    """Up to ``count`` more spawn places (x, z, heading, y or None) for tanks of footprint
    ``radius`` and ``length``, a tank's length from the spawns there are."""
    pts, ys = _candidates(world, radius)
    taken = np.array([s[:2] for s in world.spawns], dtype=np.float64).reshape(-1, 2)
    picks = _pick(pts, taken, count, length)
    (x0, z0), (x1, z1) = np.asarray(world.bounds, dtype=np.float64).tolist()
    cx, cz = 0.5 * (x0 + x1), 0.5 * (z0 + z1)
    out = []
    for k in picks:
        x, z = float(pts[k, 0]), float(pts[k, 1])
        h = math.atan2(cz - z, cx - x) if math.hypot(cx - x, cz - z) > 1.0 else 0.0
        y = float(ys[k]) if math.isfinite(ys[k]) else None
        out.append((x, z, h, y))
    return out


def capacity(world: "World", radius: float, length: float, limit: int = 64) -> int:
    """How many tanks of this size the arena holds at once (its spawn points and the
    free places a tank's length apart), up to ``limit``."""
    more = max(limit - len(world.spawns), 0)
    pts, _ = _candidates(world, radius)
    if _places_count(pts) > (len(world.spawns) + more) * _nodes_within(length):
        # the picking stops early only once every candidate lies within ``length`` of a
        # spawn or a pick, and that many discs cannot cover this many places: all
        # ``more`` are found (the picks themselves: 0.3 s on an 800 m level)
        return len(world.spawns) + more
    taken = np.array([s[:2] for s in world.spawns], dtype=np.float64).reshape(-1, 2)
    return len(world.spawns) + len(_pick(pts, taken, more, length))


def _places_count(pts: np.ndarray) -> int:
    """How many distinct places (cells of CELL) ``pts`` holds: nodes of two levels can share one."""
    if len(pts) == 0:
        return 0
    cells = np.floor(pts / CELL).astype(np.int64)
    cells -= cells.min(axis=0)
    width = int(cells[:, 1].max()) + 1
    key = cells[:, 0] * width + cells[:, 1]
    extent = int(cells[:, 0].max()) * width + width
    if extent > 4 * len(key) + (1 << 20):  # sparse places over a large extent
        return len(np.unique(key))
    # marks in a mask of the extent: np.unique's hashing of 14 M keys took 7.4 s on
    # a 2 km terrain's import (its tables outgrow the caches), the mask 0.1 s
    seen = np.zeros(extent, dtype=bool)
    seen[key] = True
    return int(np.count_nonzero(seen))


def _nodes_within(r: float) -> float:
    """At most this many nodes (cell centres CELL apart) lie closer than ``r`` to any
    point: each one's cell lies inside the disc of radius r + CELL / sqrt 2."""
    return math.pi * (r / CELL + math.sqrt(0.5)) ** 2


def extend(world: "World", tanks: int, radius: float, length: float, vehicle: str) -> None:
    """Add free places to ``world.spawns`` / ``world.spawn_y`` until ``tanks`` fit, or
    raise ArenaError saying how many the arena holds."""
    need = tanks - len(world.spawns)
    if need <= 0:
        return
    more = places(world, need, radius, length)
    for x, z, h, y in more:
        world.spawns.append((x, z, h))
        world.spawn_y.append(y)
    if len(more) < need:
        raise ArenaError(f"the arena holds {len(world.spawns)} tanks of {vehicle} at once "
                         f"({len(world.spawns) - len(more)} spawn points and {len(more)} free places a tank's length "
                         f"apart), {tanks} asked for")


def holds(info: Any, specs: list, limit: int = 64) -> list[tuple[str, int]]:
    """(vehicle, how many of it the arena ``info`` (``match.ArenaInfo``) holds at once,
    up to ``limit``) for each TankSpec of ``specs``."""
    from .world import World

    out = []
    for spec in specs:
        own = info.spawns_for(spec)      # a smaller vehicle's own spawns, where it has a grid of its own
        w = World(info.walls, [spec], own[:1] if len(own) else own, bounds=info.bounds, ground=info.ground)
        w.spawns, w.spawn_y = w.spawns[:0], w.spawn_y[:0]   # count from the arena's own spawn points
        for row in np.asarray(own, dtype=np.float64).reshape(len(own), -1):
            w.spawns.append((float(row[0]), float(row[1]), float(row[2])))
            w.spawn_y.append(float(row[3]) if len(row) > 3 and math.isfinite(row[3]) else None)
        out.append((spec.name, min(capacity(w, spec.radius, spec.box[2] - spec.box[0], limit), limit)))
    return out


def slots(info: Any, spec: Any, limit: int) -> int:
    """How many tanks of ``spec`` a match on ``info`` (``match.ArenaInfo``) can seat, up
    to ``limit`` (a network session's player numbers): ``limit`` when the arena has that
    many spawn points, else what it holds at once (:func:`holds`)."""
    if len(info.spawns_for(spec)) >= limit:
        return limit
    return holds(info, [spec], limit)[0][1]
