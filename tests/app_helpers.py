"""Synthetic keyboard input for the game window's tests (SDL's dummy video driver)."""

from __future__ import annotations

import pygame


def key(k: int, down: bool = True, uni: str = "") -> pygame.event.Event:
    return pygame.event.Event(pygame.KEYDOWN if down else pygame.KEYUP, key=k, mod=0, unicode=uni, scancode=0)


def press(app, k: int, uni: str = "") -> None:
    """A key pressed and released (``uni``: the character it types)."""
    app.handle(key(k, uni=uni))
    app.handle(key(k, down=False))


def goto(app, item: str) -> None:
    """Move the menu's cursor down to ``item``."""
    while app.menu.item() != item:
        press(app, pygame.K_DOWN)
