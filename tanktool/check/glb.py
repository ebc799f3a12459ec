"""Triangles of a binary glTF (``model.glb``) with numpy alone.

``check`` needs only the vertices and triangles of a bundle's model, in the frame the
scene places them.  Importing trimesh for that costs more than every rule together,
so this reads the common case itself: triangle-list meshes with float32 positions,
optional integer indices, node matrices or TRS.  Anything else (sparse accessors,
strips, Draco, ...) makes :func:`read_glb_triangles` return None and the caller falls
back to :func:`tanktool.formats.models.load_model`.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np

_COMPONENTS = {5121: np.uint8, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
_WIDTH = {"SCALAR": 1, "VEC3": 3}


class _Unsupported(Exception):
    pass


def _accessor(doc: dict, binary: bytes, index: int) -> np.ndarray:
    acc = doc["accessors"][index]
    if "sparse" in acc or "bufferView" not in acc:
        raise _Unsupported("sparse or empty accessor")
    dtype = np.dtype(_COMPONENTS[acc["componentType"]]).newbyteorder("<")
    width = _WIDTH[acc["type"]]
    view = doc["bufferViews"][acc["bufferView"]]
    if view.get("buffer", 0) != 0:
        raise _Unsupported("external buffer")
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    count = acc["count"]
    item = dtype.itemsize * width
    stride = view.get("byteStride", item)
    if start + stride * (count - 1) + item > len(binary) or count < 0:
        raise _Unsupported("accessor beyond the binary chunk")
    if stride == item:
        arr = np.frombuffer(binary, dtype=dtype, count=count * width, offset=start)
    else:
        rows = np.lib.stride_tricks.as_strided(
            np.frombuffer(binary, dtype=np.uint8, offset=start), shape=(count, item), strides=(stride, 1))
        arr = np.ascontiguousarray(rows).view(dtype).reshape(-1)
    return arr.reshape(count, width) if width > 1 else arr


def _local(node: dict) -> np.ndarray:
    if "matrix" in node:
        return np.asarray(node["matrix"], dtype=np.float64).reshape(4, 4).T  # column-major
    m = np.eye(4)
    x, y, z, w = node.get("rotation", [0.0, 0.0, 0.0, 1.0])
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m[:3, :3] *= np.asarray(node.get("scale", [1.0, 1.0, 1.0]))[None, :]
    m[:3, 3] = node.get("translation", [0.0, 0.0, 0.0])
    return m


def read_glb_triangles(path: str | Path) -> tuple[np.ndarray, np.ndarray] | None:
    """(vertices (n, 3) float64, triangles (m, 3) int64) of the default scene, or None."""
    try:
        data = Path(path).read_bytes()
        magic, version, _ = struct.unpack_from("<4sII", data, 0)
        if magic != b"glTF" or version != 2:
            return None
        off, doc, binary = 12, None, b""
        while off + 8 <= len(data):
            length, kind = struct.unpack_from("<II", data, off)
            chunk = data[off + 8: off + 8 + length]
            if kind == 0x4E4F534A:
                doc = json.loads(chunk)
            elif kind == 0x004E4942:
                binary = chunk
            off += 8 + length
        if doc is None:
            return None
        verts: list[np.ndarray] = []
        tris: list[np.ndarray] = []
        base = 0
        scene = doc.get("scenes", [{}])[doc.get("scene", 0)]
        stack = [(int(n), np.eye(4)) for n in scene.get("nodes", [])]
        depth = 0
        while stack:
            depth += 1
            if depth > 100_000:
                return None  # a cycle in the node graph
            n, parent = stack.pop()
            node = doc["nodes"][n]
            world = parent @ _local(node)
            stack += [(int(c), world) for c in node.get("children", [])]
            if "mesh" not in node:
                continue
            for prim in doc["meshes"][node["mesh"]]["primitives"]:
                if prim.get("mode", 4) != 4 or "extensions" in prim:
                    return None
                pos = _accessor(doc, binary, prim["attributes"]["POSITION"]).astype(np.float64)
                if "indices" in prim:
                    idx = _accessor(doc, binary, prim["indices"]).astype(np.int64).reshape(-1, 3)
                else:
                    idx = np.arange(len(pos), dtype=np.int64).reshape(-1, 3)
                if len(idx) and (idx.max() >= len(pos) or idx.min() < 0):
                    return None
                verts.append(pos @ world[:3, :3].T + world[:3, 3])
                tris.append(idx + base)
                base += len(pos)
        if not verts:
            return None
        return np.concatenate(verts), np.concatenate(tris)
    except (_Unsupported, KeyError, IndexError, TypeError, ValueError, struct.error, OSError):
        return None


def load_triangles(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of any model file, Y up as stored: .glb read here, the
    rest (and unusual .glb files) through trimesh.  Raises FormatError when unreadable."""
    path = Path(path)
    if path.suffix.lower() == ".glb":
        got = read_glb_triangles(path)
        if got is not None and np.isfinite(got[0]).all():
            return got
    from ..formats.models import load_model

    mesh = load_model(path, up="y", scale=1.0)
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)
