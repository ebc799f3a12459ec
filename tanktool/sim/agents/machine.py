"""A state machine whose transitions are data.

A :class:`State` has ``enter``, ``update`` (the command for this think, or None when
it is done) and ``exit``.  The transitions are a table of rows ``(from, when, to)``
(:class:`Transition`), checked in order at every think: the first row whose ``from``
holds the current state and whose guard ``when`` holds is taken; a guard returns
False/None, or a value handed to the new state's ``enter`` (where to search from,
what to evade).  The guard ``"done"`` holds when the state's ``update`` returned no
command; the value it hands on is the finished state's ``handoff``.  A transition may
lead on to another in the same think (attack --killed--> wander --leading--> ambush),
at most ``HOPS`` of them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Generic, Mapping, Sequence, TypeVar

from ..commands import Command

if TYPE_CHECKING:  # pragma: no cover
    from ..bots import View
    from .perception import Percept

A = TypeVar("A")
#: transitions taken in one think at most (a chain of them)
HOPS = 4


class State(Generic[A]):
    """One state of an agent ``A`` (see the module docstring)."""

    name = ""
    #: what a finished state hands to the next (by a ``done`` row)
    handoff: Any = None

    def enter(self, agent: A, view: "View", p: "Percept", arg: Any) -> None:
        """Called on entering, with the guard's value."""

    def update(self, agent: A, view: "View", p: "Percept") -> Command | None:
        """The command for this think; None: done."""
        return None

    def exit(self, agent: A, view: "View") -> None:
        """Called on leaving."""


@dataclass(frozen=True)
class Transition:
    """From any state in ``source`` (``("*",)``: every state), when the guard ``when``
    holds, to ``target``."""

    source: tuple[str, ...]
    when: str
    target: str
    #: what the row means, for the table in the docs
    why: str = ""

    def applies(self, state: str) -> bool:
        return self.source == ("*",) or state in self.source


Guard = Callable[[A, "View", "Percept"], Any]


def table_text(table: Sequence[Transition], states: Sequence[str]) -> str:
    """The transition table as text, one row a line (``from  when  to  why``); a row
    from most of ``states`` reads "any but" the others."""
    def source(row: Transition) -> str:
        if row.source == ("*",) or set(row.source) == set(states):
            return "any"
        if len(row.source) > len(states) / 2:
            return "any but " + ", ".join(n for n in states if n not in row.source)
        return ", ".join(row.source)

    rows = [("from", "when", "to", "")] + [(source(r), r.when, r.target, r.why) for r in table]
    # each column as wide as its widest cell and two spaces
    wa, ww, wb = (max(len(r[k]) for r in rows) + 2 for k in range(3))
    return "\n".join(f"{a:<{wa}}{w:<{ww}}{b:<{wb}}{why}".rstrip() for a, w, b, why in rows)


class StateMachine(Generic[A]):
    """Runs ``states`` (by name) under ``table``, guards looked up by name in
    ``guards``; starts in ``start``; ``on_change(agent)`` is called between leaving a
    state and entering the next."""

    def __init__(self, states: Mapping[str, State[A]], table: Sequence[Transition], guards: Mapping[str, Guard],
                 start: str, on_change: Callable[[A], None] | None = None) -> None:
        missing = {r.when for r in table if r.when != "done"} - set(guards)
        unknown = {n for r in table for n in (*r.source, r.target) if n != "*"} - set(states)
        if missing or unknown:
            raise ValueError(f"transition table: guards {sorted(missing)} / states {sorted(unknown)} not defined")
        self.states, self.table, self.guards, self.start = dict(states), tuple(table), guards, start
        self.on_change = on_change
        self.state: State[A] = self.states[start]
        self.since = 0.0
        self.trace: list[tuple[float, str, str, str]] = []      # (t, from, when, to) of the last think

    @property
    def name(self) -> str:
        return self.state.name

    def reset(self, agent: A, view: "View") -> None:
        """Back to the start state (after a death)."""
        self.state.exit(agent, view)
        self.state, self.since = self.states[self.start], view.t

    def think(self, agent: A, view: "View", p: "Percept", idle: Callable[[], Command]) -> Command:
        """Take the transitions that hold, then the state's command; a state that is
        done gives way by the ``done`` rows (``idle()`` if none is left)."""
        self.trace = []
        self._transit(agent, view, p, done=False)
        for _ in range(HOPS):
            cmd = self.state.update(agent, view, p)
            if cmd is not None:
                return cmd
            if not self._transit(agent, view, p, done=True):
                break
        return idle()

    def go(self, agent: A, view: "View", p: "Percept", target: str, arg: Any = None) -> None:
        """Leave the current state for ``target`` (entered afresh even if current)."""
        self.state.exit(agent, view)
        if self.on_change is not None:
            self.on_change(agent)
        self.state, self.since = self.states[target], view.t
        self.state.enter(agent, view, p, arg)

    def _transit(self, agent: A, view: "View", p: "Percept", done: bool) -> bool:
        moved = False
        for _ in range(HOPS):
            row, arg = self._first(agent, view, p, done)
            if row is None:
                break
            self.trace.append((view.t, self.state.name, row.when, row.target))
            self.go(agent, view, p, row.target, arg)
            moved, done = True, False
        return moved

    def _first(self, agent: A, view: "View", p: "Percept", done: bool) -> tuple[Transition | None, Any]:
        name = self.state.name
        for row in self.table:
            if not row.applies(name):
                continue
            if row.when == "done":
                if done:
                    return row, self.state.handoff
                continue
            arg = self.guards[row.when](agent, view, p)
            if arg is not None and arg is not False:
                return row, arg
        return None, None
