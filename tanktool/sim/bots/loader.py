"""Bots by name: ``load_bot("hard")``, ``load_bot("bots/mine.py:Sniper")``.

A spec is a built-in name (``BUILTIN``: the agents ``easy``, ``normal``, ``hard`` and
the yardsticks ``robot``, ``camper``, ``duellist``, ``novice``) or ``FILE.py:Class``
(``FILE.py`` alone when the file defines exactly one bot class).  The result is a
:class:`BotMaker`: ``make()`` gives a fresh bot (one per tank and match: bots keep
state), ``driver(seed)`` the driver a match calls.  Anything wrong with the spec, the
file or the class is one ``TanktoolError`` line naming them; the file is run once
per process (its module is kept by path and modification time).
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import inspect
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from ...errors import TanktoolError
from .driver import DEFAULT_BUDGET, BotDriver

#: the built-in bots: the agents (sim.agents) by difficulty and the yardsticks (sim.agents.robots)
AGENTS = ("easy", "normal", "hard")
YARDSTICKS = ("robot", "camper", "duellist", "novice")
BUILTIN = AGENTS + YARDSTICKS
_MODULES: dict[tuple[str, int], Any] = {}


@dataclass(frozen=True)
class BotMaker:
    """A loaded bot spec: ``name`` (the built-in name or the class name), the
    ``spec`` it came from, and ``make() -> bot``."""

    name: str
    spec: str
    make: Callable[[], Any]

    def driver(self, seed: int, budget: float = DEFAULT_BUDGET) -> BotDriver:
        """A driver for one tank, with a fresh bot seeded by ``seed``."""
        return BotDriver(self.make(), seed, budget=budget, name=self.name)


def _builtin(name: str) -> Callable[[], Any]:
    if name in AGENTS:
        from ..agents import Agent

        return functools.partial(Agent, name)
    from ..agents import robots

    return {"robot": robots.Robot, "camper": robots.Camper, "duellist": robots.Duellist,
            "novice": robots.Novice}[name]


def load_bot(spec: str) -> BotMaker:
    """The bot a spec names (see the module docstring)."""
    if not isinstance(spec, str) or not spec.strip():
        raise TanktoolError(f"bot {spec!r}: expected a name ({', '.join(BUILTIN)}) or FILE.py:Class")
    spec = spec.strip()
    if spec in BUILTIN:
        return BotMaker(spec, spec, _builtin(spec))
    path_text, sep, cls_name = spec.rpartition(":")
    if not sep or not path_text.endswith(".py"):
        path_text, cls_name = spec, ""
    if not path_text.endswith(".py"):
        raise TanktoolError(f"bot {spec!r}: no such built-in bot (one of {', '.join(BUILTIN)}) and not FILE.py:Class")
    module = _load_file(spec, Path(path_text))
    cls = _find_class(spec, module, cls_name, Path(path_text).name)
    return BotMaker(cls.__name__, spec, cls)


def _load_file(spec: str, path: Path) -> Any:
    try:
        real = path.resolve(strict=True)
        if not real.is_file():
            raise TanktoolError(f"bot {spec!r}: {path} is not a file")
        stamp = real.stat().st_mtime_ns
    except (OSError, RuntimeError):
        raise TanktoolError(f"bot {spec!r}: {path}: no such file") from None
    key = (str(real), stamp)
    if key in _MODULES:
        return _MODULES[key]
    name = "tanktool_bot_" + hashlib.sha1(key[0].encode()).hexdigest()[:12]
    loader = importlib.util.spec_from_file_location(name, real)
    if loader is None or loader.loader is None:
        raise TanktoolError(f"bot {spec!r}: {path} cannot be loaded as Python")
    module = importlib.util.module_from_spec(loader)
    sys.modules[name] = module          # dataclasses and pickling look the module up
    try:
        loader.loader.exec_module(module)
    except SyntaxError as e:
        sys.modules.pop(name, None)
        raise TanktoolError(f"bot {spec!r}: {path}:{e.lineno}: syntax error: {e.msg}") from None
    except Exception as e:
        sys.modules.pop(name, None)
        raise TanktoolError(f"bot {spec!r}: {path}: loading it raised {type(e).__name__}: {e}") from None
    _MODULES[key] = module
    return module


def _is_bot_class(obj: Any) -> bool:
    return inspect.isclass(obj) and callable(getattr(obj, "act", None))


def _find_class(spec: str, module: Any, cls_name: str, file: str) -> Any:
    mine = [v for v in vars(module).values() if _is_bot_class(v) and v.__module__ == module.__name__]
    if not cls_name:
        if len(mine) != 1:
            names = ", ".join(sorted(c.__name__ for c in mine)) or "none"
            raise TanktoolError(f"bot {spec!r}: name the class as {file}:Class (bot classes in the file: {names})")
        cls = mine[0]
    else:
        cls = getattr(module, cls_name, None)
        if cls is None:
            names = ", ".join(sorted(c.__name__ for c in mine)) or "none"
            raise TanktoolError(f"bot {spec!r}: {file} has no {cls_name} (bot classes in it: {names})")
        if not inspect.isclass(cls):
            raise TanktoolError(f"bot {spec!r}: {cls_name} in {file} is not a class")
        if not _is_bot_class(cls):
            raise TanktoolError(f"bot {spec!r}: class {cls_name} has no act(self, view) method")
    try:
        inspect.signature(cls).bind()
    except (TypeError, ValueError):
        raise TanktoolError(f"bot {spec!r}: class {cls.__name__} must be callable without arguments "
                            f"(its __init__ takes parameters)") from None
    return cls
