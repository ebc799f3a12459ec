"""Random levels for the import pipeline: a floor with boxes, triangle soups, ramps at
any angle and duplicated or flipped copies of earlier parts, sometimes a NaN vertex or a
degenerate face.  Nobody shaped them to pass: the import must either write a bundle or
refuse with one clear error (tests/test_random_levels.py runs a few, its slow test many).

    python tools/random_levels.py OUT_DIR [--first 0] [--count 20]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

#: a box's faces, wound so their normals point out (y up)
BOX_FACES = np.array([[2, 1, 0], [3, 2, 0], [5, 6, 4], [6, 7, 4], [5, 4, 0], [1, 5, 0],
                      [6, 5, 1], [2, 6, 1], [7, 6, 2], [3, 7, 2], [4, 7, 3], [0, 4, 3]])


def _box(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1],
                  [x0, y1, z0], [x1, y1, z0], [x1, y1, z1], [x0, y1, z1]], dtype=np.float64)
    return v, BOX_FACES.copy()


def _part(rng: np.random.Generator, size: float, parts: list) -> tuple[np.ndarray, np.ndarray]:
    """One random part: a box (half the time), a soup of triangles, a ramp at any
    angle, or a copy of an earlier part (flipped half the time)."""
    kind = rng.integers(0, 6)
    c = rng.uniform(0, size, 3)
    c[1] = rng.uniform(-1, 6)
    s = rng.uniform(0.01, size / 4, 3)
    if kind <= 2:
        return _box(c - s / 2, c + s / 2)
    if kind == 3:
        n = int(rng.integers(1, 50))
        return c + rng.normal(0, s, (3 * n, 3)), np.arange(3 * n).reshape(-1, 3)
    if kind == 4:
        rise = s[0] * np.tan(rng.uniform(-1.2, 1.2))
        v = np.array([[0, 0, 0], [s[0], 0, 0], [s[0], rise, s[2]], [0, rise, s[2]]]) + c
        return v, np.array([[0, 2, 1], [0, 3, 2]])
    v, f = parts[int(rng.integers(0, len(parts)))]
    return v.copy(), (f[:, ::-1] if rng.random() < 0.5 else f).copy()


def random_level(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(vertices, faces) of random level ``seed`` (y up)."""
    rng = np.random.default_rng(seed)
    size = float(rng.choice([20.0, 60.0, 150.0, 400.0]))
    parts = [(np.array([[0, 0, 0], [size, 0, 0], [size, 0, size], [0, 0, size]], dtype=np.float64),
              np.array([[0, 2, 1], [0, 3, 2]]))]
    for _ in range(int(rng.integers(0, 40))):
        parts.append(_part(rng, size, parts))
    offsets = np.cumsum([0] + [len(v) for v, _ in parts[:-1]])
    v = np.vstack([p[0] for p in parts])
    f = np.vstack([p[1] + o for p, o in zip(parts, offsets)])
    if rng.random() < 0.05:
        v[rng.integers(0, len(v))] = np.nan
    if rng.random() < 0.05:
        f[rng.integers(0, len(f))] = [0, 0, 0]
    return v, f


def write_obj(path: Path, v: np.ndarray, f: np.ndarray) -> None:
    lines = ["v %r %r %r" % tuple(float(x) for x in p) for p in v]
    lines += ["f %d %d %d" % tuple(int(i) + 1 for i in t) for t in f]
    path.write_text("\n".join(lines) + "\n")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--count", type=int, default=20)
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for seed in range(args.first, args.first + args.count):
        write_obj(args.out / f"random_{seed}.obj", *random_level(seed))
    print(f"wrote {args.count} levels into {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
