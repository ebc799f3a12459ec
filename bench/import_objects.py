"""Cost of a model's number of objects, and of a floor plan's number of pillars.

    python bench/import_objects.py [--max 20000] [--json]

Table 1: a .3ds of N small boxes read into the world frame and written as the bundle's
model.glb (what import-arena does before the wall geometry), with tanktool's reader
(objects merged into one mesh beyond formats/limits.py MERGE_OBJECTS) beside the peer:
the same objects as one trimesh geometry each, turned upright with
``Scene.apply_transform`` (what tanktool did before: its cost grows with the square of
N, so it runs only while it takes under a minute).

Table 2: a floor plan of 61 x 61 grid lines and K round pillars through
``formats.floorplan`` (read, wall footprint, extrusion) beside the peer: the same
steps done as before (the whole line network buffered at once, every pillar tested
against every line one by one).

``--json`` prints one JSON object with both tables instead.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))


def timed(fn) -> float:
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def ours_3ds(path: Path) -> None:
    from tanktool.formats.models import load_scene

    load_scene(path).export(file_type="glb")


def peer_3ds(path: Path) -> None:
    """The old way: one trimesh geometry per object, the scene graph turned upright."""
    import trimesh

    from tanktool.formats import limits, threeds
    from tanktool.formats.models import Z_UP_TO_Y_UP

    saved = limits.MERGE_OBJECTS
    limits.MERGE_OBJECTS = 10 ** 9
    try:
        model = threeds.read_3ds(path)
        scene = trimesh.Scene()
        for name, kw in threeds._geometry_kwargs(model).items():
            scene.add_geometry(trimesh.Trimesh(**kw), geom_name=name, node_name=name)
        scene.apply_transform(Z_UP_TO_Y_UP)
        scene.export(file_type="glb")
    finally:
        limits.MERGE_OBJECTS = saved


def plan_dxf(pillars: int) -> bytes:
    rng = np.random.default_rng(1)
    n = 60
    lines = ["0", "SECTION", "2", "ENTITIES"]
    for i in range(n + 1):
        for x1, y1, x2, y2 in ((0, i * 5, n * 5, i * 5), (i * 5, 0, i * 5, n * 5)):
            lines += ["0", "LINE", "8", "0", "10", str(x1), "20", str(y1), "11", str(x2), "21", str(y2)]
    for x, y in rng.uniform(2.5, n * 5 - 2.5, (pillars, 2)):
        x, y = 5 * np.floor(x / 5) + 2.5, 5 * np.floor(y / 5) + 2.5   # in the middle of a cell
        lines += ["0", "CIRCLE", "8", "0", "10", f"{x:.3f}", "20", f"{y:.3f}", "40", "0.8"]
    lines += ["0", "ENDSEC", "0", "EOF"]
    return ("\n".join(lines) + "\n").encode()


def ours_plan(path: Path) -> None:
    from tanktool.formats import floorplan

    floorplan.extrude(floorplan.plan_walls(floorplan.read_plan(path), 0.5), 3.0)


def peer_plan(path: Path) -> None:
    """The old steps: the merged network buffered as one geometry, each pillar tested
    against every line with one shapely call per pair, triangles made one by one."""
    import shapely

    from tanktool.formats import floorplan

    lines = floorplan.read_plan(path)
    t = 0.5
    geoms = [shapely.LineString(ln) for ln in lines]
    merged = shapely.simplify(shapely.line_merge(shapely.union_all(geoms)), t / 20.0, preserve_topology=True)
    walls = shapely.buffer(merged, t / 2, cap_style="flat", join_style="mitre", mitre_limit=floorplan.MITRE_LIMIT)
    closed = [i for i, ln in enumerate(lines) if len(ln) >= 4 and np.allclose(ln[0], ln[-1])]
    polys = {i: shapely.make_valid(shapely.Polygon(lines[i])) for i in closed}
    largest = max(closed, key=lambda i: polys[i].area) if closed else None
    fills = []
    for i in closed:
        if i == largest:
            continue
        inner = shapely.buffer(polys[i], -t / 2)
        if not any(j != i and shapely.intersects(inner, geoms[j]) for j in range(len(geoms))):
            fills.append(polys[i])
    walls = shapely.make_valid(shapely.union_all([walls, *fills]))
    for poly in shapely.get_parts(walls):
        for tri in shapely.get_parts(shapely.constrained_delaunay_triangles(poly)):
            np.asarray(tri.exterior.coords)[:3]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--max", type=int, default=20000, help="largest number of objects (default 20000)")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    import fuzz_files

    rows, plans = [], []
    peer_ok = True
    with tempfile.TemporaryDirectory() as tmp:
        warm = Path(tmp) / "warm.3ds"          # imports and first calls out of the timings
        warm.write_bytes(fuzz_files.threeds_objects(20))
        ours_3ds(warm)
        peer_3ds(warm)
        for n in [k for k in (250, 500, 1000, 2000, 5000, 10000, 20000) if k <= args.max]:
            p = Path(tmp) / f"m{n}.3ds"
            p.write_bytes(fuzz_files.threeds_objects(n))
            ours = timed(lambda: ours_3ds(p))
            peer = timed(lambda: peer_3ds(p)) if peer_ok else None
            peer_ok = peer_ok and peer is not None and peer * 4.5 < 60   # the next size would pass a minute
            rows.append({"objects": n, "bytes": p.stat().st_size, "tanktool_s": round(ours, 3),
                         "peer_s": None if peer is None else round(peer, 3),
                         "tanktool_us_per_object": round(1e6 * ours / n, 1)})
        for k in (0, 200, 800):
            p = Path(tmp) / f"plan{k}.dxf"
            p.write_bytes(plan_dxf(k))
            plans.append({"pillars": k, "bytes": p.stat().st_size, "tanktool_s": round(timed(lambda: ours_plan(p)), 3),
                          "peer_s": round(timed(lambda: peer_plan(p)), 3)})
    if args.json:
        print(json.dumps({"threeds_objects": rows, "floor_plan_pillars": plans}))
        return
    print("objects in a .3ds -> world frame -> model.glb")
    print(f"{'objects':>8} {'bytes':>10} {'tanktool s':>11} {'us/object':>10} {'peer s':>9}")
    for r in rows:
        peer = f"{r['peer_s']:9.2f}" if r["peer_s"] is not None else f"{'(> 60)':>9}"
        print(f"{r['objects']:>8} {r['bytes']:>10,} {r['tanktool_s']:11.2f} {r['tanktool_us_per_object']:10.1f} {peer}")
    print()
    print("floor plan (61 x 61 grid lines + pillars): read, wall footprint, extrusion")
    print(f"{'pillars':>8} {'bytes':>10} {'tanktool s':>11} {'peer s':>9}")
    for r in plans:
        print(f"{r['pillars']:>8} {r['bytes']:>10,} {r['tanktool_s']:11.2f} {r['peer_s']:9.2f}")


if __name__ == "__main__":
    main()
