"""Triangles of a bundle's model for ``check``, with numpy alone for ``model.glb``.

``check`` needs only the vertices and triangles of a bundle's model, in the frame the
scene places them.  Importing trimesh for that costs more than every rule together,
so a ``.glb`` is read by :mod:`tanktool.formats.gltf`, which validates every accessor,
stride, count and the node graph before any byte of the buffers is read (a hostile
file cannot crash the interpreter or ask for gigabytes), then gathers the triangles
of the default scene.  Other model files go through
:func:`tanktool.formats.models.load_model`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import FormatError


def _read(path: str | Path):
    from ..formats.bundle import read_input
    from ..formats.gltf import read_gltf
    from ..formats.limits import MAX_MODEL_BYTES

    return read_gltf(read_input(path, "a .glb model", limit=MAX_MODEL_BYTES), str(path))


def read_glb_triangles(path: str | Path) -> tuple[np.ndarray, np.ndarray] | None:
    """(vertices (n, 3) float64, triangles (m, 3) int64) of the default scene, or None
    when the file is not a glTF this tool reads (:func:`load_triangles` says why)."""
    from ..formats.gltf_scene import scene_triangles

    try:
        v, f = scene_triangles(_read(path))
    except FormatError:
        return None
    return (v, f) if len(f) else None


def load_triangles(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of any model file, Y up as stored: .glb read here, the
    rest through trimesh.  Raises FormatError naming the file and the place."""
    from ..formats.gltf_scene import scene_triangles

    path = Path(path)
    if path.suffix.lower() == ".glb":
        v, f = scene_triangles(_read(path))
        if not len(f):
            raise FormatError(f"{path}: the model has no triangles")
        if not np.isfinite(v).all():
            raise FormatError(f"{path}: a vertex is not finite (NaN or inf) once the node transforms are applied")
        return v, f
    from ..formats.models import load_model

    mesh = load_model(path, up="y", scale=1.0)
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)
