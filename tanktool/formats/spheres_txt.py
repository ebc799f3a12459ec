"""``spheres.txt`` and the sphere tree it holds (the data; geometry/spheres.py does
the geometry on it).

File format: one sphere a line, ``id parent level cx cy cz r``, root first with
parent -1 and level 1, parents before their children, ``#`` starts a comment; vehicle
frame (+x forward, +y up, +z right), metres.  Kept in formats/ so that reading a
vehicle bundle (formats/vehicle_bundle.py) needs nothing from geometry/.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import FormatError


@dataclass
class SphereTree:
    """A sphere hierarchy stored as flat arrays, root at index 0, parents first.

    Attributes
    ----------
    centers : (k, 3) float, vehicle frame, metres
    radii : (k,) float, metres
    parent : (k,) int, -1 for the root
    level : (k,) int, 1 for the root
    """

    centers: np.ndarray
    radii: np.ndarray
    parent: np.ndarray
    level: np.ndarray
    _children: list[np.ndarray] = field(default_factory=list, repr=False, compare=False)

    def __post_init__(self) -> None:
        self.centers = np.asarray(self.centers, dtype=np.float64).reshape(-1, 3)
        self.radii = np.asarray(self.radii, dtype=np.float64).reshape(-1)
        self.parent = np.asarray(self.parent, dtype=np.int64).reshape(-1)
        self.level = np.asarray(self.level, dtype=np.int64).reshape(-1)
        k = len(self.radii)
        if not (len(self.centers) == len(self.parent) == len(self.level) == k) or k == 0:
            raise ValueError("sphere tree arrays must be non-empty and of equal length")
        order = np.argsort(self.parent[1:], kind="stable") + 1
        counts = np.bincount(self.parent[1:], minlength=k) if k > 1 else np.zeros(k, np.int64)
        splits = np.cumsum(counts)[:-1]
        self._children = list(np.split(order, splits)) if k > 1 else [np.zeros(0, np.int64)]
        self._leaf = np.array([len(c) == 0 for c in self._children])
        # row i: the spheres that replace i one level down (its children, or i itself
        # for a leaf), padded with -1, so a whole frontier expands in one numpy step
        width = max(1, max(len(c) for c in self._children))
        self._expand = np.full((k, width), -1, dtype=np.int64)
        for i, c in enumerate(self._children):
            row = c if len(c) else np.array([i])
            self._expand[i, : len(row)] = row

    def __len__(self) -> int:
        return len(self.radii)

    @property
    def levels(self) -> int:
        return int(self.level.max())

    def children(self, i: int) -> np.ndarray:
        """Indices of sphere ``i``'s children (empty for a leaf)."""
        return self._children[i]

    def is_leaf(self) -> np.ndarray:
        """(k,) bool: True for spheres without children."""
        return self._leaf.copy()

    def leaves(self) -> np.ndarray:
        """Indices of the leaf spheres, in file order."""
        return np.flatnonzero(self.is_leaf())

    def ancestors(self, i: int) -> list[int]:
        """``[i, parent(i), ..., root]``."""
        out = [int(i)]
        while self.parent[out[-1]] >= 0:
            out.append(int(self.parent[out[-1]]))
        return out


# ---------------------------------------------------------------------------
# spheres.txt


def format_spheres(tree: SphereTree, header: str = "") -> str:
    """``spheres.txt`` text: ``id parent level cx cy cz r`` a line, 4 decimals (0.1 mm).

    Radii are rounded up and centres to nearest so the written tree still encloses
    what the exact one did (a rounded centre moves at most 0.5e-4 * sqrt(3) m, added
    to the radius).
    """
    lines = [f"# {line}" for line in header.splitlines()] if header else []
    lines.append("# id parent level cx cy cz r   (vehicle frame: +x forward, +y up, +z right; metres)")
    slack = 0.5e-4 * np.sqrt(3.0)
    for i in range(len(tree)):
        cx, cy, cz = (float(v) + 0.0 for v in np.round(tree.centers[i], 4))  # no "-0.0000"
        r = np.ceil((tree.radii[i] + slack) * 1e4) / 1e4
        lines.append(f"{i} {int(tree.parent[i])} {int(tree.level[i])} {cx:.4f} {cy:.4f} {cz:.4f} {r:.4f}")
    return "\n".join(lines) + "\n"


def write_spheres(path: str | os.PathLike, tree: SphereTree, header: str = "") -> None:
    from .bundle import atomic_write_text

    atomic_write_text(path, format_spheres(tree, header))


def read_spheres(path: str | os.PathLike) -> SphereTree:
    """Read ``spheres.txt``; any defect is a FormatError naming the file and line."""
    from .bundle import data_lines, read_input_text

    path = Path(path)
    text = read_input_text(path, "a spheres.txt file")
    rows: list[tuple[int, int, int, float, float, float, float]] = []
    for lineno, line, parts in data_lines(text):
        where = f"{path}:{lineno}"
        if len(parts) != 7:
            raise FormatError(f"{where}: expected 7 fields 'id parent level cx cy cz r', got {len(parts)}")
        try:
            sid, par, lev = int(parts[0]), int(parts[1]), int(parts[2])
            cx, cy, cz, r = (float(v) for v in parts[3:])
        except ValueError:
            raise FormatError(f"{where}: expected integers id parent level then 4 numbers, got {line!r}") from None
        if not all(np.isfinite([cx, cy, cz, r])):
            raise FormatError(f"{where}: centre and radius must be finite numbers")
        if r < 0:
            raise FormatError(f"{where}: radius must not be negative, got {r}")
        n = len(rows)
        if sid != n:
            raise FormatError(f"{where}: expected sphere id {n} (ids count up from 0), got {sid}")
        if n == 0:
            if par != -1 or lev != 1:
                raise FormatError(f"{where}: the first sphere must be the root (parent -1, level 1)")
        else:
            if not (0 <= par < n):
                raise FormatError(f"{where}: parent {par} must be an earlier sphere id (0..{n - 1})")
            if lev != rows[par][2] + 1:
                raise FormatError(f"{where}: level {lev} must be one more than its parent's ({rows[par][2]})")
        rows.append((sid, par, lev, cx, cy, cz, r))
    if not rows:
        raise FormatError(f"{path}: no spheres (expected at least the root line)")
    arr = np.array(rows, dtype=np.float64)
    return SphereTree(arr[:, 3:6], arr[:, 6], arr[:, 1].astype(np.int64), arr[:, 2].astype(np.int64))
