"""The end-of-match screen: why the match ended and the final scoreboard.

Rank, tank, kills, deaths, shots, hits and accuracy, best first (kills, then fewest
deaths); the winner's row is marked, the player's in their colour.  Enter (or a
click) goes back to the menu, R plays the same match again, Q quits.
"""

from __future__ import annotations

from typing import Any

import pygame

from .hud import panel, text
from .menu import BG, HELP, HILITE
from .session import tank_colour


def final_rows(session: Any) -> list[dict[str, Any]]:
    """The scoreboard as dicts (name, index, kills, deaths, shots, hits, accuracy), best first."""
    tanks = {t.name: t for t in session.world.tanks}
    rows = []
    for name, kills, deaths, _hp, _alive in session.scoreboard():
        t = tanks.get(name)
        shots = int(getattr(t, "shots", 0)) if t is not None else 0
        hits = int(getattr(t, "hits", 0)) if t is not None else 0
        rows.append({"name": name, "index": t.index if t is not None else 0, "kills": int(kills),
                     "deaths": int(deaths), "shots": shots, "hits": hits,
                     "accuracy": hits / shots if shots else None})
    return rows


def winner(session: Any) -> int | None:
    """The index of the match's winner, as the report names it (``sim.match.make_report``):
    the tank alone at the top of the standings with at least one kill; None for a draw
    (equal kills and deaths at the top) or a match nobody scored in."""
    world = getattr(session, "world_all", session.world)
    match = getattr(world, "match", None)
    if match is None:
        return None
    lead = match.winner if match.over else match.leader(world)
    return lead if lead is not None and world.tanks[lead].kills > 0 else None


def result_line(session: Any) -> str:
    """Who won, for the end screen: "bot1 wins", or "a draw"."""
    w = winner(session)
    return f"{getattr(session, 'world_all', session.world).tanks[w].name} wins" if w is not None else "a draw"


def end_reason(session: Any, seconds: float | None = None) -> str | None:
    """Why the match in ``session`` is over and who won, or None while it goes on:
    ``seconds`` of simulated time are up (``play --seconds``), or the simulation's rules
    ended it (``world.match``: a time or score limit)."""
    if session is None:
        return None
    if seconds is not None and session.world.steps * session.dt >= seconds - 1e-9:
        return f"time up: the match lasted {seconds:g} s (--seconds): {result_line(session)}"
    w = getattr(session, "world_all", getattr(session, "world", None))
    m = getattr(w, "match", None)
    if m is None or not m.over:
        return None
    why = {"time": "time up", "score": "score limit reached"}.get(m.reason, "the match is over")
    return f"{why}: {result_line(session)}"


def draw_end(app: Any, surf: "pygame.Surface") -> None:
    surf.fill(BG)
    w, h = surf.get_size()
    big = max(min(64, h // 9), 26)
    text(surf, "MATCH OVER", (w // 2, 18), big, HILITE, anchor="midtop")
    text(surf, app.over_reason or "", (w // 2, 24 + big), 24, HELP, anchor="midtop")
    session = app.session
    if session is None:
        return
    rows = final_rows(session)
    line = max(min(30, (h - 200) // max(len(rows) + 1, 1)), 14)
    size = max(int(line * 0.85), 13)
    x = w // 2 - min(300, w // 2 - 10)
    y = 40 + big + 30
    cols = (0, 50, 200, 260, 320, 390, 450)
    player = getattr(session, "player", None)
    best = winner(session)
    table = [(("#", "tank", "K", "D", "shots", "hits", "accuracy"), HELP)]
    for rank, r in enumerate(rows, 1):
        acc = f"{100 * r['accuracy']:.0f} %" if r["accuracy"] is not None else "-"
        cells = (rank, r["name"] + ("  (winner)" if r["index"] == best else ""), r["kills"],
                 r["deaths"], r["shots"], r["hits"], acc)
        table.append((cells, tank_colour(r["index"]) if r["index"] == player else (230, 230, 225)))
    panel(surf, pygame.Rect(x, y, min(cols[-1] + 110, w - x), line * len(table)), (30, 36, 34, 255))
    for cells, colour in table:
        for c, dx in zip(cells, cols):
            text(surf, str(c), (x + dx, y), size, colour)
        y += line
    text(surf, "Enter or click: menu    R: play again    Q: quit", (w // 2, h - 40), 22, HELP, anchor="midtop")
