"""The images, samplers, textures and materials of a glTF, sanitised (:mod:`.gltf`
calls these while it validates a document).

An image is kept only when it is a PNG or JPEG held in a bufferView, at most
``MAX_IMAGE_PIXELS`` by its header (read without decoding) and its pixels decode; a
damaged one is an error (trimesh would decode it lazily, far from here), any other is
dropped with the textures naming it and the materials' references to those: a model
keeps its colours.  Materials keep their colours, colour textures, metal and
roughness, alpha mode, sides and name, clamped to their ranges.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from ..errors import FormatError
from .limits import MAX_IMAGE_PIXELS

if TYPE_CHECKING:
    from .gltf import Gltf, _Doc

_IMAGE_TYPES = {"image/png": b"\x89PNG\r\n\x1a\n", "image/jpeg": b"\xff\xd8"}


def _image_size(data: bytes) -> tuple[int, int] | None:
    """(width, height) from an image's header, without decoding it; None if unreadable."""
    import io

    try:
        from PIL import Image

        with Image.open(io.BytesIO(data)) as im:
            return im.size
    except Exception:  # PIL raises many kinds for a damaged header
        return None


def _decode_error(data: bytes) -> str | None:
    """Why an image's pixels cannot be decoded (its size is checked first), or None."""
    import io

    from PIL import Image

    try:
        with Image.open(io.BytesIO(data)) as im:
            im.load()
    except Exception as e:  # PIL raises OSError, SyntaxError, ValueError, zlib.error ...
        return " ".join(str(e).split())[:160] or type(e).__name__
    return None


def sanitized_textures(doc: dict, g: Gltf) -> tuple[list[dict], list[dict], list[dict], dict[int, int]]:
    """Sanitised images, samplers and textures, and old texture index -> new.

    An image is kept only when it is a PNG or JPEG in a bufferView, no larger than
    MAX_IMAGE_PIXELS by its header; the rest (URIs, other kinds, damaged or huge ones)
    are dropped with the textures that name them: a model keeps its colours."""
    views = g.doc["bufferViews"]
    images: list[dict] = []
    image_map: dict[int, int] = {}
    raw_images = doc.get("images", [])
    for i, im in enumerate(raw_images if isinstance(raw_images, list) else []):
        if not isinstance(im, dict):
            continue
        vi, mime = im.get("bufferView"), im.get("mimeType")
        if isinstance(vi, bool) or not isinstance(vi, int) or not 0 <= vi < len(views) or mime not in _IMAGE_TYPES:
            continue
        v = views[vi]
        data = g.binary[v["byteOffset"]: v["byteOffset"] + v["byteLength"]]
        if not data.startswith(_IMAGE_TYPES[mime]):
            continue
        size = _image_size(data)
        if size is None or size[0] < 1 or size[1] < 1 or size[0] * size[1] > MAX_IMAGE_PIXELS:
            continue
        damage = _decode_error(data)
        if damage:  # a header that reads but pixels that do not: trimesh decodes lazily, far from here
            name = im.get("name")
            named = f" {name!r:.60}" if isinstance(name, str) and name else ""
            raise FormatError(f"{g.label}: images[{i}]{named} ({mime} in bufferView {vi}): "
                              f"the image is damaged: {damage}")
        image_map[i] = len(images)
        images.append({"bufferView": vi, "mimeType": mime})
    samplers: list[dict] = []
    sampler_map: dict[int, int] = {}
    raw_samplers = doc.get("samplers", [])
    for i, sm in enumerate(raw_samplers if isinstance(raw_samplers, list) else []):
        if isinstance(sm, dict):
            sampler_map[i] = len(samplers)
            samplers.append({k: sm[k] for k in ("magFilter", "minFilter", "wrapS", "wrapT")
                             if isinstance(sm.get(k), int) and not isinstance(sm.get(k), bool)
                             and sm[k] in (9728, 9729, 9984, 9985, 9986, 9987, 33071, 33648, 10497)})
    textures: list[dict] = []
    texture_map: dict[int, int] = {}
    raw_textures = doc.get("textures", [])
    for i, t in enumerate(raw_textures if isinstance(raw_textures, list) else []):
        src = t.get("source") if isinstance(t, dict) else None
        if isinstance(src, bool) or not isinstance(src, int) or src not in image_map:
            continue
        tex: dict[str, Any] = {"source": image_map[src]}
        smp = t.get("sampler")
        if isinstance(smp, int) and not isinstance(smp, bool) and smp in sampler_map:
            tex["sampler"] = sampler_map[smp]
        texture_map[i] = len(textures)
        textures.append(tex)
    return images, samplers, textures, texture_map


def sanitized_materials(d: _Doc, doc: dict, texture_map: dict[int, int] | None = None) -> list[dict]:
    """Materials with their colours and colour textures (``texture_map``: the textures
    kept, old index -> new; a reference to any other is dropped)."""
    texture_map = texture_map or {}
    out = []
    for i, m in enumerate(d.array(doc, "materials")):
        where = f"materials[{i}]"
        mat: dict[str, Any] = {}
        pbr = m.get("pbrMetallicRoughness", {})
        if not isinstance(pbr, dict):
            raise d.fail(f"{where}.pbrMetallicRoughness", "must be an object")
        colour = d.numbers(pbr, "baseColorFactor", f"{where}.pbrMetallicRoughness", 4)
        p2: dict[str, Any] = {}
        if colour is not None:
            p2["baseColorFactor"] = [min(max(c, 0.0), 1.0) for c in colour]
        tex = pbr.get("baseColorTexture")
        if isinstance(tex, dict):
            k = tex.get("index")
            uv = tex.get("texCoord", 0)
            if isinstance(k, int) and not isinstance(k, bool) and k in texture_map and uv == 0:
                p2["baseColorTexture"] = {"index": texture_map[k]}
        for key in ("metallicFactor", "roughnessFactor"):
            v = pbr.get(key)
            if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v):
                p2[key] = min(max(float(v), 0.0), 1.0)
        if p2:
            mat["pbrMetallicRoughness"] = p2
        if m.get("alphaMode") in ("OPAQUE", "MASK", "BLEND"):
            mat["alphaMode"] = m["alphaMode"]
        if m.get("doubleSided") is True:
            mat["doubleSided"] = True
        if isinstance(m.get("name"), str):
            mat["name"] = m["name"][:200]
        out.append(mat)
    return out
