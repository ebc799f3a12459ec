"""Where the bundled arenas and vehicles are.

In the checkout they are the top-level ``arenas/`` and ``vehicles/`` folders.  A wheel
carries them inside the package as ``tanktool/bundled/arenas`` and
``tanktool/bundled/vehicles`` (pyproject.toml maps the two folders there as package
data), so an installed tanktool finds them with :mod:`importlib.resources`; an
editable install or a plain checkout has no ``tanktool/bundled`` and falls back to
the checkout's folders.
"""

from __future__ import annotations

import importlib.resources
from pathlib import Path

KINDS = ("arenas", "vehicles")
MANIFESTS = {"arenas": "arena.toml", "vehicles": "vehicle.toml"}
#: the checkout holding this package (its arenas/ and vehicles/ are the bundled content)
CHECKOUT = Path(__file__).resolve().parent.parent


def _has_bundles(folder: Path, kind: str) -> bool:
    try:
        return folder.is_dir() and any(folder.glob(f"*/{MANIFESTS[kind]}"))
    except OSError:
        return False


def bundled_dir(kind: str) -> Path | None:
    """The folder holding the bundled ``kind`` ("arenas" or "vehicles"): inside the
    installed package, else the checkout's; None when neither has any."""
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    try:
        inside = importlib.resources.files("tanktool") / "bundled" / kind
    except (ModuleNotFoundError, TypeError):  # pragma: no cover - tanktool is importable: we are in it
        inside = None
    # a wheel is installed unpacked, so the resource is a real folder
    if inside is not None and _has_bundles(Path(str(inside)), kind):
        return Path(str(inside))
    if _has_bundles(CHECKOUT / kind, kind):
        return CHECKOUT / kind
    return None


def bundled_names(kind: str) -> list[str]:
    """Names of the bundled ``kind``, sorted."""
    base = bundled_dir(kind)
    if base is None:
        return []
    return sorted(d.parent.name for d in base.glob(f"*/{MANIFESTS[kind]}"))


def bundled_paths(kind: str) -> list[Path]:
    """Folders of the bundled ``kind``, sorted by name."""
    base = bundled_dir(kind)
    return [base / n for n in bundled_names(kind)] if base is not None else []
