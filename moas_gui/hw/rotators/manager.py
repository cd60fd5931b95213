"""The server's rotators: one driver per configured rotator, one view per rotator.

Usage (asyncio, no Qt)::

    manager = RotatorManager.from_config(config, on_change=broadcast,
                                         select_direction=engine_select)
    await manager.start()
    manager.views()                  # the client protocol's "rotators" list
    await manager.rotate(1, 270)     # RotatorError(code, sentence) when it cannot
    await manager.stop(1)
    manager.start_rotate(1, 270)     # the same without waiting (errors found at once raise)
    await manager.close()

``on_change(view)`` is called whenever a rotator's ``heading`` (whole
degrees), ``target``, ``moving`` or ``online`` changes: exactly the client
protocol's ``rotator`` event.  Serial rotators at the same address share one
connection to their MOAS Rotator program, as do the two rotators of one
Rotator Genius.  A rotator whose configuration cannot work (bad Address,
unknown Model, Rotation out of range) is shown offline and answers every
request with ``unavailable`` and the reason; the others carry on.  The
rotctld-compatible listeners of rotators with a ``RotctldPort``
(:mod:`moas_gui.net.rotctld_server`) are started by the server, which hands
them this manager.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Coroutine, Iterable, Sequence
from typing import TYPE_CHECKING

from moas_gui.aio import BackgroundTasks
from moas_gui.config.model import Antenna, Config, Rotator, RotatorControl

from .addresses import is_local, split_address
from .base import (
    RotatorDriver,
    RotatorError,
    RotatorStatus,
    RotatorView,
    Timing,
    UnusableRotator,
    describe,
)
from .electrical import ElectricalRotator, SelectDirection
from .headings import Travel, normalize
from .simulated import SimulatedRotator

if TYPE_CHECKING:
    from .genius import GeniusLink
    from .moas_rotator_link import MoasRotatorLink
    from .moas_rotator_process import LocalMoasRotator

log = logging.getLogger(__name__)

OnChange = Callable[[RotatorView], None]


class RotatorManager:
    def __init__(
        self,
        rotators: Sequence[Rotator],
        *,
        on_change: OnChange | None = None,
        antennas: Sequence[Antenna] = (),
        select_direction: SelectDirection | None = None,
        start_moas_rotator: bool = True,
        moas_rotator_port: int | None = None,
        moas_rotator_command: Sequence[str] | None = None,
        timing: Timing | None = None,
    ) -> None:
        self.timing = timing or Timing()
        self.on_change = on_change
        self._rotators = {r.id: r for r in rotators}
        self._views: dict[int, RotatorView] = {
            r.id: RotatorView.of(r, RotatorStatus()) for r in rotators
        }
        self._moas_links: dict[tuple[str, int], MoasRotatorLink] = {}
        self._genius_links: dict[tuple[str, int], GeniusLink] = {}
        self.drivers: dict[int, RotatorDriver] = {}
        for rotator in rotators:
            self.drivers[rotator.id] = self._driver(
                rotator, antennas, select_direction, moas_rotator_port
            )
        self.local_program: LocalMoasRotator | None = None
        local = [port for host, port in self._moas_links if is_local(host)]
        if start_moas_rotator and local:
            self.local_program = self._program(rotators, local[0], moas_rotator_command)
        self._tasks = BackgroundTasks(self._failed)
        """Turns and stops started for callers that cannot wait (:meth:`start_rotate`)."""

    def _program(self, rotators: Sequence[Rotator], port: int,
                 command: Sequence[str] | None) -> LocalMoasRotator:
        """The MOAS Rotator program this computer starts for its Serial rotators."""
        from . import moas_rotator_process as program

        ports = [r.comm_port for r in rotators
                 if r.control is RotatorControl.SERIAL and r.comm_port]
        return program.LocalMoasRotator(
            command or program.default_command(port, ports), port,
            restart_min=self.timing.restart_min, restart_max=self.timing.restart_max,
            clock=self.timing.clock)

    @classmethod
    def from_config(cls, config: Config, **options: object) -> RotatorManager:
        """A manager for ``config``'s rotators (and the antennas of Electrical ones)."""
        options.setdefault("start_moas_rotator", config.start_moas_rotator)
        return cls(config.rotators, antennas=config.antennas, **options)  # type: ignore[arg-type]

    # ---- building --------------------------------------------------------------------

    def _driver(self, rotator: Rotator, antennas: Sequence[Antenna],
                select: SelectDirection | None, moas_port: int | None) -> RotatorDriver:
        publish = self._publisher(rotator)
        try:
            travel = Travel(rotator.ccw_limit, rotator.rotation, rotator.has_stop)
        except ValueError as exc:
            return UnusableRotator(rotator, Travel(), publish, str(exc))
        try:
            return self._build(rotator, travel, publish, antennas, select, moas_port)
        except ValueError as exc:
            return UnusableRotator(rotator, travel, publish, str(exc))

    def _build(self, rotator: Rotator, travel: Travel, publish: Callable[[RotatorStatus], None],
               antennas: Sequence[Antenna], select: SelectDirection | None,
               moas_port: int | None) -> RotatorDriver:
        control = rotator.control
        if control is RotatorControl.TEST:
            return SimulatedRotator(rotator, travel, publish, self.timing)
        if control is RotatorControl.ELECTRICAL:
            directions = tuple(float(a.offset) for a in _antennas_turned_by(rotator, antennas))
            return ElectricalRotator(rotator, travel, publish, directions, select)
        if control is RotatorControl.SERIAL:
            return self._serial(rotator, travel, publish, moas_port)
        if control is RotatorControl.ROTATOR_GENIUS:
            return self._genius(rotator, travel, publish)
        if control is RotatorControl.HAMLIB:
            from .hamlib import HamlibRotator
            from .hamlib_codec import HAMLIB_PORT

            host, port = split_address(rotator.address, HAMLIB_PORT)
            return HamlibRotator(rotator, travel, publish, self.timing, host, port)
        raise ValueError(f"Control {control!r} is not a kind of rotator this server knows")

    # The drivers and codecs of the kinds a station does not use are loaded only when a
    # rotator of that kind is configured: a tower computer with Test or Electrical rotators
    # starts without them.

    def _serial(self, rotator: Rotator, travel: Travel, publish: Callable[[RotatorStatus], None],
                moas_port: int | None) -> RotatorDriver:
        from .moas_rotator_codec import PORT, check_field, model_field
        from .moas_rotator_link import MoasRotatorLink, SerialRotator

        field, scale = model_field(rotator.model)
        if not rotator.comm_port:
            raise ValueError("CommPort is missing (the serial port on the MOAS Rotator "
                             "computer, e.g. COM14)")
        check_field("CommPort", rotator.comm_port)
        port = PORT if moas_port is None else moas_port
        key = split_address(rotator.address or "127.0.0.1", port)
        link = self._moas_links.get(key)
        if link is None:
            link = self._moas_links[key] = MoasRotatorLink(key[0], key[1], self.timing)
        return SerialRotator(rotator, travel, publish, self.timing, link, field, scale)

    def _genius(self, rotator: Rotator, travel: Travel,
                publish: Callable[[RotatorStatus], None]) -> RotatorDriver:
        from .genius import GENIUS_PORT, GeniusLink, GeniusRotator

        if rotator.port not in (1, 2):
            raise ValueError(f"Port must be 1 or 2 (which rotator of the Rotator Genius), "
                             f"not {rotator.port}")
        key = split_address(rotator.address, GENIUS_PORT)
        genius = self._genius_links.get(key)
        if genius is None:
            genius = self._genius_links[key] = GeniusLink(key[0], key[1], self.timing)
        return GeniusRotator(rotator, travel, publish, genius)

    def _publisher(self, rotator: Rotator) -> Callable[[RotatorStatus], None]:
        def publish(status: RotatorStatus) -> None:
            view = RotatorView.of(rotator, status)
            if view == self._views.get(rotator.id):
                return
            self._views[rotator.id] = view
            if self.on_change is not None:
                try:
                    self.on_change(view)
                except Exception:
                    log.exception("the rotator change callback failed for %s", describe(rotator))
        return publish

    # ---- life ------------------------------------------------------------------------

    async def start(self) -> None:
        if self.local_program is not None:
            await self.local_program.start()
        for driver in self.drivers.values():
            await driver.start()
        for link in self._links():
            await link.start()

    async def close(self) -> None:
        await self._tasks.close()
        for link in self._links():
            await link.close()
        for driver in self.drivers.values():
            await driver.close()
        if self.local_program is not None:
            await self.local_program.stop()

    def _links(self) -> Iterable[MoasRotatorLink | GeniusLink]:
        yield from self._moas_links.values()
        yield from self._genius_links.values()

    # ---- what clients see ------------------------------------------------------------

    def views(self) -> list[RotatorView]:
        """Every rotator not marked Invisible, in configuration order."""
        return [self._views[i] for i, r in self._rotators.items() if not r.invisible]

    def view(self, rotator_id: int) -> RotatorView:
        self._rotator(rotator_id)
        return self._views[rotator_id]

    def rotator(self, rotator_id: int) -> Rotator:
        return self._rotator(rotator_id)

    # ---- requests --------------------------------------------------------------------

    async def rotate(self, rotator_id: object, heading: object) -> None:
        """Turn to compass ``heading``; a heading outside the travel turns to the
        nearer end.  Returns once the controller took the request.  Raises
        :class:`RotatorError`."""
        driver, wanted = self._request(rotator_id, heading)
        await driver.rotate(wanted)

    def travel_position(self, rotator_id: int) -> float | None:
        """Where on its travel the rotator is, when its driver knows."""
        return self.drivers[self._rotator(rotator_id).id].travel_position()

    async def stop(self, rotator_id: object) -> None:
        await self.drivers[self._rotator(rotator_id).id].stop()

    def start_rotate(self, rotator_id: object, heading: object) -> None:
        """``rotate`` for callers that cannot wait (the client protocol's backend):
        what can be checked at once raises :class:`RotatorError` here; the
        request then goes on in the background, and a later refusal by the
        controller is logged."""
        driver, wanted = self._request(rotator_id, heading)
        driver.check_ready()
        if isinstance(driver, ElectricalRotator):
            driver.turn(wanted)  # selecting antennas waits for nothing: errors come back now
            return
        self._background(driver.rotate(wanted), f"turning {driver.name} to {wanted:.0f}")

    def start_stop(self, rotator_id: object) -> None:
        """``stop`` for callers that cannot wait; see :meth:`start_rotate`."""
        driver = self.drivers[self._rotator(rotator_id).id]
        driver.forget_turn()
        driver.check_ready()
        self._background(driver.stop(), f"stopping {driver.name}")

    def _request(self, rotator_id: object, heading: object) -> tuple[RotatorDriver, float]:
        rotator = self._rotator(rotator_id)
        if isinstance(heading, bool) or not isinstance(heading, int | float):
            raise RotatorError("bad_request", f"heading must be a number of degrees, "
                               f"not {heading!r}")
        if not math.isfinite(heading):
            raise RotatorError("bad_request", f"heading must be a finite number, not {heading}")
        return self.drivers[rotator.id], normalize(float(heading))

    def _background(self, work: Coroutine[object, object, None], what: str) -> None:
        self._tasks.spawn(work, what)

    @staticmethod
    def _failed(what: str, error: BaseException) -> None:
        if isinstance(error, RotatorError):
            log.warning("%s failed: %s", what, error.message)
        else:
            log.error("%s failed unexpectedly", what, exc_info=error)

    def note_direction(self, rotator_id: int, heading: float) -> None:
        """An Electrical rotator's array now points at ``heading`` (the server
        calls this when the engine's selection changed the direction)."""
        driver = self.drivers.get(rotator_id)
        if isinstance(driver, ElectricalRotator):
            driver.note_direction(heading)

    def _rotator(self, rotator_id: object) -> Rotator:
        if isinstance(rotator_id, bool) or not isinstance(rotator_id, int):
            raise RotatorError("bad_request", f"rotator must be a rotator number, "
                               f"not {rotator_id!r}")
        rotator = self._rotators.get(rotator_id)
        if rotator is None:
            raise RotatorError("not_found", f"there is no rotator {rotator_id}")
        return rotator


def _antennas_turned_by(rotator: Rotator, antennas: Iterable[Antenna]) -> list[Antenna]:
    """The antennas naming this rotator; an antenna made of others has its Rotator
    ignored (6.4)."""
    return [
        a for a in antennas
        if a.rotator == rotator.id and not (set(a.in_use) - {a.id})
    ]


__all__ = ["OnChange", "RotatorManager"]
