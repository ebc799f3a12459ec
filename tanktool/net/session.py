"""A networked match: one :class:`~tanktool.net.peer.Peer` and a local World, in real time.

Every peer runs a World with one tank slot per player number (tank ``n - 1`` is player
``n``).  Authority, per tank:

- **movement**: each peer simulates its own tank (driven by Commands, like any other
  driver) and sends its state by UDP at ``state_hz``; remote tanks are placed from their
  buffered states, ``INTERP_DELAY`` in the past (:mod:`.remote`).
- **every peer judges** the states and shots it receives (:mod:`.judge`): a state its
  vehicle could not have reached is corrected to the last valid pose, a shot faster
  than the reload, from afar or while dead is not launched; the view of a cheating peer
  never leaves what its vehicle could have done.
- **shots**: the shooter's peer fires and sends SHOT (TCP) with the pose it fired from;
  every other peer launches the same shell from that pose in its own world.
- **hits: the host decides.**  Its world flies every shell against every tank (its own
  exactly, the others where their judged states put them); when one hits, the host
  sends HIT (the victim's hit points after it, and whether it died) to everyone.  A hit
  another peer's world sees is not scored, on its own tank neither: it waits for the
  host's HIT.  Hit points come from the vehicle and the host's HITs, never from a
  peer's state; HITs from anyone but the host are dropped.  So nobody is killed by a
  peer that merely claims it, a cheater cannot refuse to be hit, and no two peers
  score a hit differently.  The host disconnects a member corrected more than 3 times
  a second for 5 seconds.

Computer opponents (``bots``) run on the host like its own tank: they have numbers in the
table (owned by the host), their states and shots go out from the host, and the host
decides hits on them.  When the host leaves, the new host adopts them where it last saw
them and drives them on.
"""

from __future__ import annotations

import logging
import math
import random
import time
import dataclasses
from dataclasses import dataclass, field
from typing import Any, Callable

from ..errors import NetError
from ..sim.body import TankSpec
from ..sim.commands import IDLE, Command
from ..sim.driver import ScriptedDriver
from ..sim.rules import DEFAULT as DEFAULT_RULES
from ..sim.weapons import fire
from ..sim.world import World
from . import protocol as P
from .judge import Judge
from .names import visible
from .peer import Peer, percentile
from .remote import INTERP_DELAY, RemoteTank

STATE_HZ = 30.0
#: a process that falls further behind than this skips steps rather than spiral [s]
MAX_LAG = 0.25
#: what the peer dropped or refused is logged (at ``-v``: one line per kind) as soon as
#: it starts, then at most this often [s]
DROP_LOG_INTERVAL = 5.0
#: ``tanktool -v`` shows this logger's INFO lines
log = logging.getLogger("tanktool.net")



#: the rules of a network match: the default ones without the random spread (each
#: peer makes the shells of the others' shots from their messages, and a spread drawn
#: by the shooter's generator would fly them differently on every peer)
NET_RULES = dataclasses.replace(DEFAULT_RULES, spread=0.0)

@dataclass
class Score:
    shots: int = 0
    hits: int = 0
    kills: int = 0
    deaths: int = 0


@dataclass
class NetMatch:
    """A peer's side of a networked match (build it, then :meth:`run`)."""

    peer: Peer
    arena: Any                       # sim.match.ArenaInfo
    spec: TankSpec
    seed: int = 0
    driver: Callable[[World, Any], Command] | None = None
    bots: int = 0
    #: bots (``play --bot``: names or FILE.py:Class) driving the first computer opponents
    bot_specs: tuple[str, ...] = ()
    state_hz: float = STATE_HZ
    log: Callable[[str], None] = lambda line: None
    world: World = field(init=False)
    remotes: dict[int, RemoteTank] = field(init=False, default_factory=dict)
    scores: dict[int, Score] = field(init=False, default_factory=dict)
    views: list[dict[str, Any]] = field(init=False, default_factory=list)
    left: list[dict[str, Any]] = field(init=False, default_factory=list)
    names: dict[int, str] = field(init=False, default_factory=dict)
    #: set (e.g. from a signal handler) to end the match at the next loop turn
    stop: bool = field(init=False, default=False)
    #: set to restart the traffic statistics at the next loop turn (SIGUSR1 in the CLI)
    restart_stats: bool = field(init=False, default=False)

    def __post_init__(self) -> None:
        self._seat()
        names = [f"p{n}" for n in range(1, self.peer.slots + 1)]
        spawns = self.arena.spawns_for(self.spec)      # its vehicle's own, where it has a grid of its own
        self.world = World(self.arena.walls, [self.spec] * self.peer.slots, spawns, seed=self.seed, names=names,
                           bounds=self.arena.bounds, ground=getattr(self.arena, "ground", None), rules=NET_RULES)
        for t in self.world.tanks:
            self._start(t)
        self.me = self.world.tanks[self.peer.number - 1]
        self.judge = self.peer.judge = Judge(self.world)     # the core judges what comes in
        self.kicked: list[dict[str, Any]] = []
        self.rejoins: list[dict[str, Any]] = []
        self.world.t = self.peer.session_time()
        for t in self.world.tanks:
            if t is not self.me:
                self._absent(t)
        self.drivers: dict[int, Callable[[World, Any], Command]] = {}
        if self.driver is not None:
            self.drivers[self.peer.number] = self.driver
        listed: list = []
        if self.bot_specs:
            from ..sim.bots.lineup import lineup

            listed = lineup(self.bot_specs)
        for k in range(max(self.bots, len(listed))):
            n = self.peer.add_bot(listed[k][0] if k < len(listed) else f"bot{k + 1}")
            if n is None:
                break
            if k < len(listed):     # a bot from a file runs here only: a new host adopts it as a scripted bot
                self.drivers[n] = listed[k][1].driver(self.seed * 1009 + n)
            self._adopt(n, fresh=True)
        for e in self.peer.players():
            self.names[e.number] = e.name

    # ------------------------------------------------------------------ pieces
    def _seat(self) -> None:
        """One slot per tank the arena holds at once, up to the protocol's players: the
        host's room check refuses joiners beyond it, so a 4-tank arena hosts 2-4 players."""
        from ..sim.extra_spawns import slots

        n = self.peer.slots = slots(self.arena, self.spec, P.MAX_PLAYERS)
        want = 1 + max(self.bots, len(self.bot_specs))
        if n < 2 or self.peer.number > n or want > n:
            raise NetError(f"arena {self.arena.name} holds {n} tank{'s' * (n != 1)} of {self.spec.name} at once: "
                           + ("a network match needs 2" if n < 2 else f"not {max(want, self.peer.number)}"))

    @staticmethod
    def _absent(t: Any) -> None:
        t.alive = False
        t.respawn_at = math.inf      # only its own peer brings it back

    def _start(self, t: Any) -> None:
        """Put tank ``t`` at its player number's own spawn place (player n at the n-th):
        the World shuffles its tanks' places with the peer's own seed, and peers choose
        seeds independently, so a member would else start where another peer's tank
        stands (both worlds then push the tanks apart: the host's own tank jumped metres
        when a member joined).  The same on every peer, a different place per number."""
        k = t.index % len(self.world.spawns)
        x, z, h = self.world.spawns[k]
        t.place(x, z, h)
        self.world.stand(t, self.world.spawn_y[k])

    def _local(self) -> list[int]:
        return self.peer.speaks_for()

    def _driver(self, n: int) -> Callable[[World, Any], Command]:
        d = self.drivers.get(n)
        if d is None:
            d = self.drivers[n] = ScriptedDriver(random.Random(self.seed * 1009 + n))
        return d

    def _adopt(self, n: int, fresh: bool = False) -> None:
        """Run tank ``n`` here from now on (a new computer opponent, or one whose host
        left): it goes on from where it was last seen; if dead, it respawns in 3 s."""
        t = self.world.tanks[n - 1]
        if fresh:            # at the spawn point the world gave its slot
            t.hp, t.alive, t.reload = t.spec.hit_points, True, 0.0
        elif not t.alive:
            t.respawn_at = self.world.t + self.world.respawn_delay
        self.remotes.pop(n, None)

    def _score(self, n: int) -> Score:
        return self.scores.setdefault(n, Score())

    def _place_remotes(self, t_view: float) -> None:
        """Remote tanks where their buffered states put them at ``t_view``."""
        local = set(self._local())
        for tank in self.world.tanks:
            n = tank.index + 1
            if n in local:
                continue
            rt = self.remotes.get(n) if n in self.peer.table else None
            s = rt.sample(t_view) if rt is not None else None
            if s is None:
                self._absent(tank)
                continue
            tank.x, tank.z, tank.heading = s.x, s.z, s.heading
            tank.vx, tank.vz, tank.omega = s.vx, s.vz, s.omega
            tank.c, tank.s = math.cos(s.heading), math.sin(s.heading)
            # on a ground: height, level and tilt from where it now is, on the level
            # nearest its last height (states carry no height: the path is continuous)
            self.world.stand(tank, tank.y)
            # hit points and life as the host decided them, never as the peer says
            tank.hp = self.judge.hp(n)
            tank.alive = s.alive and self.judge.alive(n)
            tank.respawn_at = math.inf

    def _remote_shot(self, shot: P.Shot) -> None:
        """Launch a remote tank's shell from the pose it fired from."""
        tank = self.world.tanks[shot.tank - 1]
        saved = (tank.x, tank.z, tank.heading, tank.vx, tank.vz, tank.c, tank.s, tank.y, tank.level, tank.pitch,
                 tank.roll)
        tank.x, tank.z, tank.heading, tank.vx, tank.vz = shot.x, shot.z, shot.heading, shot.vx, shot.vz
        tank.c, tank.s = math.cos(shot.heading), math.sin(shot.heading)
        self.world.stand(tank, tank.y)    # the height and pitch it fired at
        self.world.shells.append(fire(tank, self.world.walls, self.world.rules, None, self.world.ground))
        (tank.x, tank.z, tank.heading, tank.vx, tank.vz, tank.c, tank.s, tank.y, tank.level, tank.pitch,
         tank.roll) = saved

    def _on_net(self, events: list) -> None:
        """What the core took (its judge already checked states and shots)."""
        for ev in events:
            if ev.kind == "state":
                n = ev.body.tank
                self.remotes.setdefault(n, RemoteTank()).push(ev.body)
                if ev.reason == "respawn":
                    # the spawn protection its own world gives it, here too (the host
                    # decides hits; a shot of its own ends it only there)
                    self.world.protected_until[n - 1] = self.world.t + self.world.rules.spawn_protection
            elif ev.kind == "shot":
                self.world.protected_until[ev.body.tank - 1] = -math.inf     # firing ends it
                self._score(ev.body.tank).shots += 1
                self._remote_shot(ev.body)
            elif ev.kind == "hit":
                self._host_hit(ev.body)
            elif ev.kind == "kicked":
                self.log(f"the host disconnected us: {visible(ev.reason)}")
                self.stop = True
            elif ev.kind == "stepdown":
                self._rejoin(ev.reason)
                return                    # the rest of this batch was of the old session
            elif ev.kind == "joined":
                self.names[ev.number] = ev.body.name
                self.remotes.pop(ev.number, None)
                self.log(f"player {ev.number} ({visible(ev.body.name)}) joined")
            elif ev.kind == "left":
                self.remotes.pop(ev.number, None)
                self._absent(self.world.tanks[ev.number - 1])
                self.left.append({"time": round(self.peer.session_time(), 3), "number": ev.number,
                                  "name": ev.body.name, "reason": ev.reason})
                self.log(f"player {ev.number} ({visible(ev.body.name)}) left ({ev.reason})")
            elif ev.kind == "cheater":
                self.kicked.append({"time": round(self.peer.session_time(), 3), "number": ev.number,
                                    "name": ev.body.name, "reason": ev.reason})
                self.log(f"disconnected player {ev.number} ({visible(ev.body.name)}): {ev.reason}")
            elif ev.kind == "host":
                self.log(f"host is now player {ev.number}" + (" (me)" if ev.number == self.peer.number else ""))
            elif ev.kind == "adopt":
                self._adopt(ev.number)
                self.log(f"running computer opponent {ev.number} ({visible(ev.body.name)})")

    def _rejoin(self, why: str) -> None:
        """A newer session goes on without us (we were frozen, or cut off, longer than
        the silence): drop our computer opponents (its host adopted them) and join it as
        a member, our tank carried over to its new number (net/terms.py)."""
        old = self.peer.number
        self.log(f"the session went on without us ({why}): rejoining it")
        self.rejoins.append({"time": round(self.peer.session_time(), 3), "old_number": old, "why": why})
        try:
            self.peer.rejoin()
        except NetError as e:
            # the peer hosts its own session again (net/peer.py): our tank goes on as player 1
            self.log(f"could not rejoin: {e}; hosting alone again, still looking for the others")
            self.rejoins[-1]["failed"] = str(e)
        new = self.peer.number
        self.rejoins[-1]["number"] = new
        mine, tank = self.world.tanks[old - 1], self.world.tanks[new - 1]
        (tank.x, tank.z, tank.heading, tank.c, tank.s, tank.vx, tank.vz, tank.omega) = (
            mine.x, mine.z, mine.heading, mine.c, mine.s, mine.vx, mine.vz, mine.omega)
        self.world.stand(tank, mine.y)
        tank.hp, tank.alive, tank.reload, tank.respawn_at = mine.hp, mine.alive, mine.reload, mine.respawn_at
        self._absent(mine)
        self.me = tank
        driver = self.drivers.get(old)
        self.drivers = {new: driver} if driver is not None else {}
        self.remotes.clear()
        self.judge = self.peer.judge = Judge(self.world)
        self.names = {e.number: e.name for e in self.peer.players()}
        self.world.t = self.peer.session_time()

    def _host_hit(self, h: P.Hit) -> None:
        """The host's HIT (the core's judge noted the victim's hit points and death): a
        tank of ours takes them (and, killed, respawns after the delay)."""
        self._count_hit(h.shooter, h.victim, h.killed)
        if h.victim in self._local():
            t = self.world.tanks[h.victim - 1]
            t.hp = max(0.0, min(h.hp, t.spec.hit_points))
            if h.killed and t.alive:
                t.alive = False
                t.respawn_at = self.world.t + self.world.respawn_delay

    def _count_hit(self, shooter: int, victim: int, killed: bool) -> None:
        self._score(shooter).hits += 1
        if killed:
            self._score(shooter).kills += 1
            self._score(victim).deaths += 1

    def _state_of(self, n: int) -> P.State:
        m = self.world.tanks[n - 1]
        return P.State(n, max(self.world.t, 0.0), m.x, m.z, math.remainder(m.heading, 2 * math.pi),
                       m.vx, m.vz, m.omega, m.hp, m.alive)

    def _record_view(self, second: int) -> None:
        tanks = {}
        for n in sorted(self.peer.table):
            t = self.world.tanks[n - 1]
            tanks[str(n)] = [round(t.x, 3), round(t.z, 3), bool(t.alive), round(t.y, 3)]
        self.views.append({"t": second, "tanks": tanks})

    def step(self) -> list:
        """One fixed step of the local world, with the network around it; returns the
        world's events of this step."""
        w = self.world
        local = self._local()
        self._place_remotes(w.t + w.dt - INTERP_DELAY)
        commands: list[Command | None] = [None] * len(w.tanks)
        poses = {}
        before = {}
        for n in local:
            t = w.tanks[n - 1]
            commands[n - 1] = self._driver(n)(w, t) if t.alive else IDLE
            poses[n] = (t.x, t.z, t.heading, t.vx, t.vz)
            before[n] = (t.hp, t.alive, t.respawn_at)
        events = w.step(None, commands)
        host = self.peer.is_host
        for ev in events:
            if ev.kind == "shot" and ev.tank + 1 in poses:
                self._score(ev.tank + 1).shots += 1
                self.peer.send_event(P.Shot(ev.tank + 1, w.t, *poses[ev.tank + 1]))
            elif ev.kind == "hit" and host:
                # the host decides: this hit is real, tell everyone
                victim = w.tanks[ev.other]
                killed = not victim.alive
                self.judge.hit(ev.other + 1, max(victim.hp, 0.0), killed, w.t)
                self._count_hit(ev.tank + 1, ev.other + 1, killed)
                self.peer.send_event(P.Hit(ev.tank + 1, ev.other + 1, w.t, ev.value, max(victim.hp, 0.0), killed,
                                           ev.x, ev.z))
            elif ev.kind == "hit" and ev.other + 1 in before:
                # not the host: our own tank waits for the host's HIT
                t = w.tanks[ev.other]
                t.hp, t.alive, t.respawn_at = before[ev.other + 1]
        for t in w.tanks:     # a remote tank "killed" in our world waits for its own peer
            if t.index + 1 not in poses and not t.alive:
                t.respawn_at = math.inf
        return events

    def begin(self) -> None:
        """Start the real-time clocks (``run`` does; a front end that calls :meth:`pump`
        from its own loop calls this first)."""
        start = time.monotonic()
        self.started = start
        self.next_step = start
        self.next_state = start
        self.next_view = math.floor(self.world.t) + 1
        self.skipped = 0
        self.stats_since = start
        self.drop_log_since = start          # the span the next drop lines cover
        self.drop_log_at = -math.inf         # when drop lines were last logged

    def pump(self, until: float | None = None, before_step: Callable[[], None] | None = None) -> list:
        """One turn of the real-time loop: read the network (waiting at most until the
        next step or state is due, or ``until``; without ``until`` it does not wait),
        take the steps that are due (``before_step`` is called before each), send the
        local tanks' states when due.  Returns the events of the steps taken."""
        w, peer = self.world, self.peer
        now = time.monotonic()
        if self.restart_stats:
            self.restart_stats = False
            peer.reset_stats()
            self.stats_since = now
        wait = 0.0 if until is None else max(0.0, min(self.next_step, self.next_state, until) - now)
        self._on_net(peer.poll(wait))
        now = time.monotonic()
        if now - self.next_step > MAX_LAG:          # starved of CPU: skip, keep real time
            self.skipped += int((now - self.next_step) / w.dt)
            self.next_step = now
            w.t = peer.session_time()
        events: list = []
        while self.next_step <= now:
            if before_step is not None:
                before_step()
            events.extend(self.step())
            self.next_step += w.dt
            if w.t >= self.next_view:
                self._record_view(self.next_view)
                self.next_view = math.floor(w.t) + 1
        if now >= self.next_state:
            for n in self._local():
                peer.send_state(self._state_of(n))
            self.next_state += 1.0 / self.state_hz
            if now - self.next_state > MAX_LAG:
                self.next_state = now
        if peer.dropped.grown and now - self.drop_log_at >= DROP_LOG_INTERVAL:
            self.log_drops()
        return events

    def log_drops(self) -> None:
        """Log (INFO, shown at ``-v``) one line per kind of message the peer dropped or
        refused since the last call: attacks leave a trace, not a line per packet."""
        now = time.monotonic()
        for line in self.peer.dropped.lines(now - self.drop_log_since):
            log.info(line)
        self.drop_log_since = self.drop_log_at = now

    def run(self, seconds: float) -> dict[str, Any]:
        """Play ``seconds`` of real time; return the report."""
        self.begin()
        end = self.started + seconds
        while not self.stop:
            if time.monotonic() >= end:
                break
            self.pump(until=end)
        return self.finish()

    def finish(self) -> dict[str, Any]:
        """The report of the match so far (``run`` ends with it)."""
        if hasattr(self, "drop_log_at"):
            self.log_drops()
        return self.report(time.monotonic() - self.started, self.skipped)

    # ------------------------------------------------------------------ report
    def report(self, wall: float, skipped: int = 0) -> dict[str, Any]:
        peer = self.peer
        if not hasattr(self, "stats_since"):
            self.stats_since = time.monotonic() - wall
        peers = []
        for e in peer.players():
            t = self.world.tanks[e.number - 1]
            sc = self._score(e.number)
            peers.append({"number": e.number, "name": e.name, "address": f"{e.ip}:{e.tcp_port}",
                          "bot": e.is_bot, "run_by": e.owner or e.number,
                          "position": [round(t.x, 3), round(t.z, 3)], "alive": bool(t.alive),
                          "hit_points": round(max(t.hp, 0.0), 2), "shots": sc.shots, "hits": sc.hits,
                          "kills": sc.kills, "deaths": sc.deaths})
        lat = list(peer.latencies)
        return {
            "mode": "network",
            "arena": self.arena.name,
            "vehicle": self.spec.name,
            "seed": self.seed,
            "me": peer.number,
            "name": peer.name,
            "host": peer.host_number,
            "seconds": round(wall, 3),
            "stats_seconds": round(time.monotonic() - self.stats_since, 3),   # what network counts cover
            "session_time": round(self.world.t, 3),
            "peers": peers,
            "left": self.left,
            "host_changes": [{"time": round(t, 3), "host": h} for t, h in peer.host_changes],
            "term": peer.term,
            "rejoined": self.rejoins,
            "network": peer.network_report(),
            "judge": dict(self.judge.report(), kicked=self.kicked),
            "latency_ms": {"samples": len(lat), "p50": _ms(percentile(lat, 50)), "p99": _ms(percentile(lat, 99))},
            "views": self.views,
            "timing": {"wall_clock_s": round(wall, 3), "steps": self.world.steps, "skipped_steps": skipped},
        }


def _ms(v: float) -> float | None:
    return None if math.isnan(v) else round(v * 1000.0, 3)
