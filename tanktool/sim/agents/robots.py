"""Yardstick opponents: bots written from issue 28's descriptions (in the spirit of the
opponents held back to judge the agents, not copies), to measure the agents against
(``bench/ladder.py``), not to play the game with.  All of them read the match's rules
(shell speed and range) and act on the bot API's view only (``sim.bots``):

* :class:`Robot` -- BZFlag-style.  Knows where every tank and shell is (radar, as
  BZFlag's robots do); drives A* paths to the nearest enemy, planned again twice a
  second; with a clear line to it and within the shells' range, turns onto the lead
  point (the enemy moved on at the relative velocity for distance / shell speed) and
  fires when the shot's predicted miss there is under half a tank length; dodges any
  shell whose closest approach comes within its footprint + 1.5 m in the next 1.5 s,
  driving across the shell's path.
* :class:`Camper` -- picks the spot near its spawn that sees the most of the arena,
  waits there facing the widest view, turns to every shot it hears, and fires only on
  the exact intercept with a predicted miss under 0.35 m.
* :class:`Duellist` -- pursues like the robot; once it has a clear line to the enemy
  it never stands still: it strafes across the line of fire, flipping every 0.8-2.2 s,
  holds 25-40 m, aims at the exact intercept and fires only under 0.35 m of predicted
  miss.
* :class:`Novice` -- a stand-in for a first-time player: reaction 0.4 s, a 5 degree
  aim error, no lead, drives straight at what it sees, and when it sees nothing heads
  for the nearest enemy on the minimap (the window shows every tank there) along the
  map's paths, roaming like the scripted baseline (``sim.driver.ScriptedDriver``)
  without one.

They drive with the agents' pilot (``driving.Pilot``: speed control and wall feelers,
so a yardstick does not lose by bumping into walls); their randomness is the view's
generator, so duels replay exactly.

On relief they plan on a grid of what the tank can drive (``yardstick_grid``): no way
up a slope steeper than it climbs (the way down one kept, one way), and decks and
ramps wider than the hull joined where the footprint circle leaves them out.  Driving
and not getting anywhere (under ``NO_PROGRESS`` m in ``NO_PROGRESS_S`` s: rocking on a
ramp too steep, wedged at a ramp's side) they back out and plan round that spot for
``AVOID_S`` s (``Yardstick.recover``) -- tools/make_levels.py's bridge once stranded
the robot at a ramp's foot for the rest of every other duel.
"""

from __future__ import annotations

import copy
import math
from typing import TYPE_CHECKING

import numpy as np

from ..bots import IDLE, Command, Senses
from ..driver import Roam
from . import aim, dodge
from .driving import Pilot, trim
from .sight import vantages_for
from .perception import Sighting, wrap

if TYPE_CHECKING:  # pragma: no cover
    from ...nav.navgrid import NavGrid
    from ..bots import View

#: the robot and the duellist plan their way to the enemy this often [s]
REPLAN = 0.5
#: the robot dodges a shell coming within its footprint + DODGE_MARGIN [m] in the next DODGE_HORIZON [s]
DODGE_MARGIN = 1.5
DODGE_HORIZON = 1.5
#: the camper and the duellist fire only when the shot's predicted miss is under this [m]
EXACT = 0.35
#: the duellist holds this range of distances [m], strafing, flipping after a time in FLIP [s]
HOLD = (25.0, 40.0)
FLIP = (0.8, 2.2)
#: the steepest way up of their grid on relief, as a share of the steepest slope the
#: engine holds the tank on (the agents' ``agent.GRADE``: slower is a stall)
CLIMB = 0.8
#: no progress: driving, and under NO_PROGRESS m [m] in NO_PROGRESS_S s [s]; then the
#: spot (AVOID_R m round the way ahead [m]) is planned round for AVOID_S s [s]
NO_PROGRESS = 1.0
NO_PROGRESS_S = 2.5
AVOID_R = 3.0
AVOID_S = 12.0
#: off its grid on a slope steeper than this (rise a metre), it drives up it first
SLOPE = 0.1
#: driving up onto its grid for longer than this [s] is given up for twice as long
CLIMB_S = 6.0
#: a drop: lower by more than 1 m + this a metre off [m/m] (a plateau's edge; 0.25, the
#: slope of its grid, made the hills' hollows 14 m off drops, and held its moves back there)
DROP_RISE = 0.4
#: the rise a metre its grid's links allow (about; the trap test's slack) [m/m]
CLIMB_RISE = 0.25


def yardstick_grid(view: "View", one_way: bool = True) -> "NavGrid":
    """The grid the yardsticks plan on: the map's (1 m nodes, footprint radius + 0.5 m
    off the walls), on relief with the grade the tank climbs cut uphill only (both
    ways: ``one_way`` False, where it can come back from), and the runs as wide as the
    hull + 0.5 m joining parts apart (``navigation.agent_grid``)."""
    m, v = view.map, view.me.vehicle
    if not m.relief:
        return m.grid
    from ..rules import GRAVITY
    from .navigation import agent_grid

    half = 0.5 * (v.box[3] - v.box[1])
    return agent_grid(m, 1.0, v.radius + 0.5, CLIMB * v.engine_force / (v.mass * GRAVITY),
                      narrow=half + 0.5, one_way=one_way)


def without(grid: "NavGrid", x: float, z: float, r: float) -> "NavGrid":
    """A copy of ``grid`` (and of its layered grid) with the nodes within ``r`` m of
    (x, z) taken out, on every level."""
    def cut(g: "NavGrid") -> "NavGrid":
        out = copy.copy(g)
        out.__dict__.pop("_kernel_arrays", None)    # nav.path's cache of the valid nodes
        ci, cj = g.node_of(x, z)
        k = int(math.ceil(r / g.cell))
        valid = g.valid.copy()
        valid[:, max(ci - k, 0):ci + k + 1, max(cj - k, 0):cj + k + 1] = False
        out.valid = valid
        return out

    out = cut(grid)
    if getattr(grid, "layers", None) is not None:
        out.layers = cut(grid.layers)
    return out


class Yardstick(Pilot):
    """What the yardsticks share: a path being followed, forgotten when the tank dies."""

    think_hz: float | None = 20.0
    senses = Senses()

    def __init__(self) -> None:
        super().__init__()
        self.path: list[tuple[float, float]] = []
        self.planned_at = -math.inf
        self.grid: "NavGrid | None" = None
        self.home: "NavGrid | None" = None      # its grid without the ways down it cannot come back up
        # (until, x, z): a spot it got nowhere at, planned round until then
        self.avoid: tuple[float, float, float] | None = None
        self.avoid_grid: "NavGrid | None" = None
        self.moved: tuple[float, float, float] = (-math.inf, math.nan, math.nan)
        self.climb = (math.inf, -math.inf)      # (driving up onto its grid since, not again until)

    def act(self, view: "View") -> Command:
        if not view.me.alive:
            self.reset()
            return IDLE
        if self.grid is None:
            self.grid, self.home = yardstick_grid(view), yardstick_grid(view, one_way=False)
        back = self.back_on_grid(view) if view.t >= self.climb[1] else None
        if back is None:
            self.climb = (math.inf, self.climb[1])
        elif view.t - min(self.climb[0], view.t) > CLIMB_S:
            # not up in that time: wedged on something, not on a slope; the rest (and
            # its recovery) for a while
            self.climb, back = (math.inf, view.t + 2.0 * CLIMB_S), None
        else:
            self.climb = (min(self.climb[0], view.t), self.climb[1])
        return back if back is not None else self.think(view)

    def back_on_grid(self, view: "View") -> Command | None:
        """Off its grid on a slope (more than ``SLOPE`` rise a metre) with its grid a few
        metres uphill -- a spawn at the top of a ramp too steep, where a tank that
        stands to shoot slides down and stays down: straight up onto it first, forward
        or backward, whichever faces it more (turning round on the slope it slides),
        no strafe (the pilot's push off the walls of the ramp's level strafed it down)."""
        m, me = view.map, view.me
        layers = getattr(self.home, "layers", None)
        if not m.relief or layers is None or self._on_grid(layers, me.x, me.z, me.y):
            return None
        g, lv, h = m.ground, me.level, 1.5
        gx = g.height(me.x + h, me.z, lv) - g.height(me.x - h, me.z, lv)
        gz = g.height(me.x, me.z + h, lv) - g.height(me.x, me.z - h, lv)
        n = math.hypot(gx, gz)
        if n / (2.0 * h) <= SLOPE:
            return None
        if not any(self._on_grid(layers, me.x + r * gx / n, me.z + r * gz / n, me.y + 0.5 * r * n / h, 1.5)
                   for r in (2.0, 4.0, 6.0)):
            return None

        err = wrap(math.atan2(gz, gx) - me.heading)
        way = 1.0
        if abs(err) > 0.5 * math.pi:   # backing up it: turning round on the slope, it slides
            err, way = wrap(err - math.pi), -1.0
        return Command(advance=way if abs(err) < 0.8 else 0.0, rotate=self.turn(me, err), strafe=0.0)

    def drive(self, view: "View", forward: float, lateral: float, rotate: float, fire: bool = False) -> Command:
        """``Pilot.drive``; on relief, a forward or sideways speed whose way ahead (the
        footprint radius + 1 m + 0.5 s of it + the way to stop) meets a trap (``_trap``: a ramp too
        steep, a drop) is not driven -- shooting and dodging, the robot slid down a
        ramp it could not climb back."""
        layers = getattr(self.home, "layers", None)
        if view.map.relief and layers is not None:
            me = view.me
            for k, (speed, c, s) in enumerate(((forward, me.c, me.s), (lateral, -me.s, me.c))):
                if abs(speed) < 0.3:
                    continue
                # as far as it takes to stop from the speed it has that way, or wants
                v = max(abs(speed), math.copysign(1.0, speed) * (me.vx * c + me.vz * s))
                brake = 0.6 * me.vehicle.engine_force / me.vehicle.mass
                reach = min(me.vehicle.radius + 1.0 + 0.5 * v + v * v / (2.0 * brake), 14.0)
                r = me.vehicle.radius
                while r < reach:
                    r = min(r + 1.5, reach)
                    if self._trap(view, layers, me.x + c * math.copysign(r, speed), me.z + s * math.copysign(r, speed),
                                  r):
                        forward, lateral = (0.0, lateral) if k == 0 else (forward, 0.0)
                        break
        return super().drive(view, forward, lateral, rotate, fire)

    def _trap(self, view: "View", layers: "NavGrid", x: float, z: float, r: float) -> bool:
        """Whether (x, z), ``r`` m off, is off the grid it can come back from and below
        here: on a ramp too steep (on the map's plain grid) or more than 1 m +
        ``DROP_RISE`` m a metre below (a drop).  Not what is above (a rock: the pilot's feelers
        are for that; held back there too, its dodges and moves were lost)."""
        me = view.me
        if self._on_grid(layers, x, z, me.y, 1.0 + CLIMB_RISE * r):
            return False
        g = view.map.ground
        drop = g.height(me.x, me.z, me.level) - g.height(x, z, me.level)
        if drop <= 0.3:
            return False
        plain = view.map.grid.layers
        if plain is not None and self._on_grid(plain, x, z, me.y, 1.0 + r):
            return True
        return drop > 1.0 + DROP_RISE * r

    @staticmethod
    def _on_grid(layers: "NavGrid", x: float, z: float, y: float, within: float = 1.0) -> bool:
        i, j = layers.node_of(x, z)
        nz, nx = layers.valid.shape[1:]
        if not (0 <= i < nz and 0 <= j < nx):
            return False
        col = layers.height[:, i, j]
        return bool(np.any(layers.valid[:, i, j] & (np.abs(np.nan_to_num(col, nan=1e9) - y) <= within)))

    def plan(self, view: "View", goal: tuple[float, ...]) -> list[tuple[float, float]]:
        """A* waypoints from here to ``goal`` on its grid, round the spot it got nowhere
        at while that is remembered (straight on its grid when that leaves no way)."""
        me = view.me
        start = (me.x, me.z, me.y)
        grid = self.grid if self.grid is not None else view.map.grid
        if self.avoid is not None and view.t < self.avoid[0]:
            if self.avoid_grid is None:
                self.avoid_grid = without(grid, self.avoid[1], self.avoid[2], AVOID_R)
            path = view.map.path(start, goal, self.avoid_grid)
            if path:
                return path
        return view.map.path(start, goal, grid)

    def recover(self, view: "View", cmd: Command) -> Command:
        """The pilot's unstick, and over it: driving (a path being followed) and under
        ``NO_PROGRESS`` m in ``NO_PROGRESS_S`` s -- rocking on a slope too steep, held
        at a ramp's side -- the spot ahead on its way is avoided for ``AVOID_S`` s and it
        backs out, turning, and plans afresh round it."""
        me, t = view.me, view.t
        t0, x0, z0 = self.moved
        driving = bool(self.path) and abs(cmd.advance) >= 0.3
        if not driving or not math.isfinite(x0) or math.hypot(me.x - x0, me.z - z0) >= NO_PROGRESS:
            self.moved = (t, me.x, me.z)
        elif t - t0 >= NO_PROGRESS_S:
            ax, az = self.path[0]
            d = math.hypot(ax - me.x, az - me.z) or 1.0
            ahead = min(d, AVOID_R)
            self.avoid = (t + AVOID_S, me.x + (ax - me.x) / d * ahead, me.z + (az - me.z) / d * ahead)
            self.avoid_grid = None
            self.moved = (t + 0.8, math.nan, math.nan)
            self.reverse_until = t + 0.8
            self.reverse_turn = 1.0 if view.rng.random() < 0.5 else -1.0
            self._replan()
            return self.drive(view, -4.0, 0.0, self.reverse_turn)
        return self.unstick(view, cmd)

    def think(self, view: "View") -> Command:  # pragma: no cover - abstract
        raise NotImplementedError

    def reset(self) -> None:
        self.path, self.planned_at = [], -math.inf
        self.avoid, self.avoid_grid, self.moved = None, None, (-math.inf, math.nan, math.nan)
        self.climb = (math.inf, -math.inf)

    def _on_path(self) -> bool:
        return bool(self.path)

    def _replan(self) -> None:
        self.path = []
        self.planned_at = -math.inf

    def clear_line(self, view: "View", e: Sighting) -> bool:
        """Nothing between the guns, and the enemy within the shells' range."""
        me = view.me
        ey = e.y + (e.vehicle.eye if e.vehicle is not None else me.vehicle.eye)
        return e.distance <= view.rules.shell_range and not view.map.line_blocked(me.x, me.z, e.x, e.z, me.eye, ey)

    def pursue(self, view: "View", e: Sighting) -> Command:
        """Along an A* path to ``e``, planned again every ``REPLAN`` s."""
        me = view.me
        if view.t >= self.planned_at + REPLAN or not self.path:
            self.path = self.plan(view, (e.x, e.z, e.y))
            self.planned_at = view.t
        trim(self.path, me.x, me.z)
        return self.follow(view, self.path, speed=1.0, lookahead=4.0, corner=self.path[0] if self.path else None)

    def exact_shot(self, view: "View", s: Sighting) -> tuple[float, bool]:
        """(heading error to the exact intercept, fire: the gun is loaded and the shot's
        predicted miss is under ``EXACT`` m)."""
        me = view.me
        v = me.vehicle.shell_speed
        sol = aim.intercept(me.x, me.z, me.vx, me.vz, s.x, s.z, s.vx, s.vz, v)
        heading = sol.heading if sol is not None else math.atan2(s.z - me.z, s.x - me.x)
        miss = aim.predicted_miss(me.x, me.z, me.vx, me.vz, me.heading, s.x, s.z, s.vx, s.vz, v)
        return wrap(heading - me.heading), me.reload <= 0.0 and sol is not None and miss < EXACT


class Robot(Yardstick):
    """The BZFlag-style robot (see the module docstring)."""

    senses = Senses(radar=True)

    def think(self, view: "View") -> Command:
        if not view.radar:
            return self.drive(view, 0.0, 0.0, 0.0)
        e = view.radar[0]
        lateral = self.dodge(view)
        if self.clear_line(view, e):
            return self._shoot(view, e, lateral)
        cmd = self.pursue(view, e)
        if lateral is not None:      # dodging on the way: across the shell's path, steering on
            return self.drive(view, lateral[0], lateral[1], cmd.rotate)
        return self.recover(view, cmd)

    def _shoot(self, view: "View", e: Sighting, lateral: tuple[float, float] | None) -> Command:
        me = view.me
        v = me.vehicle.shell_speed
        sol = aim.lead_by_distance(me.x, me.z, me.vx, me.vz, e.x, e.z, e.vx, e.vz, v)
        err = wrap(sol.heading - me.heading)
        # where a shell fired now is when the lead point is reached
        sx = me.x + (v * me.c + me.vx) * sol.time
        sz = me.z + (v * me.s + me.vz) * sol.time
        miss = math.hypot(sx - sol.x, sz - sol.z)
        box = e.vehicle.box if e.vehicle is not None else me.vehicle.box
        fire = miss < 0.5 * (box[2] - box[0]) and me.reload <= 0.0
        forward = 0.0
        if abs(err) < 0.5:
            forward = 0.4 * me.vehicle.top_speed if e.distance > 30.0 else -3.0 if e.distance < 12.0 else 0.0
        if lateral is not None:
            forward, side = lateral
        else:
            side = 0.0
        return self.drive(view, forward, side, self.turn(me, err), fire)

    def dodge(self, view: "View") -> tuple[float, float] | None:
        """(forward, sideways) speeds [m/s] that drive straight across the path of the
        soonest shell coming within the footprint + ``DODGE_MARGIN`` in the next
        ``DODGE_HORIZON`` s, away from its line; None: nothing to dodge."""
        me = view.me
        th = dodge.threats(me, view.shells, horizon=DODGE_HORIZON, margin=DODGE_MARGIN)
        if not th:
            return None
        s = th[0].shell
        n = math.hypot(s.vx, s.vz) or 1.0
        ux, uz = s.vx / n, s.vz / n
        # away from the line, on the side the tank is on (to its left when on it)
        side = ux * (me.z - s.z) - uz * (me.x - s.x)
        px, pz = (-uz, ux) if side >= 0.0 else (uz, -ux)
        # as fast as the tracks allow along that way (the strafe has half the top speed)
        top = me.vehicle.top_speed
        pf, pr = px * me.c + pz * me.s, -px * me.s + pz * me.c
        k = min(top / max(abs(pf), 1e-9), 0.5 * top / max(abs(pr), 1e-9))
        return k * pf, k * pr


class Camper(Yardstick):
    """Holds the spot near its spawn that sees most of the arena (see the module
    docstring).

    Parameters
    ----------
    reaction : seconds from first seeing an enemy to shooting at it
    near : the spot is the block seeing most of the arena within this many metres of
        path from where it (re)spawned
    """

    def __init__(self, reaction: float = 0.25, near: float = 30.0) -> None:
        super().__init__()
        self.reaction, self.near = reaction, near
        self.spot: tuple[float, float] | None = None
        self.face = 0.0
        self.turn_to: tuple[float, float] | None = None     # (heading, until)
        self.target: int | None = None
        self.acquired = math.inf

    def reset(self) -> None:
        super().reset()
        self.spot, self.turn_to, self.target, self.acquired = None, None, None, math.inf

    def _choose_spot(self, view: "View") -> None:
        me, sn = view.me, view.senses
        views = view.map.sight_table()
        here = views.cell_at(me.x, me.z, me.y)
        if here < 0:
            self.spot, self.face = (me.x, me.z), me.heading
            return
        sees = (views.visible & (views.distance <= sn.vision_range)).sum(axis=1)
        score = np.where(views.path_distances(here) <= self.near, sees, -1)
        b = int(np.argmax(score))
        self.spot = (float(views.points[b][0]), float(views.points[b][1]))
        self.face = float(vantages_for(views, sn.half_angle, sn.vision_range).block_face[b])
        self.path = self.plan(view, (*self.spot, float(views.heights[b])))

    def think(self, view: "View") -> Command:
        t, me = view.t, view.me
        if self.spot is None:
            self._choose_spot(view)
        sight = next((s for s in view.seen if s.index == self.target), view.seen[0] if view.seen else None)
        if sight is None:
            self.target, self.acquired = None, math.inf
        elif sight.index != self.target:
            self.target, self.acquired = sight.index, t + self.reaction
        if sight is not None and t >= self.acquired and sight.distance <= view.rules.shell_range:
            err, fire = self.exact_shot(view, sight)
            return self.drive(view, 0.0, 0.0, self.turn(me, err), fire)
        if view.heard:
            h = view.heard[0]
            self.turn_to = (math.atan2(h.z - me.z, h.x - me.x), t + 3.0)     # a half turn takes ~2.5 s
        gx, gz = self.spot  # type: ignore[misc]
        if math.hypot(gx - me.x, gz - me.z) > 2.5 and self.path:
            trim(self.path, me.x, me.z)
            return self.recover(view, self.follow(view, self.path, speed=1.0, lookahead=4.0, corner=self.path[0],
                                                  stop=True))
        face = self.face + 0.35 * math.sin(0.5 * t)
        if self.turn_to is not None and t < self.turn_to[1]:
            face = self.turn_to[0]
        return self.drive(view, 0.0, 0.0, self.turn(me, wrap(face - me.heading)))


class Duellist(Yardstick):
    """Pursues like the robot, strafes and shoots exactly once in sight (see the module
    docstring).  Its strafe flips every 0.8-2.2 s and a surge forward or back flips
    half way between (inside the distance it holds), so that it is never still: a
    strafe comes to a stop at each flip, the surge then carries it on."""

    senses = Senses(radar=True)

    def __init__(self) -> None:
        super().__init__()
        self.side = self.surge = 1.0
        self.flip_at = self.surge_at = -math.inf

    def think(self, view: "View") -> Command:
        if not view.radar:
            return self.drive(view, 0.0, 0.0, 0.0)
        e = view.radar[0]
        if not self.clear_line(view, e):
            return self.recover(view, self.pursue(view, e))
        me, t = view.me, view.t
        err, fire = self.exact_shot(view, e)
        top = me.vehicle.top_speed
        look = me.vehicle.radius + 8.0
        room = {k: self.free(view, me.heading + k * math.pi / 2, look, (0.0,)) for k in (1.0, -1.0)}
        if t >= self.flip_at or room[self.side] < me.vehicle.radius + 2.0:
            if t >= self.flip_at or room[-self.side] > room[self.side]:
                self.side = -self.side
            gap = view.rng.uniform(*FLIP)
            self.flip_at, self.surge_at = t + gap, t + 0.5 * gap
        if t >= self.surge_at:
            self.surge, self.surge_at = -self.surge, math.inf
        lo, hi = HOLD
        forward = 0.5 * top if e.distance > hi else -0.5 * top if e.distance < lo else self.surge * 0.3 * top
        return self.drive(view, forward, self.side * 0.5 * top, self.turn(me, err), fire)


class Novice(Yardstick):
    """A first-time player (see the module docstring): off towards the nearest enemy on
    the minimap (the radar) or the scripted baseline's roaming (``sim.driver.Roam``), and
    for what it sees, reaction 0.4 s, 5 degrees of aim error (drawn anew after each
    shot), no lead, full speed straight at it."""

    think_hz = 10.0
    #: the window's minimap shows every tank: the radar stands for a glance at it
    senses = Senses(vision_range=100.0, radar=True)

    def __init__(self, reaction: float = 0.4, aim_error: float = math.radians(5.0)) -> None:
        super().__init__()
        self.reaction, self.spread = reaction, aim_error
        self.aim_error: float | None = None
        self.seen: int | None = None
        self.seen_at = math.inf
        self.roam: Roam | None = None

    def think(self, view: "View") -> Command:
        t, me = view.t, view.me
        if self.roam is None:
            self.roam = Roam(1.0 if view.rng.random() < 0.5 else -1.0)
            self.aim_error = view.rng.gauss(0.0, self.spread)
        target = view.seen[0] if view.seen else None
        if target is None:
            self.seen, self.seen_at = None, math.inf
        elif target.index != self.seen:
            self.seen, self.seen_at = target.index, t + self.reaction
        if target is None or t < self.seen_at:
            if view.radar:             # the dots on the minimap: off towards the nearest enemy
                return self.unstick(view, self.pursue(view, view.radar[0]))
            m = view.map
            return self.roam.command(t, me, me.vehicle.radius, m.walls_of(me.level), m.spawns, m.bounds, view.rng)
        err = wrap(math.atan2(target.z - me.z, target.x - me.x) + self.aim_error - me.heading)
        fire = abs(err) < math.radians(3.0) and me.reload <= 0.0
        if fire:
            self.aim_error = view.rng.gauss(0.0, self.spread)
        # straight at it; backing off a little once about to ram it
        close = target.distance < 2.5 * me.vehicle.radius
        return Command(advance=-0.3 if close else 1.0, rotate=max(-1.0, min(1.0, 3.0 * err)), fire=fire)

    def reset(self) -> None:
        super().reset()
        if self.roam is not None:
            self.roam.waypoint = None


#: the yardsticks by name
YARDSTICKS = {"robot": Robot, "camper": Camper, "duellist": Duellist, "novice": Novice}
