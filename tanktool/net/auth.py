"""Passwords on the wire: the HMAC handshake, the datagram key it yields, and the tags
that authenticate every UDP datagram of a password session.

With a password, every TCP link starts with a challenge: the listener sends a fresh
16-byte nonce, the connecting peer answers with ``HMAC-SHA256(password, label ‖ nonce ‖
...)`` (JOIN to the host, HELLO to a member).  The password never travels and a recorded
answer does not fit the next nonce.  Both ends of the link then hold that handshake MAC,
and derive the pair's datagram key from it::

    key = HMAC-SHA256(password, b"tanktool udp key" ‖ handshake MAC)        # 32 bytes

Someone who saw the handshake knows the MAC but not the password, so cannot compute the
key; each link has its own nonce, so each pair of peers has its own key.  A datagram is
then the message followed by a tag, keyed BLAKE2b (RFC 7693's MAC mode) cut to 8 bytes::

    tag = BLAKE2b(message, key=key, digest_size=8)                          # 8 bytes

BLAKE2b's keyed mode is a MAC by design and costs under 1 us a datagram here, against
3-4 us for HMAC-SHA256 (bench/net.py); 64 bits is plenty for states that are stale in a
tenth of a second (forging one takes ~2^63 tries, online) and keeps a state datagram at
44 bytes.
"""

from __future__ import annotations

import hmac
from hashlib import blake2b, sha256

#: bytes of the truncated HMAC-SHA256 tag that ends every datagram of a password session
TAG_SIZE = 8
KEY_LABEL = b"tanktool udp key"


def join_mac(password: str, nonce: bytes, name: str) -> bytes:
    """A JOIN's answer to the host's challenge."""
    return hmac.new(password.encode(), b"join" + nonce + name.encode(), sha256).digest()


def hello_mac(password: str, nonce: bytes, number: int, epoch: int) -> bytes:
    """A HELLO's answer to a member's challenge (the joiner's number and epoch)."""
    return hmac.new(password.encode(), b"hello" + nonce + bytes([number]) + epoch.to_bytes(4, "big"),
                    sha256).digest()


def datagram_key(password: str, handshake_mac: bytes) -> bytes:
    """The key of the datagrams between the two ends of a link, from its handshake MAC."""
    return hmac.new(password.encode(), KEY_LABEL + handshake_mac, sha256).digest()


def seal(key: bytes, message: bytes) -> bytes:
    """``message`` followed by its tag."""
    return message + blake2b(message, key=key, digest_size=TAG_SIZE).digest()


def unseal(key: bytes, datagram: bytes) -> bytes | None:
    """The message of a sealed datagram, or None when the tag is missing or wrong."""
    if len(datagram) <= TAG_SIZE:
        return None
    message, tag = datagram[:-TAG_SIZE], datagram[-TAG_SIZE:]
    if not hmac.compare_digest(tag, blake2b(message, key=key, digest_size=TAG_SIZE).digest()):
        return None
    return message
