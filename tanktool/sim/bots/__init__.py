"""The bot API (issue 31): a bot is any class with ``act(self, view) -> Command``.

    from tanktool.bots import Bot, Command

    class Charger(Bot):
        def act(self, view):
            if view.seen:                       # an enemy in sight: turn onto it, fire
                s = view.seen[0]
                err = math.remainder(math.atan2(s.z - view.me.z, s.x - view.me.x) - view.me.heading, math.tau)
                return Command(advance=1.0, rotate=max(-1.0, min(1.0, 3.0 * err)), fire=abs(err) < 0.05)
            return Command(advance=0.5, rotate=0.3)

``view`` (:class:`View`) is what that tank perceives, under the same rules as the
built-in agents (``perceive``): its own state, what it sees and hears, its memory,
the match's rules and the static map with its grid and path queries -- never the
world's internals.  ``load_bot(spec)`` resolves built-in names and ``FILE.py:Class``;
``BotDriver`` turns a bot into the driver a match calls.  docs/bots.md has the whole
API and two complete example bots (examples/bots/).
"""

from ..commands import IDLE, Command
from .driver import DEFAULT_BUDGET, BotDriver, BotStats
from .loader import BUILTIN, BotMaker, load_bot
from .map import Map
from .perceive import Perceiver
from .view import LIMITS, Bot, Heard, Memory, Senses, ShellSeen, Sighting, TankState, Vehicle, View

__all__ = ["BUILTIN", "Bot", "BotDriver", "BotMaker", "BotStats", "Command", "DEFAULT_BUDGET", "Heard", "IDLE",
           "LIMITS", "Map", "Memory", "Perceiver", "Senses", "ShellSeen", "Sighting", "TankState", "Vehicle", "View",
           "load_bot"]
