"""The agents' state machine as data: the table, the toy machine it runs on, the docs."""

from __future__ import annotations

import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from tanktool.bots import IDLE, Command
from tanktool.sim.agents.agent import GUARDS, STATES, TRANSITIONS, transition_table
from tanktool.sim.agents.machine import State, StateMachine, Transition, table_text

ROOT = Path(__file__).resolve().parent.parent


class Count(State):
    """Gives ``n`` commands, then is done and hands on how many it gave."""

    def __init__(self, name: str, n: int) -> None:
        self.name, self.n, self.left, self.entered = name, n, 0, []

    def enter(self, agent, view, p, arg) -> None:
        self.left = self.n
        self.entered.append(arg)
        self.handoff = self.n

    def update(self, agent, view, p):
        if self.left <= 0:
            return None
        self.left -= 1
        return Command(advance=1.0)


def test_rows_are_taken_in_order_done_hands_on_and_chains_stop():
    a, b, c = Count("a", 1), Count("b", 2), Count("c", 0)
    table = [Transition(("a", "b"), "alarm", "c"), Transition(("a",), "done", "b"), Transition(("b",), "done", "a")]
    alarm = {"on": False}
    m = StateMachine({"a": a, "b": b, "c": c}, table, {"alarm": lambda ag, v, p: alarm["on"] and "why"}, "a")
    view = SimpleNamespace(t=0.0)
    m.state.enter(None, view, None, None)
    assert m.think(None, view, None, lambda: IDLE).advance == 1.0 and m.name == "a"
    assert m.think(None, view, None, lambda: IDLE).advance == 1.0 and m.name == "b"
    assert b.entered == [1] and m.trace[-1][1:] == ("a", "done", "b")     # a's handoff went to b
    alarm["on"] = True
    # the alarm's row comes first and c is done at once: c has no done row, so idle
    assert m.think(None, view, None, lambda: IDLE) is IDLE and m.name == "c" and c.entered == ["why"]


def test_an_unknown_guard_or_state_is_refused():
    with pytest.raises(ValueError, match="guards"):
        StateMachine({"a": Count("a", 1)}, [Transition(("a",), "nope", "a")], {}, "a")
    with pytest.raises(ValueError, match="states"):
        StateMachine({"a": Count("a", 1)}, [Transition(("a",), "done", "zz")], {}, "a")


def test_the_agents_table_names_real_states_and_guards_and_every_state_is_reachable():
    named = {n for r in TRANSITIONS for n in r.source} | {r.target for r in TRANSITIONS}
    assert named == set(STATES)
    assert {r.when for r in TRANSITIONS} - {"done"} == set(GUARDS)
    assert all(r.why for r in TRANSITIONS)
    assert table_text(TRANSITIONS, STATES) == transition_table()
    assert transition_table().splitlines()[1].startswith("any but evade, return_fire ")


def test_the_docs_show_the_table_the_code_runs():
    sys.path.insert(0, str(ROOT / "tools"))
    import agent_docs

    text = (ROOT / "docs" / "agents.md").read_text(encoding="utf-8")
    assert agent_docs.with_table(text) == text, "run tools/agent_docs.py"
    assert transition_table() in text


def test_no_agent_module_is_over_600_lines():
    for f in (ROOT / "tanktool" / "sim" / "agents").glob("*.py"):
        assert len(f.read_text(encoding="utf-8").splitlines()) <= 600, f.name


def test_breaking_off_a_lost_fight_is_a_levels_choice_and_no_level_makes_it():
    import dataclasses

    from tanktool.sim.agents import DIFFICULTIES, Agent

    assert not any(lv.break_off for lv in DIFFICULTIES.values())
    sight = SimpleNamespace(x=10.0, z=0.0, index=1, vehicle=None)
    vehicle = SimpleNamespace(shell_damage=25.0, hit_points=115.0)
    view = SimpleNamespace(me=SimpleNamespace(hp=40.0, vehicle=vehicle))
    p = SimpleNamespace(sight=sight, t=10.0)
    lost = Agent(dataclasses.replace(DIFFICULTIES["hard"], break_off=True))
    assert GUARDS["losing"](lost, view, p) == (10.0, 0.0)       # 40 hp left, the enemy whole
    assert not GUARDS["losing"](Agent("hard"), view, p)
    view.me.hp = 115.0
    assert not GUARDS["losing"](lost, view, p)
