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
from ...nav.steering import children, children3, decide, heading_of_move

if TYPE_CHECKING:  # pragma: no cover
    from ..world import World


_GRIDS: "weakref.WeakKeyDictionary[object, dict[tuple[float, float], NavGrid]]" = weakref.WeakKeyDictionary()


#: an agent grid keeps the asked clearance, else the largest of these fractions of it
#: that leaves valid nodes by a spawn (a corridor or deck barely wider than the tank)
FALLBACK = (0.85, 0.7, 0.55, 0.4, 0.25, 0.0)


def agent_grid(world: "World", cell: float, clearance: float, grade: float = math.inf,
               narrow: float | None = None, one_way: bool = False) -> NavGrid:
    """The navigation grid agents of this clearance use in ``world`` (cached per wall
    set, or per ground on an arena with relief or levels: then a projection carrying
    the layered grid as ``.layers``, see ``agents.layers``).

    Where the clearance leaves no valid node by any spawn (an arena barely wider than
    the tank), the grid is made again with less (``FALLBACK``), down to every node off
    the walls: its ``clearance`` says which it kept.  Agents then plan as close to the
    walls as they must; the physics keeps them out.  ``grade``: on a ground, links
    rising or falling more than this per metre are cut (``layers.ground_agent_grid``),
    only those rising with ``one_way``; ``narrow``: straight runs this far from the
    edges that join parts of the grid apart are added (there too)."""
    per = _GRIDS.setdefault(world.ground if world.ground.relief else world.walls, {})
    relief = world.ground.relief
    grade = float(grade) if relief else math.inf
    key: tuple = (float(cell), float(clearance)) if not math.isfinite(grade) else (float(cell), float(clearance), grade)
    extra = (narrow if relief else None, bool(one_way and relief and math.isfinite(grade)))
    if extra != (None, False):   # the keys of the grids before these options unchanged
        key += extra
    if key not in per:
        grid = None
        for c in (clearance, *(clearance * f for f in FALLBACK)):
            grid = _make_grid(world, cell, c, grade, narrow=extra[0], one_way=extra[1])
            if grid.spawn_nodes and grid.valid.any():
                break
        per[key] = grid
    return per[key]


def strict_grid(world: "World", cell: float, clearance: float) -> NavGrid:
    """The agents' grid of ``world`` at exactly ``clearance`` (no fallback, not cached):
    where a tank of that footprint radius fits (sim/extra_spawns.py)."""
    return _make_grid(world, cell, clearance)


def _make_grid(world: "World", cell: float, clearance: float, grade: float = math.inf,
               narrow: float | None = None, one_way: bool = False) -> NavGrid:
    if world.ground.relief:  # a flat ground: the 2002 grid of the walls
        from .layers import ground_agent_grid

        spawns = [(x, z, y) for (x, z, _), y in zip(world.spawns, world.spawn_y)]
        return ground_agent_grid(world.ground, cell, clearance, spawns, grade, narrow=narrow, one_way=one_way)
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
    grid.spawn_nodes = [(0, *n) for n in seeds]
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
                n = nearest_valid_node(grid.valid[0], grid.node_of(cx, cz), steps)
                if n is not None:
                    gx, gz = grid.centre(*n)
                    if self.key(gx, gz) == key:
                        out.append((key, (gx, gz)))
            self._goals = out
        return self._goals



class Wanderer:
    """The paper's decision among the three nodes ahead, with novelty and jitter.

    ``memory`` None and ``jitter`` 0 give ``nav.steering.choose_next``'s choice.  On a
    ground (an agent grid with ``.layers``) it walks the layered grid itself: nodes are
    ``(level, i, j)`` and each step follows the links (:func:`wander_start` gives the
    first), so a tank under a deck is never sent into a column only the deck has.
    """

    def __init__(self, grid: NavGrid, memory: Memory | None = None, rng: random.Random | None = None,
                 jitter: float = 0.2, cap: int = 12, look: int = 16, forget: float = 60.0,
                 floor: float = 0.08, straight: float = 1.5) -> None:
        self.layers = getattr(grid, "layers", None)
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
        x, z = self.grid.centre(node[-2] + di * k, node[-1] + dj * k)
        return self.floor + min(self.memory.since(x, z, t) / self.forget, 1.0)

    def choose(self, node: Node, heading: str, t: float = 0.0) -> tuple[Node, str] | None:
        """The next node and the heading after moving there; None when boxed in."""
        kids = children(self.grid, node, heading) if self.layers is None else children3(self.layers, node, heading)
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
        from ...nav.steering import choose_next, turn_in_place3

        nxt = choose_next(self.grid, node, heading) if self.layers is None else \
            turn_in_place3(self.layers, node, heading)
        if nxt is None:
            return None
        return nxt, heading_of_move(node[-2:], nxt[-2:], heading)


def wander_start(grid: NavGrid, x: float, z: float, y: float | None, steps: int = 6) -> tuple | None:
    """The wanderer's first node near (x, z): on the 2002 grid the nearest valid node
    (i, j); on a ground's agent grid the layered node (level, i, j) nearest the tank's
    height ``y`` -- its own level, not a deck above it."""
    layers = grid.layers
    if layers is None:
        return nearest_valid_node(grid.valid[0], grid.node_of(x, z), steps)
    if y is None:
        return nearest_valid_node3(layers.valid, layers.height, layers.node_of(x, z), y, steps)
    col, best = layers.node_of(x, z), None
    for lv in range(layers.levels):      # a level within a metre of the tank first, then the nearest node
        n = nearest_valid_node(layers.valid[lv], col, steps)
        if n is None:
            continue
        dy = abs(float(layers.height[lv, n[0], n[1]]) - y)
        key = (not dy <= 1.0, (n[0] - col[0]) ** 2 + (n[1] - col[1]) ** 2, dy)
        if best is None or key < best[0]:
            best = (key, (lv, n[0], n[1]))
    return None if best is None else best[1]


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
    n = nearest_valid_node(grid.valid[0], grid.node_of(cx, cz), steps)
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
    valid, height = grid.valid, grid.height
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
            first3 = nearest_valid_node3(layers.valid, layers.height, layers.node_of(x, z), y,
                                         int(math.ceil(6.0 / grid.cell)))
            if first3 is not None:
                lv, i, j = first3
                self.goals = [(*layers.centre(i, j), float(layers.height[first3]))]
        else:
            first = nearest_valid_node(grid.valid[0], grid.node_of(x, z), int(math.ceil(6.0 / grid.cell)))
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

    valid, height = grid.valid, grid.height
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

