"""The computer opponent: a small state machine over sensors and ``Command`` values.

States (each a method ``_wander``, ``_watch``, ``_search``, ``_attack``, ``_evade``
that returns the command for this think; ``_watch`` plays Watch and Ambush):

* **Wander** (start): explore.  A* to the block that sees the most of what was not
  seen in the last minute per metre of path (``navigation.Coverage.goal``: the sight
  memory); when nothing is left unseen, a route of grid nodes chosen by the paper's
  three-node heuristic with memory (``navigation.Wanderer``).
* **Search** (an enemy was seen or heard, and is not in sight): the quadrant search
  (``navigation.SearchPlan``), A* paths to each quadrant's centre.
* **Attack** (an enemy in sight and the reaction time passed): the fuzzy controller
  (``fuzzy.AttackController``) turns, advances or backs off, strafes to dodge, fires.
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

from ...nav.navgrid import nearest_valid_node
from ...nav.steering import heading_from_angle
from ..commands import IDLE, Command
from .fuzzy import PREDICT, AttackController, FIRE_THRESHOLD
from .navigation import (EYE, Coverage, Memory, SearchPlan, Vantages, Wanderer, agent_grid, plan_path, vantages_for,
                         views_for)
from .perception import Senses, Sighting, wrap

if TYPE_CHECKING:  # pragma: no cover
    from ..body import Tank
    from ..world import World

#: corners: braking at this fraction of the engine's deceleration, and up to this much
#: faster than 3 m/s through a bend gentler than a right angle [m/s]
CORNER_BRAKE = 0.8
CORNER_FAST = 6.0
STATES = ("wander", "watch", "ambush", "search", "attack", "evade")
#: a vantage point sees at least this fraction of the arena's blocks in one cone
WATCH_COVER = 0.4
#: choosing a vantage: its cover less this much per metre of path to it
WATCH_PER_M = 0.004
#: watch this long [s] before going to look at what has not been seen for a minute
WATCH_STINT = 30.0
#: ... if more than this fraction of the arena's blocks has not been seen for a minute
STALE = 0.2
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


DIFFICULTIES: dict[str, Difficulty] = {
    "easy": Difficulty("easy", reaction=0.6, aim_noise=math.radians(4.0), vision_range=60.0,
                       hearing_radius=50.0, think_hz=8.0, engine_radius=25.0),
    "normal": Difficulty("normal", reaction=0.2, aim_noise=math.radians(1.5), vision_range=90.0,
                         hearing_radius=80.0, think_hz=15.0, engine_radius=35.0),
    "hard": Difficulty("hard", reaction=0.1, aim_noise=math.radians(0.5), vision_range=130.0,
                       hearing_radius=120.0, think_hz=20.0, engine_radius=40.0),
}


def difficulty(name: str | Difficulty) -> Difficulty:
    """A difficulty by name (easy, normal, hard)."""
    if isinstance(name, Difficulty):
        return name
    try:
        return DIFFICULTIES[name]
    except KeyError:
        raise ValueError(f"difficulty must be one of {', '.join(DIFFICULTIES)}, got {name!r}") from None


class Agent:
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
        self.controller: AttackController | None = None
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
        self.threat: tuple[float, float] | None = None
        # attack
        self.target: int | None = None
        self.acquired_at = math.inf
        self.aim_error = rng.gauss(0.0, self.level.aim_noise)
        self.dodge = 1.0 if rng.random() < 0.5 else -1.0
        self.dodge_flip = 0.0
        self.hits: list[float] = []
        # its own kills (the HUD), and when the target last died at its hands
        self.own_kills = 0
        self.killed_at = -math.inf
        # watching: the vantage table, the spot chosen, the way it faces, the path there
        self.watches = watch
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
        # stuck recovery
        self.progress_at = (0.0, math.nan, math.nan)
        self.reverse_until = -math.inf
        self.reverse_turn = 1.0

    # ------------------------------------------------------------------ driver
    def __call__(self, world: "World", tank: "Tank") -> Command:
        if not tank.alive:
            self._reset()
            return IDLE
        if world.t + 1e-12 < self.next_think:
            return self.command
        self.next_think = world.t + self.period
        self.command = self.think(world, tank)
        return self.command

    def _reset(self) -> None:
        self.state = "wander"
        self.route, self.walker, self.path, self.plan, self.goal = [], None, [], None, None
        self.target, self.acquired_at = None, math.inf
        self.hits = []
        self.spot, self.spot_replan, self.spot_path, self.exploring = None, -math.inf, [], False
        self.return_to = (0.0, -math.inf)
        self.senses.hp = math.inf
        self.reverse_until = -math.inf
        self.next_think = -math.inf

    def _setup(self, world: "World", tank: "Tank") -> None:
        self.grid = agent_grid(world, self.cell, tank.spec.radius + self.margin)
        self.memory = Memory(self.grid, region=16.0)
        self.wanderer = Wanderer(self.grid, self.memory, self.rng)
        self.controller = AttackController(tank.spec.shell_speed)
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
        self._kills(tank, t)

        sight = self._pick_target(seen)
        if sight is not None:
            fresh = previous is None or previous.index != sight.index or t - previous.t > 1.0
            if self.target != sight.index or fresh:
                self.acquired_at = t + self.level.reaction
            self.target = sight.index

        if self.state != "evade" and sight is None and len(self.hits) >= 2 and t >= self.evade_cooldown:
            threat = (sight.x, sight.z, sight.y) if sight else self._estimate(t)
            if threat is not None:
                self._start_evade(world, tank, threat, t)
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
        best = cov.goal(x, z, t, y=tank.y)
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

    # ------------------------------------------------------------------ attack
    def _attack(self, world: "World", tank: "Tank", s: Sighting) -> Command:
        ctl = self.controller
        t = world.t
        dx, dz = s.x - tank.x, s.z - tank.z
        d = max(math.hypot(dx, dz), 1e-6)
        px, pz = -dz / d, dx / d       # the right of the line of sight
        v_lat = (s.vx - tank.vx) * px + (s.vz - tank.vz) * pz
        aim = math.atan2(dz, dx) + ctl.lead(v_lat) + self.aim_error  # type: ignore[union-attr]
        err = wrap(aim - tank.heading)
        out = ctl(err, tank.omega, d)  # type: ignore[misc]
        fire = out.fire >= FIRE_THRESHOLD and tank.reload <= self.period
        if fire:
            self.aim_error = self.rng.gauss(0.0, self.level.aim_noise)
        if t >= self.dodge_flip:
            self.dodge = -self.dodge
            self.dodge_flip = t + self.rng.uniform(1.0, 2.5)
        top = tank.spec.top_speed
        advance, strafe = out.advance, out.strafe_size
        lateral = self._dodge_side(world, tank) * strafe * 0.5 * top
        return self._drive(world, tank, advance * 0.5 * top, lateral, out.rotate, fire)

    def _dodge_side(self, world: "World", tank: "Tank") -> float:
        """The dodge direction, flipped when a wall is near on that side."""
        angle = tank.heading + self.dodge * math.pi / 2
        if self._free(world, tank, angle, tank.spec.radius + 6.0, (0.0,)) < tank.spec.radius + 5.0:
            self.dodge = -self.dodge
        return self.dodge

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
            if cell < 0:            # off the map (no valid node near): nothing to watch from
                self.spot = None
                return None
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
        """Pure pursuit of the first point at least ``lookahead`` away (or the last),
        at up to ``speed`` x top speed, slowing to turn and for ``corner`` (the next
        waypoint where the path bends); ``stop``: braking to stand at the last point."""
        if not points:
            return self._drive(world, tank, 0.0, 0.0, 0.0)
        x, z = tank.x, tank.z
        tx, tz = points[-1]
        for p in points:
            if math.hypot(p[0] - x, p[1] - z) >= lookahead:
                tx, tz = p
                break
        err = wrap(math.atan2(tz - z, tx - x) - tank.heading)
        rotate = self._turn(tank, err)
        top = tank.spec.top_speed
        # turn first, then drive: full speed only when pointing the right way
        v = speed * top * max(0.0, 1.0 - abs(err) / 1.2)
        if corner is not None:
            # the speed to take the bend at: 3 m/s for a right angle or sharper, more
            # for a gentler one; braking at CORNER_BRAKE of the engine's deceleration
            brake = CORNER_BRAKE * tank.spec.engine_force / tank.spec.mass
            bend = math.pi / 2
            k = points.index(corner) if corner in points else -1
            if 0 <= k < len(points) - 1:
                nx, nz = points[k + 1]
                bend = abs(wrap(math.atan2(nz - corner[1], nx - corner[0]) - math.atan2(corner[1] - z, corner[0] - x)))
            vc = 3.0 + CORNER_FAST * max(0.0, 1.0 - bend / (math.pi / 2))
            v = min(v, vc + math.sqrt(2.0 * brake * math.hypot(corner[0] - x, corner[1] - z)))
        if stop:
            # planned at half the corner braking: the speed controller lags the wish
            brake = 0.5 * CORNER_BRAKE * tank.spec.engine_force / tank.spec.mass
            v = min(v, math.sqrt(2.0 * brake * math.hypot(points[-1][0] - x, points[-1][1] - z)))
        return self._drive(world, tank, v, 0.0, rotate)

    def _turn(self, tank: "Tank", err: float) -> float:
        """The turn command for a heading error, read where the gun will point
        ``PREDICT`` s from now (the fuzzy turn rules)."""
        return self.controller.turn(err - PREDICT * tank.omega)  # type: ignore[union-attr]

    def _free(self, world: "World", tank: "Tank", angle: float, length: float, offsets: tuple[float, ...]) -> float:
        """Free distance along ``angle`` from points beside the centre, up to ``length``."""
        c, s = math.cos(angle), math.sin(angle)
        best = length
        for o in offsets:
            ox, oz = tank.x - s * o, tank.z + c * o
            hit = world.walls_of(tank).first_hit(ox, oz, ox + c * length, oz + s * length)
            if hit is not None:
                best = min(best, hit[0] * length)
        return best

    def _drive(self, world: "World", tank: "Tank", forward: float, lateral: float, rotate: float,
               fire: bool = False) -> Command:
        """Commands that reach a wanted forward and sideways speed [m/s] (+ = right).

        Tracks coast far on their own (the rolling drag is weak), so speed is
        controlled, braking included, and capped by the walls: the speed from which
        the tank can still stop, at 60 % of its engine's deceleration, before its
        centre comes within footprint radius + 1 m of a wall.  Feelers are rays from
        the centre and beside it, along the way the tank is going.
        """
        spec = tank.spec
        c, s = tank.c, tank.s
        vf = tank.vx * c + tank.vz * s
        vr = -tank.vx * s + tank.vz * c
        bx0, bz0, bx1, bz1 = spec.box
        half = 0.5 * (bz1 - bz0)
        length = 0.5 * (bx1 - bx0)
        if abs(forward) > 0.05:
            brake = 0.8 * spec.engine_force / spec.mass
            stop = (bx1 if forward > 0 else -bx0) + 1.0
            reach = stop + forward * forward / (2.0 * brake) + 1.0
            angle = tank.heading if forward > 0 else tank.heading + math.pi
            free = self._free(world, tank, angle, reach, (0.0, half, -half))
            forward = math.copysign(min(abs(forward), math.sqrt(2.0 * brake * max(free - stop, 0.0))), forward)
        if abs(lateral) > 0.05:
            brake = 0.6 * spec.strafe_force / spec.mass
            stop = spec.radius + 1.0
            angle = tank.heading + math.copysign(math.pi / 2, lateral)
            free = self._free(world, tank, angle, stop + 10.0, (0.0, 0.8 * length, -0.8 * length))
            lateral = math.copysign(min(abs(lateral), math.sqrt(2.0 * brake * max(free - stop, 0.0))), lateral)
        # a wall closer than the footprint radius + 1.5 m pushes the tank away: turning
        # in place sweeps the whole footprint circle, and attack moves go anywhere
        push = spec.radius + 1.5
        px = pz = 0.0
        walls = world.walls_of(tank)
        for k in walls.near(tank.x, tank.z, push):
            w = walls.walls[k]
            ax, az, ex, ez, l2, _ = w  # type: ignore[misc]
            u = min(max(((tank.x - ax) * ex + (tank.z - az) * ez) / l2, 0.0), 1.0)
            dx, dz = tank.x - (ax + u * ex), tank.z - (az + u * ez)
            d = math.hypot(dx, dz)
            if d > 1e-9:
                px += dx / d * (push - d)
                pz += dz / d * (push - d)
        if px or pz:
            forward += 2.0 * (px * c + pz * s)
            lateral += 2.0 * (-px * s + pz * c)
        top = spec.top_speed
        advance = forward / top + 0.3 * (forward - vf)
        strafe = lateral / (0.5 * top) + 0.3 * (lateral - vr)
        return Command(advance=advance, rotate=rotate, strafe=strafe, fire=fire)

    def _corner(self, tank: "Tank") -> tuple[float, float] | None:
        """The next waypoint of the A* path where it bends (the path's end counts)."""
        return self.path[0] if self.path else None

    def _back_off(self, tank: "Tank") -> Command:
        return Command(advance=-0.3, rotate=self.reverse_turn)

    def _unstick(self, world: "World", tank: "Tank", cmd: Command) -> Command:
        """Pushing (or held still on a path) but not moving for a second: reverse and
        turn for 0.8 s, then replan."""
        t = world.t
        if t < self.reverse_until:
            back = self._free(world, tank, tank.heading + math.pi, 8.0, (0.0,))
            ahead = self._free(world, tank, tank.heading, 8.0, (0.0,))
            return self._drive(world, tank, -4.0 if back >= ahead else 4.0, 0.0, self.reverse_turn)
        t0, x0, z0 = self.progress_at
        # pushing, or on a path and neither driving nor turning (a wall feeler holding
        # it still, facing the next waypoint past a corner)
        pushing = abs(cmd.advance) >= 0.3 or (bool(self.path or self.route) and abs(cmd.rotate) < 0.1
                                               and abs(tank.omega) < 0.1)
        if not pushing or not math.isfinite(x0) or math.hypot(tank.x - x0, tank.z - z0) > 0.5:
            self.progress_at = (t, tank.x, tank.z)
            return cmd
        if t - t0 > 1.0:
            # back out the way there is room for, turning; then plan afresh from here
            self.reverse_until = t + 0.8
            self.reverse_turn = 1.0 if self.rng.random() < 0.5 else -1.0
            self.progress_at = (t + 0.8, math.nan, math.nan)
            self.route, self.walker, self.path, self.spot_path = [], None, [], []
            return self._drive(world, tank, -4.0, 0.0, self.reverse_turn)
        return cmd


def _eye(y: float | None) -> float | None:
    """The eye height over a tank standing at ``y`` (None: not known)."""
    return None if y is None else y + EYE


def trim(path: list[tuple[float, float]], x: float, z: float, reach: float = 3.0) -> None:
    """Drop the waypoints of ``path`` already within ``reach`` m of (x, z), keeping the last."""
    while len(path) > 1 and math.hypot(path[0][0] - x, path[0][1] - z) < reach:
        path.pop(0)


def make_agents(world: "World", level: str | Difficulty = "normal",
                which: range | list[int] | None = None) -> list[Agent]:
    """One agent per tank (or per index in ``which``), each seeded from the world's generator."""
    idx = range(len(world.tanks)) if which is None else which
    return [Agent(random.Random(world.rng.getrandbits(64)), level) for _ in idx]
