"""The builder's Save and Restart from a process of its own (``moas-server --edit FILE``):
both ends of the request, over the single-instance channel (moas_gui/single_instance.py,
with its checks: the same user only; on Windows the token only that user can read).

The builder's side, :func:`ask_to_restart`, first *looks* (``{"command": "station"}``:
the file the server runs and who transmits, which changes nothing), so the builder can
ask the operator before anything is sent that acts; then it sends ``{"command":
"restart", "file": ..., "confirmed": [who the operator agreed may be transmitting],
"replace": bool}`` once.  Each answer is read into a
:class:`moas_gui.builder.apply.ServerAnswer`.

The server's side, :func:`restart_request`, is registered as the ``"restart"`` command
by the headless server and the window server.  Right before it restarts it looks at who
transmits: anyone keyed whom the operator has not confirmed by name, and the request is
refused naming them (nothing changes); the same for a file other than the one running
until the change of file is confirmed.  Then it restarts through the same path as File >
Restart (``restart(path)``: the server's own check refuses a file with errors and the
running configuration carries on) and answers what happened.
"""

from __future__ import annotations

import logging
from collections.abc import Awaitable, Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    # the builder's side only: a server answering the builder does not load the builder
    from moas_gui.builder.apply import ServerAnswer
    from moas_gui.config import LoadResult

log = logging.getLogger(__name__)

RESTART_COMMAND = "restart"
STATION_COMMAND = "station"
RESTART_TIMEOUT = 60.0
"""Seconds the builder waits for the server's answer (opening a station's ports and
loggers takes a moment; a keyed or refused request answers at once)."""
SHOWN_ERRORS = 5
"""Errors named in a refusal (the server's log and window have them all)."""

Restart = Callable[[Path], Awaitable["LoadResult | None"]]


class Restartable(Protocol):
    """What :func:`restart_request` reads of the running server (a ``ServerApp``)."""

    @property
    def path(self) -> Path | None: ...

    def keyed_radios(self) -> list[str]: ...


def _same(one: Path | None, other: Path) -> bool:
    return one is not None and one.resolve() == other.resolve()


def _only_its_own(running: Path | None, target: object) -> str | None:
    """Why a server that restarts only on its own file (headless) refuses ``target``."""
    if running is None or not isinstance(target, str) or _same(running, Path(target)):
        return None
    return (f"it runs {running.name} headless and restarts only on that file, not on "
            f"{Path(target).name}; stop it (or its service) to run another file")


async def station_request(app: Restartable, launch: dict[str, object], *,
                          other_files: bool = True) -> dict[str, object]:
    """The running server's answer to the builder's ``"station"`` (with the ``"file"`` the
    builder has): what it runs and who transmits (nothing changes); refused at once when
    it takes no other file (``other_files`` False: headless) and that one is another."""
    running = app.path
    refusal = None if other_files else _only_its_own(running, launch.get("file"))
    if refusal is not None:
        return {"ok": False, "error": refusal}
    return {"ok": True, "done": f"runs {running.name if running else 'no configuration'}",
            "running": str(running) if running is not None else None,
            "keyed": app.keyed_radios()}


async def restart_request(app: Restartable, launch: dict[str, object], restart: Restart,
                          *, other_files: bool = True) -> dict[str, object]:
    """The running server's answer to the builder's ``"restart"`` (see the module);
    ``other_files`` False (headless): only its own file."""
    target = launch.get("file")
    if not isinstance(target, str) or not target or "\0" in target:
        return {"ok": False, "error": f"'file' must be a path, not {target!r:.60}"}
    refusal = None if other_files else _only_its_own(app.path, target)
    if refusal is not None:
        return {"ok": False, "error": refusal}
    path = Path(target)
    confirmed = launch.get("confirmed")
    agreed = {str(name) for name in confirmed} if isinstance(confirmed, list) else set()
    running = app.path
    log.info("The station builder asked to restart on %s", path)
    keyed = app.keyed_radios()
    unconfirmed = not set(keyed) <= agreed
    if running is not None and not _same(running, path) and launch.get("replace") is not True:
        return {"ok": False, "running": str(running), "keyed": keyed if unconfirmed else [],
                "error": f"it runs {running.name}, not {path.name}"}
    if unconfirmed:
        who = ", ".join(keyed)
        log.warning("Not restarted for the station builder: %s transmit%s and the operator "
                    "has not confirmed it", who, "s" if len(keyed) == 1 else "")
        return {"ok": False, "keyed": keyed, "error": f"transmitting now: {who}"}
    if keyed:
        log.warning("Restart while %s transmit%s, confirmed by the operator in the station "
                    "builder", ", ".join(keyed), "s" if len(keyed) == 1 else "")
    result = await restart(path)
    if result is None or result.config is None:
        return {"ok": False, "error": _refusal(path, running, result)}
    return {"ok": True, "done": f"restarted on {path.name}"
            + (f" (it ran {running.name})" if running is not None and not _same(running, path)
               else "")}


def _refusal(path: Path, running: Path | None, result: LoadResult | None) -> str:
    carries = (f"{running.name} carries on unchanged" if running is not None
               else "no configuration runs")
    if result is None:
        return f"{path.name} was not restarted: {carries}"
    errors = result.errors
    shown = "; ".join((f"line {p.line}, column {p.column}: " if p.line else "") + p.message
                      for p in errors[:SHOWN_ERRORS])
    more = f"; ... and {len(errors) - SHOWN_ERRORS} more" if len(errors) > SHOWN_ERRORS else ""
    return (f"{path.name} has {len(errors)} error{'s' if len(errors) != 1 else ''}, so it "
            f"was not restarted: {carries}. {shown}{more}")


def ask_to_restart(path: Path, confirmed: Sequence[str] | None = None, replace: bool = False,
                   *, timeout: float = RESTART_TIMEOUT) -> ServerAnswer:
    """Ask the running server (this user's, through the single-instance channel) to
    restart on ``path`` (``confirmed``: who the operator agreed may transmit; ``replace``:
    the operator agreed to a file other than the running one); ``confirmed`` None only
    looks (:func:`station_request`).  Blocks: the builder calls it off its window's
    thread."""
    from moas_gui.builder.apply import NOT_REACHABLE, ServerAnswer
    from moas_gui.single_instance import command

    if confirmed is None:
        reply = command(launch={"command": STATION_COMMAND, "file": str(path.resolve())},
                        timeout=timeout)
    else:
        reply = command(launch={"command": RESTART_COMMAND, "file": str(path.resolve()),
                                "confirmed": list(confirmed), "replace": replace},
                        timeout=timeout)
    if not reply.running:
        return ServerAnswer(False, NOT_REACHABLE, reached=False)
    if reply.trouble is not None:
        return ServerAnswer(False, f"The running moas-server did not answer ({reply.trouble}); "
                             "nothing was restarted from here. A server started with "
                             "--new-instance takes no requests from the builder.",
                      reached=False)
    keyed = reply.answer.get("keyed")
    running = reply.answer.get("running")
    who = tuple(str(k) for k in keyed) if isinstance(keyed, list) else ()
    if confirmed is None and not reply.taken:
        return ServerAnswer(False, f"The running server refused: {reply.refusal}")
    if confirmed is None:
        other = (str(running) if isinstance(running, str)
                 and Path(running).resolve() != path.resolve() else None)
        return ServerAnswer(False, f"The running server {reply.done or reply.refusal}.",
                      keyed=who, running=other, looked=True)
    if reply.taken:
        return ServerAnswer(True, f"The running server {reply.done or 'restarted'}.")
    return ServerAnswer(False, f"The running server refused: {reply.refusal}", keyed=who,
                  running=str(running) if isinstance(running, str) else None)


__all__ = ["RESTART_COMMAND", "RESTART_TIMEOUT", "STATION_COMMAND", "Restartable",
           "ask_to_restart", "restart_request", "station_request"]
