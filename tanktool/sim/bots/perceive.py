"""The game's side of the bot API: what one tank perceives, made into a ``View``.

The rules of perception (the same for the built-in agents and every user bot):

* **Sight**: an enemy is seen when it lies within the vision range, within the cone's
  half-angle of the heading (the hull carries the gun and the crew's view), and
  nothing blocks the line between the two guns: a wall on a flat arena (the paper's
  "línea imaginaria R" against the wall quadtree), the model's solid on a ground (a
  hill or a deck hides; a low wall does not hide a tank on a hill behind it).  A
  sighting shows position, velocity, the hull's heading, height, spawn shield and
  vehicle.
* **Hearing**: each gunshot (the world's ``shot`` events since the bot last acted)
  within the hearing radius is heard from the shooter's place plus Gaussian noise of
  ``hearing_noise`` x the distance.
* **Engines**: a live enemy moving at ``ENGINE_QUIET`` m/s or more is heard through
  walls within ``engine_radius x min(1, ENGINE_FLOOR + (1 - ENGINE_FLOOR) x speed /
  ENGINE_FULL)``, with the same noise.
* **Shells**: enemy shells in the cone, in range and in line of sight.
* **Radar** (``Senses.radar``, BZFlag's): every live enemy and every enemy shell.
* **Events**: its own (shots, hits scored and taken, kills, deaths, bumps, respawns)
  and the kill feed (every kill; others' without a position).

Noise comes from the perceiver's own generator, seeded with the bot's, so a match
replays exactly.  The perceiver reads the world; the ``View`` it hands out holds only
values and the static ``Map``.
"""

from __future__ import annotations

import math
import random
from dataclasses import replace
from typing import TYPE_CHECKING

from .map import Map
from .view import Heard, Memory, Senses, ShellSeen, Sighting, TankState, Vehicle, View

if TYPE_CHECKING:  # pragma: no cover
    from ..body import Tank
    from ..world import Event, World

#: an engine is heard within the full engine radius from this speed up [m/s]
ENGINE_FULL = 6.0
#: and not at all below this speed [m/s]
ENGINE_QUIET = 0.5
#: the fraction of the radius an engine is heard over just above ENGINE_QUIET
ENGINE_FLOOR = 0.5
#: the events a tank perceives when they concern it (as actor or victim)
OWN_KINDS = frozenset(("shot", "hit", "kill", "shielded", "wall_bump", "respawn"))


def wrap(a: float) -> float:
    """An angle in (-pi, pi]."""
    return math.remainder(a, 2.0 * math.pi)


def in_cone(ox: float, oz: float, heading: float, tx: float, tz: float, half_angle: float, vision_range: float) -> bool:
    """Is (tx, tz) within range and within ``half_angle`` of ``heading`` seen from (ox, oz)?"""
    dx, dz = tx - ox, tz - oz
    d2 = dx * dx + dz * dz
    if d2 > vision_range * vision_range:
        return False
    if d2 == 0.0:
        return True
    return abs(wrap(math.atan2(dz, dx) - heading)) <= half_angle


def engine_reach(radius: float, speed: float) -> float:
    """How far [m] an engine moving at ``speed`` is heard by ears of ``radius`` (0:
    not at all)."""
    if speed < ENGINE_QUIET:
        return 0.0
    return radius * min(1.0, ENGINE_FLOOR + (1.0 - ENGINE_FLOOR) * speed / ENGINE_FULL)


class Perceiver:
    """Makes the views of tank ``index`` in ``world`` under ``senses``; its noise
    comes from ``seed``.  Call :meth:`collect` every step (events), :meth:`view`
    when the bot acts."""

    def __init__(self, world: "World", index: int, senses: Senses, seed: int) -> None:
        self.index = index
        self.senses = senses
        self.rng = random.Random(seed)
        self.memory = Memory()
        self.vehicles = [Vehicle.of(t.spec) for t in world.tanks]
        self.map = Map.of(world, self.vehicles[index].radius)
        self.pending: list["Event"] = []
        self.collected = world.steps

    # ------------------------------------------------------------------ events
    def collect(self, world: "World") -> None:
        """Keep the last step's events this tank perceives (once per step)."""
        if world.steps == self.collected:
            return
        self.collected = world.steps
        me = self.index
        for e in world.events:
            if e.kind == "kill" and e.tank != me and e.other != me:
                self.pending.append(replace(e, x=math.nan, z=math.nan))     # the kill feed
            elif e.kind in OWN_KINDS and (e.tank == me or e.other == me or e.kind == "shot"):
                self.pending.append(e)
            elif e.kind == "match_end":
                self.pending.append(e)

    # ------------------------------------------------------------------ the view
    def view(self, world: "World", rng: random.Random) -> View:
        """What the tank perceives now, and since the last view (its events); the
        memory updated with what is seen and heard."""
        tank = world.tanks[self.index]
        pending, self.pending = self.pending, []
        shots = [e for e in pending if e.kind == "shot" and e.tank != self.index]
        events = tuple(e for e in pending if not (e.kind == "shot" and e.tank != self.index))
        me = self.state(world, tank)
        if tank.alive:
            seen = self.look(world, tank)
            heard = self.listen(world, tank, shots)
            engines = self.listen_engines(world, tank)
            shells = self.shells(world, tank)
            radar = self.radar(world, tank) if self.senses.radar else ()
        else:
            seen = heard = engines = shells = radar = ()
        mem = self.memory
        for s in seen:
            mem.last_seen[s.index] = s
        if heard or engines:
            mem.heard = heard[0] if heard else engines[0]
        return View(world.t, world.dt, world.steps, me, seen, heard, engines, shells, radar, events, mem,
                    self.map, world.rules, self.senses, rng)

    def state(self, world: "World", t: "Tank") -> TankState:
        return TankState(t.index, t.name, t.x, t.z, t.y, t.heading, t.vx, t.vz, t.omega, t.pitch, t.roll, t.level,
                         t.hp, t.alive, t.reload, t.kills, t.deaths, t.shots, t.hits,
                         world.protection_left(t.index), self.vehicles[t.index])

    def sighting(self, world: "World", me: "Tank", o: "Tank") -> Sighting:
        return Sighting(o.index, o.x, o.z, o.vx, o.vz, world.t, math.hypot(o.x - me.x, o.z - me.z), o.heading,
                        o.y, world.protection_left(o.index), self.vehicles[o.index])

    def look(self, world: "World", me: "Tank") -> tuple[Sighting, ...]:
        """The live enemies in sight now, nearest first."""
        sn = self.senses
        cand = [o for o in world.tanks if o is not me and o.alive
                and in_cone(me.x, me.z, me.heading, o.x, o.z, sn.half_angle, sn.vision_range)]
        if not cand:
            return ()
        out = [self.sighting(world, me, o) for o, seen in zip(cand, world.sees_all(me, cand)) if seen]
        out.sort(key=lambda s: (s.distance, s.index))
        return tuple(out)

    def listen(self, world: "World", me: "Tank", shots: list["Event"]) -> tuple[Heard, ...]:
        """The shots among ``shots`` within the hearing radius, nearest first, each
        placed with noise growing with the distance."""
        out = []
        for e in shots:
            d = math.hypot(e.x - me.x, e.z - me.z)
            if d <= self.senses.hearing_radius:
                sd = self.senses.hearing_noise * d
                y = world.tanks[e.tank].y
                out.append((d, e.t, Heard(e.x + self.rng.gauss(0.0, sd), e.z + self.rng.gauss(0.0, sd), e.t, y=y)))
        out.sort(key=lambda h: (h[0], -h[1]))
        return tuple(h for _, _, h in out)

    def listen_engines(self, world: "World", me: "Tank") -> tuple[Heard, ...]:
        """The live enemies heard moving now (through walls), nearest first."""
        r = self.senses.engine_radius
        if r <= 0.0:
            return ()
        near = []
        for o in world.tanks:
            if o is me or not o.alive:
                continue
            d = math.hypot(o.x - me.x, o.z - me.z)
            if d <= engine_reach(r, math.hypot(o.vx, o.vz)):
                near.append((d, o.index, o))
        near.sort(key=lambda n: (n[0], n[1]))
        out = []
        for d, _, o in near:
            sd = self.senses.hearing_noise * d
            out.append(Heard(o.x + self.rng.gauss(0.0, sd), o.z + self.rng.gauss(0.0, sd), world.t, True, o.y))
        return tuple(out)

    def shells(self, world: "World", me: "Tank") -> tuple[ShellSeen, ...]:
        """Enemy shells in sight (all of them with radar)."""
        sn = self.senses
        out = []
        eye = world.eye(me)
        for sh in world.shells:
            if sh.owner == self.index or not sh.alive:
                continue
            if not sn.radar:
                if not in_cone(me.x, me.z, me.heading, sh.x, sh.z, sn.half_angle, sn.vision_range):
                    continue
                if world.line_blocked(me.x, me.z, sh.x, sh.z, eye, sh.y):
                    continue
            key = (sh.owner, world.steps + 1 - int(round(sh.age / world.dt)))      # the step it was fired in
            out.append(ShellSeen(key, sh.owner, sh.x, sh.y, sh.z, sh.vx, sh.vy, sh.vz))
        return tuple(out)

    def radar(self, world: "World", me: "Tank") -> tuple[Sighting, ...]:
        """Every live enemy, nearest first."""
        out = [self.sighting(world, me, o) for o in world.tanks if o is not me and o.alive]
        out.sort(key=lambda s: (s.distance, s.index))
        return tuple(out)
