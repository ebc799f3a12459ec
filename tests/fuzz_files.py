"""Hostile files made here for the fuzz harness (:mod:`fuzz_inputs`) and the tests:
the cases issues 18, 21 and 26 name (glTF documents with negative strides, cyclic node
graphs, huge counts; 3DS files of many objects; SVG arcs and DXF circles that would
explode; zlib bombs and odd replay headers), and small valid images and models to
mutate (PNG, JPEG, a textured box, a textured .obj)."""

from __future__ import annotations

import functools
import io
import json
import random
import struct
import zlib
from pathlib import Path

import numpy as np

def glb_bytes(doc: dict, binary: bytes = b"") -> bytes:
    """A GLB container holding ``doc`` (JSON) and ``binary``."""
    return glb_raw(json.dumps(doc).encode(), binary)


def glb_raw(text: bytes, binary: bytes = b"") -> bytes:
    """A GLB container holding the JSON ``text`` as it is, and ``binary``."""
    text += b" " * (-len(text) % 4)
    binary = binary + b"\0" * (-len(binary) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text
    if binary:
        body += struct.pack("<II", len(binary), 0x004E4942) + binary
    return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body


def box_gltf(interleaved: bool = False) -> tuple[dict, bytes]:
    """A unit cube as a glTF document and its binary buffer (indices + positions
    (+ normals, interleaved with a byteStride when asked))."""
    import trimesh

    box = trimesh.creation.box()
    v = np.asarray(box.vertices, dtype=np.float32)
    f = np.asarray(box.faces, dtype=np.uint16).reshape(-1)
    idx = f.tobytes() + b"\0" * (-len(f.tobytes()) % 4)
    if interleaved:
        n = np.asarray(box.vertex_normals, dtype=np.float32)
        verts = np.hstack([v, n]).tobytes()
        views = [{"buffer": 0, "byteOffset": 0, "byteLength": len(f) * 2},
                 {"buffer": 0, "byteOffset": len(idx), "byteLength": len(verts), "byteStride": 24}]
        acc = [{"bufferView": 0, "componentType": 5123, "count": len(f), "type": "SCALAR"},
               {"bufferView": 1, "componentType": 5126, "count": len(v), "type": "VEC3",
                "min": v.min(axis=0).tolist(), "max": v.max(axis=0).tolist()},
               {"bufferView": 1, "byteOffset": 12, "componentType": 5126, "count": len(v), "type": "VEC3"}]
        attrs = {"POSITION": 1, "NORMAL": 2}
    else:
        verts = v.tobytes()
        views = [{"buffer": 0, "byteOffset": 0, "byteLength": len(f) * 2},
                 {"buffer": 0, "byteOffset": len(idx), "byteLength": len(verts)}]
        acc = [{"bufferView": 0, "componentType": 5123, "count": len(f), "type": "SCALAR"},
               {"bufferView": 1, "componentType": 5126, "count": len(v), "type": "VEC3"}]
        attrs = {"POSITION": 1}
    binary = idx + verts
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
           "nodes": [{"mesh": 0, "children": [1]}, {"mesh": 0, "translation": [2.0, 0.0, 0.0]}],
           "meshes": [{"primitives": [{"attributes": attrs, "indices": 0, "material": 0}]}],
           "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.2, 1.0]}}],
           "accessors": acc, "bufferViews": views, "buffers": [{"byteLength": len(binary)}]}
    return doc, binary


def box_glb(interleaved: bool = False) -> bytes:
    return glb_bytes(*box_gltf(interleaved))


@functools.lru_cache(maxsize=1)
def named_glb_cases() -> dict[str, bytes]:
    """The glTF attacks of issue 21, each a small valid-looking file."""
    out = {}
    doc, binary = box_gltf(interleaved=True)
    d = json.loads(json.dumps(doc))
    d["bufferViews"][1]["byteStride"] = -24          # segfaulted check/glb.py
    out["negative_stride"] = glb_bytes(d, binary)
    d = json.loads(json.dumps(doc))
    d["nodes"] = [{"mesh": 0, "children": [0] * 1000}]  # 3.9 GB before the crash
    out["node_lists_itself"] = glb_bytes(d, binary)
    d = json.loads(json.dumps(doc))
    d["nodes"] = [{"mesh": 0, "children": [1]}, {"mesh": 0, "children": [0]}]
    d["scenes"] = [{"nodes": [0]}]
    out["node_cycle"] = glb_bytes(d, binary)
    d = json.loads(json.dumps(doc))
    d["nodes"] = [{"mesh": 0, "children": [1, 2]}, {"children": [3] * 2}, {"children": [3]}, {"mesh": 0}]
    out["node_two_parents"] = glb_bytes(d, binary)
    d = json.loads(json.dumps(doc))
    d["accessors"][1]["count"] = 500_000_000         # check asked for 11 GiB
    out["huge_count"] = glb_bytes(d, binary)
    d = json.loads(json.dumps(doc))
    d["bufferViews"][0]["byteOffset"] = 2 ** 31
    out["view_outside_buffer"] = glb_bytes(d, binary)
    d = json.loads(json.dumps(doc))
    d["accessors"][0]["bufferView"] = 9
    out["accessor_view_missing"] = glb_bytes(d, binary)
    d = json.loads(json.dumps(doc))
    bad = np.frombuffer(binary[:72], dtype=np.uint16).copy()
    bad[5] = 60000                                   # an index past the 24 vertices
    out["index_out_of_range"] = glb_bytes(d, bad.tobytes() + binary[72:])
    d = json.loads(json.dumps(doc))
    d["buffers"][0]["uri"] = "/etc/passwd"
    out["buffer_uri_passwd"] = glb_bytes(d, binary)
    d = json.loads(json.dumps(doc))
    d["buffers"][0]["uri"] = "../../../../dev/zero"
    out["buffer_uri_dev_zero"] = glb_bytes(d, binary)
    text = json.dumps(doc)[:-1] + ', "extras": ' + "[" * 100_000 + "]" * 100_000 + "}"
    out["deep_json"] = glb_raw(text.encode(), binary)
    d = json.loads(json.dumps(doc))
    d["accessors"] = [dict(d["accessors"][1]) for _ in range(5000)]   # many views of the same bytes
    out["accessor_bomb"] = glb_bytes(d, binary)
    d = json.loads(json.dumps(doc))
    d["accessors"][1]["sparse"] = {"count": 1}
    out["sparse"] = glb_bytes(d, binary)
    d = json.loads(json.dumps(doc))
    d["nodes"] = [{"mesh": 0} for _ in range(3000)]
    d["scenes"] = [{"nodes": list(range(3000))}]
    out["many_nodes"] = glb_bytes(d, binary)
    out["truncated"] = box_glb(True)[:200]
    return out


def deep_json_bytes(depth: int = 100_000) -> bytes:
    return b"[" * depth + b"]" * depth


def threeds_objects(n: int, spacing: float = 1.0) -> bytes:
    """A valid .3ds of ``n`` small box objects on a grid (Z up)."""
    import trimesh

    from tanktool.formats.threeds_write import encode_3ds

    box = trimesh.creation.box(extents=[0.5, 0.5, 2.0])
    objs = []
    side = max(int(np.sqrt(n)), 1)
    for i in range(n):
        v = np.asarray(box.vertices) + [(i % side) * spacing, (i // side) * spacing, 1.0]
        objs.append(("box", v, box.faces, (0.5, 0.5, 0.5)))
    return encode_3ds(objs)


def svg_arc_bomb() -> bytes:
    """556-byte-ish SVG whose arc trimesh sampled into billions of points (issue 21)."""
    return (b'<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">\n'
            b'<path d="M 0 0 L 10 0 L 10 10 L 0 10 Z" stroke="black"/>\n'
            b'<circle cx="5" cy="5" r="10000000" stroke="black"/>\n'
            b'<path d="M 1 1 A 50000000 50000000 0 1 0 2 1" stroke="black"/>\n</svg>\n')


def dxf_circle_bomb() -> bytes:
    return ("0\nSECTION\n2\nENTITIES\n0\nLINE\n8\n0\n10\n0\n20\n0\n11\n10\n21\n0\n"
            "0\nCIRCLE\n8\n0\n10\n5\n20\n5\n40\n1e9\n0\nENDSEC\n0\nEOF\n").encode()


def zlib_bomb_replay(seed_replay: bytes, inflate_to: int = 256 << 20) -> bytes:
    """A replay whose command data inflates to ``inflate_to`` bytes (zeros compress
    about 1000:1) and whose header claims as many changes."""
    hlen = struct.unpack_from("<I", seed_replay, 5)[0]
    head = json.loads(seed_replay[9:9 + hlen])
    head["changes"] = inflate_to // 31
    head["steps"] = 10 ** 7
    head["seconds"] = head["steps"] * head["dt"]
    c = zlib.compressobj(9)
    chunk = b"\0" * (1 << 20)
    body = b"".join(c.compress(chunk) for _ in range(inflate_to >> 20)) + c.flush()
    h = json.dumps(head).encode()
    return b"TTRP\x01" + struct.pack("<I", len(h)) + h + body


def replay_with(seed_replay: bytes, **fields) -> bytes:
    """``seed_replay`` with header fields replaced (the command data kept)."""
    hlen = struct.unpack_from("<I", seed_replay, 5)[0]
    head = json.loads(seed_replay[9:9 + hlen])
    head.update(fields)
    h = json.dumps(head).encode()
    return b"TTRP\x01" + struct.pack("<I", len(h)) + h + seed_replay[9 + hlen:]


def make_replay(tmp: Path) -> bytes:
    """A real 1-second recording on the bundled box arena (2 scripted bots)."""
    from tanktool.sim.match import load_match_arena, load_tank_spec
    from tanktool.sim.replay import encode, record_match

    arena = load_match_arena("box")
    spec = load_tank_spec("light")
    _, tape = record_match(arena, spec, bots=2, seconds=1.0, seed=1, arena_ref="box", vehicle_ref="light",
                           bot="scripted")
    return encode(tape)


def _png_chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def png_bytes(w: int, h: int, rows: int | None = None, colour: int = 2) -> bytes:
    """A PNG declaring w x h pixels (any size: the header is written by hand) holding
    ``rows`` rows of pixel data (all of them by default; fewer make a short image)."""
    channels = {0: 1, 2: 3, 6: 4}[colour]
    n = h if rows is None else rows
    data = zlib.compress(b"".join(b"\0" + bytes(channels * w) for _ in range(n)), 9)
    return (b"\x89PNG\r\n\x1a\n" + _png_chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, colour, 0, 0, 0))
            + _png_chunk(b"IDAT", data) + _png_chunk(b"IEND", b""))


@functools.lru_cache(maxsize=1)
def full_size_png() -> bytes:
    """4096 x 4096 RGBA, every row there (64 MB of pixels in about 70 KB)."""
    row = b"\0" + bytes(4 * 4096)
    z = zlib.compressobj(9)
    data = b"".join(z.compress(row) for _ in range(4096)) + z.flush()
    return (b"\x89PNG\r\n\x1a\n" + _png_chunk(b"IHDR", struct.pack(">IIBBBBB", 4096, 4096, 8, 6, 0, 0, 0))
            + _png_chunk(b"IDAT", data) + _png_chunk(b"IEND", b""))


@functools.lru_cache(maxsize=1)
def jpeg_bytes() -> bytes:
    """A small valid JPEG (PIL's)."""
    from PIL import Image

    buf = io.BytesIO()
    Image.new("RGB", (16, 8), (200, 120, 40)).save(buf, format="JPEG")
    return buf.getvalue()


def jpeg_claiming(w: int, h: int) -> bytes:
    """The small JPEG with its frame header (SOF0) claiming w x h pixels."""
    b = bytearray(jpeg_bytes())
    i = b.find(b"\xff\xc0")
    b[i + 5:i + 9] = struct.pack(">HH", h & 0xFFFF, w & 0xFFFF)
    return bytes(b)


def textured_box_gltf(image: bytes, mime, view=None, rng: random.Random | None = None) -> tuple[dict, bytes]:
    """The box of :func:`box_gltf` with texture coordinates and ``image`` embedded as
    its material's base colour texture (``view``: the image's bufferView index when not
    the one holding it; ``rng``: sometimes a view that leaves the buffer)."""
    import trimesh  # noqa: F401  (box_gltf's)

    doc, binary = box_gltf(False)
    n = doc["accessors"][1]["count"]
    uv = np.random.default_rng(0).random((n, 2), dtype=np.float32).tobytes()
    binary += b"\0" * (-len(binary) % 4)
    doc["bufferViews"].append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(uv)})
    doc["accessors"].append({"bufferView": len(doc["bufferViews"]) - 1, "componentType": 5126, "count": n,
                             "type": "VEC2"})
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = len(doc["accessors"]) - 1
    binary += uv
    binary += b"\0" * (-len(binary) % 4)
    img_view = {"buffer": 0, "byteOffset": len(binary), "byteLength": len(image)}
    if rng is not None and rng.random() < 0.15:
        img_view[rng.choice(["byteOffset", "byteLength"])] = rng.choice([len(binary) + len(image) + 4, 2 ** 31, -1, 0])
    doc["bufferViews"].append(img_view)
    binary += image
    im = {"bufferView": len(doc["bufferViews"]) - 1 if view is None else view}
    if mime != "":
        im["mimeType"] = mime
    doc["images"] = [im]
    doc["samplers"] = [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}]
    doc["textures"] = [{"source": 0, "sampler": 0}]
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    doc["buffers"][0]["byteLength"] = len(binary) + (-len(binary) % 4)
    return doc, binary

#: an .obj with texture coordinates naming a material library (the box with a vt per vertex)
TEXTURED_OBJ = "mtllib case.mtl\n" + "".join(
    f"v {x} {y} {z}\n" for x in (0, 4) for y in (0, 1) for z in (0, 4)) + "".join(
    f"vt {u} {v}\n" for u in (0, 1) for v in (0, 1)) + "usemtl skin\n" + "".join(
    f"f {a}/{1 + (a % 4)} {b}/{1 + (b % 4)} {c}/{1 + (c % 4)}\n" for a, b, c in (
        (1, 3, 4), (1, 4, 2), (5, 6, 8), (5, 8, 7), (1, 2, 6), (1, 6, 5),
        (3, 7, 8), (3, 8, 4), (1, 5, 7), (1, 7, 3), (2, 4, 8), (2, 8, 6)))
