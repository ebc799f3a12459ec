"""Vehicle wrapping benchmark: hull footprints, sphere-tree tightness, build time.

Per model: footprint area of 8 and 16 hull points over the convex hull's area (and
the 8-point rectangle over shapely's minimum rotated rectangle, a peer that must
agree); the excess volume (union of leaf spheres outside the model, over the model's
volume, Monte Carlo) of our sphere tree beside Hubbard's octree baseline with at
least as many leaves; the time import-vehicle spends deriving hull, tree and mass.

Goals: 16 points within 1.15x of the convex hull's area; our excess at most half the
octree's; under 1 s for a 30,000-face model.

    python bench/vehicles.py [--json] [--samples N] [--quick]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))

REAL_3DS = ["fels.3ds", "test1.3ds", "testFormatDetection", "cubes_with_alpha.3DS"]
TARGET_FACES = 30_000


def models(quick: bool) -> list[tuple[str, object]]:
    """(name, vehicle-frame trimesh) for the bundled tanks, real 3DS files, a 30k tank."""
    import trimesh

    from tanktool.cli.import_vehicle import vehicle_frame_offset
    from tanktool.formats.bundle import read_toml
    from tanktool.formats.models import load_model

    out = []

    def framed(mesh):
        mesh.apply_translation(vehicle_frame_offset(np.asarray(mesh.vertices)))
        return mesh

    for toml in sorted((ROOT / "vehicles").glob("*/vehicle.toml")):
        doc = read_toml(toml)
        src = doc["source"]
        out.append((f"{doc['name']} (bundled)", framed(load_model(toml.parent / src["file"], src["up"], src["scale"]))))
    data = ROOT / "tests" / "data" / "vehicles3ds"
    for f in REAL_3DS[: 2 if quick else None]:
        if (data / f).exists():
            out.append((f, framed(load_model(data / f))))
    # a ~30,000-face tank: the light tank's triangles split until no edge is long
    import make_vehicle_models as mv

    tank = mv.tank_scene(mv.SPECS[0]).to_geometry()
    lo, hi = 0.2, 1.0
    for _ in range(12):
        mid = (lo + hi) / 2
        v, f = trimesh.remesh.subdivide_to_size(tank.vertices, tank.faces, max_edge=mid)
        if len(f) > TARGET_FACES * 1.1:
            lo = mid
        elif len(f) < TARGET_FACES * 0.95:
            hi = mid
        else:
            break
    dense = trimesh.Trimesh(v, f, process=True)
    out.append((f"light tank, {len(dense.faces) // 1000}k faces", framed(dense)))
    return out


def measure(name: str, mesh, samples: int) -> dict:
    from shapely import MultiPoint

    from tanktool.cli.import_vehicle import derive
    from tanktool.geometry.hull import hull_points
    from tanktool.geometry.sphere_build import build_points, excess_volume, octree_spheres, solid_inside

    v = np.asarray(mesh.vertices, dtype=np.float64)
    t0 = time.perf_counter()
    hull16, fp16, tree, mp = derive(mesh, 16, 3, 4, None)
    build = time.perf_counter() - t0
    _, fp8 = hull_points(v, 8)
    t0 = time.perf_counter()
    shapely_rect = MultiPoint(v[:, [0, 2]]).minimum_rotated_rectangle.area
    t_shapely = time.perf_counter() - t0
    leaves = tree.leaves()
    pts = build_points(v, np.asarray(mesh.faces), 4000, seed=0)
    t0 = time.perf_counter()
    oc, orad = octree_spheres(pts, len(leaves))
    t_oct = time.perf_counter() - t0
    inside = solid_inside(mesh)
    ours = excess_volume(tree.centers[leaves], tree.radii[leaves], inside, samples, seed=1)
    octree = excess_volume(oc, orad, inside, samples, seed=1)
    return {
        "model": name, "faces": int(len(mesh.faces)), "vertices": int(len(v)),
        "hull8_ratio": fp8.ratio, "hull16_ratio": fp16.ratio,
        "rect_vs_shapely": fp8.area / shapely_rect if shapely_rect > 0 else 1.0,
        "leaves_ours": int(len(leaves)), "leaves_octree": int(len(orad)),
        "excess_ours": ours, "excess_octree": octree, "excess_ratio": ours / octree,
        "build_s": build, "octree_s": t_oct, "shapely_rect_s": t_shapely, "mass_method": mp.method,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    ap.add_argument("--samples", type=int, default=60_000, help="Monte Carlo points per excess estimate")
    ap.add_argument("--quick", action="store_true", help="fewer models and samples (for a smoke test)")
    args = ap.parse_args(argv)
    samples = 5_000 if args.quick else args.samples
    rows = [measure(name, mesh, samples) for name, mesh in models(args.quick)]
    dense = rows[-1]
    goals = {
        "hull16_within_1.15": [r["model"] for r in rows if r["hull16_ratio"] > 1.15],
        "excess_at_most_half_octree": [r["model"] for r in rows if r["excess_ratio"] > 0.5],
        "dense_build_under_1s": [dense["model"]] if dense["build_s"] >= 1.0 else [],
    }
    if args.json:
        print(json.dumps({"samples": samples, "models": rows, "goals_missed_by": goals}, indent=1))
        return 0
    head = (f"{'model':<26} {'faces':>6} {'hull8/CH':>8} {'hull16/CH':>9} {'rect/shapely':>12} "
            f"{'leaves':>7} {'excess ours':>11} {'octree':>7} {'ours/oct':>8} {'build s':>8} {'octree s':>8}")
    print(head)
    print("-" * len(head))
    for r in rows:
        print(f"{r['model'][:26]:<26} {r['faces']:>6} {r['hull8_ratio']:>8.3f} {r['hull16_ratio']:>9.3f} "
              f"{r['rect_vs_shapely']:>12.4f} {r['leaves_ours']:>3}/{r['leaves_octree']:<3} "
              f"{r['excess_ours']:>11.3f} {r['excess_octree']:>7.3f} {r['excess_ratio']:>8.3f} "
              f"{r['build_s']:>8.3f} {r['octree_s']:>8.3f}")
    print(f"\nexcess = leaf-sphere volume outside the model / model volume ({samples} Monte Carlo points); "
          "build = hull + sphere tree + mass, as import-vehicle does")
    for goal, missed in goals.items():
        print(f"goal {goal}: {'met' if not missed else 'missed by ' + ', '.join(missed)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
