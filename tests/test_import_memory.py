"""What the import lets go of before its grid stage, and the report's blocked loops
(docs/speed.md, "Memory of large imports"): same results, less held at once."""

from __future__ import annotations

import numpy as np

from tanktool.importer import import_arena
from tanktool.nav import surface_report
from tests.test_import_arena import write_room


def _steep_whole(vertices: np.ndarray, faces: np.ndarray, max_slope: float) -> tuple[np.ndarray, np.ndarray]:
    """steep_faces as it was before the blocks: the whole model at once."""
    tri = vertices[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(n, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        ny = np.where(norm > 0, n[:, 1] / norm, 0.0)
    sel = np.flatnonzero((ny > surface_report.WALL_NY) & (ny <= np.cos(np.radians(max_slope))))
    return sel, 0.5 * n[sel, 1]


def test_steep_faces_in_blocks_are_the_whole_models(monkeypatch):
    import tanktool.geometry.heightfield as heightfield

    rng = np.random.default_rng(7)
    vertices = rng.normal(size=(500, 3))
    faces = rng.integers(0, 500, size=(5000, 3))
    monkeypatch.setattr(heightfield, "FACE_BLOCK", 333)   # blocks that do not divide the faces
    for f in (faces, faces[:0], faces[:7]):
        got, want = surface_report.steep_faces(vertices, f, 35.0), _steep_whole(vertices, f, 35.0)
        assert len(want[0]) or len(f) < 10
        for a, b in zip(got, want):
            assert a.dtype == b.dtype and np.array_equal(a, b)


def test_import_lets_go_of_the_analysis_before_the_grid(tmp_path):
    model = write_room(tmp_path / "room.obj")
    r = import_arena(model, tmp_path / "room")
    assert r.grid is not None and r.grid.grid.valid.any()
    lv = r.levels
    assert lv.surface is None and lv.vertices is None and lv.faces is None and lv.grid is None
    assert r.faces == 12 * 6 and len(lv.levels) == 1
    # without the grid stage the analysis grid is what the import has: kept
    r = import_arena(model, tmp_path / "room2", grid=False)
    assert r.grid is None and r.levels.grid is not None and r.levels.surface is None
