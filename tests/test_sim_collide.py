"""Collision detection and impulses: conservation laws and the restitution law."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest
from sim_fixtures import box_arena, free_spec

from tanktool.nav.quadtree import WallQuadtree
from tanktool.sim.body import Tank, TankSpec
from tanktool.sim.collide import BruteWallIndex, QuadtreeIndex, WallSet, tank_contact, wall_contacts
from tanktool.sim.commands import Command
from tanktool.sim.resolve import pair_impulse, wall_impulse
from tanktool.sim.world import World


def _random_tank(rng: random.Random, i: int) -> Tank:
    spec = TankSpec.box(f"t{i}", length=rng.uniform(3, 8), width=rng.uniform(2, 4),
                        mass=rng.uniform(5e3, 6e4), restitution=rng.uniform(0, 1))
    t = Tank(i, spec, rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-math.pi, math.pi))
    t.vx, t.vz, t.omega = rng.uniform(-20, 20), rng.uniform(-20, 20), rng.uniform(-3, 3)
    return t


def _rel_normal_velocity(a: Tank, b: Tank | None, px: float, pz: float, nx: float, nz: float) -> float:
    vx, vz = a.point_velocity(px, pz)
    if b is not None:
        ox, oz = b.point_velocity(px, pz)
        vx, vz = vx - ox, vz - oz
    return vx * nx + vz * nz


def test_pair_impulse_conserves_momentum_and_obeys_restitution():
    rng = random.Random(1)
    applied = 0
    for k in range(2000):
        a, b = _random_tank(rng, 0), _random_tank(rng, 1)
        px, pz = rng.uniform(-6, 6), rng.uniform(-6, 6)
        ang = rng.uniform(-math.pi, math.pi)
        nx, nz = math.cos(ang), math.sin(ang)
        e = rng.uniform(0, 1)
        p0 = (a.spec.mass * a.vx + b.spec.mass * b.vx, a.spec.mass * a.vz + b.spec.mass * b.vz)
        # angular momentum about the origin: I ω + m (r × v)
        def L(t):
            return t.spec.inertia * t.omega + t.spec.mass * (t.x * t.vz - t.z * t.vx)
        l0 = L(a) + L(b)
        ke0 = a.kinetic_energy() + b.kinetic_energy()
        v1 = _rel_normal_velocity(a, b, px, pz, nx, nz)
        j = pair_impulse(a, b, px, pz, nx, nz, e)
        v2 = _rel_normal_velocity(a, b, px, pz, nx, nz)
        p1 = (a.spec.mass * a.vx + b.spec.mass * b.vx, a.spec.mass * a.vz + b.spec.mass * b.vz)
        scale = math.hypot(*p0) + 1e-300
        assert math.hypot(p1[0] - p0[0], p1[1] - p0[1]) / scale < 1e-9
        assert abs(L(a) + L(b) - l0) <= 1e-9 * (abs(l0) + a.spec.mass * 100 + b.spec.mass * 100)
        ke1 = a.kinetic_energy() + b.kinetic_energy()
        assert ke1 <= ke0 * (1 + 1e-12)
        if v1 < 0:
            applied += 1
            assert j > 0
            assert abs(v2 - (-e * v1)) <= 1e-6 * max(1.0, abs(v1))
        else:
            assert j == 0.0 and v2 == v1
    assert applied > 500


def test_wall_impulse_restitution_and_energy():
    rng = random.Random(2)
    applied = 0
    for k in range(2000):
        t = _random_tank(rng, 0)
        px, pz = t.x + rng.uniform(-4, 4), t.z + rng.uniform(-4, 4)
        ang = rng.uniform(-math.pi, math.pi)
        nx, nz = math.cos(ang), math.sin(ang)
        e = rng.uniform(0, 1)
        ke0 = t.kinetic_energy()
        v1 = _rel_normal_velocity(t, None, px, pz, nx, nz)
        j = wall_impulse(t, px, pz, nx, nz, e)
        v2 = _rel_normal_velocity(t, None, px, pz, nx, nz)
        assert t.kinetic_energy() <= ke0 * (1 + 1e-12)
        if v1 < 0:
            applied += 1
            # the paper's formula with the angular term: j = -(1+e) v·n / (1/m + (r×n)²/I)
            rn = (px - t.x) * nz - (pz - t.z) * nx
            expect = -(1 + e) * v1 / (1 / t.spec.mass + rn * rn / t.spec.inertia)
            assert j == pytest.approx(expect, rel=1e-12)
            assert abs(v2 + e * v1) <= 1e-6 * max(1.0, abs(v1))
        else:
            assert j == 0.0
    assert applied > 500


def _two_tank_world(e: float, offset: float, angle: float = 0.0) -> World:
    walls, _ = box_arena()
    spec = free_spec(restitution=e)
    spawns = [(20.0, 30.0 + offset, angle), (40.0, 30.0, math.pi)]
    w = World(walls, [spec, spec], spawns, seed=0)
    # put them exactly where asked (the world shuffles its spawn points)
    w.tanks[0].place(20.0, 30.0 + offset, angle)
    w.tanks[1].place(40.0, 30.0, math.pi)
    w.tanks[0].vx, w.tanks[1].vx = 9.0, -6.0
    w.tanks[1].vz = 0.7
    return w


@pytest.mark.parametrize("e,offset,angle", [(0.3, 0.0, 0.0), (0.8, 1.3, 0.4), (0.0, -2.0, -0.7), (1.0, 0.5, 1.2)])
def test_tank_tank_impact_in_world(e, offset, angle):
    w = _two_tank_world(e, offset, angle)
    a, b = w.tanks
    p0 = w.momentum()
    collided = False
    for k in range(240):
        ke_before = w.kinetic_energy()
        w.step()
        p = w.momentum()
        assert math.hypot(p[0] - p0[0], p[1] - p0[1]) / math.hypot(*p0) < 1e-9
        assert w.kinetic_energy() <= ke_before * (1 + 1e-12)
        if w.iterations_used:
            collided = True
    assert collided
    # after the impact they separate (or, for e = 0, stop approaching)
    c = tank_contact(a, b)
    if c is not None:
        assert _rel_normal_velocity(a, b, c[0], c[1], c[2], c[3]) >= -1e-9


def test_sphere_tree_level_by_level():
    spec = TankSpec.box("b", length=6, width=2, height=2)
    a = Tank(0, spec, 0.0, 0.0, 0.0)
    b = Tank(1, spec, 0.0, 0.0, 0.0)
    root = spec.spheres[0][3]
    # roots overlap (side by side, 1.2 * root radius apart) but the slim leaves do not
    b.place(0.0, 1.2 * root, 0.0)
    assert 1.2 * root < 2 * root
    leaf_r = spec.spheres[1][3]
    assert 1.2 * root > 2 * leaf_r
    assert tank_contact(a, b) is None
    # nose to nose along x, overlapping by 0.5 m at the front leaves
    b.place(6.0 - 0.5, 0.0, math.pi)
    # front leaves: centres at x = 2.25 (a) and 5.5 - 2.25 (b), radius leaf_r
    c = tank_contact(b, a)
    assert c is not None
    px, pz, nx, nz, depth = c
    assert nx == pytest.approx(1.0) and nz == pytest.approx(0.0, abs=1e-12)
    gap = (5.5 - 2.25) - 2.25
    assert depth == pytest.approx(2 * leaf_r - gap, rel=1e-9)
    assert px == pytest.approx(2.25 + gap / 2, abs=1e-9)


def test_wall_contacts_hull_points_and_wall_ends():
    spec = TankSpec.box("b", length=6, width=3)
    t = Tank(0, spec, 0.0, 0.0, 0.0)
    # a wall across the tank's nose, 0.2 m behind its front face: the two front corners
    # cross it (top and bottom corners coincide seen from above and count once)
    assert len(spec.hull_local) == 4
    ws = WallSet(np.array([[[2.8, -5.0], [2.8, 5.0]]]))
    found = wall_contacts(t, ws, [0])
    assert len(found) == 2
    for (px, pz, nx, nz, depth), k in found:
        assert (nx, nz) == (-1.0, 0.0) or (nx, nz) == pytest.approx((-1.0, 0.0))
        assert depth == pytest.approx(0.2)
    # a wall whose end pokes 0.4 m into the tank's side, between hull points
    ws = WallSet(np.array([[[0.0, 5.0], [0.0, 1.1]]]))
    found = wall_contacts(t, ws, [0])
    assert len(found) == 1
    (px, pz, nx, nz, depth), _ = found[0]
    assert (px, pz) == (0.0, 1.1)
    assert (nx, nz) == pytest.approx((0.0, -1.0))
    assert depth == pytest.approx(0.4)
    # nothing near: nothing found
    assert wall_contacts(t, WallSet(np.array([[[10.0, -1.0], [10.0, 1.0]]])), [0]) == []


def test_quadtree_index_matches_brute_force():
    rng = np.random.default_rng(5)
    for trial in range(6):
        n = int(rng.integers(5, 200))
        a = rng.uniform(0, 100, (n, 2))
        seg = np.stack([a, a + rng.uniform(-12, 12, (n, 2))], 1)
        seg[: n // 3, 1, 1] = seg[: n // 3, 0, 1]
        bounds = np.array([[-15.0, -15.0], [115.0, 115.0]])
        tree = WallQuadtree.build(seg, bounds, depth=int(rng.integers(1, 5))) if trial % 2 else WallQuadtree.adaptive(seg, bounds)
        q, brute = QuadtreeIndex(tree), BruteWallIndex(seg)
        for k in range(100):
            p = rng.uniform(-20, 120, 2)
            p2 = p + rng.uniform(-4, 4, 2) if k % 3 == 0 else rng.uniform(-20, 120, 2)
            r = float(rng.uniform(0, 15))
            assert q.query_point(p, r) == brute.query_point(p, r).tolist()
            assert q.query_segment(p, p2) == brute.query_segment(p, p2).tolist()
            assert q.query_point(p, r) == tree.query_point(p, r).tolist()


def test_kinetic_energy_never_grows_in_a_melee():
    """Eight frictionless tanks thrown at each other and at walls: no step adds energy."""
    walls, spawns = box_arena()
    rng = random.Random(7)
    specs = [free_spec(restitution=rng.uniform(0, 1), mass=rng.uniform(1e4, 4e4)) for _ in range(8)]
    w = World(walls, specs, spawns, seed=3)
    for t in w.tanks:
        ang = math.atan2(45 - t.z, 60 - t.x) + rng.uniform(-0.3, 0.3)
        t.vx, t.vz, t.omega = 14 * math.cos(ang), 14 * math.sin(ang), rng.uniform(-1, 1)
    collisions = 0
    for k in range(1500):
        ke0 = w.kinetic_energy()
        w.step(None, [Command()] * 8)
        assert w.kinetic_energy() <= ke0 * (1 + 1e-12) + 1e-9
        collisions += w.iterations_used > 0
    assert collisions > 20


@pytest.mark.parametrize("e", [0.0, 0.3, 1.0])
def test_restitution_law_in_a_world_step(e):
    """Head-on along x: after the impact step the closing speed is -e times what it was."""
    w = _two_tank_world(e, 0.0, 0.0)
    a, b = w.tanks
    b.vz = 0.0
    closing = a.vx - b.vx
    for _ in range(240):
        w.step()
        if w.iterations_used:
            break
    else:
        pytest.fail("no impact")
    assert a.vx - b.vx == pytest.approx(-e * closing, abs=1e-6)
    assert abs(a.omega) < 1e-12 and abs(b.omega) < 1e-12
