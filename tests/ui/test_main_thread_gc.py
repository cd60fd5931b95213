"""Garbage in the window programs is collected on the Qt thread only: a thread that
allocates a great deal never collects it, and the collector's timer does, on the Qt thread."""

from __future__ import annotations

import gc
import threading
import weakref
from typing import Any

from moas_gui.ui.main_thread_gc import MainThreadCollector, collect_due
from moas_gui.ui.qt import QObject, QTimer


class Cycle:
    """A reference cycle holding a Qt object with a running timer: what a window's
    parts are (a widget and its handlers refer to each other)."""

    def __init__(self) -> None:
        self.me = self
        self.qt = QObject()
        self.timer = QTimer(self.qt)
        self.timer.start(60_000)


def make_cycle(freed_on: list[str]) -> None:
    cycle = Cycle()
    weakref.finalize(cycle, lambda: freed_on.append(threading.current_thread().name))


def test_a_busy_thread_never_collects_and_the_qt_thread_does(qtbot: Any) -> None:
    gc.enable()  # as in a program (tests/conftest.py keeps it off during a Qt test)
    collector = MainThreadCollector(interval_ms=10)
    try:
        assert not gc.isenabled()
        freed_on: list[str] = []
        make_cycle(freed_on)

        def allocate() -> None:  # far past every threshold: automatic collection would run
            junk = [[] for _ in range(200_000)]
            for item in junk:
                item.append(item)
        worker = threading.Thread(target=allocate, name="busy")
        worker.start()
        worker.join()
        assert freed_on == [], "collected off the Qt thread"
        qtbot.waitUntil(lambda: freed_on != [], timeout=5000)
        assert freed_on == [threading.main_thread().name]
    finally:
        collector.stop()
        gc.disable()


def test_stop_gives_collection_back_as_it_was(qtbot: Any) -> None:
    gc.enable()
    try:
        collector = MainThreadCollector()
        assert not gc.isenabled()
        collector.stop()
        assert gc.isenabled()
    finally:
        gc.disable()


def test_collect_due_collects_only_what_python_would() -> None:
    gc.disable()
    try:
        gc.collect()
        assert collect_due() is None  # all counts below their thresholds
        threshold = gc.get_threshold()[0]
        junk = [[] for _ in range(threshold + 10)]
        assert collect_due() == 0
        assert gc.get_count()[0] < threshold
        del junk
    finally:
        gc.enable()
