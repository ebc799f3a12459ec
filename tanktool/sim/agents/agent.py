"""The computer opponent: a small state machine over sensors and ``Command`` values.

States (each a method ``_wander``, ``_watch``, ``_search``, ``_attack``, ``_evade``
that returns the command for this think; ``_watch`` plays Watch and Ambush):

* **Wander** (start): explore.  A* to the block that sees the most of what was not
  seen in the last minute per metre of path (``navigation.Coverage.goal``: the sight
  memory); when nothing is left unseen, a route of grid nodes chosen by the paper's
  three-node heuristic with memory (``navigation.Wanderer``).
* **Search** (an enemy was seen or heard, and is not in sight): the quadrant search
  (``navigation.SearchPlan``), A* paths to each quadrant's centre.
* **Attack** (an enemy in sight and the reaction time passed): turn onto the exact
  intercept (``aim.intercept``; the fuzzy turn rules of ``fuzzy.AttackController``
  turn the hull), fire when the shot's predicted miss is small (``aim.predicted_miss``),
  hold the level's fighting distance, strafe at speed, dodge seen shells
  (``dodge.Evasion``); with ``cover`` and ``scoot``, back behind the corner it came round while
  it reloads, and break off a fight it is losing.
* **Hunt** (``cover`` levels, an enemy seen standing still in the last 90 s): drive
  to the nearest place that sees it from the stand-off distance, with room to strafe
  and out of the cone it faced, the gun on it where the way comes into its sight.
* **Evade** (hit twice within 4 s by an enemy it cannot see): drive to the nearest of
  a few sampled nodes out of the threat's line of sight, or, with no cover near,
  strafe hard.
* **Watch** (instead of Wander, in an arena with a vantage point: a block from which
  the vision cone, pointed one way, sees at least ``WATCH_COVER`` of the arena's
  blocks; ``navigation.Vantages``): drive to the nearest good vantage and hold it,
  facing that way and sweeping the cone, so that an enemy coming in is seen first
  and far off.  After ``WATCH_STINT`` s, if part of the arena has gone unseen for a
  minute (more than ``STALE`` of it), Wander until it has been seen again, then back
  to Watch.
* **Ambush** (instead of Wander, Watch or a search for what it hears, while it leads:
  its kills, on the HUD, above its deaths): hold the safest place near by (a block
  that nothing can see without being in its cone: a dead end, a corner facing out;
  ``Vantages.safest``), facing out and sweeping; a tank heard (engine or shot) moves
  it to a place farther from the noise, and turns it to face the way the noise would
  come in.  A lead is kept by not being found, and, when found, by seeing first.

And, in any state but Attack, *return fire*: hit by a tank it cannot see whose shot
it heard from a place in the open, it turns to face that place (at most ``RETURN_FIRE`` s).

Transitions, checked every think (``think_hz`` times a second; the command is held in
between, as a person holds a key)::

    any      --enemy seen, reaction time over-->  Attack
    Attack   --enemy lost-->                      Search (from where it was last seen, moved on)
    Attack   --enemy killed-->                    Wander / Watch (it comes back at a spawn point)
    Wander   --shot heard / hit taken-->          Search (from the shot / from behind us)
    Search   --all quadrants done, or 60 s-->     Wander / Watch
    any      --hit repeatedly-->                  Evade --cover reached or 5 s--> Search
    Watch    --watched WATCH_STINT s, part unseen-->  Wander --all seen again--> Watch
    Wander / Watch  --kills above deaths-->       Ambush --not leading any more--> Wander / Watch
    Attack   --losing, cover-->                   Evade
    not Attack, not leading --a camp known, cover-->  Hunt --it is not there / forgotten--> Wander

Wander, Watch and Search (not Ambush) also take a heard engine (a moving tank within
the engine-hearing radius, through walls) as they take a heard shot.

Everything the agent knows comes from ``perception.Senses`` (sight, hearing of shots
and engines, memory, its own hit points), what a player's HUD shows (its own kills)
and the static map (walls, spawn points and its navigation grid); it acts only
through ``Command`` values.  Its randomness comes from its own ``random.Random``,
seeded from the world's, so matches replay exactly.

Difficulty sets the reaction time (delay between first seeing an enemy and acting on
it), the aim noise (a Gaussian error on the aim, drawn anew after every shot), the
vision range, the hearing radius (shots), the engine-hearing radius and how often it
thinks.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...nav.navgrid import nearest_valid_node
from ...nav.steering import heading_from_angle
from ..commands import IDLE, Command
from . import aim as gun
from .dodge import Evasion, half_extent_at, visible_shells
from .driving import Pilot, trim
from .navigation import (EYE, Coverage, Memory, SearchPlan, Vantages, Wanderer, agent_grid, plan_path, vantages_for,
                         views_for)
from .perception import Senses, Sighting, wrap

if TYPE_CHECKING:  # pragma: no cover
    from ..body import Tank
    from ..world import World

STATES = ("wander", "watch", "ambush", "search", "attack", "evade", "hunt")
#: a vantage point sees at least this fraction of the arena's blocks in one cone
WATCH_COVER = 0.4
#: choosing a vantage: its cover less this much per metre of path to it
WATCH_PER_M = 0.004
#: watch this long [s] before going to look at what has not been seen for a minute
WATCH_STINT = 30.0
#: ... if more than this fraction of the arena's blocks has not been seen for a minute
STALE = 0.1
#: a watching agent sweeps its cone this far either side of the vantage's way [rad],
#: at this rate [rad/s]
SWEEP = 0.35
SWEEP_RATE = 0.35
#: choosing a hiding place to ambush from: its safety less this much per metre of path
#: to it, plus AMBUSH_AWAY per metre of path (up to AMBUSH_AWAY_CAP) from an engine
#: heard in the last 2 s
AMBUSH_PER_M = 0.004
AMBUSH_AWAY = 0.01
AMBUSH_AWAY_CAP = 80.0
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
#: an enemy seen again within this long needs no new reaction time [s]
REACQUIRE = 2.0
#: cover: where it was in the last TRAIL s [s]; a standing enemy seen in the last KNOWN s is still where it was; within
#: PREAIM m of it the agent closes in with its gun on it; it goes back to cover while
#: the reload has more than SCOOT s to go
TRAIL = 6.0
KNOWN = 20.0
PREAIM = 70.0
SCOOT = 0.4
#: an enemy seen standing still is remembered there this long [s]; a way into its
#: sight is driven at most this fast [m/s], gun on it
CAMP_MEMORY = 90.0
CAMP_SPEED = 7.0


@dataclass(frozen=True)
class Difficulty:
    """How good an agent is.  Times in seconds, angles in radians, distances in metres."""

    name: str
    reaction: float
    aim_noise: float
    vision_range: float
    hearing_radius: float
    think_hz: float
    engine_radius: float = 0.0
    #: how much of the intercept lead it takes (0: aims at where the enemy is)
    lead: float = 1.0
    #: fires when a shot now would pass within this fraction of the enemy's half width
    fire_tolerance: float = 0.6
    #: notices a shell flying at it this long after it comes into view (inf: never dodges)
    dodge_reaction: float = math.inf
    #: the distance it fights at when it can choose [m]
    engage: float = 30.0
    #: and against an enemy standing still (it cannot dodge; we can, from afar) [m]
    stand_off: float = 30.0
    #: aims between where the enemy goes on and where it is if it stops this long after
    #: the shot (the stop that dodges); 0: the plain intercept [s]
    hedge: float = 0.0
    #: waits this long after its gun is loaded before it fires again (a newcomer's
    #: hesitation) [s]
    trigger: float = 0.0
    #: explores for what it has not seen (else: the paper's wander heuristic only)
    explore: bool = True
    #: holds vantage points and, leading, hiding places (``Agent(watch=...)`` too)
    watch: bool = True
    #: fights like a player who knows cover: closes in on a known enemy with the gun
    #: on it, goes back behind the corner it came from while reloading (``scoot``), and breaks off
    #: a fight it is losing
    cover: bool = False
    #: with ``cover``: goes back behind the corner it came round while it reloads
    #: (False: keeps strafing.  A strafe builds up at about 1.5 m/s^2, so a tank that
    #: shuttles to cover hardly moves across the line of fire: hard's median sideways
    #: speed in its fights with the camper in the box was 0.5 m/s with it, 1.5 without)
    scoot: bool = True


DIFFICULTIES: dict[str, Difficulty] = {
    "easy": Difficulty("easy", reaction=1.0, aim_noise=math.radians(9.0), vision_range=60.0,
                       hearing_radius=80.0, think_hz=8.0, engine_radius=40.0, lead=0.3, fire_tolerance=1.2,
                       dodge_reaction=math.inf, engage=25.0, stand_off=25.0, watch=False, trigger=1.6),
    "normal": Difficulty("normal", reaction=0.3, aim_noise=math.radians(1.5), vision_range=90.0,
                         hearing_radius=80.0, think_hz=15.0, engine_radius=35.0, lead=1.0, fire_tolerance=0.7,
                         dodge_reaction=0.45, engage=40.0, stand_off=45.0, cover=True),
    "hard": Difficulty("hard", reaction=0.1, aim_noise=math.radians(0.3), vision_range=130.0,
                       hearing_radius=120.0, think_hz=20.0, engine_radius=40.0, lead=1.0, fire_tolerance=0.5,
                       dodge_reaction=0.25, engage=50.0, stand_off=55.0, hedge=0.35, cover=True, scoot=False),
}


def difficulty(name: str | Difficulty) -> Difficulty:
    """A difficulty by name (easy, normal, hard)."""
    if isinstance(name, Difficulty):
        return name
    try:
        return DIFFICULTIES[name]
    except KeyError:
        raise ValueError(f"difficulty must be one of {', '.join(DIFFICULTIES)}, got {name!r}") from None


class Agent(Pilot):
    """A computer opponent; call it as a driver: ``agent(world, tank) -> Command``.

    Parameters
    ----------
    rng : its own generator (seed it from the world's for replays)
    level : a :class:`Difficulty` or its name
    half_angle : vision cone half-angle [rad] (60 degrees)
    cell : node spacing of its navigation grid [m]
    margin : grid clearance beyond the vehicle's footprint radius [m]
    watch : hold vantage points where the arena has them, and hiding places while it
        leads (False: always Wander)
    """

    def __init__(self, rng: random.Random, level: str | Difficulty = "normal", *,
                 half_angle: float = math.radians(60.0), cell: float = 1.0, margin: float = 0.5,
                 watch: bool = True) -> None:
        self.level = difficulty(level)
        self.rng = rng
        self.period = 1.0 / self.level.think_hz
        self.senses = Senses(half_angle, self.level.vision_range, self.level.hearing_radius, 0.15, rng,
                             engine_radius=self.level.engine_radius)
        self.cell = cell
        self.margin = margin
        self.state = "wander"
        self.command: Command = IDLE
        self.next_think = -math.inf
        self.grid = None
        self.memory: Memory | None = None
        self.views = None
        self.coverage: Coverage | None = None
        self.goal_cell = -1
        self.goal_gain = 0.0
        self.recheck = 0.0
        self.wanderer: Wanderer | None = None
        # wander route: world points of nodes, and the walker's node and heading
        self.route: list[tuple[float, float]] = []
        self.walker: tuple[tuple[int, int], str] | None = None
        # search / evade
        self.plan: SearchPlan | None = None
        self.path: list[tuple[float, float]] = []
        self.goal: tuple[float, float] | None = None
        self.state_since = 0.0
        self.evade_until = 0.0
        self.evade_cooldown = -math.inf
        self.threat: tuple[float, ...] | None = None
        # attack
        self.target: int | None = None
        self.acquired_at = math.inf
        self.aim_error = rng.gauss(0.0, self.level.aim_noise)
        self.evasion = Evasion(self.level.dodge_reaction)
        self.fired_at = -math.inf
        # cover: enemies' hit points by our count, our hits so far, where it was lately
        # (t, x, z)
        self.enemy_hp: dict[int, float] = {}
        self.own_hits = 0
        self.trail: list[tuple[float, float, float, float]] = []   # (t, x, z, eye height)
        # enemies seen standing still: where, when, facing (index -> (x, z, t, heading))
        self.camps: dict[int, tuple[float, float, float, float]] = {}
        self.hunt_for: tuple[float, float] | None = None
        self._room: np.ndarray | None = None
        self.hunt_replan = -math.inf
        self.dodge = 1.0 if rng.random() < 0.5 else -1.0
        self.dodge_flip = 0.0
        self.hits: list[float] = []
        # its own kills (the HUD), and when the target last died at its hands
        self.own_kills = 0
        self.killed_at = -math.inf
        # watching: the vantage table, the spot chosen, the way it faces, the path there
        self.watches = watch and self.level.watch
        self.vantages: Vantages | None = None
        self.spot: tuple[float, float] | None = None
        self.spot_face = 0.0
        self.spot_path: list[tuple[float, float]] = []
        self.spot_replan = -math.inf
        self.spot_chosen = -math.inf
        self.spot_ambush = False
        self.exploring = False
        # ambush: the heard engine it last turned to face, and that way
        self.faced: tuple[object, float] | None = None
        # return fire: the way to face, until when
        self.return_to = (0.0, -math.inf)
        Pilot.__init__(self)      # stuck recovery

    # ------------------------------------------------------------------ driver
    def __call__(self, world: "World", tank: "Tank") -> Command:
        if not tank.alive:
            self._reset()
            return IDLE
        if world.t + 1e-12 < self.next_think:
            return self.command
        self.next_think = world.t + self.period
        self.command = self._evade_shells(world, tank, self.think(world, tank))
        return self.command

    def _evade_shells(self, world: "World", tank: "Tank", cmd: Command) -> Command:
        """Dodge a shell seen flying at it (``dodge.Evasion``: noticed after the level's
        ``dodge_reaction``) when a way out exists: the escape's forward and sideways
        moves replace the command's, which keeps its turn and its shot."""
        if not math.isfinite(self.level.dodge_reaction):
            return cmd
        esc = self.evasion.command(world, tank, visible_shells(world, tank, self.senses.half_angle,
                                                               self.senses.vision_range))
        if esc is None or self.evasion.clearance <= 0.0:
            return cmd           # nothing to dodge, or no escape: keep fighting
        top = tank.spec.top_speed
        return self._drive(world, tank, esc[0] * top, esc[1] * 0.5 * top, cmd.rotate, cmd.fire)

    def _reset(self) -> None:
        self.state = "wander"
        self.route, self.walker, self.path, self.plan, self.goal = [], None, [], None, None
        self.target, self.acquired_at = None, math.inf
        self.hits = []
        self.spot, self.spot_replan, self.spot_path, self.exploring = None, -math.inf, [], False
        self.return_to = (0.0, -math.inf)
        self.senses.hp = math.inf
        self.trail = []
        self.reverse_until = -math.inf
        self.next_think = -math.inf

    def _setup(self, world: "World", tank: "Tank") -> None:
        self.grid = agent_grid(world, self.cell, tank.spec.radius + self.margin)
        self.memory = Memory(self.grid, region=16.0)
        self.wanderer = Wanderer(self.grid, self.memory, self.rng)
        self.views = views_for(world, self.grid)
        self.coverage = Coverage(self.views, self.senses.half_angle, self.senses.vision_range)
        self.vantages = vantages_for(self.views, self.senses.half_angle, self.senses.vision_range)

    def _enter(self, state: str, t: float) -> None:
        if state != self.state:
            self.state = state
            self.state_since = t
            self.route, self.walker, self.path = [], None, []

    # ------------------------------------------------------------------ think
    def think(self, world: "World", tank: "Tank") -> Command:
        """Perceive, pick the state, act.  Called ``think_hz`` times a second."""
        if self.grid is None:
            self._setup(world, tank)
        t = world.t
        self.memory.visit(tank.x, tank.z, t)  # type: ignore[union-attr]
        self.coverage.look(tank.x, tank.z, tank.heading, t, tank.y)  # type: ignore[union-attr]
        previous = self.senses.last_seen.get(self.target) if self.target is not None else None
        seen = self.senses.look(world, tank)
        heard = self.senses.listen(world, tank)
        engine = self.senses.listen_engines(world, tank)
        if heard is None:
            heard = engine
        if self.senses.hit_taken(tank) > 0.0:
            self.hits.append(t)
        self.hits = [h for h in self.hits if t - h < 4.0]
        self._count_hits(world, tank)
        self._kills(tank, t)

        for o in seen:
            if math.hypot(o.vx, o.vz) < STILL:
                self.camps[o.index] = (o.x, o.z, t, o.heading)
            else:
                self.camps.pop(o.index, None)
        sight = self._pick_target(seen)
        if sight is not None:
            fresh = previous is None or previous.index != sight.index or t - previous.t > REACQUIRE
            if self.target != sight.index or fresh:
                self.acquired_at = t + self.level.reaction
            self.target = sight.index

        self.trail.append((t, tank.x, tank.z, world.eye(tank)))
        while self.trail and t - self.trail[0][0] > TRAIL:
            self.trail.pop(0)
        if self.state != "evade" and sight is None and len(self.hits) >= 2 and t >= self.evade_cooldown:
            threat = (sight.x, sight.z, sight.y) if sight else self._estimate(t)
            if threat is not None:
                self._start_evade(world, tank, threat, t)
        elif (self.level.cover and sight is not None and self.state == "attack" and t >= self.evade_cooldown
              and self._losing(world, tank, sight)):
            self._start_evade(world, tank, (sight.x, sight.z), t)
        if self.state == "evade":
            cmd = self._evade(world, tank, sight)
            if cmd is not None:
                return self._unstick(world, tank, cmd)
            self.evade_cooldown = t + 8.0
            self._start_search(self.threat or (tank.x, tank.z, tank.y), t)
        if sight is None and self.state != "attack":
            cmd = self._return_fire(world, tank)
            if cmd is not None:
                return self._unstick(world, tank, cmd)

        if sight is not None and t >= self.acquired_at:
            self._enter("attack", t)
            return self._attack(world, tank, sight)
        if self.level.cover and sight is None and self.state != "attack" and not self._leading(tank):
            cmd = self._hunt(world, tank)
            if cmd is not None:
                self._enter("hunt", t)
                return self._unstick(world, tank, cmd)
            if self.state == "hunt":
                self._enter("wander", t)
        if sight is None and self.state == "attack":
            if t - self.killed_at < 1.0:
                # it died: it comes back at a spawn point, not where it was
                self._enter("wander", t)
            else:
                est = self._estimate(t)
                self._start_search(est if est is not None else (tank.x, tank.z, tank.y), t)
        elif sight is None and self.state in ("wander", "watch"):
            if heard is not None:
                self._start_search((heard.x, heard.z, heard.y), t)
            elif self.hits and self.hits[-1] == t:
                # hit by something unseen: look behind
                self._start_search((tank.x - 20.0 * tank.c, tank.z - 20.0 * tank.s, tank.y), t)
        elif sight is None and self.state == "search" and heard is not None and t - self.state_since > 2.0:
            self._start_search((heard.x, heard.z, heard.y), t)
        if self.state == "search":
            cmd = self._search(world, tank)
            if cmd is not None:
                return self._unstick(world, tank, cmd)
            self._enter("wander", t)
        cmd = self._watch(world, tank)
        if cmd is not None:
            self._enter("ambush" if self._leading(tank) else "watch", t)
            return self._unstick(world, tank, cmd)
        self._enter("wander", t)
        return self._unstick(world, tank, self._wander(world, tank))

    # ------------------------------------------------------------------ kills
    @staticmethod
    def _leading(tank: "Tank") -> bool:
        """Ahead on the HUD's score: more kills than deaths."""
        return tank.kills > tank.deaths

    def _kills(self, tank: "Tank", t: float) -> None:
        """Its kills (the HUD) went up while it was shooting at a target seen in the
        last second: that target is dead, so forget where it was seen."""
        if tank.kills > self.own_kills:
            self.own_kills = tank.kills
            s = self.senses.last_seen.get(self.target) if self.target is not None else None
            if s is not None and t - s.t < 1.0:
                del self.senses.last_seen[self.target]
                self.killed_at = t
            self.enemy_hp.pop(self.target, None)           # it comes back whole
            self.camps.pop(self.target, None)

    def _pick_target(self, seen: list[Sighting]) -> Sighting | None:
        """The current target if still in sight (no dithering), else the nearest."""
        for s in seen:
            if s.index == self.target:
                return s
        return seen[0] if seen else None

    def _estimate(self, t: float) -> tuple[float, float, float | None] | None:
        """Where the enemy probably is, (x, z, height): last seen moved on (up to 2 s),
        or last heard."""
        s = self.senses.last_seen.get(self.target) if self.target is not None else None
        h = self.senses.heard
        if s is not None and (h is None or s.t >= h.t):
            dt = min(t - s.t, 2.0)
            return s.x + s.vx * dt, s.z + s.vz * dt, s.y
        if h is not None:
            return h.x, h.z, h.y
        return None

    # ------------------------------------------------------------------ wander
    def _wander(self, world: "World", tank: "Tank") -> Command:
        """Explore: an A* path to the block that sees the most of what was not seen in
        the last minute, per metre of path (``Coverage.goal``), chosen again when that
        is seen on the way (its gain halved) or reached; with nothing left unseen
        anywhere, the paper's three-node heuristic."""
        t, x, z = world.t, tank.x, tank.z
        cov = self.coverage
        if self.path:
            trim(self.path, x, z)
            arrived = math.hypot(self.path[-1][0] - x, self.path[-1][1] - z) < 4.0
            if not arrived and t >= self.recheck:
                self.recheck = t + 1.0
                if cov.gain(self.goal_cell, t) < 0.5 * self.goal_gain:
                    arrived = True
            if not arrived:
                return self._follow(world, tank, self.path, speed=1.0, lookahead=4.0, corner=self._corner(tank))
            self.path = []
        best = cov.goal(x, z, t, y=tank.y) if self.level.explore else None
        if best is not None:
            cell, gain = best
            gx, gz = self.views.points[cell]
            path = plan_path(self.grid, (x, z, tank.y), (float(gx), float(gz), float(self.views.heights[cell])))
            if path:
                self.path, self.goal_cell, self.goal_gain, self.recheck = path, cell, gain, t + 1.0
                return self._follow(world, tank, self.path, speed=1.0, lookahead=4.0, corner=self._corner(tank))
        return self._heuristic(world, tank)

    def _heuristic(self, world: "World", tank: "Tank") -> Command:
        """The paper's ternary decision with memory: a 12-node route ahead."""
        grid, wand = self.grid, self.wanderer
        x, z = tank.x, tank.z
        while self.route and math.hypot(self.route[0][0] - x, self.route[0][1] - z) < 2.5:
            self.route.pop(0)
        if self.route and math.hypot(self.route[0][0] - x, self.route[0][1] - z) > 5.0:
            self.route, self.walker = [], None       # pushed off the route: start again here
        if self.walker is None:
            n = nearest_valid_node(grid.valid, grid.node_of(x, z), 6)  # type: ignore[union-attr]
            if n is None:
                return self._back_off(tank)
            self.walker = (n, heading_from_angle(tank.heading))
            self.route = []
        while len(self.route) < 12:
            node, h = self.walker
            nxt = wand.choose(node, h, world.t)  # type: ignore[union-attr]
            if nxt is None:
                break
            self.walker = nxt
            point = grid.centre(*nxt[0])  # type: ignore[union-attr]
            if point in self.route:     # a pocket the heuristic only turns about in
                break
            self.route.append(point)
        if not self.route:
            return self._back_off(tank)
        return self._follow(world, tank, self.route, speed=0.85, lookahead=6.0)

    # ------------------------------------------------------------------ search
    def _start_search(self, where: tuple[float, ...], t: float) -> None:
        """Search from (x, z) or (x, z, height) (the height: which level first)."""
        self.plan = SearchPlan(self.grid, where[0], where[1], y=where[2] if len(where) > 2 else None)  # type: ignore[arg-type]
        self.path, self.goal = [], None
        self.state = "wander"  # so _enter resets the route
        self._enter("search", t)

    def _search(self, world: "World", tank: "Tank") -> Command | None:
        t = world.t
        if t - self.state_since > 60.0 or self.plan is None:
            return None
        x, z = tank.x, tank.z
        known = self._known(t)
        if self.level.cover and known is not None and self.plan.k <= 1 and \
                math.hypot(known[0] - x, known[1] - z) < PREAIM:
            # an enemy where it was just seen or heard: close in with the gun on it
            if not self.path or self.goal != known:
                self.goal = known
                self.path = plan_path(self.grid, (x, z, tank.y), known)  # type: ignore[arg-type]
                self.plan.k = 1
            trim(self.path, x, z)
            if self.path and math.hypot(self.path[-1][0] - x, self.path[-1][1] - z) > 4.0:
                return self._approach(world, tank, self.path, known, 0.5 * tank.spec.top_speed)
        if self.goal is not None and math.hypot(self.goal[0] - x, self.goal[1] - z) < 4.0:
            self.goal, self.path = None, []
        tries = 0
        while self.goal is None or not self.path:
            tries += 1
            if tries > 3:
                return self._follow(world, tank, [], speed=0.0, lookahead=4.0) if self.goal else None
            self.goal = self.plan.next_goal(self.memory, t)
            if self.goal is None:
                return None
            self.path = plan_path(self.grid, (x, z, tank.y), self.goal)  # type: ignore[arg-type]
        trim(self.path, x, z)
        return self._follow(world, tank, self.path, speed=0.9, lookahead=4.0, corner=self._corner(tank))

    def _hunt(self, world: "World", tank: "Tank") -> Command | None:
        """A camping enemy is known: drive to the nearest place (by path) that sees it
        from ``stand_off`` +- 15 m (the blocks' line-of-sight table), the gun on it where
        the way comes into its sight.  There and not seeing it: it has gone, forget it.
        None: no camp known."""
        t = world.t
        live = [(ct, i) for i, (_, _, ct, _) in self.camps.items() if t - ct <= CAMP_MEMORY]
        if not live:
            return None
        _, idx = max(live)
        cx, cz, _, face = self.camps[idx]
        v = self.views
        x, z = tank.x, tank.z
        if self.hunt_for != (cx, cz) or t >= self.hunt_replan or not self.path:
            cb, here = v.cell_at(cx, cz), v.cell_at(x, z, tank.y)  # type: ignore[union-attr]
            if cb < 0 or here < 0:
                return None
            lo, hi = self.level.stand_off - 15.0, min(self.level.stand_off + 15.0, self.senses.vision_range)
            dist = v.distance[cb]  # type: ignore[union-attr]
            pd = v.path_distances(here)  # type: ignore[union-attr]
            sees = v.visible[cb] & np.isfinite(pd)  # type: ignore[union-attr]
            ok = sees & (dist >= lo) & (dist <= hi)
            if not ok.any():
                ok = sees & (dist <= hi)
            if not ok.any():
                return None
            # nearest by path, and a place with room to strafe (ROOM each way) counts
            # as much nearer as a tank drives in 2 s
            # and one outside the cone it faced (it does not see us come: first shots
            # are ours) as much nearer as a tank drives in 4 s
            roomy = self._block_room() >= ROOM
            p = v.points  # type: ignore[union-attr]
            off = np.abs(np.remainder(np.arctan2(p[:, 1] - cz, p[:, 0] - cx) - face + np.pi, 2 * np.pi) - np.pi)
            unseen = off > self.senses.half_angle + 0.2
            top = tank.spec.top_speed
            score = pd - np.where(roomy, 2.0 * top, 0.0) - np.where(unseen, 4.0 * top, 0.0)
            b = int(np.argmin(np.where(ok, score, np.inf)))
            gx, gz = (float(c) for c in v.points[b])  # type: ignore[union-attr]
            self.hunt_for, self.hunt_replan = (cx, cz), t + 5.0
            self.path = plan_path(self.grid, (x, z, tank.y), (gx, gz, float(v.heights[b])))  # type: ignore[arg-type]
            if not self.path:
                return None
        trim(self.path, x, z)
        end = self.path[-1]
        if math.hypot(end[0] - x, end[1] - z) < 3.0:
            err = abs(wrap(math.atan2(cz - z, cx - x) - tank.heading))
            if err < 0.3 or t - self.camps[idx][2] > CAMP_MEMORY:
                del self.camps[idx]            # looking at where it was, and it is not there
                return None
            return self._drive(world, tank, 0.0, 0.0, self._turn(tank, wrap(math.atan2(cz - z, cx - x) - tank.heading)))
        return self._follow(world, tank, self.path, speed=1.0, lookahead=4.0, corner=self._corner(tank))

    def _block_room(self) -> np.ndarray:
        """Per block of the sight table: the free space around its representative node
        beyond the grid's clearance [m] (the distance to the nearest invalid node)."""
        if self._room is None:
            from scipy.ndimage import distance_transform_edt

            g = self.grid
            valid = np.asarray(g.layers.valid if g.layers is not None else g.valid, dtype=bool)  # type: ignore[union-attr]
            if valid.ndim == 3:   # a layered grid: each level's own free space
                free = np.stack([distance_transform_edt(v) for v in valid]) * g.cell  # type: ignore[union-attr]
            else:
                free = distance_transform_edt(valid) * g.cell  # type: ignore[union-attr]
            self._room = np.array([free[tuple(n)] for n in self.views.nodes])  # type: ignore[union-attr]
        return self._room

    def _known(self, t: float) -> tuple[float, float] | None:
        """Where the target was seen (in the last ``KNOWN`` s, standing still, or in the
        last 3 s, moved on) or a shot was heard (in the last 3 s); None if neither."""
        s = self.senses.last_seen.get(self.target) if self.target is not None else None
        if s is not None and t - s.t < (KNOWN if math.hypot(s.vx, s.vz) < STILL else 3.0):
            dt = min(t - s.t, 2.0)
            return s.x + s.vx * dt, s.z + s.vz * dt
        h = self.senses.heard
        if h is not None and not h.engine and t - h.t < 3.0:
            return h.x, h.z
        return None

    # ------------------------------------------------------------------ attack
    def _losing(self, world: "World", tank: "Tank", s: Sighting) -> bool:
        """Down to two hits or less and behind the enemy by more than a hit (its hit
        points counted from ours that hit it, as a player counts them)."""
        dmg = tank.spec.shell_damage
        theirs = self.enemy_hp.get(s.index, world.tanks[s.index].spec.hit_points)
        return tank.hp <= 2.0 * dmg and tank.hp < theirs - dmg

    def _count_hits(self, world: "World", tank: "Tank") -> None:
        """Our hits since the last think went to the target: its hit points by our count."""
        if tank.hits > self.own_hits and self.target is not None:
            e = world.tanks[self.target]
            left = self.enemy_hp.get(self.target, e.spec.hit_points)
            self.enemy_hp[self.target] = left - (tank.hits - self.own_hits) * tank.spec.shell_damage
        self.own_hits = tank.hits

    def _attack(self, world: "World", tank: "Tank", s: Sighting) -> Command:
        """Turn onto the intercept point, fire when the shot would hit, hold the
        level's fighting distance, strafe.

        The lead is the exact intercept (``aim.intercept``) of the velocity seen (the
        level's ``lead`` share of it, relative to our own), off by the aim error drawn
        after each shot.  The gun fires when a shell leaving at the next chance to fire
        (the reload left, the hull still turning) would pass within ``fire_tolerance``
        of the enemy's half width of where it aims -- not at an enemy under spawn
        protection until that ends before the shell arrives.  It strafes at speed,
        flipping side every ``FLIP`` s and away from walls: a tank that strafes can dodge
        by stopping (``_evade_shells``)."""
        lv = self.level
        t = world.t
        v = tank.spec.shell_speed
        dx, dz = s.x - tank.x, s.z - tank.z
        d = max(math.hypot(dx, dz), 1e-6)
        tvx = tank.vx + lv.lead * (s.vx - tank.vx)
        tvz = tank.vz + lv.lead * (s.vz - tank.vz)
        sol = gun.intercept(tank.x, tank.z, tank.vx, tank.vz, s.x, s.z, tvx, tvz, v)
        if sol is not None and lv.hedge > 0.0 and sol.time > lv.hedge:
            # the enemy goes on (at sol.time) or stops (about hedge s after the shot):
            # aim at the middle, which hits both while they lie within its width (its
            # own velocity only: ours the shell keeps whatever the enemy does)
            k = 0.5 * (sol.time + lv.hedge) / sol.time
            tvx = tank.vx + lv.lead * (k * s.vx - tank.vx)
            tvz = tank.vz + lv.lead * (k * s.vz - tank.vz)
            sol = gun.intercept(tank.x, tank.z, tank.vx, tank.vz, s.x, s.z, tvx, tvz, v) or sol
        heading = sol.heading if sol is not None else math.atan2(dz, dx)
        err = wrap(heading + self.aim_error - tank.heading)
        rotate = self._turn(tank, err)
        fire = False
        hesitant = lv.trigger > 0.0 and t - self.fired_at < tank.spec.fire_interval + lv.trigger
        if tank.reload <= self.period and sol is not None and s.protected <= sol.time and not hesitant:
            delay = max(tank.reload, world.dt)
            miss = gun.predicted_miss(tank.x, tank.z, tank.vx, tank.vz, tank.heading - self.aim_error, s.x, s.z,
                                      tvx, tvz, v, delay, tank.omega)
            e = world.tanks[s.index]
            fire = miss < lv.fire_tolerance * half_extent_at(e.spec, s.heading, heading)
            if fire and world.ground is not None:
                # on relief the hull's pitch aims the gun up or down: hold fire when
                # the shell would pass over or under the enemy
                fire = gun.height_miss(world.eye(tank), tank.pitch, v, world.rules.shell_gravity, d,
                                       s.y, e.spec.height) < HEIGHT_TOLERANCE
        if fire:
            self.aim_error = self.rng.gauss(0.0, lv.aim_noise)
            self.fired_at = t
        top = tank.spec.top_speed
        cover = self._cover_behind(world, tank, s) if lv.cover and lv.scoot and tank.reload > SCOOT else None
        if cover is not None:
            # just fired: back behind the corner while the gun reloads, gun on the enemy
            cmd = self._approach(world, tank, [cover], (s.x, s.z), 0.5 * top)
            return Command(cmd.advance, cmd.rotate, cmd.strafe, fire)
        aligned = max(0.0, 1.0 - abs(err) / 0.6)
        engage = lv.stand_off if math.hypot(s.vx, s.vz) < STILL else lv.engage
        forward = max(-0.5 * top, min(0.5 * top, 0.4 * (d - engage))) * aligned
        side, room = self._strafe_side(world, tank, t)
        if forward < 0.0 and self._free(world, tank, tank.heading + math.pi, 3.0 * ROOM, (0.0,)) < 2.0 * ROOM:
            forward = 0.0                       # no backing into a wall or a corner
        if room < ROOM:
            forward = 0.5 * top * aligned       # boxed in across the line of fire: out, forwards
        lateral = side * 0.5 * top * (0.4 + 0.6 * aligned)
        return self._drive(world, tank, forward, lateral, rotate, fire)

    def _cover_behind(self, world: "World", tank: "Tank", s: Sighting) -> tuple[float, float] | None:
        """The latest place on our way here (the last ``TRAIL`` s) that the enemy cannot
        see, if it is 1.5-10 m away: the corner we came round."""
        near = []
        for _, x, z, y in reversed(self.trail):
            d = math.hypot(x - tank.x, z - tank.z)
            if d > 10.0:
                break
            if d > 1.5:
                near.append((x, z, y))
        # all the lines from the enemy at once (one array lookup on a ground)
        for (x, z, _), hidden in zip(near, world.blocked_from(s.x, s.z, _eye(s.y), near)):
            if hidden:
                return x, z
        return None

    def _strafe_side(self, world: "World", tank: "Tank", t: float) -> tuple[float, float]:
        """The side to strafe to (+1 right, -1 left) and the room [m] there: the same
        side until a random flip every 4-8 s or until there is less than ``ROOM``
        that way, then the side with more room."""
        look = tank.spec.radius + 2.0 * ROOM
        room = {k: self._free(world, tank, tank.heading + k * math.pi / 2, look, (0.0,)) - tank.spec.radius
                for k in (1.0, -1.0)}
        if t >= self.dodge_flip:
            self.dodge_flip = t + self.rng.uniform(*FLIP)
            if room[-self.dodge] >= ROOM:
                self.dodge = -self.dodge
        if room[self.dodge] < ROOM and room[-self.dodge] > room[self.dodge]:
            self.dodge = -self.dodge
        return self.dodge, room[self.dodge]

    # ------------------------------------------------------------------ watch
    def _watch(self, world: "World", tank: "Tank") -> Command | None:
        """Hold a vantage point: the nearest block (by path) whose cone sees the most of
        the arena, chosen again every 5 s; there, face its best way and sweep the cone
        ``SWEEP`` either side.  None: no vantage in this arena, or exploring (after
        ``WATCH_STINT`` s of watching, while more than ``STALE`` of the blocks are stale:
        not seen for a minute).

        Leading, in any arena and without exploring: the same at the safest place near
        by, chosen again (away from the noise) at most every 2 s while a tank is heard;
        facing the way the heard tank would come in (the first leg of the path towards
        it)."""
        v = self.vantages
        lead = self._leading(tank)
        if not self.watches or v is None or (v.top < WATCH_COVER and not lead):
            return None
        t = world.t
        if not lead:
            stale = self.coverage.stale_fraction(t) > STALE  # type: ignore[union-attr]
            if self.exploring:
                if stale:
                    return None
                self.exploring = False
            if self.state == "watch" and t - self.state_since > WATCH_STINT and stale:
                self.exploring = True
                return None
        x, z = tank.x, tank.z
        h = self.senses.heard
        noise = h if (lead and h is not None and t - h.t < 2.0) else None
        if noise is not None and noise.t == t:
            self.spot_replan = min(self.spot_replan, self.spot_chosen + 2.0)
        if self.spot is None or t >= self.spot_replan or lead != self.spot_ambush:
            self.spot_replan, self.spot_chosen, self.spot_ambush = t + 5.0, t, lead
            here = self.views.cell_at(x, z, tank.y)  # type: ignore[union-attr]
            if lead:
                away = self.views.cell_at(noise.x, noise.z, noise.y) if noise is not None else -1  # type: ignore[union-attr]
                cell, face = v.safest(here, AMBUSH_PER_M, away, AMBUSH_AWAY, AMBUSH_AWAY_CAP)
            else:
                cell, face = v.best(here, WATCH_PER_M)
            spot = tuple(float(c) for c in self.views.points[cell])  # type: ignore[union-attr]
            self.spot_face = face
            if spot != self.spot or not self.spot_path:
                self.spot = spot  # type: ignore[assignment]
                self.spot_path = plan_path(self.grid, (x, z, tank.y), (*spot, float(self.views.heights[cell])))  # type: ignore[arg-type]
        gx, gz = self.spot  # type: ignore[misc]
        path = self.spot_path
        if math.hypot(gx - x, gz - z) > 2.5 and path:
            trim(path, x, z)
            return self._follow(world, tank, path, speed=1.0, lookahead=4.0, corner=path[0], stop=True)
        # a triangle wave: the cone sweeps at a steady SWEEP_RATE, to and fro
        phase = (t * SWEEP_RATE / (2.0 * SWEEP)) % 2.0
        face = self.spot_face
        if lead and h is not None and t - h.t < 3.0:
            if self.faced is None or self.faced[0] is not h:
                path = plan_path(self.grid, (x, z, tank.y), (h.x, h.z, h.y))  # type: ignore[arg-type]
                q = next((q for q in path if math.hypot(q[0] - x, q[1] - z) >= 6.0), path[-1] if path else (h.x, h.z))
                self.faced = (h, math.atan2(q[1] - z, q[0] - x))
            face = self.faced[1]
        look = face + SWEEP * (2.0 * abs(phase - 1.0) - 1.0)
        err = wrap(look - tank.heading)
        return self._drive(world, tank, 0.0, 0.0, self._turn(tank, err))

    # ------------------------------------------------------------------ return fire
    def _return_fire(self, world: "World", tank: "Tank") -> Command | None:
        """Hit just now by a tank it cannot see, whose shot it heard from a place in its
        line of sight: turn on the spot to face there, until facing it (then it is seen
        and attacked, or was not there), for at most ``RETURN_FIRE`` s.  None: nothing
        to return."""
        t = world.t
        h = self.senses.heard            # the shot: fired up to half a second before the hit
        if self.hits and self.hits[-1] == t and h is not None and not h.engine and t - h.t < 0.5 \
                and not world.line_blocked(tank.x, tank.z, h.x, h.z, world.eye(tank), _eye(h.y)):
            self.return_to = (math.atan2(h.z - tank.z, h.x - tank.x), t + RETURN_FIRE)
        face, until = self.return_to
        err = wrap(face - tank.heading)
        if t >= until or abs(err) < 0.15:
            self.return_to = (face, -math.inf)
            return None
        return self._drive(world, tank, 0.0, 0.0, self._turn(tank, err))

    # ------------------------------------------------------------------ evade
    def _start_evade(self, world: "World", tank: "Tank", threat: tuple[float, ...], t: float) -> None:
        self.threat = threat
        self.state = "wander"
        self._enter("evade", t)
        self.evade_until = t + 5.0
        self.path = []
        cover = self._cover(world, tank, threat)
        if cover is not None:
            self.path = plan_path(self.grid, (tank.x, tank.z, tank.y), cover)  # type: ignore[arg-type]

    def _cover(self, world: "World", tank: "Tank", threat: tuple[float, ...]) -> tuple[float, float] | None:
        """The nearest of a few sampled nodes 5-25 m away that the threat (x, z and
        maybe its height) cannot see."""
        grid = self.grid
        i, j = grid.node_of(tank.x, tank.z)  # type: ignore[union-attr]
        r = int(25.0 / grid.cell)  # type: ignore[union-attr]
        i0, j0 = max(i - r, 0), max(j - r, 0)
        win = grid.valid[i0:i + r + 1, j0:j + r + 1]  # type: ignore[union-attr]
        a, b = win.nonzero()
        if len(a) == 0:
            return None
        best, best_d = None, math.inf
        for k in range(24):
            m = self.rng.randrange(len(a))
            cx, cz = grid.centre(int(a[m]) + i0, int(b[m]) + j0)  # type: ignore[union-attr]
            d = math.hypot(cx - tank.x, cz - tank.z)
            if 5.0 <= d < best_d and world.line_blocked(threat[0], threat[1], cx, cz,
                                                         _eye(threat[2] if len(threat) > 2 else None)):
                best, best_d = (cx, cz), d
        return best

    def _evade(self, world: "World", tank: "Tank", sight: Sighting | None) -> Command | None:
        t = world.t
        if t >= self.evade_until:
            return None
        x, z = tank.x, tank.z
        trim(self.path, x, z)
        if self.path:
            if math.hypot(self.path[-1][0] - x, self.path[-1][1] - z) < 3.0:
                return None
            return self._follow(world, tank, self.path, speed=1.0, lookahead=4.0, corner=self._corner(tank))
        # no cover near: strafe hard across the threat's line, gun on it when seen
        if sight is not None:
            cmd = self._attack(world, tank, sight)
            return self._drive(world, tank, 0.0, self.dodge * 0.5 * tank.spec.top_speed, cmd.rotate, cmd.fire)
        return self._follow(world, tank, [], speed=0.0, lookahead=4.0)

    # ------------------------------------------------------------------ driving
    def _follow(self, world: "World", tank: "Tank", points: list[tuple[float, float]], speed: float,
                lookahead: float, corner: tuple[float, float] | None = None, stop: bool = False) -> Command:
        """``Pilot._follow``; but with ``cover``, where the way ahead comes into the sight
        of a known camping enemy, along it with the gun on that enemy (``_approach``)."""
        camp = self._camp_ahead(world, tank, points) if self.level.cover and points else None
        if camp is not None:
            return self._approach(world, tank, points, camp, min(speed * tank.spec.top_speed, CAMP_SPEED))
        return super()._follow(world, tank, points, speed, lookahead, corner, stop)

    def _camp_ahead(self, world: "World", tank: "Tank", points: list[tuple[float, float]]
                    ) -> tuple[float, float] | None:
        """A camping enemy remembered (``CAMP_MEMORY`` s, within vision range) that sees
        us here or at the first point of the way at least 6 m ahead."""
        t, x, z = world.t, tank.x, tank.z
        ahead = next((p for p in points if math.hypot(p[0] - x, p[1] - z) >= 6.0), points[-1])
        best, best_d = None, math.inf
        for cx, cz, ct, _ in self.camps.values():
            d = math.hypot(cx - x, cz - z)
            if t - ct > CAMP_MEMORY or d > self.senses.vision_range or d >= best_d:
                continue
            if not world.line_blocked(x, z, cx, cz, world.eye(tank)) or not world.line_blocked(ahead[0], ahead[1], cx, cz):
                best, best_d = (cx, cz), d
        return best

    def _on_path(self) -> bool:
        return bool(self.path or self.route)

    def _replan(self) -> None:
        self.route, self.walker, self.path, self.spot_path = [], None, [], []

    def _corner(self, tank: "Tank") -> tuple[float, float] | None:
        """The next waypoint of the A* path where it bends (the path's end counts)."""
        return self.path[0] if self.path else None


#: a shot on relief may pass this far over or under the enemy's body [m] (its
#: sphere tree is rounder than the box the test assumes)
HEIGHT_TOLERANCE = 0.25


def _eye(y: float | None) -> float | None:
    """The eye height over a tank standing at ``y`` (None: not known)."""
    return None if y is None else y + EYE


def make_agents(world: "World", level: str | Difficulty = "normal",
                which: range | list[int] | None = None) -> list[Agent]:
    """One agent per tank (or per index in ``which``), each seeded from the world's generator."""
    idx = range(len(world.tanks)) if which is None else which
    return [Agent(random.Random(world.rng.getrandbits(64)), level) for _ in idx]
