"""Every controller model this project knows, by MOAS number and by name.

==========  ======  ========================  ===========  ======================
number      name    also accepted             baud         Hamlib model checked
==========  ======  ========================  ===========  ======================
1           DCU1    DCU-1                     4800         403
2           RotorEZ Rotor-EZ, RotorCard       4800         401
4           Yaesu   GS-232B                   9600         603
(name)      GS-232A                           9600         601
5           Alfaspid SPID                     1200         902 (frames learnt)
(name)      Rot1Prog                          1200         902
(name)      Rot2Prog                          600          901
8           RC2800P-A                         9600         1002
9           RC2800P-X                         9600         1001
10          Prosistel D  Prosistel            9600         1701
==========  ======  ========================  ===========  ======================

Names are matched without regard to case, spaces, hyphens or underscores
("prosistel-d", "GS232A").  Numbers 3, 6 and 7 are reserved by MOAS and
unknown here.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from . import dcu1, prosistel, rc2800, rotorez, spid, yaesu
from .base import DEFAULT_SPEED, ControllerCodec, ControllerEmulator, ModelInfo, UnknownModel
from .dcu1_emulator import DCU1Emulator
from .prosistel_emulator import ProsistelEmulator
from .rc2800_emulator import RC2800Emulator
from .rotorez_emulator import RotorEZEmulator
from .spid_emulator import SpidEmulator
from .yaesu_emulator import YaesuEmulator

EmulatorFactory = Callable[[float, float, float], ControllerEmulator]
"""``factory(azimuth, speed, now)``."""


@dataclass(frozen=True, slots=True)
class Model:
    """One controller model: what the driver needs and how to emulate it."""

    info: ModelInfo
    codec: Callable[[], ControllerCodec]
    emulator: EmulatorFactory
    aliases: tuple[str, ...] = ()
    hamlib: tuple[int, ...] = ()
    """``rotctl -m`` numbers that drive this model's emulator."""

    @property
    def name(self) -> str:
        return self.info.name

    def make_emulator(self, azimuth: float = 0.0, speed: float = DEFAULT_SPEED,
                      now: float = 0.0) -> ControllerEmulator:
        return self.emulator(azimuth, speed, now)


MODELS: tuple[Model, ...] = (
    Model(dcu1.INFO, dcu1.DCU1Codec,
          lambda az, speed, now: DCU1Emulator(az, speed, now), ("DCU-1",), (403,)),
    Model(rotorez.INFO, rotorez.RotorEZCodec,
          lambda az, speed, now: RotorEZEmulator(az, speed, now), ("Rotor-EZ", "RotorCard"),
          (401,)),
    Model(yaesu.INFO_B, lambda: yaesu.YaesuCodec(yaesu.INFO_B),
          lambda az, speed, now: YaesuEmulator(az, "B", speed, now), ("GS-232B",), (603,)),
    Model(yaesu.INFO_A, lambda: yaesu.YaesuCodec(yaesu.INFO_A),
          lambda az, speed, now: YaesuEmulator(az, "A", speed, now), (), (601,)),
    Model(spid.INFO_ALFASPID, lambda: spid.SpidCodec(None),
          lambda az, speed, now: SpidEmulator(az, False, speed=speed, now=now), ("SPID",),
          (902,)),
    Model(spid.INFO_ROT1, lambda: spid.SpidCodec("rot1"),
          lambda az, speed, now: SpidEmulator(az, False, speed=speed, now=now), (), (902,)),
    Model(spid.INFO_ROT2, lambda: spid.SpidCodec("rot2"),
          lambda az, speed, now: SpidEmulator(az, True, speed=speed, now=now), (), (901,)),
    Model(rc2800.INFO_A, lambda: rc2800.RC2800Codec(early=True),
          lambda az, speed, now: RC2800Emulator(az, True, speed, now), (), (1002,)),
    Model(rc2800.INFO_X, lambda: rc2800.RC2800Codec(early=False),
          lambda az, speed, now: RC2800Emulator(az, False, speed, now), (), (1001,)),
    Model(prosistel.INFO, prosistel.ProsistelCodec,
          lambda az, speed, now: ProsistelEmulator(az, speed, now), ("Prosistel",), (1701,)),
)


def _key(text: str) -> str:
    return "".join(ch for ch in text.casefold() if ch not in " -_")


_BY_KEY: dict[str, Model] = {}
for _model in MODELS:
    for _name in (_model.info.name, *_model.aliases):
        _BY_KEY[_key(_name)] = _model
    if _model.info.number is not None:
        _BY_KEY[str(_model.info.number)] = _model


def known_models() -> str:
    """A one-line list for messages: ``1 DCU1, 2 RotorEZ, ..., GS-232A, ...``."""
    return ", ".join(
        f"{m.info.number} {m.info.name}" if m.info.number is not None else m.info.name
        for m in MODELS
    )


def find_model(text: str) -> Model:
    """The model for a MOAS number ("4") or a name ("Yaesu", "prosistel d").

    Raises :class:`UnknownModel` with the list of known models.
    """
    key = _key(text.strip())
    if key.isdigit():
        key = str(int(key))
    model = _BY_KEY.get(key)
    if model is None:
        raise UnknownModel(f"unknown rotator model {text.strip()!r} (known: {known_models()})")
    return model


def is_model_name(text: str) -> bool:
    """True when ``text`` names a model (numbers do not count)."""
    key = _key(text.strip())
    return not key.isdigit() and key in _BY_KEY


__all__ = ["MODELS", "Model", "find_model", "is_model_name", "known_models"]
