"""A line said again and again reaches the log once, then with a count."""

from __future__ import annotations

import logging

import pytest

from moas_gui.log_repeats import LineFormatter, RepeatFolder, fold_repeats, lean_records


class Kept(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.lines.append(f"{record.levelname} {record.getMessage()}")


class Caught(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


def logger_with(handler: logging.Handler, name: str) -> logging.Logger:
    log = logging.getLogger(name)
    log.propagate = False
    log.setLevel(logging.DEBUG)
    log.handlers = [handler]
    return log


def record(log: logging.Logger, level: int, text: str, at: float) -> None:
    made = log.makeRecord(log.name, level, __file__, 1, text, (), None)
    made.created = at
    log.handle(made)


def test_a_repeated_line_is_shown_once_then_with_its_count() -> None:
    kept = fold_repeats(Kept(), seconds=60)
    log = logger_with(kept, "moas_gui.test.repeats")
    for second in range(5):
        record(log, logging.WARNING, "link: cannot open /dev/x: [Errno 2] gone", 1000.0 + second)
    assert kept.lines == ["WARNING link: cannot open /dev/x: [Errno 2] gone"]
    record(log, logging.INFO, "link: port open", 1010.0)
    assert kept.lines[1].startswith("WARNING link: cannot open /dev/x: [Errno 2] gone (said 4 "
                                    "more times since ")
    assert kept.lines[2] == "INFO link: port open"
    assert len(kept.lines) == 3


def test_after_the_fold_time_the_same_line_comes_with_its_count() -> None:
    kept = fold_repeats(Kept(), seconds=60)
    log = logger_with(kept, "moas_gui.test.repeats2")
    record(log, logging.ERROR, "again", 0.0)
    record(log, logging.ERROR, "again", 30.0)
    record(log, logging.ERROR, "again", 61.0)
    assert kept.lines[0] == "ERROR again"
    assert kept.lines[1].startswith("ERROR again (said 1 more time since ")
    record(log, logging.ERROR, "again", 62.0)  # a new fold begins
    assert len(kept.lines) == 2


def test_lines_that_differ_are_all_shown() -> None:
    kept = Kept()
    kept.addFilter(RepeatFolder(kept))
    log = logger_with(kept, "moas_gui.test.repeats3")
    for n in range(3):
        record(log, logging.WARNING, f"rotator {n}: cannot connect", 5.0)
    record(log, logging.INFO, "rotator 2: cannot connect", 5.0)  # another level
    assert len(kept.lines) == 4


def test_the_server_line_is_the_usual_one_and_its_time_text_made_once_a_second(
        monkeypatch: pytest.MonkeyPatch) -> None:
    usual = logging.Formatter("%(asctime)s %(levelname)-7s %(message)s", "%H:%M:%S")
    lines = LineFormatter()
    made: list[float] = []
    real = logging.Formatter.formatTime

    def counted(self: logging.Formatter, rec: logging.LogRecord,
                datefmt: str | None = None) -> str:
        made.append(rec.created)
        return real(self, rec, datefmt)

    at = 1_790_000_000.0  # a whole second
    records = []
    for offset, text in [(0.1, "one"), (0.5, "two %d"), (0.9, "three"), (1.2, "four")]:
        rec = logging.makeLogRecord({"msg": text, "args": (2,) if "%d" in text else (),
                                     "levelno": logging.INFO, "levelname": "INFO"})
        rec.created = at + offset
        records.append(rec)
    monkeypatch.setattr(logging.Formatter, "formatTime", counted)
    shown = [lines.format(r) for r in records]
    monkeypatch.undo()
    assert shown == [usual.format(r) for r in records]
    assert shown[1].endswith("INFO    two 2")
    assert made == [at + 0.1, at + 1.2], "the time's text made once for each second"


def test_lean_records_carry_no_caller_thread_or_process() -> None:
    saved = (logging._srcfile, logging.logThreads,
             logging.logProcesses, logging.logMultiprocessing)
    caught = Caught()
    log = logger_with(caught, "test.lean")
    try:
        lean_records()
        log.info("a band change")
    finally:
        (logging._srcfile, logging.logThreads,
         logging.logProcesses, logging.logMultiprocessing) = saved
    assert [r.getMessage() for r in caught.records] == ["a band change"]
    made = caught.records[0]
    assert made.lineno == 0 and made.funcName == "(unknown function)"
    assert made.thread is None and made.process is None
