"""Untextured arena models get a look by face kind (game/looks.py): a 3D screenshot of
an imported blockout shows floor, ramp and wall in different colours."""

from __future__ import annotations

import numpy as np
import trimesh
from click.testing import CliRunner
from level_helpers import make_levels

from tanktool.cli.main import cli
from tanktool.game.looks import KINDS, face_kinds, untextured


def test_face_kinds_by_normal():
    ramp = make_levels.ramp(0, 0, 16, 8, 0.0, 4.0, "+x")       # 14 degrees up
    kinds = face_kinds(ramp.vertices, ramp.faces)
    tri = ramp.vertices[ramp.faces]
    ny = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    ny = ny[:, 1] / np.linalg.norm(ny, axis=1)
    assert set(kinds[(ny > 0.9) & (ny < 0.99)]) == {1}          # the slope is a ramp
    assert set(kinds[np.abs(ny) < 0.1]) == {2}                  # its sides are walls
    assert set(kinds[ny < -0.9]) == {3}                         # its underside a ceiling
    assert untextured(trimesh.Trimesh(ramp.vertices, ramp.faces, process=False))


def test_an_untextured_blockout_reads_in_3d(tmp_path):
    from tanktool.game.render3d import Renderer3D
    from tanktool.game.session import GameSession

    m = make_levels.level("ramps_and_decks")
    trimesh.Trimesh(m.vertices, m.faces, process=False).export(tmp_path / "yard.obj")   # no material at all
    r = CliRunner().invoke(cli, ["-q", "import-arena", str(tmp_path / "yard.obj"), "-o", str(tmp_path / "yard")])
    assert r.exit_code == 0, r.output
    s = GameSession(str(tmp_path / "yard"), bots=1, seed=0, player=False)
    for t in s.world.tanks:
        t.place(8.0, 8.0 + 6 * t.index, 0.0)                    # out of the way of what is measured
    view = Renderer3D(s, (640, 360))
    try:
        view.camera = "overview"
        img = view.render(1.0, hud=False)
        colours = {}
        # a floor point in the yard, the middle of the ramp from the yard up to the deck
        # (x 24..40, z 17..24), the deck block's side facing the camera (z = 35)
        for kind, p in (("floor", (12.0, 0.0, 40.0)), ("ramp", (32.0, 2.0, 20.5)), ("wall", (52.0, 2.0, 35.0))):
            x, y, depth = view.project(p)
            assert -1 < depth < 1 and 4 <= x < 636 and 4 <= y < 356, (kind, x, y)
            colours[kind] = img[int(y) - 3:int(y) + 4, int(x) - 3:int(x) + 4].reshape(-1, 3).mean(axis=0)
    finally:
        view.release()
    names = list(colours)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            assert np.abs(colours[a] - colours[b]).max() > 20, (a, b, colours)
    assert len(KINDS) == 4
