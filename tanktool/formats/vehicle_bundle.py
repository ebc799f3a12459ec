"""Vehicle bundles on disk: ``vehicles/<name>/`` with vehicle.toml, hull.txt, spheres.txt.

``load_vehicle`` is what the simulation, the game and ``check`` read; it validates as it
goes and raises FormatError (a file's syntax) or VehicleError (values that make no
sense) naming the file and the key or line.

``hull.txt``: one ``x y z`` point a line, 8 to 16 lines, vehicle frame (+x forward,
+y up, +z right, metres), ``#`` starts a comment.  The tools write the k footprint
corners at the lowest y, then the same k corners at the highest y, counter-clockwise
from +x towards +z.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import FormatError, VehicleError
from .bundle import (atomic_write_text, bundle_file, clean_stale, data_lines, read_input, read_input_text,
                     read_toml)
from .limits import MAX_SMALL_TEXT_BYTES
from .spheres_txt import SphereTree, read_spheres

HULL_MIN, HULL_MAX = 8, 16
#: spheres a vehicle's sphere tree may have (import-vehicle makes a few dozen)
MAX_SPHERES = 4096

#: [drive] keys, their meaning and the range ``load_vehicle`` accepts
DRIVE_KEYS: dict[str, tuple[float, float]] = {
    "engine_force": (0.0, 1e8),    # N, forward/backward drive force at full throttle
    "turn_torque": (0.0, 1e9),     # N m, about the vertical axis at full steer
    "strafe_force": (0.0, 1e8),    # N, sideways drive force (0 = no strafing)
    "friction": (0.0, 100.0),      # 1/s, linear drag rate: ground decelerates by friction * v
    "restitution": (0.0, 1.0),     # collision bounce, 0 = dead stop, 1 = elastic
    "top_speed": (0.0, 200.0),     # m/s, speed cap
    "fire_interval": (0.0, 60.0),  # s between shots
    "shell_speed": (0.0, 5000.0),  # m/s muzzle speed
    "hit_points": (1.0, 1e6),      # damage the vehicle takes before it is destroyed
}


def format_hull(points: np.ndarray, header: str = "") -> str:
    """``hull.txt`` text, 4 decimals.  x and z are rounded to nearest (the footprint
    carries a 0.1 mm margin for that, see geometry.hull.MARGIN); y is rounded down
    for the bottom ring and up for the top one, so the written hull still encloses."""
    pts = np.asarray(points, dtype=np.float64)
    ymid = 0.5 * (pts[:, 1].min() + pts[:, 1].max())
    out = np.round(pts, 4)
    y = pts[:, 1] * 1e4
    out[:, 1] = np.where(pts[:, 1] >= ymid, np.ceil(y), np.floor(y)) / 1e4
    lines = [f"# {line}" for line in header.splitlines()] if header else []
    lines.append("# x y z   (vehicle frame: +x forward, +y up, +z right; metres)")
    lines += [f"{x:.4f} {y:.4f} {z:.4f}" for x, y, z in out]
    return "\n".join(lines) + "\n"


def write_hull(path: str | os.PathLike, points: np.ndarray, header: str = "") -> None:
    atomic_write_text(path, format_hull(points, header))


def read_hull(path: str | os.PathLike) -> np.ndarray:
    """Read ``hull.txt`` as (k, 3), 8 <= k <= 16; defects raise FormatError with the line."""
    path = Path(path)
    text = read_input_text(path, "a hull.txt file", limit=MAX_SMALL_TEXT_BYTES)
    rows: list[tuple[float, float, float]] = []
    for lineno, line, parts in data_lines(text):
        if len(parts) != 3:
            raise FormatError(f"{path}:{lineno}: expected 3 numbers 'x y z', got {len(parts)} fields")
        try:
            xyz = tuple(float(p) for p in parts)
        except ValueError:
            raise FormatError(f"{path}:{lineno}: expected 3 numbers 'x y z', got {line!r}") from None
        if not all(math.isfinite(c) for c in xyz):
            raise FormatError(f"{path}:{lineno}: coordinates must be finite numbers")
        rows.append(xyz)  # type: ignore[arg-type]
    if not HULL_MIN <= len(rows) <= HULL_MAX:
        raise FormatError(f"{path}: expected {HULL_MIN} to {HULL_MAX} hull points, found {len(rows)}")
    return np.array(rows, dtype=np.float64)


@dataclass
class VehicleBundle:
    """A loaded vehicle bundle; every physical quantity in SI units, vehicle frame."""

    name: str
    path: Path
    toml: dict[str, Any]
    hull: np.ndarray                 # (k, 3) hull points
    spheres: SphereTree
    mass: float                      # kg
    inertia: float                   # kg m^2 about the vertical axis through the centre of mass
    centre_of_mass: np.ndarray       # (3,)
    footprint_radius: float          # m, largest x-z distance of a hull point from the origin
    engine_force: float = 0.0
    turn_torque: float = 0.0
    strafe_force: float = 0.0
    friction: float = 0.0
    restitution: float = 0.0
    top_speed: float = 0.0
    fire_interval: float = 0.0
    shell_speed: float = 0.0
    hit_points: float = 0.0
    drive: dict[str, float] = field(default_factory=dict)

    @property
    def model_path(self) -> Path | None:
        """The model file inside the bundle (``load_vehicle`` refused one that leads out)."""
        t = self.toml.get("model")
        m = t.get("file") if isinstance(t, dict) else None
        return bundle_file(self.path, m, f"{self.path / 'vehicle.toml'}: [model] file") if m else None


def _number(manifest: Path, table: dict[str, Any], key: str, where: str, lo: float, hi: float) -> float:
    if key not in table:
        raise VehicleError(f"{manifest}: missing {where}{key}")
    v = table[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise VehicleError(f"{manifest}: {where}{key} must be a finite number, got {v!r}")
    if not lo <= v <= hi:
        raise VehicleError(f"{manifest}: {where}{key} = {v} is outside {lo:g}..{hi:g}")
    return float(v)


def _table(manifest: Path, doc: dict[str, Any], key: str) -> dict[str, Any]:
    t = doc.get(key)
    if not isinstance(t, dict):
        raise VehicleError(f"{manifest}: missing table [{key}]")
    return t


#: optional keys the simulation takes from anywhere in vehicle.toml (sim/body.py
#: TankSpec.from_vehicle), and the range each must have
SIM_KEYS: dict[str, tuple[float, float]] = {
    "turn_rate": (1e-6, 100.0),    # rad/s, top turning speed
    "grip": (0.0, 1e4),            # 1/s, lateral grip
    "shell_damage": (0.0, 1e6),    # hit points a shell takes
}


def _find(doc: dict[str, Any], key: str) -> Any:
    """The first ``key`` anywhere in nested tables, as the simulation finds it."""
    stack = [doc]
    while stack:
        d = stack.pop(0)
        if key in d:
            return d[key]
        stack[:0] = [v for v in d.values() if isinstance(v, dict)]
    return None


def _check_sim_keys(manifest: Path, doc: dict[str, Any]) -> None:
    for key, (lo, hi) in SIM_KEYS.items():
        v = _find(doc, key)
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))
                              or not math.isfinite(v) or not lo <= v <= hi):
            raise VehicleError(f"{manifest}: {key} must be a number from {lo:g} to {hi:g}, got {v!r:.60}")
    m = _find(doc, "muzzle")
    if m is not None and (not isinstance(m, list) or len(m) != 3 or not all(
            isinstance(c, (int, float)) and not isinstance(c, bool) and math.isfinite(c) for c in m)):
        raise VehicleError(f"{manifest}: muzzle must be a list of 3 finite numbers (vehicle frame), got {m!r:.60}")


def load_vehicle(path: str | os.PathLike) -> VehicleBundle:
    """Load ``vehicles/<name>/`` (or its ``vehicle.toml``) and check it is usable."""
    path = Path(path)
    if path.is_file() and path.name == "vehicle.toml":
        path = path.parent
    manifest = path / "vehicle.toml"
    if not path.is_dir():
        clean_stale(path.parent, path.name)  # a replacement killed half-way: put the bundle back
    if not path.is_dir():
        from .models import refuse_model

        refuse_model(path, "vehicle")
        raise VehicleError(f"{path}: no such vehicle bundle folder")
    if not manifest.exists():
        raise VehicleError(f"{path}: not a vehicle bundle (no vehicle.toml)")
    doc = read_toml(manifest)
    name = doc.get("name", path.name)
    if not isinstance(name, str) or not name:
        raise VehicleError(f"{manifest}: name must be a non-empty string")

    mass_t = _table(manifest, doc, "mass")
    mass = _number(manifest, mass_t, "mass", "[mass] ", 1e-6, 1e9)
    inertia = _number(manifest, mass_t, "inertia", "[mass] ", 1e-12, 1e15)
    com = mass_t.get("centre_of_mass")
    if (not isinstance(com, list) or len(com) != 3
            or not all(isinstance(c, (int, float)) and not isinstance(c, bool) and math.isfinite(c) for c in com)):
        raise VehicleError(f"{manifest}: [mass] centre_of_mass must be a list of 3 finite numbers, got {com!r:.60}")

    drive_t = _table(manifest, doc, "drive")
    drive = {k: _number(manifest, drive_t, k, "[drive] ", lo, hi) for k, (lo, hi) in DRIVE_KEYS.items()}

    hull_t = _table(manifest, doc, "hull")
    spheres_t = _table(manifest, doc, "spheres")
    model_t = doc.get("model", {})
    if not isinstance(model_t, dict):
        raise VehicleError(f"{manifest}: [model] must be a table, got model = {model_t!r:.60}")
    try:  # a name that leads out of the bundle: the manifest is wrong
        hull_f = bundle_file(path, hull_t.get("file", "hull.txt"), f"{manifest}: [hull] file")
        spheres_f = bundle_file(path, spheres_t.get("file", "spheres.txt"), f"{manifest}: [spheres] file")
        if "file" in model_t:
            bundle_file(path, model_t["file"], f"{manifest}: [model] file")
    except FormatError as e:
        raise VehicleError(str(e)) from None
    hull = read_hull(hull_f)
    read_input(spheres_f, "a spheres.txt file", limit=MAX_SMALL_TEXT_BYTES)  # a device, a FIFO, a huge file
    spheres = read_spheres(spheres_f)
    if len(spheres) > MAX_SPHERES:
        raise FormatError(f"{spheres_f}: {len(spheres):,} spheres, more than the {MAX_SPHERES:,} a vehicle may have")

    _check_sim_keys(manifest, doc)
    radius = float(np.max(np.hypot(hull[:, 0], hull[:, 2])))
    return VehicleBundle(
        name=name, path=path, toml=doc, hull=hull, spheres=spheres, mass=mass, inertia=inertia,
        centre_of_mass=np.array(com, dtype=np.float64), footprint_radius=radius, drive=drive, **drive,
    )
