"""What one input file may ask for: bytes, counts, nesting depth, decompressed size.

Every reader checks a file against these *before* it allocates what the file asks
for, so a hostile or damaged file costs time and memory in proportion to its own
size and is refused with one clear message otherwise (docs/formats.md, "Limits").
The figures are far above anything a real arena or vehicle needs.
"""

from __future__ import annotations

import math
from typing import Any

MiB = 1 << 20

#: a model file (.3ds .obj .glb .stl .ply .off .bzw .dxf .svg); also read_input's default
MAX_MODEL_BYTES = 512 * MiB
#: hull.txt, spheres.txt (a few hundred bytes when made by import-vehicle)
MAX_SMALL_TEXT_BYTES = 4 * MiB
#: arena.toml, vehicle.toml, bindings.toml (a few KB when made by tanktool)
MAX_MANIFEST_BYTES = 4 * MiB
#: the JSON header of a replay
MAX_REPLAY_HEADER_BYTES = 4 * MiB
#: nesting of TOML tables / arrays and JSON objects / arrays
MAX_DEPTH = 32
#: triangles of one model, all its objects and instances together
MAX_FACES = 8_000_000
#: objects of one model (3DS objects, glTF nodes / meshes / primitives / accessors)
MAX_OBJECTS = 100_000
#: more objects than this are merged into one mesh (keeps the scene graph small, so
#: the cost of a model stays linear in its number of objects)
MERGE_OBJECTS = 64
#: the largest texture, by its header (a glTF's embedded image, a bundle's texture file)
MAX_IMAGE_PIXELS = 4096 * 4096
#: a model's extent after --scale, metres: beyond these it is a unit mistake
MAX_EXTENT = 1.0e5
MIN_EXTENT = 1.0e-3
#: one coordinate of a wall, a spawn or the bounds of an arena, metres from the
#: origin: a plan may sit far from its origin, but not so far that a grid index
#: (coordinate / cell) overflows or a float loses the centimetres
MAX_COORDINATE = 1.0e6
#: the arrays of one .npz file (navgrid, quadtree), decompressed
MAX_NPZ_BYTES = 1024 * MiB
#: a bundle file hashed or copied by the tools
MAX_BUNDLE_FILE_BYTES = MAX_MODEL_BYTES


def nesting_depth(value: Any, limit: int = MAX_DEPTH) -> int:
    """Depth of nested lists / dicts in ``value`` (a scalar is 0), counting no further
    than ``limit + 1``: iterative, so a hostile document cannot exhaust the stack."""
    deepest = 0
    stack = [(value, 0)]
    while stack:
        v, d = stack.pop()
        if isinstance(v, dict):
            items = v.values()
        elif isinstance(v, (list, tuple)):
            items = v
        else:
            continue
        d += 1
        deepest = max(deepest, d)
        if deepest > limit:
            return deepest
        stack.extend((c, d) for c in items if isinstance(c, (dict, list, tuple)))
    return deepest


#: cells (columns of the voxel heightfield, nodes of the grid) an arena model may ask
#: for: a base that admits an 800 m BZFlag world or a 1 km square at 0.5 m, plus a
#: share for each byte of the file (a 2 km terrain at 0.5 m, 16 M cells, needs a
#: file of 60 KB: any real terrain or town plan is larger), never above the
#: heightfield's own ceiling.  A 385-byte drawing stretched to 65 km asks for 7 M
#: cells, 3.7 GB and 40 s of work: refused before the work starts.
CELLS_BASE = 4_000_000
CELLS_PER_BYTE = 200
MAX_CELLS = 40_000_000


def cell_budget(file_bytes: int, max_cells: int | None = None) -> int:
    """The cells a model file of ``file_bytes`` may ask for (``max_cells``: the
    user's --max-cells, which replaces the file-size rule but not MAX_CELLS)."""
    if max_cells is not None:
        return min(int(max_cells), MAX_CELLS)
    return min(CELLS_BASE + CELLS_PER_BYTE * int(file_bytes), MAX_CELLS)


def check_cells(label: str, extent_x: float, extent_z: float, cell: float, file_bytes: int,
                max_cells: int | None = None, what: str = "the model") -> int:
    """The cells of an arena ``extent_x`` by ``extent_z`` metres at ``cell`` metres;
    FormatError naming the limit and the options that change it when more than the
    file may ask for (:func:`cell_budget`)."""
    from ..errors import FormatError

    nx = math.ceil(extent_x / cell) + 2   # the heightfield pads a cell on each side
    nz = math.ceil(extent_z / cell) + 2
    cells = nx * nz
    budget = cell_budget(file_bytes, max_cells)
    if cells > budget:
        rule = (f"--max-cells {max_cells:,}" if max_cells is not None else
                f"{CELLS_BASE:,} + {CELLS_PER_BYTE} per byte of its {file_bytes:,}-byte file")
        raise FormatError(
            f"{label}: {what} is {extent_x:,.1f} x {extent_z:,.1f} m: {cells:,} cells of {cell:g} m, more than the "
            f"{budget:,} it may ask for ({rule}; at most {MAX_CELLS:,}): wrong units? use --scale, a larger "
            f"--cell, or raise the limit with --max-cells")
    return cells
