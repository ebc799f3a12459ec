from pathlib import Path

import numpy as np
import pytest

from tanktool.errors import FormatError
from tanktool.formats.walls_txt import read_walls
from tanktool.geometry.segments import (
    clip_segment_box,
    point_segment_dist2,
    segment_hits_box,
    segment_segment_dist2,
    segments_intersect,
)
from tanktool.nav.quadtree import WallQuadtree
from tanktool.nav.synthetic import block_maze, box_arena, random_arena

ROOT = Path(__file__).resolve().parent.parent
BUNDLED = sorted(ROOT.glob("arenas/*/walls.txt"))


def _arenas():
    out = [("box", box_arena()), ("maze", block_maze(3)), ("random", random_arena(5))]
    out += [(p.parent.name, read_walls(p)) for p in BUNDLED]
    return out


ARENAS = _arenas()


# ------------------------------------------------------------------ kernels
def test_point_segment_distance_cases():
    a, b = np.array([0.0, 0.0]), np.array([4.0, 0.0])
    p = np.array([[2, 3], [-3, 4], [7, 4], [2, 0]], dtype=float)
    assert np.allclose(point_segment_dist2(p, a, b), [9, 25, 25, 0])
    # zero-length segment is a point
    assert point_segment_dist2(np.array([3.0, 4.0]), a, a) == 25


def test_segments_intersect_cases():
    s = lambda *v: np.array(v, dtype=float)  # noqa: E731
    assert segments_intersect(s(0, 0), s(2, 2), s(0, 2), s(2, 0))  # proper crossing
    assert segments_intersect(s(0, 0), s(2, 0), s(2, 0), s(3, 5))  # shared end point
    assert segments_intersect(s(0, 0), s(2, 0), s(1, 0), s(1, 3))  # T touch
    assert segments_intersect(s(0, 0), s(2, 0), s(1, 0), s(3, 0))  # collinear overlap
    assert not segments_intersect(s(0, 0), s(1, 0), s(2, 0), s(3, 0))  # collinear apart
    assert not segments_intersect(s(0, 0), s(2, 2), s(3, 0), s(5, -2))
    assert segment_segment_dist2(s(0, 0), s(1, 0), s(2, 0), s(3, 0)) == 1
    assert segment_segment_dist2(s(0, 0), s(2, 2), s(0, 2), s(2, 0)) == 0


def test_clip_segment_box():
    hit, t0, t1 = clip_segment_box(np.array([-1.0, 0.5]), np.array([3.0, 0.5]), np.array([0.0, 0.0]), np.array([1.0, 1.0]))
    assert hit and t0 == pytest.approx(0.25) and t1 == pytest.approx(0.5)
    # a long diagonal passing through a box with no end point in it
    assert segment_hits_box(np.array([-5.0, -4.0]), np.array([5.0, 6.0]), np.array([0.0, 0.0]), np.array([2.0, 2.0]))
    # missing the corner
    assert not segment_hits_box(np.array([-1.0, 3.5]), np.array([3.5, -1.0]), np.array([0.0, 0.0]), np.array([1.0, 1.0]))
    # touching a side counts; a degenerate segment inside counts
    assert segment_hits_box(np.array([1.0, -1.0]), np.array([1.0, 3.0]), np.array([0.0, 0.0]), np.array([1.0, 1.0]))
    assert segment_hits_box(np.array([0.5, 0.5]), np.array([0.5, 0.5]), np.array([0.0, 0.0]), np.array([1.0, 1.0]))


# ---------------------------------------------------------------- structure
def test_default_tree_is_the_2002_one():
    w = box_arena()
    t = WallQuadtree.build(w.segments, w.bounds)
    assert len(t.leaves) == 64 and len(t) == 1 + 4 + 16 + 64
    assert t.max_depth == 3
    # leaves tile the root exactly
    lb = t.box[t.leaves]
    assert np.isclose(np.prod(lb[:, 1] - lb[:, 0], axis=1).sum(), np.prod(t.box[0, 1] - t.box[0, 0]))


@pytest.mark.parametrize("name,walls", ARENAS, ids=[a[0] for a in ARENAS])
def test_walls_are_in_every_leaf_they_cross(name, walls):
    seg = walls.segments
    t = WallQuadtree.build(seg, walls.bounds, depth=3)
    for leaf in t.leaves:
        stored = set(t.walls[t.offsets[leaf]:t.offsets[leaf + 1]].tolist())
        lo, hi = t.box[leaf]
        exact = set(np.flatnonzero(segment_hits_box(seg[:, 0], seg[:, 1], lo, hi)).tolist())
        grown = set(np.flatnonzero(segment_hits_box(seg[:, 0], seg[:, 1], lo - 2 * t.eps, hi + 2 * t.eps)).tolist())
        assert exact <= stored <= grown


def test_long_wall_is_stored_in_leaves_between_its_end_points():
    seg = np.array([[[0.5, 0.5], [7.5, 7.4]]])
    t = WallQuadtree.build(seg, np.array([[0, 0], [8, 8.0]]), depth=3)
    holding = [leaf for leaf in t.leaves if t.offsets[leaf + 1] > t.offsets[leaf]]
    # the diagonal passes 8 leaves on the diagonal and grazes some neighbours
    assert len(holding) >= 8
    centres = t.box[holding].mean(axis=1)
    assert any(np.all(np.abs(c - [3.5, 3.5]) < 0.6) for c in centres)


def test_adaptive_splits_only_crowded_nodes():
    w = block_maze(2, n=6)
    t = WallQuadtree.adaptive(w.segments, w.bounds, max_walls=6, max_depth=7)
    counts = t.leaf_counts()
    deep = t.depth[t.leaves] == 7
    assert (counts[~deep] <= 6).all()
    assert len(t.leaves) < 4 ** 7 / 8  # far from a full tree
    # every split node held more than 6 walls
    inner = np.flatnonzero(t.child >= 0)
    for k in inner:
        lo, hi = t.box[k]
        assert segment_hits_box(w.segments[:, 0], w.segments[:, 1], lo - t.eps, hi + t.eps).sum() > 6
    assert t.max_depth > 3


# ------------------------------------------------------------------ queries
def _random_probes(walls, rng, m):
    lo, hi = walls.bounds
    pad = 0.1 * (hi - lo)
    return rng.uniform(lo - pad, hi + pad, size=(m, 2))


@pytest.mark.parametrize("mode", ["build", "adaptive"])
@pytest.mark.parametrize("name,walls", ARENAS, ids=[a[0] for a in ARENAS])
def test_queries_equal_brute_force(name, walls, mode):
    rng = np.random.default_rng(17)
    seg = walls.segments
    if mode == "build":
        t = WallQuadtree.build(seg, walls.bounds)
    else:
        t = WallQuadtree.adaptive(seg, walls.bounds, max_walls=4, max_depth=6)
    span = float(np.max(walls.bounds[1] - walls.bounds[0]))
    P = _random_probes(walls, rng, 400)
    # include wall end points and mid points: the touching cases
    P = np.concatenate([P, seg[:50, 0], seg[:50].mean(axis=1)])
    for radius in (0.0, 0.02 * span, 0.15 * span):
        off, idx = t.query_points(P, radius)
        brute = point_segment_dist2(P[:, None], seg[None, :, 0], seg[None, :, 1]) <= radius * radius
        for k in range(len(P)):
            assert np.array_equal(idx[off[k]:off[k + 1]], np.flatnonzero(brute[k]))
        assert np.array_equal(t.query_point(P[3], radius), np.flatnonzero(brute[3]))

    A = _random_probes(walls, rng, 300)
    B = A + rng.normal(0, 0.2 * span, size=A.shape)
    k0 = min(20, len(seg))
    A[:k0], B[:k0] = seg[:k0, 0], seg[:k0, 1] + 1.0  # starting on a wall's end
    off, idx = t.query_segments(A, B)
    hit = segments_intersect(A[:, None], B[:, None], seg[None, :, 0], seg[None, :, 1])
    coff, cidx = t.candidates_segments(A, B)
    for k in range(len(A)):
        exact = np.flatnonzero(hit[k])
        assert np.array_equal(idx[off[k]:off[k + 1]], exact)
        assert set(exact) <= set(cidx[coff[k]:coff[k + 1]].tolist())
    assert np.array_equal(t.query_segment(A[7], B[7]), np.flatnonzero(hit[7]))
    assert set(np.flatnonzero(hit[7])) <= set(t.candidates_segment(A[7], B[7]).tolist())

    r = 0.03 * span
    off, idx = t.query_capsules(A, B, r)
    near = segment_segment_dist2(A[:, None], B[:, None], seg[None, :, 0], seg[None, :, 1]) <= r * r
    for k in range(len(A)):
        assert np.array_equal(idx[off[k]:off[k + 1]], np.flatnonzero(near[k]))


def test_broad_phase_is_narrower_than_all_walls():
    w = block_maze(1, n=8)
    t = WallQuadtree.build(w.segments, w.bounds, depth=3)
    c = t.candidates_segment(np.array([1.0, 1.0]), np.array([5.0, 2.0]))
    assert 0 < len(c) < len(w.segments) / 4


def test_empty_and_degenerate_inputs():
    t = WallQuadtree.build(np.zeros((0, 2, 2)), np.array([[0, 0], [10, 10.0]]))
    assert len(t.query_point(np.array([5.0, 5.0]), 100.0)) == 0
    off, idx = t.query_points(np.zeros((3, 2)), 1.0)
    assert off.tolist() == [0, 0, 0, 0] and len(idx) == 0
    with pytest.raises(ValueError):
        WallQuadtree.build(np.zeros((0, 2, 2)), np.array([[0, 0], [1, 1.0]]), depth=-1)
    with pytest.raises(ValueError):
        t.query_point(np.zeros(2), -1.0)


def test_save_load_round_trip(tmp_path):
    w = random_arena(9)
    t = WallQuadtree.adaptive(w.segments, w.bounds, max_walls=5, max_depth=6)
    t.save(tmp_path / "quadtree.npz")
    u = WallQuadtree.load(tmp_path / "quadtree.npz")
    for f in ("segments", "box", "child", "depth", "offsets", "walls"):
        assert np.array_equal(getattr(t, f), getattr(u, f))
    p = np.array([30.0, 30.0])
    assert np.array_equal(t.query_point(p, 10.0), u.query_point(p, 10.0))


def test_load_rejects_other_files(tmp_path):
    bad = tmp_path / "bad.npz"
    np.savez(bad, x=np.zeros(3))
    with pytest.raises(FormatError, match="bad.npz: not a tanktool quadtree"):
        WallQuadtree.load(bad)
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"not a zip")
    with pytest.raises(FormatError, match="junk.npz"):
        WallQuadtree.load(junk)
    with pytest.raises(FormatError, match="no such file"):
        WallQuadtree.load(tmp_path / "missing.npz")
