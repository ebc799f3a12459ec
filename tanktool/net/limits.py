"""The limits of network play in one place: silences, deadlines, caps and rates
(:mod:`.peer` and its parts read them; tests may patch them on :mod:`.peer`)."""

from __future__ import annotations

#: a peer silent this long has left (and if it hosted, the host migrates) [s]
SILENCE = 3.0
#: an accepted TCP connection must say JOIN or HELLO within this time [s]: a real peer
#: answers the challenge within a round trip (a joiner answers its mesh links' challenges
#: before ``Peer.join`` returns)
PENDING_TIMEOUT = 2.0
#: a HELLO waits this long for the host's NEW_PLAYER to name its number [s]
HELLO_WAIT = 5.0
#: HELLOs waiting at once for a number the table does not know yet: a real joiner's
#: waits a round trip at most (the host's NEW_PLAYER is on its way), so a few suffice;
#: more would let parked HELLOs crowd real joiners out of the pending list
MAX_HELLO_WAITING = 4
#: unidentified connections at once, and from one address; past either, a new connection
#: closes the oldest silent one (of the busiest address), so silent connections cannot
#: lock a real player out: it answers within a round trip, they never do
MAX_PENDING = 64
MAX_PENDING_PER_IP = 48
#: connections accepted per poll, after the data of those already open has been read (so
#: a new one is read before ACCEPTS_PER_POLL more can push it out)
ACCEPTS_PER_POLL = 16
LISTEN_BACKLOG = 128
#: per link / per tank message rates: a tank state at 30 Hz, a few events
TCP_RATE, TCP_BURST = 100.0, 200.0
UDP_RATE, UDP_BURST = 90.0, 45.0
#: datagrams read per poll at most (a poll comes every step, 120 a second)
UDP_READS = 1024
#: joins (host): per address a burst that lets a whole LAN party (or a loopback test
#: session) in at once, then one a second; overall, what many addresses together get
JOIN_RATE, JOIN_BURST = 1.0, 10.0
JOINS_RATE, JOINS_BURST = 5.0, 20.0
#: wrong passwords per address before its answers are no longer even checked
AUTH_FAIL_RATE, AUTH_FAIL_BURST = 1.0, 10.0
#: how long ``Peer.join`` waits for its mesh links' challenges before it returns [s]
JOIN_SETTLE = 1.0
#: how long ``Peer.join`` keeps retrying a host that says "too many joins" [s]
JOIN_BUSY_WAIT = 0.5
MAX_OUTBUF = 256 * 1024
LATENCY_SAMPLES = 200_000
