"""An in-memory antenna journal for the tests of the ADIF export and the contest report.

:class:`MemoryJournal` implements :class:`moas_gui.antenna_log.records.JournalReader` over
plain lists: it filters by period and clips spans to it as the real journal does, so the
export and the report can be tested on a journal whose every record the test wrote.
:func:`contest_journal` builds a small two-radio contest hour with known figures.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import gc
import importlib
import os
import signal
import socket
import sys
from collections.abc import AsyncIterator, Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Protocol, TypeVar

from helpers import free_port, until

from moas_gui.antenna_log.records import (
    AntennaSpan,
    Contact,
    HeadingMark,
    KeySpan,
    Period,
)

__all__ = ["T0", "MemoryJournal", "charts_loaded", "contact", "contest_journal"]

T0 = 1_795_000_000.0
"""2026-11-18 ... UTC: the contest journal's first second (a whole hour)."""
T0 -= T0 % 3600

CHART_MODULES = ("matplotlib.figure", "matplotlib.image", "matplotlib.backends.backend_agg",
                 "matplotlib.backends.backend_svg", "moas_gui.antenna_log.report_charts",
                 "moas_gui.ui.report_window")
"""matplotlib and the report's modules that load it."""


@functools.cache
def charts_loaded() -> None:
    """Imports :data:`CHART_MODULES` once per process, then keeps what they made (about
    66,000 objects) out of the cyclic collector (:func:`gc.freeze`, as ``tests/conftest.py``
    does with what collection loaded): every full collection after them -- one after each
    Qt test of the worker -- would walk them again, about 20 ms each.  The test modules
    that draw charts call it (a module fixture) before they make anything of their own;
    they import matplotlib where they use it, so that collecting the suite does not."""
    for name in CHART_MODULES:
        importlib.import_module(name)
    gc.collect()  # the garbage of what ran before is not kept with them
    gc.freeze()


@dataclass
class MemoryJournal:
    """A :class:`JournalReader` over lists (``contacts`` oldest first)."""

    contacts_: list[Contact] = field(default_factory=list)
    spans: list[AntennaSpan] = field(default_factory=list)
    keys: list[KeySpan] = field(default_factory=list)
    marks: list[HeadingMark] = field(default_factory=list)

    def extent(self) -> Period | None:
        times = (
            [c.time for c in self.contacts_]
            + [s.start for s in self.spans]
            + [s.end for s in self.spans]
            + [k.start for k in self.keys]
            + [k.end for k in self.keys]
            + [m.time for m in self.marks]
        )
        return Period(min(times), max(times)) if times else None

    def contacts(self, period: Period) -> list[Contact]:
        return [c for c in self.contacts_ if period.start <= c.time < period.end]

    def antenna_spans(self, period: Period) -> list[AntennaSpan]:
        return [
            replace(s, start=max(s.start, period.start), end=min(s.end, period.end))
            for s in self.spans
            if s.start < period.end and s.end > period.start
        ]

    def key_spans(self, period: Period) -> list[KeySpan]:
        return [
            replace(k, start=max(k.start, period.start), end=min(k.end, period.end))
            for k in self.keys
            if k.start < period.end and k.end > period.start
        ]

    def headings(self, period: Period) -> list[HeadingMark]:
        return [m for m in self.marks if period.start <= m.time < period.end]


def contact(
    number: int,
    time: float,
    call: str,
    band: str = "14",
    mode: str = "CW",
    *,
    radio: int | None = 1,
    tx: str = "Yagi 20",
    rx: str = "",
    heading: float | None = None,
    khz: float | None = 14025.0,
    rx_khz: float | None = None,
    operator: str = "K1AB",
    contest: str = "CQ-WW-CW",
    path: str = "",
) -> Contact:
    """One contact with sensible defaults (station 1)."""
    return Contact(
        contact_id=f"id{number}",
        time=time,
        call=call,
        band=band,
        mode=mode,
        station=None if radio is None else 1,
        radio=radio,
        tx_antenna=tx if radio is not None else "",
        rx_antenna=(rx or tx) if radio is not None else "",
        switch_path=path if radio is not None else "",
        heading=heading,
        operator=operator,
        contest=contest,
        tx_khz=khz,
        rx_khz=rx_khz,
    )


def contest_journal() -> MemoryJournal:
    """Two radios over two hours from :data:`T0`.

    Radio 1 is on 20 m: ``Yagi 20`` for the first 90 minutes, then ``Dipole 20``.  Radio 2
    is on 40 m with ``4-Square`` all along, receiving on ``Bev NE`` for its first hour.
    Contacts: radio 1 makes 6 in hour one (all Yagi 20) and 3 in hour two (1 on Yagi 20,
    2 on Dipole 20); radio 2 makes 4 in hour one and 2 in hour two (4-Square).
    Transmit time: Yagi 20 600 s, Dipole 20 300 s, 4-Square 1200 s.
    """
    hour = 3600.0
    spans = [
        AntennaSpan(1, 1, "tx", "Yagi 20", T0, T0 + 1.5 * hour),
        AntennaSpan(1, 1, "rx", "Yagi 20", T0, T0 + 1.5 * hour),
        AntennaSpan(1, 1, "tx", "Dipole 20", T0 + 1.5 * hour, T0 + 2 * hour),
        AntennaSpan(1, 1, "rx", "Dipole 20", T0 + 1.5 * hour, T0 + 2 * hour),
        AntennaSpan(1, 2, "tx", "4-Square", T0, T0 + 2 * hour),
        AntennaSpan(1, 2, "rx", "Bev NE", T0, T0 + hour),
        AntennaSpan(1, 2, "rx", "4-Square", T0 + hour, T0 + 2 * hour),
    ]
    keys = [
        KeySpan(1, 1, "Yagi 20", T0 + 100, T0 + 400),
        KeySpan(1, 1, "Yagi 20", T0 + 2000, T0 + 2300),
        KeySpan(1, 1, "Dipole 20", T0 + 1.6 * hour, T0 + 1.6 * hour + 300),
        KeySpan(1, 2, "4-Square", T0 + 500, T0 + 1100),
        KeySpan(1, 2, "4-Square", T0 + 1.2 * hour, T0 + 1.2 * hour + 600),
    ]
    contacts: list[Contact] = []
    number = 0

    def add(time: float, call: str, band: str, radio: int, tx: str, rx: str, khz: float) -> None:
        nonlocal number
        number += 1
        contacts.append(
            contact(
                number,
                time,
                call,
                band,
                radio=radio,
                tx=tx,
                rx=rx,
                khz=khz,
                heading=45.0 if radio == 1 else None,
            )
        )

    for i in range(6):
        add(T0 + 300 + i * 500, f"DL{i}AA", "14", 1, "Yagi 20", "Yagi 20", 14025)
    for i in range(4):
        add(T0 + 600 + i * 700, f"G{i}BB", "7", 2, "4-Square", "Bev NE", 7010)
    add(T0 + hour + 600, "F1CC", "14", 1, "Yagi 20", "Yagi 20", 14030)
    for i in range(2):
        add(T0 + 1.7 * hour + i * 300, f"I{i}DD", "14", 1, "Dipole 20", "Dipole 20", 14030)
    for i in range(2):
        add(T0 + 1.3 * hour + i * 300, f"EA{i}EE", "7", 2, "4-Square", "4-Square", 7012)
    contacts.sort(key=lambda c: c.time)
    marks = [HeadingMark("Rotor 20", 45.0, T0 + 10)]
    return MemoryJournal(contacts, spans, keys, marks)


class _Running(Protocol):
    process: asyncio.subprocess.Process
    lines: list[str]


RunningT = TypeVar("RunningT", bound=_Running)


@contextlib.asynccontextmanager
async def headless_server(config: Path, tmp_path: Path,
                          make: Callable[[asyncio.subprocess.Process, int, int], RunningT],
                          ) -> AsyncIterator[RunningT]:
    """``moas-server --headless`` on ``config`` (its own state and configuration folders
    under ``tmp_path``; the caller sets ``XDG_DATA_HOME``, which its journal reader shares),
    with the web page and N1MM's port on free ports; ``make(process, udp, web)`` wraps it.
    Its log lines gather in the wrapper's ``lines``; SIGTERM at the end, which must end it
    with status 0."""
    env = dict(os.environ, PYTHONUNBUFFERED="1", XDG_STATE_HOME=str(tmp_path / "state"),
               XDG_CONFIG_HOME=str(tmp_path / "config"))
    udp = free_port(socket.SOCK_DGRAM)
    web = free_port()
    process = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "moas_gui.cli.server", "--headless", str(config),
        "--bind", "127.0.0.1", "--tcp-port", "0", "--web-port", str(web),
        "--udp-port", str(udp), "--udp-bind", "127.0.0.1", "--no-rotator-program",
        "--new-instance", "--log-level", "info", stderr=asyncio.subprocess.PIPE, env=env)
    running = make(process, udp, web)

    async def collect() -> None:
        assert process.stderr is not None
        async for line in process.stderr:
            running.lines.append(line.decode(errors="replace"))
    reading = asyncio.ensure_future(collect())
    try:
        await until(lambda: any("Serving " in line for line in running.lines)
                    or process.returncode is not None, timeout=30, what="the server serving")
        assert process.returncode is None, "".join(running.lines)
        yield running
    finally:
        if process.returncode is None:
            process.send_signal(signal.SIGTERM)
            assert await asyncio.wait_for(process.wait(), 15) == 0, "".join(running.lines)
        await reading
