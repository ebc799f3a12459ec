"""``.npz`` archives (navgrid.npz, quadtree.npz) read without trusting them.

``numpy.load`` on a damaged archive raises BadZipFile, zlib.error, EOFError or
NotImplementedError, and one whose members claim gigabytes inflates them.  Here the
file is read through :func:`~tanktool.formats.bundle.read_input` (a regular file of
bounded size), every member's declared size is added up *before* anything is
inflated (zipfile then stops each member at its declared size), each ``.npy`` header
is checked (a plain numeric dtype, a shape that matches the member's bytes, never
pickled objects), and every failure is one FormatError naming the file.
"""

from __future__ import annotations

import io
import os
import tokenize
import zipfile
import zlib

import numpy as np

from ..errors import FormatError
from .limits import MAX_NPZ_BYTES

#: members one archive may have (ours have about ten)
MAX_MEMBERS = 64


def read_npz(path: str | os.PathLike, what: str = "an .npz file", limit: int = MAX_NPZ_BYTES,
             skip: tuple[str, ...] = ()) -> dict[str, np.ndarray]:
    """The arrays of an ``.npz`` file by name (without the ``.npy``); the members named
    in ``skip`` are not read (a reader that needs few of a large file's arrays)."""
    from .bundle import read_input

    label = str(path)
    data = read_input(path, what, limit=limit)
    try:
        zf = zipfile.ZipFile(io.BytesIO(data))
        infos = zf.infolist()
    except (zipfile.BadZipFile, zipfile.LargeZipFile, ValueError, OSError, EOFError, NotImplementedError) as e:
        raise FormatError(f"{label}: not {what} (not a readable zip archive: {e})") from None
    if len(infos) > MAX_MEMBERS:
        raise FormatError(f"{label}: {len(infos)} members, more than {MAX_MEMBERS} ({what} has about ten)")
    total = sum(i.file_size for i in infos)
    if total > limit:
        raise FormatError(f"{label}: its arrays claim {total:,} bytes, more than {limit:,}")
    out: dict[str, np.ndarray] = {}
    for info in infos:
        name = info.filename
        if not name.endswith(".npy") or info.is_dir():
            raise FormatError(f"{label}: member {name[:60]!r} is not an array (.npy)")
        if name[:-4] in skip:
            continue
        try:
            with zf.open(info) as f:
                version = np.lib.format.read_magic(f)
                if version == (1, 0):
                    shape, fortran, dtype = np.lib.format.read_array_header_1_0(f)
                elif version == (2, 0):
                    shape, fortran, dtype = np.lib.format.read_array_header_2_0(f)
                else:
                    raise ValueError(f"unsupported .npy version {version}")
                if dtype.hasobject or dtype.kind not in "biufU" or dtype.fields is not None:
                    raise ValueError(f"dtype {dtype} is not a plain number or text type")
                count = 1
                for d in shape:
                    count *= int(d)
                if count * dtype.itemsize > info.file_size:
                    raise ValueError(f"shape {shape} needs {count * dtype.itemsize} bytes, the member holds fewer")
                raw = f.read(count * dtype.itemsize)
                if len(raw) != count * dtype.itemsize:
                    raise ValueError("the member is cut short")
                arr = np.frombuffer(raw, dtype=dtype).copy()
                arr = arr.reshape(shape[::-1]).T if fortran else arr.reshape(shape)
        except (zipfile.BadZipFile, zlib.error, EOFError, OSError, ValueError, TypeError, SyntaxError,
                NotImplementedError, RuntimeError, tokenize.TokenError) as e:   # numpy tokenizes the header
            raise FormatError(f"{label}: member {name[:60]!r} cannot be read: {e}") from None
        out[name[:-4]] = arr
    return out


#: deflate level of :func:`write_npz`: zlib's fast strategy (levels 1-3).  On hix's
#: grids (2.6 M nodes) level 3 took 74 ms a grid where savez_compressed's 6 took 275,
#: and with the column arrays stored column by column (``fortran``) the file was smaller
LEVEL = 3
#: arrays of fewer values than this in all are deflated at zlib's default (6) instead:
#: milliseconds either way, and the bundled arenas' grids were up to 28 % larger at 3
SMALL = 1 << 20


def write_npz(arrays: dict[str, np.ndarray], level: int | None = None, fortran: tuple[str, ...] = ()) -> bytes:
    """The ``.npz`` bytes of ``arrays`` as ``numpy.savez_compressed`` writes them, at
    deflate ``level`` (None: :data:`LEVEL`, or 6 below :data:`SMALL` values).  The
    arrays named in ``fortran`` are stored column-major, which ``numpy.load`` and
    :func:`read_npz` read back as the same array: a column run's numbers then lie one
    after the other, as a row run's do, and deflate finds them (hix's col_index:
    349 -> 112 KB)."""
    if level is None:
        level = LEVEL if sum(np.size(a) for a in arrays.values()) >= SMALL else 6
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=level) as zf:
        for name, a in arrays.items():
            a = np.asarray(a)   # (ascontiguousarray would make a 0-d array 1-d)
            if name in fortran and a.ndim > 1:
                a = np.asfortranarray(a)
            with zf.open(f"{name}.npy", "w", force_zip64=True) as f:
                np.lib.format.write_array(f, a, allow_pickle=False)
    return buf.getvalue()
