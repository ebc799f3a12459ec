"""Mutators for the fuzz harness (:mod:`fuzz_inputs`): byte mutations (flips, extreme
integers, truncation, splices), line mutations of text formats, structure mutations
(glTF JSON: counts, strides, offsets, references; TOML values of the wrong type and
deep nesting; replay headers), damaged image pixels and floor-plan coordinate bombs.
Each takes (data, rng, pool of other seeds) and returns the mutated bytes."""

from __future__ import annotations

import json
import random
import re
import struct
import zlib
from pathlib import Path

import numpy as np
from fuzz_files import (full_size_png, glb_bytes, jpeg_bytes, jpeg_claiming, png_bytes, textured_box_gltf,
                        zlib_bomb_replay)

EXTREME_INTS = [0, 1, 2, 3, 4, 7, 0x7F, 0x80, 0xFF, 0x100, 0x7FFF, 0x8000, 0xFFFF, 0x10000, 0x7FFFFFFF,
                0x80000000, 0xFFFFFFFF, 6, 12, 20, 24, 100000]

JSON_VALUES = [0, 1, -1, 2, 3, 4, 5, 6, 7, 12, 252, 253, -4, 2 ** 31, 2 ** 32 + 4, 10 ** 9, 10 ** 30, 1e308, -1e308,
               0.5, "x", "", None, True, False, [], [0], [0, 0, 0], {}, {"a": 1}, "data:,", "../../etc/passwd",
               "/dev/zero", "/etc/passwd", "VEC3", "SCALAR", "MAT4", 5126, 5125, 5123, 5121, 5120]

TOML_VALUES = ["nan", "inf", "-inf", "-1", "0", "1e308", '"text"', "[]", "[1, 2]", "true", "{}", "-0.0", "1e-300",
               "3", "1", '"/etc/passwd"', '"/dev/zero"', '"../../../etc/passwd"', '"model.glb"', "[[1, 2, 3]]",
               "[[0.0, 0.0], [1.0, 1.0]]", "2e9", '"\\u0000"', "[" * 40 + "]" * 40, '{a = {b = {c = 1}}}']


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
