"""Computer opponents (issues 7, 28): bots on the bot API (``sim.bots``) with
perception digested each think, a state machine whose transitions are data, aim and
dodging, grid navigation and search; the yardstick opponents in ``robots``.

    from tanktool.sim.agents import Agent, make_agents
    drivers = make_agents(world, "normal")            # one per tank, seeded from the world
    commands = [d(world, t) for d, t in zip(drivers, world.tanks)]
"""

from .agent import STATES, TRANSITIONS, Agent, make_agents
from .difficulty import DIFFICULTIES, Difficulty, difficulty

__all__ = ["Agent", "DIFFICULTIES", "Difficulty", "STATES", "TRANSITIONS", "difficulty", "make_agents"]
