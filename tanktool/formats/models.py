"""Load any supported 3D model into the world frame of DESIGN.md.

World frame: metres, right-handed, Y up, floor in the x-z plane.  3DS files are Z-up
and are converted with (x, y, z) -> (x, z, -y); everything else is taken as Y-up.
``up`` overrides the guess and ``scale`` multiplies after the rotation.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import FormatError

#: extensions trimesh (plus our .3ds reader) loads as meshes
MESH_EXTENSIONS = {".3ds", ".obj", ".glb", ".gltf", ".stl", ".ply", ".off"}
#: files that are not meshes but are turned into one (a Z-up scene) before the usual
#: pipeline: BZFlag worlds (formats/bzw.py) and 2D floor plans (formats/floorplan.py)
BUILT_EXTENSIONS = {".bzw", ".dxf", ".svg"}
#: built formats that take --wall-height / --wall-thickness
PLAN_FORMATS = ("dxf", "svg")

#: rotation taking a Z-up frame to our Y-up frame: (x, y, z) -> (x, z, -y)
Z_UP_TO_Y_UP = np.array(
    [[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]], dtype=np.float64
)


def detect_format(path: str | os.PathLike) -> str:
    """File type by extension, else by magic bytes ('3ds' for 0x4D4D).

    Returns the extension without the dot, lower case.  Raises FormatError when the
    file is missing or of no known kind.
    """
    path = Path(path)
    if not path.exists():
        raise FormatError(f"{path}: no such file")
    if path.is_dir():
        raise FormatError(f"{path}: is a folder, expected a model file")
    ext = path.suffix.lower()
    if ext in MESH_EXTENSIONS or ext in BUILT_EXTENSIONS:
        return ext[1:]
    with open(path, "rb") as f:
        head = f.read(16)
    if len(head) >= 6 and head[:2] == b"\x4d\x4d":
        return "3ds"
    if head[:4] == b"glTF":
        return "glb"
    if head[:5].lower() == b"solid" or path.suffix == "":
        # ascii STL or unknown text; let the caller's message say what we accept
        pass
    kinds = ", ".join(sorted(MESH_EXTENSIONS | BUILT_EXTENSIONS))
    raise FormatError(f"{path}: not a model file this tool reads (expected one of {kinds})")


def _check_binary_stl(path: Path) -> None:
    """Refuse a damaged binary STL with the byte offset, before trimesh sees it.

    A binary STL is an 80-byte header, a u32 triangle count at byte 80 and 50 bytes
    per triangle.  trimesh falls back to the ASCII reader when the length is wrong,
    which fails with an unrelated message; ASCII files start with ``solid``.
    """
    size = path.stat().st_size
    with open(path, "rb") as f:
        head = f.read(84)
    if size >= 84 and size == 84 + 50 * int.from_bytes(head[80:84], "little"):
        return  # consistent binary STL (some start with "solid" too)
    if head[:5].lower() == b"solid":
        return  # ASCII STL: trimesh's own reader judges it
    if size < 84:
        raise FormatError(f"{path}: byte {size}: binary STL needs an 84-byte header, file has {size} bytes")
    count = int.from_bytes(head[80:84], "little")
    raise FormatError(
        f"{path}: byte 80: binary STL says {count} triangles ({84 + 50 * count} bytes) "
        f"but the file has {size} bytes"
    )


def default_up(fmt: str) -> str:
    # .bzw worlds are Z-up, like .3ds; floor plans are built Z-up (plan y stored as -y)
    return "z" if fmt in ("3ds", "bzw", *PLAN_FORMATS) else "y"


def load_scene(path: str | os.PathLike, up: str | None = None, scale: float = 1.0,
               warn: Callable[[str], None] | None = None, wall_height: float | None = None,
               wall_thickness: float | None = None):
    """Load ``path`` as a ``trimesh.Scene`` in the world frame (Y up, metres).

    ``warn`` receives the non-fatal remarks of built formats (a .bzw file's
    unknown objects); ``wall_height`` / ``wall_thickness`` shape the walls of a
    .dxf/.svg floor plan (defaults in formats/floorplan.py).  Raises FormatError for
    unreadable files, models without triangles and non-finite vertices.
    """
    import trimesh

    from . import threeds  # noqa: F401  (registers the .3ds loader with trimesh)

    path = Path(path)
    fmt = detect_format(path)
    if fmt in PLAN_FORMATS and up not in (None, "z"):
        raise FormatError(f"{path}: --up does not apply to a floor plan (its x, y are the arena's x, z)")
    if fmt not in PLAN_FORMATS and (wall_height is not None or wall_thickness is not None):
        raise FormatError(f"{path}: --wall-height / --wall-thickness apply only to .dxf/.svg floor plans")
    if up is None:
        up = default_up(fmt)
    if up not in ("y", "z"):
        raise FormatError(f"--up must be 'y' or 'z', got {up!r}")
    if not (isinstance(scale, (int, float)) and math.isfinite(scale) and scale > 0):
        raise FormatError(f"--scale must be a positive number, got {scale!r}")
    try:
        if fmt == "3ds":
            scene = threeds.load_scene(path)
        elif fmt == "bzw":
            from . import bzw

            scene = bzw.load_scene(path, warn=warn)
        elif fmt in PLAN_FORMATS:
            from . import floorplan

            scene = floorplan.load_scene(
                path,
                floorplan.DEFAULT_WALL_HEIGHT if wall_height is None else wall_height,
                floorplan.DEFAULT_WALL_THICKNESS if wall_thickness is None else wall_thickness)
        else:
            if fmt == "stl":
                _check_binary_stl(path)
            scene = trimesh.load(str(path), file_type=fmt, force="scene", process=False)
    except FormatError:
        raise
    except Exception as e:  # trimesh raises many kinds for bad files
        raise FormatError(f"{path}: cannot read as .{fmt}: {e}") from None
    geoms = [g for g in scene.geometry.values() if isinstance(g, trimesh.Trimesh) and len(g.faces)]
    if not geoms:
        raise FormatError(f"{path}: the model has no triangles")
    for name, g in scene.geometry.items():
        if isinstance(g, trimesh.Trimesh) and not np.isfinite(g.vertices).all():
            bad = int(np.flatnonzero(~np.isfinite(g.vertices).all(axis=1))[0])
            raise FormatError(f"{path}: object {name!r} vertex {bad} is not finite (NaN or inf)")
    transform = np.eye(4)
    if up == "z":
        transform = Z_UP_TO_Y_UP.copy()
    if scale != 1.0:
        transform = np.diag([scale, scale, scale, 1.0]) @ transform
    if not np.allclose(transform, np.eye(4)):
        scene.apply_transform(transform)
    return scene


def load_model(path: str | os.PathLike, up: str | None = None, scale: float = 1.0):
    """Load ``path`` as one ``trimesh.Trimesh`` in the world frame (all objects joined,
    per-face colours kept)."""
    import trimesh

    scene = load_scene(path, up=up, scale=scale)
    meshes = [m for m in scene.dump() if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    if len(meshes) == 1:
        return meshes[0]
    return trimesh.util.concatenate(meshes)
