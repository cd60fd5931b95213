"""Checking secrets (operators' tokens, Antenna Genius codes) without the event loop
ever waiting, and without letting anyone guess at will.

Every front asks one :class:`SecretGuard` (the server has one, shared by the client
port, the WebSocket, the contest report's token and the Antenna Genius front):

* the hash (scrypt, a few ms) and every read of the operators file run on **one**
  worker thread (:class:`SecretWorker`: a station computer may have two cores, and the
  loop that drives the switches keeps the other), with a bounded queue: when it is
  full the check is refused at once as *busy, try again*, never queued on the loop;
* failed checks are **budgeted per address** (:func:`budget_key`: an IPv4 address,
  or an IPv6 address's whole /64): an address may fail :data:`ADDRESS_FREE` checks
  (the size of an address's reserve in the admission,
  :data:`~moas_gui.edge.admission.DEFAULT_BEFORE_HELLO`), then waits a back-off that
  starts at :data:`BACKOFF_FIRST` seconds and doubles with each failure up to
  :data:`BACKOFF_CAP`;
* and **per operator**, from every address together: a token's key id (whether or
  not an operator has it: the answer must not tell), and, for Antenna Genius codes
  (which do not say whose they are), every operator's code at once.  That back-off
  starts at :data:`BACKOFF_FIRST` seconds at the first failure and doubles to
  :data:`BACKOFF_CAP`;
* a **known device** -- an address that has signed in as that operator before (kept
  across restarts in the state directory, :class:`~moas_gui.operators.KnownDevices`)
  -- is exempt from the per-operator back-off, so a guesser elsewhere cannot lock a
  real operator out; a token from a known device is never throttled at all (a token is
  256 random bits: its own address guessing it is hopeless).  For AG codes, which do
  not say whose they are, an address that has signed in as anyone is known, and still
  keeps its address's budget (a code is six digits).

While a back-off runs, a check is refused without hashing ("try again in N s"); a
failure's count is forgotten after :data:`FORGET_AFTER` quiet seconds.  Every table
here is bounded (:data:`MAX_TRACKED`).

The guard also watches the operators file (:meth:`SecretGuard.watch`): a ``stat``
every :data:`WATCH_EVERY` seconds on the loop, the read itself on the worker; an
operator that is gone (or whose token or role changed) has its sessions ended on every
front that listens (:meth:`SecretGuard.listen`), whichever process changed the file.
"""

from __future__ import annotations

import asyncio
import ipaddress
import logging
import time
from collections import OrderedDict
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Final, TypeVar

from moas_gui.edge.admission import DEFAULT_BEFORE_HELLO
from moas_gui.errors import MoasError
from moas_gui.log_limit import LogLimiter, held_text
from moas_gui.operators import (
    Device,
    KnownDevices,
    Operator,
    OperatorBook,
    OperatorError,
    file_signature,
)

log = logging.getLogger(__name__)

T = TypeVar("T")

QUEUE_MOST: Final = 8
"""Checks waiting for the worker at once (about 0.1 s of hashing); more are busy."""
QUEUE_KNOWN: Final = 8
"""Further places for known devices' checks, beyond :data:`QUEUE_MOST`."""
ADDRESS_FREE: Final = DEFAULT_BEFORE_HELLO
"""Failed checks an address may make before its back-off starts."""
BACKOFF_FIRST: Final = 1.0
BACKOFF_CAP: Final = 60.0
FORGET_AFTER: Final = 600.0
"""Seconds without a failure after which a key's failures are forgotten."""
MAX_TRACKED: Final = 4096
"""Addresses, key ids and known devices remembered at most (each table)."""
WATCH_EVERY: Final = 0.5
"""Seconds between two looks at the operators file's modification time."""


class Busy(MoasError):
    """The worker's queue is full: the check was not made."""


def budget_key(host: str) -> str:
    """The "address" a failure budget counts: an IPv4 address (an IPv4-mapped IPv6
    one as IPv4), or the /64 an IPv6 address is in (one subscriber's, or one LAN's,
    whole allocation: counting each of its 2**64 addresses apart would be no bound)."""
    try:
        parsed = ipaddress.ip_address(host.strip().split("%", 1)[0])
    except ValueError:
        return host
    if isinstance(parsed, ipaddress.IPv6Address):
        if parsed.ipv4_mapped is not None:
            return str(parsed.ipv4_mapped)
        return str(ipaddress.IPv6Network((int(parsed) >> 64 << 64, 64)))
    return str(parsed)


class SecretWorker:
    """One thread for every secret check, and a bounded queue in front of it."""

    def __init__(self, most: int = QUEUE_MOST, known: int = QUEUE_KNOWN) -> None:
        self.most, self.known_most = most, known
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="moas-secrets")
        self.waiting = 0
        """Checks queued or running now."""

    async def run(self, job: Callable[[], T], *, known: bool = False) -> T:
        """``job()`` on the worker; raises :class:`Busy` at once when the queue is full
        (known devices have :data:`QUEUE_KNOWN` places more)."""
        if self.waiting >= self.most + (self.known_most if known else 0):
            raise Busy
        self.waiting += 1
        try:
            return await asyncio.get_running_loop().run_in_executor(self._pool, job)
        finally:
            self.waiting -= 1

    def close(self) -> None:
        self._pool.shutdown(wait=False, cancel_futures=True)


@dataclass(slots=True)
class _Failures:
    """One key's failures so far, when the last one was, and its checks under way."""

    count: int
    last: float
    checking: int = 0


class FailureBackoff:
    """Failures per key, and how long each key must wait (see the module notes):
    ``free`` failures cost nothing, each further one doubles the wait from
    :data:`BACKOFF_FIRST` to :data:`BACKOFF_CAP`.  While a key waits for its first
    check after a failure, no second check of it starts."""

    def __init__(self, free: int = 0, limit: int = MAX_TRACKED) -> None:
        self.free, self.limit = free, limit
        self._keys: OrderedDict[str, _Failures] = OrderedDict()

    def wait(self, key: str, now: float) -> float:
        """Seconds ``key`` must still wait before a check (0: none)."""
        entry = self._keys.get(key)
        if entry is None:
            return 0.0
        if now - entry.last >= FORGET_AFTER:
            del self._keys[key]
            return 0.0
        over = entry.count - self.free
        if over <= 0:
            return 0.0
        left = entry.last + delay(over) - now
        if entry.checking:
            return max(left, BACKOFF_FIRST)
        return max(left, 0.0)

    def checking(self, key: str, delta: int) -> None:
        entry = self._keys.get(key)
        if entry is not None:
            entry.checking = max(0, entry.checking + delta)

    def failed(self, key: str, now: float) -> None:
        entry = self._keys.get(key)
        if entry is None:
            if len(self._keys) >= self.limit:
                self._prune(now)
            entry = self._keys[key] = _Failures(0, now)
        entry.count += 1
        entry.last = now
        self._keys.move_to_end(key)

    def forget(self, key: str) -> None:
        self._keys.pop(key, None)

    def _prune(self, now: float) -> None:
        """Forgets quiet keys; when none is, the oldest (so the table stays bounded)."""
        for key in [k for k, e in self._keys.items() if now - e.last >= FORGET_AFTER]:
            del self._keys[key]
        while len(self._keys) >= self.limit:
            self._keys.popitem(last=False)

    def __len__(self) -> int:
        return len(self._keys)


def delay(over: int) -> float:
    """The wait after the ``over``-th failure beyond the free ones."""
    return min(BACKOFF_CAP, BACKOFF_FIRST * 2.0 ** min(over - 1, 16))


@dataclass(frozen=True, slots=True)
class SecretVerdict:
    """What a check found: the operator, or why not (``refusal``: a sentence for the
    peer; ``busy``: the worker was full, ``wait``: a back-off, in seconds)."""

    operator: Operator | None = None
    name: str | None = None
    """The operator's name (for an AG code from a test's own table: a name alone)."""
    refusal: str | None = None
    busy: bool = False
    wait: float = 0.0

    @property
    def ok(self) -> bool:
        return self.name is not None


WRONG_TOKEN: Final = "that token is not one of this station's operators (it may have been removed)"
WRONG_CODE: Final = "wrong code"
BUSY: Final = ("busy: the server is checking many secrets at once; try again in a moment")
AG_KEY: Final = "ag-codes"
"""The per-operator key of every Antenna Genius code together."""


def _waiting(wait: float, whose: str) -> SecretVerdict:
    seconds = max(1, round(wait + 0.49))
    return SecretVerdict(refusal=f"too many wrong {whose} lately; try again in {seconds} s",
                   wait=wait)


class SecretGuard:
    """The server's one place for secret checks; see the module notes.  ``codes`` (for
    tests of the AG front without an operators file): AG code -> name."""

    def __init__(self, book: OperatorBook | None = None, *,
                 codes: dict[str, str] | None = None,
                 clock: Callable[[], float] = time.monotonic,
                 worker: SecretWorker | None = None,
                 devices: KnownDevices | None = None) -> None:
        self.book = book
        self.codes = dict(codes or {})
        self.clock = clock
        self.worker = worker or SecretWorker()
        self.addresses = FailureBackoff(ADDRESS_FREE)
        self.keys = FailureBackoff()
        """Per operator: a token's key id (whether or not an operator has it)."""
        self.ag_codes = FailureBackoff()
        """Per operator for AG codes: every operator's together (:data:`AG_KEY`), in a
        table of its own, which no flood of made-up key ids can push out."""
        self._known: OrderedDict[Device, None] = OrderedDict()
        self._addresses_known: dict[str, int] = {}
        """How many operators each known address has signed in as."""
        self.devices = devices
        """Where the known devices are kept across restarts (None: nowhere)."""
        self._devices_read = devices is None
        self._devices_dirty = False
        self.trouble = LogLimiter()
        """One line a minute per kind (wrong token, wrong code, throttled, busy)."""
        self._listeners: list[Callable[[str], int]] = []
        self._watch: asyncio.Task[None] | asyncio.TimerHandle | None = None
        """The watch of the operators file: its next glance (a timer), or a look under
        way (a task)."""
        self._seen: dict[str, tuple[object, ...]] | None = None
        self._signature: object = None
        self.ended: dict[str, tuple[int, float]] = {}
        """Sessions ended per operator name (lower case) when its removal was noticed."""

    @classmethod
    def station(cls) -> SecretGuard:
        """The guard of the station's own operators file (the configuration directory's)."""
        return cls(OperatorBook(), devices=KnownDevices())

    # -- known devices ------------------------------------------------------------------
    def known(self, host: str, name: str) -> bool:
        return (budget_key(host), name.lower()) in self._known

    def _remember(self, host: str, name: str) -> None:
        self._add_known((budget_key(host), name.lower()))

    def _add_known(self, device: Device) -> None:
        if device in self._known:
            self._known.move_to_end(device)
            return
        self._known[device] = None
        self._addresses_known[device[0]] = self._addresses_known.get(device[0], 0) + 1
        self._devices_dirty = True
        while len(self._known) > MAX_TRACKED:
            self._drop_known(next(iter(self._known)))

    def _drop_known(self, device: Device) -> None:
        del self._known[device]
        left = self._addresses_known.pop(device[0], 1) - 1
        if left > 0:
            self._addresses_known[device[0]] = left
        self._devices_dirty = True

    def _known_key(self, key: str | None, host: str) -> bool:
        """Whether ``host`` has signed in with the operator whose key id is ``key``."""
        if key is None or self.book is None:
            return False
        op = next((o for o in self.book.cached() if o.key == key), None)
        return op is not None and self.known(host, op.name)

    # -- tokens -------------------------------------------------------------------------
    async def check_token(self, token: str, host: str) -> SecretVerdict:
        """Whose token this is (:class:`SecretVerdict`), checked on the worker."""
        book = self.book
        key = None if book is None else book.key_of(token)
        if book is None or key is None:  # not even a token's shape: no hash to make
            self._failed(host, None, "token")
            return SecretVerdict(refusal=WRONG_TOKEN)
        known = self._known_key(key, host)
        if not known:
            refused = self._throttled(host, key, "tokens")
            if refused is not None:
                return refused
        operator = await self._run(lambda: book.check(token), host, None if known else key,
                                   known)
        if isinstance(operator, SecretVerdict):
            return operator
        if operator is None:
            if not known:
                self._failed(host, key, "token")
            return SecretVerdict(refusal=WRONG_TOKEN)
        self._remember(host, operator.name)
        return SecretVerdict(operator, operator.name)

    # -- Antenna Genius codes -------------------------------------------------------------
    async def check_code(self, code: str, host: str) -> SecretVerdict:
        """Whose AG code (or token, which AG clients may send as well) this is."""
        code = code.strip()
        known = budget_key(host) in self._addresses_known
        refused = self._throttled(host, None if known else AG_KEY, "codes")
        if refused is not None:
            return refused
        named = self.codes.get(code)
        if named is not None:  # a test's own table: no hash
            self._remember(host, named)
            return SecretVerdict(name=named)
        book = self.book
        if book is None:
            self._failed(host, None if known else AG_KEY, "code")
            return SecretVerdict(refusal=WRONG_CODE)
        result = await self._run(lambda: book.check_ag_code(code) or book.check(code), host,
                                 None if known else AG_KEY, known)
        if isinstance(result, SecretVerdict):
            return result
        if result is None:
            self._failed(host, None if known else AG_KEY, "code")
            return SecretVerdict(refusal=WRONG_CODE)
        self._remember(host, result.name)
        return SecretVerdict(result, result.name)

    # -- the rules ------------------------------------------------------------------------
    def _throttled(self, host: str, key: str | None, whose: str) -> SecretVerdict | None:
        now = self.clock()
        wait = self.addresses.wait(budget_key(host), now)
        if wait <= 0 and key is not None:
            wait = self._table(key).wait(key, now)
        if wait <= 0:
            return None
        self._line(("throttled", whose), logging.WARNING,
                   "Refused a check of %s from %s without making it: too many wrong %s "
                   "lately (%.0f s to wait)", whose, budget_key(host), whose, wait)
        return _waiting(wait, whose)

    async def _run(self, job: Callable[[], T], host: str, key: str | None,
                   known: bool) -> T | SecretVerdict:
        address = budget_key(host)
        self.addresses.checking(address, 1)
        if key is not None:
            self._table(key).checking(key, 1)
        try:
            return await self.worker.run(job, known=known)
        except Busy:
            self._line("busy", logging.WARNING,
                       "A secret check from %s was refused: %d checks are waiting, the "
                       "most at once", address, self.worker.waiting)
            return SecretVerdict(refusal=BUSY, busy=True)
        finally:
            self.addresses.checking(address, -1)
            if key is not None:
                self._table(key).checking(key, -1)

    def _failed(self, host: str, key: str | None, what: str) -> None:
        now = self.clock()
        address = budget_key(host)
        self.addresses.failed(address, now)
        if key is not None:
            self._table(key).failed(key, now)
        self._line(("wrong", what), logging.INFO, "A wrong %s from %s", what, address)

    def _table(self, key: str) -> FailureBackoff:
        return self.ag_codes if key == AG_KEY else self.keys


    def _line(self, kind: object, level: int, message: str, *args: object) -> None:
        held = self.trouble.allow(kind)
        if held is not None:
            log.log(level, message + "%s", *args, held_text(held))

    # -- the operators file -------------------------------------------------------------
    def listen(self, end: Callable[[str], int]) -> None:
        """``end(name)`` closes the sessions of operator ``name`` on one front and says
        how many; called when the file no longer has that operator as it was."""
        if end not in self._listeners:
            self._listeners.append(end)
        if self._watch is None and self.book is not None:
            self._watch = asyncio.get_running_loop().create_task(self._watching())

    def unlisten(self, end: Callable[[str], int]) -> None:
        if end in self._listeners:
            self._listeners.remove(end)
        if not self._listeners and self._watch is not None:
            self._watch.cancel()
            self._watch = None

    @property
    def watched(self) -> bool:
        """The watcher has read the operators file at least once."""
        return self._seen is not None

    def end_operator(self, name: str) -> int:
        """Ends ``name``'s sessions on every front now; how many."""
        ended = 0
        for end in tuple(self._listeners):
            try:
                ended += end(name)
            except Exception:
                log.exception('Ending the sessions of operator "%s" failed', name)
        self.ended[name.lower()] = (ended + self.recently_ended(name), self.clock())
        return ended

    def current(self, operator: Operator | None) -> bool:
        """Whether ``operator`` is still in the operators file as it was (as last read:
        no file access) -- a session started before its removal must not go on."""
        if operator is None or self.book is None:
            return True
        return operator in self.book.cached()

    def recently_ended(self, name: str) -> int:
        """Sessions of ``name`` ended in the last minute when its removal was noticed."""
        ended, when = self.ended.get(name.lower(), (0, 0.0))
        return ended if self.clock() - when < 60.0 else 0

    async def _watching(self) -> None:
        """One look (the file read again on the worker when its ``stat`` changed, the
        known devices read or written), then the next glance in :data:`WATCH_EVERY`."""
        book = self.book
        assert book is not None
        try:
            await self._look(book)
            await self._keep_devices()
        except Busy:
            pass  # the worker is full: next time
        self._watch = asyncio.get_running_loop().call_later(WATCH_EVERY, self._glance)

    def _glance(self) -> None:
        """The file's ``stat`` unchanged and nothing of the devices to do: the next glance
        in :data:`WATCH_EVERY` (one loop turn, no task); else a look (:meth:`_watching`)."""
        loop = asyncio.get_running_loop()
        book = self.book
        quiet = (book is not None and self._seen is not None
                 and file_signature(book.path) == self._signature
                 and (self.devices is None or (self._devices_read and not self._devices_dirty)))
        if quiet:
            self._watch = loop.call_later(WATCH_EVERY, self._glance)
        else:
            self._watch = loop.create_task(self._watching())

    async def _look(self, book: OperatorBook) -> None:
        """Reads the operators file again (on the worker) when its ``stat`` changed."""
        signature = file_signature(book.path)  # one stat: nothing is read on the loop
        if signature == self._signature and self._seen is not None:
            return
        now = await self.worker.run(lambda: _entries(book), known=True)
        self._signature = signature
        self._compare(now)

    async def _keep_devices(self) -> None:
        """Reads the known devices once, then writes them when they changed (both on
        the worker)."""
        devices = self.devices
        if devices is None:
            return
        if not self._devices_read:
            loaded = await self.worker.run(lambda: self._read_devices(devices), known=True)
            self._devices_read = True
            newer = list(self._known)  # signed in since the start: the newest
            for device in [*loaded, *newer]:
                if self._seen is None or device[1] in self._seen:
                    self._add_known(device)
            self._devices_dirty = bool(newer)
            return
        if self._devices_dirty:
            self._devices_dirty = False
            snapshot = list(self._known)
            try:
                await self.worker.run(lambda: devices.save(snapshot), known=True)
            except Busy:
                self._devices_dirty = True
                raise
            except OSError as exc:
                self._line("devices not saved", logging.WARNING,
                           "Cannot keep the known devices in %s: %s", devices.path,
                           exc.strerror or exc)

    def _read_devices(self, devices: KnownDevices) -> list[Device]:
        try:
            return devices.load()
        except (OperatorError, OSError) as exc:
            self._line("devices not read", logging.WARNING,
                       "%s; each device is known again at its next sign-in", exc)
            return []

    def _compare(self, now: dict[str, tuple[object, ...]]) -> None:
        before, self._seen = self._seen, now
        if before is None:
            return
        for name, entry in before.items():
            if now.get(name) == entry:
                continue
            shown = str(entry[0])
            self._forget_known(name)
            if self.recently_ended(shown):  # --remove-operator told this server already
                continue
            ended = self.end_operator(shown)
            log.info('Operator "%s" was removed: %d session%s ended', shown, ended,
                     "" if ended == 1 else "s")

    def _forget_known(self, name: str) -> None:
        """A removed operator's devices are known no more (``name`` in lower case)."""
        for device in [d for d in self._known if d[1] == name]:
            self._drop_known(device)

    def close(self) -> None:
        if self._watch is not None:
            self._watch.cancel()
            self._watch = None
        self.worker.close()


def _entries(book: OperatorBook) -> dict[str, tuple[object, ...]]:
    """Each operator as the file has it now (an unreadable file: none, which no
    token passes either)."""
    try:
        operators = book.operators()
    except OperatorError as exc:
        log.warning("%s: no operator's token or code is valid until it is mended", exc)
        operators = ()
    return {op.name.lower(): (op.name, op.role, op.radios, op.key, op.digest, op.ag_digest)
            for op in operators}


__all__ = [
    "ADDRESS_FREE",
    "AG_KEY",
    "BACKOFF_CAP",
    "BACKOFF_FIRST",
    "BUSY",
    "FORGET_AFTER",
    "MAX_TRACKED",
    "QUEUE_KNOWN",
    "QUEUE_MOST",
    "WATCH_EVERY",
    "Busy",
    "FailureBackoff",
    "SecretGuard",
    "SecretVerdict",
    "SecretWorker",
    "budget_key",
    "delay",
]
