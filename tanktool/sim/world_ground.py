"""The world on its ground: walls per level, sight, standing and tilting, spawn sight
(out of sim/world.py: ``World`` takes these methods from :class:`GroundMixin`).

A tank's walls are its level's; a line of sight is blocked by the walls on a flat arena
(the 2002 walls, infinitely tall) and by the model's solid on a ground; a tank stands
at the ground's height under it with its tilt.  The methods read the world's
``ground``, ``walls``, ``level_walls``, ``_wall_y``, ``bounds``, ``spawns`` and
``spawn_y``, which ``World.__init__`` sets.
"""

from __future__ import annotations

import math
from typing import Any, Iterable, Sequence

import numpy as np

from ..nav.quadtree import WallQuadtree
from .body import Tank
from .collide import QuadtreeIndex, WallSet
from .on_ground import put_back

#: eye height over the surface of a point of sight given without one [m]
EYE = 1.2


class GroundMixin:
    """World methods on levels, sight and standing (see the module docstring)."""

    def _build_level_walls(self, walls: Any, segments: np.ndarray) -> None:
        """One wall set per level (its walls and the auxiliary rectangle), and the
        height range of the region each wall bounds (a wall stops only the tanks on its
        own surface: not one on a deck above it)."""
        level = np.asarray(getattr(walls, "level", np.zeros(0)), dtype=np.int64)
        region = np.asarray(getattr(walls, "region", np.zeros(0)), dtype=np.int64)
        seg = np.asarray(getattr(walls, "segments", segments), dtype=np.float64).reshape(-1, 2, 2)
        regions = getattr(walls, "regions", None) or {}
        aux = segments[len(seg):]
        for lv in range(max(self.ground.levels, int(level.max()) + 1 if len(level) else 1)):
            sel = np.flatnonzero(level == lv) if len(level) == len(seg) else np.arange(len(seg))
            ys = []
            for k in sel:
                r = regions.get(int(region[k])) if len(region) == len(seg) else None
                lo, hi = (r[1], r[2]) if r is not None and math.isfinite(r[1]) and math.isfinite(r[2]) \
                    else (-math.inf, math.inf)
                ys.append((lo, hi))
            ys += [(-math.inf, math.inf)] * len(aux)
            part = np.concatenate([seg[sel], aux]) if len(sel) else aux
            tree = WallQuadtree.build(part, self.bounds, depth=3) if len(part) else None
            self.level_walls.append(WallSet(part, QuadtreeIndex(tree) if tree is not None else None))
            self._wall_y.append(ys)

    def eye(self, t: Tank) -> float:
        """World y a tank looks from (and is seen at): its gun's height over its base."""
        return t.y + t.spec.muzzle_local[1]

    def _eye_at(self, x: float, z: float) -> float:
        """Eye height over the lowest surface at (x, z) of the ground: for a point of
        sight given without a height."""
        g = self.ground
        return g.height(x, z, max(g.locate(x, z), 0)) + EYE

    def line_blocked(self, ax: float, az: float, bx: float, bz: float,
                     ay: float | None = None, by: float | None = None) -> bool:
        """Whether a line of sight from (ax, ay, az) to (bx, by, bz) is blocked: by a
        wall on a flat arena (the 2002 walls, infinitely tall; heights unused), by the
        model's solid on a ground (terrain, decks, ceilings, walls; a height left out is
        eye height over the lowest surface there)."""
        g = self.ground
        if g.mesh is None:
            return self.walls.blocked(ax, az, bx, bz)
        a = (ax, self._eye_at(ax, az) if ay is None else ay, az)
        return g.solids.blocked(a, (bx, self._eye_at(bx, bz) if by is None else by, bz))

    def sees(self, a: Tank, b: Tank) -> bool:
        """Whether nothing stands between two tanks' eyes (range and cone aside)."""
        return not self.line_blocked(a.x, a.z, b.x, b.z, self.eye(a), self.eye(b))

    def sees_all(self, a: Tank, others: Sequence[Tank]) -> list[bool]:
        """``sees(a, b)`` for each of ``others``, in one go (see :meth:`blocked_from`)."""
        return [not hidden for hidden in
                self.blocked_from(a.x, a.z, self.eye(a), [(b.x, b.z, self.eye(b)) for b in others])]

    def blocked_from(self, ax: float, az: float, ay: float | None,
                     points: Sequence[tuple[float, float, float | None]]) -> Iterable[bool]:
        """``line_blocked`` from (ax, ay, az) to each (x, z, y) of ``points``: on a
        ground in one go (``SolidField.visible_from``; a height left out is eye height
        over the lowest surface there), on a flat arena one by one as asked for."""
        g = self.ground
        if g.mesh is None:
            return (self.line_blocked(ax, az, x, z, ay, y) for x, z, y in points)
        a = (ax, self._eye_at(ax, az) if ay is None else ay, az)
        pts = [(x, self._eye_at(x, z) if y is None else y, z) for x, z, y in points]
        return (~g.solids.visible_from(a, pts)).tolist()

    def walls_of(self, t: Tank) -> WallSet:
        """The walls a tank can hit: its level's (all walls on a flat arena)."""
        if not self.level_walls:
            return self.walls
        return self.level_walls[min(max(t.level, 0), len(self.level_walls) - 1)]

    def _wall_candidates(self, t: Tank, slack: float) -> tuple:
        """(x, z, walls within reach, level) of a tank: on a ground, only the walls of its
        level whose region lies within the climb of its height."""
        ws = self.walls_of(t)
        cand = ws.near(t.x, t.z, t.spec.radius + slack)
        if self.level_walls:
            ys = self._wall_y[min(max(t.level, 0), len(self._wall_y) - 1)]
            tol = self.ground.climb + t.spec.height
            cand = [k for k in cand if ys[k][0] - tol <= t.y <= ys[k][1] + tol]
        return (t.x, t.z, cand, t.level)

    def stand(self, t: Tank, y: float | None) -> None:
        """Put a tank on the ground under it: its level (the one nearest ``y``), height
        and tilt (nothing on a flat arena).  For a tank placed from outside the step (a
        network peer's state, a test): the nearest level to where it was keeps it on
        its deck or under it.  Where the ground has no level under it (a spawn point in
        a hole), it is put on the nearest node first (sim/on_ground.py)."""
        g = self.ground
        put_back(g, t, y)
        lv = g.near_level(t.x, t.z, y) if y is not None else g.locate(t.x, t.z)
        if lv < 0:
            lv = g.locate(t.x, t.z, y)
        t.level = max(lv, 0)
        self._tilt(t)

    def _tilt(self, t: Tank) -> None:
        bx0, bz0, bx1, bz1 = t.spec.box
        t.y, t.pitch, t.roll = self.ground.tilt(t.x, t.z, t.level, t.c, t.s, 0.5 * (bx1 - bx0), 0.5 * (bz1 - bz0))

    def _spawn_eye(self, k: int) -> float | None:
        """Eye height at spawn point ``k`` (None on a flat arena or with no height)."""
        y = self.spawn_y[k]
        return None if not self.ground.relief or y is None else y + EYE

    def _watchers(self, k: int, tanks: Sequence[Tank]) -> int:
        """How many of ``tanks`` have a line of sight to spawn point ``k``."""
        x, z, _ = self.spawns[k]
        y = self._spawn_eye(k)
        return sum(1 for o in tanks if not self.line_blocked(o.x, o.z, x, z, self.eye(o), y))

    def _hidden_order(self, order: list[int], n: int) -> list[int]:
        """The first ``n`` spawn points for the tanks, taken from the shuffled ``order``
        so that each is seen by as few of the ones before it as possible (lines of
        sight between spawn points; the first of the fewest in ``order``)."""
        spawns = self.spawns

        def sees(a: int, b: int) -> bool:
            return not self.line_blocked(spawns[a][0], spawns[a][1], spawns[b][0], spawns[b][1],
                                         self._spawn_eye(a), self._spawn_eye(b))

        left, taken = list(order), []
        for _ in range(n):
            k = min(left, key=lambda c: sum(sees(c, p) for p in taken))
            left.remove(k)
            taken.append(k)
        return taken + left
