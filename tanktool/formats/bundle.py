"""Bundles on disk: TOML manifests, hashes, files confined to their bundle, and single
files written so that they survive being killed at any moment.

Reading.  :func:`read_input` is the one way the tools read an input file: only a
regular file (never a device, a FIFO or a folder), at most a given number of bytes,
every failure a :class:`~tanktool.errors.FormatError` naming the file.
:func:`bundle_file` resolves a file name written in a manifest inside its bundle, or
refuses it (``/etc/passwd``, ``../x``, a symbolic link that leads out).

Writing.  Single files go to a temporary file in the same folder and are renamed over
the target (:func:`atomic_write_bytes`).  Whole bundles are swapped into place by
:mod:`tanktool.formats.bundle_swap`.

Every temporary name carries ``tanktool-<pid>-<random>``: when a run is killed
(SIGKILL, power loss of the process) what it left behind is recognised by the next
run (the pid is gone) and removed -- or, for the rare file systems without
RENAME_EXCHANGE, the previous bundle is put back (:func:`clean_stale`).
An OSError while writing (read-only folder, full disk, file size limit) becomes one
:class:`~tanktool.errors.OutputError` line.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import os
import re
import secrets
import shutil
import stat
import sys
from pathlib import Path
from typing import Any, Iterator

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from ..errors import FormatError, OutputError
from .limits import MAX_DEPTH, MAX_MANIFEST_BYTES, MAX_MODEL_BYTES, nesting_depth

# ---------------------------------------------------------------------------
# reading


def current_umask() -> int:
    """The process's umask (read by setting it and putting it back)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


_umask = current_umask      # the name this module's functions use


def _open_regular(path: str | os.PathLike, label: str, expected: str) -> int:
    """An fd of a regular file, opened without blocking (a FIFO would hang ``open``)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise FormatError(f"{label}: no such file") from None
    except IsADirectoryError:
        raise FormatError(f"{label}: is a folder, expected {expected}") from None
    except (OSError, ValueError) as e:  # ValueError: a NUL byte in the name
        raise FormatError(f"{label}: cannot read: {getattr(e, 'strerror', None) or e}") from None
    try:
        st = os.fstat(fd)
    except OSError as e:
        os.close(fd)
        raise FormatError(f"{label}: cannot read: {e.strerror}") from None
    if stat.S_ISDIR(st.st_mode):
        os.close(fd)
        raise FormatError(f"{label}: is a folder, expected {expected}")
    if not stat.S_ISREG(st.st_mode):
        os.close(fd)
        raise FormatError(f"{label}: is not a regular file (a device, pipe or socket), expected {expected}")
    return fd


def read_input(path: str | os.PathLike, expected: str = "a file", label: str | None = None,
               limit: int = MAX_MODEL_BYTES) -> bytes:
    """The bytes of an input file, at most ``limit`` of them.

    A missing file, a folder, a device or FIFO, an unreadable or too large file is a
    FormatError naming ``label`` (default: the path) and saying what was ``expected``.
    """
    label = label or str(path)
    fd = _open_regular(path, label, expected)
    try:
        size = os.fstat(fd).st_size
        if size > limit:
            raise FormatError(f"{label}: {size:,} bytes, more than the {limit:,} bytes {expected} may have")
        chunks, total = [], 0
        with os.fdopen(fd, "rb", closefd=False) as f:
            while True:
                block = f.read(min(1 << 24, limit + 1 - total))
                if not block:
                    break
                chunks.append(block)
                total += len(block)
                if total > limit:  # it grew while we read it
                    raise FormatError(f"{label}: more than the {limit:,} bytes {expected} may have")
        return b"".join(chunks)
    except OSError as e:
        raise FormatError(f"{label}: cannot read: {e.strerror}") from None
    finally:
        os.close(fd)


def read_input_text(path: str | os.PathLike, expected: str = "a text file", limit: int = MAX_MODEL_BYTES) -> str:
    """An input file as UTF-8 text; bytes that are not UTF-8 are a FormatError naming the
    line and the byte offset."""
    data = read_input(path, expected, limit=limit)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = data[: e.start].count(b"\n") + 1
        raise FormatError(f"{path}:{line}: not UTF-8 text (byte offset {e.start})") from None


def data_lines(text: str) -> Iterator[tuple[int, str, list[str]]]:
    """(line number, the line without its ``#`` comment, its fields) of every line of a
    small text format (hull.txt, spheres.txt) that holds data."""
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if line:
            yield lineno, line, line.split()


def parse_toml(data: bytes, label: str) -> dict[str, Any]:
    """TOML bytes as a dict; syntax errors, non-UTF-8 bytes and nesting deeper than
    ``MAX_DEPTH`` are FormatErrors naming ``label``."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = data[: e.start].count(b"\n") + 1
        raise FormatError(f"{label}:{line}: not UTF-8 text (byte offset {e.start})") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise FormatError(f"{label}: invalid TOML: {e}") from None
    except RecursionError:
        raise FormatError(f"{label}: invalid TOML: values nested deeper than {MAX_DEPTH} levels") from None
    if nesting_depth(doc) > MAX_DEPTH:
        raise FormatError(f"{label}: values nested deeper than {MAX_DEPTH} levels")
    return doc


def read_toml(path: str | os.PathLike, limit: int = MAX_MANIFEST_BYTES) -> dict[str, Any]:
    """Read a TOML file (a manifest, the bindings); every defect is a FormatError naming it."""
    return parse_toml(read_input(path, "a TOML file", limit=limit), str(path))


def sha256_file(path: str | os.PathLike) -> str:
    """Hex sha256 of a regular file's bytes (a device or FIFO is a FormatError)."""
    label = str(path)
    fd = _open_regular(path, label, "a file")
    h = hashlib.sha256()
    try:
        with os.fdopen(fd, "rb", closefd=False) as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
    finally:
        os.close(fd)
    return h.hexdigest()


def bundle_file(bundle: str | os.PathLike, name: Any, where: str) -> Path:
    """``bundle/name`` for a file name written in a bundle's manifest, or a FormatError.

    The name must be a relative path that stays inside the bundle once symbolic links
    are followed: ``/etc/passwd``, ``../../x``, a link to ``/dev/zero`` are refused
    (``where`` says which key named it, e.g. ``vehicles/x/vehicle.toml: [hull] file``).
    """
    if not isinstance(name, str) or not name or "\0" in name:
        raise FormatError(f"{where} must be a file name in the bundle, got {name!r}")
    p = Path(name)
    if p.is_absolute() or ".." in p.parts or "\\" in name:
        raise FormatError(f"{where} must be a file name inside the bundle, got {name!r}")
    root = Path(bundle)
    try:
        real_root = root.resolve()
        real = (root / p).resolve()
    except (OSError, RuntimeError):  # a loop of symbolic links
        raise FormatError(f"{where}: {name!r} cannot be resolved (a loop of symbolic links?)") from None
    if real != real_root and real_root not in real.parents:
        raise FormatError(f"{where}: {name!r} leads outside the bundle (to {real})")
    return root / p


#: an array of scalars that tomli_w spread over one line per item
_SCALAR_ARRAY = re.compile(r"\[\n((?:[ \t]+[^\[\]{}\n]+,\n)+)[ \t]*\]")


def dumps_toml(data: dict[str, Any]) -> str:
    """TOML text; arrays of numbers (points, bounds) each on one line, as people write them."""
    import tomli_w

    def one_line(m: re.Match) -> str:
        return "[" + ", ".join(item.strip()[:-1] for item in m.group(1).splitlines()) + "]"

    return _SCALAR_ARRAY.sub(one_line, tomli_w.dumps(data))


# ---------------------------------------------------------------------------
# OS errors as one line


_OS_HINTS = {
    errno.ENOSPC: "no space left on the disk",
    errno.EFBIG: "file size limit reached (ulimit -f)",
    errno.EROFS: "read-only file system",
    errno.EACCES: "permission denied",
    errno.EPERM: "operation not permitted",
    errno.EDQUOT: "disk quota exceeded",
}


#: a temporary name inside a path, as the user should see it: the final name
_TEMP_IN_PATH = re.compile(r"\.([^/]+?)\.tanktool-\d+-[0-9a-f]+(?:\.tmp|\.old)?(?=/|$)")


def os_error_text(e: OSError) -> str:
    """What went wrong, in words: 'no space left on the disk', 'permission denied', ...
    and the file it happened to (temporary names shown as the file they become)."""
    text = _OS_HINTS.get(e.errno or 0) or e.strerror or str(e)
    where = _TEMP_IN_PATH.sub(r"\1", os.fsdecode(e.filename)) if e.filename else ""
    return f"{text} ({where})" if where else text


def output_error(target: str | os.PathLike, e: OSError, what: str = "cannot write") -> OutputError:
    """One line: the file (a staging name shown as the file it becomes), what failed, why."""
    shown = _TEMP_IN_PATH.sub(r"\1", os.fspath(target))
    if e.filename and _TEMP_IN_PATH.sub(r"\1", os.fsdecode(e.filename)) == shown:
        e.filename = None  # said once is enough
    return OutputError(f"{shown}: {what}: {os_error_text(e)}")


# ---------------------------------------------------------------------------
# temporary names and what killed runs leave behind

#: ``.<name>.tanktool-<pid>-<hex>`` (a staging folder), ``...tmp`` (a file being
#: written), ``...old`` (a bundle moved aside during a swap without RENAME_EXCHANGE)
_TEMP = re.compile(r"^\.(?P<name>.+)\.tanktool-(?P<pid>\d+)-[0-9a-f]+(?P<kind>\.tmp|\.old)?$")


def _temp_name(name: str, suffix: str = "") -> str:
    return f".{name}.tanktool-{os.getpid()}-{secrets.token_hex(4)}{suffix}"


def is_temp_name(name: str) -> bool:
    """True for the names of tanktool's own temporary files and folders."""
    return _TEMP.match(name) is not None


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return pid > 0  # someone else's process
    return True


def _remove(p: Path) -> None:
    if p.is_dir() and not p.is_symlink():
        shutil.rmtree(p, ignore_errors=True)
    else:
        with contextlib.suppress(OSError):
            p.unlink()


def clean_stale(folder: str | os.PathLike, name: str | None = None) -> list[str]:
    """Remove what killed tanktool runs left in ``folder`` (only for ``name`` if
    given): staging folders and temporary files of processes that no longer exist.
    A bundle moved aside by an interrupted swap is put back when its place is empty.
    Returns the names handled; failures (a read-only folder) are ignored."""
    folder = Path(folder)
    try:
        entries = os.listdir(folder)
    except OSError:
        return []
    done = []
    # put moved-aside bundles back first, then drop staging folders and temporary files
    found = [(m, e) for e in entries if (m := _TEMP.match(e)) and (name is None or m["name"] == name)]
    found.sort(key=lambda me: me[0]["kind"] != ".old")
    for m, entry in found:
        if _alive(int(m["pid"])):
            continue
        p = folder / entry
        home = folder / m["name"]
        if m["kind"] == ".old" and not os.path.lexists(home):
            with contextlib.suppress(OSError):
                os.replace(p, home)
                done.append(entry)
                continue
        _remove(p)
        done.append(entry)
    return done


# ---------------------------------------------------------------------------
# single files


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file and a rename.

    The file gets the mode a plain ``open()`` would give it.  On any failure the
    temporary file is removed and ``path`` is left as it was; an OSError becomes an
    OutputError naming ``path``.
    """
    path = Path(path)
    if not path.name:
        raise OutputError(f"{path}: not a file name")
    clean_stale(path.parent, path.name)
    tmp = path.parent / _temp_name(path.name, ".tmp")
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o666)
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view):]
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except BaseException as e:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(e, OSError):
            raise output_error(path, e) from None
        raise


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))


def write_toml(path: str | os.PathLike, data: dict[str, Any]) -> None:
    atomic_write_text(path, dumps_toml(data))
