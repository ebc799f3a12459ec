"""The bot API, for users: ``from tanktool.bots import Bot, Command`` (see
``tanktool.sim.bots`` and docs/bots.md)."""

from .sim.bots import *  # noqa: F401,F403
from .sim.bots import __all__  # noqa: F401
