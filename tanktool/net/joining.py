"""The listener's side: accepting connections, challenges, JOIN and HELLO (password,
digest, names, numbers and epochs), the table, computer opponents and kicks.  No I/O:
part of :class:`~tanktool.net.core.Core`."""

from __future__ import annotations

import hmac

from ..errors import NetError
from . import protocol as P
from .auth import datagram_key, hello_mac, join_mac
from . import limits as L
from .links import Link, NetEvent
from .names import name_problem


class JoiningMixin:
    """Admitting players and keeping the table."""

    #: player numbers this session gives (1..slots): fewer than the protocol's when the
    #: arena holds fewer tanks at once (set by net/session.py before anyone joins)
    slots: int = P.MAX_PLAYERS

    def accepted(self, addr: tuple, now: float) -> int | None:
        """A connection from ``addr`` (ip, port) was accepted: its link number (a
        challenge is on its way), or None when there is no room (close it)."""
        self.now = now
        self.dropped.source = addr[0]      # TCP: by address (each connection has its own port)
        if self.closed:                    # left or kicked: no session to offer anyone
            return None
        if not self._make_room(addr[0]):
            self.dropped["too_many_pending"] += 1
            return None
        link = self._new_link(tuple(addr), nonce=self.nonce_source(P.NONCE_SIZE))
        self.pending.append(link)
        challenge = P.Challenge(link.nonce, self.password is not None, self.term, self.host_number,
                                len(self._others()) + (1 if self.number else 0))
        self._queue(link, self._pack_control(challenge))
        return link.id

    def _on_pending(self, link: Link, m: P.Message) -> None:
        body = m.body
        now = self.now
        ip = link.addr[0]
        if isinstance(body, (P.Join, P.Hello)) and self.password:
            # every answer is checked: a player who proves the password gets in however
            # many wrong guesses an attacker sharing its address made (finding 5); the
            # guesses only earn "too many wrong passwords" once over their budget
            if isinstance(body, P.Join):
                good = join_mac(self.password, link.nonce, body.name)
            else:
                good = hello_mac(self.password, link.nonce, m.sender, body.epoch)
            if not hmac.compare_digest(body.mac, good):
                if not self.auth_failures.take(ip, now):
                    self._refuse(link, P.RefuseCode.RATE, f"too many wrong passwords from {ip}: try again later")
                else:
                    self._refuse(link, P.RefuseCode.PASSWORD, "wrong password")
                return
            link.proven = True
        if isinstance(body, P.Join):
            if self.step_down_to is not None:
                # a newer session goes on there: we are stale, send the joiner on
                self._refuse(link, P.RefuseCode.NOT_HOST, f"{self.step_down_to[0]}:{self.step_down_to[1]}")
                return
            if not self.is_host:
                h = self.table.get(self.host_number)
                self._refuse(link, P.RefuseCode.NOT_HOST, f"{h.ip}:{h.tcp_port}" if h else "")
                return
            if self.probing():
                # alone after losing everyone: maybe left behind by a newer session (terms.py)
                self._refuse(link, P.RefuseCode.RATE, "checking whether the session goes on elsewhere: try again")
                return
            if not self.joins.allow(ip, now):
                # each join makes the host send every member the new table: a flood of
                # joins would fill the members' rate limiters with the host's messages
                self._refuse(link, P.RefuseCode.RATE, f"too many joins from {ip}: try again in a few seconds")
                return
            self._admit(link, m)
        elif isinstance(body, P.Hello):
            link.hello = m
            self._try_hello(link)
        else:
            self.dropped["unexpected"] += 1

    def _try_hello(self, link: Link) -> bool:
        """Bind a HELLO link when the table knows its number with that epoch and the
        address matches; otherwise it waits (the host's NEW_PLAYER may still be on
        its way) until HELLO_WAIT."""
        m = link.hello
        assert m is not None
        n = m.sender
        e = self.table.get(n)
        if e is None or e.epoch != m.body.epoch:
            epoch = m.body.epoch
            if (n, epoch) in self.departed:
                self._refuse(link, P.RefuseCode.BAD_REQUEST, "you left the session")
            elif self.is_host or epoch <= self.max_epoch:
                # the host knows every number it gave, and epochs only grow: this HELLO
                # is for no player that is or will be (finding 5: parked HELLOs)
                self.dropped["unknown"] += 1
                self._refuse(link, P.RefuseCode.BAD_REQUEST, f"no player {n} with epoch {epoch} here")
            else:
                waiting = [k for k in self.pending if k.hello is not None and not k.closing]
                if len(waiting) > L.MAX_HELLO_WAITING:
                    # a real joiner's HELLO waits a round trip at most: the oldest goes
                    self._refuse(min(waiting, key=lambda k: (k.proven, k.opened)), P.RefuseCode.BAD_REQUEST,
                                 "no such player yet")
            return False
        ip = link.addr[0]
        mine = self.links.get(n)
        if mine is not None and mine.initiated and n > self.number and ip == e.ip:
            # both opened a link at once: the one opened by the higher number stays
            mine.refused = True
            self._close_link(mine)
        elif n == self.number or n in self.links or (ip != e.ip and e.ip != "0.0.0.0"):
            self.dropped["impostor"] += 1
            self._refuse(link, P.RefuseCode.BAD_REQUEST, f"player {n} is already linked")
            return False
        self.pending.remove(link)
        if self.password:
            link.udp_key = datagram_key(self.password, m.body.mac)
        self.window.anchor(n, m.seq, self.now)
        self._bind_link(link, n)
        return True

    def _admit(self, link: Link, m: P.Message) -> None:
        join: P.Join = m.body
        if not hmac.compare_digest(join.digest, self.digest):
            what = f" ({self.label})" if self.label else ""
            self._refuse(link, P.RefuseCode.MISMATCH,
                         f"your arena or vehicle differs from the host's{what}: their hashes do not match")
            return
        problem = name_problem(join.name, [e.name for e in self.table.values()])
        if problem is not None:
            self._refuse(link, P.RefuseCode.NAME, problem)
            return
        slot = self._new_slot()
        if slot is None:
            room = "" if self.slots >= P.MAX_PLAYERS else f" (the arena holds {self.slots} tanks at once)"
            self._refuse(link, P.RefuseCode.FULL, f"session full: {self.slots} players already{room}")
            return
        ip = link.addr[0]
        n, epoch = slot
        self.table[n] = P.Entry(n, epoch, ip, join.tcp_port, join.udp_port, join.name)
        self._saw(self.table[n])
        self.pending.remove(link)
        if self.password:
            link.udp_key = datagram_key(self.password, join.mac)
        self.window.anchor(n, m.seq, self.now)
        self._bind_link(link, n)
        table = self._table()
        t = self.session_time()
        lost = self._probe_list()
        self._queue(link, self._pack(P.Assign(n, t, table, self.term, lost), P.MessageType.NUMBER))
        news = self._pack(P.Assign(n, t, table, self.term, lost), P.MessageType.NEW_PLAYER)
        for k, other in list(self.links.items()):
            if k != n:
                self._queue(other, news)
        self._forget(n)
        self.events.append(NetEvent("joined", n, self.table[n]))

    def _refuse(self, link: Link, code: P.RefuseCode, text: str) -> None:
        self.dropped[f"refused_{code.name.lower()}"] += 1
        self._queue(link, self._pack_control(P.Refuse(code, text)))
        link.closing = True
        link.hello = None
        self._close_link(link, "refused")

    def _saw(self, e: P.Entry) -> None:
        """Note an entry's epoch and number as used (never given again)."""
        self.addr_buckets.clear()            # the tanks per address may have changed
        self.max_epoch = max(self.max_epoch, e.epoch)
        self.used_numbers.add(e.number)
        if e.number in self.freed:
            self.freed.remove(e.number)

    def _new_slot(self) -> tuple[int, int] | None:
        """(number, epoch) for a newcomer: a number never used in this session while
        there is one, else the one freed longest ago; an epoch above every one seen.
        None when full."""
        free = [n for n in range(1, self.slots + 1) if n not in self.table]
        if not free:
            return None
        fresh = [n for n in free if n not in self.used_numbers]
        if fresh:
            n = fresh[0]
        else:
            order = [k for k in self.freed if k in free]
            n = order[0] if order else free[0]
        return n, self.max_epoch + 1

    def add_bot(self, name: str, now: float) -> int | None:
        """The host adds a computer opponent (it runs it): its number, or None when full."""
        self.now = now
        if not self.is_host:
            raise NetError("only the host adds computer opponents")
        slot = self._new_slot()
        if slot is None:
            return None
        n, epoch = slot
        me = self.table[self.number]
        taken = [e.name for e in self.table.values()]
        base, k = name, 1
        while name_problem(name, taken) is not None:     # a player already took "bot1"
            k += 1
            name = f"{base}-{k}"
        self.table[n] = P.Entry(n, epoch, me.ip, me.tcp_port, me.udp_port, name, owner=self.number)
        self._saw(self.table[n])
        news = self._pack(P.Assign(n, self.session_time(), self._table(), self.term, self._probe_list()),
                          P.MessageType.NEW_PLAYER)
        for link in list(self.links.values()):
            if not link.outgoing:
                self._queue(link, news)
        self._forget(n)
        self.events.append(NetEvent("joined", n, self.table[n]))
        return n

    def kick(self, n: int, reason: str, now: float) -> None:
        """The host disconnects player ``n``: a refusal saying why, then it leaves
        every table (TABLE), and its (number, epoch) is never let back in."""
        self.now = now
        if not self.is_host or n == self.number or n not in self.table:
            return
        link = self.links.get(n)
        if link is not None:
            self._queue(link, self._pack(P.Refuse(P.RefuseCode.BAD_REQUEST, reason)))
            self._close_link(link, "kicked", linger=1.0)
        self._remove(n, "disconnected: " + reason)

    def _table(self) -> P.Table:
        return P.Table(self.host_number, tuple(self.table[n] for n in sorted(self.table)))

    def _merge_table(self, table: P.Table, new: int) -> None:
        """The host's table: add who we do not know (unless we saw them leave)."""
        for e in table.entries:
            self.max_epoch = max(self.max_epoch, e.epoch)
            if (e.number, e.epoch) in self.departed or e.number == self.number:
                continue
            old = self.table.get(e.number)
            if old is not None and old.epoch == e.epoch and old.owner != e.owner:
                self.table[e.number] = e           # a computer opponent changed hands
                self.addr_buckets.clear()
                if e.owner == self.number:
                    self.events.append(NetEvent("adopt", e.number, e))
                continue
            if old is None or old.epoch != e.epoch:
                if old is not None:
                    self._remove(e.number, "replaced")
                self.table[e.number] = e
                self._saw(e)
                self.last_heard[e.number] = self.now
                self._forget(e.number)
                self.events.append(NetEvent("joined", e.number, e))
        for link in list(self.pending):
            if link.hello is not None:
                self._try_hello(link)
