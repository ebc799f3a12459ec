"""The AI navigation grid (the 2002 "malla"): valid nodes, runs, reachable regions.

Nodes sit at cell centres over the arena bounds: node (i, j) is at
``x = origin_x + (j + 1/2) cell``, ``z = origin_z + (i + 1/2) cell``; a row (index i)
is a line of constant z, a column (index j) one of constant x.

**Free space.**  Orient every wall so that its normal (the side ``Direction`` picks)
is on its left; the auxiliary rectangle is not a wall.  Walking along any line from
outside the arena, count +1 for each wall crossed along its normal (entering free
space) and -1 for each crossed against it.  A point is in free space when this count
is positive walking from *both* ends of the line up to the point (the 2002 paper's
two pointers walking a line's crossing list from both ends).  For walls made of closed
loops with consistent normals -- the walls of any solid sliced at a height -- the count
is the winding number of the oriented walls: 1 in free space, 0 in solids and outside,
the same along every line, and shared edges of touching solids (opposite normals)
cancel.  :func:`open_ends` lists the vertices where that fails (loose ends, flipped
normals); only near those can the two classifiers below disagree.

A node is **valid** when it is in free space and its distance to every wall is at
least the clearance (and not zero: a node on a wall is never valid).

Two classifiers, which agree exactly on every node farther than rounding from a wall:

* :func:`classify_reference`, the 2002 method: the line through each node and the
  arena origin (the auxiliary rectangle's low corner), its crossings with every wall
  sorted into a list and walked from both ends; clearance by brute force.
* :func:`classify`, the vectorised default: the same count along each grid row (one
  crossing list per row, a cumulative sum per node), and clearance by rasterising each
  wall's capsule row by row: nodes well inside it are marked at once, the few near
  its edge are decided by the same exact distance kernel the reference uses.  Crossings use a half-open rule on the row's z (an end point exactly
  on the row counts as above it), so a line through a vertex is never counted twice.
"""

from __future__ import annotations

import io
import math
import os
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import ArenaError, FormatError
from ..formats.walls_txt import WallList
from ..geometry.segments import point_segment_dist2

#: refuse grids larger than this (nodes); 25 M nodes is ~300 MB of arrays
MAX_NODES = 25_000_000
#: refuse grids of more levels than this
MAX_LEVELS = 64
_FIELDS = ("valid", "row_index", "row_total", "col_index", "col_total", "reachable")

Node = tuple[int, int]
#: the four grid directions as (di, dj): +x (east, j+1), +z (i+1), -x, -z
STEPS: dict[str, Node] = {"+x": (0, 1), "+z": (1, 0), "-x": (0, -1), "-z": (-1, 0)}


def _node3(n: tuple) -> tuple[int, int, int]:
    """A node as ``(level, i, j)``; an ``(i, j)`` is on level 0."""
    return (0, int(n[0]), int(n[1])) if len(n) == 2 else (int(n[0]), int(n[1]), int(n[2]))


@dataclass
class NavGrid:
    """A navigation grid.  Per-node arrays have shape ``(L, nz, nx)`` in memory, on every
    arena: L levels (node ``(level, i, j)``), L = 1 on a flat one.  Arrays given as
    ``(nz, nx)`` (a hand-made mask, a file of one level) gain the level axis on
    construction; :meth:`to_bytes` writes a one-level grid's arrays as ``(nz, nx)``
    (docs/formats.md), so such files keep their bytes.

    row_index / row_total: 1-based position of the node in its row run of valid
    nodes, and that run's length (0 for invalid nodes); col_* the same for columns.
    Runs are counted per level and break where two neighbours are not linked.
    height: world y of the walkable surface at each node (NaN where there is none);
    a node may be invalid (a tank does not fit there) and still have a height.
    link: ``(L, nz, nx, 4)`` int8, the level of the node reached by each step of
    STEPS (+x, +z, -x, -z), -1 where the step is blocked (a wall, a drop-off, a slope
    too steep, another level out of the climb), between nodes of the surface valid or
    not.  None on grids made from walls alone: then neighbours on the same level are
    linked whenever both are valid.
    """

    origin: np.ndarray
    cell: float
    shape: tuple[int, int]
    valid: np.ndarray
    row_index: np.ndarray
    row_total: np.ndarray
    col_index: np.ndarray
    col_total: np.ndarray
    reachable: np.ndarray
    clearance: float = float("nan")  # how it was built; kept in arena.toml, not in the npz
    spawn_nodes: list[tuple[int, int, int]] = field(default_factory=list)  # (level, i, j)
    height: np.ndarray | None = None
    link: np.ndarray | None = None
    layers: "NavGrid | None" = None  # a one-level projection's layered grid (the agents' on a ground); not saved

    def __post_init__(self) -> None:
        # one representation in memory: a (nz, nx) array is level 0 of (1, nz, nx)
        if np.ndim(self.valid) == 2:
            for k in _FIELDS + ("height",):
                a = getattr(self, k)
                if a is not None:
                    setattr(self, k, np.asarray(a)[None])
            if self.link is not None:
                self.link = np.asarray(self.link)[None]
        self.spawn_nodes = [_node3(n) for n in self.spawn_nodes]

    # ------------------------------------------------------------ levels
    @property
    def levels(self) -> int:
        """Number of levels (1 on a flat arena)."""
        return int(self.valid.shape[0])

    def links(self) -> np.ndarray:
        """``(L, nz, nx, 4)`` levels reached by each step (-1: blocked), derived from
        validity when the grid has no ``link`` array."""
        return self.link if self.link is not None else links_from_valid(self.valid)

    def heights(self) -> np.ndarray:
        """``(L, nz, nx)`` surface heights (0 at valid nodes of a grid without heights)."""
        return self.height if self.height is not None else np.where(self.valid, 0.0, np.nan)

    # ------------------------------------------------------------ geometry
    @property
    def nz(self) -> int:
        return int(self.shape[0])

    @property
    def nx(self) -> int:
        return int(self.shape[1])

    @property
    def node_x(self) -> np.ndarray:
        """(nx,) x of each column of nodes."""
        return node_coords(self.origin[0], self.cell, self.nx)

    @property
    def node_z(self) -> np.ndarray:
        """(nz,) z of each row of nodes."""
        return node_coords(self.origin[1], self.cell, self.nz)

    def centre(self, i: int, j: int) -> tuple[float, float]:
        """World (x, z) of node (i, j)."""
        return (float(self.origin[0] + (j + 0.5) * self.cell), float(self.origin[1] + (i + 0.5) * self.cell))

    def centres(self, nodes: np.ndarray) -> np.ndarray:
        """(m, 2) world points of (m, 2) nodes ``[[i, j], ...]``."""
        n = np.asarray(nodes).reshape(-1, 2)
        return np.stack([self.origin[0] + (n[:, 1] + 0.5) * self.cell, self.origin[1] + (n[:, 0] + 0.5) * self.cell], axis=1)

    def node_of(self, x: float, z: float) -> Node:
        """The node whose cell contains (x, z), clamped into the grid."""
        j = math.floor((x - float(self.origin[0])) / self.cell)   # plain floats: called per think
        i = math.floor((z - float(self.origin[1])) / self.cell)
        nz, nx = int(self.shape[0]), int(self.shape[1])
        return (0 if i < 0 else nz - 1 if i >= nz else i, 0 if j < 0 else nx - 1 if j >= nx else j)

    def nodes_of(self, points: np.ndarray) -> np.ndarray:
        """(m, 2) nodes of (m, 2) world points, clamped into the grid."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        j = np.clip(np.floor((p[:, 0] - self.origin[0]) / self.cell), 0, self.nx - 1)
        i = np.clip(np.floor((p[:, 1] - self.origin[1]) / self.cell), 0, self.nz - 1)
        return np.stack([i, j], axis=1).astype(np.int64)

    def inside(self, i: int, j: int) -> bool:
        return 0 <= i < self.nz and 0 <= j < self.nx

    def is_valid(self, node: Node, level: int = 0) -> bool:
        """Whether node (i, j) of ``level`` is inside the grid and valid."""
        i, j = node
        return self.inside(i, j) and bool(self.valid[level, i, j])

    def neighbours4(self, i: int, j: int, level: int = 0) -> list[Node]:
        """The valid 4-neighbours of (i, j) on ``level``, in the order +x, +z, -x, -z."""
        out = []
        for di, dj in STEPS.values():
            a, b = i + di, j + dj
            if self.inside(a, b) and self.valid[level, a, b]:
                out.append((a, b))
        return out

    @property
    def bounds(self) -> np.ndarray:
        return np.array([self.origin, self.origin + self.cell * np.array([self.nx, self.nz])])

    # ------------------------------------------------------------ save / load
    def save(self, path: str | os.PathLike) -> None:
        """``navgrid.npz``: origin, cell, shape, valid, row/col index/total, reachable."""
        from ..formats.bundle import atomic_write_bytes

        atomic_write_bytes(path, self.to_bytes())

    def to_bytes(self) -> bytes:
        """The npz bytes; a one-level grid's arrays are written as ``(nz, nx)`` (the
        2002 grids' format, unchanged since before levels existed)."""
        buf = io.BytesIO()
        arrays = {k: getattr(self, k) for k in _FIELDS}
        arrays["height"] = np.asarray(self.heights(), dtype=np.float32)
        if self.link is not None:
            arrays["link"] = np.asarray(self.link, dtype=np.int8)
        if self.levels == 1:
            arrays = {k: a[0] for k, a in arrays.items()}
        np.savez_compressed(
            buf, origin=np.asarray(self.origin, dtype=np.float64),
            cell=np.array(float(self.cell)), shape=np.array(self.shape, dtype=np.int64), **arrays,
        )
        return buf.getvalue()

    @classmethod
    def load(cls, path: str | os.PathLike) -> "NavGrid":
        """Read a ``navgrid.npz``; anything malformed raises FormatError naming the file."""
        import zipfile
        import zlib

        from ..formats.npz import read_npz

        try:
            z = read_npz(path, "a navgrid file")  # bounded, no pickles, a damaged zip one clear error
            missing = [k for k in ("origin", "cell", "shape", *_FIELDS[:-1]) if k not in z]
            if missing:
                raise FormatError(f"{path}: not a navgrid file (missing {', '.join(missing)})")
            raw_shape = z["shape"]
            if raw_shape.shape != (2,) or raw_shape.dtype.kind not in "iu":
                raise FormatError(f"{path}: 'shape' must be two integers (nz, nx)")
            shape = (int(raw_shape[0]), int(raw_shape[1]))
            if min(shape) < 1 or shape[0] * shape[1] > MAX_NODES:
                raise FormatError(f"{path}: shape {shape} is not a grid of 1 to {MAX_NODES:,} nodes")
            arrays = {}
            for k in (*_FIELDS, "height", "link"):
                if k in z:
                    a = z[k]
                    if a.size > 16 * MAX_NODES * 4:
                        raise FormatError(f"{path}: {k} is too large ({a.size:,} values)")
                    arrays[k] = a
            origin = z["origin"].astype(np.float64)
            cell = float(z["cell"])
        except FileNotFoundError:
            raise FormatError(f"{path}: no such file") from None
        except FormatError:
            raise
        except (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile, zlib.error) as e:
            raise FormatError(f"{path}: cannot read navgrid: {e}") from None
        if origin.shape != (2,) or not np.isfinite(origin).all() or not (math.isfinite(cell) and cell > 0):
            raise FormatError(f"{path}: bad origin/cell/shape")
        v = arrays["valid"]
        if v.ndim == 3 and v.shape[1:] == shape and 1 <= v.shape[0] <= MAX_LEVELS:
            full = v.shape
        elif v.shape == shape:  # one level, stored as (nz, nx) (NavGrid adds the level axis)
            full = shape
        else:
            raise FormatError(f"{path}: valid has shape {v.shape}, expected {shape} or (levels, {shape[0]}, {shape[1]})")
        for k, a in arrays.items():
            want = full + (4,) if k == "link" else full
            if a.shape != want:
                raise FormatError(f"{path}: {k} has shape {a.shape}, expected {want}")
        if "reachable" not in arrays:  # files written before regions existed
            arrays["reachable"] = arrays["valid"].copy()
        height = arrays.get("height")
        link = arrays.get("link")
        levels = 1 if v.ndim == 2 else v.shape[0]
        if link is not None and ((link < -1) | (link >= levels)).any():
            raise FormatError(f"{path}: link holds levels outside -1 .. {levels - 1}")
        return cls(
            origin, cell, shape, arrays["valid"].astype(bool),
            *(arrays[k].astype(np.int32) for k in ("row_index", "row_total", "col_index", "col_total")),
            arrays["reachable"].astype(bool),
            height=None if height is None else height.astype(np.float64),
            link=None if link is None else link.astype(np.int8),
        )


# ====================================================================== geometry
def node_coords(origin: float, cell: float, n: int) -> np.ndarray:
    """Coordinates of n node centres along one axis.  Both classifiers use these."""
    return origin + (np.arange(n) + 0.5) * cell


def grid_shape(bounds: np.ndarray, cell: float) -> tuple[int, int]:
    """(nz, nx) for cells of size ``cell`` covering ``bounds``; refuses absurd grids."""
    b = np.asarray(bounds, dtype=np.float64).reshape(2, 2)
    if not (math.isfinite(cell) and cell > 0):
        raise ArenaError(f"cell must be a positive number of metres, got {cell}")
    ext = b[1] - b[0]
    if not (ext > 0).all():
        raise ArenaError(f"arena bounds {b.tolist()} have no area")
    nxf, nzf = ext / cell
    if nxf * nzf > MAX_NODES:
        raise ArenaError(
            f"cell {cell} m over {ext[0]:g} x {ext[1]:g} m makes {nxf * nzf:,.0f} nodes "
            f"(limit {MAX_NODES:,}); use a larger --cell"
        )
    # a whisker of tolerance so that 20 m / 0.5 m is 40 cells, not 41
    nx = max(1, int(math.ceil(nxf - 1e-9)))
    nz = max(1, int(math.ceil(nzf - 1e-9)))
    return (nz, nx)


def on_wall_tolerance(bounds: np.ndarray) -> float:
    """Nodes closer than this to a wall count as on it (never valid)."""
    b = np.asarray(bounds, dtype=np.float64).reshape(2, 2)
    return 1e-9 * max(1.0, float(np.max(np.abs(b))))


def _oriented(walls: WallList) -> tuple[np.ndarray, np.ndarray]:
    """Wall end points (A, B) swapped where needed so free space is on the left of A->B."""
    s = walls.segments
    flip = walls.direction < 0
    A = np.where(flip[:, None], s[:, 1], s[:, 0])
    B = np.where(flip[:, None], s[:, 0], s[:, 1])
    return A, B


def open_ends(walls: WallList) -> np.ndarray:
    """(k, 2) vertices where the oriented walls do not close up.

    With free space on the left of every wall, each vertex of a closed, consistently
    oriented wall set has as many walls leaving it as arriving.  Zero-length walls
    are ignored.
    """
    A, B = _oriented(walls)
    keep = np.any(A != B, axis=1)
    A, B = A[keep], B[keep]
    if len(A) == 0:
        return np.zeros((0, 2))
    pts = np.concatenate([A, B])
    verts, inv = np.unique(pts, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    bal = np.bincount(inv[: len(A)], minlength=len(verts)) - np.bincount(inv[len(A):], minlength=len(verts))
    return verts[bal != 0]


# ================================================================ free space
def row_crossings(A: np.ndarray, B: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Crossings of oriented walls with the horizontal lines ``z`` (ascending).

    Returns ``(row, x, sign)``: for each crossing, the index into ``z``, where it
    crosses, and +1 when walking +x crosses the wall along its normal.  Half-open
    rule: a wall crosses line z when exactly one end point has ``z_end > z``.
    """
    lo = np.minimum(A[:, 1], B[:, 1])
    hi = np.maximum(A[:, 1], B[:, 1])
    # rows with lo <= z < hi, i.e. exactly one end strictly above
    r0 = np.searchsorted(z, lo, side="left")
    r1 = np.searchsorted(z, hi, side="left")
    cnt = np.maximum(r1 - r0, 0)
    w = np.repeat(np.arange(len(A)), cnt)
    row = np.repeat(r0, cnt) + _ramp(cnt)
    a, b, zz = A[w], B[w], z[row]
    x = a[:, 0] + (zz - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    # free space on the left of a->b: going up (b above) the left is -x, so walking +x
    # crosses against the normal
    sign = np.where(b[:, 1] > zz, -1, 1).astype(np.int32)
    return row, x, sign


def free_space(walls: WallList, origin: np.ndarray, cell: float, shape: tuple[int, int], rows: slice = slice(None)) -> np.ndarray:
    """Free-space mask of the nodes of ``rows`` by the row-scan count (from both ends)."""
    nz, nx = shape
    z = node_coords(origin[1], cell, nz)[rows]
    x_nodes = node_coords(origin[0], cell, nx)
    A, B = _oriented(walls)
    row, x, sign = row_crossings(A, B, z)
    # +sign for every node strictly right of the crossing: scatter at the first such
    # node and take a running sum along the row
    j = np.searchsorted(x_nodes, x, side="right")
    acc = np.bincount(row * (nx + 1) + j, weights=sign, minlength=len(z) * (nx + 1))
    acc = acc.reshape(len(z), nx + 1).astype(np.int32)
    left = np.cumsum(acc, axis=1)
    total = left[:, -1:]
    left = left[:, :nx]
    # walking in from the +x end the count is sum(-sign) over crossings right of the node
    right = left - total
    return (left > 0) & (right > 0)


# ================================================================= clearance
def _ramp(cnt: np.ndarray) -> np.ndarray:
    """0, 1, .., cnt[0]-1, 0, 1, .., cnt[1]-1, ...: positions inside repeated blocks."""
    total = int(cnt.sum())
    return np.arange(total) - np.repeat(np.cumsum(cnt) - cnt, cnt)


def _capsule_pairs(A: np.ndarray, B: np.ndarray, R: float, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(wall, row) for every row whose line may meet the wall's capsule of radius R."""
    zlo = np.minimum(A[:, 1], B[:, 1]) - R
    zhi = np.maximum(A[:, 1], B[:, 1]) + R
    r0 = np.searchsorted(z, zlo, side="left")
    r1 = np.searchsorted(z, zhi, side="right")
    cnt = np.maximum(r1 - r0, 0)
    return np.repeat(np.arange(len(A)), cnt), np.repeat(r0, cnt) + _ramp(cnt)


def _capsule_chords(a: np.ndarray, b: np.ndarray, zz: np.ndarray, R: float) -> tuple[np.ndarray, np.ndarray]:
    """x-interval [lo, hi] where the line z = zz meets the capsule of radius R around
    segment a-b (all arrays per pair); lo > hi when it misses."""
    lo = np.full(len(zz), np.inf)
    hi = np.full(len(zz), -np.inf)
    for p in (a, b):  # end discs
        dz = zz - p[:, 1]
        h2 = R * R - dz * dz
        ok = h2 >= 0
        h = np.sqrt(np.where(ok, h2, 0.0))
        lo = np.where(ok, np.minimum(lo, p[:, 0] - h), lo)
        hi = np.where(ok, np.maximum(hi, p[:, 0] + h), hi)
    # the band between: 0 <= s <= 1 along the wall and |u| <= R across it, both linear in x:
    # s = c1 + (x - ax) dx / L2,  u = c2 - (x - ax) dz / L
    d = b - a
    L2 = d[:, 0] ** 2 + d[:, 1] ** 2
    L = np.sqrt(L2)
    with np.errstate(divide="ignore", invalid="ignore"):
        c1 = (zz - a[:, 1]) * d[:, 1] / L2
        c2 = (zz - a[:, 1]) * d[:, 0] / L
        s_lo = a[:, 0] + (0 - c1) * L2 / d[:, 0]
        s_hi = a[:, 0] + (1 - c1) * L2 / d[:, 0]
        u_lo = a[:, 0] + (R - c2) * L / -d[:, 1]
        u_hi = a[:, 0] + (-R - c2) * L / -d[:, 1]
    s_a, s_b = np.minimum(s_lo, s_hi), np.maximum(s_lo, s_hi)
    s_all = (c1 >= 0) & (c1 <= 1)
    s_flat = d[:, 0] == 0
    s_a = np.where(s_flat, np.where(s_all, -np.inf, np.inf), s_a)
    s_b = np.where(s_flat, np.where(s_all, np.inf, -np.inf), s_b)
    u_a, u_b = np.minimum(u_lo, u_hi), np.maximum(u_lo, u_hi)
    u_all = np.abs(c2) <= R
    u_flat = d[:, 1] == 0
    u_a = np.where(u_flat, np.where(u_all, -np.inf, np.inf), u_a)
    u_b = np.where(u_flat, np.where(u_all, np.inf, -np.inf), u_b)
    band_lo = np.maximum(s_a, u_a)
    band_hi = np.minimum(s_b, u_b)
    band = (L > 0) & (band_lo <= band_hi)
    lo = np.where(band, np.minimum(lo, band_lo), lo)
    hi = np.where(band, np.maximum(hi, band_hi), hi)
    return lo, hi


def too_close(
    segments: np.ndarray, origin: np.ndarray, cell: float, shape: tuple[int, int], clearance: float,
    rows: slice = slice(None), tol: float = 0.0,
) -> np.ndarray:
    """Nodes of ``rows`` whose distance to some wall is < clearance (or <= tol).

    Exact with respect to the distance kernel: on each row, the nodes well inside a
    wall's capsule (its chord for a radius shrunk by 1e-7, far beyond rounding) are
    marked at once; the few nodes near the chord's ends (the chord for a radius grown
    a hair, widened by one node each side) are decided by the kernel itself.
    """
    nz, nx = shape
    z = node_coords(origin[1], cell, nz)[rows]
    x_nodes = node_coords(origin[0], cell, nx)
    out = np.zeros((len(z), nx), dtype=bool)
    seg = np.asarray(segments, dtype=np.float64).reshape(-1, 2, 2)
    R = max(float(clearance), tol)
    if len(seg) == 0 or len(z) == 0:
        return out
    w, row = _capsule_pairs(seg[:, 0], seg[:, 1], R * (1 + 1e-9) + 1e-7 * cell, z)
    a, b, zz = seg[w, 0], seg[w, 1], z[row]
    olo, ohi = _capsule_chords(a, b, zz, R * (1 + 1e-9) + 1e-7 * cell)
    ilo, ihi = _capsule_chords(a, b, zz, R * (1 - 1e-7))
    j0 = np.clip(np.searchsorted(x_nodes, olo, side="left") - 1, 0, nx)
    j1 = np.clip(np.searchsorted(x_nodes, ohi, side="right") + 1, 0, nx)
    j1 = np.maximum(j1, j0)
    # interior [k0, k1): nodes inside the shrunk chord, clipped into [j0, j1]
    k0 = np.clip(np.searchsorted(x_nodes, ilo, side="left"), j0, j1)
    k1 = np.clip(np.searchsorted(x_nodes, ihi, side="right"), j0, j1)
    inner = k1 > k0
    k0 = np.where(inner, k0, j1)
    k1 = np.where(inner, k1, j1)
    # mark interiors with a running sum of +1/-1 per row
    if inner.any():
        m = nx + 1
        acc = np.bincount(row[inner] * m + k0[inner], minlength=len(z) * m)
        acc -= np.bincount(row[inner] * m + k1[inner], minlength=len(z) * m)
        out |= np.cumsum(acc.reshape(len(z), m), axis=1)[:, :nx] > 0
    # kernel on the two edge pieces [j0, k0) and [k1, j1)
    for lo_, hi_ in ((j0, k0), (k1, j1)):
        cnt = np.maximum(hi_ - lo_, 0)
        sel = cnt > 0
        if not sel.any():
            continue
        cnt_s = cnt[sel]
        ww = np.repeat(w[sel], cnt_s)
        rr = np.repeat(row[sel], cnt_s)
        jj = np.repeat(lo_[sel], cnt_s) + _ramp(cnt_s)
        p = np.stack([x_nodes[jj], z[rr]], axis=1)
        d2 = point_segment_dist2(p, seg[ww, 0], seg[ww, 1])
        hit = (d2 < clearance * clearance) | (d2 <= tol * tol)
        out[rr[hit], jj[hit]] = True
    return out


# ================================================================ classifiers
def classify(
    walls: WallList, origin: np.ndarray, cell: float, shape: tuple[int, int], clearance: float,
    progress: Callable[[int], None] | None = None, band_nodes: int = 1_000_000,
) -> np.ndarray:
    """Valid-node mask (the fast default): row-scan free space minus the wall capsules.

    Rows are processed in bands of about ``band_nodes`` nodes; ``progress(rows_done)``
    is called after each band.
    """
    nz, nx = shape
    tol = on_wall_tolerance(walls.bounds)
    valid = np.empty(shape, dtype=bool)
    step = max(1, band_nodes // max(nx, 1))
    for r0 in range(0, nz, step):
        rows = slice(r0, min(nz, r0 + step))
        valid[rows] = free_space(walls, origin, cell, shape, rows) & ~too_close(
            walls.segments, origin, cell, shape, clearance, rows, tol
        )
        if progress is not None:
            progress(rows.stop - rows.start)
    return valid


# ====================================================================== runs
def _runs_along_last_axis(valid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """1-based index of each valid node in its run along the last axis, and run length."""
    m, n = valid.shape
    v = np.zeros((m, n + 2), dtype=np.int8)
    v[:, 1:-1] = valid  # False borders keep runs from spilling across lines
    d = np.diff(v.ravel())
    starts = np.flatnonzero(d == 1)  # index (in the padded flat array) of a run's first node, minus 1
    ends = np.flatnonzero(d == -1)
    lengths = ends - starts
    where = np.flatnonzero(v.ravel())
    index = np.zeros(v.size, dtype=np.int32)
    total = np.zeros(v.size, dtype=np.int32)
    index[where] = _ramp(lengths) + 1
    total[where] = np.repeat(lengths, lengths)
    return index.reshape(m, n + 2)[:, 1:-1], total.reshape(m, n + 2)[:, 1:-1]


def runs(valid: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(row_index, row_total, col_index, col_total) of a valid mask (the paper's numbering).

    Row runs go along +x (j increasing), column runs along +z (i increasing).
    """
    ri, rt = _runs_along_last_axis(valid)
    ci, ct = _runs_along_last_axis(valid.T)
    return ri, rt, np.ascontiguousarray(ci.T), np.ascontiguousarray(ct.T)


def links_from_valid(valid: np.ndarray) -> np.ndarray:
    """``(L, nz, nx, 4)`` links of a grid without heights: a step joins two valid
    nodes of the same level."""
    v = np.asarray(valid, dtype=bool)
    L, nz, nx = v.shape
    pad = np.zeros((L, nz + 2, nx + 2), dtype=bool)
    pad[:, 1:-1, 1:-1] = v
    out = np.full((L, nz, nx, 4), -1, dtype=np.int8)
    lev = np.arange(L, dtype=np.int8)[:, None, None]
    for d, (di, dj) in enumerate(STEPS.values()):
        nb = pad[:, 1 + di:1 + di + nz, 1 + dj:1 + dj + nx]
        out[..., d] = np.where(v & nb, lev, -1)
    return out


def layered_runs(valid: np.ndarray, link: np.ndarray) -> tuple[np.ndarray, ...]:
    """(row_index, row_total, col_index, col_total) of a layered grid, per level: a row
    run goes along +x over valid nodes of one level each linked to the next on the same
    level; a column run likewise along +z."""
    L = valid.shape[0]
    lev = np.arange(L)[:, None, None]
    out = []
    for axis, d in ((2, 0), (1, 1)):  # rows along +x (step 0), columns along +z (step 1)
        joined = valid & (link[..., d] == lev)  # node continues its run to the next one
        v = valid if axis == 2 else valid.transpose(0, 2, 1)
        jn = joined if axis == 2 else joined.transpose(0, 2, 1)
        idx, tot = _runs_joined(v.reshape(-1, v.shape[2]), jn.reshape(-1, v.shape[2]))
        idx, tot = idx.reshape(v.shape), tot.reshape(v.shape)
        if axis == 1:
            idx, tot = idx.transpose(0, 2, 1), tot.transpose(0, 2, 1)
        out += [np.ascontiguousarray(idx), np.ascontiguousarray(tot)]
    return out[0], out[1], out[2], out[3]


#: rows of _runs_joined worked on at once (about this many nodes): its temporaries are
#: ~60 bytes a node, which on a whole large grid was the import's peak
RUN_BLOCK = 1 << 20


def _runs_joined(valid: np.ndarray, joined: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Runs along the last axis where each node's run continues to the next node only
    when ``joined`` (and that node is valid); rows are independent, so they are worked
    on in blocks of about RUN_BLOCK nodes."""
    m, n = valid.shape
    step = max(1, RUN_BLOCK // max(n, 1))
    if m <= step:
        return _runs_block(valid, joined)
    index = np.empty((m, n), dtype=np.int32)
    total = np.empty((m, n), dtype=np.int32)
    for a in range(0, m, step):
        index[a:a + step], total[a:a + step] = _runs_block(valid[a:a + step], joined[a:a + step])
    return index, total


def _runs_block(valid: np.ndarray, joined: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    m, n = valid.shape
    cont = np.zeros((m, n), dtype=bool)
    cont[:, :-1] = joined[:, :-1] & valid[:, 1:]
    start = valid.copy()
    start[:, 1:] &= ~cont[:, :-1]
    flat_v = valid.ravel()
    flat_s = start.ravel()
    run_id = np.cumsum(flat_s) - 1
    lengths = np.bincount(run_id[flat_v], minlength=int(flat_s.sum())) if flat_v.any() else np.zeros(0, dtype=np.int64)
    first = np.flatnonzero(flat_s)
    pos = np.arange(flat_v.size)
    index = np.zeros(flat_v.size, dtype=np.int32)
    total = np.zeros(flat_v.size, dtype=np.int32)
    index[flat_v] = (pos[flat_v] - first[run_id[flat_v]] + 1)
    total[flat_v] = lengths[run_id[flat_v]]
    return index.reshape(m, n), total.reshape(m, n)


def compiled_labels(valid: np.ndarray, link: np.ndarray) -> tuple[np.ndarray, int] | None:
    """(labels, k): the components of a layered grid's valid nodes over its links
    (either way), int32 (L, nz, nx) numbered 1..k in the order of each one's first node
    as scipy numbers them, 0 off the valid nodes -- by the compiled union-find over the
    grid (4 bytes a node, where index pairs and scipy's graph take ~70); None without
    the compiled kernels (callers then use scipy)."""
    from ..geometry.kernels import active

    kern = active()
    if kern is None or valid.size >= 2**31 or link.dtype != np.int8:
        return None
    L, nz, nx = valid.shape
    out = np.empty(valid.shape, dtype=np.int32)
    k = kern.grid_labels(np.ascontiguousarray(valid, dtype=bool), np.ascontiguousarray(link), L, nz, nx, out)
    return out, int(k)


def layered_reachable(valid: np.ndarray, link: np.ndarray, seeds: list) -> np.ndarray:
    """Valid nodes connected through links to any seed node ``(level, i, j)``."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    L, nz, nx = valid.shape
    n = valid.size
    if not seeds:
        return valid.copy()
    compiled = compiled_labels(valid, link)
    if compiled is not None:
        label = compiled[0]
        keep = np.unique([label[s] for s in seeds])
        return np.isin(label, keep[keep > 0])
    src, dst = [], []
    base = np.arange(n).reshape(L, nz, nx)
    for d, (di, dj) in enumerate(STEPS.values()):
        lv = link[..., d]
        ok = valid & (lv >= 0)
        l_, i_, j_ = np.nonzero(ok)
        ii, jj = i_ + di, j_ + dj
        inside = (ii >= 0) & (ii < nz) & (jj >= 0) & (jj < nx)
        l_, i_, j_, ii, jj = l_[inside], i_[inside], j_[inside], ii[inside], jj[inside]
        tl = lv[l_, i_, j_].astype(np.int64)
        good = valid[tl, ii, jj]
        src.append(base[l_, i_, j_][good])
        dst.append(base[tl, ii, jj][good])
    src_a = np.concatenate(src) if src else np.zeros(0, dtype=np.int64)
    dst_a = np.concatenate(dst) if dst else np.zeros(0, dtype=np.int64)
    g = coo_matrix((np.ones(len(src_a), dtype=np.int8), (src_a, dst_a)), shape=(n, n))
    _, label = connected_components(g, directed=True, connection="weak")
    label = label.reshape(L, nz, nx)
    keep = np.unique([label[s] for s in seeds])
    return valid & np.isin(label, keep)


def nearest_valid_node3(valid: np.ndarray, height: np.ndarray, x_node: tuple[int, int], y: float | None,
                        max_steps: int) -> tuple[int, int, int] | None:
    """The valid node ``(level, i, j)`` nearest to column ``x_node`` within ``max_steps``
    (ties and, when ``y`` is given, the level by the smallest height difference)."""
    L = valid.shape[0]
    best = None
    for lv in range(L):
        n = nearest_valid_node(valid[lv], x_node, max_steps)
        if n is None:
            continue
        d = (n[0] - x_node[0]) ** 2 + (n[1] - x_node[1]) ** 2
        dy = abs(float(height[lv, n[0], n[1]]) - y) if y is not None and np.isfinite(height[lv, n[0], n[1]]) else 0.0
        key = (d, dy)
        if best is None or key < best[0]:
            best = (key, (lv, n[0], n[1]))
    return None if best is None else best[1]


# =================================================================== regions
def nearest_valid_node(valid: np.ndarray, node: Node, max_steps: int) -> Node | None:
    """The valid node nearest to ``node`` (Euclidean in nodes) within ``max_steps``."""
    i, j = node
    nz, nx = valid.shape
    i0, i1 = max(0, i - max_steps), min(nz, i + max_steps + 1)
    j0, j1 = max(0, j - max_steps), min(nx, j + max_steps + 1)
    win = valid[i0:i1, j0:j1]
    if not win.any():
        return None
    a, b = np.nonzero(win)
    d = (a + i0 - i) ** 2 + (b + j0 - j) ** 2
    k = int(np.argmin(d))
    return (int(a[k] + i0), int(b[k] + j0))


def reachable_from(valid: np.ndarray, seeds: list[Node]) -> np.ndarray:
    """Valid nodes 4-connected to any seed (8-connected moves without corner cutting
    connect exactly the same nodes)."""
    from scipy import ndimage

    if not seeds:
        return valid.copy()
    labels, _ = ndimage.label(valid)
    keep = np.unique([labels[s] for s in seeds])
    keep = keep[keep > 0]
    return np.isin(labels, keep)


# ===================================================================== build
def build_navgrid(
    walls: WallList, cell: float, clearance: float, spawns: np.ndarray | None = None,
    bounds: np.ndarray | None = None, reference: bool = False,
    progress: Callable[[int], None] | None = None,
) -> NavGrid:
    """Classify, number the runs and mark the regions reachable from the spawn points.

    walls : the arena's walls (auxiliary rectangle = default bounds)
    cell, clearance : metres
    spawns : (k, 2+) spawn points ``[x, z, ...]``; each seeds the region of its
             nearest valid node (within the clearance plus two cells).  None or empty:
             every valid node counts as reachable.
    reference : use the 2002 classifier instead of the fast one (slow).
    progress : called with the number of rows just classified.
    """
    if not (math.isfinite(clearance) and clearance >= 0):
        raise ArenaError(f"clearance must be >= 0 metres, got {clearance}")
    b = walls.bounds if bounds is None else np.asarray(bounds, dtype=np.float64).reshape(2, 2)
    shape = grid_shape(b, cell)
    origin = b[0].copy()
    if reference:
        from .reference2002 import classify_reference

        valid = classify_reference(walls, origin, cell, shape, clearance)
        if progress is not None:
            progress(shape[0])
    else:
        valid = classify(walls, origin, cell, shape, clearance, progress=progress)
    ri, rt, ci, ct = runs(valid)
    seeds: list[Node] = []
    reachable = valid.copy()
    if spawns is not None and len(spawns):
        reach = int(math.ceil(clearance / cell)) + 2
        for s in np.asarray(spawns, dtype=np.float64).reshape(len(spawns), -1):
            n = nearest_valid_node(valid, _node_at(origin, cell, shape, s[0], s[1]), reach)
            if n is not None:
                seeds.append(n)
        reachable = reachable_from(valid, seeds) if seeds else np.zeros_like(valid)
    # the (nz, nx) arrays of the 2002 classifier are level 0 of the grid
    return NavGrid(origin, float(cell), shape, valid, ri, rt, ci, ct, reachable, float(clearance), spawn_nodes=seeds)


def _node_at(origin: np.ndarray, cell: float, shape: tuple[int, int], x: float, z: float) -> Node:
    """The node whose cell holds (x, z), clamped into a grid of ``shape`` (NavGrid.node_of)."""
    j = math.floor((x - float(origin[0])) / cell)
    i = math.floor((z - float(origin[1])) / cell)
    return (min(max(i, 0), shape[0] - 1), min(max(j, 0), shape[1] - 1))


def grid_from_mask(valid: np.ndarray, origin: tuple[float, float] = (0.0, 0.0), cell: float = 1.0) -> NavGrid:
    """A NavGrid from a hand-made valid mask (rows = z, columns = x); all reachable."""
    v = np.asarray(valid, dtype=bool)
    ri, rt, ci, ct = runs(v)
    return NavGrid(np.asarray(origin, dtype=np.float64), float(cell), v.shape, v, ri, rt, ci, ct, v.copy())


# ===================================================================== table
def format_table(grid: NavGrid, region: np.ndarray | None = None) -> str:
    """The 2002-style table, one node a line: position, validity and the four numbers.

    ``region`` ``[[x0, z0], [x1, z1]]`` keeps only the nodes inside it.  On a grid of
    several levels every line starts with the node's level (level by level); a
    one-level grid's table is the 2002 one, without that column.
    """
    lv, i, j = np.nonzero(np.ones(grid.valid.shape, dtype=bool))
    x = grid.node_x[j]
    z = grid.node_z[i]
    if region is not None:
        r = np.asarray(region, dtype=np.float64).reshape(2, 2)
        keep = (x >= r[0, 0]) & (x <= r[1, 0]) & (z >= r[0, 1]) & (z <= r[1, 1])
        lv, i, j, x, z = lv[keep], i[keep], j[keep], x[keep], z[keep]
    many = grid.levels > 1
    head = [
        "# tanktool navigation grid: one node a line (the 2002 'malla' table)",
        f"# origin {grid.origin[0]:g} {grid.origin[1]:g}  cell {grid.cell:g}  shape nz={grid.nz} nx={grid.nx}"
        + (f"  levels {grid.levels}" if many else ""),
        "# renglon/columna = 1-based index of the node in its row/column run of valid nodes,",
        "# total = that run's length (0 for invalid nodes); rows run along +x, columns along +z",
        "# " + ("level " if many else "") + "i j x z valid reachable renglon columna total_renglones total_columnas",
    ]
    n = (lv, i, j)
    cols = [
        i, j, x, z, grid.valid[n].astype(int), grid.reachable[n].astype(int),
        grid.row_index[n], grid.col_index[n], grid.row_total[n], grid.col_total[n],
    ]
    body = [
        f"{a} {b} {c:.4f} {d:.4f} {e} {f} {g} {h} {k} {m}"
        for a, b, c, d, e, f, g, h, k, m in zip(*(c.tolist() for c in cols))
    ]
    if many:
        body = [f"{a} {line}" for a, line in zip(lv.tolist(), body)]
    return "\n".join(head + body) + "\n"
