"""Top view of an arena: walls with their normals, the auxiliary rectangle, spawns.

matplotlib is imported inside the function (Agg backend), so importing this module
costs nothing and works without a display.
"""

from __future__ import annotations

import io
import os
from typing import Any

import numpy as np

from ..formats.walls_txt import WallList


def render_preview(walls: WallList, spawns: np.ndarray, title: str, free: Any = None,
                   size_px: int = 900) -> bytes:
    """PNG bytes of the arena's top view.

    walls : the wall list (auxiliary rectangle drawn dashed)
    spawns : (k, 3) ``[x, z, heading]``, drawn as numbered arrows
    free : optional shapely geometry of the free space, filled light grey
    The x axis points right and z up, equal aspect; each wall has a short tick
    along its normal, on the free-space side.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    (xmin, zmin), (xmax, zmax) = walls.bounds
    w = max(xmax - xmin, 1e-6)
    h = max(zmax - zmin, 1e-6)
    aspect = h / w
    fig_w = 9.0
    fig_h = float(np.clip(fig_w * aspect + 0.8, 3.0, 14.0))
    fig = Figure(figsize=(fig_w, fig_h), dpi=size_px / fig_w)
    ax = fig.add_subplot(1, 1, 1)
    ax.set_aspect("equal")
    if free is not None and not free.is_empty:
        import shapely

        for poly in shapely.get_parts(free):
            ax.fill(*poly.exterior.xy, color="#e8efe6", zorder=0, lw=0)
            for hole in poly.interiors:
                ax.fill(*hole.xy, color="white", zorder=0, lw=0)
    seg = walls.segments
    ax.add_collection(LineCollection(seg, colors="#202020", linewidths=1.4, zorder=2))
    if len(seg):
        mid = seg.mean(axis=1)
        tick = 0.012 * max(w, h)
        tips = mid + walls.normals * tick
        ax.add_collection(LineCollection(np.stack([mid, tips], axis=1), colors="#d04020",
                                         linewidths=0.8, zorder=3))
    if walls.aux is not None:
        ax.add_collection(LineCollection(walls.aux, colors="#4060c0", linewidths=0.9,
                                         linestyles="dashed", zorder=1))
    spawns = np.asarray(spawns, dtype=np.float64).reshape(-1, 3)
    arrow = 0.03 * max(w, h)
    for k, (x, z, th) in enumerate(spawns, start=1):
        ax.annotate("", xy=(x + arrow * np.cos(th), z + arrow * np.sin(th)), xytext=(x, z),
                    arrowprops=dict(arrowstyle="-|>", color="#1a7a1a", lw=1.5), zorder=4)
        ax.plot([x], [z], "o", color="#1a7a1a", ms=4, zorder=4)
        ax.text(x - 0.4 * arrow * np.cos(th), z - 0.4 * arrow * np.sin(th), str(k), color="#1a7a1a",
                fontsize=8, ha="center", va="center", zorder=5)
    pad = 0.03 * max(w, h)
    ax.set_xlim(xmin - pad, xmax + pad)
    ax.set_ylim(zmin - pad, zmax + pad)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, lw=0.3, alpha=0.5)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return buf.getvalue()


def save_preview(path: str | os.PathLike, walls: WallList, spawns: np.ndarray, title: str, free: Any = None) -> None:
    """Write :func:`render_preview` to ``path`` atomically."""
    from ..formats.bundle import atomic_write_bytes

    atomic_write_bytes(path, render_preview(walls, spawns, title, free))
