"""The adapter from a bot to a driver: ``BotDriver(bot, seed)(world, tank) -> Command``,
what ``run_match``, the game and network sessions call every step.

Each step it keeps the events the tank perceives; at the bot's think rate
(``bot.think_hz``; every step when it has none) it builds the view, calls
``bot.act(view)`` and holds the command it returns until the next call.  While the
tank is dead the bot is called once (``view.me.alive`` False: time to forget) and
then not until it respawns; the first call after a respawn comes at once.

A bot that raises (or returns something that is not a ``Command``) gets ``IDLE``
for that call, a warning is logged (once per kind of failure) and the match goes on;
``stats.errors`` counts the failures.  The time of each call (perception and
``act``) is measured: ``stats.over_budget`` counts the calls longer than the budget
(``DEFAULT_BUDGET``), which never changes what happens, so results do not depend on
the machine's speed.
"""

from __future__ import annotations

import logging
import math
import random
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..commands import IDLE, Command
from .perceive import Perceiver
from .view import LIMITS, Senses

if TYPE_CHECKING:  # pragma: no cover
    from ..body import Tank
    from ..world import World

#: a bot's call may take this long before it is counted over budget [s]
DEFAULT_BUDGET = 0.005
log = logging.getLogger("tanktool.bots")


@dataclass
class BotStats:
    """What a bot cost: calls, failures (deterministic), and the measured time
    (machine-dependent: ``over_budget``, ``total_s``, ``max_s``)."""

    calls: int = 0
    errors: int = 0
    over_budget: int = 0
    total_s: float = 0.0
    max_s: float = 0.0

    def timing(self) -> dict[str, Any]:
        """The machine-dependent part, for a report's ``timing``."""
        return {"calls": self.calls, "over_budget": self.over_budget,
                "mean_ms": round(1000.0 * self.total_s / max(self.calls, 1), 4), "max_ms": round(1000.0 * self.max_s, 3)}


class BotDriver:
    """Drives one tank with ``bot`` (any object with ``act(view) -> Command``).

    Parameters
    ----------
    bot : the bot
    seed : seeds the bot's generator (``view.rng``) and its perception's noise
    budget : seconds a call may take before it is counted over budget
    name : what warnings and reports call it (default: the bot's class name)
    """

    def __init__(self, bot: Any, seed: int, *, budget: float = DEFAULT_BUDGET, name: str | None = None) -> None:
        if not callable(getattr(bot, "act", None)):
            raise TypeError(f"{type(bot).__name__} is not a bot: it has no act(view) method")
        self.bot = bot
        self.name = name or type(bot).__name__
        self.budget = float(budget)
        root = random.Random(seed)
        self.rng = random.Random(root.getrandbits(64))
        self._noise_seed = root.getrandbits(64)
        senses = getattr(bot, "senses", LIMITS)
        self.senses = senses.limited() if isinstance(senses, Senses) else LIMITS
        hz = getattr(bot, "think_hz", None)
        self.period = 1.0 / float(hz) if isinstance(hz, (int, float)) and hz > 0 and math.isfinite(hz) else 0.0
        self.perceiver: Perceiver | None = None
        self.command: Command = IDLE
        self.next_think = -math.inf
        self.dead = False
        self.stats = BotStats()
        self._warned: set[tuple[str, str]] = set()

    def prepare(self, world: "World", tank: "Tank") -> None:
        """Before the match's clock: the perception (as the first call makes it) and the
        bot's ``prepare(map, vehicle)`` when it has one (the arena's tables it would
        make in its first call).  A failing one is logged and counted like a failing
        ``act``; the match goes on."""
        if self.perceiver is None:
            self.perceiver = Perceiver(world, tank.index, self.senses, self._noise_seed)
        hook = getattr(self.bot, "prepare", None)
        if not callable(hook):
            return
        try:
            hook(self.perceiver.map, self.perceiver.vehicles[tank.index])
        except Exception as e:          # a bot's bug must not end the match
            self.stats.errors += 1
            log.warning("bot %s (tank %d) failed to prepare: %s: %s", self.name, tank.index, type(e).__name__, e)

    def __call__(self, world: "World", tank: "Tank") -> Command:
        if self.perceiver is None:
            self.perceiver = Perceiver(world, tank.index, self.senses, self._noise_seed)
        self.perceiver.collect(world)
        if not tank.alive:
            if self.dead:
                return IDLE
            self.dead = True                 # one call to tell it: then quiet until it respawns
            self._act(world)
            self.command = IDLE
            return IDLE
        if self.dead:
            self.dead, self.next_think = False, -math.inf
        if world.t + 1e-12 < self.next_think:
            return self.command
        self.next_think = world.t + self.period
        self.command = self._act(world)
        return self.command

    def _act(self, world: "World") -> Command:
        start = time.perf_counter()
        view = self.perceiver.view(world, self.rng)  # type: ignore[union-attr]
        try:
            cmd = self.bot.act(view)
            if not isinstance(cmd, Command):
                raise TypeError(f"act returned {type(cmd).__name__}, not a Command")
        except Exception as e:          # a bot's bug must not end the match
            self.stats.errors += 1
            what = (type(e).__name__, str(e))
            if what not in self._warned:
                self._warned.add(what)
                log.warning("bot %s (tank %d) failed at t=%.2f s: %s: %s; it idles for this step",
                            self.name, view.me.index, view.t, what[0], what[1])
            cmd = IDLE
        spent = time.perf_counter() - start
        st = self.stats
        st.calls += 1
        st.total_s += spent
        st.max_s = max(st.max_s, spent)
        if spent > self.budget:
            st.over_budget += 1
        return cmd

    def debug(self) -> dict[str, Any]:
        """What the top view draws over the tank: the bot's own ``debug()`` with its
        sight (range and half-angle)."""
        info: dict[str, Any] = {"sight": self.senses.vision_range, "fov": self.senses.half_angle}
        hook = getattr(self.bot, "debug", None)
        if callable(hook):
            try:
                info.update(hook())
            except Exception:        # drawing must not end the match either
                pass
        return info
