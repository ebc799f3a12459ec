"""The judge and spawning beyond the spawn points (issues 25 and 27): when more tanks play
than an arena has spawn points, a tank (re)spawns at a free place of the ground
(sim/extra_spawns.py); every peer's judge takes a respawn there -- whatever number of
tanks its own world was built with -- and still corrects one anywhere else."""

from __future__ import annotations

import math

import numpy as np
import pytest
from judge_helpers import judge_match, judge_world

from tanktool.net import protocol as P
from tanktool.net.judge import Judge
from tanktool.sim.match import load_match_arena, load_tank_spec


def _world(arena: str, tanks: int, seed: int = 0):
    """A world on ``arena`` cut to its first 2 spawn points."""
    return judge_world(arena, tanks, seed=seed, spawns=2)


def _respawn(judge: Judge, x: float, z: float, t0: float = 1.0) -> P.State | None:
    """Tank 2 seen alive at a spawn point, killed by the host, then back at (x, z)."""
    sx, sz, _ = judge.world.spawns[1]
    judge.state(P.State(2, t0, sx, sz, 0.0, 0.0, 0.0, 0.0, 100.0, True), t0)
    judge.hit(2, 0.0, True, t0 + 0.1)
    t = t0 + 0.2 + judge.world.respawn_delay
    return judge.state(P.State(2, t, x, z, 0.0, 0.0, 0.0, 0.0, 100.0, True), t)


@pytest.mark.parametrize("arena", ["maze", "fort"])
def test_a_respawn_at_every_free_place_is_taken_and_elsewhere_corrected(arena):
    """The judge's world was built for the 4 tanks that play; the players' worlds for 8
    (a network match's slots), so a tank may come back at any of 6 free places."""
    places = _world(arena, 8).spawns
    for x, z, _ in places:
        judge = Judge(_world(arena, 4))
        s = _respawn(judge, x, z)
        assert s is not None and s.alive and (s.x, s.z) == (x, z), (x, z, judge.report())
        assert judge.corrections == {}
    # a teleport disguised as a respawn: on the ground, but far from every place
    judge = Judge(_world(arena, 4))
    g = judge.world.ground
    (x0, z0), (x1, z1) = judge.world.bounds
    far = [(float(x), float(z)) for x in np.arange(x0 + 1.0, x1, 1.0) for z in np.arange(z0 + 1.0, z1, 1.0)
           if g.locate(x, z) >= 0 and min(math.hypot(x - px, z - pz) for px, pz, _ in places) > 5.0]
    assert far
    x, z = far[len(far) // 2]
    s = _respawn(judge, x, z)
    assert s is not None and not s.alive and (s.x, s.z) != (x, z)
    assert judge.corrections == {"respawn": 1}
    # nor a first shot from there before any state (a tank starts at a spawn place)
    assert judge.shot(P.Shot(3, 1.0, x, z, 0.0, 0.0, 0.0), 1.0) == "pose"
    assert judge.shot(P.Shot(4, 1.0, places[5][0], places[5][1], 0.0, 0.0, 0.0), 1.0) is None


def test_six_honest_tanks_on_two_spawn_points_are_never_corrected():
    """Six scripted tanks fight for 40 s on box cut to 2 spawn points, in worlds of a
    network match's 8 slots (2 empty); their states (UDP: 50-200 ms, 5 % lost), shots
    and the host's hits (TCP) reach a judge whose world was built for the 6.  Tanks die
    and come back at free places; none is corrected."""
    seed = 4
    w = _world("box", P.MAX_PLAYERS, seed=seed)
    for t in w.tanks[6:]:                     # empty slots, as net/session.py keeps them
        t.alive, t.respawn_at = False, math.inf
    judge = Judge(_world("box", 6, seed=seed))
    run = judge_match(w, judge, 40.0, seed, senders=6)
    extra_respawns = sum(min(math.hypot(rx - x, rz - z) for x, z, _ in w.spawns[:2]) > 2.0
                         for rx, rz in run.respawns)
    assert judge.corrections == {} and judge.refused_shots == {}, judge.report()
    assert run.judged > 2000 and extra_respawns >= 1


class _Peer:
    """What NetMatch reads of its peer while it is built."""

    def __init__(self, number: int) -> None:
        self.number = number

    def session_time(self) -> float:
        return 0.0

    def players(self) -> list:
        return []


@pytest.mark.parametrize("arena", ["box", "maze"])
def test_each_player_starts_at_its_own_place_whatever_the_seeds(arena):
    """Peers choose their seeds independently (the window's and ``play``'s own): player n
    starts at the n-th spawn place on every peer, so no two players start on the same
    one (a member joining on the host's tank pushed it metres away)."""
    from tanktool.net.session import NetMatch

    info = load_match_arena(arena)
    if arena == "maze":
        info.spawns = info.spawns[:2]             # 6 of the 8 start at free places
    spec = load_tank_spec("light")
    starts = {}
    for n in range(1, P.MAX_PLAYERS + 1):
        for seed in (0, 4, 11):
            m = NetMatch(_Peer(n), info, spec, seed=seed)
            x, z, h = m.world.spawns[n - 1]
            t = m.world.tanks[n - 1]
            assert t is m.me and t.position == pytest.approx((x, z)) and t.heading == h
            starts.setdefault(n, t.position)
            assert t.position == pytest.approx(starts[n])
    xz = np.array(list(starts.values()))
    assert np.hypot(*(xz[:, None] - xz[None]).transpose(2, 0, 1))[np.triu_indices(len(xz), 1)].min() > 3.0
