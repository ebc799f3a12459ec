"""The 2002 wall list, ``walls.txt``.

One wall a line, ``X1 Z1 X2 Z2 Direction``, whitespace separated, ``#`` starts a
comment.  Direction (+1 or -1) picks the normal
``n = Direction * (-(Z2-Z1), X2-X1) / length`` that points into free space.  The last
four walls are the auxiliary bounding rectangle, written after a ``# auxiliary`` line;
files without the marker are accepted when their last four walls form an
axis-aligned rectangle enclosing the rest.

On an arena of several levels (or of several separate surfaces on one level) the
walls come in blocks, each after a marker comment::

    # level 1 region 4 y 3.00 3.00
    12.5 4 20 4 1

``level`` is the navigation grid's level, ``region`` numbers the connected surface
the block's walls bound (unique over the file), ``y`` the lowest and highest floor
height along them.  Markers are comments, so tools that know only the five columns
read the same walls; a file without markers is one block on level 0.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import FormatError
from .bundle import atomic_write_text, read_input_text
from .limits import MAX_COORDINATE

AUX_MARKER = "# auxiliary"
LEVEL_MARKER = "# level"
#: a level marker: "# level" and a number (other comments may start with "# level ...")
_MARKER_RE = re.compile(r"^#\s*level\s+[-+]?\d", re.IGNORECASE)


@dataclass
class WallList:
    """Walls in the (x, z) plane.

    segments : (n, 2, 2) float64, ``segments[k] = [[x1, z1], [x2, z2]]``
    direction : (n,) int8, +1 or -1
    aux : (4, 2, 2) float64, the auxiliary bounding rectangle (may be None when
          the file has none; :attr:`bounds` then falls back to the walls' extent)
    lines : (n,) int, the 1-based line of each wall in the file it came from (0 if made in memory)
    level, region : (n,) int, each wall's level and region (0 and 0 without markers)
    regions : region -> (level, y_lo, y_hi) of every marked block
    """

    segments: np.ndarray
    direction: np.ndarray
    aux: np.ndarray | None = None
    lines: np.ndarray | None = None
    path: str | None = None
    level: np.ndarray | None = None
    region: np.ndarray | None = None
    regions: dict | None = None

    def __post_init__(self) -> None:
        self.segments = np.asarray(self.segments, dtype=np.float64).reshape(-1, 2, 2)
        self.direction = np.asarray(self.direction, dtype=np.int8).reshape(-1)
        if self.lines is None:
            self.lines = np.zeros(len(self.segments), dtype=np.int64)
        n = len(self.segments)
        self.level = np.zeros(n, dtype=np.int64) if self.level is None else np.asarray(self.level, dtype=np.int64).reshape(-1)
        self.region = np.zeros(n, dtype=np.int64) if self.region is None else np.asarray(self.region, dtype=np.int64).reshape(-1)
        if self.regions is None:
            self.regions = {}
        if self.aux is not None:
            self.aux = np.asarray(self.aux, dtype=np.float64).reshape(4, 2, 2)

    def __len__(self) -> int:
        return len(self.segments)

    @property
    def normals(self) -> np.ndarray:
        """(n, 2) unit normals pointing into free space (zero for zero-length walls)."""
        d = self.segments[:, 1] - self.segments[:, 0]
        length = np.hypot(d[:, 0], d[:, 1])
        n = np.stack([-d[:, 1], d[:, 0]], axis=1) * self.direction[:, None]
        with np.errstate(invalid="ignore", divide="ignore"):
            n = np.where(length[:, None] > 0, n / length[:, None], 0.0)
        return n

    @property
    def bounds(self) -> np.ndarray:
        """(2, 2) ``[[xmin, zmin], [xmax, zmax]]`` of the auxiliary rectangle."""
        pts = (self.aux if self.aux is not None else self.segments).reshape(-1, 2)
        if len(pts) == 0:
            return np.zeros((2, 2))
        return np.array([pts.min(axis=0), pts.max(axis=0)])

    @property
    def levels(self) -> int:
        """Number of levels the walls are marked with (1 without markers)."""
        return int(self.level.max()) + 1 if len(self.level) else 1

    @property
    def layered(self) -> bool:
        """True when the file has level/region markers (more than one block)."""
        return bool(self.regions) and (len(self.regions) > 1 or self.levels > 1)

    def select(self, mask: np.ndarray) -> "WallList":
        """The walls where ``mask`` holds (the same auxiliary rectangle and regions)."""
        m = np.asarray(mask, dtype=bool)
        return WallList(self.segments[m], self.direction[m], self.aux, self.lines[m], self.path,
                        self.level[m], self.region[m], dict(self.regions))

    def on_level(self, level: int) -> "WallList":
        return self.select(self.level == level)

    def all_segments(self) -> np.ndarray:
        """Walls followed by the auxiliary walls, (n + 4, 2, 2)."""
        if self.aux is None:
            return self.segments
        return np.concatenate([self.segments, self.aux])


def aux_rectangle(xmin: float, zmin: float, xmax: float, zmax: float) -> np.ndarray:
    """The four auxiliary walls of a bounding rectangle, counter-clockwise, (4, 2, 2)."""
    c = [(xmin, zmin), (xmax, zmin), (xmax, zmax), (xmin, zmax)]
    return np.array([[c[i], c[(i + 1) % 4]] for i in range(4)], dtype=np.float64)


def aux_direction(aux: np.ndarray) -> np.ndarray:
    """Directions making the auxiliary walls' normals point inwards."""
    centre = aux.reshape(-1, 2).mean(axis=0)
    d = aux[:, 1] - aux[:, 0]
    n = np.stack([-d[:, 1], d[:, 0]], axis=1)
    to_c = centre - aux[:, 0]
    return np.where((n * to_c).sum(axis=1) >= 0, 1, -1).astype(np.int8)


def _is_enclosing_rectangle(aux: np.ndarray, rest: np.ndarray) -> bool:
    pts = aux.reshape(-1, 2)
    xmin, zmin = pts.min(axis=0)
    xmax, zmax = pts.max(axis=0)
    if not (xmax > xmin and zmax > zmin):
        return False
    # each auxiliary wall axis-aligned and lying on the rectangle's border
    for (x1, z1), (x2, z2) in aux:
        horizontal = z1 == z2 and z1 in (zmin, zmax) and {x1, x2} == {xmin, xmax}
        vertical = x1 == x2 and x1 in (xmin, xmax) and {z1, z2} == {zmin, zmax}
        if not (horizontal or vertical):
            return False
    if len(rest):
        r = rest.reshape(-1, 2)
        eps = 1e-9 * max(1.0, float(np.abs(pts).max()))
        if (r[:, 0] < xmin - eps).any() or (r[:, 0] > xmax + eps).any():
            return False
        if (r[:, 1] < zmin - eps).any() or (r[:, 1] > zmax + eps).any():
            return False
    return True


class WallRows:
    """The walls a reader has taken so far, each with its line, level and region
    (shared by :func:`parse_walls` and check's tolerant scanner)."""

    def __init__(self) -> None:
        self.segs: list[list[float]] = []
        self.dirs: list[int] = []
        self.lines: list[int] = []
        self.levels: list[int] = []
        self.region_of: list[int] = []

    def __len__(self) -> int:
        return len(self.segs)

    def add(self, vals: list[float], direction: int, lineno: int, current: tuple[int, int]) -> None:
        """One wall: its coordinates, Direction and line, under the marker ``current`` (level, region)."""
        self.segs.append(vals)
        self.dirs.append(direction)
        self.lines.append(lineno)
        self.levels.append(current[0])
        self.region_of.append(current[1])

    def wall_lists(self, path: str, regions: dict) -> tuple[Callable[..., WallList], np.ndarray, np.ndarray]:
        """A maker of the WallList of a slice of the walls (with ``aux`` as its auxiliary
        rectangle), and the walls as arrays: (segments (n, 2, 2), lines (n,))."""
        seg = np.array(self.segs, dtype=np.float64).reshape(-1, 2, 2)
        direction = np.array(self.dirs, dtype=np.int8)
        line_arr = np.array(self.lines, dtype=np.int64)
        lev = np.array(self.levels, dtype=np.int64)
        reg = np.array(self.region_of, dtype=np.int64)

        def make(sl: slice, aux: np.ndarray | None = None) -> WallList:
            return WallList(seg[sl], direction[sl], aux, line_arr[sl], path, lev[sl], reg[sl], regions)

        return make, seg, line_arr


def parse_walls(text: str, path: str = "<walls>") -> WallList:
    """Parse the text of a wall list.  Raises FormatError naming ``path:line``."""
    rows = WallRows()
    regions: dict[int, tuple[int, float, float]] = {}
    current = (0, 0)
    aux_start: int | None = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        stripped = raw.strip()
        if stripped.lower().startswith(AUX_MARKER):
            if aux_start is not None:
                raise FormatError(f"{path}:{lineno}: second '{AUX_MARKER}' marker")
            aux_start = len(rows)
            continue
        if _MARKER_RE.match(stripped) and aux_start is None:
            current = _parse_marker(stripped, f"{path}:{lineno}", regions)
            continue
        body = raw.split("#", 1)[0].split()
        if not body:
            continue
        if len(body) != 5:
            raise FormatError(
                f"{path}:{lineno}: expected 5 fields 'X1 Z1 X2 Z2 Direction', got {len(body)}"
            )
        try:
            vals = [float(v) for v in body[:4]]
        except ValueError:
            raise FormatError(f"{path}:{lineno}: expected numbers, got {' '.join(body[:4])!r}") from None
        if not all(math.isfinite(v) for v in vals):
            raise FormatError(f"{path}:{lineno}: coordinates must be finite, got {' '.join(body[:4])}")
        if max(abs(v) for v in vals) > MAX_COORDINATE:
            raise FormatError(f"{path}:{lineno}: coordinates must lie within {MAX_COORDINATE:g} m of the origin, "
                              f"got {' '.join(body[:4])}")
        try:
            d = float(body[4])
        except ValueError:
            raise FormatError(f"{path}:{lineno}: Direction must be +1 or -1, got {body[4]!r}") from None
        if d not in (1.0, -1.0):
            raise FormatError(f"{path}:{lineno}: Direction must be +1 or -1, got {body[4]}")
        rows.add(vals, int(d), lineno, current)
    make, seg, line_arr = rows.wall_lists(path, regions)
    if aux_start is not None:
        if len(seg) - aux_start != 4:
            raise FormatError(
                f"{path}: expected 4 auxiliary walls after '{AUX_MARKER}', got {len(seg) - aux_start}"
            )
        aux = seg[aux_start:]
        if not _is_enclosing_rectangle(aux, seg[:aux_start]):
            raise FormatError(
                f"{path}:{line_arr[aux_start]}: auxiliary walls must form an axis-aligned "
                "rectangle enclosing every wall"
            )
        return make(slice(None, aux_start), aux)
    if len(seg) >= 4 and _is_enclosing_rectangle(seg[-4:], seg[:-4]):
        return make(slice(None, -4), seg[-4:])
    return make(slice(None))


#: the most levels a wall list may name
MAX_LEVEL = 63


def _parse_marker(text: str, where: str, regions: dict) -> tuple[int, int]:
    """``# level L [region R] [y LO HI]`` -> (L, R); records R's level and heights."""
    words = text[1:].split()
    fields: dict[str, list[str]] = {}
    k = 0
    try:
        while k < len(words):
            key = words[k].lower()
            n = 2 if key == "y" else 1
            if key not in ("level", "region", "y") or key in fields:
                raise ValueError
            fields[key] = words[k + 1:k + 1 + n]
            if len(fields[key]) != n:
                raise ValueError
            k += 1 + n
        level = int(fields["level"][0])
        region = int(fields["region"][0]) if "region" in fields else len(regions)
        y = [float(v) for v in fields["y"]] if "y" in fields else [math.nan, math.nan]
    except (ValueError, KeyError):
        raise FormatError(f"{where}: expected a level marker '# level L region R y LO HI', got {text!r}") from None
    if not 0 <= level <= MAX_LEVEL or region < 0:
        raise FormatError(f"{where}: level must be 0..{MAX_LEVEL} and region >= 0, got {text!r}")
    if region in regions and regions[region][0] != level:
        raise FormatError(f"{where}: region {region} was marked on level {regions[region][0]} before")
    regions[region] = (level, y[0], y[1])
    return level, region


def read_walls(path: str | os.PathLike) -> WallList:
    """Read ``walls.txt``; errors name the file and line."""
    return parse_walls(read_input_text(path, "a walls.txt file"), str(path))


def format_walls(walls: WallList, header: str | None = None) -> str:
    """The text of a wall list; auxiliary walls last after ``# auxiliary``."""
    out = []
    if header:
        out += [f"# {line}" for line in header.splitlines()]
    out.append("# X1 Z1 X2 Z2 Direction")

    def fmt(v: float) -> str:
        s = f"{v:.4f}".rstrip("0").rstrip(".")
        return "0" if s in ("-0", "") else s

    marked = walls.layered
    order = np.lexsort((np.arange(len(walls)), walls.region, walls.level)) if marked else np.arange(len(walls))
    block = None
    for k in order:
        (p, q), d = walls.segments[k], walls.direction[k]
        if marked and (walls.level[k], walls.region[k]) != block:
            block = (int(walls.level[k]), int(walls.region[k]))
            lv, lo, hi = walls.regions.get(block[1], (block[0], math.nan, math.nan))
            ys = f" y {lo:.2f} {hi:.2f}" if math.isfinite(lo) and math.isfinite(hi) else ""
            out.append(f"{LEVEL_MARKER} {block[0]} region {block[1]}{ys}")
        out.append(f"{fmt(p[0])} {fmt(p[1])} {fmt(q[0])} {fmt(q[1])} {int(d)}")
    if walls.aux is not None:
        out.append(AUX_MARKER)
        for (p, q), d in zip(walls.aux, aux_direction(walls.aux)):
            out.append(f"{fmt(p[0])} {fmt(p[1])} {fmt(q[0])} {fmt(q[1])} {int(d)}")
    return "\n".join(out) + "\n"


def write_walls(path: str | os.PathLike, walls: WallList, header: str | None = None) -> None:
    atomic_write_text(path, format_walls(walls, header))
