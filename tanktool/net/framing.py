"""Messages out of a TCP byte stream (:class:`StreamReader`, also reachable as
``protocol.StreamReader``)."""

from __future__ import annotations

from collections import Counter

from .protocol import HEADER, MAX_PAYLOAD, BadMessage, Message, decode, parse_header


class StreamReader:
    """Frames messages out of a TCP byte stream.

    A stream cannot resynchronise after a bad header (where would the next message
    start?), so the first malformed header marks the stream ``broken`` and its owner
    closes the connection; a bad payload inside a well-framed message is only dropped.
    """

    def __init__(self, counter: Counter, max_buffer: int = 16 * (HEADER.size + MAX_PAYLOAD)) -> None:
        self.buffer = bytearray()
        self.counter = counter
        self.broken = False
        self.max_buffer = max_buffer

    def feed(self, data: bytes) -> list[Message]:
        """Messages completed by ``data`` (bad ones counted and dropped)."""
        if self.broken:
            return []
        self.buffer += data
        out: list[Message] = []
        while len(self.buffer) >= HEADER.size:
            try:
                _, _, _, _, length = parse_header(self.buffer)
            except BadMessage as e:
                self.counter[e.reason] += 1
                self.broken = True
                self.buffer.clear()
                return out
            end = HEADER.size + length
            if len(self.buffer) < end:
                break
            msg = decode(bytes(self.buffer[:end]), self.counter)
            del self.buffer[:end]
            if msg is not None:
                out.append(msg)
        if len(self.buffer) > self.max_buffer:      # cannot happen with valid headers; be safe
            self.counter["overflow"] += 1
            self.broken = True
            self.buffer.clear()
        return out
