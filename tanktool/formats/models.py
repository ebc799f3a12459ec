"""Load any supported 3D model into the world frame of DESIGN.md.

World frame: metres, right-handed, Y up, floor in the x-z plane.  3DS files are Z-up
and are converted with (x, y, z) -> (x, z, -y); everything else is taken as Y-up.
``up`` overrides the guess and ``scale`` multiplies after the rotation.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import warnings
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from ..errors import FormatError
from .limits import MAX_EXTENT, MAX_FACES, MAX_MODEL_BYTES, MAX_OBJECTS, MERGE_OBJECTS, MIN_EXTENT

#: extensions trimesh (plus our .3ds reader) loads as meshes
MESH_EXTENSIONS = {".3ds", ".obj", ".glb", ".gltf", ".stl", ".ply", ".off"}
#: files that are not meshes but are turned into one (a Z-up scene) before the usual
#: pipeline: BZFlag worlds (formats/bzw.py) and 2D floor plans (formats/floorplan.py)
BUILT_EXTENSIONS = {".bzw", ".dxf", ".svg"}
#: built formats that take --wall-height / --wall-thickness
PLAN_FORMATS = ("dxf", "svg")

#: rotation taking a Z-up frame to our Y-up frame: (x, y, z) -> (x, z, -y)
Z_UP_TO_Y_UP = np.array(
    [[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]], dtype=np.float64
)


def detect_format(path: str | os.PathLike) -> str:
    """File type by extension, else by magic bytes ('3ds' for 0x4D4D).

    Returns the extension without the dot, lower case.  Raises FormatError when the
    file is missing or of no known kind.
    """
    import stat

    path = Path(path)
    try:
        st = path.stat()
    except FileNotFoundError:
        raise FormatError(f"{path}: no such file") from None
    except (OSError, ValueError) as e:
        raise FormatError(f"{path}: cannot read: {getattr(e, 'strerror', None) or e}") from None
    if stat.S_ISDIR(st.st_mode):
        raise FormatError(f"{path}: is a folder, expected a model file")
    if not stat.S_ISREG(st.st_mode):
        raise FormatError(f"{path}: is not a regular file (a device, pipe or socket), expected a model file")
    ext = path.suffix.lower()
    if ext in MESH_EXTENSIONS or ext in BUILT_EXTENSIONS:
        return ext[1:]
    from .bundle import _open_regular

    fd = _open_regular(path, str(path), "a model file")
    try:
        head = os.read(fd, 16)
    except OSError as e:
        raise FormatError(f"{path}: cannot read: {e.strerror}") from None
    finally:
        os.close(fd)
    if len(head) >= 6 and head[:2] == b"\x4d\x4d":
        return "3ds"
    if head[:4] == b"glTF":
        return "glb"
    if head[:5].lower() == b"solid" or path.suffix == "":
        # ascii STL or unknown text; let the caller's message say what we accept
        pass
    kinds = ", ".join(sorted(MESH_EXTENSIONS | BUILT_EXTENSIONS))
    raise FormatError(f"{path}: not a model file this tool reads (expected one of {kinds})")


def refuse_model(path: str | os.PathLike, kind: str = "arena") -> None:
    """Where a bundle (or a walls file) is expected but ``path`` is a model file, say
    so and how to make the bundle (a walls reader's "expected 5 fields" or "no such
    folder" would send the user the wrong way).  ``kind``: 'arena' or 'vehicle'."""
    p = Path(path)
    if p.suffix.lower() in MESH_EXTENSIONS | BUILT_EXTENSIONS and p.is_file():
        raise FormatError(f"{p} is a model: import it first with `tanktool import-{kind} {p}`")


def _check_binary_stl(path: Path, data: bytes) -> None:
    """Refuse a damaged binary STL with the byte offset, before trimesh sees it.

    A binary STL is an 80-byte header, a u32 triangle count at byte 80 and 50 bytes
    per triangle.  trimesh falls back to the ASCII reader when the length is wrong,
    which fails with an unrelated message; ASCII files start with ``solid``.
    """
    size = len(data)
    head = data[:84]
    if size >= 84 and size == 84 + 50 * int.from_bytes(head[80:84], "little"):
        return  # consistent binary STL (some start with "solid" too)
    if head[:5].lower() == b"solid":
        return  # ASCII STL: trimesh's own reader judges it
    if size < 84:
        raise FormatError(f"{path}: byte {size}: binary STL needs an 84-byte header, file has {size} bytes")
    count = int.from_bytes(head[80:84], "little")
    raise FormatError(
        f"{path}: byte 80: binary STL says {count} triangles ({84 + 50 * count} bytes) "
        f"but the file has {size} bytes"
    )


def default_up(fmt: str) -> str:
    # .bzw worlds are Z-up, like .3ds; floor plans are built Z-up (plan y stored as -y)
    return "z" if fmt in ("3ds", "bzw", *PLAN_FORMATS) else "y"


@contextlib.contextmanager
def quiet() -> Iterator[None]:
    """Silence trimesh's log (it logs tracebacks for files it fails to read) and
    numpy's warnings while a model is read: the reader's own FormatError says what is
    wrong, in one line.  ``-vv`` (DEBUG) keeps them."""
    log = logging.getLogger("trimesh")
    if logging.getLogger().isEnabledFor(logging.DEBUG):
        yield
        return
    level = log.level
    log.setLevel(logging.CRITICAL)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            yield
    finally:
        log.setLevel(level)


def load_scene(path: str | os.PathLike, up: str | None = None, scale: float = 1.0,
               warn: Callable[[str], None] | None = None, wall_height: float | None = None,
               wall_thickness: float | None = None, progress: Callable[[str], None] | None = None):
    """Load ``path`` as a ``trimesh.Scene`` in the world frame (Y up, metres).

    ``warn`` receives the non-fatal remarks of built formats (a .bzw file's
    unknown objects); ``wall_height`` / ``wall_thickness`` shape the walls of a
    .dxf/.svg floor plan (defaults in formats/floorplan.py) and ``progress`` receives
    its stages (floorplan.PLAN_STAGES; big plans take a while).  Raises FormatError for
    unreadable files, models without triangles, non-finite vertices, models beyond the
    limits of formats/limits.py (objects, triangles) and extents that are a unit
    mistake (over 100 km or under 1 mm after ``scale``).

    The scene is flat: every geometry is in the world frame and used by one node with
    the identity transform; more than ``MERGE_OBJECTS`` objects are merged into one
    mesh (per-face colours kept), so the cost stays linear in the number of objects.
    """
    from . import threeds  # noqa: F401  (registers the .3ds loader with trimesh)

    path = Path(path)
    fmt = detect_format(path)
    if fmt in PLAN_FORMATS and up not in (None, "z"):
        raise FormatError(f"{path}: --up does not apply to a floor plan (its x, y are the arena's x, z)")
    if fmt not in PLAN_FORMATS and (wall_height is not None or wall_thickness is not None):
        raise FormatError(f"{path}: --wall-height / --wall-thickness apply only to .dxf/.svg floor plans")
    if up is None:
        up = default_up(fmt)
    if up not in ("y", "z"):
        raise FormatError(f"--up must be 'y' or 'z', got {up!r}")
    if isinstance(scale, bool) or not (isinstance(scale, (int, float)) and math.isfinite(scale) and scale > 0):
        raise FormatError(f"--scale must be a positive number, got {scale!r}")
    with quiet():
        scene = _read_scene(path, fmt, warn, wall_height, wall_thickness, progress)
        return _to_world(scene, path, up, scale)


def _read_scene(path: Path, fmt: str, warn, wall_height, wall_thickness, progress):
    from . import threeds

    try:
        if fmt == "3ds":
            scene = threeds.load_scene(path)
        elif fmt == "bzw":
            from . import bzw

            scene = bzw.load_scene(path, warn=warn)
        elif fmt in PLAN_FORMATS:
            from . import floorplan

            scene = floorplan.load_scene(
                path,
                floorplan.DEFAULT_WALL_HEIGHT if wall_height is None else wall_height,
                floorplan.DEFAULT_WALL_THICKNESS if wall_thickness is None else wall_thickness, progress=progress)
        elif fmt in ("glb", "gltf"):
            scene = _load_gltf(path)
        else:
            scene = _load_with_trimesh(path, fmt)
        left_out = list(scene.metadata.get("left_out", []))   # what a built format did not build
        scene = flat_scene(scene, str(path))
        scene.metadata["left_out"] = left_out
    except FormatError:
        raise
    except MemoryError:
        raise FormatError(f"{path}: the model needs more memory than this machine has") from None
    except RecursionError:
        raise FormatError(f"{path}: cannot read as .{fmt}: structures nested too deeply") from None
    except Exception as e:  # trimesh raises many kinds for bad files
        raise FormatError(f"{path}: cannot read as .{fmt}: {_one_line(e)}") from None
    return scene


def _one_line(e: Exception) -> str:
    return " ".join(str(e).split())[:300] or type(e).__name__


def _to_world(scene, path: Path, up: str, scale: float):
    """Check the scene's triangles and vertices, turn it into the world frame (Y up,
    metres) and check its extent."""
    import trimesh

    geoms = [g for g in scene.geometry.values() if isinstance(g, trimesh.Trimesh) and len(g.faces)]
    if not geoms:
        raise FormatError(f"{path}: the model has no triangles")
    for name, g in scene.geometry.items():
        if not isinstance(g, trimesh.Trimesh):
            continue
        v, f = np.asarray(g.vertices), np.asarray(g.faces)
        if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or (len(f) and f.shape[1] != 3):
            raise FormatError(f"{path}: object {name!r} is not a triangle mesh (faces of shape {f.shape})")
        if len(f) and (f.min() < 0 or f.max() >= len(v)):
            k = int(np.flatnonzero((f < 0).any(axis=1) | (f >= len(v)).any(axis=1))[0])
            raise FormatError(f"{path}: object {name!r} face {k} uses vertex {int(f[k].max())}, "
                              f"the object has {len(v)} vertices")
        if not np.isfinite(v).all():
            bad = int(np.flatnonzero(~np.isfinite(v).all(axis=1))[0])
            raise FormatError(f"{path}: object {name!r} vertex {bad} is not finite (NaN or inf)")
    transform = np.eye(4)
    if up == "z":
        transform = Z_UP_TO_Y_UP.copy()
    if scale != 1.0:
        transform = np.diag([scale, scale, scale, 1.0]) @ transform
    if not np.allclose(transform, np.eye(4)):
        for g in scene.geometry.values():
            g.apply_transform(transform)
    _check_extent(path, geoms, scale)
    return scene


def _check_extent(path: Path, geoms: list, scale: float) -> None:
    """Refuse a model whose size in metres is a unit mistake (or overflowed to inf)."""
    lo = np.min([g.vertices.min(axis=0) for g in geoms], axis=0)
    hi = np.max([g.vertices.max(axis=0) for g in geoms], axis=0)
    with np.errstate(over="ignore", invalid="ignore"):
        extent = float(np.max(hi - lo))
    hint = f" after --scale {scale:g}" if scale != 1.0 else ""
    if not math.isfinite(extent) or extent > MAX_EXTENT:
        raise FormatError(f"{path}: the model is {extent:.3g} m across{hint}, more than "
                          f"{MAX_EXTENT / 1000:g} km: wrong --scale?")
    if extent < MIN_EXTENT:
        raise FormatError(f"{path}: the model is {extent:.3g} m across{hint}, less than "
                          f"{MIN_EXTENT * 1000:g} mm: wrong --scale?")


class _FolderResolver:
    """trimesh resolver for the files a model names (an .obj's material libraries, a
    .gltf's buffers): regular files inside the model's folder only, bounded in size,
    and never images (textures are not needed, and decoding one is a memory bomb)."""

    IMAGES = (".png", ".jpg", ".jpeg", ".bmp", ".tga", ".gif", ".tif", ".tiff", ".webp", ".dds", ".ktx", ".ktx2")

    def __init__(self, folder: Path, label: str) -> None:
        self.folder = folder
        self.label = label

    def get(self, name: str) -> bytes:
        from .bundle import bundle_file, read_input

        if str(name).lower().endswith(self.IMAGES):
            # not decoded here (formats/materials.py reads textures, bounded); an empty
            # answer keeps the rest of the material library (an error would drop it all)
            return b""
        f = bundle_file(self.folder, str(name), f"{self.label}: {name!r}")
        return read_input(f, "a file the model names", label=f"{self.label}: {name!r}", limit=MAX_MODEL_BYTES)

    __getitem__ = get   # the .obj loader asks for its material library as resolver[name]

    def namespaced(self, namespace: str) -> "_FolderResolver":
        return _FolderResolver(self.folder / namespace, self.label)

    def keys(self):
        return iter(())

    def write(self, name: str, data) -> None:  # pragma: no cover - loaders never write
        raise FormatError(f"{self.label}: loading a model must not write {name!r}")


def _load_with_trimesh(path: Path, fmt: str):
    """.obj .stl .ply .off through trimesh, from bytes read by read_input (a device or a
    huge file is refused first) with a resolver confined to the model's folder."""
    import io

    import trimesh

    from .bundle import read_input

    data = read_input(path, f"a .{fmt} model", limit=MAX_MODEL_BYTES)
    if not data:
        raise FormatError(f"{path}: byte 0: empty file, expected a .{fmt} model")
    if fmt == "stl":
        _check_binary_stl(path, data)
    if fmt == "obj":
        data = obj_text(data).encode("utf-8")
    try:
        scene = trimesh.load(io.BytesIO(data), file_type=fmt, force="scene", process=False,
                             resolver=_FolderResolver(path.parent, str(path)))
    except IndexError:
        if fmt == "obj":
            where = obj_bad_index(data.decode("utf-8"))
            if where:
                raise FormatError(f"{path}:{where}") from None
        raise
    # trimesh keeps the file object it read with the scene and its meshes (their shared
    # LoadSource): the whole file's bytes, 0.12 GB for a 2 km terrain's .obj held
    # through the import; nothing reads it again
    source = getattr(scene, "_source", None)
    if source is not None and hasattr(source, "file_obj"):
        source.file_obj = None
    return scene


def obj_text(data: bytes) -> str:
    """An .obj file's text: UTF-8, else Latin-1 (old exporters write names and
    comments in their system's 8-bit code page; every byte is a Latin-1 character, so
    this never fails and the numbers, which are ASCII, read the same)."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def obj_bad_index(text: str) -> str | None:
    """``"<line>: <what>"`` for the first face of an .obj naming a vertex that does not
    exist (looked for only after trimesh failed: a scan costs a pass over the text)."""
    count = {"v": 0, "vt": 0, "vn": 0}
    names = {0: "v", 1: "vt", 2: "vn"}
    for lineno, line in enumerate(text.splitlines(), 1):
        head, _, rest = line.strip().partition(" ")
        if head in count:
            count[head] += 1
        elif head == "f":
            for corner in rest.split():
                for k, field in enumerate(corner.split("/")[:3]):
                    if not field:
                        continue
                    try:
                        i = int(field)
                    except ValueError:
                        return f"{lineno}: face corner {corner!r:.40} is not vertex numbers"
                    n = count[names[k]]
                    if not (1 <= i <= n or -n <= i <= -1):
                        what, many = {"v": ("vertex", "vertices"), "vt": ("texture coordinate", "texture coordinates"),
                                      "vn": ("normal", "normals")}[names[k]]
                        return (f"{lineno}: face names {what} {i}, but the file defines {n} {many} "
                                f"before this line (1..{n}, or -1..-{n} counting back)")
    return None


def _load_gltf(path: Path):
    """.glb / .gltf: validated and sanitised by formats/gltf.py before trimesh reads it."""
    import io

    import trimesh

    from .bundle import read_input
    from .gltf import read_gltf, sanitized_glb

    data = read_input(path, "a glTF model", limit=MAX_MODEL_BYTES)
    if not data:
        raise FormatError(f"{path}: byte 0: empty file, expected a glTF model")
    g = read_gltf(data, str(path), folder=path.parent)
    return trimesh.load(io.BytesIO(sanitized_glb(g)), file_type="glb", force="scene", process=False)


def face_colours(mesh) -> np.ndarray:
    """(m, 4) uint8 RGBA of each face: its colour, or its material's main colour."""
    m = len(mesh.faces)
    vis = getattr(mesh, "visual", None)
    try:
        if vis is not None and vis.kind == "texture":
            c = getattr(vis.material, "main_color", None)
            if c is not None:
                return np.tile(np.asarray(c, dtype=np.uint8).reshape(1, 4), (m, 1))
        elif vis is not None and vis.kind in ("face", "vertex"):
            fc = np.asarray(vis.face_colors, dtype=np.uint8)
            if fc.shape == (m, 4):
                return fc
    except Exception:  # a visual trimesh cannot convert: keep the default colour
        pass
    return np.tile(np.array([[128, 128, 128, 255]], dtype=np.uint8), (m, 1))


def flat_scene(scene, label: str):
    """``scene`` with every geometry in the scene's frame, used once, identity node
    transforms; merged into one mesh beyond ``MERGE_OBJECTS`` objects.  Refuses more
    than ``MAX_OBJECTS`` objects or ``MAX_FACES`` triangles (instances counted)."""
    import trimesh

    graph = scene.graph
    nodes = graph.nodes_geometry
    if len(nodes) > MAX_OBJECTS:
        raise FormatError(f"{label}: {len(nodes):,} objects, more than the {MAX_OBJECTS:,} this tool reads")
    placed = []  # (node, transform, geometry name)
    faces = 0
    for node in nodes:
        transform, gname = graph[node]
        g = scene.geometry.get(gname)
        if g is None:
            continue
        faces += len(getattr(g, "faces", ()))
        if faces > MAX_FACES:
            raise FormatError(f"{label}: more than {MAX_FACES:,} triangles (all objects together)")
        placed.append((node, np.asarray(transform, dtype=np.float64), gname))
    used = [p[2] for p in placed]
    eye = np.eye(4)
    if (len(placed) <= MERGE_OBJECTS and len(set(used)) == len(used) and len(used) == len(scene.geometry)
            and all(np.array_equal(t, eye) for _, t, _ in placed)):
        return scene  # flat already (every reader of ours, most files)
    out = trimesh.Scene()
    out.metadata.update(scene.metadata)
    if len(placed) <= MERGE_OBJECTS:
        for node, t, gname in placed:
            g = scene.geometry[gname].copy()
            if not np.array_equal(t, eye):
                g.apply_transform(t)
            out.add_geometry(g, geom_name=str(node), node_name=str(node))
        return out
    # many objects: one mesh, per-face colours kept
    verts, tris, cols, base = [], [], [], 0
    for _, t, gname in placed:
        g = scene.geometry[gname]
        if not isinstance(g, trimesh.Trimesh) or not len(g.faces):
            continue
        v = np.asarray(g.vertices, dtype=np.float64)
        f = np.asarray(g.faces, dtype=np.int64)
        if not np.array_equal(t, eye):
            v = v @ t[:3, :3].T + t[:3, 3]
            if np.linalg.det(t[:3, :3]) < 0:
                f = f[:, ::-1]  # a mirror turns the faces inside out: turn them back
        verts.append(v)
        tris.append(f + base)
        cols.append(face_colours(g))
        base += len(v)
    if not verts:
        return out
    merged = trimesh.Trimesh(np.concatenate(verts), np.concatenate(tris), face_colors=np.concatenate(cols),
                             process=False)
    out.add_geometry(merged, geom_name="merged", node_name="merged")
    out.metadata["merged_objects"] = len(placed)
    return out


def load_model(path: str | os.PathLike, up: str | None = None, scale: float = 1.0):
    """Load ``path`` as one ``trimesh.Trimesh`` in the world frame (all objects joined,
    per-face colours kept)."""
    import trimesh

    scene = load_scene(path, up=up, scale=scale)
    meshes = [m for m in scene.dump() if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    if len(meshes) == 1:
        return meshes[0]
    return trimesh.util.concatenate(meshes)
