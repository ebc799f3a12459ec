"""One lattice for a bundle's layered grid, whichever command builds it.

import-arena analyses the model on a heightfield over the model's bounds; build-navgrid
rebuilds the grid from model.glb.  A heightfield's rasteriser works relative to its own
origin, so the same triangles on two origins give spans a step apart here and there:
two commands that rasterised on two lattices gave two grids.  The rule both follow:

* the surface is built on the **model lattice**: the model's (x, z) bounds with the
  low corner snapped down to a multiple of the cell (:func:`model_lattice`);
* the grid's nodes are that lattice's columns **cropped to the walls' bounds**: every
  column that overlaps them (:func:`grid_window`), the window's origin a lattice point.

So import-arena builds the bundle's grid from the surface it analysed (no second
surface), and build-navgrid on the bundle gives the same grid by construction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: a whisker so that a bound a rounding error past a lattice line stays on it
_EPS = 1e-9


def model_lattice(vertices: np.ndarray, cell: float) -> tuple[np.ndarray, tuple[int, int]]:
    """((x, z) origin, (nz, nx)) of the heightfield over ``vertices``: the low corner
    snapped down to a multiple of ``cell``, enough columns to reach the high one."""
    v = np.asarray(vertices)
    # column by column: numpy's reduction over axis 0 of an (n, 3) array is ~8x slower
    lo = np.array([float(v[:, 0].min()), float(v[:, 2].min())])
    hi = np.array([float(v[:, 0].max()), float(v[:, 2].max())])
    origin = np.array([math.floor(x / cell + _EPS) * cell for x in lo], dtype=np.float64)
    nx, nz = (max(1, int(math.ceil((h - o) / cell - _EPS))) for h, o in zip(hi, origin))
    return origin, (nz, nx)


@dataclass(frozen=True)
class Window:
    """The grid's columns on the model lattice: rows ``i0 .. i0 + nz``, columns
    ``j0 .. j0 + nx`` (they may reach past the lattice: no spans there)."""

    i0: int
    j0: int
    nz: int
    nx: int
    origin: np.ndarray   # (x, z) of the window's low corner (a lattice point)

    @property
    def shape(self) -> tuple[int, int]:
        return (self.nz, self.nx)


def grid_window(lattice_origin: np.ndarray, cell: float, bounds: np.ndarray) -> Window:
    """The lattice's columns overlapping ``bounds`` ((2, 2): low and high (x, z))."""
    b = np.asarray(bounds, dtype=np.float64).reshape(2, 2)
    o = np.asarray(lattice_origin, dtype=np.float64)
    first = [int(math.floor((b[0, k] - o[k]) / cell + _EPS)) for k in (0, 1)]
    end = [int(math.ceil((b[1, k] - o[k]) / cell - _EPS)) for k in (0, 1)]
    nx, nz = (max(1, e - f) for e, f in zip(end, first))
    origin = np.array([o[0] + first[0] * cell, o[1] + first[1] * cell], dtype=np.float64)
    return Window(first[1], first[0], nz, nx, origin)


def crop(a: np.ndarray, w: Window, fill: bool | float | int, ax: int = 1) -> np.ndarray:
    """``a`` with its axes ``ax``, ``ax + 1`` the lattice's (NZ, NX) cut to the window's
    (nz, nx) (layers (L, NZ, NX), links (L, NZ, NX, 4), a mask (NZ, NX) with ``ax`` 0),
    ``fill`` where the window reaches past the lattice."""
    NZ, NX = a.shape[ax], a.shape[ax + 1]
    if (w.i0, w.j0, w.nz, w.nx) == (0, 0, NZ, NX):
        return a
    out = np.full(a.shape[:ax] + (w.nz, w.nx) + a.shape[ax + 2:], fill, dtype=a.dtype)
    zi, zj = max(w.i0, 0), max(w.j0, 0)
    ei, ej = min(w.i0 + w.nz, NZ), min(w.j0 + w.nx, NX)
    if ei > zi and ej > zj:
        src = (slice(None),) * ax + (slice(zi, ei), slice(zj, ej))
        dst = (slice(None),) * ax + (slice(zi - w.i0, ei - w.i0), slice(zj - w.j0, ej - w.j0))
        out[dst] = a[src]
    return out


def crop_links(link: np.ndarray, w: Window) -> np.ndarray:
    """(L, NZ, NX, 4) grid links (navgrid.STEPS order: +x, +z, -x, -z) cut to the
    window: a link from the window's edge to a column outside it is dropped (-1), as
    the grid has no node there."""
    out = crop(link, w, -1)
    if out is link:   # the whole lattice: no link leaves it
        return out
    out[:, :, -1, 0] = -1
    out[:, -1, :, 1] = -1
    out[:, :, 0, 2] = -1
    out[:, 0, :, 3] = -1
    return out


def window_nodes(mask: np.ndarray, w: Window) -> np.ndarray:
    """A lattice's (NZ, NX) mask cut to the window."""
    return crop(mask, w, False, ax=0)
