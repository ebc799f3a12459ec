"""How long an arena's preview.png takes on a big floor plan, against the previous
drawing in the same process.

    python bench/preview.py [--json] [--pillars 0,200,800,2000]

A 300 m hall with K round pillars (each a hole in the free space, its outline walls
drawn as well), drawn by :func:`tanktool.plots.arena.render_preview`.  ``ours`` fills
the free space as one compound path (``plots.arena.fill_region``) and strokes the
walls and their normal ticks as one path each (``draw_segments``); the peer is the
previous code, put back for the run: one matplotlib patch for each part's outline,
one white patch for each hole, and LineCollections (a Path per segment).  The table also says how far apart the two pictures
are (share of pixels that differ by more than 8 of 255 in any channel, and the
largest difference).  The same fill draws the flat levels of ``render_levels``, the
preview ``import-arena`` writes.
"""

from __future__ import annotations

import argparse
import io
import json
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def hall(pillars: int, size: float = 300.0, seed: int = 1):
    """(walls, spawns, free) of a square hall with ``pillars`` round pillars."""
    import shapely

    from tanktool.formats.walls_txt import WallList, aux_rectangle
    from tanktool.geometry.walls import outline_walls

    rng = np.random.default_rng(seed)
    n = max(int(np.ceil(np.sqrt(pillars * 1.3))), 1)
    step = size / n
    cells = rng.choice(n * n, pillars, replace=False) if pillars else np.zeros(0, int)
    centres = np.column_stack([(cells % n + 0.5) * step, (cells // n + 0.5) * step])
    free = shapely.box(0, 0, size, size)
    if pillars:
        free = shapely.difference(free, shapely.union_all(shapely.buffer(shapely.points(centres), 0.8, quad_segs=4)))
    seg = outline_walls(free, 1e-6)          # free space on their left, as import writes them
    walls = WallList(seg, np.ones(len(seg), np.int8), aux_rectangle(-1, -1, size + 1, size + 1))
    spawns = np.array([[10.0, 10.0, 0.0], [size - 10, size - 10, np.pi]])
    return walls, spawns, free


def old_fill(ax, geom, colour, zorder=0):
    """The previous drawing: a patch per outline, a white patch per hole."""
    import shapely

    if geom is None or geom.is_empty:
        return
    for poly in shapely.get_parts(geom):
        ax.fill(*poly.exterior.xy, color=colour, zorder=0, lw=0)
        for hole in poly.interiors:
            ax.fill(*hole.xy, color="white", zorder=0, lw=0)


def old_segments(ax, seg, colour, width, zorder):
    """The previous drawing of walls and normal ticks: a LineCollection (a Path per segment)."""
    from matplotlib.collections import LineCollection

    ax.add_collection(LineCollection(seg, colors=colour, linewidths=width, zorder=zorder))


@contextmanager
def previous_drawing():
    from tanktool.plots import arena

    saved = arena.fill_region, arena.draw_segments
    arena.fill_region, arena.draw_segments = old_fill, old_segments
    try:
        yield
    finally:
        arena.fill_region, arena.draw_segments = saved


def holes(free) -> int:
    import shapely

    return int(sum(len(p.interiors) for p in shapely.get_parts(free)))


def timed(fn, repeat: int = 3) -> tuple[float, bytes]:
    best, out = float("inf"), b""
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def pixels(png: bytes) -> np.ndarray:
    import matplotlib.image

    return (matplotlib.image.imread(io.BytesIO(png), format="png")[..., :3] * 255).astype(np.int16)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    ap.add_argument("--pillars", default="0,200,800,2000", help="pillar counts (comma separated)")
    args = ap.parse_args()
    from tanktool.plots.arena import render_preview

    w0, s0, f0 = hall(10)
    render_preview(w0, s0, "warm-up", f0)   # matplotlib's import and font cache out of the first row
    rows = []
    for k in (int(x) for x in args.pillars.split(",")):
        walls, spawns, free = hall(k)
        t_ours, ours = timed(lambda: render_preview(walls, spawns, f"hall, {k} pillars", free))
        with previous_drawing():
            t_peer, peer = timed(lambda: render_preview(walls, spawns, f"hall, {k} pillars", free))
        a, b = pixels(ours), pixels(peer)
        diff = np.abs(a - b).max(axis=-1) if a.shape == b.shape else None
        row = {"pillars": k, "walls": len(walls.segments), "holes": holes(free),
               "ours_s": round(t_ours, 3), "peer_s": round(t_peer, 3),
               "same_size": a.shape == b.shape,
               "pixels_differing": None if diff is None else round(float((diff > 8).mean()), 6),
               "max_difference": None if diff is None else int(diff.max())}
        rows.append(row)
        if not args.json:
            if len(rows) == 1:
                print("preview.png of a 300 m hall with K round pillars (best of 3)")
                print(f"{'pillars':>8} {'walls':>7} {'ours s':>8} {'peer s':>8} {'speed-up':>9} {'pixels > 8 apart':>17} {'max diff':>9}")
            print(f"{k:>8} {row['walls']:>7,} {t_ours:8.2f} {t_peer:8.2f} {t_peer / t_ours:8.1f}x "
                  f"{100 * row['pixels_differing']:16.3f}% {row['max_difference']:>9}", flush=True)
    if args.json:
        print(json.dumps({"rows": rows}))


if __name__ == "__main__":
    main()
