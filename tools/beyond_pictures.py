"""Make the pictures of docs/beyond.md from the test files (BZFlag world, DXF plan, replay).

    .venv/bin/python tools/beyond_pictures.py [OUT_DIR]      (default: docs/)

Each import picture shows the model import-arena built (a 3D view, the world frame's
x and z on the ground, y up) beside the walls it extracted (the bundle's preview).
The replay pictures are the final state of a match recorded on the imported BZFlag
arena and played back from the file (the playback must match bit for bit), and its
frame at 30 s in the game's 3D view.
"""

from __future__ import annotations

import io
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def model_and_walls(bundle: Path, out: Path, title: str) -> None:
    """A 3D view of ``bundle``'s model.glb beside its preview.png, as one PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt
    import numpy as np
    import trimesh
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from tanktool.formats.bundle import atomic_write_bytes

    scene = trimesh.load(str(bundle / "model.glb"), force="scene")
    fig = plt.figure(figsize=(14, 6.4))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    tris, cols = [], []
    for mesh in scene.dump():
        v = mesh.vertices[:, [0, 2, 1]]                 # plot (x, z) on the ground, y up
        tris.append(v[mesh.faces])
        colours = np.asarray(mesh.visual.face_colors, dtype=float)[:, :3] / 255.0
        # light from above-front: the top faces brightest, sides by their facing
        n = mesh.face_normals[:, [0, 2, 1]]
        shade = 0.55 + 0.45 * np.clip(n @ np.array([0.3, -0.4, 0.87]), 0, 1)
        cols.append(colours * shade[:, None])
    tri, col = np.concatenate(tris), np.concatenate(cols)
    lo, hi = tri.reshape(-1, 3).min(axis=0), tri.reshape(-1, 3).max(axis=0)
    # mplot3d sorts polygons by their centres, so the big ground triangles would hide
    # what stands on them: draw the ground first, then everything else depth-sorted
    ground = (tri[:, :, 2] < lo[2] + 0.05).all(axis=1)
    ax.computed_zorder = False
    ax.add_collection3d(Poly3DCollection(tri[ground], facecolors=col[ground], edgecolors="none", zorder=0))
    ax.add_collection3d(Poly3DCollection(tri[~ground], facecolors=col[~ground], edgecolors="none", zorder=1))
    span = float((hi - lo)[:2].max())
    mid = (hi + lo) / 2
    ax.set_xlim(mid[0] - span / 2, mid[0] + span / 2)
    ax.set_ylim(mid[1] - span / 2, mid[1] + span / 2)
    ax.set_zlim(0, span / 3)
    ax.set_box_aspect((1, 1, 1 / 3))
    ax.view_init(elev=38, azim=-60)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_zlabel("y (m)")
    ax.set_title(f"{title}: the model built (model.glb)")
    right = fig.add_subplot(1, 2, 2)
    right.imshow(mpimg.imread(bundle / "preview.png"))
    right.axis("off")
    right.set_title("walls at the 1 m cut (preview.png)")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    atomic_write_bytes(out, buf.getvalue())


def main(argv: list[str]) -> int:
    from tanktool.importer import import_arena
    from tanktool.plots.match import save_match_picture
    from tanktool.sim.match import load_match_arena, load_tank_spec
    from tanktool.sim.replay import play_replay, read_replay, record_match, write_replay

    out = Path(argv[0]) if argv else ROOT / "docs"
    out.mkdir(parents=True, exist_ok=True)
    data = ROOT / "tests" / "data"
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        court = import_arena(data / "bzw" / "courtyard.bzw", tmp / "courtyard")
        model_and_walls(court.path, out / "beyond-bzw.png", "courtyard.bzw")
        room = import_arena(data / "plans" / "room.dxf", tmp / "room", wall_height=3.0, wall_thickness=0.5)
        model_and_walls(room.path, out / "beyond-plan.png", "room.dxf")
        arena, spec = load_match_arena(court.path), load_tank_spec("light")
        _, replay = record_match(arena, spec, bots=6, seconds=60.0, seed=3, arena_ref=str(court.path),
                                 vehicle_ref="light")
        write_replay(tmp / "court.ttr", replay)
        playback = play_replay(read_replay(tmp / "court.ttr"), arena, spec)
        if not playback.matches:
            print("error: the replay did not reach the recorded state", file=sys.stderr)
            return 1
        save_match_picture(playback.result, out / "beyond-replay.png")
        # frame 1800 (t = 30 s) of the same tape in the game's 3D view
        from tanktool.game.headless import screenshot
        from tanktool.game.replay_session import replay_session

        screenshot(out / "beyond-replay-3d.png", view="3d", frames=1800, size=(960, 540),
                   session=replay_session(read_replay(tmp / "court.ttr")))
    for name in ("beyond-bzw.png", "beyond-plan.png", "beyond-replay.png", "beyond-replay-3d.png"):
        print(out / name)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
