"""heightfield's passes over the model's triangles, compiled (tanktool/_kernels_raster.c,
_kernels_faces.c), with the numpy code's results.

:func:`walkable_faces` and :func:`flat_faces`: each face's normal and what the numpy
code decides from it (walkable, flat; an upward flat face's height and area), the same
arithmetic in the same order, one pass where numpy made a dozen arrays of them.

:func:`raster_merge`: :func:`tanktool.geometry.heightfield.rasterize` hands every
triangle to the kernel in one call when the kernels are built: the pieces of each (triangle, cell) pair are made
as its numpy code makes them (gentle triangles by their planes, steep ones by their
exact sections) and kept as the packed keys its ``_merge`` sorts, 8 bytes a piece
where four int64 columns took 32; the keys are counted into their columns and each
column's few keys sorted, which gives the array one sort of them all would give, and
so the same spans.  Where the kernel replaced two calls (gentle, steep) and a merge, it
also saves their concatenation and the gathers of each piece's flags.
"""

from __future__ import annotations

import numpy as np


def walkable_faces(kern, vertices: np.ndarray, faces: np.ndarray, cos_slope: float,
                   flat_ny: float) -> tuple[np.ndarray, np.ndarray] | None:
    """heightfield.walkable_faces' (walkable, flat) per face; None when a face's corner
    is not a vertex (the numpy code then raises as it did)."""
    X, Y, Z, f0, f1, f2 = _columns(vertices, faces)
    walk, flat = np.empty(len(f0), dtype=bool), np.empty(len(f0), dtype=bool)
    return (walk, flat) if kern.walkable_faces(X, Y, Z, f0, f1, f2, float(cos_slope), float(flat_ny), walk,
                                               flat) else None


def flat_faces(kern, vertices: np.ndarray, faces: np.ndarray, up_min2: float,
               flat_ny: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The heights and areas of the upward faces (walls._upward_faces, ``up_min2`` the
    square of its UP_NORMAL_MIN) whose normal is within ``flat_ny`` of +y, in face
    order (heightfield.flat_heights); None for a bad corner."""
    X, Y, Z, f0, f1, f2 = _columns(vertices, faces)
    height, area = np.empty(len(f0)), np.empty(len(f0))
    k = kern.flat_faces(X, Y, Z, f0, f1, f2, float(up_min2), float(flat_ny), height, area)
    return (height[:k], area[:k]) if k >= 0 else None


def _columns(vertices: np.ndarray, faces: np.ndarray) -> list[np.ndarray]:
    """The vertices' x, y, z and the faces' three corners as contiguous columns."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces).reshape(-1, 3)
    return ([np.ascontiguousarray(v[:, k]) for k in range(3)]
            + [np.ascontiguousarray(f[:, k], dtype=np.int64) for k in range(3)])


def raster_merge(kern, X: list, Z: list, Y: list, normal: tuple, gentle: np.ndarray, walkable: np.ndarray,
                 flat: np.ndarray, shape: tuple[int, int], ch: float, rows: tuple[int, int] | None,
                 steps: tuple[int, int]):
    """rasterize's result (the merged spans, the number of pieces) from the triangles'
    vertices in grid units (``X``, ``Z``, ``Y``: three arrays each), their normals
    ``(n_x, n_z, n_y)`` and which are gentle (see rasterize); ``steps``: the merge's
    threshold and the highest span top, in cell heights."""
    n_x, n_z, n_y = normal
    nz, nx = shape
    abc = np.zeros((len(gentle), 3))
    g = np.flatnonzero(gentle)
    # the plane y = A + B x + C z of each gentle triangle: rasterize's arithmetic on the
    # gentle ones, element by element the same values
    ny_ = n_y[g]
    B, C = -n_x[g] / ny_, -n_z[g] / ny_
    abc[g, 0] = Y[0][g] - B * X[0][g] - C * Z[0][g]
    abc[g, 1], abc[g, 2] = B, C
    tri = np.ascontiguousarray(np.column_stack(X + Z + Y), dtype=np.float64)
    flags = [np.ascontiguousarray(a, dtype=bool) for a in (~gentle, walkable, flat)]
    merge_steps, max_steps = steps
    pieces, *spans = kern.raster_merge(tri, abc, *flags, nz, nx, float(ch), int(max_steps), *(rows or (0, nz)),
                                       int(merge_steps))
    types = (np.int64,) * 3 + (bool,) * 3
    return tuple(np.frombuffer(b, dtype=t) for b, t in zip(spans, types)), int(pieces)
