"""Spawn points spread over an arena's free space.

Candidates are the nodes of a regular grid inside the free space's largest
connected region (the one a match is played in: tanks spawned in a sealed pocket
could never meet) that keep at least ``clearance`` metres from every wall.  The
spawns are then picked by farthest-point sampling -- the first is the candidate
nearest the region's centre, each next one the candidate farthest from all chosen
so far -- so they are spread out and deterministic.  Each faces the arena centre
(the centre of the auxiliary rectangle); one within 1 m of it faces +x.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from ..errors import ArenaError

#: default distance from a spawn point to the nearest wall (m): the bundled heavy
#: tank's footprint radius is 4.6 m, so it spawns clear of every wall
SPAWN_CLEARANCE = 5.0
#: default number of spawn points
SPAWN_COUNT = 8
#: upper bound on grid candidates (sets the grid step on big arenas)
MAX_CANDIDATES = 20_000


def spawn_candidates(free, clearance: float) -> np.ndarray:
    """(k, 2) grid points of the largest free region with ``clearance`` to its outline."""
    parts = shapely.get_parts(free)
    if len(parts) == 0:
        return np.zeros((0, 2))
    region = parts[int(np.argmax(shapely.area(parts)))]
    inner = shapely.buffer(region, -clearance, quad_segs=4)
    if inner.is_empty:
        return np.zeros((0, 2))
    x0, z0, x1, z1 = inner.bounds
    step = max(math.sqrt(max(inner.area, 1e-9) / MAX_CANDIDATES), 0.25)
    xs = np.arange(x0 + step / 2, x1, step) if x1 - x0 > step else np.array([(x0 + x1) / 2])
    zs = np.arange(z0 + step / 2, z1, step) if z1 - z0 > step else np.array([(z0 + z1) / 2])
    gx, gz = np.meshgrid(xs, zs)
    pts = np.stack([gx.ravel(), gz.ravel()], axis=1)
    pts = pts[shapely.contains_xy(inner, pts[:, 0], pts[:, 1])]
    if len(pts) == 0:  # a sliver narrower than the grid: its own interior point
        p = shapely.get_coordinates(shapely.point_on_surface(inner))
        pts = p
    return pts


def spread(pts: np.ndarray, count: int, min_separation: float = 0.0, start: np.ndarray | None = None,
           accept=None) -> np.ndarray:
    """Indices of up to ``count`` candidates by farthest-point sampling: the first is the
    candidate nearest ``start`` (default their centroid), each next the one farthest
    from all chosen so far, while that is at least ``min_separation`` away.
    ``accept(i)`` may refuse a candidate when it comes up (it is then skipped)."""
    if len(pts) == 0:
        return np.zeros(0, dtype=np.int64)
    centre = pts.mean(axis=0) if start is None else np.asarray(start, dtype=np.float64)
    alive = np.ones(len(pts), dtype=bool)
    order = np.argsort(((pts - centre) ** 2).sum(axis=1), kind="stable")
    chosen: list[int] = []
    for k in order:  # the first: the acceptable candidate nearest the start
        if accept is None or accept(int(k)):
            chosen.append(int(k))
            break
        alive[k] = False
    if not chosen:
        return np.zeros(0, dtype=np.int64)
    dist = ((pts - pts[chosen[0]]) ** 2).sum(axis=1)
    while len(chosen) < count:
        d = np.where(alive, dist, -1.0)
        k = int(np.argmax(d))
        if d[k] < min_separation * min_separation or d[k] < 0:
            break
        if accept is not None and not accept(k):
            alive[k] = False
            continue
        chosen.append(k)
        dist = np.minimum(dist, ((pts - pts[k]) ** 2).sum(axis=1))
    return np.array(chosen, dtype=np.int64)


def facing_centre(p: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """Headings from points (k, 2) to the centre of ``bounds``; +x within 1 m of it."""
    centre = np.asarray(bounds, dtype=np.float64).mean(axis=0)
    heading = np.arctan2(centre[1] - p[:, 1], centre[0] - p[:, 0])
    # a spawn on the centre itself has no direction to face: it faces +x
    return np.where(np.hypot(*(centre - p).T) < 1.0, 0.0, heading)


def place_spawns(free, bounds: np.ndarray, count: int = SPAWN_COUNT, clearance: float = SPAWN_CLEARANCE,
                 min_clearance: float = 0.5, min_separation: float = 0.0) -> np.ndarray:
    """``count`` spawn points ``[x, z, heading]`` (k, 3) over the free space.

    When fewer than ``count`` candidates keep the clearance, the clearance is halved
    (down to ``min_clearance``) before giving up with an ArenaError; spawns keep
    ``min_separation`` from each other (fewer than ``count`` when the space is small).
    """
    c = clearance
    while True:
        pts = spawn_candidates(free, c)
        if len(pts) >= count:
            break
        if c <= min_clearance:
            if len(pts) and min_separation > 0:
                break  # fewer spawns, but where a tank fits
            raise ArenaError(
                f"the free space is too small for {count} spawn points "
                f"(found {len(pts)} places at least {c:g} m from every wall)"
            )
        c = max(min_clearance, c / 2)
    centre_region = np.asarray(shapely.get_coordinates(shapely.centroid(free))[0])
    p = pts[spread(pts, count, min_separation, centre_region)]
    return np.column_stack([p, facing_centre(p, bounds)])
