"""What a remote tank could have done: every peer checks the states and shots it
receives against the vehicle's limits and the arena, as BZFlag's server checks player
states; the host's decisions (hits, kills) set hit points and deaths.

No I/O and no clock of its own: the caller passes the receive time (its session time)
with each message, so tests drive it with simulated networks (:mod:`.simnet`).

A **state** is taken when, against the tank's last valid state:

- its session time is not ahead of ours by more than ``ahead`` (a sender cannot buy
  itself time);
- it is inside the arena's bounds and, on a ground, over a walkable node;
- its speed is within ``speed_factor`` x top speed + ``speed_margin`` and its turn rate
  within ``turn_factor`` x turn rate + ``turn_margin`` (collisions spin tanks up to 2.7x
  their turn rate: measured over 90 s of 8 scripted tanks on box, fort and hills);
- the distance from the last valid position fits that speed over the time between them,
  where the time is the smaller of the two states' session times and the receive times
  plus ``jitter`` (so a sender cannot claim time that did not pass), and the straight
  line between them crosses no wall (flat and one-level arenas);
- a tank the host declared dead comes back only ``respawn_delay`` after its death
  (less ``respawn_slack``) and within ``spawn_radius`` of a place the simulation's own
  spawn rules could put it: a spawn point, or one of the free places
  :mod:`..sim.extra_spawns` gives the arena for the vehicle when more tanks play than it
  has spawn points (as many as a match has players, whatever number of tanks the
  judge's world was built with).  Anywhere else it is a teleport disguised as a respawn.

A state that fails is **corrected**: the tank stays at its last valid pose, standing
still, and the correction is counted.  A tank corrected more than ``kick_rate`` times a
second for ``kick_seconds`` seconds in a row is one the host disconnects.  Hit points
never come from a peer: they start at the vehicle's ``hit_points`` and only the host's
HITs change them; a respawn restores them.

A **shot** is taken only from a tank alive in the judge's eyes, no sooner than
``reload_factor`` x the reload after its previous one (by the shot's time, and by receive
time less ``jitter``), from within reach of its last valid pose.

The defaults keep honest peers under 200 ms of delay, jitter and 5 % loss free of any
correction (tests/test_net_judge.py, over simulated networks on three arenas).
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field, replace
from typing import Any

from .protocol import MAX_PLAYERS, Shot, State


@dataclass(frozen=True)
class JudgeConfig:
    """The tolerances of the checks (see the module's docstring)."""

    speed_factor: float = 1.25
    speed_margin: float = 1.5          # m/s
    turn_factor: float = 3.0
    turn_margin: float = 1.0           # rad/s
    jitter: float = 0.35               # s: delay variation (200 ms) and a late state or two
    jump_margin: float = 0.5           # m
    ahead: float = 0.5                 # s
    bounds_margin: float = 0.5         # m
    spawn_radius: float = 2.0          # m
    respawn_slack: float = 0.5         # s
    reload_factor: float = 0.95
    kick_rate: int = 3                 # corrections in a second ...
    kick_seconds: int = 5              # ... for this many seconds in a row


@dataclass
class _Record:
    """What the judge knows of one tank."""

    hp: float
    last: State | None = None          # the last valid state
    last_recv: float = 0.0
    alive: bool = True
    died_at: float = -math.inf
    shot_t: float = -math.inf
    shot_recv: float = -math.inf
    strikes: Counter = field(default_factory=Counter)    # whole second -> corrections


class Judge:
    """The checks for one peer's view of the others (build one per match).

    ``world`` is the peer's ``sim.world.World``: its tanks' specs, bounds, walls, ground,
    spawns, respawn delay and rules are read, never changed.
    """

    def __init__(self, world: Any, config: JudgeConfig = JudgeConfig()) -> None:
        self.world = world
        self.config = config
        self.records: dict[int, _Record] = {}
        self.corrections: Counter = Counter()            # reason -> count (all tanks)
        self.refused_shots: Counter = Counter()
        self._places: list[tuple[float, float]] | None = None

    # ------------------------------------------------------------------ limits
    def _spec(self, n: int) -> Any:
        return self.world.tanks[n - 1].spec

    def _vlim(self, n: int) -> float:
        c = self.config
        return self._spec(n).top_speed * c.speed_factor + c.speed_margin

    def _wlim(self, n: int) -> float:
        c = self.config
        return self._spec(n).turn_rate * c.turn_factor + c.turn_margin

    def _reload(self, n: int) -> float:
        r = getattr(self.world.rules, "reload", None)
        return float(r) if r is not None else float(self._spec(n).fire_interval)

    def record(self, n: int) -> _Record:
        r = self.records.get(n)
        if r is None:
            r = self.records[n] = _Record(hp=float(self._spec(n).hit_points))
        return r

    def forget(self, n: int) -> None:
        """Tank ``n`` left (or a new player took its number): start afresh."""
        self.records.pop(n, None)

    def on_surface(self, x: float, z: float) -> bool:
        """Inside the bounds and, on a ground, over a node of the walkable grid."""
        b = self.world.bounds
        m = self.config.bounds_margin
        if not (b[0][0] - m <= x <= b[1][0] + m and b[0][1] - m <= z <= b[1][1] + m):
            return False
        g = getattr(self.world, "ground", None)
        return g is None or g.locate(x, z) >= 0

    def through_wall(self, ax: float, az: float, bx: float, bz: float) -> bool:
        """Whether going straight from a to b crosses a wall (flat and one-level arenas;
        on several levels a wall of another level is no obstacle, and the walkable check
        stands in for it)."""
        g = getattr(self.world, "ground", None)
        if g is not None and getattr(g, "levels", 1) > 1:
            return False
        return bool(self.world.walls.blocked(ax, az, bx, bz))

    def spawn_places(self) -> list[tuple[float, float]]:
        """Where a tank may (re)spawn: the world's spawn points, then the free places
        sim/extra_spawns picks after them for the world's largest vehicle (as World does),
        up to ``MAX_PLAYERS`` (or the world's tank count if larger) places in all.  The
        picks are farthest-point sampling, so continuing from a world already extended
        for fewer tanks gives the same places a world built for more would have."""
        if self._places is None:
            from ..sim.extra_spawns import places

            w = self.world
            out = [(float(s[0]), float(s[1])) for s in w.spawns]
            need = max(MAX_PLAYERS, len(w.tanks)) - len(out)
            if need > 0 and w.tanks:
                big = max((t.spec for t in w.tanks), key=lambda s: s.radius)
                out += [(x, z) for x, z, _h, _y in places(w, need, big.radius, big.box[2] - big.box[0])]
            self._places = out
        return self._places

    def near_spawn(self, x: float, z: float) -> bool:
        """Within ``spawn_radius`` of a place a tank may (re)spawn at."""
        r = self.config.spawn_radius
        return any(math.hypot(x - sx, z - sz) <= r for sx, sz in self.spawn_places())

    # ------------------------------------------------------------------ states
    def _fault(self, n: int, s: State, now: float) -> str | None:
        """Why state ``s`` of tank ``n`` received at ``now`` is not one it could have
        sent, or None."""
        c, r = self.config, self.record(n)
        if s.t > now + c.ahead:
            return "ahead"
        if not self.on_surface(s.x, s.z):
            return "outside"
        if math.hypot(s.vx, s.vz) > self._vlim(n):
            return "speed"
        if abs(s.omega) > self._wlim(n):
            return "turn"
        last = r.last
        if last is None:
            return None                                    # the first: where it starts
        if not r.alive and s.alive:                       # a respawn
            if s.t - r.died_at < self.world.respawn_delay - c.respawn_slack:
                return "respawn"
            return None if self.near_spawn(s.x, s.z) else "respawn"
        if not (r.alive and s.alive and last.alive):
            return None                                    # dead, or dying: where does not matter
        dt = max(0.0, min(s.t - last.t, now - r.last_recv + c.jitter))
        if math.hypot(s.x - last.x, s.z - last.z) > self._vlim(n) * dt + c.jump_margin:
            return "jump"
        if abs(math.remainder(s.heading - last.heading, 2 * math.pi)) > self._wlim(n) * dt + 0.1:
            return "turn"
        if self.through_wall(last.x, last.z, s.x, s.z):
            return "wall"
        return None

    def state(self, s: State, now: float) -> State | None:
        """The state to show for ``s`` received at session time ``now``: ``s`` itself
        (with the judge's hit points and life) when valid; else the last valid pose,
        standing still (None before any valid state)."""
        n = s.tank
        r = self.record(n)
        if s.t <= (r.last.t if r.last is not None else -math.inf) or (not r.alive and s.t <= r.died_at):
            return None                   # older than what we hold, or from before its death
        if not r.alive and s.alive and s.t - r.died_at < self.config.jitter:
            # sent before its peer heard of its death: the host's HIT overtook it (or the
            # clocks differ by that much): not a respawn, and no cheat either
            return None
        fault = self._fault(n, s, now)
        if fault is None:
            if not r.alive and s.alive:
                r.alive, r.hp = True, float(self._spec(n).hit_points)
            elif r.alive and not s.alive:
                r.alive, r.died_at = False, s.t            # its own peer says it died
            shown = replace(s, hp=r.hp, alive=r.alive)
            r.last, r.last_recv = shown, now
            return shown
        self.corrections[fault] += 1
        r.strikes[int(now)] += 1
        if r.last is None:
            return None
        last = r.last
        return State(n, s.t, last.x, last.z, last.heading, 0.0, 0.0, 0.0, r.hp, r.alive)

    # ------------------------------------------------------------------ shots
    def shot(self, shot: Shot, now: float) -> str | None:
        """None when tank ``shot.tank`` could have fired ``shot`` (it is then counted as
        its latest); else why not (counted in ``refused_shots``)."""
        fault = self._shot_fault(shot, now)
        if fault is not None:
            self.refused_shots[fault] += 1
            return fault
        r = self.record(shot.tank)
        r.shot_t, r.shot_recv = shot.t, now
        return None

    def _shot_fault(self, shot: Shot, now: float) -> str | None:
        c, n = self.config, shot.tank
        r = self.record(n)
        last = r.last
        if last is None and r.alive:
            # no state yet (the first may be lost or slower than the shot): a tank starts
            # at a spawn point, so that is where its first shots may come from
            if shot.t > now + c.ahead:
                return "ahead"
            return None if self.near_spawn(shot.x, shot.z) and self.on_surface(shot.x, shot.z) else "pose"
        if not r.alive or last is None or not last.alive:
            # a shot fired just before its death may arrive after the host's HIT: taken
            # (from its last pose, within its reload) when it says so by at most ``jitter``
            if r.alive or last is None or not r.died_at - c.jitter <= shot.t <= r.died_at:
                return "dead"
        if shot.t > now + c.ahead:
            return "ahead"
        reload = self._reload(n) * c.reload_factor
        if shot.t - r.shot_t < reload or now - r.shot_recv < reload - c.jitter:
            return "reload"
        dt = abs(shot.t - last.t) + max(0.0, now - r.last_recv) + c.jitter
        if math.hypot(shot.x - last.x, shot.z - last.z) > self._vlim(n) * dt + c.jump_margin:
            return "pose"
        if math.hypot(shot.vx, shot.vz) > self._vlim(n):
            return "speed"
        return None

    # ------------------------------------------------------------------ the host's word
    def hit(self, victim: int, hp: float, killed: bool, t: float) -> None:
        """The host decided: ``victim`` has ``hp`` hit points left (and died at ``t``)."""
        r = self.record(victim)
        r.hp = max(0.0, min(float(hp), float(self._spec(victim).hit_points)))
        if killed and r.alive:
            r.alive, r.died_at = False, t
            if r.last is not None:
                r.last = replace(r.last, alive=False, hp=r.hp)

    def hp(self, n: int) -> float:
        return self.record(n).hp

    def alive(self, n: int) -> bool:
        return self.record(n).alive

    def to_kick(self, n: int, now: float) -> bool:
        """Whether tank ``n`` was corrected more than ``kick_rate`` times in each of the
        last ``kick_seconds`` whole seconds."""
        r = self.records.get(n)
        if r is None or not r.strikes:
            return False
        c, sec = self.config, int(now)
        for old in [k for k in r.strikes if k < sec - c.kick_seconds - 1]:
            del r.strikes[old]
        return all(r.strikes.get(sec - k, 0) > c.kick_rate for k in range(1, c.kick_seconds + 1))

    def report(self) -> dict[str, Any]:
        return {"corrected": dict(sorted(self.corrections.items())),
                "shots_refused": dict(sorted(self.refused_shots.items()))}
