"""The last good state of a running configuration, on disk, so that a restart
(a crash, ``kill -9``, a power cut of the PC) changes nothing on the air.

One file per configuration file, in the user's state directory
(``$XDG_STATE_HOME/moas-gui/``, ``~/.local/state/moas-gui/`` by default;
``~/Library/Application Support/moas-gui/`` on macOS;
``%LOCALAPPDATA%\\moas-gui\\state`` on Windows: :mod:`moas_gui.places`).  It holds a
fingerprint of the configuration file's bytes, the engine's selections
(:mod:`moas_gui.engine.snapshot`) and, per switch, the :class:`SwitchState` last
sent to the box.  It is written whole to a temporary file in the same
directory, flushed to the disk, and renamed over the old one, so whatever a
crash leaves behind is either the old file or the new one, never half of one.
Writes are coalesced (:class:`StateKeeper`): a change after a quiet spell is
written at once, and everything that changes within ``SAVE_DELAY_S`` of a write
goes out together in the next; only the collecting of the state is done on the
event loop, its encoding and writing on a worker thread.

A file that cannot be read, is cut short, belongs to another version of the
configuration, or does not fit it is ignored with one log line: the server
then starts as if there were no file.  See ``docs/server.md``.
"""

from __future__ import annotations

import asyncio
import contextlib
import hashlib
import json
import logging
import os
import stat
import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from moas_gui.errors import MoasError

from . import files, places
from .engine.switchstate import STATIONS, StationAntennas, SwitchState

log = logging.getLogger(__name__)

FORMAT = 1
SAVE_DELAY_S = 1.0
"""How long after a write the changes that follow it wait, to be written together.

A logger at a contest's pace (a band change every 100 ms) then costs one write a
second rather than one every other change; a restart within that second finds the
box holding a newer state than the file, and the box wins (docs/server.md)."""

SAVE_DELAY_HOOK = "MOAS_GUI_SAVE_DELAY"
"""The test hook: a shorter :data:`SAVE_DELAY_S` for a ``moas-server`` process, in
seconds (``0.1``), read by ``moas-server`` alone when it starts serving (not a user
setting; docs/reliability.md).  The fault tests' servers use it so that a change
after a write is on disk in a tenth of a second rather than a second."""


def save_delay_from_environment(environ: Mapping[str, str] = os.environ) -> float | None:
    """The test hook's delay (:data:`SAVE_DELAY_HOOK`), or None when it is not set.

    Raises ValueError naming the variable unless it is a number of seconds above 0 and
    at most :data:`SAVE_DELAY_S` (saves may lag the engine by a second, never more)."""
    text = environ.get(SAVE_DELAY_HOOK)
    if text is None:
        return None
    try:
        seconds = float(text)
    except ValueError:
        raise ValueError(f"{SAVE_DELAY_HOOK}: {text!r} is not a number of seconds") from None
    if not 0 < seconds <= SAVE_DELAY_S:
        raise ValueError(f"{SAVE_DELAY_HOOK}: {text} is not a number of seconds above 0 and "
                         f"at most {SAVE_DELAY_S:g}")
    return seconds


class StateError(MoasError, ValueError):
    """A state file that cannot be used (the message says why)."""


def state_dir() -> Path:
    """The per-user directory for state files (not made here): see :mod:`moas_gui.places`."""
    return places.state_dir()


def state_path(config_path: Path) -> Path:
    """Where the state of ``config_path`` is kept: one file per configuration file."""
    where = str(Path(config_path).resolve())
    digest = hashlib.sha256(where.encode("utf-8", "surrogateescape")).hexdigest()[:16]
    stem = "".join(c if c.isalnum() or c in "-_." else "_" for c in Path(config_path).stem)
    return state_dir() / f"{stem[:40]}-{digest}.state.json"


def last_good_path(config_path: Path) -> Path:
    """Where the last version of ``config_path`` that opened is kept, beside its state: a
    headless or service start on a file that has since got an error starts that one."""
    return state_path(config_path).with_name(
        state_path(config_path).name.removesuffix(".state.json") + ".last-good.moas")


def keep_last_good(config_path: Path) -> None:
    """Keep ``config_path``'s bytes (it opened) as its last good version, unless they are
    kept already; a failure is logged.  Blocking: the app runs it off the loop."""
    kept = last_good_path(config_path)
    try:
        data = config_path.read_bytes()
        if kept.is_file() and kept.read_bytes() == data:
            return
        write_atomic(kept, data)
    except OSError as exc:
        log.warning("Cannot keep the last good version of %s in %s: %s", config_path.name,
                    kept, exc.strerror or exc)


def fingerprint(config_bytes: bytes) -> str:
    return hashlib.sha256(config_bytes).hexdigest()


# -- SwitchState as plain data ----------------------------------------------------------------

def _sorted(values: frozenset[int]) -> list[int]:
    return sorted(values)


def switch_to_data(state: SwitchState) -> dict[str, Any]:
    return {
        "stations": [[s.tx, _sorted(s.tx_relays), s.rx, _sorted(s.rx_relays), s.alt,
                      _sorted(s.alt_relays), _sorted(s.extra)] for s in state.stations],
        "station0": _sorted(state.station0),
        "conflicts": sorted(list(p) for p in state.conflicts),
        "fast": sorted(list(p) for p in state.fast),
        "systems": [list(p) for p in state.systems],
        "inhibited": _sorted(state.inhibited),
        "inhibit_others": [_sorted(s) for s in state.inhibit_others],
        "use_alternate": [_sorted(s) for s in state.use_alternate],
        "interrupt": _sorted(state.interrupt),
        "enable_low": _sorted(state.enable_low),
        "receive_delay": list(state.receive_delay),
        "inhibit_time": state.inhibit_time,
        "interrupt_delay": state.interrupt_delay,
        "active": state.active,
    }


def _int(value: object, where: str, low: int = 0, high: int = 9999) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise StateError(f"{where}: expected a whole number {low}-{high}, found {value!r:.40}")
    return value


def _list(value: object, where: str, length: int | None = None) -> list[Any]:
    if not isinstance(value, list) or (length is not None and len(value) != length):
        raise StateError(f"{where}: expected a list{'' if length is None else f' of {length}'}")
    return value


def _set(value: object, where: str, low: int = 0, high: int = 63) -> frozenset[int]:
    return frozenset(_int(v, where, low, high) for v in _list(value, where))


def _pairs(value: object, where: str) -> frozenset[tuple[int, int]]:
    pairs = set()
    for item in _list(value, where):
        a, b = _list(item, where, 2)
        pairs.add((_int(a, where, 0, 63), _int(b, where, 0, 63)))
    return frozenset(pairs)


def switch_from_data(data: object, where: str) -> SwitchState:
    if not isinstance(data, dict):
        raise StateError(f"{where}: expected an object")
    stations = []
    for n, item in zip(STATIONS, _list(data.get("stations"), f"{where} stations", 6), strict=True):
        w = f"{where} station {n}"
        tx, txr, rx, rxr, alt, altr, extra = _list(item, w, 7)
        stations.append(StationAntennas(_int(tx, w, 0, 63), _set(txr, w), _int(rx, w, 0, 63),
                                        _set(rxr, w), _int(alt, w, 0, 63), _set(altr, w),
                                        _set(extra, w)))
    systems = tuple(sorted((a, s) for a, s in _pairs(data.get("systems"), f"{where} systems")))
    active = data.get("active")
    if not isinstance(active, bool):
        raise StateError(f"{where}: active is not true or false")
    per_station = [_set(s, f"{where} interlocks", 1, 6)
                   for key in ("inhibit_others", "use_alternate")
                   for s in _list(data.get(key), f"{where} {key}", 6)]
    return SwitchState(
        stations=tuple(stations),
        station0=_set(data.get("station0"), f"{where} station0"),
        conflicts=_pairs(data.get("conflicts"), f"{where} conflicts"),
        fast=_pairs(data.get("fast"), f"{where} fast"),
        systems=systems,
        inhibited=_set(data.get("inhibited"), f"{where} inhibited", 1, 6),
        inhibit_others=tuple(per_station[:6]),
        use_alternate=tuple(per_station[6:]),
        interrupt=_set(data.get("interrupt"), f"{where} interrupt", 1, 6),
        enable_low=_set(data.get("enable_low"), f"{where} enable_low", 1, 6),
        receive_delay=tuple(_int(v, f"{where} receive_delay") for v in
                            _list(data.get("receive_delay"), f"{where} receive_delay", 6)),
        inhibit_time=_int(data.get("inhibit_time"), f"{where} inhibit_time"),
        interrupt_delay=_int(data.get("interrupt_delay"), f"{where} interrupt_delay"),
        active=active,
    )


# -- the file ---------------------------------------------------------------------------------

@dataclass(frozen=True, slots=True)
class SavedState:
    """What one state file holds."""

    fingerprint: str
    engine: dict[str, Any] = field(default_factory=dict)
    switches: dict[int, SwitchState] = field(default_factory=dict)
    """Per switch id: what the box was last told to hold."""
    seen: dict[int, tuple[tuple[int, int, int], ...]] = field(default_factory=dict)
    """Per switch id: each station's antennas (transmit, receive, alternate slots) the box
    last reported in use.  Beside ``switches`` it tells, after a restart, a change the
    box still holds back for a transmitting station (the box shows what it was seen
    holding) from a state file older than the box (it shows something else)."""
    focus: dict[int, tuple[int | None, int | None]] = field(default_factory=dict)
    """Per station: the radio with the transmit focus and the one with the receive focus."""


def encode(saved: SavedState) -> bytes:
    data = {
        "format": FORMAT,
        "config": saved.fingerprint,
        "engine": saved.engine,
        "switches": {str(i): switch_to_data(s) for i, s in sorted(saved.switches.items())},
        "seen": {str(i): [list(slots) for slots in seen] for i, seen in sorted(saved.seen.items())},
        "focus": {str(n): list(pair) for n, pair in sorted(saved.focus.items())},
    }
    return json.dumps(data, separators=(",", ":")).encode()


def decode(raw: bytes, expected_fingerprint: str) -> SavedState:
    """The state in ``raw``; raises :class:`StateError` saying why it cannot be used."""
    try:
        data = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise StateError(f"it is not readable ({type(exc).__name__}: {str(exc)[:80]})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise StateError("it is not a state file of this version")
    if data.get("config") != expected_fingerprint:
        raise StateError("it was written for another version of the configuration file")
    engine = data.get("engine")
    switches = data.get("switches")
    if not isinstance(engine, dict) or not isinstance(switches, dict):
        raise StateError("it lacks the engine or the switches")
    held = {}
    for name, value in switches.items():
        if not name.isdigit():
            raise StateError(f"switch {name!r:.20} is not a number")
        held[int(name)] = switch_from_data(value, f"switch {name}")
    return SavedState(expected_fingerprint, engine, held, _seen(data.get("seen", {})),
                      _focus(data.get("focus", {})))


def _seen(data: object) -> dict[int, tuple[tuple[int, int, int], ...]]:
    """The ``seen`` part (absent in files of earlier versions: empty)."""
    if not isinstance(data, dict):
        raise StateError("its seen antennas are not a table")
    seen = {}
    for name, value in data.items():
        where = f"seen antennas of switch {name!r:.20}"
        if not name.isdigit():
            raise StateError(f"{where}: not a switch number")
        rows = _list(value, where, len(STATIONS))
        seen[int(name)] = tuple(
            (_int(r[0], where, 0, 63), _int(r[1], where, 0, 63), _int(r[2], where, 0, 63))
            for r in (_list(row, where, 3) for row in rows))
    return seen


def _focus(data: object) -> dict[int, tuple[int | None, int | None]]:
    """The ``focus`` part (absent in files of earlier versions: empty)."""
    if not isinstance(data, dict):
        raise StateError("its focus is not a table")
    focus = {}
    for name, value in data.items():
        where = f"focus of station {name!r:.20}"
        if not name.isdigit():
            raise StateError(f"{where}: not a station number")
        pair = _list(value, where, 2)
        active, rx = (None if v is None else _int(v, where, 1, 99) for v in pair)
        focus[int(name)] = (active, rx)
    return focus


def write_atomic(path: Path, data: bytes) -> None:
    """Replace ``path`` by ``data``: a temporary file, flushed to disk, renamed over it
    (:func:`moas_gui.files.write_atomic`), in a private directory made if need be."""
    path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    files.write_atomic(path, data)


STALE_TEMPORARY_S = 60.0


def remove_stale_temporaries(path: Path) -> int:
    """Remove temporary files of ``path`` that a killed writer left: those of a process
    that no longer runs (the name carries the writer's process id), and any older than a
    minute (so a second server writing right now keeps its own); returns how many."""
    removed = 0
    now = time.time()
    with contextlib.suppress(OSError):
        for candidate in path.parent.glob(f".{path.name}.*.tmp"):
            with contextlib.suppress(OSError):
                if now - candidate.stat().st_mtime > STALE_TEMPORARY_S \
                        or _writer_gone(candidate):
                    candidate.unlink()
                    removed += 1
    return removed


def _writer_gone(temporary: Path) -> bool:
    """Whether the process that wrote ``temporary`` (``.NAME.PID.tmp``) has ended."""
    pid_text = temporary.name.removesuffix(".tmp").rsplit(".", 1)[-1]
    if sys.platform == "win32" or not pid_text.isdigit() or int(pid_text) == os.getpid():
        return False
    try:
        os.kill(int(pid_text), 0)
    except ProcessLookupError:
        return True
    except OSError:  # it runs, as another user
        return False
    return False


MAX_STATE_BYTES = 4 << 20
"""The largest saved state read: a station's is a few kilobytes; anything near this is
not one of ours, and is not read into memory."""


def _kind_of(mode: int) -> str:
    """What a file that is not a regular one is, in words."""
    kinds = (
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
        (stat.S_ISDIR, "a directory"),
    )
    return next((words for test, words in kinds if test(mode)), "not a regular file")


def read_state_file(path: Path, limit: int = MAX_STATE_BYTES) -> bytes | None:
    """The bytes of the saved state at ``path``, read safely: ``None`` when there is no
    file; :class:`StateError` saying why for anything that is not a regular file of at
    most ``limit`` bytes (a FIFO, a device, a link leading outside the state directory, a
    huge file).  Opening never waits (a FIFO with no writer would block forever), and no
    more than ``limit`` bytes are ever read."""
    try:
        if path.is_symlink():
            target = path.resolve()
            home = path.parent.resolve()
            if target.parent != home:
                raise StateError(f"it is a link to {target}, outside the state directory {home}")
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise StateError(f"it cannot be read ({exc.strerror or exc})") from exc
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):
        os.close(fd)
        raise StateError(f"it is {_kind_of(info.st_mode)}, not a regular file")
    with os.fdopen(fd, "rb") as opened:
        if info.st_size > limit:
            raise StateError(f"it holds {info.st_size:,} bytes, more than a saved state "
                             f"ever does (at most {limit:,})")
        raw = opened.read(limit + 1)
    if len(raw) > limit:
        raise StateError(f"it holds more than {limit:,} bytes, more than a saved state ever does")
    return raw


def load(path: Path, expected_fingerprint: str) -> SavedState | None:
    """The usable state at ``path``, or None (then one log line says why, unless there is
    simply no file yet)."""
    try:
        raw = read_state_file(path)
    except StateError as exc:
        log.warning("The saved state %s is ignored: %s; starting without it", path, exc)
        return None
    if raw is None:
        return None
    try:
        return decode(raw, expected_fingerprint)
    except StateError as exc:
        log.warning("The saved state %s is ignored: %s; starting without it", path, exc)
        return None


def restore(config_path: Path, engine: Any) -> tuple[str, SavedState | None]:
    """The fingerprint of ``config_path`` ("" when it cannot be read again) and its saved
    state, already put into ``engine`` (a fresh engine of that configuration); None when
    there is none or it does not fit (one log line says why)."""
    from .engine.snapshot import SnapshotError, restore_selections

    try:
        printed = fingerprint(Path(config_path).read_bytes())
    except OSError as exc:
        log.warning("%s cannot be read again to keep its state (%s); a restart will "
                    "reload the switches", config_path, exc.strerror or exc)
        return "", None
    where = state_path(config_path)
    saved = load(where, printed)
    if saved is None:
        return printed, None
    try:
        restore_selections(engine, saved.engine)
    except SnapshotError as exc:
        log.warning("The saved state %s is ignored: %s; starting without it", where, exc)
        return printed, None
    chosen = sum(1 for view in engine.radios() if view.tx is not None)
    log.info("Restored the saved state (%s): %d radio%s with antennas%s", where, chosen,
             "" if chosen == 1 else "s", "" if engine.running else "; switches stopped")
    return printed, saved


class StateKeeper:
    """Writes the state of one running configuration whenever it changes, coalesced.

    ``collect`` returns the state to write now; it runs on the event loop, the
    write itself on a worker thread.  At most one write is in flight; a change
    during a write gets its own write after it.
    """

    def __init__(self, path: Path, collect: Callable[[], SavedState],
                 delay: float = SAVE_DELAY_S) -> None:
        self.path = path
        remove_stale_temporaries(path)
        self._collect = collect
        self.delay = delay
        """Seconds after a write during which later changes wait, to be written together."""
        self._timer: asyncio.TimerHandle | None = None
        self._writing: asyncio.Task[None] | None = None
        self._again = False
        self._failed = False
        self._last: bytes | None = None
        self._started = -float("inf")
        self.writes = 0

    def changed(self) -> None:
        """Something in the state may have changed: write it soon.

        A change after a quiet spell is written at the loop's next turn (so the file
        lags the box as little as possible); changes that follow within ``delay`` of
        the last write are gathered and written together when it has passed."""
        if self._writing is not None:
            self._again = True
        elif self._timer is None:
            loop = asyncio.get_running_loop()
            wait = max(0.0, self._started + self.delay - loop.time())
            self._timer = loop.call_later(wait, self._start)

    def _start(self) -> None:
        self._timer = None
        self._started = asyncio.get_running_loop().time()
        try:
            saved = self._collect()  # on the loop: the engine as it stands now
        except Exception:
            log.exception("The state could not be collected for saving")
            return
        self._writing = asyncio.get_running_loop().create_task(self._write(saved))

    def _encode_and_write(self, saved: SavedState) -> bool:
        """On the worker thread: the file unless it would hold what it holds; whether
        it was written.  (One write at a time: ``_last`` is never shared.)"""
        data = encode(saved)
        if data == self._last:
            return False
        write_atomic(self.path, data)
        self._last = data
        return True

    async def _write(self, saved: SavedState) -> None:
        try:
            written = await asyncio.get_running_loop().run_in_executor(
                None, self._encode_and_write, saved)
        except OSError as exc:
            if not self._failed:
                log.error("The state cannot be saved to %s (%s); a restart will reload the "
                          "switches", self.path, exc.strerror or exc)
            self._failed = True
        except Exception:
            log.exception("The state could not be encoded for saving")
        else:
            if written:
                self.writes += 1
                if self._failed:
                    log.info("The state is saved to %s again", self.path)
                self._failed = False
        finally:
            self._writing = None
            if self._again:
                self._again = False
                self.changed()

    async def flush(self) -> None:
        """Write what is pending now (closing, or a test)."""
        while True:
            if self._writing is not None:
                await asyncio.shield(self._writing)
                continue
            if self._timer is None and not self._again:
                return
            if self._timer is not None:
                self._timer.cancel()
                self._timer = None
            self._again = False
            self._start()
            if self._writing is None:
                return

    def close(self) -> None:
        """Stop writing (a pending write is dropped; call :meth:`flush` first to keep it)."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None


__all__ = [
    "MAX_STATE_BYTES",
    "SAVE_DELAY_HOOK",
    "SAVE_DELAY_S",
    "SavedState",
    "StateError",
    "StateKeeper",
    "decode",
    "encode",
    "fingerprint",
    "keep_last_good",
    "last_good_path",
    "load",
    "read_state_file",
    "remove_stale_temporaries",
    "restore",
    "save_delay_from_environment",
    "state_dir",
    "state_path",
    "switch_from_data",
    "switch_to_data",
    "write_atomic",
]
