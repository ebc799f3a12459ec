"""A game session driven by a replay (``tanktool play --replay F --headless --screenshot``).

The session is the one the window and the screenshots use (``game.session``), with
every tank driven from the tape and the world's generator put back where the
recording had it, so after all the recorded steps its state is the recorded final
state, bit for bit; rendering frame N of it gives frame N of the match (a video is
``--frames 0, 1, 2, ...``).
"""

from __future__ import annotations

import math
from typing import Any

from ..errors import TanktoolError


def replay_session(replay: Any, arena: str | None = None, vehicle: str | None = None):
    """A ``GameSession`` (no local player) that plays ``replay`` (a ``sim.replay.Replay``);
    ``arena``/``vehicle`` override the bundles the recording names."""
    from ..sim.replay import ReplayDriver, arena_fingerprint, spec_fingerprint
    from ..sim.world import DT
    from .session import GameSession

    h = replay.header
    # the session steps with the world's defaults: a replay made otherwise cannot play here
    if float(h["dt"]) != DT or h["integrator"] != "semi-implicit":
        raise TanktoolError(f"this replay uses dt={h['dt']} and the {h['integrator']} integrator; "
                            f"only headless matches (--report/--picture) can play it back")
    bots = int(h["bots"])
    drivers = [ReplayDriver(*replay.timeline(i)) for i in range(bots)]
    session = GameSession(arena or h.get("arena_ref"), vehicle or h.get("vehicle_ref"), bots=bots,
                          seed=int(h["seed"]), player=False, drivers=drivers)
    if h.get("arena_sha256") and arena_fingerprint(session.info) != h["arena_sha256"]:
        raise TanktoolError(f"arena {session.info.name!r} is not the one the replay was recorded on "
                            f"(its walls, spawns or bounds differ)")
    if h.get("vehicle_sha256") and spec_fingerprint(session.spec) != h["vehicle_sha256"]:
        raise TanktoolError(f"vehicle {session.spec.name!r} is not the one the replay was recorded with")
    replay.restore_rng(session.world)
    replay.apply_names(session.world)
    session.max_steps = int(h["steps"])
    if isinstance(h.get("player"), int) and 0 <= h["player"] < bots:
        session.follow = h["player"]          # a window recording: ride with the player's tank
    return session


def replay_frames(replay: Any, frame: float) -> int:
    """How many frames of ``frame`` seconds the recording lasts (a last part-frame
    counts: its frame shows the final state)."""
    return math.ceil(int(replay.header["steps"]) * float(replay.header["dt"]) / frame - 1e-9)
