"""Problems found in a configuration file, each with its place.

Errors of the project form a small tree::

    MoasError
     +-- ConfigError        the user's configuration file is unusable
     +-- ProtocolError      a peer (switch, client, rotator) sent nonsense
     +-- HardwareError      a port vanished or cannot be opened

Only :class:`ConfigError` lives here; it carries every :class:`Problem` found.
"""

from __future__ import annotations

import re
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


SHOWN_PER_KIND = 10
"""Problems of one kind listed before the rest of that kind are only counted."""

_PARTICULARS = re.compile(r'"[^"]*"|\'[^\']*\'|\d[\d,.]*')
"""What differs between two problems of one kind: names, texts and numbers."""


def problem_kind(severity: Severity, message: str) -> tuple[Severity, str]:
    """Problems whose messages differ only in names, texts and numbers are of one kind."""
    return severity, _PARTICULARS.sub("#", message)


class ProblemList:
    """Problems as they are found, kept within bounds whatever the file holds.

    The first :data:`SHOWN_PER_KIND` problems of each kind (:func:`problem_kind`) are
    kept; the rest of that kind are counted, and :meth:`listed` gives one more problem,
    at the first of them, saying how many there are ("and N more like this").  While
    :attr:`muted` is above 0, nothing is recorded at all (a caller that sums up a stretch
    of problems in its own words)."""

    def __init__(self, filename: str = "", shown: int = SHOWN_PER_KIND) -> None:
        self.filename = filename
        self.shown = shown
        self.muted = 0
        self.total = 0
        """Every problem recorded, listed or only counted."""
        self._kept: list[Problem] = []
        self._counts: dict[tuple[Severity, str], int] = {}
        self._first_hidden: dict[tuple[Severity, str], Problem] = {}

    def add(self, line: int, column: int, severity: Severity, message: str) -> None:
        if self.muted:
            return
        self.total += 1
        kind = problem_kind(severity, message)
        seen = self._counts.get(kind, 0)
        self._counts[kind] = seen + 1
        if seen < self.shown:
            self._kept.append(Problem(line, column, severity, message, self.filename))
        elif seen == self.shown:
            self._first_hidden[kind] = Problem(line, column, severity, message, self.filename)

    def __len__(self) -> int:
        return self.total

    def listed(self) -> list[Problem]:
        """The problems to show: those kept, and one line per kind with more than that."""
        out = list(self._kept)
        for kind, first in self._first_hidden.items():
            more = self._counts[kind] - self.shown - 1
            message = first.message if more == 0 else \
                f"{first.message} (and {more:,} more like this, not listed)"
            out.append(Problem(first.line, first.column, first.severity, message, first.file))
        return out


class ConfigError(MoasError):
    """A configuration that cannot be used; ``problems`` says every reason."""

    def __init__(self, problems: tuple[Problem, ...]) -> None:
        self.problems = problems
        errors = [p for p in problems if p.severity is Severity.ERROR]
        first = str(errors[0]) if errors else "configuration is unusable"
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        super().__init__(first + more)


__all__ = ["SHOWN_PER_KIND", "ConfigError", "Problem", "ProblemList", "Severity", "problem_kind"]
