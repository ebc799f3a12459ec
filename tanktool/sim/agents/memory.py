"""An agent's memory of the fight, fed by its view each think.

* where each enemy was last seen and the latest sound: the bot API's ``Memory``;
* its target and when the reaction time to it ends (an enemy seen again within
  ``REACQUIRE`` s needs none);
* the enemies' hit points, counted from the hits it scored (the world's ``hit``
  events: what a player's hit markers show);
* the hits it took lately (``hit`` events on it), kills (``kill`` events: its own and
  the kill feed's, after which the dead enemy is forgotten: it comes back at a spawn
  point, not where it fell);
* enemies seen standing still (camping): where, when, facing;
* where it drove in the last ``TRAIL`` s (to find the corner it came round).
"""

from __future__ import annotations

import math
from collections import deque
from typing import TYPE_CHECKING

from .perception import Heard, Percept, Sighting

if TYPE_CHECKING:  # pragma: no cover
    from ..bots import View
    from .difficulty import Difficulty

#: an enemy slower than this is standing still [m/s]
STILL = 1.0
#: an enemy seen again within this long needs no new reaction time [s]
REACQUIRE = 2.0
#: hits taken are kept this long [s]
HITS_KEPT = 4.0
#: where it was in the last TRAIL s [s]
TRAIL = 6.0
#: a standing enemy seen in the last KNOWN s is still where it was [s]
KNOWN = 20.0


class AgentMemory:
    """See the module docstring; :meth:`digest` turns a view into a :class:`Percept`."""

    def __init__(self) -> None:
        self.target: int | None = None
        self.acquired_at = math.inf
        self.enemy_hp: dict[int, float] = {}
        self.hits: list[float] = []
        self.killed_at = -math.inf
        self.camps: dict[int, tuple[float, float, float, float]] = {}     # index -> (x, z, t, heading)
        self.trail: deque[tuple[float, float, float, float]] = deque()    # (t, x, z, eye height)
        self.seen_at: dict[int, float] = {}        # when each enemy was last in sight (before this think)
        self.evade_cooldown = -math.inf
        self.faced_t = self.faced_at = -math.inf     # the noise it last turned to: heard at, turned at
        self.waited_until = -math.inf                # the end of its last lying in wait
        self.last_seen: dict[int, Sighting] = {}   # the view's memory (the same dict)
        self.heard: Heard | None = None
        #: an enemy has been seen or heard since the match began (it outlives a death)
        self.met = False

    def reset(self) -> None:
        """It died: the fight is over (what it knows of the map stays)."""
        self.target, self.acquired_at = None, math.inf
        self.hits = []
        self.trail.clear()

    def digest(self, view: "View", level: "Difficulty") -> Percept:
        t, me = view.t, view.me
        self.last_seen, self.heard = view.memory.last_seen, view.memory.heard
        self.met = self.met or bool(self.last_seen) or self.heard is not None
        hit, killed = self._events(view)
        self.hits = [h for h in self.hits if t - h < HITS_KEPT]
        for o in view.seen:
            if math.hypot(o.vx, o.vz) < STILL:
                self.camps[o.index] = (o.x, o.z, t, o.heading)
            else:
                self.camps.pop(o.index, None)
        sight = next((s for s in view.seen if s.index == self.target), view.seen[0] if view.seen else None)
        if sight is not None:
            before = self.seen_at.get(sight.index, -math.inf)
            if self.target != sight.index or t - before > REACQUIRE:
                self.acquired_at = t + level.reaction
            self.target = sight.index
        for s in view.seen:
            self.seen_at[s.index] = t
        self.trail.append((t, me.x, me.z, me.eye))
        while self.trail and t - self.trail[0][0] > TRAIL:
            self.trail.popleft()
        heard = view.heard[0] if view.heard else (view.engines[0] if view.engines else None)
        return Percept(t, sight, sight is not None and t >= self.acquired_at, heard, self._shot(view), hit,
                       tuple(self.hits), me.kills > me.deaths, killed)

    def _events(self, view: "View") -> tuple[bool, bool]:
        """Hits and kills since the last think: (hit taken, its target killed by it)."""
        me = view.me.index
        hit = killed = False
        for e in view.events:
            if e.kind == "hit" and e.other == me:
                self.hits.append(e.t)
                hit = True
            elif e.kind == "hit" and e.tank == me:
                self.enemy_hp[e.other] = self.enemy_hp.get(e.other, self._full(view, e.other)) - e.value
            elif e.kind == "kill" and e.other != me:
                if e.tank == me and e.other == self.target:
                    killed = True
                    self.killed_at = e.t
                self.forget(e.other)
        return hit, killed

    @staticmethod
    def _full(view: "View", index: int) -> float:
        s = view.memory.last_seen.get(index)
        return s.vehicle.hit_points if s is not None and s.vehicle is not None else view.me.vehicle.hit_points

    def forget(self, index: int) -> None:
        """An enemy died: it comes back whole at a spawn point."""
        self.last_seen.pop(index, None)
        self.enemy_hp.pop(index, None)
        self.camps.pop(index, None)

    def _shot(self, view: "View") -> Heard | None:
        """The latest shot heard, if a shell fired then could arrive about now."""
        h = view.memory.heard
        if h is None or h.engine:
            return None
        d = math.hypot(h.x - view.me.x, h.z - view.me.z)
        return h if view.t - h.t < d / max(view.me.vehicle.shell_speed, 1e-9) + 0.5 else None

    # ------------------------------------------------------------------ estimates
    def estimate(self, t: float) -> tuple[float, float, float | None] | None:
        """Where the enemy probably is, (x, z, height): last seen moved on (up to 2 s),
        or last heard."""
        s = self.last_seen.get(self.target) if self.target is not None else None
        h = self.heard
        if s is not None and (h is None or s.t >= h.t):
            dt = min(t - s.t, 2.0)
            return s.x + s.vx * dt, s.z + s.vz * dt, s.y
        if h is not None:
            return h.x, h.z, h.y
        return None

    def known(self, t: float) -> tuple[float, float] | None:
        """Where the target was seen (in the last ``KNOWN`` s, standing still, or in the
        last 3 s, moved on) or a shot was heard (in the last 3 s); None if neither."""
        s = self.last_seen.get(self.target) if self.target is not None else None
        if s is not None and t - s.t < (KNOWN if math.hypot(s.vx, s.vz) < STILL else 3.0):
            dt = min(t - s.t, 2.0)
            return s.x + s.vx * dt, s.z + s.vz * dt
        h = self.heard
        if h is not None and not h.engine and t - h.t < 3.0:
            return h.x, h.z
        return None

    def losing(self, view: "View", s: Sighting) -> bool:
        """Down to two hits or less and behind the enemy by more than a hit (its hit
        points counted from ours that hit it, as a player counts them)."""
        me = view.me
        dmg = me.vehicle.shell_damage
        full = s.vehicle.hit_points if s.vehicle is not None else me.vehicle.hit_points
        theirs = self.enemy_hp.get(s.index, full)
        return me.hp <= 2.0 * dmg and me.hp < theirs - dmg
