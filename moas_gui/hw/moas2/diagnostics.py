"""What the switch link says about a box: which command an error belongs to,
and the text of Save Switch Data.  Pure: values in, text out."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field

from ...engine.switchstate import SwitchState
from .commands import encode, split
from .messages import BoxMessage, Command, ErrorReply
from .replies import encode_reply
from .sync import initialise


@dataclass(slots=True)
class Batch:
    """Commands written before one ping; the box answers them in order, so an
    error that arrives before that ping's answer belongs to one of them."""

    expect_active: bool | None
    commands: list[bytes] = field(default_factory=list)


_CAN_CAUSE: dict[str, Callable[[bytes], bool]] = {
    "T": lambda c: c[:1] in (b"~", b"@"),
    "A": lambda c: c not in (b"';", b"|;"),
}
"""Which commands can draw each error letter (others: any command)."""


def blame(where: str, reply: ErrorReply, commands: Sequence[bytes]) -> str:
    """A sentence naming the command (or the few) that drew ``reply``."""
    fits = _CAN_CAUSE.get(reply.code, _any_command)
    suspects = [c.decode("ascii", "replace") for c in commands if fits(c)]
    what = f"?{reply.code} ({reply.meaning})"
    if len(suspects) == 1:
        return f"{where} refused {suspects[0]}: {what}"
    if suspects:
        return f"{where} answered {what} to one of: {' '.join(_last(suspects, 8))}"
    return f"{where} sent {what} for no command this link sent"


def switch_data(
    header: Iterable[str],
    answers: Iterable[tuple[Command, BoxMessage | None]],
    state: SwitchState,
    errors: Iterable[str],
) -> str:
    """The text of Save Switch Data for one switch."""
    lines = [*header, f"written: {time.strftime('%Y-%m-%d %H:%M:%S')}", ""]
    for command, reply in answers:
        sent = encode(command).decode()
        if reply is None:
            lines.append(f"{sent:6} -> no answer")
        else:
            lines.append(f"{sent:6} -> {encode_reply(reply).decode()}  {reply}")
    lines += ["", "Tables and settings as loaded (the commands, one per line):"]
    lines += [f"  {encode(part).decode()}" for c in initialise(state).commands for part in split(c)]
    lines += ["", f"conflict pairs: {sorted(state.conflicts)}"]
    lines += [f"fast pairs: {sorted(state.fast)}", f"systems: {list(state.systems)}"]
    errors = list(errors)
    lines += ["", "Recent errors:", *(f"  {e}" for e in errors)]
    if not errors:
        lines.append("  none")
    return "\n".join(lines) + "\n"


def _any_command(command: bytes) -> bool:
    return True


def _last(items: list[str], n: int) -> Iterable[str]:
    return items if len(items) <= n else ["...", *items[-n:]]


__all__ = ["Batch", "blame", "switch_data"]
