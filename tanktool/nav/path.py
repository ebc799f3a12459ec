"""Path planning on the navigation grid: A* (8-connected, no corner cutting) and
line-of-sight smoothing against the grid or the wall quadtree."""

from __future__ import annotations

import heapq
import math

import numpy as np

from .navgrid import NavGrid, Node
from .quadtree import WallQuadtree

_SQRT2 = math.sqrt(2.0)


def astar(grid: NavGrid, start: Node, goal: Node, passable: np.ndarray | None = None) -> list[Node]:
    """Shortest 8-connected path of valid nodes from ``start`` to ``goal`` (both included).

    A diagonal step needs both orthogonal neighbours it passes valid (no corner
    cutting).  Step costs 1 and sqrt(2); the octile distance is the heuristic, so the
    path is optimal.  Returns ``[]`` when either end is not passable or no path exists.
    ``passable`` defaults to ``grid.valid``.
    """
    ok = grid.valid if passable is None else passable
    nz, nx = ok.shape
    (si, sj), (gi, gj) = start, goal
    for i, j in (start, goal):
        if not (0 <= i < nz and 0 <= j < nx):
            raise ValueError(f"node {(i, j)} is outside the {nz} x {nx} grid")
    if not (ok[si, sj] and ok[gi, gj]):
        return []
    flat = ok.ravel().tolist()  # list indexing is much faster than numpy scalars here
    s, g = si * nx + sj, gi * nx + gj
    k = _SQRT2 - 2.0

    def h(n: int) -> float:
        di = abs(n // nx - gi)
        dj = abs(n % nx - gj)
        return di + dj + k * min(di, dj)

    best = {s: 0.0}
    came: dict[int, int] = {}
    # ties on f go to the node nearer the goal: far fewer expansions on open ground
    heap = [(h(s), h(s), 0.0, s)]
    closed = set()
    while heap:
        f, _, gc, n = heapq.heappop(heap)
        if n == g:
            out = [n]
            while n in came:
                n = came[n]
                out.append(n)
            return [divmod(m, nx) for m in reversed(out)]
        if n in closed:
            continue
        closed.add(n)
        i, j = divmod(n, nx)
        e = j + 1 < nx and flat[n + 1]
        w = j > 0 and flat[n - 1]
        no = i + 1 < nz and flat[n + nx]
        so = i > 0 and flat[n - nx]
        steps = []
        if e:
            steps.append((n + 1, 1.0))
        if w:
            steps.append((n - 1, 1.0))
        if no:
            steps.append((n + nx, 1.0))
            if e and flat[n + nx + 1]:
                steps.append((n + nx + 1, _SQRT2))
            if w and flat[n + nx - 1]:
                steps.append((n + nx - 1, _SQRT2))
        if so:
            steps.append((n - nx, 1.0))
            if e and flat[n - nx + 1]:
                steps.append((n - nx + 1, _SQRT2))
            if w and flat[n - nx - 1]:
                steps.append((n - nx - 1, _SQRT2))
        for m, c in steps:
            if m in closed:
                continue
            ng = gc + c
            if ng < best.get(m, math.inf):
                best[m] = ng
                came[m] = n
                hm = h(m)
                heapq.heappush(heap, (ng + hm, hm, ng, m))
    return []


def path_length(grid: NavGrid, path: list[Node]) -> float:
    """Length in metres of a node path (straight lines between node centres)."""
    if len(path) < 2:
        return 0.0
    p = grid.centres(np.array(path))
    return float(np.hypot(*np.diff(p, axis=0).T).sum())


def grid_line_of_sight(grid: NavGrid, a: Node, b: Node, passable: np.ndarray | None = None) -> bool:
    """True when every cell the segment between the two node centres touches is passable.

    An integer walk over the cells (exact: no floating point); where the segment
    passes exactly through a cell corner, both cells beside the corner must be
    passable too (no corner cutting, as in :func:`astar`).
    """
    ok = grid.valid if passable is None else passable
    nz, nx = ok.shape
    (z, x), (bi, bj) = a, b
    if not (0 <= z < nz and 0 <= x < nx and 0 <= bi < nz and 0 <= bj < nx):
        return False
    dz, dx = bi - z, bj - x
    sz, sx = (dz > 0) - (dz < 0), (dx > 0) - (dx < 0)
    mz, mx = abs(dz), abs(dx)
    if not ok[z, x]:
        return False
    iz = ix = 0
    while ix < mx or iz < mz:
        # the next boundary crossed: x's at t = (ix + 1/2) / mx, z's at (iz + 1/2) / mz
        d = (1 + 2 * ix) * mz - (1 + 2 * iz) * mx
        if d == 0:
            if not (ok[z, x + sx] and ok[z + sz, x]):
                return False
            x += sx
            z += sz
            ix += 1
            iz += 1
        elif d < 0:
            x += sx
            ix += 1
        else:
            z += sz
            iz += 1
        if not ok[z, x]:
            return False
    return True


def smooth_path(
    obstacles: NavGrid | WallQuadtree, path, *, grid: NavGrid | None = None, clearance: float = 0.0,
):
    """Drop the waypoints a straight line can skip (greedy string pulling).

    obstacles : a NavGrid (line of sight = every touched cell passable) or a
                WallQuadtree (line of sight = no wall within ``clearance`` of the line).
    path : a list of nodes (as :func:`astar` returns), or an (m, 2) array of world
           points when ``obstacles`` is a quadtree.  Nodes with a quadtree need ``grid``
           to place them.
    Returns the kept waypoints in the same form, first and last always kept.
    """
    nodes_given = not (isinstance(path, np.ndarray) and path.dtype.kind == "f")
    if len(path) <= 2:
        return list(path) if nodes_given else np.asarray(path)
    if isinstance(obstacles, NavGrid):
        if not nodes_given:
            raise TypeError("smoothing against a NavGrid takes a list of nodes")
        nodes = [tuple(map(int, n)) for n in path]
        ok = obstacles.valid
        keep = [0]
        while keep[-1] < len(nodes) - 1:
            a = keep[-1]
            # walk forward while the straight line still holds (string pulling)
            k = a + 1
            while k + 1 < len(nodes) and grid_line_of_sight(obstacles, nodes[a], nodes[k + 1], ok):
                k += 1
            keep.append(k)
        return [nodes[k] for k in keep]
    if nodes_given:
        if grid is None:
            raise TypeError("smoothing nodes against a quadtree needs grid= to place them")
        pts = grid.centres(np.array(path))
    else:
        pts = np.asarray(path, dtype=np.float64).reshape(-1, 2)
    keep = [0]
    while keep[-1] < len(pts) - 1:
        a = keep[-1]
        later = np.arange(a + 1, len(pts))
        off, _ = obstacles.query_capsules(np.repeat(pts[a][None], len(later), axis=0), pts[later], clearance)
        clear = np.flatnonzero(np.diff(off) == 0)
        # the next waypoint always stays: it was reachable from a in the input path
        keep.append(int(later[clear[-1]]) if len(clear) else a + 1)
    if nodes_given:
        return [tuple(map(int, path[k])) for k in keep]
    return pts[keep]


def find_path(
    grid: NavGrid, start: tuple[float, float], goal: tuple[float, float], *,
    quadtree: WallQuadtree | None = None, clearance: float | None = None, snap: int = 4,
) -> np.ndarray:
    """World waypoints (k, 2) from world point ``start`` to ``goal``; (0, 2) when none.

    Both ends snap to the nearest valid node within ``snap`` cells (an agent may stand
    inside the clearance band); the A* path is smoothed against the quadtree with
    ``clearance`` (default: the grid's own, a hair less) when one is given, else against
    the grid.  The first and last waypoints are the given points themselves.
    """
    from .navgrid import nearest_valid_node

    s = nearest_valid_node(grid.valid, grid.node_of(*start), snap)
    g = nearest_valid_node(grid.valid, grid.node_of(*goal), snap)
    if s is None or g is None:
        return np.zeros((0, 2))
    nodes = astar(grid, s, g)
    if not nodes:
        return np.zeros((0, 2))
    if quadtree is not None:
        r = clearance if clearance is not None else (grid.clearance * 0.999 if np.isfinite(grid.clearance) else 0.0)
        kept = smooth_path(quadtree, nodes, grid=grid, clearance=r)
    else:
        kept = smooth_path(grid, nodes)
    pts = grid.centres(np.array(kept))
    return np.concatenate([np.asarray(start, dtype=np.float64)[None], pts[1:-1], np.asarray(goal, dtype=np.float64)[None]]) \
        if len(pts) >= 2 else np.array([start, goal], dtype=np.float64)
