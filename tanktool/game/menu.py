"""The start menu and the settings page: drawing them and what keys, joystick and
mouse do there.

The main menu lists the match's choices on the left and shows rendered previews of
the chosen arena and vehicle on the right (game/thumbnails.py).  Keys: up/down (W/S)
choose, left/right (A/D) change, Enter selects, Esc quits; the joystick's hat and
button 0 do the same.  The mouse: pointing at an item selects it, a click on ``<`` or
``>`` (or the right button) changes a choice, a click elsewhere on it moves it on, the
wheel turns it, a click on a preview shows the next arena or vehicle, and a click on a
field (address, name, password) starts typing there.

The settings page holds the graphics quality (a preset, and shadows or particles
overriding it), the resolution and full screen, and the sound: master, effects and
music volumes and mute; every change is saved at once to ``settings.toml``
(game/quality.py), the sound's heard at once, the rest used from the next match on.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import pygame

from .hud import panel, text
from .quality import NAME_CHARS, PARTICLES, PRESETS, SHADOWS, Settings
from .session import DIFFICULTY

BG = (18, 22, 20)
HILITE = (250, 210, 70)
PLAIN = (220, 220, 220)
HELP = (170, 170, 170)
ADDRESS_CHARS = set("0123456789.:abcdefghijklmnopqrstuvwxyz")
MAX_PASSWORD = 64
FIELDS = ("address", "name", "password")
ACTION_LABELS = {"settings": "settings...", "bindings": "key and joystick bindings...", "start": "START", "quit": "quit",
                 "back": "back"}
SETTINGS_ITEMS = ("quality", "shadows", "particles", "resolution", "fullscreen", "master_volume", "effects_volume",
                  "music_volume", "mute", "back")
#: a volume step on the settings page
VOLUME_STEP = 0.1
RESOLUTIONS = ["1280x720", "1600x900", "1920x1080", "1024x576", "800x600"]
#: the menu's network address: host on it, or join the session there
DEFAULT_ADDRESS = "127.0.0.1:5000"


# ---------------------------------------------------------------- state
@dataclass
class Choice:
    label: str
    options: list[Any]
    index: int = 0

    @property
    def value(self) -> Any:
        return self.options[self.index]

    def shift(self, d: int) -> None:
        self.index = (self.index + d) % len(self.options)

    def set(self, value: Any) -> None:
        if value in self.options:
            self.index = self.options.index(value)


@dataclass
class Menu:
    """The start menu and the settings page: their choices (the 2002 game let the
    player pick vehicle and arena), cursors, the field being typed into and the
    clickable rectangles last drawn.  The handlers below change only this; they tell
    the window what to do next by the action they return."""

    arena: Choice
    vehicle: Choice
    bots: Choice = field(default_factory=lambda: Choice("opponents", list(range(0, 8)), 3))
    #: who drives the first opponents: () the built-in computer players, or bot specs
    #: (a bot file of the user's bots folder or the examples, game/bot_files.py; play --bot's)
    bot_file: Choice = field(default_factory=lambda: Choice("opponent bot", [()]))
    difficulty: Choice = field(default_factory=lambda: Choice("difficulty", list(DIFFICULTY), 1))
    view: Choice = field(default_factory=lambda: Choice("view", ["3d", "top"]))
    resolution: Choice = field(default_factory=lambda: Choice("resolution", list(RESOLUTIONS)))
    fullscreen: Choice = field(default_factory=lambda: Choice("fullscreen", [False, True]))
    #: network play: off, host a session (listening on ``address``), or join the one at ``address``
    network: Choice = field(default_factory=lambda: Choice("network", ["off", "host", "join"]))
    address: str = DEFAULT_ADDRESS
    #: the network session's password ("" for none), typed into a field that shows only stars
    password: str = ""
    #: the player's name in a network session (saved in the settings)
    name: str = ""
    cursor: int = 0
    settings_cursor: int = 0
    #: clickable rectangles of the page last drawn: (item index, rect), (kind, rect)
    hits: list[Any] = field(default_factory=list)
    preview_hits: list[Any] = field(default_factory=list)
    #: typing into a field: ``field`` says which ("address", "name" or "password");
    #: last, as the name hides dataclasses.field in the class body
    editing: bool = False
    field: str = "address"

    #: the main menu; resolution and full screen are on the settings page
    ITEMS = ("arena", "vehicle", "bots", "bot_file", "difficulty", "view", "network", "address", "name", "password",
             "settings", "bindings", "start", "quit")
    CHOICES = ("arena", "vehicle", "bots", "bot_file", "difficulty", "view", "network")

    def item(self) -> str:
        return self.ITEMS[self.cursor]

    def size(self) -> tuple[int, int]:
        w, h = (int(v) for v in str(self.resolution.value).split("x"))
        return w, h


def menu_for(cfg: Any, settings: Settings, arenas: list[str], vehicles: list[str]) -> Menu:
    """The menu's first values: a ``game.config.MatchConfig``'s, the settings' where it
    names none (``arenas``, ``vehicles``: the bundled names to choose from)."""
    from ..sim.match import default_arena, default_vehicle
    from .config import DEFAULT_SIZE

    size = cfg.view.size
    if tuple(size) == DEFAULT_SIZE and settings.resolution:
        size = tuple(int(v) for v in settings.resolution.split("x"))   # --size overrides the saved one
    arena, vehicle = cfg.arena, cfg.vehicle
    m = Menu(Choice("arena", arenas + ([arena] if arena and arena not in arenas else [])),
             Choice("vehicle", vehicles + ([vehicle] if vehicle and vehicle not in vehicles else []) or [None]))
    m.arena.set(arena or default_arena())
    m.vehicle.set(vehicle or default_vehicle())
    m.bots.set(min(max(cfg.opponents.count, 0), 7))
    from .bot_files import find_bots

    # the bot files found (play --bot's specs first, chosen, when given)
    m.bot_file.options = [()] + [(spec,) for spec in find_bots()]
    if cfg.opponents.bots:
        m.bot_file.options.insert(1, tuple(cfg.opponents.bots))
        m.bot_file.index = 1
    m.view.set(cfg.view.mode)
    # a first start offers easy; then the menu's last choice (--difficulty wins)
    m.difficulty.set(cfg.opponents.difficulty or settings.difficulty or "easy")
    res = f"{size[0]}x{size[1]}"
    if res not in m.resolution.options:
        m.resolution.options.insert(0, res)
    m.resolution.set(res)
    m.fullscreen.set(cfg.view.fullscreen or settings.fullscreen)
    m.name = settings.name
    if cfg.network is not None:
        m.network.set(cfg.network.mode)
        m.address = cfg.network.address
        m.name = cfg.network.name or m.name
        m.password = cfg.network.password or ""
    return m


# ---------------------------------------------------------------- labels
def _shown(value: Any) -> str:
    if isinstance(value, bool):
        return "on" if value else "off"
    if value is None:
        return "built-in box tank"
    return str(value)


def item_label(m: Menu, item: str, selected: bool) -> tuple[str, str]:
    """(label, value) of a main-menu item, as drawn in two columns."""
    if item in ACTION_LABELS:
        label = ACTION_LABELS[item]
        if item == "start" and m.network.value != "off":
            label = f"START: {m.network.value} {m.address}"
        return label, ""
    if item in FIELDS:
        typing = m.editing and m.field == item
        value = getattr(m, item)
        if item == "password":
            shown = "*" * len(value) + ("_" if typing else "") if value or typing else "none"
        elif item == "name":
            shown = value + ("_" if typing else "") if value or typing else "(for network play)"
        else:
            shown = value + ("_" if typing else "")
        return item, f"[ {shown} ]" + ("" if m.editing or not selected else "  Enter: type")
    c = getattr(m, item)
    if item == "bot_file":
        from .bot_files import short

        return c.label, f"<  {', '.join(short(b) for b in c.value) or 'built-in (difficulty below)'}  >"
    return c.label, f"<  {_shown(c.value)}  >"


def settings_label(m: Menu, s: Settings, item: str) -> tuple[str, str]:
    if item == "back":
        return "back", ""
    if item == "quality":
        return "quality", f"<  {s.quality}  >"
    if item in ("shadows", "particles"):
        v = getattr(s, item)
        preset = getattr(PRESETS[s.quality], item)
        return item, f"<  {v if v is not None else f'as the preset ({preset})'}  >"
    if item.endswith("_volume"):
        label = item.replace("_", " ")
        return label, f"<  {round(100 * getattr(s, item)):d} %  >" + ("  (muted)" if s.mute else "")
    if item == "mute":
        return "mute", f"<  {_shown(s.mute)}  >"
    c = getattr(m, item)
    return c.label, f"<  {_shown(c.value)}  >"


# ---------------------------------------------------------------- drawing
def _list(surf: "pygame.Surface", labels: list[tuple[str, str]], cursor: int, x: int, y: int, line: int,
          size: int) -> list[tuple[int, "pygame.Rect"]]:
    """Draw a list of (label, value) in two columns; return each item's clickable rectangle."""
    hits = []
    w = surf.get_width()
    column = max(int(size * 6.2), 90)
    for i, (label, value) in enumerate(labels):
        colour = HILITE if i == cursor else PLAIN
        if i == cursor:
            text(surf, ">", (x - size // 2 - 4, y), size, colour)
        r = text(surf, label, (x, y), size, colour)
        if value:
            r = r.union(text(surf, value, (x + column, y), size, colour))
        hits.append((i, pygame.Rect(x, y - 2, max(r.right - x, int(w * 0.38)), line)))
        y += line
    return hits


Preview = Callable[[str, Any, tuple[int, int]], "pygame.Surface | None"]


def draw_menu(m: Menu, surf: "pygame.Surface", preview: Preview, notice: str = "") -> None:
    """The main menu; ``preview(kind, ref, size)`` renders an arena's or vehicle's picture
    (None while it is being made)."""
    surf.fill(BG)
    w, h = surf.get_size()
    title = max(min(72, h // 8), 28)
    text(surf, "tanktool", (w // 2, 16), title, anchor="midtop")
    top = 16 + title + 14
    items = m.ITEMS
    line = max(min(36, (h - top - 70) // len(items)), 14)
    size = max(int(line * 0.8), 13)
    wide = w >= 640
    x = int(w * 0.06) if wide else 18
    m.hits = _list(surf, [item_label(m, it, i == m.cursor) for i, it in enumerate(items)], m.cursor,
                   x, top, line, size)
    m.preview_hits = []
    if wide:
        # two 16:9 pictures one above the other, as large as the window lets them be
        ph = min(int(w * 0.36) * 9 // 16, (h - top - 80) // 2 - 24)
        pw = ph * 16 // 9
        px = w - pw - int(w * 0.05)
        py = top
        for kind, choice in (("arenas", m.arena), ("vehicles", m.vehicle)):
            pic = preview(kind, choice.value, (pw, ph))
            rect = pygame.Rect(px, py, pw, ph)
            pygame.draw.rect(surf, (70, 80, 74), rect.inflate(6, 6), 3)
            if pic is None:                      # rendered on the next frame: the menu shows first
                surf.fill((40, 44, 42), rect)
                text(surf, "rendering preview...", rect.center, 24, HELP, anchor="center")
            else:
                surf.blit(pic, rect)
            caption = f"{'arena' if kind == 'arenas' else 'vehicle'}: {_shown(choice.value)}"
            text(surf, caption, (rect.x + 8, rect.bottom - 6), 24, anchor="bottomleft")
            m.preview_hits.append((kind, rect))
            py += ph + 24
    text(surf, "up/down choose, left/right or mouse change, Enter or click select, Esc quit", (w // 2, h - 56),
         max(min(22, w // 40), 14), HELP, anchor="midtop")
    if notice:
        text(surf, notice, (w // 2, h - 30), 22, (240, 160, 120), anchor="midtop")


def draw_settings(m: Menu, settings: Settings, surf: "pygame.Surface", notice: str = "") -> None:
    surf.fill(BG)
    w, h = surf.get_size()
    text(surf, "settings", (w // 2, 24), max(min(60, h // 9), 26), anchor="midtop")
    # the list, then three lines of notes, then the footer: all fit the window
    line = max(min(40, (h - 100 - 16 - 3 * 26 - 70) // len(SETTINGS_ITEMS)), 16)
    x = int(w * 0.12) if w >= 640 else 18
    m.hits = _list(surf, [settings_label(m, settings, it) for it in SETTINGS_ITEMS], m.settings_cursor,
                   x, 100, line, max(int(line * 0.8), 13))
    q = settings.graphics()
    lines = [f"shadows {q.shadows} ({q.shadow_size or 'no'} map), particles {q.particles}, sky {q.sky}, "
             f"arena lit per {q.arena_light}",
             "low keeps software OpenGL (Mesa llvmpipe) fastest; high is everything on",
             "effects and music play at their volume times the master's; mute silences both"]
    y = 100 + line * len(SETTINGS_ITEMS) + 16
    rects = [text(surf, s, (x, y + 26 * i), 22, HELP) for i, s in enumerate(lines)]
    panel(surf, rects[0].unionall(rects[1:]), (30, 36, 34, 255))
    for i, s in enumerate(lines):
        text(surf, s, (x, y + 26 * i), 22, HELP)
    text(surf, "saved at once; a new resolution opens with the next match.   Esc: back", (w // 2, h - 56), 20,
         HELP, anchor="midtop")
    if notice:
        text(surf, notice, (w // 2, h - 30), 22, (170, 220, 170), anchor="midtop")


# ---------------------------------------------------------------- input
def _choice_step(event: Any) -> int:
    if event.type == pygame.KEYDOWN:
        return {pygame.K_LEFT: -1, pygame.K_RIGHT: 1, pygame.K_a: -1, pygame.K_d: 1}.get(event.key, 0)
    if event.type == getattr(pygame, "MOUSEWHEEL", -1):
        return 1 if getattr(event, "y", 0) > 0 else -1 if getattr(event, "y", 0) < 0 else 0
    return 0


def _hit(m: Menu, pos: tuple[int, int]) -> int | None:
    for i, rect in m.hits:
        if rect.collidepoint(pos):
            return i
    return None


def _click_step(rect: "pygame.Rect", pos: tuple[int, int], button: int) -> int:
    """A click on a choice: on its label or value's left half (or with the right
    button) goes back, on the right half on."""
    if button == 3 or pos[0] < rect.x + rect.w * 0.45:
        return -1
    return 1


def type_into(m: Menu, event: Any) -> str | None:
    """A key while typing into the address, name or password field; returns "name"
    when the name has been typed (the window keeps it in the settings)."""
    if event.type != pygame.KEYDOWN:
        return None
    field = m.field
    value = getattr(m, field)
    if event.key in (pygame.K_RETURN, pygame.K_KP_ENTER, pygame.K_ESCAPE, pygame.K_TAB):
        m.editing = False
        if field == "address":
            m.address = m.address.strip() or DEFAULT_ADDRESS
        return "name" if field == "name" else None
    if event.key == pygame.K_BACKSPACE:
        setattr(m, field, value[:-1])
        return None
    ch = getattr(event, "unicode", "") or ""
    if field == "address":
        ch = ch.lower()
        if len(ch) == 1 and ch in ADDRESS_CHARS and len(value) < 40:
            m.address += ch
    elif field == "name":
        if len(ch) == 1 and NAME_CHARS.match(value + ch):
            m.name += ch
    elif len(ch) == 1 and ch.isprintable() and len(value) < MAX_PASSWORD:
        m.password += ch
    return None


def handle_menu(m: Menu, event: Any) -> str | None:
    """One event on the main menu.  Returns what the window should do: "start",
    "quit", "settings", "bindings", "name" (the player's name was typed), or None."""
    if m.editing:
        if event.type == pygame.MOUSEBUTTONDOWN:
            m.editing = False               # a click elsewhere ends the typing
        else:
            return type_into(m, event)
    step = _choice_step(event)
    if event.type == pygame.KEYDOWN:
        if event.key in (pygame.K_UP, pygame.K_w):
            m.cursor = (m.cursor - 1) % len(m.ITEMS)
        elif event.key in (pygame.K_DOWN, pygame.K_s):
            m.cursor = (m.cursor + 1) % len(m.ITEMS)
        elif event.key in (pygame.K_RETURN, pygame.K_SPACE, pygame.K_KP_ENTER):
            return activate(m)
        elif event.key == pygame.K_ESCAPE:
            return "quit"
    elif event.type == pygame.JOYHATMOTION:
        hx, hy = event.value
        m.cursor = (m.cursor - hy) % len(m.ITEMS)
        step = hx
    elif event.type == pygame.JOYBUTTONDOWN and event.button == 0:
        return activate(m)
    elif event.type == pygame.MOUSEMOTION:
        i = _hit(m, event.pos)
        if i is not None:
            m.cursor = i
    elif event.type == pygame.MOUSEBUTTONDOWN and event.button in (1, 3):
        for kind, rect in m.preview_hits:
            if rect.collidepoint(event.pos):
                (m.arena if kind == "arenas" else m.vehicle).shift(1 if event.button == 1 else -1)
                return None
        i = _hit(m, event.pos)
        if i is None:
            return None
        m.cursor = i
        if m.item() in m.CHOICES:
            rect = dict(m.hits)[i]
            step = _click_step(rect, event.pos, event.button)
        elif event.button == 1:
            return activate(m)
    if step and m.item() in m.CHOICES:
        getattr(m, m.item()).shift(step)
    return None


def activate(m: Menu) -> str | None:
    """Enter on the item under the cursor: start typing into a field, or the action
    the window carries out ("start", "settings", "bindings", "quit")."""
    item = m.item()
    if item in FIELDS:
        m.editing, m.field = True, item
        setattr(m, item, "")
        return None
    if item == "settings":
        m.settings_cursor = 0
    return item if item in ("start", "settings", "bindings", "quit") else None


def handle_settings(m: Menu, settings: Settings, event: Any) -> str | None:
    """One event on the settings page.  Returns "back", the name of the setting that
    was changed (the window saves and applies it), or None."""
    n = len(SETTINGS_ITEMS)
    step = _choice_step(event)
    enter = False
    if event.type == pygame.KEYDOWN:
        if event.key in (pygame.K_UP, pygame.K_w):
            m.settings_cursor = (m.settings_cursor - 1) % n
        elif event.key in (pygame.K_DOWN, pygame.K_s):
            m.settings_cursor = (m.settings_cursor + 1) % n
        elif event.key in (pygame.K_RETURN, pygame.K_SPACE, pygame.K_KP_ENTER):
            enter = True
        elif event.key == pygame.K_ESCAPE:
            return "back"
    elif event.type == pygame.JOYHATMOTION:
        hx, hy = event.value
        m.settings_cursor = (m.settings_cursor - hy) % n
        step = hx
    elif event.type == pygame.JOYBUTTONDOWN and event.button == 0:
        enter = True
    elif event.type == pygame.MOUSEMOTION:
        i = _hit(m, event.pos)
        if i is not None:
            m.settings_cursor = i
    elif event.type == pygame.MOUSEBUTTONDOWN and event.button in (1, 3):
        i = _hit(m, event.pos)
        if i is None:
            return None
        m.settings_cursor = i
        if SETTINGS_ITEMS[i] == "back":
            enter = True
        else:
            step = _click_step(dict(m.hits)[i], event.pos, event.button)
    item = SETTINGS_ITEMS[m.settings_cursor]
    if item == "back":
        return "back" if enter else None
    if enter and not step:
        step = 1
    if not step:
        return None
    change_setting(m, settings, item, step)
    return item


def change_setting(m: Menu, s: Settings, item: str, step: int) -> None:
    """Turn one setting by ``step``."""
    if item == "quality":
        names = list(PRESETS)
        s.quality = names[(names.index(s.quality) + step) % len(names)]
        s.shadows = s.particles = None            # a preset's own choices
    elif item in ("shadows", "particles"):
        options = [None, *(SHADOWS if item == "shadows" else PARTICLES)]
        cur = getattr(s, item)
        setattr(s, item, options[(options.index(cur) + step) % len(options)])
    elif item.endswith("_volume"):
        setattr(s, item, round(min(max(getattr(s, item) + step * VOLUME_STEP, 0.0), 1.0), 2))
    elif item == "mute":
        s.mute = not s.mute
    else:
        c = getattr(m, item)
        c.shift(step)
        if item == "resolution":
            s.resolution = str(c.value)
        else:
            s.fullscreen = bool(c.value)
