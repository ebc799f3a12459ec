"""Sphere trees: exact minimum spheres, conservative trees, queries vs brute force."""

import numpy as np
import pytest
import trimesh

from tanktool.errors import FormatError
from tanktool.geometry.min_sphere import min_enclosing_sphere
from tanktool.geometry.sphere_build import build_points, build_sphere_tree, octree_spheres
from tanktool.geometry.spheres import (
    SphereTree, contains_points, point_query, read_spheres, segment_query, segment_sphere_hits, to_world,
    tree_overlap, write_spheres,
)


def tank_like() -> trimesh.Trimesh:
    body = trimesh.creation.box([4.0, 1.0, 2.4])
    body.apply_translation([0, 0.7, 0])
    turret = trimesh.creation.box([1.6, 0.6, 1.4])
    turret.apply_translation([-0.3, 1.5, 0])
    barrel = trimesh.creation.cylinder(radius=0.08, height=2.0)
    barrel.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 0, 1]))
    barrel.apply_translation([1.5, 1.5, 0])
    return trimesh.util.concatenate([body, turret, barrel])


@pytest.fixture(scope="module")
def tank_tree():
    m = tank_like()
    pts = build_points(m.vertices, m.faces, 2000)
    return pts, build_sphere_tree(pts, levels=3, branching=4)


def test_min_enclosing_sphere_known_cases():
    c, r = min_enclosing_sphere(np.array([[-1.0, 0, 0], [1.0, 0, 0], [0, 0.5, 0]]))
    assert np.allclose(c, 0) and r == pytest.approx(1.0)
    cube = np.array([[x, y, z] for x in (0, 2) for y in (0, 2) for z in (0, 2)], float)
    c, r = min_enclosing_sphere(cube)
    assert np.allclose(c, 1) and r == pytest.approx(np.sqrt(3))
    c, r = min_enclosing_sphere(np.array([[3.0, 4, 5]]))
    assert np.allclose(c, [3, 4, 5]) and r == 0


def test_min_enclosing_sphere_is_minimal_against_random_search():
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(500, 3)) * [3, 1, 0.5]
    c, r = min_enclosing_sphere(pts)
    assert np.max(np.linalg.norm(pts - c, axis=1)) <= r + 1e-12
    # no nearby centre does better: the optimum of a convex function
    for _ in range(200):
        c2 = c + rng.normal(scale=0.05, size=3)
        assert np.max(np.linalg.norm(pts - c2, axis=1)) >= r - 1e-9


def test_tree_structure_and_conservative(tank_tree):
    pts, tree = tank_tree
    assert tree.levels == 3 and tree.parent[0] == -1 and tree.level[0] == 1
    assert len(tree.children(0)) == 4
    assert len(tree.leaves()) == 16
    for i in range(1, len(tree)):
        assert tree.level[i] == tree.level[tree.parent[i]] + 1
    assert contains_points(tree, pts).all()


def test_tree_levels_and_branching_options():
    m = tank_like()
    pts = build_points(m.vertices, m.faces, 500)
    t1 = build_sphere_tree(pts, levels=1, branching=4)
    assert len(t1) == 1 and list(t1.leaves()) == [0]
    t = build_sphere_tree(pts, levels=2, branching=6)
    assert len(t.leaves()) == 6 and contains_points(t, pts).all()


def test_leaves_are_tighter_than_octree(tank_tree):
    pts, tree = tank_tree
    oc, orad = octree_spheres(pts, len(tree.leaves()))
    assert len(orad) >= len(tree.leaves())
    # every point inside some octree sphere as well: the baseline is conservative too
    d = np.linalg.norm(pts[:, None] - oc[None], axis=2) <= orad[None] + 1e-9
    assert d.any(axis=1).all()
    assert np.sum(tree.radii[tree.leaves()] ** 3) < np.sum(orad**3)


def test_to_world_heading_convention():
    tree = SphereTree([[0, 0, 0], [1, 0, 0], [0, 0, 1]], [2, 1, 1], [-1, 0, 0], [1, 2, 2])
    w = to_world(tree, [10, 0, 5], np.pi / 2)
    # vehicle +x -> world (cos, 0, sin) = +z; vehicle +z (right) -> (-sin, 0, cos) = -x
    assert np.allclose(w[1], [10, 0, 6]) and np.allclose(w[2], [9, 0, 5])


def _chain_ok(tree, leaf, ok):
    return all(ok[i] for i in tree.ancestors(leaf))


def brute_overlap(tA, pA, tB, pB):
    ca, cb = to_world(tA, *pA), to_world(tB, *pB)
    out = []
    for a in tA.leaves():
        for b in tB.leaves():
            chA, chB = tA.ancestors(a)[::-1], tB.ancestors(b)[::-1]
            n = max(len(chA), len(chB))
            ok = True
            for d in range(n):
                i, j = chA[min(d, len(chA) - 1)], chB[min(d, len(chB) - 1)]
                if np.linalg.norm(ca[i] - cb[j]) > tA.radii[i] + tB.radii[j]:
                    ok = False
                    break
            if ok:
                out.append((int(a), int(b)))
    return sorted(out)


def test_queries_match_brute_force_on_random_poses(tank_tree):
    pts, tree = tank_tree
    m = trimesh.creation.icosphere(2, radius=1.2)
    other = build_sphere_tree(build_points(m.vertices, m.faces, 300), levels=2, branching=3)
    rng = np.random.default_rng(7)
    hits = 0
    for _ in range(150):
        pA = (np.array([*rng.uniform(-3, 3, 1), 0.0, *rng.uniform(-3, 3, 1)]), rng.uniform(-np.pi, np.pi))
        pB = (np.array([*rng.uniform(-3, 3, 1), rng.uniform(0, 1), *rng.uniform(-3, 3, 1)]), rng.uniform(-np.pi, np.pi))
        got = tree_overlap(tree, pA, other, pB)
        assert got == brute_overlap(tree, pA, other, pB)
        assert sorted((b, a) for a, b in got) == tree_overlap(other, pB, tree, pA)
        hits += bool(got)
        c = to_world(tree, *pA)
        p = rng.uniform(-4, 4, 3)
        inside = np.linalg.norm(c - p, axis=1) <= tree.radii
        assert point_query(tree, pA, p) == sorted(int(l) for l in tree.leaves() if _chain_ok(tree, l, inside))
        a, b = rng.uniform(-5, 5, 3), rng.uniform(-5, 5, 3)
        touched = segment_sphere_hits(a, b, c, tree.radii)
        assert segment_query(tree, pA, a, b) == sorted(int(l) for l in tree.leaves() if _chain_ok(tree, l, touched))
    assert 10 < hits < 150  # the poses exercised both outcomes


def test_segment_sphere_hits_by_sampling():
    rng = np.random.default_rng(1)
    centers = rng.uniform(-2, 2, (50, 3))
    radii = rng.uniform(0.1, 1.0, 50)
    a, b = np.array([-3.0, 0, 0]), np.array([3.0, 0.5, -0.2])
    t = np.linspace(0, 1, 20001)[:, None]
    samples = a + t * (b - a)
    sampled = (np.linalg.norm(samples[:, None] - centers[None], axis=2) <= radii[None]).any(axis=0)
    assert np.array_equal(segment_sphere_hits(a, b, centers, radii), sampled)


def test_spheres_txt_round_trip_stays_conservative(tmp_path, tank_tree):
    pts, tree = tank_tree
    f = tmp_path / "spheres.txt"
    write_spheres(f, tree, header="test tree")
    back = read_spheres(f)
    assert np.array_equal(back.parent, tree.parent) and np.array_equal(back.level, tree.level)
    assert np.allclose(back.centers, tree.centers, atol=1e-4)
    assert contains_points(back, pts, tol=0).all()


@pytest.mark.parametrize("text, message", [
    ("", "no spheres"),
    ("0 -1 1 0 0 0\n", "expected 7 fields"),
    ("0 0 1 0 0 0 1\n", "must be the root"),
    ("0 -1 1 0 0 0 1\n1 0 3 0 0 0 1\n", "level 3 must be one more"),
    ("0 -1 1 0 0 0 1\n2 0 2 0 0 0 1\n", "expected sphere id 1"),
    ("0 -1 1 0 0 0 1\n1 5 2 0 0 0 1\n", "parent 5 must be an earlier"),
    ("0 -1 1 0 0 nan 1\n", "finite"),
    ("0 -1 1 0 0 0 -1\n", "negative"),
    ("0 -1 1 a 0 0 1\n", "expected integers"),
])
def test_read_spheres_errors_name_file_and_line(tmp_path, text, message):
    f = tmp_path / "spheres.txt"
    f.write_text("# header\n" + text)
    with pytest.raises(FormatError) as e:
        read_spheres(f)
    assert message in str(e.value) and str(f) in str(e.value)


def _room(L=20.0, W=10.0, H=20.0, t=0.3) -> trimesh.Trimesh:
    """Six thin wall plates around empty space (like test1.3ds)."""
    walls = []
    for size, pos in [([L, t, W], [0, 0, 0]), ([L, t, W], [0, H, 0]), ([t, H, W], [-L / 2, H / 2, 0]),
                      ([t, H, W], [L / 2, H / 2, 0]), ([L, H, t], [0, H / 2, -W / 2]), ([L, H, t], [0, H / 2, W / 2])]:
        b = trimesh.creation.box(size)
        b.apply_translation(pos)
        walls.append(b)
    return trimesh.util.concatenate(walls)


def test_thin_plate_leaves_tile_it_along_length_and_width():
    plate = trimesh.creation.box([8.0, 0.05, 4.0])
    pts = build_points(plate.vertices, plate.faces, 3000)
    tree = build_sphere_tree(pts, levels=3, branching=4)
    leaves = tree.leaves()
    assert len(leaves) == 16 and contains_points(tree, pts).all()
    # 16 tiles of 2 x 1 m need radius sqrt(1 + 0.25) = 1.118 each; the root needs 4.47
    assert tree.radii[leaves].max() <= 1.2
    span = np.ptp(tree.centers[leaves], axis=0)
    assert span[0] > 0.75 * 8.0 and span[2] > 0.6 * 4.0 and span[1] < 0.05 + 1e-9


def test_hollow_room_leaves_claim_much_less_than_plain_kmeans():
    from tanktool.geometry.sphere_build import _exact_tree, _kmeans_parts, _union_count

    room = _room()
    pts = build_points(room.vertices, room.faces, 3000)
    tree = build_sphere_tree(pts, levels=3, branching=4)
    assert len(tree.leaves()) == 16 and contains_points(tree, pts).all()
    for i in range(1, len(tree)):  # every point of a leaf lies in all its ancestors too
        assert tree.level[i] == tree.level[tree.parent[i]] + 1
    plain = _exact_tree(pts, _kmeans_parts(pts, 3, 4, 0), 0)
    # the union of the leaf spheres (the space the tree claims): columns spanning two
    # facing walls instead of spheres centred on the plates
    assert _union_count(tree) < 0.85 * _union_count(plain)


def test_tree_is_never_worse_than_plain_kmeans(tank_tree):
    from tanktool.geometry.sphere_build import _exact_tree, _kmeans_parts, _union_count

    pts, tree = tank_tree
    plain = _exact_tree(pts, _kmeans_parts(pts, 3, 4, 0), 0)
    assert _union_count(tree) <= _union_count(plain) + 1e-9
