"""The agent's states for fighting: Attack, Evade, Hunt, ReturnFire.

* **Attack** (an enemy in sight and the reaction time over): turn onto the exact
  intercept (``aim.intercept``; the fuzzy turn rules of ``fuzzy.AttackController``
  turn the hull), fire when the shot's predicted miss is small
  (``aim.predicted_miss``), hold the level's fighting distance, strafe at speed;
  with ``cover`` and ``scoot``, back behind the corner it came round while it reloads.
* **Evade** (hit twice within 4 s by an enemy it cannot see, or losing a fight):
  drive to the nearest of a few sampled nodes out of the threat's line of sight, or,
  with no cover near, strafe hard.  Done in cover or after ``EVADE_TIME`` s.
* **Hunt** (``cover`` levels, an enemy seen standing still in the last
  ``CAMP_MEMORY`` s): drive to the nearest place that sees it from the stand-off
  distance, with room to strafe and out of the cone it faced, the gun on it where the
  way comes into its sight.  Done when it is not there.
* **ReturnFire** (hit by a tank it cannot see whose shot it heard from a place in its
  line of sight, or a shot or engine heard close by): turn on the spot to face there, until facing it or for at most
  ``RETURN_FIRE`` s; then it searches from there.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..commands import Command
from . import aim as gun
from . import relief
from .dodge import half_extent_at
from .driving import trim
from .machine import State
from .perception import Sighting, wrap

if TYPE_CHECKING:  # pragma: no cover
    from ..bots import View
    from .agent import Agent
    from .perception import Percept

#: hit by a tank it cannot see, shot heard in the open: turn to face it, for at most
#: this long [s] (a half turn takes a light tank about 2.5 s from rest)
RETURN_FIRE = 3.0
#: fighting: strafe to a side with at least this much room [m]
ROOM = 6.0
#: ... the same side for a random time in this range [s] (a strafe takes about 5 s
#: to reach full speed)
FLIP = (4.0, 8.0)
#: an enemy slower than this is standing still [m/s]
STILL = 1.0
#: it goes back to cover while the reload has more than SCOOT s to go [s]
SCOOT = 0.4
#: an enemy seen standing still is remembered there this long [s]; a way into its
#: sight is driven at most this fast [m/s], gun on it
CAMP_MEMORY = 90.0
CAMP_SPEED = 7.0
#: hunting: no nearer to the place to look from for this long, it looks from where it is [s]
HUNT_STALL = 4.0
#: on relief, the places to see a camp from whose shot onto it is tried, best first
CARRY_LOOK = 24
#: lying in wait (``Difficulty.wait``): an engine heard within WAIT_NEAR m behind cover
#: is waited for at most WAIT s, the gun on where its way to us comes into our sight;
#: not again for WAIT_COOLDOWN s after [m, s, s]
WAIT_NEAR = 35.0
WAIT = 3.0
WAIT_COOLDOWN = 6.0
#: evading lasts at most this long [s]; then no new evasion for EVADE_COOLDOWN s
EVADE_TIME = 5.0
EVADE_COOLDOWN = 8.0
#: on relief, a level that is ``outgunned`` breaks off when no shot of its carries for
#: this long and it is hit meanwhile [s]
OUTGUNNED = 1.5
#: on relief, the place to shoot from is looked for again after this long [s]
SPOT_AGAIN = 1.0
#: fighting with the gun loaded and no shot fired for this long (and no place to shoot
#: from on relief to drive to), it closes in along the A* way to the enemy, the gun on
#: it (two tanks at 40 m on different heights, neither shot carrying, stared at each
#: other for 100 s: 0-0; after 4 s it cost kills against the camper on the hills) [s];
#: the way is planned again every CLOSE_REPLAN s
QUIET = 6.0
CLOSE_REPLAN = 1.0
#: the enemy back in sight within this long [s] of losing it, the fight goes on: the
#: time without a shot is not counted again (an enemy strafing in and out of sight
#: over a crest reset it every few seconds, and the agent stared for 50 s unfired)
REGAIN = 3.0
#: ... and after CHASED times as long even with a place to shoot from that it has not
#: fired from (an enemy moving on moves the place on: one chased for 40 s)
CHASED = 2.0
#: a shot on relief may pass this far over or under the enemy's body [m] (its
#: sphere tree is rounder than the box the test assumes)
HEIGHT_TOLERANCE = 0.25


def _eye(y: float | None) -> float | None:
    """The eye height over a tank standing at ``y`` (None: not known)."""
    from .sight import EYE

    return None if y is None else y + EYE


class Attack(State["Agent"]):
    """Fight the enemy in sight (see the module docstring)."""

    name = "attack"

    def __init__(self) -> None:
        self.side = 1.0
        self.flip_at = 0.0
        self.spot: tuple[float, float] | None = None      # where to shoot from on relief
        self.spot_at = -math.inf
        self.blind_since: float | None = None
        self.quiet_since = 0.0
        self.way: list[tuple[float, float]] = []
        self.way_at = -math.inf
        self.left_at = -math.inf

    def exit(self, agent: "Agent", view: "View") -> None:
        self.left_at = view.t

    def enter(self, agent: "Agent", view: "View", p: "Percept", arg: Any) -> None:
        self.spot, self.spot_at = None, -math.inf
        self.blind_since: float | None = None     # on relief: since when no shot carries from here
        if view.t - self.left_at > REGAIN:
            self.quiet_since = view.t             # since when loaded and not firing
        self.way, self.way_at = [], -math.inf

    def update(self, agent: "Agent", view: "View", p: "Percept") -> Command | None:
        """Turn onto the intercept point, fire when the shot would hit, hold the level's
        fighting distance, strafe at speed, flipping side every ``FLIP`` s and away from
        walls: a tank that strafes can dodge by stopping (``Agent.evade_shells``).  On
        relief, where the hull's pitch will not carry a shot onto the enemy, to a place
        that will (``relief.firing_spot``), the gun on the enemy."""
        s = p.sight
        if s is None:
            return None
        lv, me = agent.level, view.me
        rotate, fire, err = aim_and_fire(agent, view, s)
        top = me.vehicle.top_speed
        if fire or me.reload > agent.period:
            self.quiet_since = view.t
        spot = self.firing_spot(agent, view, s) if lv.relief and view.map.relief else None
        if spot is None:
            self.blind_since = None
        elif self.blind_since is None:
            self.blind_since = view.t
        quiet = view.t - self.quiet_since
        if spot is None and quiet > QUIET or quiet > CHASED * QUIET:
            cmd = self.close_in(agent, view, s)
            if cmd is not None:
                return Command(cmd.advance, rotate, cmd.strafe, fire)
        if spot is not None:
            # through it, not to a stop on it: a tank standing still is the easiest shot
            ux, uz = spot[0] - me.x, spot[1] - me.z
            n = max(math.hypot(ux, uz), 1e-6)
            k = 0.7 * top / n
            fwd, lat = k * (ux * me.c + uz * me.s), k * (-ux * me.s + uz * me.c)
            return agent.drive(view, fwd, max(-0.5 * top, min(0.5 * top, lat)), rotate, fire)
        cover = cover_behind(agent, view, s) if lv.cover and lv.scoot and me.reload > SCOOT else None
        if cover is not None:
            # just fired: back behind the corner while the gun reloads, gun on the enemy
            cmd = agent.approach(view, [cover], (s.x, s.z), 0.5 * top)
            return Command(cmd.advance, cmd.rotate, cmd.strafe, fire)
        d = max(math.hypot(s.x - me.x, s.z - me.z), 1e-6)
        aligned = max(0.0, 1.0 - abs(err) / 0.6)
        engage = lv.stand_off if math.hypot(s.vx, s.vz) < STILL else lv.engage
        forward = max(-0.5 * top, min(0.5 * top, 0.4 * (d - engage))) * aligned
        side, room = self.strafe_side(agent, view)
        if forward < 0.0 and agent.free(view, me.heading + math.pi, 3.0 * ROOM, (0.0,)) < 2.0 * ROOM:
            forward = 0.0                       # no backing into a wall or a corner
        if room < ROOM:
            forward = 0.5 * top * aligned       # boxed in across the line of fire: out, forwards
        lateral = side * 0.5 * top * (0.4 + 0.6 * aligned)
        return agent.drive(view, forward, lateral, rotate, fire)

    def close_in(self, agent: "Agent", view: "View", s: Sighting) -> Command | None:
        """Along the A* way to the enemy with the gun on it (planned again every
        ``CLOSE_REPLAN`` s); None when there is no way or it is within 12 m."""
        me = view.me
        if math.hypot(s.x - me.x, s.z - me.z) < 12.0:
            return None
        if view.t - self.way_at >= CLOSE_REPLAN:
            self.way = view.map.path((me.x, me.z, me.y), (s.x, s.z, s.y), agent.nav.grid)  # type: ignore[union-attr]
            self.way_at = view.t
        trim(self.way, me.x, me.z)
        if not self.way:
            return None
        return agent.approach(view, self.way, (s.x, s.z), 0.7 * me.vehicle.top_speed)

    def firing_spot(self, agent: "Agent", view: "View", s: Sighting) -> tuple[float, float] | None:
        """None while a shot from here would pass through the enemy's height; else the
        place to shoot from (``relief.firing_spot``, looked for again every
        ``SPOT_AGAIN`` s or when reached)."""
        me = view.me
        ev = s.vehicle if s.vehicle is not None else me.vehicle
        if relief.miss_from(view, me.x, me.z, me.eye, me.pitch, s, ev) < relief.TOLERANCE and \
                relief.shell_clear(view, me.x, me.z, me.eye, me.pitch, s):
            self.spot = None
            return None
        near = self.spot is not None and math.hypot(self.spot[0] - me.x, self.spot[1] - me.z) < 1.0
        if view.t - self.spot_at >= SPOT_AGAIN or near:
            grid = agent.nav.grid  # type: ignore[union-attr]
            self.spot = relief.firing_spot(view, s, lambda x, z: grid.is_valid(grid.node_of(x, z)))
            self.spot_at = view.t
        return self.spot

    def strafe_side(self, agent: "Agent", view: "View") -> tuple[float, float]:
        """The side to strafe to (+1 right, -1 left) and the room [m] there: the same
        side until a random flip every 4-8 s or until there is less than ``ROOM``
        that way, then the side with more room."""
        me = view.me
        look = me.vehicle.radius + 2.0 * ROOM
        # walls and, on relief, edges (a plateau's: the pilot will not strafe off it)
        room = {k: min(agent.free(view, me.heading + k * math.pi / 2, look, (0.0,)),
                       agent.edge_free(view, me.heading + k * math.pi / 2, look)) - me.vehicle.radius
                for k in (1.0, -1.0)}
        if view.t >= self.flip_at:
            self.flip_at = view.t + agent.rng.uniform(*FLIP)
            if room[-self.side] >= ROOM:
                self.side = -self.side
        if room[self.side] < ROOM and room[-self.side] > room[self.side]:
            self.side = -self.side
        return self.side, room[self.side]


def aim_and_fire(agent: "Agent", view: "View", s: Sighting) -> tuple[float, bool, float]:
    """(turn command, fire, heading error) against a sighting.

    The lead is the exact intercept (``aim.intercept``) of the velocity seen (the
    level's ``lead`` share of it, relative to our own), off by the aim error drawn
    after each shot; with ``hedge``, aimed between where the enemy goes on and where
    it is if it stops ``hedge`` s after the shot (the stop that dodges).  The gun fires
    when a shell leaving at the next chance to fire (the reload left, the hull still
    turning) would pass within ``fire_tolerance`` of the enemy's half width of where it
    aims -- not at an enemy under spawn protection until that ends before the shell
    arrives, and on relief not when the shell would pass over or under it."""
    lv, me, t = agent.level, view.me, view.t
    v = me.vehicle.shell_speed
    dx, dz = s.x - me.x, s.z - me.z
    tvx = me.vx + lv.lead * (s.vx - me.vx)
    tvz = me.vz + lv.lead * (s.vz - me.vz)
    sol = gun.intercept(me.x, me.z, me.vx, me.vz, s.x, s.z, tvx, tvz, v)
    if sol is not None and lv.hedge > 0.0 and sol.time > lv.hedge:
        # the enemy goes on (at sol.time) or stops (about hedge s after the shot): aim
        # at the middle, which hits both while they lie within its width (its own
        # velocity only: ours the shell keeps whatever the enemy does)
        k = 0.5 * (sol.time + lv.hedge) / sol.time
        tvx = me.vx + lv.lead * (k * s.vx - me.vx)
        tvz = me.vz + lv.lead * (k * s.vz - me.vz)
        sol = gun.intercept(me.x, me.z, me.vx, me.vz, s.x, s.z, tvx, tvz, v) or sol
    heading = sol.heading if sol is not None else math.atan2(dz, dx)
    err = wrap(heading + agent.aim_error - me.heading)
    rotate = agent.turn(me, err)
    fire = False
    hesitant = lv.trigger > 0.0 and t - agent.fired_at < me.vehicle.fire_interval + lv.trigger
    if me.reload <= agent.period and sol is not None and s.protected <= sol.time and not hesitant:
        delay = max(me.reload, view.dt)
        miss = gun.predicted_miss(me.x, me.z, me.vx, me.vz, me.heading - agent.aim_error, s.x, s.z,
                                  tvx, tvz, v, delay, me.omega)
        ev = s.vehicle if s.vehicle is not None else me.vehicle
        fire = miss < lv.fire_tolerance * half_extent_at(ev, s.heading, heading)
        if fire and view.map.relief:
            # on relief the hull's pitch aims the gun up or down: hold fire when the
            # shell would pass over or under the enemy, or meet a crest on the way
            # at the intercept's time of flight, not the distance's at the shell's own
            # speed: it keeps our velocity across the ground (not up), and the enemy
            # drives on -- closing at 5 m/s a 45 m shot up a 6 degree slope climbs
            # 0.5 m less (the tolerance is 0.25) -- and where the enemy will be
            reach = sol.time * v * math.cos(me.pitch)
            fire = gun.height_miss(me.eye, me.pitch, v, view.rules.shell_gravity, reach,
                                   s.y + relief.rise(view, s, sol), ev.height) < HEIGHT_TOLERANCE and \
                relief.shell_clear(view, me.x, me.z, me.eye, me.pitch, s, (me.heading, me.vx, me.vz))
    if fire:
        agent.aim_error = agent.rng.gauss(0.0, lv.aim_noise)
        agent.fired_at = t
    return rotate, fire, err


def cover_behind(agent: "Agent", view: "View", s: Sighting) -> tuple[float, float] | None:
    """The latest place on our way here (the last ``memory.TRAIL`` s) that the enemy
    cannot see, if it is 1.5-10 m away: the corner we came round."""
    me = view.me
    near = []
    for _, x, z, y in reversed(agent.memory.trail):
        d = math.hypot(x - me.x, z - me.z)
        if d > 10.0:
            break
        if d > 1.5:
            near.append((x, z, y))
    # all the lines from the enemy at once (one array lookup on a ground)
    for (x, z, _), hidden in zip(near, view.map.blocked_from(s.x, s.z, _eye(s.y), near)):
        if hidden:
            return x, z
    return None


class Evade(State["Agent"]):
    """Get out of a threat's sight (see the module docstring); hands the threat on."""

    name = "evade"

    def __init__(self) -> None:
        self.until = 0.0

    def enter(self, agent: "Agent", view: "View", p: "Percept", arg: Any) -> None:
        """``arg``: the threat, (x, z) or (x, z, height)."""
        me = view.me
        self.handoff = arg
        self.until = view.t + EVADE_TIME
        agent.path = []
        cover = self._cover(agent, view, arg)
        if cover is not None:
            agent.path = view.map.path((me.x, me.z, me.y), cover, agent.nav.grid)

    def exit(self, agent: "Agent", view: "View") -> None:
        agent.memory.evade_cooldown = view.t + EVADE_COOLDOWN

    def _cover(self, agent: "Agent", view: "View", threat: tuple[float, ...]) -> tuple[float, float] | None:
        """The nearest of a few sampled nodes 5-25 m away that the threat (x, z and
        maybe its height) cannot see."""
        grid, me = agent.nav.grid, view.me
        i, j = grid.node_of(me.x, me.z)
        r = int(25.0 / grid.cell)
        i0, j0 = max(i - r, 0), max(j - r, 0)
        a, b = grid.valid[0, i0:i + r + 1, j0:j + r + 1].nonzero()
        if len(a) == 0:
            return None
        best, best_d = None, math.inf
        eye = _eye(threat[2] if len(threat) > 2 else None)
        for _ in range(24):
            m = agent.rng.randrange(len(a))
            cx, cz = grid.centre(int(a[m]) + i0, int(b[m]) + j0)
            d = math.hypot(cx - me.x, cz - me.z)
            if 5.0 <= d < best_d and view.map.line_blocked(threat[0], threat[1], cx, cz, eye):
                best, best_d = (cx, cz), d
        return best

    def update(self, agent: "Agent", view: "View", p: "Percept") -> Command | None:
        me = view.me
        if view.t >= self.until:
            return None
        trim(agent.path, me.x, me.z)
        if agent.path:
            if math.hypot(agent.path[-1][0] - me.x, agent.path[-1][1] - me.z) < 3.0:
                return None
            # backing and sliding along the way with the hull (and gun) kept on the
            # threat, firing when the shot is good: turning round to drive it first
            # left the tank crawling (about 1 m/s) in the threat's sight for seconds
            threat = (p.sight.x, p.sight.z) if p.sight is not None else self.handoff[:2]
            cmd = agent.approach(view, agent.path, threat, me.vehicle.top_speed)
            fire = aim_and_fire(agent, view, p.sight)[1] if p.sight is not None else False
            return Command(cmd.advance, cmd.rotate, cmd.strafe, fire)
        # no cover near: strafe hard across the threat's line, gun on it when seen
        if p.sight is not None:
            rotate, fire, _ = aim_and_fire(agent, view, p.sight)
            side = agent.machine.states["attack"].side  # type: ignore[attr-defined]
            return agent.drive(view, 0.0, side * 0.5 * me.vehicle.top_speed, rotate, fire)
        return agent.follow(view, [], speed=0.0, lookahead=4.0)


class ReturnFire(State["Agent"]):
    """Turn to face a shot that hit it from out of sight; hands its place on."""

    name = "return_fire"

    def __init__(self) -> None:
        self.face, self.until = 0.0, -math.inf

    def enter(self, agent: "Agent", view: "View", p: "Percept", arg: Any) -> None:
        """``arg``: the heard shot (``Heard``)."""
        me = view.me
        self.face = math.atan2(arg.z - me.z, arg.x - me.x)
        self.until = view.t + RETURN_FIRE
        agent.memory.faced_t, agent.memory.faced_at = arg.t, view.t
        self.handoff = (arg.x, arg.z, arg.y)

    def update(self, agent: "Agent", view: "View", p: "Percept") -> Command | None:
        me = view.me
        err = wrap(self.face - me.heading)
        if view.t >= self.until or abs(err) < 0.15:
            return None
        return agent.drive(view, 0.0, 0.0, agent.turn(me, err))


class Hunt(State["Agent"]):
    """Go for an enemy seen camping (see the module docstring)."""

    name = "hunt"

    def __init__(self) -> None:
        self.camp: tuple[float, float] | None = None
        self.replan = -math.inf
        self.best, self.best_at = math.inf, 0.0      # nearest to the path's end so far, since
        self.closing = False                         # on the way to the camp itself
        self._room: np.ndarray | None = None

    def enter(self, agent: "Agent", view: "View", p: "Percept", arg: Any) -> None:
        self.camp, self.replan, self.closing = None, -math.inf, False
        self.best, self.best_at = math.inf, view.t

    @staticmethod
    def _looked(agent: "Agent", view: "View", cx: float, cz: float) -> bool:
        """Whether the camp lies in our cone (with a margin), in vision range and in
        our line of sight: then an enemy there would be seen."""
        me = view.me
        d = math.hypot(cx - me.x, cz - me.z)
        off = abs(wrap(math.atan2(cz - me.z, cx - me.x) - me.heading))
        return d <= agent.senses.vision_range and off < agent.senses.half_angle - 0.2 and \
            not view.map.line_blocked(me.x, me.z, cx, cz, me.eye)

    def update(self, agent: "Agent", view: "View", p: "Percept") -> Command | None:
        """To the nearest place (by path) that sees the camp from ``stand_off`` +- 15 m
        (the blocks' line-of-sight table), the gun on it where the way comes into its
        sight.  There (or stalled) and not seeing it: along the way to the camp itself,
        gun on it.  The camp in our cone and line of sight and nobody there, or the way
        to it driven: it has gone, forget it.  None: no camp."""
        t, me, mem = view.t, view.me, agent.memory
        idx = agent.camp_known(t)
        if idx is None:
            return None
        cx, cz, seen_t, face = mem.camps[idx]
        if p.sight is None and self._looked(agent, view, cx, cz):
            del mem.camps[idx]                # in our cone and line of sight, and not there
            return None
        if self.closing and self.camp == (cx, cz):
            return self._close_in(agent, view, idx)
        if self.camp != (cx, cz) or t >= self.replan or not agent.path:
            if not self._plan(agent, view, (cx, cz), face):
                del mem.camps[idx]             # nowhere to see it from: give it up
                return None
        trim(agent.path, me.x, me.z)
        if self._stalled(agent, view):
            # there (the block's point sees the camp, but not the place a few metres off
            # it where we stand: the camp is not in sight), or no nearer for HUNT_STALL s
            # (circling a place it cannot stand on: seen on a hillside of the hills for
            # 70 s): close in on the camp itself, the gun on it
            self.closing = True
            agent.path = view.map.path((me.x, me.z, me.y), (cx, cz), agent.nav.grid)  # type: ignore[union-attr]
            self.best, self.best_at = math.inf, t
            return self._close_in(agent, view, idx)
        return agent.follow(view, agent.path, speed=1.0, lookahead=4.0, corner=agent.corner())

    def _stalled(self, agent: "Agent", view: "View") -> bool:
        """At the path's end (within 3 m, or no path), or no nearer to it for ``HUNT_STALL`` s."""
        me = view.me
        if not agent.path:
            return True
        d_end = math.hypot(agent.path[-1][0] - me.x, agent.path[-1][1] - me.z)
        if d_end < self.best - 1.0:
            self.best, self.best_at = d_end, view.t
        return d_end < 3.0 or view.t - self.best_at > HUNT_STALL

    def _close_in(self, agent: "Agent", view: "View", idx: int) -> Command | None:
        """Along the A* way to the camp, gun on it, until it is in sight (``_looked``
        ends the hunt); at its end, or stalled, it is not there: forget it."""
        cx, cz = agent.memory.camps[idx][:2]
        trim(agent.path, view.me.x, view.me.z)
        if self._stalled(agent, view):
            del agent.memory.camps[idx]
            return None
        return agent.approach(view, agent.path, (cx, cz), CAMP_SPEED)

    def _plan(self, agent: "Agent", view: "View", camp: tuple[float, float], face: float) -> bool:
        """A path to the best place to see ``camp`` from (facing ``face``)."""
        v, me, lv = agent.nav.views, view.me, agent.level
        cx, cz = camp
        cb, here = v.cell_at(cx, cz), v.cell_at(me.x, me.z, me.y)
        if cb < 0 or here < 0:
            return False
        lo, hi = lv.stand_off - 15.0, min(lv.stand_off + 15.0, agent.senses.vision_range)
        dist = v.distance[cb]
        pd = v.path_distances(here)
        sees = v.visible[cb] & np.isfinite(pd)
        ok = sees & (dist >= lo) & (dist <= hi)
        if not ok.any():
            ok = sees & (dist <= hi)
        if not ok.any():
            return False
        # nearest by path; a place with room to strafe (ROOM each way) counts as much
        # nearer as a tank drives in 2 s, and one outside the cone it faced (it does not
        # see us come: first shots are ours) as much nearer as a tank drives in 4 s
        roomy = self._block_room(agent) >= ROOM
        pts = v.points
        off = np.abs(np.remainder(np.arctan2(pts[:, 1] - cz, pts[:, 0] - cx) - face + np.pi, 2 * np.pi) - np.pi)
        unseen = off > agent.senses.half_angle + 0.2
        top = me.vehicle.top_speed
        score = np.where(ok, pd - np.where(roomy, 2.0 * top, 0.0) - np.where(unseen, 4.0 * top, 0.0), np.inf)
        b = self._carrying(agent, view, score) if view.map.relief else -1
        b = b if b >= 0 else int(np.argmin(score))
        if self.camp != camp:
            self.best, self.best_at, self.closing = math.inf, view.t, False
        self.camp, self.replan = camp, view.t + 5.0
        agent.path = view.map.path((me.x, me.z, me.y), (float(pts[b][0]), float(pts[b][1]), float(v.heights[b])),
                                   agent.nav.grid)
        return bool(agent.path)

    def _carrying(self, agent: "Agent", view: "View", score: np.ndarray) -> int:
        """On relief, of the ``CARRY_LOOK`` best places (by ``score``), the best from
        which a shot at the camp carries (the hull's pitch there facing it: an enemy
        seen standing still is where it was); -1 if none does.  Seeing a camper is not
        shooting it: hard sat 60 s on the hills 20-45 m below one, the hull pitched 2-4
        degrees up, every shot 2-4 m over it, and never fired while it was killed."""
        idx = agent.camp_known(view.t)
        s = agent.memory.last_seen.get(idx) if idx is not None else None
        if s is None:
            return -1
        v, me = agent.nav.views, view.me
        ev = s.vehicle if s.vehicle is not None else me.vehicle
        for b in np.argsort(score)[:CARRY_LOOK]:
            if not np.isfinite(score[b]):
                break
            x, z = float(v.points[b][0]), float(v.points[b][1])
            eye, pitch = relief.pitch_at(view, x, z, math.atan2(s.z - z, s.x - x))
            if relief.miss_from(view, x, z, eye, pitch, s, ev) < relief.TOLERANCE and \
                    relief.shell_clear(view, x, z, eye, pitch, s):
                return int(b)
        return -1

    def _block_room(self, agent: "Agent") -> np.ndarray:
        """Per block of the sight table: the free space around its representative node
        beyond the grid's clearance [m] (the distance to the nearest invalid node)."""
        if self._room is None:
            from scipy.ndimage import distance_transform_edt

            g = agent.nav.grid
            valid = np.asarray((g.layers if g.layers is not None else g).valid, dtype=bool)
            free = np.stack([distance_transform_edt(m) for m in valid]) * g.cell   # each level's own free space
            free = free if g.layers is not None else free[0]   # the flat sight table's nodes are (i, j)
            self._room = np.array([free[tuple(n)] for n in agent.nav.views.nodes])
        return self._room


class LieInWait(State["Agent"]):
    """An enemy heard coming (its engine, behind cover, close): stand with the gun on
    the place where its way to us comes into our sight, so that the first shot is
    ours; hands the noise on to a search when it does not come."""

    name = "lie_in_wait"

    def __init__(self) -> None:
        self.until = self.aimed = -math.inf
        self.face = 0.0
        self.heard: list[Any] = []          # the engines heard while waiting

    def enter(self, agent: "Agent", view: "View", p: "Percept", arg: Any) -> None:
        """``arg``: the engine heard (``Heard``)."""
        self.until = view.t + WAIT
        self.heard = [arg]
        self._aim(agent, view)

    def exit(self, agent: "Agent", view: "View") -> None:
        agent.memory.waited_until = view.t

    def _aim(self, agent: "Agent", view: "View") -> None:
        """Face the last point of the A* way from us to the noise (the mean of the
        engines heard while waiting: each is off by 15 % of the distance, and one
        apart from the next may put the way round the other end of a wall) that we
        see, before the first we do not: the corner the enemy comes round."""
        me = view.me
        n = len(self.heard)
        x, z = sum(h.x for h in self.heard) / n, sum(h.z for h in self.heard) / n
        y = self.heard[-1].y
        self.handoff, self.aimed = (x, z, y), view.t
        way = view.map.path((me.x, me.z, me.y), (x, z, y), agent.nav.grid)  # type: ignore[union-attr]
        entry = (x, z)
        for q in way:
            if view.map.line_blocked(me.x, me.z, q[0], q[1], me.eye):
                break
            entry = q
        else:
            entry = way[-1] if way else entry
        self.face = math.atan2(entry[1] - me.z, entry[0] - me.x)

    def update(self, agent: "Agent", view: "View", p: "Percept") -> Command | None:
        me = view.me
        if view.t >= self.until:
            return None
        h = p.heard
        if h is not None and h.engine and h is not self.heard[-1]:
            self.heard.append(h)
            if view.t - self.aimed >= 1.0:
                self._aim(agent, view)
        return agent.drive(view, 0.0, 0.0, agent.turn(me, wrap(self.face - me.heading)))
