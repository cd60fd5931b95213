"""What-if: what the engine does with a draft station, asked of a fresh engine.

:func:`what_if` builds a new :class:`~moas_gui.engine.Engine` from the configuration
(never the running server's: nothing here reaches a switch), tunes the radios it is
given in the order given, keys those said to transmit, and reads each radio's
transmit, receive and alternate antennas with the engine's own :class:`Why`.
``moas-server --what-if`` prints the same answers.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

from moas_gui.config.model import Config, RadioRef
from moas_gui.engine import Engine, EngineError, RadioView
from moas_gui.engine.index import RadioKind
from moas_gui.errors import MoasError


class WhatIfError(MoasError, ValueError):
    """A question the draft cannot answer (a radio that is not in it, a frequency below 0)."""


@dataclass(frozen=True, slots=True)
class Answer:
    """One radio's antennas in the scenario, and why."""

    radio: RadioRef
    khz: float | None
    transmitting: bool
    tx: int | None
    rx: int | None
    alt: int | None
    inhibited: bool
    note: str
    rule: str
    why: str
    passed_over: tuple[tuple[int, str], ...] = ()
    names: dict[int, str] = field(default_factory=dict, compare=False, repr=False)

    def name(self, antenna: int | None) -> str:
        if antenna is None:
            return "none"
        return f"{antenna} {self.names.get(antenna, '')}".rstrip()

    def to_dict(self) -> dict[str, Any]:
        def antenna(a: int | None) -> dict[str, Any] | None:
            return None if a is None else {"id": a, "name": self.names.get(a, "")}
        return {"station": self.radio.station, "radio": self.radio.radio, "khz": self.khz,
                "transmitting": self.transmitting, "tx": antenna(self.tx),
                "rx": antenna(self.rx), "alt": antenna(self.alt),
                "inhibited": self.inhibited, "note": self.note,
                "why": {"rule": self.rule, "text": self.why,
                        "passed_over": [{"antenna": a, "reason": r}
                                        for a, r in self.passed_over]}}

    def to_text(self) -> str:
        where = f"at {self.khz:g} kHz" if self.khz is not None else "with no frequency"
        keyed = ", transmitting" if self.transmitting else ""
        lines = [(f"station {self.radio.station} radio {self.radio.radio} {where}{keyed}: "
                 f"transmit {self.name(self.tx)}; receive {self.name(self.rx)}; "
                 f"alternate {self.name(self.alt)}")]
        if self.inhibited:
            lines.append(f"  inhibited: {self.note or 'transmit is inhibited'}")
        elif self.note:
            lines.append(f"  note: {self.note}")
        if self.why:
            lines.append(f"  why: {self.why}" + (f" [{self.rule}]" if self.rule else ""))
        lines += [f"  passed over {self.name(a)}: {reason}" for a, reason in self.passed_over
                  if not reason.startswith("does not cover")]
        return "\n".join(lines)


def _answer(view: RadioView, names: dict[int, str]) -> Answer:
    why = view.why
    return Answer(RadioRef(view.station, view.radio), view.khz, view.transmitting, view.tx,
                  view.rx, view.alt, view.inhibited, view.note,
                  why.rule if why else "", why.text if why else "",
                  why.passed_over if why else (), names)


def what_if(config: Config, tunings: Sequence[tuple[RadioRef, float]],
            transmitting: Iterable[RadioRef] = ()) -> list[Answer]:
    """Each radio's antennas once the radios of ``tunings`` are on their frequencies (in
    that order) and those of ``transmitting`` are keyed, by a fresh engine."""
    engine = Engine(config)
    ix = engine._ix  # the engine's read-only index of the configuration (as the plan uses)
    known = {ref for ref in ix.order}
    for ref, khz in tunings:
        if ref not in known:
            raise WhatIfError(f"station {ref.station} radio {ref.radio} is not in \"Radios\"")
        try:
            engine.set_frequency(ref.station, ref.radio, khz)
        except EngineError as exc:
            raise WhatIfError(f"station {ref.station} radio {ref.radio}: {exc}") from None
    for ref in transmitting:
        if ref not in known:
            raise WhatIfError(f"station {ref.station} radio {ref.radio} is not in \"Radios\"")
        if ix.radios[ref].kind is not RadioKind.MAIN:
            raise WhatIfError(f"station {ref.station} radio {ref.radio} is a receiver of "
                              "another radio and does not transmit")
        for switch, port in ix.radios[ref].ports[:1]:
            engine.set_transmitting(switch, port, True)
    names = {a.id: a.label for a in config.antennas}
    return [_answer(view, names) for view in engine.radios()]


def answers_text(answers: Sequence[Answer]) -> str:
    return "".join(answer.to_text() + "\n" for answer in answers)


def answers_json(file: str, answers: Sequence[Answer]) -> str:
    return json.dumps({"file": file, "radios": [a.to_dict() for a in answers]}, indent=2) + "\n"


def parse_radio(text: str) -> RadioRef:
    """``S/R`` (station and radio numbers) as a :class:`RadioRef`."""
    station, slash, radio = text.strip().partition("/")
    if not slash or not station.strip().isdigit() or not radio.strip().isdigit():
        raise WhatIfError(f"{text!r} is not a station and radio such as 1/2")
    return RadioRef(int(station), int(radio))


def parse_khz(text: str) -> float:
    try:
        khz = float(text)
    except ValueError:
        raise WhatIfError(f"{text!r} is not a frequency in kHz (for example 14025)") from None
    if not 0 < khz < float("inf"):
        raise WhatIfError(f"{text!r} is not a frequency in kHz above 0")
    return khz


__all__ = ["Answer", "WhatIfError", "answers_json", "answers_text", "parse_khz", "parse_radio",
           "what_if"]
