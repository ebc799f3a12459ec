"""The 3D view's matrices (column vectors, OpenGL's conventions) and small GL helpers:
pure numpy, so the cameras and tests use them without a context."""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def perspective(fov_y: float, aspect: float, near: float, far: float) -> np.ndarray:
    f = 1.0 / math.tan(fov_y / 2.0)
    return np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)], [0, 0, -1, 0]])


def frustum(left: float, right: float, bottom: float, top: float, near: float, far: float) -> np.ndarray:
    """glFrustum: an off-centre perspective (the shadow map's, fitted to the arena)."""
    return np.array([[2 * near / (right - left), 0, (right + left) / (right - left), 0],
                     [0, 2 * near / (top - bottom), (top + bottom) / (top - bottom), 0],
                     [0, 0, -(far + near) / (far - near), -2 * far * near / (far - near)],
                     [0, 0, -1, 0]])


def look_at(eye, target, up=(0.0, 1.0, 0.0)) -> np.ndarray:
    eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    if np.linalg.norm(s) < 1e-9:          # looking straight down: any horizontal "up" will do
        s = np.cross(f, (1.0, 0.0, 0.0))
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.identity(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def tank_matrix(x: float, z: float, heading: float, y: float = 0.0, pitch: float = 0.0,
                roll: float = 0.0) -> np.ndarray:
    """Vehicle frame (+x forward, +y up, +z right) to world, as ``Tank.to_world`` turns
    points: heading about the world's up, then pitch (nose up) about the tank's right
    axis, then roll (right side down) about its forward axis."""
    c, s = math.cos(heading), math.sin(heading)
    yaw = np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])
    cp, sp = math.cos(pitch), math.sin(pitch)
    pit = np.array([[cp, -sp, 0], [sp, cp, 0], [0, 0, 1]])        # about +z: +x towards +y
    cr, sr = math.cos(roll), math.sin(roll)
    rol = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])        # about +x: +z towards -y
    m = np.identity(4)
    m[:3, :3] = yaw @ pit @ rol
    m[:3, 3] = (x, y, z)
    return m


def vertex_format(prog: Any, buf: Any, fields: tuple[tuple[str, int], ...]) -> tuple:
    """(buffer, format, names...) for interleaved float ``fields``, skipping those the
    compiled program does not use (the compiler drops unused inputs)."""
    parts, names = [], []
    for name, n in fields:
        if name in prog:
            parts.append(f"{n}f")
            names.append(name)
        else:
            parts.append(f"{n}x4")
    return (buf, " ".join(parts), *names)


def set_uniform(prog: Any, name: str, value: Any) -> None:
    """Set a uniform if the compiled program kept it (unused ones are optimised away)."""
    if name in prog:
        if isinstance(value, bytes):
            prog[name].write(value)
        else:
            prog[name].value = value


def _gl(m: np.ndarray) -> bytes:
    return np.ascontiguousarray(m.T, dtype="f4").tobytes()   # OpenGL wants column-major


def cloud_pixels(size: int = 256, seed: int = 7) -> np.ndarray:
    """(size, size) uint8 seamless cloud cover for the sky."""
    from .noise import fbm

    n = fbm(np.random.default_rng(seed), size, (40, 16, 6, 2), (0.45, 0.3, 0.17, 0.08))
    return np.round(n * 255).astype(np.uint8)
