"""A default look for arena models that come without materials.

An arena modelled with no material at all (a blockout from Blender, a generated
level) would be drawn one flat grey, floor, walls and ramps alike, and read badly in
3D.  Its faces get a look by what they are, from their normals, with textures the
bundled arenas already carry (tools/make_textures.py, CC0):

=========  ==========================  ===========  =======
kind       normal's up component n_y   texture      tile
=========  ==========================  ===========  =======
floor      n_y >= 0.99 (under 8 deg)   dirt         4 m
ramp       0.82 <= n_y < 0.99          concrete     3 m
wall       -0.5 < n_y < 0.82           brick        3 m
ceiling    n_y <= -0.5                 stone        3 m
=========  ==========================  ===========  =======

0.82 is cos 35 deg, the steepest slope a tank drives (import-arena's default): what a
tank can drive up that is not level ground looks like a ramp.  Texture coordinates are
a box projection per face (the axis its normal is nearest), ``tile`` metres a repeat,
as tools/make_textures.py gives the bundled models.  Without the textures (an
installation without bundled arenas) each kind gets its own plain colour instead.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

#: kind -> (texture, tile [m], the plain colour when the texture is missing (RGB 0..1))
KINDS = {
    "floor": ("dirt", 4.0, (0.55, 0.47, 0.36)),
    "ramp": ("concrete", 3.0, (0.66, 0.66, 0.64)),
    "wall": ("brick", 3.0, (0.58, 0.32, 0.26)),
    "ceiling": ("stone", 3.0, (0.52, 0.50, 0.46)),
}
FLOOR_NY, RAMP_NY, CEILING_NY = 0.99, 0.82, -0.5


def untextured(mesh: Any) -> bool:
    """Whether a trimesh mesh carries no look of its own: no colours, no texture, no
    material colour."""
    vis = getattr(mesh, "visual", None)
    if vis is None:
        return True
    if type(vis).__name__ == "ColorVisuals":
        return getattr(vis, "kind", None) is None
    mat = getattr(vis, "material", None)
    if mat is None:
        return True
    image = getattr(mat, "baseColorTexture", None) or getattr(mat, "image", None)
    colour = getattr(mat, "baseColorFactor", None)
    if colour is None:
        colour = getattr(mat, "main_color", None)
    return image is None and colour is None


def face_kinds(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F,) the kind of each face: 0 floor, 1 ramp, 2 wall, 3 ceiling (see KINDS)."""
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1)
    ny = np.divide(n[:, 1], length, out=np.zeros(len(n)), where=length > 0)
    return np.select([ny >= FLOOR_NY, ny >= RAMP_NY, ny > CEILING_NY], [0, 1, 2], 3)


def box_uv(vertices: np.ndarray, faces: np.ndarray, tile: float) -> np.ndarray:
    """(F, 3, 2) texture coordinates: each face projected along the axis its normal is
    nearest, ``tile`` metres a repeat."""
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]
    n = np.abs(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]))
    axis = np.argmax(n, axis=1)
    # x-facing: (z, y); y-facing: (x, z); z-facing: (x, y)
    u = np.where(axis[:, None] == 0, tri[:, :, 2], tri[:, :, 0])
    v = np.where(axis[:, None] == 1, tri[:, :, 2], tri[:, :, 1])
    return np.stack([u, v], axis=2) / tile


@lru_cache(maxsize=8)
def texture(name: str) -> np.ndarray | None:
    """A bundled arena texture by name, (h, w, 3|4) uint8, or None when none is installed."""
    from PIL import Image

    from ..content import bundled_dir

    base = bundled_dir("arenas")
    if base is None:
        return None
    for path in sorted(base.glob(f"*/textures/{name}.png")):
        try:
            with Image.open(path) as im:
                return np.asarray(im.convert("RGB"), dtype=np.uint8)
        except OSError:
            continue
    return None


def looked_parts(vertices: np.ndarray, faces: np.ndarray, normals: np.ndarray
                 ) -> list[tuple[np.ndarray, np.ndarray | None]]:
    """An untextured mesh as parts by face kind, each (vertices (n, 11) float32 as
    ``meshes.STRIDE`` lays them out: position, normal, colour, uv; its texture image or
    None).  ``normals``: (F, 3, 3) corner normals (``meshes.smooth_normals``)."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    kinds = face_kinds(v, f)
    out = []
    for k, (name, tile, plain) in enumerate(KINDS.values()):
        sel = kinds == k
        if not sel.any():
            continue
        image = texture(name)
        colour = np.broadcast_to(np.asarray((1.0, 1.0, 1.0) if image is not None else plain), (int(sel.sum()), 3, 3))
        arr = np.concatenate([v[f[sel]], normals[sel], colour, box_uv(v, f[sel], tile)], axis=2)
        out.append((arr.reshape(-1, 11).astype("f4"), image))
    return out
