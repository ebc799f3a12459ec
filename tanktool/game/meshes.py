"""Models as the 3D view draws them: vertex arrays grouped by texture.

A bundle's ``model.glb`` (scene transforms applied) becomes a :class:`Model`: one
:class:`Batch` per texture image (all untextured parts in one more), each an
interleaved float32 array ``x y z  nx ny nz  r g b  u v`` with three vertices per
triangle.  Normals are smooth across edges gentler than 35° (wheels, barrels) and
split at sharper ones (box edges stay hard); corners are matched by position, so a
texture's seams do not break the smoothing.  A batch whose parts are all closed and
consistently wound may be drawn with back faces culled (half the triangles the
software rasteriser sets up).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import TanktoolError

SMOOTH_ANGLE = math.radians(35.0)
#: floats per vertex: position, normal, colour, uv
STRIDE = 11
#: grey of faces that say nothing about their colour
NEUTRAL = (180, 180, 180, 255)


@dataclass
class Batch:
    """Triangles drawn with one texture (``image`` (h, w, 3|4) uint8, top row first, or None)."""

    vertices: np.ndarray
    image: np.ndarray | None = None
    closed: bool = False

    @property
    def triangles(self) -> int:
        return len(self.vertices) // 3

    def tessellated(self, max_edge: float) -> "Batch":
        return Batch(tessellate(self.vertices, max_edge), self.image, self.closed)

    def floor_share(self) -> float:
        """The share of the batch's area facing up (1: all floor)."""
        if not len(self.vertices):
            return 0.0
        tri = self.vertices[:, :3].reshape(-1, 3, 3).astype(np.float64)
        cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        area = np.linalg.norm(cross, axis=1)
        return float(np.sum(np.maximum(cross[:, 1], 0.0)) / max(float(area.sum()), 1e-12))

    def mean_luma(self) -> float:
        """Mean luminance of the batch's texture (1 without one): team tints keep the detail."""
        if self.image is None:
            return 1.0
        rgb = self.image[..., :3].reshape(-1, 3).mean(axis=0) / 255.0
        return float(max(0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2], 0.05))


#: parts smaller than this share of the model's size (wheels, a muzzle brake) are left
#: out of its far version
FAR_PART = 0.15


@dataclass
class Model:
    batches: list[Batch] = field(default_factory=list)
    #: the same model without its small parts, for when it is far away (None: no such parts)
    far: "Model | None" = None

    @property
    def triangles(self) -> int:
        return sum(b.triangles for b in self.batches)

    def tessellated(self, max_edge: float) -> "Model":
        """The same surface with no triangle edge longer than ``max_edge`` (per-vertex lighting)."""
        return Model([b.tessellated(max_edge) for b in self.batches])

    def bounds(self) -> np.ndarray:
        """(2, 3) min and max corner of every vertex (zeros when empty)."""
        pts = [b.vertices[:, :3] for b in self.batches if len(b.vertices)]
        if not pts:
            return np.zeros((2, 3))
        allp = np.concatenate(pts)
        return np.array([allp.min(axis=0), allp.max(axis=0)], dtype=np.float64)


def smooth_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3, 3) corner normals: the area-weighted mean of the faces meeting at a
    position where they bend less than SMOOTH_ANGLE, else the face's own."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    cross = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    fn = cross / np.maximum(np.linalg.norm(cross, axis=1, keepdims=True), 1e-20)
    span = max(float(np.ptp(v, axis=0).max()) if len(v) else 1.0, 1e-9)
    _, where = np.unique(np.round(v / (span * 1e-7)).astype(np.int64), axis=0, return_inverse=True)
    where = where.reshape(-1)
    acc = np.zeros((int(where.max()) + 1 if len(where) else 0, 3))
    np.add.at(acc, where[f].reshape(-1), np.repeat(cross, 3, axis=0))
    vn = acc / np.maximum(np.linalg.norm(acc, axis=1, keepdims=True), 1e-20)
    corner = vn[where[f]]                                           # (F, 3, 3)
    close = np.einsum("fkc,fc->fk", corner, fn) > math.cos(SMOOTH_ANGLE)
    return np.where(close[:, :, None], corner, fn[:, None, :])


def _is_closed(vertices: np.ndarray, faces: np.ndarray) -> bool:
    """Watertight and consistently wound when corners are matched by position."""
    import trimesh

    if len(faces) < 4:
        return False
    m = trimesh.Trimesh(np.asarray(vertices), np.asarray(faces), process=False)
    m.merge_vertices(merge_tex=True, merge_norm=True)
    return bool(m.is_watertight and m.is_winding_consistent and m.volume > 0)


def _colours_and_image(mesh: Any) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    """(F, 3) face colours in [0, 1], the texture image and the (n, 2) UVs (None without)."""
    vis = mesh.visual
    n = len(mesh.faces)
    if getattr(vis, "kind", None) in ("face", "vertex") or type(vis).__name__ == "ColorVisuals":
        try:
            return np.asarray(vis.face_colors, dtype=np.float64)[:, :3] / 255.0, None, None
        except Exception:
            pass
    mat = getattr(vis, "material", None)
    image = None
    if mat is not None:
        image = getattr(mat, "baseColorTexture", None) or getattr(mat, "image", None)
    uv = getattr(vis, "uv", None)
    if image is not None and uv is not None and len(uv) == len(mesh.vertices):
        factor = getattr(mat, "baseColorFactor", None)
        rgb = np.asarray(factor if factor is not None else (255, 255, 255, 255), dtype=np.float64)[:3]
        if rgb.max() > 1.0:
            rgb = rgb / 255.0
        pixels = np.asarray(image.convert("RGBA" if "A" in image.getbands() else "RGB"), dtype=np.uint8)
        return np.tile(rgb, (n, 1)), pixels, np.asarray(uv, dtype=np.float64)
    colour = getattr(mat, "main_color", None) if mat is not None else None
    colour = NEUTRAL if colour is None else colour
    return np.tile(np.asarray(colour[:3], dtype=np.float64) / 255.0, (n, 1)), None, None


def mesh_vertices(mesh: Any) -> tuple[np.ndarray, np.ndarray | None]:
    """One mesh as (n, STRIDE) float32 triangle-list vertices and its texture image."""
    faces = np.asarray(mesh.faces, dtype=np.int64)
    verts = np.asarray(mesh.vertices, dtype=np.float64)
    colours, image, uv = _colours_and_image(mesh)
    tri = verts[faces]
    normals = smooth_normals(verts, faces)
    cols = np.repeat(colours[:, None, :], 3, axis=1)
    uvs = uv[faces] if uv is not None else np.zeros((len(faces), 3, 2))
    out = np.concatenate([tri, normals, cols, uvs], axis=2).reshape(-1, STRIDE)
    return out.astype("f4"), image


def _batches(parts: list[tuple[np.ndarray, np.ndarray | None, bool]]) -> list[Batch]:
    """Parts (vertices, image, closed) grouped into batches by texture image."""
    groups: dict[Any, tuple[list[np.ndarray], np.ndarray | None, list[bool]]] = {}
    for arr, image, closed in parts:
        key = None if image is None else (image.shape, hash(image.tobytes()))
        arrays, _, shut = groups.setdefault(key, ([], image, []))
        arrays.append(arr)
        shut.append(closed)
    batches = [Batch(np.concatenate(arrays), image, all(shut)) for arrays, image, shut in groups.values()]
    # floors last: what stands on them is drawn first and hides floor pixels from the
    # (per pixel costly) lighting; the depth test then rejects them cheaply
    batches.sort(key=lambda b: b.floor_share())
    return batches


def model_from_meshes(meshes: list[Any], default_look: bool = False) -> Model:
    """Group meshes into batches by texture image (same pixels, one batch), and the far
    version without the parts smaller than FAR_PART of the whole.  ``default_look``: a
    mesh without any material gets one by face kind (floor, ramp, wall, ceiling:
    game/looks.py), as an arena should."""
    from .looks import looked_parts, untextured

    parts, sizes = [], []
    for m in meshes:
        if len(m.faces) == 0:
            continue
        closed = _is_closed(m.vertices, m.faces)
        size = float(np.linalg.norm(np.ptp(np.asarray(m.vertices), axis=0)))
        if default_look and untextured(m):
            normals = smooth_normals(m.vertices, m.faces)
            for arr, image in looked_parts(m.vertices, m.faces, normals):
                parts.append((arr, image, closed))
                sizes.append(size)
            continue
        arr, image = mesh_vertices(m)
        parts.append((arr, image, closed))
        sizes.append(size)
    model = Model(_batches(parts))
    if parts:
        whole = float(np.linalg.norm(np.ptp(np.concatenate([p[0][:, :3] for p in parts]), axis=0)))
        big = [p for p, size in zip(parts, sizes) if size >= FAR_PART * whole]
        if big and len(big) < len(parts):
            model.far = Model(_batches(big))
    return model


def tessellate(vertices: np.ndarray, max_edge: float) -> np.ndarray:
    """Split triangles (rows of 3 vertices, any attributes, position first) along their
    longest edge until no edge is longer than ``max_edge``; every attribute is
    interpolated linearly, so the surface, its normals and its texture stay as they
    were.  Lighting worked out per vertex is then sampled densely enough on big floors
    and walls."""
    tri = np.asarray(vertices).reshape(-1, 3, vertices.shape[-1])
    done = []
    for _ in range(32):                                 # each pass halves the longest edges
        p = tri[:, :, :3].astype(np.float64)
        edges = np.stack([np.linalg.norm(p[:, 1] - p[:, 0], axis=1), np.linalg.norm(p[:, 2] - p[:, 1], axis=1),
                          np.linalg.norm(p[:, 0] - p[:, 2], axis=1)], axis=1)
        longest = edges.max(axis=1)
        big = longest > max_edge
        done.append(tri[~big])
        if not big.any():
            break
        tri = tri[big]
        k = np.argmax(edges[big], axis=1)             # edge k joins corner k and corner k+1
        a = tri[np.arange(len(tri)), k]
        b = tri[np.arange(len(tri)), (k + 1) % 3]
        c = tri[np.arange(len(tri)), (k + 2) % 3]
        m = (a + b) / 2
        # (a, m, c) and (m, b, c) keep the winding of (a, b, c)
        tri = np.concatenate([np.stack([a, m, c], axis=1), np.stack([m, b, c], axis=1)])
    else:
        done.append(tri)
    return np.concatenate(done).reshape(-1, vertices.shape[-1]).astype(vertices.dtype)


@lru_cache(maxsize=16)
def load_model(path: str, default_look: bool = False) -> Model:
    """A bundle's model.glb as batches (scene transforms applied; ``default_look``: see
    :func:`model_from_meshes`)."""
    import trimesh

    p = Path(path)
    if not p.is_file():
        raise TanktoolError(f"{p}: no such model (rebuild the bundle: tanktool import-arena / import-vehicle)")
    try:
        import io

        from ..formats.bundle import read_input
        from ..formats.gltf import read_gltf, sanitized_glb

        # validated first (formats/gltf.py): a hostile model.glb cannot crash the game
        glb = sanitized_glb(read_gltf(read_input(p, "a .glb model"), str(p)))
        scene = trimesh.load(io.BytesIO(glb), file_type="glb", force="scene", process=False)
    except Exception as e:
        raise TanktoolError(f"{p}: cannot read the model ({e})") from None
    meshes = []
    for node in scene.graph.nodes_geometry:
        transform, name = scene.graph[node]
        g = scene.geometry[name]
        if not hasattr(g, "faces"):
            continue
        m = g.copy()
        m.apply_transform(transform)
        meshes.append(m)
    return model_from_meshes(meshes, default_look)


def box_tank_model(spec: Any) -> Model:
    """The built-in box tank (no vehicle bundle): its hull as a box."""
    import trimesh

    xs = [p[0] for p in spec.hull]
    zs = [p[2] for p in spec.hull]
    ext = (max(xs) - min(xs), spec.height, max(zs) - min(zs))
    m = trimesh.creation.box(extents=ext)
    m.apply_translation(((max(xs) + min(xs)) / 2, spec.height / 2, (max(zs) + min(zs)) / 2))
    m.visual.face_colors = (110, 120, 80, 255)
    return model_from_meshes([m])


def sphere_model(subdivisions: int = 1) -> Model:
    import trimesh

    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    m.visual.face_colors = (255, 255, 255, 255)
    return model_from_meshes([m])
