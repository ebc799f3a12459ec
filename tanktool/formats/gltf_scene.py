"""The triangles of a validated glTF's default scene, read without trimesh (the
checks and the walkable-surface import use them)."""

from __future__ import annotations

import numpy as np

from .gltf import FAN, STRIP, TRIANGLES, Gltf, read_accessor


def node_matrix(node: dict) -> np.ndarray:
    """A validated node's local transform (column vectors): matrix, or T x R x S."""
    if "matrix" in node:
        return np.asarray(node["matrix"], dtype=np.float64).reshape(4, 4).T
    m = np.eye(4)
    x, y, z, w = node.get("rotation", [0.0, 0.0, 0.0, 1.0])
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m[:3, :3] *= np.asarray(node.get("scale", [1.0, 1.0, 1.0]))[None, :]
    m[:3, 3] = node.get("translation", [0.0, 0.0, 0.0])
    return m


def scene_triangles(g: Gltf) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 3) float64, triangles (m, 3) int64) of the default scene's
    triangle primitives in the scene's frame (node transforms applied)."""
    doc = g.doc
    nodes, meshes = doc["nodes"], doc["meshes"]
    verts: list[np.ndarray] = []
    tris: list[np.ndarray] = []
    base = 0
    stack = [(r, np.eye(4)) for r in doc["scenes"][doc["scene"]]["nodes"]]
    while stack:
        v, parent = stack.pop()
        node = nodes[v]
        world = parent @ node_matrix(node)
        stack += [(c, world) for c in node.get("children", ())]
        if "mesh" not in node:
            continue
        for prim in meshes[node["mesh"]]["primitives"]:
            mode = prim["mode"]
            if mode not in (TRIANGLES, STRIP, FAN):
                continue
            pos = read_accessor(g, prim["attributes"]["POSITION"]).astype(np.float64)
            idx = (read_accessor(g, prim["indices"]).astype(np.int64) if "indices" in prim
                   else np.arange(len(pos), dtype=np.int64))
            if mode == TRIANGLES:
                t = idx.reshape(-1, 3)
            elif len(idx) < 3:
                continue
            elif mode == STRIP:
                k = np.arange(len(idx) - 2)
                t = np.column_stack([idx[k], idx[k + 1 + (k % 2)], idx[k + 2 - (k % 2)]])
            else:
                k = np.arange(1, len(idx) - 1)
                t = np.column_stack([np.full(len(k), idx[0]), idx[k], idx[k + 1]])
            verts.append(pos @ world[:3, :3].T + world[:3, 3])
            tris.append(t + base)
            base += len(pos)
    if not verts:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return np.concatenate(verts), np.concatenate(tris)
