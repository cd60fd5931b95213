"""Reading a ``.moas`` file into a :class:`~.model.Config`, or every reason it cannot be.

A file with any error is never half-loaded: :func:`load_config` returns either a
complete configuration (perhaps with warnings) or none at all.
"""

from __future__ import annotations

import gc
import sys
from dataclasses import dataclass
from pathlib import Path

from .jsontree import JObject, describe, parse
from .model import Config
from .ports import check_port_names
from .problems import ConfigError, Problem, Severity
from .reading import BAD, Reading
from .rigs import check_rig_sources
from .schema import TOP
from .validate import check
from .wiring import check_wiring

MAX_BYTES = 10 * 1024 * 1024
"""Files larger than this are refused: no station needs a configuration this big."""


@dataclass(frozen=True, slots=True)
class LoadResult:
    """The outcome of reading a configuration: ``config`` is None when there are errors."""

    config: Config | None
    problems: tuple[Problem, ...]

    @property
    def errors(self) -> tuple[Problem, ...]:
        return tuple(p for p in self.problems if p.severity is Severity.ERROR)

    @property
    def warnings(self) -> tuple[Problem, ...]:
        return tuple(p for p in self.problems if p.severity is Severity.WARNING)

    @property
    def ok(self) -> bool:
        return self.config is not None

    def unwrap(self) -> Config:
        """The configuration, or :class:`ConfigError` carrying every problem."""
        if self.config is None:
            raise ConfigError(self.problems)
        return self.config


def _whole_file(path: str, message: str) -> LoadResult:
    return LoadResult(None, (Problem(0, 0, Severity.ERROR, message, path),))


def load_config(path: str | Path, *, platform: str = sys.platform) -> LoadResult:
    """Read and check the configuration file at ``path`` (``platform``: the system it is
    to run on, for the port names; this one by default)."""
    path = Path(path)
    name = str(path)
    try:
        size = path.stat().st_size
        if path.is_dir():
            return _whole_file(name, "this is a folder, not a configuration file")
        if size > MAX_BYTES:
            return _whole_file(name, f"the file is {size / 1_048_576:.1f} MB; a configuration "
                                     "file is refused above 10 MB (is this the right file?)")
        data = path.read_bytes()
    except FileNotFoundError:
        return _whole_file(name, "there is no such file")
    except PermissionError:
        return _whole_file(name, "the file cannot be read: permission denied")
    except OSError as exc:
        return _whole_file(name, f"the file cannot be read: {exc.strerror or exc}")
    return read_config(data, name, path, platform=platform)


def read_config(data: bytes, filename: str = "<config>", path: Path | None = None, *,
                platform: str = sys.platform) -> LoadResult:
    """Read and check a configuration file's bytes (``filename`` is used in messages)."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        return LoadResult(None, (Problem(line, column, Severity.ERROR,
                                         "the file is not UTF-8 text (byte "
                                         f"0x{data[exc.start]:02X}); save it as UTF-8",
                                         filename),))
    return parse_config(text, filename, path, platform=platform)


def parse_config(text: str, filename: str = "<config>", path: Path | None = None, *,
                 platform: str = sys.platform) -> LoadResult:
    """Read and check configuration ``text`` (``filename`` is used in messages)."""
    # Reading makes a great many small objects and no cycles: the cycle collector,
    # left on, would walk them all again and again (it doubled the time of a large file).
    collecting = gc.isenabled()
    gc.disable()
    try:
        return _parse_config(text, filename, path, platform)
    finally:
        if collecting:
            gc.enable()


def _parse_config(text: str, filename: str, path: Path | None, platform: str) -> LoadResult:
    root, syntax = parse(text, filename)
    reading = Reading(filename)
    config: Config | None = None
    if root is not None:
        if not isinstance(root, JObject):
            reading.error(root, f"a configuration is a group that starts with '{{', not {describe(root)}")
        else:
            values = reading.group(root, TOP, "the configuration")
            if values is not BAD:
                config = Config(path=path, **values)
                reading.remember(config, root)
                check(config, reading)
                check_wiring(config, reading)
                check_rig_sources(config, reading)
                check_port_names(config, reading, platform)
    problems = tuple(sorted(syntax + reading.problems.listed(),
                            key=lambda p: (p.line == 0, p.line, p.column)))
    has_errors = any(p.severity is Severity.ERROR for p in problems)
    return LoadResult(None if has_errors else config, problems)


__all__ = ["MAX_BYTES", "LoadResult", "load_config", "parse_config", "read_config"]
