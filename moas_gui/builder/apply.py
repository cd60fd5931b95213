"""What the running server answered the builder's Save and Restart, when the builder runs
in a process of its own (``moas-server --edit FILE``).

The asking is done by the command line's side (``moas_gui/cli/builder_restart.py``,
through the single-instance channel); the window reads an :class:`ServerAnswer` and decides
what to say or ask.  The running server checks, at the moment it would restart, who
transmits: while a station is keyed and the operator has not confirmed it by name, it
refuses and names who does (``keyed``); the builder asks, and only a *Yes* sends the
request again with those names (``confirmed``).  A file other than the one it runs is
refused the same way (``running``) until the operator confirms the change of file.
Before the first request the builder *looks* (what the server runs, who transmits),
which changes nothing, so that a *No* to its question sends no request at all.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

NOT_REACHABLE = ("No moas-server of this user answers the builder: start one on the file "
                 "(moas-server FILE). A server started with --new-instance takes no "
                 "requests from the builder (by design: tests run such servers side by "
                 "side); restart it from its own window's File > Restart.")
"""What the builder says when no server can be reached."""


@dataclass(frozen=True, slots=True)
class ServerAnswer:
    """The running server's answer to one restart request."""

    restarted: bool
    said: str
    """In the builder's words, with the server's own when it gave some."""
    reached: bool = True
    """False when no server could be reached (none runs, one started with
    ``--new-instance``, or it did not answer)."""
    keyed: tuple[str, ...] = ()
    """Who transmits now, as the server names them (when it refused because of them)."""
    running: str | None = None
    """The file the server runs, when it refused because it is another one (or, for a
    look, when it is another one)."""
    looked: bool = False
    """The answer to a look (what runs, who transmits), not to a restart."""

    @property
    def asks(self) -> bool:
        """Whether the operator must be asked before the request is sent again."""
        return self.reached and not self.restarted and (bool(self.keyed)
                                                         or self.running is not None)


def question(path: Path, answer: ServerAnswer) -> tuple[str, str]:
    """The title and text of the question the builder asks about ``answer``."""
    parts = []
    if answer.running is not None:
        parts.append(f"The running server runs {answer.running}, not {path}.\n\n"
                     f"Stop it and restart on {path.name}? The switches are set up again "
                     "from the new file.")
    if answer.keyed:
        who = "\n".join(f"  {name}" for name in answer.keyed)
        parts.append(f"Restart restarts the server on the saved file: the antennas of every "
                     f"radio are chosen again.\n\nTransmitting now:\n{who}\n\nTheir relays "
                     "could change under the key (hot switching): unkey first, or restart "
                     "anyway?")
    title = "Restart while transmitting?" if answer.keyed else "Restart on another file?"
    return title, "\n\n".join(parts)


__all__ = ["NOT_REACHABLE", "ServerAnswer", "question"]
