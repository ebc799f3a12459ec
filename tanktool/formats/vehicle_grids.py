"""arena.toml's ``[grids.<vehicle>]`` tables: one navigation grid per smaller vehicle.

``navgrid.npz`` is for the largest bundled vehicle that fits the arena; each smaller one
has ``navgrid.<vehicle>.npz`` (grid_files.py builds it) and a table with its
``clearance``, ``spawns`` (``[x, z, heading, y]``) and ``file``.  Read here, at the
bottom of the layers, because the simulation (the spawns a vehicle plays on), the
freshness check and ``check`` all need them.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

from ..errors import ArenaError

#: a vehicle name that may be part of a file name
_VEHICLE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]{0,63}")


def vehicle_file(name: str) -> str | None:
    """The grid file of a smaller vehicle, ``navgrid.<name>.npz`` (None: a name that
    cannot be part of a file name)."""
    return f"navgrid.{name}.npz" if isinstance(name, str) and _VEHICLE_NAME.fullmatch(name) else None


def is_grid_file(name: str) -> bool:
    """navgrid.npz, quadtree.npz or a vehicle's navgrid.<name>.npz: build-navgrid remakes them."""
    return name in ("navgrid.npz", "quadtree.npz") or (name.startswith("navgrid.") and name.endswith(".npz")
                                                       and vehicle_file(name[8:-4]) == name)


def vehicle_grids(doc: dict[str, Any], where: Any = "arena.toml") -> dict[str, tuple[float, Any]]:
    """{vehicle: (clearance, (k, 4) spawns [x, z, heading, y])} of the manifest's
    [grids.<vehicle>] tables (none in a bundle made before them); ArenaError naming
    ``where`` for a malformed one."""
    grids = doc.get("grids", {})
    if not isinstance(grids, dict):
        raise ArenaError(f"{where}: [grids] must be a table of vehicles")
    out: dict[str, tuple[float, Any]] = {}
    for name, t in grids.items():
        c = t.get("clearance") if isinstance(t, dict) else None
        if vehicle_file(name) is None or isinstance(c, bool) or not isinstance(c, (int, float)) \
                or not (math.isfinite(c) and c > 0):
            raise ArenaError(f"{where}: [grids.{name}] needs a vehicle name of letters, digits, - and _ and a "
                             f"clearance > 0")
        try:
            sp = np.asarray(t.get("spawns", []), dtype=np.float64).reshape(-1, 4)
        except (TypeError, ValueError):
            raise ArenaError(f"{where}: [grids.{name}] spawns must be a list of [x, z, heading, y]") from None
        if not np.isfinite(sp).all() or len(sp) == 0:
            raise ArenaError(f"{where}: [grids.{name}] spawns must be a list of finite [x, z, heading, y]")
        out[str(name)] = (float(c), sp)
    return out
