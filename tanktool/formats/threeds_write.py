"""3D Studio (.3ds) writer: the bundled models and tests are written with it.

Objects are (name, vertices Z-up, faces, diffuse rgb), optionally followed by per-vertex
texture coordinates (n, 2) and the file name of a diffuse texture map; a mesh larger
than the format's u16 counts is split into parts.  Colours are written both as 24-bit (for old readers)
and as linear floats (for an exact round trip through :mod:`.threeds`).
"""

from __future__ import annotations

import struct
import os
from typing import TYPE_CHECKING, Any, Sequence, Union

import numpy as np

from .bundle import atomic_write_bytes
from .threeds import (
    COLOR_24, DEFAULT_COLOR, FACE_ARRAY, FACE_DTYPE, HEADER, LIN_COLOR_F, M3D_VERSION, MAIN, MASTER_SCALE,
    MAT_AMBIENT, MAT_DIFFUSE, MAT_ENTRY, MAT_NAME, MAX_COUNT, MDATA, MESH_MATRIX, MESH_VERSION, MSH_MAT_GROUP,
    N_TRI_OBJECT, NAMED_OBJECT, POINT_ARRAY, INT_PERCENTAGE, MAT_MAPNAME, TEX_VERTS,
)

#: the diffuse texture map chunk of a material (threeds.MAP_CHUNKS names it "diffuse")
MAT_TEXMAP = 0xA200

if TYPE_CHECKING:
    import trimesh

#: what :func:`write_3ds` takes: (name, vertices (n, 3) Z-up, faces (m, 3), diffuse rgb 0..1)
Object3DS = tuple[str, np.ndarray, np.ndarray, tuple[float, float, float]]

__all__ = ["Object3DS", "encode_3ds", "scene_to_3ds_objects", "write_3ds"]


def _chunk(cid: int, *parts: bytes) -> bytes:
    body = b"".join(parts)
    if len(body) + HEADER.size > 0xFFFFFFFF:
        raise ValueError(f"chunk 0x{cid:04X} would exceed the 4 GiB limit of the format")
    return HEADER.pack(cid, len(body) + HEADER.size) + body


def _name_bytes(name: str, what: str) -> bytes:
    if "\0" in name:
        raise ValueError(f"{what} {name!r} contains a NUL character")
    return name.encode("latin-1", errors="replace") + b"\0"


def _split_mesh(vertices: np.ndarray, faces: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Split a mesh into parts of at most 65535 vertices and 65535 faces (u16 counts).

    Faces keep their order; each part takes the longest run of faces whose distinct
    vertices still fit: the run stops at the face that brings in the 65536th
    distinct vertex, found from the first position of each vertex in the window.
    """
    if len(vertices) <= MAX_COUNT and len(faces) <= MAX_COUNT:
        return [(vertices, faces)]
    parts = []
    start, m = 0, len(faces)
    used = np.zeros(len(vertices), dtype=bool)  # reused scratch: O(n) per part, no sort
    while start < m:
        stop = min(m, start + MAX_COUNT)
        used[:] = False
        used[faces[start:stop]] = True
        if np.count_nonzero(used) > MAX_COUNT:
            _, first = np.unique(faces[start:stop].ravel(), return_index=True)
            first.sort()
            # first[MAX_COUNT] >= 65535, so at least 21845 faces are taken: progress
            stop = start + int(first[MAX_COUNT]) // 3
            used[:] = False
            used[faces[start:stop]] = True
        remap = np.cumsum(used) - 1
        parts.append((vertices[used], remap[faces[start:stop]]))
        start = stop
    return parts


def _color_chunk(cid: int, rgb: tuple[float, float, float]) -> bytes:
    rgb24 = bytes(int(round(c * 255)) for c in rgb)
    # 24-bit for old readers, linear float for an exact round trip
    return _chunk(
        cid,
        _chunk(COLOR_24, rgb24),
        _chunk(LIN_COLOR_F, struct.pack("<3f", *rgb)),
    )


def encode_3ds(
    objects: Sequence[tuple[str, Any, Any, Sequence[float]]], master_scale: float = 1.0
) -> bytes:
    """The bytes of a .3ds file holding ``objects``; see :func:`write_3ds`."""
    if not (np.isfinite(master_scale) and master_scale > 0):
        raise ValueError(f"master_scale must be a positive number, got {master_scale!r}")
    colors: dict[tuple[tuple[float, float, float], str | None], int] = {}
    object_chunks = []
    for k, item in enumerate(objects):
        try:
            name, vertices, faces, rgb = item[:4]
            uv, texture = (list(item[4:]) + [None, None])[:2]
        except (TypeError, ValueError):
            raise ValueError(f"object {k}: expected (name, vertices, faces, rgb[, uv[, texture]])") from None
        vertices = np.asarray(vertices, dtype=np.float64)
        faces = np.asarray(faces)
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ValueError(f"object {name!r}: vertices must be (n, 3), got {vertices.shape}")
        if faces.size == 0:
            faces = faces.reshape(0, 3).astype(np.int64)
        if faces.ndim != 2 or faces.shape[1] != 3 or not np.issubdtype(faces.dtype, np.integer):
            raise ValueError(f"object {name!r}: faces must be (m, 3) integers, got {faces.shape} {faces.dtype}")
        if not np.isfinite(vertices).all():
            raise ValueError(f"object {name!r}: vertices must be finite")
        if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
            raise ValueError(f"object {name!r}: face index out of range 0..{len(vertices) - 1}")
        rgb_t = tuple(float(c) for c in rgb)
        if len(rgb_t) != 3 or not all(0.0 <= c <= 1.0 for c in rgb_t):
            raise ValueError(f"object {name!r}: colour must be 3 floats in 0..1, got {rgb!r}")
        if np.abs(vertices).max(initial=0.0) > np.finfo(np.float32).max:
            raise ValueError(f"object {name!r}: vertices exceed the float32 range of the format")
        if uv is not None:
            uv = np.asarray(uv, dtype=np.float64)
            if uv.shape != (len(vertices), 2) or not np.isfinite(uv).all():
                raise ValueError(f"object {name!r}: uv must be finite (n, 2) with n = {len(vertices)} vertices")
        if texture is not None and (not isinstance(texture, str) or not texture):
            raise ValueError(f"object {name!r}: texture must be a file name, got {texture!r}")
        mat = colors.setdefault((rgb_t, texture), len(colors))
        if uv is None:
            parts = [(v, f, None) for v, f in _split_mesh(vertices, faces)]
        else:   # split with the UVs riding along as two more coordinates
            parts = [(v[:, :3], f, v[:, 3:]) for v, f in _split_mesh(np.hstack([vertices, uv]), faces)]
        for p, (v, f, t) in enumerate(parts):
            part_name = name if len(parts) == 1 else f"{name}_{p}"
            object_chunks.append(_object_chunk(part_name, v, f, f"Material{mat}", t))
    material_chunks = [
        _chunk(
            MAT_ENTRY,
            _chunk(MAT_NAME, _name_bytes(f"Material{i}", "material")),
            _color_chunk(MAT_AMBIENT, rgb),
            _color_chunk(MAT_DIFFUSE, rgb),
            *([] if texture is None else [_chunk(
                MAT_TEXMAP,
                _chunk(INT_PERCENTAGE, struct.pack("<h", 100)),
                _chunk(MAT_MAPNAME, _name_bytes(texture, "texture")),
            )]),
        )
        for (rgb, texture), i in colors.items()
    ]
    mdata = _chunk(
        MDATA,
        _chunk(MESH_VERSION, struct.pack("<I", 3)),
        *material_chunks,
        _chunk(MASTER_SCALE, struct.pack("<f", master_scale)),
        *object_chunks,
    )
    return _chunk(MAIN, _chunk(M3D_VERSION, struct.pack("<I", 3)), mdata)


def _object_chunk(name: str, vertices: np.ndarray, faces: np.ndarray, material: str,
                  uv: np.ndarray | None = None) -> bytes:
    points = np.ascontiguousarray(vertices, dtype="<f4")
    tex = [] if uv is None else [_chunk(TEX_VERTS, struct.pack("<H", len(uv)),
                                        np.ascontiguousarray(uv, dtype="<f4").tobytes())]
    rec = np.zeros(len(faces), dtype=FACE_DTYPE)
    rec["vertices"] = faces
    rec["flags"] = 0x0007  # all three edges visible, as 3ds Max writes them
    group = _chunk(
        MSH_MAT_GROUP,
        _name_bytes(material, "material"),
        struct.pack("<H", len(faces)),
        np.arange(len(faces), dtype="<u2").tobytes(),
    )
    matrix = np.zeros((4, 3), dtype="<f4")
    matrix[:3] = np.eye(3)
    return _chunk(
        NAMED_OBJECT,
        _name_bytes(name, "object name"),
        _chunk(
            N_TRI_OBJECT,
            _chunk(POINT_ARRAY, struct.pack("<H", len(points)), points.tobytes()),
            *tex,
            _chunk(MESH_MATRIX, matrix.tobytes()),
            _chunk(FACE_ARRAY, struct.pack("<H", len(faces)), rec.tobytes(), group),
        ),
    )


def write_3ds(
    path: str | os.PathLike,
    objects: Sequence[tuple[str, Any, Any, Sequence[float]]],
    master_scale: float = 1.0,
) -> None:
    """Write ``objects`` to a .3ds file, atomically.

    Parameters
    ----------
    path : where to write
    objects : list of ``(name, vertices, faces, rgb)``: vertices (n, 3) float in the
        FILE's axes (Z up), faces (m, 3) int, rgb three floats 0..1 (the diffuse
        colour); optionally ``(..., uv, texture)``: (n, 2) texture coordinates and
        the diffuse map's file name.  One material is written per distinct colour and
        texture; objects over 65535 vertices or faces are split into ``name_0``, ...
    master_scale : stored in the 0x0100 chunk (readers multiply vertices by it)

    Raises ValueError for malformed objects (nothing is written then).
    """
    atomic_write_bytes(path, encode_3ds(objects, master_scale))


#: (x, y, z) Y-up -> (x, -z, y) Z-up, the inverse of models.Z_UP_TO_Y_UP
_Y_UP_TO_Z_UP = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], dtype=np.float64)


def _mesh_face_rgb(mesh: Any) -> np.ndarray:
    """(m, 3) uint8 colour of each face; grey when the mesh has no colours."""
    m = len(mesh.faces)
    visual = mesh.visual
    kind = getattr(visual, "kind", None)
    if kind in ("face", "vertex"):
        return np.asarray(visual.face_colors)[:, :3].astype(np.uint8)
    if kind == "texture":
        material = getattr(visual, "material", None)
        main = getattr(material, "main_color", None)
        if main is not None:
            return np.tile(np.asarray(main, dtype=np.uint8)[:3], (m, 1))
    return np.tile(np.array(DEFAULT_COLOR[:3], dtype=np.uint8), (m, 1))


def scene_to_3ds_objects(geometry: Union["trimesh.Trimesh", "trimesh.Scene"]) -> list[Object3DS]:
    """Turn a Y-up ``trimesh.Trimesh`` or ``trimesh.Scene`` into :func:`write_3ds` objects.

    Scene transforms are applied; axes go back to the 3DS convention
    (x, y, z) -> (x, -z, y); each mesh is split by face colour into one object per
    colour (named ``<node>`` or ``<node>_<k>``), keeping only the vertices used.
    """
    import trimesh

    items: list[tuple[str, Any, np.ndarray]] = []
    if isinstance(geometry, trimesh.Trimesh):
        items.append((str(geometry.metadata.get("name") or "mesh"), geometry, np.eye(4)))
    elif isinstance(geometry, trimesh.Scene):
        for node in geometry.graph.nodes_geometry:
            transform, geom_name = geometry.graph[node]
            mesh = geometry.geometry.get(geom_name)
            if isinstance(mesh, trimesh.Trimesh):
                items.append((str(node), mesh, np.asarray(transform, dtype=np.float64)))
    else:
        raise TypeError(f"expected a trimesh.Trimesh or trimesh.Scene, got {type(geometry).__name__}")

    objects = []
    for name, mesh, transform in items:
        faces = np.asarray(mesh.faces, dtype=np.int64)
        if len(faces) == 0:
            continue
        verts = np.asarray(mesh.vertices, dtype=np.float64) @ transform[:3, :3].T + transform[:3, 3]
        verts = verts @ _Y_UP_TO_Z_UP.T
        rgb = _mesh_face_rgb(mesh)
        palette, which = np.unique(rgb, axis=0, return_inverse=True)
        which = which.reshape(-1)
        for k, color in enumerate(palette):
            sel = faces[which == k]
            used, inverse = np.unique(sel, return_inverse=True)
            obj_name = name if len(palette) == 1 else f"{name}_{k}"
            objects.append(
                (
                    obj_name,
                    verts[used],
                    inverse.reshape(-1, 3),
                    (color[0] / 255.0, color[1] / 255.0, color[2] / 255.0),
                )
            )
    return objects
