"""The controls overlay: what each key does, from the player's own bindings.

It shows by itself over a player's first match (``Settings.controls_seen`` then
remembers it was seen) for ``FIRST_S`` seconds or until F1, and F1 (the ``help``
action) shows or hides it at any time.  The rows come from the bindings, so a
remapped key reads as the player set it.
"""

from __future__ import annotations

import pygame

from .hud import DIM, TEXT, font, panel, text
from .input import Bindings, describe

#: seconds the overlay stays over a first match unless F1 hides it
FIRST_S = 20.0
#: (label, actions) a row each: the actions' inputs are joined on the row
ROWS = (
    ("drive forward / back", ("advance", "reverse")),
    ("turn left / right", ("turn_left", "turn_right")),
    ("strafe left / right", ("strafe_left", "strafe_right")),
    ("fire", ("fire",)),
    ("pause, restart, menu", ("pause",)),
    ("camera: chase, 1st person, above", ("camera",)),
    ("3D or top view", ("view",)),
    ("these controls", ("help",)),
)


def controls_rows(bindings: Bindings) -> list[tuple[str, str]]:
    """(what it does, the inputs that do it) for the overlay, from ``bindings``."""
    rows = []
    for label, actions in ROWS:
        keys = []
        for a in actions:
            names = bindings.inputs(a)
            # keys and mouse first (the joystick's are on the bindings page): a narrow panel
            own = [n for n in names if n.startswith(("key:", "mouse:"))][:2] or names[:2]
            keys.append(describe(own))
        rows.append((label, " / ".join(keys)))
    return rows


def draw_controls(surface: "pygame.Surface", rows: list[tuple[str, str]]) -> "pygame.Rect":
    """The overlay in the left half of the screen, under the top-left counters;
    returns the rectangle it covers."""
    w, h = surface.get_size()
    size = max(min(24, h // 30), 14)
    line = size + 4
    x, y = max(int(w * 0.03), 12), max(int(h * 0.2), 100)
    column = max(font(size).size(label)[0] for label, _ in rows) + size
    title = text(surface, "CONTROLS", (x, y), size + 6, (250, 210, 70))
    drawn = [title]
    y += line + 10
    for label, keys in rows:
        drawn.append(text(surface, label, (x, y), size, DIM))
        drawn.append(text(surface, keys, (x + column, y), size, TEXT))
        y += line
    for k, hint in enumerate(("aim by turning: the crosshair marks where", "your shell would hit.  F1 hides this")):
        drawn.append(text(surface, hint, (x, y + 6 + k * (size - 2)), max(size - 4, 12), DIM))
    box = drawn[0].unionall(drawn[1:])
    under = surface.subsurface(box.clip(surface.get_rect())).copy()
    r = panel(surface, box, (8, 10, 12, 190)).clip(surface.get_rect())
    surface.blit(under, box.topleft)
    return r

