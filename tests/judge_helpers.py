"""Helpers for the judge's tests: a world as a network match builds it, a tank's state
as a peer sends it, and scripted tanks fighting while their states, shots and the
host's hits reach another peer's judge over a simulated network."""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field

from tanktool.net import protocol as P
from tanktool.net.judge import Judge
from tanktool.net.session import NET_RULES
from tanktool.net.simnet import SimNet
from tanktool.sim.driver import ScriptedDriver
from tanktool.sim.match import load_match_arena, load_tank_spec
from tanktool.sim.world import World

STATE_DT = 1.0 / 30.0     # the game's state rate


def judge_world(arena: str, tanks: int = 4, seed: int = 0, vehicle: str = "light",
                spawns: int | None = None) -> World:
    """A world on ``arena`` with ``tanks`` of ``vehicle`` under the network rules; with
    ``spawns``, cut to its first that many spawn points."""
    info = load_match_arena(arena)
    spec = load_tank_spec(vehicle)
    points = info.spawns if spawns is None else info.spawns[:spawns]
    return World(info.walls, [spec] * tanks, points, seed=seed, bounds=info.bounds, ground=info.ground,
                 rules=NET_RULES)


def tank_state(t, now: float) -> P.State:
    """The state a peer sends for tank ``t`` (player number: its index + 1)."""
    return P.State(t.index + 1, now, t.x, t.z, math.remainder(t.heading, 2 * math.pi), t.vx, t.vz, t.omega, t.hp,
                   t.alive)


@dataclass
class JudgedMatch:
    """What the judge took in ``judge_match``."""

    judged: int = 0                 # states shown (not dropped as older than the newest)
    shots: int = 0                  # shots the judge took (a refused one fails the run)
    deaths: int = 0                 # kills the host reported
    respawns: list[tuple[float, float]] = field(default_factory=list)    # where tanks came back
    udp: SimNet | None = None


def judge_match(w: World, judge: Judge, seconds: float, seed: int, senders: int | None = None) -> JudgedMatch:
    """Scripted tanks fight in ``w`` for ``seconds``; the states of the first ``senders``
    (all by default) go over UDP (30 Hz, 50-200 ms, 5 % lost, some reordered), shots and
    the host's hits over TCP (delayed, not lost), to ``judge``.  Asserts that the judge
    refuses none of the honest shots."""
    drivers = [ScriptedDriver(random.Random(seed * 10 + k)) for k in range(len(w.tanks))]
    udp = SimNet(seed=seed, delay=0.05, jitter=0.15, loss=0.05, reorder=0.05)
    tcp = SimNet(seed=seed + 100, delay=0.05, jitter=0.15)
    out = JudgedMatch(udp=udp)
    next_state = 0.0
    while w.t < seconds:
        poses = {t.index: (t.x, t.z, t.heading, t.vx, t.vz) for t in w.tanks}
        events = w.step(None, [d(w, t) if t.alive else None for d, t in zip(drivers, w.tanks)])
        for ev in events:
            n = ev.tank + 1
            if ev.kind == "shot":
                tcp.send(n, 0, P.Shot(n, w.t, *poses[ev.tank]))
            elif ev.kind == "hit":
                victim = w.tanks[ev.other]
                tcp.send(0, 0, ("hit", ev.other + 1, victim.hp, not victim.alive, w.t))
            elif ev.kind == "respawn":
                out.respawns.append((ev.x, ev.z))
        if w.t >= next_state:
            next_state += STATE_DT
            for t in w.tanks[:senders]:
                udp.send(t.index + 1, 0, tank_state(t, w.t))
        for net in (udp, tcp):
            net.advance(w.dt)
        for _, _, m in tcp.deliver():
            if isinstance(m, P.Shot):
                assert judge.shot(m, tcp.now) is None, (m, judge.record(m.tank))
                out.shots += 1
            else:
                _, victim, hp, killed, t_hit = m
                judge.hit(victim, hp, killed, t_hit)
                out.deaths += killed
        for _, _, s in udp.deliver():
            out.judged += judge.state(s, udp.now) is not None
    return out
