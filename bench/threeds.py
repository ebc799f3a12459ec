"""Read and write speed of the .3ds module beside trimesh's own binary readers.

Usage: ``.venv/bin/python bench/threeds.py [--faces N]``.  Builds a wavy grid of
about N triangles (default one million), writes it as .3ds (split into parts of at
most 65535 faces), binary PLY and binary STL, and prints the best of 3 timings.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
import trimesh

from tanktool.formats.threeds import load_scene, read_3ds
from tanktool.formats.threeds_write import write_3ds


def grid(faces: int) -> tuple[np.ndarray, np.ndarray]:
    n = int(np.sqrt(faces / 2)) + 1
    x, y = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    v = np.column_stack([x.ravel(), y.ravel(), np.sin(x.ravel()) * np.cos(y.ravel())])
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    return v, np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])


def best(fn, repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--faces", type=int, default=1_000_000)
    args = parser.parse_args()
    v, f = grid(args.faces)
    mesh = trimesh.Trimesh(v, f, process=False)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        p3ds, pply, pstl = tmp / "m.3ds", tmp / "m.ply", tmp / "m.stl"
        rows = [
            ("write .3ds (write_3ds)", best(lambda: write_3ds(p3ds, [("grid", v, f, (0.5, 0.5, 0.5))]))),
            ("write .ply (trimesh export)", best(lambda: mesh.export(pply))),
            ("write .stl (trimesh export)", best(lambda: mesh.export(pstl))),
            ("read .3ds: read_3ds (plain arrays)", best(lambda: read_3ds(p3ds))),
            ("read .3ds: threeds.load_scene", best(lambda: load_scene(p3ds))),
            ("read .3ds: trimesh.load_scene", best(lambda: trimesh.load_scene(p3ds))),
            ("read .ply: trimesh.load_scene", best(lambda: trimesh.load_scene(pply, process=False))),
            ("read .stl: trimesh.load_scene", best(lambda: trimesh.load_scene(pstl, process=False))),
        ]
        parts = len(read_3ds(p3ds).objects)
        sizes = {ext: p.stat().st_size for ext, p in (("3ds", p3ds), ("ply", pply), ("stl", pstl))}
    print(f"{len(f):,} faces, {len(v):,} vertices; .3ds in {parts} objects; "
          f"file sizes: " + ", ".join(f".{k} {s / 1e6:.1f} MB" for k, s in sizes.items()))
    print(f"| {'operation':<36} | {'best of 3 (s)':>13} |")
    print(f"|{'-' * 38}|{'-' * 15}|")
    for name, t in rows:
        print(f"| {name:<36} | {t:>13.3f} |")


if __name__ == "__main__":
    main()
