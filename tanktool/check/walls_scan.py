"""A tolerant reader of ``walls.txt`` for ``check``.

:func:`tanktool.formats.walls_txt.parse_walls` stops at the first problem, which is
right for the tools that need walls; a linter must keep going and report every bad
line.  This scanner applies the same field rules line by line, keeps the good walls
(with their line numbers) and turns each bad line into a diagnostic.
"""

from __future__ import annotations

import math
from pathlib import Path

from ..errors import FormatError
from ..formats.walls_txt import (_MARKER_RE, AUX_MARKER, WallList, WallRows, _is_enclosing_rectangle,
                                 _parse_marker)
from .diagnostics import Diagnostic, diag

MAX_COORD = 1e6  # m


def _scan_wall(raw: str, path: str, lineno: int, out: list[Diagnostic]) -> tuple[list[float], int] | None:
    """A wall line's coordinates and Direction, or None (blank, or a diagnostic added to ``out``)."""
    body = raw.split("#", 1)[0].split()
    if not body:
        return None
    if len(body) != 5:
        out.append(diag("A101", path, lineno, f"expected 5 fields 'X1 Z1 X2 Z2 Direction', got {len(body)}"))
        return None
    try:
        vals = [float(v) for v in body[:4]]
    except ValueError:
        out.append(diag("A101", path, lineno, f"expected 4 numbers then the Direction, got {' '.join(body[:4])!r}"))
        return None
    if not all(math.isfinite(v) for v in vals):
        out.append(diag("A102", path, lineno, f"coordinates must be finite, got {' '.join(body[:4])}"))
        return None
    if max(abs(v) for v in vals) > MAX_COORD:
        # no arena is 1000 km wide; such numbers are typos, and they would drown
        # every other wall in floating-point rounding
        out.append(diag("A102", path, lineno, f"coordinates beyond +-{MAX_COORD:g} m: {' '.join(body[:4])}",
                        "check the number: walls are in metres"))
        return None
    try:
        d = float(body[4])
    except ValueError:
        d = math.nan
    if d not in (1.0, -1.0):
        out.append(diag("A103", path, lineno, f"Direction must be +1 or -1, got {body[4]!r}"))
        return None
    return vals, int(d)


def scan_walls_text(text: str, path: str) -> tuple[WallList, list[Diagnostic]]:
    """Parse what can be parsed; return the walls and one diagnostic per bad line."""
    out: list[Diagnostic] = []
    rows = WallRows()
    regions: dict = {}
    current = (0, 0)
    aux_start: int | None = None
    marker_line = 0
    for lineno, raw in enumerate(text.splitlines(), start=1):
        stripped = raw.strip()
        if _MARKER_RE.match(stripped) and aux_start is None:
            try:
                current = _parse_marker(stripped, f"{path}:{lineno}", regions)
            except FormatError as e:
                out.append(diag("A101", path, lineno, str(e).split(": ", 1)[-1].split(": ", 1)[-1],
                                "write '# level L region R y LO HI' (region numbers unique in the file)"))
            continue
        if stripped.lower().startswith(AUX_MARKER):
            if aux_start is not None:
                out.append(diag("A101", path, lineno, f"a second '{AUX_MARKER}' marker (the first is on line {marker_line})",
                                "keep one marker, right before the 4 auxiliary walls"))
                continue
            aux_start, marker_line = len(rows), lineno
            continue
        wall = _scan_wall(raw, path, lineno, out)
        if wall is not None:
            rows.add(wall[0], wall[1], lineno, current)
    return _with_aux(rows, regions, aux_start, marker_line, path, out), out


def _with_aux(rows: WallRows, regions: dict, aux_start: int | None, marker_line: int, path: str,
              out: list[Diagnostic]) -> WallList:
    """The walls with their auxiliary rectangle taken apart (after the marker, else
    the last 4 walls when they enclose the rest); what is wrong with it added to ``out``."""
    wl, seg, line_arr = rows.wall_lists(path, regions)
    if aux_start is not None:
        n_aux = len(seg) - aux_start
        if n_aux != 4:
            out.append(diag("A104", path, marker_line,
                            f"expected 4 auxiliary walls after '{AUX_MARKER}', got {n_aux}"))
            # keep every wall as a wall: the checks below still see the arena's shape
            return wl(slice(None))
        aux = seg[aux_start:]
        if not _is_enclosing_rectangle(aux, seg[:aux_start]):
            out.append(diag("A105", path, int(line_arr[aux_start]),
                            "the auxiliary walls must form an axis-aligned rectangle enclosing every wall"))
        return wl(slice(None, aux_start), aux)
    if len(seg) >= 4 and _is_enclosing_rectangle(seg[-4:], seg[:-4]):
        return wl(slice(None, -4), seg[-4:])
    last = int(line_arr[-1]) if len(line_arr) else 0
    out.append(diag("A104", path, last,
                    f"no '{AUX_MARKER}' marker, and the last 4 walls are not a rectangle enclosing the others"))
    return wl(slice(None))


def scan_walls_file(path: str | Path) -> tuple[WallList, list[Diagnostic]]:
    """Read and scan a walls file; OSError propagates (the runner decides what it means)."""
    data = Path(path).read_bytes()
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = data[: e.start].count(b"\n") + 1
        # keep checking the readable part: undecodable bytes become U+FFFD and that line fails A101
        text = data.decode("utf-8", errors="replace")
        walls, out = scan_walls_text(text, str(path))
        if not any(d.line == line and d.code == "A101" for d in out):
            out.insert(0, diag("A101", str(path), line, f"not UTF-8 text (byte offset {e.start})",
                               "save the file as UTF-8 (plain ASCII numbers)"))
        return walls, out
    return scan_walls_text(text, str(path))
