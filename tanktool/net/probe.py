"""Raw clients of the protocol, for tests, benchmarks and anyone checking that a host holds:
one join attempt spoken by hand, and connections that never say anything.

They speak just enough of the protocol to be what an attacker would be: a join that
leaves at once (a flood of these is what the host's join limiter is for), and silent
connections (what the pending-connection caps are for).
"""

from __future__ import annotations

import socket
import threading
import time
from collections import Counter

from . import auth
from . import protocol as P


def _read_one(sock: socket.socket, reader: P.StreamReader) -> P.Message | None:
    msgs: list[P.Message] = []
    while not msgs:
        data = sock.recv(4096)
        if not data:
            return None
        msgs = reader.feed(data)
    return msgs[0]


def join_once(address: tuple[str, int], password: str | None = None, name: str = "probe",
              timeout: float = 3.0) -> str:
    """One join attempt that leaves at once if admitted (its link just closes).  Returns
    the answer: ``"NUMBER"`` (admitted), ``"REFUSE <code>"``, ``"closed"`` or ``"error"``."""
    try:
        sock = socket.create_connection(address, timeout=timeout)
    except OSError:
        return "error"
    try:
        reader = P.StreamReader(Counter())
        challenge = _read_one(sock, reader)
        if challenge is None or not isinstance(challenge.body, P.Challenge):
            return "closed"
        mac = auth.join_mac(password, challenge.body.nonce, name) if password else bytes(P.MAC_SIZE)
        sock.sendall(P.encode(P.Join(name, 1, 1, mac), 0, 1, time.time()))
        answer = _read_one(sock, reader)
        if answer is None:
            return "closed"
        if isinstance(answer.body, P.Refuse):
            return f"REFUSE {answer.body.code}"
        return answer.type.name
    except OSError:
        return "error"
    finally:
        sock.close()


def silent_connection(address: tuple[str, int], source: str | None = None) -> socket.socket:
    """A connection (being) opened to ``address`` that will never say anything."""
    sock = socket.socket()
    if source is not None:
        sock.bind((source, 0))
    sock.setblocking(False)
    sock.connect_ex(address)
    return sock


def silent_flood(address: tuple[str, int], stop: threading.Event, held: int = 200, per_second: float = 500.0,
                 opened: list[socket.socket] | None = None) -> list[socket.socket]:
    """Open silent connections at ``per_second`` until ``stop`` is set, keeping the newest
    ``held`` open (an attacker's own descriptors run out too); closes them at the end."""
    socks: list[socket.socket] = [] if opened is None else opened
    try:
        while not stop.is_set():
            socks.append(silent_connection(address))
            if len(socks) > held:
                socks.pop(0).close()
            time.sleep(1.0 / per_second)
    finally:
        for s in socks:
            s.close()
    return socks
