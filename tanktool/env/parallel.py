"""The PettingZoo environment: ``parallel_env(arena=, vehicle=, agents=N,
opponents=[...], seconds=)``, each learning agent a tank (docs/env.md)."""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from .core import Arena, EnvConfig, Episode, RewardWeights
from .observe import SIZE


def observation_space() -> spaces.Box:
    """53 numbers in [-1, 1] (``observe.FIELDS``)."""
    return spaces.Box(-1.0, 1.0, (SIZE,), dtype=np.float32)


def action_space() -> spaces.Box:
    """(advance, rotate, strafe, fire) in [-1, 1]; the gun fires when fire > 0."""
    return spaces.Box(-1.0, 1.0, (4,), dtype=np.float32)


class TankParallelEnv(ParallelEnv):
    """A match on an arena: agents ``agent_0`` .. ``agent_{n-1}`` drive tanks 0..n-1,
    the opponents the others.  An episode lasts ``seconds`` (every agent is then
    truncated) or until the match ends by its rules (terminated).  Tanks that die
    respawn: a dead agent stays in the episode, its observation says so."""

    metadata = {"name": "tanktool_v0", "render_modes": []}

    def __init__(self, config: EnvConfig) -> None:
        self.config = config
        self.arena = Arena(config)
        self.possible_agents = [f"agent_{i}" for i in range(config.agents)]
        self.agents: list[str] = []
        self.render_mode = None
        self.episode: Episode | None = None
        self._np_random = np.random.default_rng()

    @functools.lru_cache(maxsize=None)
    def observation_space(self, agent: str) -> spaces.Box:
        return observation_space()

    @functools.lru_cache(maxsize=None)
    def action_space(self, agent: str) -> spaces.Box:
        return action_space()

    def reset(self, seed: int | None = None, options: dict | None = None) -> tuple[dict, dict]:
        if seed is not None:
            self._np_random = np.random.default_rng(seed)
        world_seed = int(self._np_random.integers(0, 2 ** 62))
        self.episode = Episode(self.config, self.arena, world_seed)
        self.agents = list(self.possible_agents)
        ep = self.episode
        return ({a: ep.observe(i) for i, a in enumerate(self.agents)},
                {a: ep.info(i) for i, a in enumerate(self.agents)})

    def step(self, actions: dict[str, Any]) -> tuple[dict, dict, dict, dict, dict]:
        ep = self.episode
        if ep is None or not self.agents:
            raise RuntimeError("step() before reset(), or after the episode ended")
        zero = np.zeros(4, dtype=np.float32)
        rewards, terminated, truncated = ep.step([actions.get(a, zero) for a in self.possible_agents])
        truncated = truncated and not terminated
        agents = self.agents
        obs = {a: ep.observe(i) for i, a in enumerate(agents)}
        rew = {a: float(rewards[i]) for i, a in enumerate(agents)}
        term = {a: terminated for a in agents}
        trunc = {a: truncated for a in agents}
        infos = {a: ep.info(i) for i, a in enumerate(agents)}
        if terminated or truncated:
            self.agents = []
        return obs, rew, term, trunc, infos

    def render(self) -> None:
        return None

    def close(self) -> None:
        self.episode = None

    def state(self) -> np.ndarray:
        """Every learning tank's observation, concatenated."""
        ep = self.episode
        if ep is None:
            return np.zeros(SIZE * len(self.possible_agents), dtype=np.float32)
        return np.concatenate([ep.observe(i) for i in range(len(self.possible_agents))])


def parallel_env(arena: str = "box", vehicle: str | None = "light", agents: int = 1,
                 opponents: list[str] | tuple[str, ...] = ("easy",), seconds: float = 60.0,
                 action_repeat: int = 4, weights: RewardWeights | dict | None = None) -> TankParallelEnv:
    """The PettingZoo parallel environment (see :class:`TankParallelEnv`); ``weights``
    a :class:`RewardWeights` or a dict of its fields."""
    if isinstance(weights, dict):
        weights = RewardWeights(**weights)
    return TankParallelEnv(EnvConfig(arena, vehicle, int(agents), tuple(opponents), float(seconds),
                                     int(action_repeat), weights or RewardWeights()))
