"""The one-way data flow as a contract (issue 25): `lint-imports` checks the layers
written in pyproject.toml's [tool.importlinter] (formats -> geometry -> nav -> sim ->
net -> front ends) on every import in tanktool/, lazy ones inside functions included."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def test_the_layer_contract_holds():
    pytest.importorskip("importlinter", reason="import-linter is in the test extra: make install")
    exe = shutil.which("lint-imports") or str(Path(sys.executable).parent / "lint-imports")
    r = subprocess.run([exe, "--config", str(ROOT / "pyproject.toml")], cwd=ROOT, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-2000:]
    assert "1 kept, 0 broken" in r.stdout
