"""The sight memory of an agent: which parts of the arena see which, and what it has
seen lately.

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
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ...nav.navgrid import NavGrid, nearest_valid_node, nearest_valid_node3

if TYPE_CHECKING:  # pragma: no cover
    from ..world import World

#: on a ground, the eye height of a block's point [m], the blocks at most (each line of
#: the sight map is sampled through the model's solid), and how far they look [m]
EYE = 1.2
VIEW_BLOCKS = 450
VIEW_RANGE = 150.0
#: the link steps (di, dj): +x, +z, -x, -z
STEP_LIST = ((0, 1), (1, 0), (0, -1), (-1, 0))


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


def _linked_cells(cell_of: np.ndarray, to: np.ndarray, di: int, dj: int) -> np.ndarray:
    """(nz, nx) the block cell of the node each node's step (di, dj) links to (``to``:
    its level, -1 none), -1 where none or off the grid."""
    L, nz, nx = cell_of.shape
    out = np.full((nz, nx), -1, dtype=np.int32)
    # the nodes whose step stays on the grid, and the nodes they step onto
    src = (slice(max(-di, 0), nz - max(di, 0)), slice(max(-dj, 0), nx - max(dj, 0)))
    dst = (slice(max(di, 0), nz + min(di, 0)), slice(max(dj, 0), nx + min(dj, 0)))
    t, o = to[src], out[src]
    for lv in range(L):
        m = t == lv
        o[m] = cell_of[lv][dst][m]
    return out


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
        valid = np.asarray(base.valid, dtype=bool)   # (L, nz, nx): L = 1 on a flat grid
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
        height = base.height if layers is not None else None
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
        # neighbouring blocks (path distances between blocks go through these); int32
        # and whole levels shifted, not int64 lists of every valid node (+228 MB on a
        # 2 km terrain), the pairs met in the same order
        blown = np.repeat(np.repeat(index.astype(np.int32), k, axis=1), k, axis=2)[:, :nz, :nx]
        cell_of = np.where(valid, blown, np.int32(-1))
        del blown
        pairs: set[tuple[int, int]] = set()
        if layers is None:
            c2 = cell_of[0]
            for a, b in ((c2[:, :-1], c2[:, 1:]), (c2[:-1, :], c2[1:, :])):
                m = (a >= 0) & (b >= 0) & (a != b)
                pairs.update(zip(a[m].tolist(), b[m].tolist()))
        else:
            link = base.links()
            for d, (di, dj) in enumerate(STEP_LIST):
                for lv in range(L):
                    a, b = cell_of[lv], _linked_cells(cell_of, link[lv, :, :, d], di, dj)
                    m = valid[lv] & (b >= 0) & (a != b)
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
            m = nearest_valid_node(self.grid.valid[0], n, 6)
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
        m3 = nearest_valid_node3(lay.valid, self._height, (i, j), y, 6)
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


_VIEWS: dict[tuple, tuple[Any, Views]] = {}


def views_for(world: "World", grid: NavGrid) -> Views:
    """The :class:`Views` of this arena and grid (cached by the walls' content)."""
    seg = np.asarray(world.walls.segments, dtype=np.float64)
    valid = grid.layers.valid if grid.layers is not None else grid.valid
    key = (hash(seg.tobytes()), hash(np.asarray(valid).tobytes()), float(grid.cell),
           tuple(np.asarray(grid.origin, dtype=np.float64).tolist()), id(world.ground))
    hit = _VIEWS.get(key)
    # the entry holds the ground it was made for: while it is cached its id() cannot
    # be reused by another world's ground (a later match in the same process)
    if hit is not None and hit[0] is world.ground:
        return hit[1]
    if len(_VIEWS) >= 8:
        _VIEWS.pop(next(iter(_VIEWS)))
    solids = world.ground.solids if grid.layers is not None else None
    v = Views(grid, seg, max_blocks=VIEW_BLOCKS if solids is not None else 700, solids=solids)
    _VIEWS[key] = (world.ground, v)
    return v


#: the exploration's weight of a block never seen (one not seen for ``forget`` s: 1)
NEVER_SEEN = 3.0


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

    def look(self, x: float, z: float, heading: float, t: float, y: float | None = None) -> np.ndarray:
        """Mark the blocks in sight now as seen at ``t``; returns them (the block it
        stands in first)."""
        v = self.views
        c = v.cell_at(x, z, y)
        if c < 0:
            return np.zeros(0, dtype=np.int64)
        self.seen[c] = t
        cand = np.flatnonzero(self.sees[c])
        if len(cand) == 0:
            return np.array([c], dtype=np.int64)
        p = v.points[cand]
        dx, dz = p[:, 0] - x, p[:, 1] - z
        ang = np.abs(np.remainder(np.arctan2(dz, dx) - heading + math.pi, 2.0 * math.pi) - math.pi)
        near = dx * dx + dz * dz < (0.75 * v.k * v.grid.cell) ** 2
        cells = cand[(ang <= self.half_angle) | near]
        self.seen[cells] = t
        return np.concatenate(([c], cells))

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

    def worth(self, t: float) -> np.ndarray:
        """Each block's worth to go and look at: its staleness, and ``NEVER_SEEN`` for a
        block never looked at.  Everything is looked at once before the rounds begin
        again: in 120 s duels in the maze, with staleness alone, a fifth of the blocks
        were never looked at (a camper in one of them never found) while the big
        stretches seen in the first minute drew the agent back in the second."""
        return np.where(np.isinf(self.seen), NEVER_SEEN, self.staleness(t))

    def gain(self, cell: int, t: float) -> float:
        """The worth (``worth``) in sight of ``cell``."""
        return float(self.sees[cell] @ self.worth(t))

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
        s = self.worth(t)
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
