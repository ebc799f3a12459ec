"""The flat ground, and which ground an arena bundle gets.

Every arena has a ground (issue 25): one model of the world, and no branch in its
callers on a ground that is missing.  A flat one-floor arena (the 2002 kind: box, maze,
paper2002) gets a :class:`FlatGround`: one level at the floor's real height (an
imported floor at y = -2.37 stands at -2.37, not at 0), no tilt, no model to hit,
and no links to follow -- the walls alone keep tanks in, as in 2002.  Its methods
are the fast paths of :class:`sim.ground.Ground`'s: a move is never refused, the
height is a constant, so a match on it plays exactly as before the two models met.
"""

from __future__ import annotations

import gc
import math
from typing import Any

import numpy as np

#: an arena whose surface heights differ by less than this is flat: a FlatGround
FLAT_RANGE = 0.2
#: a flat ground's cell for its picture and its cell lookups [m]
FLAT_CELL = 0.5


class FlatGround:
    """A plane floor at height ``y`` over ``bounds`` ([[xmin, zmin], [xmax, zmax]])."""

    relief = False
    levels = 1
    mesh = None
    solids = None

    def __init__(self, bounds: Any, y: float = 0.0, climb: float = 0.9, cell: float = FLAT_CELL) -> None:
        b = np.asarray(bounds, dtype=np.float64).reshape(2, 2)
        self.y = float(y)
        self.climb = float(climb)
        self.cell = float(cell)
        self.ox, self.oz = float(b[0, 0]), float(b[0, 1])
        self.nx = max(int(math.ceil((b[1, 0] - b[0, 0]) / cell)), 1)
        self.nz = max(int(math.ceil((b[1, 1] - b[0, 1]) / cell)), 1)

    @property
    def h(self) -> np.ndarray:
        """(1, nz, nx) node heights, all the floor's (as Ground.h)."""
        return np.full((1, self.nz, self.nx), self.y)

    def sight_blocked(self, a: tuple[float, float, float], b: tuple[float, float, float]) -> bool:
        return False      # no model: the walls block sight (World.line_blocked)

    def cell_of(self, x: float, z: float) -> tuple[int, int]:
        j = min(max(int((x - self.ox) // self.cell), 0), self.nx - 1)
        i = min(max(int((z - self.oz) // self.cell), 0), self.nz - 1)
        return i, j

    def node_height(self, level: int, i: int, j: int) -> float | None:
        return self.y if level == 0 and 0 <= i < self.nz and 0 <= j < self.nx else None

    def locate(self, x: float, z: float, y: float | None = None) -> int:
        return 0

    def near_level(self, x: float, z: float, y: float) -> int:
        return 0

    def follow(self, level: int, i0: int, j0: int, i1: int, j1: int) -> int:
        return 0

    def height(self, x: float, z: float, level: int) -> float:
        return self.y

    def tilt(self, x: float, z: float, level: int, c: float, s: float, half_length: float,
             half_width: float) -> tuple[float, float, float]:
        return self.y, 0.0, 0.0

    def keep_move(self, t: Any, dx: float, dz: float) -> tuple[float, float]:
        """Every move stays on a plane floor (walls stop tanks, not the ground)."""
        return dx, dz

    def contain(self, tanks: Any, before: Any, tilt: Any) -> None:
        """Nothing to undo after the collision pushes on a plane floor."""


def load_ground(bundle: Any) -> "Any":
    """The ground of an arena bundle (``arena.ArenaBundle``): a ``sim.ground.Ground``
    from its navgrid.npz and model when the surface has relief or several levels, else
    a :class:`FlatGround` at the floor's height (the grid's, else the manifest's
    ``floor_y``)."""
    from ..formats.models import load_model
    from ..nav.navgrid import NavGrid
    from ..nav.walkable import CLIMB
    from .ground import Ground, MeshIndex

    wk = bundle.toml.get("walkable", {})
    climb = wk.get("climb", CLIMB) if isinstance(wk, dict) else CLIMB
    climb = float(climb) if isinstance(climb, (int, float)) and not isinstance(climb, bool) and math.isfinite(climb) \
        else CLIMB
    path = bundle.path / "navgrid.npz"
    if not path.is_file():
        return FlatGround(bundle.bounds, bundle.floor_y, climb)
    grid = NavGrid.load(path, runs=False)   # the ground reads heights and links: no run arrays
    h = grid.heights()
    hv = h[np.isfinite(h)]
    if grid.height is None or len(hv) == 0 or (grid.levels == 1 and float(hv.max() - hv.min()) < FLAT_RANGE):
        # the manifest's floor, unless the grid's surface lies elsewhere (a hand-edited toml)
        y = float(bundle.floor_y)
        if len(hv) and not float(hv.min()) - FLAT_RANGE <= y <= float(hv.max()) + FLAT_RANGE:
            y = float(np.median(hv))
        return FlatGround(bundle.bounds, y, climb)
    # the ground first and the grid let go before the model loads: the grid's other
    # arrays (runs, validity) and the model's at once set a 2 km terrain's peak
    ground = Ground(grid, None, climb)
    del grid, h, hv
    model = bundle.file("model")
    if model.is_file():
        m = load_model(model, up="y")
        # the model's arrays taken and the model let go before the index's temporaries
        # (a 2 km load's peak 751 -> 644 MB); a trimesh mesh and its caches refer to
        # each other, so only the collector frees them (128 MB of a 2 km terrain's
        # model stayed for the whole match)
        v, f = np.asarray(m.vertices), np.asarray(m.faces)
        del m
        gc.collect()
        ground.mesh = MeshIndex(v, f)
        del v, f
    return ground
