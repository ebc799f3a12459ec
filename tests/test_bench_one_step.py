"""bench/one_step.py's helpers: the two ways take turns, and the grid-surface clock
times only the grid build's call and puts the real function back."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _bench():
    spec = importlib.util.spec_from_file_location("one_step", ROOT / "bench" / "one_step.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_ways_take_turns_and_keep_their_best():
    bench = _bench()
    order = []
    (t_a, c_a, r_a), (t_b, c_b, r_b) = bench.best_turns([lambda: order.append("a") or 1,
                                                          lambda: order.append("b") or 2], 3)
    assert order == ["a", "b"] * 3
    assert (r_a, r_b) == (1, 2)
    assert min(t_a, c_a, t_b, c_b) >= 0


def test_grid_surface_clock_times_the_late_bound_call_and_restores_it(monkeypatch):
    import tanktool.nav.walkable as walkable

    def busy(*args, **kw):  # stands for the surface: some CPU time, then a result
        sum(i * i for i in range(200_000))
        return ("surface", args, kw)

    monkeypatch.setattr(walkable, "walkable_surface", busy)
    bench = _bench()
    with bench.GridSurfaceClock() as clock:
        assert walkable.walkable_surface is not busy
        assert walkable.walkable_surface(1, 2, cell=3) == ("surface", (1, 2), {"cell": 3})
    assert walkable.walkable_surface is busy
    assert clock.seconds > 0.0
