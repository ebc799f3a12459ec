"""`make vehicles`: rebuild every bundled vehicle's derived files from its source model.

Each vehicles/<name>/ is rebuilt with the parameters its vehicle.toml records (up,
scale, hull points, sphere levels, branching, a given mass) and keeps its [drive]
table, so hand-tuned driving figures survive.  The source model is copied aside first
because the whole bundle folder is replaced atomically.

    python tools/build_vehicles.py [NAME ...]
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def rebuild(bundle: Path) -> str:
    from tanktool.cli.import_vehicle import build_vehicle_bundle, rebuild_params
    from tanktool.formats.bundle import read_toml

    doc = read_toml(bundle / "vehicle.toml")
    params = rebuild_params(doc)
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / doc["source"]["file"]
        shutil.copyfile(bundle / doc["source"]["file"], src)
        result = build_vehicle_bundle(src, bundle, doc["name"], force=True, **params)
    return result.summary()


def main(argv: list[str]) -> int:
    from tanktool.errors import TanktoolError

    bundles = sorted(p.parent for p in (ROOT / "vehicles").glob("*/vehicle.toml"))
    if argv:
        bundles = [b for b in bundles if b.name in argv]
    if not bundles:
        print("no vehicle bundles to rebuild", file=sys.stderr)
        return 1
    for b in bundles:
        try:
            print(rebuild(b))
        except TanktoolError as e:
            print(f"error: {e}", file=sys.stderr)
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
