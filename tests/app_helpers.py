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


def match_config(arena="box", vehicle=None, bots=3, seed=0, view="top", size=(320, 240), difficulty="normal",
                 bot="agent", seconds=None, rules=None, record=None, replay=None, replay_name="", quality=None, sound=False, watch=None):
    """A MatchConfig from the few choices a test names (no sound: tests have no audio device)."""
    from tanktool.game.config import MatchConfig, Opponents, Recording, ViewConfig

    return MatchConfig(arena=arena, vehicle=vehicle, opponents=Opponents(bots, difficulty, bot), seed=seed,
                       rules=rules, seconds=seconds, view=ViewConfig(view, tuple(size), False, quality),
                       recording=Recording(record=record, replay=replay, replay_name=replay_name), sound=sound,
                       watch=watch)
