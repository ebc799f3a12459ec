"""A scripted bot: the stand-in opponent until the agent issue lands.

It produces :class:`Command` values like any other driver: roam towards a random
waypoint, steer away from walls ahead, back off when stuck, and turn on and fire at
any tank it can see roughly ahead.  It thinks at ``think_hz`` (10 Hz by default) and
holds its command in between, as a person or an agent would; all its randomness
comes from a ``random.Random`` the world seeds, so matches replay exactly.
"""

from __future__ import annotations

import math
import random
from typing import TYPE_CHECKING

import numpy as np

from .commands import IDLE, Command

if TYPE_CHECKING:  # pragma: no cover
    from .body import Tank
    from .world import World


def _wrap(a: float) -> float:
    return math.remainder(a, 2.0 * math.pi)


class Roam:
    """The scripted bot's roaming, shared with the yardstick novice
    (``sim.agents.robots.Novice``): towards a random waypoint (a spawn point or a point
    in the bounds, a new one every 20 s or when within 6 m), turning towards the open
    side of a wall ahead, backing off for 1 s, turning the other way, after 1.5 s of
    pushing without moving.  ``bias`` is the side it turns to when both are open."""

    def __init__(self, bias: float) -> None:
        self.bias = bias
        self.waypoint: tuple[float, float] | None = None
        self.deadline = 0.0
        self.stuck_since: float | None = None
        self.reverse_until = -math.inf

    def command(self, t: float, me, radius: float, walls, spawns, bounds, rng: random.Random) -> Command:
        """The command for tank ``me`` (x, z, heading, c, s, speed()) of footprint
        ``radius`` among ``walls`` (``blocked(ax, az, bx, bz)``) at time ``t``."""
        if t < self.reverse_until:
            return Command(advance=-1.0, rotate=self.bias)
        if self.waypoint is None or t > self.deadline or \
                math.hypot(self.waypoint[0] - me.x, self.waypoint[1] - me.z) < 6.0:
            self._new_waypoint(t, spawns, bounds, rng)
        wx, wz = self.waypoint  # type: ignore[misc]
        err = _wrap(math.atan2(wz - me.z, wx - me.x) - me.heading)
        rotate = max(-1.0, min(1.0, 2.5 * err))
        advance = 1.0 if abs(err) < 0.6 else 0.25
        # a feeler ahead: a wall there means turn towards the side that is open
        look = radius + 3.0 + 0.6 * me.speed()
        if walls.blocked(me.x, me.z, me.x + me.c * look, me.z + me.s * look):
            rotate = self._open_side(me, walls, look)
            advance = 0.2
        # stuck: pushing but not moving
        if advance > 0.5 and me.speed() < 0.5:
            if self.stuck_since is None:
                self.stuck_since = t
            elif t - self.stuck_since > 1.5:
                self.stuck_since = None
                self.reverse_until = t + 1.0
                self.bias = -self.bias
                self.waypoint = None
        else:
            self.stuck_since = None
        return Command(advance=advance, rotate=rotate)

    def _open_side(self, me, walls, look: float) -> float:
        """+1 to turn right (increasing heading), -1 left, whichever 45° feeler is clear."""
        clear = []
        for side in (1.0, -1.0):
            a = me.heading + side * math.pi / 4
            clear.append(not walls.blocked(me.x, me.z, me.x + math.cos(a) * look, me.z + math.sin(a) * look))
        if clear[0] and not clear[1]:
            return 1.0
        if clear[1] and not clear[0]:
            return -1.0
        return self.bias

    def _new_waypoint(self, t: float, spawns, bounds, rng: random.Random) -> None:
        """A spawn point (known to be open floor) or a random point inside the bounds."""
        if rng.random() < 0.5:
            x, z = spawns[rng.randrange(len(spawns))][:2]
        else:
            (x0, z0), (x1, z1) = np.asarray(bounds).tolist()
            m = 5.0
            x = rng.uniform(x0 + m, max(x0 + m, x1 - m))
            z = rng.uniform(z0 + m, max(z0 + m, z1 - m))
        self.waypoint = (x, z)
        self.deadline = t + 20.0


class ScriptedDriver:
    """Roam (:class:`Roam`), avoid walls, shoot what is in front.

    Parameters
    ----------
    rng : the driver's own generator (``World.rng`` derived, for replays)
    think_hz : decisions per simulated second
    sight : how far it looks for targets [m]
    aim_tolerance : fire when the target is within this angle of the gun [rad]
    aim_spread : standard deviation of the aiming error, drawn anew after each shot [rad]
    """

    def __init__(self, rng: random.Random, think_hz: float = 10.0, sight: float = 120.0,
                 aim_tolerance: float = math.radians(4.0), aim_spread: float = math.radians(3.0)) -> None:
        self.rng = rng
        self.period = 1.0 / think_hz
        self.sight = sight
        self.aim_tolerance = aim_tolerance
        self.next_think = -math.inf
        self.command: Command = IDLE
        self.roam = Roam(1.0 if rng.random() < 0.5 else -1.0)
        # aim error: a person (or bot) does not lay the gun perfectly; redrawn per shot
        self.aim_error = rng.gauss(0.0, aim_spread)
        self.aim_spread = aim_spread

    @property
    def waypoint(self) -> tuple[float, float] | None:
        return self.roam.waypoint

    @property
    def reverse_until(self) -> float:
        return self.roam.reverse_until

    def __call__(self, world: "World", tank: "Tank") -> Command:
        if not tank.alive:
            self.roam.waypoint = None
            return IDLE
        if world.t + 1e-12 < self.next_think:
            return self.command
        self.next_think = world.t + self.period
        self.command = self._think(world, tank)
        return self.command

    # ------------------------------------------------------------------
    def _think(self, world: "World", tank: "Tank") -> Command:
        t = world.t
        # backing off after getting stuck
        if t < self.roam.reverse_until:
            return Command(advance=-1.0, rotate=self.roam.bias)
        target = self._target(world, tank)
        if target is not None:
            dx, dz = target.x - tank.x, target.z - tank.z
            err = _wrap(math.atan2(dz, dx) + self.aim_error - tank.heading)
            dist = math.hypot(dx, dz)
            advance = 0.6 if dist > 30.0 else -0.3 if dist < 12.0 else 0.0
            strafe = self.roam.bias * 0.5 if abs(err) < 0.3 else 0.0
            fire = abs(err) < self.aim_tolerance and tank.reload <= 0.0
            if fire:
                self.aim_error = self.rng.gauss(0.0, self.aim_spread)
            return Command(advance=advance, rotate=max(-1.0, min(1.0, 3.0 * err)), strafe=strafe, fire=fire)
        return self.roam.command(t, tank, tank.spec.radius, world.walls, world.spawns, world.bounds, self.rng)

    def _target(self, world: "World", tank: "Tank") -> "Tank | None":
        """The nearest live tank within sight, within 60° of the gun, not behind a wall."""
        best, best_d = None, self.sight
        for o in world.tanks:
            if o is tank or not o.alive:
                continue
            dx, dz = o.x - tank.x, o.z - tank.z
            d = math.hypot(dx, dz)
            if d >= best_d:
                continue
            if abs(_wrap(math.atan2(dz, dx) - tank.heading)) > math.radians(60):
                continue
            if world.walls.blocked(tank.x, tank.z, o.x, o.z):
                continue
            best, best_d = o, d
        return best


def make_drivers(world: "World") -> list[ScriptedDriver]:
    """One scripted driver per tank, each seeded from the world's generator."""
    return [ScriptedDriver(random.Random(world.rng.getrandbits(64))) for _ in world.tanks]
