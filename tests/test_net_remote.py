"""Remote tanks: interpolation of buffered states, extrapolation, respawns."""

from __future__ import annotations

import math

from tanktool.net.protocol import State
from tanktool.net.remote import RemoteTank


def _s(t, x, z=0.0, h=0.0, vx=0.0, alive=True):
    return State(2, t, x, z, h, vx, 0.0, 0.0, 100.0, alive)


def test_interpolates_between_bracketing_states():
    r = RemoteTank()
    assert r.sample(1.0) is None
    for k in range(5):
        r.push(_s(k * 0.1, k * 1.0, h=3.0 if k % 2 else -3.0, vx=10.0))
    s = r.sample(0.25)
    assert math.isclose(s.x, 2.5)
    # headings interpolate the short way round the ±π seam
    assert abs(abs(s.heading) - math.pi) < 0.2
    assert r.sample(-1.0).x == 0.0                  # before the buffer: the oldest


def test_extrapolates_a_little_then_holds():
    r = RemoteTank(max_extrapolation=0.25)
    r.push(_s(0.0, 0.0, vx=10.0))
    r.push(_s(0.1, 1.0, vx=10.0))
    assert math.isclose(r.sample(0.2).x, 2.0)
    assert math.isclose(r.sample(5.0).x, 1.0 + 10.0 * 0.25)


def test_out_of_order_dropped_and_no_lerp_across_respawn():
    r = RemoteTank()
    r.push(_s(1.0, 10.0))
    r.push(_s(0.5, 99.0))                           # older than the newest: ignored
    assert len(r.states) == 1
    r.push(_s(1.1, 10.0, alive=False))
    r.push(_s(4.0, 50.0))                           # respawned far away
    assert r.sample(3.9).x == 10.0 and not r.sample(3.9).alive
    assert r.sample(4.0).x == 50.0 and r.sample(4.0).alive
