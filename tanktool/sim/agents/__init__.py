"""Computer opponents (issue 7): perception, aim and dodging, grid navigation and search;
the yardstick opponents of issue 19 in ``robots``.

    from tanktool.sim.agents import Agent, make_agents
    agents = make_agents(world, "normal")            # one per tank, seeded from the world
    commands = [a(world, t) for a, t in zip(agents, world.tanks)]
"""

from .agent import DIFFICULTIES, STATES, Agent, Difficulty, difficulty, make_agents

__all__ = ["Agent", "DIFFICULTIES", "Difficulty", "STATES", "difficulty", "make_agents"]
