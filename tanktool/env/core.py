"""The engine under both environments: a match with learning tanks and bot
opponents, stepped by actions, with rewards from the world's events.

``EnvConfig`` is the setup (one dataclass); ``Arena`` loads once what every episode
shares; ``Episode`` is one match: ``Episode(config, arena, seed)``, then
``step(actions) -> (rewards, over)`` and ``observe(i)``.  Neither imports Gymnasium
nor PettingZoo, so the engine is tested and benchmarked on its own.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from ..bots import LIMITS, Command, Perceiver, load_bot
from ..errors import TanktoolError
from ..sim.match import choose_vehicle, load_match_arena, load_tank_spec
from ..sim.world import World
from .observe import observe


@dataclass(frozen=True)
class RewardWeights:
    """Reward per event, for the tank concerned: ``hit`` a shell of yours hit an enemy,
    ``hurt`` you were hit, ``kill`` you destroyed an enemy, ``death`` you were
    destroyed, ``shot`` you fired, ``step`` every env step (a time cost)."""

    hit: float = 1.0
    hurt: float = -0.5
    kill: float = 5.0
    death: float = -5.0
    shot: float = 0.0
    step: float = 0.0


@dataclass(frozen=True)
class EnvConfig:
    """An environment's setup.

    arena, vehicle : bundled names or bundle folders
    agents : learning tanks (tanks 0 .. agents-1)
    opponents : bot specs for the other tanks (built-in names or FILE.py:Class)
    seconds : simulated seconds per episode (then every agent is truncated)
    action_repeat : simulation steps per env step (120 Hz / 4 = 30 decisions a second)
    weights : the rewards
    """

    arena: str = "box"
    vehicle: str | None = "light"
    agents: int = 1
    opponents: tuple[str, ...] = ("easy",)
    seconds: float = 60.0
    action_repeat: int = 4
    weights: RewardWeights = field(default_factory=RewardWeights)

    def check(self) -> None:
        if not (1 <= self.agents <= 64):
            raise TanktoolError(f"agents must be 1..64, got {self.agents}")
        if self.agents + len(self.opponents) > 64:
            raise TanktoolError("at most 64 tanks (agents + opponents)")
        if not (self.seconds > 0 and math.isfinite(self.seconds)):
            raise TanktoolError(f"seconds must be a positive number, got {self.seconds}")
        if not (1 <= self.action_repeat <= 120):
            raise TanktoolError(f"action_repeat must be 1..120, got {self.action_repeat}")


class Arena:
    """What every episode shares: the arena, the vehicle and the opponents' makers."""

    def __init__(self, config: EnvConfig) -> None:
        config.check()
        self.info = load_match_arena(config.arena)
        self.spec = load_tank_spec(choose_vehicle(self.info, config.vehicle))
        self.makers = [load_bot(s) for s in config.opponents]
        n = config.agents + len(config.opponents)
        own = self.info.spawns_for(self.spec)      # the vehicle's own, where it has a grid of its own
        if n > len(own):
            raise TanktoolError(f"arena {self.info.name} has {len(own)} spawn points for {self.spec.name}: "
                                f"{config.agents} agents and {len(config.opponents)} opponents do not fit")


def command_of(action: Any) -> Command:
    """An action (advance, rotate, strafe, fire) as a Command: fire when > 0."""
    a = np.asarray(action, dtype=np.float64).reshape(-1)
    if a.size != 4:
        raise ValueError(f"an action is 4 numbers (advance, rotate, strafe, fire), got {a.size}")
    return Command(float(a[0]), float(a[1]), float(a[2]), bool(a[3] > 0.0))


class Episode:
    """One match: learning tanks 0..n-1 driven by actions, the rest by bots."""

    def __init__(self, config: EnvConfig, arena: Arena, seed: int) -> None:
        self.config = config
        n = config.agents + len(config.opponents)
        info = arena.info
        names = [f"agent_{i}" for i in range(config.agents)] + [
            f"{m.name}_{k}" for k, m in enumerate(arena.makers)]
        self.world = World(info.walls, [arena.spec] * n, info.spawns_for(arena.spec), seed=seed, bounds=info.bounds,
                           ground=info.ground, names=names)
        w = self.world
        # seeds drawn in tank order from the world's generator, as a match seeds its bots
        seeds = [w.rng.getrandbits(64) for _ in range(n)]
        self.perceivers = [Perceiver(w, i, LIMITS, seeds[i]) for i in range(config.agents)]
        self.view_rngs = [random.Random(seeds[i] ^ 0x5EED) for i in range(config.agents)]
        self.opponents = [m.driver(seeds[config.agents + k]) for k, m in enumerate(arena.makers)]
        self.steps = 0
        self.limit = int(round(config.seconds / w.dt))

    def step(self, actions: Sequence[Any]) -> tuple[list[float], bool, bool]:
        """Apply one action per learning tank for ``action_repeat`` world steps;
        (rewards per learning tank, terminated: the match is over by its rules,
        truncated: the episode's time is up)."""
        w, cfg = self.world, self.config
        wt = cfg.weights
        n = cfg.agents
        learn = [command_of(a) for a in actions]
        rewards = [wt.step] * n
        tanks = w.tanks
        for _ in range(cfg.action_repeat):
            if w.match.over or w.steps >= self.limit:
                break
            cmds = learn + [d(w, t) for d, t in zip(self.opponents, tanks[n:])]
            for e in w.step(None, cmds):
                k = e.kind
                if k == "hit":
                    if e.tank < n:
                        rewards[e.tank] += wt.hit
                    if e.other < n:
                        rewards[e.other] += wt.hurt
                elif k == "kill":
                    if e.tank < n and e.tank != e.other:
                        rewards[e.tank] += wt.kill
                    if e.other < n:
                        rewards[e.other] += wt.death
                elif k == "shot" and e.tank < n:
                    rewards[e.tank] += wt.shot
            for p in self.perceivers:
                p.collect(w)
        self.steps += 1
        return rewards, bool(w.match.over), w.steps >= self.limit

    def observe(self, i: int) -> np.ndarray:
        """Learning tank ``i``'s observation now."""
        view = self.perceivers[i].view(self.world, self.view_rngs[i])
        return observe(view, self.config.seconds)

    def info(self, i: int) -> dict[str, Any]:
        t = self.world.tanks[i]
        return {"kills": t.kills, "deaths": t.deaths, "hits": t.hits, "shots": t.shots, "alive": t.alive,
                "t": round(self.world.t, 6)}
