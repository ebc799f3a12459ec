"""One tournament match, as a worker plays it: ``play_match(task) -> result``.

The worker loads (once per process) the arena, the vehicle and the two bots -- a
bot file from its path when that file is there with the same sha256, else from the
source the task carries (written to a private folder named by its hash): a Ray
worker on another machine plays the same bot.  The match is ``sim.match.run_match``
with the two bots' drivers, seeded from the world's generator in tank order as the
game seeds its agents, and recorded (``sim.replay.Recorder``): the result carries the
replay's bytes, which the caller writes.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path
from typing import Any

from ..bots import load_bot
from ..errors import TanktoolError
from ..sim.match import load_match_arena, load_tank_spec, run_match
from ..sim.replay import Recorder, encode, match_header
from .schedule import SCRIPTED, MatchTask, Player

_ARENAS: dict[str, Any] = {}
_SPECS: dict[str, Any] = {}
_MAKERS: dict[tuple[str, str | None], Any] = {}


def _arena(ref: str) -> Any:
    if ref not in _ARENAS:
        _ARENAS[ref] = load_match_arena(ref)
    return _ARENAS[ref]


def _spec(ref: str) -> Any:
    if ref not in _SPECS:
        _SPECS[ref] = load_tank_spec(ref)
    return _SPECS[ref]


class _Scripted:
    """The scripted baseline as a maker: ``driver(seed)`` like a bot's."""

    name = SCRIPTED

    @staticmethod
    def driver(seed: int, budget: float = 0.0) -> Any:
        import random

        from ..sim.driver import ScriptedDriver

        return ScriptedDriver(random.Random(seed))


def _maker(player: Player) -> Any:
    key = (player.spec, player.sha256)
    if key in _MAKERS:
        return _MAKERS[key]
    if player.spec == SCRIPTED:
        maker: Any = _Scripted()
    elif player.path is None:
        maker = load_bot(player.spec)
    else:
        path = Path(player.path)
        try:
            same = path.is_file() and hashlib.sha256(path.read_bytes()).hexdigest() == player.sha256
        except OSError:
            same = False
        if not same:
            if player.source is None:
                raise TanktoolError(f"bot {player.spec!r}: {path} is not on this worker")
            # the file as the tournament read it, in a folder named by its hash
            home = Path(tempfile.gettempdir()) / f"tanktool-bots-{os.getuid() if hasattr(os, 'getuid') else 0}"
            path = home / str(player.sha256)[:16] / path.name
            if not path.is_file():
                path.parent.mkdir(parents=True, exist_ok=True)
                tmp = path.with_suffix(f".{os.getpid()}.tmp")
                tmp.write_text(player.source, encoding="utf-8")
                os.replace(tmp, path)
        maker = load_bot(f"{path}:{player.cls}")
    _MAKERS[key] = maker
    return maker


def play_match(task: MatchTask) -> dict[str, Any]:
    """Play one match; the result (JSON-ready, ``timing`` apart) and ``replay`` bytes."""
    arena, spec = _arena(task.arena), _spec(task.vehicle)
    makers = [_maker(p) for p in task.players]
    order = [0, 1] if task.a_tank == 0 else [1, 0]      # order[tank] = which player drives it
    drivers: list[Any] = []
    rec = Recorder()

    def wrap(world: Any, _made: list) -> list:
        seeds = [world.rng.getrandbits(64) for _ in world.tanks]
        for tank, who in enumerate(order):
            try:
                drivers.append(makers[who].driver(seeds[tank], budget=task.budget))
            except Exception as e:      # a constructor that fails only sometimes, or only there
                raise TanktoolError(f"bot {task.players[who].spec!r}: making one raised "
                                    f"{type(e).__name__}: {e}") from None
            world.tanks[tank].name = task.players[who].name[:64]
        return rec.wrap(world, drivers) if task.record else drivers

    # the scripted baseline is the cheapest stand-in for the drivers the wrap replaces
    result = run_match(arena, spec, bots=2, seconds=task.seconds, seed=task.seed, bot="scripted",
                       wrap_drivers=wrap)
    world = result.world
    tanks = [world.tanks[order.index(0)], world.tanks[order.index(1)]]     # a's tank, b's tank
    kills = [t.kills for t in tanks]
    score = 1.0 if kills[0] > kills[1] else 0.0 if kills[0] < kills[1] else 0.5
    out: dict[str, Any] = {
        "index": task.index, "arena": arena.name, "vehicle": spec.name, "a": task.players[0].name,
        "b": task.players[1].name, "k": task.k, "seed": task.seed, "a_tank": task.a_tank,
        "kills": kills, "deaths": [t.deaths for t in tanks], "shots": [t.shots for t in tanks],
        "hits": [t.hits for t in tanks], "score": score, "seconds": result.report["seconds"],
    }
    errors = result.report.get("bot_errors")
    if errors:
        out["bot_errors"] = [errors.get(t.name, 0) for t in tanks]
    timing = result.report["timing"]
    bots = timing.get("bots", {})
    out["timing"] = {"wall_clock_s": timing["wall_clock_s"],
                     "bots": [bots.get(t.name) for t in tanks]}
    if task.record:
        seconds = world.steps * world.dt if world.match.over else task.seconds
        header = match_header(arena, spec, world, seconds=seconds, seed=task.seed, arena_ref=task.arena,
                              vehicle_ref=task.vehicle, options={"bot": "scripted"},
                              winner=result.report.get("winner"),
                              tournament={"match": task.index, "players": [p.public() for p in task.players],
                                          "a_tank": task.a_tank})
        out["replay"] = encode(rec.replay(header))
    return out
