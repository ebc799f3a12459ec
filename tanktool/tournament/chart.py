"""The tournament's picture: Elo ratings with their 95 % intervals, and the score
matrix (the mean score of each row bot against each column bot over every match:
1 all won, 0 all lost)."""

from __future__ import annotations

import io
import os
from typing import Any

import numpy as np


def score_matrix(report: dict[str, Any]) -> tuple[list[str], np.ndarray]:
    """(n, n) mean score of bot i against bot j (NaN on the diagonal)."""
    names = [b["name"] for b in report["bots"]]
    at = {n: i for i, n in enumerate(names)}
    total = np.zeros((len(names), len(names)))
    count = np.zeros_like(total)
    for m in report["matches"]:
        i, j = at[m["a"]], at[m["b"]]
        total[i, j] += m["score"]
        total[j, i] += 1.0 - m["score"]
        count[i, j] += 1
        count[j, i] += 1
    with np.errstate(invalid="ignore"):
        return names, np.where(count > 0, total / np.maximum(count, 1), np.nan)


def chart_png(report: dict[str, Any], dpi: int = 110) -> bytes:
    """The chart as PNG bytes."""
    import matplotlib

    if os.environ.get("DISPLAY") is None:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = sorted(report["elo"], key=lambda r: r["elo"])
    names, mat = score_matrix(report)
    n = len(names)
    fig, (ax, mx) = plt.subplots(1, 2, figsize=(11.0, max(3.2, 0.45 * n + 1.8)),
                                 gridspec_kw={"width_ratios": [1.0, 1.1]})
    y = np.arange(len(rows))
    elo = np.array([r["elo"] for r in rows])
    lo = np.array([r["lo"] for r in rows])
    hi = np.array([r["hi"] for r in rows])
    ax.errorbar(elo, y, xerr=[elo - lo, hi - elo], fmt="o", color="#1f5f8b", ecolor="#7fa7c4",
                capsize=4, lw=2)
    ax.axvline(1500.0, color="#999999", lw=0.8, ls="--")
    ax.set_yticks(y, [r["bot"] for r in rows])
    ax.set_xlabel("Elo (mean 1500), 95 % bootstrap interval")
    ax.set_title("ratings")
    ax.grid(axis="x", alpha=0.3)
    im = mx.imshow(mat, cmap="RdYlGn", vmin=0.0, vmax=1.0)
    mx.set_xticks(range(n), names, rotation=30, ha="right")
    mx.set_yticks(range(n), names)
    for i in range(n):
        for j in range(n):
            if not np.isnan(mat[i, j]):
                mx.text(j, i, f"{mat[i, j]:.2f}", ha="center", va="center", fontsize=9)
    mx.set_title("mean score, row bot vs column bot")
    fig.colorbar(im, ax=mx, fraction=0.046, pad=0.04)
    fig.suptitle(f"tournament: {', '.join(report['arenas'])} / {', '.join(report['vehicles'])}, "
                 f"{report['matches_per_pairing']} x {report['seconds']:g} s per pairing")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    return buf.getvalue()
