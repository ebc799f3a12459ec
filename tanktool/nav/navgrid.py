"""The AI navigation grid (the 2002 "malla"): valid nodes, runs, reachable regions.

Nodes sit at cell centres over the arena bounds: node (i, j) is at
``x = origin_x + (j + 1/2) cell``, ``z = origin_z + (i + 1/2) cell``; a row (index i)
is a line of constant z, a column (index j) one of constant x.

**Free space** and the **valid** nodes (the two classifiers, the clearance): see
:mod:`tanktool.nav.free_space`, whose functions this module re-exports.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import ArenaError, FormatError
from ..formats.walls_txt import WallList
# the free space and clearance of the walls (free_space.py): re-exported, callers import them from here
from .free_space import (_ramp, classify, free_space, node_coords, on_wall_tolerance, open_ends,  # noqa: F401
                         row_crossings, too_close)

#: refuse grids larger than this (nodes); 25 M nodes is ~300 MB of arrays
MAX_NODES = 25_000_000
#: refuse grids of more levels than this
MAX_LEVELS = 64
_FIELDS = ("valid", "row_index", "row_total", "col_index", "col_total", "reachable")
_RUN_FIELDS = _FIELDS[1:5]

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
        2002 grids' format, unchanged since before levels existed).  The run numbers
        are int16 when the grid's sides allow (a run is at most a side long) and the
        column runs are stored column-major: the loader reads them back as int32."""
        from ..formats.npz import write_npz

        runs = np.int16 if max(self.shape) <= np.iinfo(np.int16).max else np.int32
        arrays = {k: getattr(self, k) if k not in _RUN_FIELDS else getattr(self, k).astype(runs) for k in _FIELDS}
        arrays["height"] = np.asarray(self.heights(), dtype=np.float32)
        if self.link is not None:
            arrays["link"] = np.asarray(self.link, dtype=np.int8)
        if self.levels == 1:
            arrays = {k: a[0] for k, a in arrays.items()}
        return write_npz({"origin": np.asarray(self.origin, dtype=np.float64), "cell": np.array(float(self.cell)),
                          "shape": np.array(self.shape, dtype=np.int64), **arrays},
                         fortran=("col_index", "col_total"))

    @classmethod
    def load(cls, path: str | os.PathLike, runs: bool = True) -> "NavGrid":
        """Read a ``navgrid.npz``; anything malformed raises FormatError naming the file.
        ``runs=False``: without the four run arrays (None; the simulation's ground reads
        heights and links only: 256 MB of a 2 km terrain's file not read)."""
        import zipfile
        import zlib

        from ..formats.npz import read_npz

        try:
            skip = () if runs else _RUN_FIELDS
            # bounded, no pickles, a damaged zip one clear error
            z = read_npz(path, "a navgrid file", skip=skip)
            missing = [k for k in ("origin", "cell", "shape", *_FIELDS[:-1]) if k not in z and k not in skip]
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
        # copy=False: arrays already of their type are kept, not copied (a 2 km terrain's
        # grid was read twice over at once: the load's peak of a match on it); runs
        # written int16 and column-major (to_bytes) come back int32 and C-ordered
        return cls(
            origin, cell, shape, arrays.pop("valid").astype(bool, copy=False),
            *(np.ascontiguousarray(arrays.pop(k), dtype=np.int32) if runs else None for k in _RUN_FIELDS),
            arrays.pop("reachable").astype(bool, copy=False),
            height=None if height is None else height.astype(np.float64, copy=False),
            link=None if link is None else link.astype(np.int8, copy=False),
        )


# ====================================================================== geometry
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
    from ..geometry.kernels import active

    L, nz, nx = valid.shape
    kern = active()
    if kern is not None and link.dtype == np.int8 and L <= 127:  # one pass a line, no temporaries
        out = [np.empty(valid.shape, dtype=np.int32) for _ in range(4)]
        kern.grid_runs(np.ascontiguousarray(valid, dtype=bool), np.ascontiguousarray(link), L, nz, nx, *out)
        return out[0], out[1], out[2], out[3]
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


def layered_labels(valid: np.ndarray, link: np.ndarray) -> tuple[np.ndarray, int]:
    """(labels, k): the components of a layered grid's valid nodes over its links
    (either way), numbered 1..k in the order of each one's first node, 0 off the valid
    nodes: :func:`compiled_labels`, else scipy's connected components (the same numbers)."""
    compiled = compiled_labels(valid, link)
    if compiled is not None:
        return compiled
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    L, nz, nx = valid.shape
    ids = np.full(valid.shape, -1, dtype=np.int64)
    pts = np.nonzero(valid)
    ids[pts] = np.arange(len(pts[0]))
    src, dst = [], []
    for d, (di, dj) in enumerate(STEPS.values()):
        l_, i_, j_ = pts
        t = link[l_, i_, j_, d].astype(np.int64)
        ii, jj = i_ + di, j_ + dj
        ok = (t >= 0) & (ii >= 0) & (ii < nz) & (jj >= 0) & (jj < nx)
        to = ids[t[ok], ii[ok], jj[ok]]
        src.append(ids[l_[ok], i_[ok], j_[ok]][to >= 0])
        dst.append(to[to >= 0])
    s, t = np.concatenate(src), np.concatenate(dst)
    n = len(pts[0])
    k, lab = connected_components(coo_matrix((np.ones(len(s), dtype=np.int8), (s, t)), shape=(n, n)),
                                  directed=True, connection="weak")
    labels = np.zeros(valid.shape, dtype=np.int32)
    labels[pts] = lab + 1
    return labels, int(k)


def layered_reachable(valid: np.ndarray, link: np.ndarray, seeds: list) -> np.ndarray:
    """Valid nodes connected through links to any seed node ``(level, i, j)``."""
    if not seeds:
        return valid.copy()
    label = layered_labels(valid, link)[0]
    keep = np.unique([label[s] for s in seeds])
    keep = keep[keep > 0]
    if len(keep) > 32:
        return np.isin(label, keep)
    # a comparison per seed's component: 1 byte a node at a time, where isin's table
    # lookup took ~12 (the same nodes)
    out = np.zeros(valid.shape, dtype=bool)
    for k in keep:
        out |= label == k
    return out


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
