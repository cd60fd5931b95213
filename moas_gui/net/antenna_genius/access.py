"""Who may use the Antenna Genius front, and whether they must authenticate.

The AG protocol has no TLS: it is served only to loopback and the ``ClientAllow``
networks, never beyond.  Everything the front asks about access goes through one
:class:`AgAccess`, so that the server's one access policy (operators, tokens,
``--require-token``) can take its place whole:

* :meth:`~AgAccess.allowed` -- one call when a connection is accepted: None (it may
  stay) or why it is refused (an address outside ``ClientAllow``);
* :attr:`~AgAccess.admission` -- the pool the front's listener admits connections
  to: the program's one admission policy (:mod:`moas_gui.edge.admission`: caps per
  address and in total, the fair share, the reserve before a first command);
* :meth:`~AgAccess.needs_token` -- whether that peer gets ``V... AG AUTH`` and must send
  ``auth code=N`` before anything else;
* :meth:`~AgAccess.check_code` -- the operator an ``auth`` code stands for, or None.

:class:`SimpleAccess` is what runs today: loopback never needs a code; another
allowed address needs one only when ``require_token`` is set; codes map to
operators' names.  Failed ``auth`` attempts are limited per address
(:class:`AuthFailures`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Protocol

from moas_gui.edge.admission import Admission, address_key
from moas_gui.net.access import allowed_networks, is_allowed, peer_address
from moas_gui.net.identity import Identity, is_local

MAX_AUTH_FAILURES = 5
"""Wrong ``auth`` codes one address may send before it is shut out for a while."""
AUTH_LOCKOUT = 300.0
"""Seconds an address that sent too many wrong codes is refused."""


class AgAccess(Protocol):
    admission: Admission

    def identity(self, host: str, address: str, operator: str | None) -> Identity | None: ...

    def allowed(self, host: str) -> str | None: ...

    def needs_token(self, host: str) -> bool: ...

    def check_code(self, code: str) -> str | None: ...


def is_loopback(host: str) -> bool:
    address = peer_address(host)
    return address is not None and address.is_loopback


class SimpleAccess:
    """Loopback and ``ClientAllow`` only; codes required beyond loopback only when
    ``require_token``; at most ``total`` connections, ``per_address`` from one address."""

    def __init__(self, client_allow: Callable[[], Iterable[str] | None] = lambda: None, *,
                 require_token: bool = False, codes: Mapping[str, str] | None = None,
                 check: Callable[[str], str | None] | None = None,
                 total: int = 64, per_address: int = 16) -> None:
        self.client_allow = client_allow
        self.require_token = require_token
        self.codes = dict(codes or {})
        self.check = check
        """The station's own check of a code: an operator's AG code or token -> its
        name (the server passes the operators book's)."""
        self.identify: Callable[[str, str, str | None], Identity | None] | None = None
        """Who a connection is for the roles' rules (:mod:`moas_gui.net.identity`): the
        server's; None (tests): nobody in particular, which the rules let through."""

        self.admission = Admission(total, per_address, what="Antenna Genius connections")

    def identity(self, host: str, address: str, operator: str | None) -> Identity | None:
        return None if self.identify is None else self.identify(host, address, operator)

    def allowed(self, host: str) -> str | None:
        if not is_allowed(host, allowed_networks(self.client_allow())):
            return ("the address is not in the allowed networks (ClientAllow in the "
                    "configuration decides)")
        return None

    def needs_token(self, host: str) -> bool:
        """As for the client port: never from this computer (``127.0.0.1``, ``::1``);
        from the LAN (other loopback addresses count as the LAN) with ``require_token``."""
        return self.require_token and not is_local(host)

    def check_code(self, code: str) -> str | None:
        named = self.codes.get(code.strip())
        if named is None and self.check is not None:
            named = self.check(code.strip())
        return named


class AuthFailures:
    """Wrong ``auth`` codes per address: after :data:`MAX_AUTH_FAILURES` the address is
    refused for :data:`AUTH_LOCKOUT` seconds (``now`` is the caller's clock)."""

    def __init__(self, limit: int = MAX_AUTH_FAILURES, lockout: float = AUTH_LOCKOUT) -> None:
        self.limit, self.lockout = limit, lockout
        self._failed: dict[str, tuple[int, float]] = {}

    def failed(self, host: str, now: float) -> bool:
        """Counts a wrong code; True when the address is now locked out."""
        key = address_key(host)
        count, _ = self._failed.get(key, (0, now))
        self._failed[key] = (count + 1, now)
        return count + 1 >= self.limit

    def locked(self, host: str, now: float) -> bool:
        key = address_key(host)
        count, when = self._failed.get(key, (0, now))
        if count >= self.limit and now - when < self.lockout:
            return True
        if count >= self.limit:
            del self._failed[key]
        return False

    def succeeded(self, host: str) -> None:
        self._failed.pop(address_key(host), None)


__all__ = ["AUTH_LOCKOUT", "MAX_AUTH_FAILURES", "AgAccess", "AuthFailures", "SimpleAccess",
           "is_loopback"]
