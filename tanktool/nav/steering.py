"""The 2002 navigation heuristic: a ternary decision among the three nodes ahead.

From node (i, j) facing one of the four grid headings, the children are the nodes
ahead-left, ahead and ahead-right.  Each valid child is scored by the number of free
nodes between it and the next wall *in the direction it leads*: the ahead child keeps
the heading, the ahead-right child is where the agent turns right (the paper's "HIJO 1
... operador de rotación hacia la derecha"), the ahead-left child where it turns left.
That count comes straight from the child's run numbers ("renglón o columna según sea
el caso"), no walking:

=========  ===================  =============================
heading    along                free nodes ahead of a node
=========  ===================  =============================
``+x``     its row, j grows     ``row_total - row_index``
``-x``     its row, j shrinks   ``row_index - 1``
``+z``     its column, i grows  ``col_total - col_index``
``-z``     its column, i shrinks ``col_index - 1``
=========  ===================  =============================

The highest score wins; ties go straight, and a tie between the two sides alone goes
right.  When no node ahead is valid the agent turns in place: the left or right
neighbour with more room (right on ties), else the node behind; ``None`` when boxed in.

Headings follow the world convention: heading angle 0 is +x, pi/2 is +z, and the
right of a facing f is (-f_z, f_x), so turning right goes +x -> +z -> -x -> -z.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .navgrid import STEPS, NavGrid, Node

#: headings in order of increasing angle; the next one is a right turn
HEADINGS = ("+x", "+z", "-x", "-z")


def heading_from_angle(theta: float) -> str:
    """The grid heading nearest to a world heading angle (radians)."""
    k = int(round(theta / (math.pi / 2))) % 4
    return HEADINGS[k]


def heading_angle(heading: str) -> float:
    """World heading angle (radians) of a grid heading."""
    return HEADINGS.index(_check(heading)) * math.pi / 2


def turn_right(heading: str) -> str:
    return HEADINGS[(HEADINGS.index(_check(heading)) + 1) % 4]


def turn_left(heading: str) -> str:
    return HEADINGS[(HEADINGS.index(_check(heading)) - 1) % 4]


def _check(heading: str | float) -> str:
    """A grid heading; a number is taken as a world heading angle and snapped."""
    if isinstance(heading, (int, float)) and not isinstance(heading, bool):
        return heading_from_angle(float(heading))
    if heading not in STEPS:
        raise ValueError(f"heading must be one of {', '.join(HEADINGS)} or an angle in radians, got {heading!r}")
    return heading


def run_ahead(row_index: int, col_index: int, row_total: int, col_total: int, heading: str) -> int:
    """Free nodes ahead of a node from its four numbers (the paper's table order:
    renglón, columna, total renglones, total columnas), travelling ``heading``."""
    h = _check(heading)
    if h == "+x":
        return int(row_total - row_index)
    if h == "-x":
        return int(row_index - 1)
    if h == "+z":
        return int(col_total - col_index)
    return int(col_index - 1)


def nodes_ahead(grid: NavGrid, node: Node, heading: str) -> int:
    """Free nodes after ``node`` before a wall, travelling ``heading`` (0 if invalid)."""
    i, j = node
    if not grid.is_valid(node):
        return 0
    n = (0, i, j)   # the 2002 heuristic runs on level 0 (a flat grid's only one)
    return run_ahead(grid.row_index[n], grid.col_index[n], grid.row_total[n], grid.col_total[n], heading)


@dataclass(frozen=True)
class Child:
    """One branch of the decision: which node, the heading it leads to, its score."""

    name: str  # "left", "ahead" or "right"
    node: Node
    heading: str
    ahead: int


def children(grid: NavGrid, node: Node, heading: str) -> list[Child]:
    """The valid ones of ahead-left, ahead and ahead-right, with their scores."""
    h = _check(heading)
    fi, fj = STEPS[h]
    out = []
    for name, side in (("left", turn_left(h)), ("ahead", None), ("right", turn_right(h))):
        si, sj = STEPS[side] if side else (0, 0)
        c = (node[0] + fi + si, node[1] + fj + sj)
        if grid.is_valid(c):
            travel = side or h
            out.append(Child(name, c, travel, nodes_ahead(grid, c, travel)))
    return out


def decide(scores: dict[str, int]) -> str | None:
    """The ternary decision on ``{"left": n, "ahead": n, "right": n}`` (missing = invalid).

    Most free nodes wins; ties go straight; left/right ties go right.
    """
    best = max(scores.values(), default=None)
    if best is None:
        return None
    for name in ("ahead", "right", "left"):
        if scores.get(name) == best:
            return name
    return None  # unreachable


def choose_next(grid: NavGrid, node: Node, heading: str | float) -> Node | None:
    """The node to move to next from ``node`` facing ``heading`` (see the module doc).

    ``heading`` is "+x", "+z", "-x" or "-z", or a world heading angle in radians
    (snapped to the nearest of the four).
    """
    heading = _check(heading)
    kids = {c.name: c for c in children(grid, node, heading)}
    pick = decide({k: c.ahead for k, c in kids.items()})
    if pick is not None:
        return kids[pick].node
    # nothing valid ahead: turn in place towards the side with more room
    h = _check(heading)
    side = {}
    for name, t in (("right", turn_right(h)), ("left", turn_left(h))):
        di, dj = STEPS[t]
        n = (node[0] + di, node[1] + dj)
        if grid.is_valid(n):
            side[name] = (n, nodes_ahead(grid, n, t))
    if side:
        name = max(side, key=lambda k: (side[k][1], k == "right"))
        return side[name][0]
    di, dj = STEPS[turn_right(turn_right(h))]
    back = (node[0] + di, node[1] + dj)
    return back if grid.is_valid(back) else None


def heading_of_move(src: Node, dst: Node, heading: str) -> str:
    """The heading after moving ``src -> dst``: straight keeps it, a side step turns."""
    di, dj = dst[0] - src[0], dst[1] - src[1]
    for h, (si, sj) in STEPS.items():
        if (di, dj) == (si, sj):
            return h
    fi, fj = STEPS[_check(heading)]
    # diagonal: the part that is not the current forward step is the turn
    rest = (di - fi, dj - fj)
    for h, s in STEPS.items():
        if s == rest:
            return h
    return heading


# ------------------------------------------------------------------ on levels
Node3 = tuple[int, int, int]
#: a grid heading's link direction (navgrid.STEPS order: +x, +z, -x, -z)
_DIR = {h: d for d, h in enumerate(STEPS)}


def step3(grid: NavGrid, node: Node3, heading: str) -> Node3 | None:
    """The valid node one step ``heading`` from ``node`` along its link (the level the
    link reaches: up a ramp, onto a deck), None where the link is blocked."""
    lv, i, j = node
    di, dj = STEPS[heading]
    ni, nj = i + di, j + dj
    if not (0 <= ni < grid.nz and 0 <= nj < grid.nx):
        return None
    to = int(grid.links()[lv, i, j, _DIR[heading]])
    return (to, ni, nj) if to >= 0 and grid.valid[to, ni, nj] else None


def nodes_ahead3(grid: NavGrid, node: Node3, heading: str) -> int:
    """Free nodes after ``node`` on its level before a wall or an edge, travelling ``heading``."""
    if not grid.valid[node]:
        return 0
    return run_ahead(grid.row_index[node], grid.col_index[node], grid.row_total[node], grid.col_total[node],
                     heading)


def _diagonal(grid: NavGrid, node: Node3, first: str, second: str) -> Node3 | None:
    """The node a step ``first`` then ``second`` away along links (either way round)."""
    for a, b in ((first, second), (second, first)):
        mid = step3(grid, node, a)
        end = step3(grid, mid, b) if mid is not None else None
        if end is not None:
            return end
    return None


def children3(grid: NavGrid, node: Node3, heading: str) -> list[Child]:
    """:func:`children` on a layered grid (nodes ``(level, i, j)``): the ahead-left, ahead
    and ahead-right nodes reached along the links from ``node``, so the decision never
    leaves the tank's level but where a ramp or a step links it to another."""
    h = _check(heading)
    out = []
    for name, side in (("left", turn_left(h)), ("ahead", None), ("right", turn_right(h))):
        c = step3(grid, node, h) if side is None else _diagonal(grid, node, h, side)
        if c is not None:
            travel = side or h
            out.append(Child(name, c, travel, nodes_ahead3(grid, c, travel)))  # type: ignore[arg-type]
    return out


def turn_in_place3(grid: NavGrid, node: Node3, heading: str) -> Node3 | None:
    """:func:`choose_next`'s turn when nothing ahead is valid, on a layered grid: the
    linked side neighbour with more room (right on ties), else the one behind."""
    h = _check(heading)
    side = {}
    for name, t in (("right", turn_right(h)), ("left", turn_left(h))):
        n = step3(grid, node, t)
        if n is not None:
            side[name] = (n, nodes_ahead3(grid, n, t))
    if side:
        name = max(side, key=lambda k: (side[k][1], k == "right"))
        return side[name][0]
    return step3(grid, node, turn_right(turn_right(h)))
