"""Rules on the walls themselves: A201-A205, and A301 (leaks) for a bare walls.txt.

Pair rules (duplicates, overlaps, crossings): geometry.wall_pairs.classify_pairs, the
test import-arena also runs on the walls it writes.
"""

from __future__ import annotations

import numpy as np

from ..formats.walls_txt import WallList
from ..geometry.wall_pairs import classify_pairs
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
    pairs = classify_pairs(seg, walls.direction, live, tol)
    out: list[Diagnostic] = repeats
    for a, b in zip(*pairs.repeat):
        out.append(diag("A202", path, _line(walls, b), f"this wall repeats the wall on line {_line(walls, a)}"))
    for a, b, along in zip(*pairs.overlap):
        out.append(diag("A203", path, _line(walls, b),
                        f"this wall overlaps the wall on line {_line(walls, a)} along {along:.3g} m"))
    for a, b, x in zip(*pairs.cross):
        out.append(diag("A204", path, _line(walls, b),
                        f"this wall crosses the wall on line {_line(walls, a)} at {fmt_xz(x)}"))
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
