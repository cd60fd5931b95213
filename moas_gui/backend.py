"""The client protocol's backend for the real server: requests become engine calls.

:class:`~moas_gui.net.server.ClientServer` asks a backend for everything
(:mod:`moas_gui.net.backend`); this one answers from the running
:class:`~moas_gui.app.ServerApp`: the engine for antennas, the rotator manager
for rotators.  Engine refusals keep their code and sentence.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeVar

from moas_gui.engine import EngineError
from moas_gui.hw.rotators.base import RotatorError
from moas_gui.net.backend import ErrorCode, FocusKind, JSONObject, RequestError, Target

if TYPE_CHECKING:
    from moas_gui.app import ServerApp

T = TypeVar("T")


class EngineBackend:
    """Serves client requests from a :class:`ServerApp`."""

    def __init__(self, app: ServerApp) -> None:
        self.app = app

    def _engine(self) -> Any:
        engine = self.app.engine
        if engine is None:
            raise RequestError(ErrorCode.NOT_RUNNING, "No configuration is open")
        return engine

    def _now(self) -> float:
        return asyncio.get_running_loop().time()

    def _call(self, action: Callable[[], T]) -> T:
        try:
            return action()
        except EngineError as exc:
            raise RequestError(exc.code, str(exc)) from None

    def _antennas(self, station: int, radio: int) -> JSONObject:
        view = self._engine().radio_view(station, radio)
        return {"tx": view.tx, "rx": view.rx}

    def snapshot(self) -> JSONObject:
        app = self.app
        engine = app.engine
        if engine is None:
            return {"config": None, "radios": [], "antennas": [], "rotators": [], "switches": []}
        rotators = app.rotator_manager.views() if app.rotator_manager is not None else []
        return {
            "config": app.status.file,
            "radios": [app.radio_entry(v.station, v.radio) for v in engine.radios()],
            "antennas": [v.to_dict() for v in engine.antenna_views()],
            "rotators": [v.to_json() for v in rotators],
            "switches": [{"id": i, "status": s} for i, s in app.status.switches],
        }

    def frequency(self, station: int, radio: int, khz: float, tx_khz: float | None) -> None:
        engine = self._engine()
        self.app.apply_changes(self._call(
            lambda: engine.set_frequency(station, radio, khz, tx_khz, now=self._now())))

    def set_focus(self, station: int, radio: int, kind: FocusKind) -> None:
        self._engine()
        self._call(lambda: self.app.set_focus(station, radio, kind))

    def select(self, station: int, radio: int, antenna: int, target: Target,
               exclusive: bool) -> JSONObject:
        engine = self._engine()
        self.app.apply_changes(self._call(
            lambda: engine.select(station, radio, antenna, target, exclusive, now=self._now())))
        return self._antennas(station, radio)

    def function(self, station: int, radio: int, function: int) -> None:
        engine = self._engine()
        self.app.apply_changes(self._call(
            lambda: engine.run_function(station, radio, function, now=self._now())))

    def relative(self, station: int, radio: int, step: int | None,
                 index: int | None) -> JSONObject:
        engine = self._engine()
        self.app.apply_changes(self._call(
            lambda: engine.relative(station, radio, step=step, index=index, now=self._now())))
        return self._antennas(station, radio)

    def layout(self, station: int, radio: int, rows: int, columns: int) -> JSONObject:
        engine = self._engine()
        return self._call(lambda: engine.layout(station, radio, rows, columns)).to_dict()  # type: ignore[no-any-return]

    def _rotators(self) -> Any:
        self._engine()
        manager = self.app.rotator_manager
        if manager is None:
            raise RequestError(ErrorCode.NOT_FOUND, "This station has no rotators")
        return manager

    def rotate(self, rotator: int, heading: float) -> None:
        manager = self._rotators()
        try:
            manager.start_rotate(rotator, heading)
        except RotatorError as exc:
            raise RequestError(exc.code, exc.message) from None

    def stop(self, rotator: int) -> None:
        manager = self._rotators()
        try:
            manager.start_stop(rotator)
        except RotatorError as exc:
            raise RequestError(exc.code, exc.message) from None


__all__ = ["EngineBackend"]
