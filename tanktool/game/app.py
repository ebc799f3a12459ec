"""The game window: start menu (game/menu.py: previews, mouse, the settings page),
bindings remap screen, the match with pause, restart and quit, and the end-of-match
scoreboard, in a fixed-timestep loop.

The loop follows "Fix Your Timestep": real time accumulates, the simulation takes
whole steps of ``World.dt`` out of it (at most a quarter second per frame, so a stall
does not snowball), and the frame is drawn ``alpha = leftover / dt`` of the way
between the last two steps.

The window is an OpenGL one when moderngl can make a context on it: the 3D view
draws straight into it, and the top view, menus and remap screen are pygame surfaces
shown as a full-window texture (game/display.py, which also says when there is no
display).  What to play comes in one :class:`~tanktool.game.config.MatchConfig`.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path
from typing import Any

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")   # the command's output is ours

import pygame  # noqa: E402

from ..errors import TanktoolError  # noqa: E402
from .config import MatchConfig  # noqa: E402
from .controls import controls_rows  # noqa: E402
from .display import (DisplayError, NoDisplay, Presenter, display_problem, stale_display,  # noqa: E402,F401
                      x_display_socket)
from .input import END_KEYS, PAUSE_KEYS, Bindings, InputState, load_bindings, save_bindings, screen_action  # noqa: E402
from .remap import Remap  # noqa: E402
from .session import GameSession  # noqa: E402

MAX_FRAME = 0.25
#: seconds a notice stays over the match
NOTICE_S = 4.0


def bundled(kind: str) -> list[str]:
    """Names of the bundled arenas or vehicles (in the package or the checkout)."""
    from ..content import bundled_names

    return bundled_names(kind)


class App:
    """The whole game as a state machine: ``menu``, ``remap``, ``playing``, ``paused``,
    ``quit``.  :meth:`handle` takes one pygame event, :meth:`frame` advances real time
    and draws; tests drive both directly."""

    def __init__(self, presenter: Presenter | None = None, config: MatchConfig | None = None, *,
                 bindings: Bindings | None = None, bindings_file: Path | None = None,
                 settings_file: Path | None = None) -> None:
        from .quality import load_settings

        cfg = config if config is not None else MatchConfig()
        #: what to play: the CLI's choices (the menu starts from them and changes its own copy)
        self.config = cfg
        #: the settings page's choices (quality, resolution, name), read at every start
        self.settings_file = settings_file
        self.settings = load_settings(settings_file)
        if cfg.view.quality is not None:   # --quality: this run's preset, as it is (saved only from the settings page)
            self.settings.quality, self.settings.shadows, self.settings.particles = cfg.view.quality, None, None
        from .menu import menu_for

        self.menu = menu_for(cfg, self.settings, bundled("arenas"), bundled("vehicles"))
        self.quality = self.settings.graphics()
        self._asked: set[tuple] = set()
        #: why the last match ended (the end-of-match screen)
        self.over_reason = ""
        self.bindings_file = bindings_file
        self.input = InputState(bindings or load_bindings(bindings_file))
        self.presenter = presenter
        self.state = "menu"
        self.remap = Remap()
        #: a line for the player on the page being shown; ``match_notice``: one about the
        #: match view (camera, view, overlays), shown only over the match
        self.notice = ""
        self.match_notice = ""
        #: the controls overlay is up (F1); over a first match it goes by itself at ``help_until`` [s]
        self.help_on = False
        self.help_until: float | None = None
        self.session: GameSession | None = None
        self.view = cfg.view.mode
        self.top = None
        self.r3d = None
        self.audio = None
        self.acc = 0.0
        self.fps = 0.0
        self._fps_frames, self._fps_t = 0, time.perf_counter()
        #: what was written (one line each), for the command to print when the window closes
        self.saved: list[str] = []
        self.replay_done = False
        self._notice_seen, self._notice_t, self._notice_text = ("", ""), 0.0, ""
        self._said_silent = False

    @property
    def replay(self) -> Any:
        """``--replay FILE`` in the window: a ``sim.replay.Replay`` shown instead of the menu."""
        return self.config.recording.replay

    @property
    def record_path(self) -> Path | None:
        """``--record FILE``: every match played is recorded; the file holds the last one."""
        rec = self.config.recording.record
        return Path(rec) if rec is not None else None

    # ------------------------------------------------------------------ lifecycle
    def size(self) -> tuple[int, int]:
        return self.menu.size()

    @property
    def password(self) -> str | None:
        """The network session's password: the menu's field (``--password`` fills it)."""
        return self.menu.password or None

    @property
    def player_name(self) -> str | None:
        """The name for network play: the menu's field (``--name`` or the settings fill it)."""
        return self.menu.name or None

    def save_settings(self) -> Path | None:
        """Write the settings file; returns its path (None, and a notice, if it could not be written)."""
        from .quality import save_settings

        try:
            return save_settings(self.settings, self.settings_file)
        except (OSError, TanktoolError) as e:
            self.notice = f"settings not saved: {e}"
            return None

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
        bots = tuple(m.bot_file.value)          # the menu's bot file (or play --bot's): the first computer tanks
        self.session = GameSession(m.arena.value, m.vehicle.value, bots=max(int(m.bots.value), len(bots)),
                                   seed=self.config.seed, difficulty=str(m.difficulty.value), player=True,
                                   bot=self.config.opponents.driver, rules=self.config.rules, bot_specs=bots)
        if self.record_path is not None:
            self.session.record()
        self._first_start_settings()
        self._begin(str(m.view.value))

    def _first_start_settings(self) -> None:
        """Remember the difficulty played; over a first match, the controls overlay."""
        from .controls import FIRST_S

        s, changed = self.settings, False
        if s.difficulty != self.menu.difficulty.value:
            s.difficulty, changed = str(self.menu.difficulty.value), True
        if not s.controls_seen:
            s.controls_seen, changed = True, True
            self.help_on, self.help_until = True, FIRST_S
        if changed:
            self.save_settings()

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
        if self.config.sound:
            from .sounds import GameAudio

            self.audio = GameAudio(self.session, volumes=self.settings.volumes())
            if not self.audio.sound.enabled and not self._said_silent:
                self._said_silent = True           # one line a run, then silence
                line = f"sound: off, {self.audio.sound.reason}; the game goes on silent"
                print(line, file=sys.stderr)
                self.notice = line

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
        from ..net.digest import match_digest, match_label

        same = {"digest": match_digest(info, spec), "label": match_label(info, spec)}   # refuse other arenas
        if mode == "host":
            peer = Peer.host(parse_address(m.address), name, self.password, **same)
            ip, port = peer.tcp_address
            said = f"hosting on {ip}:{port} as player 1 ({name})"
        else:
            peer = Peer.join(parse_address(m.address, need_host=True), name, self.password, **same)
            h = peer.table[peer.host_number]
            said = f"joined {h.ip}:{h.tcp_port} as player {peer.number} ({name})"
        try:
            self.session = NetGameSession(peer, info, spec, seed=self.config.seed,
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
        self.notice = f"replay {self.config.recording.replay_name}".strip()
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

    def _watch_model(self) -> None:
        """``--watch``: a finished re-import replaces the arena (game/watch.py); a failed
        one is shown and the last good arena stays."""
        done = self.config.watch.poll()
        if done is None:
            return
        kind, what = done
        if kind == "error":
            self.notice = f"{what}  (the last good arena stays)"
            return
        from .watch import moved_session

        self.menu.arena.options.append(str(what))
        self.menu.arena.set(str(what))
        if self.session is None or getattr(self.session, "realtime", False) or self.state not in ("playing", "paused"):
            self.notice = f"{self.config.watch.model.name} re-imported: the next match plays it"
            return
        self.session, self.notice = moved_session(self.session, self.menu, self.config)
        self._make_views(self.view)
        if self.audio is not None:
            self._restart_audio()

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
        elif self.state == "settings":
            self._handle_settings(event)
        elif self.state == "over":
            self._handle_over(event)
        elif self.state == "menu":
            self.input.handle(event)
            self._handle_menu(event)
        else:
            self._handle_match(event, self.input.handle(event))

    def _handle_menu(self, event: Any) -> None:
        from .menu import handle_menu

        action = handle_menu(self.menu, event)
        if action == "start":
            try:
                self.start()
            except TanktoolError as e:
                self.notice = str(e)       # a broken bundle, nobody at the address: say so, stay in the menu
        elif action == "name":
            self.settings.name = self.menu.name
            self.save_settings()
        elif action == "bindings":
            self.state, self.remap = "remap", Remap()
        elif action in ("settings", "quit"):
            self.state = action

    def _handle_settings(self, event: Any) -> None:
        from .menu import handle_settings

        item = handle_settings(self.menu, self.settings, event)
        if item == "back":
            self.state = "menu"
        elif item is not None:
            path = self.save_settings()
            if path is not None:
                self.notice = f"{item.replace('_', ' ')} changed (saved to {path})"
            self.apply_quality()
            if self.audio is not None:
                self.audio.set_volumes(self.settings.volumes())

    def _handle_match(self, event: Any, actions: list[str]) -> None:
        """Playing or paused: the input layer's actions (and the pause screen's keys)."""
        if self.replay is not None and event.type == pygame.KEYDOWN and event.key == pygame.K_TAB \
                and self.session is not None:
            n = len(self.session.world.tanks)       # Tab: ride with the next tank
            self.session.follow = (self.session.focus() + 1) % n
            self.match_notice = f"following {self.session.world.tanks[self.session.follow].name}"
            return
        if self.state == "paused":
            self._handle_paused(screen_action(event, PAUSE_KEYS) or ("resume" if "pause" in actions else None))
            return
        for a in actions:
            if a == "pause":
                self.state = "paused"
            elif a == "quit":
                self.state = "quit"
            elif a == "help":
                self.help_on, self.help_until = not self.help_on, None
            elif a == "camera" and self.r3d is not None:
                self.match_notice = f"camera: {self.r3d.toggle_camera()}"
            elif a == "view":
                try:
                    self._make_views("top" if self.view == "3d" else "3d")
                except TanktoolError as e:      # e.g. an arena bundle without model.glb
                    self.notice = str(e)
                    self._make_views("top")
            elif a.startswith("overlay_") and self.top is not None:
                self.top.toggle(a[len("overlay_"):])
                if self.view != "top":
                    self.match_notice = "overlays show in the top view (V)"

    def _handle_paused(self, action: str | None) -> None:
        if action == "resume":
            self.state = "playing"
            self.input.release_all()
        elif action == "restart" and getattr(self.session, "realtime", False):
            self.notice = "a network match goes on: no restart (M leaves it)"
        elif action == "restart":
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
        elif action == "menu" and self.replay is None:
            self.stop()
            self.state = "menu"
        elif action == "quit":
            self.state = "quit"

    def _handle_remap(self, event: Any) -> None:
        what = self.remap.handle(event, self.input.bindings)
        if what == "back":
            self.state = "menu"
        elif what == "remapped":
            said = self.remap.said(self.input.bindings)
            try:
                path = save_bindings(self.input.bindings, self.bindings_file)
                self.notice = f"{said}  (saved to {path})"
            except TanktoolError as e:              # read-only or full config folder: used, not kept
                self.notice = f"{said}, for this session only: not saved: {e}"

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
            if self._match_end():
                break
            events = self.session.step(self.input.command())
            if self.audio is not None:
                self.audio.on_events(events)
            self.acc -= dt
            steps += 1
        return steps

    def _match_end(self) -> bool:
        """The match is over: ``--seconds`` of a local match are up, or the simulation's
        rules say so (``world.match``; game/scoreboard.py words why): the end screen."""
        from .scoreboard import end_reason

        why = None if self.replay is not None else end_reason(self.session, self.config.seconds)
        if why is None:
            return False
        self.end_match()
        self.acc, self.state = 0.0, "over"
        self.over_reason = self.notice = why
        return True

    def _handle_over(self, event: Any) -> None:
        """The end-of-match screen (its keys: input.END_KEYS)."""
        action = screen_action(event, END_KEYS)
        if action == "restart":
            self.start()
        elif action is not None:
            self.state = action

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
        if self.config.watch is not None:
            self._watch_model()
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

            if self.state == "menu":
                draw_menu(self.menu, canvas, self.preview, self.notice)
            elif self.state == "settings":
                draw_settings(self.menu, self.settings, canvas, self.notice)
            elif self.state == "remap":
                self.remap.draw(canvas, self.input.bindings, self.notice)
            else:
                draw_end(self, canvas)
            self.presenter.show(canvas)
            return
        if self.session is None:
            return
        paused = "PAUSED   P resume  R restart  Q quit" if self.replay is not None else \
            "PAUSED   P resume  R restart  M menu  Q quit"
        # the newest of the two notices shows for NOTICE_S seconds over the match
        seen = (self.notice, self.match_notice)
        if seen != self._notice_seen:
            newest = self.match_notice if self.match_notice != self._notice_seen[1] else self.notice
            self._notice_seen, self._notice_t, self._notice_text = seen, time.perf_counter(), newest
        fresh = self.replay_done or time.perf_counter() - self._notice_t < NOTICE_S
        msg = paused if self.state == "paused" else (self._notice_text if self._notice_text and fresh else None)
        if self.help_until is not None and self.session.t >= self.help_until:
            self.help_on, self.help_until = False, None
        controls = controls_rows(self.input.bindings) if self.help_on else None
        if self.view == "3d" and self.r3d is not None:
            self.r3d.render(self.alpha, self.fps, msg, controls=controls)
            pygame.display.flip()
        else:
            self.top.draw(canvas, self.alpha, self.fps, msg, controls=controls)
            self.presenter.show(canvas)


def run_window(config: MatchConfig) -> list[str]:
    """Open the window and play until the player quits: the menu, starting from the
    configuration's choices; a replay in it (``config.recording.replay``) or a network
    match (``config.network``) starts at once.  Returns the lines saying what happened
    (files written, network summary).  Raises NoDisplay when there is no screen,
    DisplayError when the one named is not there."""
    problem = display_problem()
    if problem is not None:
        raise NoDisplay(problem)
    pygame.init()
    app = App(None, config)
    app.open_window()
    try:
        if config.recording.replay is not None:
            app.start_replay()
        elif config.network is not None:
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
