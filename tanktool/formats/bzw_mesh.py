"""BZFlag ``mesh`` objects (formats/bzw.py reads the rest of a world file).

A mesh is ``vertex x y z`` lines, ``face`` ... ``endface`` blocks each naming its
``vertices`` (numbers from 0, three or more: a polygon, cut into a fan of
triangles), and ``shift x y z`` / ``scale x y z`` / ``spin degrees ax ay az``
transformations applied in the order given; ``drawinfo`` blocks (how BZFlag draws
it) are skipped.  Example::

    mesh
      vertex 0 0 0
      vertex 10 0 0
      vertex 10 10 0
      vertex 0 10 5
      face
        vertices 0 1 2 3
      endface
      shift 100 0 0
    end
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import FormatError


@dataclass
class BzwMesh:
    """A ``mesh`` object: its vertices and polygon faces (indices from 0), with the
    ``shift`` / ``scale`` / ``spin`` transformations in the order given."""

    line: int
    vertices: list[tuple[float, float, float]] = field(default_factory=list)
    faces: list[tuple[int, list[int]]] = field(default_factory=list)   # (line, vertex indices)
    face: list[int] | None = None          # an open ``face`` block's indices
    face_line: int = 0
    transforms: list[tuple[str, tuple[float, ...]]] = field(default_factory=list)
    drivethrough: bool = False
    drawinfo: int = 0                      # depth of an open drawinfo block (skipped)


def _numbers(path: Path, lineno: int, key: str, args: list[str], count: int) -> tuple[float, ...]:
    from .bzw import _numbers as numbers

    return numbers(path, lineno, key, args, count)


def _mesh_line(path: Path, lineno: int, key: str, args: list[str], m: BzwMesh, world: Any) -> bool:
    """One line inside a ``mesh`` block; True when the mesh's ``end`` closed it."""
    if m.drawinfo:   # drawinfo and its lod/matref blocks close with their own ``end``
        if key in ("lod", "matref", "drawinfo"):
            m.drawinfo += 1
        elif key == "end":
            m.drawinfo -= 1
        return False
    if m.face is not None:
        if key == "endface":
            m.faces.append((m.face_line, m.face))
            m.face = None
        elif key == "vertices":
            nums = _numbers(path, lineno, key, args, len(args))
            if len(nums) < 3 or any(v != int(v) or v < 0 for v in nums):
                raise FormatError(f"{path}:{lineno}: face 'vertices' expects 3 or more vertex numbers (from 0), "
                                  f"got {' '.join(args)!r:.60}")
            m.face = [int(v) for v in nums]
        return False
    if key == "vertex":
        m.vertices.append(_numbers(path, lineno, key, args, 3))  # type: ignore[arg-type]
    elif key == "face":
        m.face, m.face_line = [], lineno
    elif key == "drawinfo":
        m.drawinfo = 1
    elif key in TRANSFORMS:
        m.transforms.append(_transform(path, lineno, key, args))
    elif key in ("drivethrough", "passable"):
        m.drivethrough = True
    elif key == "end":
        _finish_mesh(path, m, world)
        return True
    return False


#: a mesh's or a group's transformations and how many numbers each takes
TRANSFORMS = {"shift": 3, "scale": 3, "spin": 4}


def _transform(path: Path, lineno: int, key: str, args: list[str]) -> tuple[str, tuple[float, ...]]:
    """One ``shift``/``scale``/``spin`` line of a mesh or a group, its numbers checked."""
    return key, _numbers(path, lineno, key, args, TRANSFORMS[key])


def _finish_mesh(path: Path, m: BzwMesh, world: Any) -> None:
    """Triangulate the mesh's faces (fans), check their vertex numbers, place it."""
    if m.drivethrough:
        world.leave_out("drivethrough mesh", m.line)
        return
    n = len(m.vertices)
    tris = []
    for line, idx in m.faces:
        if not idx:
            raise FormatError(f"{path}:{line}: face has no 'vertices'")
        bad = next((i for i in idx if i >= n), None)
        if bad is not None:
            raise FormatError(f"{path}:{line}: face names vertex {bad}, the mesh has {n} (0..{n - 1})")
        tris += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
    if not tris:
        world.leave_out("mesh without faces", m.line)
        return
    v = transform(np.array(m.vertices, dtype=np.float64), m.transforms)
    if not np.isfinite(v).all():
        raise FormatError(f"{path}:{m.line}: the mesh's transformed vertices are not finite")
    world.meshes.append((v, np.array(tris, dtype=np.int64)))


def transform(v: np.ndarray, transforms: list[tuple[str, tuple[float, ...]]]) -> np.ndarray:
    """(n, 3) points after ``shift`` / ``scale`` / ``spin`` (degrees about an axis), in order."""
    for kind, t in transforms:
        if kind == "shift":
            v = v + np.array(t)
        elif kind == "scale":
            v = v * np.array(t)
        else:   # spin (Rodrigues)
            axis = np.array(t[1:])
            norm = float(np.linalg.norm(axis))
            if norm > 0:
                k = axis / norm
                a = math.radians(t[0])
                kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
                r = np.eye(3) + math.sin(a) * kx + (1 - math.cos(a)) * (kx @ kx)
                v = v @ r.T
    return v


# ---------------------------------------------------------------- groups

#: groups inside definitions inside groups ...: deeper than this is refused
MAX_GROUP_DEPTH = 8


@dataclass
class BzwGroup:
    """A ``group NAME`` block: an instance of ``define NAME``, moved by its transformations."""

    line: int
    name: str
    transforms: list[tuple[str, tuple[float, ...]]] = field(default_factory=list)
    drivethrough: bool = False


def _group_line(path: Path, lineno: int, key: str, args: list[str], g: BzwGroup, world: Any) -> bool:
    """One line inside a ``group`` block; True when its ``end`` closed it."""
    if key in TRANSFORMS:
        g.transforms.append(_transform(path, lineno, key, args))
    elif key in ("drivethrough", "passable"):
        g.drivethrough = True
    elif key == "end":
        place_group(path, g, world)
        return True
    return False


def place_group(path: Path, g: BzwGroup, world: Any) -> None:
    """Every solid of the group's definition, moved by the group's transformations,
    added to ``world.meshes`` (the definition is read once, with its own line numbers)."""
    from .bzw import object_mesh, parse_bzw
    from .limits import MAX_OBJECTS

    if g.drivethrough:
        world.leave_out("drivethrough group", g.line)
        return
    if g.name not in world.defines:
        world.leave_out("group of no definition", g.line)
        world.warnings.append(f"{path}:{g.line}: group {g.name!r}: no 'define {g.name}' before it")
        return
    if world.depth >= MAX_GROUP_DEPTH:
        raise FormatError(f"{path}:{g.line}: groups nested more than {MAX_GROUP_DEPTH} deep")
    sub = world.parsed.get(g.name)
    if sub is None:
        start, body = world.defines[g.name]
        # padded with empty lines: errors in the body name the file's own line numbers
        sub = parse_bzw(path, "\n" * start + "\n".join(body), defines=world.defines, depth=world.depth + 1)
        world.parsed[g.name] = sub
        world.warnings.extend(sub.warnings)
        for kind, lines in sub.left_out.items():
            world.left_out.setdefault(kind, []).extend(lines)
    parts = [object_mesh(o) for o in sub.objects] + list(sub.meshes)
    if len(world.meshes) + len(parts) > MAX_OBJECTS:
        raise FormatError(f"{path}:{g.line}: the groups make more than {MAX_OBJECTS:,} objects "
                          f"(a world this tool reads has fewer)")
    for v, f in parts:
        world.meshes.append((transform(v, g.transforms), f))

