"""What an agent can know: sight, hearing and memory (the paper's "perceptores").

* **Sight**: a target is seen when it lies within the vision range, within the cone's
  half-angle of the heading (the hull carries the gun and the crew's view), and the
  segment between the two centres crosses no wall.  That last test is the paper's
  "línea imaginaria R" against every wall, asked of the world's wall quadtree (only
  the walls in the leaves the segment passes are intersected).  On an arena with
  relief or levels the segment runs between the two guns in 3D and the model's solid
  stops it (``World.sees``): a hill or a deck between two tanks hides them, a low
  wall does not hide a tank on a hill behind it.  Range and angle are checked first
  because they cost nothing.
* **Hearing**: a gunshot within the hearing radius reveals roughly where it came from:
  the shooter's position plus Gaussian noise growing with distance.  A shot is the
  shooter's shot counter going up (the same thing the world's ``shot`` event reports).
* **Engines**: tanks are loud.  A moving enemy within the engine-hearing radius
  (through walls) reveals roughly where it is, with the same noise.  The radius grows
  with its speed: ``engine_radius * min(1, speed / ENGINE_FULL)``; below
  ``ENGINE_QUIET`` m/s it is not heard at all (an idling engine is lost in the noise).
* What a seen enemy shows: its position, velocity and the way its hull (and so its
  gun) points, as a player sees an enemy tank's hull.
* **Memory**: where each enemy was last seen (and its velocity then) and where the
  latest shot or engine was heard, with times; nothing else about other tanks is kept.
* **Own state**: hit points (so the agent knows it was hit), speed, reload.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    from ..body import Tank
    from ..world import World


#: an engine is heard within the full engine radius from this speed up [m/s]
ENGINE_FULL = 6.0
#: and not at all below this speed [m/s]
ENGINE_QUIET = 0.5
#: the fraction of the radius an engine is heard over just above ENGINE_QUIET
ENGINE_FLOOR = 0.5


def wrap(a: float) -> float:
    """An angle in (-pi, pi]."""
    return math.remainder(a, 2.0 * math.pi)


@dataclass(frozen=True)
class Sighting:
    """One enemy seen at time ``t``: its index, centre and velocity then, distance,
    which way its hull (and gun) points, the height it stands at and the seconds of
    spawn protection it has left (a player sees its shield)."""

    index: int
    x: float
    z: float
    vx: float
    vz: float
    t: float
    distance: float
    heading: float = 0.0
    y: float = 0.0
    protected: float = 0.0


@dataclass(frozen=True)
class Heard:
    """A shot (or, ``engine`` True, a moving tank) heard at time ``t`` from around
    (x, z) (noisy), at about height ``y`` (which floor it came from)."""

    x: float
    z: float
    t: float
    engine: bool = False
    y: float | None = None


def in_cone(ox: float, oz: float, heading: float, tx: float, tz: float, half_angle: float, vision_range: float) -> bool:
    """Is (tx, tz) within range and within ``half_angle`` of ``heading`` seen from (ox, oz)?"""
    dx, dz = tx - ox, tz - oz
    d2 = dx * dx + dz * dz
    if d2 > vision_range * vision_range:
        return False
    if d2 == 0.0:
        return True
    return abs(wrap(math.atan2(dz, dx) - heading)) <= half_angle


def can_see(walls, ox: float, oz: float, heading: float, tx: float, tz: float,
            half_angle: float, vision_range: float) -> bool:
    """The sight test: in the cone, in range, and no wall crossing the line of sight.

    ``walls`` is the world's ``WallSet`` (or anything with ``blocked(ax, az, bx, bz)``).
    """
    return in_cone(ox, oz, heading, tx, tz, half_angle, vision_range) and not walls.blocked(ox, oz, tx, tz)


def _protection(world: "World", index: int) -> float:
    """Seconds of spawn protection tank ``index`` has left (0 in worlds without it)."""
    left = getattr(world, "protection_left", None)
    return left(index) if left is not None else 0.0


class Senses:
    """One agent's sensors and memory.

    Parameters
    ----------
    half_angle : vision cone half-angle [rad]
    vision_range : how far it sees [m]
    hearing_radius : how far a shot is heard [m]
    hearing_noise : standard deviation of the heard position, as a fraction of the distance
    rng : the agent's generator (noise)
    engine_radius : how far a tank moving at ``ENGINE_FULL`` m/s or faster is heard [m]
        (0: engines are not heard)
    """

    def __init__(self, half_angle: float, vision_range: float, hearing_radius: float,
                 hearing_noise: float, rng: random.Random, engine_radius: float = 0.0) -> None:
        self.engine_radius = engine_radius
        self.half_angle = half_angle
        self.vision_range = vision_range
        self.hearing_radius = hearing_radius
        self.hearing_noise = hearing_noise
        self.rng = rng
        self.last_seen: dict[int, Sighting] = {}
        self.heard: Heard | None = None
        self._shots: dict[int, int] = {}
        self.hp = math.inf

    def look(self, world: "World", me: "Tank") -> list[Sighting]:
        """The live enemies in sight now, nearest first; remembered as last seen."""
        out = []
        cand = [o for o in world.tanks if o is not me and o.alive
                and in_cone(me.x, me.z, me.heading, o.x, o.z, self.half_angle, self.vision_range)]
        for o, seen in zip(cand, world.sees_all(me, cand)):
            if seen:
                s = Sighting(o.index, o.x, o.z, o.vx, o.vz, world.t, math.hypot(o.x - me.x, o.z - me.z), o.heading,
                             o.y, _protection(world, o.index))
                self.last_seen[o.index] = s
                out.append(s)
        out.sort(key=lambda s: (s.distance, s.index))
        return out

    def listen(self, world: "World", me: "Tank") -> Heard | None:
        """Shots fired since the last call within the hearing radius: the nearest one."""
        best, best_d = None, math.inf
        for o in world.tanks:
            if o is me:
                continue
            before = self._shots.get(o.index, o.shots)
            self._shots[o.index] = o.shots
            if o.shots <= before:
                continue
            d = math.hypot(o.x - me.x, o.z - me.z)
            if d <= self.hearing_radius and d < best_d:
                best_d = d
                sd = self.hearing_noise * d
                best = Heard(o.x + self.rng.gauss(0.0, sd), o.z + self.rng.gauss(0.0, sd), world.t, y=o.y)
        if best is not None:
            self.heard = best
        return best

    def listen_engines(self, world: "World", me: "Tank") -> Heard | None:
        """The nearest live enemy heard moving now (through walls): within
        ``engine_radius * min(1, speed / ENGINE_FULL)``, not below ``ENGINE_QUIET`` m/s;
        its position with Gaussian noise of ``hearing_noise`` x the distance."""
        if self.engine_radius <= 0.0:
            return None
        best, best_d = None, math.inf
        for o in world.tanks:
            if o is me or not o.alive:
                continue
            speed = math.hypot(o.vx, o.vz)
            if speed < ENGINE_QUIET:
                continue
            d = math.hypot(o.x - me.x, o.z - me.z)
            loud = min(1.0, ENGINE_FLOOR + (1.0 - ENGINE_FLOOR) * speed / ENGINE_FULL)
            if d <= self.engine_radius * loud and d < best_d:
                best, best_d = o, d
        if best is None:
            return None
        sd = self.hearing_noise * best_d
        heard = Heard(best.x + self.rng.gauss(0.0, sd), best.z + self.rng.gauss(0.0, sd), world.t, True, best.y)
        self.heard = heard
        return heard

    def hit_taken(self, me: "Tank") -> float:
        """Damage taken since the last call (0 on the first call and after a respawn's refill)."""
        lost = self.hp - me.hp if (me.hp < self.hp and math.isfinite(self.hp)) else 0.0
        self.hp = me.hp
        return lost

    def forget(self, index: int) -> None:
        self.last_seen.pop(index, None)
