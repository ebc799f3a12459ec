"""The top of a ramp onto a deck over walkable ground, lifted to the deck's level.

:func:`tanktool.nav.level_stack.stack_levels` gives a span the level of the spans below
it in its column, then of most of its neighbours.  A ramp coming up to a deck that
stands on pillars over walkable ground (tools/make_levels.py's stacked_floors and
two_storeys) is then on the ground's level up to its top, where it ends beside the
ground under the deck, 4-5 m below: on that level the edge is a wall (the ground's,
rightly: the ramp's end face), and a wall of its own level cuts the ramp's top off from
the deck for every tank.  :func:`lift_to_portals` moves the ramp's top to the deck's
level for :data:`LIFT` metres, so that the seam between the ramp's two levels is a
portal away from the ground's wall.
"""

from __future__ import annotations

import math

import numpy as np

from ..geometry.kernels import active, i64

#: how far down a ramp its top joins the level of the deck it comes up to, where the
#: deck stands over walkable ground (:func:`lift_to_portals`), in metres: past the
#: largest bundled footprint radius (heavy, 4.63 m) with a cell to spare.  A constant,
#: not the grid's clearance, so that every grid of a bundle (each vehicle's, a rebuild
#: with other settings) stacks the levels its walls were drawn on; a grid for a wider
#: clearance finds the ramp's top cut off from the deck again
LIFT = 6.0


def lift_steps(cell: float) -> int:
    """:data:`LIFT` in links of a grid of ``cell``."""
    return int(math.ceil(LIFT / cell))


def lift_to_portals(col: np.ndarray, level: np.ndarray, link: np.ndarray, steps: int) -> None:
    """Move, in place, the spans near a *ledged portal* to the level across it.

    A ramp coming up to a deck that stands on pillars over walkable ground ends beside
    the ground under the deck: its top cells link to the deck (another level) across
    an edge where a cell of their own level (the ground, 4 m below) lies unlinked.  On
    one level, that edge is a wall for the ground and so for the ramp too: the ramp's
    top would be cut off from the deck by a clearance's width, and no tank reaches the
    deck (stacked_floors, two_storeys).  So the spans within ``steps`` links of such an
    edge, along links on their own level, join the deck's level where it is free in
    their column: the seam moves down the ramp, away from the ground's wall, to a
    portal between the ramp's two levels."""
    kern = active()
    if (kern is not None and link.dtype == np.int32 and level.dtype == np.int64 and level.flags.c_contiguous
            and level.flags.writeable):
        # one pass a direction and a look along the column for held(), where numpy sorts
        # every kept span's key and searches it per step (tanktool/_kernels_surface.c)
        kern.lift_portals(i64(col), level, np.ascontiguousarray(link), int(steps))
        return
    kept = np.flatnonzero(level >= 0)
    if len(kept) == 0:
        return
    L = int(level.max()) + 1
    keys = np.sort(col[kept] * L + level[kept])  # (column, level) pairs that hold a span

    def held(c: np.ndarray, lv: np.ndarray) -> np.ndarray:
        k = c * L + lv
        at = np.minimum(np.searchsorted(keys, k), len(keys) - 1)
        return keys[at] == k

    target = np.full(len(level), -1, dtype=np.int64)
    away = np.full(len(level), -1, dtype=np.int64)  # the direction back down the ramp
    for d in range(4):
        nb = link[kept, d].astype(np.int64)
        s, t = kept[nb >= 0], nb[nb >= 0]
        cross = level[t] != level[s]
        s, t = s[cross], t[cross]
        # the neighbour column holds a span of s's own level that s does not link to
        ledged = held(col[t], level[s]) & ~held(col[s], level[t])
        target[s[ledged]] = level[t[ledged]]
        away[s[ledged]] = (d + 2) % 4
    # straight back from the edge (a band as wide as the edge, its seam a straight
    # portal: a diagonal seam's simplified outline would read partly as a wall)
    front = np.flatnonzero(target >= 0)
    for _ in range(steps):
        u = link[front, away[front]].astype(np.int64)
        ok = u >= 0
        f, u = front[ok], u[ok]
        ok = (level[u] == level[f]) & (target[u] < 0) & ~held(col[u], target[f])
        target[u[ok]], away[u[ok]] = target[f[ok]], away[f[ok]]
        front = u[ok]
        if len(front) == 0:
            break
    moved = np.flatnonzero(target >= 0)
    if len(moved) == 0:
        return
    # two spans of one column sent to the same level (not met in practice): neither moves
    k = col[moved] * L + target[moved]
    _, inv, cnt = np.unique(k, return_inverse=True, return_counts=True)
    moved = moved[cnt[inv] == 1]
    level[moved] = target[moved]
