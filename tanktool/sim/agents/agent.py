"""The computer opponent: a small state machine over sensors and ``Command`` values.

States (each a method ``_wander``, ``_search``, ``_attack``, ``_evade``, ``_hide``
that returns the command for this think):

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
* **Hide** (protecting a lead: ahead on the scoreboard and damaged, or ahead with
  less than ``LATE`` s on the clock): drive to a block out of the threats' line of
  sight (the enemy seen, else where one was last seen or heard, else the spawn
  points), far from them, and watch the way they would come, sweeping the cone.
  Cornered (the enemy closer than ``CORNERED`` m, or its gun pointing within 60° of
  us) or with no block out of its sight: Attack.  Level or behind: never hides.

Transitions, checked every think (``think_hz`` times a second; the command is held in
between, as a person holds a key)::

    any      --enemy seen, reaction time over-->  Attack
    Attack   --enemy lost-->                      Search (from where it was last seen, moved on)
    Wander   --shot heard / hit taken-->          Search (from the shot / from behind us)
    Search   --all quadrants done, or 60 s-->     Wander
    any      --hit repeatedly-->                  Evade --cover reached or 5 s--> Search
    any      --protecting a lead, a block out of sight-->  Hide --not protecting--> Search
    Hide     --enemy seen and cornered-->         Attack

Wander and Search also take a heard engine (a moving tank within the engine-hearing
radius, through walls) as they take a heard shot.

Everything the agent knows comes from ``perception.Senses`` (sight, hearing of shots
and engines, memory, its own hit points), what a player's HUD shows (its own kills,
hits landed and hit points, the scoreboard's kills, the match clock when told its
length) and the static map (walls, spawn points and its navigation grid); it acts only
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
from .fuzzy import PREDICT, AttackController, FIRE_THRESHOLD
from .navigation import Coverage, Memory, SearchPlan, Wanderer, agent_grid, plan_path, views_for
from .perception import Senses, Sighting, wrap

if TYPE_CHECKING:  # pragma: no cover
    from ..body import Tank
    from ..world import World

#: corners: braking at this fraction of the engine's deceleration, and up to this much
#: faster than 3 m/s through a bend gentler than a right angle [m/s]
CORNER_BRAKE = 0.8
CORNER_FAST = 6.0
STATES = ("wander", "search", "attack", "evade", "hide")
#: protecting a lead: also when ahead with this little of the match left [s]
LATE = 15.0
#: ... and fighting anyway when the enemy is this close [m]
CORNERED = 20.0
#: a sighting or a heard position older than this is no threat to hide from [s]
THREAT_MEMORY = 10.0
#: a hiding agent sweeps its cone this far either side of the way danger comes [rad]
SWEEP = 0.4
SWEEP_RATE = 0.35


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
    match_seconds : the match's length, as the HUD's clock shows it (None: unknown;
        then only damage decides when to protect a lead)
    """

    def __init__(self, rng: random.Random, level: str | Difficulty = "normal", *,
                 half_angle: float = math.radians(60.0), cell: float = 1.0, margin: float = 0.5,
                 match_seconds: float | None = None) -> None:
        self.level = difficulty(level)
        self.rng = rng
        self.match_seconds = match_seconds
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
        # the score as the agent saw it: its own hits and kills, and the hits it saw land
        # on each enemy since that enemy's last death at its hands
        self.own_hits = 0
        self.own_kills = 0
        self.enemy_hits: dict[int, int] = {}
        # hiding (protecting a lead)
        self.hide_goal: tuple[float, float] | None = None
        self.hide_path: list[tuple[float, float]] = []
        self.hide_face = 0.0
        self.hide_replan = -math.inf
        self.hide_exposure = 1.0
        self.threats: list[tuple[float, float]] = []
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
        self.hide_goal, self.hide_replan, self.hide_path = None, -math.inf, []
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
        self.coverage.look(tank.x, tank.z, tank.heading, t)  # type: ignore[union-attr]
        previous = self.senses.last_seen.get(self.target) if self.target is not None else None
        seen = self.senses.look(world, tank)
        heard = self.senses.listen(world, tank)
        engine = self.senses.listen_engines(world, tank)
        if heard is None:
            heard = engine
        if self.senses.hit_taken(tank) > 0.0:
            self.hits.append(t)
        self.hits = [h for h in self.hits if t - h < 4.0]
        self._score(tank)

        sight = self._pick_target(seen)
        if sight is not None:
            fresh = previous is None or previous.index != sight.index or t - previous.t > 1.0
            if self.target != sight.index or fresh:
                self.acquired_at = t + self.level.reaction
            self.target = sight.index

        if self.state != "evade" and sight is None and len(self.hits) >= 2 and t >= self.evade_cooldown:
            threat = (sight.x, sight.z) if sight else self._estimate(t)
            if threat is not None:
                self._start_evade(world, tank, threat, t)
        if self.state == "evade":
            cmd = self._evade(world, tank, sight)
            if cmd is not None:
                return self._unstick(world, tank, cmd)
            self.evade_cooldown = t + 8.0
            self._start_search(self.threat or (tank.x, tank.z), t)

        protect = self.protecting(world, tank)
        if protect and sight is not None and t < self.acquired_at:
            # seen, not reacted to yet: carry on (hiding as before, if it was)
            sight = None if self.state == "hide" else sight
        if protect and (sight is None or t >= self.acquired_at):
            if sight is not None and self._cornered(tank, sight):
                self._enter("attack", t)
                return self._attack(world, tank, sight)
            cmd = self._hide(world, tank, sight, heard)
            if cmd is not None and self.hide_exposure < 0.5:
                self._enter("hide", t)
                return self._unstick(world, tank, cmd)
            if sight is not None:                  # nowhere out of its sight: fight
                self._enter("attack", t)
                return self._attack(world, tank, sight)
        if self.state == "hide":
            est = self._estimate(t)
            self._start_search(est if est is not None else (tank.x, tank.z), t)

        if sight is not None and t >= self.acquired_at:
            self._enter("attack", t)
            return self._attack(world, tank, sight)
        if sight is None and self.state == "attack":
            est = self._estimate(t)
            self._start_search(est if est is not None else (tank.x, tank.z), t)
        elif sight is None and self.state == "wander":
            if heard is not None:
                self._start_search((heard.x, heard.z), t)
            elif self.hits and self.hits[-1] == t:
                # hit by something unseen: look behind
                self._start_search((tank.x - 20.0 * tank.c, tank.z - 20.0 * tank.s), t)
        elif sight is None and self.state == "search" and heard is not None and t - self.state_since > 2.0:
            self._start_search((heard.x, heard.z), t)
        if self.state == "search":
            cmd = self._search(world, tank)
            if cmd is not None:
                return self._unstick(world, tank, cmd)
            self._enter("wander", t)
        return self._unstick(world, tank, self._wander(world, tank))

    # ------------------------------------------------------------------ the score
    def _score(self, tank: "Tank") -> None:
        """Count the hits it saw its shells land (on the target it shot at) and forget
        them when that enemy dies at its hands (its own kills go up)."""
        if tank.hits > self.own_hits:
            if self.target is not None:
                self.enemy_hits[self.target] = self.enemy_hits.get(self.target, 0) + tank.hits - self.own_hits
            self.own_hits = tank.hits
        if tank.kills > self.own_kills:
            if self.target is not None:
                self.enemy_hits.pop(self.target, None)
            self.own_kills = tank.kills

    def protecting(self, world: "World", tank: "Tank") -> bool:
        """Protect the lead?  What the HUD shows: its own kills against the best enemy
        score on the scoreboard, the clock, its own hit points.  Ahead, and damaged or
        with less than ``LATE`` s left, unless the enemy it fights is nearer death than
        it is (counted from the hits it saw land)."""
        lead = tank.kills - max((o.kills for o in world.tanks if o is not tank), default=0)
        if lead <= 0:
            return False
        left = math.inf if self.match_seconds is None else self.match_seconds - world.t
        full = tank.spec.hit_points
        if tank.hp >= full and left >= LATE:
            return False
        dmg = tank.spec.shell_damage
        mine = math.ceil(tank.hp / dmg)
        if self.target is not None and self.target in self.enemy_hits:
            theirs = math.ceil(full / dmg) - self.enemy_hits[self.target]
            if theirs < mine:
                return False
        return True

    def _cornered(self, tank: "Tank", s: Sighting) -> bool:
        """Too close to get away, or the enemy's gun (its hull) points within 60° of us:
        it sees us, and turning our back would give it free shots."""
        if s.distance < CORNERED:
            return True
        back = math.atan2(tank.z - s.z, tank.x - s.x)
        return abs(wrap(s.heading - back)) < math.radians(60.0)

    def _pick_target(self, seen: list[Sighting]) -> Sighting | None:
        """The current target if still in sight (no dithering), else the nearest."""
        for s in seen:
            if s.index == self.target:
                return s
        return seen[0] if seen else None

    def _estimate(self, t: float) -> tuple[float, float] | None:
        """Where the enemy probably is: last seen moved on (up to 2 s), or last heard."""
        s = self.senses.last_seen.get(self.target) if self.target is not None else None
        h = self.senses.heard
        if s is not None and (h is None or s.t >= h.t):
            dt = min(t - s.t, 2.0)
            return s.x + s.vx * dt, s.z + s.vz * dt
        if h is not None:
            return h.x, h.z
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
            while len(self.path) > 1 and math.hypot(self.path[0][0] - x, self.path[0][1] - z) < 3.0:
                self.path.pop(0)
            arrived = math.hypot(self.path[-1][0] - x, self.path[-1][1] - z) < 4.0
            if not arrived and t >= self.recheck:
                self.recheck = t + 1.0
                if cov.gain(self.goal_cell, t) < 0.5 * self.goal_gain:
                    arrived = True
            if not arrived:
                return self._follow(world, tank, self.path, speed=1.0, lookahead=4.0, corner=self._corner(tank))
            self.path = []
        best = cov.goal(x, z, t)
        if best is not None:
            cell, gain = best
            gx, gz = self.views.points[cell]
            path = plan_path(self.grid, (x, z), (float(gx), float(gz)))
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
    def _start_search(self, where: tuple[float, float], t: float) -> None:
        self.plan = SearchPlan(self.grid, where[0], where[1])  # type: ignore[arg-type]
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
            self.path = plan_path(self.grid, (x, z), self.goal)  # type: ignore[arg-type]
        while len(self.path) > 1 and math.hypot(self.path[0][0] - x, self.path[0][1] - z) < 3.0:
            self.path.pop(0)
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

    # ------------------------------------------------------------------ hide
    def _threats(self, world: "World", tank: "Tank", sight: Sighting | None) -> list[tuple[float, float]]:
        """Where danger comes from: the enemy in sight, else where one was last seen
        (moved on) or heard in the last ``THREAT_MEMORY`` s, else the spawn points
        (the map: where a respawned enemy appears, and the open floor roamers head for)."""
        t = world.t
        if sight is not None:
            return [(sight.x, sight.z)]
        recent = [s for s in self.senses.last_seen.values() if t - s.t < THREAT_MEMORY]
        h = self.senses.heard
        if recent:
            s = max(recent, key=lambda s: s.t)
            if h is None or s.t >= h.t:
                dt = min(t - s.t, 2.0)
                return [(s.x + s.vx * dt, s.z + s.vz * dt)]
        if h is not None and t - h.t < THREAT_MEMORY:
            return [(h.x, h.z)]
        return [(x, z) for x, z, _ in world.spawns if math.hypot(x - tank.x, z - tank.z) > 10.0]

    def hide_spot(self, tank: "Tank", threats: list[tuple[float, float]]) -> tuple[float, float] | None:
        """The block to hide in: out of the threats' line of sight (the blocks' table),
        far from them, near by path: ``mean(min(distance, 70)) - 40 x exposure - 0.3 x path``
        (exposure: the fraction of the threats that see it; mean over the threats)."""
        views = self.views
        cells = [c for c in (views.cell_at(x, z) for x, z in threats) if c >= 0]
        me = views.cell_at(tank.x, tank.z)
        if not cells or me < 0:
            return None
        path = views.path_distances(me)
        exposure = views.visible[cells].mean(axis=0)
        far = np.minimum(views.distance[cells], 70.0).mean(axis=0)
        score = far - 40.0 * exposure - 0.3 * np.where(np.isfinite(path), path, 0.0)
        score[~np.isfinite(path)] = -np.inf
        b = int(np.argmax(score))
        gx, gz = views.points[b]
        self.hide_exposure = float(exposure[b])
        return float(gx), float(gz)

    def _hide(self, world: "World", tank: "Tank", sight: Sighting | None, heard) -> Command | None:
        """Protect the lead: drive to a hiding block away from the threats and out of
        their sight, chosen again every 3 s (every second while an enemy is in sight or
        just heard); there, watch the way the nearest threat would come, sweeping the
        cone ±0.6 rad.  None: nowhere to go."""
        t = world.t
        if self.state != "hide" and t >= self.hide_replan + 1.0:
            self.hide_goal, self.hide_replan = None, -math.inf
        if t >= self.hide_replan:
            threats = self._threats(world, tank, sight)
            self.threats = threats
            goal = self.hide_spot(tank, threats)
            self.hide_replan = t + (1.0 if sight is not None or heard is not None else 3.0)
            if goal != self.hide_goal:
                self.hide_goal = goal
                self.hide_path = plan_path(self.grid, (tank.x, tank.z), goal) if goal is not None else []  # type: ignore[arg-type]
            if goal is not None and threats:
                cx = sum(p[0] for p in threats) / len(threats)
                cz = sum(p[1] for p in threats) / len(threats)
                self.hide_face = math.atan2(cz - goal[1], cx - goal[0])
        if self.hide_goal is None:
            return None
        x, z = tank.x, tank.z
        gx, gz = self.hide_goal
        path = self.hide_path
        if math.hypot(gx - x, gz - z) > 3.0:
            while len(path) > 1 and math.hypot(path[0][0] - x, path[0][1] - z) < 3.0:
                path.pop(0)
            if not path:
                path = self.hide_path = plan_path(self.grid, (x, z), self.hide_goal)  # type: ignore[arg-type]
                if not path:
                    return None
            return self._follow(world, tank, path, speed=1.0, lookahead=4.0, corner=path[0])
        # a triangle wave: the cone sweeps at a steady SWEEP_RATE, to and fro
        phase = (t * SWEEP_RATE / (2.0 * SWEEP)) % 2.0
        look = self.hide_face + SWEEP * (2.0 * abs(phase - 1.0) - 1.0)
        err = wrap(look - tank.heading)
        return self._drive(world, tank, 0.0, 0.0, self.controller.turn(err - PREDICT * tank.omega))  # type: ignore[union-attr]

    # ------------------------------------------------------------------ evade
    def _start_evade(self, world: "World", tank: "Tank", threat: tuple[float, float], t: float) -> None:
        self.threat = threat
        self.state = "wander"
        self._enter("evade", t)
        self.evade_until = t + 5.0
        self.path = []
        cover = self._cover(world, tank, threat)
        if cover is not None:
            self.path = plan_path(self.grid, (tank.x, tank.z), cover)  # type: ignore[arg-type]

    def _cover(self, world: "World", tank: "Tank", threat: tuple[float, float]) -> tuple[float, float] | None:
        """The nearest of a few sampled nodes 5-25 m away that the threat cannot see."""
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
            if 5.0 <= d < best_d and world.walls.blocked(threat[0], threat[1], cx, cz):
                best, best_d = (cx, cz), d
        return best

    def _evade(self, world: "World", tank: "Tank", sight: Sighting | None) -> Command | None:
        t = world.t
        if t >= self.evade_until:
            return None
        x, z = tank.x, tank.z
        while len(self.path) > 1 and math.hypot(self.path[0][0] - x, self.path[0][1] - z) < 3.0:
            self.path.pop(0)
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
                lookahead: float, corner: tuple[float, float] | None = None) -> Command:
        """Pure pursuit of the first point at least ``lookahead`` away (or the last),
        at up to ``speed`` x top speed, slowing to turn and for ``corner`` (the next
        waypoint where the path bends)."""
        if not points:
            return self._drive(world, tank, 0.0, 0.0, 0.0)
        x, z = tank.x, tank.z
        tx, tz = points[-1]
        for p in points:
            if math.hypot(p[0] - x, p[1] - z) >= lookahead:
                tx, tz = p
                break
        err = wrap(math.atan2(tz - z, tx - x) - tank.heading)
        rotate = self.controller.turn(err - PREDICT * tank.omega)  # type: ignore[union-attr]
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
        return self._drive(world, tank, v, 0.0, rotate)

    def _free(self, world: "World", tank: "Tank", angle: float, length: float, offsets: tuple[float, ...]) -> float:
        """Free distance along ``angle`` from points beside the centre, up to ``length``."""
        c, s = math.cos(angle), math.sin(angle)
        best = length
        for o in offsets:
            ox, oz = tank.x - s * o, tank.z + c * o
            hit = world.walls.first_hit(ox, oz, ox + c * length, oz + s * length)
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
        for k in world.walls.near(tank.x, tank.z, push):
            w = world.walls.walls[k]
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
        """Pushing but not moving for a second: reverse and turn for 0.8 s, then replan."""
        t = world.t
        if t < self.reverse_until:
            back = self._free(world, tank, tank.heading + math.pi, 8.0, (0.0,))
            ahead = self._free(world, tank, tank.heading, 8.0, (0.0,))
            return self._drive(world, tank, -4.0 if back >= ahead else 4.0, 0.0, self.reverse_turn)
        t0, x0, z0 = self.progress_at
        if abs(cmd.advance) < 0.3 or not math.isfinite(x0) or math.hypot(tank.x - x0, tank.z - z0) > 0.5:
            self.progress_at = (t, tank.x, tank.z)
            return cmd
        if t - t0 > 1.0:
            # back out the way there is room for, turning; then plan afresh from here
            self.reverse_until = t + 0.8
            self.reverse_turn = 1.0 if self.rng.random() < 0.5 else -1.0
            self.progress_at = (t + 0.8, math.nan, math.nan)
            self.route, self.walker, self.path, self.hide_path = [], None, [], []
            return self._drive(world, tank, -4.0, 0.0, self.reverse_turn)
        return cmd


def make_agents(world: "World", level: str | Difficulty = "normal", which: range | list[int] | None = None,
                match_seconds: float | None = None) -> list[Agent]:
    """One agent per tank (or per index in ``which``), each seeded from the world's generator;
    ``match_seconds``: the match's length (the HUD's clock), if known."""
    idx = range(len(world.tanks)) if which is None else which
    return [Agent(random.Random(world.rng.getrandbits(64)), level, match_seconds=match_seconds) for _ in idx]
