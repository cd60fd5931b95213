"""Problems found in a configuration file, each with its place.

Errors of the project form a small tree::

    MoasError
     +-- ConfigError        the user's configuration file is unusable
     +-- ProtocolError      a peer (switch, client, rotator) sent nonsense
     +-- HardwareError      a port vanished or cannot be opened

Only :class:`ConfigError` lives here; it carries every :class:`Problem` found.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from moas_gui.errors import MoasError


class Severity(str, Enum):
    ERROR = "error"
    WARNING = "warning"


@dataclass(frozen=True, slots=True, order=True)
class Problem:
    """One thing wrong with a file, at a line and column (both 1-based; 0 = whole file)."""

    line: int
    column: int
    severity: Severity
    message: str
    file: str = ""

    def __str__(self) -> str:
        where = self.file or "<config>"
        if self.line:
            where += f":{self.line}:{self.column}"
        return f"{where}: {self.severity.value}: {self.message}"


class ConfigError(MoasError):
    """A configuration that cannot be used; ``problems`` says every reason."""

    def __init__(self, problems: tuple[Problem, ...]) -> None:
        self.problems = problems
        errors = [p for p in problems if p.severity is Severity.ERROR]
        first = str(errors[0]) if errors else "configuration is unusable"
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        super().__init__(first + more)


__all__ = ["ConfigError", "Problem", "Severity"]
