"""The agents' grid on an arena with relief or levels, from the simulation's ground.

On a flat arena an agent's grid comes from the walls (``navigation.agent_grid``).  On
a ground (``sim.ground.Ground``: the walkable surface at 0.5 m with each node's
height and links) the walls alone say nothing of a deck's edge or a slope too steep,
so the agent grid is made from the surface itself:

* **clearance**: for every node of the surface, the chamfer distance along its links
  to the nearest edge of walkable space (a side without a link: a wall's foot, a
  drop-off, a slope too steep), so a node under a bridge is measured on its own floor;
  a node is *valid* for an agent when that distance is at least its clearance;
* **coarse nodes** every ``k`` surface cells (the agent's cell, 1 m by default),
  each at the centre of a surface node, on that node's level and height;
* **links** between coarse neighbours: the ``k`` surface steps between their centres
  followed link by link, every one on a valid node (so a coarse link never cuts a
  corner of a wall nor jumps a drop); the level it arrives on is the link's level;
* **reachable**: the valid nodes joined by links to a spawn.

The result is a layered ``NavGrid`` (``(L, nz, nx)`` arrays, ``height``, ``link``):
``nav.path.astar_layered`` plans on it across ramps, steps and decks, and the Wander
heuristic walks it along its links (``navigation.Wanderer``).  The agents' 2-D views of
the map (where it has been, the quadrants' leaves) read its projection: a column is
valid when any of its levels is.
"""

from __future__ import annotations

import math
import weakref
from typing import TYPE_CHECKING

import numpy as np

from ...nav.navgrid import NavGrid, layered_labels, layered_reachable, layered_runs, nearest_valid_node3, runs
from ...nav.walkable import CELL_HEIGHT, chamfer_clearance

if TYPE_CHECKING:  # pragma: no cover
    from ..ground import Ground

#: steps (di, dj) of the links +x, +z, -x, -z
_STEPS = ((0, 1), (1, 0), (0, -1), (-1, 0))
#: the direction back
_BACK = (2, 3, 0, 1)


def surface_clearance(ground: "Ground", limit: float) -> np.ndarray:
    """(L, nz, nx) metres from each surface node's centre to the nearest edge of the
    walkable surface along its links (capped a little above ``limit``; NaN off the
    surface)."""
    half = 0.5 * ground.cell
    dist = _grid_chamfer(ground, limit)
    if dist is not None:
        return np.where(ground.exists, dist * half, np.nan)
    return _compact_clearance(ground, limit)


#: the last clear_enough mask by ground (an agent asks for its grid at two grades with
#: one clearance: 2.7 s a time on a 2 km terrain)
_LAST_CLEAR: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def clear_enough(ground: "Ground", clearance: float) -> np.ndarray:
    """(L, nz, nx) bool: ``surface_clearance(ground, clearance) >= clearance``, without
    its float64 grid where the kernel runs (from int32 distances, a million at a time).
    The last mask of each ground is kept (read only)."""
    try:
        last = _LAST_CLEAR.get(ground)
    except TypeError:   # not weakly referable (a stand-in ground): no cache
        return _clear_enough(ground, clearance)
    if last is not None and last[0] == float(clearance) and last[1] is ground.link:
        return last[2]
    out = _clear_enough(ground, clearance)
    out.flags.writeable = False
    _LAST_CLEAR[ground] = (float(clearance), ground.link, out)
    return out


def _clear_enough(ground: "Ground", clearance: float) -> np.ndarray:
    dist = _grid_chamfer(ground, clearance)
    if dist is None:
        return np.nan_to_num(_compact_clearance(ground, clearance), nan=-1.0) >= clearance
    half = 0.5 * ground.cell
    out = np.empty(dist.shape, dtype=bool)
    flat, done, ex = dist.reshape(-1), out.reshape(-1), ground.exists.reshape(-1)
    for a in range(0, len(flat), 1 << 20):   # the same float64 products, a million at a time
        b = a + (1 << 20)
        np.greater_equal(flat[a:b] * half, clearance, out=done[a:b])
        done[a:b] &= ex[a:b]
    return out


def _grid_chamfer(ground: "Ground", limit: float) -> np.ndarray | None:
    """(L, nz, nx) int32 chamfer distances (half cells) by the compiled kernel on the
    ground's own int8 links (4 bytes a grid node; the compact graph below took 16 a node
    and int64 temporaries), or None without the kernel."""
    from ...geometry.kernels import active

    kern = active()
    fn = getattr(kern, "chamfer_grid", None)
    if fn is None:
        return None
    L, nz, nx = ground.exists.shape
    dist = np.empty((L, nz, nx), dtype=np.int32)
    link = np.ascontiguousarray(ground.link, dtype=np.int8)
    exists = np.ascontiguousarray(ground.exists).view(np.uint8)
    fn(link, exists, dist, L, nz, nx, _steps(ground, limit))
    return dist


def _steps(ground: "Ground", limit: float) -> int:
    return int(math.ceil(limit / (0.5 * ground.cell))) + 2


def _compact_clearance(ground: "Ground", limit: float) -> np.ndarray:
    """surface_clearance in numpy: the surface as a compact graph for ``chamfer_clearance``."""
    exists = ground.exists
    L, nz, nx = exists.shape
    per = nz * nx
    node = np.flatnonzero(exists)
    compact = np.full(L * per + 1, -1, dtype=np.int64)   # flat node -> surface index; last: none
    compact[node] = np.arange(len(node))
    lv, rest = np.divmod(node, per)
    i, j = np.divmod(rest, nx)
    link = ground.link.reshape(L * per, 4)[node].astype(np.int64)
    nb = np.full((len(node), 4), -1, dtype=np.int64)
    for d, (di, dj) in enumerate(_STEPS):
        a, b = i + di, j + dj
        ok = (link[:, d] >= 0) & (a >= 0) & (a < nz) & (b >= 0) & (b < nx)
        target = np.where(ok, link[:, d] * per + np.clip(a, 0, nz - 1) * nx + np.clip(b, 0, nx - 1), L * per)
        nb[:, d] = compact[target]
    half = 0.5 * ground.cell
    steps = _steps(ground, limit)
    out = np.full(L * per, np.nan)
    out[node] = chamfer_clearance(nb, steps) * half
    return out.reshape(L, nz, nx)


#: rows of the agent grid walked at a time: the walks' int32 temporaries are a band's
WALK_BAND = 256
#: the last walk of each ground (an agent asks for its grid at two grades: one walk)
_LAST_WALK: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _walked(ground: "Ground", clearance: float, ok_fine: np.ndarray, ii: np.ndarray, jj: np.ndarray,
            k: int, remember: bool = True) -> np.ndarray:
    """(L, NZ, NX, 4) int8: the level each coarse node (ii, jj) arrives on after ``k``
    surface steps in each direction, every one on an ``ok_fine`` node (-1: none); the
    last of each ground kept (read only; ``remember`` False: neither read nor kept)."""
    key = (clearance, k, len(ii), len(jj))
    try:
        last = _LAST_WALK.get(ground) if remember else None
    except TypeError:   # not weakly referable (a stand-in ground): no cache
        last = None
    if last is not None and last[0] == key and last[1] is ground.link:
        return last[2]
    L, nz, nx = ok_fine.shape
    out = np.full((L, len(ii), len(jj), 4), -1, dtype=np.int8)
    from ...geometry.kernels import active

    kern = active()
    if getattr(kern, "grid_walk", None) is not None:   # one pass, no temporaries (2 km: 3 s -> 0.1 s)
        kern.grid_walk(np.ascontiguousarray(ground.link, dtype=np.int8),
                       np.ascontiguousarray(ok_fine, dtype=bool).view(np.uint8),
                       np.ascontiguousarray(ii, dtype=np.int32), np.ascontiguousarray(jj, dtype=np.int32), out,
                       L, nz, nx, k)
    else:
        for r0 in range(0, len(ii), WALK_BAND):   # rows are walked independently
            rows = ii[r0:r0 + WALK_BAND]
            out[:, r0:r0 + len(rows)] = _walk_band(ground.link, ok_fine, rows, jj, k)
    out.flags.writeable = False
    if not remember:
        return out
    try:
        _LAST_WALK[ground] = (key, ground.link, out)
    except TypeError:
        pass
    return out


def _walk_band(fl: np.ndarray, ok_fine: np.ndarray, rows: np.ndarray, jj: np.ndarray, k: int) -> np.ndarray:
    """_walked for coarse nodes on surface rows ``rows``: (L, len(rows), len(jj), 4)."""
    L, nz, nx = ok_fine.shape
    valid = ok_fine[:, rows][:, :, jj]
    out = np.empty(valid.shape + (4,), dtype=np.int8)
    lvl = np.broadcast_to(np.arange(L, dtype=np.int32)[:, None, None], valid.shape)
    I = np.broadcast_to(rows[None, :, None], valid.shape)
    J = np.broadcast_to(jj[None, None, :], valid.shape)
    for d, (di, dj) in enumerate(_STEPS):
        cur, ci, cj = lvl.copy(), I.copy(), J.copy()
        alive = valid.copy()
        for _ in range(k):
            ni, nj = ci + di, cj + dj
            inside = (ni >= 0) & (ni < nz) & (nj >= 0) & (nj < nx)
            alive &= inside
            nxt = np.where(alive, fl[np.where(alive, cur, 0), np.clip(ci, 0, nz - 1), np.clip(cj, 0, nx - 1), d], -1)
            alive &= nxt >= 0
            ci, cj = np.clip(ni, 0, nz - 1), np.clip(nj, 0, nx - 1)
            cur = np.where(alive, nxt, 0)
            alive &= ok_fine[cur, ci, cj]
        out[..., d] = np.where(alive, cur, -1)
    return out


def _cut_grade(link: np.ndarray, heights: np.ndarray, most: float, uphill_only: bool = False) -> None:
    """Cut (in place) the coarse links rising or falling more than ``most`` metres,
    a band of rows at a time (in C where it is built: one pass); ``uphill_only``: only
    those rising more (a way down a slope it cannot drive back up is kept one way)."""
    L, NZ, NX = heights.shape
    from ...geometry.kernels import active

    kern = active()
    if not uphill_only and getattr(kern, "grade_cut", None) is not None and link.flags.c_contiguous \
            and link.dtype == np.int8:
        kern.grade_cut(link, np.ascontiguousarray(heights, dtype=np.float64), L, NZ, NX, float(most))
        return
    for r0 in range(0, NZ, WALK_BAND):
        r1 = min(r0 + WALK_BAND, NZ)
        here = heights[:, r0:r1]
        for d, (di, dj) in enumerate(_STEPS):
            to = link[:, r0:r1, :, d]
            alive = to >= 0
            cur = np.where(alive, to, 0)
            ti = np.broadcast_to(np.clip(np.arange(r0, r1)[None, :, None] + di, 0, NZ - 1), cur.shape)
            tj = np.broadcast_to(np.clip(np.arange(NX)[None, None, :] + dj, 0, NX - 1), cur.shape)
            rise = heights[cur, ti, tj] - here
            alive &= ~((rise if uphill_only else np.abs(rise)) > most)
            link[:, r0:r1, :, d] = np.where(alive, cur, -1)


def ground_agent_grid(ground: "Ground", cell: float, clearance: float, spawns: list,
                      grade: float = math.inf, narrow: float | None = None, one_way: bool = False) -> NavGrid:
    """The projection grid (one level, see the module docstring) of the layered agent grid,
    which it carries as ``.layers``; ``spawns`` are (x, z, y or None).  ``grade``: a
    link rising or falling more than this per metre is cut both ways (a slope the
    vehicle cannot drive back up: the light tank climbs an 18 degree ramp at 0.25 m/s,
    and a tank gone down one stays down for the rest of a duel); ``one_way``: only
    rising (the way down kept, one way).  ``narrow``: the clearance of a tank driven
    straight (its half width plus a margin): where the grid at ``clearance`` leaves the
    spawns in parts apart, straight runs at least ``narrow`` from the edges that join
    two parts are added (``_narrow_joins``: a deck or ramp narrower than the tank's
    footprint circle but wider than its hull)."""
    fine = ground.cell
    k = max(int(round(cell / fine)), 1)
    ok_fine = clear_enough(ground, clearance)
    L, nz, nx = ok_fine.shape
    off = k // 2
    NZ, NX = max((nz - off - 1) // k + 1, 1), max((nx - off - 1) // k + 1, 1)
    # int32 node indices: the walks below hold several whole coarse grids of them
    ii = (off + k * np.arange(NZ)).astype(np.int32)
    jj = (off + k * np.arange(NX)).astype(np.int32)
    valid = ok_fine[:, ii][:, :, jj]
    heights = ground.h[:, ii][:, :, jj]
    link = _walked(ground, float(clearance), ok_fine, ii, jj, k).copy()
    walked = link.copy() if one_way and math.isfinite(grade) else None
    # heights come in voxel steps (CELL_HEIGHT): one step of slack, or a ramp just
    # under the grade is cut where its steps fall unevenly
    most = grade * k * fine + CELL_HEIGHT
    if math.isfinite(grade):
        _cut_grade(link, heights, most)
    # coarse node (I, J) sits at the centre of surface node (off + k I, off + k J)
    step = k * fine
    origin = np.array([ground.ox + (off + 0.5) * fine - 0.5 * step, ground.oz + (off + 0.5) * fine - 0.5 * step])
    seeds = []
    for x, z, y in spawns:
        node = (int(np.clip((z - origin[1]) // step, 0, NZ - 1)), int(np.clip((x - origin[0]) // step, 0, NX - 1)))
        n = nearest_valid_node3(valid, heights, node, y, int(math.ceil(clearance / step)) + 2)
        if n is not None:
            seeds.append(n)
    if narrow is not None and narrow < clearance and len(seeds) > 1:
        joins = _narrow_joins(ground, valid, link, heights, (ii, jj, k), float(clearance), float(narrow), seeds, most)
        if joins is not None:
            valid = valid | joins[0]
            link = np.where(link >= 0, link, joins[1])
            if walked is not None:
                walked = np.where(walked >= 0, walked, joins[1])
    if walked is not None:
        link = walked
        _cut_grade(link, heights, most, uphill_only=True)
    reach = layered_reachable(valid, link, seeds) if seeds else valid.copy()
    valid = valid & reach
    link = np.where(valid[..., None], link, -1).astype(np.int8)
    layered = GroundGrid(origin, step, (NZ, NX), valid, None, None, None, None, valid.copy(), float(clearance),
                         height=np.where(valid, heights, np.nan), link=link)
    layered.spawn_nodes = seeds
    proj = valid.any(axis=0)[None]
    grid = GroundGrid(origin, step, (NZ, NX), proj, None, None, None, None, proj.copy(), float(clearance),
                      spawn_nodes=[(0, *n[1:]) for n in seeds])
    grid.layers = layered
    return grid


def _labels(valid: np.ndarray, link: np.ndarray) -> np.ndarray:
    """Components of a layered grid's valid nodes over its links (either way): int32
    labels, 0 off the valid nodes (``navgrid.layered_labels``)."""
    return layered_labels(valid, np.ascontiguousarray(link, dtype=np.int8))[0]


def _target_index(values: np.ndarray, link: np.ndarray, d: int) -> np.ndarray:
    """``values`` at the node each link of direction ``d`` reaches (at the node itself
    where there is no link)."""
    L, nz, nx = values.shape
    di, dj = _STEPS[d]
    lv = link[..., d].astype(np.intp)
    here = lv < 0
    i = np.clip(np.arange(nz)[None, :, None] + di, 0, nz - 1)
    j = np.clip(np.arange(nx)[None, None, :] + dj, 0, nx - 1)
    I = np.where(here, np.arange(nz)[None, :, None], i)
    J = np.where(here, np.arange(nx)[None, None, :], j)
    return values[np.where(here, np.arange(L)[:, None, None], lv), I, J]


def _target(mask: np.ndarray, link: np.ndarray, d: int) -> np.ndarray:
    """Whether the link of direction ``d`` exists and reaches a node of ``mask``."""
    return (link[..., d] >= 0) & _target_index(mask, link, d)


def _narrow_joins(ground: "Ground", valid: np.ndarray, link: np.ndarray, heights: np.ndarray, coarse: tuple,
                  clearance: float, narrow: float, seeds: list, most: float) -> tuple[np.ndarray, np.ndarray] | None:
    """(nodes, links) to add to an agent grid whose spawns are in parts apart: straight
    runs of nodes ``narrow`` m from the edges, along one axis, where the tank driven
    along that axis has ``clearance`` m of way before and behind (its hull fits, not
    its turning circle: it turns on the parts' nodes, a step ahead or aside), that
    meet two different parts -- a deck or ramp barely wider than the hull (tools/make_levels.py's
    bridge: 8 m, 3.96 m of footprint clearance from each edge).  Runs that join a part
    to itself (the bands along every edge) are not added: the grid hugs no more edges.
    None when the spawns are in one part."""
    part = _labels(valid, link)
    if len({int(part[s]) for s in seeds}) < 2:
        return None
    ii, jj, k = coarse
    ok_n = _clear_enough(ground, narrow)
    step = _walked(ground, narrow, ok_n, ii, jj, k, remember=False).copy()
    if math.isfinite(most):
        _cut_grade(step, heights, most)
    room = _walked(ground, narrow, ok_n, ii, jj, int(math.ceil(clearance / ground.cell)), remember=False) >= 0
    cand = ok_n[:, ii][:, :, jj] & ~valid
    nodes = np.zeros_like(valid)
    links = np.full(step.shape, -1, dtype=np.int8)
    for axis in ((0, 2), (1, 3)):
        fits = (cand | valid) & room[..., axis[0]] & room[..., axis[1]]
        own = np.full(step.shape, -1, dtype=np.int8)
        run = fits & cand
        # a node a step aside (that way) of a part's
        nears = {d: cand & _target(valid, step, d) for d in range(4) if d not in axis}
        for d in range(4):
            if d in axis:   # along the axis: between two nodes the hull fits along it, one end narrow
                ok = fits & _target(fits, step, d) & (cand | _target(cand, step, d))
            else:           # a step or two aside between a run's node and a part's (it turns there)
                near, back = nears[d], nears[_BACK[d]]
                ok = run & (_target(valid, step, d) | _target(near, step, d))          # run -> part, run -> near
                ok |= near & _target(run, step, _BACK[d])                               # near -> part
                ok |= (valid | back) & _target(run, step, d)                            # part, near -> run
                ok |= valid & _target(back & _target(run, step, d), step, d)            # part -> near
            own[..., d] = np.where(ok, step[..., d], -1)
        along = own.copy()
        along[..., [d for d in range(4) if d not in axis]] = -1
        chain = _labels(cand, _only_between(cand, along))
        pairs = []
        for d in range(4):   # (run, part) where a run meets a part, a step or two aside
            end = cand & _target(valid, own, d)
            pairs.append(np.stack([chain[end], _target_index(part, own, d)[end]], axis=1))
            if d in nears:
                end = cand & ~nears[d] & _target(nears[d], own, d)
                far = np.where(nears[d], _target_index(part, step, d), 0)
                pairs.append(np.stack([chain[end], _target_index(far, own, d)[end]], axis=1))
        pairs_a = np.unique(np.concatenate(pairs), axis=0)
        pairs_a = pairs_a[(pairs_a[:, 0] > 0) & (pairs_a[:, 1] > 0)]
        ids, n = np.unique(pairs_a[:, 0], return_counts=True)
        keep = np.isin(chain, ids[n >= 2]) & cand
        if not keep.any():
            continue
        for d, near in nears.items():   # the steps aside of the runs kept
            keep |= near & _target(keep & fits, own, _BACK[d])
        nodes |= keep
        for d in range(4):
            ok = (own[..., d] >= 0) & (keep | _target(keep, own, d))
            links[..., d] = np.where(ok, own[..., d], links[..., d])
    return (nodes, links) if nodes.any() else None


def _only_between(mask: np.ndarray, link: np.ndarray) -> np.ndarray:
    """``link`` kept only from and to nodes of ``mask``."""
    out = np.full(link.shape, -1, dtype=np.int8)
    for d in range(4):
        out[..., d] = np.where(mask & _target(mask, link, d), link[..., d], -1)
    return out


_RUN_NAMES = ("row_index", "row_total", "col_index", "col_total")


class _RunsOnDemand:
    """One of a GroundGrid's four run arrays, made with the other three on first read."""

    def __set_name__(self, owner: type, name: str) -> None:
        self.k = _RUN_NAMES.index(name)

    def __get__(self, obj: "GroundGrid | None", owner: type | None = None) -> np.ndarray:
        if obj is None:
            return self  # type: ignore[return-value]
        return _runs_of(obj)[self.k]

    def __set__(self, obj: "GroundGrid", value: np.ndarray | None) -> None:
        if value is not None:   # given: this one as given, the others made
            runs_ = list(_runs_of(obj))
            runs_[self.k] = value
            obj.__dict__["_runs"] = tuple(runs_)


def _runs_of(grid: "GroundGrid") -> tuple[np.ndarray, ...]:
    runs_ = grid.__dict__.get("_runs")
    if runs_ is None:
        runs_ = grid.__dict__["_runs"] = grid.make_runs()
    return runs_


class GroundGrid(NavGrid):
    """An agent grid on a ground whose run arrays (``navgrid.runs``: the Wander
    heuristic's nodes ahead) are made on first read, int16 where the grid allows: a
    match reads those of one grid of the four an agent's two grids carry (each four
    int32 arrays a node took 245 MB on a 2 km terrain); the values are the same."""

    row_index = _RunsOnDemand()
    row_total = _RunsOnDemand()
    col_index = _RunsOnDemand()
    col_total = _RunsOnDemand()

    def make_runs(self) -> tuple[np.ndarray, ...]:
        """(row_index, row_total, col_index, col_total) of this grid's valid nodes (and links)."""
        if self.link is not None:
            out = layered_runs(self.valid, self.link)
        else:
            out = tuple(a[None] for a in runs(self.valid[0]))
        small = max(self.valid.shape[1:]) < np.iinfo(np.int16).max
        return tuple(a.astype(np.int16) if small else a for a in out)
