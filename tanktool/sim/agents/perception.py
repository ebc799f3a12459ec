"""What an agent takes in at each think: its view (``sim.bots``), digested.

The rules of sight, hearing and engines are the bot API's (``sim.bots.perceive``: the
same for every bot).  A think's :class:`Percept` is what the state machine's guards
and states read: the enemy it fights (kept while in sight, else the nearest seen),
what it heard, whether it was hit since the last think (the world's ``hit`` events),
the recent hits, and whether it leads (kills above deaths, as its HUD shows).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..bots.perceive import ENGINE_FLOOR, ENGINE_FULL, ENGINE_QUIET, in_cone, wrap
from ..bots.view import Heard, Sighting

__all__ = ["ENGINE_FLOOR", "ENGINE_FULL", "ENGINE_QUIET", "Heard", "Percept", "Sighting", "can_see", "in_cone", "wrap"]


def can_see(walls, ox: float, oz: float, heading: float, tx: float, tz: float,
            half_angle: float, vision_range: float) -> bool:
    """The flat sight test: in the cone, in range, and no wall crossing the line of
    sight (``walls`` anything with ``blocked(ax, az, bx, bz)``, e.g. a ``WallSet``)."""
    return in_cone(ox, oz, heading, tx, tz, half_angle, vision_range) and not walls.blocked(ox, oz, tx, tz)


@dataclass(frozen=True)
class Percept:
    """One think's digest of the view.

    t : the time [s]
    sight : the enemy it fights if in sight (its target still, else the nearest seen)
    reacted : the reaction time since first seeing ``sight`` is over
    heard : a shot heard since the last think (the nearest), else an engine heard now
    shot : the latest shot heard (any think) that could have fired a shell arriving
        now: for returning fire
    hit : hit since the last think
    hits : times of the hits it took in the last 4 s
    leading : more kills than deaths
    killed_target : its target died at its hands since the last think
    """

    t: float
    sight: Sighting | None
    reacted: bool
    heard: Heard | None
    shot: Heard | None
    hit: bool
    hits: tuple[float, ...]
    leading: bool
    killed_target: bool
