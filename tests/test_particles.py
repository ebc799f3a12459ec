"""Particles (game/particles.py): bursts by recipe and level, motion, the budget,
steady emitters, and a session's effects becoming bursts, dust and wreck smoke."""

import numpy as np
import pytest

from tanktool.game.particles import INSTANCE, RECIPES, Particles, SessionEffects
from tanktool.game.session import Effect, GameSession


def test_levels_scale_bursts_and_off_makes_none():
    made = {lvl: Particles(lvl, seed=1).emit("explosion", (0, 1, 0)) for lvl in ("off", "low", "normal", "high")}
    assert made["off"] == 0 < made["low"] < made["normal"] < made["high"]
    assert made["high"] == sum(b.count for b in RECIPES["explosion"])


def test_motion_gravity_floor_and_death():
    p = Particles("high", seed=2)
    p.emit("hit", (0.0, 1.0, 0.0), (1.0, 0.0, 0.0))
    sparks = p.lift < 0
    y0 = p.pos[sparks, 1].copy()
    for _ in range(30):
        p.update(1 / 60)
    assert (p.pos[:, 1] >= 0.0 - 1e-9).all()              # nothing falls through the floor
    assert len(p) < sum(b.count for b in RECIPES["hit"])   # the shortest-lived are gone
    for _ in range(200):
        p.update(1 / 60)
    assert len(p) == 0                                    # all die
    assert len(y0)


def test_budget_and_instances_sorted_far_first():
    p = Particles("low", seed=3)
    for k in range(100):
        p.emit("explosion", (k * 3.0, 1.0, 0.0))
    assert len(p) == p.budget
    rows = p.instances((0.0, 0.0, 0.0))
    assert rows.shape == (len(p), INSTANCE) and rows.dtype == np.float32
    d = np.linalg.norm(rows[:, :3], axis=1)
    assert (np.diff(d) <= 1e-3).all()                     # back to front for blending
    assert ((rows[:, 4:8] >= 0) & (rows[:, 4:8] <= 1)).all()


def test_steady_emitter_keeps_its_rate():
    p = Particles("high", seed=4)
    made = sum(p.emit_steady("k", "dust", 10.0, 1 / 60, (0, 0, 0)) for _ in range(120))
    assert made in (19, 20)                               # 10 a second for 2 s (the last may round down)


def test_session_effects_become_bursts_dust_and_smoke():
    s = GameSession("box", bots=3, seed=5, player=False)
    fx = SessionEffects("high", seed=0)
    fx.sync(s)
    s.effects.append(Effect("explosion", 30.0, 1.5, 30.0, s.t))
    s.effects.append(Effect("flash", 10.0, 1.5, 10.0, s.t, heading=0.0))
    fx.sync(s)
    n = len(fx.particles)
    assert n == sum(b.count for b in RECIPES["explosion"]) + sum(b.count for b in RECIPES["shot"])
    fx.sync(s)
    assert len(fx.particles) == n                         # an effect bursts once
    t = s.world.tanks[0]
    t.vx, t.vz = 10.0, 0.0                                # moving: dust behind the tracks
    wreck = s.world.tanks[1]
    wreck.alive = False                                   # a wreck: smoke and flames
    fx.sync(s)
    s.world.t += 0.5
    fx.sync(s)
    p = fx.particles
    assert np.isfinite(p.pos).all()
    young = p.age <= 0.51
    near_wreck = young & (np.hypot(p.pos[:, 0] - wreck.x, p.pos[:, 2] - wreck.z) < 4.0)
    assert (near_wreck & (p.glow > 0.5)).sum() >= 5       # it burns
    assert (near_wreck & (p.glow < 0.5)).sum() >= 2       # and smokes
    behind = young & (np.hypot(p.pos[:, 0] - t.x, p.pos[:, 2] - t.z) < 6.0) & (p.glow < 0.5)
    assert behind.sum() >= 3                              # dust behind the tracks
    for _ in range(20):                                   # 10 s on: the fire is out, the smoke goes on
        s.world.t += 0.5
        fx.sync(s)
    young = p.age <= 0.51
    near_wreck = young & (np.hypot(p.pos[:, 0] - wreck.x, p.pos[:, 2] - wreck.z) < 4.0)
    assert (near_wreck & (p.glow > 0.5)).sum() == 0 and (near_wreck & (p.glow < 0.5)).sum() >= 2


def test_a_shell_stopped_by_a_wall_ricochets():
    s = GameSession("box", bots=6, seed=6, player=False)
    fx = SessionEffects("high", seed=0)
    ricochets = 0
    for _ in range(120 * 15):
        s.step()
        before = len(fx.particles)
        shells = len(fx._shells)
        fx.sync(s)
        if shells and len(s.world.shells) < shells and not any(e.kind == "impact" and e.age(s.t) < 0.05
                                                                 for e in s.effects):
            ricochets += len(fx.particles) > before
    assert ricochets > 0


@pytest.mark.parametrize("kind", sorted(RECIPES))
def test_recipes_are_sane(kind):
    for b in RECIPES[kind]:
        assert b.count >= 1 and 0 < b.life[0] <= b.life[1] and b.size[0] > 0
        assert all(0.0 <= c <= 1.0 for c in b.rgba0 + b.rgba1) and 0.0 <= b.glow <= 1.0
