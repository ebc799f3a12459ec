"""The one message layout of network play (paper §3.3: "the same data structure for
every message type, each field treated differently").

Every message, on TCP or UDP, is a 15-byte header followed by its payload, all
big-endian (network order)::

    offset size field      type   meaning
    0      2    magic      2s     b"TK"
    2      1    version    u8     VERSION
    3      1    type       u8     one of the MessageType values
    4      1    sender     u8     the sender's player number 1..8 (0: not assigned yet)
    5      4    sequence   u32    grows by one with every message the sender sends
    9      4    timestamp  u32    the sender's clock when sent, in microseconds modulo 2^32
                                  (only differences matter: :func:`age`)
    13     2    length     u16    payload bytes that follow (<= MAX_PAYLOAD)
    15     n    payload           type-specific, below

:func:`decode` checks every field (magic, version, known type, sender range, the exact
length each type needs, finite numbers within range, valid names) and returns None for
anything that fails, counting the reason in a :class:`Counter`: garbage never raises.
"""

from __future__ import annotations

import enum
import math
import struct
from collections import Counter
from dataclasses import dataclass
from typing import Union

MAGIC = b"TK"
#: 2: the JOIN carries the digest of the arena and vehicle (peers on different ones
#: refuse the match), control messages carry the game counter without advancing it;
#: 3: host terms (Raft-like) in CHALLENGE, NUMBER, NEW_PLAYER and TABLE; the header's
#: timestamp a u32 of microseconds (4 bytes less a datagram: 16 KB/s per peer sealed);
#: 4: NUMBER, NEW_PLAYER and TABLE carry the addresses the host is probing (net/terms.py)
VERSION = 4
MAX_PLAYERS = 8
MAX_NAME = 24                      # bytes of UTF-8
MAX_PAYLOAD = 512
MAC_SIZE = 32                      # HMAC-SHA256
NONCE_SIZE = 16
DIGEST_SIZE = 16                   # the arena + vehicle digest a JOIN carries (net/digest.py)
HEADER = struct.Struct("!2sBBBIIH")
_WRAP = 1 << 32
#: positions, velocities: generous bounds that still reject absurd values [m, m/s];
#: speeds and hit points travel as half floats in a state (|v| < 65504)
MAX_COORD = 1.0e6
MAX_SPEED = 1.0e4
MAX_HP = 6.0e4
MAX_TIME = 1.0e10


class MessageType(enum.IntEnum):
    CHALLENGE = 1    # listener -> connector: a nonce (and whether a password is needed)
    JOIN = 2         # joiner -> host: join request (name, ports, HMAC)
    HELLO = 3        # peer -> peer: open a mesh link for my number (HMAC)
    NUMBER = 4       # host -> joiner: your player number, the session clock, the table
    NEW_PLAYER = 5   # host -> everyone: a new player, and the whole table
    STATE = 6        # UDP: one tank's state
    SHOT = 7         # a tank fired
    HIT = 8          # the victim's peer: a shell hit my tank
    EXIT = 9         # I am leaving
    REFUSE = 10      # a join or link refused, with a reason
    TABLE = 11       # host -> everyone: the table after someone left (it is the reference)


class RefuseCode(enum.IntEnum):
    FULL = 1
    PASSWORD = 2
    NOT_HOST = 3
    BAD_REQUEST = 4
    RATE = 5         # too many joins (or wrong passwords) from your address: try again later
    MISMATCH = 6     # your arena or vehicle is not the host's (their digests differ)
    NAME = 7         # your name is blank or looks like a name already in the session


@dataclass(frozen=True, slots=True)
class Entry:
    """One row of the player table: who, and where to reach them."""

    number: int
    epoch: int          # the host's join counter: tells a reused number from its old owner
    ip: str             # dotted IPv4
    tcp_port: int
    udp_port: int
    name: str
    owner: int = 0      # 0: a player; else the number of the peer that runs this computer opponent

    @property
    def is_bot(self) -> bool:
        return self.owner != 0


@dataclass(frozen=True, slots=True)
class Table:
    host: int
    entries: tuple[Entry, ...]

    def numbers(self) -> list[int]:
        return [e.number for e in self.entries]

    def get(self, number: int) -> Entry | None:
        for e in self.entries:
            if e.number == number:
                return e
        return None


@dataclass(frozen=True, slots=True)
class Challenge:
    """A listener's greeting: the nonce to answer, and where its session stands (its
    host term, host number and players), so a peer that lost its session can tell a
    newer one when it calls."""

    nonce: bytes
    password: bool
    term: int = 0
    host: int = 0
    players: int = 0


@dataclass(frozen=True, slots=True)
class Join:
    name: str
    tcp_port: int
    udp_port: int
    mac: bytes
    digest: bytes = bytes(DIGEST_SIZE)   # of the arena + vehicle the joiner plays


@dataclass(frozen=True, slots=True)
class Hello:
    epoch: int
    mac: bytes


@dataclass(frozen=True, slots=True)
class Assign:
    """NUMBER (to the joiner), NEW_PLAYER and TABLE (to everyone else) share this payload;
    ``number`` is the joiner for NUMBER and NEW_PLAYER, the host itself for TABLE."""

    number: int
    session_t: float
    table: Table
    term: int = 1       # the host's term: +1 at every host change
    #: (ip, tcp port) of players the host lost uncleanly and is probing (at most
    #: MAX_PLAYERS): a member that joined after the loss probes them too, so the session
    #: finds the other side of a partition even if its host leaves (net/terms.py)
    lost: tuple[tuple[str, int], ...] = ()


@dataclass(frozen=True, slots=True)
class State:
    tank: int
    t: float            # the sender's session time of this state [s]
    x: float
    z: float
    heading: float
    vx: float
    vz: float
    omega: float
    hp: float           # not on the wire (decoded as 0): the judge's, from the host's HITs
    alive: bool


@dataclass(frozen=True, slots=True)
class Shot:
    tank: int
    t: float
    x: float
    z: float
    heading: float
    vx: float
    vz: float


@dataclass(frozen=True, slots=True)
class Hit:
    shooter: int
    victim: int
    t: float
    damage: float
    hp: float           # the victim's hit points after the hit
    killed: bool
    x: float
    z: float


@dataclass(frozen=True, slots=True)
class Exit:
    pass


@dataclass(frozen=True, slots=True)
class Refuse:
    code: int
    text: str


Body = Union[Challenge, Join, Hello, Assign, State, Shot, Hit, Exit, Refuse]


@dataclass(frozen=True, slots=True)
class Message:
    type: MessageType
    sender: int
    seq: int
    timestamp: float
    body: Body


class BadMessage(Exception):
    """Raised inside decoding only; :func:`decode` turns it into None + a counted reason."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


# ---------------------------------------------------------------------- payloads
_CHALLENGE = struct.Struct(f"!{NONCE_SIZE}sBIBB")
_JOIN = struct.Struct(f"!{MAC_SIZE}s{DIGEST_SIZE}sHHB")
_HELLO = struct.Struct(f"!{MAC_SIZE}sI")
_ASSIGN = struct.Struct("!BdIBB")         # number, session t, term, table host, entry count
_ENTRY = struct.Struct("!BBI4sHHB")       # number, owner, epoch, ip, tcp, udp, name length
_LOST = struct.Struct("!4sH")              # a probed address after the entries (a count byte first)
#: tank (low 7 bits) and alive (high bit), session time [ms], x, z (f32), heading, vx, vz,
#: omega (f16): 21 bytes, so a state datagram is 36 bytes (64 on the wire, 72 sealed) and
#: 30 Hz to 7 peers is 13.4 KB/s (15.1 sealed) counting IPv4/UDP headers.  Hit points are
#: not sent: they come from the vehicle and the host's HITs (net/judge.py)
_STATE = struct.Struct("!BI2f4e")
ALIVE_BIT = 0x80
_SHOT = struct.Struct("!Bd5f")
_HIT = struct.Struct("!BBdffBff")
_REFUSE = struct.Struct("!BB")


def name_bytes(name: str) -> bytes:
    b = name.encode("utf-8")
    if not b or len(b) > MAX_NAME:
        raise ValueError(f"a player name must be 1 to {MAX_NAME} bytes of UTF-8, got {name!r}")
    return b


def _read_name(raw: bytes) -> str:
    try:
        s = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise BadMessage("name") from None
    if not s or not s.isprintable():
        raise BadMessage("name")
    return s


def _ip_bytes(ip: str) -> bytes:
    parts = ip.split(".")
    if len(parts) != 4:
        raise ValueError(f"not an IPv4 address: {ip!r}")
    return bytes(int(p) for p in parts)


def _ip_str(b: bytes) -> str:
    return ".".join(str(x) for x in b)


def _finite(*values: float) -> None:
    for v in values:
        if not math.isfinite(v):
            raise BadMessage("nan")


def _in(v: float, lo: float, hi: float) -> None:
    if not lo <= v <= hi:
        raise BadMessage("range")


def _player(n: int) -> None:
    if not 1 <= n <= MAX_PLAYERS:
        raise BadMessage("range")


def _encode_table(body: Assign) -> bytes:
    table = body.table
    out = [_ASSIGN.pack(body.number, body.session_t, body.term, table.host, len(table.entries))]
    for e in table.entries:
        name = name_bytes(e.name)
        out.append(_ENTRY.pack(e.number, e.owner, e.epoch, _ip_bytes(e.ip), e.tcp_port, e.udp_port, len(name))
                   + name)
    if len(body.lost) > MAX_PLAYERS:
        raise ValueError(f"{len(body.lost)} probed addresses: at most {MAX_PLAYERS}")
    out.append(bytes([len(body.lost)]))
    out.extend(_LOST.pack(_ip_bytes(ip), port) for ip, port in body.lost)
    return b"".join(out)


def _decode_lost(p: bytes, off: int) -> tuple[tuple[str, int], ...]:
    if off >= len(p):
        raise BadMessage("length")
    count = p[off]
    if count > MAX_PLAYERS:
        raise BadMessage("range")
    if off + 1 + count * _LOST.size != len(p):
        raise BadMessage("length")
    lost = []
    for k in range(count):
        ip, port = _LOST.unpack_from(p, off + 1 + k * _LOST.size)
        if port == 0:
            raise BadMessage("range")
        lost.append((_ip_str(ip), port))
    return tuple(lost)


def _decode_table(p: bytes) -> Assign:
    if len(p) < _ASSIGN.size:
        raise BadMessage("length")
    number, session_t, term, host, count = _ASSIGN.unpack_from(p)
    _player(number)
    _finite(session_t)
    _in(session_t, 0.0, MAX_TIME)
    _player(host)
    if not 1 <= count <= MAX_PLAYERS:
        raise BadMessage("range")
    off = _ASSIGN.size
    entries = []
    seen = set()
    for _ in range(count):
        if off + _ENTRY.size > len(p):
            raise BadMessage("length")
        n, owner, epoch, ip, tcp, udp, nlen = _ENTRY.unpack_from(p, off)
        off += _ENTRY.size
        if off + nlen > len(p) or not 1 <= nlen <= MAX_NAME:
            raise BadMessage("length")
        name = _read_name(p[off:off + nlen])
        off += nlen
        _player(n)
        if n in seen or tcp == 0 or udp == 0 or owner > MAX_PLAYERS or owner == n:
            raise BadMessage("range")
        seen.add(n)
        entries.append(Entry(n, epoch, _ip_str(ip), tcp, udp, name, owner))
    lost = _decode_lost(p, off)
    players = {e.number for e in entries if e.owner == 0}
    # the host is a player, and every computer opponent belongs to a player in the table
    if host not in players or number not in seen or any(e.owner and e.owner not in players for e in entries):
        raise BadMessage("range")
    return Assign(number, session_t, Table(host, tuple(entries)), term, lost)


def encode_body(body: Body) -> tuple[MessageType, bytes]:
    """The message type and payload bytes of a body."""
    if isinstance(body, Challenge):
        return MessageType.CHALLENGE, _CHALLENGE.pack(body.nonce, int(body.password), body.term, body.host,
                                                      body.players)
    if isinstance(body, Join):
        name = name_bytes(body.name)
        return MessageType.JOIN, _JOIN.pack(body.mac, body.digest, body.tcp_port, body.udp_port, len(name)) + name
    if isinstance(body, Hello):
        return MessageType.HELLO, _HELLO.pack(body.mac, body.epoch)
    if isinstance(body, Assign):
        raise TypeError("Assign is sent as NUMBER or NEW_PLAYER: use encode(..., kind=...)")
    if isinstance(body, State):
        def c(v: float, lim: float) -> float:
            return max(-lim, min(lim, v))     # half floats overflow past 65504
        return MessageType.STATE, _STATE.pack(body.tank | (ALIVE_BIT if body.alive else 0),
                                              int(round(body.t * 1000.0)) & 0xFFFFFFFF, body.x, body.z,
                                              math.remainder(body.heading, 2 * math.pi), c(body.vx, MAX_SPEED),
                                              c(body.vz, MAX_SPEED), c(body.omega, MAX_SPEED))
    if isinstance(body, Shot):
        return MessageType.SHOT, _SHOT.pack(body.tank, body.t, body.x, body.z, body.heading, body.vx, body.vz)
    if isinstance(body, Hit):
        return MessageType.HIT, _HIT.pack(body.shooter, body.victim, body.t, body.damage, body.hp,
                                          int(body.killed), body.x, body.z)
    if isinstance(body, Exit):
        return MessageType.EXIT, b""
    if isinstance(body, Refuse):
        text = body.text.encode("utf-8")[:200]
        return MessageType.REFUSE, _REFUSE.pack(body.code, len(text)) + text
    raise TypeError(f"not a message body: {body!r}")


def encode(body: Body, sender: int, seq: int, timestamp: float, kind: MessageType | None = None) -> bytes:
    """One whole message.  ``kind`` picks NUMBER, NEW_PLAYER or TABLE for an :class:`Assign`."""
    if isinstance(body, Assign):
        if kind not in (MessageType.NUMBER, MessageType.NEW_PLAYER, MessageType.TABLE):
            raise TypeError("an Assign needs kind=NUMBER, NEW_PLAYER or TABLE")
        mtype, payload = kind, _encode_table(body)
    else:
        mtype, payload = encode_body(body)
    if len(payload) > MAX_PAYLOAD:
        raise ValueError(f"payload of {len(payload)} bytes is over {MAX_PAYLOAD}")
    if not math.isfinite(timestamp):
        raise ValueError(f"a message timestamp must be finite, got {timestamp}")
    stamp = int(round(timestamp * 1e6)) % _WRAP
    return HEADER.pack(MAGIC, VERSION, mtype, sender, seq & 0xFFFFFFFF, stamp, len(payload)) + payload


def age(now: float, timestamp: float) -> float:
    """Seconds from a message's ``timestamp`` (as decoded) to ``now`` on the same clock,
    across the microsecond counter's wrap (every 71 minutes); negative if ahead."""
    d = (int(round(now * 1e6)) - int(round(timestamp * 1e6))) % _WRAP
    if d >= _WRAP // 2:
        d -= _WRAP
    return d / 1e6


def _decode_payload(mtype: MessageType, p: bytes) -> Body:
    def exact(s: struct.Struct) -> tuple:
        if len(p) != s.size:
            raise BadMessage("length")
        return s.unpack(p)

    if mtype == MessageType.CHALLENGE:
        nonce, pw, term, host, players = exact(_CHALLENGE)
        if pw > 1 or host > MAX_PLAYERS or players > MAX_PLAYERS:
            raise BadMessage("range")
        return Challenge(nonce, bool(pw), term, host, players)
    if mtype == MessageType.JOIN:
        if len(p) < _JOIN.size:
            raise BadMessage("length")
        mac, digest, tcp, udp, nlen = _JOIN.unpack_from(p)
        if len(p) != _JOIN.size + nlen or not 1 <= nlen <= MAX_NAME:
            raise BadMessage("length")
        if tcp == 0 or udp == 0:
            raise BadMessage("range")
        return Join(_read_name(p[_JOIN.size:]), tcp, udp, mac, digest)
    if mtype == MessageType.HELLO:
        mac, epoch = exact(_HELLO)
        return Hello(epoch, mac)
    if mtype in (MessageType.NUMBER, MessageType.NEW_PLAYER, MessageType.TABLE):
        return _decode_table(p)
    if mtype == MessageType.STATE:
        tank_alive, t_ms, x, z, h, vx, vz, om = exact(_STATE)
        tank, alive = tank_alive & ~ALIVE_BIT, bool(tank_alive & ALIVE_BIT)
        t = t_ms / 1000.0
        _player(tank)
        _finite(t, x, z, h, vx, vz, om)
        _in(t, 0.0, MAX_TIME)
        for c in (x, z):
            _in(c, -MAX_COORD, MAX_COORD)
        for v in (vx, vz, om):
            _in(v, -MAX_SPEED, MAX_SPEED)
        _in(h, -4 * math.pi, 4 * math.pi)
        return State(tank, t, x, z, h, vx, vz, om, 0.0, alive)
    if mtype == MessageType.SHOT:
        tank, t, x, z, h, vx, vz = exact(_SHOT)
        _player(tank)
        _finite(t, x, z, h, vx, vz)
        _in(t, 0.0, MAX_TIME)
        for c in (x, z):
            _in(c, -MAX_COORD, MAX_COORD)
        for v in (vx, vz):
            _in(v, -MAX_SPEED, MAX_SPEED)
        _in(h, -4 * math.pi, 4 * math.pi)
        return Shot(tank, t, x, z, h, vx, vz)
    if mtype == MessageType.HIT:
        shooter, victim, t, dmg, hp, killed, x, z = exact(_HIT)
        _player(shooter)
        _player(victim)
        _finite(t, dmg, hp, x, z)
        _in(t, 0.0, MAX_TIME)
        _in(dmg, 0.0, MAX_HP)
        _in(hp, -MAX_HP, MAX_HP)
        for c in (x, z):
            _in(c, -MAX_COORD, MAX_COORD)
        if killed > 1 or shooter == victim:
            raise BadMessage("range")
        return Hit(shooter, victim, t, dmg, hp, bool(killed), x, z)
    if mtype == MessageType.EXIT:
        if p:
            raise BadMessage("length")
        return Exit()
    if mtype == MessageType.REFUSE:
        if len(p) < _REFUSE.size:
            raise BadMessage("length")
        code, tlen = _REFUSE.unpack_from(p)
        if len(p) != _REFUSE.size + tlen:
            raise BadMessage("length")
        if code not in {c.value for c in RefuseCode}:
            raise BadMessage("range")
        try:
            text = p[_REFUSE.size:].decode("utf-8")
        except UnicodeDecodeError:
            raise BadMessage("name") from None
        return Refuse(code, text)
    raise BadMessage("type")      # pragma: no cover - the caller checked the type


def parse_header(data: bytes) -> tuple[MessageType, int, int, float, int]:
    """(type, sender, seq, timestamp, payload length) of a header, or BadMessage."""
    if len(data) < HEADER.size:
        raise BadMessage("short")
    magic, version, mtype, sender, seq, ts, length = HEADER.unpack_from(data)
    if magic != MAGIC:
        raise BadMessage("magic")
    if version != VERSION:
        raise BadMessage("version")
    try:
        mt = MessageType(mtype)
    except ValueError:
        raise BadMessage("type") from None
    if sender > MAX_PLAYERS:
        raise BadMessage("sender")
    if length > MAX_PAYLOAD:
        raise BadMessage("length")
    return mt, sender, seq, ts / 1e6, length


def decode(data: bytes, counter: Counter | None = None) -> Message | None:
    """A whole message (one datagram), or None with ``counter[reason] += 1``."""
    try:
        mt, sender, seq, ts, length = parse_header(data)
        if len(data) != HEADER.size + length:
            raise BadMessage("length")
        body = _decode_payload(mt, bytes(data[HEADER.size:]))
        # only a joiner (and a listener answering one) may not have a number yet
        if sender == 0 and mt not in (MessageType.JOIN, MessageType.CHALLENGE, MessageType.REFUSE):
            raise BadMessage("sender")
        return Message(mt, sender, seq, ts, body)
    except BadMessage as e:
        if counter is not None:
            counter[e.reason] += 1
        return None
    except (struct.error, ValueError, TypeError):   # belt and braces: never raise on input
        if counter is not None:
            counter["payload"] += 1
        return None


# the TCP framing lives in its own module; it is part of this API
from .framing import StreamReader  # noqa: E402,F401
