"""Random and scripted policies in the tanktool environment, and a plot of their
returns (issue 31: an example that trains nothing heavy).

    python examples/env_policies.py [--episodes 5] [--seconds 30] [--arena box]
                                    [--opponent easy] [--out env_returns.png]

The scripted policy reads the documented observation (tanktool.env.FIELDS): it
turns onto the nearest enemy in sight and fires when lined up, else turns onto where
it last saw one or heard a shot, and drives away from a wall the front feeler finds.
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

import tanktool.env as te

F = {name: k for k, name in enumerate(te.FIELDS)}


def scripted(obs: np.ndarray) -> np.ndarray:
    """(advance, rotate, strafe, fire) from an observation."""
    def get(name: str) -> float:
        return float(obs[F[name]])

    if get("seen0.present") > 0:
        right, dist = get("seen0.right"), get("seen0.distance")
        return np.array([0.5 if dist > 0.2 else 0.0, np.clip(5.0 * right / max(dist, 0.02), -1, 1), 0.0,
                         1.0 if abs(right) < 0.015 else -1.0], dtype=np.float32)
    for group in ("last_seen", "heard", "engine"):
        if get(f"{group}.present") > 0:
            fwd, right = get(f"{group}.fwd"), get(f"{group}.right")
            turn = np.clip(3.0 * np.arctan2(right, fwd), -1, 1)
            return np.array([0.8 if get("feeler0") > 0.2 else -0.3, turn, 0.0, -1.0], dtype=np.float32)
    blocked = get("feeler0") < 0.2
    return np.array([-0.3 if blocked else 0.8, 1.0 if blocked else 0.2, 0.0, -1.0], dtype=np.float32)


def run(policy, env: "te.TankEnv", episodes: int, seed: int) -> list[float]:
    returns = []
    for k in range(episodes):
        obs, _ = env.reset(seed=seed + k)
        env.action_space.seed(seed + k)
        total, done = 0.0, False
        while not done:
            action = env.action_space.sample() if policy is None else policy(obs)
            obs, r, term, trunc, info = env.step(action)
            total += r
            done = term or trunc
        returns.append(total)
        print(f"  {'random' if policy is None else 'scripted'} episode {k}: return {total:+.1f} "
              f"(kills {info['kills']}, deaths {info['deaths']}, hits {info['hits']})")
    return returns


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--episodes", type=int, default=5)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--arena", default="box")
    ap.add_argument("--opponent", default="easy")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="env_returns.png")
    args = ap.parse_args(argv)
    env = te.TankEnv(arena=args.arena, opponents=[args.opponent], seconds=args.seconds)
    results = {"random": run(None, env, args.episodes, args.seed),
               "scripted": run(scripted, env, args.episodes, args.seed)}
    for name, r in results.items():
        print(f"{name:>8}: mean return {np.mean(r):+.2f} over {len(r)} episodes")
    import matplotlib

    if os.environ.get("DISPLAY") is None:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    for name, r in results.items():
        ax.plot(range(len(r)), r, "o-", label=f"{name} (mean {np.mean(r):+.1f})")
    ax.axhline(0.0, color="#999999", lw=0.8)
    ax.set_xticks(range(args.episodes))
    ax.set_xlabel("episode (seed)")
    ax.set_ylabel("return")
    ax.set_title(f"tanktool env: {args.arena}, one learning tank vs {args.opponent}, {args.seconds:g} s episodes")
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
