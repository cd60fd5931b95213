"""Every error raised on purpose hangs from MoasError's branches, as docs/architecture.md draws."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

from moas_gui.client.connection import ClientError
from moas_gui.config import ConfigError
from moas_gui.engine import BadRequest, EngineError, NotFound, NotRunning, Unavailable
from moas_gui.engine.snapshot import SnapshotError
from moas_gui.errors import HardwareError, MoasError, ProtocolError, RequestRefused
from moas_gui.hw.moas2.errors import CommandRejected, EncodeError, Moas2Error, PortError
from moas_gui.hw.moas2.sixbit import SixbitError
from moas_gui.hw.rotators.base import RotatorError
from moas_gui.hw.rotators.controllers.base import ControllerError, OutOfRange, UnknownModel
from moas_gui.net.backend import ErrorCode, RequestError
from moas_gui.net.client import ConnectionClosed
from moas_gui.net.identity import Forbidden
from moas_gui.net.messages import MessageEncodeError
from moas_gui.operators import OperatorError
from moas_gui.rotator_program.serial_link import PortError as RotatorPortError
from moas_gui.single_instance import InstanceError
from moas_gui.sources.n1mm_packet import N1MMPacketError
from moas_gui.state_store import StateError
from moas_gui.tls import TLSError

BRANCHES = {
    ConfigError: MoasError,
    RequestRefused: MoasError,
    ProtocolError: MoasError,
    HardwareError: MoasError,
    StateError: MoasError,
    SnapshotError: MoasError,
    EngineError: RequestRefused,
    RotatorError: RequestRefused,
    RequestError: RequestRefused,
    BadRequest: EngineError,
    NotFound: EngineError,
    Unavailable: EngineError,
    NotRunning: EngineError,
    Moas2Error: MoasError,
    ClientError: MoasError,
    CommandRejected: ProtocolError,
    EncodeError: Moas2Error,
    PortError: HardwareError,
    RotatorPortError: HardwareError,
    SixbitError: ProtocolError,
    ControllerError: ProtocolError,
    OutOfRange: ControllerError,
    UnknownModel: ControllerError,
    MessageEncodeError: ProtocolError,
    N1MMPacketError: ProtocolError,
    InstanceError: MoasError,
    ConnectionClosed: MoasError,
    Forbidden: RequestRefused,
    OperatorError: MoasError,
    TLSError: MoasError,
}


@pytest.mark.parametrize("error", list(BRANCHES), ids=lambda e: f"{e.__module__}.{e.__name__}")
def test_each_error_sits_on_its_branch(error: type[Exception]) -> None:
    assert issubclass(error, BRANCHES[error])
    assert issubclass(error, MoasError)


def test_every_refusal_carries_a_client_protocol_code_and_a_sentence() -> None:
    refusals: list[RequestRefused] = [
        Unavailable("Antenna 3 is in use by station 2"),
        RotatorError("not_found", "There is no rotator 9"),
        RequestError(ErrorCode.NOT_RUNNING, "No configuration is open"),
    ]
    assert [(r.code, r.message) for r in refusals] == [
        ("unavailable", "Antenna 3 is in use by station 2"),
        ("not_found", "There is no rotator 9"),
        ("not_running", "No configuration is open"),
    ]
    assert {ErrorCode(r.code) for r in refusals} <= set(ErrorCode)


def _every_module() -> list[str]:
    import moas_gui

    root = Path(moas_gui.__file__).parent
    names = []
    for path in sorted(root.rglob("*.py")):
        parts = path.relative_to(root).with_suffix("").parts
        if parts[0] in {"manual", "resources", "examples"} or parts[-1] == "__main__":
            continue
        names.append(".".join(("moas_gui", *(parts[:-1] if parts[-1] == "__init__" else parts))))
    return names


def test_every_error_class_the_package_defines_is_a_moas_error() -> None:
    """Not only the ones listed above: a new error anywhere must join the tree too."""
    outside = []
    for name in _every_module():
        module = importlib.import_module(name)
        for value in vars(module).values():
            if (isinstance(value, type) and issubclass(value, Exception)
                    and value.__module__ == name and not value.__name__.startswith("_")
                    and not issubclass(value, MoasError)):  # (a private one is a signal)
                outside.append(f"{name}.{value.__name__}")
    assert outside == [], f"errors outside MoasError (docs/architecture.md): {outside}"
