"""No tank stands where the ground has no level (issue 25).

A spawn point in a hole of the surface, a tank placed by hand off every level, one a
push left where no node is: :func:`put_back` moves it onto the nearest node of the
ground (in the (x, z) plane, a node nearer its height first among equals), so
``Ground.locate`` finds its level and the height under it is the surface's, never
the 0.0 a ground answers where it has none.
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: metres of height difference that weigh as one metre across, choosing the node
HEIGHT_WEIGHT = 0.5


def _nodes(ground: Any) -> tuple[np.ndarray, ...]:
    """(level, x, z, y) of every node of the ground, computed once per ground."""
    cached = getattr(ground, "_node_list", None)
    if cached is None:
        ll, ii, jj = np.nonzero(np.isfinite(np.asarray(ground.h)))
        xs = ground.ox + (jj + 0.5) * ground.cell
        zs = ground.oz + (ii + 0.5) * ground.cell
        cached = (ll, xs, zs, np.asarray(ground.h)[ll, ii, jj])
        ground._node_list = cached
    return cached


def nearest_node(ground: Any, x: float, z: float, y: float | None = None) -> tuple[int, float, float] | None:
    """(level, x, z) of the node of ``ground`` nearest (x, z) (and height ``y``), or
    None when the ground has no node at all."""
    ll, xs, zs, ys = _nodes(ground)
    if len(ll) == 0:
        return None
    d = (xs - x) ** 2 + (zs - z) ** 2
    if y is not None:
        d = d + (HEIGHT_WEIGHT * (ys - y)) ** 2
    k = int(np.argmin(d))
    return int(ll[k]), float(xs[k]), float(zs[k])


def put_back(ground: Any, t: Any, y: float | None = None) -> bool:
    """Move tank ``t`` onto the nearest node when no level of ``ground`` lies under it
    (within a cell); returns whether it moved."""
    if ground.locate(t.x, t.z) >= 0 or ground.near_level(t.x, t.z, t.y if y is None else y) >= 0:
        return False
    node = nearest_node(ground, t.x, t.z, y)
    if node is None:
        return False
    t.level, t.x, t.z = node
    t.vx = t.vz = 0.0
    return True
