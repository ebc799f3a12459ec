"""The arena as a bot knows it: the static map, its navigation grid and path queries.

A ``Map`` is made once per tank from the arena's static parts (walls, the ground's
surface and solid, spawn points, bounds), never from anything that moves: it holds no
world and no tank.  Its queries are the ones the built-in agents use:

* ``grid`` / ``grid_for(cell, clearance)``: a navigation grid (``nav.navgrid.NavGrid``;
  on relief or levels a projection carrying the layered grid as ``.layers``) whose
  valid nodes keep the vehicle's footprint radius plus a margin off every wall;
* ``path(start, goal)``: A* waypoints [(x, z), ...] on that grid (a point may carry
  its height as a third number: which level it is on);
* ``line_blocked`` / ``blocked_from``: lines of sight (walls on a flat arena, the
  model's solid on a ground), as the game tests sight;
* ``walls_of(level)``: the walls a tank on that level can run into (for feelers);
* ``sight_table()``: which parts of the arena see which (``agents.sight.Views``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Iterable, Sequence

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from ...nav.navgrid import NavGrid
    from ..agents.sight import Views
    from ..collide import WallSet

#: eye height over the surface of a point of sight given without a height [m]
EYE = 1.2
#: the default grid: 1 m nodes, the footprint radius plus this margin off the walls [m]
CELL = 1.0
MARGIN = 0.5


class Map:
    """The static arena for a tank of footprint radius ``radius`` (see the module
    docstring).  ``ground`` is the arena's ``sim.ground.Ground`` (a ``FlatGround``, no model, on a flat
    arena), ``walls`` its ``WallSet`` and ``level_walls`` one per ground level;
    ``spawns`` are (x, z, heading) and ``spawn_y`` their heights (None: unknown)."""

    def __init__(self, walls: "WallSet", level_walls: Sequence["WallSet"], ground: Any, bounds: np.ndarray,
                 spawns: Sequence[tuple[float, float, float]], spawn_y: Sequence[float | None],
                 radius: float) -> None:
        self.walls = walls
        self.level_walls = tuple(level_walls)
        self.ground = ground
        self.bounds = np.array(bounds, dtype=np.float64).reshape(2, 2)
        self.bounds.flags.writeable = False
        self.spawns = tuple(tuple(float(v) for v in s) for s in spawns)
        self.spawn_y = tuple(spawn_y)
        self.radius = float(radius)
        self._grid: "NavGrid | None" = None

    @classmethod
    def of(cls, world: Any, radius: float) -> "Map":
        """The map of a world's arena (its static parts only)."""
        return cls(world.walls, world.level_walls, world.ground, world.bounds, world.spawns, world.spawn_y, radius)

    @property
    def relief(self) -> bool:
        """Whether the arena has a ground with a solid (heights, slopes, levels)."""
        return getattr(self.ground, "mesh", None) is not None

    # ------------------------------------------------------------------ navigation
    @property
    def grid(self) -> "NavGrid":
        """The default grid: ``CELL`` m nodes, ``radius + MARGIN`` off the walls."""
        if self._grid is None:
            self._grid = self.grid_for(CELL, self.radius + MARGIN)
        return self._grid

    def grid_for(self, cell: float, clearance: float) -> "NavGrid":
        """A grid of ``cell`` m nodes keeping ``clearance`` m off the walls (cached per
        arena: every map of it shares it)."""
        from ..agents.navigation import agent_grid

        return agent_grid(self, cell, clearance)

    def path(self, start: Sequence[float], goal: Sequence[float], grid: "NavGrid | None" = None
             ) -> list[tuple[float, float]]:
        """A* waypoints from ``start`` to ``goal`` ((x, z) or (x, z, height)) on
        ``grid`` (default: :attr:`grid`), the start left out; [] when there is no way."""
        from ..agents.navigation import plan_path

        return plan_path(self.grid if grid is None else grid, tuple(start), tuple(goal))

    def sight_table(self, grid: "NavGrid | None" = None) -> "Views":
        """Which blocks of the arena see which (``agents.sight.Views``; cached)."""
        from ..agents.sight import views_for

        return views_for(self, self.grid if grid is None else grid)

    # ------------------------------------------------------------------ sight
    def eye_at(self, x: float, z: float) -> float:
        """Eye height over the lowest surface at (x, z) (``EYE`` on a flat arena)."""
        g = self.ground
        if not self.relief:
            return EYE
        return g.height(x, z, max(g.locate(x, z), 0)) + EYE

    def line_blocked(self, ax: float, az: float, bx: float, bz: float,
                     ay: float | None = None, by: float | None = None) -> bool:
        """Whether the line of sight from (ax, ay, az) to (bx, by, bz) is blocked: by a
        wall on a flat arena (heights unused), by the model's solid on a ground (a
        height left out is eye height over the lowest surface there)."""
        if not self.relief:
            return self.walls.blocked(ax, az, bx, bz)
        a = (ax, self.eye_at(ax, az) if ay is None else ay, az)
        return bool(self.ground.solids.blocked(a, (bx, self.eye_at(bx, bz) if by is None else by, bz)))

    def blocked_from(self, ax: float, az: float, ay: float | None,
                     points: Sequence[tuple[float, float, float | None]]) -> Iterable[bool]:
        """``line_blocked`` from (ax, ay, az) to each (x, z, y) of ``points`` (on a ground
        in one go)."""
        if not self.relief:
            return (self.walls.blocked(ax, az, x, z) for x, z, _ in points)
        a = (ax, self.eye_at(ax, az) if ay is None else ay, az)
        pts = [(x, self.eye_at(x, z) if y is None else y, z) for x, z, y in points]
        return (~self.ground.solids.visible_from(a, pts)).tolist()

    def walls_of(self, level: int = 0) -> "WallSet":
        """The walls a tank standing on ``level`` can run into (all of them on a flat
        arena): ``near(x, z, r)``, ``first_hit(ax, az, bx, bz)``, ``walls[k]``."""
        if not self.level_walls:
            return self.walls
        return self.level_walls[min(max(level, 0), len(self.level_walls) - 1)]
