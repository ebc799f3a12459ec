"""Path planning on the navigation grid: A* (8-connected, no corner cutting) and
line-of-sight smoothing against the grid or the wall quadtree."""

from __future__ import annotations

import heapq
import math
from typing import Any

import numpy as np

from .navgrid import NavGrid, Node
from .quadtree import WallQuadtree

_SQRT2 = math.sqrt(2.0)


def move_masks(passable: np.ndarray) -> np.ndarray:
    """(nz, nx) uint8: bit k set when move k is allowed from the node.

    Moves in bit order: +x, -x, +z, -z, then the diagonals +z+x, +z-x, -z+x, -z-x; a
    diagonal needs both orthogonal neighbours it passes (no corner cutting).
    """
    nz, nx = passable.shape
    p = np.zeros((nz + 2, nx + 2), dtype=bool)
    p[1:-1, 1:-1] = passable
    c = p[1:-1, 1:-1]
    e, w, n, s = p[1:-1, 2:], p[1:-1, :-2], p[2:, 1:-1], p[:-2, 1:-1]
    m = (c & e) * 1 | (c & w) * 2 | (c & n) * 4 | (c & s) * 8
    m |= (c & n & e & p[2:, 2:]) * 16 | (c & n & w & p[2:, :-2]) * 32
    m |= (c & s & e & p[:-2, 2:]) * 64 | (c & s & w & p[:-2, :-2]) * 128
    return m.astype(np.uint8)


def astar(grid: NavGrid, start: Node, goal: Node, passable: np.ndarray | None = None) -> list[Node]:
    """Shortest 8-connected path of valid nodes from ``start`` to ``goal`` (both included).

    A diagonal step needs both orthogonal neighbours it passes valid (no corner
    cutting).  Step costs 1 and sqrt(2); the octile distance is the heuristic, so the
    path is optimal.  Returns ``[]`` when either end is not passable or no path exists.
    ``passable`` (nz, nx) defaults to the valid nodes of the grid's level 0 (the 2002
    planner: one level; :func:`astar_layered` plans across levels).
    """
    ok = grid.valid[0] if passable is None else passable
    nz, nx = ok.shape
    (si, sj), (gi, gj) = start, goal
    for i, j in (start, goal):
        if not (0 <= i < nz and 0 <= j < nx):
            raise ValueError(f"node {(i, j)} is outside the {nz} x {nx} grid")
    if not (ok[si, sj] and ok[gi, gj]):
        return []
    # the allowed moves of every node in one vectorised pass; the search loop then
    # only looks up a small int per node (lists beat numpy scalars here)
    masks = move_masks(ok).ravel().tolist()
    offsets = [(1, 1.0), (-1, 1.0), (nx, 1.0), (-nx, 1.0),
               (nx + 1, _SQRT2), (nx - 1, _SQRT2), (-nx + 1, _SQRT2), (-nx - 1, _SQRT2)]
    table = [[offsets[k] for k in range(8) if b >> k & 1] for b in range(256)]
    s, g = si * nx + sj, gi * nx + gj
    k2 = _SQRT2 - 2.0

    def h(n: int) -> float:
        di = abs(n // nx - gi)
        dj = abs(n % nx - gj)
        return di + dj + k2 * (di if di < dj else dj)

    best = {s: 0.0}
    came: dict[int, int] = {}
    closed: set[int] = set()
    heap = [(h(s), 0.0, s)]
    pop, push = heapq.heappop, heapq.heappush
    while heap:
        _, gc, n = pop(heap)
        if n == g:
            out = [n]
            while n in came:
                n = came[n]
                out.append(n)
            return [divmod(m, nx) for m in reversed(out)]
        if n in closed:
            continue
        closed.add(n)
        for off, cost in table[masks[n]]:
            m = n + off
            if m in closed:
                continue
            ng = gc + cost
            if ng < best.get(m, math.inf):
                best[m] = ng
                came[m] = n
                push(heap, (ng + h(m), ng, m))
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
    ok = grid.valid[0] if passable is None else passable   # level 0, as astar
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
        ok = obstacles.valid[0]
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

    s = nearest_valid_node(grid.valid[0], grid.node_of(*start), snap)
    g = nearest_valid_node(grid.valid[0], grid.node_of(*goal), snap)
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


Node3 = tuple[int, int, int]


def layered_moves(grid: NavGrid) -> tuple[np.ndarray, list[tuple[int, int, float]]]:
    """Move table of a layered grid: for each node (flat index over (L, nz, nx)) the
    target of each of the 8 moves (-1: not allowed), and the moves' (di, dj, cost).

    A straight move follows the node's link; a diagonal one needs both of its two
    straight paths (d then e, e then d) to exist and to end on the same node (no corner
    cutting, and no cutting between levels)."""
    from .navgrid import STEPS

    valid = grid.valid
    link = grid.links().astype(np.int64)
    L, nz, nx = valid.shape
    n = valid.size
    flat = np.arange(n).reshape(L, nz, nx)
    steps = list(STEPS.values())  # +x, +z, -x, -z
    target = np.full((n, 8), -1, dtype=np.int64)
    li, ii, jj = np.nonzero(valid)
    src = flat[li, ii, jj]
    straight = []
    for d, (di, dj) in enumerate(steps):
        t = link[li, ii, jj, d]
        a, b = ii + di, jj + dj
        ok = (t >= 0) & (a >= 0) & (a < nz) & (b >= 0) & (b < nx)
        ok[ok] = valid[t[ok], a[ok], b[ok]]
        tgt = np.full(len(src), -1, dtype=np.int64)
        tgt[ok] = flat[t[ok], a[ok], b[ok]]
        target[src, d] = tgt
        straight.append(tgt)
    moves = [(di, dj, 1.0) for di, dj in steps]
    for k, (d, e) in enumerate(((0, 1), (1, 2), (2, 3), (3, 0))):
        first, second = target[:, d], target[:, e]
        via_d = np.where(first >= 0, target[np.maximum(first, 0), e], -1)
        via_e = np.where(second >= 0, target[np.maximum(second, 0), d], -1)
        target[:, 4 + k] = np.where((via_d >= 0) & (via_d == via_e), via_d, -1)
        moves.append((steps[d][0] + steps[e][0], steps[d][1] + steps[e][1], _SQRT2))
    return target, moves


class _LazyMoves(dict):
    """``table[m]``: layered_moves' row of node ``m`` as a tuple, worked out from the
    grid's links on first use and kept.  The whole table as lists took ~300 bytes a
    node (2.5 GB and a minute on a 2 km terrain's 16 M nodes) where a path visits a
    few of them; past MAX_KEPT rows the kept ones are dropped (made again if needed)."""

    MAX_KEPT = 1 << 20

    def __init__(self, grid: NavGrid) -> None:
        from .navgrid import STEPS

        super().__init__()
        L, nz, nx = grid.valid.shape
        self.nz, self.nx, self.per = nz, nx, nz * nx
        # flat views: indexing a memoryview gives Python ints without numpy scalars
        self.valid = memoryview(np.ascontiguousarray(grid.valid, dtype=np.uint8).reshape(-1))
        self.link = memoryview(np.ascontiguousarray(grid.links(), dtype=np.int8).reshape(-1))
        self.steps = list(STEPS.values())  # +x, +z, -x, -z

    def straight(self, m: int, d: int) -> int:
        """The target of straight move ``d`` from the valid node ``m`` (-1: none)."""
        lv, r = divmod(m, self.per)
        i, j = divmod(r, self.nx)
        t = self.link[4 * m + d]
        di, dj = self.steps[d]
        a, b = i + di, j + dj
        if t < 0 or not (0 <= a < self.nz and 0 <= b < self.nx):
            return -1
        n = t * self.per + a * self.nx + b
        return n if self.valid[n] else -1

    def __missing__(self, m: int) -> tuple:
        if not self.valid[m]:
            row = (-1,) * 8
        else:
            s = [self.straight(m, d) for d in range(4)]
            row = list(s)
            for d, e in ((0, 1), (1, 2), (2, 3), (3, 0)):
                via_d = self.straight(s[d], e) if s[d] >= 0 else -1
                via_e = self.straight(s[e], d) if s[e] >= 0 else -1
                row.append(via_d if via_d >= 0 and via_d == via_e else -1)
            row = tuple(row)
        if len(self) >= self.MAX_KEPT:
            self.clear()
        self[m] = row
        return row


def _move_table(grid: NavGrid) -> tuple[Any, list[float]]:
    """layered_moves' table, a row made on first use (_LazyMoves), once per grid (kept
    on it: a grid is not changed once built, and an agent plans on its grid many times)."""
    cached = grid.__dict__.get("_move_table")
    if cached is None:
        cost = [1.0] * 4 + [_SQRT2] * 4   # layered_moves' costs: straight, then diagonal
        cached = grid.__dict__["_move_table"] = (_LazyMoves(grid), cost)
    return cached


def _path_kernel():
    """The compiled kernels when built, in use and holding ``astar_layered``, else None."""
    from ..geometry.kernels import active

    kern = active()
    return kern if getattr(kern, "astar_layered", None) is not None else None


def _kernel_arrays(grid: NavGrid) -> tuple[np.ndarray, np.ndarray]:
    """(valid as bytes, links as int8), C-ordered, kept on the grid (not changed once built)."""
    cached = grid.__dict__.get("_kernel_arrays")
    if cached is None:
        cached = grid.__dict__["_kernel_arrays"] = (
            np.ascontiguousarray(grid.valid, dtype=bool).view(np.uint8),
            np.ascontiguousarray(grid.links(), dtype=np.int8))
    return cached


def astar_layered(grid: NavGrid, start: Node3, goal: Node3) -> list[Node3]:
    """Shortest path of valid nodes ``(level, i, j)`` across levels (ramps, steps,
    decks), 8-connected along the grid's links; ``[]`` when there is none.  The octile
    distance over (i, j) is the heuristic (a change of level costs nothing extra), so
    the path is optimal."""
    valid = grid.valid
    L, nz, nx = valid.shape
    for n in (start, goal):
        if not (0 <= n[0] < L and 0 <= n[1] < nz and 0 <= n[2] < nx):
            raise ValueError(f"node {n} is outside the {L} x {nz} x {nx} grid")
    if not (valid[start] and valid[goal]):
        return []
    per = nz * nx
    kern = _path_kernel()
    if kern is not None:   # the same search in C (_kernels_path.c): 16 ms a path on 2 km in Python
        flat = kern.astar_layered(*_kernel_arrays(grid), L, nz, nx, start[0] * per + start[1] * nx + start[2],
                                  goal[0] * per + goal[1] * nx + goal[2])
        return [(v // per, (v % per) // nx, v % nx) for v in flat]
    table, cost = _move_table(grid)
    s = start[0] * per + start[1] * nx + start[2]
    g = goal[0] * per + goal[1] * nx + goal[2]
    gi, gj = goal[1], goal[2]
    k2 = _SQRT2 - 2.0

    def h(m: int) -> float:
        r = m % per
        di = abs(r // nx - gi)
        dj = abs(r % nx - gj)
        return di + dj + k2 * (di if di < dj else dj)

    best = {s: 0.0}
    came: dict[int, int] = {}
    closed: set[int] = set()
    heap = [(h(s), 0.0, s)]
    while heap:
        _, gc, m = heapq.heappop(heap)
        if m == g:
            out = [m]
            while m in came:
                m = came[m]
                out.append(m)
            return [(v // per, (v % per) // nx, v % nx) for v in reversed(out)]
        if m in closed:
            continue
        closed.add(m)
        for k, t in enumerate(table[m]):
            if t < 0 or t in closed:
                continue
            ng = gc + cost[k]
            if ng < best.get(t, math.inf):
                best[t] = ng
                came[t] = m
                heapq.heappush(heap, (ng + h(t), ng, t))
    return []
