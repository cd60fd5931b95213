"""The MOAS II firmware as a pure model: bytes and time in, bytes out.

``model.feed(data, now)`` takes what the computer sent, ``model.set_tr(station,
transmitting, now)`` what a radio's key line did, ``model.advance(now)`` lets
time pass; each returns the bytes the box sends.  ``now`` is in seconds from
any fixed point; the model never reads a clock, so tests can step time by
hand and watch an inhibit come and go.

The model is built in layers, one module each: :mod:`.boxstate` (every
setting and table, and the power-on values), :mod:`.switching` (closed
relays, station phases and timers, the conflict resolver), :mod:`.handlers`
(what each command does), and this module (input, public calls, the view).

What it does, in plain words (docs/switch.md has the full list of decisions
where the manual is silent):

* Input: characters at or below space are ignored, ``$`` throws away the
  command so far, ``;`` ends a command.  The input buffer holds 128
  characters; a longer command is answered ``?F`` and dropped up to its ``;``.
* After power-on or ``*0`` the box is inactive: all relays open (a reset
  under a transmitting station opens its relays too: the manual's "power-up
  state"), nothing switches, antenna commands are remembered, every station is
  in wait mode; the key lines are still followed.  ``*1`` activates it and
  turns the conflict resolver on.  A station whose key line is asserted at
  that moment is transmitting: it goes on the air where it stands (on no
  relays, after a reset) and its remembered antenna commands are changes on
  the air -- in wait mode they wait until it stops transmitting, in interrupt
  mode (set by ``&`` before ``*1``) its inhibit is asserted, the interrupt
  delay runs and the relays move the slow way.  Receive and alternate
  antennas are not in use while it transmits and are taken at once.
* Antenna commands become requests; the resolver (see :mod:`.resolver`)
  carries them out when there is no conflict and the station's phase table
  (see :mod:`.station`) allows, and holds them otherwise.  A newer request of
  the same kind for a station replaces a held one.
* The closed relays are: station 0's relays, plus for each station its
  transmit relays and extra relays while it is on the air, otherwise its
  receive relays -- the alternate's while a station listed for it with ``@``
  is on the air (none at all if the alternate conflicts with another
  station's antenna), the transmit antenna's if the transmit/receive pair is
  not in the fast table.
* Every change of the closed relays, every key line change and every ``*0``
  goes into :attr:`record` with each station's key state and relays at that
  moment (see :mod:`.record`).
* A station's inhibit is asserted while it is inhibited by command, while a
  station that ``~`` lists it for is on the air, and during slow transitions
  and interrupts.  The output is pulled down when inhibited (or, with ``^E``,
  when not inhibited); an inactive box pulls nothing down.
"""

from __future__ import annotations

from ..commands import parse_command
from ..errors import CommandRejected
from ..messages import (
    ErrorReply,
)
from ..replies import encode_reply
from .boxstate import INPUT_BUFFER, STATIONS, StationConnection
from .handlers import HANDLERS, CommandHandlers
from .record import EntryCause
from .station import NO_SLOT, SlotRole, Station, Trigger
from .view import BoxView, StationView


class EmulatorModel(CommandHandlers):
    """One MOAS II box."""

    def __init__(self, unit_id: int = 0, version: str = "100") -> None:
        self._input = bytearray()
        self._overflowed = False
        super().__init__(unit_id, version)

    # ------------------------------------------------------------------ public

    @property
    def now(self) -> float:
        return self._now

    def feed(self, data: bytes, now: float) -> bytes:
        """Take bytes from the computer; return the box's answer."""
        self._advance_to(now)
        for byte in data:
            self._take(byte)
        return self._flush()

    def advance(self, now: float) -> bytes:
        """Let time pass up to ``now``; return what the box sent meanwhile."""
        self._advance_to(now)
        return self._flush()

    def set_tr(self, station: int, transmitting: bool, now: float) -> bytes:
        """A station's key line changed (True: asserted)."""
        self._advance_to(now)
        st = self.stations[station]
        if st.key != transmitting:
            st.key = transmitting
            if not transmitting:
                st.released_at = self._now
            if self.active:
                if transmitting:
                    self._key_down(st)
                else:
                    self._fire(st, Trigger.KEY_UP)
                self._settle()
            self._write(EntryCause.KEY, f"{'key' if transmitting else 'unkey'} {station}")
        return self._flush()

    def view(self) -> BoxView:
        """A still picture of everything."""
        return BoxView(
            active=self.active,
            resolver_on=self.resolver_on,
            relays=self.relays(),
            station0=self.station0,
            stations=tuple(self._station_view(st) for st in self.stations.values()),
            unit_id=self.unit_id,
            version=self.version,
            inhibit_ms=self.inhibit_ms,
            interrupt_ms=self.interrupt_ms,
            events=frozenset(self.events),
        )

    # ------------------------------------------------------------------ input

    def _flush(self) -> bytes:
        out = b"".join(encode_reply(m) for m in self._out)
        self._out.clear()
        return out

    def _take(self, byte: int) -> None:
        if byte <= 0x20:
            return
        if byte == 0x24:  # "$"
            self._input.clear()
            self._overflowed = False
        elif byte == 0x3B:  # ";"
            if not self._overflowed and self._input:
                self._execute(self._input.decode("latin-1"))
            self._input.clear()
            self._overflowed = False
        elif not self._overflowed:
            if len(self._input) >= INPUT_BUFFER:
                self._overflowed = True
                self._input.clear()
                self._emit(ErrorReply("F"))
            else:
                self._input.append(byte)

    def _execute(self, text: str) -> None:
        try:
            command = parse_command(text)
        except CommandRejected as exc:
            self._emit(ErrorReply(exc.code))
            return
        self._command = f"{text};"
        HANDLERS[type(command)](self, command)
        self._settle()
        self._note(self._command)

    # ------------------------------------------------------------------ view

    def _station_view(self, st: Station) -> StationView:
        inhibited = self.inhibited(st.number)
        enable_low = st.number in self.enable_low
        return StationView(
            number=st.number,
            key=st.key,
            phase=st.phase,
            transmitting=st.tx_side,
            on_alternate=self._alternate_selected(st),
            tx=st.current[SlotRole.TX],
            rx=st.current[SlotRole.RX],
            alt=st.current[SlotRole.ALT],
            extra=st.current[SlotRole.EXTRA].relays,
            pending=tuple((k.value, r.slot.antenna) for k, r in st.pending.items()),
            mode=st.mode,
            receive_delay_ms=st.receive_delay_ms,
            inhibited=inhibited,
            inhibited_by_command=st.number in self.cmd_inhibited,
            inhibited_by=self._inhibited_by(st),
            inhibit_line_low=self.active and inhibited != enable_low,
            enable_low=enable_low,
            closed=self._closed(st) if self.active else frozenset(),
        )


__all__ = ["INPUT_BUFFER", "NO_SLOT", "STATIONS", "EmulatorModel", "StationConnection"]
