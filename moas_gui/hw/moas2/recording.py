"""A recording of switch sessions (``--record-serial FILE``), and its replay.

A recording is a text file of JSON lines, one per event, written as it happens:

* ``{"kind": "session", "switch": 1, ...}`` when a switch link is made: what its
  :class:`~.session.SwitchSession` starts from (unit id, events, timing, the saved
  state it holds and the antennas it last saw), so that a replay starts alike;
* ``{"kind": "out", "switch": 1, "t": 12.345, "data": "..."}``: bytes written to the box;
* ``{"kind": "in", ...}``: bytes read from the box, in the pieces the port gave;
* the other calls the link made on its session, each with its time ``t``:
  ``opened``, ``tick``, ``lost``, ``closed``, ``want`` (the engine's wanted state),
  ``stop`` and ``start`` (a driver without an engine: the wanted state made inactive,
  or active again), ``reset``, ``reconcile`` (with the wanted state it was handed) and
  ``ask`` (a question); each is written by :class:`.calls.SessionCalls`, the one
  place the link calls its session.

Bytes are written as text with ``\\xNN`` escapes (:func:`bytes_text`), so both
directions read at a glance: ``"';"`` out, ``"!;"`` in.  Times are seconds on the
link's monotonic clock; ``wall`` in the header line says when the recording began.

:func:`replay` drives a new session through the same calls with the same times and
compares what it writes with the recorded ``out`` lines: a session (or a change
to it) that answers a recorded box differently is found at the first byte that
differs.  ``moas-server --probe PORT --record-serial FILE`` writes ``out`` and
``in`` lines only (no session): an owner's first exchange with a real box, to share.

Recording costs a line of text per event; it is meant for finding a problem, not
for every contest (the file grows with the traffic: about 40 bytes per ping).
"""

from __future__ import annotations

import json
import logging
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import IO, Any

from ...engine.switchstate import SwitchState
from .actions import Action, LinkStatus, Write
from .commands import encode, parse_command
from .errors import RecordingError
from .messages import (
    BoxStatus,
    Command,
    Ping,
    PolarityStatus,
    Pong,
    RelayStatus,
    RelayStatusRequest,
    StateOp,
    StatusKind,
    StatusRequest,
    UnitId,
    UnitIdReply,
)
from .session import SwitchSession
from .timing import LinkTiming

log = logging.getLogger(__name__)

StateEncoder = Callable[[SwitchState], object]
StateDecoder = Callable[[object, str], SwitchState]

FORMAT = 1
"""The recording's format number, in its first line."""

SESSION_CALLS = ("opened", "tick", "lost", "closed", "want", "stop", "start", "reset",
                 "reconcile", "ask")
"""The session calls a recording holds besides the bytes."""


def bytes_text(data: bytes) -> str:
    """``data`` as readable text: printable ASCII as it is, the rest as ``\\xNN``."""
    return "".join(chr(b) if 0x20 <= b < 0x7F and b != 0x5C else f"\\x{b:02x}" for b in data)


def text_bytes(text: str) -> bytes:
    """The bytes :func:`bytes_text` wrote."""
    out = bytearray()
    i = 0
    while i < len(text):
        if text.startswith("\\x", i):
            out.append(int(text[i + 2:i + 4], 16))
            i += 4
        else:
            out.append(ord(text[i]))
            i += 1
    return bytes(out)


def answer_type(command: Command) -> type[Any]:
    """The reply a question waits for (the recording keeps the question alone)."""
    if isinstance(command, Ping):
        return Pong
    if isinstance(command, UnitId):
        return UnitIdReply
    if isinstance(command, RelayStatusRequest):
        return RelayStatus
    if isinstance(command, StatusRequest):
        return BoxStatus if command.kind is StatusKind.BOX else PolarityStatus
    raise TypeError(f"{type(command).__name__} is not a question")


class SerialRecorder:
    """Writes a recording (see the module docstring) to ``path``, a line per event.

    A recording is added to, never overwritten: a Restart (a new configuration run)
    goes on in the same file, with new ``session`` lines.  Every line is flushed as it
    is written, so what a crash or a pulled plug ends
    is in the file up to its last event.  A recording that cannot be written any
    more (a full disk) says so once and stops: the server goes on without it."""

    def __init__(self, path: str | Path, *, encode_state: StateEncoder | None = None) -> None:
        self.path = Path(path)
        self._encode_state = encode_state
        self._file: IO[str] | None = self.path.open("a", encoding="ascii", buffering=1)
        self.lines = 0
        self._put({"kind": "recording", "format": FORMAT, "wall": time.time()})

    def session(self, switch_id: int, *, port: str, echo: int | None,
                events: Iterable[StateOp], timing: LinkTiming, held: SwitchState | None,
                seen: Iterable[tuple[int, int, int]] | None) -> None:
        """A switch link was made: what its session starts from."""
        self._put({"kind": "session", "switch": switch_id, "port": port, "echo": echo,
                   "events": [op.value for op in events],
                   "timing": {k: v for k, v in asdict(timing).items() if _plain(v)},
                   "held": self._state(held), "seen": None if seen is None else
                   [list(s) for s in seen]})

    def note(self, switch_id: int, kind: str, now: float, **fields: object) -> None:
        """One event of switch ``switch_id`` at ``now`` (bytes go as ``data``)."""
        line: dict[str, object] = {"kind": kind, "switch": switch_id, "t": now}
        for key, value in fields.items():
            if isinstance(value, bytes):
                line[key] = bytes_text(value)
            elif isinstance(value, SwitchState):
                line[key] = self._state(value)
            else:
                line[key] = value
        self._put(line)

    def close(self) -> None:
        file, self._file = self._file, None
        if file is not None:
            file.close()

    def _state(self, state: SwitchState | None) -> object:
        if state is None or self._encode_state is None:
            return None
        return self._encode_state(state)

    def _put(self, line: dict[str, object]) -> None:
        if self._file is None:
            return
        try:
            self._file.write(json.dumps(line, separators=(",", ":")) + "\n")
            self.lines += 1
        except OSError as exc:
            log.error("Recording to %s stopped: %s; the server goes on without it",
                      self.path, exc.strerror or exc)
            self.close()


def _plain(value: object) -> bool:
    return isinstance(value, int | float | str | bool) or value is None


# -- reading and replaying ---------------------------------------------------------------------


def read_recording(path: str | Path) -> list[dict[str, Any]]:
    """The lines of a recording; :class:`RecordingError` names a line that is not one."""
    lines = []
    for number, text in enumerate(Path(path).read_text(encoding="ascii").splitlines(), 1):
        if not text.strip():
            continue
        try:
            line = json.loads(text)
        except json.JSONDecodeError as exc:
            raise RecordingError(f"{path}:{number}: not a recording line: {exc.msg}") from None
        if not isinstance(line, dict) or not isinstance(line.get("kind"), str):
            raise RecordingError(f"{path}:{number}: a line without its kind")
        line["line"] = number
        lines.append(line)
    return lines


@dataclass(slots=True)
class ReplayResult:
    """What a replay of one switch's sessions found."""

    switch: int
    recorded: bytes = b""
    """Everything the recorded session wrote, in order."""
    replayed: bytes = b""
    """Everything the replayed session wrote for the same calls."""
    calls: int = 0
    """Session calls replayed."""
    difference: str | None = None
    """Where the two first differ, in words (None when they are the same)."""

    @property
    def same(self) -> bool:
        return self.recorded == self.replayed


def replay(lines: list[dict[str, Any]], switch_id: int, *,
           decode_state: StateDecoder) -> ReplayResult:
    """Drive a new session of switch ``switch_id`` through the recorded calls, at the
    recorded times, and compare everything it writes with the recorded ``out`` lines.

    The two streams are compared whole: a call's writes may be recorded after the
    calls nested in it (the ``reconcile`` after an adoption, and an ``apply`` the
    engine makes on adopting, come while the box's answer is still being handled),
    so only the order of the bytes, not which call each belongs to, is the session's
    answer."""
    result = ReplayResult(switch_id)
    session: SwitchSession | None = None
    recorded = bytearray()
    out_lines: list[tuple[int, int]] = []  # (offset in recorded, recording line)
    for line in lines:
        if line.get("switch") != switch_id:
            continue
        kind = line["kind"]
        if kind == "session":
            session = _new_session(line, decode_state)
        elif kind == "out":
            out_lines.append((len(recorded), line["line"]))
            recorded += text_bytes(line["data"])
        elif session is None:
            raise RecordingError(f"line {line['line']}: switch {switch_id}'s {kind} comes "
                                 "before its session line")
        else:
            result.calls += 1
            result.replayed += _written(_call(session, line, decode_state))
    result.recorded = bytes(recorded)
    if not result.same:
        result.difference = _first_difference(result, out_lines)
    return result


def _first_difference(result: ReplayResult, out_lines: list[tuple[int, int]]) -> str:
    a, b = result.recorded, result.replayed
    at = next((i for i, (x, y) in enumerate(zip(a, b, strict=False)) if x != y), min(len(a), len(b)))
    line = next((n for offset, n in reversed(out_lines) if offset <= at), None)
    where = f"the out line {line}" if line is not None else "the start"
    return (f"byte {at} ({where}): the recording has {bytes_text(a[at:at + 40])!r}, "
            f"the replayed session wrote {bytes_text(b[at:at + 40])!r}")


def _new_session(line: dict[str, Any], decode_state: StateDecoder) -> SwitchSession:
    held = line.get("held")
    seen = line.get("seen")
    return SwitchSession(
        line["switch"], line.get("echo"),
        events=tuple(StateOp(op) for op in line.get("events", ())),
        timing=LinkTiming(**line.get("timing", {})),
        held=None if held is None else decode_state(held, "the recorded held state"),
        seen=None if seen is None else [tuple(s) for s in seen],
        where=f"switch {line['switch']} (replayed)")


def _call(session: SwitchSession, line: dict[str, Any],
          decode_state: StateDecoder) -> list[Action]:
    kind, now = line["kind"], float(line.get("t", 0.0))
    if kind == "in":
        return session.feed(text_bytes(line["data"]), now)
    if kind == "want":
        return session.apply(decode_state(line["state"], f"line {line['line']}"), now,
                             automatic=bool(line.get("automatic")))
    if kind == "ask":
        command = parse_command(line["command"].removesuffix(";"))
        return session.ask(command, answer_type(command), now)[1]
    if kind == "reconcile":
        state = line.get("state")
        desired = session.desired if state is None else \
            decode_state(state, f"line {line['line']}")
        return session.reconcile(desired, now)
    if kind in ("opened", "tick"):
        return list(getattr(session, kind)(now))
    if kind == "lost":
        return session.lost(line.get("reason", "lost"))
    if kind == "closed":
        return session.voice.set(LinkStatus.UNRESPONSIVE)
    if kind in ("stop", "start"):  # Stop and Start Switches: the wanted state
        return session.apply(replace(session.desired, active=kind == "start"))
    if kind == "reset":
        return session.reset()
    raise RecordingError(f"line {line['line']}: unknown kind {kind!r}")


def _written(actions: Iterator[Action] | list[Action]) -> bytes:
    return b"".join(a.data for a in actions if isinstance(a, Write))


def command_text(command: Command) -> str:
    """A question as the recording keeps it (the bytes sent, as text)."""
    return encode(command).decode("ascii")


__all__ = [
    "SESSION_CALLS",
    "RecordingError",
    "ReplayResult",
    "SerialRecorder",
    "answer_type",
    "bytes_text",
    "command_text",
    "read_recording",
    "replay",
    "text_bytes",
]
