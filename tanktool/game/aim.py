"""Where the player's gun points and where its shell would land, for the crosshair.

The shell is made by the simulation's own ``sim.weapons.fire`` (the same speed, start
point, pitch, drift with the tank's velocity, and first wall on its line or, on an arena
with relief, the time its flight first meets the model, as a real shot), then followed
as the rules fly it (straight by default, spent at their range) until it meets that
wall, the model or the ground, or leaves the arena's bounds; tanks on the way are
tested against their footprint circle and height.  Nothing here changes the world.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

#: how far the crosshair looks along the barrel when no wall is in the way [m]
SIGHT = 150.0
#: samples along the flight when looking for tanks on the way
SAMPLES = 48


@dataclass
class Aim:
    """``aim``: the point the barrel points at (the first wall on its line, or SIGHT
    metres ahead); ``impact``: where the shell stops (a wall, the ground or a tank);
    ``target``: the index of the tank it would hit, or None; ``time``: its flight [s]."""

    muzzle: tuple[float, float, float]
    aim: tuple[float, float, float]
    impact: tuple[float, float, float]
    target: int | None
    time: float


def _shell(world: Any, tank: Any) -> Any:
    """The shell ``tank`` would fire now, under the world's rules, without their random
    spread (the crosshair shows the gun's line)."""
    from ..sim import weapons

    return weapons.fire(tank, world.walls, getattr(world, "rules", None), None, getattr(world, "ground", None))


def predict(world: Any, tank: Any, floor_y: float = 0.0) -> Aim:
    """The crosshair's two points for ``tank`` firing now."""
    s = _shell(world, tank)
    g = s.g
    x0, y0, z0 = s.x, s.y, s.z
    base = float(getattr(tank, "y", floor_y))
    # the barrel's line (at the hull's pitch): to the first wall on it, else SIGHT ahead
    pitch = float(getattr(tank, "pitch", 0.0))
    hit = world.walls.first_hit(x0, z0, x0 + tank.c * SIGHT, z0 + tank.s * SIGHT)
    d = hit[0] * SIGHT if hit is not None else SIGHT
    aim = (x0 + tank.c * d, y0 + math.tan(pitch) * d, z0 + tank.s * d)
    vh = math.hypot(s.vx, s.vz)
    t_spent = min(s.reach, SIGHT) / vh if vh > 0 else 0.0      # its range flown (or as far as we look)
    stop_at = float(getattr(s, "stop_at", math.nan))
    if not math.isnan(stop_at):               # on a ground: where the flight meets the model
        t_end = min(stop_at, t_spent)
    else:
        # the ground is the tank's own floor
        drop = max(y0 - base, 0.0)
        if g > 0.0:
            t_ground = (s.vy + math.sqrt(s.vy * s.vy + 2.0 * g * drop)) / g
        else:
            t_ground = drop / -s.vy if s.vy < 0.0 else math.inf
        t_wall = s.wall_dist / vh if vh > 0 and math.isfinite(s.wall_dist) else math.inf
        t_end = min(t_ground, t_wall, t_spent)

    t_end = min(t_end, _leaves(world, x0, z0, s.vx, s.vz))     # the world drops shells that leave it

    def at(t: float) -> tuple[float, float, float]:
        return x0 + s.vx * t, y0 + s.vy * t - 0.5 * g * t * t, z0 + s.vz * t

    # the flight at SAMPLES times against every other live tank's cylinder, all at once
    others = [o for o in world.tanks if o.index != tank.index and o.alive]
    target = None
    if others:
        ts = t_end * np.arange(1, max(int(SAMPLES), 2) + 1) / max(int(SAMPLES), 2)
        px, py, pz = x0 + s.vx * ts, y0 + s.vy * ts - 0.5 * g * ts * ts, z0 + s.vz * ts
        ox = np.array([o.x for o in others])
        oz = np.array([o.z for o in others])
        oy = np.array([float(getattr(o, "y", floor_y)) for o in others])
        r2 = np.array([o.spec.radius ** 2 for o in others])
        top = oy + np.array([o.spec.height for o in others])
        inside = (((px[:, None] - ox) ** 2 + (pz[:, None] - oz) ** 2 < r2)
                  & (oy <= py[:, None]) & (py[:, None] <= top))                  # (samples, tanks)
        hit = np.flatnonzero(inside.any(axis=1))
        if len(hit):
            k = int(hit[0])
            target = others[int(np.flatnonzero(inside[k])[0])].index
            t_end = float(ts[k])
    return Aim((x0, y0, z0), aim, at(t_end), target, t_end)


def _leaves(world: Any, x: float, z: float, vx: float, vz: float) -> float:
    """Seconds until a shell at (x, z) flying (vx, vz) leaves the world's bounds (with
    the 1 m the world allows before it drops a shell); inf if it never does."""
    (x0, z0), (x1, z1) = (tuple(map(float, row)) for row in world.bounds)
    t = math.inf
    for p, v, lo, hi in ((x, vx, x0 - 1.0, x1 + 1.0), (z, vz, z0 - 1.0, z1 + 1.0)):
        if v > 1e-12:
            t = min(t, (hi - p) / v)
        elif v < -1e-12:
            t = min(t, (lo - p) / v)
    return max(t, 0.0)
