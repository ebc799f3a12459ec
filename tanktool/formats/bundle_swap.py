"""Whole bundles replaced atomically, and only bundles tanktool wrote.

A new bundle is assembled in a staging folder beside the target (:func:`staged_dir`)
and swapped into place with one atomic ``renameat2(RENAME_EXCHANGE)``, so at every
moment the target is either the complete old bundle or the complete new one;
:func:`bundle_update` changes some files of an existing bundle and its manifest
together the same way.  Only a bundle tanktool wrote is ever replaced
(:func:`check_replaceable`).  Staging folders carry tanktool's temporary names, so
what a killed run leaves is cleaned by the next (:func:`~tanktool.formats.bundle.clean_stale`).
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import os
import re
import shutil
import stat
from pathlib import Path
from typing import Any, Iterator

from ..errors import FormatError, OutputError
from .bundle import _temp_name, clean_stale, is_temp_name, output_error, read_input, read_toml

# ---------------------------------------------------------------------------
# which folders may be replaced

MANIFESTS = ("arena.toml", "vehicle.toml")
#: files each kind of bundle holds besides those its manifest names
_STANDARD = {
    "arena.toml": ("model.glb", "walls.txt", "preview.png", "navgrid.npz", "quadtree.npz", "navgrid.png"),
    "vehicle.toml": ("model.glb", "hull.txt", "spheres.txt", "preview.png"),
}


def _obj_materials(model: Path) -> set[str]:
    """Plain file names of an .obj's ``mtllib`` lines (copied into bundles beside it)."""
    out: set[str] = set()
    try:
        data = read_input(model, "an .obj file")
    except FormatError:
        return out
    # the lines that start with mtllib, found by bytes.find (a memchr-speed scan): on a
    # 120 MB model bytes.splitlines made 3 M lines and a regex anchored at line starts
    # tried every position, ~2.3 s a call and three calls replacing a bundle; this ~0.09 s
    i = data.find(b"mtllib")
    while i != -1:
        if i == 0 or data[i - 1] in b"\r\n":   # lines end at \n, \r or \r\n
            line = _TO_LINE_END.match(data, i).group()
            out.update(n.decode("utf-8", "replace") for n in line.split()[1:])
        i = data.find(b"mtllib", i + 6)
    return out


_TO_LINE_END = re.compile(rb"[^\r\n]*")


def _texture_folders(folder: Path, doc: dict[str, Any]) -> set[str]:
    """The sub-folders (``textures/``) holding the textures ``[model] textures`` lists,
    when they hold nothing else: a file a user put there keeps the folder his."""
    model = doc.get("model")
    listed = model.get("textures") if isinstance(model, dict) else None
    if not isinstance(listed, list):
        return set()
    listed_set = {t for t in listed if isinstance(t, str)}
    tops = {t.split("/")[0] for t in listed_set if "/" in t}
    out = set()
    for top in tops:
        sub = folder / top
        if sub.is_symlink() or not sub.is_dir():
            continue
        try:
            inside = {f"{top}/{n}" for n in os.listdir(sub)}
        except OSError:
            continue
        if inside <= listed_set:
            out.add(top)
    return out


def bundle_files(folder: Path, doc: dict[str, Any], manifest: str) -> set[str]:
    """Names of the files a bundle written by tanktool holds (its own, not a user's)."""
    names = {manifest, *_STANDARD.get(manifest, ())}
    for table in doc.values():
        if isinstance(table, dict) and isinstance(table.get("file"), str):
            names.add(table["file"])
    derived = doc.get("derived")
    if isinstance(derived, dict):
        names.update(str(k) for k in derived)
    names |= _texture_folders(folder, doc)
    src = doc.get("source")
    if isinstance(src, dict):
        comp = src.get("companions")
        if isinstance(comp, list):
            names.update(c.split("/")[0] for c in comp if isinstance(c, str))   # "data/scene.bin": data/
        f = src.get("file")
        if isinstance(f, str) and f.lower().endswith(".obj") and "/" not in f:
            names |= _obj_materials(folder / f)
    return names


def check_replaceable(target: str | os.PathLike, force: bool, manifest: str | None = None) -> None:
    """Raise OutputError unless ``target`` is free or may be replaced.

    A path that exists is replaced only with ``force`` and only when it is a bundle
    tanktool wrote: a real folder (not a link) holding ``manifest`` (any kind when
    None) with a ``tool_version``, and no file the bundle does not account for.  A
    user's folder, a file, another kind of bundle are refused with the reason.
    """
    target = Path(target)
    if not os.path.lexists(target):
        return
    if not force:
        raise OutputError(f"{target}: already exists (use --force to overwrite)")
    kinds = (manifest,) if manifest else MANIFESTS
    if os.path.islink(target):
        raise OutputError(f"{target}: is a symbolic link; refusing to replace it (give the folder it points to)")
    if not target.is_dir():
        raise OutputError(f"{target}: exists and is not a folder; refusing to replace it with a bundle")
    found = next((k for k in kinds if (target / k).is_file()), None)
    if found is None:
        other = next((k for k in MANIFESTS if k not in kinds and (target / k).is_file()), None)
        if other:
            raise OutputError(f"{target}: is {'an arena' if other == 'arena.toml' else 'a vehicle'} bundle "
                              f"(it has {other}); refusing to replace it")
        raise OutputError(f"{target}: is not a tanktool bundle (no {kinds[0]}); refusing to replace a folder "
                          f"tanktool did not write (choose another -o)")
    try:
        doc = read_toml(target / found)
    except FormatError as e:
        raise OutputError(f"{target}: its {found} cannot be read, so it is not a bundle tanktool wrote ({e}); "
                          f"refusing to replace it") from None
    if not isinstance(doc.get("tool_version"), str):
        raise OutputError(f"{target}: its {found} has no tool_version, so tanktool did not write it; "
                          f"refusing to replace it")
    known = bundle_files(target, doc, found)
    try:
        foreign = sorted(n for n in os.listdir(target) if n not in known and not is_temp_name(n))
    except OSError as e:
        raise output_error(target, e, "cannot list the folder") from None
    if foreign:
        shown = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
        raise OutputError(f"{target}: holds {len(foreign)} file(s) that are not part of the bundle ({shown}); "
                          f"refusing to replace it (move them away, or choose another -o)")


# ---------------------------------------------------------------------------
# whole bundles

_AT_FDCWD = -100
_RENAME_EXCHANGE = 2
_renameat2: Any = None


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths in one atomic step (Linux ``renameat2(RENAME_EXCHANGE)``).
    False when the system or the file system cannot; other failures raise OSError."""
    global _renameat2
    if _renameat2 is None:
        try:
            _renameat2 = getattr(ctypes.CDLL(None, use_errno=True), "renameat2", False)
        except OSError:  # pragma: no cover - no C library to ask
            _renameat2 = False
    if not _renameat2:
        return False
    if _renameat2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP, errno.EOPNOTSUPP):
        return False
    raise OSError(err, os.strerror(err), str(b))


def _install(stage: Path, target: Path) -> None:
    """Put the complete ``stage`` folder at ``target``, replacing what is there.

    With RENAME_EXCHANGE the target is never missing; without, the old bundle is
    renamed aside first (a killed run leaves it there, and :func:`clean_stale` puts
    it back)."""
    if not os.path.lexists(target):
        os.rename(stage, target)
        return
    if _exchange(stage, target):
        shutil.rmtree(stage, ignore_errors=True)  # now holds the old bundle
        return
    old = stage.with_name(stage.name + ".old")
    os.rename(target, old)
    try:
        os.rename(stage, target)
    except BaseException:
        os.rename(old, target)
        raise
    shutil.rmtree(old, ignore_errors=True)


def _absolute(target: str | os.PathLike) -> Path:
    """``target`` as an absolute path with a real last component (``.`` -> the folder's name)."""
    t = Path(os.path.abspath(os.fspath(target)))
    if not t.name or t == t.parent:
        raise OutputError(f"{target}: cannot write a bundle there (the root of the file system)")
    return t


@contextlib.contextmanager
def staged_dir(target: str | os.PathLike, force: bool = False, manifest: str | None = None) -> Iterator[Path]:
    """Yield an empty staging folder beside ``target``; on success it replaces ``target``.

    On any exception the staging folder is removed and ``target`` is left as it was.
    An existing ``target`` is refused before any work unless ``force`` is given and it
    is a bundle tanktool wrote (:func:`check_replaceable`; ``manifest`` names the
    kind).  OSErrors (a folder that cannot be made, a full disk) become OutputError.
    """
    shown = target
    target = _absolute(target)
    check_replaceable(target, force, manifest)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise output_error(shown, e, "cannot make the folder") from None
    clean_stale(target.parent, target.name)
    tmp = target.parent / _temp_name(target.name)
    try:
        os.mkdir(tmp, 0o777)  # the umask applies, as for any folder the user makes
    except OSError as e:
        e.filename = None
        raise output_error(shown, e, f"cannot make a folder in {target.parent}") from None
    # nothing may have appeared at the target meanwhile
    with _installing(tmp, target, shown, lambda: check_replaceable(target, force, manifest)):
        yield tmp


@contextlib.contextmanager
def _installing(stage: Path, target: Path, shown: Any, before: Any = None) -> Iterator[None]:
    """Run the body, then put ``stage`` at ``target``; on any failure remove ``stage``
    (an OSError becomes an OutputError naming ``shown``)."""
    try:
        yield
        if before is not None:
            before()
        _install(stage, target)
    except OSError as e:
        shutil.rmtree(stage, ignore_errors=True)
        raise output_error(shown, e) from None
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise


def _link_or_copy(src: str, dst: str) -> None:
    try:
        os.link(src, dst, follow_symlinks=False)
    except OSError:
        shutil.copy2(src, dst, follow_symlinks=False)


@contextlib.contextmanager
def bundle_update(bundle: str | os.PathLike) -> Iterator[Path]:
    """Change files of an existing bundle and its manifest together, atomically.

    Yields a staged copy of ``bundle`` (hard links to its files, so it costs almost
    nothing); write the new files into it, each with :func:`atomic_write_bytes` (a
    rename, never writing into a linked file), manifest included.  On success the
    copy replaces the bundle in one atomic exchange: readers see the old bundle or the
    new one, never new derived files with an old manifest.  On failure (or when the
    process is killed) the bundle is untouched and the copy is removed (at the next
    run).  OSErrors become OutputError.
    """
    shown = bundle
    bundle = _absolute(bundle)
    if not bundle.is_dir() or bundle.is_symlink():
        raise OutputError(f"{shown}: not a bundle folder")
    clean_stale(bundle.parent, bundle.name)
    clean_stale(bundle)
    stage = bundle.parent / _temp_name(bundle.name)
    try:
        os.mkdir(stage, 0o700)
        os.chmod(stage, stat.S_IMODE(os.stat(bundle).st_mode))
        for entry in os.scandir(bundle):
            if is_temp_name(entry.name):
                continue
            dst = stage / entry.name
            if entry.is_symlink():
                os.symlink(os.readlink(entry.path), dst)
            elif entry.is_dir():
                shutil.copytree(entry.path, dst, symlinks=True, copy_function=_link_or_copy)
            else:
                _link_or_copy(entry.path, str(dst))
    except OSError as e:
        shutil.rmtree(stage, ignore_errors=True)
        raise output_error(shown, e) from None
    with _installing(stage, bundle, shown):
        yield stage
