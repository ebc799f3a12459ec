"""The bot API (tanktool.bots, issue 31): load_bot's names and files and its errors,
the driver (a failing bot idles and the match goes on; time over the budget counted,
never acted on; the think rate; death), a view that holds no world internals, senses
kept within the limits, and the two example bots of docs/bots.md."""

from __future__ import annotations

import gc
import logging
import math
import types

import numpy as np
import pytest

from bot_helpers import view_of
from sim_fixtures import ROOT, box_world
from tanktool.bots import BUILTIN, LIMITS, Bot, BotDriver, Command, Senses, load_bot
from tanktool.errors import TanktoolError
from tanktool.sim.body import Tank
from tanktool.sim.commands import IDLE
from tanktool.sim.match import load_match_arena, load_tank_spec
from tanktool.sim.world import World

EXAMPLES = ROOT / "examples" / "bots"


def test_builtin_names_make_fresh_bots_that_act():
    w = box_world([(20.0, 10.0), (50.0, 14.0)], headings=[0.0, math.pi])
    assert set(BUILTIN) == {"easy", "normal", "hard", "robot", "camper", "duellist", "novice"}
    for name in BUILTIN:
        maker = load_bot(name)
        a, b = maker.make(), maker.make()
        assert a is not b and callable(a.act) and maker.name == name
        cmd = maker.driver(1)(w, w.tanks[0])
        assert isinstance(cmd, Command)


def _write(tmp_path, text, name="mybot.py"):
    p = tmp_path / name
    p.write_text(text)
    return p


GOOD = """
from tanktool.bots import Bot, Command

class Spinner(Bot):
    def act(self, view):
        return Command(rotate=1.0)

class Helper:
    pass
"""


def test_a_bot_from_a_file(tmp_path):
    p = _write(tmp_path, GOOD)
    maker = load_bot(f"{p}:Spinner")
    assert maker.name == "Spinner" and maker.make().act(None) == Command(rotate=1.0)
    assert load_bot(str(p)).name == "Spinner"          # the only bot class: no need to name it


@pytest.mark.parametrize("spec, text, message", [
    ("{dir}/missing.py:Bot", None, "no such file"),
    ("{p}:Nope", GOOD, "has no Nope (bot classes in it: Spinner)"),
    ("{p}:Helper", GOOD, "class Helper has no act(self, view) method"),
    ("{p}", "x = (\n", "syntax error"),
    ("{p}:B", "raise RuntimeError('boom')\n", "loading it raised RuntimeError: boom"),
    ("{p}:B", "class B:\n    def __init__(self, level):\n        pass\n    def act(self, view):\n        pass\n",
     "must be callable without arguments"),
    ("{p}", "class A:\n    def act(self, v): pass\nclass B:\n    def act(self, v): pass\n", "bot classes in the file: A, B"),
    ("godlike", None, "no such built-in bot"),
    ("", None, "expected a name"),
])
def test_bad_bot_specs_are_one_clear_line(tmp_path, spec, text, message):
    p = _write(tmp_path, text) if text is not None else tmp_path / "x.py"
    with pytest.raises(TanktoolError) as e:
        load_bot(spec.format(dir=tmp_path, p=p))
    assert message in str(e.value) and "\n" not in str(e.value)
    if text == "x = (\n":
        assert f"{p}:1" in str(e.value)


class Flaky(Bot):
    """Fails every other call, in two ways."""

    def __init__(self):
        self.calls = 0

    def act(self, view):
        self.calls += 1
        if self.calls % 4 == 1:
            raise ValueError("oops")
        if self.calls % 4 == 3:
            return "full speed"
        return Command(advance=1.0)


def test_a_bot_that_raises_idles_that_step_with_a_warning_and_the_match_goes_on(caplog):
    w = box_world([(20.0, 10.0)])
    drv = BotDriver(Flaky(), 0, name="flaky")
    with caplog.at_level(logging.WARNING, logger="tanktool.bots"):
        cmds = []
        for _ in range(8):
            cmds.append(drv(w, w.tanks[0]))
            w.step(None, [cmds[-1]])
    assert cmds[0] is IDLE and cmds[1] == Command(advance=1.0) and cmds[2] is IDLE
    assert drv.stats.errors == 4 and drv.stats.calls == 8
    # one warning per kind of failure, naming the bot and what went wrong
    msgs = [r.getMessage() for r in caplog.records]
    assert len(msgs) == 2 and "flaky" in msgs[0] and "ValueError: oops" in msgs[0]
    assert "act returned str, not a Command" in msgs[1]


def test_time_over_the_budget_is_counted_and_changes_nothing():
    def play(budget):
        arena, spec = load_match_arena("box"), load_tank_spec("light")
        w = World(arena.walls, [spec, spec], arena.spawns, seed=4, bounds=arena.bounds)
        drivers = [load_bot("hard").driver(11, budget=budget), load_bot("robot").driver(12, budget=budget)]
        for _ in range(600):
            w.step(None, [d(w, t) for d, t in zip(drivers, w.tanks)])
        return w.state(), [d.stats for d in drivers]

    (a, sa), (b, sb) = play(0.0), play(math.inf)
    assert a == b
    assert all(s.over_budget == s.calls > 0 for s in sa) and all(s.over_budget == 0 for s in sb)


def test_the_think_rate_and_death():
    calls = []

    class Counter(Bot):
        think_hz = 10.0

        def act(self, view):
            calls.append((view.t, view.me.alive))
            return Command(advance=0.5)

    w = box_world([(20.0, 10.0), (50.0, 10.0)])
    drv = BotDriver(Counter(), 0)
    me = w.tanks[0]
    for _ in range(120):
        assert drv(w, me) == Command(advance=0.5)        # held between calls
        w.step(None, [drv.command])
    assert len(calls) == 10
    me.alive, me.respawn_at = False, w.t + 0.5
    for _ in range(120):
        w.step(None, [drv(w, me)])
    # called once dead, and at once when back
    dead = [c for c in calls[10:] if not c[1]]
    assert len(dead) == 1 and me.alive and calls[11][1] and calls[11][0] - me.respawn_at < 2 * w.dt


def test_a_view_holds_no_world_or_tank_and_senses_stay_within_the_limits():
    class Greedy(Bot):
        senses = Senses(half_angle=math.pi, vision_range=1e9, hearing_radius=math.inf, engine_radius=-3.0,
                        hearing_noise=0.0, radar=False)

    w = box_world([(20.0, 10.0), (50.0, 10.0)])
    drv = BotDriver(Greedy(), 0)
    view = view_of(drv, w)
    s = view.senses
    assert (s.half_angle, s.vision_range, s.hearing_radius, s.engine_radius, s.hearing_noise) == \
        (LIMITS.half_angle, LIMITS.vision_range, LIMITS.hearing_radius, 0.0, LIMITS.hearing_noise)
    # nothing reachable from the view is the world or a tank (modules and classes are
    # not followed: they reach everything)
    seen, todo = set(), [view]
    while todo:
        o = todo.pop()
        if id(o) in seen or isinstance(o, (type, types.ModuleType, types.FunctionType, np.ndarray)):
            continue
        seen.add(id(o))
        assert not isinstance(o, (World, Tank)), type(o)
        todo.extend(gc.get_referents(o))
    assert len(seen) > 20


def _duel(spec: str, opponent: str, arena: str, seed: int, seconds: float = 60.0):
    a, tank = load_match_arena(arena), load_tank_spec("light")
    w = World(a.walls, [tank, tank], a.spawns, seed=seed, bounds=a.bounds, ground=a.ground)
    drivers = [load_bot(spec).driver(w.rng.getrandbits(64)), load_bot(opponent).driver(w.rng.getrandbits(64))]
    for _ in range(int(seconds / w.dt)):
        w.step(None, [d(w, t) for d, t in zip(drivers, w.tanks)])
    return w, drivers


@pytest.mark.parametrize("example", ["charger.py:Charger", "sniper.py:Sniper"])
def test_the_example_bots_play_and_beat_easy_in_the_box(example):
    w, (drv, _) = _duel(f"{EXAMPLES / example}", "easy", "box", seed=0)
    me, other = w.tanks
    assert drv.stats.errors == 0 and me.shots >= 5 and me.kills > other.kills
    again, _ = _duel(f"{EXAMPLES / example}", "easy", "box", seed=0)
    assert again.state() == w.state()                        # a seed replays exactly
