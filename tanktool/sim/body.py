"""Tank bodies: the fixed description of a vehicle (:class:`TankSpec`) and the moving
state of one tank in a world (:class:`Tank`).

A tank is a rigid body in the (x, z) plane.  Internally every local point (hull points,
sphere centres, muzzle) is stored relative to the centre of mass, so that rotation
and the impulse arms r = P − CM are right; :attr:`Tank.position` converts back to the
vehicle-frame origin that the rest of the program speaks about.

Small data (8–16 hull points, a handful of spheres, 8 tanks) is kept in plain Python
floats and tuples: for arrays this small, one numpy call costs more than the whole
loop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

from ..errors import VehicleError

def _convex_hull(points: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """Counter-clockwise (in x, z) convex hull, Andrew's monotone chain."""
    pts = sorted(set(points))
    if len(pts) <= 2:
        return pts

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list[tuple[float, float]] = []
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


@dataclass
class TankSpec:
    """Everything the simulation needs to know about one kind of vehicle.

    Geometry is in the vehicle frame (+x forward, +y up, +z right, origin at the centre
    of the footprint's bounding box, y = 0 at the lowest point) and is re-expressed
    about the centre of mass in :meth:`__post_init__`.

    Units: metres, kilograms, newtons, newton-metres, seconds.
    """

    name: str
    hull: Sequence[Sequence[float]]                  # (k, 3) hull points, 8..16
    sphere_centers: Sequence[Sequence[float]]        # (s, 3)
    sphere_radii: Sequence[float]                    # (s,)
    sphere_parent: Sequence[int]                     # (s,), -1 for the root (index 0)
    mass: float = 20000.0
    inertia: float = 60000.0                         # about the vertical axis through the CM
    centre_of_mass: Sequence[float] = (0.0, 0.0, 0.0)
    engine_force: float = 120000.0
    turn_torque: float = 150000.0
    strafe_force: float = 60000.0
    friction: float = 0.5                            # 1/s, rolling drag rate: a = −friction·v
    restitution: float = 0.3
    top_speed: float = 12.0                          # m/s, the engine gives nothing beyond it
    turn_rate: float = 1.6                           # rad/s, terminal turn rate at full rotate
    grip: float = 8.0                                # 1/s, lateral drag rate: tracks resist sliding sideways
    fire_interval: float = 1.0
    shell_speed: float = 500.0
    shell_damage: float = 25.0
    hit_points: float = 100.0
    muzzle: Sequence[float] | None = None            # vehicle frame; default: front, 3/4 height

    # derived in __post_init__ (about the centre of mass)
    hull_local: list[tuple[float, float]] = field(init=False, repr=False)
    footprint: list[tuple[float, float]] = field(init=False, repr=False)
    footprint_normals: list[tuple[float, float]] = field(init=False, repr=False)
    spheres: list[tuple[float, float, float, float]] = field(init=False, repr=False)
    sphere_children: list[list[int]] = field(init=False, repr=False)
    radius: float = field(init=False)
    box: tuple[float, float, float, float] = field(init=False, repr=False)   # footprint's (xmin, zmin, xmax, zmax)
    muzzle_local: tuple[float, float, float] = field(init=False, repr=False)
    height: float = field(init=False)

    def __post_init__(self) -> None:
        hull = [tuple(float(c) for c in p) for p in self.hull]
        if not 3 <= len(hull) <= 64 or any(len(p) != 3 for p in hull):
            raise VehicleError(f"vehicle {self.name!r}: hull must be 3..64 points (x, y, z), got {len(hull)}")
        for key in ("mass", "inertia", "top_speed", "turn_rate", "hit_points"):
            v = float(getattr(self, key))
            if not (math.isfinite(v) and v > 0):
                raise VehicleError(f"vehicle {self.name!r}: {key} must be a positive number, got {v}")
            setattr(self, key, v)
        for key in ("engine_force", "turn_torque", "strafe_force", "friction", "grip", "shell_damage",
                    "shell_speed", "fire_interval"):
            v = float(getattr(self, key))
            if not (math.isfinite(v) and v >= 0):
                raise VehicleError(f"vehicle {self.name!r}: {key} must be >= 0, got {v}")
            setattr(self, key, v)
        self.restitution = float(self.restitution)
        if not 0.0 <= self.restitution <= 1.0:
            raise VehicleError(f"vehicle {self.name!r}: restitution must lie in [0, 1], got {self.restitution}")
        cx, _, cz = (float(c) for c in self.centre_of_mass)
        # seen from above the top and bottom rings of a hull coincide: keep each (x, z) once
        self.hull_local = list(dict.fromkeys((x - cx, z - cz) for x, _, z in hull))
        self.height = max(p[1] for p in hull)
        self.footprint = _convex_hull(self.hull_local)
        if len(self.footprint) < 3:
            raise VehicleError(f"vehicle {self.name!r}: hull points have no area seen from above")
        # outward normals of the footprint's edges (CCW in (x, z): outward = (dz, -dx))
        self.footprint_normals = []
        fp = self.footprint
        for i in range(len(fp)):
            (x1, z1), (x2, z2) = fp[i], fp[(i + 1) % len(fp)]
            dx, dz = x2 - x1, z2 - z1
            ln = math.hypot(dx, dz)
            self.footprint_normals.append((dz / ln, -dx / ln))
        self.radius = max(math.hypot(x, z) for x, z in self.hull_local)
        xs = [x for x, _ in self.hull_local]
        zs = [z for _, z in self.hull_local]
        self.box = (min(xs), min(zs), max(xs), max(zs))
        centers = [tuple(float(c) for c in p) for p in self.sphere_centers]
        radii = [float(r) for r in self.sphere_radii]
        parent = [int(p) for p in self.sphere_parent]
        if not centers or not (len(centers) == len(radii) == len(parent)) or parent[0] != -1:
            raise VehicleError(f"vehicle {self.name!r}: sphere tree must start with a root (parent -1)")
        self.spheres = [(x - cx, y, z - cz, r) for (x, y, z), r in zip(centers, radii)]
        self.sphere_children = [[] for _ in centers]
        for i, p in enumerate(parent[1:], start=1):
            if not 0 <= p < i:
                raise VehicleError(f"vehicle {self.name!r}: sphere {i} has parent {p}; parents must come first")
            self.sphere_children[p].append(i)
        if self.muzzle is None:
            front = max(x for x, _ in self.hull_local)
            self.muzzle_local = (front, 0.75 * self.height, 0.0)
        else:
            mx, my, mz = (float(c) for c in self.muzzle)
            self.muzzle_local = (mx - cx, my, mz - cz)

    @property
    def turn_drag(self) -> float:
        """Angular drag [N m s] so that full rotate levels off at ``turn_rate``."""
        return max(self.turn_torque, 1e-9) / self.turn_rate

    @classmethod
    def box(cls, name: str = "box", length: float = 6.0, width: float = 3.4, height: float = 2.4,
            mass: float = 20000.0, **params: Any) -> "TankSpec":
        """A box-shaped tank: 8 hull points at the corners and a 2-level sphere tree
        (a root around everything, four leaves along the hull's length)."""
        hx, hz = length / 2, width / 2
        hull = [(sx * hx, y, sz * hz) for y in (0.0, height) for sx in (-1, 1) for sz in (-1, 1)]
        root_r = math.sqrt(hx * hx + hz * hz + (height / 2) ** 2)
        leaf_r = math.sqrt((length / 8) ** 2 + hz * hz + (height / 2) ** 2)
        centers = [(0.0, height / 2, 0.0)] + [(-hx + length / 8 * (2 * i + 1), height / 2, 0.0) for i in range(4)]
        radii = [root_r] + [leaf_r] * 4
        parent = [-1, 0, 0, 0, 0]
        inertia = mass * (length ** 2 + width ** 2) / 12.0
        params.setdefault("inertia", inertia)
        return cls(name=name, hull=hull, sphere_centers=centers, sphere_radii=radii,
                   sphere_parent=parent, mass=mass, **params)

    @classmethod
    def from_vehicle(cls, vb: Any, name: str | None = None) -> "TankSpec":
        """Build from a vehicle bundle (``tanktool.formats.vehicle_bundle.VehicleBundle``).

        Read by attribute so that the simulation does not import the bundle reader;
        drive parameters the bundle lacks keep this class's defaults.
        """
        tree = vb.spheres
        kw: dict[str, Any] = {}
        for key in ("engine_force", "turn_torque", "strafe_force", "friction", "restitution",
                    "top_speed", "fire_interval", "shell_speed", "hit_points", "turn_rate",
                    "grip", "shell_damage", "muzzle"):
            v = getattr(vb, key, None)
            if v is None and isinstance(getattr(vb, "toml", None), dict):
                v = _find_key(vb.toml, key)
            if v is not None:
                kw[key] = v
        com = getattr(vb, "centre_of_mass", None)
        try:
            return cls._from_parts(vb, tree, kw, com, name)
        except VehicleError as e:
            where = getattr(vb, "path", None)
            raise VehicleError(f"{where}/vehicle.toml: {e}" if where else str(e)) from None

    @classmethod
    def _from_parts(cls, vb: Any, tree: Any, kw: dict[str, Any], com: Any, name: str | None) -> "TankSpec":
        return cls(
            name=name or str(vb.name),
            hull=[tuple(p) for p in _tolist(vb.hull)],
            sphere_centers=[tuple(p) for p in _tolist(tree.centers)],
            sphere_radii=_tolist(tree.radii),
            sphere_parent=_tolist(tree.parent),
            mass=float(vb.mass),
            inertia=float(vb.inertia),
            centre_of_mass=tuple(_tolist(com)) if com is not None else (0.0, 0.0, 0.0),
            **kw,
        )


def _tolist(a: Any) -> list:
    return a.tolist() if hasattr(a, "tolist") else list(a)


def _find_key(d: dict, key: str) -> Any:
    """A key anywhere in a (nested) toml table: bundles may group drive parameters."""
    if key in d:
        return d[key]
    for v in d.values():
        if isinstance(v, dict):
            found = _find_key(v, key)
            if found is not None:
                return found
    return None


class Tank:
    """The moving state of one tank.  ``x, z`` is its centre of mass; ``y`` the height
    of the ground under it (the base of its hull), ``level`` the navigation grid's
    level it drives on, ``pitch`` (nose up) and ``roll`` (right side down) its tilt
    from that ground (all 0 on a flat arena)."""

    __slots__ = ("index", "name", "spec", "x", "z", "heading", "vx", "vz", "omega",
                 "c", "s", "hp", "alive", "respawn_at", "reload", "kills", "deaths", "shots",
                 "hits", "wall_bumps", "distance", "touching_wall", "wall_cache",
                 "fx", "fz", "torque", "intent", "y", "level", "pitch", "roll")

    def __init__(self, index: int, spec: TankSpec, x: float, z: float, heading: float,
                 name: str | None = None) -> None:
        self.index = index
        self.name = name or f"{spec.name}{index + 1}"
        self.spec = spec
        self.x, self.z, self.heading = float(x), float(z), float(heading)
        self.vx = self.vz = self.omega = 0.0
        self.c, self.s = math.cos(self.heading), math.sin(self.heading)
        self.hp = spec.hit_points
        self.alive = True
        self.respawn_at = 0.0
        self.reload = 0.0          # seconds until the gun may fire again
        self.kills = self.deaths = self.shots = self.hits = self.wall_bumps = 0
        self.distance = 0.0
        self.touching_wall = -math.inf   # time of the last wall contact
        self.wall_cache: tuple[float, float, list[int]] | None = None
        self.fx = self.fz = self.torque = 0.0
        self.intent = (0.0, 0.0, 0.0, False)
        self.y = 0.0
        self.level = 0
        self.pitch = self.roll = 0.0

    # --- frames -------------------------------------------------------------------
    def to_world(self, lx: float, lz: float) -> tuple[float, float]:
        """A point given about the centre of mass, in world (x, z)."""
        return self.x + lx * self.c - lz * self.s, self.z + lx * self.s + lz * self.c

    def point_velocity(self, px: float, pz: float) -> tuple[float, float]:
        """Velocity of the body point at world (px, pz): v + ω × r (ω about +y)."""
        # with θ increasing from +x towards +z, d/dt of r is ω·(−r_z, r_x)
        return self.vx - self.omega * (pz - self.z), self.vz + self.omega * (px - self.x)

    @property
    def position(self) -> tuple[float, float]:
        """World (x, z) of the vehicle-frame origin (not the centre of mass)."""
        cx, _, cz = self.spec.centre_of_mass
        return self.to_world(-float(cx), -float(cz))

    def place(self, x: float, z: float, heading: float) -> None:
        """Put the vehicle-frame origin at (x, z) facing ``heading``, at rest."""
        self.heading = float(heading)
        self.c, self.s = math.cos(self.heading), math.sin(self.heading)
        cx, _, cz = (float(v) for v in self.spec.centre_of_mass)
        self.x = x + cx * self.c - cz * self.s
        self.z = z + cx * self.s + cz * self.c
        self.vx = self.vz = self.omega = 0.0
        self.wall_cache = None

    def hull_world(self) -> list[tuple[float, float]]:
        x, z, c, s = self.x, self.z, self.c, self.s
        return [(x + lx * c - lz * s, z + lx * s + lz * c) for lx, lz in self.spec.hull_local]

    def kinetic_energy(self) -> float:
        return 0.5 * self.spec.mass * (self.vx * self.vx + self.vz * self.vz) + 0.5 * self.spec.inertia * self.omega ** 2

    def speed(self) -> float:
        return math.hypot(self.vx, self.vz)
