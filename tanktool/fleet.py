"""The bundled vehicles' sizes: the defaults the arena tools take from them.

An arena is built for the tanks that will play on it: the headroom a walkable
surface needs is the tallest bundled vehicle's height, the clearance of the
navigation grid and of spawn points the largest footprint radius, and spawns keep a
tank's length apart.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np



@dataclass
class Fleet:
    """Extremes over the bundled vehicles (each with the vehicle that sets it)."""

    radius: float = 2.0
    length: float = 4.0
    height: float = 2.0
    radius_of: str = "built-in default"
    length_of: str = "built-in default"
    height_of: str = "built-in default"
    names: list[str] = field(default_factory=list)
    #: (name, footprint radius, length) of every vehicle, the largest radius first
    sizes: list[tuple[str, float, float]] = field(default_factory=list)

    def down_to(self, name: str, radius: float, length: float) -> "Fleet":
        """The fleet an arena too small for its larger vehicles keeps: the same
        headroom, the radius and length of vehicle ``name`` and those smaller."""
        rest = [s for s in self.sizes if s[1] <= radius]
        longest = max(rest, key=lambda s: s[2]) if rest else (name, radius, length)
        return Fleet(radius, longest[2], self.height, name, longest[0], self.height_of,
                     [s[0] for s in rest], rest)


def bundled_fleet(folder: Path | None = None, warn: Callable[[str], None] | None = None) -> Fleet:
    """The largest footprint radius, length and height over the vehicle bundles in
    ``folder`` (default the bundled ones); a broken bundle is skipped with a warning."""
    from .content import bundled_dir
    from .formats.vehicle_bundle import load_vehicle

    fleet = Fleet()
    found = False
    folder = folder if folder is not None else bundled_dir("vehicles")
    for vt in sorted(folder.glob("*/vehicle.toml")) if folder is not None else []:
        try:
            v = load_vehicle(vt.parent)
        except Exception as e:  # a broken vehicle must not stop the arena tools
            if warn is not None:
                warn(f"{vt}: skipped for the arena defaults ({e})")
            continue
        hull = np.asarray(v.hull, dtype=np.float64)
        r = float(v.footprint_radius)
        length = float(hull[:, 0].max() - hull[:, 0].min())
        height = float(hull[:, 1].max() - hull[:, 1].min())
        if not all(math.isfinite(a) and a > 0 for a in (r, length, height)):
            continue
        if not found:
            fleet = Fleet(r, length, height, v.name, v.name, v.name)
            found = True
        else:
            if r > fleet.radius:
                fleet.radius, fleet.radius_of = r, v.name
            if length > fleet.length:
                fleet.length, fleet.length_of = length, v.name
            if height > fleet.height:
                fleet.height, fleet.height_of = height, v.name
        fleet.names.append(v.name)
        fleet.sizes.append((v.name, r, length))
    fleet.sizes.sort(key=lambda s: (-s[1], s[0]))
    return fleet
