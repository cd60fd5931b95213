"""Answering one line of one connection: the bad-line rule, then the command.

:func:`answer` takes what :mod:`.framing` split off and replies exactly once
(a blank line excepted), calling the backend for the work.  A refusal by the
backend (:class:`~.backend.RequestError`) becomes an error reply with its code
and sentence; any other failure becomes an ``internal`` error reply and an
Error log line with the traceback, and the connection carries on.

A client decides how many bad or refused lines it sends: each kind of refusal is a
Debug line once a minute at most, all connections together, the next saying how many
were left out (:data:`TROUBLE`); a failure of the server's, an Error line once a
minute per command.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Coroutine
from typing import Any

from moas_gui.edge.admission import checking
from moas_gui.log_limit import LogLimiter, held_text

from .backend import ClientBackend, ErrorCode, RequestError
from .connection import Connection, LayoutKey, clean_name
from .framing import MAX_LINE, Line, LongLine
from .identity import Party, as_operator, serving
from .messages import event, hello_result
from .requests import BadLine, InvalidRequest, Request, parse_line

log = logging.getLogger(__name__)

MAX_BAD_LINES = 3
"""Bad lines in a row after which a connection is closed."""
TROUBLE = LogLimiter()
"""The lines about refused requests: one a minute per kind, every connection together."""


def _trouble(kind: object, level: int, message: str, *args: object) -> None:
    held = TROUBLE.allow(kind)
    if held is not None:
        log.log(level, message + "%s", *args, held_text(held))


Waiting = Coroutine[Any, Any, None]
"""What :func:`answer` returns for a line whose answer waits (a hello's token, checked
off the loop): the caller awaits it before it reads the connection's next line."""


def answer(backend: ClientBackend, conn: Connection, item: Line | LongLine) -> Waiting | None:
    """Answers one line; None, or what to await for the answer (a token to check)."""
    if conn.closed:  # ended meanwhile (an operator removed): nothing more is obeyed
        return None
    if isinstance(item, LongLine):
        parsed: Request | InvalidRequest | BadLine | None = BadLine(
            f"the line is longer than {MAX_LINE:,} bytes"
        )
    else:
        parsed = parse_line(item.data)
    if parsed is None:
        return None
    if isinstance(parsed, BadLine):
        conn.bad_lines += 1
        _trouble("bad line", logging.DEBUG, "Bad line from %s: %s", conn, parsed.message)
        conn.reply_error(None, ErrorCode.BAD_REQUEST, parsed.message)
        if conn.bad_lines >= MAX_BAD_LINES:
            conn.close(f"{MAX_BAD_LINES} bad lines in a row")
        return None
    conn.bad_lines = 0
    if isinstance(parsed, InvalidRequest):
        _trouble("invalid", logging.DEBUG, "Refused a request from %s: %s", conn,
                 parsed.message)
        conn.reply_error(parsed.id, parsed.code, parsed.message)
        return None
    if conn.identity.kind is Party.NOBODY and parsed.cmd != "hello":
        _trouble("no token", logging.DEBUG, "Refused %s from %s: no token yet", parsed.cmd,
                 conn)
        conn.reply_error(parsed.id, ErrorCode.FORBIDDEN, "this address needs an operator's "
                         'token: say hello with "token" first')
        return None
    if parsed.cmd == "hello" and parsed.args["token"] and conn.authenticate is not None:
        return _hello_with_token(backend, conn, parsed, parsed.args["token"])
    try:
        with serving(conn.identity):
            HANDLERS[parsed.cmd](backend, conn, parsed)
    except RequestError as e:
        _trouble(("refused", parsed.cmd), logging.DEBUG, "Refused %s from %s: %s",
                 parsed.cmd, conn, e.message)
        conn.reply_error(parsed.id, e.code, e.message)
    except Exception as e:
        if TROUBLE.allow(("failed", parsed.cmd)) is not None:
            log.exception("The server failed on %s from %s", parsed.cmd, conn)
        conn.reply_error(
            parsed.id, ErrorCode.INTERNAL,
            f"the server failed on {parsed.cmd}: {type(e).__name__}: {e}",
        )
    return None


def _identify(conn: Connection, token: str | None) -> str | None:
    """Settles who a saying-hello connection without a token check is; the refusal's
    sentence, or None."""
    if token is None:
        if conn.identity.kind is Party.NOBODY:
            return ("this address needs an operator's token (moas-server --add-operator "
                    'makes one; give it as "token" in hello)')
        return None
    return "that token is not one of this station's operators (it may have been removed)"


async def _hello_with_token(backend: ClientBackend, conn: Connection, request: Request,
                            token: str) -> None:
    """A hello with a token: the check runs off the loop (:mod:`moas_gui.net.secrets`),
    and this connection's next line waits for it."""
    assert conn.authenticate is not None
    with checking(conn.ticket):  # its place in the admission kept while it waits
        verdict = await conn.authenticate(token)
    if conn.closed:
        return
    if verdict.operator is None:
        refusal = verdict.refusal or "that token is not one of this station's operators"
        kind = "busy" if verdict.busy else "throttled" if verdict.wait > 0 else "wrong token"
        _refused_hello(kind, conn, refusal)
        conn.reply_error(request.id, ErrorCode.UNAVAILABLE if verdict.busy
                         else ErrorCode.FORBIDDEN, refusal)
        return
    conn.identity = as_operator(verdict.operator, conn.address)
    if conn.identified is not None:
        conn.identified(conn.identity)
    _greet(backend, conn, request)


def _hello(backend: ClientBackend, conn: Connection, request: Request) -> None:
    args = request.args
    refusal = _identify(conn, args["token"] or None)
    if refusal is not None:  # not greeted: the hello deadline closes it unless it tries again
        _refused_hello("wrong token" if args["token"] else "no token", conn, refusal)
        conn.reply_error(request.id, ErrorCode.FORBIDDEN, refusal)
        return
    _greet(backend, conn, request)


def _refused_hello(kind: str, conn: Connection, refusal: str) -> None:
    """Anyone may say hello with a wrong token (or none) as often as it likes: one line a
    minute per kind of refusal, every connection together, then with the count."""
    _trouble(("refused hello", kind), logging.INFO, "Refused the hello of %s: %s", conn,
             refusal)


def _greet(backend: ClientBackend, conn: Connection, request: Request) -> None:
    args = request.args
    conn.name = clean_name(args["client"])
    conn.station, conn.radio = args["station"], args["radio"]
    conn.wants_log = args["log"]
    serves = ""
    if conn.station is not None:
        serves = f" for station {conn.station}" + (
            f" radio {conn.radio}" if conn.radio is not None else ""
        )
    operator = conn.identity.operator
    if operator is not None:
        serves += f' (operator "{operator.name}", role {operator.role.value})'
    conn.note('Client at %s is "%s"%s', conn.address, conn.name, serves)
    shown = None if operator is None else {
        "name": operator.name, "role": operator.role.value,
        "radios": None if operator.radios is None else sorted(list(r) for r in operator.radios)}
    conn.reply(request.id, request.cmd, hello_result(shown))
    conn.greeted = True
    if conn.ticket is not None:
        conn.ticket.greeted()  # out of its address's reserve for newcomers (admission)
    try:
        line = event("state", backend.snapshot())
    except RequestError as e:
        log.debug("No state event for %s yet: %s", conn, e.message)
        return
    conn.send(line)


def _state(backend: ClientBackend, conn: Connection, request: Request) -> None:
    conn.reply(request.id, request.cmd, backend.snapshot())


def _frequency(backend: ClientBackend, conn: Connection, request: Request) -> None:
    a = request.args
    backend.frequency(a["station"], a["radio"], a["khz"], a["tx_khz"])
    conn.reply(request.id, request.cmd, {})


def _active(backend: ClientBackend, conn: Connection, request: Request) -> None:
    backend.set_focus(request.args["station"], request.args["radio"], "active")
    conn.reply(request.id, request.cmd, {})


def _focus(backend: ClientBackend, conn: Connection, request: Request) -> None:
    backend.set_focus(request.args["station"], request.args["radio"], "focus")
    conn.reply(request.id, request.cmd, {})


def _select(backend: ClientBackend, conn: Connection, request: Request) -> None:
    a = request.args
    result = backend.select(a["station"], a["radio"], a["antenna"], a["target"], a["exclusive"])
    conn.reply(request.id, request.cmd, result)


def _function(backend: ClientBackend, conn: Connection, request: Request) -> None:
    a = request.args
    backend.function(a["station"], a["radio"], a["function"])
    conn.reply(request.id, request.cmd, {})


def _release(backend: ClientBackend, conn: Connection, request: Request) -> None:
    backend.release(request.args["station"], request.args["radio"])
    conn.reply(request.id, request.cmd, {})


def _relative(backend: ClientBackend, conn: Connection, request: Request) -> None:
    a = request.args
    result = backend.relative(a["station"], a["radio"], a["step"], a["index"])
    conn.reply(request.id, request.cmd, result)


def _layout(backend: ClientBackend, conn: Connection, request: Request) -> None:
    a = request.args
    key: LayoutKey = (a["station"], a["radio"], a["rows"], a["columns"])
    layout = backend.layout(*key)
    conn.follow(key, layout)
    conn.reply(request.id, request.cmd, layout)


def _rotate(backend: ClientBackend, conn: Connection, request: Request) -> None:
    backend.rotate(request.args["rotator"], request.args["heading"])
    conn.reply(request.id, request.cmd, {})


def _stop(backend: ClientBackend, conn: Connection, request: Request) -> None:
    backend.stop(request.args["rotator"])
    conn.reply(request.id, request.cmd, {})


def _switches(backend: ClientBackend, conn: Connection, request: Request) -> None:
    backend.switches(request.cmd.split("_", 1)[0],  # type: ignore[arg-type]
                     force=bool(request.args.get("force", False)))
    conn.reply(request.id, request.cmd, {})


Handler = Callable[[ClientBackend, Connection, Request], Any]

HANDLERS: dict[str, Handler] = {
    "hello": _hello,
    "state": _state,
    "frequency": _frequency,
    "active": _active,
    "focus": _focus,
    "select": _select,
    "function": _function,
    "relative": _relative,
    "release": _release,
    "layout": _layout,
    "rotate": _rotate,
    "stop": _stop,
    "stop_switches": _switches,
    "start_switches": _switches,
    "reset_switches": _switches,
}


__all__ = ["HANDLERS", "MAX_BAD_LINES", "answer"]
