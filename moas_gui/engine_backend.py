"""The client protocol's backend for the real server: requests become operations.

:class:`~moas_gui.net.server.ClientServer` asks a backend for everything
(:mod:`moas_gui.net.backend`); this one answers from a :class:`ServerCore`
(the running :class:`~moas_gui.app.ServerApp` is one): every request that
changes something becomes one operation handed to ``act`` (the engine's one
door), rotator requests go to the rotator manager, and the rest are read from
the engine's views.  Engine and rotator refusals keep their code and sentence.
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol, TypeVar

from moas_gui.engine import Engine
from moas_gui.engine.operations import (
    Hold,
    Operation,
    Relative,
    RunFunction,
    Select,
    SetFrequency,
    perform,
)
from moas_gui.engine.views import RadioView
from moas_gui.errors import RequestRefused
from moas_gui.hw.rotators.manager import RotatorManager
from moas_gui.net.backend import (
    ErrorCode,
    FocusKind,
    JSONObject,
    RequestError,
    SwitchAction,
    Target,
)
from moas_gui.net.identity import Action, Forbidden, check, current, enforce
from moas_gui.rights import action_for, rotator_radios
from moas_gui.status import ServerStatus

if TYPE_CHECKING:  # the Antenna Genius front is loaded when a station serves it
    from moas_gui.net.antenna_genius.server import PortRequest

T = TypeVar("T")

log = logging.getLogger(__name__)


class ServerCore(Protocol):
    """What the client backend needs from the server, and nothing more."""

    @property
    def engine(self) -> Engine | None:
        """The running engine (read for views only), None when no configuration runs."""
        ...

    @property
    def rotator_manager(self) -> RotatorManager | None:
        """The running rotators, None when the configuration has none."""
        ...

    @property
    def status(self) -> ServerStatus:
        """The file that runs and each switch's status."""
        ...

    def act(self, op: Operation) -> set[tuple[int, int]]:
        """Apply one engine input now; raises :class:`EngineError` when refused.  Returns
        the radios whose entries were published to clients."""
        ...

    def radio_entry(self, station: int, radio: int) -> JSONObject:
        """A radio's entry as clients see it (the engine's view plus its station's focus)."""
        ...

    def set_focus(self, station: int, radio: int, kind: FocusKind) -> set[tuple[int, int]]:
        """The station's transmit (``"active"``) or receive (``"focus"``) focus is on
        ``radio``; raises the engine's not-found error for a radio that does not exist."""
        ...

    def stop_switches(self) -> None:
        """Every relay off (File > Stop Switches)."""
        ...

    def start_switches(self) -> None:
        """The switches run again (File > Start Switches)."""
        ...

    def reset_switches(self) -> None:
        """Every switch reset and loaded again (File > Reset Switches)."""
        ...

    def keyed_radios(self) -> list[str]:
        """The radios transmitting now, as the switches say, in words."""
        ...


def _refused(action: Callable[[], T]) -> T:
    """``action()``, with an engine's or rotator's refusal as the client protocol's error."""
    try:
        return action()
    except RequestError:
        raise
    except RequestRefused as exc:  # EngineError, RotatorError
        raise RequestError(exc.code, exc.message) from None


class EngineBackend:
    """Serves client requests from a :class:`ServerCore`."""

    def __init__(self, core: ServerCore) -> None:
        self.core = core

    def _engine(self) -> Engine:
        engine = self.core.engine
        if engine is None:
            raise RequestError(ErrorCode.NOT_RUNNING, "No configuration is open")
        return engine

    def _act(self, op: Operation) -> None:
        self._engine()
        _refused(lambda: self.core.act(op))

    def _antennas(self, station: int, radio: int) -> JSONObject:
        view = self._engine().radio_view(station, radio)
        return {"tx": view.tx, "rx": view.rx}

    def snapshot(self) -> JSONObject:
        core = self.core
        engine = core.engine
        if engine is None:
            return {"config": None, "radios": [], "antennas": [], "rotators": [], "switches": [],
                    "loop_lag_ms": core.status.loop_lag_ms}
        manager = core.rotator_manager
        rotators = manager.views() if manager is not None else []
        return {
            "config": core.status.file,
            "radios": [core.radio_entry(v.station, v.radio) for v in engine.radios()],
            "antennas": [v.to_dict() for v in engine.antenna_views()],
            "rotators": [v.to_json() for v in rotators],
            "switches": [{"id": i, "status": s} for i, s in core.status.switches],
            "loop_lag_ms": core.status.loop_lag_ms,
        }

    def frequency(self, station: int, radio: int, khz: float, tx_khz: float | None) -> None:
        self._act(SetFrequency(station, radio, khz, tx_khz))

    def set_focus(self, station: int, radio: int, kind: FocusKind) -> None:
        self._engine()
        _refused(lambda: enforce(Action(f"{kind} on radio {station}/{radio}",
                                        frozenset({(station, radio)}))))
        _refused(lambda: self.core.set_focus(station, radio, kind))

    def select(self, station: int, radio: int, antenna: int, target: Target,
               exclusive: bool) -> JSONObject:
        self._act(Select(station, radio, antenna, target, exclusive))
        return self._antennas(station, radio)

    def function(self, station: int, radio: int, function: int) -> None:
        self._act(RunFunction(station, radio, function))

    def release(self, station: int, radio: int) -> None:
        held_by = _refused(lambda: self._engine().radio_view(station, radio)).held_by
        if held_by is None:
            return  # nothing held: nothing to do
        self._act(Hold(station, radio, None))
        who = current()
        if who is None or not who.is_operator:  # an operator's is logged by the role check
            log.info("%s released the hold of radio %d/%d (held by %s)",
                     who or "the server", station, radio, held_by)

    def relative(self, station: int, radio: int, step: int | None,
                 index: int | None) -> JSONObject:
        self._act(Relative(station, radio, step, index))
        return self._antennas(station, radio)

    def layout(self, station: int, radio: int, rows: int, columns: int) -> JSONObject:
        engine = self._engine()
        return _refused(lambda: engine.layout(station, radio, rows, columns)).to_dict()

    def _rotators(self) -> RotatorManager:
        self._engine()
        manager = self.core.rotator_manager
        if manager is None:
            raise RequestError(ErrorCode.NOT_FOUND, "This station has no rotators")
        return manager

    def _may_turn(self, rotator: int, what: str) -> None:
        radios = rotator_radios(self._engine(), rotator)
        _refused(lambda: enforce(Action(f"{what} rotator {rotator}", radios)))

    def rotate(self, rotator: int, heading: float) -> None:
        manager = self._rotators()
        self._may_turn(rotator, "turning")
        _refused(lambda: manager.start_rotate(rotator, heading))

    def stop(self, rotator: int) -> None:
        manager = self._rotators()
        self._may_turn(rotator, "stopping")
        _refused(lambda: manager.start_stop(rotator))

    def switches(self, action: SwitchAction, force: bool = False) -> None:
        self._engine()
        _refused(lambda: enforce(Action(f"{action} the switches", admin=True)))
        keyed = self.core.keyed_radios() if action != "start" and not force else []
        if keyed:
            what = "Stop Switches" if action == "stop" else "Reset Switches"
            raise RequestError(
                ErrorCode.UNAVAILABLE,
                f"{what} opens relays at once, and {', '.join(keyed)} "
                f"transmit{'s' if len(keyed) == 1 else ''} now (hot switching): unkey "
                'first, or send "force": true to do it anyway')
        {"stop": self.core.stop_switches, "start": self.core.start_switches,
         "reset": self.core.reset_switches}[action]()


class AgEngineBackend:
    """The Antenna Genius front's backend (:class:`~moas_gui.net.antenna_genius.server.AgBackend`):
    a ``port set`` becomes the engine's operations -- release (:class:`Hold` with no
    one), a frequency, the presses, a hold -- tried together on a copy of the engine,
    then handed one by one to ``act``, the server's one door."""

    def __init__(self, core: ServerCore) -> None:
        self.core = core

    @property
    def running(self) -> bool:
        return self.core.engine is not None

    def radio(self, station: int, radio: int) -> RadioView | None:
        engine = self.core.engine
        if engine is None:
            return None
        try:
            return engine.radio_view(station, radio)
        except RequestRefused:
            return None

    def port_set(self, request: PortRequest) -> None:
        engine = self.core.engine
        if engine is None:
            raise RequestError(ErrorCode.NOT_RUNNING, "No configuration is open")
        ops = operations(request)
        # the role first, for every operation: a command partly refused changes nothing
        who = current()
        for op in ops:
            action = action_for(op, engine.config)
            refusal = None if action is None else check(who, action)
            if refusal is not None:
                raise Forbidden(refusal)
        trial = engine.clone()
        now = asyncio.get_running_loop().time()  # the clock the server's door stamps with
        for op in ops:
            perform(trial, op, now=now)
        for op in ops:
            self.core.act(op)


def operations(request: PortRequest) -> list[Operation]:
    """The engine's operations for one ``port set``, in their order."""
    station, radio = request.station, request.radio
    ops: list[Operation] = []
    if request.release:
        ops.append(Hold(station, radio, None))
    if request.khz is not None:
        ops.append(SetFrequency(station, radio, request.khz))
    if request.tx is not None and request.tx == request.rx:
        ops.append(Select(station, radio, request.tx, "both", True))
    else:
        if request.tx is not None:
            ops.append(Select(station, radio, request.tx, "tx", True))
        if request.rx is not None:
            ops.append(Select(station, radio, request.rx, "rx", True))
    if request.hold_by is not None:
        ops.append(Hold(station, radio, request.hold_by, since=time.time()))
    return ops


__all__ = ["AgEngineBackend", "EngineBackend", "ServerCore", "operations"]
