"""Yardstick opponents: drivers written from issue 19's descriptions, to measure the
computer agents against (``bench/ladder.py``), not to play the game with.

* :class:`Robot` -- BZFlag-style.  Knows where every tank is (as BZFlag's robots
  do); drives an A* path to the nearest enemy; with a line of sight it turns onto
  the lead point, the enemy moved on at the relative velocity for distance / shell
  speed, and fires only when the shot's predicted miss there is under half a tank
  length; it strafes away from shells coming at it.
* :class:`Camper` -- holds the spot near its spawn point that sees most of the arena,
  turns to what it sees or hears, and shoots on the exact intercept.
* :class:`Novice` -- a stand-in for a first-time player: reaction 0.4 s, a 5 degree
  aim error, no lead, drives straight at what it sees (and roams like the scripted
  baseline when it sees nothing).

They see the world through the same sensors as the agents where the description
says "sees" or "hears" (``perception.Senses``), drive with the same pilot
(``driving.Pilot``: speed control and wall feelers, so a yardstick does not lose by
bumping into walls) and act only through ``Command`` values.  Each has its own
seeded generator, so duels replay exactly.
"""

from __future__ import annotations

import math
import random
from typing import TYPE_CHECKING, Callable

import numpy as np

from ..commands import IDLE, Command
from ..driver import ScriptedDriver
from . import aim, dodge
from .driving import Pilot, trim
from .navigation import agent_grid, plan_path, vantages_for, views_for
from .perception import Senses, Sighting, wrap

if TYPE_CHECKING:  # pragma: no cover
    from ..body import Tank
    from ..world import World


class _Held(Pilot):
    """Think ``think_hz`` times a second and hold the command in between."""

    def __init__(self, rng: random.Random, think_hz: float) -> None:
        super().__init__()
        self.rng = rng
        self.period = 1.0 / think_hz
        self.next_think = -math.inf
        self.command: Command = IDLE
        self.path: list[tuple[float, float]] = []

    def __call__(self, world: "World", tank: "Tank") -> Command:
        if not tank.alive:
            self.reset()
            return IDLE
        if world.t + 1e-12 < self.next_think:
            return self.command
        self.next_think = world.t + self.period
        self.command = self.think(world, tank)
        return self.command

    def reset(self) -> None:
        self.path = []
        self.next_think = -math.inf

    def think(self, world: "World", tank: "Tank") -> Command:  # pragma: no cover - abstract
        raise NotImplementedError

    def _on_path(self) -> bool:
        return bool(self.path)

    def _replan(self) -> None:
        self.path = []


class Robot(_Held):
    """The BZFlag-style robot (see the module docstring).

    Parameters
    ----------
    rng : its generator
    think_hz : decisions per second
    cell, margin : its navigation grid (as the agents': node spacing, clearance
        beyond the footprint radius) [m]
    replan : seconds between A* plans to the enemy
    """

    def __init__(self, rng: random.Random, think_hz: float = 20.0, cell: float = 1.0, margin: float = 0.5,
                 replan: float = 1.0) -> None:
        super().__init__(rng, think_hz)
        self.cell, self.margin, self.replan_every = cell, margin, replan
        self.planned_at = -math.inf
        self.target: int | None = None

    def think(self, world: "World", tank: "Tank") -> Command:
        enemies = [o for o in world.tanks if o is not tank and o.alive]
        if not enemies:
            return self._drive(world, tank, 0.0, 0.0, 0.0)
        e = min(enemies, key=lambda o: (math.hypot(o.x - tank.x, o.z - tank.z), o.index))
        if e.index != self.target:
            self.target, self.planned_at = e.index, -math.inf
        lateral = self._strafe_away(world, tank)
        if world.sees(tank, e):
            return self._shoot(world, tank, e, lateral)
        t = world.t
        if t >= self.planned_at + self.replan_every or not self.path:
            grid = agent_grid(world, self.cell, tank.spec.radius + self.margin)
            self.path = plan_path(grid, (tank.x, tank.z, tank.y), (e.x, e.z, e.y))
            self.planned_at = t
        trim(self.path, tank.x, tank.z)
        cmd = self._follow(world, tank, self.path, speed=1.0, lookahead=4.0, corner=self.path[0] if self.path else None)
        if lateral:         # dodging on the way: hold the speed it has, strafe, keep steering
            return self._drive(world, tank, tank.vx * tank.c + tank.vz * tank.s, lateral, cmd.rotate)
        return self._unstick(world, tank, cmd)

    def _shoot(self, world: "World", tank: "Tank", e: "Tank", lateral: float) -> Command:
        v = tank.spec.shell_speed
        sol = aim.lead_by_distance(tank.x, tank.z, tank.vx, tank.vz, e.x, e.z, e.vx, e.vz, v)
        err = wrap(sol.heading - tank.heading)
        # where a shell fired now is when the lead point is reached
        sx = tank.x + (v * tank.c + tank.vx) * sol.time
        sz = tank.z + (v * tank.s + tank.vz) * sol.time
        miss = math.hypot(sx - sol.x, sz - sol.z)
        bx0, _, bx1, _ = e.spec.box
        fire = miss < 0.25 * (bx1 - bx0) and tank.reload <= 0.0
        d = math.hypot(e.x - tank.x, e.z - tank.z)
        forward = 0.0
        if abs(err) < 0.5:
            forward = 0.4 * tank.spec.top_speed if d > 30.0 else -3.0 if d < 12.0 else 0.0
        return self._drive(world, tank, forward, lateral, self._turn(tank, err), fire)

    def _strafe_away(self, world: "World", tank: "Tank") -> float:
        """Wanted sideways speed [m/s]: full strafe away from the line of the soonest
        shell coming at it (it knows every shell), else 0."""
        th = dodge.threats(world, tank)
        if not th:
            return 0.0
        s = th[0].shell
        # which side of the shell's line the tank is on, as seen along its right
        ux, uz = s.vx, s.vz
        n = math.hypot(ux, uz) or 1.0
        off_x, off_z = tank.x - s.x, tank.z - s.z
        cross = (ux * off_z - uz * off_x) / n          # > 0: the tank is left of the line
        px, pz = -uz / n, ux / n                          # that left, as a vector
        if cross < 0.0:
            px, pz = -px, -pz
        right = px * -tank.s + pz * tank.c
        return math.copysign(0.5 * tank.spec.top_speed, right if right != 0.0 else 1.0)


class Camper(_Held):
    """Holds the spot near its spawn point that sees most of the arena (see the module
    docstring).

    Parameters
    ----------
    rng : its generator
    reaction : seconds from first seeing an enemy to shooting at it
    near : the spot is the block seeing most of the arena within this many metres of
        path from where it (re)spawned
    vision_range, half_angle, hearing_radius, engine_radius : its senses (the hard
        agent's)
    """

    def __init__(self, rng: random.Random, reaction: float = 0.25, near: float = 30.0,
                 vision_range: float = 130.0, half_angle: float = math.radians(60.0), hearing_radius: float = 120.0,
                 engine_radius: float = 40.0, think_hz: float = 20.0) -> None:
        super().__init__(rng, think_hz)
        self.reaction, self.near = reaction, near
        self.senses = Senses(half_angle, vision_range, hearing_radius, 0.15, rng, engine_radius=engine_radius)
        self.spot: tuple[float, float] | None = None
        self.face = 0.0
        self.turn_to: tuple[float, float] | None = None     # (heading, until)
        self.target: int | None = None
        self.acquired = math.inf

    def reset(self) -> None:
        super().reset()
        self.spot, self.turn_to, self.target, self.acquired = None, None, None, math.inf
        self.senses.hp = math.inf

    def _choose_spot(self, world: "World", tank: "Tank") -> None:
        grid = agent_grid(world, 1.0, tank.spec.radius + 0.5)
        views = views_for(world, grid)
        here = views.cell_at(tank.x, tank.z, tank.y)
        if here < 0:
            self.spot, self.face = (tank.x, tank.z), tank.heading
            return
        sees = (views.visible & (views.distance <= self.senses.vision_range)).sum(axis=1)
        reach = views.path_distances(here)
        score = np.where(reach <= self.near, sees, -1)
        b = int(np.argmax(score))
        self.spot = (float(views.points[b][0]), float(views.points[b][1]))
        v = vantages_for(views, self.senses.half_angle, self.senses.vision_range)
        self.face = float(v.block_face[b])
        self.path = plan_path(grid, (tank.x, tank.z, tank.y), (*self.spot, float(views.heights[b])))

    def think(self, world: "World", tank: "Tank") -> Command:
        t = world.t
        if self.spot is None:
            self._choose_spot(world, tank)
        seen = self.senses.look(world, tank)
        heard = self.senses.listen(world, tank) or self.senses.listen_engines(world, tank)
        hit = self.senses.hit_taken(tank) > 0.0
        sight = next((s for s in seen if s.index == self.target), seen[0] if seen else None)
        if sight is None:
            self.target, self.acquired = None, math.inf
        elif sight.index != self.target:
            self.target, self.acquired = sight.index, t + self.reaction
        if sight is not None and t >= self.acquired:
            return self._shoot(world, tank, sight)
        if heard is not None or (hit and self.senses.heard is not None):
            h = heard or self.senses.heard
            self.turn_to = (math.atan2(h.z - tank.z, h.x - tank.x), t + 3.0)     # a half turn takes ~2.5 s
        gx, gz = self.spot  # type: ignore[misc]
        if math.hypot(gx - tank.x, gz - tank.z) > 2.5 and self.path:
            trim(self.path, tank.x, tank.z)
            return self._unstick(world, tank, self._follow(world, tank, self.path, speed=1.0, lookahead=4.0,
                                                           corner=self.path[0], stop=True))
        face = self.face + 0.35 * math.sin(0.5 * t)
        if self.turn_to is not None and t < self.turn_to[1]:
            face = self.turn_to[0]
        return self._drive(world, tank, 0.0, 0.0, self._turn(tank, wrap(face - tank.heading)))

    def _shoot(self, world: "World", tank: "Tank", s: Sighting) -> Command:
        e = world.tanks[s.index]
        v = tank.spec.shell_speed
        sol = aim.intercept(tank.x, tank.z, tank.vx, tank.vz, s.x, s.z, s.vx, s.vz, v)
        heading = sol.heading if sol is not None else math.atan2(s.z - tank.z, s.x - tank.x)
        err = wrap(heading - tank.heading)
        miss = aim.predicted_miss(tank.x, tank.z, tank.vx, tank.vz, tank.heading, s.x, s.z, s.vx, s.vz, v)
        fire = miss < 0.6 * dodge.half_extent(e, heading) and tank.reload <= 0.0
        return self._drive(world, tank, 0.0, 0.0, self._turn(tank, err), fire)


class Novice(ScriptedDriver):
    """A first-time player (see the module docstring): the scripted baseline's roaming,
    and for what it sees, reaction 0.4 s, 5 degrees of aim error (drawn anew after
    each shot), no lead, full speed straight at it."""

    def __init__(self, rng: random.Random, reaction: float = 0.4, aim_error: float = math.radians(5.0),
                 sight: float = 100.0, half_angle: float = math.radians(60.0)) -> None:
        super().__init__(rng, think_hz=10.0, sight=sight, aim_spread=aim_error)
        self.reaction = reaction
        self.half_angle = half_angle
        self.seen: int | None = None
        self.seen_at = math.inf
        self._looking = True

    def _target(self, world: "World", tank: "Tank") -> "Tank | None":
        if not self._looking:
            return None
        best, best_d = None, self.sight
        for o in world.tanks:
            if o is tank or not o.alive:
                continue
            d = math.hypot(o.x - tank.x, o.z - tank.z)
            if d < best_d and abs(wrap(math.atan2(o.z - tank.z, o.x - tank.x) - tank.heading)) <= self.half_angle \
                    and world.sees(tank, o):
                best, best_d = o, d
        return best

    def _think(self, world: "World", tank: "Tank") -> Command:
        t = world.t
        target = self._target(world, tank)
        if target is None:
            self.seen, self.seen_at = None, math.inf
        elif target.index != self.seen:
            self.seen, self.seen_at = target.index, t + self.reaction
        if target is None or t < self.seen_at:
            self._looking = False          # roam as the baseline does, blind to targets
            try:
                return super()._think(world, tank)
            finally:
                self._looking = True
        err = wrap(math.atan2(target.z - tank.z, target.x - tank.x) + self.aim_error - tank.heading)
        fire = abs(err) < math.radians(3.0) and tank.reload <= 0.0
        if fire:
            self.aim_error = self.rng.gauss(0.0, self.aim_spread)
        # straight at it; backing off a little once about to ram it
        close = math.hypot(target.x - tank.x, target.z - tank.z) < 2.5 * tank.spec.radius
        return Command(advance=-0.3 if close else 1.0, rotate=max(-1.0, min(1.0, 3.0 * err)), fire=fire)


#: the yardsticks by name: a factory from a generator to a driver
YARDSTICKS: dict[str, Callable[[random.Random], Callable]] = {
    "robot": Robot,
    "camper": Camper,
    "novice": Novice,
}
