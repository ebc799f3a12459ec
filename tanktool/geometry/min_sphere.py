"""The minimum enclosing sphere of a point set (Welzl's move-to-front algorithm in plain
floats, started from the points extreme along 13 directions), and a quick bounding
sphere.  The sphere tree's leaves are exact minimum spheres of their parts."""

from __future__ import annotations

import numpy as np

# 13 directions (axes, face and body diagonals): the points extreme along them
# start the core set of the minimum sphere and stand for a part's extent
DIRECTIONS = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [1, -1, 0], [1, 0, 1], [1, 0, -1],
                  [0, 1, 1], [0, 1, -1], [1, 1, 1], [1, 1, -1], [1, -1, 1], [-1, 1, 1]], dtype=np.float64)
DIRECTIONS /= np.linalg.norm(DIRECTIONS, axis=1)[:, None]

Ball = tuple  # ((x, y, z), r²) in plain floats


def _ball2(a, b) -> Ball:
    c = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2)
    return c, (a[0] - c[0]) ** 2 + (a[1] - c[1]) ** 2 + (a[2] - c[2]) ** 2


def _ball3(a, b, c) -> Ball:
    """Circumcircle of a triangle in 3D (the farthest pair's ball if it is degenerate)."""
    ab = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
    ac = (c[0] - a[0], c[1] - a[1], c[2] - a[2])
    n = (ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0])
    nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2]
    lab = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]
    lac = ac[0] * ac[0] + ac[1] * ac[1] + ac[2] * ac[2]
    if nn <= 1e-20 * lab * lac:
        return max((_ball2(a, b), _ball2(a, c), _ball2(b, c)), key=lambda t: t[1])
    acn = (ac[1] * n[2] - ac[2] * n[1], ac[2] * n[0] - ac[0] * n[2], ac[0] * n[1] - ac[1] * n[0])
    nab = (n[1] * ab[2] - n[2] * ab[1], n[2] * ab[0] - n[0] * ab[2], n[0] * ab[1] - n[1] * ab[0])
    o = tuple((lab * acn[i] + lac * nab[i]) / (2 * nn) for i in range(3))
    return (a[0] + o[0], a[1] + o[1], a[2] + o[2]), o[0] * o[0] + o[1] * o[1] + o[2] * o[2]


def _ball4(a, b, c, d) -> Ball:
    """Circumsphere of a tetrahedron (the largest face circle's ball if it is flat)."""
    u = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
    v = (c[0] - a[0], c[1] - a[1], c[2] - a[2])
    w = (d[0] - a[0], d[1] - a[1], d[2] - a[2])
    vw = (v[1] * w[2] - v[2] * w[1], v[2] * w[0] - v[0] * w[2], v[0] * w[1] - v[1] * w[0])
    wu = (w[1] * u[2] - w[2] * u[1], w[2] * u[0] - w[0] * u[2], w[0] * u[1] - w[1] * u[0])
    uv = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    det = u[0] * vw[0] + u[1] * vw[1] + u[2] * vw[2]
    uu, vv, ww = (sum(t * t for t in x) for x in (u, v, w))
    if abs(det) <= 1e-10 * (uu * vv * ww) ** 0.5:
        return max((_ball3(a, b, c), _ball3(a, b, d), _ball3(a, c, d), _ball3(b, c, d)), key=lambda t: t[1])
    o = tuple((uu * vw[i] + vv * wu[i] + ww * uv[i]) / (2 * det) for i in range(3))
    return (a[0] + o[0], a[1] + o[1], a[2] + o[2]), o[0] * o[0] + o[1] * o[1] + o[2] * o[2]


def _mtf(P: list, n: int, R: list) -> Ball:
    """Welzl's move-to-front recursion: the smallest ball of P[:n] with R on its surface."""
    if len(R) == 0:
        c, r2 = P[0], 0.0
        start = 1
    else:
        c, r2 = (R[0], 0.0) if len(R) == 1 else _ball2(*R) if len(R) == 2 else _ball3(*R) if len(R) == 3 else _ball4(*R)
        if len(R) == 4:
            return c, r2
        start = 0
    for i in range(start, n):
        p = P[i]
        if (p[0] - c[0]) ** 2 + (p[1] - c[1]) ** 2 + (p[2] - c[2]) ** 2 > r2 * (1 + 1e-12) + 1e-24:
            c, r2 = _mtf(P, i, R + [p])
            P.insert(0, P.pop(i))
    return c, r2


def _small_ball(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Minimum ball of a few (up to ~100) points: Welzl in plain floats, fast for small sets."""
    P = [tuple(p) for p in points.tolist()]
    c, r2 = _mtf(P, len(P), [])
    return np.array(c, dtype=np.float64), float(np.sqrt(max(r2, 0.0)))


def _core(proj: np.ndarray) -> np.ndarray:
    """Indices of the points extreme along the 13 directions (``proj`` = points @ DIRECTIONS.T)."""
    return np.unique(np.concatenate([proj.argmax(axis=0), proj.argmin(axis=0)]))


def min_enclosing_sphere(points: np.ndarray, seed: int = 0) -> tuple[np.ndarray, float]:
    """Exact minimum enclosing sphere of (n, 3) points (Welzl's algorithm).

    The returned radius is the true maximum distance from the
    centre, so every point is inside whatever rounding happened.
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(pts) == 0:
        raise ValueError("no points")
    # Welzl on a small core set, growing it by the points still outside: the extreme
    # points along 13 directions start it, and each round adds the farthest
    # violators.  The answer is the exact minimum sphere of the core set, which
    # encloses everything once no point is outside, i.e. the exact sphere of all.
    core = _core(pts @ DIRECTIONS.T)
    rng = np.random.default_rng(seed)
    for _ in range(100):
        c, r = _small_ball(pts[core[rng.permutation(len(core))]])
        d2 = np.sum((pts - c) ** 2, axis=1)
        out = np.flatnonzero(d2 > (r * (1 + 1e-9) + 1e-12) ** 2)
        if len(out) == 0:
            break
        worst = out[np.argsort(d2[out])[-16:]]
        core = np.union1d(core, worst)
    r = float(np.sqrt(np.max(np.sum((pts - c) ** 2, axis=1))))
    return c, r


_QUICK = [0, 1, 2, 9, 10, 11, 12]  # the axes and the body diagonals


def quick_sphere(points: np.ndarray, proj: np.ndarray) -> tuple[np.ndarray, float]:
    """A sphere around ``points`` within a few per cent of the minimum: the minimum
    sphere of the extremes along the axes and body diagonals, its radius grown to the
    farthest point."""
    ext = proj[:, _QUICK]
    c, _ = _small_ball(points[np.unique(np.concatenate([ext.argmax(axis=0), ext.argmin(axis=0)]))])
    return c, float(np.sqrt(np.max(np.sum((points - c) ** 2, axis=1))))
