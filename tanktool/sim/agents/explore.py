"""The agent's states for finding enemies: Wander, Watch, Ambush, Search.

* **Wander**: explore.  A* to the block that sees the most of what was not seen in
  the last minute per metre of path (``sight.Coverage.goal``: the sight memory);
  when nothing is left unseen, a route of grid nodes chosen by the paper's three-node
  heuristic with memory (``navigation.Wanderer``).
* **Watch** (in an arena with a vantage point: a block from which the vision cone,
  pointed one way, sees at least ``WATCH_COVER`` of the arena's blocks;
  ``sight.Vantages``): drive to the nearest good vantage and hold it, facing
  that way and sweeping the cone, so that an enemy coming in is seen first and far
  off.  After ``WATCH_STINT`` s, if more than ``STALE`` of the arena has gone unseen
  for a minute, it is done (the agent explores until all has been seen again).
* **Ambush** (while it leads: kills above deaths): hold the safest place near by (a
  block that nothing can see without being in its cone: ``Vantages.safest``), facing
  out and sweeping; a tank heard moves it to a place farther from the noise and turns
  it to face the way the noise would come in.  Done when it no longer leads.
* **Search** (an enemy was seen or heard, and is not in sight): the quadrant search
  (``navigation.SearchPlan``) from where it was, A* paths to each quadrant's centre;
  with ``cover``, an enemy just seen or heard near by is closed in on with the gun on
  it.  Done when every quadrant was visited or after 60 s.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from ...nav.steering import heading_from_angle
from ..commands import Command
from .driving import trim
from .machine import State
from .navigation import SearchPlan, wander_start
from .perception import wrap

if TYPE_CHECKING:  # pragma: no cover
    from ..bots import View
    from .agent import Agent
    from .perception import Percept

#: a vantage point sees at least this fraction of the arena's blocks in one cone
WATCH_COVER = 0.4
#: choosing a vantage: its cover less this much per metre of path to it
WATCH_PER_M = 0.004
#: watch this long [s] before going to look at what has not been seen for a minute
WATCH_STINT = 30.0
#: ... but while nobody has been seen or heard yet, after this [s]: holding a corner
#: that sees the whole arena waits for tanks that may be waiting too (two watchers
#: would draw), so until a first contact the agent goes and looks
FIRST_CONTACT_PATIENCE = 1.0
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
#: searching with cover: an enemy known within this many metres is closed in on, gun on it
PREAIM = 70.0
#: a search ends after this long [s]
SEARCH_TIME = 60.0


class Wander(State["Agent"]):
    """Explore what has not been seen lately (see the module docstring)."""

    name = "wander"

    def __init__(self) -> None:
        self.goal_cell, self.goal_gain, self.recheck = -1, 0.0, 0.0

    def update(self, agent: "Agent", view: "View", p: "Percept") -> Command:
        """An A* path to the block that sees the most of what was not seen in the last
        minute, per metre of path (``Coverage.goal``), chosen again when that is seen
        on the way (its gain halved) or reached; with nothing left unseen anywhere,
        the paper's three-node heuristic."""
        t, me, nav = view.t, view.me, agent.nav
        x, z = me.x, me.z
        if agent.path:
            trim(agent.path, x, z)
            arrived = math.hypot(agent.path[-1][0] - x, agent.path[-1][1] - z) < 4.0
            if not arrived and t >= self.recheck:
                self.recheck = t + 1.0
                if nav.coverage.gain(self.goal_cell, t) < 0.5 * self.goal_gain:
                    arrived = True
            if not arrived:
                return agent.follow(view, agent.path, speed=1.0, lookahead=4.0, corner=agent.corner())
            agent.path = []
        best = nav.coverage.goal(x, z, t, y=me.y) if agent.level.explore else None
        if best is not None:
            cell, gain = best
            gx, gz = nav.views.points[cell]
            path = view.map.path((x, z, me.y), (float(gx), float(gz), float(nav.views.heights[cell])), nav.grid)
            if path:
                agent.path, self.goal_cell, self.goal_gain, self.recheck = path, cell, gain, t + 1.0
                return agent.follow(view, agent.path, speed=1.0, lookahead=4.0, corner=agent.corner())
        return self._heuristic(agent, view)

    def _heuristic(self, agent: "Agent", view: "View") -> Command:
        """The paper's ternary decision with memory: a 12-node route ahead."""
        grid, wand, me = agent.nav.grid, agent.nav.wanderer, view.me
        x, z = me.x, me.z
        route = agent.route
        while route and math.hypot(route[0][0] - x, route[0][1] - z) < 2.5:
            route.pop(0)
        if route and math.hypot(route[0][0] - x, route[0][1] - z) > 5.0:
            route.clear()                      # pushed off the route: start again here
            agent.walker = None
        if agent.walker is None:
            n = wander_start(grid, x, z, me.y)     # (level, i, j) on a ground's layered grid
            if n is None:
                return agent.back_off()
            agent.walker = (n, heading_from_angle(me.heading))
            route.clear()
        while len(route) < 12:
            node, h = agent.walker
            nxt = wand.choose(node, h, view.t)
            if nxt is None:
                break
            agent.walker = nxt
            point = grid.centre(*nxt[0][-2:])
            if point in route:     # a pocket the heuristic only turns about in
                break
            route.append(point)
        if not route:
            return agent.back_off()
        return agent.follow(view, route, speed=0.85, lookahead=6.0)


class Watch(State["Agent"]):
    """Hold a vantage point (``ambush`` False) or, while leading, the safest place
    near by (``ambush`` True): see the module docstring."""

    def __init__(self, ambush: bool) -> None:
        self.ambush = ambush
        self.name = "ambush" if ambush else "watch"
        self.spot: tuple[float, float] | None = None
        self.face = 0.0
        self.path: list[tuple[float, float]] = []
        self.replan = self.chosen = -math.inf
        self.faced: tuple[object, float] | None = None     # ambush: the heard noise it turned to, that way

    def reset(self) -> None:
        self.spot, self.path, self.replan = None, [], -math.inf

    def update(self, agent: "Agent", view: "View", p: "Percept") -> Command | None:
        """The nearest block (by path) whose cone sees the most of the arena (ambush:
        the safest, away from a tank heard in the last 2 s), chosen again every 5 s
        (ambush: at most every 2 s while a tank is heard); there, face its best way
        (ambush: the way the heard tank would come in) and sweep the cone ``SWEEP``
        either side.  None: nothing to watch from, time to explore, or (ambush) not
        leading any more."""
        nav, t, me = agent.nav, view.t, view.me
        v = nav.vantages
        if self.ambush and not p.leading:
            return None
        if not self.ambush and (agent.stale(t) and t - agent.machine.since > WATCH_STINT
                                or not agent.memory.met
                                and t - agent.machine.since > FIRST_CONTACT_PATIENCE):
            agent.exploring = True
            return None
        h = agent.memory.heard
        noise = h if (self.ambush and h is not None and t - h.t < 2.0) else None
        if noise is not None and p.heard is noise:
            self.replan = min(self.replan, self.chosen + 2.0)
        if self.spot is None or t >= self.replan:
            if not self._choose(agent, view, noise):
                return None
        gx, gz = self.spot  # type: ignore[misc]
        if math.hypot(gx - me.x, gz - me.z) > 2.5 and self.path:
            trim(self.path, me.x, me.z)
            return agent.follow(view, self.path, speed=1.0, lookahead=4.0, corner=self.path[0], stop=True)
        # a triangle wave: the cone sweeps at a steady SWEEP_RATE, to and fro
        phase = (t * SWEEP_RATE / (2.0 * SWEEP)) % 2.0
        face = self.face
        if self.ambush and h is not None and t - h.t < 3.0:
            if self.faced is None or self.faced[0] is not h:
                path = view.map.path((me.x, me.z, me.y), (h.x, h.z, h.y), nav.grid)
                q = next((q for q in path if math.hypot(q[0] - me.x, q[1] - me.z) >= 6.0),
                         path[-1] if path else (h.x, h.z))
                self.faced = (h, math.atan2(q[1] - me.z, q[0] - me.x))
            face = self.faced[1]
        look = face + SWEEP * (2.0 * abs(phase - 1.0) - 1.0)
        return agent.drive(view, 0.0, 0.0, agent.turn(me, wrap(look - me.heading)))

    def _choose(self, agent: "Agent", view: "View", noise: Any) -> bool:
        nav, me = agent.nav, view.me
        views, v = nav.views, nav.vantages
        self.replan, self.chosen = view.t + 5.0, view.t
        here = views.cell_at(me.x, me.z, me.y)
        if self.ambush:
            away = views.cell_at(noise.x, noise.z, noise.y) if noise is not None else -1
            cell, face = v.safest(here, AMBUSH_PER_M, away, AMBUSH_AWAY, AMBUSH_AWAY_CAP)
        else:
            cell, face = v.best(here, WATCH_PER_M)
        if cell < 0:
            return False
        spot = (float(views.points[cell][0]), float(views.points[cell][1]))
        self.face = face
        if spot != self.spot or not self.path:
            self.spot = spot
            self.path = view.map.path((me.x, me.z, me.y), (*spot, float(views.heights[cell])), nav.grid)
        return True


class Search(State["Agent"]):
    """The quadrant search from where the enemy was (see the module docstring)."""

    name = "search"

    def __init__(self) -> None:
        self.plan: SearchPlan | None = None
        self.goal: tuple[float, ...] | None = None
        self.cell, self.gain, self.recheck = -1, 0.0, -math.inf

    def enter(self, agent: "Agent", view: "View", p: "Percept", arg: Any) -> None:
        """``arg``: (x, z) or (x, z, height) to search from (the height: which level first)."""
        where = arg if isinstance(arg, tuple) else (view.me.x, view.me.z, view.me.y)
        self.plan = SearchPlan(agent.nav.grid, where[0], where[1], y=where[2] if len(where) > 2 else None)
        self.goal = None
        self.cell, self.gain, self.recheck = -1, 0.0, -math.inf

    def _hunt(self, agent: "Agent", view: "View") -> tuple[float, ...] | None:
        """Hunting (``Difficulty.hunt``): the block whose sight holds the most of where
        the enemy may be by now (``belief.Belief.goal``), not the next quadrant; None
        (done) once it may be anywhere (``Belief.spread_out``): leading, it then lies
        in wait (against a robot that comes straight at it, searching on for 60 s
        drove normal into its fire: 4-0-2 -> 2-2-2 in the maze)."""
        nav, me = agent.nav, view.me
        if nav.belief.spread_out():
            return None
        best = nav.belief.goal(nav.coverage.sees, nav.views.cell_at(me.x, me.z, me.y))
        if best is None:
            return None
        self.cell, self.gain = best
        self.recheck = view.t + 1.0
        gx, gz = nav.views.points[self.cell]
        return float(gx), float(gz), float(nav.views.heights[self.cell])

    def _spent(self, agent: "Agent", t: float) -> bool:
        """Hunting: the goal's block sees less than half what it did when chosen
        (looked at on the way, or the enemy seen or heard elsewhere); asked once a second."""
        if not agent.level.hunt or self.cell < 0 or t < self.recheck:
            return False
        self.recheck = t + 1.0
        return agent.nav.belief.gain(agent.nav.coverage.sees, self.cell) < 0.5 * self.gain

    def update(self, agent: "Agent", view: "View", p: "Percept") -> Command | None:
        t, me = view.t, view.me
        if t - agent.machine.since > SEARCH_TIME or self.plan is None:
            return None
        x, z = me.x, me.z
        known = agent.memory.known(t)
        if agent.level.cover and known is not None and self.plan.k <= 1 and \
                math.hypot(known[0] - x, known[1] - z) < PREAIM:
            # an enemy where it was just seen or heard: close in with the gun on it
            if not agent.path or self.goal != known:
                self.goal = known
                agent.path = view.map.path((x, z, me.y), known, agent.nav.grid)
                self.plan.k = 1
            trim(agent.path, x, z)
            if agent.path and math.hypot(agent.path[-1][0] - x, agent.path[-1][1] - z) > 4.0:
                return agent.approach(view, agent.path, known, 0.5 * me.vehicle.top_speed)
        if self.goal is not None and (math.hypot(self.goal[0] - x, self.goal[1] - z) < 4.0 or self._spent(agent, t)):
            self.goal, agent.path = None, []
        tries = 0
        while self.goal is None or not agent.path:
            tries += 1
            if tries > 3:
                return agent.follow(view, [], speed=0.0, lookahead=4.0) if self.goal else None
            self.goal = self._hunt(agent, view) if agent.level.hunt else self.plan.next_goal(agent.nav.regions, t)
            if self.goal is None:
                return None
            agent.path = view.map.path((x, z, me.y), self.goal, agent.nav.grid)
        trim(agent.path, x, z)
        return agent.follow(view, agent.path, speed=0.9, lookahead=4.0, corner=agent.corner())
