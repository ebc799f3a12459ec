"""The arena preview (plots/arena.py): the levels' picture import-arena writes."""

from __future__ import annotations

import io

import matplotlib
import numpy as np

matplotlib.use("Agg", force=False)


def _png_pixels(png: bytes) -> np.ndarray:
    import matplotlib.image

    return (matplotlib.image.imread(io.BytesIO(png), format="png")[..., :3] * 255).round().astype(int)


def test_the_levels_picture_reuses_the_reports_masks_and_has_no_empty_bands(monkeypatch):
    """The picture paints what the report left out from the same masks (worked out once
    per surface), and its panels fill the figure: a two-level arena's PNG is as tall as
    its two panels side by side need, not the old fixed height with white above and below."""
    import sys
    from pathlib import Path

    import tanktool.nav.surface_report as sr
    from tanktool.fleet import Fleet
    from tanktool.nav.arena_levels import analyse_arena
    from tanktool.nav.walkable import WalkableParams
    from tanktool.plots.arena import _LevelsLayout, render_levels

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))
    import make_levels

    calls = {"unreachable": 0, "low_headroom": 0}
    for name in calls:
        work = getattr(sr, "_" + name)

        def counted(*a, _work=work, _name=name):
            calls[_name] += 1
            return _work(*a)
        monkeypatch.setattr(sr, "_" + name, counted)
    m = make_levels.level("bridge")
    r = analyse_arena(np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64),
                      WalkableParams(cell=0.5, cell_height=0.1, max_slope=35.0, climb=0.9, headroom=2.35),
                      Fleet(radius=3.0, length=6.0, height=2.3))
    assert len(r.levels) == 2
    png = render_levels(r, "bridge", size_px=800)
    assert calls == {"unreachable": 1, "low_headroom": 1}
    h, w = _png_pixels(png).shape[:2]
    (x0, z0), (x1, z1) = r.walls.walls.bounds
    layout = _LevelsLayout.of(2, (z1 - z0) / (x1 - x0), bar=True)
    assert w == 800 and abs(h - 800 * layout.height / layout.width) <= 1
    # the last row of the picture is no more than the legend's band below the panels: not white for a tenth of it
    pixels = _png_pixels(png)
    drawn_rows = np.flatnonzero((pixels < 250).any(axis=(1, 2)))
    assert drawn_rows.max() >= 0.8 * h and drawn_rows.min() <= 0.1 * h
