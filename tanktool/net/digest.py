"""The match digest: what two peers must share to play one match (issue 22 / 25).

A JOIN carries it (16 bytes, protocol version 2); a host whose own digest differs
refuses the joiner (``REFUSE 6``, "your arena or vehicle differs from the host's"),
so peers never play on worlds that disagree on a wall, a level or a vehicle limit.

It is BLAKE2b-128 over, in order: the arena's walls, spawns and bounds as the match
loaded them; the bytes of the bundle's manifest, walls and grid files (``*.toml``,
``*.txt``, ``*.npz`` at the top of the bundle folder, by name), which is where a ground
lives; and the vehicle's defining fields (``TankSpec``'s constructor arguments, as JSON).
"""

from __future__ import annotations

import dataclasses
import json
from hashlib import blake2b
from pathlib import Path
from typing import Any

import numpy as np

from .protocol import DIGEST_SIZE

#: bundle files that decide the world a match runs in (pictures and models do not)
DECIDING = ("*.toml", "*.txt", "*.npz")


def _arrays(h: Any, *arrays: Any) -> None:
    for a in arrays:
        if a is None:
            h.update(b"none")
            continue
        a = np.ascontiguousarray(np.asarray(a, dtype=np.float64))
        h.update(str(a.shape).encode() + a.tobytes())


def _spec_fields(spec: Any) -> dict[str, Any]:
    if not dataclasses.is_dataclass(spec):
        return {"repr": repr(spec)}
    return {f.name: getattr(spec, f.name) for f in dataclasses.fields(spec) if f.init}


def match_digest(arena: Any, spec: Any) -> bytes:
    """16 bytes naming the arena (``sim.match.ArenaInfo``) and vehicle (``TankSpec``)."""
    h = blake2b(digest_size=DIGEST_SIZE, person=b"tanktool match")
    walls = getattr(arena, "walls", None)
    _arrays(h, getattr(walls, "segments", None), getattr(walls, "direction", None),
            getattr(arena, "spawns", None), getattr(arena, "bounds", None))
    path = getattr(arena, "path", None)
    if path is not None and Path(path).is_dir():
        files = sorted({p for pattern in DECIDING for p in Path(path).glob(pattern) if p.is_file()})
        for p in files:
            h.update(p.name.encode() + b"\0" + p.read_bytes())
    h.update(json.dumps(_spec_fields(spec), sort_keys=True, default=lambda o: np.asarray(o).tolist()).encode())
    return h.digest()


def match_label(arena: Any, spec: Any) -> str:
    """How the refusal names what the host plays."""
    return f"the host plays {getattr(arena, 'name', '?')} with {getattr(spec, 'name', '?')}"
