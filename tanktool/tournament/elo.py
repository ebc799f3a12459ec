"""Elo ratings from a round robin: a Bradley-Terry fit (draws count half) and
bootstrap intervals.

``fit_elo`` is the maximum-likelihood Bradley-Terry strength of each player from
games ``(i, j, score of i)``, with ``prior`` virtual draws per pair so that a clean
sweep stays finite, on the Elo scale (400 log10) with the players' mean at 1500.
``elo_table`` adds a percentile interval from resampling the games within each cell
(pairing, arena, vehicle) with a seeded generator: the same games give the same
table on every machine.
"""

from __future__ import annotations

import itertools
from typing import Sequence

import numpy as np

#: the players' mean rating
MEAN = 1500.0


def fit_elo(n: int, games: Sequence[tuple[int, int, float]], prior: float = 1.0) -> np.ndarray:
    """(n,) Elo ratings (mean 1500) from games (i, j, score of i in [0, 1]) by the
    minorise-maximise iteration of the Bradley-Terry likelihood."""
    wins = np.zeros(n)
    count = np.zeros((n, n))
    for i, j, s in games:
        wins[i] += s
        wins[j] += 1.0 - s
        count[i, j] += 1.0
        count[j, i] += 1.0
    for i, j in itertools.combinations(range(n), 2):
        wins[i] += 0.5 * prior
        wins[j] += 0.5 * prior
        count[i, j] += prior
        count[j, i] += prior
    g = np.ones(n)
    for _ in range(2000):
        denom = (count / (g[:, None] + g[None, :])).sum(axis=1)
        new = wins / np.maximum(denom, 1e-300)
        new /= np.exp(np.mean(np.log(new)))
        done = np.max(np.abs(np.log(new) - np.log(g))) < 1e-10
        g = new
        if done:
            break
    r = 400.0 * np.log10(g)
    return r - r.mean() + MEAN


def elo_table(names: Sequence[str], games: Sequence[tuple[int, int, float, int]], boot: int = 200,
              level: float = 0.95, seed: int = 1) -> list[dict]:
    """One row per player: ``bot``, ``elo`` and the ``level`` bootstrap interval
    ``lo``, ``hi`` from ``boot`` resamples of the games (i, j, score, cell) within
    each cell."""
    n = len(names)
    elo = fit_elo(n, [(i, j, s) for i, j, s, _ in games])
    by_cell: dict[int, list[tuple[int, int, float]]] = {}
    for i, j, s, c in games:
        by_cell.setdefault(c, []).append((i, j, s))
    rng = np.random.default_rng(seed)
    boots = []
    for _ in range(max(boot, 0)):
        sample: list[tuple[int, int, float]] = []
        for c in sorted(by_cell):
            gs = by_cell[c]
            sample.extend(gs[k] for k in rng.integers(0, len(gs), len(gs)))
        boots.append(fit_elo(n, sample))
    tail = 50.0 * (1.0 - level)
    rows = []
    for k, name in enumerate(names):
        lo, hi = (np.percentile([b[k] for b in boots], [tail, 100.0 - tail]) if boots else (elo[k], elo[k]))
        rows.append({"bot": name, "elo": round(float(elo[k]), 1), "lo": round(float(lo), 1),
                     "hi": round(float(hi), 1)})
    return rows
