"""Who a connection is, and what that may do: pure functions, no sockets.

Every connection has an :class:`Identity`, settled by its ``hello``:

* **local** -- an anonymous peer at ``127.0.0.1`` or ``::1`` (a program on this
  computer): every right, as before operators existed;
* **lan** -- an anonymous peer inside ``ClientAllow`` on a LAN kept open (no
  ``--require-token``): today's rights, everything but the admin commands;
* **operator** -- a peer that gave a valid ``"token"`` in its hello: its
  :class:`~moas_gui.operators.Role` and radios;
* **nobody** -- a connection that has not said who it is where a token is
  needed: it may say hello and nothing else.

Other loopback addresses (``127.0.0.2`` ...) count as the LAN, so tests play
other hosts.  Where a token is needed (:func:`token_needed`): never from
``127.0.0.1``/``::1``; from ``ClientAllow`` networks only with
``--require-token``; from anywhere else always, and only over TLS.

The admission policy (:mod:`.admission`) reads :attr:`Identity.is_operator`:
an authenticated operator has capacity of its own.

:func:`check` is the rule: given an identity and an :class:`Action`, the
refusal's sentence or None.  The server's one door (``ServerApp.act``) and the
backend's rotator and switch calls ask it with the identity of the request
being served (:func:`current`, set by :mod:`.dispatch` around each request with
:func:`serving`; a task or callback the request started does not inherit it).
"""

from __future__ import annotations

import contextlib
import contextvars
import ipaddress
import logging
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from enum import Enum

from moas_gui.errors import RequestRefused
from moas_gui.operators import Operator, Role

from .access import IPNetwork, is_allowed, peer_address

log = logging.getLogger(__name__)

RadioRef = tuple[int, int]


class Party(Enum):
    """What a connection is before its role: this computer, the LAN, an operator, or
    nobody yet."""

    LOCAL = "local"
    LAN = "lan"
    OPERATOR = "operator"
    NOBODY = "nobody"


@dataclass(frozen=True, slots=True)
class Identity:
    """Who a connection is (see the module's docstring)."""

    kind: Party
    address: str
    operator: Operator | None = None

    @property
    def is_operator(self) -> bool:
        """An authenticated operator (the admission policy gives it capacity of its own)."""
        return self.kind is Party.OPERATOR

    @property
    def name(self) -> str:
        """How the log names it: the operator's name, else what it is."""
        if self.operator is not None:
            return self.operator.name
        return {Party.LOCAL: "local client", Party.LAN: "LAN client"}.get(self.kind, "anonymous")

    def __str__(self) -> str:
        return f"{self.name} at {self.address}"


LOCAL_ADDRESSES = (ipaddress.ip_address("127.0.0.1"), ipaddress.ip_address("::1"))


def is_local(host: str, local: Iterable[object] = LOCAL_ADDRESSES) -> bool:
    """This computer itself: ``127.0.0.1`` or ``::1`` (not other loopback addresses).
    ``local``: the addresses that count as this computer (a test that drives a browser,
    which always connects from ``127.0.0.1``, gives none to play a LAN peer)."""
    return peer_address(host) in tuple(local)


def token_needed(host: str, allowed: Iterable[IPNetwork], require_token: bool,
                 local: Iterable[object] = LOCAL_ADDRESSES) -> bool:
    """Whether a peer at ``host`` must give an operator's token."""
    if is_local(host, local):
        return False
    if is_allowed(host, allowed):
        return require_token
    return True


def anonymous(host: str, address: str, allowed: Iterable[IPNetwork], require_token: bool,
              local: Iterable[object] = LOCAL_ADDRESSES) -> Identity:
    """The identity of a connection before (or without) a token."""
    if token_needed(host, allowed, require_token, local):
        return Identity(Party.NOBODY, address)
    return Identity(Party.LOCAL if is_local(host, local) else Party.LAN, address)


def as_operator(operator: Operator, address: str) -> Identity:
    return Identity(Party.OPERATOR, address, operator)


class Forbidden(RequestRefused):
    """What the role of the one asking may not do: the client protocol's ``forbidden``."""

    code = "forbidden"

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message


# -- what may be done ------------------------------------------------------------------------

@dataclass(frozen=True, slots=True)
class Action:
    """A change asked for: ``radios`` it touches (for a rotator: the radios using its
    antennas; empty: none own it), and whether it is an admin command."""

    what: str
    radios: frozenset[RadioRef] = frozenset()
    admin: bool = False


def enforce(action: Action) -> None:
    """Raises :class:`Forbidden` when the identity being served (:func:`current`) may not
    do ``action``; logs who did it otherwise (an operator at Info, never rate-limited;
    an anonymous client at Debug: the engine's own line says what changed)."""
    identity = current()
    refusal = check(identity, action)
    if refusal is not None:
        raise Forbidden(refusal)
    if identity is not None:  # an operator's every change at Info; anonymous ones at Debug
        log.log(logging.INFO if identity.is_operator else logging.DEBUG,
                "%s: %s", identity, action.what)


def check(identity: Identity | None, action: Action) -> str | None:
    """Why ``identity`` may not do ``action``, or None.  ``None`` as identity is the
    server's own window (and code that acts for nobody in particular): allowed."""
    if identity is None or identity.kind is Party.LOCAL:
        return None
    if identity.kind is Party.NOBODY:
        return f"{action.what} needs an operator's token from this address (say it in hello)"
    if identity.kind is Party.LAN:
        if action.admin:
            return (f"{action.what} is for an operator with the admin role "
                    "(or a program on the server's own computer)")
        return None
    operator = identity.operator
    assert operator is not None
    if operator.role is Role.ADMIN:
        return None
    if operator.role is Role.VIEW:
        return f'operator "{operator.name}" has the view role: it may look, not change'
    if action.admin:
        return f'{action.what} is for the admin role; operator "{operator.name}" has operate'
    if operator.radios is None:
        return None
    if not action.radios:
        return (f'{action.what} is not tied to a radio of operator "{operator.name}" '
                f"({operator.radios_text()})")
    foreign = sorted(action.radios - operator.radios)
    if foreign:
        shown = ", ".join(f"{s}/{r}" for s, r in foreign)
        return (f'{action.what} touches radio {shown}, not one of operator "{operator.name}"\'s '
                f"({operator.radios_text()})")
    return None


class _Serving:
    """The identity of the request being served, for as long as it is served: a task or
    callback that the request started copies the context, and finds it over."""

    __slots__ = ("identity", "open")

    def __init__(self, identity: Identity) -> None:
        self.identity = identity
        self.open = True


_serving: contextvars.ContextVar[_Serving | None] = contextvars.ContextVar(
    "moas_serving", default=None)


@contextlib.contextmanager
def serving(identity: Identity) -> Iterator[None]:
    """Within it, :func:`current` is ``identity`` (:mod:`.dispatch` wraps each request)."""
    scope = _Serving(identity)
    token = _serving.set(scope)
    try:
        yield
    finally:
        scope.open = False
        _serving.reset(token)


def current() -> Identity | None:
    """The identity whose request is being served now (None: the server itself, or a
    task a request once started, which acts for nobody in particular)."""
    scope = _serving.get()
    return scope.identity if scope is not None and scope.open else None


__all__ = [
    "LOCAL_ADDRESSES",
    "Action",
    "Forbidden",
    "Identity",
    "Party",
    "RadioRef",
    "anonymous",
    "as_operator",
    "check",
    "current",
    "enforce",
    "is_local",
    "serving",
    "token_needed",
]
