"""The simulation: deterministic, headless, never importing pygame.

    from tanktool.sim import World, TankSpec, Command
    world = World(walls, [TankSpec.box()] * 2, spawns, seed=1)
    events = world.step(None, [Command(advance=1.0), Command(rotate=-1.0, fire=True)])
    World(walls, specs, spawns, rules=Rules(score_limit=5))   # world.match.over, .winner
"""

from .body import Tank, TankSpec
from .commands import Command
from .rules import MatchState, Rules
from .world import DT, Event, World

__all__ = ["Command", "DT", "Event", "MatchState", "Rules", "Tank", "TankSpec", "World"]
