"""The importer's wall repairs (geometry/wall_pairs.py): repeated and overlapping walls
joined, walls turned to face their free space, what is left reported -- and check's
pair rules, which share the same test."""

from __future__ import annotations

import numpy as np
import shapely
from click.testing import CliRunner

from tanktool.check.walls_rules import pair_rules
from tanktool.cli.main import cli
from tanktool.formats.walls_txt import WallList
from tanktool.geometry.wall_pairs import (Repairs, classify_pairs, merge_overlaps, orient_to_free, pair_tolerance,
                                          repair_walls)

TOL = 1e-4


def _w(*rows) -> np.ndarray:
    return np.array(rows, dtype=np.float64).reshape(-1, 2, 2)


def _key(seg: np.ndarray) -> list:
    return sorted(tuple(np.round(s, 6).ravel()) for s in seg)


def test_classify_pairs_finds_repeats_overlaps_and_crossings():
    seg = _w([0, 0, 10, 0], [10, 0, 0, 0], [0, 0, 10, 0], [5, 0, 15, 0], [5, -5, 5, 5], [10, 0, 20, 0])
    p = classify_pairs(seg, np.ones(len(seg)), np.arange(len(seg)), TOL)
    assert list(zip(*p.repeat)) == [(0, 2)]                   # 0 and 1: the same place, opposite sides
    assert sorted((int(a), int(b)) for a, b, _ in zip(*p.overlap)) == [(0, 3), (2, 3), (3, 5)]
    # wall 4 crosses 0, 1 and 2; it only meets 3 at 3's end (a T, not an X)
    assert sorted((int(a), int(b)) for a, b, _ in zip(*p.cross)) == [(0, 4), (1, 4), (2, 4)]
    assert np.allclose(p.cross[2], [5, 0])


def test_merge_overlaps_joins_stretches_and_keeps_walls_meeting_end_to_end():
    seg = _w([0, 0, 10, 0], [0, 0, 10, 0], [5, 0, 15, 0], [15, 0, 20, 0], [0, 5, 10, 5], [10, 5, 0, 5])
    out, fewer = merge_overlaps(seg, TOL)
    assert fewer == 2
    assert _key(out) == _key(_w([0, 0, 15, 0], [15, 0, 20, 0], [0, 5, 10, 5], [10, 5, 0, 5]))
    same, none = merge_overlaps(_w([0, 0, 1, 0], [1, 0, 2, 0]), TOL)
    assert none == 0 and _key(same) == _key(_w([0, 0, 1, 0], [1, 0, 2, 0]))


def test_orient_to_free_turns_walls_whose_normal_points_out_of_it():
    free = shapely.box(0, 0, 10, 10)
    ccw = _w([0, 0, 10, 0], [10, 0, 10, 10], [10, 10, 0, 10], [0, 10, 0, 0])   # free space on the left
    same, n = orient_to_free(ccw, free, 0.04)
    assert n == 0 and np.array_equal(same, ccw)
    bad = ccw.copy()
    bad[[1, 3]] = bad[[1, 3]][:, ::-1]
    fixed, n = orient_to_free(bad, free, 0.04)
    assert n == 2 and np.array_equal(fixed, ccw)


def test_repair_walls_reports_what_it_cannot_repair():
    free = shapely.box(0, 0, 10, 10)
    outline = _w([0, 0, 10, 0], [10, 0, 10, 10], [10, 10, 0, 10], [0, 10, 0, 0])
    thin = _w([2, 2, 8, 2], [8, 2, 2, 2], [5, 0.5, 5, 9.5], [5, 4, 5, 6])  # a copy written backwards, an X, an overlap
    r = Repairs()
    segs, n_thin = repair_walls(outline, thin, free, TOL, r)
    assert n_thin == 4 and len(segs) == 8          # the outline, two thin walls both ways
    assert r.merged == 4 and r.overlaps == 0 and len(r.crossings) == 4
    text = " ".join(r.remarks())
    assert "joined" in text and "cross each other" in text and "A204" in text


def test_pair_rules_report_as_before():
    seg = _w([0, 0, 10, 0], [0, 0, 10, 0], [5, 0, 15, 0], [5, -5, 5, 5])
    walls = WallList(seg, np.ones(4, dtype=np.int8), None, np.arange(1, 5), "w.txt")
    codes = sorted((d.code, d.line) for d in pair_rules(walls, pair_tolerance(seg) / 4))
    assert codes == [("A202", 2), ("A203", 3), ("A204", 4)]


def test_import_prints_the_problems_it_leaves(tmp_path, monkeypatch):
    """A wall left crossing another after the repairs is a warning of import-arena itself."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))
    import make_levels

    from tanktool.geometry import wall_pairs

    def leave_a_crossing(outline, thin, free, tol, repairs):
        segs, n = real(outline, thin, free, tol, repairs)
        repairs.crossings.append(np.array([1.5, 2.5]))
        return segs, n

    real = wall_pairs.repair_walls
    monkeypatch.setattr("tanktool.nav.level_walls.repair_walls", leave_a_crossing)
    src = make_levels.write_obj(make_levels.level("corridor"), tmp_path / "c.obj")
    r = CliRunner().invoke(cli, ["-q", "import-arena", str(src), "-o", str(tmp_path / "c")])
    assert r.exit_code == 0
    assert "warning:" in r.output and "cross each other, the first at (1.50, 2.50)" in r.output


def test_a_pocket_closed_by_thin_walls_alone_is_sealed():
    """Three fences meeting in a small triangle: the copies facing into it go (check
    takes the pocket as solid: its walls' normals cancel), the copies facing out stay."""
    free = shapely.box(0, 0, 20, 20)
    outline = _w([0, 0, 20, 0], [20, 0, 20, 20], [20, 20, 0, 20], [0, 20, 0, 0])
    thin = _w([4, 5, 10, 5], [10, 5, 7, 9], [7, 9, 4, 5], [12, 12, 16, 12])
    r = Repairs()
    segs, n_thin = repair_walls(outline, thin, free, TOL, r)
    assert r.sealed == 3 and n_thin == 5 and len(segs) == 9
    tri = shapely.Polygon([(4, 5), (10, 5), (7, 9)])
    d = segs[4:, 1] - segs[4:, 0]
    front = segs[4:].mean(axis=1) + 0.01 * np.stack([-d[:, 1], d[:, 0]], axis=1) / np.hypot(*d.T)[:, None]
    assert not shapely.contains_xy(tri, *front.T).any()
    assert any("pockets" in line for line in r.remarks())
