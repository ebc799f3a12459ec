"""Bundle manifests for ``check``: TOML read tolerantly, keys located by line, files hashed.

tomllib gives values but not where they were written; a linter must point at the
line, so :class:`TomlLines` finds a key's line (and the lines of an array's items) by
a light scan of the text.  The rules shared by arena and vehicle bundles (B1xx,
B2xx) live here too.
"""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from ..formats.bundle import sha256_file
from ..formats.limits import MAX_DEPTH, nesting_depth
from .diagnostics import Diagnostic, diag

_HEADER = re.compile(r"^\s*\[\s*([A-Za-z0-9_.\-\" ]+?)\s*\]\s*(#.*)?$")


class TomlLines:
    """Line numbers of keys in a TOML text (top-level tables and plain keys)."""

    def __init__(self, text: str) -> None:
        self.lines = text.splitlines()
        self._where: dict[tuple[str, str], int] = {}
        self._tables: dict[str, int] = {}
        table = ""
        depth = 0
        for no, raw in enumerate(self.lines, 1):
            line = raw.split("#", 1)[0]
            if depth == 0:
                m = _HEADER.match(raw)
                if m and not raw.lstrip().startswith("[["):
                    table = m.group(1).strip().strip('"')
                    self._tables.setdefault(table, no)
                    continue
                k = re.match(r'^\s*("?)([^"=\s]+)\1\s*=', line)
                if k:
                    self._where.setdefault((table, k.group(2)), no)
            depth = max(0, depth + line.count("[") - line.count("]")) if "=" in line or depth else depth

    def key(self, table: str, key: str) -> int:
        """Line of ``key`` in ``[table]`` ('' for top level); else the table's line; else 0."""
        return self._where.get((table, key), self._tables.get(table, 0))

    def table(self, table: str) -> int:
        return self._tables.get(table, 0)

    def items(self, table: str, key: str, count: int) -> list[int]:
        """Lines of the first ``count`` items of an array of arrays written at ``key``."""
        start = self._where.get((table, key))
        if start is None:
            return [0] * count
        out: list[int] = []
        depth = 0
        for no in range(start, len(self.lines) + 1):
            line = self.lines[no - 1].split("#", 1)[0]
            if no == start:
                line = line.split("=", 1)[1] if "=" in line else line
            for ch in line:
                if ch == "[":
                    depth += 1
                    if depth == 2:
                        out.append(no)
                elif ch == "]":
                    depth -= 1
            if depth <= 0 and no > start or (depth <= 0 and out):
                break
        out += [start] * (count - len(out))
        return out[:count]


def _manifest_bytes(path: Path) -> bytes:
    """A manifest's bytes: a regular file of at most MAX_MANIFEST_BYTES, else OSError
    (the runner reports the path as unreadable)."""
    import errno

    from ..errors import FormatError
    from ..formats.bundle import read_input
    from ..formats.limits import MAX_MANIFEST_BYTES

    try:
        return read_input(path, "a TOML manifest", limit=MAX_MANIFEST_BYTES)
    except FormatError as e:
        raise OSError(errno.EINVAL, str(e).split(": ", 1)[-1], str(path)) from None


class Manifest:
    """A bundle's manifest: the parsed document (or None), its text lines, its path."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.doc: dict[str, Any] | None = None
        self.lines = TomlLines("")
        self.diagnostics: list[Diagnostic] = []
        data = _manifest_bytes(path)  # OSError goes to the runner: the path cannot be read
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError as e:
            line = data[: e.start].count(b"\n") + 1
            self.diagnostics.append(diag("B101", str(path), line, f"not UTF-8 text (byte offset {e.start})"))
            return
        self.lines = TomlLines(text)
        try:
            self.doc = tomllib.loads(text)
        except tomllib.TOMLDecodeError as e:
            m = re.search(r"line (\d+)", str(e))
            self.diagnostics.append(diag("B101", str(path), int(m.group(1)) if m else 0, f"invalid TOML: {e}"))
        except RecursionError:
            self.diagnostics.append(diag("B101", str(path), 0, "invalid TOML: values nested too deeply"))
        if self.doc is not None and nesting_depth(self.doc) > MAX_DEPTH:
            self.doc = None
            self.diagnostics.append(diag("B101", str(path), 0, f"values nested deeper than {MAX_DEPTH} levels"))

    def missing(self, table: str, key: str, what: str) -> Diagnostic:
        name = f"[{table}] {key}" if table else key
        return diag("B102", str(self.path), self.lines.key(table, key), f"{name} {what}")

    def table(self, name: str) -> dict[str, Any] | None:
        t = (self.doc or {}).get(name)
        return t if isinstance(t, dict) else None

    def get(self, table: str, key: str) -> Any:
        t = self.doc if not table else self.table(table)
        return None if t is None else t.get(key)

    def number(self, table: str, key: str, out: list[Diagnostic]) -> float | None:
        """A finite number at ``[table] key``, or None after adding a B102."""
        v = self.get(table, key)
        if v is None:
            out.append(self.missing(table, key, "is missing"))
            return None
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            out.append(self.missing(table, key, f"must be a finite number, got {v!r}"))
            return None
        return float(v)

    def string(self, table: str, key: str, out: list[Diagnostic], default: str | None = None) -> str | None:
        v = self.get(table, key)
        if v is None and default is not None:
            return default
        if not isinstance(v, str) or not v:
            what = "is missing" if v is None else f"must be a file name, got {v!r}"
            out.append(self.missing(table, key, what))
            return None
        return v


def safe_file(bundle: Path, name: str) -> Path | None:
    """``bundle/name`` if ``name`` is a relative path that stays inside the bundle
    (symbolic links followed), else None: ``/etc/passwd`` or a link to ``/dev/zero``
    is never opened."""
    from ..errors import FormatError
    from ..formats.bundle import bundle_file

    try:
        return bundle_file(bundle, name, "")
    except FormatError:
        return None


def file_rules(man: Manifest, bundle: Path, required_derived: tuple[str, ...]) -> list[Diagnostic]:
    """B102/B201/B202/B203/B204: model and source present, derived files present and fresh."""
    out: list[Diagnostic] = []
    mpath = str(man.path)
    src = man.string("source", "file", out)
    if src is not None:
        f = safe_file(bundle, src)
        if f is None or not f.is_file():
            out.append(diag("B201", mpath, man.lines.key("source", "file"), f"source model {src!r} is missing"))
        else:
            want = man.get("source", "sha256")
            if not isinstance(want, str):
                out.append(man.missing("source", "sha256", "must be the source model's sha256 (hex)"))
            elif sha256_file(f) != want.lower():
                out.append(diag("B204", mpath, man.lines.key("source", "sha256"),
                                f"source model {src!r} does not match its recorded sha256"))
    model = man.string("model", "file", out)
    if model is not None:
        f = safe_file(bundle, model)
        if f is None or not f.is_file():
            out.append(diag("B201", mpath, man.lines.key("model", "file"), f"model file {model!r} is missing"))
    derived = man.table("derived")
    if derived is None:
        out.append(diag("B102", mpath, 0, "table [derived] is missing (the sha256 of each derived file)"))
        return out
    for name in required_derived:
        if name not in derived and not (bundle / name).is_file():
            out.append(diag("B202", mpath, man.lines.table("derived"), f"derived file {name!r} is missing"))
    for name, want in derived.items():
        line = man.lines.key("derived", str(name))
        f = safe_file(bundle, str(name))
        if f is None or not f.is_file():
            out.append(diag("B202", mpath, line, f"derived file {name!r} is missing"))
        elif not isinstance(want, str):
            out.append(diag("B102", mpath, line, f"[derived] {name} must be a sha256 (hex string), got {want!r}"))
        elif sha256_file(f) != want.lower():
            out.append(diag("B203", mpath, line, f"derived file {name!r} is stale: its sha256 does not match"))
    return out + texture_rules(man, bundle)


#: a texture file larger than this is refused unread (a 4096 x 4096 RGBA image is 64 MiB
#: uncompressed; a PNG or JPEG of it is far smaller)
MAX_TEXTURE_BYTES = 128 << 20


def vehicle_grid_files(man: Manifest, out: list[Diagnostic]) -> tuple[str, ...]:
    """The grid files of the smaller vehicles, ``navgrid.<vehicle>.npz`` of [grids.<vehicle>]
    (they must be there, hashed, like navgrid.npz); a B102 for a malformed [grids]."""
    from ..errors import ArenaError
    from ..formats.vehicle_grids import vehicle_file, vehicle_grids

    if man.doc is None or "grids" not in man.doc:
        return ()
    try:
        return tuple(str(vehicle_file(name)) for name in vehicle_grids(man.doc, man.path))
    except ArenaError as e:
        out.append(diag("B102", str(man.path), man.lines.table("grids"), str(e).split(": ", 1)[-1]))
        return ()


def texture_rules(man: Manifest, bundle: Path) -> list[Diagnostic]:
    """B205: every texture ``[model] textures`` lists is a file inside the bundle that
    is an image (by its name and its content), at most the glTF sanitiser's
    4096 x 4096 pixels (read from its header, never decoded in full)."""
    model = man.table("model")
    if model is None or "textures" not in model:
        return []
    mpath = str(man.path)
    line = man.lines.key("model", "textures")
    names = model["textures"]
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        return [diag("B102", mpath, line, f"[model] textures must be a list of file names, got {str(names)[:60]}")]
    out = []
    for name in names:
        problem = _texture_problem(bundle, name)
        if problem:
            out.append(diag("B205", mpath, line, f"texture {name[:200]!r} {problem}"))
    return out


def _texture_problem(bundle: Path, name: str) -> str:
    """'' when ``name`` is a usable texture of ``bundle``, else what is wrong with it."""
    import warnings

    from ..formats.limits import MAX_IMAGE_PIXELS
    from ..formats.materials import IMAGE_SUFFIXES

    f = safe_file(bundle, name) if name else None
    if f is None:
        return "is outside the bundle (textures are named relative to it, inside it)"
    if not f.is_file():
        return "is missing" if not f.exists() else "is not a regular file"
    if f.suffix.lower() not in IMAGE_SUFFIXES:
        return f"is not an image file ({', '.join(IMAGE_SUFFIXES)})"
    size = f.stat().st_size
    if size > MAX_TEXTURE_BYTES:
        return f"is too large: {size:,} bytes, more than {MAX_TEXTURE_BYTES:,}"
    from PIL import Image

    side = int(MAX_IMAGE_PIXELS ** 0.5)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # PIL's DecompressionBombWarning: the size is judged here
            with Image.open(f) as im:
                w, h = im.size
                if w * h > MAX_IMAGE_PIXELS:
                    return f"is too large: {w} x {h} pixels, more than {side} x {side}"
                im.verify()  # chunks and checksums, without decoding the pixels
    except Image.DecompressionBombError as e:
        return f"is too large: {e}"
    except Exception as e:  # PIL raises many kinds for a damaged or foreign file
        return f"is not a readable image ({type(e).__name__}: {str(e)[:120]})"
    return ""
