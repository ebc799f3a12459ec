"""The game window: start menu (game/menu.py: previews, mouse, the settings page),
bindings remap screen, the match with pause, restart and quit, and the end-of-match
scoreboard, in a fixed-timestep loop.

The loop follows "Fix Your Timestep": real time accumulates, the simulation takes
whole steps of ``World.dt`` out of it (at most a quarter second per frame, so a stall
does not snowball), and the frame is drawn ``alpha = leftover / dt`` of the way
between the last two steps.

The window is an OpenGL one when moderngl can make a context on it: the 3D view
draws straight into it, and the top view, menus and remap screen are pygame surfaces
shown as a full-window texture.  When OpenGL is not available the window is a plain
pygame one and only the top view is offered.  With no display at all,
:func:`run_window` raises :class:`NoDisplay` and the CLI falls back to a headless match;
with a display variable that leads nowhere (``DISPLAY`` set, no X server behind it, and
SDL falling back to its invisible ``offscreen`` driver) it raises :class:`DisplayError`:
one clear error instead of a game running forever with nothing shown.
"""

from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")   # the command's output is ours

import pygame  # noqa: E402

from ..errors import TanktoolError
from .input import ACTIONS, Bindings, InputState, describe, input_name, load_bindings, save_bindings
from .menu import BG, HILITE
from .session import DIFFICULTY, GameSession

RESOLUTIONS = ["1280x720", "1600x900", "1920x1080", "1024x576", "800x600"]
MAX_FRAME = 0.25
#: the menu's network address: host on it, or join the session there
DEFAULT_ADDRESS = "127.0.0.1:5000"
#: seconds a notice stays over the match
NOTICE_S = 4.0
DEFAULT_SIZE = (1280, 720)
#: SDL's video drivers that show nothing on any screen
INVISIBLE_DRIVERS = ("offscreen", "dummy", "evdev")


class NoDisplay(TanktoolError):
    """There is no screen to open the window on."""


class DisplayError(TanktoolError):
    """A display is named (``DISPLAY``/``WAYLAND_DISPLAY``) but cannot be used."""


def x_display_socket(display: str) -> Path | None:
    """The Unix socket of a local X display (``:1``, ``:1.0``, ``unix:1``), or None
    for a remote one (``host:1``) or a name that is not a display."""
    host, sep, rest = display.rpartition(":")
    if not sep or host not in ("", "unix"):
        return None
    number = rest.split(".")[0]
    return Path("/tmp/.X11-unix") / f"X{number}" if number.isdigit() else None


def stale_display() -> str | None:
    """Why the display SDL opened is no display (None when it is a real one).

    ``DISPLAY=:99`` with no X server: SDL tries X11, then Wayland, then settles on its
    ``offscreen`` driver, and a game would run on it forever with nothing shown."""
    requested = os.environ.get("SDL_VIDEODRIVER", "")
    driver = pygame.display.get_driver() if pygame.display.get_init() else ""
    if driver not in INVISIBLE_DRIVERS or requested == driver:
        return None
    return _stale_message(driver)


def _stale_message(driver: str, detail: str = "") -> str:
    keys = [k for k in ("DISPLAY", "WAYLAND_DISPLAY") if os.environ.get(k)]
    named = [f"{k}={os.environ[k]}" for k in keys]
    why = " and ".join(named) or "a display"
    var = " and ".join(keys) or "DISPLAY"
    hint = ""
    sock = x_display_socket(os.environ.get("DISPLAY", ""))
    if sock is not None and not sock.exists():
        hint = f" ({sock} does not exist: no X server is running there)"
    shown = detail or f"SDL could only open its invisible '{driver}' driver, so nothing would be shown"
    return (f"{why} is set but no display answers there{hint}; {shown}.  Start the display server or fix "
            f"{var}, or unset {var} to run a headless match (or use tanktool play --headless)")


def display_problem() -> str | None:
    """Why no window can be opened here, or None when one can.  Raises DisplayError
    when a display is named but is not there (see :func:`stale_display`)."""
    driver = os.environ.get("SDL_VIDEODRIVER", "")
    if driver in ("dummy", "offscreen"):
        return f"SDL_VIDEODRIVER={driver}"
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        return "neither DISPLAY nor WAYLAND_DISPLAY is set"
    # only X is named: SDL need not try Wayland (which prints its own complaints) nor
    # fall back to an invisible driver
    only_x = not driver and os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY")
    if only_x:
        os.environ["SDL_VIDEODRIVER"] = "x11"
    try:
        pygame.display.init()
    except pygame.error as e:
        if only_x:
            del os.environ["SDL_VIDEODRIVER"]
            raise DisplayError(_stale_message("x11", f"SDL cannot open it: {e}")) from None
        return f"SDL cannot open a display: {e}"
    stale = stale_display()
    if stale is not None:
        pygame.display.quit()
        raise DisplayError(stale)
    return None


def bundled(kind: str) -> list[str]:
    """Names of the bundled arenas or vehicles (in the package or the checkout)."""
    from ..content import bundled_names

    return bundled_names(kind)


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
    """The start menu's choices (the 2002 game let the player pick vehicle and arena)."""

    arena: Choice
    vehicle: Choice
    bots: Choice = field(default_factory=lambda: Choice("opponents", list(range(0, 8)), 3))
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

    #: the main menu; resolution and full screen are on the settings page
    ITEMS = ("arena", "vehicle", "bots", "difficulty", "view", "network", "address", "name", "password", "settings",
             "bindings", "start", "quit")
    CHOICES = ("arena", "vehicle", "bots", "difficulty", "view", "network")

    def item(self) -> str:
        return self.ITEMS[self.cursor]


class Presenter:
    """Shows a finished pygame surface in the window (plain or OpenGL)."""

    def __init__(self, size: tuple[int, int], fullscreen: bool, want_gl: bool) -> None:
        self.size = size
        self.ctx = None
        flags = pygame.FULLSCREEN if fullscreen else 0
        if want_gl:
            try:
                import moderngl

                pygame.display.gl_set_attribute(pygame.GL_CONTEXT_MAJOR_VERSION, 3)
                pygame.display.gl_set_attribute(pygame.GL_CONTEXT_MINOR_VERSION, 3)
                pygame.display.gl_set_attribute(pygame.GL_CONTEXT_PROFILE_MASK, pygame.GL_CONTEXT_PROFILE_CORE)
                self.window = pygame.display.set_mode(size, flags | pygame.OPENGL | pygame.DOUBLEBUF)
                self.ctx = moderngl.create_context(require=330)
            except Exception:
                self.ctx = None         # no OpenGL 3.3 here: a plain window, top view only
        if self.ctx is None:
            self.window = pygame.display.set_mode(size, flags)
        else:
            from .render3d import HUD_FRAGMENT, HUD_VERTEX
            import numpy as np

            prog = self.ctx.program(vertex_shader=HUD_VERTEX, fragment_shader=HUD_FRAGMENT)
            quad = np.array([-1, -1, 1, -1, -1, 1, 1, 1], dtype="f4")
            self._vao = self.ctx.vertex_array(prog, [(self.ctx.buffer(quad.tobytes()), "2f", "in_pos")])
            self._tex = self.ctx.texture(size, 4)
        self.canvas = pygame.Surface(size)
        pygame.display.set_caption("tanktool")

    @property
    def gl(self) -> bool:
        return self.ctx is not None

    def show(self, surface: "pygame.Surface") -> None:
        if self.ctx is None:
            self.window.blit(surface, (0, 0))
        else:
            import moderngl

            self.ctx.screen.use()
            self.ctx.viewport = (0, 0, *self.size)
            self.ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
            self._tex.write(pygame.image.tobytes(surface, "RGBA"))
            self._tex.use(0)
            self._vao.render(moderngl.TRIANGLE_STRIP)
        pygame.display.flip()


class App:
    """The whole game as a state machine: ``menu``, ``remap``, ``playing``, ``paused``,
    ``quit``.  :meth:`handle` takes one pygame event, :meth:`frame` advances real time
    and draws; tests drive both directly."""

    def __init__(self, presenter: Presenter | None = None, arena: str | None = None, vehicle: str | None = None,
                 bots: int = 3, seed: int = 0, view: str = "3d", size: tuple[int, int] = (1280, 720),
                 fullscreen: bool = False, bindings: Bindings | None = None, sound: bool = True,
                 bindings_file: Path | None = None, difficulty: str = "normal", bot: str = "agent",
                 record: Path | None = None, replay: Any = None, replay_name: str = "",
                 seconds: float | None = None, settings_file: Path | None = None, rules: Any = None,
                 quality: str | None = None) -> None:
        from .quality import load_settings

        #: the rules of every local match (``sim.rules.Rules``; None: the default ones)
        self.rules = rules

        #: the settings page's choices (quality, resolution, name), read at every start
        self.settings_file = settings_file
        self.settings = load_settings(settings_file)
        if quality is not None:      # --quality: this run's preset, as it is (saved only from the settings page)
            self.settings.quality, self.settings.shadows, self.settings.particles = quality, None, None
        if tuple(size) == DEFAULT_SIZE and self.settings.resolution:
            size = tuple(int(v) for v in self.settings.resolution.split("x"))   # --size overrides the saved one
        fullscreen = fullscreen or self.settings.fullscreen
        arenas, vehicles = bundled("arenas"), bundled("vehicles")
        self.menu = Menu(Choice("arena", arenas + ([arena] if arena and arena not in arenas else [])),
                         Choice("vehicle", vehicles + ([vehicle] if vehicle and vehicle not in vehicles else [])
                                or [None]))
        from ..sim.match import default_arena, default_vehicle

        self.menu.arena.set(arena or default_arena())
        self.menu.vehicle.set(vehicle or default_vehicle())
        self.menu.bots.set(min(max(bots, 0), 7))
        self.menu.view.set(view)
        self.menu.difficulty.set(difficulty)
        res = f"{size[0]}x{size[1]}"
        if res not in self.menu.resolution.options:
            self.menu.resolution.options.insert(0, res)
        self.menu.resolution.set(res)
        self.menu.fullscreen.set(fullscreen)
        self.menu.name = self.settings.name
        self.settings_cursor = 0
        self.quality = self.settings.graphics()
        #: clickable rectangles of the screen last drawn (game/menu.py)
        self.menu_hits: list[Any] = []
        self.preview_hits: list[Any] = []
        self._asked: set[tuple] = set()
        #: why the last match ended (the end-of-match screen)
        self.over_reason = ""
        self.seed = seed
        self.bot = bot
        self.bindings_file = bindings_file
        self.input = InputState(bindings or load_bindings(bindings_file))
        self.presenter = presenter
        self.state = "menu"
        self.remap_cursor = 0
        self.remap_waiting = False
        self.notice = ""
        self.session: GameSession | None = None
        self.view = view
        self.top = None
        self.r3d = None
        self.audio = None
        self.want_sound = sound
        self.acc = 0.0
        self.fps = 0.0
        self._fps_frames, self._fps_t = 0, time.perf_counter()
        #: ``--record FILE``: every match played is recorded; the file holds the last one
        self.record_path = Path(record) if record is not None else None
        #: what was written (one line each), for the command to print when the window closes
        self.saved: list[str] = []
        #: ``--replay FILE`` in the window: a ``sim.replay.Replay`` shown instead of the menu
        self.replay = replay
        self.replay_name = replay_name
        self.replay_done = False
        #: typing into a menu field: ``field`` says which ("address" or "password")
        self.editing = False
        self.field = "address"
        self._notice_seen, self._notice_t = "", 0.0
        self.password: str | None = None
        #: ``--seconds``: a local match ends after this much simulated time (None: when you quit)
        self.match_seconds = seconds

    # ------------------------------------------------------------------ lifecycle
    def size(self) -> tuple[int, int]:
        w, h = (int(v) for v in str(self.menu.resolution.value).split("x"))
        return w, h

    @property
    def password(self) -> str | None:
        """The network session's password: the menu's field (``--password`` fills it)."""
        return self.menu.password or None

    @password.setter
    def password(self, value: str | None) -> None:
        self.menu.password = value or ""

    @property
    def player_name(self) -> str | None:
        """The name for network play: the menu's field (``--name`` or the settings fill it)."""
        return self.menu.name or None

    @player_name.setter
    def player_name(self, value: str | None) -> None:
        if value:
            self.menu.name = value

    def save_settings(self) -> Path | None:
        from .menu import save

        return save(self)

    def apply_quality(self) -> None:
        """The settings' graphics quality, for the 3D view from now on."""
        self.quality = self.settings.graphics()
        if self.r3d is not None:
            self.r3d.set_quality(self.quality)

    def preview(self, kind: str, ref: Any, size: tuple[int, int]) -> "pygame.Surface | None":
        """A rendered preview of an arena or vehicle for the menu (game/thumbnails.py);
        None the first time it is asked for: it is made at the next frame, so the menu
        shows before the models are loaded."""
        from .thumbnails import cached, preview

        key = (kind, str(ref), size)
        if cached(key) is None and key not in self._asked:
            self._asked.add(key)
            return None
        ctx = self.presenter.ctx if self.presenter is not None and self.presenter.gl else None
        return preview(kind, ref, size, ctx)

    def open_window(self) -> None:
        self.presenter = Presenter(self.size(), bool(self.menu.fullscreen.value), want_gl=True)

    def start(self) -> None:
        """Start a match with the menu's choices (re-opening the window if its size changed)."""
        m = self.menu
        if self.presenter is None or self.presenter.size != self.size():
            self.open_window()
        if self.replay is not None:
            self.start_replay()
            return
        self.end_match()
        if m.network.value != "off":
            self.start_network()
            return
        self.session = GameSession(m.arena.value, m.vehicle.value, bots=int(m.bots.value), seed=self.seed,
                                   difficulty=str(m.difficulty.value), player=True, bot=self.bot, rules=self.rules)
        if self.record_path is not None:
            self.session.record()
        self._begin(str(m.view.value))

    def _begin(self, view: str) -> None:
        self._make_views(view)
        self._restart_audio()
        self.input.release_all()
        self.acc = 0.0
        self.state = "playing"

    def _restart_audio(self) -> None:
        if self.audio is not None:
            self.audio.close()
            self.audio = None
        if self.want_sound:
            from .sounds import GameAudio

            self.audio = GameAudio(self.session)

    def start_network(self) -> None:
        """Host or join a network session (the menu's ``network`` and ``address``) and
        play it in the window: your tank is yours, the others come over the network
        (``game.net_session``).  Raises NetError/TanktoolError (the menu shows it)."""
        from ..net.peer import Peer, parse_address
        from ..sim.match import choose_vehicle, load_match_arena, load_tank_spec
        from .net_session import NetGameSession

        m = self.menu
        mode = str(m.network.value)
        if self.presenter is None or self.presenter.size != self.size():
            self.open_window()
        info = load_match_arena(m.arena.value)
        spec = load_tank_spec(choose_vehicle(info, m.vehicle.value))   # refuses one too big for the arena
        name = self.player_name or ("host" if mode == "host" else "player")
        if mode == "host":
            peer = Peer.host(parse_address(m.address), name, self.password)
            ip, port = peer.tcp_address
            said = f"hosting on {ip}:{port} as player 1 ({name})"
        else:
            peer = Peer.join(parse_address(m.address, need_host=True), name, self.password)
            h = peer.table[peer.host_number]
            said = f"joined {h.ip}:{h.tcp_port} as player {peer.number} ({name})"
        try:
            self.session = NetGameSession(peer, info, spec, seed=self.seed,
                                          bots=int(m.bots.value) if mode == "host" else 0,
                                          arena_ref=m.arena.value, vehicle_ref=m.vehicle.value)
            self._begin(str(m.view.value))
        except BaseException:
            peer.close()
            raise
        self.saved.append(said)
        self.notice = said

    def start_replay(self) -> None:
        """Show the replay from its start: the game's session driven by the tape
        (``game.replay_session``); the player's input only pauses, quits and changes views."""
        from .replay_session import replay_session

        if self.presenter is None:
            self.open_window()
        self.session = replay_session(self.replay)
        self.replay_done = False
        self.notice = f"replay {self.replay_name}".strip()
        self._begin(self.view)

    def end_match(self) -> str | None:
        """The match being recorded is over (quit, restart, back to the menu): write its
        tape atomically to ``--record``'s file, replacing the last match's.  A match that
        never took a step writes nothing.  Returns the line saying what was written."""
        s = self.session
        if getattr(s, "realtime", False):       # a network match: leave the session
            if not s.closed:
                s.close()
                self.saved.append(s.summary())
            return None
        if s is None or s.recorder is None or self.record_path is None:
            return None
        if s.world.steps == 0:
            return None                       # still armed: a match that starts later is recorded
        s_tape = s.tape()
        s.recorder = None                     # written once
        from ..sim.replay import write_replay

        nbytes = write_replay(self.record_path, s_tape)
        line = (f"replay: {self.record_path} ({nbytes} bytes, {len(s_tape)} command changes, "
                f"{s.world.steps} steps = {s.world.steps * s.dt:.2f} s)")
        self.saved.append(line)
        self.notice = f"recorded to {self.record_path}"
        return line

    def _make_views(self, view: str) -> None:
        from .render_top import TopView

        if self.r3d is not None:
            self.r3d = None          # its GL objects go with the context it was made on
        if view == "3d" and not self.presenter.gl:
            self.notice = "no OpenGL 3.3 on this display: top view only"
            view = "top"
        self.view = view
        self.top = TopView(self.session, self.presenter.size)
        if view == "3d":
            from .render3d import Renderer3D

            self.r3d = Renderer3D(self.session, self.presenter.size, ctx=self.presenter.ctx, quality=self.quality)

    def stop(self) -> None:
        self.end_match()
        if self.audio is not None:
            self.audio.close()
            self.audio = None

    # ------------------------------------------------------------------ events
    def handle(self, event: Any) -> None:
        if event.type == pygame.QUIT:
            self.state = "quit"
            return
        if event.type == getattr(pygame, "WINDOWFOCUSLOST", -1):
            self.input.release_all()
        if self.state == "remap":
            self._handle_remap(event)
            return
        if self.state == "settings":
            from .menu import handle_settings

            handle_settings(self, event)
            return
        if self.state == "over":
            self._handle_over(event)
            return
        actions = self.input.handle(event)
        if self.replay is not None and self.state in ("playing", "paused") and event.type == pygame.KEYDOWN \
                and event.key == pygame.K_TAB and self.session is not None:
            n = len(self.session.world.tanks)       # Tab: ride with the next tank
            self.session.follow = (self.session.focus() + 1) % n
            self.notice = f"following {self.session.world.tanks[self.session.follow].name}"
            return
        if self.state == "menu":
            from .menu import handle_menu

            handle_menu(self, event)
        elif self.state == "playing":
            for a in actions:
                if a == "pause":
                    self.state = "paused"
                elif a == "quit":
                    self.state = "quit"
                elif a == "camera" and self.r3d is not None:
                    self.notice = f"camera: {self.r3d.toggle_camera()}"
                elif a == "view":
                    try:
                        self._make_views("top" if self.view == "3d" else "3d")
                    except TanktoolError as e:      # e.g. an arena bundle without model.glb
                        self.notice = str(e)
                        self._make_views("top")
                elif a.startswith("overlay_") and self.top is not None:
                    self.top.toggle(a[len("overlay_"):])
                    if self.view != "top":
                        self.notice = "overlays show in the top view (V)"
        elif self.state == "paused":
            if event.type == pygame.KEYDOWN:
                if event.key in (pygame.K_p, pygame.K_ESCAPE, pygame.K_RETURN) or "pause" in actions:
                    self.state = "playing"
                    self.input.release_all()
                elif event.key == pygame.K_r and getattr(self.session, "realtime", False):
                    self.notice = "a network match goes on: no restart (M leaves it)"
                elif event.key == pygame.K_r:
                    if self.replay is not None:
                        self.start_replay()
                        return
                    self.end_match()
                    self.session.restart()
                    if self.record_path is not None:
                        self.session.record()
                    self._make_views(self.view)
                    if self.audio is not None:
                        self._restart_audio()
                    self.state = "playing"
                elif event.key == pygame.K_m and self.replay is None:
                    self.stop()
                    self.state = "menu"
                elif event.key in (pygame.K_q, pygame.K_F10):
                    self.state = "quit"

    def _handle_remap(self, event: Any) -> None:
        if self.remap_waiting:
            if event.type == pygame.KEYDOWN and event.key == pygame.K_ESCAPE:
                self.remap_waiting = False          # cancelled; Escape itself stays unbindable here
                return
            name = input_name(event)
            if name is None:
                return
            action = ACTIONS[self.remap_cursor]
            self.input.bindings.remap(action, name)
            said = f"{action.upper().replace('_', ' ')} = {describe([name])}"
            try:
                path = save_bindings(self.input.bindings, self.bindings_file)
                self.notice = f"{said}  (saved to {path})"
            except TanktoolError as e:              # read-only or full config folder: used, not kept
                self.notice = f"{said}, for this session only: not saved: {e}"
            self.remap_waiting = False
            return
        if event.type == pygame.KEYDOWN:
            if event.key in (pygame.K_UP, pygame.K_w):
                self.remap_cursor = (self.remap_cursor - 1) % len(ACTIONS)
            elif event.key in (pygame.K_DOWN, pygame.K_s):
                self.remap_cursor = (self.remap_cursor + 1) % len(ACTIONS)
            elif event.key in (pygame.K_RETURN, pygame.K_SPACE, pygame.K_KP_ENTER):
                self.remap_waiting = True
            elif event.key == pygame.K_ESCAPE:
                self.state = "menu"
        elif event.type == pygame.JOYBUTTONDOWN and event.button == 0:
            self.remap_waiting = True

    # ------------------------------------------------------------------ time and drawing
    def advance(self, real_dt: float) -> int:
        """Add real time and take the fixed steps it pays for; returns how many.  A
        network match keeps its own clock (and runs on while paused: the others do)."""
        if getattr(self.session, "realtime", False) and self.state in ("playing", "paused"):
            from ..sim.commands import IDLE

            events = self.session.advance(self.input.command() if self.state == "playing" else IDLE)
            if self.audio is not None:
                self.audio.on_events(events)
            return len({e.step for e in events})
        if self.state != "playing" or self.session is None:
            return 0
        self.acc += min(max(real_dt, 0.0), MAX_FRAME)
        dt = self.session.dt
        steps = 0
        while self.acc >= dt:
            if self.session.max_steps is not None and self.session.world.steps >= self.session.max_steps:
                self._replay_over()
                self.acc = 0.0
                break
            if self._time_up() or self._match_over():
                break
            events = self.session.step(self.input.command())
            if self.audio is not None:
                self.audio.on_events(events)
            self.acc -= dt
            steps += 1
        return steps

    def _time_up(self) -> bool:
        """``--seconds`` is over for a local match: record it, back to the menu with a notice."""
        if self.match_seconds is None or self.replay is not None or self.session is None:
            return False
        if self.session.world.steps * self.session.dt < self.match_seconds - 1e-9:
            return False
        self.end_match()
        self.acc = 0.0
        self.state = "over"
        self.over_reason = f"time up: the match lasted {self.match_seconds:g} s (--seconds)"
        self.notice = self.over_reason
        return True

    def _match_over(self) -> bool:
        """The simulation says the match is over (its rules' time or score limit,
        ``world.match``): the end screen."""
        w = getattr(self.session, "world_all", getattr(self.session, "world", None))
        m = getattr(w, "match", None)
        if self.replay is not None or m is None or not m.over:
            return False
        self.end_match()
        self.acc = 0.0
        self.state = "over"
        why = {"time": "time up", "score": "score limit reached"}.get(m.reason, "the match is over")
        winner = w.tanks[m.winner].name if m.winner is not None else None
        self.over_reason = f"{why}: {winner} wins" if winner else f"{why}: a draw"
        self.notice = self.over_reason
        return True

    def _handle_over(self, event: Any) -> None:
        """The end-of-match screen: Enter, Esc, M or a click: the menu; R: the same match
        again; Q or F10: quit."""
        if event.type == pygame.MOUSEBUTTONDOWN and event.button == 1:
            self.state = "menu"
        elif event.type == pygame.KEYDOWN:
            if event.key in (pygame.K_RETURN, pygame.K_KP_ENTER, pygame.K_ESCAPE, pygame.K_m, pygame.K_SPACE):
                self.state = "menu"
            elif event.key == pygame.K_r:
                self.start()
            elif event.key in (pygame.K_q, pygame.K_F10):
                self.state = "quit"

    def _replay_over(self) -> None:
        if self.replay_done:
            return
        from ..sim.replay import state_digest

        self.replay_done = True
        same = state_digest(self.session.world) == self.replay.header["final_state"]
        self.notice = ("end of replay: the recorded final state, bit for bit" if same else
                       "end of replay: the state DIFFERS from the recording") + "   (Esc, R: again)"

    @property
    def alpha(self) -> float:
        if getattr(self.session, "realtime", False):
            return self.session.alpha()
        return self.acc / self.session.dt if self.session is not None else 1.0

    def frame(self, real_dt: float) -> None:
        self.advance(real_dt)
        self.input.end_frame()
        if self.audio is not None and self.state == "playing":
            self.audio.update(self.alpha)
        self._fps_frames += 1
        now = time.perf_counter()
        if now - self._fps_t >= 0.5:
            self.fps = self._fps_frames / (now - self._fps_t)
            self._fps_frames, self._fps_t = 0, now
        if self.presenter is not None:
            self.draw()

    def draw(self) -> None:
        canvas = self.presenter.canvas
        if self.state in ("menu", "remap", "settings", "over"):
            from .menu import draw_menu, draw_settings
            from .scoreboard import draw_end

            {"menu": draw_menu, "settings": draw_settings, "remap": lambda a, c: a._draw_remap(c),
             "over": draw_end}[self.state](self, canvas)
            self.presenter.show(canvas)
            return
        if self.session is None:
            return
        paused = "PAUSED   P resume  R restart  Q quit" if self.replay is not None else \
            "PAUSED   P resume  R restart  M menu  Q quit"
        if self.notice != self._notice_seen:        # a notice shows for NOTICE_S seconds over the match
            self._notice_seen, self._notice_t = self.notice, time.perf_counter()
        fresh = self.replay_done or time.perf_counter() - self._notice_t < NOTICE_S
        msg = paused if self.state == "paused" else (self.notice if self.notice and fresh else None)
        if self.view == "3d" and self.r3d is not None:
            self.r3d.render(self.alpha, self.fps, msg)
            pygame.display.flip()
        else:
            self.top.draw(canvas, self.alpha, self.fps, msg)
            self.presenter.show(canvas)

    def _draw_remap(self, surf: "pygame.Surface") -> None:
        from .hud import text

        surf.fill(BG)
        w, h = surf.get_size()
        text(surf, "bindings", (w // 2, 30), 56, anchor="midtop")
        y = 90
        line = max(min(30, (h - 260) // len(ACTIONS)), 14)
        for i, action in enumerate(ACTIONS):
            colour = HILITE if i == self.remap_cursor else (220, 220, 220)
            text(surf, action.replace('_', ' '), (w // 2 - 260, y), line, colour)
            text(surf, describe(self.input.bindings.inputs(action)), (w // 2 - 20, y), line, colour)
            y += line
        if self.remap_waiting:
            text(surf, f"press the button for {ACTIONS[self.remap_cursor].upper().replace('_', ' ')}",
                 (w // 2, h - 100), 40, HILITE, anchor="midtop")
        else:
            text(surf, "Enter: remap   Esc: back", (w // 2, h - 100), 26, (170, 170, 170), anchor="midtop")
        if self.notice:
            text(surf, self.notice, (w // 2, h - 50), 22, (170, 220, 170), anchor="midtop")


def run_window(arena: str | None = None, vehicle: str | None = None, bots: int = 3, seed: int = 0,
               view: str = "3d", size: tuple[int, int] = (1280, 720), fullscreen: bool = False,
               difficulty: str = "normal", bot: str = "agent", record: Path | None = None,
               replay: Any = None, replay_name: str = "", network: tuple[str, str] | None = None,
               name: str | None = None, password: str | None = None,
               seconds: float | None = None, rules: Any = None, quality: str | None = None) -> list[str]:
    """Open the window and play until the player quits (``record``: every match is
    recorded, the file holds the last one; ``replay``: show that recording instead of
    the menu; ``network``: ("host" or "join", address) starts that network match at
    once; ``seconds``: each local match ends after that much simulated time and the
    menu comes back).  Returns the lines saying what happened (files written, network summary).
    Raises NoDisplay when there is no screen, DisplayError when the one named is not there."""
    problem = display_problem()
    if problem is not None:
        raise NoDisplay(problem)
    pygame.init()
    app = App(None, arena, vehicle, bots, seed, view, size, fullscreen, difficulty=difficulty, bot=bot,
              record=record, replay=replay, replay_name=replay_name, seconds=seconds, rules=rules,
              quality=quality)
    app.player_name, app.password = name, password
    app.open_window()
    try:
        if replay is not None:
            app.start_replay()
        elif network is not None:
            app.menu.network.set(network[0])
            app.menu.address = network[1]
            app.start_network()
    except BaseException:
        app.stop()
        pygame.quit()
        raise
    clock = pygame.time.Clock()
    last = time.perf_counter()
    try:
        while app.state != "quit":
            for event in pygame.event.get():
                app.handle(event)
            now = time.perf_counter()
            app.frame(now - last)
            last = now
            clock.tick(240)         # yield the CPU between frames; the accumulator keeps time
    finally:
        app.stop()
        pygame.quit()
    return app.saved
