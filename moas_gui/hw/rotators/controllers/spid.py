"""SPID / Alfaspid Rot1Prog and Rot2Prog: fixed binary frames.

Computer to controller, always 13 bytes::

    W  H1 H2 H3 H4  PH  V1 V2 V3 V4  PV  K  0x20
    K = 0x1F status, 0x0F stop (both: all other fields 0x00), 0x2F set

    set, Rot1Prog:  H = 360 + azimuth (whole degrees) as three ASCII digits in H1-H3, H4 = "0"
    set, Rot2Prog:  H = PH * (360 + azimuth), V = PV * (360 + elevation), four ASCII digits each;
                    PH/PV = pulses per degree (1, 2 or 4) as the unit reports them

Controller to computer, answering status and stop (never set)::

    Rot1Prog  W H1 H2 H3 0x20                      azimuth = 100*H1 + 10*H2 + H3 - 360
    Rot2Prog  W H1 H2 H3 H4 PH V1 V2 V3 V4 PV 0x20  azimuth = 100*H1 + 10*H2 + H3 + H4/10 - 360
              (digits are binary values 0-9 here, not ASCII)

MOAS model 5 ("Alfaspid") starts at 1200 baud like a Rot1Prog and learns
which frame the unit speaks from its first answer; a turn asked for before
that answer waits for it (the codec asks at once).  "Rot1Prog" and
"Rot2Prog" (600 baud) name the protocol outright.  A Rot2Prog's set frame
needs its pulses per degree, which only a status answer tells, so the same
wait applies there, once.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import (
    NEED_MORE,
    NO_FRAME,
    FrameScanner,
    Heading,
    ModelInfo,
    Output,
    Send,
    SerialSettings,
    check_range,
    whole,
)


def _info(number: int | None, name: str, description: str, baudrate: int) -> ModelInfo:
    return ModelInfo(number=number, name=name, description=description,
                     serial=SerialSettings(baudrate), minimum=-180.0, maximum=540.0,
                     write_gap=0.3, reply_timeout=1.0)


INFO_ALFASPID = _info(5, "Alfaspid", "Alfaspid / SPID controller (Rot1Prog or Rot2Prog frames)",
                      1200)
INFO_ROT1 = _info(None, "Rot1Prog", "SPID Rot1Prog", 1200)
INFO_ROT2 = _info(None, "Rot2Prog", "SPID Rot2Prog", 600)

STATUS = b"W" + bytes(10) + b"\x1f\x20"
STOP = b"W" + bytes(10) + b"\x0f\x20"
SET = 0x2F
END = 0x20


@dataclass(frozen=True, slots=True)
class Position:
    """A decoded answer: which protocol, where, and the Rot2Prog resolution."""

    rot2: bool
    azimuth: float
    elevation: float = 0.0
    ph: int = 1
    pv: int = 1


def _digits(frame: bytes) -> bool:
    return all(b <= 9 for b in frame)


def match_answer(buffer: bytes) -> tuple[int, Position | None]:
    """Matcher for :class:`FrameScanner`: a 5-byte Rot1Prog or 12-byte Rot2Prog answer."""
    if buffer[0] != ord("W"):
        return NO_FRAME, None
    if len(buffer) < 5:
        return (NEED_MORE, None) if _digits(buffer[1:]) else (NO_FRAME, None)
    if not _digits(buffer[1:4]):
        return NO_FRAME, None
    if buffer[4] == END:
        h = buffer[1] * 100 + buffer[2] * 10 + buffer[3]
        return 5, Position(False, float(h - 360))
    if buffer[4] > 9:
        return NO_FRAME, None
    if len(buffer) < 12:
        part = buffer[6:11]
        return (NEED_MORE, None) if _digits(part[:4]) else (NO_FRAME, None)
    ph, pv = buffer[5], buffer[10]
    if not _digits(buffer[6:10]) or buffer[11] != END or not 1 <= ph <= 10 or not 1 <= pv <= 10:
        return NO_FRAME, None
    az = buffer[1] * 100 + buffer[2] * 10 + buffer[3] + buffer[4] / 10 - 360
    el = buffer[6] * 100 + buffer[7] * 10 + buffer[8] + buffer[9] / 10 - 360
    return 12, Position(True, round(az, 1), round(el, 1), ph, pv)


def set_frame_rot1(azimuth: float) -> bytes:
    return b"W" + b"%03d0" % (360 + whole(azimuth)) + bytes(6) + bytes((SET, END))


def set_frame_rot2(azimuth: float, elevation: float, ph: int, pv: int) -> bytes:
    h = whole(ph * (360 + azimuth))
    v = whole(pv * (360 + elevation))
    return (b"W" + b"%04d" % h + bytes((ph,)) + b"%04d" % v + bytes((pv,))
            + bytes((SET, END)))


class SpidCodec:
    """The driver's side of a SPID controller (``protocol`` None, "rot1" or "rot2")."""

    def __init__(self, protocol: str | None = None) -> None:
        if protocol not in (None, "rot1", "rot2"):
            raise ValueError(f"SPID protocol must be None, 'rot1' or 'rot2', not {protocol!r}")
        self.info = {None: INFO_ALFASPID, "rot1": INFO_ROT1, "rot2": INFO_ROT2}[protocol]
        self._rot2: bool | None = None if protocol is None else protocol == "rot2"
        self._resolution: tuple[int, int] | None = None
        self._elevation = 0.0
        self._waiting: float | None = None
        """A commanded azimuth held until the unit has told what it speaks."""
        self._scanner: FrameScanner[Position] = FrameScanner(
            match_answer, "SPID answer frame (W ... 0x20)")

    def opening(self) -> list[Send]:
        return []

    def poll(self, now: float) -> list[Output]:
        return [Send(STATUS, expects_reply=True)]

    def rotate(self, degrees: float, now: float) -> list[Output]:
        check_range(self.info, degrees)
        frame = self._set_frame(degrees)
        if frame is not None:
            self._waiting = None
            return [Send(frame)]
        self._waiting = degrees
        return [Send(STATUS, expects_reply=True)]

    def stop(self, now: float) -> list[Output]:
        self._waiting = None
        return [Send(STOP, expects_reply=True)]

    def receive(self, data: bytes, now: float) -> list[Output]:
        out: list[Output] = []
        for item in self._scanner.feed(data):
            if not isinstance(item, Position):
                out.append(item)
                continue
            self._rot2 = item.rot2  # the unit's own frames settle which protocol it speaks
            if item.rot2:
                self._resolution = (item.ph, item.pv)
                self._elevation = item.elevation
            out.append(Heading(item.azimuth))
            if self._waiting is not None:
                frame = self._set_frame(self._waiting)
                if frame is not None:
                    self._waiting = None
                    out.append(Send(frame))
        return out

    def deadline(self) -> float | None:
        return None

    def tick(self, now: float) -> list[Output]:
        return []

    def _set_frame(self, azimuth: float) -> bytes | None:
        if self._rot2 is None:
            return None
        if not self._rot2:
            return set_frame_rot1(azimuth)
        if self._resolution is None:
            return None
        ph, pv = self._resolution
        return set_frame_rot2(azimuth, self._elevation, ph, pv)


__all__ = ["INFO_ALFASPID", "INFO_ROT1", "INFO_ROT2", "STATUS", "STOP", "Position", "SpidCodec",
           "match_answer", "set_frame_rot1", "set_frame_rot2"]
