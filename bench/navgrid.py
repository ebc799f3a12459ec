"""Navigation grid build speed, beside shapely and the 2002 method, in one process.

Cases:

* **dungeon**: Recast's ``dungeon.obj`` (tests/data/arenas_obj/), cell 0.3 m,
  clearance 0.6 m (Recast's demo settings), walls extracted as ``import-arena``
  does (a section 1 m above the floor, solids by winding number, thin walls).
* **maze 1000x1000**: a block maze 100 m square at cell 0.1 m = 1,000,000 nodes.

For each: ``ours`` is the whole build (free-space classification, clearance, row and
column runs, regions reachable from a spawn, and the depth-3 quadtree); ``shapely``
is ``shapely.contains_xy`` on a prepared free-space polygon for the same nodes
(free space only, no clearance: it does less work than ours); ``2002`` is the paper's
method (a line from each node to the origin, crossings walked from both ends, brute
force clearance) timed on a random sample of nodes and extrapolated per node.  The
ratios are their time over ours.  Agreement: nodes where the 2002 method (on its
sample) and shapely (away from walls) say something different from ours.

    python bench/navgrid.py [--repeat N] [--sample K] [--json]
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tanktool.formats.walls_txt import WallList  # noqa: E402
from tanktool.nav.navgrid import (  # noqa: E402
    build_navgrid,
    free_space,
    grid_shape,
    node_coords,
    open_ends,
    _oriented,
)
from tanktool.nav.reference2002 import classify_reference, reference_node  # noqa: E402
from tanktool.nav.quadtree import WallQuadtree  # noqa: E402
from tanktool.nav.synthetic import block_maze  # noqa: E402

DUNGEON = [ROOT / "tests" / "data" / "arenas_obj" / "dungeon.obj",
           ROOT.parent / "shared" / "testdata" / "arenas_obj" / "dungeon.obj"]
GOALS = {"dungeon_ms": 30.0, "grid1000_ms": 150.0, "vs_2002": 100.0}


def dungeon_walls(path: Path | None = None) -> tuple[WallList, np.ndarray, str]:
    """The dungeon's walls and spawn points as ``import-arena`` makes them."""
    import trimesh

    from tanktool.formats.models import load_scene
    from tanktool.geometry.spawns import place_spawns
    from tanktool.geometry.walls import extract_walls

    path = path or next(p for p in DUNGEON if p.exists())
    scene = load_scene(path)
    meshes = [m for m in scene.dump() if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    mesh = meshes[0] if len(meshes) == 1 else trimesh.util.concatenate(meshes)
    ex = extract_walls(mesh.vertices, mesh.faces, height=1.0, tolerance=0.01)
    spawns = place_spawns(ex.free, ex.walls.bounds)
    return ex.walls, spawns, (f"tanktool.geometry.walls.extract_walls, cut at y = {ex.cut_y:g} "
                      f"(floor {ex.floor_y:g} + 1 m), {ex.thin_walls} thin-wall halves")


def free_polygon(walls: WallList):
    """Free space as a shapely polygon: the faces the walls enclose, kept when the 2002
    test says their inside is free (building it is not timed)."""
    import shapely

    faces = shapely.get_parts(shapely.polygonize(shapely.linestrings(walls.segments)))
    A, B = _oriented(walls)
    O = walls.bounds[0]
    keep = []
    for f in faces:
        p = np.array(f.representative_point().coords[0])
        if reference_node(walls, A, B, O, p):
            keep.append(f)
    poly = shapely.union_all(keep)
    shapely.prepare(poly)
    return poly


def timed(fn, repeat: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def run_case(name: str, walls: WallList, cell: float, clearance: float, spawn, bounds, repeat: int, sample: int, rng) -> dict:
    import shapely

    shape = grid_shape(bounds, cell)
    n = shape[0] * shape[1]
    origin = bounds[0]

    def ours():
        g = build_navgrid(walls, cell, clearance, spawns=spawn, bounds=bounds)
        t = WallQuadtree.build(walls.segments, bounds, depth=3)
        return g, t

    ours()  # warm up imports and caches
    t_ours, (grid, _tree) = timed(ours, repeat)
    # the stages, for the table's breakdown
    t_free, free = timed(lambda: free_space(walls, origin, cell, shape), repeat)

    poly = free_polygon(walls)
    X, Z = np.meshgrid(node_coords(origin[0], cell, shape[1]), node_coords(origin[1], cell, shape[0]))
    t_shp, inside = timed(lambda: shapely.contains_xy(poly, X, Z), max(1, repeat // 3))
    # compare with shapely away from the walls (on-wall nodes are invalid anyway)
    off_wall = grid.valid[0] | ~free  # valid nodes, and those that are not free at all
    shp_disagree = int((inside[off_wall] != free[off_wall]).sum())

    k = min(sample, n)
    pick = rng.choice(n, size=k, replace=False)
    nodes = np.stack(np.divmod(pick, shape[1]), axis=1)
    t0 = time.perf_counter()
    ref = classify_reference(walls, origin, cell, shape, clearance, nodes=nodes)
    t_ref = (time.perf_counter() - t0) / k * n
    ref_disagree = int((ref != grid.valid[0, nodes[:, 0], nodes[:, 1]]).sum())

    return {
        "case": name, "nodes": n, "shape": list(shape), "walls": len(walls), "open_ends": int(len(open_ends(walls))),
        "valid": int(grid.valid.sum()), "reachable": int(grid.reachable.sum()),
        "ours_ms": t_ours * 1e3, "free_space_ms": t_free * 1e3,
        "shapely_ms": t_shp * 1e3, "shapely_ratio": t_shp / t_ours, "shapely_vs_free_ratio": t_shp / t_free,
        "shapely_disagree": shp_disagree,
        "ref2002_ms": t_ref * 1e3, "ref2002_ratio": t_ref / t_ours, "ref2002_sample": k, "ref2002_disagree": ref_disagree,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=15, help="runs per timing; the median is shown (default 15)")
    ap.add_argument("--sample", type=int, default=1500, help="nodes the 2002 method classifies (default 1500)")
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(0)

    rows = []
    source = None
    if any(p.exists() for p in DUNGEON):
        walls, spawns, source = dungeon_walls()
        rows.append(run_case("dungeon", walls, 0.3, 0.6, spawns, walls.bounds,
                             args.repeat, args.sample, rng))
    maze = block_maze(1, n=12)  # 25 x 25 blocks of 4 m = 100 m
    rows.append(run_case("maze 1000x1000", maze, 0.1, 0.6, np.array([[6.0, 6.0, 0.0]]),
                         np.array([[0.0, 0.0], [100.0, 100.0]]), max(3, args.repeat // 3), args.sample // 3, rng))

    goals = {}
    for r in rows:
        if r["case"] == "dungeon":
            goals["dungeon under 30 ms"] = r["ours_ms"] < GOALS["dungeon_ms"]
        else:
            goals["1000x1000 under 150 ms"] = r["ours_ms"] < GOALS["grid1000_ms"]
        goals[f"{r['case']}: >= 100x the 2002 method"] = r["ref2002_ratio"] >= GOALS["vs_2002"]
    if args.json:
        print(json.dumps({"bench": "navgrid", "dungeon_walls": source, "cases": rows, "goals": goals}))
        return 0
    print("navigation grid build: ours (classify + clearance + runs + regions + quadtree) vs peers, same process")
    if source:
        print(f"dungeon walls: {source}")
    head = f"{'case':<16}{'nodes':>10}{'walls':>7}{'ours ms':>9}{'free ms':>9}{'shapely ms':>12}{'x':>6}{'x free':>8}" \
           f"{'2002 ms*':>11}{'x':>8}{'disagree shp/2002':>19}"
    print(head)
    print("-" * len(head))
    for r in rows:
        print(f"{r['case']:<16}{r['nodes']:>10,}{r['walls']:>7}{r['ours_ms']:>9.1f}{r['free_space_ms']:>9.1f}"
              f"{r['shapely_ms']:>12.1f}{r['shapely_ratio']:>6.1f}{r['shapely_vs_free_ratio']:>8.1f}"
              f"{r['ref2002_ms']:>11.0f}{r['ref2002_ratio']:>8.0f}"
              f"{r['shapely_disagree']:>11}/{r['ref2002_disagree']}")
    print(f"* 2002 method timed on {rows[0]['ref2002_sample']:,} (dungeon) / {rows[-1]['ref2002_sample']:,} (maze) "
          "random nodes and extrapolated per node; x = peer time / ours")
    print("shapely: contains_xy on a prepared polygon, free space only (no clearance); "
          "'x free' = shapely / our free-space step alone (the like-for-like figure)")
    for k, ok in goals.items():
        print(f"goal {k}: {'met' if ok else 'NOT met'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
