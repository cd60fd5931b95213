"""Who gets a connection, for every listener of the program: one admission policy.

Every listener (the client port, the web page and its WebSocket, the rotctld-compatible
ports, the Antenna Genius ports, the MOAS Rotator port, the emulator's control socket,
the single-instance hand-over socket, and any front added later) asks an
:class:`Admission` for a :class:`Ticket` the moment a connection is accepted, before a
byte of it is read, through its one door (:mod:`.gate`), and gives the ticket back when
the connection closes.  The ticket carries the peer (``host``, ``address``), read once.  A
ticket has a *standing*, which only rises:

``NEW``
    accepted, has not said who it is (before the client protocol's ``hello``, before a
    rotctld command, ...);
``GREETED``
    has said who it is (:meth:`Ticket.greeted`: a valid ``hello``, a first good command);
``OPERATOR``
    an authenticated operator (:meth:`Ticket.operator`, called after a ``hello`` whose
    token names one).

The rules, in the order they are applied to a newcomer:

1. Operators have capacity of their own (``operators``): an operator is never refused
   or evicted because of the connections of anyone else.
2. At most ``per_address`` connections (``NEW`` and ``GREETED``) from one address.
3. At most ``before_hello`` connections of one address may be ``NEW`` at once: that is
   each address's reserve for connections that have not said who they are yet, and a
   crowd that never says hello cannot take more than it from any one address.
4. At most ``total`` connections that are not operators, all addresses together.  When
   they are all taken, the newcomer takes the place of another connection -- the fair
   share -- chosen among the addresses that hold *more* connections than the
   newcomer's own: a ``NEW`` one before a ``GREETED`` one (the one waiting longest to
   say who it is: a client's own connections, opened a moment ago, are the last to
   go), else the ``GREETED`` one idle the longest of the address holding the most.
   A ``NEW`` connection that has waited :data:`PATIENCE` seconds may also give its
   place to a newcomer from an address holding as many as its own.  One younger than
   :data:`GRACE` goes last of all (it has had no time to say who it is: under a crowd
   that comes back as fast as it is closed, an operator's new connection would
   otherwise never live to give its token).  Later still goes one whose secret (a
   token, an Antenna Genius code) is being checked (:meth:`Ticket.checking`): the check
   runs on a worker thread, and an operator's connection must not lose its place while
   it waits for the answer that would move it to the operators' capacity (the checks
   waiting at once are few: the worker's queue is bounded).  The connection so chosen is
   closed (its front tells it why) and its place given at once.  A newcomer whose address holds
   as many as any other is refused.

Deadlines (:class:`Deadlines`, per listener): a ``NEW`` connection must say who it is
within ``hello`` seconds of its acceptance, and any other must show a sign of life (a
line, a message, a command: :meth:`Ticket.touch`) at least every ``idle`` seconds.
The admission checks them itself every :data:`SWEEP_EVERY` seconds on its clock
(:meth:`Admission.sweep`), and closes the late ones through their front: a listener gets
them without a timer of its own.

Addresses are compared by :func:`address_key` (an IPv4 client of a dual-stack socket is
its IPv4 address).  Loopback is no exception: ``127.0.0.1`` and ``127.0.0.2`` are two
addresses.

Log lines go through :attr:`Admission.trouble`, one line a minute for each kind of
trouble (never per address: a crowd of addresses writes no more than one), with the
count of those left out.
"""

from __future__ import annotations

import contextlib
import enum
import ipaddress
import logging
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Final

from moas_gui.clock import LOOP_CLOCK, Clock, Timer
from moas_gui.errors import MoasError
from moas_gui.log_limit import LogLimiter, held_text

log = logging.getLogger(__name__)


DEFAULT_PER_ADDRESS: Final = 32
"""Connections from one address at once unless told otherwise: far more than one
computer's clients and browser pages need, well under the client server's whole limit."""

DEFAULT_BEFORE_HELLO: Final = 16
"""Connections of one address that may be waiting to say who they are at once: more
than a browser opens to load a page in a few tabs (six per page, kept a few seconds)."""

DEFAULT_OPERATORS: Final = 64
"""Authenticated operators' connections at once, beside everyone else's."""

PATIENCE: Final = 0.5
"""Seconds after which a connection that has not said who it is may give its place to a
newcomer from any other address, even one holding as many (a client says hello within
milliseconds; a silent crowd spread one connection to an address would otherwise keep
every client to a single connection)."""

GRACE: Final = 0.1
"""Seconds a new connection has to say who it is before it is the first to make room
for a newcomer (a hello, an ``auth`` line, within one round trip on a LAN)."""

SWEEP_EVERY: Final = 1.0
"""Seconds between two checks of the deadlines."""


class Standing(enum.IntEnum):
    """How far a connection has come; see the module notes."""

    NEW = 0
    GREETED = 1
    OPERATOR = 2


@dataclass(frozen=True, slots=True)
class Deadlines:
    """A listener's clocks: ``hello`` seconds to say who one is, then at most ``idle``
    seconds of silence (``None``: no such deadline)."""

    hello: float | None = None
    idle: float | None = None


NO_DEADLINES: Final = Deadlines()


class Refused(MoasError):
    """A newcomer the admission does not take; ``reason`` says why in words, ``limit``
    which limit (``"hello"``, ``"address"`` or ``"total"``)."""

    def __init__(self, reason: str, limit: str) -> None:
        super().__init__(reason)
        self.reason = reason
        self.limit = limit


def address_key(host: str) -> str:
    """The key under which a peer is counted: its normalised address (an IPv6 zone
    dropped, an IPv4-mapped IPv6 address as the IPv4 one)."""
    try:
        parsed = ipaddress.ip_address(host.strip())
    except ValueError:
        return host
    if isinstance(parsed, ipaddress.IPv6Address):
        if parsed.ipv4_mapped is not None:
            return str(parsed.ipv4_mapped)
        if parsed.scope_id is not None:
            return str(ipaddress.IPv6Address(int(parsed)))
    return str(parsed)


Evict = Callable[[str], None]
"""How a front closes one of its connections, told why (one sentence)."""


class Ticket:
    """One admitted connection's place; see the module notes.

    The hook for the fronts: call :meth:`greeted` once the peer has said who it is
    (the client protocol: after a valid ``hello``), :meth:`operator` once it is known
    to be an authenticated operator, :meth:`touch` on every sign of life, and
    :meth:`release` when the connection closes (again is harmless)."""

    __slots__ = (
        "_admission",
        "_evict",
        "address",
        "admitted_at",
        "checks",
        "deadlines",
        "evicted",
        "front",
        "host",
        "key",
        "last_active",
        "released",
        "standing",
    )

    def __init__(
        self,
        admission: Admission,
        key: str,
        address: str,
        front: str,
        evict: Evict | None,
        deadlines: Deadlines,
        now: float,
        host: str = "",
    ) -> None:
        self._admission = admission
        self._evict = evict
        self.key = key
        self.host = host or key
        """The peer's host as its socket gave it (what a front checks it against)."""
        self.address = address
        """The peer as log lines name it (``host:port``), read once when it was accepted."""
        self.front = front
        self.deadlines = deadlines
        self.standing = Standing.NEW
        self.admitted_at = now
        self.last_active = now
        self.released = False
        self.checks = 0
        """Secret checks of this connection's under way (:meth:`checking`)."""
        self.evicted: str | None = None
        """Why the admission closed this connection, once it has."""

    def __repr__(self) -> str:
        return f"<Ticket {self.front} {self.address} {self.standing.name}>"

    def set_evict(self, evict: Evict) -> None:
        """How to close this connection from now on (a front's inner layer, once made)."""
        self._evict = evict

    def touch(self) -> None:
        """A sign of life: the idle clock starts again."""
        self.last_active = self._admission.clock.now()

    def greeted(self) -> None:
        """The peer has said who it is: it leaves its address's reserve for newcomers."""
        if self.standing is Standing.NEW and not self.released:
            self.standing = Standing.GREETED
            self.touch()

    def operator(self) -> bool:
        """The peer is an authenticated operator: from now on it counts against the
        operators' own capacity, and is never evicted for anyone else.  ``False`` (and
        it stays as it was) when the operators' capacity is full."""
        if self.released:
            return False
        if self.standing is not Standing.OPERATOR:
            if not self._admission._promote(self):
                return False
            self.standing = Standing.OPERATOR
        self.touch()
        return True

    @contextlib.contextmanager
    def checking(self) -> Iterator[None]:
        """While a secret this connection sent is checked off the loop: it is the last
        to make room for a newcomer (see the module notes), so that an operator's
        connection lives to be moved to the operators' capacity by the answer."""
        self.checks += 1
        try:
            yield
        finally:
            self.checks -= 1

    def release(self) -> None:
        """The connection has closed: its place is free."""
        if not self.released:
            self.released = True
            self._admission._forget(self)

    def _close(self, reason: str) -> None:
        self.evicted = reason
        self.release()
        if self._evict is not None:
            try:
                self._evict(reason)
            except Exception:
                log.exception("Closing the connection from %s failed", self.address)

    def overdue(self, now: float) -> str | None:
        """Why this connection is past a deadline at ``now``, or ``None``."""
        hello, idle = self.deadlines.hello, self.deadlines.idle
        if self.standing is Standing.NEW and hello is not None and now - self.admitted_at >= hello:
            return f"it did not say who it is within {hello:g} s"
        if (
            self.standing is not Standing.NEW
            and idle is not None
            and now - self.last_active >= idle
        ):
            return f"silent for {idle:g} s"
        return None


def checking(ticket: Ticket | None) -> contextlib.AbstractContextManager[None]:
    """:meth:`Ticket.checking` of ``ticket``; nothing when there is none (a connection
    no admission holds: a test's)."""
    return contextlib.nullcontext() if ticket is None else ticket.checking()


class Admission:
    """One pool of connections under the rules of the module notes."""

    def __init__(
        self,
        total: int,
        per_address: int = DEFAULT_PER_ADDRESS,
        *,
        before_hello: int = DEFAULT_BEFORE_HELLO,
        operators: int = DEFAULT_OPERATORS,
        clock: Clock = LOOP_CLOCK,
        trouble: LogLimiter | None = None,
        what: str = "connections",
    ) -> None:
        if min(total, per_address, before_hello) < 1 or operators < 0:
            raise ValueError(
                f"limits must be at least 1, not {total}, {per_address} and {before_hello}"
            )
        self.total = total
        self.per_address = per_address
        self.before_hello = before_hello
        self.operators = operators
        self.clock = clock
        self.trouble = trouble if trouble is not None else LogLimiter()
        """One log line a minute per kind of trouble (shared with the fronts that ask)."""
        self.what = what
        """What this pool holds, in words, for its log lines."""
        self._by_address: dict[str, dict[Ticket, None]] = {}
        self._rest = 0
        self._operators: dict[Ticket, None] = {}
        self._sweep: Timer | None = None

    # -- counts ---------------------------------------------------------------------------
    @property
    def count(self) -> int:
        """Connections admitted and open now, operators included."""
        return self._rest + len(self._operators)

    @property
    def operator_count(self) -> int:
        return len(self._operators)

    def open_from(self, host: str) -> int:
        """Connections from ``host`` that are not operators'."""
        return len(self._by_address.get(address_key(host), ()))

    def tickets(self) -> list[Ticket]:
        """Every open ticket (operators' last)."""
        rest = [t for held in self._by_address.values() for t in held]
        return rest + list(self._operators)

    # -- admitting ------------------------------------------------------------------------
    def admit(
        self,
        host: str,
        evict: Evict | None = None,
        *,
        front: str = "connection",
        deadlines: Deadlines = NO_DEADLINES,
        address: str | None = None,
    ) -> Ticket:
        """A ticket for a newcomer from ``host``; raises :class:`Refused` saying why not.
        ``evict`` is how the admission closes it should it have to (told why)."""
        key = address_key(host)
        held = self._by_address.get(key, {})
        if len(held) >= self.per_address:
            raise Refused(
                f"{len(held)} connections from that address are open, the most one "
                "address may hold",
                "address",
            )
        waiting = sum(1 for t in held if t.standing is Standing.NEW)
        if waiting >= self.before_hello:
            raise Refused(
                f"{waiting} connections from that address have not said who they "
                "are yet, the most one address may have waiting",
                "hello",
            )
        if self._rest >= self.total:
            victim = self._victim(key, len(held))
            if victim is None:
                raise Refused(
                    f"{self._rest} {self.what} are open, the most this server "
                    "takes at once, and no other address holds more",
                    "total",
                )
            self._make_room(victim, address or host)
        ticket = Ticket(self, key, address or host, front, evict, deadlines, self.clock.now(),
                        host)
        self._by_address.setdefault(key, {})[ticket] = None
        self._rest += 1
        if deadlines != NO_DEADLINES:
            self._keep_sweeping()
        return ticket

    def _victim(self, key: str, held: int) -> Ticket | None:
        """The connection a newcomer from ``key``, an address holding ``held``, takes the
        place of."""
        best: Ticket | None = None
        best_rank: tuple[int, int, float] | None = None
        now = self.clock.now()
        patient, young = now - PATIENCE, now - GRACE
        for other, tickets in self._by_address.items():
            size = len(tickets)
            if other == key:
                continue
            for ticket in tickets:
                if size <= held and not (
                    ticket.standing is Standing.NEW and ticket.admitted_at <= patient
                ):
                    continue
                # one waiting to say who it is: the longest waiting, whatever its address
                # holds (a client's own connections, opened together, are the youngest);
                # else the idlest of the address holding the most; one just opened
                # later, one whose secret is being checked last of all
                new = ticket.standing is Standing.NEW
                order = 2 if new and ticket.admitted_at > young else int(ticket.standing)
                if ticket.checks:
                    order = 3
                rank = (order, 0 if new else -size, ticket.last_active)
                if best_rank is None or rank < best_rank:
                    best, best_rank = ticket, rank
        return best

    def _make_room(self, victim: Ticket, newcomer: str) -> None:
        standing = "before saying who it was" if victim.standing is Standing.NEW else "idle"
        why = (
            "the server is full, and a newcomer from an address holding fewer connections "
            f"took the place of this one ({standing} the longest, of an address holding "
            f"{len(self._by_address.get(victim.key, ()))})"
        )
        held = self.trouble.allow(("made room", self.what))
        if held is not None:
            log.warning(
                "Made room for a newcomer from %s: closed the %s from %s, the %s of "
                "an address holding more%s",
                newcomer,
                victim.front,
                victim.address,
                "waiting longest" if victim.standing is Standing.NEW else "idle longest",
                held_text(held, "more closed to make room"),
            )
        victim._close(why)

    def _promote(self, ticket: Ticket) -> bool:
        if len(self._operators) >= self.operators:
            held = self.trouble.allow(("operators full", self.what))
            if held is not None:
                log.warning(
                    "An operator at %s stays an ordinary connection: %d operators' "
                    "connections are open, the most at once%s",
                    ticket.address,
                    len(self._operators),
                    held_text(held),
                )
            return False
        self._drop(ticket)
        self._operators[ticket] = None
        return True

    def _drop(self, ticket: Ticket) -> None:
        held = self._by_address.get(ticket.key)
        if held is not None and ticket in held:
            del held[ticket]
            self._rest -= 1
            if not held:
                del self._by_address[ticket.key]

    def _forget(self, ticket: Ticket) -> None:
        self._operators.pop(ticket, None)
        self._drop(ticket)

    # -- deadlines ------------------------------------------------------------------------
    def sweep(self) -> int:
        """Closes every connection past a deadline; returns how many."""
        now = self.clock.now()
        late = [(t, why) for t in self.tickets() if (why := t.overdue(now)) is not None]
        for ticket, why in late:
            held = self.trouble.allow(("deadline", self.what, ticket.standing is Standing.NEW))
            if held is not None:
                log.info(
                    "Closed the %s from %s: %s%s",
                    ticket.front,
                    ticket.address,
                    why,
                    held_text(held, "more closed for the same reason"),
                )
            ticket._close(why)
        return len(late)

    def _keep_sweeping(self) -> None:
        if self._sweep is None:
            try:
                self._sweep = self.clock.call_later(SWEEP_EVERY, self._swept)
            except RuntimeError:  # no running loop: whoever admits without one sweeps
                self._sweep = None

    def _swept(self) -> None:
        self._sweep = None
        self.sweep()
        if any(t.deadlines != NO_DEADLINES for t in self.tickets()):
            self._keep_sweeping()

    def close(self) -> None:
        """Stops checking the deadlines (the listener is closing)."""
        if self._sweep is not None:
            self._sweep.cancel()
            self._sweep = None


__all__ = [
    "DEFAULT_BEFORE_HELLO",
    "DEFAULT_OPERATORS",
    "DEFAULT_PER_ADDRESS",
    "GRACE",
    "NO_DEADLINES",
    "PATIENCE",
    "SWEEP_EVERY",
    "Admission",
    "Deadlines",
    "Evict",
    "Refused",
    "Standing",
    "Ticket",
    "address_key",
    "checking",
]
