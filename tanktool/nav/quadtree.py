"""The wall quadtree of the 2002 design (§3.4.4.1), plus an adaptive variant.

The root covers the arena (the auxiliary rectangle); each node splits into four
children, down to a fixed depth (default 3: A, B, C levels, 64 leaves).  Every wall is
stored in every leaf it actually crosses: segment-box clipping (Liang-Barsky), not
just the leaves of its end points.  ``WallQuadtree.adaptive`` splits a node only while
it holds more than ``max_walls`` walls, up to ``max_depth``.

Nodes are flat arrays (box, first child, depth) and the walls of each node a CSR list,
so every query is a few vectorised passes over (probe, node) pairs, one level at a
time: points, segments and capsules are all "probes".  Children of node k are
``child[k] + q`` for q = 0..3: q & 1 selects the +x half, q >> 1 the +z half.

The broad phase tests boxes grown by a tiny margin so that rounding can never drop a
wall; the narrow phase calls the kernels of :mod:`tanktool.geometry.segments`, the same
ones a brute-force search uses, so results equal brute force exactly.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import FormatError
from ..geometry.segments import (
    point_box_dist2,
    point_segment_dist2,
    segment_hits_box,
    segment_segment_dist2,
    segments_intersect,
)

_FORMAT = "tanktool-quadtree-1"


def _children_boxes(box: np.ndarray) -> np.ndarray:
    """(m, 2, 2) boxes -> (m, 4, 2, 2) quadrants in child order."""
    lo, hi = box[:, 0], box[:, 1]
    mid = 0.5 * (lo + hi)
    out = np.empty((len(box), 4, 2, 2))
    for q in range(4):
        sx, sz = q & 1, q >> 1
        out[:, q, 0, 0] = np.where(sx, mid[:, 0], lo[:, 0])
        out[:, q, 1, 0] = np.where(sx, hi[:, 0], mid[:, 0])
        out[:, q, 0, 1] = np.where(sz, mid[:, 1], lo[:, 1])
        out[:, q, 1, 1] = np.where(sz, hi[:, 1], mid[:, 1])
    return out


def _csr(keys: np.ndarray, values: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Group ``values`` by integer ``keys`` in [0, n): (offsets (n+1,), values sorted)."""
    order = np.argsort(keys, kind="stable")
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(keys, minlength=n), out=offsets[1:])
    return offsets, values[order]


@dataclass
class WallQuadtree:
    """Walls bucketed in a quadtree over the arena.

    segments : (n, 2, 2) the walls, indices into it are what queries return
    box : (N, 2, 2) node boxes ``[[xmin, zmin], [xmax, zmax]]``, node 0 the root
    child : (N,) index of the first of four children, -1 for a leaf
    depth : (N,) 0 for the root
    offsets, walls : CSR of the wall indices stored in each node (leaves only)
    """

    segments: np.ndarray
    box: np.ndarray
    child: np.ndarray
    depth: np.ndarray
    offsets: np.ndarray
    walls: np.ndarray
    eps: float = 0.0

    # ------------------------------------------------------------------ building
    @classmethod
    def build(cls, segments: np.ndarray, bounds: np.ndarray, depth: int = 3) -> "WallQuadtree":
        """A full tree of the given depth (``4**depth`` leaves), as in the 2002 design."""
        if depth < 0 or depth > 12:
            raise ValueError(f"quadtree depth must be 0..12, got {depth}")
        return cls._grow(segments, bounds, lambda d, count: d < depth)

    @classmethod
    def adaptive(
        cls, segments: np.ndarray, bounds: np.ndarray, max_walls: int = 8, max_depth: int = 8
    ) -> "WallQuadtree":
        """Split a node while it holds more than ``max_walls`` walls, up to ``max_depth``."""
        if max_walls < 1:
            raise ValueError(f"max_walls must be >= 1, got {max_walls}")
        if max_depth < 0 or max_depth > 16:
            raise ValueError(f"max_depth must be 0..16, got {max_depth}")
        return cls._grow(segments, bounds, lambda d, count: (d < max_depth) & (count > max_walls))

    @classmethod
    def _grow(
        cls, segments: np.ndarray, bounds: np.ndarray, split: Callable[[np.ndarray, np.ndarray], np.ndarray]
    ) -> "WallQuadtree":
        seg = np.asarray(segments, dtype=np.float64).reshape(-1, 2, 2)
        b = np.asarray(bounds, dtype=np.float64).reshape(2, 2)
        # the root covers the bounds and every wall, so no wall is ever lost
        pts = np.concatenate([b, seg.reshape(-1, 2)])
        root = np.array([pts.min(axis=0), pts.max(axis=0)])
        span = float(np.max(root[1] - root[0])) if len(pts) else 1.0
        eps = 1e-9 * max(span, 1.0)
        if not (root[1] > root[0]).all():  # degenerate extent: give it some area
            root[1] = np.maximum(root[1], root[0] + max(span, 1.0))

        boxes = [root[None]]
        children = [np.full(1, -1, dtype=np.int64)]
        depths = [np.zeros(1, dtype=np.int64)]
        # (node, wall) pairs of the current level
        pn = np.zeros(len(seg), dtype=np.int64)
        pw = np.arange(len(seg), dtype=np.int64)
        level_first, level_boxes = 0, root[None]
        total = 1
        leaf_nodes: list[np.ndarray] = []
        leaf_walls: list[np.ndarray] = []
        d = 0
        while True:
            m = len(level_boxes)
            count = np.bincount(pn - level_first, minlength=m)
            splitting = np.asarray(split(np.full(m, d), count), dtype=bool)
            # pairs of nodes that stay leaves are final
            keep = ~splitting[pn - level_first]
            leaf_nodes.append(pn[keep])
            leaf_walls.append(pw[keep])
            idx = np.flatnonzero(splitting)
            if len(idx) == 0:
                break
            first = total + 4 * np.arange(len(idx))
            children[-1][idx] = first
            kid_boxes = _children_boxes(level_boxes[idx]).reshape(-1, 2, 2)
            # renumber: the k-th split node's children are new-level nodes 4k..4k+3
            rank = np.full(m, -1, dtype=np.int64)
            rank[idx] = np.arange(len(idx))
            sp = ~keep
            r = rank[pn[sp] - level_first]
            w = pw[sp]
            cand_node = (4 * r[:, None] + np.arange(4)).reshape(-1)
            cand_wall = np.repeat(w, 4)
            kb = kid_boxes[cand_node]
            hit = segment_hits_box(seg[cand_wall, 0], seg[cand_wall, 1], kb[:, 0] - eps, kb[:, 1] + eps)
            level_first = total
            pn = level_first + cand_node[hit]
            pw = cand_wall[hit]
            level_boxes = kid_boxes
            total += len(kid_boxes)
            boxes.append(kid_boxes)
            children.append(np.full(len(kid_boxes), -1, dtype=np.int64))
            depths.append(np.full(len(kid_boxes), d + 1, dtype=np.int64))
            d += 1
        node = np.concatenate(leaf_nodes)
        wall = np.concatenate(leaf_walls)
        offsets, walls = _csr(node, wall, total)
        return cls(seg, np.concatenate(boxes), np.concatenate(children), np.concatenate(depths), offsets, walls, eps)

    # ----------------------------------------------------------------- properties
    @property
    def leaves(self) -> np.ndarray:
        """Indices of the leaf nodes."""
        return np.flatnonzero(self.child < 0)

    @property
    def max_depth(self) -> int:
        return int(self.depth.max())

    def leaf_counts(self) -> np.ndarray:
        """Number of walls stored in each leaf, in the order of :attr:`leaves`."""
        lv = self.leaves
        return self.offsets[lv + 1] - self.offsets[lv]

    def __len__(self) -> int:
        return len(self.box)

    # ------------------------------------------------------------------- queries
    def _descend(self, n_probes: int, touches: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """All (probe, leaf) pairs whose leaf box ``touches`` the probe.

        ``touches(probe_idx, node_idx)`` -> bool, given node boxes grown by ``eps``.
        """
        probe = np.arange(n_probes, dtype=np.int64)
        node = np.zeros(n_probes, dtype=np.int64)
        out_p, out_n = [], []
        while len(probe):
            ok = touches(probe, node)
            probe, node = probe[ok], node[ok]
            leaf = self.child[node] < 0
            out_p.append(probe[leaf])
            out_n.append(node[leaf])
            inner = ~leaf
            probe = np.repeat(probe[inner], 4)
            node = (self.child[node[inner]][:, None] + np.arange(4)).reshape(-1)
        return np.concatenate(out_p), np.concatenate(out_n)

    def _pairs(self, probe: np.ndarray, node: np.ndarray, n_probes: int) -> tuple[np.ndarray, np.ndarray]:
        """Expand (probe, leaf) to unique (probe, wall) pairs sorted by probe then wall."""
        start = self.offsets[node]
        cnt = self.offsets[node + 1] - start
        total = int(cnt.sum())
        if total == 0:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        rep_probe = np.repeat(probe, cnt)
        # position inside each leaf's list: a ramp restarting at each leaf
        ramp = np.arange(total) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        wall = self.walls[np.repeat(start, cnt) + ramp]
        key = np.unique(rep_probe * max(len(self.segments), 1) + wall)
        n = max(len(self.segments), 1)
        return key // n, key % n

    @staticmethod
    def _to_csr(probe: np.ndarray, wall: np.ndarray, n_probes: int) -> tuple[np.ndarray, np.ndarray]:
        offsets = np.zeros(n_probes + 1, dtype=np.int64)
        np.cumsum(np.bincount(probe, minlength=n_probes), out=offsets[1:])
        return offsets, wall  # pairs come sorted by probe already

    def query_points(self, points: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
        """Walls within ``radius`` (distance <= radius) of each point.

        points : (m, 2).  Returns CSR ``(offsets (m+1,), indices)``: the walls of point
        k are ``indices[offsets[k]:offsets[k+1]]``, ascending.
        """
        P = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        r = float(radius)
        if r < 0:
            raise ValueError(f"radius must be >= 0, got {radius}")
        reach = (r + self.eps) ** 2

        def touches(pi, ni):
            b = self.box[ni]
            return point_box_dist2(P[pi], b[:, 0] - self.eps, b[:, 1] + self.eps) <= reach

        pi, wi = self._pairs(*self._descend(len(P), touches), len(P))
        s = self.segments[wi]
        near = point_segment_dist2(P[pi], s[:, 0], s[:, 1]) <= r * r
        return self._to_csr(pi[near], wi[near], len(P))

    def query_point(self, point: np.ndarray, radius: float) -> np.ndarray:
        """Indices (ascending) of the walls within ``radius`` of one point."""
        return self.query_points(np.asarray(point, dtype=np.float64).reshape(1, 2), radius)[1]

    def _segment_pairs(self, A: np.ndarray, B: np.ndarray, grow: float) -> tuple[np.ndarray, np.ndarray]:
        g = grow + self.eps

        def touches(pi, ni):
            b = self.box[ni]
            return segment_hits_box(A[pi], B[pi], b[:, 0] - g, b[:, 1] + g)

        return self._pairs(*self._descend(len(A), touches), len(A))

    def candidates_segments(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Broad phase only: walls stored in the leaves each segment passes through (CSR)."""
        A = np.asarray(a, dtype=np.float64).reshape(-1, 2)
        B = np.asarray(b, dtype=np.float64).reshape(-1, 2)
        pi, wi = self._segment_pairs(A, B, 0.0)
        return self._to_csr(pi, wi, len(A))

    def candidates_segment(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Broad phase only: walls stored in the leaves the segment ``a b`` passes through."""
        return self.candidates_segments(a, b)[1]

    def query_segments(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Walls each segment ``a[k] b[k]`` crosses or touches, CSR over segments."""
        A = np.asarray(a, dtype=np.float64).reshape(-1, 2)
        B = np.asarray(b, dtype=np.float64).reshape(-1, 2)
        pi, wi = self._segment_pairs(A, B, 0.0)
        s = self.segments[wi]
        hit = segments_intersect(A[pi], B[pi], s[:, 0], s[:, 1])
        return self._to_csr(pi[hit], wi[hit], len(A))

    def query_segment(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Walls the segment ``a b`` actually crosses or touches (exact), ascending."""
        return self.query_segments(a, b)[1]

    def query_capsules(self, a: np.ndarray, b: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
        """Walls within ``radius`` of each segment ``a[k] b[k]`` (a swept disc), CSR."""
        A = np.asarray(a, dtype=np.float64).reshape(-1, 2)
        B = np.asarray(b, dtype=np.float64).reshape(-1, 2)
        r = float(radius)
        if r < 0:
            raise ValueError(f"radius must be >= 0, got {radius}")
        pi, wi = self._segment_pairs(A, B, r)
        s = self.segments[wi]
        near = segment_segment_dist2(A[pi], B[pi], s[:, 0], s[:, 1]) <= r * r
        return self._to_csr(pi[near], wi[near], len(A))

    def query_capsule(self, a: np.ndarray, b: np.ndarray, radius: float) -> np.ndarray:
        """Walls within ``radius`` of the segment ``a b``: line of sight for a body of that radius."""
        return self.query_capsules(a, b, radius)[1]

    # ---------------------------------------------------------------- save/load
    def save(self, path: str | os.PathLike) -> None:
        """Write an ``.npz`` (atomically: temporary file, then rename)."""
        import io

        from ..formats.bundle import atomic_write_bytes

        buf = io.BytesIO()
        np.savez_compressed(
            buf, format=np.array(_FORMAT), segments=self.segments, box=self.box, child=self.child,
            depth=self.depth, offsets=self.offsets, walls=self.walls, eps=np.array(self.eps),
        )
        atomic_write_bytes(path, buf.getvalue())

    @classmethod
    def load(cls, path: str | os.PathLike) -> "WallQuadtree":
        """Read what :meth:`save` wrote; a damaged file raises FormatError naming it
        (read by formats/npz.py: bounded, no pickles, every array's type and shape
        checked, node links checked before any query follows them)."""
        from ..formats.npz import read_npz

        z = read_npz(path, "a quadtree file")
        fmt = z.get("format")
        if fmt is None or fmt.dtype.kind != "U" or fmt.size != 1 or str(fmt.reshape(())) != _FORMAT:
            raise FormatError(f"{path}: not a tanktool quadtree file (expected '{_FORMAT}')")
        kinds = {"segments": "f", "box": "f", "child": "iu", "depth": "iu", "offsets": "iu", "walls": "iu",
                 "eps": "f"}
        for key, kind in kinds.items():
            if key not in z:
                raise FormatError(f"{path}: not a tanktool quadtree file (no '{key}' array)")
            if z[key].dtype.kind not in kind:
                raise FormatError(f"{path}: '{key}' holds {z[key].dtype}, expected {'numbers' if kind == 'f' else 'integers'}")
        if z["eps"].size != 1 or z["segments"].ndim != 3 or z["box"].ndim != 3:
            raise FormatError(f"{path}: inconsistent quadtree arrays")
        tree = cls(
            z["segments"].astype(np.float64), z["box"].astype(np.float64), z["child"].astype(np.int64),
            z["depth"].astype(np.int64), z["offsets"].astype(np.int64), z["walls"].astype(np.int64),
            float(z["eps"].reshape(())),
        )
        n, N = len(tree.box), len(tree.segments)
        child = tree.child
        if (
            n == 0 or tree.segments.shape[1:] != (2, 2) or tree.box.shape != (n, 2, 2) or child.shape != (n,)
            or tree.depth.shape != (n,) or tree.offsets.shape != (n + 1,) or tree.walls.ndim != 1
            or tree.offsets[0] != 0 or tree.offsets[-1] != len(tree.walls) or (np.diff(tree.offsets) < 0).any()
            or (len(tree.walls) and (tree.walls.min() < 0 or tree.walls.max() >= N))
            or ((child != -1) & ((child <= np.arange(n)) | (child + 3 >= n))).any()
            or (tree.depth < 0).any() or tree.depth[0] != 0
            or not (np.isfinite(tree.segments).all() and np.isfinite(tree.box).all() and math.isfinite(tree.eps))
        ):
            raise FormatError(f"{path}: inconsistent quadtree arrays")
        kids = child[child != -1]
        if len(kids) and (tree.depth[kids] != tree.depth[child != -1] + 1).any():
            raise FormatError(f"{path}: inconsistent quadtree arrays (child depths)")
        return tree
