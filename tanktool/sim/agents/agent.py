"""The computer opponent: a bot (``sim.bots``) whose states and transitions are data.

Each think (``think_hz`` times a second; the command is held in between, as a person
holds a key) the agent digests its view into a ``perception.Percept`` (its
``memory.AgentMemory`` keeps what it learnt: target, hits, kills, camps, trail), runs
the state machine (``machine.StateMachine``) over ``TRANSITIONS``, dodges the shells
it sees (``dodge.Evasion``) and backs out when it is stuck (``driving.Pilot``).

The states (``explore``: wander, watch, ambush, search; ``combat``: attack, evade,
hunt, return_fire, lie_in_wait) and when it goes from one to another are the table
``TRANSITIONS``, rows ``(from, when, to, why)`` checked in this order (the first that
holds is taken; ``done``: the state has nothing more to do); ``transition_table()``
prints it, and docs/agents.md shows it (``tools/agent_docs.py`` writes it there).

Everything the agent knows comes from its view: sight, hearing, shells in sight, its
own state, the events of hits and kills, and the static map (walls, spawn points, its
navigation grid, which places see which); it acts only through ``Command`` values.
Its randomness is the view's generator, so matches replay exactly.

Difficulty (``difficulty.Difficulty``) sets its senses, reaction time, aim noise,
dodging, how often it thinks and how it fights.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from ..bots import IDLE, Command
from ..rules import GRAVITY
from .belief import HEARD, SEEN, Belief
from .combat import CAMP_MEMORY, CAMP_SPEED, OUTGUNNED, WAIT_COOLDOWN, WAIT_NEAR, Attack, Evade, Hunt, LieInWait, ReturnFire
from .difficulty import DIFFICULTIES, Difficulty, difficulty
from .dodge import Evasion
from .driving import Pilot
from .explore import STALE, WATCH_COVER, Search, Wander, Watch
from .machine import State, StateMachine, Transition, table_text
from .perception import wrap
from .memory import AgentMemory
from .navigation import Memory, Wanderer
from .sight import Coverage, Vantages, Views, vantages_for

if TYPE_CHECKING:  # pragma: no cover
    from ...nav.navgrid import NavGrid
    from ..bots import View
    from .perception import Percept

_ALL = ("wander", "watch", "ambush", "search", "attack", "evade", "hunt", "return_fire", "lie_in_wait")
STATES = _ALL
_ROAM = ("wander", "watch")


#: the steepest link of its grid on relief, as a share of the steepest slope its engine
#: holds it on (the light tank's 0.31: 17 degrees; the hills' slopes are 10)
GRADE = 0.8
#: off its grid on a slope steeper than this (rise per metre), it drives up it first
SLOPE = 0.1
#: ... but not with its hull pitched or rolled more than this [rad] (26 degrees: more
#: than any slope its engine holds it on): it is up on a rock, not on the slope, and
#: driving on (the ground's slope round the rock said "up") wedged it there until it
#: was shot (the hills: 34 degrees nose up on a rock for 3 s, adv 1.0); the pilot's
#: unstick backs it off instead
WEDGED = 0.45
#: free moves on relief look this far ahead [m] beyond the footprint radius, plus the
#: way covered in EDGE_TIME s [s], for a place off the grid EDGE_RISE m [m] above or
#: below
EDGE_AHEAD = 1.0
EDGE_TIME = 0.5
EDGE_RISE = 0.5
#: ... looked at every EDGE_STEP m up to EDGE_MAX m [m]
EDGE_STEP = 1.5
EDGE_MAX = 14.0

#: a noise heard within NEAR m is turned to, at most once in FACED s [m, s]
NEAR = 30.0
FACED = 3.0


def _but(*names: str) -> tuple[str, ...]:
    return tuple(n for n in _ALL if n not in names)


TRANSITIONS = tuple(Transition(*row) for row in (
    (_but("evade", "return_fire"), "ambushed", "evade", "hit twice in 4 s, nobody in sight, shot from cover"),
    (("attack",), "losing", "evade", "out-traded (Difficulty.break_off: no level)"),
    (("attack",), "outgunned", "evade",
     "on relief, no shot of its carries for 1.5 s and it is hit (Difficulty.outgunned): out of its sight"),
    (("evade",), "done", "search", "in cover or 5 s: from the threat"),
    (_but("evade", "attack", "return_fire"), "shot_from_open", "return_fire",
     "hit, the shot heard from a place in sight"),
    (_but("evade", "attack"), "enemy_acquired", "attack", "in sight, reaction time over"),
    (_but("evade", "attack", "return_fire"), "heard_near", "return_fire",
     "a shot or engine heard within 30 m from a place in sight: face it"),
    (("return_fire",), "done", "search", "facing the shot: from there"),
    (("wander", "watch", "search"), "coming", "lie_in_wait",
     "an engine heard within 35 m behind cover (Difficulty.wait): gun on where it comes in"),
    (("lie_in_wait",), "done", "search", "it did not come in 3 s: from the noise"),
    (("wander", "watch", "search"), "camp_known", "hunt", "an enemy seen standing (cover levels)"),
    (("hunt",), "done", "wander", "it was not there"),
    (("attack",), "enemy_killed", "wander", "it comes back at a spawn point"),
    (("attack",), "enemy_lost", "search", "from where it was last seen, moved on"),
    (_ROAM, "heard", "search", "from the shot or engine heard"),
    (_ROAM, "hit_unseen", "search", "from behind"),
    (("search",), "heard_again", "search", "a new noise after 2 s of searching"),
    (("search",), "done", "wander", "every quadrant (hunting: it may be anywhere by now), or 60 s"),
    (_ROAM, "leading", "ambush", "kills above deaths"),
    (("ambush",), "done", "wander", "not leading any more"),
    (("wander",), "vantage", "watch", "an arena with a vantage point"),
    (("watch",), "done", "wander", "part of the arena unseen, or nobody met yet: explore"),
))


def transition_table() -> str:
    """``TRANSITIONS`` as text (``machine.table_text``), as docs/agents.md shows it."""
    return table_text(TRANSITIONS, STATES)


class Nav:
    """What an agent knows of the arena: its grid, where it has been (regions), the
    paper's wanderer, the sight table, what it has seen lately, the vantage points."""

    def __init__(self, view: "View", rng: Any, cell: float, margin: float, half_angle: float,
                 vision_range: float) -> None:
        self.grade, self.grid, self.plain, self.views, self.vantages = Nav.tables(
            view.map, view.me.vehicle, cell, margin, half_angle, vision_range)
        self.regions = Memory(self.grid, region=16.0)
        self.wanderer = Wanderer(self.grid, self.regions, rng)
        self.coverage = Coverage(self.views, half_angle, vision_range)
        m = view.map
        self.belief = Belief(self.views, [(x, z, y) for (x, z, _), y in zip(m.spawns, m.spawn_y)])

    @staticmethod
    def tables(map: Any, vehicle: Any, cell: float, margin: float, half_angle: float,
               vision_range: float) -> tuple[float, "NavGrid", "NavGrid", Views, Vantages]:
        """(grade, grid, plain grid, sight table, vantages) of the arena for this vehicle:
        the map's, not anything seen (each cached per arena)."""
        from .navigation import agent_grid

        # on relief, no link steeper than the vehicle climbs at a useful speed
        grade = GRADE * vehicle.engine_force / (vehicle.mass * GRAVITY)
        # and a deck or ramp joining parts apart driven straight at the hull's half width
        half = 0.5 * (vehicle.box[3] - vehicle.box[1])
        grid = agent_grid(map, cell, vehicle.radius + margin, grade, narrow=half + margin)
        plain = agent_grid(map, cell, vehicle.radius + margin)
        views = map.sight_table(grid)
        return grade, grid, plain, views, vantages_for(views, half_angle, vision_range)


class Agent(Pilot):
    """A computer opponent, a bot: ``act(view) -> Command``.

    Parameters
    ----------
    level : a :class:`Difficulty` or its name
    half_angle : vision cone half-angle [rad] (60 degrees)
    cell : node spacing of its navigation grid [m]
    margin : grid clearance beyond the vehicle's footprint radius [m]
    watch : hold vantage points where the arena has them, and hiding places while it
        leads (False: always Wander)
    """

    def __init__(self, level: str | Difficulty = "normal", *, half_angle: float = math.radians(60.0),
                 cell: float = 1.0, margin: float = 0.5, watch: bool = True) -> None:
        super().__init__()
        self.level = difficulty(level)
        self.senses = self.level.senses(half_angle)
        self.think_hz = self.level.think_hz
        self.period = 1.0 / self.level.think_hz
        self.cell, self.margin = cell, margin
        self.watches = watch and self.level.watch
        self.memory = AgentMemory()
        self.evasion = Evasion(self.level.dodge_reaction)
        self.nav: Nav | None = None
        self.rng: Any = None
        self.aim_error = 0.0
        self.fired_at = -math.inf
        self.exploring = False
        # the way being driven: an A* path (search, evade, hunt, explore) or the
        # wander heuristic's route of nodes and its walker (node, heading)
        self.path: list[tuple[float, float]] = []
        self.route: list[tuple[float, float]] = []
        self.walker: tuple[tuple[int, int], str] | None = None
        states: list[State[Agent]] = [Wander(), Watch(False), Watch(True), Search(), Attack(), Evade(), Hunt(),
                                      ReturnFire(), LieInWait()]
        self.machine = StateMachine({s.name: s for s in states}, TRANSITIONS, GUARDS, "wander",
                                    on_change=Agent._clear_way)

    #: stuck: less than this far in a second [m] (the light tank climbs a 17 degree
    #: slope at about 0.4 m/s: not stuck)
    STUCK_MOVE = 0.25

    @property
    def state(self) -> str:
        return self.machine.name

    def off_slope(self, view: "View") -> Command | None:
        """On a slope with a trap below (``_trap`` within 6 m downhill: a spawn point at
        the top of a ramp too steep; the tank slid down it in its first fight and stayed
        at its foot all duel): up the slope first, whatever the state (its shot is
        kept), while it still can (from a standstill, not once sliding)."""
        nav, me = self.nav, view.me
        if not view.map.relief or nav is None or abs(me.pitch) > WEDGED or abs(me.roll) > WEDGED:
            return None
        g, lv, h = view.map.ground, me.level, 1.5
        gx = g.height(me.x + h, me.z, lv) - g.height(me.x - h, me.z, lv)
        gz = g.height(me.x, me.z + h, lv) - g.height(me.x, me.z - h, lv)
        n = math.hypot(gx, gz)
        if n / (2.0 * h) <= SLOPE:
            return None
        here = g.height(me.x, me.z, lv)
        if not any(self._trap(view, me.x - r * gx / n, me.z - r * gz / n, here, r) for r in (2.0, 4.0, 6.0)):
            return None
        # straight up, no strafe (the pilot's push off the walls of the ramp's level
        # strafed it down)
        err = wrap(math.atan2(gz, gx) - me.heading)
        return Command(advance=1.0 if abs(err) < 0.8 else 0.0, rotate=self.turn(me, err), strafe=0.0)

    def _trap(self, view: "View", x: float, z: float, here: float, r: float) -> bool:
        """Whether (x, z), ``r`` m off, is off our grid and on a slope too steep (cut
        from it: valid on the plain grid) or more than ``EDGE_RISE`` m above or below
        ``here`` beyond the slope we climb (a drop)."""
        nav = self.nav
        node = nav.grid.node_of(x, z)  # type: ignore[union-attr]
        if nav.grid.is_valid(node):  # type: ignore[union-attr]
            return False
        if nav.plain.layers is not None and nav.plain.is_valid(node):  # type: ignore[union-attr]
            return True
        g = view.map.ground
        return abs(g.height(x, z, view.me.level) - here) > EDGE_RISE + nav.grade * r  # type: ignore[union-attr]

    def edge_free(self, view: "View", angle: float, length: float) -> float:
        """Free distance along ``angle`` before an edge (``_trap``: a drop or a slope
        it cannot climb), up to ``length``; ``length`` off relief."""
        if not view.map.relief or self.nav is None:
            return length
        me = view.me
        here = view.map.ground.height(me.x, me.z, me.level)
        c, s = math.cos(angle), math.sin(angle)
        r = me.vehicle.radius
        while r < length:
            r = min(r + EDGE_STEP, length)
            if self._trap(view, me.x + c * r, me.z + s * r, here, r):
                return r - EDGE_STEP
        return length

    def drive(self, view: "View", forward: float, lateral: float, rotate: float, fire: bool = False) -> Command:
        """``Pilot.drive``; on relief, not towards an edge: a wanted forward or sideways
        speed whose way ahead (footprint radius + ``EDGE_AHEAD`` m + ``EDGE_TIME`` s of
        it + the way to stop from it) ends off its grid, on a slope steeper than it climbs (cut from its grid) or
        more than ``EDGE_RISE`` m above or below here beyond the slope it climbs (a drop;
        not the hills' 10 degrees: holding those back lost half the duels there), is
        not driven.  The world keeps a tank's centre on the surface, so one driven at a
        plateau's edge hangs over it, its hull (and gun) pitched 40 degrees; one backed
        down a ramp too steep stays down."""
        if view.map.relief and self.nav is not None:
            me = view.me
            here = view.map.ground.height(me.x, me.z, me.level)
            brake = 0.6 * me.vehicle.engine_force / me.vehicle.mass
            for k, (speed, c, s) in enumerate(((forward, me.c, me.s), (lateral, -me.s, me.c))):
                if abs(speed) < 0.3:
                    continue
                # as far as it takes to stop from the speed it has that way, or wants:
                # sideways the tracks' grip kills a slide at ``grip``/s (v / grip m: 0.9 m
                # from a full strafe; the engine's braking distance, 14 m, held normal's
                # strafe a plateau's width from its edge, still in a quarter of its fights)
                v = max(abs(speed), math.copysign(1.0, speed) * (me.vx * c + me.vz * s))
                stop = v * v / (2.0 * brake) if k == 0 else v / max(me.vehicle.grip, 1.0)
                reach = min(me.vehicle.radius + EDGE_AHEAD + v * EDGE_TIME + stop, EDGE_MAX)
                r = me.vehicle.radius
                while r < reach:
                    r = min(r + EDGE_STEP, reach)
                    if self._trap(view, me.x + c * math.copysign(r, speed), me.z + s * math.copysign(r, speed),
                                  here, r):
                        forward, lateral = (0.0, lateral) if k == 0 else (forward, 0.0)
                        break
        return super().drive(view, forward, lateral, rotate, fire)

    # ------------------------------------------------------------------ the bot
    def prepare(self, map: Any, vehicle: Any) -> None:
        """Make the arena's tables the first think reads (``Nav.tables``, cached per
        arena): ``run_match`` calls it before its clock, as it loads the arena (on a
        2 km terrain they take seconds; the steps after them a millisecond)."""
        Nav.tables(map, vehicle, self.cell, self.margin, self.senses.half_angle, self.senses.vision_range)

    def act(self, view: "View") -> Command:
        if self.rng is None:
            self.rng = view.rng
            self.aim_error = self.rng.gauss(0.0, self.level.aim_noise)
            self.machine.states["attack"].side = 1.0 if self.rng.random() < 0.5 else -1.0  # type: ignore[attr-defined]
        if not view.me.alive:
            self._reset(view)
            return IDLE
        if self.nav is None:
            self.nav = Nav(view, self.rng, self.cell, self.margin, self.senses.half_angle, self.senses.vision_range)
        return self.evade_shells(view, self.think(view))

    def think(self, view: "View") -> Command:
        """Perceive, take the transitions that hold, act."""
        me, nav = view.me, self.nav
        nav.regions.visit(me.x, me.z, view.t)  # type: ignore[union-attr]
        looked = nav.coverage.look(me.x, me.z, me.heading, view.t, me.y)  # type: ignore[union-attr]
        if self.level.hunt:
            self._believe(view, looked)
        p = self.memory.digest(view, self.level)
        cmd = self.machine.think(self, view, p, lambda: self.drive(view, 0.0, 0.0, 0.0))
        up = self.off_slope(view)
        if up is not None:
            return Command(up.advance, up.rotate, up.strafe, cmd.fire)
        # fighting too: wedged on a ramp's side (37 degrees of pitch, the gen-bridge),
        # hard pushed forward and sideways at 0.1 m/s for the rest of a duel, 0-0
        return self.unstick(view, cmd, strafe=self.state == "attack")

    def _believe(self, view: "View", looked: Any) -> None:
        """Where the enemy probably is (``belief.Belief``), from this think's view:
        spread since the last, nobody in the blocks looked at but those an enemy is
        seen in, the sightings, the noises heard, the kills in the feed."""
        b, views, me = self.nav.belief, self.nav.views, view.me  # type: ignore[union-attr]
        if not math.isfinite(b.t):
            b.start(view.t, int(looked[0]) if len(looked) else -1)
        b.spread(view.t, me.vehicle.top_speed)
        b.looked(looked)
        if any(e.kind == "kill" and e.other != me.index for e in view.events):
            b.respawned()
        b.at([views.cell_at(h.x, h.z, h.y) for h in (*view.heard, *view.engines)], HEARD)
        b.at([views.cell_at(s.x, s.z, s.y) for s in view.seen], SEEN)

    def evade_shells(self, view: "View", cmd: Command) -> Command:
        """Dodge a shell seen flying at it (``dodge.Evasion``: noticed after the level's
        ``dodge_reaction``) when a way out exists: the escape's forward and sideways
        moves replace the command's, which keeps its turn and its shot."""
        if not math.isfinite(self.level.dodge_reaction):
            return cmd
        esc = self.evasion.command(view.t, view.me, view.shells)
        if esc is None or self.evasion.clearance <= 0.0:
            return cmd           # nothing to dodge, or no escape: keep fighting
        top = view.me.vehicle.top_speed
        return self.drive(view, esc[0] * top, esc[1] * 0.5 * top, cmd.rotate, cmd.fire)

    def _reset(self, view: "View") -> None:
        """Dead: forget the fight and the ways being driven."""
        self.machine.reset(self, view)
        self.memory.reset()
        self._replan()
        for name in ("watch", "ambush"):
            self.machine.states[name].reset()  # type: ignore[attr-defined]
        self.exploring = False
        self.reverse_until = -math.inf

    def debug(self) -> dict[str, Any]:
        return {"state": self.state, "path": list(self.path or self.route) or None}

    # ------------------------------------------------------------------ helpers for the states
    def stale(self, t: float) -> bool:
        """More than ``STALE`` of the arena unseen for a minute."""
        return self.nav.coverage.stale_fraction(t) > STALE  # type: ignore[union-attr]

    def corner(self) -> tuple[float, float] | None:
        """The next waypoint of the A* path where it bends (the path's end counts)."""
        return self.path[0] if self.path else None

    def camp_known(self, t: float) -> int | None:
        """The enemy seen camping most recently (within ``CAMP_MEMORY`` s), if any."""
        live = [(ct, i) for i, (_, _, ct, _) in self.memory.camps.items() if t - ct <= CAMP_MEMORY]
        return max(live)[1] if live else None

    def follow(self, view: "View", points: list[tuple[float, float]], speed: float, lookahead: float,
               corner: tuple[float, float] | None = None, stop: bool = False) -> Command:
        """``Pilot.follow``; but with ``cover``, where the way ahead comes into the sight
        of a known camping enemy, along it with the gun on that enemy (``approach``)."""
        camp = self._camp_ahead(view, points) if self.level.cover and points else None
        if camp is not None:
            return self.approach(view, points, camp, min(speed * view.me.vehicle.top_speed, CAMP_SPEED))
        return super().follow(view, points, speed, lookahead, corner, stop)

    def _camp_ahead(self, view: "View", points: list[tuple[float, float]]) -> tuple[float, float] | None:
        """A camping enemy remembered (``CAMP_MEMORY`` s, within vision range), or where
        the enemy was seen or heard in the last seconds (``memory.known``), that sees us
        here or at the first point of the way at least 6 m ahead: the gun goes on it
        before the way comes round the corner (peeking with the gun on it)."""
        t, me = view.t, view.me
        ahead = next((q for q in points if math.hypot(q[0] - me.x, q[1] - me.z) >= 6.0), points[-1])
        best, best_d = None, math.inf
        places = [(cx, cz, ct) for cx, cz, ct, _ in self.memory.camps.values()]
        known = self.memory.known(t)
        if known is not None:
            places.append((known[0], known[1], t))
        for cx, cz, ct in places:
            d = math.hypot(cx - me.x, cz - me.z)
            if t - ct > CAMP_MEMORY or d > self.senses.vision_range or d >= best_d:
                continue
            if not view.map.line_blocked(me.x, me.z, cx, cz, me.eye) or \
                    not view.map.line_blocked(ahead[0], ahead[1], cx, cz):
                best, best_d = (cx, cz), d
        return best

    def _on_path(self) -> bool:
        return bool(self.path or self.route)

    def _clear_way(self) -> None:
        self.path, self.route, self.walker = [], [], None

    def _replan(self) -> None:
        self._clear_way()
        for name in ("watch", "ambush"):
            self.machine.states[name].path = []  # type: ignore[attr-defined]


# ------------------------------------------------------------------ the guards
def _ambushed(a: Agent, view: "View", p: "Percept") -> Any:
    # a shot from a place in sight is better answered by turning on it (return_fire)
    # than by driving off with it hitting our back
    if p.sight is None and len(p.hits) >= 2 and p.t >= a.memory.evade_cooldown and not _in_open(view, p.shot):
        return a.memory.estimate(p.t)
    return None


def _in_open(view: "View", h: Any) -> bool:
    """Whether a heard shot came from a place in our line of sight."""
    me = view.me
    return h is not None and not view.map.line_blocked(me.x, me.z, h.x, h.z, me.eye,
                                                        None if h.y is None else h.y + me.vehicle.eye)


def _losing(a: Agent, view: "View", p: "Percept") -> Any:
    lv = a.level
    if lv.cover and lv.break_off and p.sight is not None and p.t >= a.memory.evade_cooldown \
            and a.memory.losing(view, p.sight):
        return (p.sight.x, p.sight.z)
    return None


def _outgunned(a: Agent, view: "View", p: "Percept") -> Any:
    """On relief: no shot of ours carries onto the enemy from here (we drive to a place
    whence one would) for ``OUTGUNNED`` s, and its shots hit us meanwhile: its ground
    serves it, ours does not.  Out of its sight, then look for it again."""
    since = a.machine.states["attack"].blind_since  # type: ignore[attr-defined]
    s = p.sight
    if a.level.outgunned and s is not None and since is not None and p.t - since >= OUTGUNNED \
            and p.t >= a.memory.evade_cooldown and any(h >= since for h in p.hits):
        return (s.x, s.z, s.y)
    return None


def _shot_from_open(a: Agent, view: "View", p: "Percept") -> Any:
    return p.shot if p.sight is None and p.hit and _in_open(view, p.shot) else None


def _heard_near(a: Agent, view: "View", p: "Percept") -> Any:
    """A shot or engine heard within ``NEAR`` m from a place in our line of sight,
    since the last one it turned to (and not within ``FACED`` s of that): someone is
    close, out of its cone.  (One behind a wall is searched for, or lain in wait for.)"""
    h, me = p.heard, view.me
    if p.sight is None and h is not None and h.t > a.memory.faced_t and p.t - a.memory.faced_at > FACED \
            and math.hypot(h.x - me.x, h.z - me.z) < NEAR and _in_open(view, h):
        return h
    return None


def _coming(a: Agent, view: "View", p: "Percept") -> Any:
    """An engine heard now within ``WAIT_NEAR`` m from a place out of our line of
    sight, by a level that lies in wait, not within ``WAIT_COOLDOWN`` s of the last."""
    h, me = p.heard, view.me
    if a.level.wait and p.sight is None and h is not None and h.engine and h.t >= p.t - 1e-9 \
            and p.t - a.memory.waited_until > WAIT_COOLDOWN and math.hypot(h.x - me.x, h.z - me.z) < WAIT_NEAR \
            and not _in_open(view, h):
        return h
    return None


def _enemy_acquired(a: Agent, view: "View", p: "Percept") -> Any:
    return p.sight is not None and p.reacted


def _camp_known(a: Agent, view: "View", p: "Percept") -> Any:
    return a.level.cover and p.sight is None and not p.leading and a.camp_known(p.t) is not None


def _enemy_killed(a: Agent, view: "View", p: "Percept") -> Any:
    return p.sight is None and p.t - a.memory.killed_at < 1.0


def _enemy_lost(a: Agent, view: "View", p: "Percept") -> Any:
    if p.sight is not None:
        return None
    est = a.memory.estimate(p.t)
    return est if est is not None else (view.me.x, view.me.z, view.me.y)


def _heard(a: Agent, view: "View", p: "Percept") -> Any:
    h = p.heard
    return (h.x, h.z, h.y) if p.sight is None and h is not None else None


def _hit_unseen(a: Agent, view: "View", p: "Percept") -> Any:
    me = view.me
    return (me.x - 20.0 * me.c, me.z - 20.0 * me.s, me.y) if p.sight is None and p.hit else None


def _heard_again(a: Agent, view: "View", p: "Percept") -> Any:
    return _heard(a, view, p) if p.t - a.machine.since > 2.0 else None


def _leading(a: Agent, view: "View", p: "Percept") -> Any:
    return a.watches and p.leading


def _vantage(a: Agent, view: "View", p: "Percept") -> Any:
    if not a.watches or a.nav.vantages.top < WATCH_COVER:  # type: ignore[union-attr]
        return False
    if a.exploring:
        if a.stale(view.t) or not a.memory.met:    # still looking for a first contact
            return False
        a.exploring = False
    return True


GUARDS = {"ambushed": _ambushed, "losing": _losing, "outgunned": _outgunned, "shot_from_open": _shot_from_open, "heard_near": _heard_near,
          "enemy_acquired": _enemy_acquired, "coming": _coming, "camp_known": _camp_known, "enemy_killed": _enemy_killed,
          "enemy_lost": _enemy_lost, "heard": _heard, "hit_unseen": _hit_unseen, "heard_again": _heard_again,
          "leading": _leading, "vantage": _vantage}


def make_agents(world: Any, level: str | Difficulty = "normal", which: range | list[int] | None = None) -> list:
    """One agent driver per tank (or per index in ``which``), each seeded from the
    world's generator (``sim.bots.BotDriver``)."""
    from ..bots import BotDriver

    idx = range(len(world.tanks)) if which is None else which
    return [BotDriver(Agent(level), world.rng.getrandbits(64), name=difficulty(level).name) for _ in idx]


__all__ = ["Agent", "DIFFICULTIES", "Difficulty", "GUARDS", "STATES", "TRANSITIONS", "difficulty", "make_agents",
           "transition_table"]
