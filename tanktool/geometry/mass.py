"""Mass properties and default driving parameters of a vehicle.

The physics (§3.4.1-3.4.3 of the 2002 paper) needs a mass, a centre of mass and the
moment of inertia about the vertical axis through it (tanks turn about +y only).  A
watertight model gives all three from its solid (trimesh's mass properties); any other
model is treated as its hull prism — the footprint polygon extruded over the model's
height — filled uniformly.

Density: a tank is a steel shell around air, engine and ammunition, so its mass over
its outer volume is far below steel's 7850 kg/m^3.  DEFAULT_DENSITY = 2000 kg/m^3
gives 26 t for the bundled light tank (5.8 x 2.9 x 1.8 m) and 68 t for the heavy one
(8.4 x 3.9 x 2.4 m), close to real vehicles of those sizes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .hull import polygon_area

DEFAULT_DENSITY = 2000.0  # kg/m^3, effective density of a whole tank (see module doc)

#: default driving figures, chosen so that a 20 t tank feels like a light tank
ACCELERATION = 3.0        # m/s^2 at full throttle from rest
TURN_ACCELERATION = 1.5   # rad/s^2 at full steer from rest
SHELL_SPEED = 200.0       # m/s: slow enough to see, fast enough to need leading
RESTITUTION = 0.2


def sig(x: float, digits: int = 8) -> float:
    """``x`` to ``digits`` significant digits, for writing: a small vehicle's figures
    keep their digits (fixed decimals turned a 1.2e-5 N m turn torque into 0.0)."""
    x = float(x)
    if x == 0.0 or not math.isfinite(x):
        return x + 0.0
    return float(f"{x:.{digits}g}") + 0.0     # + 0.0: no "-0.0"


def to_scale(x: float, scale: float, digits: int = 8) -> float:
    """``x`` (a coordinate of a body ``scale`` metres across) rounded to ``digits``
    significant digits of ``scale``: the same absolute precision for every coordinate,
    fine enough for a toy, not noisy for a tank."""
    x = float(x)
    if not (scale > 0 and math.isfinite(scale)) or not math.isfinite(x):
        return sig(x, digits)
    return round(x, digits - 1 - math.floor(math.log10(scale))) + 0.0


@dataclass
class MassProperties:
    mass: float                  # kg
    volume: float                # m^3 (of the solid used)
    centre_of_mass: np.ndarray   # (3,) vehicle frame
    inertia: float               # kg m^2 about the vertical axis through the centre of mass
    method: str                  # "mesh" or "hull-box"


def polygon_moments(poly: np.ndarray) -> tuple[float, np.ndarray, float]:
    """Area, centroid (2,) and polar second moment about the centroid of a polygon.

    Uses the shoelace sums; the polar moment J = Ixx + Iyy of a unit-density lamina.
    """
    p = np.asarray(poly, dtype=np.float64)
    if polygon_area(p) < 0:
        p = p[::-1]
    x, y = p[:, 0], p[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    a = cross.sum() / 2
    cx = ((x + x1) * cross).sum() / (6 * a)
    cy = ((y + y1) * cross).sum() / (6 * a)
    ixx = ((y * y + y * y1 + y1 * y1) * cross).sum() / 12   # about the origin
    iyy = ((x * x + x * x1 + x1 * x1) * cross).sum() / 12
    j = ixx + iyy - a * (cx * cx + cy * cy)                 # parallel axes to the centroid
    return float(a), np.array([cx, cy]), float(j)


def mesh_is_solid(mesh) -> bool:
    """True when the mesh closes a positive volume (watertight, consistently wound)."""
    m = mesh.copy()
    m.merge_vertices()
    return bool(m.is_watertight and m.is_winding_consistent and m.volume > 1e-12)


def mass_properties(mesh, footprint: np.ndarray, mass: float | None = None,
                    density: float = DEFAULT_DENSITY) -> MassProperties:
    """Mass, centre of mass and vertical-axis inertia of a vehicle-frame mesh.

    ``footprint`` is the hull's (k, 2) footprint polygon (x, z), used when the mesh is
    not a closed solid.  ``mass`` overrides density x volume; inertia scales with it.
    """
    y0, y1 = float(mesh.vertices[:, 1].min()), float(mesh.vertices[:, 1].max())
    if mesh_is_solid(mesh):
        m = mesh.copy()
        m.merge_vertices()
        volume = float(m.volume)
        com = np.asarray(m.center_mass, dtype=np.float64)
        # trimesh's tensor is for unit density about the centre of mass; [1, 1] is y
        inertia_unit = float(m.moment_inertia[1, 1]) / float(m.density)
        method = "mesh"
    else:
        height = max(y1 - y0, 1e-9)
        area, centroid, polar = polygon_moments(footprint)
        volume = area * height
        com = np.array([centroid[0], (y0 + y1) / 2, centroid[1]])
        inertia_unit = polar * height
        method = "hull-box"
    total = float(mass) if mass is not None else density * volume
    inertia = inertia_unit * (total / volume)
    return MassProperties(total, volume, com, float(inertia), method)


def drive_defaults(mass: float, inertia: float) -> dict[str, float]:
    """Driving parameters scaled with the vehicle, for the [drive] table.

    Heavier tanks are slower (top speed 15 m/s at 20 t down to 10 m/s at 60 t and
    beyond), fire less often and take more hits.  ``friction`` is a linear drag rate
    in 1/s (the ground slows the tank by friction x velocity, in m/s^2), set so that
    drive and drag balance at the top speed: engine_force = mass x friction x top_speed.
    """
    tonnes = mass / 1000.0
    top_speed = float(np.clip(17.5 - tonnes / 8.0, 10.0, 15.0))
    engine_force = mass * ACCELERATION
    friction = ACCELERATION / top_speed
    # significant digits, never fixed decimals: a 2 kg model's turn torque is 1e-3 N m
    return {
        "engine_force": sig(engine_force, 6),
        "turn_torque": sig(inertia * TURN_ACCELERATION, 6),
        "strafe_force": sig(0.5 * engine_force, 6),
        "friction": sig(friction, 4),
        "restitution": RESTITUTION,
        "top_speed": sig(top_speed, 4),
        "fire_interval": sig(float(np.clip(0.6 + tonnes / 50.0, 0.8, 2.5)), 3),
        "shell_speed": SHELL_SPEED,
        "hit_points": int(round(float(np.clip(100.0 * np.sqrt(max(tonnes, 1e-9) / 20.0), 50.0, 300.0)))),
    }
