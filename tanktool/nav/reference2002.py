"""The 2002 paper's free-space test, node by node: the reference the vectorised
:func:`tanktool.nav.navgrid.classify` is tested and benchmarked against (slow)."""

from __future__ import annotations

import numpy as np

from ..formats.walls_txt import WallList
from ..geometry.segments import point_segment_dist2
from .free_space import _oriented, node_coords, on_wall_tolerance


def reference_node(walls: WallList, A: np.ndarray, B: np.ndarray, origin: np.ndarray, p: np.ndarray) -> bool:
    """The 2002 test of one point: is it in free space?

    The line L through the arena origin O and the point P is cut by every wall it
    crosses (its end points classified by side of L, half-open, so a vertex on L is
    counted once); the crossings, sorted along L, form the list whose two ends are
    where L leaves the auxiliary rectangle.  Two pointers walk in from both ends,
    starting "outside", adding +1 for each wall crossed along its normal and -1
    against it, until they meet at P.  P is free when both counts are positive.
    """
    u = p - origin
    side_a = (u[0] * (A[:, 1] - origin[1]) - u[1] * (A[:, 0] - origin[0])) > 0
    side_b = (u[0] * (B[:, 1] - origin[1]) - u[1] * (B[:, 0] - origin[0])) > 0
    k = np.flatnonzero(side_a != side_b)
    if len(k) == 0:
        return False
    a, d = A[k], B[k] - A[k]
    # L(t) = O + t u meets a + s d: t = cross(a - O, d) / cross(u, d); P is at t = 1
    t = ((a[:, 0] - origin[0]) * d[:, 1] - (a[:, 1] - origin[1]) * d[:, 0]) / (u[0] * d[:, 1] - u[1] * d[:, 0])
    # walking +u: a wall from the left of L to its right has its left side (free) ahead
    sign = np.where(side_a[k], 1, -1)
    order = np.argsort(t, kind="stable")
    crossings = list(zip(t[order].tolist(), sign[order].tolist()))  # the "doubly linked list"
    head, tail = 0, len(crossings) - 1
    from_head = from_tail = 0
    while head <= tail and crossings[head][0] < 1.0:
        from_head += crossings[head][1]
        head += 1
    while tail >= head and crossings[tail][0] > 1.0:
        from_tail -= crossings[tail][1]
        tail -= 1
    # head > tail: the pointers met at P; otherwise a crossing sits exactly on P
    return head > tail and from_head > 0 and from_tail > 0


def classify_reference(
    walls: WallList, origin: np.ndarray, cell: float, shape: tuple[int, int], clearance: float,
    nodes: np.ndarray | None = None,
) -> np.ndarray:
    """Valid-node mask by the 2002 method, node by node (slow; the reference).

    ``nodes`` (m, 2) restricts the work to some nodes and returns an (m,) mask;
    otherwise the whole ``shape`` mask is returned.
    """
    nz, nx = shape
    if nodes is None:
        ii, jj = np.divmod(np.arange(nz * nx), nx)
    else:
        ii, jj = np.asarray(nodes).reshape(-1, 2).T
    xs = node_coords(origin[0], cell, nx)
    zs = node_coords(origin[1], cell, nz)
    A, B = _oriented(walls)
    seg = walls.segments
    tol = on_wall_tolerance(walls.bounds)
    O = np.asarray(walls.bounds[0], dtype=np.float64)
    out = np.zeros(len(ii), dtype=bool)
    for k, (i, j) in enumerate(zip(ii.tolist(), jj.tolist())):
        p = np.array([xs[j], zs[i]])
        d2 = point_segment_dist2(p, seg[:, 0], seg[:, 1])
        if len(d2) and (d2.min() < clearance * clearance or d2.min() <= tol * tol):
            continue
        out[k] = reference_node(walls, A, B, O, p)
    return out.reshape(shape) if nodes is None else out
