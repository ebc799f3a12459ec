"""Bundles on disk: TOML manifests, hashes, and atomic writes.

Nothing the tools write is ever half-written: single files go to a temporary file
in the same folder and are renamed over the target; whole bundles are assembled in a
temporary sibling folder (:func:`staged_dir`) and renamed into place at the end.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import shutil
import sys
import tempfile
from pathlib import Path
from typing import Any, Iterator

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from ..errors import FormatError


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def sha256_file(path: str | os.PathLike) -> str:
    """Hex sha256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file and a rename."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        # mkstemp makes 0600 files; give the result the mode a plain open() would
        os.chmod(tmp, 0o666 & ~_umask())
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))


def read_input(path: str | os.PathLike, expected: str = "a file", label: str | None = None) -> bytes:
    """The bytes of an input file.  A missing file, a folder or an unreadable file is a
    FormatError naming ``label`` (default: the path) and saying what was ``expected``."""
    label = label or str(path)
    try:
        return Path(path).read_bytes()
    except FileNotFoundError:
        raise FormatError(f"{label}: no such file") from None
    except IsADirectoryError:
        raise FormatError(f"{label}: is a folder, expected {expected}") from None
    except OSError as e:
        raise FormatError(f"{label}: cannot read: {e.strerror}") from None


def read_input_text(path: str | os.PathLike, expected: str = "a text file") -> str:
    """An input file as UTF-8 text; bytes that are not UTF-8 are a FormatError naming the
    line and the byte offset."""
    data = read_input(path, expected)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = data[: e.start].count(b"\n") + 1
        raise FormatError(f"{path}:{line}: not UTF-8 text (byte offset {e.start})") from None


def read_toml(path: str | os.PathLike) -> dict[str, Any]:
    """Read a TOML file; a syntax error becomes a FormatError naming the file."""
    path = Path(path)
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except FileNotFoundError:
        raise FormatError(f"{path}: no such file") from None
    except tomllib.TOMLDecodeError as e:
        raise FormatError(f"{path}: invalid TOML: {e}") from None
    except UnicodeDecodeError as e:
        raise FormatError(f"{path}: not UTF-8 text at byte {e.start}") from None


#: an array of scalars that tomli_w spread over one line per item
_SCALAR_ARRAY = re.compile(r"\[\n((?:[ \t]+[^\[\]{}\n]+,\n)+)[ \t]*\]")


def dumps_toml(data: dict[str, Any]) -> str:
    """TOML text; arrays of numbers (points, bounds) each on one line, as people write them."""
    import tomli_w

    def one_line(m: re.Match) -> str:
        return "[" + ", ".join(item.strip()[:-1] for item in m.group(1).splitlines()) + "]"

    return _SCALAR_ARRAY.sub(one_line, tomli_w.dumps(data))


def write_toml(path: str | os.PathLike, data: dict[str, Any]) -> None:
    atomic_write_text(path, dumps_toml(data))


@contextlib.contextmanager
def staged_dir(target: str | os.PathLike, force: bool = False) -> Iterator[Path]:
    """Yield a temporary folder beside ``target``; on success it replaces ``target``.

    On any exception the temporary folder is removed and ``target`` is left as it
    was.  Without ``force`` an existing ``target`` is refused before any work.
    """
    target = Path(target)
    if target.exists() and not force:
        raise FormatError(f"{target}: already exists (use --force to overwrite)")
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
    os.chmod(tmp, 0o777 & ~_umask())  # mkdtemp makes 0700 folders; bundles are shared
    try:
        yield tmp
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    old = None
    if target.exists():
        old = target.with_name(f".{target.name}.old")
        shutil.rmtree(old, ignore_errors=True)
        os.replace(target, old)
    os.replace(tmp, target)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
