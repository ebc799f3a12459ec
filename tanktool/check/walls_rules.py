"""Rules on the walls themselves: A201-A205, and A301 (leaks) for a bare walls.txt.

Pair rules (duplicates, overlaps, crossings) look only at pairs whose bounding boxes
meet (shapely's STRtree), then classify all candidate pairs at once with numpy.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely import STRtree

from ..formats.walls_txt import WallList
from .diagnostics import Diagnostic, diag, fmt_xz
from .freespace import UNBOUNDED, FreeSpace, gaps, near_copies


def _line(walls: WallList, i: int) -> int:
    return int(walls.lines[i]) if walls.lines is not None and len(walls.lines) > i else 0


def zero_length(walls: WallList, path: str) -> list[Diagnostic]:
    seg = walls.segments
    zero = np.flatnonzero(np.all(seg[:, 0] == seg[:, 1], axis=1))
    return [diag("A201", path, _line(walls, i), f"wall from {fmt_xz(seg[i, 0])} to itself has zero length")
            for i in zero]


def pair_rules(walls: WallList, grid: float) -> list[Diagnostic]:
    """A202 duplicates, A203 overlaps along the length, A204 X crossings."""
    path = str(walls.path or "walls.txt")
    seg = walls.segments
    d = seg[:, 1] - seg[:, 0]
    length = np.hypot(d[:, 0], d[:, 1])
    live = np.flatnonzero(length > 0)
    if len(live) < 2:
        return []
    # copies (both ends within the tolerance, in either order, same free side) are A202
    # against the first copy of their bin and take no further part: a wall pasted 1,000
    # times with tiny offsets would otherwise make 500,000 candidate pairs (and as many
    # diagnostics)
    tol = 4.0 * grid
    origin = near_copies(seg, walls.direction, live, tol)
    repeats = [diag("A202", path, _line(walls, k), f"this wall repeats the wall on line {_line(walls, o)}")
               for k, o in zip(live.tolist(), origin.tolist()) if k != o]
    live = live[origin == live]
    if len(live) < 2:
        return repeats
    lines = shapely.linestrings(seg[live])
    # within the tolerance, not only touching: a copy moved off its wall by a hair
    # (parallel, not meeting it) is a copy all the same
    i, j = STRtree(lines).query(lines, predicate="dwithin", distance=tol)
    keep = i < j
    a, b = live[i[keep]], live[j[keep]]
    if not len(a):
        return repeats
    P, Q = seg[a, 0], seg[a, 1]
    R, S = seg[b, 0], seg[b, 1]
    u = d[a] / length[a, None]
    v = d[b] / length[b, None]

    def side(o, t, p):  # signed distance of p from the line through o along unit t
        return t[:, 0] * (p[:, 1] - o[:, 1]) - t[:, 1] * (p[:, 0] - o[:, 0])

    with np.errstate(all="ignore"):
        collinear = (np.abs(side(P, u, R)) <= tol) & (np.abs(side(P, u, S)) <= tol)
        # overlap of b's projection onto a
        r0 = np.einsum("ij,ij->i", R - P, u)
        s0 = np.einsum("ij,ij->i", S - P, u)
        overlap = np.minimum(np.maximum(r0, s0), length[a]) - np.maximum(np.minimum(r0, s0), 0.0)
        normal_a = np.stack([-u[:, 1], u[:, 0]], axis=1) * walls.direction[a, None]
        normal_b = np.stack([-v[:, 1], v[:, 0]], axis=1) * walls.direction[b, None]
        same_side = np.einsum("ij,ij->i", normal_a, normal_b) > 0
        same_ends = (((np.abs(P - R) <= tol).all(1) & (np.abs(Q - S) <= tol).all(1))
                     | ((np.abs(P - S) <= tol).all(1) & (np.abs(Q - R) <= tol).all(1)))
        # proper crossing: each wall's ends strictly on both sides of the other, away from its ends
        ca1, ca2 = side(P, u, R), side(P, u, S)
        cb1, cb2 = side(R, v, P), side(R, v, Q)
        cross = ((ca1 > tol) & (ca2 < -tol) | (ca1 < -tol) & (ca2 > tol)) & \
                ((cb1 > tol) & (cb2 < -tol) | (cb1 < -tol) & (cb2 > tol))

    out: list[Diagnostic] = repeats
    # two coincident walls with opposite normals are the shared face of two touching
    # solids (both normals point into solid, they cancel): legal, so only same-side pairs count
    dup = collinear & same_ends & same_side
    over = collinear & ~same_ends & same_side & (overlap > tol)
    for k in np.flatnonzero(dup):
        out.append(diag("A202", path, _line(walls, b[k]),
                        f"this wall repeats the wall on line {_line(walls, a[k])}"))
    for k in np.flatnonzero(over):
        out.append(diag("A203", path, _line(walls, b[k]),
                        f"this wall overlaps the wall on line {_line(walls, a[k])} along {overlap[k]:.3g} m"))
    for k in np.flatnonzero(cross & ~collinear):
        t = ca1[k] / (ca1[k] - ca2[k])
        x = R[k] + t * (S[k] - R[k])
        out.append(diag("A204", path, _line(walls, b[k]),
                        f"this wall crosses the wall on line {_line(walls, a[k])} at {fmt_xz(x)}"))
    return out


def flipped_normals(fs: FreeSpace, path: str) -> list[Diagnostic]:
    walls = fs.walls
    out = []
    free = np.append(fs.free, False)
    # the first bad piece of each wall, found in one pass (a scan of every piece per
    # flipped wall was quadratic on a wall pasted many times)
    bad = np.flatnonzero((fs.piece_front != fs.piece_back) & ~free[fs.piece_front] & free[fs.piece_back])
    first_bad = {}
    for p, k in zip(bad.tolist(), fs.piece_wall[bad].tolist()):
        first_bad.setdefault(k, p)
    for k in np.flatnonzero(fs.flipped()).tolist():
        into = fs.piece_front[first_bad[k]] if k in first_bad else fs.front[k]
        where = "the outside of the arena" if into == UNBOUNDED else "solid material"
        out.append(diag("A205", path, _line(walls, k),
                        f"the normal of this wall points into {where}; free space is behind it"))
    return out


def leak_diagnostics(fs: FreeSpace, path: str, what: str) -> list[Diagnostic]:
    """A301 for every gap between dangling wall ends that opens onto the outside."""
    walls = fs.walls
    out = []
    for wa, wb, ea, eb in gaps(fs):
        mid = 0.5 * (ea + eb)
        if fs.face_of(mid[None])[0] != UNBOUNDED:
            continue  # a gap inside a closed room: nothing can get out through it
        width = float(np.hypot(*(eb - ea)))
        out.append(diag("A301", path, _line(walls, wa),
                        f"{what} is not closed: a gap {width:.2f} m wide at {fmt_xz(mid)} "
                        f"between the walls on lines {_line(walls, wa)} and {_line(walls, wb)}"))
    if not out and len(fs.dangling):
        k = int(fs.dangling_wall[0])
        out.append(diag("A301", path, _line(walls, k),
                        f"{what} is not closed: the wall end at {fmt_xz(fs.dangling[0])} is joined to no other wall"))
    return out


def bare_walls_leaks(fs: FreeSpace, path: str) -> list[Diagnostic]:
    """Without spawn points, the free space is what the normals point at: it leaks
    when a wall's normal points into the unbounded outside and wall ends are loose."""
    if not len(fs.dangling):
        return []
    if not (fs.piece_front == UNBOUNDED).any():
        return []
    return leak_diagnostics(fs, path, "the free space")


def check_walls(walls: WallList, fs: FreeSpace, path: str) -> list[Diagnostic]:
    """The wall rules that need no spawn points."""
    return zero_length(walls, path) + pair_rules(walls, fs.grid) + flipped_normals(fs, path)
