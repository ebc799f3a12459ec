"""3D Studio (.3ds) reader (the writer is :mod:`.threeds_write`, what it reads is in
:mod:`.model3ds`).

A .3ds file is a tree of chunks: a little-endian ``u16`` id and a ``u32`` length that
counts the 6-byte header, followed by the chunk's own data and then its children.
The reader walks that tree with explicit bounds, so a damaged file can only ever
produce a :class:`~tanktool.errors.FormatError` naming the file and byte offset:

* every chunk must fit inside its parent (and the parent inside the file);
* every loop over chunks advances by a chunk length of at least 6 bytes, so a
  parse always terminates;
* every count read from the file (vertices, faces, UVs, group sizes) is checked
  against the bytes left in its chunk *before* an array is made, so no array is
  ever larger than about twice the bytes it was read from (float32 -> float64).
  Memory is therefore proportional to the file: about 3x its size for real models;
  the per-chunk Python objects make the worst case (a file of nothing but empty
  6-byte material chunks) about 40x.

Only the chunks a static import needs are interpreted (objects, triangle meshes,
materials, master scale, keyframer node names); everything else, including lights
and cameras, is skipped by its length.

Vertices stay in the file's own axes (3DS is Z-up); :mod:`tanktool.formats.models`
turns them into the world frame.  Importing this module registers ``"3ds"`` with
trimesh's loader registry, so ``trimesh.load("x.3ds")`` works afterwards.
"""

from __future__ import annotations

import os
import struct
from typing import TYPE_CHECKING, Any, BinaryIO, Iterator, Sequence

import numpy as np

from ..errors import FormatError
from .bundle import read_input
from .limits import MAX_FACES, MAX_OBJECTS
from .model3ds import (_NO_FACES, _NO_FLAGS, _NO_MATERIALS, _NO_VERTICES, DEFAULT_COLOR, KeyframerNode, Material,
                       MeshObject, Model3DS, TextureMap)

if TYPE_CHECKING:
    import trimesh

__all__ = [
    "DEFAULT_COLOR",
    "KeyframerNode",
    "Material",
    "MeshObject",
    "Model3DS",
    "TextureMap",
    "load_scene",
    "read_3ds",
]

# ---------------------------------------------------------------------------
# chunk ids (names follow lib3ds)

MAIN = 0x4D4D
M3D_VERSION = 0x0002
MDATA = 0x3D3D
MESH_VERSION = 0x3D3E
MASTER_SCALE = 0x0100
NAMED_OBJECT = 0x4000
N_TRI_OBJECT = 0x4100
POINT_ARRAY = 0x4110
FACE_ARRAY = 0x4120
MSH_MAT_GROUP = 0x4130
TEX_VERTS = 0x4140
SMOOTH_GROUP = 0x4150
MESH_MATRIX = 0x4160
MAT_ENTRY = 0xAFFF
MAT_NAME = 0xA000
MAT_AMBIENT = 0xA010
MAT_DIFFUSE = 0xA020
MAT_SPECULAR = 0xA030
MAT_SHININESS = 0xA040
MAT_SHIN2PCT = 0xA041
MAT_TRANSPARENCY = 0xA050
MAT_TWO_SIDE = 0xA081
MAT_MAPNAME = 0xA300
COLOR_F = 0x0010
COLOR_24 = 0x0011
LIN_COLOR_24 = 0x0012
LIN_COLOR_F = 0x0013
INT_PERCENTAGE = 0x0030
FLOAT_PERCENTAGE = 0x0031
KFDATA = 0xB000
OBJECT_NODE_TAG = 0xB002
NODE_HDR = 0xB010
INSTANCE_NAME = 0xB011
NODE_ID = 0xB030

#: texture-map chunks inside a material, by the name we report them under
MAP_CHUNKS = {
    0xA200: "diffuse",
    0xA33A: "diffuse2",
    0xA204: "specular",
    0xA210: "opacity",
    0xA230: "bump",
    0xA33C: "shininess",
    0xA33D: "self_illumination",
    0xA220: "reflection",
}

#: vertex and face counts are u16 in the format
MAX_COUNT = 0xFFFF

HEADER = struct.Struct("<HI")
VERTEX_DTYPE = np.dtype(("<f4", (3,)))
UV_DTYPE = np.dtype(("<f4", (2,)))
FACE_DTYPE = np.dtype([("vertices", "<u2", (3,)), ("flags", "<u2")])

#: colour sub-chunks in order of preference: linear forms first (they are what the
#: artist picked; the plain ones are gamma-corrected copies), float before 24-bit
_COLOR_PREFERENCE = (LIN_COLOR_F, LIN_COLOR_24, COLOR_F, COLOR_24)


# ---------------------------------------------------------------------------
# reader


class _Reader:
    """Walks the chunk tree of one file held in memory."""

    def __init__(self, data: bytes, source: str) -> None:
        self.data = data
        self.source = source
        # 0x4130 groups as (the per-face material array they were checked against,
        # material name, face indices), resolved once the whole file is read because
        # materials may follow the objects that use them
        self.pending_groups: list[tuple[np.ndarray, str, np.ndarray]] = []
        self.faces = 0

    # -- helpers -------------------------------------------------------------

    def error(self, offset: int, message: str) -> FormatError:
        return FormatError(f"{self.source}: byte {offset}: {message}")

    def children(self, start: int, end: int, parent: int) -> Iterator[tuple[int, int, int, int]]:
        """Yield ``(id, offset, body_start, chunk_end)`` for each chunk in [start, end).

        Each step advances by the chunk's length, which is checked to be at least
        the 6-byte header: the loop cannot stall.
        """
        pos = start
        while pos < end:
            if end - pos < HEADER.size:
                raise self.error(
                    pos,
                    f"{end - pos} stray byte(s) at the end of chunk 0x{parent:04X}, "
                    f"too few for a 6-byte chunk header",
                )
            cid, length = HEADER.unpack_from(self.data, pos)
            if length < HEADER.size:
                raise self.error(
                    pos, f"chunk 0x{cid:04X} has length {length}, less than its 6-byte header"
                )
            if length > end - pos:
                where = (
                    f"the file ends at byte {len(self.data)}"
                    if end == len(self.data) and parent == -1
                    else f"its parent chunk 0x{parent:04X} ends at byte {end}"
                )
                raise self.error(
                    pos,
                    f"chunk 0x{cid:04X} claims {length} bytes (to byte {pos + length}) "
                    f"but {where}",
                )
            yield cid, pos, pos + HEADER.size, pos + length
            pos += length

    def need(self, offset: int, end: int, size: int, what: str, cid: int) -> None:
        """Raise unless ``size`` bytes are left between ``offset`` and ``end``."""
        if size > end - offset:
            raise self.error(
                offset,
                f"chunk 0x{cid:04X}: {what}: {size} bytes needed but only {end - offset} left",
            )

    def cstring(self, offset: int, end: int, cid: int) -> tuple[str, int]:
        """A NUL-terminated name at ``offset``; returns (text, offset after the NUL)."""
        nul = self.data.find(b"\0", offset, end)
        if nul < 0:
            raise self.error(
                offset, f"chunk 0x{cid:04X}: name not terminated by a NUL byte before byte {end}"
            )
        # 3DS names are 8-bit; latin-1 maps every byte, so decoding cannot fail
        return self.data[offset:nul].decode("latin-1"), nul + 1

    def u16(self, offset: int, end: int, cid: int, what: str) -> int:
        self.need(offset, end, 2, what, cid)
        return struct.unpack_from("<H", self.data, offset)[0]

    def array(self, offset: int, end: int, count: int, dtype: np.dtype, what: str, cid: int) -> np.ndarray:
        """``count`` items of ``dtype`` at ``offset``, after checking they fit."""
        self.need(offset, end, count * dtype.itemsize, what, cid)
        return np.frombuffer(self.data, dtype=dtype, count=count, offset=offset)

    def floats(self, offset: int, end: int, n: int, cid: int, what: str) -> np.ndarray:
        arr = self.array(offset, end, n, np.dtype("<f4"), what, cid).astype(np.float64)
        bad = ~np.isfinite(arr)
        if bad.any():
            at = offset + 4 * int(np.flatnonzero(bad)[0])
            raise self.error(at, f"chunk 0x{cid:04X}: {what}: value not finite (NaN or inf)")
        return arr

    # -- the tree ------------------------------------------------------------

    def read(self) -> Model3DS:
        data = self.data
        if len(data) == 0:
            raise FormatError(f"{self.source}: byte 0: empty file, expected a 3DS model (magic 0x4D4D)")
        if len(data) < HEADER.size:
            raise self.error(0, f"file has {len(data)} bytes, too short for a 3DS header")
        cid = HEADER.unpack_from(data, 0)[0]
        if cid != MAIN:
            raise self.error(0, f"not a 3DS file: expected magic 0x4D4D, found 0x{cid:04X}")
        model = Model3DS(source=self.source)
        # only the first top-level chunk is the model; anything after it (some
        # exporters pad the file) is not part of the tree
        for cid, off, body, end in self.children(0, len(data), -1):
            self.main(model, body, end)
            break
        index: dict[str, int] = {}
        for i, m in enumerate(model.materials):
            index.setdefault(m.name, i)  # the first of equal names wins, as in lookups
        for face_material, name, idx in self.pending_groups:
            face_material[idx] = index.get(name, -1)
        return model

    def main(self, model: Model3DS, start: int, end: int) -> None:
        for cid, off, body, cend in self.children(start, end, MAIN):
            if cid == M3D_VERSION:
                self.need(body, cend, 4, "version", cid)
                model.version = struct.unpack_from("<I", self.data, body)[0]
            elif cid == MDATA:
                self.mdata(model, body, cend)
            elif cid == KFDATA:
                self.keyframer(model, body, cend)

    def mdata(self, model: Model3DS, start: int, end: int) -> None:
        for cid, off, body, cend in self.children(start, end, MDATA):
            if cid == MESH_VERSION:
                self.need(body, cend, 4, "mesh version", cid)
                model.mesh_version = struct.unpack_from("<I", self.data, body)[0]
            elif cid == MASTER_SCALE:
                scale = float(self.floats(body, cend, 1, cid, "master scale")[0])
                if not scale > 0:
                    raise self.error(body, f"master scale must be positive, got {scale}")
                model.master_scale = scale
            elif cid == MAT_ENTRY:
                model.materials.append(self.material(off, body, cend))
            elif cid == NAMED_OBJECT:
                self.named_object(model, off, body, cend)

    def named_object(self, model: Model3DS, off: int, start: int, end: int) -> None:
        name, pos = self.cstring(start, end, NAMED_OBJECT)
        for cid, coff, body, cend in self.children(pos, end, NAMED_OBJECT):
            # lights (0x4600) and cameras (0x4700) are skipped by their length
            if cid == N_TRI_OBJECT:
                if len(model.objects) >= MAX_OBJECTS:
                    raise self.error(coff, f"more than {MAX_OBJECTS:,} mesh objects (a model this tool reads has fewer)")
                obj = self.trimesh(name, off, body, cend)
                self.faces += len(obj.faces)
                if self.faces > MAX_FACES:
                    raise self.error(coff, f"more than {MAX_FACES:,} triangles in all (a model this tool reads has fewer)")
                model.objects.append(obj)

    def trimesh(self, name: str, off: int, start: int, end: int) -> MeshObject:
        obj = MeshObject(
            name=name,
            vertices=_NO_VERTICES,
            faces=_NO_FACES,
            face_flags=_NO_FLAGS,
            face_material=_NO_MATERIALS,
            offset=off,
        )
        face_offset = None
        for cid, coff, body, cend in self.children(start, end, N_TRI_OBJECT):
            if cid == POINT_ARRAY:
                n = self.u16(body, cend, cid, "vertex count")
                obj.vertices = self.floats(body + 2, cend, 3 * n, cid, f"{n} vertices").reshape(n, 3)
            elif cid == TEX_VERTS:
                n = self.u16(body, cend, cid, "texture vertex count")
                obj.uv = self.floats(body + 2, cend, 2 * n, cid, f"{n} texture vertices").reshape(n, 2)
            elif cid == MESH_MATRIX:
                m = self.floats(body, cend, 12, cid, "object matrix").reshape(4, 3)
                matrix = np.eye(4)
                matrix[:3, :] = m.T  # rows in the file are the x, y, z axes and origin
                obj.matrix = matrix
            elif cid == FACE_ARRAY:
                face_offset = coff
                self.face_array(obj, body, cend)
        if len(obj.faces):
            bad = obj.faces >= len(obj.vertices)
            if bad.any():
                i = int(np.flatnonzero(bad.any(axis=1))[0])
                raise self.error(
                    face_offset + HEADER.size + 2 + 8 * i,
                    f"object {name!r}: face {i} uses vertex {int(obj.faces[i].max())} "
                    f"but the object has {len(obj.vertices)} vertices",
                )
        return obj

    def face_array(self, obj: MeshObject, start: int, end: int) -> None:
        n = self.u16(start, end, FACE_ARRAY, "face count")
        rec = self.array(start + 2, end, n, FACE_DTYPE, f"{n} faces", FACE_ARRAY)
        # a repeated 0x4120 replaces the earlier one, smoothing groups included
        obj.smoothing = None
        if n:
            obj.faces = rec["vertices"].astype(np.int32)
            obj.face_flags = rec["flags"].copy()
            obj.face_material = np.full(n, -1, dtype=np.int32)
        else:
            obj.faces, obj.face_flags, obj.face_material = _NO_FACES, _NO_FLAGS, _NO_MATERIALS
        for cid, off, body, cend in self.children(start + 2 + n * FACE_DTYPE.itemsize, end, FACE_ARRAY):
            if cid == MSH_MAT_GROUP:
                name, pos = self.cstring(body, cend, cid)
                k = self.u16(pos, cend, cid, "group face count")
                idx = self.array(pos + 2, cend, k, np.dtype("<u2"), f"{k} face indices", cid)
                if k and int(idx.max()) >= n:
                    raise self.error(
                        pos + 2,
                        f"material group {name!r} names face {int(idx.max())} "
                        f"but the object has {n} faces",
                    )
                if k:
                    self.pending_groups.append((obj.face_material, name, idx.astype(np.int32)))
            elif cid == SMOOTH_GROUP:
                if cend - body != 4 * n:
                    raise self.error(
                        off,
                        f"smoothing groups chunk has {cend - body} bytes, "
                        f"expected 4 per face = {4 * n}",
                    )
                obj.smoothing = np.frombuffer(self.data, "<u4", n, body).astype(np.uint32)

    def material(self, off: int, start: int, end: int) -> Material:
        mat = Material(name="", offset=off)
        for cid, coff, body, cend in self.children(start, end, MAT_ENTRY):
            if cid == MAT_NAME:
                mat.name = self.cstring(body, cend, cid)[0]
            elif cid == MAT_AMBIENT:
                mat.ambient = self.color(body, cend, cid)
            elif cid == MAT_DIFFUSE:
                mat.diffuse = self.color(body, cend, cid)
            elif cid == MAT_SPECULAR:
                mat.specular = self.color(body, cend, cid)
            elif cid == MAT_SHININESS:
                mat.shininess = self.percent(body, cend, cid)
            elif cid == MAT_SHIN2PCT:
                mat.shininess_strength = self.percent(body, cend, cid)
            elif cid == MAT_TRANSPARENCY:
                t = self.percent(body, cend, cid)
                mat.transparency = 0.0 if t is None else t
            elif cid == MAT_TWO_SIDE:
                mat.two_sided = True
            elif cid in MAP_CHUNKS:
                kind = MAP_CHUNKS[cid]
                mat.maps[kind] = self.texture_map(kind, body, cend, cid)
        return mat

    def color(self, start: int, end: int, parent: int) -> tuple[float, float, float] | None:
        found: dict[int, tuple[float, float, float]] = {}
        for cid, off, body, cend in self.children(start, end, parent):
            if cid in (COLOR_F, LIN_COLOR_F):
                rgb = self.floats(body, cend, 3, cid, "colour")
                found[cid] = (float(rgb[0]), float(rgb[1]), float(rgb[2]))
            elif cid in (COLOR_24, LIN_COLOR_24):
                self.need(body, cend, 3, "colour", cid)
                r, g, b = self.data[body : body + 3]
                found[cid] = (r / 255.0, g / 255.0, b / 255.0)
        for cid in _COLOR_PREFERENCE:
            if cid in found:
                return found[cid]
        return None

    def percent(self, start: int, end: int, parent: int) -> float | None:
        """A 0x0030 (int16 0..100) or 0x0031 (float 0..100) percentage, as a fraction."""
        for cid, off, body, cend in self.children(start, end, parent):
            if cid == INT_PERCENTAGE:
                self.need(body, cend, 2, "percentage", cid)
                return struct.unpack_from("<h", self.data, body)[0] / 100.0
            if cid == FLOAT_PERCENTAGE:
                return float(self.floats(body, cend, 1, cid, "percentage")[0]) / 100.0
        return None

    def texture_map(self, kind: str, start: int, end: int, parent: int) -> TextureMap:
        tex = TextureMap(kind=kind)
        for cid, off, body, cend in self.children(start, end, parent):
            if cid == MAT_MAPNAME:
                tex.file = self.cstring(body, cend, cid)[0]
            elif cid in (INT_PERCENTAGE, FLOAT_PERCENTAGE):
                # the strength is stored directly as a percentage sub-chunk
                if cid == INT_PERCENTAGE:
                    self.need(body, cend, 2, "percentage", cid)
                    tex.strength = struct.unpack_from("<h", self.data, body)[0] / 100.0
                else:
                    tex.strength = float(self.floats(body, cend, 1, cid, "percentage")[0]) / 100.0
        return tex

    def keyframer(self, model: Model3DS, start: int, end: int) -> None:
        for cid, off, body, cend in self.children(start, end, KFDATA):
            if cid != OBJECT_NODE_TAG:
                continue
            node = KeyframerNode(name="")
            for sid, soff, sbody, send in self.children(body, cend, cid):
                if sid == NODE_ID:
                    node.node_id = self.u16(sbody, send, sid, "node id")
                elif sid == NODE_HDR:
                    node.name, pos = self.cstring(sbody, send, sid)
                    self.need(pos, send, 6, "node flags and parent", sid)
                    parent = struct.unpack_from("<H", self.data, pos + 4)[0]
                    node.parent = None if parent == 0xFFFF else parent
                elif sid == INSTANCE_NAME:
                    node.instance = self.cstring(sbody, send, sid)[0] or None
            model.nodes.append(node)


def read_3ds(source: str | os.PathLike | bytes | BinaryIO, name: str | None = None) -> Model3DS:
    """Parse a .3ds file (a path, its bytes, or an open binary file).

    ``name`` is used in error messages (default: the path, or ``<bytes>``).  Raises
    FormatError for anything that is not a well-formed 3DS chunk tree.
    """
    if isinstance(source, (bytes, bytearray, memoryview)):
        data = bytes(source)
        label = name or "<bytes>"
    elif isinstance(source, (str, os.PathLike)):
        label = name or str(source)
        data = read_input(source, "a .3ds file", label)
    else:
        data = source.read()
        label = name or str(getattr(source, "name", "<stream>"))
    return _Reader(data, label).read()


# ---------------------------------------------------------------------------
# trimesh


def _unique_names(names: Sequence[str]) -> list[str]:
    seen: dict[str, int] = {}
    out = []
    for n in names:
        n = n or "object"
        if n in seen:
            seen[n] += 1
            candidate = f"{n}_{seen[n]}"
            while candidate in seen:
                seen[n] += 1
                candidate = f"{n}_{seen[n]}"
            n = candidate
        seen.setdefault(n, 0)
        out.append(n)
    return out


def _palette(model: Model3DS) -> np.ndarray:
    """(k + 1, 4) uint8 RGBA of each material, then the default colour (index -1)."""
    return np.array([m.rgba() for m in model.materials] + [DEFAULT_COLOR], dtype=np.uint8)


def _face_colors(model: Model3DS, obj: MeshObject, palette: np.ndarray | None = None) -> np.ndarray:
    """(m, 4) uint8 RGBA per face from its material (grey when it has none)."""
    if palette is None:
        palette = _palette(model)
    # -1 (no material) picks the last row, the default colour
    return palette[obj.face_material]


def _geometry_kwargs(model: Model3DS) -> dict[str, dict[str, Any]]:
    """Trimesh keyword arguments for each mesh object with faces, master scale applied.

    More than ``MERGE_OBJECTS`` objects become one geometry ``merged`` (per-face
    colours kept, object names in its metadata): a scene of 20,000 small objects
    costs trimesh time that grows with the square of their number, one mesh does not.
    """
    from .limits import MERGE_OBJECTS

    objs = [o for o in model.objects if len(o.faces)]
    palette = _palette(model)
    names = _unique_names([o.name for o in objs])
    if len(objs) > MERGE_OBJECTS:
        sizes = np.array([len(o.vertices) for o in objs], dtype=np.int64)
        base = np.concatenate([[0], np.cumsum(sizes)[:-1]])
        used = np.unique(np.concatenate([o.face_material for o in objs]))
        return {"merged": {
            "vertices": np.concatenate([o.vertices for o in objs]) * model.master_scale,
            "faces": np.concatenate([o.faces.astype(np.int64) + b for o, b in zip(objs, base)]),
            "face_colors": palette[np.concatenate([o.face_material for o in objs])],
            "process": False,
            "metadata": {"name": "merged", "3ds_objects": names,
                         "materials": sorted({model.materials[i].name for i in used if i >= 0})},
        }}
    out = {}
    for name, obj in zip(names, objs):
        out[name] = {
            "vertices": obj.vertices * model.master_scale,
            "faces": obj.faces.astype(np.int64),
            "face_colors": _face_colors(model, obj, palette),
            "process": False,
            "metadata": {
                "name": name,
                "3ds_object": obj.name,
                "materials": sorted(
                    {model.materials[i].name for i in np.unique(obj.face_material) if i >= 0}
                ),
            },
        }
    return out


def _scene_metadata(model: Model3DS) -> dict[str, Any]:
    return {
        "3ds_master_scale": model.master_scale,
        "3ds_instances": model.instance_names,
    }


def load_scene(path: str | os.PathLike) -> "trimesh.Scene":
    """Read ``path`` as a ``trimesh.Scene`` in the file's own axes (Z up).

    One geometry per mesh object with faces, named after the object (beyond
    ``MERGE_OBJECTS`` objects, one geometry ``merged``); per-face colours from the
    material diffuse colour (alpha from its transparency; faces without a material are
    neutral grey); master scale applied.
    """
    import trimesh

    model = read_3ds(path)
    geometry = {name: trimesh.Trimesh(**kw) for name, kw in _geometry_kwargs(model).items()}
    scene = trimesh.Scene()
    for name, mesh in geometry.items():
        scene.add_geometry(mesh, geom_name=name, node_name=name)
    scene.metadata.update(_scene_metadata(model))
    return scene


def load_3ds(file_obj: BinaryIO, file_type: str | None = None, resolver: Any = None, **kwargs: Any) -> dict[str, Any]:
    """trimesh loader: returns the keyword arguments of a Scene (see ``load_scene``)."""
    model = read_3ds(file_obj)
    return {"geometry": _geometry_kwargs(model), "metadata": _scene_metadata(model)}


def _register() -> None:
    from trimesh.exchange import load as trimesh_load

    trimesh_load.mesh_loaders["3ds"] = load_3ds


_register()
