"""Player names and text from the network: what makes two names the same, and how any
text a peer sent is shown.

Two names are the same when their keys are equal: NFKC folding (full-width "Ａ" is
"A"), format characters dropped (zero-width joiners), runs of spaces made one, the
Unicode TR39 skeleton (Cyrillic "а" is Latin "a", "0" is "O", "rn" is "m"; the table
in :mod:`.confusables_table`, made by ``tools/make_confusables.py``) and case folding.
A name whose key is empty (only spaces or invisible characters) is blank.

Every text that came over the network (names, refusal reasons) is printed through
:func:`visible`: control, format and other unprintable characters become ``\\xNN`` or
``\\uNNNN``, so an escape sequence cannot clear a terminal or repaint a line.
"""

from __future__ import annotations

import unicodedata
from functools import lru_cache

from .confusables_table import DATA


@lru_cache(maxsize=1)
def _table() -> dict[str, str]:
    out = {}
    for line in DATA.splitlines():
        src, _, dst = line.partition("\t")
        out[src] = dst
    return out


def skeleton(text: str) -> str:
    """The TR39 skeleton (NFD, each character mapped by the confusables table, NFD)."""
    table = _table()
    d = unicodedata.normalize("NFD", text)
    return unicodedata.normalize("NFD", "".join(table.get(c, c) for c in d))


def name_key(name: str) -> str:
    """What two names must differ in: equal keys are the same name on the scoreboard."""
    s = unicodedata.normalize("NFKC", name)
    s = "".join(c for c in s if unicodedata.category(c) not in ("Cf", "Cc", "Mn", "Me"))
    s = " ".join(s.split())
    # skeleton first: case folding would make "I" an "i" before the table makes it an "l"
    sk = skeleton(s)
    # the skeleton of a combining mark is dropped as above: "é" is "e" on a scoreboard
    sk = "".join(c for c in sk if unicodedata.category(c) not in ("Mn", "Me"))
    return skeleton(sk.casefold())


def name_problem(name: str, taken: list[str]) -> str | None:
    """Why ``name`` cannot join a session whose players are named ``taken``, or None."""
    key = name_key(name)
    if not key.strip():
        return f"the name {visible(name)!s} is blank"
    for other in taken:
        if name_key(other) == key:
            return f"the name {visible(name)} looks like {visible(other)}, already playing"
    return None


def visible(text: str) -> str:
    """``text`` with every control, format and unprintable character escaped (a
    backslash too), safe to print on a terminal."""
    out = []
    for c in text:
        if c == "\\":
            out.append("\\\\")
        elif c.isprintable():
            out.append(c)
        elif ord(c) < 0x100:
            out.append(f"\\x{ord(c):02x}")
        elif ord(c) < 0x10000:
            out.append(f"\\u{ord(c):04x}")
        else:
            out.append(f"\\U{ord(c):08x}")
    return "".join(out)
