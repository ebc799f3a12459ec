"""Author the bundled tanks' 3D models and import them into vehicles/<name>/.

Each tank is built from closed parts — hull (with a sloped glacis), two tracks with
road wheels, turret, barrel with a muzzle brake — each with its own material colour,
facing +x, in metres, Y up; written as .3ds (Z up) by the project's 3DS writer, then
run through import-vehicle.  Every part has texture coordinates (a planar projection,
``TILE`` metres per repeat, on its own vertices) and its material names a texture of tools/make_textures.py
(``TEXTURES``: camouflage for the body, links for the tracks, steel for the running
gear and gun), found in ``vehicles/<name>/textures/`` when the bundle is built.  Run it once to (re)create the bundles from scratch; `make
vehicles` (tools/build_vehicles.py) rebuilds the derived files from the stored .3ds.

    python tools/make_vehicle_models.py [--only light] [--out vehicles]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

#: part kind -> texture, per tank (tools/make_textures.py paints them)
TEXTURES = {
    "light": {"hull": "camo_green", "turret": "camo_green", "mantlet": "camo_green", "track": "tracks",
              "wheel": "steel", "barrel": "steel", "muzzle": "steel"},
    "heavy": {"hull": "camo_sand", "turret": "camo_sand", "mantlet": "camo_sand", "track": "tracks",
              "wheel": "steel", "barrel": "steel", "muzzle": "steel"},
}
#: metres per repeat of each texture
TILE = {"camo_green": 3.0, "camo_sand": 3.0, "tracks": 2.4, "steel": 1.0}


@dataclass
class TankSpec:
    name: str
    length: float          # hull length (x), m
    hull_width: float      # hull body width between the tracks (z), m
    hull_height: float     # hull body height above its floor, m
    floor: float           # hull floor height above ground, m
    track_width: float
    track_length: float
    wheels: int
    turret_length: float
    turret_width: float
    turret_height: float
    turret_x: float        # turret centre, x
    barrel_length: float
    barrel_radius: float
    colours: dict[str, tuple[float, float, float]]
    hull_points: int = 16
    levels: int = 3
    branching: int = 4


SPECS = [
    TankSpec("light", length=4.6, hull_width=1.9, hull_height=0.75, floor=0.45, track_width=0.5,
             track_length=4.8, wheels=5, turret_length=1.9, turret_width=1.6,
             turret_height=0.6, turret_x=-0.2, barrel_length=3.0, barrel_radius=0.07,
             colours={"hull": (0.36, 0.42, 0.24), "turret": (0.42, 0.48, 0.28), "track": (0.16, 0.16, 0.15),
                      "wheel": (0.28, 0.28, 0.26), "barrel": (0.22, 0.24, 0.21)}),
    TankSpec("heavy", length=6.6, hull_width=2.5, hull_height=1.0, floor=0.5, track_width=0.7,
             track_length=6.9, wheels=7, turret_length=2.8, turret_width=2.3,
             turret_height=0.85, turret_x=-0.5, barrel_length=4.6, barrel_radius=0.11,
             colours={"hull": (0.62, 0.54, 0.38), "turret": (0.68, 0.60, 0.43), "track": (0.18, 0.17, 0.15),
                      "wheel": (0.32, 0.30, 0.27), "barrel": (0.30, 0.28, 0.24)}),
]


def _side_extrusion(profile_xy: list[tuple[float, float]], z0: float, z1: float) -> trimesh.Trimesh:
    """Extrude a convex side profile (x, y) across z from z0 to z1.

    The profiles are convex, so the prism is the convex hull of its two end faces
    (no polygon triangulation library needed)."""
    p = np.asarray(profile_xy, dtype=np.float64)
    n = len(p)
    pts = np.vstack([np.column_stack([p, np.full(n, z0)]), np.column_stack([p, np.full(n, z1)])])
    return trimesh.convex.convex_hull(pts)


def _coloured(mesh: trimesh.Trimesh, rgb: tuple[float, float, float]) -> trimesh.Trimesh:
    mesh.visual.face_colors = np.array([*(np.array(rgb) * 255).round(), 255], dtype=np.uint8)
    return mesh


def tank_scene(s: TankSpec) -> trimesh.Scene:
    """The tank as a Y-up scene of named, coloured, closed parts facing +x."""
    parts: dict[str, trimesh.Trimesh] = {}
    half_l = s.length / 2
    top = s.floor + s.hull_height
    # hull: flat floor, sloped glacis at the front, shorter slope at the back
    glacis = 0.45 * s.hull_height / np.tan(np.radians(30))
    hull_profile = [(-half_l, s.floor + 0.15 * s.hull_height), (-half_l + 0.25, s.floor), (half_l - 0.35, s.floor),
                    (half_l, s.floor + 0.45 * s.hull_height), (half_l - glacis, top), (-half_l + 0.15, top),
                    (-half_l, top - 0.2 * s.hull_height)]
    # the hull spans the tracks too (the fenders over them)
    parts["hull"] = _side_extrusion(hull_profile, -s.hull_width / 2 - s.track_width, s.hull_width / 2 + s.track_width)
    # tracks run from the ground up to the hull floor, under the hull's fenders
    half_t = s.track_length / 2
    th = s.floor
    track_profile = [(-half_t + th * 0.5, 0.0), (half_t - th * 0.5, 0.0), (half_t, th * 0.6),
                     (half_t - th * 0.25, th), (-half_t + th * 0.25, th), (-half_t, th * 0.6)]
    zin = s.hull_width / 2
    for side, sign in (("left", -1), ("right", 1)):
        z0, z1 = sorted([sign * zin, sign * (zin + s.track_width)])
        parts[f"track_{side}"] = _side_extrusion(track_profile, z0, z1)
        # road wheels: short cylinders along z on the outer face of the track
        r = th * 0.36
        xs = np.linspace(-half_t + th * 0.8, half_t - th * 0.8, s.wheels)
        outer = z1 if sign > 0 else z0
        for i, x in enumerate(xs):
            w = trimesh.creation.cylinder(radius=r, height=0.06, sections=14)
            w.apply_translation([x, r + 0.03, outer + sign * 0.03])
            parts[f"wheel_{side}_{i}"] = w
    # turret: a tapered octagonal prism (convex hull of a larger base and a smaller roof)
    def octagon(length: float, width: float) -> np.ndarray:
        c = 0.3
        return np.array([[length / 2, width / 2 * (1 - c)], [length / 2 * (1 - c), width / 2],
                         [-length / 2 * (1 - c / 2), width / 2], [-length / 2, width / 2 * (1 - c / 2)],
                         [-length / 2, -width / 2 * (1 - c / 2)], [-length / 2 * (1 - c / 2), -width / 2],
                         [length / 2 * (1 - c), -width / 2], [length / 2, -width / 2 * (1 - c)]])
    base = octagon(s.turret_length, s.turret_width)
    roof = octagon(s.turret_length * 0.8, s.turret_width * 0.82) + [-0.08 * s.turret_length, 0]
    pts = np.vstack([np.column_stack([base[:, 0], np.full(8, top), base[:, 1]]),
                     np.column_stack([roof[:, 0], np.full(8, top + s.turret_height), roof[:, 1]])])
    turret = trimesh.convex.convex_hull(pts)
    turret.apply_translation([s.turret_x, 0, 0])
    parts["turret"] = turret
    # barrel along +x from inside the turret front, with a muzzle brake
    y_gun = top + 0.5 * s.turret_height
    x0 = s.turret_x + 0.3 * s.turret_length
    barrel = trimesh.creation.cylinder(radius=s.barrel_radius, height=s.barrel_length, sections=16)
    barrel.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    barrel.apply_translation([x0 + s.barrel_length / 2, y_gun, 0])
    parts["barrel"] = barrel
    brake = trimesh.creation.cylinder(radius=s.barrel_radius * 1.6, height=s.barrel_length * 0.08, sections=16)
    brake.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    brake.apply_translation([x0 + s.barrel_length * 0.96, y_gun, 0])
    parts["muzzle"] = brake
    mantlet = trimesh.creation.box([0.25 * s.turret_length, 0.45 * s.turret_height, 0.35 * s.turret_width])
    mantlet.apply_translation([s.turret_x + 0.45 * s.turret_length, y_gun, 0])
    parts["mantlet"] = mantlet

    scene = trimesh.Scene()
    for name, mesh in parts.items():
        kind = name.split("_")[0]
        colour = s.colours.get(kind, s.colours["turret"] if kind in ("mantlet", "muzzle") else s.colours["hull"])
        if kind == "muzzle":
            colour = s.colours["barrel"]
        scene.add_geometry(_coloured(mesh, colour), node_name=name, geom_name=name)
    return scene


def tank_uv(yup: np.ndarray, tile: float) -> np.ndarray:
    """Per-vertex texture coordinates of a part without splitting its vertices: one
    sheared planar projection, u = x + z/2, v = y + z/2 (Y up), ``tile`` metres per
    repeat.  Sides, roofs and fronts all get a non-degenerate mapping, and the part keeps
    exactly the vertices the hull points and sphere tree are computed from."""
    return np.column_stack([yup[:, 0] + 0.5 * yup[:, 2], yup[:, 1] + 0.5 * yup[:, 2]]) / tile


def write_tank_3ds(spec: TankSpec, path: Path) -> None:
    """The tank as a .3ds (Z up): one object per part, with texture coordinates and
    its texture's file name (in the bundle's textures/ folder)."""
    from tanktool.formats.threeds_write import scene_to_3ds_objects, write_3ds

    objects = []
    for part, verts, faces, rgb in scene_to_3ds_objects(tank_scene(spec)):   # Z-up, one colour per part
        texture = TEXTURES[spec.name][part.split("_")[0]]
        yup = np.column_stack([verts[:, 0], verts[:, 2], -verts[:, 1]])      # Z-up (x, y, z) is (x, z, -y)
        objects.append((part, verts, faces, rgb, tank_uv(yup, TILE[texture]), f"textures/{texture}.png"))
    write_3ds(path, objects)


def main(argv: list[str] | None = None) -> int:
    from tanktool.cli.import_vehicle import build_vehicle_bundle

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", action="append", help="build only this tank (repeatable)")
    ap.add_argument("--out", type=Path, default=ROOT / "vehicles")
    ap.add_argument("--models-only", action="store_true",
                    help="only (re)write each bundle's source .3ds; `make vehicles` then rebuilds the rest "
                         "keeping the bundle's hand-tuned [drive] table")
    args = ap.parse_args(argv)
    for spec in SPECS:
        if args.only and spec.name not in args.only:
            continue
        if args.models_only:
            write_tank_3ds(spec, args.out / spec.name / f"{spec.name}.3ds")
            print(f"{spec.name}: wrote {args.out / spec.name / f'{spec.name}.3ds'}")
            continue
        with tempfile.TemporaryDirectory() as tmp:
            src = Path(tmp) / f"{spec.name}.3ds"
            write_tank_3ds(spec, src)
            result = build_vehicle_bundle(src, args.out / spec.name, spec.name, hull_points_n=spec.hull_points,
                                          levels=spec.levels, branching=spec.branching, force=True)
        print(result.summary())
    return 0


if __name__ == "__main__":
    sys.exit(main())
