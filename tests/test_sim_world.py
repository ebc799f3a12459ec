"""The world step: stages, forces, integrators, determinism, and the soak."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_fixtures import box_arena, bundled_arenas, free_spec, maze_arena

from tanktool.errors import ArenaError, TanktoolError, VehicleError
from tanktool.formats.walls_txt import read_walls
from tanktool.sim.body import TankSpec
from tanktool.sim.commands import Command, parse_command
from tanktool.sim.driver import make_drivers
from tanktool.sim.match import ArenaInfo, run_match
from tanktool.sim.world import World


def _open_world(spec: TankSpec, heading: float = 0.0, integrator: str = "semi-implicit") -> World:
    walls, _ = box_arena()
    w = World(walls, [spec], [(20.0, 10.0, heading)], seed=0, integrator=integrator)
    w.tanks[0].place(20.0, 10.0, heading)
    return w


def test_commands_clamp_and_parse():
    c = Command(advance=3.0, rotate=-7.0, strafe=float("nan"), fire=1)
    assert c.to_tuple() == (1.0, -1.0, 0.0, True)
    assert Command.from_keys(forward=True, left=True, strafe_right=True).to_tuple() == (1.0, -1.0, 1.0, False)
    assert parse_command("0.5 -1 0 1") == Command(0.5, -1.0, 0.0, True)
    with pytest.raises(TanktoolError):
        parse_command("1 2")
    with pytest.raises(TanktoolError):
        parse_command("1 0 0 2")


def test_stages_are_named_and_in_order():
    names = ["initialise_objects", "direction", "forces", "integrate", "vertices",
             "detect_collisions", "resolve_collisions"]
    for n in names:
        assert callable(getattr(World, n))
    import inspect

    src = inspect.getsource(World.step)
    pos = [src.index(f"self.{n}(") for n in names]
    assert pos == sorted(pos)


def test_full_throttle_levels_off_at_top_speed():
    spec = TankSpec.box("t", top_speed=10.0, friction=0.3)
    w = _open_world(spec, heading=0.0)
    t = w.tanks[0]
    for _ in range(int(8 / w.dt)):      # 8 s: steady long before the east wall
        w.step(None, [Command(advance=1.0)])
        assert t.speed() <= spec.top_speed * (1 + 1e-9)
    # drag and the engine balance where E·min(1, 20(1 - v/top)) = m μ v
    E, mu_m, top = spec.engine_force, spec.mass * spec.friction, spec.top_speed
    expect = E / mu_m if E / mu_m <= 0.95 * top else 20 * E / (mu_m + 20 * E / top)
    assert expect > 0.9 * top
    assert t.vx == pytest.approx(expect, rel=1e-3)
    assert abs(t.vz) < 1e-9 and t.heading == 0.0
    # coasting: rolling drag brings it to rest
    for _ in range(int(30 / w.dt)):
        w.step(None, [Command()])
    assert t.speed() < 0.01 * expect


def test_turn_strafe_and_grip_directions():
    spec = TankSpec.box("t")
    w = _open_world(spec, heading=0.3)
    t = w.tanks[0]
    for _ in range(60):
        w.step(None, [Command(rotate=1.0)])
    assert t.heading > 0.3 and t.omega > 0          # rotate > 0 turns towards the right side
    w = _open_world(spec, heading=0.3)
    t = w.tanks[0]
    x0, z0 = t.x, t.z
    for _ in range(120):
        w.step(None, [Command(strafe=1.0)])
    dx, dz = t.x - x0, t.z - z0
    right = (-math.sin(0.3), math.cos(0.3))
    assert dx * right[0] + dz * right[1] > 0.5
    assert abs(dx * math.cos(0.3) + dz * math.sin(0.3)) < 1e-6
    # lateral grip: a sideways slide dies far faster than a forward roll
    w = _open_world(spec, heading=0.0)
    t = w.tanks[0]
    t.vz = 5.0                                       # sideways for heading 0
    for _ in range(120):
        w.step(None, [Command()])
    side_left = abs(t.vz)
    w = _open_world(spec, heading=0.0)
    t = w.tanks[0]
    t.vx = 5.0
    for _ in range(120):
        w.step(None, [Command()])
    assert side_left < 0.01 and t.vx > 2.0


@pytest.mark.parametrize("integrator", ["semi-implicit", "euler"])
def test_one_step_of_each_integrator(integrator):
    spec = free_spec(engine_force=50000.0, top_speed=1000.0)
    w = _open_world(spec, heading=0.0, integrator=integrator)
    t = w.tanks[0]
    t.vx = 2.0
    x0, dt = t.x, w.dt
    w.step(None, [Command(advance=1.0)])
    a = spec.engine_force / spec.mass
    assert t.vx == pytest.approx(2.0 + a * dt, rel=1e-12)
    if integrator == "euler":
        assert t.x - x0 == pytest.approx(2.0 * dt, rel=1e-12)        # old velocity
    else:
        assert t.x - x0 == pytest.approx((2.0 + a * dt) * dt, rel=1e-12)  # new velocity
    with pytest.raises(ValueError):
        World(box_arena()[0], [spec], [(1, 1, 0)], integrator="rk4")


def _run(seed: int, steps: int = 1200, integrator: str = "semi-implicit"):
    walls, spawns = box_arena()
    w = World(walls, [TankSpec.box("t")] * 8, spawns, seed=seed, integrator=integrator)
    drivers = make_drivers(w)
    events = []
    for _ in range(steps):
        events += w.step(None, [d(w, t) for d, t in zip(drivers, w.tanks)])
    return w.state(), [e.to_dict() for e in events]


def test_determinism_same_seed_same_everything():
    s1, e1 = _run(11)
    s2, e2 = _run(11)
    assert s1 == s2 and e1 == e2
    assert any(e["kind"] == "shot" for e in e1)
    s3, e3 = _run(12)
    assert s3 != s1
    s4, _ = _run(11, integrator="euler")
    assert s4 != s1


def test_report_is_reproducible_apart_from_timing():
    walls, spawns = maze_arena()
    arena = ArenaInfo("maze", walls, spawns, None)
    r1 = run_match(arena, TankSpec.box("t"), bots=6, seconds=8, seed=5).report
    r2 = run_match(arena, TankSpec.box("t"), bots=6, seconds=8, seed=5).report
    assert "timing" in r1 and r1["timing"]["steps_per_second"] > 0
    r1.pop("timing"), r2.pop("timing")
    assert r1 == r2
    assert r1["seconds"] == pytest.approx(8.0) and r1["steps"] == 960
    keys = {"name", "kills", "deaths", "shots", "hits", "wall_bumps", "distance", "position"}
    assert all(keys <= set(t) for t in r1["tanks"])
    kills = sum(t["kills"] for t in r1["tanks"])
    assert kills == sum(1 for e in r1["events"] if e["kind"] == "kill") == sum(t["deaths"] for t in r1["tanks"])
    assert sum(t["shots"] for t in r1["tanks"]) == sum(1 for e in r1["events"] if e["kind"] == "shot")
    assert sum(t["wall_bumps"] for t in r1["tanks"]) == sum(1 for e in r1["events"] if e["kind"] == "wall_bump")


def test_bad_setup_errors():
    walls, spawns = box_arena()
    # more tanks than spawn points take free places (sim/extra_spawns.py), up to what fits
    with pytest.raises(ArenaError, match=r"holds \d+ tanks of t at once \(10 spawn points"):
        World(walls, [TankSpec.box("t")] * 400, spawns)
    with pytest.raises(VehicleError, match="restitution"):
        TankSpec.box("t", restitution=1.5)
    with pytest.raises(VehicleError, match="mass"):
        TankSpec.box("t", mass=-1.0)


def _soak(walls, spawns, seconds: float, seed: int = 1):
    specs = [TankSpec.box("light", length=5.0, width=3.0, mass=15000.0),
             TankSpec.box("heavy", length=7.0, width=3.6, mass=40000.0, engine_force=200000.0)]
    w = World(walls, [specs[i % 2] for i in range(8)], spawns, seed=seed)
    drivers = make_drivers(w)
    (x0, z0), (x1, z1) = w.bounds.tolist()
    kinds = set()
    for k in range(int(seconds / w.dt)):
        for e in w.step(None, [d(w, t) for d, t in zip(drivers, w.tanks)]):
            kinds.add(e.kind)
        if k % 12 == 0:
            for t in w.tanks:
                assert all(math.isfinite(v) for v in (t.x, t.z, t.heading, t.vx, t.vz, t.omega))
                if t.alive:
                    for px, pz in t.hull_world():
                        assert x0 - 0.02 <= px <= x1 + 0.02 and z0 - 0.02 <= pz <= z1 + 0.02
            for s in w.shells:
                assert math.isfinite(s.x + s.y + s.z) and x0 - 1 <= s.x <= x1 + 1 and z0 - 1 <= s.z <= z1 + 1
    return kinds


def _soak_arenas():
    out = [("box-fixture", *box_arena()), ("maze-fixture", *maze_arena())]
    for p in bundled_arenas():
        toml = p / "arena.toml"
        from tanktool.formats.bundle import read_toml

        raw = read_toml(toml).get("spawns", [])
        sp = np.asarray([s[:3] for s in raw], float).reshape(-1, 3)
        walls = read_walls(p / "walls.txt")
        if len(sp) >= 8 and not walls.layered:  # levels: tests/test_sim_ground.py
            out.append((p.name, walls, sp))
    return out


@pytest.mark.parametrize("name,walls,spawns", _soak_arenas(), ids=[a[0] for a in _soak_arenas()])
def test_soak_30s(name, walls, spawns):
    kinds = _soak(walls, spawns, 30.0)
    assert "shot" in kinds


@pytest.mark.slow
@pytest.mark.parametrize("name,walls,spawns", _soak_arenas(), ids=[a[0] for a in _soak_arenas()])
def test_soak_10min(name, walls, spawns):
    kinds = _soak(walls, spawns, 600.0, seed=2)
    assert {"shot", "hit", "kill", "respawn"} <= kinds


def test_spec_from_vehicle_bundle():
    from tanktool.formats.vehicle_bundle import VehicleBundle
    from tanktool.geometry.spheres import SphereTree

    hull = np.array([[x, y, z] for y in (0.0, 2.0) for x, z in ((3, 1.5), (-3, 1.5), (-3, -1.5), (3, -1.5))])
    tree = SphereTree(centers=[[0, 1, 0], [-1.5, 1, 0], [1.5, 1, 0]], radii=[3.5, 2.2, 2.2],
                      parent=[-1, 0, 0], level=[1, 2, 2])
    vb = VehicleBundle(name="lt", path=None, toml={"drive": {}}, hull=hull, spheres=tree, mass=18000.0,
                       inertia=60000.0, centre_of_mass=np.array([0.5, 0.8, 0.0]), footprint_radius=3.4,
                       engine_force=90000.0, turn_torque=80000.0, strafe_force=45000.0, friction=0.4,
                       restitution=0.25, top_speed=12.5, fire_interval=1.5, shell_speed=400.0, hit_points=120.0)
    spec = TankSpec.from_vehicle(vb)
    assert (spec.name, spec.mass, spec.top_speed, spec.hit_points, spec.shell_speed) == ("lt", 18000.0, 12.5, 120.0, 400.0)
    # geometry is kept about the centre of mass
    assert max(x for x, _ in spec.hull_local) == pytest.approx(2.5)
    assert spec.spheres[0] == pytest.approx((-0.5, 1.0, 0.0, 3.5))
    assert spec.sphere_children[0] == [1, 2]
    # and the tank's position is still the vehicle-frame origin
    from tanktool.sim.body import Tank

    t = Tank(0, spec, 0.0, 0.0, 0.0)
    t.place(10.0, 20.0, math.pi / 2)
    assert t.position == pytest.approx((10.0, 20.0))
    assert (t.x, t.z) == pytest.approx((10.0, 20.5))
    vb.top_speed = 0.0
    with pytest.raises(VehicleError, match="top_speed"):
        TankSpec.from_vehicle(vb)


def test_sim_never_imports_pygame_or_matplotlib():
    import subprocess
    import sys

    code = ("import sys, tanktool.sim, tanktool.sim.match, tanktool.sim.driver; "
            "print('pygame' in sys.modules, 'matplotlib' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]


def test_bounds_become_walls_when_the_list_has_no_auxiliary_rectangle():
    from tanktool.formats.walls_txt import WallList

    walls = WallList(np.array([[[20.0, 0.0], [20.0, 10.0]]]), np.ones(1, np.int8), None)
    spec = TankSpec.box("t")
    w = World(walls, [spec], [(10.0, 20.0, math.pi / 2)], bounds=[[0.0, 0.0], [40.0, 30.0]])
    t = w.tanks[0]
    t.place(10.0, 20.0, math.pi / 2)
    for _ in range(1200):
        w.step(None, [Command(advance=1.0)])
    assert len(w.walls) == 5
    assert max(z for _, z in t.hull_world()) <= 30.0 + 1e-3 and t.wall_bumps >= 1


def test_snapshot_and_restore_continue_identically():
    walls, spawns = box_arena()
    w = World(walls, [TankSpec.box("t")] * 6, spawns, seed=8, respawn_delay=1.0)
    w.tanks[0].place(30.0, 30.0, 0.0)
    w.tanks[1].place(55.0, 30.0, math.pi)
    cmds = [Command(fire=True), Command(fire=True)] + [Command(advance=1.0, rotate=0.3 * i) for i in range(4)]
    for _ in range(200):
        w.step(None, cmds)
    snap = w.snapshot()
    later = []
    for _ in range(700):
        later += [e.to_dict() for e in w.step(None, cmds)]
    end = w.state()
    w.restore(snap)
    again = []
    for _ in range(700):
        again += [e.to_dict() for e in w.step(None, cmds)]
    assert w.state() == end and again == later
    assert {"hit", "kill", "respawn"} <= {e["kind"] for e in later}
