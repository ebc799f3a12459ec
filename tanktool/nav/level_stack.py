"""Levels of the played region's spans: stacked per column, then settled by votes.

:func:`stack_levels` is the last step of :func:`tanktool.nav.walkable.build_surface`:
a span's level is first the number of kept spans below it in its column, then spans
at a level's border move, round by round, to the level most of their neighbours are
on (where it is free in their column), and last the top of a ramp onto a deck over
walkable ground joins the deck's level (:mod:`.level_lift`).
"""

from __future__ import annotations

import numpy as np

from ..geometry.kernels import active, i64
from .level_lift import lift_to_portals


def stack_levels(col: np.ndarray, keep: np.ndarray, link: np.ndarray | None = None, rounds: int = 64,
                 lift: int = 0) -> np.ndarray:
    """Level of each kept span: first how many kept spans lie below it in its column;
    then, round by round, a span moves to the level most of its linked neighbours are
    on when that level is free in its column (the deck over a pillar joins the deck
    over the passage instead of standing alone on level 0); last, with ``lift`` > 0,
    the top of a ramp onto a deck over walkable ground joins the deck's level
    (:func:`tanktool.nav.level_lift.lift_to_portals`)."""
    level = np.full(len(col), -1, dtype=np.int64)
    kern = active()
    if kern is not None and link is not None and link.dtype == np.int32:
        # the ranks and the rounds in one call (tanktool/_kernels_surface.c): the same
        # moves, without numpy's passes over every kept span to set them up
        top = kern.level_votes(i64(col), np.ascontiguousarray(keep, dtype=bool), np.ascontiguousarray(link),
                               level, int(rounds))
        if top <= 0:  # nothing kept, or one kept span a column: the ranks are the levels
            return level
    else:
        c = col[keep]
        if len(c) == 0:
            return level
        if not (c[1:] == c[:-1]).any():  # one kept span a column (a terrain): all on level 0, nothing to move
            level[keep] = 0            # (without the kept spans' indices: 8 bytes a span less)
            return level
        _column_ranks(c, keep, level)
        if link is None or level.max() == 0:
            return level
        level = _vote_rounds(c, keep, link, level, rounds)
    if lift > 0:
        lift_to_portals(col, level, link, lift)
    # levels numbered from 0 without gaps, in order of height (small counts: no
    # hashing sort; no pass at all when no level was left empty, as is usual)
    used = np.flatnonzero(np.bincount(level + 1)[1:])
    if used[-1] != len(used) - 1:
        remap = np.full(int(used[-1]) + 2, -1)
        remap[used + 1] = np.arange(len(used))
        level[:] = remap[level + 1]
    return level


def _column_ranks(c: np.ndarray, keep: np.ndarray, level: np.ndarray) -> None:
    """Each kept span's rank among the kept spans of its column (``c``: their columns,
    sorted), written into ``level``."""
    first = np.ones(len(c), dtype=bool)
    first[1:] = c[1:] != c[:-1]
    start = np.flatnonzero(first)
    level[keep] = np.arange(len(c)) - np.repeat(start, np.diff(np.append(start, len(c))))


def _vote_rounds(c: np.ndarray, keep: np.ndarray, link: np.ndarray, level: np.ndarray, rounds: int) -> np.ndarray:
    """The voting rounds of :func:`stack_levels` over the kept spans' ranks ``level``
    (``c``: the kept spans' columns); the new levels."""
    idx = np.flatnonzero(keep)
    first = np.ones(len(c), dtype=bool)
    first[1:] = c[1:] != c[:-1]
    lv = np.append(level, -1)
    pos = np.full(len(level) + 1, -1, dtype=np.int64)  # span -> its row in idx
    pos[idx] = np.arange(len(idx))
    nb = np.where(link[idx] >= 0, link[idx], len(level))
    col_rank = np.cumsum(first) - 1  # c is sorted: the rank of each span's column
    active = (lv[nb] != lv[idx][:, None]).any(axis=1)  # only spans at a level's border can move
    is_cand = np.zeros(len(idx), dtype=bool)
    for _ in range(rounds):
        a = np.flatnonzero(active)
        if len(a) == 0:
            break
        nl = lv[nb[a]]  # (k, 4) levels of the linked neighbours
        cur = lv[idx[a]]
        votes = np.stack([(nl == nl[:, d:d + 1]).sum(axis=1) for d in range(4)], axis=1)
        votes = np.where(nl >= 0, votes, -1)
        top = votes.max(axis=1)
        # of the levels with the most votes, the highest
        best = np.where(votes == top[:, None], nl, -1).max(axis=1)
        mine = (nl == cur[:, None]).sum(axis=1)
        # more neighbours there, or as many (at least two) and it is the higher level: a
        # tie at the corner of a deck's patch over a pillar resolves upwards, but a
        # corridor one cell wide (one neighbour each way) stays where it is
        move = (best >= 0) & (best != cur) & ((top > mine) | ((top == mine) & (top >= 2) & (best > cur)))
        if not move.any():
            break
        # the new level must be free in the column: no other kept span there holds it,
        # and of two spans of one column moving to the same level in a round, neither does
        cand = a[move]
        taken = _level_taken(c, col_rank, lv[idx], cand, best[move], is_cand)
        ok = cand[~taken]
        if len(ok) == 0:
            break
        lv[idx[ok]] = best[move][~taken]
        active[:] = False
        near = pos[nb[ok]].ravel()
        active[near[near >= 0]] = True
        active[ok] = True
    return lv[:-1]


def _level_taken(c: np.ndarray, col_rank: np.ndarray, lv: np.ndarray, cand: np.ndarray, new: np.ndarray,
                 is_cand: np.ndarray) -> np.ndarray:
    """Whether each candidate's new level is held in its column by another kept span
    (at its current level, or a candidate's new one): the (column, level) keys of the
    candidates' columns only (``c`` sorted), where one sort over every kept span would
    find the same."""
    cc = c[cand]  # sorted, as cand is
    ucol = cc[np.append(True, cc[1:] != cc[:-1])]
    lo = np.searchsorted(c, ucol, side="left")
    cnt = np.searchsorted(c, ucol, side="right") - lo
    rows = np.repeat(lo, cnt) + (np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt))
    is_cand[cand] = True
    others = rows[~is_cand[rows]]
    is_cand[cand] = False
    key_cand = col_rank[cand] * 256 + new
    keys = np.concatenate([col_rank[others] * 256 + lv[others], key_cand])
    uniq, counts = np.unique(keys, return_counts=True)
    return counts[np.searchsorted(uniq, key_cand)] > 1
