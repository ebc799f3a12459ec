"""Hostile inputs for every reader: hand-made cases (the ones issues 18 and 21 name) and
generators of mutated files, plus the harness that runs them.

Each *kind* of input has seed files (real ones from tests/data, the bundled arenas and
vehicles, and small files made here), a mutator and a target: the function that reads
such a file the way the tools do (``models.load_scene`` for models, ``run_check`` and
play's loaders for bundles, ``read_replay`` for replays, ...).  A target may succeed or
raise a :class:`TanktoolError`; anything else is a failure, and so is an input whose
reading takes more than ``TIME_LIMIT`` seconds of CPU time.

Generators by kind of attack: byte mutations (flips, extreme integers, truncation,
splices), structure mutations (glTF JSON: counts, strides, offsets, self-referencing
and cyclic node graphs; 3DS chunk lengths; TOML values of the wrong type and deep
nesting; replay headers), paths (files named in manifests pointing out of the bundle,
at /etc/passwd, /dev/zero, through symbolic links), bombs (zlib, huge arcs and
counts), and many objects.
"""

from __future__ import annotations

import base64
import functools
import io
import json
import os
import random
import re
import shutil
import struct
import time
import traceback
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
DATA = Path(__file__).resolve().parent / "data"
CLEAN = DATA / "check_clean"
#: seconds of CPU time one input may take (issue 18)
TIME_LIMIT = 2.0

EXTREME_INTS = [0, 1, 2, 3, 4, 7, 0x7F, 0x80, 0xFF, 0x100, 0x7FFF, 0x8000, 0xFFFF, 0x10000, 0x7FFFFFFF,
                0x80000000, 0xFFFFFFFF, 6, 12, 20, 24, 100000]
JSON_VALUES = [0, 1, -1, 2, 3, 4, 5, 6, 7, 12, 252, 253, -4, 2 ** 31, 2 ** 32 + 4, 10 ** 9, 10 ** 30, 1e308, -1e308,
               0.5, "x", "", None, True, False, [], [0], [0, 0, 0], {}, {"a": 1}, "data:,", "../../etc/passwd",
               "/dev/zero", "/etc/passwd", "VEC3", "SCALAR", "MAT4", 5126, 5125, 5123, 5121, 5120]
TOML_VALUES = ["nan", "inf", "-inf", "-1", "0", "1e308", '"text"', "[]", "[1, 2]", "true", "{}", "-0.0", "1e-300",
               "3", "1", '"/etc/passwd"', '"/dev/zero"', '"../../../etc/passwd"', '"model.glb"', "[[1, 2, 3]]",
               "[[0.0, 0.0], [1.0, 1.0]]", "2e9", '"\\u0000"', "[" * 40 + "]" * 40, '{a = {b = {c = 1}}}']


# ---------------------------------------------------------------------------- builders

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


# ---------------------------------------------------------------------------- mutators

def mutate_bytes(data: bytes, rng: random.Random, pool: list[bytes] | None = None) -> bytes:
    b = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        op = rng.randrange(9)
        n = len(b)
        if op == 0 and n:
            i = rng.randrange(n)
            b[i] ^= 1 << rng.randrange(8)
        elif op == 1 and n:
            b[rng.randrange(n)] = rng.choice([0, 0xFF, 0x7F, 0x80, rng.randrange(256)])
        elif op == 2 and n >= 4:
            i = rng.randrange(n - 3)
            b[i:i + 4] = struct.pack("<I", rng.choice(EXTREME_INTS + [n, n - i, rng.randrange(2 ** 32)]) & 0xFFFFFFFF)
        elif op == 3 and n >= 2:
            i = rng.randrange(n - 1)
            b[i:i + 2] = struct.pack("<H", rng.choice(EXTREME_INTS) & 0xFFFF)
        elif op == 4:
            b = b[: rng.randrange(n + 1)]
        elif op == 5 and n:
            i, j = sorted(rng.randrange(n) for _ in range(2))
            del b[i:j]
        elif op == 6 and n:
            i, j = sorted(rng.randrange(n) for _ in range(2))
            k = rng.randrange(n + 1)
            b[k:k] = b[i:j] * rng.choice([1, 2, 8])
        elif op == 7:
            k = rng.randrange(n + 1)
            b[k:k] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
        elif op == 8 and pool:
            other = rng.choice(pool)
            if other:
                i = rng.randrange(len(other))
                k = rng.randrange(n + 1)
                b[k:k] = other[i:i + rng.randint(1, 256)]
    return bytes(b)


NUMBERS = ["0", "-0", "1e300", "-1e300", "1e-300", "nan", "inf", "-inf", "1e15", "-1", "2", "65535", "4294967296",
           "1" * 50, "0x10", "", "--", "1e99999", "3.4e38", "-3.4e38", "999999999", "1e7", "1e9"]


LINE_OPS = ("delete", "duplicate", "swap", "field", "cut_line", "cut_file")


def line_op(lines: list[str], i: int, op: str, rng: random.Random, numbers: list[str]) -> list[str]:
    """One of the mutations every line-based format gets (``LINE_OPS``) at line ``i``:
    delete it, duplicate it elsewhere, swap it with another, replace one of its fields
    by one of ``numbers``, cut it short, cut the file short.  Returns the lines."""
    if op == "delete":
        del lines[i]
    elif op == "duplicate":
        lines.insert(rng.randrange(len(lines) + 1), lines[i])
    elif op == "swap":
        j = rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
    elif op == "field":
        fields = lines[i].split()
        if fields:
            fields[rng.randrange(len(fields))] = rng.choice(numbers)
            lines[i] = " ".join(fields)
    elif op == "cut_line":
        lines[i] = lines[i][: rng.randrange(len(lines[i]) + 1)]
    elif op == "cut_file":
        lines = lines[: rng.randrange(len(lines) + 1)]
    return lines


def mutate_text(data: bytes, rng: random.Random, pool: list[bytes] | None = None) -> bytes:
    text = data.decode("utf-8", "replace")
    lines = text.splitlines()
    for _ in range(rng.randint(1, 4)):
        if not lines:
            lines = ["0"]
        i = rng.randrange(len(lines))
        op = rng.randrange(8)
        if op < len(LINE_OPS):
            lines = line_op(lines, i, LINE_OPS[op], rng, NUMBERS)
        elif op == 6:
            lines[i:i] = [lines[i]] * rng.choice([10, 100, 1000])
        else:
            # a number in the middle of a line replaced (keeps XML / DXF structure)
            import re
            nums = list(re.finditer(r"-?\d+(\.\d+)?(e[-+]?\d+)?", lines[i]))
            if nums:
                m = rng.choice(nums)
                lines[i] = lines[i][:m.start()] + rng.choice(NUMBERS) + lines[i][m.end():]
    out = ("\n".join(lines) + "\n").encode()
    if rng.random() < 0.2:
        out = mutate_bytes(out, rng, pool)
    return out


def _json_paths(value, path=()):
    yield path, value
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _json_paths(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value[:50]):
            yield from _json_paths(v, path + (i,))


def _set(doc, path, value):
    cur = doc
    for p in path[:-1]:
        cur = cur[p]
    cur[path[-1]] = value


def mutate_json_doc(doc: dict, rng: random.Random) -> dict:
    doc = json.loads(json.dumps(doc))
    for _ in range(rng.randint(1, 3)):
        paths = [p for p, _ in _json_paths(doc) if p]
        if not paths:
            break
        path = rng.choice(paths)
        op = rng.randrange(6)
        cur = doc
        for p in path[:-1]:
            cur = cur[p]
        old = cur[path[-1]]
        if op <= 2:
            _set(doc, path, rng.choice(JSON_VALUES))
        elif op == 3 and isinstance(old, (int, float)) and not isinstance(old, bool):
            _set(doc, path, old + rng.choice([-1, 1, -4, 4, 2 ** 20, -(2 ** 20), 0.5]))
        elif op == 4 and isinstance(old, list):
            if old and rng.random() < 0.5:
                _set(doc, path, old * rng.choice([2, 10, 100]))
            else:
                _set(doc, path, old + [rng.choice(JSON_VALUES)])
        elif op == 5 and isinstance(cur, dict):
            del cur[path[-1]]
    return doc


def mutate_glb(data: bytes, rng: random.Random, pool: list[bytes] | None = None) -> bytes:
    """Structure-aware: edit the JSON chunk (counts, strides, offsets, node graph),
    sometimes the bytes too."""
    from tanktool.formats.gltf import _split_glb

    try:
        text, binary = _split_glb(data, "seed")
        doc = json.loads(text)
    except Exception:
        return mutate_bytes(data, rng, pool)
    r = rng.random()
    if r < 0.15 and doc.get("nodes"):
        # graph attacks: self children, cycles, shared children
        n = len(doc["nodes"])
        a, b = rng.randrange(n), rng.randrange(n)
        doc["nodes"][a].setdefault("children", []).extend([b] * rng.choice([1, 2, 1000]))
    else:
        doc = mutate_json_doc(doc, rng)
    out = glb_bytes(doc, binary or b"")
    if rng.random() < 0.15:
        out = mutate_bytes(out, rng, pool)
    return out


def mutate_toml(data: bytes, rng: random.Random, pool: list[bytes] | None = None) -> bytes:
    lines = data.decode("utf-8", "replace").splitlines()
    for _ in range(rng.randint(1, 3)):
        if not lines:
            break
        i = rng.randrange(len(lines))
        op = rng.randrange(7)
        if op in (0, 1) and "=" in lines[i]:
            key = lines[i].split("=", 1)[0]
            lines[i] = f"{key}= {rng.choice(TOML_VALUES)}"
        elif op == 2:
            del lines[i]
        elif op == 3:
            lines.insert(i, lines[rng.randrange(len(lines))])
        elif op == 4:
            key = rng.choice(["walls", "model", "hull", "spheres", "source", "derived", "mass", "drive", "navgrid",
                              "spawns", "bounds", "floor_y", "name", "grip", "muzzle", "turn_rate"])
            lines.insert(0, f"{key} = {rng.choice(TOML_VALUES)}")
        elif op == 5:
            lines = lines[: rng.randrange(len(lines) + 1)]
        else:
            d = rng.choice([50, 500, 5000])
            lines.insert(0, "deep = " + "[" * d + "]" * d)
    out = ("\n".join(lines) + "\n").encode()
    if rng.random() < 0.1:
        out = mutate_bytes(out, rng, pool)
    return out


def mutate_replay(data: bytes, rng: random.Random, pool: list[bytes] | None = None) -> bytes:
    r = rng.random()
    try:
        hlen = struct.unpack_from("<I", data, 5)[0]
        head = json.loads(data[9:9 + hlen])
    except Exception:
        return mutate_bytes(data, rng, pool)
    if r < 0.55:
        key = rng.choice(list(head) + ["options", "player", "names"])
        head[key] = rng.choice(JSON_VALUES + [float("nan"), float("inf"), "../../../../etc/passwd", 1e-300,
                                              365 * 86400.0, 10 ** 12, {"bot": "x"}, {"integrator": 1}])
        h = json.dumps(head).encode()
        return b"TTRP\x01" + struct.pack("<I", len(h)) + h + data[9 + hlen:]
    if r < 0.7:
        body = bytearray(zlib.decompress(data[9 + hlen:]))
        if body:
            for _ in range(rng.randint(1, 8)):
                i = rng.randrange(len(body))
                body[i] = rng.choice([0, 0xFF, 0x7F, 0xF0, rng.randrange(256)])
        return data[:9 + hlen] + zlib.compress(bytes(body))
    if r < 0.75:
        return zlib_bomb_replay(data, rng.choice([8, 64]) << 20)
    return mutate_bytes(data, rng, pool)


# ---------------------------------------------------------------------------- images

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


def image_case(rng: random.Random) -> tuple[bytes, str]:
    """(image bytes, the mime type a glTF would give them): valid, huge by header,
    truncated, damaged, of another kind than said."""
    r = rng.randrange(12)
    if r == 0:
        return png_bytes(rng.choice([1, 4, 64]), rng.choice([1, 4, 64]), colour=rng.choice([0, 2, 6])), "image/png"
    if r == 1:
        return jpeg_bytes(), "image/jpeg"
    if r == 2:   # huge by header, little or no pixel data
        w, h = rng.choice([(4097, 4096), (5000, 5000), (9000, 9000), (65535, 65535), (2 ** 31 - 1, 1), (1, 10 ** 9)])
        return png_bytes(w, h, rows=rng.choice([0, 1]) if w <= 65535 else 0), "image/png"
    if r == 3:   # at the limit, all its rows (a 64 MB image from a few KB: a zlib bomb the limit allows)
        return full_size_png(), "image/png"
    if r == 4:
        return jpeg_claiming(*rng.choice([(65500, 65500), (4097, 4097), (0, 0), (9000, 9000)])), "image/jpeg"
    if r == 5:   # truncated
        data = png_bytes(64, 64) if rng.random() < 0.5 else jpeg_bytes()
        return data[:rng.randrange(8, len(data))], "image/png" if data.startswith(b"\x89PNG") else "image/jpeg"
    if r == 6:   # the wrong mime type for the bytes
        return rng.choice([(png_bytes(4, 4), "image/jpeg"), (jpeg_bytes(), "image/png"),
                           (b"GIF89a" + bytes(40), "image/png"), (png_bytes(4, 4), rng.choice(["image/gif", "text/plain", "", 7]))])
    if r == 7:   # the magic, then garbage
        return rng.choice([b"\x89PNG\r\n\x1a\n", b"\xff\xd8\xff"]) + bytes(rng.randrange(256) for _ in range(200)), \
            rng.choice(["image/png", "image/jpeg"])
    data, mime = image_case(rng) if rng.random() < 0.9 else (png_bytes(8, 8), "image/png")
    return mutate_bytes(data, rng), mime


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


def mutate_textured_glb(data: bytes, rng: random.Random, pool: list[bytes] | None = None) -> bytes:
    """A textured box with one of :func:`image_case`'s images, its bufferView index
    sometimes out of range or of the wrong type; else a structure mutation."""
    if rng.random() < 0.7:
        image, mime = image_case(rng)
        view = None
        if rng.random() < 0.2:
            view = rng.choice([-1, 99, 2 ** 40, True, "0", None, 1.5, 0])
        doc, binary = textured_box_gltf(image, mime, view, rng)
        return glb_bytes(doc, binary)
    return mutate_glb(data, rng, pool)


def _textured_glb_seeds(_tmp: Path) -> list[bytes]:
    return [glb_bytes(*textured_box_gltf(png_bytes(8, 8), "image/png")),
            glb_bytes(*textured_box_gltf(jpeg_bytes(), "image/jpeg"))]


#: an .obj with texture coordinates naming a material library (the box with a vt per vertex)
TEXTURED_OBJ = "mtllib case.mtl\n" + "".join(
    f"v {x} {y} {z}\n" for x in (0, 4) for y in (0, 1) for z in (0, 4)) + "".join(
    f"vt {u} {v}\n" for u in (0, 1) for v in (0, 1)) + "usemtl skin\n" + "".join(
    f"f {a}/{1 + (a % 4)} {b}/{1 + (b % 4)} {c}/{1 + (c % 4)}\n" for a, b, c in (
        (1, 3, 4), (1, 4, 2), (5, 6, 8), (5, 8, 7), (1, 2, 6), (1, 6, 5),
        (3, 7, 8), (3, 8, 4), (1, 5, 7), (1, 7, 3), (2, 4, 8), (2, 8, 6)))


def textured_obj_companions(folder: Path, rng: random.Random) -> None:
    """Beside ``folder/case.obj``: a material library whose ``map_Kd`` lines name an
    image (one of :func:`image_case`'s, or none), with options, under odd names, or
    leading out of the folder (``..``, /etc/passwd, /dev/zero, a link, a folder)."""
    image, _ = image_case(rng)
    name = rng.choice(["skin.png", "SKIN.PNG", "textures/skin.png", "maps\\skin.png", "skin.jpg"])
    target = folder / name.replace("\\", "/")
    target.parent.mkdir(parents=True, exist_ok=True)
    r = rng.random()
    if r < 0.75:
        target.write_bytes(image)
    elif r < 0.82:
        target.symlink_to(rng.choice(["/dev/zero", "/etc/passwd", "../../../etc/hostname"]))
    elif r < 0.86:
        target.mkdir(exist_ok=True)
    named = rng.choice([name, name, name, "../skin.png", "/etc/passwd", "/dev/zero", "missing.png", "",
                        "-s 2 2 1 " + name, "-o 0.5 0.5 -clamp on " + name, "-bm", "a" * 5000 + ".png"])
    lines = ["newmtl skin", "Kd 1 1 1", f"map_Kd {named}"]
    if rng.random() < 0.3:
        lines += ["newmtl other", f"map_Kd {name}", "map_Kd " + name]
    text = "\n".join(lines) + "\n"
    if rng.random() < 0.3:
        text = mutate_text(text.encode(), rng).decode("utf-8", "replace")
    (folder / "case.mtl").write_text(text)


def _textured_import(path: Path) -> None:
    """What import does with a textured model: load it, then the game's model.glb
    with the textures attached and embedded, the texture files copied."""
    from tanktool.formats.materials import export_glb
    from tanktool.formats.models import load_scene

    export_glb(path, load_scene(path), path.parent / "bundle", warn=lambda _m: None)


def mutate_image_pixels(data: bytes, rng: random.Random, pool: list[bytes] | None = None) -> bytes:
    """A textured box whose embedded PNG has bytes changed past its header (inside
    the compressed pixels): the header still reads, the pixels do not (issue 26)."""
    image = bytearray(png_bytes(rng.choice([8, 32, 64]), rng.choice([8, 32, 64])))
    for _ in range(rng.randint(1, 3)):
        k = rng.randrange(41, max(42, len(image) - 12))   # past IHDR (8 + 25 bytes) and the IDAT length/tag
        image[k] = rng.randrange(256)
    return glb_bytes(*textured_box_gltf(bytes(image), "image/png"))


#: what a coordinate of a plan is changed to: a stretch to 65 km, far, huge, tiny, overflowing
COORDINATE_BOMBS = ["65535", "-65535", "1e6", "1e9", "-1e12", "1e308", "-1e308", "1e-300", "1e309", "4e5"]


def mutate_plan_coordinates(data: bytes, rng: random.Random, pool: list[bytes] | None = None) -> bytes:
    """A floor plan with one to three of its numbers replaced by a coordinate bomb."""
    text = data.decode("utf-8", "replace")
    spans = [m.span() for m in re.finditer(r"(?<![\w.])-?\d+(\.\d+)?(?![\w.])", text)]
    if "ENTITIES" in text:   # DXF: only the values of coordinate group codes (10-39), not the codes
        lines = text.split("\n")
        at = np.cumsum([0] + [len(ln) + 1 for ln in lines])
        spans = [(int(at[i + 1]), int(at[i + 1]) + len(lines[i + 1])) for i in range(0, len(lines) - 1, 2)
                 if lines[i].strip().isdigit() and 10 <= int(lines[i].strip()) <= 39]
    if not spans:
        return data
    for a, b in sorted(rng.sample(spans, min(len(spans), rng.randint(1, 3))), reverse=True):
        text = text[:a] + rng.choice(COORDINATE_BOMBS) + text[b:]
    return text.encode()


def mutate_replay_fields(data: bytes, rng: random.Random, pool: list[bytes] | None = None) -> bytes:
    """A replay with one to three header fields removed (or set to null)."""
    hlen = struct.unpack_from("<I", data, 5)[0]
    head = json.loads(data[9:9 + hlen])
    for key in rng.sample(sorted(head), min(len(head), rng.randint(1, 3))):
        if rng.random() < 0.8:
            del head[key]
        else:
            head[key] = None
    h = json.dumps(head).encode()
    return data[:5] + struct.pack("<I", len(h)) + h + data[9 + hlen:]


def _plan_work(path: Path) -> None:
    """What import-arena does with a plan before the heavy work: read it (the overlap
    limit), then check the cells it asks for against the file's budget."""
    from tanktool.formats.limits import check_cells
    from tanktool.formats.models import load_scene

    scene = load_scene(path)
    lo, hi = scene.bounds
    check_cells(str(path), float(hi[0] - lo[0]), float(hi[2] - lo[2]), 0.5, path.stat().st_size)


# ---------------------------------------------------------------------------- targets

def _load_scene(path: Path) -> None:
    from tanktool.formats.models import load_scene

    load_scene(path)


def _check_triangles(path: Path) -> None:
    from tanktool.check.glb import load_triangles

    load_triangles(path)


def _walls(path: Path) -> None:
    from tanktool.formats.walls_txt import read_walls

    read_walls(path)


def _hull(path: Path) -> None:
    from tanktool.formats.vehicle_bundle import read_hull

    read_hull(path)


def _spheres(path: Path) -> None:
    from tanktool.geometry.spheres import read_spheres

    read_spheres(path)


def _bindings(path: Path) -> None:
    from tanktool.game.input import load_bindings

    load_bindings(path)


def _quadtree(path: Path) -> None:
    from tanktool.nav.quadtree import WallQuadtree

    WallQuadtree.load(path)


def _replay(path: Path) -> None:
    from tanktool.sim.match import load_match_arena, load_tank_spec
    from tanktool.sim.replay import play_replay, read_replay

    tape = read_replay(path)
    # what play does next: the bundles the tape names, then the playback itself
    arena = load_match_arena(tape.header.get("arena_ref") or "box")
    spec = load_tank_spec(tape.header.get("vehicle_ref") or "light")
    if int(tape.header["steps"]) <= 240:   # a long valid recording is long to play: that is no bug
        play_replay(tape, arena, spec)


def _check_bundle(path: Path) -> None:
    """``tanktool check`` on the bundle, then play's loaders on it."""
    from tanktool.check import run_check
    from tanktool.errors import TanktoolError
    from tanktool.sim.match import load_match_arena, load_tank_spec

    report = run_check([path])
    crashes = [d.format() for d in report.diagnostics if d.code == "X001"]
    if crashes:
        raise AssertionError(f"check crashed: {crashes[0]}")
    try:
        if (path / "arena.toml").exists():
            load_match_arena(path)
        else:
            load_tank_spec(path)
        failed = None
    except TanktoolError as e:
        failed = e
    errors = [d for d in report.diagnostics if d.severity == "error"]
    if failed is not None and not errors and not report.unreadable:
        raise AssertionError(f"check found no error but play stops: {failed}")
    if failed is not None:
        raise failed


@dataclass
class Kind:
    """One kind of input: where its seeds come from, how to mutate, what reads it."""

    name: str
    suffix: str
    seeds: Callable[[Path], list[bytes]]
    mutate: Callable[[bytes, random.Random, list[bytes] | None], bytes]
    target: Callable[[Path], None]
    bundle: Path | None = None     # a bundle the file is put into (as ``suffix``), else a bare file
    share: int = 1                 # relative number of cases in a run
    companions: Callable[[Path, random.Random], None] | None = None   # more files beside a bare one


def _files(*globs: str) -> Callable[[Path], list[bytes]]:
    def seeds(_tmp: Path) -> list[bytes]:
        out = []
        for g in globs:
            for p in sorted(ROOT.glob(g)):
                if p.is_file() and p.stat().st_size < 400_000:
                    out.append(p.read_bytes())
        return out
    return seeds


def _trimesh_seeds(ext: str) -> Callable[[Path], list[bytes]]:
    def seeds(_tmp: Path) -> list[bytes]:
        import trimesh

        out = []
        for mesh in (trimesh.creation.box(extents=(2, 1, 3)), trimesh.creation.icosphere(1)):
            for ft in ([ext] if ext != "stl" else ["stl", "stl_ascii"]) if ext != "ply" else ["ply"]:
                data = mesh.export(file_type=ft)
                out.append(data.encode() if isinstance(data, str) else data)
        if ext == "ply":
            data = trimesh.creation.box().export(file_type="ply", encoding="ascii")
            out.append(data.encode() if isinstance(data, str) else data)
        return out
    return seeds


def _glb_seeds(_tmp: Path) -> list[bytes]:
    return [box_glb(False), box_glb(True), (ROOT / "arenas/box/model.glb").read_bytes(),
            (CLEAN / "vehicles/tank/model.glb").read_bytes(), *named_glb_cases().values()]


def _3ds_seeds(tmp: Path) -> list[bytes]:
    return _files("tests/data/models3ds/*.3ds", "tests/data/models3ds/*.3DS", "arenas/paper2002/*.3ds")(tmp) + \
        [threeds_objects(40), threeds_objects(300)]


def _gltf_seeds(_tmp: Path) -> list[bytes]:
    doc, binary = box_gltf(True)
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(binary).decode()
    return [json.dumps(doc).encode()]


def _replay_seeds(tmp: Path) -> list[bytes]:
    data = make_replay(tmp)
    return [data, replay_with(data, integrator="../../../../etc/passwd"), replay_with(data, dt=0.0),
            replay_with(data, steps=365 * 86400 * 120, seconds=365 * 86400.0), replay_with(data, bots="4")]


def _bindings_seeds(_tmp: Path) -> list[bytes]:
    from tanktool.formats.bundle import dumps_toml
    from tanktool.game.input import Bindings

    return [dumps_toml(Bindings().to_dict()).encode()]


KINDS: dict[str, Kind] = {k.name: k for k in [
    Kind("3ds", ".3ds", _3ds_seeds, mutate_bytes, _load_scene, share=4),
    Kind("obj", ".obj", lambda t: _files("arenas/box/box.obj", "arenas/maze/maze.obj")(t) + _trimesh_seeds("obj")(t),
         mutate_text, _load_scene, share=2),
    Kind("stl", ".stl", _trimesh_seeds("stl"), mutate_bytes, _load_scene, share=2),
    Kind("ply", ".ply", _trimesh_seeds("ply"), mutate_bytes, _load_scene),
    Kind("off", ".off", _trimesh_seeds("off"), mutate_text, _load_scene),
    Kind("glb", ".glb", _glb_seeds, mutate_glb, _load_scene, share=4),
    Kind("glb-check", ".glb", _glb_seeds, mutate_glb, _check_triangles, share=3),
    Kind("glb-images", ".glb", _textured_glb_seeds, mutate_textured_glb, _textured_import, share=3),
    Kind("obj-textured", ".obj", lambda t: [TEXTURED_OBJ.encode()],
         lambda d, r, p: mutate_text(d, r, p) if r.random() < 0.3 else d, _textured_import, share=3,
         companions=textured_obj_companions),
    Kind("gltf", ".gltf", _gltf_seeds, lambda d, r, p: json.dumps(mutate_json_doc(json.loads(d), r)).encode(),
         _load_scene),
    Kind("bzw", ".bzw", _files("tests/data/bzw/*.bzw"), mutate_text, _load_scene, share=2),
    Kind("dxf", ".dxf", lambda t: _files("tests/data/plans/*.dxf")(t) + [dxf_circle_bomb()], mutate_text,
         _load_scene, share=2),
    Kind("svg", ".svg", lambda t: _files("tests/data/plans/*.svg")(t) + [svg_arc_bomb()], mutate_text,
         _load_scene, share=2),
    Kind("walls", ".txt", _files("arenas/*/walls.txt"), mutate_text, _walls, share=2),
    Kind("hull", ".txt", _files("vehicles/*/hull.txt"), mutate_text, _hull),
    Kind("spheres", ".txt", _files("vehicles/*/spheres.txt"), mutate_text, _spheres),
    Kind("bindings", ".toml", _bindings_seeds, mutate_toml, _bindings),
    Kind("replay", ".ttr", _replay_seeds, mutate_replay, _replay, share=3),
    Kind("replay-fields", ".ttr", lambda t: _replay_seeds(t)[:1], mutate_replay_fields, _replay),
    Kind("glb-pixels", ".glb", _textured_glb_seeds, mutate_image_pixels, _textured_import, share=2),
    Kind("plan-coords-dxf", ".dxf", _files("tests/data/plans/room.dxf"), mutate_plan_coordinates, _plan_work,
         share=2),
    Kind("plan-coords-svg", ".svg", _files("tests/data/plans/yard.svg"), mutate_plan_coordinates, _plan_work,
         share=2),
    Kind("quadtree", ".npz", _files("arenas/*/quadtree.npz"), mutate_bytes, _quadtree),
    Kind("arena", "arena.toml", _files("arenas/box/arena.toml"), mutate_toml, _check_bundle,
         bundle=ROOT / "arenas" / "box", share=3),
    Kind("arena-walls", "walls.txt", _files("arenas/box/walls.txt"), mutate_text, _check_bundle,
         bundle=ROOT / "arenas" / "box"),
    Kind("arena-glb", "model.glb", _files("arenas/box/model.glb"), mutate_glb, _check_bundle,
         bundle=ROOT / "arenas" / "box"),
    Kind("arena-npz", "quadtree.npz", _files("arenas/box/quadtree.npz"), mutate_bytes, _check_bundle,
         bundle=ROOT / "arenas" / "box"),
    Kind("arena-navgrid", "navgrid.npz", _files("arenas/box/navgrid.npz"), mutate_bytes, _check_bundle,
         bundle=ROOT / "arenas" / "box"),
    Kind("vehicle", "vehicle.toml", _files("tests/data/check_clean/vehicles/tank/vehicle.toml"), mutate_toml,
         _check_bundle, bundle=CLEAN / "vehicles" / "tank", share=3),
    Kind("vehicle-hull", "hull.txt", _files("tests/data/check_clean/vehicles/tank/hull.txt"), mutate_text,
         _check_bundle, bundle=CLEAN / "vehicles" / "tank"),
    Kind("vehicle-spheres", "spheres.txt", _files("tests/data/check_clean/vehicles/tank/spheres.txt"), mutate_text,
         _check_bundle, bundle=CLEAN / "vehicles" / "tank"),
]}


def _navgrid(path: Path) -> None:
    from tanktool.nav.navgrid import NavGrid

    NavGrid.load(path)


def _import_arena(path: Path) -> None:
    """The whole import (formats, then the wall geometry of geometry/walls.py)."""
    from tanktool.importer import import_arena

    import_arena(path, path.parent / "bundle")


def _import_vehicle(path: Path) -> None:
    from tanktool.cli.import_vehicle import build_vehicle_bundle

    build_vehicle_bundle(path, path.parent / "bundle", "v")


def _any_model(tmp: Path) -> list[bytes]:
    return _3ds_seeds(tmp)[:8]


#: readers owned elsewhere (nav/navgrid.py, geometry/walls.py): run on request
#: (``python tests/fuzz_inputs.py N navgrid import-3ds``), not by the tests
EXTRA_KINDS: dict[str, Kind] = {k.name: k for k in [
    Kind("navgrid", ".npz", _files("arenas/*/navgrid.npz"), mutate_bytes, _navgrid),
    Kind("import-3ds", ".3ds", _any_model, mutate_bytes, _import_arena),
    Kind("import-obj", ".obj", _files("arenas/box/box.obj"), mutate_text, _import_arena),
    Kind("import-bzw", ".bzw", _files("tests/data/bzw/*.bzw"), mutate_text, _import_arena),
    Kind("import-svg", ".svg", _files("tests/data/plans/*.svg"), mutate_text, _import_arena),
    Kind("import-stl", ".stl", _trimesh_seeds("stl"), mutate_bytes, _import_arena),
    Kind("import-vehicle", ".3ds", _files("vehicles/*/*.3ds"), mutate_bytes, _import_vehicle),
]}


# ---------------------------------------------------------------------------- running

@dataclass
class Outcome:
    kind: str
    seed: int
    status: str          # "ok", "error" (a TanktoolError), "crash" (anything else)
    seconds: float       # CPU time
    message: str = ""


def case_file(kind: Kind, seed: int, tmp: Path, seeds: list[bytes]) -> Path:
    """Write case ``seed`` of ``kind`` under ``tmp`` and return what the target reads."""
    rng = random.Random(seed * 7919 + zlib.crc32(kind.name.encode()))
    base = seeds[rng.randrange(len(seeds))]
    data = kind.mutate(base, rng, seeds) if rng.random() < 0.95 else base
    case = tmp / f"{kind.name}-{seed}"
    if case.exists():
        shutil.rmtree(case)
    case.mkdir(parents=True)
    if kind.bundle is not None:
        bundle = case / kind.bundle.parent.name / kind.bundle.name
        shutil.copytree(kind.bundle, bundle)
        (bundle / kind.suffix).write_bytes(data)
        manifest = bundle / ("arena.toml" if (bundle / "arena.toml").exists() else "vehicle.toml")
        if kind.suffix != manifest.name and rng.random() < 0.7:
            # the manifest made to agree with the damaged file: no "stale" error to stop at
            from tanktool.formats.bundle import dumps_toml, read_toml, sha256_file

            doc = read_toml(manifest)
            doc.setdefault("derived", {})[kind.suffix] = sha256_file(bundle / kind.suffix)
            manifest.write_text(dumps_toml(doc))
        if rng.random() < 0.05:
            # a file the manifest names replaced by a link out of the bundle
            victim = rng.choice([p for p in bundle.iterdir() if p.name != kind.suffix])
            if victim.is_dir() and not victim.is_symlink():   # the bundle's textures/
                shutil.rmtree(victim)
            else:
                victim.unlink()
            victim.symlink_to(rng.choice(["/etc/passwd", "/dev/zero", "../../../../etc"]))
        return bundle
    f = case / f"case{kind.suffix}"
    f.write_bytes(data)
    if kind.companions is not None:
        kind.companions(case, rng)
    if kind.name == "obj" and rng.random() < 0.3:
        (case / "box.mtl").write_bytes((ROOT / "arenas/box/box.mtl").read_bytes())
    return f


def run_one(kind: Kind, seed: int, tmp: Path, seeds: list[bytes]) -> Outcome:
    from tanktool.errors import TanktoolError

    target = case_file(kind, seed, tmp, seeds)
    t0 = time.process_time()
    try:
        kind.target(target)
        status, msg = "ok", ""
    except TanktoolError as e:
        status, msg = "error", str(e)
        if "\n" in msg.strip():
            status, msg = "crash", f"a multi-line error message: {msg[:300]!r}"
    except Exception as e:  # noqa: BLE001 - that is what the fuzzer looks for
        tb = traceback.extract_tb(e.__traceback__)[-1]
        status, msg = "crash", f"{type(e).__name__}: {str(e)[:300]} ({Path(tb.filename).name}:{tb.lineno})"
    seconds = time.process_time() - t0
    shutil.rmtree(target.parent if kind.bundle is None else target.parent.parent, ignore_errors=True)
    return Outcome(kind.name, seed, status, seconds, msg)


def plan(total: int) -> list[tuple[str, int]]:
    """(kind, seed) pairs: ``total`` cases shared between the kinds by their ``share``."""
    weight = sum(k.share for k in KINDS.values())
    out = []
    for k in KINDS.values():
        n = max(1, round(total * k.share / weight))
        out += [(k.name, s) for s in range(n)]
    return out


def run_inline(cases: list[tuple[str, int]], tmp: Path) -> list[Outcome]:
    """Run the cases in this process (the quick version in the default suite)."""
    seeds: dict[str, list[bytes]] = {}
    out = []
    for name, seed in cases:
        kind = KINDS[name]
        if name not in seeds:
            seeds[name] = kind.seeds(tmp)
        out.append(run_one(kind, seed, tmp, seeds[name]))
    return out


def _worker(conn, cases: list[tuple[str, int]], tmp: str, memory: int) -> None:
    """Child process: bounded address space, one message before and after each case."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    seeds: dict[str, list[bytes]] = {}
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    for i, (name, seed) in enumerate(cases):
        conn.send(("start", i))
        kind = KINDS[name]
        try:
            if name not in seeds:
                seeds[name] = kind.seeds(Path(tmp))
            o = run_one(kind, seed, Path(tmp), seeds[name])
        except MemoryError:
            o = Outcome(name, seed, "crash", 0.0, "MemoryError (more memory than the limit)")
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        if peak - base > 600_000:  # KB: a case took over 600 MB more than the first cases
            o = Outcome(name, seed, "crash", o.seconds, f"peak memory grew to {peak // 1024} MB ({o.message})")
            base = peak
        conn.send(("done", i, o.__dict__))
    conn.send(("end", len(cases)))


def run_isolated(cases: list[tuple[str, int]], tmp: Path, hang: float = 30.0,
                 memory: int = 6 << 30) -> list[Outcome]:
    """Run the cases in child processes with an address-space limit; a case that hangs
    (no answer in ``hang`` s of wall time) or kills the interpreter (a segmentation
    fault) is recorded as a crash and the run goes on with the next case."""
    import multiprocessing as mp

    ctx = mp.get_context("fork")
    out: list[Outcome] = []
    start = 0
    while start < len(cases):
        parent, child = ctx.Pipe()
        p = ctx.Process(target=_worker, args=(child, cases[start:], str(tmp), memory), daemon=True)
        p.start()
        child.close()
        current = None
        while True:
            if not parent.poll(hang):
                name, seed = cases[start + (current or 0)]
                out.append(Outcome(name, seed, "crash", hang, f"no answer in {hang:g} s (a hang)"))
                p.kill()
                p.join()
                start += (current or 0) + 1
                break
            try:
                msg = parent.recv()
            except EOFError:
                p.join()
                name, seed = cases[start + (current or 0)]
                out.append(Outcome(name, seed, "crash", 0.0, f"the interpreter died (exit {p.exitcode})"))
                start += (current or 0) + 1
                break
            if msg[0] == "start":
                current = msg[1]
            elif msg[0] == "done":
                out.append(Outcome(**msg[2]))
            else:
                p.join()
                start = len(cases)
                break
    return out


def failures(outcomes: list[Outcome], limit: float = TIME_LIMIT) -> list[str]:
    return [f"{o.kind} #{o.seed}: {o.message}" if o.status == "crash"
            else f"{o.kind} #{o.seed}: took {o.seconds:.2f} s of CPU ({o.status}: {o.message[:120]})"
            for o in outcomes if o.status == "crash" or o.seconds > limit]


def summary(outcomes: list[Outcome]) -> str:
    rows = {}
    for o in outcomes:
        r = rows.setdefault(o.kind, [0, 0, 0, 0.0])
        r[{"ok": 0, "error": 1, "crash": 2}[o.status]] += 1
        r[3] = max(r[3], o.seconds)
    lines = [f"{'kind':<16}{'ok':>7}{'error':>7}{'crash':>7}{'max s':>8}"]
    lines += [f"{k:<16}{a:>7}{b:>7}{c:>7}{m:>8.2f}" for k, (a, b, c, m) in sorted(rows.items())]
    return "\n".join(lines)


if __name__ == "__main__":  # a manual run: python tests/fuzz_inputs.py [N [KIND...]]
    import sys
    import tempfile

    sys.path.insert(0, str(ROOT))

    n = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    with tempfile.TemporaryDirectory() as d:
        t0 = time.time()
        asked = sys.argv[2:]
        if asked and all(a in EXTRA_KINDS for a in asked):
            KINDS.update(EXTRA_KINDS)
            todo = [(a, s) for a in asked for s in range(n)]
        else:
            todo = [c for c in plan(n) if not asked or c[0] in asked]
        res = run_isolated(todo, Path(d))
        print(summary(res))
        for line in failures(res)[:60]:
            print("FAIL", line)
        print(f"{len(res)} inputs in {time.time() - t0:.0f} s")
