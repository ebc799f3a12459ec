"""Network play in the game window (SDL's dummy driver): the menu's network item and
address field, a window that hosts and one that joins, each against a headless
``NetMatch`` peer in a thread on loopback.  Conditions are polled until a generous
deadline: nothing here depends on how fast a loaded machine is."""

from __future__ import annotations

import threading
import time

import pygame
import pytest
from app_helpers import goto, key, press
from net_helpers import match_kw

from tanktool.net.peer import Peer
from tanktool.net.session import NetMatch
from tanktool.sim.match import load_match_arena, load_tank_spec

DEADLINE = 60.0


def type_address(app, text):
    goto(app, "address")
    press(app, pygame.K_RETURN)              # Enter: type into the field
    assert app.menu.editing and app.menu.address == ""
    for ch in text:
        press(app, pygame.K_UNKNOWN, ch)
    press(app, pygame.K_RETURN)
    assert not app.menu.editing and app.menu.address == text


@pytest.fixture
def app(make_app):
    return make_app(bots=0)


def _same(app) -> dict:
    """The match digest the window's peer uses (the host refuses any other)."""
    return match_kw(app.menu.arena.value, app.menu.vehicle.value)


class Headless:
    """A headless peer (scripted driver) playing a NetMatch in a thread."""

    def __init__(self, make_peer, bots: int = 0) -> None:
        self.report = None
        self.error = None
        self.match = None
        self.ready = threading.Event()
        self.thread = threading.Thread(target=self._run, args=(make_peer, bots), daemon=True)
        self.thread.start()

    def _run(self, make_peer, bots: int) -> None:
        try:
            peer = make_peer()
            try:
                self.match = NetMatch(peer, load_match_arena("box"), load_tank_spec("light"), seed=4, bots=bots)
                self.ready.set()
                self.report = self.match.run(DEADLINE * 3)
            finally:
                peer.close()
        except Exception as e:           # handed to the test thread
            self.error = e
            self.ready.set()

    def finish(self) -> dict:
        if self.match is not None:
            self.match.stop = True
        self.thread.join(DEADLINE)
        assert not self.thread.is_alive()
        if self.error is not None:
            raise self.error
        return self.report


def play_until(app, condition, hold=()):
    """Run the window's frames in real time, keys held, until ``condition()``."""
    for k in hold:
        app.handle(key(k))
    deadline = time.monotonic() + DEADLINE
    last = time.perf_counter()
    while not condition():
        assert time.monotonic() < deadline, "condition not reached"
        now = time.perf_counter()
        app.frame(now - last)
        last = now
        time.sleep(0.004)
    for k in hold:
        app.handle(key(k, down=False))


def test_menu_network_item_and_address_field(app):
    assert app.menu.network.value == "off" and app.menu.address == "127.0.0.1:5000"
    goto(app, "network")
    press(app, pygame.K_RIGHT)
    assert app.menu.network.value == "host"
    press(app, pygame.K_RIGHT)
    assert app.menu.network.value == "join"
    type_address(app, "127.0.0.1:1")     # w, a, s, d typed into the field do not move the cursor
    app.frame(0.016)                          # draws "START: join 127.0.0.1:1"
    goto(app, "start")
    press(app, pygame.K_RETURN)               # nobody there: one line, still in the menu
    assert app.state == "menu" and "cannot reach 127.0.0.1:1" in app.notice
    type_address(app, "nonsense")
    goto(app, "start")
    press(app, pygame.K_RETURN)
    assert app.state == "menu" and "expected ADDR:PORT" in app.notice


def test_window_hosts_a_headless_peer_joins(app):
    goto(app, "network")
    press(app, pygame.K_RIGHT)                # host
    type_address(app, "127.0.0.1:0")          # any free port
    goto(app, "start")
    press(app, pygame.K_RETURN)
    assert app.state == "playing", app.notice
    s = app.session
    assert s.realtime and s.player == 0 and "hosting on 127.0.0.1:" in app.notice
    address = s.peer.tcp_address
    assert [t.index for t in s.world.tanks] == [0]          # alone: one tank shown, not 8
    x0, z0 = s.world_all.tanks[0].position
    joiner = Headless(lambda: Peer.join(address, "bob", timeout=DEADLINE, **_same(app)))
    try:
        # the joiner's tank appears in the window's session, placed from its states;
        # meanwhile the player holds W and the tank drives on its own keys
        play_until(app, lambda: 1 in [t.index for t in s.world.tanks] and s.world_all.tanks[1].alive
                   and s.match.remotes[2].states and s.world_all.tanks[0].distance > 2.0, hold=(pygame.K_w,))
        assert s.world_all.tanks[1].name == "bob"
        assert [r[0] for r in s.scoreboard()].count("bob") == 1
        # and the headless peer sees the window's tank where the window drives it
        m = joiner.match
        play_until(app, lambda: 1 in m.remotes and len(m.remotes[1].states) > 5)
        app.frame(0.016)
        x1, z1 = s.world_all.tanks[0].position
        assert abs(x1 - x0) + abs(z1 - z0) > 1.0
    finally:
        report = joiner.finish()
    assert report["me"] == 2 and {p["number"] for p in report["peers"]} == {1, 2}
    assert report["network"]["received"] > 10
    seen = [v["tanks"]["1"] for v in report["views"] if "1" in v["tanks"]]
    assert seen, report["views"]
    press(app, pygame.K_p)
    assert app.state == "paused"
    press(app, pygame.K_m)                    # leave the session, back to the menu
    assert app.state == "menu" and s.closed and any(line.startswith("network:") for line in app.saved)


def test_window_joins_a_headless_host_with_a_bot(app):
    host = Headless(lambda: Peer.host(("127.0.0.1", 0), "alice", **_same(app)), bots=1)
    try:
        assert host.ready.wait(DEADLINE) and host.error is None
        ip, port = host.match.peer.tcp_address
        goto(app, "network")
        press(app, pygame.K_LEFT)             # off -> join
        assert app.menu.network.value == "join"
        type_address(app, f"{ip}:{port}")
        goto(app, "start")
        press(app, pygame.K_RETURN)           # Peer.join blocks; the host's thread answers
        assert app.state == "playing", app.notice
        s = app.session
        assert s.player == 2 and "as player 3" in app.notice        # the host's bot took number 2
        play_until(app, lambda: {0, 1, 2} <= {t.index for t in s.world.tanks} and s.world_all.tanks[0].alive
                   and s.world_all.tanks[1].alive)
        names = {t.index: t.name for t in s.world.tanks}
        assert names[0] == "alice" and names[1] == "bot1"
        play_until(app, lambda: 3 in host.match.remotes and len(host.match.remotes[3].states) > 5,
                   hold=(pygame.K_d,))
        app.handle(pygame.event.Event(pygame.QUIT))
        app.stop()                            # EXIT to everyone
        assert any(line.startswith("network:") for line in app.saved)
        deadline = time.monotonic() + DEADLINE
        while not any(x["number"] == 3 for x in list(host.match.left)):
            assert time.monotonic() < deadline, "the host never saw the window leave"
            time.sleep(0.02)
    finally:
        app.stop()
        report = host.finish()
    assert [x["reason"] for x in report["left"] if x["number"] == 3] == ["exit"]
    assert any(p["shots"] >= 0 and p["number"] == 2 and p["bot"] for p in report["peers"])


def test_menu_password_field_is_masked_and_used(app):
    from tanktool.errors import NetError

    goto(app, "password")
    press(app, pygame.K_RETURN)
    assert app.menu.editing and app.menu.field == "password"
    for ch in "S3cr et!":                      # any printable character, upper case too
        press(app, pygame.K_UNKNOWN, ch)
    press(app, pygame.K_BACKSPACE)
    press(app, pygame.K_RETURN)
    assert not app.menu.editing and app.menu.password == "S3cr et" and app.password == "S3cr et"
    app.frame(0.016)                           # drawn as stars (never the text)
    goto(app, "network")
    press(app, pygame.K_RIGHT)                 # host
    type_address(app, "127.0.0.1:0")
    goto(app, "start")
    press(app, pygame.K_RETURN)
    assert app.state == "playing", app.notice
    s = app.session
    assert s.peer.password == "S3cr et"
    address = s.peer.tcp_address
    out = {}
    same = _same(app)

    def try_join(password):
        try:
            out[password] = Peer.join(address, "bob", password, timeout=DEADLINE, **same)
        except NetError as e:
            out[password] = e

    for password in (None, "S3cr et"):
        th = threading.Thread(target=try_join, args=(password,), daemon=True)
        th.start()
        play_until(app, lambda: password in out)
        th.join(5)
    assert isinstance(out[None], NetError) and "wants a password" in str(out[None])
    joined = out["S3cr et"]
    assert isinstance(joined, Peer) and joined.number == 2
    joined.close()
    press(app, pygame.K_p)
    press(app, pygame.K_m)
