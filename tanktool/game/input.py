"""The input layer: keyboard, mouse and joystick events become game actions and
:class:`~tanktool.sim.commands.Command` values; game code never sees a key code.

Every physical input has a name:

- ``key:<pygame key name>`` (``key:w``, ``key:up``, ``key:space``)
- ``mouse:<button>`` (``mouse:1`` is the left button), and ``mouse:x+`` / ``mouse:x-`` /
  ``mouse:y+`` / ``mouse:y-`` for moving the mouse (strength: pixels moved during the
  frame over ``MOUSE_FULL``; the window calls :meth:`InputState.end_frame` after each frame)
- ``joybutton:<n>``, and ``joyaxis:<n>+`` / ``joyaxis:<n>-`` for one half of an axis

and :class:`Bindings` maps each action to a list of names.  Driving actions are
analogue: an action's strength is the largest of its inputs (keys and buttons 1, an
axis half its deflection beyond the dead zone), and ``advance = advance − reverse``
etc.  Menu actions (pause, camera, view, overlays) fire once on press.

Bindings live in ``$XDG_CONFIG_HOME/tanktool/bindings.toml`` (``~/.config/...`` when
the variable is unset), written atomically; a missing file means the defaults.
Joysticks are opened as they are plugged in (``JOYDEVICEADDED``) and forgotten when
pulled out, so hot-plugging needs nothing from the player.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable

from ..errors import FormatError
from ..sim.commands import Command

DRIVE_ACTIONS = ("advance", "reverse", "turn_left", "turn_right", "strafe_left", "strafe_right", "fire")
MENU_ACTIONS = ("pause", "help", "camera", "view", "overlay_quadtree", "overlay_navgrid", "overlay_agents", "quit")
ACTIONS = DRIVE_ACTIONS + MENU_ACTIONS

DEFAULTS: dict[str, list[str]] = {
    "advance": ["key:w", "key:up", "joyaxis:1-"],
    "reverse": ["key:s", "key:down", "joyaxis:1+"],
    "turn_left": ["key:a", "key:left", "joyaxis:0-"],
    "turn_right": ["key:d", "key:right", "joyaxis:0+"],
    "strafe_left": ["key:q", "joybutton:4"],
    "strafe_right": ["key:e", "joybutton:5"],
    "fire": ["key:space", "joybutton:0", "mouse:1"],
    "pause": ["key:p", "key:escape", "joybutton:7"],
    "help": ["key:f1", "joybutton:6"],
    "camera": ["key:c", "joybutton:3"],
    "view": ["key:v"],
    "overlay_quadtree": ["key:f2"],
    "overlay_navgrid": ["key:f3"],
    "overlay_agents": ["key:f4"],
    "quit": ["key:f10"],
}
INPUT_NAME = re.compile(r"^(key:.+|mouse:\d{1,4}|mouse:[xy][+-]|joybutton:\d{1,4}|joyaxis:\d{1,4}[+-])$")
#: inputs one action may be bound to
MAX_INPUTS = 16
#: mouse travel in one frame [px] that counts as a full-strength action
MOUSE_FULL = 24.0
#: a mouse move this long in one event is a deliberate choice on the remap screen
MOUSE_PRESS = 40
DEADZONE = 0.15
#: an axis pushed this far counts as a press when remapping or for menu actions
AXIS_PRESS = 0.6


def config_dir() -> Path:
    """The user's tanktool config folder (XDG base directory spec)."""
    base = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    return Path(base) / "tanktool"


def bindings_path() -> Path:
    return config_dir() / "bindings.toml"


@dataclass
class Bindings:
    """Action -> input names, plus the joystick dead zone."""

    actions: dict[str, list[str]] = field(default_factory=lambda: {a: list(v) for a, v in DEFAULTS.items()})
    deadzone: float = DEADZONE

    def inputs(self, action: str) -> list[str]:
        return self.actions.get(action, [])

    def remap(self, action: str, name: str) -> None:
        """Make ``name`` the only input of ``action``, and take it away from any other
        action so one button never does two things."""
        if action not in ACTIONS:
            raise ValueError(f"unknown action {action!r}")
        for other, names in self.actions.items():
            if other != action and name in names:
                names.remove(name)
        self.actions[action] = [name]

    def to_dict(self) -> dict[str, Any]:
        return {"deadzone": self.deadzone, "actions": {a: list(self.actions.get(a, [])) for a in ACTIONS}}


def load_bindings(path: str | os.PathLike | None = None) -> Bindings:
    """Read the bindings file; defaults when it does not exist.  Actions the file does
    not name keep their defaults, so a file from an older version still works."""
    from ..formats.bundle import read_toml

    path = Path(path) if path is not None else bindings_path()
    if not path.is_file():
        return Bindings()
    doc = read_toml(path)
    b = Bindings()
    dz = doc.get("deadzone", DEADZONE)
    if not isinstance(dz, (int, float)) or isinstance(dz, bool) or not 0.0 <= dz < 1.0:
        raise FormatError(f"{path}: deadzone must be a number in [0, 1), got {dz!r:.60}")
    b.deadzone = float(dz)
    table = doc.get("actions", {})
    if not isinstance(table, dict):
        raise FormatError(f"{path}: [actions] must be a table of action = [input names]")
    for action, names in table.items():
        if action not in ACTIONS:
            raise FormatError(f"{path}: [actions] {str(action)[:60]}: unknown action (one of {', '.join(ACTIONS)})")
        if (not isinstance(names, list) or len(names) > MAX_INPUTS
                or not all(isinstance(n, str) and len(n) <= 64 and INPUT_NAME.match(n) for n in names)):
            raise FormatError(f"{path}: [actions] {action}: expected a list of at most {MAX_INPUTS} input names "
                              f"like \"key:w\", \"mouse:1\", \"joybutton:0\", \"joyaxis:1-\", got {names!r:.120}")
        b.actions[action] = list(names)
    return b


def save_config(path: Path, doc: dict[str, Any]) -> Path:
    """Write a config file atomically, creating its folder; returns the path."""
    from ..formats.bundle import output_error, write_toml

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:  # a parent that is a file, a read-only home: one OutputError naming the file
        raise output_error(path, e, "cannot make its folder") from None
    write_toml(path, doc)
    return path


def save_bindings(bindings: Bindings, path: str | os.PathLike | None = None) -> Path:
    """Write the bindings atomically (creating the config folder); returns the path."""
    return save_config(Path(path) if path is not None else bindings_path(), bindings.to_dict())


def input_name(event: Any) -> str | None:
    """The input name a *press* event stands for (for the remap screen), or None."""
    import pygame

    if event.type == pygame.KEYDOWN:
        return f"key:{pygame.key.name(event.key)}"
    if event.type == pygame.MOUSEBUTTONDOWN:
        return f"mouse:{event.button}"
    if event.type == pygame.MOUSEMOTION:
        dx, dy = event.rel
        if max(abs(dx), abs(dy)) >= MOUSE_PRESS:
            axis, v = ("x", dx) if abs(dx) >= abs(dy) else ("y", dy)
            return f"mouse:{axis}{'+' if v > 0 else '-'}"
        return None
    if event.type == pygame.JOYBUTTONDOWN:
        return f"joybutton:{event.button}"
    if event.type == pygame.JOYAXISMOTION and abs(event.value) >= AXIS_PRESS:
        return f"joyaxis:{event.axis}{'+' if event.value > 0 else '-'}"
    return None


class InputState:
    """Pressed keys and buttons, joystick axes, and the joysticks plugged in.

    Feed it every pygame event with :meth:`handle` (which returns the menu actions
    pressed by that event) and read :meth:`command` once per simulation step.
    """

    def __init__(self, bindings: Bindings | None = None) -> None:
        self.bindings = bindings or Bindings()
        self.pressed: set[str] = set()                 # key:, mouse:, joybutton: names held
        self.axes: dict[tuple[int, int], float] = {}   # (joystick instance, axis) -> value
        self.joy_buttons: dict[int, set[str]] = {}     # instance -> buttons held
        self.joysticks: dict[int, Any] = {}            # instance -> pygame Joystick
        self.mouse_move = [0.0, 0.0]                   # pixels moved during this frame

    # ------------------------------------------------------------------ events
    def handle(self, event: Any) -> list[str]:
        """Update the state from one event; return the menu actions it triggered."""
        import pygame

        t = event.type
        name: str | None = None
        if t == pygame.KEYDOWN:
            name = f"key:{pygame.key.name(event.key)}"
            self.pressed.add(name)
        elif t == pygame.KEYUP:
            self.pressed.discard(f"key:{pygame.key.name(event.key)}")
        elif t == pygame.MOUSEBUTTONDOWN:
            name = f"mouse:{event.button}"
            self.pressed.add(name)
        elif t == pygame.MOUSEBUTTONUP:
            self.pressed.discard(f"mouse:{event.button}")
        elif t == pygame.MOUSEMOTION:
            self.mouse_move[0] += float(event.rel[0])
            self.mouse_move[1] += float(event.rel[1])
        elif t == pygame.JOYBUTTONDOWN:
            name = f"joybutton:{event.button}"
            self.joy_buttons.setdefault(self._joy(event), set()).add(name)
        elif t == pygame.JOYBUTTONUP:
            self.joy_buttons.get(self._joy(event), set()).discard(f"joybutton:{event.button}")
        elif t == pygame.JOYAXISMOTION:
            key = (self._joy(event), int(event.axis))
            old = self.axes.get(key, 0.0)
            self.axes[key] = float(event.value)
            # an axis crossing the press threshold acts like a button for menu actions
            if abs(event.value) >= AXIS_PRESS > abs(old) or (old * event.value < 0 and abs(event.value) >= AXIS_PRESS):
                name = f"joyaxis:{event.axis}{'+' if event.value > 0 else '-'}"
        elif t == getattr(pygame, "JOYDEVICEADDED", -1):
            self._plug(event.device_index)
        elif t == getattr(pygame, "JOYDEVICEREMOVED", -1):
            self._unplug(event.instance_id)
        if name is None:
            return []
        return [a for a in MENU_ACTIONS if name in self.bindings.inputs(a)]

    @staticmethod
    def _joy(event: Any) -> int:
        return int(getattr(event, "instance_id", getattr(event, "joy", 0)))

    def _plug(self, device_index: int) -> None:
        import pygame

        try:
            js = pygame.joystick.Joystick(device_index)
            js.init()
        except pygame.error:
            return                  # gone again before we could open it
        self.joysticks[js.get_instance_id()] = js

    def _unplug(self, instance_id: int) -> None:
        self.joysticks.pop(instance_id, None)
        self.joy_buttons.pop(instance_id, None)
        for key in [k for k in self.axes if k[0] == instance_id]:
            del self.axes[key]

    def end_frame(self) -> None:
        """The frame's mouse travel has been used: the next frame starts from rest."""
        self.mouse_move = [0.0, 0.0]

    def release_all(self) -> None:
        """Forget held inputs (the window lost focus: keys released elsewhere never arrive)."""
        self.mouse_move = [0.0, 0.0]
        self.pressed.clear()
        self.joy_buttons.clear()
        self.axes.clear()

    # ------------------------------------------------------------------ reading
    def strength(self, action: str) -> float:
        """How hard an action is pressed, in [0, 1]."""
        best = 0.0
        held = self.pressed.union(*self.joy_buttons.values()) if self.joy_buttons else self.pressed
        dz = self.bindings.deadzone
        for name in self.bindings.inputs(action):
            if name.startswith("joyaxis:"):
                axis, sign = int(name[8:-1]), (1.0 if name[-1] == "+" else -1.0)
                for (_, a), v in self.axes.items():
                    if a == axis:
                        v = v * sign
                        if v > dz:
                            best = max(best, min((v - dz) / (1.0 - dz), 1.0))
            elif name.startswith("mouse:") and name[6] in "xy":
                v = self.mouse_move[0 if name[6] == "x" else 1] * (1.0 if name[7] == "+" else -1.0)
                best = max(best, min(v / MOUSE_FULL, 1.0))
            elif name in held:
                return 1.0
        return best

    def command(self) -> Command:
        s = self.strength
        return Command(advance=s("advance") - s("reverse"), rotate=s("turn_right") - s("turn_left"),
                       strafe=s("strafe_right") - s("strafe_left"), fire=s("fire") >= 0.5)


#: the pause screen's own keys (fixed, as a menu's are; the bound "pause" action resumes too)
PAUSE_KEYS: dict[str, tuple[str, ...]] = {
    "resume": ("key:p", "key:escape", "key:return"),
    "restart": ("key:r",),
    "menu": ("key:m",),
    "quit": ("key:q", "key:f10"),
}


#: the end-of-match screen's: back to the menu (a click too), the same match again, quit
END_KEYS: dict[str, tuple[str, ...]] = {
    "menu": ("key:return", "key:enter", "key:escape", "key:m", "key:space", "mouse:1"),
    "restart": ("key:r",),
    "quit": ("key:q", "key:f10"),
}


def screen_action(event: Any, keys: dict[str, tuple[str, ...]]) -> str | None:
    """The screen action (a key of ``keys``) a press (key, mouse or joystick button)
    stands for, or None: screens such as the pause screen read their keys through this,
    never as key codes."""
    import pygame

    if event.type not in (pygame.KEYDOWN, pygame.MOUSEBUTTONDOWN, pygame.JOYBUTTONDOWN):
        return None
    name = input_name(event)
    return next((a for a, names in keys.items() if name in names), None)


def describe(names: Iterable[str]) -> str:
    """Input names for people: ``key:space`` -> ``SPACE``, ``joyaxis:1-`` -> ``axis 1-``."""
    out = []
    for n in names:
        kind, _, what = n.partition(":")
        out.append({"key": what.upper(), "mouse": f"mouse {what}", "joybutton": f"button {what}",
                    "joyaxis": f"axis {what}"}.get(kind, n))
    return ", ".join(out) or "(none)"
