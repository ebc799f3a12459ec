"""``tanktool import-vehicle MODEL``: a vehicle model in, a vehicle bundle out.

The work is in :func:`build_vehicle_bundle` (also used by tools/build_vehicles.py);
the click command only checks options, calls it and prints the summary.
"""

from __future__ import annotations

import math
import re
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import click
import numpy as np

from .. import __version__
from ..errors import VehicleError
from .main import echo
from .options import force_option, name_option, out_option, scale_option, up_option

#: the model file's axes a vehicle may face (``--forward``)
FORWARD_AXES = ("+x", "-x", "+y", "-y", "+z", "-z")
HULL_POINTS = (8, 16)
LEVELS = (1, 5)
BRANCHING = (2, 8)
MASS_RANGE = (1.0, 1.0e6)  # kg: a toy to ten times the heaviest tank ever built
SURFACE_SAMPLES = 4000     # points spread over the surface besides the vertices


@dataclass
class ImportResult:
    out: Path
    name: str
    hull_points: int
    footprint_area: float
    convex_area: float
    sphere_count: int
    leaf_count: int
    levels: int
    root_radius: float
    mass: float
    inertia: float
    method: str
    seconds: float
    warnings: list[str] = field(default_factory=list)

    def summary(self) -> str:
        ratio = self.footprint_area / self.convex_area if self.convex_area else 1.0
        return "\n".join([
            f"wrote {self.out}/",
            f"  hull     {self.hull_points} points, footprint {self.footprint_area:.3f} m^2 = "
            f"{ratio:.3f} x convex hull ({self.convex_area:.3f} m^2)",
            f"  spheres  {self.sphere_count} in {self.levels} levels, {self.leaf_count} leaves, "
            f"root radius {self.root_radius:.3f} m",
            f"  mass     {_amount(self.mass)} kg ({self.method}), inertia {_amount(self.inertia)} kg m^2 "
            "about the vertical axis",
            f"  took     {self.seconds:.2f} s",
        ])


def _amount(x: float) -> str:
    """A figure as people read it: thousands separated, small ones with their digits."""
    return f"{x:,.0f}" if abs(x) >= 1000 else f"{x:.4g}"


def check_options(hull_points: int, sphere_levels: int, branching: int, mass: float | None, name: str) -> None:
    """Reject bad option values with one VehicleError line (exit 2)."""
    lo, hi = HULL_POINTS
    if not (lo <= hull_points <= hi) or hull_points % 2:
        raise VehicleError(f"--hull-points must be an even number from {lo} to {hi} "
                           f"(a bottom and a top point per footprint corner), got {hull_points}")
    if not LEVELS[0] <= sphere_levels <= LEVELS[1]:
        raise VehicleError(f"--sphere-levels must be from {LEVELS[0]} to {LEVELS[1]}, got {sphere_levels}")
    if not BRANCHING[0] <= branching <= BRANCHING[1]:
        raise VehicleError(f"--branching must be from {BRANCHING[0]} to {BRANCHING[1]} children per sphere, got {branching}")
    if mass is not None and not (math.isfinite(mass) and MASS_RANGE[0] <= mass <= MASS_RANGE[1]):
        raise VehicleError(f"--mass must be from {MASS_RANGE[0]:g} to {MASS_RANGE[1]:g} kg, got {mass:g}")
    if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.-]*", name):
        raise VehicleError(f"--name {name!r}: use letters, digits, '_', '-' and '.' only")


def forward_rotation(forward: str, up: str) -> np.ndarray:
    """4x4 rotation about the world's vertical (y) axis that turns the model file's
    ``forward`` axis to +x, the vehicle frame's front.

    The file's axes have already been turned Y-up by :func:`load_scene` (``up``: "z"
    maps file (x, y, z) to (x, z, -y)), so ``forward`` is first mapped the same way;
    it must be horizontal, i.e. not the file's up axis.
    """
    if forward not in FORWARD_AXES:
        raise VehicleError(f"--forward must be one of {' '.join(FORWARD_AXES)}, got {forward!r}")
    if forward[1] == up:
        raise VehicleError(f"--forward {forward} is the model's up axis (--up {up}): the front must be "
                           "a horizontal axis")
    e = np.zeros(3)
    e["xyz".index(forward[1])] = 1.0 if forward[0] == "+" else -1.0
    wx, _, wz = (e[0], e[2], -e[1]) if up == "z" else (e[0], e[1], e[2])
    m = np.eye(4)
    m[:3, :3] = [[wx, 0.0, wz], [0.0, 1.0, 0.0], [-wz, 0.0, wx]]
    return m


def _across_axis(up: str) -> str:
    """The model file's horizontal axis that is not x (the one that maps to world z)."""
    return "y" if up == "z" else "z"


def vehicle_frame_offset(vertices: np.ndarray) -> np.ndarray:
    """Translation into the vehicle frame: origin at the centre of the footprint's
    bounding box, y = 0 at the lowest point."""
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    return np.array([-(lo[0] + hi[0]) / 2, -lo[1], -(lo[2] + hi[2]) / 2])


def derive(mesh, hull_points_n: int, levels: int, branching: int, mass: float | None):
    """Hull, sphere tree and mass properties of a vehicle-frame mesh.

    The sphere tree is built on the vertices and surface samples, then refitted to
    hold the whole surface (``cover_surface``): ``check`` tests it on points sampled
    over the surface, not only on the vertices.
    """
    from ..geometry.hull import hull_points
    from ..geometry.mass import mass_properties
    from ..geometry.sphere_build import build_points, build_sphere_tree, cover_surface

    v = np.asarray(mesh.vertices, dtype=np.float64)
    f = np.asarray(mesh.faces)
    hull, fp = hull_points(v, hull_points_n)
    pts = build_points(v, f, SURFACE_SAMPLES, seed=0)
    tree = cover_surface(build_sphere_tree(pts, levels=levels, branching=branching, seed=0), v, f)
    mp = mass_properties(mesh, fp.polygon, mass=mass)
    return hull, fp, tree, mp


def sanity_warnings(model: Path, vertices: np.ndarray, mass: float, forward: str, up: str) -> list[str]:
    """What looks wrong with an imported vehicle (it is still written): lying on its
    side, facing sideways, an absurd size or mass.  The same tests as ``check``'s
    V105-V107 and V303 (:mod:`tanktool.geometry.proportions`)."""
    from ..geometry.proportions import mass_problem, on_its_side, proportions, sideways, size_problem

    p = proportions(vertices)
    out = []
    why = on_its_side(p)
    if why:
        other = "y" if up == "z" else "z"
        out.append(f"{model}: {why}: is the file's up axis {other}? (--up {other}; it was read as --up {up})")
    why = sideways(p)
    if why:
        ax = _across_axis(up) if forward[1] == "x" else "x"
        out.append(f"{model}: {why} (--forward {forward}): does it face +{ax} or -{ax}? "
                   f"(--forward +{ax} or --forward -{ax})")
    why = size_problem(p)
    if why:
        out.append(f"{model}: {why}: wrong --scale? (the model's units times --scale must be metres)")
    why = mass_problem(mass)
    if why:
        out.append(f"{model}: {why}: wrong --scale or --mass?")
    return out


def _vehicle_mesh(model: Path, up: str, scale: float, forward: str) -> tuple[Any, Any, np.ndarray]:
    """The model in the vehicle frame: (scene, its meshes as one, the offset applied),
    refused when flat from above or absurdly large."""
    import trimesh

    from ..formats.models import load_scene

    turn = forward_rotation(forward, up)
    scene = load_scene(model, up=up, scale=scale)
    if not np.array_equal(turn, np.eye(4)):
        scene.apply_transform(turn)
    meshes = [m for m in scene.dump() if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    mesh = meshes[0] if len(meshes) == 1 else trimesh.util.concatenate(meshes)
    extent = np.ptp(mesh.vertices, axis=0)
    if not (extent[0] > 0 and extent[2] > 0):
        raise VehicleError(f"{model}: the model is flat seen from above (extent {extent[0]:g} x {extent[2]:g} m in x-z)")
    if extent.max() > 1e4:
        raise VehicleError(f"{model}: the model is {extent.max():g} m across: wrong --scale?")
    offset = vehicle_frame_offset(np.asarray(mesh.vertices))
    scene.apply_translation(offset)
    mesh.apply_translation(offset)
    return scene, mesh, offset


def build_vehicle_bundle(model: Path, out: Path, name: str, up: str | None = None, scale: float = 1.0,
                         hull_points_n: int = 16, levels: int = 3, branching: int = 4,
                         mass: float | None = None, force: bool = False,
                         drive: dict[str, Any] | None = None, forward: str = "+x") -> ImportResult:
    """Read ``model`` and write the vehicle bundle ``out`` atomically.

    ``forward`` is the model file's axis that points to the vehicle's front; it is
    turned to +x.  ``drive`` replaces the computed [drive] defaults (``make vehicles``
    keeps the hand-edited figures of a bundled vehicle this way).  What looks wrong
    but is written anyway is in the result's ``warnings``.
    """
    from ..formats.bundle import atomic_write_bytes, atomic_write_text, dumps_toml
    from ..formats.bundle_swap import check_replaceable, staged_dir
    from ..formats.materials import export_glb
    from ..formats.models import default_up, detect_format
    from ..formats.vehicle_bundle import write_hull
    from ..geometry.mass import drive_defaults
    from ..geometry.spheres import write_spheres
    from ..plots.vehicle import plot_vehicle

    t0 = time.perf_counter()
    model = Path(model)
    check_options(hull_points_n, levels, branching, mass, name)
    out = Path(out)
    check_replaceable(out, force, "vehicle.toml")  # only a vehicle bundle tanktool wrote is replaced
    if out.resolve() == model.resolve().parent:
        raise VehicleError(f"{out}: the output folder must not be the folder of the model being imported")
    up_used = up or default_up(detect_format(model))
    scene, mesh, offset = _vehicle_mesh(model, up_used, scale, forward)
    hull, fp, tree, mp = derive(mesh, hull_points_n, levels, branching, mass)
    if not MASS_RANGE[0] <= mp.mass <= MASS_RANGE[1]:
        raise VehicleError(f"{model}: its volume ({mp.volume:.3g} m^3, {mp.method}) gives a mass of "
                           f"{mp.mass:.4g} kg, outside {MASS_RANGE[0]:g}..{MASS_RANGE[1]:g} kg: "
                           f"wrong --scale? or give --mass")
    warnings = sanity_warnings(model, np.asarray(mesh.vertices), mp.mass, forward, up_used)
    params = drive_defaults(mp.mass, mp.inertia)
    if drive:
        params.update({k: drive[k] for k in params if k in drive})
    header = f"{name}: made by tanktool {__version__} import-vehicle from {model.name}"

    with staged_dir(out, force=force, manifest="vehicle.toml") as tmp:
        shutil.copyfile(model, tmp / model.name)
        glb, textures = export_glb(model, scene, tmp, extra=[out], warn=warnings.append)   # textures copied in
        atomic_write_bytes(tmp / "model.glb", glb)
        write_hull(tmp / "hull.txt", hull, header)
        write_spheres(tmp / "spheres.txt", tree, header)
        plot_vehicle(tmp / "preview.png", mesh, hull, tree,
                     title=f"{name}: {len(hull)} hull points, {len(tree)} spheres, {mp.mass / 1000:.1f} t")
        doc = _manifest(tmp, name, model.name, (up_used, forward, scale, offset), mesh, textures, mp, mass,
                        params, (hull, fp, hull_points_n), (tree, branching, levels))
        atomic_write_text(tmp / "vehicle.toml", DRIVE_COMMENT + dumps_toml(doc))
    return ImportResult(out, name, len(hull), fp.area, fp.convex_area, len(tree), len(tree.leaves()),
                        int(tree.levels), float(tree.radii[0]), mp.mass, mp.inertia, mp.method,
                        time.perf_counter() - t0, warnings)


def _manifest(tmp: Path, name: str, source_name: str, frame: tuple, mesh: Any, textures: list, mp: Any,
              mass: float | None, params: dict, hull_info: tuple, tree_info: tuple) -> dict[str, Any]:
    """vehicle.toml of the bundle staged in ``tmp`` (its files written): ``frame`` is
    (up, forward, scale, offset), ``hull_info`` (hull, footprint, points asked for),
    ``tree_info`` (sphere tree, branching, levels asked for)."""
    from ..formats.bundle import sha256_file
    from ..geometry.mass import sig, to_scale

    up_used, forward, scale, offset = frame
    hull, fp, hull_points_n = hull_info
    tree, branching, levels = tree_info
    radius = float(np.max(np.hypot(hull[:, 0], hull[:, 2])))
    size = float(np.ptp(np.asarray(mesh.vertices), axis=0).max())
    # significant digits, not fixed decimals: a 5 cm model keeps its figures too
    return {
        "name": name,
        "tool_version": __version__,
        "footprint_radius": sig(radius),
        "source": {"file": source_name, "sha256": sha256_file(tmp / source_name), "up": up_used,
                   "forward": forward, "scale": float(scale),
                   "vehicle_frame_offset": [to_scale(x, size) for x in offset]},
        "model": {"file": "model.glb", **({"textures": textures} if textures else {})},
        "mass": {"mass": sig(mp.mass), "inertia": sig(mp.inertia),
                 "centre_of_mass": [to_scale(x, size) for x in mp.centre_of_mass],
                 "method": mp.method, "volume": sig(mp.volume),
                 "mass_given": mass is not None},
        "drive": params,
        "hull": {"file": "hull.txt", "points": int(len(hull)), "requested": hull_points_n,
                 "footprint_area": sig(fp.area), "convex_area": sig(fp.convex_area)},
        "spheres": {"file": "spheres.txt", "levels": int(tree.levels), "branching": branching,
                    "count": int(len(tree)), "leaves": int(len(tree.leaves())),
                    "requested_levels": levels},
        "derived": {f: sha256_file(tmp / f) for f in ("model.glb", "hull.txt", "spheres.txt", "preview.png")},
    }


DRIVE_COMMENT = """\
# Vehicle bundle made by `tanktool import-vehicle`.  Frame: +x forward, +y up, +z right,
# origin at the centre of the footprint's bounding box, y = 0 at the lowest point.
# [mass]: mass kg; inertia kg m^2 about the vertical axis through centre_of_mass;
#   method "mesh" (closed model) or "hull-box" (hull prism filled uniformly).
# [drive] may be edited by hand: engine_force N; turn_torque N m; strafe_force N;
#   friction 1/s (linear drag rate: the ground slows the tank by friction * velocity,
#   so engine_force = mass * friction * top_speed balances at top speed);
#   restitution 0..1; top_speed m/s; fire_interval s; shell_speed m/s; hit_points.
# [derived] sha256 of each derived file: `tanktool check` reports stale data.
"""


@click.command("import-vehicle")
@click.argument("model", type=click.Path(path_type=Path))
@out_option
@name_option
@up_option
@scale_option
@click.option("--hull-points", type=int, default=16, show_default=True,
              help="Hull points, even, 8..16: 8 = minimum rectangle box, more = N/2-gon prism.")
@click.option("--sphere-levels", type=int, default=3, show_default=True, help="Levels of the sphere tree (1..5).")
@click.option("--branching", type=int, default=4, show_default=True, help="Children per sphere (2..8).")
@click.option("--mass", type=float, default=None,
              help="Mass in kg (default: 2000 kg/m^3 times the model's volume).")
@click.option("--forward", type=click.Choice(FORWARD_AXES), default="+x", show_default=True,
              help="The model file's axis that points to the vehicle's front (it is turned to +x).")
@force_option
def import_vehicle(model: Path, out: Path | None, name: str | None, up: str | None, scale: float,
                   hull_points: int, sphere_levels: int, branching: int, mass: float | None, forward: str,
                   force: bool) -> None:
    """Turn a vehicle MODEL (.3ds, .obj, .stl, .glb, ...) into a vehicle bundle.

    Writes vehicle.toml, a copy of MODEL, model.glb, hull.txt, spheres.txt and
    preview.png into the bundle folder, all or nothing.  The vehicle's front is the
    file's --forward axis (default +x).  A vehicle that looks wrong (on its side,
    facing sideways, an absurd size or mass) is written with a warning.
    """
    name = name or model.stem
    out = out if out is not None else Path(name)
    result = build_vehicle_bundle(model, out, name, up=up, scale=scale, hull_points_n=hull_points,
                                  levels=sphere_levels, branching=branching, mass=mass, force=force,
                                  forward=forward)
    for w in result.warnings:
        click.echo(f"warning: {w}", err=True)
    echo(result.summary())


def load_vehicle_source(bundle: Path):
    """The bundle's source model in the vehicle frame, read with its stored up/scale."""
    import trimesh

    from ..formats.bundle import read_toml
    from ..formats.models import load_scene

    doc = read_toml(Path(bundle) / "vehicle.toml")
    src = doc["source"]
    scene = load_scene(Path(bundle) / src["file"], up=src["up"], scale=src["scale"])
    scene.apply_transform(forward_rotation(src.get("forward", "+x"), src["up"]))
    meshes = [m for m in scene.dump() if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    mesh = meshes[0] if len(meshes) == 1 else trimesh.util.concatenate(meshes)
    mesh.apply_translation(vehicle_frame_offset(np.asarray(mesh.vertices)))
    return mesh


def rebuild_params(doc: dict[str, Any]) -> dict[str, Any]:
    """The build_vehicle_bundle keyword arguments a bundle was made with."""
    src, hull, spheres, mass = doc["source"], doc["hull"], doc["spheres"], doc["mass"]
    return {
        "up": src["up"], "scale": float(src["scale"]), "forward": src.get("forward", "+x"),
        "hull_points_n": int(hull.get("requested", hull["points"])),
        "levels": int(spheres.get("requested_levels", spheres["levels"])),
        "branching": int(spheres["branching"]),
        "mass": float(mass["mass"]) if mass.get("mass_given") else None,
        "drive": dict(doc.get("drive", {})),
    }
