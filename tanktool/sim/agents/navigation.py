"""Where an agent drives: its navigation grid, the wander heuristic with memory, the
sight memory and exploration, the quadrant search.

**The agent's grid.**  The bundled ``navgrid.npz`` is built at 0.5 m for the largest
vehicle; an agent wants coarser nodes (A* over a few thousand nodes, not forty
thousand) and its own vehicle's clearance.  So each agent grid is built from the
world's walls: nodes every ``cell`` metres, valid when at least ``clearance`` (the
footprint radius plus a margin) from every wall and 4-connected to a spawn point (which
also throws out the inside of solid blocks), with the paper's row and column run
numbers.  One grid per (walls, cell, clearance) is cached.

**Wander** is the paper's ternary decision (``nav.steering.children``: the three
nodes ahead, scored by the free nodes before a wall in the direction each leads) with
two additions the nav engineer's notes ask for, because the greedy rule alone circles a
few nodes of an open room: the count is capped (a long hall is not ten times better
than a short one), and each child is weighted by the *novelty* of where it leads -- the
time since the agent last visited the region (``region`` metres square) of the node
``look`` nodes down that way, as a fraction of ``forget`` seconds -- times a small
random jitter.  With no memory and no jitter the weights are all 1 and the choice is
exactly ``choose_next``'s (tested on the paper's example).

**Explore** (what Wander does now) uses a memory of what was *seen*, not only where
the agent drove: ``Views`` cuts the grid into 4 m blocks (coarser in big arenas), one
representative valid node each, and works out once per arena which blocks are in line
of sight of which (the walls against every pair of representatives) and which blocks
touch; ``Coverage`` keeps, per agent, when each block was last in its vision cone,
within its vision range and in line of sight.  The exploration goal is the block that
sees the most *stale* blocks (not seen for ``fresh`` = 60 s; staleness grows to 1 at
``forget`` = 90 s, never seen is 1) per metre of path to it (Dijkstra over touching
blocks, + 10 m), so it looks into what it has not looked at, nearest first, without
ever reading where an enemy is.

**Search** is the paper's division into quadrants: the arena's rectangle is split into
four, ordered by their distance to where the enemy was last seen or heard (the one
holding it first), and each is split again until its longer side is at most
``leaf`` metres; the agent drives an A* path (``nav.path.find_path``) to the centre
of each leaf in that depth-first order, skipping leaves it visited recently.
"""

from __future__ import annotations

import math
import random
import weakref
from typing import TYPE_CHECKING, Iterator

import numpy as np

from ...nav.navgrid import (NavGrid, Node, STEPS, grid_from_mask, grid_shape, nearest_valid_node, nearest_valid_node3,
                            reachable_from, too_close)
from ...nav.path import find_path
from ...nav.steering import children, decide, heading_of_move

if TYPE_CHECKING:  # pragma: no cover
    from ..world import World

#: on a ground, the eye height of a block's point [m], the blocks at most (each line of
#: the sight map is sampled through the model's solid), and how far they look [m]
EYE = 1.2
VIEW_BLOCKS = 450
VIEW_RANGE = 150.0
#: the link steps (di, dj): +x, +z, -x, -z
STEP_LIST = ((0, 1), (1, 0), (0, -1), (-1, 0))

_GRIDS: "weakref.WeakKeyDictionary[object, dict[tuple[float, float], NavGrid]]" = weakref.WeakKeyDictionary()


#: an agent grid keeps the asked clearance, else the largest of these fractions of it
#: that leaves valid nodes by a spawn (a corridor or deck barely wider than the tank)
FALLBACK = (0.85, 0.7, 0.55, 0.4, 0.25, 0.0)


def agent_grid(world: "World", cell: float, clearance: float) -> NavGrid:
    """The navigation grid agents of this clearance use in ``world`` (cached per wall
    set, or per ground on an arena with relief or levels: then a projection carrying
    the layered grid as ``.layers``, see ``agents.layers``).

    Where the clearance leaves no valid node by any spawn (an arena barely wider than
    the tank), the grid is made again with less (``FALLBACK``), down to every node off
    the walls: its ``clearance`` says which it kept.  Agents then plan as close to the
    walls as they must; the physics keeps them out."""
    per = _GRIDS.setdefault(world.ground if world.ground is not None else world.walls, {})
    key = (float(cell), float(clearance))
    if key not in per:
        grid = None
        for c in (clearance, *(clearance * f for f in FALLBACK)):
            grid = _make_grid(world, cell, c)
            if grid.spawn_nodes and grid.valid.any():
                break
        per[key] = grid
    return per[key]


def _make_grid(world: "World", cell: float, clearance: float) -> NavGrid:
    if world.ground is not None:
        from .layers import ground_agent_grid

        spawns = [(x, z, y) for (x, z, _), y in zip(world.spawns, world.spawn_y)]
        return ground_agent_grid(world.ground, cell, clearance, spawns)
    bounds = np.asarray(world.bounds, dtype=np.float64)
    shape = grid_shape(bounds, cell)
    origin = bounds[0].copy()
    free = ~too_close(world.walls.segments, origin, cell, shape, clearance)
    g0 = grid_from_mask(free, origin, cell)
    seeds = []
    for x, z, _ in world.spawns:
        n = nearest_valid_node(free, g0.node_of(x, z), int(math.ceil(clearance / cell)) + 2)
        if n is not None:
            seeds.append(n)
    valid = reachable_from(free, seeds) if seeds else free
    grid = grid_from_mask(valid, origin, cell)
    grid.clearance = float(clearance)
    grid.spawn_nodes = seeds
    return grid


class Memory:
    """When each region (a square of ``region`` metres) was last visited."""

    def __init__(self, grid: NavGrid, region: float = 8.0) -> None:
        self.grid = grid
        self.region = region
        (x0, z0), (x1, z1) = grid.bounds.tolist()
        self.x0, self.z0 = x0, z0
        self.nx = max(int(math.ceil((x1 - x0) / region)), 1)
        self.nz = max(int(math.ceil((z1 - z0) / region)), 1)
        self.last = [-math.inf] * (self.nx * self.nz)
        self._goals: list[tuple[int, tuple[float, float]]] | None = None

    def key(self, x: float, z: float) -> int:
        i = min(max(int((x - self.x0) // self.region), 0), self.nx - 1)
        j = min(max(int((z - self.z0) // self.region), 0), self.nz - 1)
        return j * self.nx + i

    def visit(self, x: float, z: float, t: float) -> None:
        self.last[self.key(x, z)] = t

    def since(self, x: float, z: float, t: float) -> float:
        """Seconds since the region of (x, z) was visited (inf: never)."""
        return t - self.last[self.key(x, z)]

    def centre(self, key: int) -> tuple[float, float]:
        j, i = divmod(key, self.nx)
        return self.x0 + (i + 0.5) * self.region, self.z0 + (j + 0.5) * self.region

    def goals(self) -> list[tuple[int, tuple[float, float]]]:
        """(region, valid node centre) for every region holding a valid node: the node
        nearest the region's centre (computed once; cached on the memory)."""
        if self._goals is None:
            out = []
            grid = self.grid
            steps = int(math.ceil(0.5 * self.region / grid.cell))
            for key in range(len(self.last)):
                cx, cz = self.centre(key)
                n = nearest_valid_node(grid.valid, grid.node_of(cx, cz), steps)
                if n is not None:
                    gx, gz = grid.centre(*n)
                    if self.key(gx, gz) == key:
                        out.append((key, (gx, gz)))
            self._goals = out
        return self._goals



class Wanderer:
    """The paper's decision among the three nodes ahead, with novelty and jitter.

    ``memory`` None and ``jitter`` 0 give ``nav.steering.choose_next``'s choice.
    """

    def __init__(self, grid: NavGrid, memory: Memory | None = None, rng: random.Random | None = None,
                 jitter: float = 0.2, cap: int = 12, look: int = 16, forget: float = 60.0,
                 floor: float = 0.08, straight: float = 1.5) -> None:
        self.grid = grid
        self.memory = memory
        self.rng = rng
        self.jitter = jitter if rng is not None else 0.0
        self.cap = cap
        self.look = look
        self.forget = forget
        self.floor = floor
        self.straight = straight
        self.best_novelty = 1.0   # of the last choice: low when every way leads somewhere just seen

    def novelty(self, node: Node, heading: str, ahead: int, t: float) -> float:
        """1 + floor for a way into a region not visited for ``forget`` seconds, down
        to ``floor`` for one just visited (the region ``look`` nodes down that way)."""
        if self.memory is None:
            return 1.0
        k = min(ahead, self.look)
        di, dj = STEPS[heading]
        x, z = self.grid.centre(node[0] + di * k, node[1] + dj * k)
        return self.floor + min(self.memory.since(x, z, t) / self.forget, 1.0)

    def choose(self, node: Node, heading: str, t: float = 0.0) -> tuple[Node, str] | None:
        """The next node and the heading after moving there; None when boxed in."""
        kids = children(self.grid, node, heading)
        if not kids:
            return self._turn_in_place(node, heading)
        if self.memory is None and self.jitter == 0.0:
            pick = decide({c.name: c.ahead for c in kids})
            c = next(c for c in kids if c.name == pick)
            return c.node, c.heading
        scores = {}
        self.best_novelty = 0.0
        for c in kids:
            w = self.novelty(c.node, c.heading, c.ahead, t)
            self.best_novelty = max(self.best_novelty, w - self.floor)
            if self.jitter:
                w *= 1.0 + self.jitter * self.rng.random()  # type: ignore[union-attr]
            if c.name == "ahead":
                w *= self.straight   # keep going: a zigzag of side steps is slower to drive
            scores[c.name] = (min(c.ahead, self.cap) + 1) * w
        best = max(scores.values())
        for name in ("ahead", "right", "left"):
            if scores.get(name) == best:
                c = next(c for c in kids if c.name == name)
                return c.node, c.heading
        return None  # unreachable

    def _turn_in_place(self, node: Node, heading: str) -> tuple[Node, str] | None:
        from ...nav.steering import choose_next

        nxt = choose_next(self.grid, node, heading)
        if nxt is None:
            return None
        return nxt, heading_of_move(node, nxt, heading)


# ------------------------------------------------------------------ search
Rect = tuple[float, float, float, float]


def _rect_distance(r: Rect, x: float, z: float) -> float:
    x0, z0, x1, z1 = r
    dx = max(x0 - x, 0.0, x - x1)
    dz = max(z0 - z, 0.0, z - z1)
    return math.hypot(dx, dz)


def quadrants(r: Rect) -> list[Rect]:
    """The four quadrants of a rectangle (x0, z0, x1, z1)."""
    x0, z0, x1, z1 = r
    xm, zm = 0.5 * (x0 + x1), 0.5 * (z0 + z1)
    return [(x0, z0, xm, zm), (xm, z0, x1, zm), (x0, zm, xm, z1), (xm, zm, x1, z1)]


def search_order(r: Rect, x: float, z: float, leaf: float) -> Iterator[Rect]:
    """Leaf quadrants of ``r`` depth first, each level ordered by distance to (x, z)
    (the quadrant holding it first, ties by centre distance)."""
    x0, z0, x1, z1 = r
    if max(x1 - x0, z1 - z0) <= leaf:
        yield r
        return
    subs = sorted(quadrants(r), key=lambda q: (_rect_distance(q, x, z),
                                               math.hypot(0.5 * (q[0] + q[2]) - x, 0.5 * (q[1] + q[3]) - z)))
    for q in subs:
        yield from search_order(q, x, z, leaf)


def leaf_goal(grid: NavGrid, r: Rect) -> tuple[float, float] | None:
    """A valid node's centre inside the quadrant, the nearest to its centre; None if none."""
    x0, z0, x1, z1 = r
    cx, cz = 0.5 * (x0 + x1), 0.5 * (z0 + z1)
    steps = int(math.ceil(max(x1 - x0, z1 - z0) / (2 * grid.cell)))
    n = nearest_valid_node(grid.valid, grid.node_of(cx, cz), steps)
    if n is None:
        return None
    gx, gz = grid.centre(*n)
    if not (x0 <= gx <= x1 and z0 <= gz <= z1):
        return None
    return gx, gz


def leaf_goals_layered(grid: NavGrid, r: Rect, y: float | None) -> list[tuple[float, float, float]]:
    """Per level of a layered grid, the valid node inside the quadrant nearest its
    centre, as (x, z, height); the level nearest height ``y`` first (else the lowest)."""
    x0, z0, x1, z1 = r
    cx, cz = 0.5 * (x0 + x1), 0.5 * (z0 + z1)
    steps = int(math.ceil(max(x1 - x0, z1 - z0) / (2 * grid.cell)))
    valid, height = grid.layered("valid"), grid.layered("height")
    out = []
    for lv in range(valid.shape[0]):
        n = nearest_valid_node(valid[lv], grid.node_of(cx, cz), steps)
        if n is None:
            continue
        gx, gz = grid.centre(*n)
        if x0 <= gx <= x1 and z0 <= gz <= z1:
            out.append((gx, gz, float(height[lv][n])))
    out.sort(key=lambda g: abs(g[2] - y) if y is not None else g[2])
    return out


class SearchPlan:
    """The quadrant search from an estimate (x, z): goals in the paper's order.  On a
    layered grid (``grid.layers``) each quadrant is searched on every level it holds,
    the estimate's level (height ``y``) first; goals are then (x, z, height)."""

    def __init__(self, grid: NavGrid, x: float, z: float, leaf: float = 30.0, y: float | None = None) -> None:
        self.grid = grid
        (bx0, bz0), (bx1, bz1) = grid.bounds.tolist()
        layers = grid.layers
        self.goals: list[tuple[float, ...]] = []
        if layers is not None:
            first3 = nearest_valid_node3(layers.layered("valid"), layers.layered("height"), layers.node_of(x, z), y,
                                         int(math.ceil(6.0 / grid.cell)))
            if first3 is not None:
                lv, i, j = first3
                self.goals = [(*layers.centre(i, j), float(layers.layered("height")[first3]))]
        else:
            first = nearest_valid_node(grid.valid, grid.node_of(x, z), int(math.ceil(6.0 / grid.cell)))
            self.goals = [grid.centre(*first)] if first is not None else []
        for r in search_order((bx0, bz0, bx1, bz1), x, z, leaf):
            if layers is not None:
                self.goals.extend(leaf_goals_layered(layers, r, y))
                continue
            g = leaf_goal(grid, r)
            if g is not None:
                self.goals.append(g)
        self.k = 0

    def next_goal(self, memory: Memory | None, t: float, fresh: float = 25.0) -> tuple[float, ...] | None:
        """The next goal not visited within ``fresh`` seconds; None when all are done."""
        while self.k < len(self.goals):
            g = self.goals[self.k]
            self.k += 1
            if memory is None or memory.since(g[0], g[1], t) > fresh or self.k == 1:
                return g
        return None


def plan_path(grid: NavGrid, start: tuple[float, ...], goal: tuple[float, ...]) -> list[tuple[float, float]]:
    """A* waypoints from start to goal (the first, our position, dropped); [] when none.

    Points are (x, z) or (x, z, y): on a layered grid (``grid.layers``) the height
    picks the level at each end (the lowest when left out) and the path may change
    levels along the grid's links."""
    snap = int(math.ceil(4.0 / grid.cell))
    if grid.layers is not None:
        return _plan_layered(grid.layers, start, goal, snap)
    pts = find_path(grid, start[:2], goal[:2], snap=snap)
    return [(float(x), float(z)) for x, z in pts[1:]]


def _plan_layered(grid: NavGrid, start: tuple[float, ...], goal: tuple[float, ...], snap: int) -> list[tuple[float, float]]:
    """plan_path on a layered grid: A* across levels, then within each stretch on one
    level the corners the grid's line of sight lets it cut."""
    from ...nav.path import astar_layered, grid_line_of_sight

    valid, height = grid.layered("valid"), grid.layered("height")
    ends = []
    for p in (start, goal):
        y = float(p[2]) if len(p) > 2 and p[2] is not None and math.isfinite(p[2]) else None
        n = nearest_valid_node3(valid, height, grid.node_of(p[0], p[1]), y, snap)
        if n is None:
            return []
        ends.append(n)
    nodes = astar_layered(grid, ends[0], ends[1])
    if not nodes:
        return []
    kept = [nodes[0]]
    for k in range(1, len(nodes) - 1):
        a, b = kept[-1], nodes[k + 1]
        if a[0] == b[0] == nodes[k][0] and grid_line_of_sight(grid, a[1:], b[1:], valid[a[0]]):
            continue
        kept.append(nodes[k])
    kept.append(nodes[-1])
    out = [grid.centre(i, j) for _, i, j in kept[1:-1]]
    return [(float(x), float(z)) for x, z in out] + [(float(goal[0]), float(goal[1]))]


def _wall_visibility(p: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """(n, n) line of sight between points: no wall crosses the segment (the test of
    ``perception.can_see``, for all pairs at once)."""
    n = len(p)
    seg = np.asarray(segments, dtype=np.float64).reshape(-1, 2, 2)
    w0, e = seg[:, 0], seg[:, 1] - seg[:, 0]
    vis = np.zeros((n, n), dtype=bool)
    for a in range(n):
        r = p - p[a]                                      # (n, 2)
        q = w0 - p[a]                                     # (m, 2)
        den = r[:, None, 0] * e[None, :, 1] - r[:, None, 1] * e[None, :, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (q[None, :, 0] * e[None, :, 1] - q[None, :, 1] * e[None, :, 0]) / den
            u = (q[None, :, 0] * r[:, None, 1] - q[None, :, 1] * r[:, None, 0]) / den
        cross = (den != 0.0) & (s >= 0.0) & (s <= 1.0) & (u >= 0.0) & (u <= 1.0)
        vis[a] = ~cross.any(axis=1)
    return vis


# ------------------------------------------------------------------ what was seen
class Views:
    """The static half of the sight memory: the agent's grid cut into square *blocks*
    (``block`` metres; coarser in big arenas, so there are at most ``max_blocks``), one
    representative point per block (its valid node nearest the block's centre), the
    line of sight between every two representatives (no wall crossing the segment:
    the same test as ``perception.can_see``, for all pairs at once), their distances,
    and which blocks touch (a valid node of one 4-adjacent to a valid node of the other).
    Built once per (walls, grid) and cached: it is the map, not anything seen.

    On a layered grid (``grid.layers``) a block is a square *on one level* (the deck
    and the passage under it are two), its point stands at eye height over its node,
    lines of sight run in 3D through the model's solid (``solids``: a
    ``sim.ground.SolidField``) and blocks touch along the grid's links.
    """

    def __init__(self, grid: NavGrid, segments: np.ndarray, block: float = 4.0, max_blocks: int = 700,
                 solids=None) -> None:
        layers = grid.layers
        base = layers if layers is not None else grid
        valid = np.asarray(base.layered("valid"), dtype=bool)   # (L, nz, nx): L = 1 on a flat grid
        L, nz, nx = valid.shape
        k = max(int(round(block / grid.cell)), 1)
        while True:
            bz, bx = -(-nz // k), -(-nx // k)
            pad = np.zeros((L, bz * k, bx * k), dtype=bool)
            pad[:, :nz, :nx] = valid
            has = pad.reshape(L, bz, k, bx, k).any(axis=(2, 4))
            if has.sum() <= max_blocks:
                break
            k += 1
        self.k = k
        self.grid = grid
        self.layers = layers
        self.shape = (bz, bx)
        height = base.layered("height") if layers is not None else None
        pts, nodes, ys = [], [], []
        index = np.full((L, bz, bx), -1, dtype=np.int64)     # block -> cell number
        for lv, bi, bj in zip(*np.nonzero(has)):
            sub = valid[lv, bi * k:(bi + 1) * k, bj * k:(bj + 1) * k]
            ii, jj = np.nonzero(sub)
            c = 0.5 * (k - 1)
            m = int(np.argmin((ii - c) ** 2 + (jj - c) ** 2))
            n = (int(bi * k + ii[m]), int(bj * k + jj[m]))
            index[lv, bi, bj] = len(pts)
            nodes.append(n if layers is None else (int(lv), *n))
            pts.append(grid.centre(*n))
            ys.append(float(height[lv][n]) if height is not None else 0.0)
        self.index = index if layers is not None else index[0]
        self.nodes = nodes
        self.points = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
        self.heights = np.asarray(ys, dtype=np.float64)       # surface height of each point (0 when flat)
        n = len(pts)
        p = self.points
        self.distance = np.hypot(p[:, None, 0] - p[None, :, 0], p[:, None, 1] - p[None, :, 1])
        if solids is not None:
            # in 3D, eye to eye against the model's solid (hills and decks hide)
            self.visible = solids.visible(np.column_stack([p[:, 0], self.heights + EYE, p[:, 1]]), VIEW_RANGE)
        else:
            self.visible = _wall_visibility(p, segments)
        # neighbouring blocks (path distances between blocks go through these)
        cell_of = np.full(valid.shape, -1, dtype=np.int64)
        li, ii, jj = np.nonzero(valid)
        cell_of[li, ii, jj] = index[li, ii // k, jj // k]
        pairs = set()
        if layers is None:
            c2 = cell_of[0]
            for a, b in ((c2[:, :-1], c2[:, 1:]), (c2[:-1, :], c2[1:, :])):
                m = (a >= 0) & (b >= 0) & (a != b)
                pairs.update(zip(a[m].tolist(), b[m].tolist()))
        else:
            link = base.links()
            a = cell_of[li, ii, jj]
            for d, (di, dj) in enumerate(STEP_LIST):
                tl = link[li, ii, jj, d].astype(np.int64)
                ti, tj = ii + di, jj + dj
                ok = (tl >= 0) & (ti >= 0) & (ti < nz) & (tj >= 0) & (tj < nx)
                b = np.full(len(a), -1, dtype=np.int64)
                b[ok] = cell_of[tl[ok], ti[ok], tj[ok]]
                m = (b >= 0) & (a != b)
                pairs.update(zip(a[m].tolist(), b[m].tolist()))
        self.cell_of = cell_of if layers is not None else cell_of[0]
        self._height = height
        self.neighbours: list[list[tuple[int, float]]] = [[] for _ in range(n)]
        for a, b in pairs:
            if a < b or (b, a) not in pairs:
                d = float(self.distance[a, b])
                self.neighbours[a].append((b, d))
                self.neighbours[b].append((a, d))

    def __len__(self) -> int:
        return len(self.points)

    def cell_at(self, x: float, z: float, y: float | None = None) -> int:
        """The block cell holding (x, z) (on a layered grid: the level nearest height
        ``y``, the lowest when None), or the one of the nearest valid node; -1 if none."""
        if self.layers is None:
            n = self.grid.node_of(x, z)
            c = int(self.cell_of[n])
            if c >= 0:
                return c
            m = nearest_valid_node(self.grid.valid, n, 6)
            return int(self.cell_of[m]) if m is not None else -1
        lay = self.layers
        i, j = lay.node_of(x, z)
        best, best_d = -1, math.inf
        for lv in range(self.cell_of.shape[0]):    # the node under (x, z) on each level
            c = int(self.cell_of[lv, i, j])
            if c >= 0:
                d = 0.0 if y is None else abs(float(self._height[lv, i, j]) - y)
                if d < best_d:
                    best, best_d = c, d
        if best >= 0:
            return best
        m3 = nearest_valid_node3(lay.layered("valid"), self._height, (i, j), y, 6)
        return int(self.cell_of[m3]) if m3 is not None else -1

    def path_distances(self, start: int) -> np.ndarray:
        """Dijkstra over touching blocks: metres from ``start`` to every block (inf: unreachable)."""
        import heapq

        dist = [math.inf] * len(self.points)
        if not 0 <= start < len(dist):
            return np.asarray(dist)  # not on the map (no valid node near): nothing reachable
        dist[start] = 0.0
        heap = [(0.0, start)]
        nb = self.neighbours
        while heap:
            d, a = heapq.heappop(heap)
            if d > dist[a]:
                continue
            for b, w in nb[a]:
                nd = d + w
                if nd < dist[b]:
                    dist[b] = nd
                    heapq.heappush(heap, (nd, b))
        return np.asarray(dist)


_VIEWS: dict[tuple, Views] = {}


def views_for(world: "World", grid: NavGrid) -> Views:
    """The :class:`Views` of this arena and grid (cached by the walls' content)."""
    seg = np.asarray(world.walls.segments, dtype=np.float64)
    valid = grid.layers.valid if grid.layers is not None else grid.valid
    key = (hash(seg.tobytes()), hash(np.asarray(valid).tobytes()), float(grid.cell),
           tuple(np.asarray(grid.origin, dtype=np.float64).tolist()), id(world.ground))
    v = _VIEWS.get(key)
    if v is None:
        if len(_VIEWS) >= 8:
            _VIEWS.pop(next(iter(_VIEWS)))
        solids = world.ground.solids if grid.layers is not None and world.ground is not None else None
        v = _VIEWS[key] = Views(grid, seg, max_blocks=VIEW_BLOCKS if solids is not None else 700, solids=solids)
    return v


class Coverage:
    """When each block was last in the agent's sight: the dynamic half of the sight
    memory, and the exploration it drives.

    ``look`` marks the blocks whose representative lies in the vision cone (from the
    agent's own position), within the vision range and in line of sight of the agent's
    block (``Views.visible``), plus the block it stands in.  A block's *staleness* is the
    time since it was last seen over ``forget`` seconds, capped at 1: an enemy who moves
    may be anywhere not watched lately.  ``goal`` is the exploration target: the block
    that sees the most staleness (summed over the blocks in sight of it, within the
    vision range) per metre of path to it, path distances along touching blocks.
    """

    def __init__(self, views: Views, half_angle: float, vision_range: float, forget: float = 90.0,
                 fresh: float = 60.0) -> None:
        self.views = views
        self.half_angle = half_angle
        self.vision_range = vision_range
        self.forget = forget
        self.fresh = fresh
        self.seen = np.full(len(views), -math.inf)
        self.sees = (views.visible & (views.distance <= vision_range)).astype(np.float64)

    def look(self, x: float, z: float, heading: float, t: float, y: float | None = None) -> None:
        v = self.views
        c = v.cell_at(x, z, y)
        if c < 0:
            return
        self.seen[c] = t
        cand = np.flatnonzero(self.sees[c])
        if len(cand) == 0:
            return
        p = v.points[cand]
        dx, dz = p[:, 0] - x, p[:, 1] - z
        ang = np.abs(np.remainder(np.arctan2(dz, dx) - heading + math.pi, 2.0 * math.pi) - math.pi)
        near = dx * dx + dz * dz < (0.75 * v.k * v.grid.cell) ** 2
        self.seen[cand[(ang <= self.half_angle) | near]] = t

    def staleness(self, t: float) -> np.ndarray:
        age = t - self.seen
        return np.where(age < self.fresh, 0.0, np.minimum(age / self.forget, 1.0))

    def stale_fraction(self, t: float) -> float:
        """The fraction of the blocks not seen for ``fresh`` seconds (or never)."""
        return float(np.mean(t - self.seen >= self.fresh))

    def since(self, x: float, z: float, t: float, y: float | None = None) -> float:
        """Seconds since the block of (x, z) was seen (inf: never)."""
        c = self.views.cell_at(x, z, y)
        return t - self.seen[c] if c >= 0 else math.inf

    def gain(self, cell: int, t: float) -> float:
        """The staleness in sight of ``cell``."""
        return float(self.sees[cell] @ self.staleness(t))

    def goal(self, x: float, z: float, t: float, weight: np.ndarray | None = None,
             least: float = 1.0, d0: float = 60.0, y: float | None = None) -> tuple[int, float] | None:
        """(block, its gain) of the best block to go and look from; None when nothing in
        sight of any reachable block has at least ``least`` staleness.  The score is the
        gain over (path metres + ``d0``): a large ``d0`` favours the blocks that see much
        over the ones near by (against the roaming baseline in the maze, 60 m left 30 %
        of duels without a meeting where 10 m left 36 %).  ``weight`` multiplies each
        block's staleness (a prior of where enemies are likely)."""
        v = self.views
        c = v.cell_at(x, z, y)
        if c < 0:
            return None
        s = self.staleness(t)
        if weight is not None:
            s = s * weight
        gain = self.sees @ s
        dist = v.path_distances(c)
        score = np.where(np.isfinite(dist) & (gain >= least), gain / (dist + d0), -1.0)
        score[c] = -1.0
        best = int(np.argmax(score))
        if score[best] <= 0.0:
            return None
        return best, float(gain[best])


class Vantages:
    """Where to watch from: for every block and each of ``headings`` ways to face, the
    fraction of the arena's blocks in the vision cone from there (within the vision
    range, in line of sight: ``Views.visible``; its own block counts).  The cone is
    taken ``margin`` narrower than the agent's, so a block on its edge is still seen
    while it sweeps.

    Also each block's *safety*: of the blocks that can see it (line of sight, any
    range), the fraction inside its cone facing its safest way, within the vision
    range.  1 at a dead end or a corner facing out: nobody can look at a tank there
    without it looking back.  Static: the map, built once per (views, cone) and cached.
    """

    def __init__(self, views: Views, half_angle: float, vision_range: float, headings: int = 24,
                 margin: float = 0.1) -> None:
        self.views = views
        p = views.points
        bearing = np.arctan2(p[None, :, 1] - p[:, None, 1], p[None, :, 0] - p[:, None, 0])
        sees = views.visible & (views.distance <= vision_range)
        seen_by = np.maximum(views.visible.sum(axis=1), 1)
        self.headings = np.arange(headings) * (2.0 * math.pi / headings)
        self.cover = np.empty((len(p), headings))
        safety = np.empty((len(p), headings))
        for k, h in enumerate(self.headings):
            inside = np.abs(np.remainder(bearing - h + math.pi, 2.0 * math.pi) - math.pi) <= half_angle - margin
            np.fill_diagonal(inside, True)         # the block it stands in
            in_cone = (sees & inside).sum(axis=1)
            self.cover[:, k] = in_cone / max(len(p), 1)
            safety[:, k] = in_cone / seen_by
        self.safety = safety.max(axis=1) if safety.size else np.zeros(len(p))
        self.safe_face = self.headings[safety.argmax(axis=1)] if safety.size else np.zeros(len(p))
        # each block's cover facing its best way, and that way
        self.block_cover = self.cover.max(axis=1) if self.cover.size else np.zeros(len(p))
        self.block_face = self.headings[self.cover.argmax(axis=1)] if self.cover.size else np.zeros(len(p))
        self.top = float(self.block_cover.max()) if len(p) else 0.0

    def best(self, here: int, per_m: float) -> tuple[int, float]:
        """(block, heading) of the best vantage from block ``here``: the most cover less
        ``per_m`` per metre of path to it; unreachable blocks never (-1: ``here`` is
        no block)."""
        if here < 0 or len(self.views) == 0:
            return -1, 0.0                    # not on the map: nowhere to go
        score = self.block_cover - per_m * self.views.path_distances(here)    # unreachable: -inf
        b = int(np.argmax(score))
        return b, float(self.block_face[b])

    def safest(self, here: int, per_m: float, away: int = -1, per_m_away: float = 0.0,
               cap: float = 80.0) -> tuple[int, float]:
        """(block, heading) of the best hiding place from block ``here``: the most safety
        less ``per_m`` per metre of path to it, plus ``per_m_away`` per metre of path
        (up to ``cap``) from block ``away`` (where an enemy was heard; -1: none)."""
        if here < 0 or len(self.views) == 0:
            return -1, 0.0
        score = self.safety - per_m * self.views.path_distances(here)
        if away >= 0:
            d = self.views.path_distances(away)
            score = score + per_m_away * np.minimum(d, cap)        # unreachable from there: cap
        b = int(np.argmax(score))
        return b, float(self.safe_face[b])


_VANTAGES: dict[tuple, Vantages] = {}


def vantages_for(views: Views, half_angle: float, vision_range: float) -> Vantages:
    """The :class:`Vantages` of these views and this cone (cached)."""
    key = (id(views), round(half_angle, 9), round(vision_range, 6))
    v = _VANTAGES.get(key)
    if v is None or v.views is not views:
        if len(_VANTAGES) >= 16:
            _VANTAGES.pop(next(iter(_VANTAGES)))
        v = _VANTAGES[key] = Vantages(views, half_angle, vision_range)
    return v
