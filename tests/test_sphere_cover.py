"""sphere_build.cover_surface: a sphere tree refitted to hold the whole surface."""

import numpy as np
import trimesh

from tanktool.geometry.sphere_build import build_sphere_tree, cover_surface, surface_samples


def _outside(tree, p):
    """(n,) how far each point is outside every leaf, and whether its chain holds it."""
    leaves = tree.leaves()
    d = np.sqrt(((p[:, None] - tree.centers[leaves][None]) ** 2).sum(axis=2)) - tree.radii[leaves][None]
    chain_ok = np.zeros(len(p), dtype=bool)
    for leaf in leaves:
        ok = np.ones(len(p), dtype=bool)
        for s in tree.ancestors(int(leaf)):
            ok &= np.linalg.norm(p - tree.centers[s], axis=1) <= tree.radii[s] * (1 + 1e-12) + 1e-12
        chain_ok |= ok
    return d.min(axis=1), chain_ok


def test_a_tree_on_the_corners_misses_the_faces_and_the_refit_holds_them():
    box = trimesh.creation.box(extents=[6.0, 2.0, 3.0])
    v, f = np.asarray(box.vertices), np.asarray(box.faces)
    tree = build_sphere_tree(v, levels=3, branching=4)     # 8 corners: the faces bulge out
    p = surface_samples(v, f, 20000, seed=5)
    before, _ = _outside(tree, p)
    assert (before > 1e-6).mean() > 0.3
    fitted = cover_surface(tree, v, f)
    after, chained = _outside(fitted, p)
    assert after.max() <= 1e-9 and chained.all()
    # the tree keeps its shape; the root is still the minimum sphere of the box
    assert np.array_equal(fitted.parent, tree.parent) and np.array_equal(fitted.level, tree.level)
    assert fitted.radii[0] == np.float64(np.linalg.norm([3.0, 1.0, 1.5]))


def test_slivers_are_halved_not_gridded_and_the_result_is_reproducible():
    # one long thin triangle across many leaves: the pieces follow its length
    v = np.array([[0, 0, 0], [10, 0, 0], [0, 0.01, 0], [5, 1, 1], [10, 1, 1]], dtype=float)
    f = np.array([[0, 1, 2], [1, 4, 3]])
    pts = np.vstack([v, surface_samples(v, f, 500, seed=1)])
    tree = build_sphere_tree(pts, levels=2, branching=6)
    a, b = cover_surface(tree, v, f), cover_surface(tree, v, f)
    assert np.array_equal(a.centers, b.centers) and np.array_equal(a.radii, b.radii)
    out, chained = _outside(a, surface_samples(v, f, 20000, seed=9))
    assert out.max() <= 1e-9 and chained.all()
