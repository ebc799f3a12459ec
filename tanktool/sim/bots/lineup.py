"""Bots named on a command line, put in a match: ``play --bot FILE.py:Class --bot hard``.

``lineup(specs)`` loads every spec once (a bad one is one error before the match) and
names the bots uniquely (``Sniper``, ``Sniper#2``); ``seat(world, makers, first,
drivers)`` gives tanks ``first``, ``first + 1``, ... those bots, seeded from the
world's generator in tank order (a seed gives the same match), and the bots' names.
The other tanks keep the drivers they had (the ``--difficulty`` agents).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence

from ...errors import TanktoolError
from .driver import DEFAULT_BUDGET
from .loader import BotMaker, load_bot

if TYPE_CHECKING:  # pragma: no cover
    from ..world import World


def load_checked(spec: str) -> BotMaker:
    """``load_bot(spec)``, and one bot made to see that its class can be made (a
    constructor that raises is one error line here, not a traceback mid-match)."""
    maker = load_bot(spec)
    try:
        maker.make()
    except Exception as e:
        raise TanktoolError(f"bot {spec!r}: making one raised {type(e).__name__}: {e}") from None
    return maker


def lineup(specs: Sequence[str]) -> list[tuple[str, BotMaker]]:
    """(unique name, maker) per spec, in order."""
    out: list[tuple[str, BotMaker]] = []
    seen: dict[str, int] = {}
    for spec in specs:
        maker = load_checked(spec)
        seen[maker.name] = seen.get(maker.name, 0) + 1
        out.append((maker.name if seen[maker.name] == 1 else f"{maker.name}#{seen[maker.name]}", maker))
    return out


def seat(world: "World", bots: Sequence[tuple[str, BotMaker]], first: int, drivers: list[Any],
         budget: float = DEFAULT_BUDGET) -> list[Any]:
    """``drivers`` with tanks ``first`` .. driven by ``bots`` (named after them)."""
    drivers = list(drivers)
    for k, (name, maker) in enumerate(bots):
        i = first + k
        try:
            drivers[i] = maker.driver(world.rng.getrandbits(64), budget=budget)
        except Exception as e:      # a constructor that fails only sometimes
            raise TanktoolError(f"bot {maker.spec!r}: making one raised {type(e).__name__}: {e}") from None
        world.tanks[i].name = name[:64]
    return drivers
