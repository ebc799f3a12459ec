"""The crosshair's hit point (game/aim.py) is where the simulation's own shell stops."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tanktool.game.aim import predict
from tanktool.game.session import GameSession
from tanktool.sim.commands import IDLE, Command
from tanktool.sim.rules import Rules


def _segment_distance(p, a, b) -> float:
    p, a, b = (np.asarray(v, float) for v in (p, a, b))
    ab = b - a
    t = 0.0 if not ab.any() else float(np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0))
    return float(np.linalg.norm(a + t * ab - p))


def _flown(session: GameSession) -> tuple[tuple, tuple]:
    """Fire tank 0's gun once and follow its shell: the last step's segment before it stopped."""
    w = session.world
    session.step(Command(fire=True))
    assert len(w.shells) == 1
    shell = w.shells[0]
    seg = ((shell.px, shell.py, shell.pz), (shell.x, shell.y, shell.z))
    for _ in range(2000):
        session.step(IDLE)
        if shell not in w.shells:
            return seg
        seg = ((shell.px, shell.py, shell.pz), (shell.x, shell.y, shell.z))
    raise AssertionError("the shell never stopped")


@pytest.mark.parametrize("arena, gravity, spot", [
    ("box", 0.0, (30.0, 30.0, 0.0)),                 # straight at the east wall
    ("hills", 0.0, (40.0, 60.0, 0.3)),               # into the rolling ground
    ("hills", 0.0, (60.0, 40.0, 1.9)),
])
def test_the_crosshair_marks_where_the_shell_stops(arena, gravity, spot):
    s = GameSession(arena, bots=1, seed=1, player=True, rules=Rules(spread=0.0, shell_gravity=gravity))
    w = s.world
    me, other = w.tanks
    other.alive = False                                  # nobody in the way
    x, z, heading = spot
    me.place(x, z, heading)
    for _ in range(120):                                 # settle on the ground, spawn protection aside
        s.step(IDLE)
    aim = predict(w, me)
    assert aim.target is None
    a, b = _flown(s)
    miss = _segment_distance(aim.impact, a, b)
    assert miss < 0.35, (aim.impact, a, b)
    assert math.dist(aim.muzzle, aim.impact) > 3.0     # it flew somewhere, not a shot into its own hull


def test_the_hit_point_stops_where_the_world_drops_a_shell():
    from tanktool.game.aim import _leaves

    s = GameSession("box", bots=1, seed=1, player=True)
    (x0, z0), (x1, z1) = s.world.bounds
    assert _leaves(s.world, 30.0, 30.0, 10.0, 0.0) == pytest.approx((x1 + 1.0 - 30.0) / 10.0)
    assert _leaves(s.world, 30.0, 30.0, 0.0, -5.0) == pytest.approx((30.0 - (z0 - 1.0)) / 5.0)
    assert _leaves(s.world, 30.0, 30.0, 0.0, 0.0) == math.inf
