"""Rebuild the derived files of every bundled arena (``make arenas``).

    .venv/bin/python tools/build_arenas.py [NAME ...]

For each ``arenas/<name>/arena.toml`` the source model named in its ``[source]``
table is run through import-arena again with the parameters the manifest records
(up axis, scale, wall height, tolerance, the [walkable] and [navgrid] tables), replacing the bundle
atomically; import-arena writes the navigation files too (navgrid.npz, quadtree.npz,
navgrid.png), as build-navgrid would, so they follow the new walls.
tools/make_arena_models.py authors the source models themselves.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def rebuild(folder: Path, out: Path | None = None, navgrid: bool = True) -> None:
    """Re-import ``folder``'s source into ``out`` (default: the folder itself); without
    ``navgrid``, leave out the navigation files (quicker, for tests of the walls)."""
    from tanktool.importer import import_arena
    from tanktool.formats.bundle import read_toml

    doc = read_toml(folder / "arena.toml")
    src = doc["source"]
    walls = doc.get("walls", {})
    target = out or folder
    r = import_arena(folder / src["file"], target, name=doc.get("name", folder.name), up=src.get("up"),
                     scale=float(src.get("scale", 1.0)), height=float(walls.get("height", 1.0)),
                     tolerance=float(walls.get("tolerance", 0.01)), force=True, navgrid=doc.get("navgrid"),
                     wall_height=src.get("wall_height"), wall_thickness=src.get("wall_thickness"),
                     walkable=doc.get("walkable"), grid=navgrid)
    print(f"{folder.name}: {len(r.walls)} walls, {len(r.spawns)} spawns ({r.seconds:.2f} s)")


def main(argv: list[str] | None = None) -> int:
    names = argv if argv is not None else sys.argv[1:]
    folders = sorted(p.parent for p in (ROOT / "arenas").glob("*/arena.toml"))
    if names:
        folders = [f for f in folders if f.name in names]
        missing = set(names) - {f.name for f in folders}
        if missing:
            print(f"error: no bundled arena named {', '.join(sorted(missing))}", file=sys.stderr)
            return 2
    for folder in folders:
        rebuild(folder)
    return 0


if __name__ == "__main__":
    sys.exit(main())
