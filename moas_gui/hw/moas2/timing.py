"""The switch link's clocks, and the test hook that shortens them in a server process.

:class:`LinkTiming` holds the link's four durations.  The real ones are its
defaults and nobody configures them: a ``.moas`` file has no setting for them.

Tests that drive the real ``moas-server`` process (``tests/faults/``) cannot
hand it a fake clock, so they shorten the link's clocks instead through the
environment variable :data:`ENVIRONMENT`, read by ``moas-server`` alone (see
docs/reliability.md, "Fault injection")::

    MOAS_GUI_SWITCH_TIMING="ping_interval=0.1 answer_timeout=0.5 retry_first=0.1 retry_max=0.4"

Names not given keep their real values.  The text is parsed strictly: an
unknown name, a repeated one, a value that is not a positive number of
seconds, or clocks that would not work together (pings no more often than the
answer timeout, a first retry longer than the longest) are refused with a
message that says which.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, fields, replace

ENVIRONMENT = "MOAS_GUI_SWITCH_TIMING"
"""The test hook: shorter link clocks for a ``moas-server`` process."""


@dataclass(frozen=True, slots=True)
class LinkTiming:
    """The link's clocks, in seconds (tests shorten them; ``--relay-dwell`` sets the
    dwell)."""

    ping_interval: float = 1.0
    """How often the link pings a box that is ready."""
    answer_timeout: float = 3.0
    """How long a question waits for its answer; as long without a well-formed
    message makes the box unresponsive."""
    retry_first: float = 0.5
    """The pause before the first new attempt after a session ended."""
    retry_max: float = 8.0
    """The longest pause between attempts (they double up to it)."""
    relay_dwell: float = 0.1
    """Automatic updates (loggers' frequencies) move a station's relays at most once in
    this long; the latest wanted state lands at its end (:mod:`.dwell`)."""

    def problems(self) -> list[str]:
        """What makes these clocks unusable together (empty when nothing does)."""
        found = []
        if self.ping_interval >= self.answer_timeout:
            found.append(f"ping_interval ({self.ping_interval:g} s) must be shorter than "
                         f"answer_timeout ({self.answer_timeout:g} s), or the pings alone "
                         f"would make the box unresponsive")
        if self.retry_first > self.retry_max:
            found.append(f"retry_first ({self.retry_first:g} s) must not be longer than "
                         f"retry_max ({self.retry_max:g} s)")
        return found


REAL_TIMING = LinkTiming()
"""The clocks a server runs with."""


def parse_timing(text: str, where: str = ENVIRONMENT) -> LinkTiming:
    """``name=seconds`` pairs, separated by spaces or commas, over the real clocks.

    Raises :class:`ValueError` naming ``where`` and what is wrong."""
    names = [item.name for item in fields(LinkTiming)]
    given: dict[str, float] = {}
    for pair in text.replace(",", " ").split():
        name, equals, value = pair.partition("=")
        if not equals:
            raise ValueError(f"{where}: {pair!r} is not name=seconds")
        if name not in names:
            raise ValueError(f"{where}: unknown name {name!r} (known: {', '.join(names)})")
        if name in given:
            raise ValueError(f"{where}: {name} is given twice")
        try:
            seconds = float(value)
        except ValueError:
            raise ValueError(f"{where}: {name}={value!r} is not a number of seconds") from None
        if not math.isfinite(seconds) or seconds <= 0:
            raise ValueError(f"{where}: {name}={value} is not a positive number of seconds")
        given[name] = seconds
    if not given:
        raise ValueError(f"{where}: no name=seconds given (known: {', '.join(names)})")
    timing = replace(REAL_TIMING, **given)
    problems = timing.problems()
    if problems:
        raise ValueError(f"{where}: {'; '.join(problems)}")
    return timing


def timing_from_environment(environ: Mapping[str, str] = os.environ) -> LinkTiming | None:
    """The test hook's clocks, or None when :data:`ENVIRONMENT` is not set (the real
    clocks).  Raises :class:`ValueError` for a text :func:`parse_timing` refuses."""
    text = environ.get(ENVIRONMENT)
    if text is None:
        return None
    return parse_timing(text)


__all__ = ["ENVIRONMENT", "REAL_TIMING", "LinkTiming", "parse_timing", "timing_from_environment"]
