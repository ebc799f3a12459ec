"""Helpers for tests of bots: drive a world's tank with a bot, make a view, and make
the events a step would have made (a shot heard, a hit taken) without playing it."""

from __future__ import annotations

from tanktool.bots import BotDriver
from tanktool.sim.world import Event


def driver(bot, seed: int = 0) -> BotDriver:
    return BotDriver(bot, seed)


def view_of(drv: BotDriver, world, index: int = 0):
    """The view ``drv``'s bot would get now (the driver's perceiver, made if needed)."""
    if drv.perceiver is None:
        drv(world, world.tanks[index])
    drv.perceiver.collect(world)
    return drv.perceiver.view(world, drv.rng)


def happen(world, *events: tuple, dt: float | None = None) -> None:
    """As if a step of ``dt`` (default the world's) had happened with ``events``, each
    (kind, tank, other[, value]): a shot is placed at its tank, a hit or kill at the
    victim's place."""
    world.steps += 1
    world.t += world.dt if dt is None else dt
    out = []
    for kind, tank, other, *value in events:
        where = world.tanks[tank if kind == "shot" else other]
        out.append(Event(world.steps, world.t, kind, tank, where.x, where.z, other, value[0] if value else 0.0))
    world.events = out


def perceiver(world, index: int = 0, senses=None, seed: int = 0):
    """A perceiver of tank ``index`` (default senses: the most a bot perceives)."""
    from tanktool.bots import LIMITS, Perceiver

    return Perceiver(world, index, senses or LIMITS, seed)


def state_of(world, index: int = 0):
    """Tank ``index``'s own state as its view shows it."""
    return perceiver(world, index).state(world, world.tanks[index])
