"""The one admission policy (moas_gui/edge/admission.py), rule by rule, on a FakeClock:
the fair share, the order of eviction, operators' own capacity, the caps, the deadlines,
and its log lines one a minute a kind; and the accept loop's back-off
(moas_gui/edge/listener.py) when the system refuses a connection."""

from __future__ import annotations

import asyncio
import errno
import logging
import socket
from pathlib import Path

import pytest

from moas_gui.clock import FakeClock
from moas_gui.edge.admission import GRACE, Admission, Deadlines, Refused, Standing, Ticket
from moas_gui.edge.gate import Door, Gate
from moas_gui.edge.listener import BACKOFF_MOST, Listener, bind
from moas_gui.log_limit import LogLimiter


class Pool:
    """An admission on a fake clock that records whom it closed, and why."""

    def __init__(self, total: int, **options: int) -> None:
        self.clock = FakeClock()
        self.closed: list[tuple[str, str]] = []
        self.admission = Admission(
            total, clock=self.clock, trouble=LogLimiter(clock=self.clock.now), **options
        )

    def admit(self, host: str, name: str = "", deadlines: Deadlines | None = None) -> Ticket:
        label = name or host
        return self.admission.admit(
            host, lambda why: self.closed.append((label, why)), deadlines=deadlines or Deadlines()
        )

    def later(self, seconds: float) -> None:
        self.clock._now += seconds  # plain time passing; no timers are due in these tests


def test_a_newcomer_takes_the_place_of_the_longest_idle_of_the_address_holding_most() -> None:
    pool = Pool(4)
    crowd = [pool.admit("127.0.0.2", f"crowd{n}") for n in range(3)]
    other = pool.admit("127.0.0.3", "other")
    for ticket in (*crowd, other):
        ticket.greeted()
    pool.later(5)
    crowd[0].touch()
    crowd[2].touch()
    other.touch()  # crowd1 is the idlest of the address holding the most
    pool.later(5)
    pool.admit("127.0.0.9", "newcomer")
    assert [name for name, _ in pool.closed] == ["crowd1"]
    assert "newcomer from an address holding fewer connections" in pool.closed[0][1]
    assert crowd[1].released and crowd[1].evicted is not None
    assert pool.admission.count == 4 and pool.admission.open_from("127.0.0.2") == 2


def test_a_newcomer_from_the_address_holding_the_most_is_refused() -> None:
    pool = Pool(3)
    for n in range(2):
        pool.admit("127.0.0.2", f"crowd{n}")
    pool.admit("127.0.0.3")
    with pytest.raises(Refused) as refused:
        pool.admit("127.0.0.2")
    assert refused.value.limit == "total"
    assert not pool.closed


def test_one_that_never_said_hello_goes_before_a_greeted_one_even_if_less_idle() -> None:
    pool = Pool(4)
    greeted = [pool.admit("127.0.0.2", f"greeted{n}") for n in range(3)]
    for ticket in greeted:
        ticket.greeted()
    pool.later(60)  # the greeted ones are idle far longer ...
    pool.admit("127.0.0.3", "silent")  # ... but this one never said who it is
    pool.later(1)
    pool.admit("127.0.0.4", "newcomer").greeted()
    assert [name for name, _ in pool.closed] == ["silent"]
    assert "before saying who it was" in pool.closed[0][1]
    pool.admit("127.0.0.5", "another")  # no more silent ones: a greeted one of the most
    assert pool.closed[-1][0] == "greeted0"


def test_operators_have_their_own_capacity_and_are_never_evicted() -> None:
    pool = Pool(3, operators=2)
    operator = pool.admit("192.0.2.7", "operator")
    operator.greeted()
    assert operator.operator() and operator.standing is Standing.OPERATOR
    crowd = [pool.admit(f"127.0.0.{n}", f"crowd{n}") for n in range(2, 5)]
    for n in range(5, 40):  # a crowd of newcomers, each taking someone's place
        pool.admit(f"127.0.1.{n}", f"late{n}")
    assert "operator" not in [name for name, _ in pool.closed]
    assert not operator.released
    assert all(ticket.released for ticket in crowd)
    assert pool.admission.count == 4 and pool.admission.operator_count == 1
    # a second operator fits; a third does not, and stays an ordinary connection
    second = pool.admit("192.0.2.8")
    assert second.operator()
    third = pool.admit("192.0.2.9")
    assert not third.operator() and third.standing is Standing.NEW


def test_an_operator_arriving_when_the_crowd_holds_everything_is_served() -> None:
    pool = Pool(200)
    for source in range(2, 9):  # 7 x 30 greeted, idle: every place taken
        for n in range(30):
            if pool.admission.count < 200:
                pool.admit(f"127.0.0.{source}").greeted()
    pool.later(30)
    newcomer = pool.admit("127.0.0.1", "operator")
    newcomer.greeted()
    assert newcomer.operator()
    assert len(pool.closed) == 1 and pool.admission.operator_count == 1


def test_each_address_has_a_reserve_before_hello_and_a_cap() -> None:
    pool = Pool(100, per_address=5, before_hello=3)
    waiting = [pool.admit("127.0.0.2") for _ in range(3)]
    with pytest.raises(Refused) as refused:
        pool.admit("127.0.0.2")
    assert refused.value.limit == "hello"
    waiting[0].greeted()  # said who it is: out of the reserve
    pool.admit("127.0.0.2").greeted()
    pool.admit("127.0.0.2")
    with pytest.raises(Refused) as refused:
        pool.admit("127.0.0.2")
    assert refused.value.limit == "address"
    pool.admit("127.0.0.3")  # another address is not concerned
    assert pool.admission.open_from("127.0.0.2") == 5
    assert pool.admission.open_from("::ffff:127.0.0.2") == 5  # one address, two spellings


def test_deadlines_close_the_silent_on_the_clock() -> None:
    pool = Pool(10)
    clocks = Deadlines(hello=5, idle=120)
    mute = pool.admit("127.0.0.2", "mute", clocks)
    talker = pool.admit("127.0.0.3", "talker", clocks)
    talker.greeted()
    pool.later(4.9)
    assert pool.admission.sweep() == 0
    pool.later(0.2)
    assert pool.admission.sweep() == 1
    assert pool.closed == [("mute", "it did not say who it is within 5 s")]
    assert mute.released
    for _ in range(5):  # signs of life keep it
        pool.later(100)
        talker.touch()
        assert pool.admission.sweep() == 0
    pool.later(120)
    pool.admission.sweep()
    assert pool.closed[-1] == ("talker", "silent for 120 s")


@pytest.mark.asyncio
async def test_the_admission_checks_deadlines_by_itself() -> None:
    pool = Pool(10)
    pool.admit("127.0.0.2", "mute", Deadlines(hello=3))
    await pool.clock.advance(2.5)
    assert not pool.closed
    await pool.clock.advance(1.0)
    assert [name for name, _ in pool.closed] == ["mute"]
    pool.admission.close()


def test_trouble_is_logged_once_a_minute_a_kind_with_its_count(
    caplog: pytest.LogCaptureFixture,
) -> None:
    pool = Pool(2, per_address=100, before_hello=100)
    caplog.set_level(logging.INFO, logger="moas_gui.edge")
    pool.admit("127.0.0.2")
    pool.admit("127.0.0.2")
    for n in range(50):  # 50 newcomers from 50 addresses, each making room
        pool.admit(f"10.0.0.{n + 1}")
    made_room = [r for r in caplog.records if "Made room" in r.getMessage()]
    assert len(made_room) == 1
    pool.later(61)
    pool.admit("10.9.9.9")
    made_room = [r.getMessage() for r in caplog.records if "Made room" in r.getMessage()]
    assert len(made_room) == 2 and "(49 more closed to make room" in made_room[1]


@pytest.mark.asyncio
async def test_the_accept_loop_backs_off_when_out_of_file_handles(
    caplog: pytest.LogCaptureFixture,
) -> None:
    sockets = bind("127.0.0.1", 0)
    port = sockets[0].getsockname()[1]
    loop = asyncio.get_running_loop()
    attempts: list[int] = []
    failures = 7

    async def accept(sock: socket.socket) -> tuple[socket.socket, object]:
        attempts.append(1)
        if len(attempts) <= failures:
            raise OSError(errno.EMFILE, "Too many open files")
        return await loop.sock_accept(sock)

    async def no_wait(_seconds: float) -> None:
        await asyncio.sleep(0)

    made: list[asyncio.Protocol] = []

    def protocol(_gate: Gate) -> asyncio.Protocol:
        made.append(asyncio.Protocol())
        return made[-1]

    caplog.set_level(logging.WARNING, logger="moas_gui.edge")
    door = Door(Admission(4), protocol, "test client")
    listener = Listener(door, sockets, what="test clients", accept=accept, sleep=no_wait)
    try:
        with socket.create_connection(("127.0.0.1", port)):
            deadline = loop.time() + 10
            while not made and loop.time() < deadline:
                await asyncio.sleep(0.01)
            assert made, "the connection was never accepted"
        # one try per pause, never a spin: the failures, the success, and the wait for
        # the next connection
        assert len(attempts) == failures + 2
        assert listener.pauses == [0.1, 0.2, 0.4, 0.8, 1.6, BACKOFF_MOST, BACKOFF_MOST]
        lines = [r.getMessage() for r in caplog.records if "Cannot accept" in r.getMessage()]
        assert len(lines) == 1 and "Too many open files" in lines[0]
    finally:
        await listener.close()


def test_a_connection_just_opened_goes_last_so_that_it_can_say_who_it_is() -> None:
    """A crowd that comes back as fast as it is closed: the newest connection of an
    address holding more is not the first to go while it has had no time to say hello
    (:data:`GRACE`); greeted ones go first, and once its grace is over it goes first."""
    pool = Pool(3)
    crowd = [pool.admit(f"127.0.3.{n}", f"crowd{n}") for n in (1, 2)]
    for ticket in crowd:
        ticket.greeted()
    pool.later(5)
    fresh = pool.admit("127.0.0.2", "operator, about to say who it is")
    pool.later(GRACE / 2)
    pool.admit("127.0.3.9", "newcomer")
    assert [name for name, _ in pool.closed] == ["crowd1"]
    assert not fresh.released
    pool.later(GRACE)
    pool.admit("127.0.3.8", "another")
    assert pool.closed[-1][0] == "operator, about to say who it is"


def test_a_connection_whose_secret_is_being_checked_goes_after_every_other() -> None:
    """A token or AG code is checked on a worker thread: while the answer is awaited the
    connection (an operator's, perhaps, about to move to the operators' own capacity)
    is the last to make room, after the newest and the greeted; once the check is over
    it is an ordinary connection again."""
    pool = Pool(3)
    waiting = pool.admit("127.0.0.2", "checking")
    checked = waiting.checking()
    checked.__enter__()
    pool.later(5)  # far past its grace and patience: without the check it would go first
    crowd = [pool.admit(f"127.0.3.{n}", f"crowd{n}") for n in (1, 2)]
    for n in range(3, 9):  # a crowd coming back as fast as it is closed
        pool.later(GRACE / 4)
        pool.admit(f"127.0.3.{n}", f"crowd{n}")
    assert "checking" not in [name for name, _ in pool.closed]
    assert not waiting.released and waiting.checks == 1
    assert crowd[0].released and crowd[1].released
    checked.__exit__(None, None, None)
    assert waiting.checks == 0
    pool.later(GRACE)
    pool.admit("127.0.3.20", "after the check")
    assert pool.closed[-1][0] == "checking"


@pytest.mark.asyncio
async def test_the_gate_carries_the_peer_accept_gave_on_the_ticket() -> None:
    """The peer's address is read once, from ``accept()``: the protocol a door opens and
    the ticket see the same ``host`` and ``address``, and a refused peer is told why."""
    seen: list[tuple[str, str, str, str]] = []

    def open_(gate: Gate) -> asyncio.Protocol:
        assert gate.ticket is not None
        seen.append((gate.host, gate.address, gate.ticket.host, gate.ticket.address))
        return asyncio.Protocol()

    door = Door(Admission(4, 1), open_, "test connection",
                refusal=lambda refused: f"no: {refused.reason}\n".encode())
    listener = await Listener.open(door, "127.0.0.1", 0)
    try:
        kept = socket.create_connection(("127.0.0.1", listener.port),
                                        source_address=("127.0.0.3", 0))
        local = kept.getsockname()
        deadline = asyncio.get_running_loop().time() + 10
        while not seen and asyncio.get_running_loop().time() < deadline:
            await asyncio.sleep(0.01)
        address = f"127.0.0.3:{local[1]}"
        assert seen == [("127.0.0.3", address, "127.0.0.3", address)]
        reader, writer = await asyncio.open_connection("127.0.0.1", listener.port,
                                                       local_addr=("127.0.0.3", 0))
        told = await asyncio.wait_for(reader.read(), 10)
        writer.close()
        assert told.startswith(b"no: ") and b"the most one address may hold" in told
        kept.close()
    finally:
        await listener.close()


def test_the_peer_is_read_in_one_place_only() -> None:
    """No front asks a transport for its peer: the gate did, once (a rule on the source)."""
    package = Path(__file__).resolve().parents[2] / "moas_gui"
    readers = sorted(path.relative_to(package).as_posix() for path in package.rglob("*.py")
                     if '"peername"' in path.read_text(encoding="utf-8"))
    assert readers == ["edge/gate.py"]


def test_a_connection_whose_token_is_being_checked_goes_after_every_other() -> None:
    """Under a crowd of single connections from many addresses, an operator signing in
    is greeted and its token checked: it is not the one closed while the check runs,
    though the idlest (it goes only when nothing else is left), and it is an ordinary
    candidate again once the check is over."""
    pool = Pool(3)
    signing_in = pool.admit("127.0.0.2", "operator")
    crowd = [pool.admit(f"127.0.3.{n}", f"crowd{n}") for n in (1, 2)]
    for ticket in (signing_in, *crowd):
        ticket.greeted()
    pool.later(1)
    for ticket in crowd:
        ticket.touch()  # the operator's connection is the idlest
    pool.later(1)
    with signing_in.checking():  # its token is on the secret worker
        newcomers = [pool.admit("127.0.4.1", "newcomer1")]
        newcomers[0].greeted()
        newcomers.append(pool.admit("127.0.4.2", "newcomer2"))
        newcomers[1].greeted()
        assert [name for name, _ in pool.closed] == ["crowd1", "crowd2"]
        assert not signing_in.released
    pool.later(1)
    pool.admit("127.0.4.3", "newcomer3")
    assert [name for name, _ in pool.closed][-1] == "operator"
