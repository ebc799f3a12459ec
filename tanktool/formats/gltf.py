"""glTF 2.0 (``.glb``, ``.gltf``) checked before anything touches its buffers.

A glTF file is a JSON document describing how to read numbers out of binary buffers
(buffers -> bufferViews -> accessors -> mesh primitives) and a node graph placing the
meshes.  Every one of those is a hostile file's lever: a negative ``byteStride`` makes
a strided view read outside its buffer (a segmentation fault), a node listing itself
1,000 times makes a naive traversal explode, an index past the vertices or a count
past the buffer crashes whatever uses the mesh, an external URI reads any file.

:func:`read_gltf` validates the whole document against its buffers first:

* the GLB container (magic, version 2, chunk lengths inside the file), the JSON
  (UTF-8, nesting at most ``MAX_DEPTH``), every top-level array's length and type;
* buffers: the GLB binary chunk, ``data:`` URIs, or files beside a ``.gltf`` that
  stay inside its folder; each at least as long as it says;
* bufferViews inside their buffer, ``byteStride`` 4..252 and a multiple of 4;
* accessors: known component types and shapes, ``count`` >= 1, the last element
  inside the view (offset + stride x (count - 1) + element size), and all accessors
  together at most a few times the buffers' bytes (no memory bombs); sparse
  accessors are refused (they would be read as zeros);
* mesh primitives: accessors in range, POSITION float VEC3, integer SCALAR indices
  whose values are read and checked against the vertex count, equal attribute counts;
* nodes: children and meshes in range, each node at most one parent, no cycles, no
  scene root that is also a child; transforms of finite numbers; the triangles of
  every instance together at most ``MAX_FACES``.

* images: only PNG or JPEG held in a bufferView, at most ``MAX_IMAGE_PIXELS`` by
  their header (read without decoding); any other image, the textures naming it and
  the materials' references to those are dropped (the colour stays)
  (:mod:`.gltf_images`).

It returns a :class:`Gltf` whose document is *sanitised*: one binary buffer, no
URIs, cameras, skins or animations, only the keys meshes and their colour textures need,
so :func:`sanitized_glb` hands trimesh a file that cannot read anything else.
:mod:`.gltf_scene` reads the triangles of a validated glTF without trimesh.
Errors are FormatErrors naming the file and the place: a byte offset for the
container, a JSON path (``accessors[3].byteStride``) for the document.
"""

from __future__ import annotations

import base64
import json
import math
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from urllib.parse import unquote

import numpy as np

from ..errors import FormatError
from .gltf_images import sanitized_materials, sanitized_textures
from .limits import MAX_DEPTH, MAX_FACES, MAX_MODEL_BYTES, MAX_OBJECTS, nesting_depth

GLB_MAGIC = b"glTF"
CHUNK_JSON = 0x4E4F534A
CHUNK_BIN = 0x004E4942

COMPONENTS = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
INDEX_TYPES = (5121, 5123, 5125)
#: all accessors together may read this many times the buffers' bytes (interleaved
#: attributes each span the whole view; 8 leaves room for real files)
ACCESSOR_BUDGET = 8
#: extensions that change how geometry is stored: without them the numbers are wrong
_GEOMETRY_EXTENSIONS = ("KHR_draco_mesh_compression", "EXT_meshopt_compression", "KHR_mesh_quantization")
TRIANGLES, STRIP, FAN = 4, 5, 6


@dataclass
class Gltf:
    """A validated glTF: the sanitised document, its one binary buffer, and counts."""

    doc: dict[str, Any]
    binary: bytes
    faces: int          # triangles of every node instance of the default scene
    instances: int      # mesh instances (nodes with a mesh) in the default scene
    label: str = ""


class _Doc:
    """Typed access to the JSON document; every failure names its JSON path."""

    def __init__(self, label: str) -> None:
        self.label = label

    def fail(self, where: str, message: str) -> FormatError:
        return FormatError(f"{self.label}: {where}: {message}")

    @staticmethod
    def path(where: str, key: str) -> str:
        return f"{where}.{key}" if where else key

    def array(self, doc: dict, key: str) -> list:
        v = doc.get(key, [])
        if not isinstance(v, list):
            raise self.fail(key, f"must be an array, got {type(v).__name__}")
        if len(v) > MAX_OBJECTS:
            raise self.fail(key, f"{len(v):,} entries, more than the {MAX_OBJECTS:,} this tool reads")
        for i, item in enumerate(v):
            if not isinstance(item, dict):
                raise self.fail(f"{key}[{i}]", f"must be an object, got {type(item).__name__}")
        return v

    def int(self, obj: dict, key: str, where: str, lo: int = 0, hi: int | None = None,
            default: int | None = None) -> int:
        v = obj.get(key, default)
        if v is None:
            raise self.fail(self.path(where, key), "is missing")
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.fail(self.path(where, key), f"must be an integer, got {v!r:.40}")
        if v < lo or (hi is not None and v > hi):
            rng = f"{lo}..{hi}" if hi is not None else f">= {lo}"
            raise self.fail(self.path(where, key), f"{v} is outside {rng}")
        return v

    def index(self, obj: dict, key: str, where: str, n: int, what: str) -> int:
        v = obj.get(key)
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.fail(self.path(where, key), f"must be an index, got {v!r:.40}")
        if not 0 <= v < n:
            raise self.fail(self.path(where, key), f"{what} {v} does not exist (there are {n})")
        return v

    def numbers(self, obj: dict, key: str, where: str, n: int) -> list[float] | None:
        v = obj.get(key)
        if v is None:
            return None
        if (not isinstance(v, list) or len(v) != n
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)):
            raise self.fail(self.path(where, key), f"must be {n} finite numbers")
        return [float(x) for x in v]


# ---------------------------------------------------------------- container

def _split_glb(data: bytes, label: str) -> tuple[bytes, bytes | None]:
    """(JSON chunk, BIN chunk or None) of a GLB container."""
    if len(data) < 12:
        raise FormatError(f"{label}: byte 0: {len(data)} bytes, too short for a GLB header (12 bytes)")
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    if magic != GLB_MAGIC:
        raise FormatError(f"{label}: byte 0: not a binary glTF (expected magic 'glTF')")
    if version != 2:
        raise FormatError(f"{label}: byte 4: glTF version {version}, this tool reads version 2")
    if length > len(data):
        raise FormatError(f"{label}: byte 8: the header says {length} bytes but the file has {len(data)}")
    off, chunks = 12, []
    while off + 8 <= length and len(chunks) < 2:
        clen, ctype = struct.unpack_from("<II", data, off)
        if clen > length - off - 8:
            raise FormatError(f"{label}: byte {off}: chunk of {clen} bytes runs past the end of the file")
        chunks.append((off, ctype, data[off + 8: off + 8 + clen]))
        off += 8 + clen
    if not chunks or chunks[0][1] != CHUNK_JSON:
        raise FormatError(f"{label}: byte 12: the first chunk must be the JSON chunk")
    binary = None
    if len(chunks) > 1:
        at, ctype, body = chunks[1]
        if ctype != CHUNK_BIN:
            raise FormatError(f"{label}: byte {at}: the second chunk must be the binary (BIN) chunk")
        binary = body
    return chunks[0][2], binary


def _parse_json(text: bytes, label: str, at: int) -> dict[str, Any]:
    try:
        doc = json.loads(text.decode("utf-8-sig"))
    except UnicodeDecodeError as e:
        raise FormatError(f"{label}: byte {at + e.start}: the glTF JSON is not UTF-8") from None
    except RecursionError:
        raise FormatError(f"{label}: the glTF JSON is nested deeper than {MAX_DEPTH} levels") from None
    except ValueError as e:  # JSONDecodeError, or a number of more than 4300 digits
        pos = getattr(e, "pos", None)
        where = f"byte {at + pos}: " if pos is not None else ""
        raise FormatError(f"{label}: {where}the glTF JSON is not valid: {getattr(e, 'msg', e)}") from None
    if not isinstance(doc, dict):
        raise FormatError(f"{label}: byte {at}: the glTF JSON must be an object")
    if nesting_depth(doc) > MAX_DEPTH:
        raise FormatError(f"{label}: the glTF JSON is nested deeper than {MAX_DEPTH} levels")
    return doc


# ---------------------------------------------------------------- buffers

def _buffers(d: _Doc, doc: dict, binary: bytes | None, folder: Path | None) -> list[bytes]:
    from .bundle import bundle_file, read_input

    out = []
    for i, b in enumerate(d.array(doc, "buffers")):
        where = f"buffers[{i}]"
        length = d.int(b, "byteLength", where, lo=0, hi=MAX_MODEL_BYTES)
        uri = b.get("uri")
        if uri is None:
            if i != 0 or binary is None:
                raise d.fail(where, "has no uri and is not the GLB binary chunk")
            data = binary
        elif not isinstance(uri, str):
            raise d.fail(f"{where}.uri", f"must be a string, got {type(uri).__name__}")
        elif uri.startswith("data:"):
            head, sep, payload = uri.partition(",")
            if not sep or not head.endswith(";base64"):
                raise d.fail(f"{where}.uri", "a data: URI must be base64 encoded")
            try:
                data = base64.b64decode(payload, validate=True)
            except ValueError:
                raise d.fail(f"{where}.uri", "the data: URI is not valid base64") from None
        else:
            if folder is None:
                raise d.fail(f"{where}.uri", f"names an external file ({uri[:60]!r}); a .glb must hold its buffers")
            f = bundle_file(folder, unquote(uri), f"{d.label}: {where}.uri")   # a URI: %20 is a space
            data = read_input(f, "a glTF buffer", label=f"{d.label}: {where}.uri {uri!r}")
        if len(data) < length:
            raise d.fail(f"{where}.byteLength", f"says {length} bytes but the buffer holds {len(data)}")
        out.append(data[:length])
    return out


def _views(d: _Doc, doc: dict, buffers: list[bytes]) -> tuple[list[dict], list[int]]:
    """Sanitised bufferViews (all in buffer 0) and each view's length."""
    base, total = [], 0
    for data in buffers:
        base.append(total)
        total += (len(data) + 3) // 4 * 4
    views, lengths = [], []
    for i, v in enumerate(d.array(doc, "bufferViews")):
        where = f"bufferViews[{i}]"
        b = d.index(v, "buffer", where, len(buffers), "buffer")
        off = d.int(v, "byteOffset", where, default=0)
        length = d.int(v, "byteLength", where, lo=1)
        if off + length > len(buffers[b]):
            raise d.fail(where, f"bytes {off}..{off + length} lie outside buffer {b} ({len(buffers[b])} bytes)")
        out = {"buffer": 0, "byteOffset": base[b] + off, "byteLength": length}
        if "byteStride" in v:
            stride = d.int(v, "byteStride", where, lo=4, hi=252)
            if stride % 4:
                raise d.fail(f"{where}.byteStride", f"{stride} is not a multiple of 4")
            out["byteStride"] = stride
        views.append(out)
        lengths.append(length)
    return views, lengths


def _accessors(d: _Doc, doc: dict, views: list[dict], lengths: list[int], budget: int) -> list[dict]:
    out = []
    spent = 0
    for i, a in enumerate(d.array(doc, "accessors")):
        where = f"accessors[{i}]"
        if "sparse" in a:
            raise d.fail(f"{where}.sparse", "sparse accessors are not supported")
        ctype = a.get("componentType")
        if isinstance(ctype, bool) or not isinstance(ctype, int) or ctype not in COMPONENTS:
            raise d.fail(f"{where}.componentType", f"{ctype!r:.40} is not a glTF component type")
        kind = a.get("type")
        if not isinstance(kind, str) or kind not in WIDTHS:
            raise d.fail(f"{where}.type", f"{kind!r:.40} is not a glTF accessor type")
        count = d.int(a, "count", where, lo=1)
        elem = WIDTHS[kind] * np.dtype(COMPONENTS[ctype]).itemsize
        acc = {"componentType": ctype, "type": kind, "count": count}
        if a.get("normalized") is True:
            acc["normalized"] = True
        if "bufferView" in a:
            vi = d.index(a, "bufferView", where, len(views), "bufferView")
            off = d.int(a, "byteOffset", where, default=0)
            stride = views[vi].get("byteStride", elem)
            if stride < elem:
                raise d.fail(where, f"elements of {elem} bytes do not fit bufferView {vi}'s byteStride {stride}")
            end = off + stride * (count - 1) + elem
            if end > lengths[vi]:
                raise d.fail(where, f"{count} elements of {elem} bytes (stride {stride}) from byte {off} need "
                                    f"{end} bytes, bufferView {vi} has {lengths[vi]}")
            acc["bufferView"] = vi
            acc["byteOffset"] = off
            spent += end - off
        else:
            if "byteOffset" in a:
                raise d.fail(f"{where}.byteOffset", "given without a bufferView")
            spent += count * elem  # read as zeros: memory without bytes behind it
        if spent > budget:
            raise d.fail(where, f"the accessors read {spent:,} bytes, more than {ACCESSOR_BUDGET} times "
                                f"the file's buffers: a memory bomb, not a model")
        out.append(acc)
    return out


def read_accessor(g: Gltf, index: int) -> np.ndarray:
    """The values of a validated accessor as a (count,) or (count, width) array (a copy)."""
    acc = g.doc["accessors"][index]
    dtype = np.dtype(COMPONENTS[acc["componentType"]]).newbyteorder("<")
    width = WIDTHS[acc["type"]]
    count = acc["count"]
    if "bufferView" not in acc:
        arr = np.zeros((count, width), dtype=dtype)
    else:
        view = g.doc["bufferViews"][acc["bufferView"]]
        start = view["byteOffset"] + acc["byteOffset"]
        elem = dtype.itemsize * width
        stride = view.get("byteStride", elem)
        if stride == elem:
            arr = np.frombuffer(g.binary, dtype=dtype, count=count * width, offset=start).reshape(count, width)
        else:
            # rows of a strided view, gathered with plain indexing: every byte read was
            # checked to lie inside the view, and nothing is ever read past it
            raw = np.frombuffer(g.binary, dtype=np.uint8, count=stride * (count - 1) + elem, offset=start)
            rows = np.arange(count)[:, None] * stride + np.arange(elem)[None, :]
            arr = raw[rows].copy().view(dtype).reshape(count, width)
    return arr.reshape(count) if width == 1 else arr


# ---------------------------------------------------------------- meshes and nodes

def _primitive_faces(mode: int, n: int) -> int:
    if mode == TRIANGLES:
        return n // 3
    if mode in (STRIP, FAN):
        return max(n - 2, 0)
    return 0


def _meshes(d: _Doc, doc: dict, g: Gltf, materials: int) -> tuple[list[dict], list[int]]:
    """Sanitised meshes and the triangles of each."""
    accessors = g.doc["accessors"]
    out, faces = [], []
    for i, m in enumerate(d.array(doc, "meshes")):
        where = f"meshes[{i}]"
        prims = m.get("primitives")
        if not isinstance(prims, list) or not prims:
            raise d.fail(f"{where}.primitives", "must be a non-empty array")
        if len(prims) > MAX_OBJECTS:
            raise d.fail(f"{where}.primitives", f"more than {MAX_OBJECTS:,} primitives")
        kept, nf = [], 0
        for j, p in enumerate(prims):
            pw = f"{where}.primitives[{j}]"
            if not isinstance(p, dict):
                raise d.fail(pw, "must be an object")
            mode = d.int(p, "mode", pw, lo=0, hi=6, default=TRIANGLES)
            attrs = p.get("attributes")
            if not isinstance(attrs, dict) or "POSITION" not in attrs:
                raise d.fail(f"{pw}.attributes", "must be an object with a POSITION accessor")
            pos = d.index(attrs, "POSITION", f"{pw}.attributes", len(accessors), "accessor")
            pa = accessors[pos]
            if pa["type"] != "VEC3" or pa["componentType"] != 5126:
                raise d.fail(f"{pw}.attributes.POSITION", "must be a float VEC3 accessor")
            n = pa["count"]
            new_attrs = {"POSITION": pos}
            for name in ("NORMAL", "COLOR_0", "TEXCOORD_0"):
                if name in attrs:
                    k = d.index(attrs, name, f"{pw}.attributes", len(accessors), "accessor")
                    if accessors[k]["count"] != n:
                        raise d.fail(f"{pw}.attributes.{name}", f"has {accessors[k]['count']} elements, POSITION {n}")
                    want = {"NORMAL": ("VEC3",), "COLOR_0": ("VEC3", "VEC4"), "TEXCOORD_0": ("VEC2",)}[name]
                    if accessors[k]["type"] not in want:
                        raise d.fail(f"{pw}.attributes.{name}", f"must be {' or '.join(want)}")
                    new_attrs[name] = k
            prim: dict[str, Any] = {"attributes": new_attrs, "mode": mode}
            count = n
            if "indices" in p:
                k = d.index(p, "indices", pw, len(accessors), "accessor")
                ia = accessors[k]
                if ia["type"] != "SCALAR" or ia["componentType"] not in INDEX_TYPES:
                    raise d.fail(f"{pw}.indices", "must be an unsigned integer SCALAR accessor")
                idx = read_accessor(g, k)
                if len(idx) and int(idx.max()) >= n:
                    bad = int(np.flatnonzero(idx >= n)[0])
                    raise d.fail(f"{pw}.indices", f"index {bad} is {int(idx[bad])}, POSITION has {n} vertices")
                prim["indices"] = k
                count = ia["count"]
            if mode == TRIANGLES and count % 3:
                raise d.fail(pw, f"{count} vertex indices do not make whole triangles")
            if "material" in p:
                prim["material"] = d.index(p, "material", pw, materials, "material")
            nf += _primitive_faces(mode, count)
            if nf > MAX_FACES:
                raise d.fail(where, f"more than {MAX_FACES:,} triangles")
            kept.append(prim)
        mesh: dict[str, Any] = {"primitives": kept}
        if isinstance(m.get("name"), str):
            mesh["name"] = m["name"][:200]
        out.append(mesh)
        faces.append(nf)
    return out, faces


def _nodes(d: _Doc, doc: dict, meshes: int) -> tuple[list[dict], list[int]]:
    """Sanitised nodes and the parent of each (-1 for none); refuses cycles."""
    nodes = d.array(doc, "nodes")
    n = len(nodes)
    parent = [-1] * n
    out = []
    for i, node in enumerate(nodes):
        where = f"nodes[{i}]"
        new: dict[str, Any] = {}
        children = node.get("children", [])
        if not isinstance(children, list):
            raise d.fail(f"{where}.children", "must be an array of node indices")
        for k, c in enumerate(children):
            if isinstance(c, bool) or not isinstance(c, int) or not 0 <= c < n:
                raise d.fail(f"{where}.children[{k}]", f"{c!r:.40} is not a node index (there are {n} nodes)")
            if c == i:
                raise d.fail(f"{where}.children[{k}]", "a node cannot be its own child")
            if parent[c] != -1:
                raise d.fail(f"{where}.children[{k}]", f"node {c} already has parent node {parent[c]} "
                                                       f"(the node graph must be a tree)")
            parent[c] = i
        if children:
            new["children"] = list(children)
        if "mesh" in node:
            new["mesh"] = d.index(node, "mesh", where, meshes, "mesh")
        m = d.numbers(node, "matrix", where, 16)
        if m is not None:
            new["matrix"] = m
        for key, size in (("translation", 3), ("rotation", 4), ("scale", 3)):
            v = d.numbers(node, key, where, size)
            if v is not None:
                new[key] = v
        if isinstance(node.get("name"), str):
            new["name"] = node["name"][:200]
        out.append(new)
    # with at most one parent each, a cycle is a walk up the parents that comes back
    state = [0] * n  # 0 unseen, 1 on the current walk, 2 known to reach a root
    for start in range(n):
        walk, v = [], start
        while v != -1 and state[v] == 0:
            state[v] = 1
            walk.append(v)
            v = parent[v]
        if v != -1 and state[v] == 1:
            raise d.fail(f"nodes[{v}]", "the node graph has a cycle (a node is its own ancestor)")
        for w in walk:
            state[w] = 2
    return out, parent


def read_gltf(data: bytes, label: str, folder: Path | None = None) -> Gltf:
    """Validate a ``.glb`` (``data`` starts with 'glTF') or ``.gltf`` JSON document and
    return it sanitised.  ``folder`` is where a ``.gltf``'s external buffers may be
    (None: external files are refused).  Raises FormatError naming the place."""
    d = _Doc(label)
    if data[:4] == GLB_MAGIC:
        text, binary = _split_glb(data, label)
        doc = _parse_json(text, label, 20)
    else:
        doc, binary = _parse_json(data, label, 0), None
    asset = doc.get("asset")
    if isinstance(asset, dict) and isinstance(asset.get("version"), str) and not asset["version"].startswith("2"):
        raise d.fail("asset.version", f"{asset['version']!r:.20}: this tool reads glTF 2")
    required = doc.get("extensionsRequired", [])
    if isinstance(required, list):
        bad = [e for e in required if e in _GEOMETRY_EXTENSIONS]
        if bad:
            raise d.fail("extensionsRequired", f"{bad[0]} is not supported (export the model uncompressed)")
    buffers = _buffers(d, doc, binary, folder)
    views, lengths = _views(d, doc, buffers)
    total = sum(len(b) for b in buffers)
    g = Gltf({}, b"", 0, 0, label)
    g.doc["bufferViews"] = views
    g.doc["accessors"] = _accessors(d, doc, views, lengths, ACCESSOR_BUDGET * total + (1 << 20))
    g.binary = b"".join(b + b"\0" * (-len(b) % 4) for b in buffers)
    images, samplers, textures, texture_map = sanitized_textures(doc, g)
    materials = sanitized_materials(d, doc, texture_map)
    meshes, faces = _meshes(d, doc, g, len(materials))
    nodes, parent = _nodes(d, doc, len(meshes))
    scenes_in = d.array(doc, "scenes")
    scenes = []
    for i, s in enumerate(scenes_in):
        roots = s.get("nodes", [])
        if not isinstance(roots, list) or len(roots) > len(nodes):
            raise d.fail(f"scenes[{i}].nodes", "must be an array of node indices")
        for k, r in enumerate(roots):
            if isinstance(r, bool) or not isinstance(r, int) or not 0 <= r < len(nodes):
                raise d.fail(f"scenes[{i}].nodes[{k}]", f"{r!r:.40} is not a node index")
            if parent[r] != -1:
                raise d.fail(f"scenes[{i}].nodes[{k}]", f"node {r} is a child of node {parent[r]}, not a root")
        if len(set(roots)) != len(roots):
            raise d.fail(f"scenes[{i}].nodes", "lists a node twice")
        scenes.append({"nodes": list(roots)})
    if scenes:
        scene = d.int(doc, "scene", "", lo=0, hi=len(scenes) - 1, default=0)
        roots = scenes[scene]["nodes"]
    else:
        scene = 0
        roots = [i for i in range(len(nodes)) if parent[i] == -1]
        scenes = [{"nodes": roots}]
    # triangles of every instance the default scene places (a tree: each node once)
    count, inst, stack = 0, 0, list(roots)
    while stack:
        v = stack.pop()
        node = nodes[v]
        if "mesh" in node:
            inst += 1
            count += faces[node["mesh"]]
            if count > MAX_FACES:
                raise d.fail(f"nodes[{v}]", f"the scene places more than {MAX_FACES:,} triangles")
        stack.extend(node.get("children", ()))
    if inst > MAX_OBJECTS:
        raise d.fail("nodes", f"the scene places {inst:,} meshes, more than {MAX_OBJECTS:,}")
    g.doc.update({"asset": {"version": "2.0"}, "scene": scene, "scenes": scenes, "nodes": nodes,
                  "meshes": meshes, "materials": materials,
                  "buffers": [{"byteLength": len(g.binary)}] if g.binary else []})
    if not materials:
        del g.doc["materials"]
    for key, items in (("images", images), ("samplers", samplers), ("textures", textures)):
        if items and materials:
            g.doc[key] = items
    g.faces, g.instances = count, inst
    return g


def sanitized_glb(g: Gltf) -> bytes:
    """The validated document as a GLB file: one JSON chunk and one BIN chunk."""
    text = json.dumps(g.doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    parts = [struct.pack("<II", len(text), CHUNK_JSON), text]
    if g.binary:
        parts += [struct.pack("<II", len(g.binary), CHUNK_BIN), g.binary]
    body = b"".join(parts)
    return struct.pack("<4sII", GLB_MAGIC, 2, 12 + len(body)) + body
