"""An emulated box on a hand-driven clock, in milliseconds and text.

For tests and experiments at a prompt: every call says when (in ms) it
happens and returns what the box answered, as text::

    box = SteppedBox()
    box.send("*1;&1;!1B112;")
    box.key(1, True, at=5)
    box.wait(30)
"""

from __future__ import annotations

from .model import EmulatorModel
from .view import StationView


class SteppedBox:
    """An :class:`EmulatorModel` with a millisecond clock moved by hand."""

    def __init__(self, unit_id: int = 0, *, active: bool = False, events: str = "") -> None:
        self.model = EmulatorModel(unit_id=unit_id)
        self.ms = 0.0
        self._origin = 0.0
        if events:
            self.send(f"*{events};")
        if active:
            self.send("*1;")

    def send(self, text: str, at: float | None = None) -> str:
        """Commands from the computer (``at`` ms, default: now)."""
        if at is not None:
            self.ms = at
        return self.model.feed(text.encode("latin-1"), self._seconds()).decode("latin-1")

    def wait(self, until: float) -> str:
        """Let time pass up to ``until`` ms."""
        self.ms = until
        return self.model.advance(self._seconds()).decode("latin-1")

    def key(self, station: int, on: bool, at: float | None = None) -> str:
        """Assert or release a station's key line."""
        if at is not None:
            self.ms = at
        return self.model.set_tr(station, on, self._seconds()).decode("latin-1")

    def settle(self) -> str:
        """Let every running timer run out, then call that moment 0 ms."""
        out = []
        while (deadline := self.model.next_deadline()) is not None:
            out.append(self.model.advance(deadline).decode("latin-1"))
        self._origin = self.model.now * 1000
        self.ms = 0.0
        return "".join(out)

    def _seconds(self) -> float:
        return (self._origin + self.ms) / 1000

    @property
    def relays(self) -> set[int]:
        return set(self.model.relays())

    def station(self, number: int) -> StationView:
        return self.model.view().station(number)

    def inhibited(self, number: int) -> bool:
        return self.model.inhibited(number)


__all__ = ["SteppedBox"]
