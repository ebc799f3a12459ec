"""The single-agent Gymnasium environment: ``TankEnv(arena=, vehicle=,
opponents=[...], seconds=)``, one learning tank against bots (docs/env.md)."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from .core import Arena, EnvConfig, Episode, RewardWeights
from .parallel import action_space, observation_space


class TankEnv(gym.Env):
    """One learning tank (tank 0) against ``opponents``; the spaces and rewards of
    the parallel environment."""

    metadata = {"render_modes": []}

    def __init__(self, arena: str = "box", vehicle: str | None = "light",
                 opponents: list[str] | tuple[str, ...] = ("easy",), seconds: float = 60.0,
                 action_repeat: int = 4, weights: RewardWeights | dict | None = None) -> None:
        if isinstance(weights, dict):
            weights = RewardWeights(**weights)
        self.config = EnvConfig(arena, vehicle, 1, tuple(opponents), float(seconds), int(action_repeat),
                                weights or RewardWeights())
        self.arena = Arena(self.config)
        self.observation_space = observation_space()
        self.action_space = action_space()
        self.episode: Episode | None = None

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[np.ndarray, dict]:
        super().reset(seed=seed)
        self.episode = Episode(self.config, self.arena, int(self.np_random.integers(0, 2 ** 62)))
        return self.episode.observe(0), self.episode.info(0)

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict]:
        ep = self.episode
        if ep is None:
            raise RuntimeError("step() before reset()")
        rewards, terminated, truncated = ep.step([action])
        return ep.observe(0), float(rewards[0]), terminated, truncated and not terminated, ep.info(0)


#: ``gymnasium.make("tanktool/Tank-v0", arena="hills", opponents=["hard"])`` (after ``import tanktool.env``)
ENV_ID = "tanktool/Tank-v0"
if ENV_ID not in gym.registry:
    gym.register(id=ENV_ID, entry_point="tanktool.env.single:TankEnv")
