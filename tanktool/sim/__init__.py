"""The simulation: deterministic, headless, never importing pygame.

    from tanktool.sim import World, TankSpec, Command
    world = World(walls, [TankSpec.box()] * 2, spawns, seed=1)
    events = world.step(None, [Command(advance=1.0), Command(rotate=-1.0, fire=True)])
"""

from .body import Tank, TankSpec
from .commands import Command
from .world import DT, Event, World

__all__ = ["Command", "DT", "Event", "Tank", "TankSpec", "World"]
