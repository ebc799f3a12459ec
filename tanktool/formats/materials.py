"""Materials and textures of a model: which image files it names, where they are, and
the game's ``model.glb`` with them embedded.

A model names its textures in its own way:

* **.3ds**: a material's diffuse map chunk (0xA200) holds a file name (0xA300), and each
  object's 0x4140 chunk one UV pair per vertex (read by :mod:`.threeds`);
* **.obj**: the ``.mtl`` library's ``map_Kd`` lines (options such as ``-s 2 2`` before
  the file name), ``vt`` coordinates in the ``.obj``;
* **.glb**: images embedded in the binary; **.gltf**: images embedded as data URIs or
  named by a relative ``uri``.

:func:`find_texture` looks for a named image the way artists' tools leave them: the
name as written, relative to the model; then its base name, in any letter case, in the
model's folder, its ``textures/``, ``Textures/`` or ``maps/`` sub-folder, and the same
places in the bundle being rebuilt.  A texture that cannot be found (or read) is one
warning naming the material, the file and where it was looked for; the faces keep
the material's diffuse colour (neutral grey without one), so the model still draws.

:func:`export_glb` is what ``import-arena`` and ``import-vehicle`` call: the scene they
loaded, with its textures attached, as glb bytes (images embedded, so the game needs
no other file), and the image files copied into the bundle so that its copy of the
source model still finds them.
"""

from __future__ import annotations

import json
from urllib.parse import unquote
import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath, PureWindowsPath
from typing import Any, Callable, Sequence

import numpy as np

#: sub-folders where modelling tools put a model's images
TEXTURE_DIRS = ("", "textures", "Textures", "maps", "Maps", "images")
#: image files the game can read (PIL decodes them)
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tga", ".bmp", ".gif", ".tif", ".tiff")
#: an image larger than this on a side is scaled down in model.glb (software OpenGL
#: pays for every texel it keeps; the copied file stays as it was)
MAX_TEXTURE = 2048
#: ``map_Kd`` options and how many values each takes (the file name comes after them)
_MTL_OPTIONS = {"-blendu": 1, "-blendv": 1, "-bm": 1, "-boost": 1, "-cc": 1, "-clamp": 1, "-imfchan": 1,
                "-mm": 2, "-o": 3, "-s": 3, "-t": 3, "-texres": 1, "-type": 1}

Warn = Callable[[str], None]


@dataclass
class TextureUse:
    """One texture a model names: the material, the name as written, and the file
    found for it (None when it is missing or unreadable; ``problem`` says why)."""

    material: str
    name: str
    path: Path | None = None
    problem: str = ""


@dataclass
class ModelTextures:
    """What :func:`model_textures` found: every texture named, in file order."""

    uses: list[TextureUse] = field(default_factory=list)

    @property
    def found(self) -> list[TextureUse]:
        return [u for u in self.uses if u.path is not None]

    @property
    def missing(self) -> list[TextureUse]:
        return [u for u in self.uses if u.path is None]


# ---------------------------------------------------------------------------
# finding files


def _name_parts(name: str) -> tuple[str, ...]:
    """A texture name's path parts, whichever slash the tool that wrote it used."""
    if "\\" in name:
        return PureWindowsPath(name).parts
    return PurePosixPath(name).parts


def search_dirs(model: Path, extra: Sequence[Path] = ()) -> list[Path]:
    """The folders :func:`find_texture` looks in, in order (existing ones only)."""
    out: list[Path] = []
    for base in [model.parent, *extra]:
        for sub in TEXTURE_DIRS:
            d = base / sub if sub else base
            if d.is_dir() and d not in out:
                out.append(d)
    return out


def _in_folder(folder: Path, base: str) -> Path | None:
    """``folder/base``, matching the letter case loosely (3DS names are often upper case)."""
    exact = folder / base
    if exact.is_file():
        return exact
    low = base.lower()
    try:
        for entry in folder.iterdir():
            if entry.name.lower() == low and entry.is_file():
                return entry
    except OSError:
        return None
    return None


def find_texture(name: str, model: Path, extra: Sequence[Path] = ()) -> Path | None:
    """The image file a model's texture ``name`` stands for, or None.

    ``extra`` are more folders to search (the bundle being rebuilt)."""
    try:
        return _find_texture(name, model, extra)
    except (OSError, ValueError):  # a name the file system refuses (too long, a NUL byte): not found
        return None


def _find_texture(name: str, model: Path, extra: Sequence[Path]) -> Path | None:
    name = name.strip().strip('"')
    if not name or name.startswith("data:"):
        return None
    parts = _name_parts(name)
    if not parts:
        return None
    as_written = Path(*parts)
    if not as_written.is_absolute():
        candidate = model.parent / as_written
        if candidate.is_file():
            return candidate
    elif as_written.is_file():
        return as_written
    base = parts[-1]
    for folder in search_dirs(model, extra):
        hit = _in_folder(folder, base)
        if hit is not None:
            return hit
    return None


def _check_image(path: Path) -> str:
    """'' when PIL can read the image at ``path`` and it is at most MAX_IMAGE_PIXELS by
    its header, else why not (a 632-byte JPEG claiming 9000 x 9000 pixels decoded to
    243 MB and took seconds to scale down)."""
    import warnings

    from .limits import MAX_IMAGE_PIXELS

    try:
        from PIL import Image

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # DecompressionBombWarning: the size is judged here
            with Image.open(path) as im:
                w, h = im.size
                if w * h > MAX_IMAGE_PIXELS:
                    side = int(MAX_IMAGE_PIXELS ** 0.5)
                    return f"too large ({w} x {h} pixels, more than {side} x {side})"
                im.verify()
    except Exception as e:  # PIL raises many kinds for a bad image
        return f"not a readable image ({type(e).__name__}: {str(e)[:200]})"
    return ""


# ---------------------------------------------------------------------------
# what each format names


def _mtl_map_name(line: str) -> str:
    """The file name of a ``map_Kd`` line, after its options."""
    words = line.split()[1:]
    i = 0
    while i < len(words) and words[i].lower() in _MTL_OPTIONS:
        i += 1 + _MTL_OPTIONS[words[i].lower()]
    return " ".join(words[i:])


def mtl_libraries(model: Path) -> list[Path]:
    """The material libraries (``mtllib``) an .obj names: regular files in the model's
    own folder only (a name that leaves it, a link or a device is not followed)."""
    from ..errors import FormatError
    from .bundle import bundle_file, read_input

    if model.suffix.lower() != ".obj":
        return []
    try:
        data = read_input(model, "an .obj model")
    except FormatError:
        return []
    out: list[Path] = []
    for raw in data.splitlines():
        if raw.startswith(b"mtllib"):
            for name in raw.split()[1:]:
                try:
                    p = bundle_file(model.parent, name.decode("utf-8", "replace"), "mtllib")
                except FormatError:
                    continue
                if p.is_file() and not p.is_symlink() and p.parent == model.parent and p not in out:
                    out.append(p)
    return out


def mtl_textures(model: Path) -> list[tuple[str, str]]:
    """(material, texture name) of each ``map_Kd`` in the .mtl libraries an .obj names."""
    from ..errors import FormatError
    from .bundle import read_input

    out = []
    for mtl in mtl_libraries(model):
        material = ""
        try:
            text = read_input(mtl, "a material library").decode("utf-8", "replace")
        except FormatError:
            continue
        for raw in text.splitlines():
            line = raw.strip()
            key = line.split(maxsplit=1)[0].lower() if line else ""
            if key == "newmtl":
                material = line.split(maxsplit=1)[1].strip() if len(line.split()) > 1 else ""
            elif key == "map_kd":
                name = _mtl_map_name(line)
                if name:
                    out.append((material, name))
    return out


def threeds_textures(model: Path) -> list[tuple[str, str]]:
    """(material, file name) of each .3ds material with a diffuse texture map."""
    from .threeds import read_3ds

    return [(m.name, m.texture) for m in read_3ds(model).materials if m.texture]


def gltf_textures(model: Path) -> list[tuple[str, str]]:
    """(material, uri) of each image a .gltf names by a relative uri (a .glb's and data
    URIs are inside the file)."""
    try:
        doc = json.loads(model.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    images = doc.get("images") or []
    out = []
    for i, im in enumerate(images):
        uri = im.get("uri") if isinstance(im, dict) else None
        if isinstance(uri, str) and uri and not uri.startswith("data:"):
            out.append((f"image {i}", unquote(uri)))   # a URI: "textures%2Fgrass.webp" is textures/grass.webp
    return out


def gltf_buffers(model: Path) -> list[Path]:
    """The external buffer files (``.bin``) a .gltf names by a relative URI: regular
    files inside the model's folder (a .glb holds its own)."""
    from ..errors import FormatError
    from .bundle import bundle_file

    if model.suffix.lower() != ".gltf":
        return []
    try:
        doc = json.loads(model.read_text(encoding="utf-8-sig"))
    except (OSError, ValueError):
        return []
    out: list[Path] = []
    buffers = doc.get("buffers") if isinstance(doc, dict) else None
    for b in buffers if isinstance(buffers, list) else []:
        uri = b.get("uri") if isinstance(b, dict) else None
        if not isinstance(uri, str) or not uri or uri.startswith("data:"):
            continue
        try:
            p = bundle_file(model.parent, unquote(uri), "buffer")
        except FormatError:
            continue
        if p.is_file() and not p.is_symlink() and p not in out:
            out.append(p)
    return out


def companion_files(model: Path) -> list[Path]:
    """Files a model needs beside it to be read again: an .obj's material libraries,
    a .gltf's buffers.  Paths inside the model's folder (a bundle copies them to the
    same place relative to the model)."""
    return mtl_libraries(model) + gltf_buffers(model)


def _format(model: Path) -> str:
    from .models import detect_format

    try:
        return detect_format(model)
    except Exception:  # the caller has read the model already; a name we do not know has no textures
        return ""


def model_textures(model: str | os.PathLike, extra: Sequence[Path] = ()) -> ModelTextures:
    """Every texture ``model`` names and the file found for each."""
    model = Path(model)
    fmt = _format(model)
    named = {"3ds": threeds_textures, "obj": mtl_textures, "gltf": gltf_textures}.get(fmt, lambda m: [])(model)
    result = ModelTextures()
    seen: set[tuple[str, str]] = set()
    for material, name in named:
        if (material, name) in seen:
            continue
        seen.add((material, name))
        use = TextureUse(material, name)
        path = find_texture(name, model, extra)
        if path is None:
            where = ", ".join(str(d) for d in search_dirs(model, extra)) or str(model.parent)
            use.problem = f"not found (looked for it as named and by its file name in {where})"
        else:
            use.problem = _check_image(path)
            use.path = None if use.problem else path
            if use.problem:
                use.problem = f"{path}: {use.problem}"
        result.uses.append(use)
    return result


def missing_warning(model: Path, use: TextureUse) -> str:
    return (f"{model}: material {use.material!r}: texture {use.name!r} {use.problem}; "
            f"its faces keep the material's colour")


# ---------------------------------------------------------------------------
# images and textured meshes


def load_image(path: Path) -> Any:
    """A PIL image of ``path`` in RGB or RGBA, at most MAX_TEXTURE on a side."""
    from PIL import Image

    with Image.open(path) as im:
        im.load()
        img = im.convert("RGBA" if ("A" in im.getbands() or "transparency" in im.info) else "RGB")
    return fit_image(img)


def fit_image(img: Any) -> Any:
    """A PIL image at most MAX_TEXTURE on a side (scaled down, LANCZOS), else itself."""
    from PIL import Image

    if max(img.size) > MAX_TEXTURE:
        k = MAX_TEXTURE / max(img.size)
        img = img.resize((max(int(img.size[0] * k), 1), max(int(img.size[1] * k), 1)), Image.LANCZOS)
    return img


def _pbr(name: str, rgba: Sequence[int], image: Any) -> Any:
    import trimesh

    # a texture replaces the colour (3DS and MTL practice): white factor, the image as it is
    factor = [255, 255, 255, int(rgba[3])] if image is not None else [int(c) for c in rgba]
    return trimesh.visual.material.PBRMaterial(name=name, baseColorFactor=factor, baseColorTexture=image)


def _textured_3ds_scene(model: Path, scene: Any, images: dict[str, Any], warn: Warn) -> Any:
    """The loaded .3ds ``scene`` rebuilt flat, each object split by material, the parts
    of textured materials with their UVs and image."""
    import trimesh

    from .threeds import _unique_names, read_3ds

    m3 = read_3ds(model)
    objs = [o for o in m3.objects if len(o.faces)]
    by_name = dict(zip(_unique_names([o.name for o in objs]), objs))
    out = trimesh.Scene()
    for mesh in scene.dump():
        obj = by_name.get(mesh.metadata.get("name"))
        if obj is None or len(obj.vertices) != len(mesh.vertices):
            out.add_geometry(mesh)                # not one of ours (or changed): as it was
            continue
        for mi in np.unique(obj.face_material).tolist():
            idx = np.flatnonzero(obj.face_material == mi)
            mat = m3.materials[mi] if mi >= 0 else None
            image = images.get(mat.name) if mat is not None else None
            if image is not None and (obj.uv is None or len(obj.uv) < len(obj.vertices)):
                warn(f"{model}: object {obj.name!r}: material {mat.name!r} has a texture but the object has "
                     f"no texture coordinates (0x4140); drawn in the material's colour")
                image = None
            faces = obj.faces[idx]
            used = np.unique(faces)
            remap = np.full(len(mesh.vertices), -1, dtype=np.int64)
            remap[used] = np.arange(len(used))
            part = trimesh.Trimesh(np.asarray(mesh.vertices)[used], remap[faces], process=False)
            rgba = mat.rgba() if mat is not None else (128, 128, 128, 255)
            if image is not None:
                uv = np.asarray(obj.uv, dtype=np.float64)[used]
                part.visual = trimesh.visual.TextureVisuals(uv=uv, material=_pbr(mat.name, rgba, image))
            else:
                part.visual.face_colors = np.tile(np.asarray(rgba, dtype=np.uint8), (len(faces), 1))
            label = obj.name if mat is None else f"{mesh.metadata.get('name')}:{mat.name}"
            out.add_geometry(part, geom_name=label, node_name=label)
    return out


def _attach_images(scene: Any, images: dict[str, Any]) -> None:
    """Give the meshes of a loaded .obj/.gltf scene the images found for their
    materials (trimesh loads only those it finds at the exact name)."""
    for g in scene.geometry.values():
        vis = getattr(g, "visual", None)
        mat = getattr(vis, "material", None)
        name = getattr(mat, "name", None)
        if mat is None or name not in images or getattr(vis, "uv", None) is None:
            continue
        if getattr(mat, "image", None) is None and getattr(mat, "baseColorTexture", None) is None:
            if hasattr(mat, "baseColorTexture"):
                mat.baseColorTexture = images[name]
            else:
                mat.image = images[name]


def textured_scene(model: str | os.PathLike, scene: Any, extra: Sequence[Path] = (),
                   warn: Warn | None = None) -> tuple[Any, ModelTextures]:
    """``scene`` (as ``models.load_scene`` loaded ``model``, possibly moved since) with
    the model's textures attached, and what was found.  Missing textures are warned
    about once each; their faces keep the material colour."""
    model = Path(model)
    say = warn or (lambda s: None)
    found = model_textures(model, extra)
    for use in found.missing:
        say(missing_warning(model, use))
    if not found.uses:
        return scene, found
    images: dict[str, Any] = {}
    decoded: dict[Path, Any] = {}      # one image per file, however many materials use it
    for use in found.found:
        try:
            if use.path not in decoded:
                decoded[use.path] = load_image(use.path)
            images.setdefault(use.material, decoded[use.path])
        except Exception as e:  # verified above; a file that changed since, or out of memory
            use.problem, use.path = f"{use.path}: cannot be decoded ({e})", None
            say(missing_warning(model, use))
    if _format(model) == "3ds":
        return _textured_3ds_scene(model, scene, images, say), found
    _attach_images(scene, images)
    return scene, found


# ---------------------------------------------------------------------------
# into a bundle


def bundle_name(model: Path, use: TextureUse) -> str:
    """Where a texture goes in the bundle (a relative posix path): the name as the model
    writes it when that stays inside the model's folder, else ``textures/<file>``; so
    the bundle's copy of the model finds it either way."""
    parts = _name_parts(use.name)
    if use.path is not None and parts and not Path(*parts).is_absolute() and ".." not in parts:
        if (model.parent / Path(*parts)).resolve() == use.path.resolve():
            return "/".join(parts)
    return f"textures/{use.path.name if use.path is not None else parts[-1]}"


def copy_textures(model: Path, found: ModelTextures, dest: Path) -> list[str]:
    """Copy every texture found into the bundle folder ``dest`` (being staged); returns
    their bundle-relative names, sorted."""
    names: set[str] = set()
    for use in found.found:
        rel = bundle_name(model, use)
        target = dest / rel
        if rel in names or target.exists():
            names.add(rel)
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(use.path, target)
        names.add(rel)
    return sorted(names)


def export_glb(model: str | os.PathLike, scene: Any, dest: Path, extra: Sequence[Path] = (),
               warn: Warn | None = None) -> tuple[bytes, list[str]]:
    """The game's ``model.glb`` for ``scene`` (loaded from ``model``) with its textures
    embedded, and the texture files copied into ``dest``; returns (glb bytes, the
    bundle-relative names of the copied textures).

    ``extra`` are more folders to look for textures in (the bundle being rebuilt)."""
    model = Path(model)
    out, found = textured_scene(model, scene, extra, warn)
    _drop_bad_uv(model, out, warn or (lambda _m: None))
    _fit_embedded(out)
    copied = copy_textures(model, found, dest) if found.found else []
    return out.export(file_type="glb"), copied


def _fit_embedded(scene: Any) -> None:
    """Images a .glb/.gltf brought in (up to the sanitiser's 4096 x 4096) scaled to
    MAX_TEXTURE like the files found beside a model, so model.glb keeps at most 2048
    on a side (and its export does not encode a 64 MB image)."""
    for g in scene.geometry.values():
        mat = getattr(getattr(g, "visual", None), "material", None)
        for attr in ("baseColorTexture", "image"):
            img = getattr(mat, attr, None)
            if img is not None and hasattr(img, "size") and max(img.size) > MAX_TEXTURE:
                setattr(mat, attr, fit_image(img))


def _drop_bad_uv(model: Path, scene: Any, warn: Warn) -> None:
    """Meshes whose texture coordinates are not one finite (u, v) per vertex (an .obj
    ``vt`` line with one number gave (n, 1), which trimesh's glb export indexes out of
    bounds) are drawn in their material's colour instead, with a warning."""
    import trimesh

    for name, g in scene.geometry.items():
        vis = getattr(g, "visual", None)
        if getattr(vis, "kind", None) != "texture":
            continue
        uv = getattr(vis, "uv", None)
        if uv is None:
            continue
        uv = np.asarray(uv)
        with np.errstate(all="ignore"):   # beyond float32 (1e300) is as bad as NaN: inf in the glb
            ok = uv.ndim == 2 and uv.shape == (len(g.vertices), 2) and uv.dtype.kind == "f" and \
                bool(np.isfinite(uv.astype(np.float32)).all())
        if ok:
            continue
        mat = getattr(vis, "material", None)
        rgba = getattr(mat, "baseColorFactor", None)
        if rgba is None:
            rgba = getattr(mat, "diffuse", None)
        rgba = np.asarray(rgba if rgba is not None else (128, 128, 128, 255), dtype=np.float64).reshape(-1)[:4]
        if rgba.max() <= 1.0:
            rgba = rgba * 255
        g.visual = trimesh.visual.ColorVisuals(g, face_colors=np.tile(np.clip(rgba, 0, 255).astype(np.uint8), (len(g.faces), 1)))
        warn(f"{model}: mesh {name!r}: texture coordinates of shape {uv.shape} for {len(g.vertices)} vertices; "
             f"drawn in its material's colour")
