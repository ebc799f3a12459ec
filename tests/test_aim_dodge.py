"""Aiming (sim/agents/aim.py) and dodging (sim/agents/dodge.py)."""

from __future__ import annotations

import dataclasses
import math
import random

import numpy as np
import pytest

from bot_helpers import perceiver, state_of
from tanktool.bots import Senses
from tanktool.formats.walls_txt import WallList, aux_rectangle
from tanktool.sim.agents import aim, dodge
from tanktool.sim.commands import Command
from tanktool.sim.match import load_tank_spec
from tanktool.sim.rules import DEFAULT
from tanktool.sim.world import World


def field(size: float = 400.0) -> WallList:
    return WallList(np.zeros((0, 2, 2)), np.zeros(0, np.int8), aux_rectangle(0.0, 0.0, size, size))


def test_the_intercept_meets_the_target_with_the_shooters_velocity_in_the_shell():
    rng = random.Random(3)
    for _ in range(200):
        sx, sz, tx, tz = (rng.uniform(0, 100) for _ in range(4))
        svx, svz, tvx, tvz = (rng.uniform(-12, 12) for _ in range(4))
        v = rng.uniform(30, 200)
        sol = aim.intercept(sx, sz, svx, svz, tx, tz, tvx, tvz, v)
        assert sol is not None and sol.time > 0
        # the shell: muzzle speed along the heading plus the shooter's velocity
        bx = sx + (v * math.cos(sol.heading) + svx) * sol.time
        bz = sz + (v * math.sin(sol.heading) + svz) * sol.time
        assert math.hypot(bx - (tx + tvx * sol.time), bz - (tz + tvz * sol.time)) < 1e-6
        assert math.hypot(sol.x - bx, sol.z - bz) < 1e-6
        assert aim.predicted_miss(sx, sz, svx, svz, sol.heading, tx, tz, tvx, tvz, v) < 1e-6
    # a target running away faster than the shell cannot be caught
    assert aim.intercept(0, 0, 0, 0, 10, 0, 50, 0, 40) is None


def test_predicted_miss_grows_with_the_aim_error_and_knows_where_the_gun_will_be():
    d, v = 40.0, 40.0
    for err in (0.01, 0.05, 0.1):
        miss = aim.predicted_miss(0, 0, 0, 0, err, d, 0, 0, 0, v)
        assert miss == pytest.approx(d * math.sin(err), rel=1e-9)
    # turning onto the target: fired 0.1 s later at 0.5 rad/s, an error of 0.05 rad is gone
    assert aim.predicted_miss(0, 0, 0, 0, -0.05, d, 0, 0, 0, v, delay=0.1, omega=0.5) < 1e-9
    assert aim.predicted_miss(0, 0, 0, 0, math.pi, d, 0, 0, 0, v) == math.inf       # the wrong way
    # BZFlag's one-step lead is the exact intercept for a target coming straight on
    sol = aim.lead_by_distance(0, 0, 0, 0, d, 0, 0, 5.0, v)
    assert sol.heading == pytest.approx(math.atan2(5.0, v), rel=1e-9)


def test_the_course_prediction_is_the_worlds_motion():
    spec = load_tank_spec("light")
    for advance, strafe in dodge.ESCAPES:
        w = World(field(), [spec], [(200.0, 200.0, 0.3)], seed=0, bounds=[[0, 0], [400, 400]])
        t = w.tanks[0]
        for _ in range(120):                         # get moving: forward and right
            w.step(None, [Command(advance=1.0, strafe=1.0)])
        t.omega = 0.0
        path = dodge.course(state_of(w, 0), advance, strafe, 1.0, step=w.dt)
        for _ in range(120):
            w.step(None, [Command(advance=advance, strafe=strafe)])
            t.omega = 0.0
        _, px, pz = path[-1]
        assert math.hypot(px - t.x, pz - t.z) < 0.05, (advance, strafe)


def _shoot_at_strafer(evade: bool, distance: float, seed: int = 0, still: bool = False) -> tuple[int, int]:
    """A gunner on the exact intercept at a tank strafing at speed, side flipped every
    5 s (or standing, ``still``)."""
    spec = load_tank_spec("light")
    rules = dataclasses.replace(DEFAULT, spawn_protection=0.0, spread=0.0)
    w = World(field(), [spec, spec], [(200.0, 200.0, 0.0), (200.0 + distance, 200.0, math.pi)], seed=seed,
              rules=rules, bounds=[[0, 0], [400, 400]])
    g, target = w.tanks
    ev = dodge.Evasion(0.25)
    eyes = perceiver(w, 1, Senses(math.radians(60), 200.0))
    shots = hits = 0
    side = 1.0
    while w.t < 30.0:
        if int(w.t / 5.0) % 2:
            side = -1.0
        else:
            side = 1.0
        sol = aim.intercept(g.x, g.z, g.vx, g.vz, target.x, target.z, target.vx, target.vz, g.spec.shell_speed)
        err = math.remainder(sol.heading - g.heading, 2 * math.pi)
        miss = aim.predicted_miss(g.x, g.z, g.vx, g.vz, g.heading, target.x, target.z, target.vx, target.vz,
                                  g.spec.shell_speed)
        gun = Command(rotate=max(-1.0, min(1.0, 4.0 * err - 0.6 * g.omega)), fire=miss < 0.5 and w.t > 4.0)
        face = math.remainder(math.atan2(g.z - target.z, g.x - target.x) - target.heading, 2 * math.pi)
        # hold the distance (strafing while facing the gunner would spiral out)
        want = max(-4.0, min(4.0, 0.5 * (math.hypot(g.x - target.x, g.z - target.z) - distance)))
        vf = target.vx * target.c + target.vz * target.s
        cmd = Command(advance=max(-1.0, min(1.0, 0.5 * (want - vf))),
                      rotate=max(-1.0, min(1.0, 3.0 * face - 0.5 * target.omega)), strafe=0.0 if still else side)
        if evade:
            esc = ev.command(w.t, eyes.state(w, target), eyes.shells(w, target))
            if esc is not None:
                cmd = Command(advance=esc[0], rotate=cmd.rotate, strafe=esc[1])
        for e in w.step(None, [gun, cmd]):
            shots += e.kind == "shot" and e.tank == 0
            hits += e.kind == "hit" and e.tank == 0
        target.hp = target.spec.hit_points
    return shots, hits


def test_a_strafing_tank_that_dodges_avoids_shots_from_afar_and_not_close_by():
    far_shots, far_hits = _shoot_at_strafer(True, 55.0)
    assert far_shots >= 5 and far_hits <= 0.5 * far_shots
    still_shots, still_hits = _shoot_at_strafer(False, 55.0, still=True)
    assert still_shots >= 20 and still_hits >= 0.9 * still_shots     # every shot was on target
    near_shots, near_hits = _shoot_at_strafer(True, 15.0)
    assert near_shots >= 4 and near_hits >= 0.8 * near_shots


def test_threats_and_visible_shells():
    spec = load_tank_spec("light")
    walls = WallList(np.array([[[100.0, 150.0], [100.0, 250.0]]]), np.ones(1, np.int8), aux_rectangle(0, 0, 400, 400))
    w = World(walls, [spec, spec, spec], [(50, 200, 0.0), (150, 200, math.pi), (150, 300, -math.pi / 2)],
              seed=0, rules=dataclasses.replace(DEFAULT, spread=0.0, spawn_protection=0.0))
    a, b, c = w.tanks
    a.place(50.0, 200.0, 0.0)          # behind the wall from b
    b.place(150.0, 200.0, math.pi)     # faces a, the wall between
    c.place(150.0, 300.0, -math.pi / 2)
    w.step(None, [Command(fire=True), Command(), Command()])
    shell = w.shells[0]
    assert perceiver(w, 1).shells(w, b) == ()                                  # the wall is in the way
    assert perceiver(w, 0).shells(w, a) == ()                                  # its own
    seen_by_c = perceiver(w, 2).shells(w, c)
    assert len(seen_by_c) == 1 and dodge.threats(state_of(w, 2), seen_by_c) == []     # not flying at c
    # without the wall the shell flies at b: a threat arriving in about 100/40 s
    w2 = World(field(), [spec, spec], [(50, 200, 0.0), (150, 200, math.pi)], seed=0,
               rules=dataclasses.replace(DEFAULT, spread=0.0, spawn_protection=0.0))
    w2.tanks[0].place(50.0, 200.0, 0.0)
    w2.tanks[1].place(130.0, 200.0, math.pi)
    w2.step(None, [Command(fire=True), Command()])
    seen = perceiver(w2, 1).shells(w2, w2.tanks[1])
    th = dodge.threats(state_of(w2, 1), seen)
    assert len(th) == 1 and th[0].arrives == pytest.approx(80.0 / 40.0, abs=0.2) and th[0].miss < 0
    assert [(s.x, s.z, s.owner) for s in seen] == [(w2.shells[0].x, w2.shells[0].z, 0)]
    assert shell.owner == 0
    # a shell keeps its key while it flies (the step it was fired in), in any process
    w2.step(None, [Command(), Command()])
    assert perceiver(w2, 1).shells(w2, w2.tanks[1])[0].key == seen[0].key == (0, 1)
