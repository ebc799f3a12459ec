"""Environments for learning agents (issue 31): a PettingZoo parallel environment
(``parallel_env``) where each learning agent drives a tank against bot opponents,
and a single-agent Gymnasium one (``TankEnv``).  The observation is the bot API's
view as 53 numbers, the action the Command's axes and fire, rewards come from hits,
kills and deaths with configurable weights (docs/env.md).

Needs the ``rl`` extra: ``pip install 'tanktool[rl]'``.  The engine (``core``,
``observe``) does not.
"""

from __future__ import annotations

from typing import Any

from .core import EnvConfig, Episode, RewardWeights, command_of
from .observe import FIELDS, SIZE, observe

_NEED = "tanktool.env needs PettingZoo and Gymnasium: pip install 'tanktool[rl]'"


def parallel_env(*args: Any, **kwargs: Any) -> Any:
    """The PettingZoo parallel environment (``tanktool.env.parallel.parallel_env``)."""
    try:
        from .parallel import parallel_env as make
    except ImportError as e:
        from ..errors import TanktoolError

        raise TanktoolError(f"{_NEED} ({e})") from None
    return make(*args, **kwargs)


def register() -> str:
    """Register ``tanktool/Tank-v0`` with Gymnasium (``gymnasium.make``); its id."""
    try:
        from .single import ENV_ID
    except ImportError as e:
        from ..errors import TanktoolError

        raise TanktoolError(f"{_NEED} ({e})") from None
    return ENV_ID


def __getattr__(name: str) -> Any:
    if name in ("TankEnv", "TankParallelEnv"):
        try:
            from . import parallel, single
        except ImportError as e:
            from ..errors import TanktoolError

            raise TanktoolError(f"{_NEED} ({e})") from None
        return single.TankEnv if name == "TankEnv" else parallel.TankParallelEnv
    raise AttributeError(name)


__all__ = ["register", "EnvConfig", "Episode", "FIELDS", "RewardWeights", "SIZE", "TankEnv", "TankParallelEnv",
           "command_of", "observe", "parallel_env"]
