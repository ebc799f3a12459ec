"""Levels of tools/make_levels.py imported as arena bundles, for the tests of the game on
relief and levels."""

from __future__ import annotations

import sys
from pathlib import Path

from click.testing import CliRunner

from tanktool.cli.main import cli

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
import make_levels  # noqa: E402


def import_level(folder: Path, name: str) -> Path:
    """Write level ``name`` as an .obj in ``folder`` and import it (one step: the grid
    comes with the bundle); returns the bundle."""
    src = make_levels.write_obj(make_levels.level(name), folder / f"{name}.obj")
    out = folder / name
    r = CliRunner().invoke(cli, ["-q", "import-arena", str(src), "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert (out / "navgrid.npz").is_file()
    return out
