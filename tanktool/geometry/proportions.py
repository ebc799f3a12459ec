"""Is this a plausible tank, standing the right way up and facing +x?

``import-vehicle`` warns about what these functions find and ``tanktool check``
reports it (V105 on its side, V106 facing sideways, V107 an absurd size, V303 an
absurd mass), so the two always agree.  The figures come from real tanks: from
tankettes (about 2.5 m long, 2 t) to the Maus (10.1 m, 188 t); every tank is wider
than it is tall and longer than it is wide.

Everything is in the vehicle frame (+x forward, +y up, +z right) and read from
points that enclose the vehicle (its vertices, or its hull points).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .hull import convex_hull_2d, min_width

#: m, the longest extent of a plausible vehicle (a toy is smaller, a ship larger)
SIZE_RANGE = (1.0, 15.0)
#: kg, the mass of a plausible vehicle (100 kg: a go-kart; 200 t: more than the Maus)
MASS_RANGE = (100.0, 200_000.0)
#: taller than this times its narrowest width: lying on its side or standing on end
ON_SIDE_RATIO = 1.2
#: wider across (z) than this times its length along +x: facing sideways
SIDEWAYS_RATIO = 1.1


@dataclass(frozen=True)
class Proportions:
    """Extents of a vehicle, m: ``length`` along +x, ``breadth`` along z, ``height``
    along y, and ``width`` the narrowest extent of its footprint in any direction."""

    length: float
    breadth: float
    height: float
    width: float

    @property
    def size(self) -> float:
        return max(self.length, self.breadth, self.height)


def proportions(points: np.ndarray) -> Proportions:
    """The extents of (n, 3) vehicle-frame points."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    ext = np.ptp(p, axis=0) if len(p) else np.zeros(3)
    foot = convex_hull_2d(p[:, [0, 2]]) if len(p) else np.zeros((0, 2))
    width = min_width(foot) if len(foot) >= 3 else float(min(ext[0], ext[2]))
    return Proportions(float(ext[0]), float(ext[2]), float(ext[1]), float(width))


def on_its_side(p: Proportions, subject: str = "it") -> str | None:
    """Why the vehicle seems to lie on its side or stand on end, or None."""
    if p.width > 0 and p.height > ON_SIDE_RATIO * p.width:
        return (f"{subject} is {p.height:.3g} m tall but only {p.width:.3g} m wide: it lies on its side "
                f"or stands on end (a tank is wider than it is tall)")
    return None


def sideways(p: Proportions, subject: str = "it") -> str | None:
    """Why the vehicle seems to face sideways (its front not along +x), or None."""
    if p.length > 0 and p.breadth > SIDEWAYS_RATIO * p.length:
        return (f"{subject} is {p.breadth:.3g} m across but {p.length:.3g} m along its forward axis: "
                f"its longest side is not along its front")
    return None


def size_problem(p: Proportions, subject: str = "it") -> str | None:
    """Why the vehicle's size is implausible (a wrong scale), or None."""
    lo, hi = SIZE_RANGE
    if not lo <= p.size <= hi:
        return (f"{subject} is {p.size:.3g} m long at its longest, outside the {lo:g} .. {hi:g} m of real "
                f"vehicles")
    return None


def mass_problem(mass: float) -> str | None:
    """Why a vehicle's mass is implausible, or None."""
    lo, hi = MASS_RANGE
    if not lo <= mass <= hi:
        said = f"{mass / 1000:,.4g} t" if mass >= 1000 else f"{mass:.4g} kg"
        return f"a mass of {said} is outside the {lo:g} kg .. {hi / 1000:g} t of real vehicles"
    return None
