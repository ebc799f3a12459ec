"""The bindings remap screen: choose an action, press the input that should do it.

:class:`Remap` owns the screen's cursor and whether it waits for a press; the window
saves the bindings and says so (``App._handle_remap``).  Escape cancels a wait and
leaves the screen; it stays unbindable here so the player can always get out.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import pygame

from .hud import text
from .input import ACTIONS, Bindings, describe, input_name
from .menu import BG, HELP, HILITE, PLAIN


@dataclass
class Remap:
    cursor: int = 0
    waiting: bool = False

    def handle(self, event: Any, bindings: Bindings) -> str | None:
        """One event.  Returns "back" (leave the screen), "remapped" (the action under
        the cursor has a new input in ``bindings``), or None."""
        if self.waiting:
            if event.type == pygame.KEYDOWN and event.key == pygame.K_ESCAPE:
                self.waiting = False          # cancelled; Escape itself stays unbindable here
                return None
            name = input_name(event)
            if name is None:
                return None
            bindings.remap(ACTIONS[self.cursor], name)
            self.waiting = False
            return "remapped"
        if event.type == pygame.KEYDOWN:
            if event.key in (pygame.K_UP, pygame.K_w):
                self.cursor = (self.cursor - 1) % len(ACTIONS)
            elif event.key in (pygame.K_DOWN, pygame.K_s):
                self.cursor = (self.cursor + 1) % len(ACTIONS)
            elif event.key in (pygame.K_RETURN, pygame.K_SPACE, pygame.K_KP_ENTER):
                self.waiting = True
            elif event.key == pygame.K_ESCAPE:
                return "back"
        elif event.type == pygame.JOYBUTTONDOWN and event.button == 0:
            self.waiting = True
        return None

    def said(self, bindings: Bindings) -> str:
        """The line saying what the action under the cursor is bound to now."""
        action = ACTIONS[self.cursor]
        return f"{action.upper().replace('_', ' ')} = {describe(bindings.inputs(action))}"

    def draw(self, surf: "pygame.Surface", bindings: Bindings, notice: str = "") -> None:
        surf.fill(BG)
        w, h = surf.get_size()
        text(surf, "bindings", (w // 2, 30), 56, anchor="midtop")
        y = 90
        line = max(min(30, (h - 260) // len(ACTIONS)), 14)
        for i, action in enumerate(ACTIONS):
            colour = HILITE if i == self.cursor else PLAIN
            text(surf, action.replace('_', ' '), (w // 2 - 260, y), line, colour)
            text(surf, describe(bindings.inputs(action)), (w // 2 - 20, y), line, colour)
            y += line
        if self.waiting:
            text(surf, f"press the button for {ACTIONS[self.cursor].upper().replace('_', ' ')}",
                 (w // 2, h - 100), 40, HILITE, anchor="midtop")
        else:
            text(surf, "Enter: remap   Esc: back", (w // 2, h - 100), 26, HELP, anchor="midtop")
        if notice:
            text(surf, notice, (w // 2, h - 50), 22, (170, 220, 170), anchor="midtop")
