"""What the server is doing, in one value the window, tray and headless log share."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum


class ServerState(str, Enum):
    """The four states the status icon shows (manual 3.8)."""

    NO_CONFIG = "no_config"
    NORMAL = "normal"
    UNRESPONSIVE = "unresponsive"
    STOPPED = "stopped"


@dataclass(frozen=True, slots=True)
class ServerStatus:
    """What the window's status bar and tray icon show of the server."""

    state: ServerState = ServerState.NO_CONFIG
    file: str | None = None
    switches: tuple[tuple[int, str], ...] = ()
    """``(switch id, status)`` with status ``connecting``, ``ok``, ``unresponsive`` or ``stopped``."""
    clients: int = 0
    loop_lag_ms: int = 0
    """The largest lag of the event loop since the server started, in milliseconds: how
    late its 100 ms timer ran at worst, the opening of a configuration not counted
    (:mod:`moas_gui.loop_watch`)."""

    @property
    def summary(self) -> str:
        """One line for the status bar and the tray tooltip."""
        if self.file is None:
            return "No configuration open"
        parts = [self.file]
        if self.switches:
            parts.append(", ".join(f"switch {i} {s}" for i, s in self.switches))
        else:
            parts.append("no switches")
        parts.append(f"{self.clients} client{'s' if self.clients != 1 else ''}")
        parts.append(f"loop lag {self.loop_lag_ms} ms at most")
        return " \u2014 ".join(parts)


DESCRIPTIONS = {
    ServerState.NORMAL: "All switches answering",
    ServerState.UNRESPONSIVE: "A switch is not answering",
    ServerState.STOPPED: "Switches stopped: relays off",
    ServerState.NO_CONFIG: "No configuration open",
}


def overall_state(has_config: bool, stopped: bool, switch_states: list[str]) -> ServerState:
    """The one state the icon shows: no configuration, then a switch that does not
    answer (even while stopped: it needs attention before a start), then stopped,
    then normal."""
    if not has_config:
        return ServerState.NO_CONFIG
    if any(s in ("unresponsive", "connecting") for s in switch_states):
        return ServerState.UNRESPONSIVE
    if stopped:
        return ServerState.STOPPED
    return ServerState.NORMAL


__all__ = ["DESCRIPTIONS", "ServerState", "ServerStatus", "overall_state"]
