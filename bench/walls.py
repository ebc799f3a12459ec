"""Walls of imported levels: today's path beside the old one, in one run.

For each level, the whole analysis ``import-arena`` runs (``nav.arena_levels.analyse_arena``:
surface, walls, grid, spawns, report) twice in this process:

* **new**: thin walls clipped in one overlay (``geometry.thin_walls.thin_walls``) and
  cell outlines simplified as Recast does (max edge error 1.3 cells, max edge length
  12 m: ``geometry.contours``);
* **old**: thin walls clipped chain by chain (``thin_walls_reference``, the brute-force
  reference), cell outlines simplified by 0.6 cells (``level_walls(edge_error=0.6,
  edge_max_len=None, smooth_margin=False)``) and exact floors on every cluster of faces
  within 2.6 deg of level, hilltops included (``flat_heights`` for ``modelled_floors``).

Columns: the analysis time (best of ``--repeat``), the time spent in thin walls and
its share of the analysis (goal: at most a third), the ratio old / new, and the wall
counts (a smooth hillside should not be voxel steps).  Levels: tools/make_levels.py's
fence_field (1,500 fences, 400 pillars), junkyard, town, fort, hills, terraces, its
rolling terrain scaled x3 (270 m) and big_terrain (300 m), and Recast's dungeon.

    python bench/walls.py [--json] [--repeat N] [--quick]

``--json`` prints one object ``{"repeat", "levels": [{"level", "faces", "new": {"s",
"thin_s", "thin_share", "walls"}, "old": {...}, "speedup", "thin_speedup"}], "goals"}``
(``thin_speedup`` null where a path spends under a millisecond in thin walls).
"""

from __future__ import annotations

import argparse
import functools
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))

DUNGEON = ROOT / "tests" / "data" / "arenas_obj" / "dungeon.obj"
#: (name, make_levels level, scale)
GENERATED = [("fence_field", "fence_field", 1.0), ("junkyard", "junkyard", 1.0), ("town", "town", 1.0),
             ("fort", "fort", 1.0), ("hills", "hills", 1.0), ("terraces", "terraces", 1.0),
             ("rolling_terrain x3", "rolling_terrain", 3.0), ("big_terrain", "big_terrain", 1.0)]
QUICK = {"fence_field", "town", "rolling_terrain x3"}


def levels(quick: bool) -> list[tuple[str, np.ndarray, np.ndarray]]:
    import make_levels
    import trimesh

    out = []
    for name, level, scale in GENERATED:
        if quick and name not in QUICK:
            continue
        m = make_levels.level(level)
        out.append((name, np.asarray(m.vertices) * scale, np.asarray(m.faces)))
    if not quick and DUNGEON.is_file():
        d = trimesh.load(DUNGEON, force="mesh", process=False)
        out.append(("dungeon.obj", np.asarray(d.vertices), np.asarray(d.faces)))
    return out


def run(vertices: np.ndarray, faces: np.ndarray, old: bool, repeat: int) -> dict:
    """The analysis on the new or the old path: best time, time in thin walls, walls."""
    from tanktool.arena import walkable_params
    from tanktool.fleet import bundled_fleet
    from tanktool.geometry import thin_walls as tw
    from tanktool.geometry import walls as cut
    from tanktool.geometry.heightfield import flat_heights
    from tanktool.nav import arena_levels
    from tanktool.nav import level_walls as lw_module
    from tanktool.nav.level_walls import level_walls

    fleet = bundled_fleet()
    params, _ = walkable_params(fleet=fleet)
    clip = tw.thin_walls_reference if old else tw.thin_walls
    walls_fn = functools.partial(level_walls, edge_error=0.6, edge_max_len=None, smooth_margin=False) \
        if old else level_walls
    spent = [0.0]

    def timed_clip(*a):
        t = time.perf_counter()
        r = clip(*a)
        spent[0] += time.perf_counter() - t
        return r

    floors = (lambda v, f: flat_heights(v, f)[0]) if old else lw_module.modelled_floors
    saved = cut.thin_walls, arena_levels.level_walls, lw_module.modelled_floors
    cut.thin_walls, arena_levels.level_walls, lw_module.modelled_floors = timed_clip, walls_fn, floors
    best = None
    try:
        for _ in range(repeat):
            spent[0] = 0.0
            t = time.perf_counter()
            r = arena_levels.analyse_arena(vertices, faces, params, fleet)
            row = {"s": time.perf_counter() - t, "thin_s": spent[0], "walls": len(r.walls.walls)}
            if best is None or row["s"] < best["s"]:
                best = row
    finally:
        cut.thin_walls, arena_levels.level_walls, lw_module.modelled_floors = saved
    best["thin_share"] = best["thin_s"] / best["s"]
    return best


def _ratio(x: float | None) -> str:
    return "-" if x is None else f"{x:.1f}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    ap.add_argument("--repeat", type=int, default=1, help="runs per level and path (best is kept)")
    ap.add_argument("--quick", action="store_true", help="three levels only")
    a = ap.parse_args(argv)
    rows = []
    for name, v, f in levels(a.quick):
        new = run(v, f, False, a.repeat)
        old = run(v, f, True, a.repeat)
        rows.append({"level": name, "faces": int(len(f)), "new": new, "old": old,
                     "speedup": old["s"] / new["s"],
                     # no ratio where neither path has thin walls to speak of
                     "thin_speedup": old["thin_s"] / new["thin_s"] if min(old["thin_s"], new["thin_s"]) > 1e-3
                     else None})
    worst = max(r["new"]["thin_share"] for r in rows)
    goals = {"thin_share_max": worst, "thin_share_at_most_a_third": worst <= 1 / 3}
    if a.json:
        print(json.dumps({"repeat": a.repeat, "levels": rows, "goals": goals}, indent=1))
        return 0
    print(f"{'level':20s} {'faces':>7s} {'old s':>7s} {'new s':>7s} {'old/new':>7s} {'thin old':>9s} "
          f"{'thin new':>9s} {'thin x':>7s} {'share old':>9s} {'share new':>9s} {'walls old':>9s} {'walls new':>9s}")
    for r in rows:
        o, n = r["old"], r["new"]
        print(f"{r['level']:20s} {r['faces']:7d} {o['s']:7.2f} {n['s']:7.2f} {r['speedup']:7.2f} {o['thin_s']:9.3f} "
              f"{n['thin_s']:9.3f} {_ratio(r['thin_speedup']):>7s} {o['thin_share']:9.0%} {n['thin_share']:9.0%} "
              f"{o['walls']:9d} {n['walls']:9d}")
    print(f"largest share of thin walls (new): {worst:.0%} (goal: at most a third)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
