"""What one input file may ask for: bytes, counts, nesting depth, decompressed size.

Every reader checks a file against these *before* it allocates what the file asks
for, so a hostile or damaged file costs time and memory in proportion to its own
size and is refused with one clear message otherwise (docs/formats.md, "Limits").
The figures are far above anything a real arena or vehicle needs.
"""

from __future__ import annotations

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
